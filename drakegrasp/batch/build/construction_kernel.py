r"""Normalised positions, contact frames and grasp matrices in compiled loops.

The numpy routes (:func:`drakegrasp.batch.build.rowspace.normalised_positions`,
:func:`drakegrasp.batch.build.construction.batched_grasp_matrix`,
:func:`drakegrasp.batch.build.construction.batched_normal_grasp_matrix`) build a
chunk's arrays in a few dozen whole-stack passes, each with its (K, N, 3) or
(K, N, 4, 6) temporary; on a few contacts those passes cost about a third as
much as the LP itself.  Here each grasp is built in one pass over its ``N``
contacts, straight into the output.

Every number is computed with the same floating-point operations, in the same
order, as the numpy route (sums left to right, ``‖x‖ = sqrt((x₀² + x₁²) +
x₂²)``, ``a × b`` as ``numpy.cross``, no fast-math), so the outputs are
bitwise those of numpy; the tests compare the two on seeded and degenerate
stacks.  The numpy functions stay the reference, and the route used when numba
is absent.  Nothing here validates: the inputs are a chunk's checked arrays.
"""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.batch.build.kinds import KIND_COMPONENTS
from drakegrasp.batch.compiled import njit

__all__ = [
    "grasp_matrix_stack",
    "normal_rank_certain",
    "normalised_positions_stack",
]


@njit(
    cache=True,
    error_model="numpy",
    entry="readonly f8[:, :, ::1], f8[:, :, ::1], f8[::1]",
)
def _normalise(P, Pn, spread):
    """``Pn = (c_i - c̄) / L`` and ``L`` per grasp, as ``normalised_positions``."""
    K, N, d = P.shape
    centre = np.empty(d)
    for k in range(K):
        for j in range(d):
            centre[j] = P[k, 0, j]
        for i in range(1, N):
            for j in range(d):
                centre[j] += P[k, i, j]
        for j in range(d):
            centre[j] /= N
        big = 0.0
        for i in range(N):
            for j in range(d):
                x = P[k, i, j] - centre[j]
                Pn[k, i, j] = x
                big = max(big, abs(x))
        if not big > 0.0:
            big = 1.0
        top = 0.0
        for i in range(N):
            u = Pn[k, i, 0] / big
            s = u * u
            for j in range(1, d):
                u = Pn[k, i, j] / big
                s += u * u
            top = max(top, s)
        L = big * math.sqrt(top)
        if L > 0.0:
            spread[k] = L
            for i in range(N):
                for j in range(d):
                    Pn[k, i, j] = Pn[k, i, j] / L
        else:
            spread[k] = 1.0
            for i in range(N):
                for j in range(d):
                    Pn[k, i, j] = 0.0


@njit(cache=True, error_model="numpy")
def _tangents(n0, n1, n2):
    """``t1, t2`` of the contact frame of unit ``n``, as ``contact_frames``.

    ``t1``: the axis ``e`` of the smallest ``|n_j|`` (first on ties) minus its
    projection on ``n``, scaled to unit length; ``t2 = n × t1``.
    """
    e0, e1, e2 = 1.0, 0.0, 0.0
    least = abs(n0)
    if abs(n1) < least:
        e0, e1, least = 0.0, 1.0, abs(n1)
    if abs(n2) < least:
        e0, e1, e2 = 0.0, 0.0, 1.0
    dot = (e0 * n0 + e1 * n1) + e2 * n2
    a0, a1, a2 = e0 - dot * n0, e1 - dot * n1, e2 - dot * n2
    norm = math.sqrt((a0 * a0 + a1 * a1) + a2 * a2)
    a0, a1, a2 = a0 / norm, a1 / norm, a2 / norm
    return a0, a1, a2, n1 * a2 - n2 * a1, n2 * a0 - n0 * a2, n0 * a1 - n1 * a0


@njit(cache=True, error_model="numpy")
def _column3(G, k, m, r0, r1, r2, u0, u1, u2):
    """``G[k, :, m] = [u; r × u]`` (``r × u`` as ``numpy.cross``)."""
    G[k, 0, m] = u0
    G[k, 1, m] = u1
    G[k, 2, m] = u2
    G[k, 3, m] = r1 * u2 - r2 * u1
    G[k, 4, m] = r2 * u0 - r0 * u2
    G[k, 5, m] = r0 * u1 - r1 * u0


@njit(
    cache=True,
    error_model="numpy",
    entry=(
        "readonly f8[:, :, ::1], readonly f8[:, :, ::1], readonly f8[:, ::1], "
        "i8[::1], i8[::1], i8[::1], b1[::1], f8[:, :, ::1]"
    ),
)
def _grasp_stack3(P, Nrm, p, rows, start, component, tangent, G):
    """Spatial ``G[k]`` of grasp ``rows[k]``.

    Contact ``i`` owns the columns ``start[i]:start[i + 1]``, with the
    components ``component`` (0 normal, 1-2 tangents, 3 torsion).
    """
    K = rows.shape[0]
    N = P.shape[1]
    a0 = a1 = a2 = b0 = b1 = b2 = 0.0
    for k in range(K):
        g = rows[k]
        for i in range(N):
            n0, n1, n2 = Nrm[g, i, 0], Nrm[g, i, 1], Nrm[g, i, 2]
            r0 = P[g, i, 0] - p[g, 0]
            r1 = P[g, i, 1] - p[g, 1]
            r2 = P[g, i, 2] - p[g, 2]
            if tangent[i]:
                a0, a1, a2, b0, b1, b2 = _tangents(n0, n1, n2)
            for m in range(start[i], start[i + 1]):
                c = component[m]
                if c == 0:
                    _column3(G, k, m, r0, r1, r2, n0, n1, n2)
                elif c == 1:
                    _column3(G, k, m, r0, r1, r2, a0, a1, a2)
                elif c == 2:
                    _column3(G, k, m, r0, r1, r2, b0, b1, b2)
                else:  # a soft finger's torsion: a pure moment about n
                    _column3(G, k, m, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
                    G[k, 3, m] = n0
                    G[k, 4, m] = n1
                    G[k, 5, m] = n2


@njit(
    cache=True,
    error_model="numpy",
    entry=(
        "readonly f8[:, :, ::1], readonly f8[:, :, ::1], readonly f8[:, ::1], "
        "i8[::1], i8[::1], i8[::1], f8[:, :, ::1]"
    ),
)
def _grasp_stack2(P, Nrm, p, rows, start, component, G):
    """Planar ``G[k]`` (columns ``[u; r_x u_y - r_y u_x]``, ``t = (-n_y, n_x)``)."""
    K = rows.shape[0]
    N = P.shape[1]
    for k in range(K):
        g = rows[k]
        for i in range(N):
            n0, n1 = Nrm[g, i, 0], Nrm[g, i, 1]
            r0 = P[g, i, 0] - p[g, 0]
            r1 = P[g, i, 1] - p[g, 1]
            for m in range(start[i], start[i + 1]):
                u0, u1 = (n0, n1) if component[m] == 0 else (-n1, n0)
                G[k, 0, m] = u0
                G[k, 1, m] = u1
                G[k, 2, m] = r0 * u1 - r1 * u0


_EPS = 2.0**-52


@njit(
    cache=True,
    error_model="numpy",
    entry="readonly f8[:, :, ::1], readonly f8[:, :, ::1], i8[::1], f8, b1[::1]",
)
def _normal_rank(P, Nrm, rows, rank_tol, out):
    """Whether ``G_n`` (from ``P``, ``p = 0``; w × N, N <= w) has full column rank.

    Proved from the Cholesky factor ``L`` of the Gram matrix ``C = G_nᵀ G_n``
    (N × N), which costs a third of a Householder QR of ``G_n``.  Rounding:
    the computed ``L Lᵀ`` is ``C + E`` with ``‖E‖₂ <= (w + N + 2) ε ‖G_n‖_F²``
    (forming ``C`` and the Cholesky steps, Higham ch. 3 and 10), so
    ``σ_min(G_n)² >= 1 / ‖L⁻¹‖_F² - (w + N + 2) ε ‖G_n‖_F²``.  The test asks
    ``1 / ‖L⁻¹‖_F² > 2 (rank_tol² + 4 (w + N + 2) ε) ‖G_n‖_F²``, which with
    ``σ_max <= ‖G_n‖_F`` proves ``σ_min > rank_tol σ_max`` with room for the
    rounding of ``‖L⁻¹‖_F`` itself.  It certifies only ``σ_min / σ_max`` above
    about ``1e-7``; the rest is reported unsure and takes the SVD rule.
    """
    K = rows.shape[0]
    N, d = P.shape[1], P.shape[2]
    w = 6 if d == 3 else 3
    XT = np.empty((N, w))  # G_nᵀ: row i is [n_i; c_i × n_i]
    L = np.empty((N, N))
    y = np.empty(N)
    slack = 2.0 * (rank_tol * rank_tol + 4.0 * (w + N + 2) * _EPS)
    for k in range(K):
        g = rows[k]
        for i in range(N):
            n0, n1 = Nrm[g, i, 0], Nrm[g, i, 1]
            r0, r1 = P[g, i, 0], P[g, i, 1]
            XT[i, 0] = n0
            XT[i, 1] = n1
            if d == 2:
                XT[i, 2] = r0 * n1 - r1 * n0
            else:
                n2, r2 = Nrm[g, i, 2], P[g, i, 2]
                XT[i, 2] = n2
                XT[i, 3] = r1 * n2 - r2 * n1
                XT[i, 4] = r2 * n0 - r0 * n2
                XT[i, 5] = r0 * n1 - r1 * n0
        out[k] = _gram_certain(XT, N, w, L, y, slack)


@njit(cache=True, error_model="numpy")
def _gram_certain(XT, N, w, L, y, slack):
    """The test of :func:`_normal_rank` on ``XT = Xᵀ`` (N × w); scratch L, y."""
    fro2 = 0.0
    for j in range(N):  # Cholesky C = L Lᵀ, column j, C formed on the fly
        for i in range(j, N):
            acc = 0.0
            for m in range(w):
                acc += XT[i, m] * XT[j, m]
            if i == j:
                fro2 += acc
            for m in range(j):
                acc -= L[i, m] * L[j, m]
            if i > j:
                L[i, j] = acc / L[j, j]
            elif acc > 0.0:
                L[j, j] = math.sqrt(acc)
            else:
                return False  # not positive definite in floating point
    inv2 = 0.0  # ‖L⁻¹‖_F²: forward substitution of each unit vector
    for j in range(N):
        for i in range(j, N):
            acc = 1.0 if i == j else 0.0
            for m in range(j, i):
                acc -= L[i, m] * y[m]
            y[i] = acc / L[i, i]
            inv2 += y[i] * y[i]
    return inv2 * slack * fro2 < 1.0


def normalised_positions_stack(P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`~drakegrasp.batch.build.rowspace.normalised_positions`, compiled.

    Parameters
    ----------
    P : (K, N, d) float
        Checked contact points, metres.

    Returns
    -------
    scaled : (K, N, d) float
        ``(c_i - c̄) / L``, bitwise as the numpy route.
    spread : (K,) float
        ``L``, metres.
    """
    P = np.ascontiguousarray(P, dtype=float)
    Pn = np.empty_like(P)
    spread = np.empty(P.shape[0])
    if P.size:
        _normalise(P, Pn, spread)
    return Pn, spread


def _columns(layout: tuple[int, ...]):
    """Column starts (N + 1,), components (M,), tangents needed (N,) of a layout."""
    start, component, tangent = [0], [], []
    for kind in layout:
        comps = KIND_COMPONENTS[kind]
        component.extend(comps)
        start.append(start[-1] + len(comps))
        tangent.append(any(c in (1, 2) for c in comps))
    return (
        np.array(start, dtype=np.int64),
        np.array(component, dtype=np.int64),
        np.array(tangent, dtype=np.bool_),
    )


def grasp_matrix_stack(
    P: np.ndarray,
    Nrm: np.ndarray,
    layout: tuple[int, ...],
    *,
    reference_points: np.ndarray | None = None,
    rows: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`~drakegrasp.batch.build.construction.batched_grasp_matrix`, compiled.

    Parameters
    ----------
    P, Nrm : (K, N, d) float
        Contact points and checked unit normals.
    layout : tuple of N kind codes
    reference_points : (K, d) float, optional
        ``p`` (default: the origin, as for normalised positions).
    rows : (k,) int, optional
        Build only these grasps (default: all), without copying the inputs.

    Returns
    -------
    G : (k, w, M) float
        Bitwise as ``batched_grasp_matrix(P[rows], Nrm[rows], p[rows], layout)``.
    normal_columns : (N,) int
    """
    P = np.ascontiguousarray(P, dtype=float)
    Nrm = np.ascontiguousarray(Nrm, dtype=float)
    K, _, d = P.shape
    p = np.zeros((K, d)) if reference_points is None else reference_points
    p = np.ascontiguousarray(p, dtype=float)
    rows = np.arange(K) if rows is None else np.asarray(rows, dtype=np.int64)
    start, component, tangent = _columns(tuple(layout))
    G = np.empty((rows.shape[0], 6 if d == 3 else 3, component.shape[0]))
    if G.size and d == 3:
        _grasp_stack3(P, Nrm, p, rows, start, component, tangent, G)
    elif G.size:
        _grasp_stack2(P, Nrm, p, rows, start, component, G)
    return G, start[:-1].astype(int)


def normal_rank_certain(
    P: np.ndarray, Nrm: np.ndarray, rows: np.ndarray, rank_tol: float
) -> np.ndarray:
    """Grasps ``rows`` whose ``G_n`` (about the origin) is proved of full column rank.

    ``G_n`` (w, N), ``N <= w``, is
    ``batched_normal_grasp_matrix(P[rows], Nrm[rows], 0)``, built per grasp
    inside the loop; the proof (``σ_min > rank_tol σ_max``) is a Cholesky
    factor of ``G_nᵀ G_n`` with a rounding margin (``_normal_rank`` gives the bound).
    False means unsure (the SVD rule decides), never "deficient".
    """
    P = np.ascontiguousarray(P, dtype=float)
    Nrm = np.ascontiguousarray(Nrm, dtype=float)
    rows = np.asarray(rows, dtype=np.int64)
    out = np.zeros(rows.shape[0], dtype=np.bool_)
    if rows.size:
        _normal_rank(P, Nrm, rows, float(rank_tol), out)
    return out
