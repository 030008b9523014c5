r"""Normalised positions, contact frames and grasp matrices in compiled loops.

The numpy routes (:func:`drakegrasp.batch.rowspace.normalised_positions`,
:func:`drakegrasp.batch.construction.batched_grasp_matrix`,
:func:`drakegrasp.batch.construction.batched_normal_grasp_matrix`) build a
chunk's arrays in a few dozen whole-stack passes, each with its (K, N, 3) or
(K, N, 4, 6) temporary; on a few contacts those passes cost about a third as
much as the LP itself.  Here each grasp is built in one pass over its ``N``
contacts, straight into the output.

Every number is computed with the same floating-point operations, in the same
order, as the numpy route (sums left to right, ``‖x‖ = sqrt((x₀² + x₁²) +
x₂²)``, ``a × b`` as :func:`numpy.cross`, no fast-math), so the outputs are
bitwise those of numpy; the tests compare the two on seeded and degenerate
stacks.  The numpy functions stay the reference, and the route used when numba
is absent.  Nothing here validates: the inputs are a chunk's checked arrays.
"""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.batch.compiled import njit
from drakegrasp.batch.construction import KIND_COMPONENTS
from drakegrasp.batch.fused_kernel import _certain, _qr

__all__ = [
    "grasp_matrix_stack",
    "normal_rank_certain",
    "normalised_positions_stack",
]


@njit(cache=True, error_model="numpy")
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
def _frame(n, U):
    """Columns ``U[j] = R e_j`` of the contact frame of unit ``n`` (3 or 2)."""
    d = n.shape[0]
    for j in range(d):
        U[0, j] = n[j]
    if d == 2:
        U[1, 0] = -n[1]
        U[1, 1] = n[0]
        return
    # t1: the axis of the smallest |n_j| (first on ties), projected and scaled.
    axis = 0
    least = abs(n[0])
    for j in range(1, 3):
        if abs(n[j]) < least:
            axis = j
            least = abs(n[j])
    dot = (1.0 if axis == 0 else 0.0) * n[0]
    for j in range(1, 3):
        dot += (1.0 if axis == j else 0.0) * n[j]
    for j in range(3):
        U[1, j] = (1.0 if axis == j else 0.0) - dot * n[j]
    norm = math.sqrt((U[1, 0] * U[1, 0] + U[1, 1] * U[1, 1]) + U[1, 2] * U[1, 2])
    for j in range(3):
        U[1, j] = U[1, j] / norm
    U[2, 0] = n[1] * U[1, 2] - n[2] * U[1, 1]  # t2 = n × t1, as numpy.cross
    U[2, 1] = n[2] * U[1, 0] - n[0] * U[1, 2]
    U[2, 2] = n[0] * U[1, 1] - n[1] * U[1, 0]


@njit(cache=True, error_model="numpy")
def _wrench(r, u, G, k, m):
    """Column ``m`` of ``G[k]``: ``[u; r × u]`` (planar ``[u; r_x u_y - r_y u_x]``)."""
    if r.shape[0] == 2:
        G[k, 0, m] = u[0]
        G[k, 1, m] = u[1]
        G[k, 2, m] = r[0] * u[1] - r[1] * u[0]
        return
    for j in range(3):
        G[k, j, m] = u[j]
    G[k, 3, m] = r[1] * u[2] - r[2] * u[1]
    G[k, 4, m] = r[2] * u[0] - r[0] * u[2]
    G[k, 5, m] = r[0] * u[1] - r[1] * u[0]


@njit(cache=True, error_model="numpy")
def _grasp_stack(P, Nrm, p, rows, contact, component, G):
    """``G[k]`` of grasp ``rows[k]`` for the columns ``(contact, component)``."""
    K = rows.shape[0]
    N, d = P.shape[1], P.shape[2]
    M = contact.shape[0]
    U = np.empty((d, d))
    r = np.empty(d)
    n = np.empty(d)
    zero = np.zeros(d)
    for k in range(K):
        g = rows[k]
        m = 0
        for i in range(N):
            if m < M and contact[m] != i:
                continue
            for j in range(d):
                n[j] = Nrm[g, i, j]
                r[j] = P[g, i, j] - p[g, j]
            _frame(n, U)
            while m < M and contact[m] == i:
                c = component[m]
                if c < d:
                    _wrench(r, U[c], G, k, m)
                else:  # a soft finger's torsion: a pure moment about n
                    _wrench(zero, zero, G, k, m)
                    for j in range(3):
                        G[k, 3 + j, m] = n[j]
                m += 1


@njit(cache=True, error_model="numpy")
def _normal_rank(P, Nrm, rows, rank_tol, out):
    """Whether a QR of ``G_n`` (from ``P``, ``p = 0``) proves full column rank."""
    K = rows.shape[0]
    N, d = P.shape[1], P.shape[2]
    w = 6 if d == 3 else 3
    XT = np.empty((N, w))  # G_nᵀ: row i is [n_i; c_i × n_i]
    V = np.empty((N, w))
    beta = np.empty(N)
    RI = np.empty((N, N))
    r = np.empty(d)
    n = np.empty(d)
    col = np.empty((1, w, 1))
    for k in range(K):
        g = rows[k]
        for i in range(N):
            for j in range(d):
                r[j] = P[g, i, j]
                n[j] = Nrm[g, i, j]
            _wrench(r, n, col, 0, 0)
            for j in range(w):
                XT[i, j] = col[0, j, 0]
        fro = _qr(XT, w, N, V, beta)
        out[k] = _certain(XT, N, fro, rank_tol, RI)


def normalised_positions_stack(P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`~drakegrasp.batch.rowspace.normalised_positions`, compiled.

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


def _columns(layout: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    contact, component, normal = [], [], []
    for i, kind in enumerate(layout):
        normal.append(len(contact))
        for comp in KIND_COMPONENTS[kind]:
            contact.append(i)
            component.append(comp)
    return (
        np.array(contact, dtype=np.int64),
        np.array(component, dtype=np.int64),
        np.array(normal, dtype=int),
    )


def grasp_matrix_stack(
    P: np.ndarray,
    Nrm: np.ndarray,
    layout: tuple[int, ...],
    *,
    reference_points: np.ndarray | None = None,
    rows: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`~drakegrasp.batch.construction.batched_grasp_matrix`, compiled.

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
    contact, component, normal = _columns(tuple(layout))
    G = np.empty((rows.shape[0], 6 if d == 3 else 3, contact.shape[0]))
    if G.size:
        _grasp_stack(P, Nrm, p, rows, contact, component, G)
    return G, normal


def normal_rank_certain(
    P: np.ndarray, Nrm: np.ndarray, rows: np.ndarray, rank_tol: float
) -> np.ndarray:
    """Grasps ``rows`` whose ``G_n`` (about the origin) a QR proves of full column rank.

    ``G_n`` (w, N), ``N <= w``, is
    ``batched_normal_grasp_matrix(P[rows], Nrm[rows], 0)``, built per grasp
    inside the loop; the test is that of
    :func:`drakegrasp.batch.fused_kernel.full_column_rank_certain`.  False means
    unsure (the SVD rule decides), never "deficient".
    """
    P = np.ascontiguousarray(P, dtype=float)
    Nrm = np.ascontiguousarray(Nrm, dtype=float)
    rows = np.asarray(rows, dtype=np.int64)
    out = np.zeros(rows.shape[0], dtype=np.bool_)
    if rows.size:
        _normal_rank(P, Nrm, rows, float(rank_tol), out)
    return out
