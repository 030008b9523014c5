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
The closure engine (:mod:`drakegrasp.batch.reduction`) brings LP1/LP2 to this form
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

__all__ = ["MaxLPSolution", "solve_max_last"]

_STEP = 0.995  # fraction of the distance to the boundary taken per step


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


def _solve_spd(M: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve ``M z = rhs`` for a stack of small SPD matrices (K, n, n), (K, n)."""
    return np.linalg.solve(M, rhs[..., None])[..., 0]


def _max_step(v: np.ndarray, dv: np.ndarray, fraction: float = 1.0) -> np.ndarray:
    """``min(1, fraction * α_max)``, α_max the largest α with ``v + α dv >= 0``.

    ``v`` (K, r) is positive; the result is (K,).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(dv < 0.0, -v / dv, np.inf)
    return np.minimum(1.0, fraction * ratio.min(axis=1))


def _starting_point(B: np.ndarray, h: np.ndarray):
    """Mehrotra's heuristic starting point (least squares, then shifted > 0)."""
    n = B.shape[2]
    Bt = np.swapaxes(B, 1, 2)
    BtB = Bt @ B
    # Primal: least-squares fit of B x = h, slack s = h - B x.
    x = _solve_spd(BtB, (Bt @ h[..., None])[..., 0])
    s = h - (B @ x[..., None])[..., 0]
    # Dual: minimum-norm solution of B^T λ = e_{n-1}.
    e = np.zeros((B.shape[0], n))
    e[:, -1] = 1.0
    lam = (B @ _solve_spd(BtB, e)[..., None])[..., 0]
    ds = np.maximum(-1.5 * s.min(axis=1), 0.0)
    dl = np.maximum(-1.5 * lam.min(axis=1), 0.0)
    s = s + ds[:, None]
    lam = lam + dl[:, None]
    sl = np.einsum("kr,kr->k", s, lam)
    ds = 0.5 * sl / np.maximum(lam.sum(axis=1), 1e-300)
    dl = 0.5 * sl / np.maximum(s.sum(axis=1), 1e-300)
    s = s + ds[:, None] + 1e-12
    lam = lam + dl[:, None] + 1e-12
    return x, s, lam


def solve_max_last(
    B: np.ndarray,
    h: np.ndarray,
    *,
    tol: float = 1e-10,
    max_iter: int = 60,
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
        :math:`|h^T\lambda - x_{n-1}| / (1 + |x_{n-1}|)`.
    max_iter : int, optional
        Iteration cap per problem.

    Returns
    -------
    MaxLPSolution

    Notes
    -----
    Mehrotra's predictor–corrector method with separate primal and dual step
    lengths.  Both directions of an iteration share one ``n × n`` normal matrix
    :math:`B^T \operatorname{diag}(\lambda/s) B`, solved for the whole active stack
    by ``numpy.linalg.solve``.  Converged problems are dropped from the stack, so
    late iterations cost only what the slow problems need.
    """
    B = np.ascontiguousarray(B, dtype=float)
    h = np.ascontiguousarray(h, dtype=float)
    K, r, n = B.shape
    out_x = np.zeros((K, n))
    out_lam = np.zeros((K, r))
    out_conv = np.zeros(K, dtype=bool)
    out_it = np.zeros(K, dtype=int)
    if K == 0:
        return MaxLPSolution(np.zeros(0), out_x, out_lam, out_conv, out_it)

    x, s, lam = _starting_point(B, h)
    idx = np.arange(K)
    hscale = 1.0 + np.abs(h).max(axis=1)
    Bt = np.swapaxes(B, 1, 2)
    for it in range(1, max_iter + 1):
        # Residuals: rp = e - B^T λ (dual feasibility), rd = h - B x - s.
        rp = -(Bt @ lam[..., None])[..., 0]
        rp[:, -1] += 1.0
        rd = h - (B @ x[..., None])[..., 0] - s
        sl = s * lam
        gap = sl.sum(axis=1)
        obj = x[:, -1]
        done = (
            (np.abs(rp).max(axis=1) <= tol)
            & (np.abs(rd).max(axis=1) <= tol * hscale)
            & (gap <= tol * (1.0 + np.abs(obj)))
        )
        if it == max_iter:
            done[:] = True
        if done.any():
            k = idx[done]
            out_x[k] = x[done]
            out_lam[k] = lam[done]
            if it < max_iter:
                out_conv[k] = True
            else:  # accept a last iterate that is close enough, flag the rest
                loose = 1e3 * tol
                out_conv[k] = (
                    (np.abs(rp[done]).max(axis=1) <= loose)
                    & (np.abs(rd[done]).max(axis=1) <= loose * hscale[done])
                    & (gap[done] <= loose * (1.0 + np.abs(obj[done])))
                )
            out_it[k] = it
            keep = ~done
            if not keep.any():
                break
            idx, B, Bt, h, hscale = idx[keep], B[keep], Bt[keep], h[keep], hscale[keep]
            x, s, lam = x[keep], s[keep], lam[keep]
            rp, rd, sl, gap = rp[keep], rd[keep], sl[keep], gap[keep]
        mu = gap / r

        D = lam / s
        M = Bt @ (B * D[..., None])
        # Predictor (affine scaling) direction: rc = -λ∘s.
        rhs_base = rp - (Bt @ ((-sl - lam * rd) / s)[..., None])[..., 0]
        dx = _solve_spd(M, rhs_base)
        Bdx = (B @ dx[..., None])[..., 0]
        ds = rd - Bdx
        dlam = (-sl - lam * ds) / s
        a_p = _max_step(s, ds)
        a_d = _max_step(lam, dlam)
        mu_aff = (
            np.einsum("kr,kr->k", s + a_p[:, None] * ds, lam + a_d[:, None] * dlam) / r
        )
        sigma = (mu_aff / np.maximum(mu, 1e-300)) ** 3
        # Corrector: rc = σμ - λ∘s - Δλ_aff∘Δs_aff.
        rc = (sigma * mu)[:, None] - sl - dlam * ds
        rhs = rp - (Bt @ ((rc - lam * rd) / s)[..., None])[..., 0]
        dx = _solve_spd(M, rhs)
        Bdx = (B @ dx[..., None])[..., 0]
        ds = rd - Bdx
        dlam = (rc - lam * ds) / s
        a_p = _max_step(s, ds, _STEP)
        a_d = _max_step(lam, dlam, _STEP)
        x = x + a_p[:, None] * dx
        s = s + a_p[:, None] * ds
        lam = lam + a_d[:, None] * dlam

    value = out_x[:, -1].copy()
    return MaxLPSolution(value, out_x, out_lam, out_conv, out_it)
