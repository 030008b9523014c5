"""Per-contact block operations of the compiled block IPM, on flat arrays.

The facet rows of contact ``i`` are ``F[foff[i] : foff[i] + nrow[i] ncomp[i]]``
(row-major ``nrow[i] × ncomp[i]``), its components ``coff[i] …`` of the force
vector and its rows ``roff[i] …`` of the row vectors (see
``drakegrasp.batch.lp.block_kernel.flat_facets``).  Spatial hard fingers (3
components) and soft fingers (4) take unrolled code: with run-time trip
counts of 3 the loops ran at about 0.4 multiply–adds per ns, bound by latency
and loop control; unrolled, about twice that.  Nothing here takes an array
view (each costs a reference-count update inside the kernel's loops).
"""

from __future__ import annotations

import math

from drakegrasp.batch.compiled import FASTMATH, njit

__all__: list[str] = []  # helpers of the compiled kernels only

# error_model="numpy": x / 0 gives inf or NaN (IEEE) instead of raising; every
# such value is caught by the tests it feeds (isfinite, comparisons).


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
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


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
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


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
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


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
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


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
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


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
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


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
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


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
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


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
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


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
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


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _dot(x, y, n):
    acc = 0.0
    for m in range(n):
        acc += x[m] * y[m]
    return acc


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _dotrow(A, i, y, n):
    """``A[i, :n] · y[:n]`` without forming the row view."""
    acc = 0.0
    for m in range(n):
        acc += A[i, m] * y[m]
    return acc


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _dot2(A, i, B, b, n):
    """``A[i, :n] · B[b, :n]``."""
    acc = 0.0
    for m in range(n):
        acc += A[i, m] * B[b, m]
    return acc


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _max_step(vinv, dv, R):
    """``max(0, max_j -dv_j / v_j)`` given ``1 / v``."""
    q = 0.0
    for j in range(R):
        x = -dv[j] * vinv[j]
        if x > q:
            q = x
    return q
