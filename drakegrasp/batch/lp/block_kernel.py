"""The block interior-point method compiled with numba, one grasp at a time.

The same iteration as :func:`drakegrasp.batch.lp.block_ipm.solve_block_lp` (same
starting point, predictor–corrector steps, tolerances, early exit and iteration
cap), written as scalar loops over one problem's contacts and compiled.  The
numpy version pays a Python-level call per array operation, which dominates at
a few contacts, and compacts its stacks as problems converge; the compiled
loop keeps every problem's working set (a few hundred numbers) in cache and
stops each problem at its own iteration.  The numpy version stays the reference
that the tests compare against.

numba is a dependency of drakegrasp (:mod:`drakegrasp.batch.compiled`);
``AVAILABLE`` says whether this kernel can be used (False where numba is missing).
"""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.batch.compiled import AVAILABLE, FASTMATH, njit
from drakegrasp.batch.lp.block_ops import (
    _chol,
    _cmul,
    _ctmul,
    _dot,
    _dot2,
    _dotrow,
    _gram3,
    _gram4,
    _max_step,
    _solve,
    _solve3_rows,
    _solve_rows,
)
from drakegrasp.batch.lp.tolerances import IPM_MAX_ITER, IPM_TOL

__all__ = ["AVAILABLE", "solve_block_stack"]

_STEP = 0.9995
_FLOOR = 0.1


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _one(F, A, kap, f, coff, ncomp, foff, nrow, roff, tol, max_iter, stop, use_stop,
         above, wr, wm, we, WT, Hs, S):  # fmt: skip
    """Solve one problem from ``f`` (which satisfies ``A f = b``); work arrays given.

    ``WT`` (e, M) holds ``H⁻¹ Aᵀ`` transposed, so every product with ``A`` or
    ``WT`` runs along contiguous rows of length ``M``.

    ``above`` (``inf``: never) stops the problem once a feasible point with
    ``min C f > above`` is in hand, which proves ``t* > above``: ``f`` itself,
    or an iterate whose ``t`` passed ``above`` (``_proves_above``).  The
    value returned is then that point's ``min C f``, a lower bound on ``t*``.
    """
    N = coff.shape[0]
    e, M = A.shape
    R = roff[N - 1] + nrow[N - 1]
    s, lam, Cf, D, r4, q, ds, dl, r5, dsa, dla, si, li = (
        wr[0], wr[1], wr[2], wr[3], wr[4], wr[5], wr[6], wr[7], wr[8], wr[9], wr[10],
        wr[11], wr[12],
    )  # fmt: skip
    g, r1, z, dg, ah = wm[0], wm[1], wm[2], wm[3], wm[4]
    y, r3, a, u, w, dy = we[0], we[1], we[2], we[3], we[4], we[5]
    # Starting point (as block_ipm._starting_point).
    _cmul(F, foff, nrow, ncomp, roff, coff, N, f, Cf)
    lo, hi = Cf[0], Cf[0]
    for j in range(R):
        lo = min(lo, Cf[j])
        hi = max(hi, Cf[j])
    t = lo - 0.5 * (hi - lo) - 1e-3
    sl = 0.0
    ssum = 0.0
    for j in range(R):
        s[j] = Cf[j] - t
        lam[j] = 1.0 / R
        sl += s[j] * lam[j]
        ssum += s[j]
    shift = 0.5 * sl / ssum
    lsum = 0.0
    for j in range(R):
        lam[j] += shift
        lsum += lam[j]
    for j in range(R):
        lam[j] /= lsum
    # â (axis directions), g = f - t â, a = A â.
    for m in range(M):
        g[m] = f[m]
        ah[m] = 0.0
    for i in range(N):
        ah[coff[i]] = 1.0 / F[foff[i]]
        g[coff[i]] -= t * ah[coff[i]]
    if lo > above:  # f may prove it already (checked on its exact projection)
        proved = _proves_above(F, A, f, 0.0, ah, coff, ncomp, foff, nrow, roff,
                               wm[5], ds)  # fmt: skip
        if proved > above:
            return proved, True, False, 0
    _ctmul(F, foff, nrow, ncomp, roff, coff, N, lam, z)
    for i in range(e):
        y[i] = _dotrow(A, i, z, M)
        a[i] = _dotrow(A, i, ah, M)
        for b in range(i + 1):
            S[0, i, b] = _dot2(A, i, A, b, M)
    _chol(S, 0, e)
    _solve(S, 0, e, y, 0)
    a_p = 1.0
    a_d = 1.0
    dt = 0.0
    for it in range(1, max_iter + 1):
        _cmul(F, foff, nrow, ncomp, roff, coff, N, g, Cf)
        _ctmul(F, foff, nrow, ncomp, roff, coff, N, lam, r1)
        for i in range(e):
            yi = y[i]
            for m in range(M):
                r1[m] -= A[i, m] * yi
        lsum = 0.0
        gap = 0.0
        err_p = 0.0
        for j in range(R):
            lsum += lam[j]
            gap += s[j] * lam[j]
            r4[j] = s[j] - Cf[j]
            err_p = max(err_p, abs(r4[j]))
        r2 = 1.0
        for i in range(e):
            r2 -= a[i] * y[i]
            r3[i] = (1.0 if i == e - 1 else 0.0) - _dotrow(A, i, g, M) - a[i] * t
            err_p = max(err_p, abs(r3[i]))
        err_d = abs(r2)
        for m in range(M):
            err_d = max(err_d, abs(r1[m]))
        err_g = gap / (1.0 + abs(t))
        done = err_p <= tol and err_d <= tol and err_g <= tol
        if use_stop and not done and lsum > 0.0:
            worst = 0.0
            for i in range(N):
                acc = 0.0
                for c in range(ncomp[i]):
                    acc += r1[coff[i] + c] ** 2
                worst = max(worst, math.sqrt(acc) * kap[i])
            bound = (y[e - 1] + worst) / lsum
            if bound < stop:
                return bound, True, True, it
        if t > above and not done:
            proved = _proves_above(F, A, g, t, ah, coff, ncomp, foff, nrow, roff,
                                   wm[5], ds)  # fmt: skip
            if proved > above:
                return proved, True, False, it
        if done:
            return t, True, False, it
        if it == max_iter:
            loose = 1e3 * tol
            ok = err_p <= loose and err_d <= loose and err_g <= loose
            return t, ok, False, it
        mu = gap / R
        for j in range(R):
            si[j] = 1.0 / s[j]  # one division per row and iteration
            li[j] = 1.0 / lam[j]
            D[j] = lam[j] * si[j]
        for i in range(N):
            c0, r0, nc, o, nr = coff[i], roff[i], ncomp[i], foff[i], nrow[i]
            if nc == 3:
                _gram3(F, o, nr, D, r0, Hs, i)
            elif nc == 4:
                _gram4(F, o, nr, D, r0, Hs, i)
            else:
                for x in range(nc):
                    for b in range(x + 1):
                        acc = 0.0
                        for r in range(nr):
                            acc += F[o + r * nc + x] * F[o + r * nc + b] * D[r0 + r]
                        Hs[i, x, b] = acc
            _chol(Hs, i, nc)
            if nc == 3:
                _solve3_rows(Hs, i, A, WT, c0, e)
            else:
                _solve_rows(Hs, i, nc, A, WT, c0, e)
        for i in range(e):
            u[i] = a[i]
            for b in range(i + 1):
                S[0, i, b] = _dot2(A, i, WT, b, M)
        _chol(S, 0, e)
        _solve(S, 0, e, u, 0)
        denom = _dot(a, u, e)
        target = 0.0
        for phase in range(2):
            if phase == 0:
                for j in range(R):
                    r5[j] = -s[j] * lam[j]
            else:
                for j in range(R):
                    r5[j] = target - s[j] * lam[j] - dsa[j] * dla[j]
            for j in range(R):
                q[j] = r5[j] * si[j] + D[j] * r4[j]
            _ctmul(F, foff, nrow, ncomp, roff, coff, N, q, z)
            for m in range(M):
                z[m] += r1[m]
            for i in range(N):
                _solve(Hs, i, ncomp[i], z, coff[i])
            for i in range(e):
                w[i] = r3[i] - _dotrow(A, i, z, M)
            _solve(S, 0, e, w, 0)
            dt = (r2 + _dot(a, w, e)) / denom
            for i in range(e):
                dy[i] = u[i] * dt - w[i]
            for m in range(M):
                dg[m] = z[m]
            for i in range(e):
                dyi = dy[i]
                for m in range(M):
                    dg[m] -= WT[i, m] * dyi
            _cmul(F, foff, nrow, ncomp, roff, coff, N, dg, ds)
            for j in range(R):
                ds[j] = ds[j] - r4[j]
                dl[j] = r5[j] * si[j] - D[j] * ds[j]
            qp = _max_step(si, ds, R)
            qd = _max_step(li, dl, R)
            if phase == 0:
                a_p = min(1.0, 1.0 / qp) if qp > 0.0 else 1.0
                a_d = min(1.0, 1.0 / qd) if qd > 0.0 else 1.0
                acc = 0.0
                for j in range(R):
                    acc += (s[j] + a_p * ds[j]) * (lam[j] + a_d * dl[j])
                    dsa[j] = ds[j]
                    dla[j] = dl[j]
                sigma = (acc / R / max(mu, 1e-300)) ** 3
                target = max(sigma * mu, _FLOOR * tol / R)
            else:
                a_p = min(1.0, _STEP / qp) if qp > 0.0 else 1.0
                a_d = min(1.0, _STEP / qd) if qd > 0.0 else 1.0
        for m in range(M):
            g[m] += a_p * dg[m]
        t += a_p * dt
        for j in range(R):
            s[j] += a_p * ds[j]
            lam[j] += a_d * dl[j]
        for i in range(e):
            y[i] += a_d * dy[i]
    return t, False, False, max_iter


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _proves_above(F, A, g, t, ah, coff, ncomp, foff, nrow, roff, f, Cf):
    """``min C f`` of the iterate ``f = g + t â`` made exactly feasible, or -inf.

    The iterate satisfies ``A f = b`` only up to the Newton steps' rounding;
    here its components along ``A``'s orthonormal rows ``Qᵀ`` (all rows but
    the last) are removed and it is scaled to ``eᵀ f = 1`` (the last row), so
    the ``min C f`` returned is the value of a feasible point: ``t*`` is at
    least that.  ``f`` (M) and ``Cf`` (R) are scratch.
    """
    N = coff.shape[0]
    e, M = A.shape
    R = roff[N - 1] + nrow[N - 1]
    for m in range(M):
        f[m] = g[m] + t * ah[m]
    for i in range(e - 1):
        acc = _dotrow(A, i, f, M)
        for m in range(M):
            f[m] -= acc * A[i, m]
    total = _dotrow(A, e - 1, f, M)
    if not total > 0.0:
        return -math.inf
    for m in range(M):
        f[m] /= total
    _cmul(F, foff, nrow, ncomp, roff, coff, N, f, Cf)
    lo = Cf[0]
    for j in range(R):
        lo = min(lo, Cf[j])
    return lo


@njit(cache=True)
def work_arrays(R, M, e, N):
    """Work arrays of :func:`_one`.

    For ``R`` facet rows, ``M`` components, ``e`` equalities and ``N``
    contacts of at most 4 components each.
    """
    wr = np.empty((13, R))
    wm = np.empty((6, M))
    we = np.empty((6, e))
    WT = np.empty((e, M))
    Hs = np.empty((N, 4, 4))
    S = np.empty((1, e, e))
    return wr, wm, we, WT, Hs, S


@njit(
    cache=True,
    fastmath=FASTMATH,
    error_model="numpy",
    entry=(
        "f8[:, ::1], b1, f8[:, :, ::1], f8[:, ::1], f8[:, ::1], "
        "i8[::1], i8[::1], i8[::1], i8[::1], i8[::1], f8, i8, f8, "
        "b1, f8, f8[::1], b1[::1], b1[::1], i8[::1]"
    ),
)
def _stack(F, shared, A, kap, f0, coff, ncomp, foff, nrow, roff, tol, max_iter,
           stop, use_stop, above, out_t, out_conv, out_below, out_it):  # fmt: skip
    N = coff.shape[0]
    e, M = A.shape[1], A.shape[2]
    R = roff[N - 1] + nrow[N - 1]
    wr, wm, we, WT, Hs, S = work_arrays(R, M, e, N)
    for k in range(A.shape[0]):
        Fk = F[0] if shared else F[k]
        t, ok, below, it = _one(
            Fk, A[k], kap[k], f0[k], coff, ncomp, foff, nrow, roff, tol, max_iter,
            stop, use_stop, above, wr, wm, we, WT, Hs, S,
        )  # fmt: skip
        out_t[k] = t
        out_conv[k] = ok
        out_below[k] = below
        out_it[k] = it


def flat_facets(facets: list[np.ndarray], K: int):
    """Facet rows of one layout as the kernels take them.

    Returns ``(flat, shared, (coff, ncomp, foff, nrow, roff))``: ``flat``
    (1 or K, total) holds each contact's (r_i, c_i) rows one after the other
    (one copy when every contact's facets are shared by the stack), and the
    int64 offsets give each contact's first component, component count,
    first facet number, row count and first row.
    """
    ncomp = np.array([F.shape[2] for F in facets], dtype=np.int64)
    nrow = np.array([F.shape[1] for F in facets], dtype=np.int64)
    coff = np.concatenate([[0], np.cumsum(ncomp)[:-1]]).astype(np.int64)
    roff = np.concatenate([[0], np.cumsum(nrow)[:-1]]).astype(np.int64)
    foff = np.concatenate([[0], np.cumsum(nrow * ncomp)[:-1]]).astype(np.int64)
    shared = all(F.shape[0] == 1 for F in facets)
    n = 1 if shared else K
    flat = np.concatenate(
        [np.broadcast_to(F, (n,) + F.shape[1:]).reshape(n, -1) for F in facets],
        axis=1,
    )
    return (
        np.ascontiguousarray(flat, dtype=float),
        shared,
        (coff, ncomp, foff, nrow, roff),
    )


def solve_block_stack(
    facets: list[np.ndarray],
    A: np.ndarray,
    kappa: np.ndarray,
    start: np.ndarray,
    *,
    tol: float = IPM_TOL,
    max_iter: int = IPM_MAX_ITER,
    stop_below: float | None = None,
    prove_above: float | None = None,
):
    """The compiled block IPM on a stack of LPs of one layout.

    Parameters
    ----------
    facets : list of (K, r_i, c_i) or (1, r_i, c_i) float
        Facet rows of each contact (leading 1: shared by the stack).
    A : (K, e, M) float
        Equality rows ``[Qᵀ; eᵀ]``.
    kappa : (K, N) float
        Cone bounds ``‖f_i‖ <= κ_i f_{n,i}``.
    start : (K, M) float
        Starting ``f`` with ``A f = b``.
    tol, max_iter, stop_below : optional
        As in :func:`drakegrasp.batch.lp.block_ipm.solve_block_lp`.
    prove_above : float, optional
        Stop a problem once a feasible point proves ``t* > prove_above`` (its
        ``value`` is then that point's ``t``, a lower bound, with
        ``converged`` True and ``below`` False); the rows ``A`` but the last
        must be orthonormal (``Qᵀ``).  None: solve to the end.

    Returns
    -------
    value, converged, below, iterations : (K,) arrays
    """
    K = A.shape[0]
    flat, shared, (coff, ncomp, foff, nrow, roff) = flat_facets(facets, K)
    out_t = np.zeros(K)
    out_conv = np.zeros(K, dtype=np.bool_)
    out_below = np.zeros(K, dtype=np.bool_)
    out_it = np.zeros(K, dtype=np.int64)
    _stack(
        flat, shared, np.ascontiguousarray(A),
        np.ascontiguousarray(kappa, dtype=float), np.ascontiguousarray(start),
        coff, ncomp, foff, nrow, roff, float(tol), int(max_iter),
        0.0 if stop_below is None else float(stop_below), stop_below is not None,
        math.inf if prove_above is None else float(prove_above),
        out_t, out_conv, out_below, out_it,
    )  # fmt: skip
    return out_t, out_conv, out_below, out_it
