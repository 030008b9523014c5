r"""An exact active-set (vertex) method for stacks of LPs ``max x_{n-1}``, ``B x <= h``.

Compiled with numba.  The interior-point method of
:mod:`~drakegrasp.batch.lp.ipm_kernel` converges on most of the planner's
weight-capacity LPs, but not on the degenerate ones (pads on opposite flat
faces: many coplanar or repeated rows), where its normal matrices become too
ill-conditioned.  :func:`active_set_stack` solves those, and certifies each
answer it returns (feasible slacks, non-negative multipliers, ``Bᵀλ = e``);
:func:`~drakegrasp.batch.lp.ipm.solve_max_last_active` is its entry from the
batch engine.  (Not to be confused with :mod:`~drakegrasp.batch.lp.active_set`,
which solves the closure LPs in their reduced form.)
"""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.batch.compiled import njit
from drakegrasp.batch.lp.tolerances import BLOCK_TOL

__all__ = ["active_set_stack"]


_ACTIVE_D_TOL = 1e-9
"""``‖d‖`` (a projection of the unit objective) below this: stationary, so the
least-squares multipliers satisfy ``Bᵀλ = e`` to this (what is certified);
a shorter ``d`` is mostly rounding and would lead the steps astray."""
_ACTIVE_TOL = 1e-12
"""Multipliers and slacks beyond ``-this`` (relative) count as zero."""


@njit(cache=True, error_model="numpy")
def _orthonormal_rows(B, work, k0, k, Q, R):
    """Modified Gram–Schmidt (twice) of the rows ``B[work[:k]]``: ``B_W = R Q``.

    ``Q`` (k, n) gets orthonormal rows, ``R`` (k, k) is lower triangular; rows
    before ``k0`` are taken as already done.  Returns False when a row is
    (numerically) in the span of the earlier ones.
    """
    n = B.shape[1]
    for i in range(k0, k):
        row = work[i]
        for c in range(n):
            Q[i, c] = B[row, c]
        for j in range(i + 1):
            R[i, j] = 0.0
        for _ in range(2):
            for j in range(i):
                p = 0.0
                for c in range(n):
                    p += Q[j, c] * Q[i, c]
                R[i, j] += p
                for c in range(n):
                    Q[i, c] -= p * Q[j, c]
        norm = 0.0
        big = 0.0
        for c in range(n):
            norm += Q[i, c] * Q[i, c]
            big += B[row, c] * B[row, c]
        norm = math.sqrt(norm)
        if norm <= 1e-12 * math.sqrt(big):
            return False
        R[i, i] = norm
        for c in range(n):
            Q[i, c] /= norm
    return True


@njit(cache=True, error_model="numpy")
def _active_one(B, h, x, lam, max_steps):
    """The exact active-set method on one LP from a feasible ``x`` (updated).

    Returns ``(certified, steps)``; ``lam`` gets the multipliers.
    """
    r, n = B.shape
    work = np.empty(n, np.int64)
    inset = np.zeros(r, np.bool_)
    Q = np.zeros((n, n))
    R = np.zeros((n, n))
    d = np.zeros(n)
    c = np.zeros(n)
    mult = np.zeros(n)
    s = np.empty(r)
    rates = np.zeros(r)
    rown = np.empty(r)
    hscale = 1.0
    for q in range(r):
        hscale = max(hscale, abs(h[q]))
        acc = 0.0
        for i in range(n):
            acc += B[q, i] * B[q, i]
        rown[q] = math.sqrt(acc)
    # start with the rows tight at x (independent ones, lowest index first)
    k = 0
    for q in range(r):
        if k == n:
            break
        acc = h[q]
        for i in range(n):
            acc -= B[q, i] * x[i]
        if acc <= _ACTIVE_TOL * hscale:
            work[k] = q
            if _orthonormal_rows(B, work, k, k + 1, Q, R):
                inset[q] = True
                k += 1
    done = k
    fresh = True
    for step in range(max_steps):
        if not _orthonormal_rows(B, work, done, k, Q, R):
            return False, step
        done = k
        # back onto the active rows (B_W x = h_W; B_W = R Q): rounding in the
        # projected directions of nearly dependent rows would otherwise pile up
        for j in range(k):
            acc = h[work[j]]
            for i in range(n):
                acc -= B[work[j], i] * x[i]
            for i in range(j):
                acc -= R[j, i] * mult[i]
            mult[j] = acc / R[j, j]
        for j in range(k):
            for i in range(n):
                x[i] += mult[j] * Q[j, i]
        if fresh:  # slacks from scratch now and then, else updated by the steps
            for q in range(r):
                acc = 0.0
                for i in range(n):
                    acc += B[q, i] * x[i]
                s[q] = h[q] - acc
            fresh = False
        # d: the objective e_{n-1} projected onto the null space of the active rows
        for i in range(n):
            d[i] = 0.0
        d[n - 1] = 1.0
        for j in range(k):
            c[j] = Q[j, n - 1]
            for i in range(n):
                d[i] -= c[j] * Q[j, i]
        dn = 0.0
        for i in range(n):
            dn += d[i] * d[i]
        dn = math.sqrt(dn)
        if dn > _ACTIVE_D_TOL:
            for i in range(n):
                d[i] /= dn
            best = np.inf
            block = -1
            for q in range(r):
                if inset[q]:
                    continue
                rate = 0.0
                for i in range(n):
                    rate += B[q, i] * d[i]
                rates[q] = rate
                if rate > BLOCK_TOL * rown[q]:
                    t = max(s[q], 0.0) / rate
                    if t < best:
                        best = t
                        block = q
            if block < 0 or k == n:
                return False, step  # unbounded along d, or no room
            for i in range(n):
                x[i] += best * d[i]
            for q in range(r):
                if not inset[q]:
                    s[q] -= best * rates[q]
            s[block] = 0.0
            fresh = (step + 1) % 8 == 0
            work[k] = block
            inset[block] = True
            k += 1
            continue
        # stationary: multipliers of the active rows, Rᵀ mult = c (R lower)
        for i in range(k - 1, -1, -1):
            acc = c[i]
            for j in range(i + 1, k):
                acc -= R[j, i] * mult[j]
            mult[i] = acc / R[i, i]
        worst = -_ACTIVE_TOL
        leave = -1
        bland = step >= 2 * r
        for j in range(k):
            if mult[j] < -_ACTIVE_TOL:
                if bland:
                    if leave < 0 or work[j] < work[leave]:
                        leave = j
                elif mult[j] < worst:
                    worst = mult[j]
                    leave = j
        if leave < 0:  # optimal: certify from scratch
            for q in range(r):
                lam[q] = 0.0
                acc = h[q]
                for i in range(n):
                    acc -= B[q, i] * x[i]
                if acc < -_ACTIVE_TOL * hscale:
                    return False, step
            for j in range(k):
                lam[work[j]] = max(mult[j], 0.0)
            for i in range(n):
                acc = 0.0
                for q in range(r):
                    acc += B[q, i] * lam[q]
                if abs(acc - (1.0 if i == n - 1 else 0.0)) > 1e-9:
                    return False, step
            return True, step
        inset[work[leave]] = False
        for j in range(leave, k - 1):
            work[j] = work[j + 1]
        k -= 1
        done = leave  # the rows after it are orthogonalised again
    return False, max_steps


@njit(
    cache=True,
    error_model="numpy",
    entry="f8[:, :, ::1], f8[:, ::1], f8[:, ::1], f8[:, ::1], b1[::1], i8[::1], i8",
)
def _active_stack(B, h, X, LAM, ok, steps, max_steps):
    for k in range(B.shape[0]):
        good, st = _active_one(B[k], h[k], X[k], LAM[k], max_steps)
        ok[k] = good
        steps[k] = st


def active_set_stack(B: np.ndarray, h: np.ndarray, x0: np.ndarray,
                     max_steps: int):  # fmt: skip
    """Exact active-set (simplex) solutions of ``max x_{n-1}`` s.t. ``B x <= h``.

    The primal active-set method of Nocedal & Wright (*Numerical
    Optimization*, §16.5) with a linear objective, from feasible starting
    points: the objective gradient projected onto the null space of the
    active rows (a twice-orthogonalised Gram–Schmidt basis) is followed to the
    first blocking row, which joins the active set; at a stationary point the
    most negative multiplier's row leaves (after ``2 r`` steps the lowest
    index, Bland's rule).  An answer is certified only when the slacks,
    recomputed, are feasible, every multiplier is non-negative and
    ``Bᵀ λ = e_{n-1}`` holds to ``1e-9``; then ``x_{n-1}`` is optimal to
    rounding, however degenerate the LP (where the interior-point method's
    normal matrices become too ill-conditioned to converge).

    Parameters
    ----------
    B : (K, r, n) float
    h : (K, r) float
    x0 : (K, n) float
        Feasible points (``B x0 <= h`` up to rounding).
    max_steps : int

    Returns
    -------
    x : (K, n) float
    lam : (K, r) float
    certified : (K,) bool
    steps : (K,) int
    """
    B = np.ascontiguousarray(B, dtype=np.float64)
    h = np.ascontiguousarray(h, dtype=np.float64)
    K, r, n = B.shape
    X = np.array(x0, dtype=np.float64, order="C").reshape(K, n)
    LAM = np.zeros((K, r))
    ok = np.zeros(K, dtype=np.bool_)
    steps = np.zeros(K, dtype=np.int64)
    _active_stack(B, h, X, LAM, ok, steps, int(max_steps))
    return X, LAM, ok, steps
