"""Row space, starting point and block IPM of a stack of grasps in one compiled pass.

:func:`drakegrasp.batch.lp.dstar.solve_dstar_blocks` prepares each LP of a chunk
with vectorised numpy (a Householder QR of ``G̃ᵀ`` to certify full rank and
give ``Q``, then ``c = e - Q Qᵀ e``, ``f_0 = c / ‖c‖²`` and ``A = [Qᵀ; eᵀ]``)
before the compiled IPM runs.  On a few contacts that preparation costs about
half as much as the IPM, mostly numpy's per-call overhead and the (M, w, K)
temporaries.  Here the same steps run per grasp inside the compiled loop, on
a working set of a few hundred numbers, and go straight into
``drakegrasp.batch.lp.block_kernel._one``.

When the null space is small (three hard contacts: 3 dimensions, 24 facets;
see ``drakegrasp.batch.lp.active_set.worth_it``) the LP is instead solved exactly
in ``f = Z v`` by the active-set method of :mod:`drakegrasp.batch.lp.active_set`,
with ``Z`` the trailing columns of the same Householder ``Q``: 0.7–1.8 µs per
LP where the IPM took 4–6 µs.  An LP it cannot certify goes on to the IPM.

In verdict-only mode (``between``, for robustness) a grasp whose ``f_0``
(computed from the QR's reflectors alone) already clears the upper bound is
finished before any ``Q`` is formed: on the planner's robustness copies that
is nearly all of them.

Only grasps whose full row rank the QR certifies (``‖R⁻¹‖_F rank_tol ‖G̃‖_F < 1``,
as :func:`drakegrasp.batch.build.rowspace.row_spaces`) and whose IPM converges are
finished here; the caller sends the others (rank-deficient or nearly so, or an
IPM that hit its cap) through the numpy preparation, the SVD rank rule and the
HiGHS fallback, so every verdict follows the same rules as before.
"""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.batch.compiled import FASTMATH, njit
from drakegrasp.batch.lp.active_set import active_set_work, reduced_lp, worth_it
from drakegrasp.batch.lp.block_kernel import _one, flat_facets, work_arrays
from drakegrasp.batch.lp.block_ops import _cmul
from drakegrasp.batch.lp.householder import _qr, _reflect
from drakegrasp.batch.lp.tolerances import PUSH_TOL

__all__ = ["full_column_rank_certain", "solve_full_rank_stack"]


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _certain(XT, cols, fro, rank_tol, RI):
    """Whether ``R`` (from :func:`_qr`) certifies full column rank.

    ``σ_min >= 1/‖R⁻¹‖_F`` and ``σ_max <= ‖X‖_F``, so ``‖R⁻¹‖_F rank_tol ‖X‖_F
    < 1`` proves ``σ_min > rank_tol σ_max``.  ``RI`` is (cols, cols) scratch.
    """
    total = 0.0
    for j in range(cols):
        for i in range(j, -1, -1):
            if i == j:
                x = 1.0 / XT[j, j]
            else:
                acc = 0.0
                for m in range(i + 1, j + 1):
                    acc += XT[m, i] * RI[m, j]
                x = -acc / XT[i, i]
            RI[i, j] = x
            total += x * x
    inv_fro = math.sqrt(total)
    if not math.isfinite(inv_fro):
        return False
    return inv_fro * rank_tol * fro < 1.0


@njit(
    cache=True,
    fastmath=FASTMATH,
    error_model="numpy",
    entry="f8[:, :, ::1], f8, b1[::1]",
)
def _column_rank_stack(Gn, rank_tol, out):
    K, w, N = Gn.shape
    XT = np.empty((N, w))
    V = np.empty((N, w))
    beta = np.empty(N)
    RI = np.empty((N, N))
    for k in range(K):
        for i in range(w):
            for c in range(N):
                XT[c, i] = Gn[k, i, c]
        fro = _qr(XT, w, N, V, beta)
        out[k] = _certain(XT, N, fro, rank_tol, RI)


def full_column_rank_certain(Gn: np.ndarray, rank_tol: float) -> np.ndarray:
    """Matrices ``X`` (K, w, N), ``N <= w``, that a QR proves of full column rank.

    The certificate that ``_full_rank_stack`` applies to each ``G̃ᵀ``, on a
    stack of its own so tests can hold it against the numpy rule of
    ``rowspace``; False means unsure (the SVD rule decides), never "deficient".
    """
    out = np.zeros(Gn.shape[0], dtype=np.bool_)
    _column_rank_stack(np.ascontiguousarray(Gn, dtype=float), float(rank_tol), out)
    return out


@njit(
    cache=True,
    fastmath=FASTMATH,
    error_model="numpy",
    entry=(
        "f8[:, :, ::1], i8[::1], f8, f8[:, ::1], b1, f8[:, ::1], "
        "i8[::1], i8[::1], i8[::1], i8[::1], i8[::1], f8, i8, b1, f8, f8, "
        "f8[::1], b1[::1]"
    ),
)
def _full_rank_stack(G, normal, rank_tol, F, shared, kap, coff, ncomp, foff, nrow,
                     roff, tol, max_iter, active_set, stop, above, out_d,
                     out_done):  # fmt: skip
    K, w, M = G.shape
    N = coff.shape[0]
    e = w + 1
    R = roff[N - 1] + nrow[N - 1]
    XT = np.empty((w, M))
    V = np.empty((w, M))
    beta = np.empty(w)
    RI = np.empty((w, w))
    A = np.empty((e, M))
    f0 = np.empty(M)
    E = np.empty((1, M))
    Qte = np.empty(w)
    wr, wm, we, WT, Hs, S = work_arrays(R, M, e, N)
    Cf = np.empty(R)
    nz = M - w
    reduced = active_set and nz >= 2 and worth_it(nz, R)
    # The null-space basis and the active set's work arrays hold O(nz M),
    # O(nz R) and O(nz²) numbers: only for the small null spaces they serve
    # (nz <= 7), never O(N²) for a grasp of many contacts.
    nr = nz if reduced else 1
    ZT = np.empty((nr, M))
    AT = np.empty((nr, R))
    ct = np.empty(nr)
    aswork = active_set_work(nr, R)
    for k in range(K):
        for i in range(w):
            for m in range(M):
                XT[i, m] = G[k, i, m]  # Gᵀ stored transposed: G itself
        fro = _qr(XT, M, w, V, beta)
        if not _certain(XT, w, fro, rank_tol, RI):
            continue  # rank not certified: the numpy path decides
        Fk = F[0] if shared else F[k]
        if above < math.inf and M > w:
            # Verdicts only: f0 = Z Zᵀ e / ‖Zᵀ e‖² straight from the reflectors
            # (Zᵀ e is the tail of H_{w-1} … H_0 e; O(w M), no Q formed) is
            # feasible (G f0 = 0, eᵀ f0 = 1), so min C f0 > above proves t* > above.
            for m in range(M):
                E[0, m] = 0.0
            for i in range(N):
                E[0, normal[i]] = 1.0
            for j in range(w):
                _reflect(V, j, beta[j], E, 0, M)
            cn2 = 0.0
            for m in range(M):
                if m < w:
                    E[0, m] = 0.0
                else:
                    cn2 += E[0, m] * E[0, m]
            if cn2 > 4.0 * PUSH_TOL * PUSH_TOL:  # else: as the full solve
                for j in range(w - 1, -1, -1):
                    _reflect(V, j, beta[j], E, 0, M)
                for m in range(M):
                    f0[m] = E[0, m] / cn2
                _cmul(Fk, foff, nrow, ncomp, roff, coff, N, f0, Cf)
                lo = Cf[0]
                for j in range(R):
                    lo = min(lo, Cf[j])
                if lo > above:
                    out_done[k] = True
                    out_d[k] = N * lo
                    continue
        if reduced:
            # Z = H_0 … H_{w-1} [0; I]: an orthonormal basis of N(G); the LP
            # in f = Z v goes to the active-set method, the IPM if it fails.
            cn2 = 0.0
            for i in range(nz):
                for m in range(M):
                    ZT[i, m] = 1.0 if m == w + i else 0.0
                for j in range(w - 1, -1, -1):
                    _reflect(V, j, beta[j], ZT, i, M)
                acc = 0.0
                for j in range(N):
                    acc += ZT[i, normal[j]]
                ct[i] = acc
                cn2 += acc * acc
                _cmul(Fk, foff, nrow, ncomp, roff, coff, N, ZT[i], AT[i])
            if not (cn2 > PUSH_TOL * PUSH_TOL):
                out_done[k] = True
                out_d[k] = 0.0  # no balanced force pushes
                continue
            t, ok, _ = reduced_lp(AT, nz, R, ct, cn2, 10 * R + 50, aswork)
            if ok:
                out_done[k] = True
                out_d[k] = N * max(t, 0.0)
                continue
        # Thin Q = H_0 … H_{w-1} [I; 0], written straight into A = [Qᵀ; eᵀ].
        for i in range(w):
            for m in range(M):
                A[i, m] = 1.0 if m == i else 0.0
        for j in range(w - 1, -1, -1):
            for i in range(w):
                _reflect(V, j, beta[j], A, i, M)
        for m in range(M):
            A[w, m] = 0.0
        for i in range(N):
            A[w, normal[i]] = 1.0
        out_done[k] = True
        if M == w:
            out_d[k] = 0.0  # no null space: only f = 0 balances
            continue
        # c = e - Q Qᵀ e, f0 = c / ‖c‖².
        for i in range(w):
            acc = 0.0
            for j in range(N):
                acc += A[i, normal[j]]
            Qte[i] = acc
        cn2 = 0.0
        for m in range(M):
            acc = A[w, m]
            for i in range(w):
                acc -= A[i, m] * Qte[i]
            f0[m] = acc
            cn2 += acc * acc
        if not (cn2 > PUSH_TOL * PUSH_TOL):
            out_d[k] = 0.0  # no balanced force pushes
            continue
        for m in range(M):
            f0[m] /= cn2
        if M - w == 1:  # N(G) is spanned by c: t* = min C c / ‖c‖²
            _cmul(Fk, foff, nrow, ncomp, roff, coff, N, f0, Cf)
            t = Cf[0]
            for j in range(R):
                t = min(t, Cf[j])
        else:
            t, ok, _, _ = _one(
                Fk, A, kap[k], f0, coff, ncomp, foff, nrow, roff, tol, max_iter,
                stop, True, above, wr, wm, we, WT, Hs, S,
            )  # fmt: skip
            if not ok:
                out_done[k] = False  # the numpy path retries, then HiGHS
                continue
        out_d[k] = N * max(t, 0.0)


def solve_full_rank_stack(
    G: np.ndarray,
    facets: list[np.ndarray],
    normal_columns: np.ndarray,
    kappa: np.ndarray,
    *,
    rank_tol: float,
    tol: float,
    max_iter: int,
    active_set: bool = True,
    between: tuple[float, float] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``d*`` of the grasps of one layout whose full row rank a QR certifies.

    Parameters
    ----------
    G : (K, w, M) float
        Normalised effective grasp matrices, ``M >= w``.
    facets : list of (K, r_i, c_i) or (1, r_i, c_i) float
        Facet rows of each contact (leading 1: shared by the stack).
    normal_columns : (N,) int
        Column of each ``f_n``.
    kappa : (K, N) float
        Cone bounds ``‖f_i‖ <= κ_i f_{n,i}``.
    rank_tol, tol, max_iter
        Rank threshold, IPM tolerance on ``t`` and iteration cap.
    active_set : bool, optional
        Solve the LPs of small null spaces (``drakegrasp.batch.lp.active_set.worth_it``)
        with the exact active-set method first (default); False: the IPM only.
    between : (float, float), optional
        Verdicts only (:func:`drakegrasp.batch.lp.dstar.solve_dstar_blocks`'s
        ``verdict_tol``): a grasp stops once ``t*`` is proved below the first
        bound (its ``d_star`` is then an upper bound ``N max(0, t) < N`` that)
        or above the second (``d_star`` is a feasible point's ``N t``, a lower
        bound).  None (default): every ``d*`` to the IPM's accuracy.

    Returns
    -------
    d_star : (K,) float
        ``N max(0, t*)`` where ``done`` (with ``between``: a bound, as above);
        0 elsewhere.
    done : (K,) bool
        Rank ``w`` certified and the LP solved; the rest is left to the caller.
    """
    K = G.shape[0]
    flat, shared, offsets = flat_facets(facets, K)
    out_d = np.zeros(K)
    out_done = np.zeros(K, dtype=np.bool_)
    _full_rank_stack(
        np.ascontiguousarray(G, dtype=float),
        np.ascontiguousarray(normal_columns, dtype=np.int64), float(rank_tol),
        flat, shared, np.ascontiguousarray(kappa, dtype=float), *offsets,
        float(tol), int(max_iter), bool(active_set),
        0.0 if between is None else float(between[0]),
        math.inf if between is None else float(between[1]), out_d, out_done,
    )  # fmt: skip
    return out_d, out_done
