r"""The interior-point method of :mod:`~drakegrasp.batch.lp.ipm`, one LP at a time.

Compiled with numba.

:func:`~drakegrasp.batch.lp.ipm.solve_max_last` runs Mehrotra's
predictor–corrector method on a whole stack of LPs
:math:`\max x_{n-1}` s.t. :math:`B x \le h` with numpy, one vector operation
over the batch per entry of the ``n × n`` normal matrix.  For the planner's
weight-capacity LPs (thousands of problems of ``n = 9`` variables and a few
dozen rows) that is a few hundred numpy calls per iteration.  Here the same
iteration runs per problem inside one compiled loop, on a working set of a few
hundred numbers: the same starting point (Mehrotra's heuristic), the same
directions, step fractions, stopping rule and last-iterate acceptance, so the
two routes agree to round-off (tested against each other and against HiGHS in
``tests/batch/test_ipm_kernel.py``).  ``stop_below`` is not offered here: the
closure LPs that use it have their own fused kernels.

:func:`active_set_stack` solves the same LPs exactly by a vertex method from
feasible points, for the degenerate ones on which the interior-point
iteration cannot reach its tolerance.
"""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.batch.compiled import njit

__all__ = ["active_set_stack", "solve_max_last_stack"]


@njit(cache=True, error_model="numpy")
def _cholesky(M, L):
    """Lower Cholesky factor of the SPD ``M`` (upper triangle read) into ``L``."""
    n = M.shape[0]
    big = 0.0
    for i in range(n):
        big = max(big, abs(M[i, i]))
    floor = 1e-300 + 1e-14 * big
    for j in range(n):
        s = M[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        L[j, j] = math.sqrt(max(s, floor))
        for i in range(j + 1, n):
            s = M[j, i]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / L[j, j]
        for i in range(j):
            L[i, j] = 0.0


@njit(cache=True, error_model="numpy")
def _cho_solve(L, b, out, y):
    """Solve ``L Lᵀ z = b`` into ``out`` (``y`` scratch)."""
    n = L.shape[0]
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * y[k]
        y[i] = s / L[i, i]
    for i in range(n - 1, -1, -1):
        s = y[i]
        for k in range(i + 1, n):
            s -= L[k, i] * out[k]
        out[i] = s / L[i, i]


@njit(cache=True, error_model="numpy")
def _normal(B, D, M):
    """``Bᵀ diag(D) B`` (upper triangle) into ``M``."""
    r, n = B.shape
    for i in range(n):
        for j in range(i, n):
            s = 0.0
            for q in range(r):
                s += B[q, i] * D[q] * B[q, j]
            M[i, j] = s


@njit(cache=True, error_model="numpy")
def _max_step(v, dv, fraction):
    q = 0.0
    for i in range(v.shape[0]):
        t = -dv[i] / v[i]
        if t > q:
            q = t
    if q > 0.0:
        return min(1.0, fraction / q)
    return 1.0


@njit(cache=True, error_model="numpy")
def _one(B, h, tol, max_iter, step, x, lam):
    """One LP; returns (converged, iterations); ``x``, ``lam`` are outputs."""
    r, n = B.shape
    M = np.zeros((n, n))
    L = np.zeros((n, n))
    yy = np.zeros(n)
    rhs = np.zeros(n)
    dx = np.zeros(n)
    s = np.zeros(r)
    ds = np.zeros(r)
    dlam = np.zeros(r)
    D = np.ones(r)
    rd = np.zeros(r)
    rp = np.zeros(n)
    rcs = np.zeros(r)
    # Mehrotra's starting point, as ipm._starting_point
    _normal(B, D, M)
    _cholesky(M, L)
    for i in range(n):
        acc = 0.0
        for q in range(r):
            acc += B[q, i] * h[q]
        rhs[i] = acc
    _cho_solve(L, rhs, x, yy)
    for i in range(n):
        rhs[i] = 0.0
    rhs[n - 1] = 1.0
    _cho_solve(L, rhs, dx, yy)
    smin = np.inf
    lmin = np.inf
    for q in range(r):
        acc = 0.0
        acc2 = 0.0
        for i in range(n):
            acc += B[q, i] * x[i]
            acc2 += B[q, i] * dx[i]
        s[q] = h[q] - acc
        lam[q] = acc2
        smin = min(smin, s[q])
        lmin = min(lmin, lam[q])
    sshift = max(-1.5 * smin, 0.0)
    lshift = max(-1.5 * lmin, 0.0)
    sl = 0.0
    lsum = 0.0
    for q in range(r):
        s[q] += sshift
        lam[q] += lshift
        sl += s[q] * lam[q]
        lsum += lam[q]
    a = 0.5 * sl / max(lsum, 1e-300) + 1e-12
    ssum = 0.0
    for q in range(r):
        s[q] += a
        ssum += s[q]
    b = 0.5 * sl / max(ssum, 1e-300) + 1e-12  # with the shifted s, as ipm.py
    for q in range(r):
        lam[q] += b
    hscale = 0.0
    for q in range(r):
        hscale = max(hscale, abs(h[q]))
    hscale += 1.0
    for it in range(1, max_iter + 1):
        for i in range(n):
            acc = 0.0
            for q in range(r):
                acc += B[q, i] * lam[q]
            rp[i] = -acc
        rp[n - 1] += 1.0
        gap = 0.0
        err_d = 0.0
        for q in range(r):
            acc = 0.0
            for i in range(n):
                acc += B[q, i] * x[i]
            rd[q] = h[q] - acc - s[q]
            gap += s[q] * lam[q]
            err_d = max(err_d, abs(rd[q]))
        err_d /= hscale
        err_p = 0.0
        for i in range(n):
            err_p = max(err_p, abs(rp[i]))
        err_g = gap / (1.0 + abs(x[n - 1]))
        if err_p <= tol and err_d <= tol and err_g <= tol:
            return True, it
        if it == max_iter:
            loose = 1e3 * tol
            return (err_p <= loose and err_d <= loose and err_g <= loose), it
        mu = gap / r
        for q in range(r):
            D[q] = lam[q] / s[q]
        _normal(B, D, M)
        _cholesky(M, L)
        # predictor
        for i in range(n):
            acc = 0.0
            for q in range(r):
                acc += B[q, i] * D[q] * (s[q] + rd[q])
            rhs[i] = rp[i] + acc
        _cho_solve(L, rhs, dx, yy)
        for q in range(r):
            acc = 0.0
            for i in range(n):
                acc += B[q, i] * dx[i]
            ds[q] = rd[q] - acc
            dlam[q] = -lam[q] - D[q] * ds[q]
        a_p = _max_step(s, ds, 1.0)
        a_d = _max_step(lam, dlam, 1.0)
        mu_aff = 0.0
        for q in range(r):
            mu_aff += (s[q] + a_p * ds[q]) * (lam[q] + a_d * dlam[q])
        mu_aff /= r
        sigma = (mu_aff / max(mu, 1e-300)) ** 3
        # corrector
        for q in range(r):
            rcs[q] = (sigma * mu - dlam[q] * ds[q]) / s[q] - lam[q]
        for i in range(n):
            acc = 0.0
            for q in range(r):
                acc += B[q, i] * (rcs[q] - D[q] * rd[q])
            rhs[i] = rp[i] - acc
        _cho_solve(L, rhs, dx, yy)
        for q in range(r):
            acc = 0.0
            for i in range(n):
                acc += B[q, i] * dx[i]
            ds[q] = rd[q] - acc
            dlam[q] = rcs[q] - D[q] * ds[q]
        a_p = _max_step(s, ds, step)
        a_d = _max_step(lam, dlam, step)
        for i in range(n):
            x[i] += a_p * dx[i]
        for q in range(r):
            s[q] += a_p * ds[q]
            lam[q] += a_d * dlam[q]
    return False, max_iter


@njit(
    cache=True,
    error_model="numpy",
    entry=(
        "f8[:, :, ::1], f8[:, ::1], f8, i8, f8, f8[:, ::1], f8[:, ::1], b1[::1], "
        "i8[::1]"
    ),
)
def _stack(B, h, tol, max_iter, step, X, LAM, conv, its):
    for k in range(B.shape[0]):
        ok, it = _one(B[k], h[k], tol, max_iter, step, X[k], LAM[k])
        conv[k] = ok
        its[k] = it


def solve_max_last_stack(B: np.ndarray, h: np.ndarray, tol: float, max_iter: int,
                         step: float):  # fmt: skip
    """Compiled route of :func:`~drakegrasp.batch.lp.ipm.solve_max_last`.

    Parameters
    ----------
    B : (K, r, n) float
    h : (K, r) float
    tol : float
    max_iter : int
    step : float
        Fraction of the distance to the boundary per corrector step.

    Returns
    -------
    x : (K, n) float
    lam : (K, r) float
    converged : (K,) bool
    iterations : (K,) int
    """
    B = np.ascontiguousarray(B, dtype=np.float64)
    h = np.ascontiguousarray(h, dtype=np.float64)
    K, r, n = B.shape
    X = np.zeros((K, n))
    LAM = np.zeros((K, r))
    conv = np.zeros(K, dtype=np.bool_)
    its = np.zeros(K, dtype=np.int64)
    _stack(B, h, float(tol), int(max_iter), float(step), X, LAM, conv, its)
    return X, LAM, conv, its


_ACTIVE_D_TOL = 1e-9
"""``‖d‖`` (a projection of the unit objective) below this: stationary, so the
least-squares multipliers satisfy ``Bᵀλ = e`` to this (what is certified);
a shorter ``d`` is mostly rounding and would lead the steps astray."""
_ACTIVE_TOL = 1e-12
"""Multipliers and slacks beyond ``-this`` (relative) count as zero."""
_BLOCK_TOL = 1e-9
"""A row blocks a step along the unit ``d`` when its rate exceeds this times its
norm; a smaller rate is rounding of a row in the active rows' span (which the
Gram–Schmidt basis would reject)."""


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
                if rate > _BLOCK_TOL * rown[q]:
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
