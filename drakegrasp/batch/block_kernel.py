"""The block interior-point method compiled with numba, one grasp at a time.

The same iteration as :func:`drakegrasp.batch.block_ipm.solve_block_lp` (same
starting point, predictor–corrector steps, tolerances, early exit and iteration
cap), written as scalar loops over one problem's contacts and compiled.  The
numpy version pays a Python-level call per array operation, which dominates at
a few contacts, and compacts its stacks as problems converge; the compiled
loop keeps every problem's working set (a few hundred numbers) in cache and
stops each problem at its own iteration.  The numpy version stays the reference
that the tests compare against.

numba is an optional dependency (``pip install drakegrasp[fast]``);
``AVAILABLE`` says whether this kernel can be used.
"""

from __future__ import annotations

import math

import numpy as np

try:  # pragma: no cover - exercised when numba is installed
    from numba import njit

    AVAILABLE = True
except ImportError:  # pragma: no cover
    AVAILABLE = False

    def njit(*args, **kwargs):
        """Stand-in decorator when numba is absent (the kernel is then unused)."""

        def wrap(fn):
            return fn

        return wrap


__all__ = ["AVAILABLE", "solve_block_stack"]

_STEP = 0.9995
_FLOOR = 0.1
_FAST = {"nsz", "arcp", "contract", "reassoc"}  # fastmath without nnan/ninf
# error_model="numpy": x / 0 gives inf or NaN (IEEE) instead of raising; every
# such value is caught by the tests it feeds (isfinite, comparisons).


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _chol3(H, i):
    """:func:`_chol` unrolled for the 3 × 3 blocks of spatial hard fingers."""
    h00, h10, h11, h20, h21, h22 = (
        H[i, 0, 0], H[i, 1, 0], H[i, 1, 1], H[i, 2, 0], H[i, 2, 1], H[i, 2, 2]
    )  # fmt: skip
    floor = 1e-300 + 1e-14 * max(abs(h00), abs(h11), abs(h22))
    d0 = 1.0 / math.sqrt(max(h00, floor))
    l10 = h10 * d0
    l20 = h20 * d0
    d1 = 1.0 / math.sqrt(max(h11 - l10 * l10, floor))
    l21 = (h21 - l20 * l10) * d1
    d2 = 1.0 / math.sqrt(max(h22 - l20 * l20 - l21 * l21, floor))
    H[i, 0, 0], H[i, 1, 0], H[i, 1, 1] = d0, l10, d1
    H[i, 2, 0], H[i, 2, 1], H[i, 2, 2] = l20, l21, d2


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _solve3(L, i, b, off):
    """:func:`_solve` unrolled for 3 × 3 blocks."""
    d0, l10, d1, l20, l21, d2 = (
        L[i, 0, 0], L[i, 1, 0], L[i, 1, 1], L[i, 2, 0], L[i, 2, 1], L[i, 2, 2]
    )  # fmt: skip
    x0 = b[off] * d0
    x1 = (b[off + 1] - l10 * x0) * d1
    x2 = (b[off + 2] - l20 * x0 - l21 * x1) * d2
    x2 = x2 * d2
    x1 = (x1 - l21 * x2) * d1
    x0 = (x0 - l10 * x1 - l20 * x2) * d0
    b[off], b[off + 1], b[off + 2] = x0, x1, x2


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _solve3_rows(L, i, A, WT, c0, e):
    """``WT[:, c0:c0 + 3] = (L_i L_iᵀ)⁻¹ A[:, c0:c0 + 3]ᵀ`` row by row."""
    d0, l10, d1, l20, l21, d2 = (
        L[i, 0, 0], L[i, 1, 0], L[i, 1, 1], L[i, 2, 0], L[i, 2, 1], L[i, 2, 2]
    )  # fmt: skip
    for j in range(e):
        x0 = A[j, c0] * d0
        x1 = (A[j, c0 + 1] - l10 * x0) * d1
        x2 = (A[j, c0 + 2] - l20 * x0 - l21 * x1) * d2
        x2 = x2 * d2
        x1 = (x1 - l21 * x2) * d1
        WT[j, c0 + 2] = x2
        WT[j, c0 + 1] = x1
        WT[j, c0] = (x0 - l10 * x1 - l20 * x2) * d0


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _solve_rows(L, i, n, A, WT, c0, e):
    """:func:`_solve3_rows` for blocks of any size ``n``."""
    for j in range(e):
        for r in range(n):
            acc = A[j, c0 + r]
            for k in range(r):
                acc -= L[i, r, k] * WT[j, c0 + k]
            WT[j, c0 + r] = acc * L[i, r, r]
        for r in range(n - 1, -1, -1):
            acc = WT[j, c0 + r]
            for k in range(r + 1, n):
                acc -= L[i, k, r] * WT[j, c0 + k]
            WT[j, c0 + r] = acc * L[i, r, r]


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _gram3(F, o, nr, D, r0, H, i):
    """Lower triangle of ``C_iᵀ diag(D_i) C_i`` for 3 components, into H[i]."""
    h00 = h10 = h11 = h20 = h21 = h22 = 0.0
    for r in range(nr):
        p = o + 3 * r
        d = D[r0 + r]
        f0, f1, f2 = F[p], F[p + 1], F[p + 2]
        e0, e1, e2 = f0 * d, f1 * d, f2 * d
        h00 += e0 * f0
        h10 += e1 * f0
        h11 += e1 * f1
        h20 += e2 * f0
        h21 += e2 * f1
        h22 += e2 * f2
    H[i, 0, 0], H[i, 1, 0], H[i, 1, 1] = h00, h10, h11
    H[i, 2, 0], H[i, 2, 1], H[i, 2, 2] = h20, h21, h22


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _gram4(F, o, nr, D, r0, H, i):
    """:func:`_gram3` for the 4 components of soft fingers."""
    h00 = h10 = h11 = h20 = h21 = h22 = h30 = h31 = h32 = h33 = 0.0
    for r in range(nr):
        p = o + 4 * r
        d = D[r0 + r]
        f0, f1, f2, f3 = F[p], F[p + 1], F[p + 2], F[p + 3]
        e0, e1, e2, e3 = f0 * d, f1 * d, f2 * d, f3 * d
        h00 += e0 * f0
        h10 += e1 * f0
        h11 += e1 * f1
        h20 += e2 * f0
        h21 += e2 * f1
        h22 += e2 * f2
        h30 += e3 * f0
        h31 += e3 * f1
        h32 += e3 * f2
        h33 += e3 * f3
    H[i, 0, 0], H[i, 1, 0], H[i, 1, 1] = h00, h10, h11
    H[i, 2, 0], H[i, 2, 1], H[i, 2, 2] = h20, h21, h22
    H[i, 3, 0], H[i, 3, 1], H[i, 3, 2], H[i, 3, 3] = h30, h31, h32, h33


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _chol(H, i, n):
    """In-place lower Cholesky of H[i, :n, :n]; the diagonal holds 1/L_jj."""
    if n == 3:
        _chol3(H, i)
        return
    big = 0.0
    for j in range(n):
        big = max(big, abs(H[i, j, j]))
    floor = 1e-300 + 1e-14 * big
    for j in range(n):
        s = H[i, j, j]
        for k in range(j):
            s -= H[i, j, k] * H[i, j, k]
        inv = 1.0 / math.sqrt(max(s, floor))
        H[i, j, j] = inv
        for r in range(j + 1, n):
            s = H[i, r, j]
            for k in range(j):
                s -= H[i, r, k] * H[i, j, k]
            H[i, r, j] = s * inv


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _solve(L, i, n, b, off):
    """In-place solve of ``L_i L_iᵀ z = b[off:off + n]``, factors from :func:`_chol`."""
    if n == 3:
        _solve3(L, i, b, off)
        return
    for r in range(n):
        acc = b[off + r]
        for j in range(r):
            acc -= L[i, r, j] * b[off + j]
        b[off + r] = acc * L[i, r, r]
    for r in range(n - 1, -1, -1):
        acc = b[off + r]
        for j in range(r + 1, n):
            acc -= L[i, j, r] * b[off + j]
        b[off + r] = acc * L[i, r, r]


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _cmul(F, foff, nrow, ncomp, roff, coff, N, f, out):
    """Out = C f (block-diagonal facets)."""
    for i in range(N):
        c0, r0, nc, o = coff[i], roff[i], ncomp[i], foff[i]
        if nc == 3:
            f0, f1, f2 = f[c0], f[c0 + 1], f[c0 + 2]
            for r in range(nrow[i]):
                p = o + 3 * r
                out[r0 + r] = F[p] * f0 + F[p + 1] * f1 + F[p + 2] * f2
            continue
        if nc == 4:
            f0, f1, f2, f3 = f[c0], f[c0 + 1], f[c0 + 2], f[c0 + 3]
            for r in range(nrow[i]):
                p = o + 4 * r
                out[r0 + r] = F[p] * f0 + F[p + 1] * f1 + F[p + 2] * f2 + F[p + 3] * f3
            continue
        for r in range(nrow[i]):
            acc = 0.0
            for c in range(nc):
                acc += F[o + r * nc + c] * f[c0 + c]
            out[r0 + r] = acc


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _ctmul(F, foff, nrow, ncomp, roff, coff, N, v, out):
    """Out = Cᵀ v."""
    for i in range(N):
        c0, r0, nc, o = coff[i], roff[i], ncomp[i], foff[i]
        if nc == 3:
            a0 = a1 = a2 = 0.0
            for r in range(nrow[i]):
                p = o + 3 * r
                vr = v[r0 + r]
                a0 += F[p] * vr
                a1 += F[p + 1] * vr
                a2 += F[p + 2] * vr
            out[c0], out[c0 + 1], out[c0 + 2] = a0, a1, a2
            continue
        if nc == 4:
            a0 = a1 = a2 = a3 = 0.0
            for r in range(nrow[i]):
                p = o + 4 * r
                vr = v[r0 + r]
                a0 += F[p] * vr
                a1 += F[p + 1] * vr
                a2 += F[p + 2] * vr
                a3 += F[p + 3] * vr
            out[c0], out[c0 + 1], out[c0 + 2], out[c0 + 3] = a0, a1, a2, a3
            continue
        for c in range(nc):
            acc = 0.0
            for r in range(nrow[i]):
                acc += F[o + r * nc + c] * v[r0 + r]
            out[c0 + c] = acc


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _dot(x, y, n):
    acc = 0.0
    for m in range(n):
        acc += x[m] * y[m]
    return acc


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _dotrow(A, i, y, n):
    """``A[i, :n] · y[:n]`` without forming the row view."""
    acc = 0.0
    for m in range(n):
        acc += A[i, m] * y[m]
    return acc


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _dot2(A, i, B, b, n):
    """``A[i, :n] · B[b, :n]``."""
    acc = 0.0
    for m in range(n):
        acc += A[i, m] * B[b, m]
    return acc


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _max_step(vinv, dv, R):
    """``max(0, max_j -dv_j / v_j)`` given ``1 / v``."""
    q = 0.0
    for j in range(R):
        x = -dv[j] * vinv[j]
        if x > q:
            q = x
    return q


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _one(F, A, kap, f, coff, ncomp, foff, nrow, roff, tol, max_iter, stop, use_stop,
         wr, wm, we, WT, Hs, S):  # fmt: skip
    """Solve one problem from ``f`` (which satisfies ``A f = b``); work arrays given.

    ``WT`` (e, M) holds ``H⁻¹ Aᵀ`` transposed, so every product with ``A`` or
    ``WT`` runs along contiguous rows of length ``M``.
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


@njit(cache=True, fastmath=_FAST, error_model="numpy")
def _stack(F, shared, A, kap, f0, coff, ncomp, foff, nrow, roff, tol, max_iter,
           stop, use_stop, out_t, out_conv, out_below, out_it):  # fmt: skip
    N = coff.shape[0]
    e, M = A.shape[1], A.shape[2]
    R = roff[N - 1] + nrow[N - 1]
    wr = np.empty((13, R))
    wm = np.empty((5, M))
    we = np.empty((6, e))
    WT = np.empty((e, M))
    Hs = np.empty((N, 4, 4))
    S = np.empty((1, e, e))
    for k in range(A.shape[0]):
        Fk = F[0] if shared else F[k]
        t, ok, below, it = _one(
            Fk, A[k], kap[k], f0[k], coff, ncomp, foff, nrow, roff, tol, max_iter,
            stop, use_stop, wr, wm, we, WT, Hs, S,
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
    tol: float = 1e-10,
    max_iter: int = 60,
    stop_below: float | None = None,
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
        As in :func:`drakegrasp.batch.block_ipm.solve_block_lp`.

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
        out_t, out_conv, out_below, out_it,
    )  # fmt: skip
    return out_t, out_conv, out_below, out_it
