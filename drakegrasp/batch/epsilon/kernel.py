r"""Ferrari–Canny L1 ε of one wrench set by an expanding polytope, compiled.

ε is the distance from the origin to the nearest facet of ``P = conv{w_i}``
(0 when the origin is not strictly inside).  Building all of ``P`` (Qhull) is
not needed: only the facets near the origin matter.  This kernel grows an
inner polytope ``Q ⊂ P`` from a simplex, always at its facet nearest to the
origin (the expanding-polytope algorithm of GJK/EPA; Zheng's incremental Q1
algorithm, IEEE T-RO 2013, is of this family):

1. ``D + 1`` affinely independent points are chosen greedily, each the farthest
   from the affine hull of those before; ``Q`` is their simplex and ``c`` its
   centroid.  If a height is at round-off level the set is flat and ε = 0.
2. Facets are kept with their vertices, unit outward normal ``n``, offset
   ``b = n·x`` (``x`` on the facet: the signed distance of the origin's
   hyperplane) and the neighbour across each ridge.  Take the facet with the
   smallest ``b`` (a heap) and its support point ``s = argmax_i n·w_i``.  If
   ``n·s <= b + tol`` the facet's hyperplane supports all of ``P``, so
   ``ε(P) <= b``; and ``Q ⊂ P`` gives ``ε(P) >= ε(Q) = b`` when ``b > 0``.  So
   ε = b (0 if ``b <= tol``: then the origin is not strictly inside ``P``).
   Otherwise ``s`` is added beneath–beyond: the facets that see it
   (``n·s > b + tol``, a connected set found from the current facet) are
   removed and every horizon ridge is joined to ``s``.
3. At most ``M - D - 1`` points are added.

Exactly coplanar points are not visible (within ``tol``), so exact degeneracy
(a contact's cone wrenches lie in one 2-flat; symmetric grasps) never makes a
singular facet.  What round-off could spoil is detected and reported instead
of answered: a new facet whose edges are nearly dependent (``ILL``), a facet
that the interior point ``c`` does not lie clearly below, a sub-ridge not
shared by exactly two new facets (``TOPOLOGY``), or a wrench set whose simplex
is thin but not flat.  The caller then uses Qhull (which whitens).  A facet
store that fills up is reported as ``FULL`` and retried with more room.

Accuracy.  ``tol = VISIBLE_TOL × scale``, ``scale`` the largest absolute
coordinate of a primitive wrench (about 1 for hard fingers, ``ν`` for soft fingers of
large ``ν``).  A point ignored as not visible lies at most ``tol`` above a
facet, a flat answer has ε below ``FLAT_TOL × scale`` (every wrench lies that
close to a lower-dimensional flat, so no larger ball fits), and ε at most
``tol`` is reported as 0: the answer is within about ``tol`` of the exact ε
(measured: within 1e-13 relative of Qhull).  The answer's facet plane is always
recomputed from its vertices, never carried over from other facets.

The steps of one insertion (planes, visible region, cone, sub-ridge
matching, heap) are in :mod:`drakegrasp.batch.epsilon.polytope`.  numba is a
dependency of drakegrasp (:mod:`drakegrasp.batch.compiled`); ``AVAILABLE`` says
whether this kernel is compiled (False only where numba is missing).
"""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.batch.epsilon.polytope import (
    AVAILABLE,
    ILL,
    ILL_TOL,
    OK,
    TOPOLOGY,
    _cone,
    _heap_pop,
    _heap_push,
    _height,
    _plane,
    _visible_region,
    njit,
)

__all__ = [
    "AVAILABLE",
    "FLAT",
    "FULL",
    "ILL",
    "OK",
    "TOPOLOGY",
    "epsilon_l1_stack",
]

FLAT, FULL = 1, 4
"""Status of one grasp: ``OK`` (ε found), ``FLAT`` (a flat set, ε = 0), or
``ILL``, ``TOPOLOGY``, ``FULL``: the grasp needs the Qhull route (``FULL`` is
retried with more room first)."""

VISIBLE_TOL = 1e-12
"""A point sees a facet when it is above it by more than this times the scale."""

DRIFT_TOL = 1e-9
"""A recomputed facet offset off by more than this times the scale is ILL."""

MAX_CAPACITY = 2**16
"""Most facets a grasp may store (about 10 MB of work arrays in 6-D); beyond
it the grasp is handed to Qhull."""

FLAT_TOL = 1e-13
"""A simplex height below this times the scale means a flat set (ε = 0)."""


@njit(cache=True)
def _longest_row(X):
    """``(i, ‖X_i‖²)`` of the first longest row of ``X``; ``(0, -1.0)`` if none."""
    pick, top = 0, -1.0
    for i in range(X.shape[0]):
        s = 0.0
        for a in range(X.shape[1]):
            s += X[i, a] * X[i, a]
        if s > top:
            pick, top = i, s
    return pick, top


@njit(cache=True)
def _greedy_simplex(W, simplex, B, res):
    """Indices of ``D + 1`` affinely independent points; (min height, status)."""
    M, D = W.shape
    i0, _ = _longest_row(W)
    simplex[0] = i0
    for i in range(M):
        for a in range(D):
            res[i, a] = W[i, a] - W[i0, a]
    hmin = math.inf
    for j in range(D):
        # res holds each point's offset from v0 with the chosen directions removed.
        pick, top = _longest_row(res)
        h = math.sqrt(top)
        hmin = min(hmin, h)
        if not h > 0.0:
            return hmin, FLAT
        simplex[j + 1] = pick
        for a in range(D):
            B[j, a] = res[pick, a] / h
        for i in range(M):
            dot = 0.0
            for a in range(D):
                dot += res[i, a] * B[j, a]
            for a in range(D):
                res[i, a] -= dot * B[j, a]
    return hmin, OK


@njit(cache=True)
def _simplex_facets(W, simplex, c, ws):
    """The initial simplex's ``D + 1`` facets (facet ``f`` omits vertex ``f``).

    Returns the inscribed radius about ``c`` (its smallest depth below a facet).
    """
    verts, normal, offset, nbr, alive, mark, Q = (
        ws[0], ws[1], ws[2], ws[3], ws[4], ws[5], ws[6],
    )  # fmt: skip
    D = W.shape[1]
    rin = math.inf
    for f in range(D + 1):
        j = 0
        for i in range(D + 1):
            if i != f:
                verts[f, j] = simplex[i]
                nbr[f, j] = i  # across vertex i lies the facet that omits it
                j += 1
        _, side = _plane(W, verts, f, c, Q, normal, offset)
        rin = min(rin, side)
        alive[f] = True
        mark[f] = -1
    return rin


@njit(cache=True)
def _support(W, normal, f):
    best, arg = -math.inf, 0
    for i in range(W.shape[0]):
        h = 0.0
        for a in range(W.shape[1]):
            h += normal[f, a] * W[i, a]
        if h > best:
            best, arg = h, i
    return arg


@njit(cache=True)
def _epsilon(W, ws, simplex, res, c, inserted, heap, key, vis, hor, info):
    """ε of one wrench set ``W`` (M, D) and its status (see the module notes).

    ``info`` receives (points added, facets made).
    """
    M, D = W.shape
    normal, offset, alive = ws[1], ws[2], ws[4]
    cap = offset.shape[0]
    scale = 0.0
    for i in range(M):
        for a in range(D):
            scale = max(scale, abs(W[i, a]))
    if not scale > 0.0 or M <= D:
        return 0.0, FLAT
    hmin, status = _greedy_simplex(W, simplex, ws[6], res)
    if status == FLAT or not hmin > FLAT_TOL * scale:
        return 0.0, FLAT
    if not hmin >= ILL_TOL * scale:
        return 0.0, ILL
    for a in range(D):
        c[a] = 0.0
        for i in range(D + 1):
            c[a] += W[simplex[i], a]
        c[a] /= D + 1
    rin = _simplex_facets(W, simplex, c, ws)
    size = 0
    for f in range(D + 1):
        size = _heap_push(heap, key, size, f, offset[f])
    for i in range(M):
        inserted[i] = False
    for i in range(D + 1):
        inserted[simplex[i]] = True
    tol = VISIBLE_TOL * scale
    count, stamp = D + 1, 0
    while True:
        f = -1
        while size > 0:
            f, size = _heap_pop(heap, key, size)
            if alive[f]:
                break
            f = -1
        if f < 0:
            return 0.0, TOPOLOGY
        # The plane may come from its parents' (_pencil_plane): recompute it
        # from the vertices, so round-off never accumulates into the answer.
        guess = offset[f]
        rmin, _ = _plane(W, ws[0], f, c, ws[6], normal, offset)
        if (
            not rmin >= ILL_TOL * scale
            or not abs(offset[f] - guess) <= DRIFT_TOL * scale
        ):
            return 0.0, ILL
        s = _support(W, normal, f)
        ws[12][f] = _height(W, normal, offset, f, s)
        if not ws[12][f] > tol:
            info[0], info[1] = stamp, count
            b = offset[f]
            return (b if b > tol else 0.0), OK
        if inserted[s]:
            return 0.0, TOPOLOGY
        stamp += 1
        nv, nh = _visible_region(W, s, f, tol, ws, stamp, vis, hor)
        if nv < 0 or count + nh > cap:
            return 0.0, FULL
        status = _cone(W, s, hor, nh, count, ws, c, scale, rin)
        if status != OK:
            return 0.0, status
        for i in range(nv):
            alive[vis[i]] = False
        for nf in range(count, count + nh):
            size = _heap_push(heap, key, size, nf, offset[nf])
        count += nh
        inserted[s] = True


@njit(
    cache=True,
    entry="readonly f8[:, :, ::1], i8[::1], i8, f8[::1], i1[::1], i8[:, ::1]",
)
def _stack(W, hashes, cap, eps, status, info):
    K, M, D = W.shape
    verts = np.zeros((cap, D), dtype=np.int64)
    normal = np.zeros((cap, D))
    offset = np.zeros(cap)
    nbr = np.zeros((cap, D), dtype=np.int64)
    alive = np.zeros(cap, dtype=np.bool_)
    mark = np.zeros(cap, dtype=np.int64)
    Q = np.zeros((D, D))
    tsize = 1
    while tsize < 2 * (D - 1) * cap:
        tsize *= 2
    tkey = np.zeros(tsize, dtype=np.int64)
    tfac = np.zeros(tsize, dtype=np.int64)
    tslot = np.zeros(tsize, dtype=np.int64)
    tstate = np.zeros(tsize, dtype=np.int8)
    height = np.zeros(cap)
    ws = (verts, normal, offset, nbr, alive, mark, Q, hashes, tkey, tfac, tslot,
          tstate, height)  # fmt: skip
    simplex = np.zeros(D + 1, dtype=np.int64)
    res = np.zeros((M, D))
    c = np.zeros(D)
    inserted = np.zeros(M, dtype=np.bool_)
    heap = np.zeros(cap, dtype=np.int64)
    key = np.zeros(cap)
    vis = np.zeros(cap, dtype=np.int64)
    hor = np.zeros((cap, 2), dtype=np.int64)
    for k in range(K):
        eps[k], status[k] = _epsilon(
            W[k], ws, simplex, res, c, inserted, heap, key, vis, hor, info[k]
        )


def _hashes(M: int) -> np.ndarray:
    """Fixed random 62-bit keys of the points (sub-ridge hashing)."""
    return np.random.default_rng(20130601).integers(0, 2**62, size=M, dtype=np.int64)


def epsilon_l1_stack(
    W: np.ndarray, *, capacity: int | None = None, return_info: bool = False
) -> tuple[np.ndarray, ...]:
    """Ferrari–Canny L1 ε of a stack of primitive-wrench sets.

    Parameters
    ----------
    W : (K, M, D) float
        Primitive wrenches (moments already divided by the torque scale) of
        ``K`` grasps, ``M`` each (repeated points are allowed: padding).
    capacity : int, optional
        Facets stored per grasp; a grasp that needs more is retried with four
        times as many (up to ``MAX_CAPACITY``).  Default from ``M`` and ``D``.
    return_info : bool, optional
        Also return ``info`` (K, 2) int: points added and facets made per grasp
        (for benchmarks).

    Returns
    -------
    eps : (K,) float
        ε, valid where ``status`` is ``OK`` or ``FLAT`` (then 0).
    status : (K,) int8
        ``OK``, ``FLAT``, or ``ILL``/``TOPOLOGY``/``FULL``: round-off could
        spoil this grasp's answer, so the caller must use Qhull for it.
    """
    if not AVAILABLE:  # pragma: no cover
        raise RuntimeError("epsilon_l1_stack needs numba")
    W = np.ascontiguousarray(W, dtype=np.float64)
    K, M, D = W.shape
    if capacity is None:
        capacity = max(256, 8 * M * D)
    eps = np.zeros(K)
    status = np.zeros(K, dtype=np.int8)
    hashes = _hashes(M)
    info = np.zeros((K, 2), dtype=np.int64)
    _stack(W, hashes, int(capacity), eps, status, info)
    rows = np.flatnonzero(status == FULL)
    while rows.size and capacity < MAX_CAPACITY:
        capacity *= 4
        sub_eps = np.zeros(rows.size)
        sub_status = np.zeros(rows.size, dtype=np.int8)
        sub_info = np.zeros((rows.size, 2), dtype=np.int64)
        _stack(
            np.ascontiguousarray(W[rows]), hashes, capacity, sub_eps, sub_status,
            sub_info,
        )  # fmt: skip
        eps[rows], status[rows], info[rows] = sub_eps, sub_status, sub_info
        rows = rows[sub_status == FULL]
    if return_info:
        return eps, status, info
    return eps, status
