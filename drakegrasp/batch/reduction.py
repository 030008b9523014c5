r"""Null-space reduction of the closure LPs to tiny max–min problems.

LP1/LP2 (``shared/CONVENTIONS.md``) read

.. math::

    d^* = \max d \quad \text{s.t.} \quad G f = 0,\; F f - \mathbf 1 d \ge 0,\;
    d \ge 0,\; \textstyle\sum_i f_{n,i} \le N .

The feasible set without the budget is a cone, so :math:`d^* = N \max(0, t^*)` with

.. math::

    t^* = \max_{f} \min_j (F f)_j \quad \text{s.t.} \quad G f = 0,\;
    e^T f = 1

(``e`` sums the normal components): a positive margin is attained with the whole
budget spent, and ``d* = 0`` otherwise.  With an orthonormal basis ``Z`` (M, m) of
``N(G)`` (from the SVD, the same relative rank threshold as the single path),
``f = Z y`` and ``c = Zᵀ e``; the equality is eliminated with a Householder
reflection of ``c``: ``y = c/‖c‖² + W u`` with ``W`` (m, m−1) orthonormal and
``Wᵀ c = 0``.  What is left is, per grasp,

.. math::

    \max_{u, t} t \quad \text{s.t.} \quad -A W u + \mathbf 1 t \le A y_0,
    \qquad A = F Z ,

an LP with ``m`` variables (3 for three spatial hard fingers) and one row per
facet, solved for all grasps at once by :func:`drakegrasp.batch.ipm.solve_max_last`.
It is bounded because every effective cone is pointed (``F f >= 0`` and
``e^T f = 0`` force ``f = 0``).  Corner cases: ``m = 0`` (only ``f = 0`` balances)
and ``c = 0`` (no balanced force pushes) give ``d* = 0``; ``m = 1`` is solved in
closed form, ``t* = min(A y_0)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drakegrasp.batch.ipm import solve_max_last

__all__ = ["MarginSolution", "solve_margin_lp"]

_PUSH_TOL = 1e-10  # ‖Zᵀe‖ below this: no balanced force has a normal component


@dataclass(frozen=True)
class MarginSolution:
    """``d*`` and ranks of a stack of closure LPs.

    Attributes
    ----------
    d_star : (K,) float
        Optimal margin of the LP, ``>= 0``.
    rank : (K,) int
        Numerical rank of ``G``.
    singular_values : (K, min(w, M)) float
        Singular values of ``G``, descending.
    converged : (K,) bool
        False where the interior-point method stopped at its iteration cap.
    """

    d_star: np.ndarray
    rank: np.ndarray
    singular_values: np.ndarray
    converged: np.ndarray


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


def solve_margin_lp(
    G: np.ndarray,
    facets: list[np.ndarray],
    component_slices: list[slice],
    normal_columns: np.ndarray,
    *,
    rank_tol: float,
    ipm_tol: float = 1e-10,
) -> MarginSolution:
    """Solve LP1/LP2 for a stack of grasps that share one layout.

    Parameters
    ----------
    G : (K, w, M) float
        Effective grasp matrices.
    facets : list of (K, r_i, k_i) float
        Unit facet rows of each contact's effective cone.
    component_slices : list of slice
        Columns of ``G`` that belong to each contact (``k_i`` of them).
    normal_columns : (N,) int
        Column of each ``f_n``.
    rank_tol : float
        Singular values ``<= rank_tol * σ_max`` count as zero.
    ipm_tol : float, optional
        Tolerance of the interior-point method on ``t*`` (relative to 1 + |t*|).

    Returns
    -------
    MarginSolution
    """
    K, _, M = G.shape
    N = len(normal_columns)
    _, sv, Vh = np.linalg.svd(G, full_matrices=True)
    rank = np.sum(sv > rank_tol * sv[:, :1], axis=1)
    d_star = np.zeros(K)
    converged = np.ones(K, dtype=bool)
    for nullity in np.unique(M - rank):
        m = int(nullity)
        if m == 0:
            continue
        sel = np.flatnonzero(M - rank == m)
        Z = np.swapaxes(Vh[sel, M - m :, :], 1, 2)  # (k, M, m)
        c = Z[:, normal_columns, :].sum(axis=1)  # (k, m)
        cnorm2 = np.einsum("ki,ki->k", c, c)
        push = cnorm2 > _PUSH_TOL**2
        if not push.all():
            sel, Z, c, cnorm2 = sel[push], Z[push], c[push], cnorm2[push]
        if sel.size == 0:
            continue
        A = np.concatenate(
            [
                F[sel] @ Z[:, s, :]
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
            sol = solve_max_last(B, h, tol=ipm_tol)
            t = sol.value
            converged[sel] = sol.converged
        d_star[sel] = N * np.maximum(t, 0.0)
    return MarginSolution(d_star, rank, sv, converged)
