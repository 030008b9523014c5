r"""A batched primal-dual interior-point method for many tiny LPs at once.

Every problem ``k`` of the batch is an LP in inequality form with ``n`` free
variables and ``r`` rows,

.. math::

    \max_x \; x_{n-1} \quad \text{s.t.} \quad B_k x \le h_k ,

paired with its dual :math:`\min_\lambda h_k^T\lambda` s.t.
:math:`B_k^T \lambda = e_{n-1},\ \lambda \ge 0`.  All problems share ``n`` and
``r`` so they live in stacked arrays ``B`` (K, r, n) and ``h`` (K, r); one
iteration of Mehrotra's predictor–corrector method is a few numpy operations on
these stacks, and each problem leaves the active set as soon as it has converged.

Arrays are kept "structure of arrays" internally — ``B`` as (n, r, K), vectors as
(r, K) — so each operation runs over the contiguous batch axis, and the ``n × n``
normal matrices are factorised by an explicit Cholesky loop over their entries
(each step one vector operation over the batch) instead of one LAPACK call per
problem.  Measured on this project's machine this is 3–5× faster than batched
``numpy.matmul``/``numpy.linalg.solve`` on (K, r, n) stacks.
The closure engine (``tests/batch/reference_lp.py``) brings LP1/LP2 to this form
with ``n`` of 1 to 7 and ``r`` of 7 to 40, where the per-problem cost of a general
purpose solver is all overhead.

Assumptions (true for the closure LPs): the primal ``{x : B x <= h}`` is non-empty
and the objective is bounded above, i.e. ``B`` has full column rank and the dual
is feasible.  A problem that fails to converge within ``max_iter`` iterations is
reported with ``converged = False`` and its last iterate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drakegrasp.batch import compiled
from drakegrasp.batch.lp.ipm_kernel import solve_max_last_stack
from drakegrasp.batch.lp.tolerances import IPM_MAX_ITER, IPM_TOL
from drakegrasp.batch.lp.vertex_kernel import active_set_stack
from drakegrasp.errors import InvalidOptionError

__all__ = ["MaxLPSolution", "solve_max_last", "solve_max_last_active"]

_STEP = 0.9995
"""Fraction of the distance to the boundary taken per step (0.995 costs about one
more iteration on the closure LPs; both pass the same agreement tests)."""


@dataclass(frozen=True)
class MaxLPSolution:
    """Solutions of a batch of inequality-form LPs.

    Attributes
    ----------
    value : (K,) float
        Optimal value ``x*_{n-1}`` (the primal objective at the last iterate).
    x : (K, n) float
        Primal optimiser.
    dual : (K, r) float
        Dual multipliers ``λ >= 0`` of the rows.
    converged : (K,) bool
        True when residuals and duality gap fell below the tolerance.
    iterations : (K,) int
        Iterations spent on each problem.
    """

    value: np.ndarray
    x: np.ndarray
    dual: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray


def _cholesky(M: np.ndarray) -> np.ndarray:
    """Lower Cholesky factors of SPD matrices stored (n, n, K) (upper part read)."""
    n = M.shape[0]
    L = np.zeros_like(M)
    floor = 1e-300 + 1e-14 * np.abs(M[np.arange(n), np.arange(n)]).max(axis=0)
    for j in range(n):
        s = M[j, j] - np.einsum("ik,ik->k", L[j, :j], L[j, :j])
        L[j, j] = np.sqrt(np.maximum(s, floor))
        for i in range(j + 1, n):
            L[i, j] = (M[j, i] - np.einsum("ik,ik->k", L[i, :j], L[j, :j])) / L[j, j]
    return L


def _cho_solve(L: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve ``L Lᵀ z = b`` for factors (n, n, K) and right-hand sides (n, K)."""
    n = L.shape[0]
    y = np.empty_like(b)
    for i in range(n):
        y[i] = (b[i] - np.einsum("ik,ik->k", L[i, :i], y[:i])) / L[i, i]
    z = np.empty_like(b)
    for i in reversed(range(n)):
        z[i] = (y[i] - np.einsum("ik,ik->k", L[i + 1 :, i], z[i + 1 :])) / L[i, i]
    return z


def _normal_matrix(B: np.ndarray, D: np.ndarray) -> np.ndarray:
    """``Bᵀ diag(D) B`` for B (n, r, K), D (r, K): upper triangle of (n, n, K)."""
    n = B.shape[0]
    DB = B * D
    M = np.empty((n, n, B.shape[2]))
    for i in range(n):
        for j in range(i, n):
            M[i, j] = np.einsum("rk,rk->k", B[i], DB[j])
    return M


def _mul(B: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``B x`` for B (n, r, K), x (n, K) -> (r, K)."""
    return np.einsum("irk,ik->rk", B, x)


def _tmul(B: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``Bᵀ y`` for B (n, r, K), y (r, K) -> (n, K)."""
    return np.einsum("irk,rk->ik", B, y)


def _max_step(v: np.ndarray, dv: np.ndarray, fraction: float = 1.0) -> np.ndarray:
    """``min(1, fraction * α_max)``, α_max the largest α with ``v + α dv >= 0``.

    ``v`` (r, K) is positive; the result is (K,).
    """
    q = -(dv / v).min(axis=0)  # 1 / α_max where positive
    with np.errstate(divide="ignore"):
        return np.where(q > 0.0, np.minimum(1.0, fraction / q), 1.0)


def _starting_point(B: np.ndarray, h: np.ndarray):
    """Mehrotra's heuristic starting point (least squares, then shifted > 0)."""
    n, r, K = B.shape
    L = _cholesky(_normal_matrix(B, np.ones((r, K))))
    # Primal: least-squares fit of B x = h, slack s = h - B x.
    x = _cho_solve(L, _tmul(B, h))
    s = h - _mul(B, x)
    # Dual: minimum-norm solution of Bᵀ λ = e_{n-1}.
    e = np.zeros((n, K))
    e[-1] = 1.0
    lam = _mul(B, _cho_solve(L, e))
    s = s + np.maximum(-1.5 * s.min(axis=0), 0.0)
    lam = lam + np.maximum(-1.5 * lam.min(axis=0), 0.0)
    sl = np.einsum("rk,rk->k", s, lam)
    s = s + 0.5 * sl / np.maximum(lam.sum(axis=0), 1e-300) + 1e-12
    lam = lam + 0.5 * sl / np.maximum(s.sum(axis=0), 1e-300) + 1e-12
    return x, s, lam, L


def solve_max_last(
    B: np.ndarray,
    h: np.ndarray,
    *,
    tol: float = IPM_TOL,
    max_iter: int = IPM_MAX_ITER,
    stop_below: float | None = None,
    kernel: str = "numpy",
) -> MaxLPSolution:
    r"""Maximise the last variable subject to ``B x <= h``, for a stack of LPs.

    Parameters
    ----------
    B : (K, r, n) float
        Constraint matrices, full column rank.
    h : (K, r) float
        Right-hand sides.
    tol : float, optional
        Convergence tolerance on the scaled residuals and on the duality gap
        :math:`\lambda^T s / (1 + |x_{n-1}|)` (which bounds the error of the
        optimal value once the residuals vanish).
    max_iter : int, optional
        Iteration cap per problem.
    stop_below : float, optional
        Stop a problem as soon as a dual certificate proves its optimum lies
        below this value; its ``value`` is then that certified upper bound, not
        the optimum.  (The closure LPs only need ``max(0, t*)``.)
    kernel : {"numpy", "compiled", "auto"}, optional
        ``"numpy"`` (default): the batched numpy iteration below;
        ``"compiled"``: the same iteration per problem in numba
        (:mod:`drakegrasp.batch.lp.ipm_kernel`; not with ``stop_below``), much
        faster on stacks of larger problems (``n`` about 9, dozens of rows);
        ``"auto"``: compiled when numba is installed and ``stop_below`` unset.

    Returns
    -------
    MaxLPSolution

    Notes
    -----
    Mehrotra's predictor–corrector method with separate primal and dual step
    lengths.  The certificate of ``stop_below``: the multipliers projected onto
    ``Bᵀ λ = e``, ``λ' = λ + B (BᵀB)⁻¹ (e - Bᵀλ)``; when ``λ' >= 0``, weak
    duality gives ``x*_{n-1} <= hᵀλ'``.  Both directions of an iteration share
    one ``n × n`` normal matrix
    :math:`B^T \operatorname{diag}(\lambda/s) B` and its Cholesky factor.
    Converged problems are dropped from the stack, so late iterations cost only
    what the slow problems need.
    """
    if kernel not in ("numpy", "compiled", "auto"):
        raise InvalidOptionError(
            f"kernel must be 'numpy', 'compiled' or 'auto', got {kernel!r}"
        )
    if kernel == "compiled" and stop_below is not None:
        raise InvalidOptionError("the compiled kernel does not take stop_below")
    if kernel == "compiled" or (
        kernel == "auto" and stop_below is None and compiled.AVAILABLE
    ):
        x, lam, conv, its = solve_max_last_stack(B, h, tol, max_iter, _STEP)
        return MaxLPSolution(x[:, -1].copy(), x, lam, conv, its)
    K, r, n = np.shape(B)
    out_x = np.zeros((K, n))
    out_lam = np.zeros((K, r))
    out_conv = np.zeros(K, dtype=bool)
    out_it = np.zeros(K, dtype=int)
    if K == 0:
        return MaxLPSolution(np.zeros(0), out_x, out_lam, out_conv, out_it)
    B = np.ascontiguousarray(np.transpose(B, (2, 1, 0)), dtype=float)  # (n, r, K)
    h = np.ascontiguousarray(np.transpose(h), dtype=float)  # (r, K)

    x, s, lam, L0 = _starting_point(B, h)
    hB = _tmul(B, h) if stop_below is not None else None
    idx = np.arange(K)
    hscale = 1.0 + np.abs(h).max(axis=0)
    for it in range(1, max_iter + 1):
        # Residuals: rp = e - Bᵀ λ (dual feasibility), rd = h - B x - s.
        rp = -_tmul(B, lam)
        rp[-1] += 1.0
        rd = h - _mul(B, x) - s
        sl = s * lam
        gap = sl.sum(axis=0)
        obj = x[-1]
        err_p = np.abs(rp).max(axis=0)
        err_d = np.abs(rd).max(axis=0) / hscale
        err_g = gap / (1.0 + np.abs(obj))
        done = (err_p <= tol) & (err_d <= tol) & (err_g <= tol)
        below = np.zeros_like(done)
        if stop_below is not None:
            # hᵀλ' = hᵀλ + (Bᵀh)ᵀ z costs O(n); form λ' only where it would stop.
            z = _cho_solve(L0, rp)
            bound = np.einsum("rk,rk->k", h, lam) + np.einsum("ik,ik->k", hB, z)
            cand = np.flatnonzero((bound < stop_below) & ~done)
            if cand.size:
                lam_f = lam[:, cand] + _mul(B[:, :, cand], z[:, cand])
                cand = cand[lam_f.min(axis=0) >= 0.0]
                below[cand] = True
                done |= below
                x = x.copy()
                x[-1, cand] = bound[cand]
        last = it == max_iter
        if last or done.any():
            if last:  # accept a last iterate that is close enough, flag the rest
                loose = 1e3 * tol
                ok = (err_p <= loose) & (err_d <= loose) & (err_g <= loose)
                ok |= below
                done[:] = True
            else:
                ok = done
            k = idx[done]
            out_x[k] = x[:, done].T
            out_lam[k] = lam[:, done].T
            out_conv[k] = ok[done]
            out_it[k] = it
            keep = ~done
            if not keep.any():
                break
            idx, B, h, hscale = idx[keep], B[:, :, keep], h[:, keep], hscale[keep]
            L0 = L0[:, :, keep]
            if hB is not None:
                hB = hB[:, keep]
            x, s, lam = x[:, keep], s[:, keep], lam[:, keep]
            rp, rd, sl, gap = rp[:, keep], rd[:, keep], sl[:, keep], gap[keep]
        mu = gap / r

        D = lam / s
        L = _cholesky(_normal_matrix(B, D))
        # Predictor (affine scaling) direction, rc = -λ∘s; with D = λ/s,
        # (rc - λ∘rd)/s = -D (s + rd) and Δλ = (rc - λ∘Δs)/s = -λ - D Δs.
        dx = _cho_solve(L, rp + _tmul(B, D * (s + rd)))
        ds = rd - _mul(B, dx)
        dlam = -lam - D * ds
        a_p = _max_step(s, ds)
        a_d = _max_step(lam, dlam)
        mu_aff = np.einsum("rk,rk->k", s + a_p * ds, lam + a_d * dlam) / r
        sigma = (mu_aff / np.maximum(mu, 1e-300)) ** 3
        # Corrector: rc = σμ - λ∘s - Δλ_aff∘Δs_aff, used as rc/s.
        rcs = (sigma * mu - dlam * ds) / s - lam
        dx = _cho_solve(L, rp - _tmul(B, rcs - D * rd))
        ds = rd - _mul(B, dx)
        dlam = rcs - D * ds
        a_p = _max_step(s, ds, _STEP)
        a_d = _max_step(lam, dlam, _STEP)
        x = x + a_p * dx
        s = s + a_p * ds
        lam = lam + a_d * dlam

    value = out_x[:, -1].copy()
    return MaxLPSolution(value, out_x, out_lam, out_conv, out_it)


def solve_max_last_active(
    B: np.ndarray, h: np.ndarray, x0: np.ndarray, *, max_steps: int = 200
) -> MaxLPSolution:
    r"""The LPs of :func:`solve_max_last` by an exact active-set method, from ``x0``.

    A vertex method is exact where the interior-point method is not: on LPs
    whose optimum is degenerate its normal matrices
    :math:`B^T \operatorname{diag}(\lambda/s) B` grow too ill-conditioned
    to reach the tolerance (the multipliers drift off :math:`B^T\lambda = e`
    while the iterate is already optimal to about ``1e-7``).  This is the
    primal active-set (simplex) method of
    :func:`~drakegrasp.batch.lp.vertex_kernel.active_set_stack`, compiled with
    numba (without it, a Python loop: use it on few problems).  On the
    planner's weight-capacity LPs (``n = 9``, a few dozen rows) it takes
    about half the interior-point method's time.  It needs a feasible
    starting point per problem.

    Parameters
    ----------
    B : (K, r, n) float
    h : (K, r) float
    x0 : (K, n) float
        Feasible points, ``B x0 <= h`` (to rounding).
    max_steps : int, optional
        Active-set changes per problem before giving up.

    Returns
    -------
    MaxLPSolution
        ``converged`` is True where the answer is certified (feasible slacks,
        non-negative multipliers with :math:`B^T\lambda = e_{n-1}`), so
        ``value`` is the optimum to rounding; ``iterations`` counts the
        active-set changes.
    """
    K, _, n = np.shape(B)
    if np.shape(x0) != (K, n):
        raise InvalidOptionError(
            f"x0 must have shape (K, n) = {(K, n)}, got {np.shape(x0)}"
        )
    x, lam, ok, steps = active_set_stack(B, h, x0, max_steps)
    return MaxLPSolution(x[:, -1].copy(), x, lam, ok, steps)
