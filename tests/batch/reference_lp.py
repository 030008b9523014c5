r"""Null-space reduction of the closure LPs to tiny max–min problems.

LP1/LP2 (``docs/conventions.md``) read

.. math::

    d^* = \max d \quad \text{s.t.} \quad G f = 0,\; F f - \mathbf 1 d \ge 0,\;
    d \ge 0,\; \textstyle\sum_i f_{n,i} \le N .

The feasible set without the budget is a cone, so :math:`d^* = N \max(0, t^*)` with

.. math::

    t^* = \max_{f} \min_j (F f)_j \quad \text{s.t.} \quad G f = 0,\;
    e^T f = 1

(``e`` sums the normal components): a positive margin is attained with the whole
budget spent, and ``d* = 0`` otherwise.  With an orthonormal basis ``Z`` (M, m) of
``N(G)`` (the same relative rank threshold as the single path, see
:func:`null_spaces`),
``f = Z y`` and ``c = Zᵀ e``; the equality is eliminated with a Householder
reflection of ``c``: ``y = c/‖c‖² + W u`` with ``W`` (m, m−1) orthonormal and
``Wᵀ c = 0``.  What is left is, per grasp,

.. math::

    \max_{u, t} t \quad \text{s.t.} \quad -A W u + \mathbf 1 t \le A y_0,
    \qquad A = F Z ,

an LP with ``m`` variables (3 for three spatial hard fingers) and one row per
facet, solved for all grasps at once by :func:`drakegrasp.batch.lp.ipm.solve_max_last`.
It is bounded because every effective cone is pointed (``F f >= 0`` and
``e^T f = 0`` force ``f = 0``).  Corner cases: ``m = 0`` (only ``f = 0`` balances)
and ``c = 0`` (no balanced force pushes) give ``d* = 0``; ``m = 1`` is solved in
closed form, ``t* = min(A y_0)``.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.batch.build.rowspace import _householder, _inverse_frobenius
from drakegrasp.batch.lp.dstar import DStarSolution
from drakegrasp.batch.lp.ipm import solve_max_last

__all__ = ["null_spaces", "solve_margin_lp"]

_PUSH_TOL = 1e-10  # ‖Zᵀe‖ below this: no balanced force has a normal component


def _householder_complement(c: np.ndarray) -> np.ndarray:
    """Orthonormal bases ``W`` (K, m, m-1) of the complements of rows of ``c`` (K, m).

    The reflection ``H = I - 2 v vᵀ / vᵀv`` with ``v = c + sign(c_0)‖c‖ e_0`` maps
    ``c`` onto ``e_0``'s line; its other columns span ``c``'s complement.
    """
    K, m = c.shape
    norm = np.linalg.norm(c, axis=1)
    v = c.copy()
    v[:, 0] += np.where(c[:, 0] >= 0.0, 1.0, -1.0) * norm
    vv = np.einsum("ki,ki->k", v, v)
    H = np.broadcast_to(np.eye(m), (K, m, m)) - (2.0 / vv)[:, None, None] * (
        v[:, :, None] * v[:, None, :]
    )
    return H[:, :, 1:]


def _householder_qr(A: np.ndarray):
    """Vectorised Householder QR of a stack stored (M, w, K), M >= w.

    Returns the upper triangles ``R`` (w, w, K) and the last ``M - w`` columns of
    the complete ``Q`` (M, M - w, K), an orthonormal basis of the complement of
    ``A``'s columns.
    """
    return _householder(A, complement=True)


def null_spaces(G: np.ndarray, *, rank_tol: float):
    """Numerical ranks and orthonormal null-space bases of a stack of matrices.

    Parameters
    ----------
    G : (K, w, M) float
    rank_tol : float
        Singular values ``<= rank_tol * σ_max`` count as zero (as
        :func:`drakegrasp.core.linalg.matrix_rank`).

    Returns
    -------
    rank : (K,) int
    groups : list of (rows, Z)
        For each nullity ``m > 0`` present: the grasp indices (k,) and bases
        ``Z`` (k, M, m) with orthonormal columns spanning ``N(G)``.

    Notes
    -----
    Fast path: a Householder QR of ``Gᵀ`` vectorised over the stack.  When it
    certifies full row rank, ``1/‖R⁻¹‖_F <= σ_min`` and ``σ_max <= ‖G‖_F``
    give ``σ_min > rank_tol σ_max`` and the trailing columns of ``Q`` span
    ``N(G)``.  The uncertain rest (rank-deficient or nearly so) takes a full SVD,
    which applies the threshold exactly.
    """
    K, w, M = G.shape
    rank = np.zeros(K, dtype=int)
    groups = []
    svd_rows = np.arange(K)
    if M > w and K > 0:
        R, Q = _householder_qr(np.transpose(G, (2, 1, 0)))
        gnorm = np.sqrt(np.einsum("kij,kij->k", G, G))
        # 1/‖R⁻¹‖_F > rank_tol ‖G‖_F, written without dividing by inf.
        certain = _inverse_frobenius(R) * rank_tol * gnorm < 1.0
        rows = np.flatnonzero(certain)
        if rows.size:
            rank[rows] = w
            groups.append(
                (rows, np.ascontiguousarray(np.transpose(Q[:, :, rows], (2, 0, 1))))
            )
        svd_rows = np.flatnonzero(~certain)
    if svd_rows.size:
        _, sv, Vh = np.linalg.svd(G[svd_rows], full_matrices=True)
        r = np.sum(sv > rank_tol * sv[:, :1], axis=1)
        rank[svd_rows] = r
        for nullity in np.unique(M - r):
            m = int(nullity)
            if m > 0:
                sel = np.flatnonzero(M - r == m)
                Z = np.swapaxes(Vh[sel, M - m :, :], 1, 2)
                groups.append((svd_rows[sel], Z))
    return rank, groups


def _highs_max_last(B: np.ndarray, h: np.ndarray, fallback: float):
    """``max x_{n-1} s.t. B x <= h`` for one LP with HiGHS: (value, success)."""
    from scipy.optimize import linprog

    c = np.zeros(B.shape[1])
    c[-1] = -1.0
    res = linprog(c, A_ub=B, b_ub=h, bounds=[(None, None)] * B.shape[1], method="highs")
    if res.status != 0:
        return fallback, False
    return -float(res.fun), True


def solve_margin_lp(
    G: np.ndarray,
    facets: list[np.ndarray],
    component_slices: list[slice],
    normal_columns: np.ndarray,
    *,
    rank_tol: float,
    ipm_tol: float = 1e-10,
    ipm_max_iter: int = 60,
) -> DStarSolution:
    """Solve LP1/LP2 for a stack of grasps that share one layout.

    Parameters
    ----------
    G : (K, w, M) float
        Effective grasp matrices.
    facets : list of (K, r_i, k_i) or (1, r_i, k_i) float
        Unit facet rows of each contact's effective cone (leading 1: the same
        cone for every grasp).
    component_slices : list of slice
        Columns of ``G`` that belong to each contact (``k_i`` of them).
    normal_columns : (N,) int
        Column of each ``f_n``.
    rank_tol : float
        Singular values ``<= rank_tol * σ_max`` count as zero.
    ipm_tol : float, optional
        Tolerance of the interior-point method on ``t*`` (relative to ``1 + |t*|``).
    ipm_max_iter : int, optional
        Iteration cap of the interior-point method.  The rare LPs that reach it
        are solved again one by one with HiGHS (``scipy.optimize.linprog``);
        ``converged`` is False only if that fails too.

    Returns
    -------
    DStarSolution
    """
    K, _, M = G.shape
    N = len(normal_columns)
    rank, groups = null_spaces(G, rank_tol=rank_tol)
    d_star = np.zeros(K)
    converged = np.ones(K, dtype=bool)
    for sel, Z in groups:
        m = Z.shape[2]
        c = Z[:, normal_columns, :].sum(axis=1)  # (k, m)
        cnorm2 = np.einsum("ki,ki->k", c, c)
        push = cnorm2 > _PUSH_TOL**2
        if not push.all():
            sel, Z, c, cnorm2 = sel[push], Z[push], c[push], cnorm2[push]
        if sel.size == 0:
            continue
        A = np.concatenate(
            [
                (F if F.shape[0] == 1 else F[sel]) @ Z[:, s, :]
                for F, s in zip(facets, component_slices, strict=True)
            ],
            axis=1,
        )  # (k, r, m)
        y0 = c / cnorm2[:, None]
        h = (A @ y0[..., None])[..., 0]
        if m == 1:
            t = h.min(axis=1)
        else:
            W = _householder_complement(c)
            B = np.concatenate([-(A @ W), np.ones(h.shape + (1,))], axis=2)
            sol = solve_max_last(
                B, h, tol=ipm_tol, max_iter=ipm_max_iter, stop_below=0.0
            )
            t, ok = sol.value, sol.converged
            if not ok.all():
                t, ok = t.copy(), ok.copy()
                for j in np.flatnonzero(~ok):
                    t[j], ok[j] = _highs_max_last(B[j], h[j], t[j])
            converged[sel] = ok
        d_star[sel] = N * np.maximum(t, 0.0)
    return DStarSolution(d_star, rank, converged)
