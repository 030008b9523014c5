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

The degenerate LPs on which the iteration cannot reach its tolerance are solved
exactly by :mod:`~drakegrasp.batch.lp.vertex_kernel`.
"""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.batch.compiled import njit

__all__ = ["solve_max_last_stack"]


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
