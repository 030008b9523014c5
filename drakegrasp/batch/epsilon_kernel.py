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

numba is optional (``pip install drakegrasp[fast]``); ``AVAILABLE`` says
whether this kernel is compiled.
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


__all__ = [
    "AVAILABLE",
    "FLAT",
    "FULL",
    "ILL",
    "OK",
    "TOPOLOGY",
    "epsilon_l1_stack",
]

OK, FLAT, ILL, TOPOLOGY, FULL = 0, 1, 2, 3, 4
"""Status of one grasp: ε found, flat set (ε = 0), or needs the Qhull route."""

VISIBLE_TOL = 1e-12
"""A point sees a facet when it is above it by more than this times the scale."""

ILL_TOL = 1e-6
"""A simplex height or facet edge residual below this times the scale is ILL."""

PENCIL_TOL = 1e-4
"""Facets whose normals have ``1 - cos² < PENCIL_TOL`` get planes from vertices."""

DRIFT_TOL = 1e-9
"""A recomputed facet offset off by more than this times the scale is ILL."""

MAX_CAPACITY = 2**16
"""Most facets a grasp may store (about 10 MB of work arrays in 6-D); beyond
it the grasp is handed to Qhull."""

FLAT_TOL = 1e-13
"""A simplex height below this times the scale means a flat set (ε = 0)."""


@njit(cache=True)
def _greedy_simplex(W, simplex, B, res):
    """Indices of ``D + 1`` affinely independent points; (min height, status)."""
    M, D = W.shape
    i0, best = 0, -1.0
    for i in range(M):
        s = 0.0
        for a in range(D):
            s += W[i, a] * W[i, a]
        if s > best:
            i0, best = i, s
    simplex[0] = i0
    for i in range(M):
        for a in range(D):
            res[i, a] = W[i, a] - W[i0, a]
    hmin = math.inf
    for j in range(D):
        # res holds each point's offset from v0 with the chosen directions removed.
        pick, top = -1, -1.0
        for i in range(M):
            s = 0.0
            for a in range(D):
                s += res[i, a] * res[i, a]
            if s > top:
                pick, top = i, s
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
def _deflate(x, i, Q, r):
    """Remove from row ``i`` of ``x`` its parts along rows ``0 … r-1`` of ``Q``.

    ``Q``'s rows are orthonormal; Gram–Schmidt twice (so the result is
    orthogonal to working precision).  Returns the row's norm after.
    """
    D = x.shape[1]
    for _ in range(2):
        for q in range(r):
            dot = 0.0
            for a in range(D):
                dot += x[i, a] * Q[q, a]
            for a in range(D):
                x[i, a] -= dot * Q[q, a]
    nrm = 0.0
    for a in range(D):
        nrm += x[i, a] * x[i, a]
    return math.sqrt(nrm)


@njit(cache=True)
def _orient(normal, offset, f, b, nc):
    """Store facet ``f``'s offset with its normal pointing away from ``c``.

    ``b = n·x`` on the facet and ``nc = n·c``; returns ``b - n·c >= 0``, the
    interior point's depth below the facet.
    """
    if b - nc < 0.0:
        for a in range(normal.shape[1]):
            normal[f, a] = -normal[f, a]
        b, nc = -b, -nc
    offset[f] = b
    return b - nc


@njit(cache=True)
def _plane(W, verts, f, c, Q, normal, offset):
    """Unit outward normal and offset of facet ``f``; returns (residual, side).

    ``residual`` is the smallest distance of a vertex from the affine hull of
    the ones before it (Gram–Schmidt on the edges, twice); ``side`` is
    ``b - n·c``, the interior point's depth below the facet.
    """
    D = W.shape[1]
    v0 = verts[f, 0]
    rmin = math.inf
    for r in range(D - 1):
        vr = verts[f, r + 1]
        for a in range(D):
            Q[r, a] = W[vr, a] - W[v0, a]
        nrm = _deflate(Q, r, Q, r)
        rmin = min(rmin, nrm)
        if not nrm > 0.0:
            return 0.0, 0.0
        for a in range(D):
            Q[r, a] /= nrm
    # Start from the coordinate axis least in the facet's span.
    axis, low = 0, math.inf
    for a in range(D):
        s = 0.0
        for r in range(D - 1):
            s += Q[r, a] * Q[r, a]
        if s < low:
            axis, low = a, s
    for a in range(D):
        normal[f, a] = 0.0
    normal[f, axis] = 1.0
    nrm = _deflate(normal, f, Q, D - 1)
    b, nc = 0.0, 0.0
    for a in range(D):
        normal[f, a] /= nrm
        nc += normal[f, a] * c[a]
    for k in range(D):
        for a in range(D):
            b += normal[f, a] * W[verts[f, k], a]
    return rmin, _orient(normal, offset, f, b / D, nc)


@njit(cache=True)
def _heap_push(heap, key, size, f, offset):
    i = size
    heap[i], key[i] = f, offset
    while i > 0:
        parent = (i - 1) // 2
        if key[parent] <= key[i]:
            break
        heap[i], heap[parent] = heap[parent], heap[i]
        key[i], key[parent] = key[parent], key[i]
        i = parent
    return size + 1


@njit(cache=True)
def _heap_pop(heap, key, size):
    """Remove the smallest entry; returns (facet, new size)."""
    top = heap[0]
    size -= 1
    heap[0], key[0] = heap[size], key[size]
    i = 0
    while True:
        lo, left, right = i, 2 * i + 1, 2 * i + 2
        if left < size and key[left] < key[lo]:
            lo = left
        if right < size and key[right] < key[lo]:
            lo = right
        if lo == i:
            break
        heap[i], heap[lo] = heap[lo], heap[i]
        key[i], key[lo] = key[lo], key[i]
        i = lo
    return top, size


@njit(cache=True)
def _height(W, normal, offset, f, s):
    h = -offset[f]
    for a in range(W.shape[1]):
        h += normal[f, a] * W[s, a]
    return h


@njit(cache=True)
def _visible_region(W, s, f0, tol, ws, stamp, vis, hor):
    """Facets that see ``s`` (from ``f0``) and the horizon ridges (facet, slot).

    Returns (number visible, number of horizon ridges); -1 if a list is full.
    ``mark`` is ``2 stamp`` for visible facets, ``2 stamp + 1`` for tested
    invisible ones; ``height`` holds each tested facet's ``n·s - b``.
    """
    normal, offset, nbr, mark, height = ws[1], ws[2], ws[3], ws[5], ws[12]
    D = W.shape[1]
    nv, nh = 1, 0
    vis[0] = f0
    mark[f0] = 2 * stamp
    i = 0
    while i < nv:
        f = vis[i]
        i += 1
        for k in range(D):
            g = nbr[f, k]
            if mark[g] == 2 * stamp:
                continue
            if mark[g] != 2 * stamp + 1:
                height[g] = _height(W, normal, offset, g, s)
                if height[g] > tol:
                    if nv >= vis.shape[0]:
                        return -1, -1
                    mark[g] = 2 * stamp
                    vis[nv] = g
                    nv += 1
                    continue
                mark[g] = 2 * stamp + 1
            if nh >= hor.shape[0]:
                return -1, -1
            hor[nh, 0], hor[nh, 1] = f, k
            nh += 1
    return nv, nh


@njit(cache=True)
def _same_subridge(verts, f, q, g, r, D):
    """Whether ridge vertices of ``f`` but slot ``q`` equal those of ``g`` but ``r``."""
    for i in range(D - 1):
        if i == q:
            continue
        u = verts[f, i]
        found = False
        for j in range(D - 1):
            if j != r and verts[g, j] == u:
                found = True
                break
        if not found:
            return False
    return True


@njit(cache=True)
def _relink(nbr, g, old, new, D):
    for m in range(D):
        if nbr[g, m] == old:
            nbr[g, m] = new
            return True
    return False


@njit(cache=True)
def _stitch(verts, nbr, first, count, hashes, tkey, tfac, tslot, tstate):
    """Link the new facets ``first … first + count - 1`` across their sub-ridges.

    Each new facet's vertices are a horizon ridge plus the new point (last
    slot); across slot ``q < D - 1`` lies the new facet that shares all its
    vertices but slot ``q``'s.  Sub-ridges are matched through a hash table
    (sum of per-point random keys); every one must be matched exactly once.
    """
    D = verts.shape[1]
    size = 1
    while size < 2 * (D - 1) * count:
        size *= 2
    mask = size - 1
    for t in range(size):
        tstate[t] = 0
    open_entries = 0
    for f in range(first, first + count):
        total = 0
        for i in range(D - 1):
            total += hashes[verts[f, i]]
        for q in range(D - 1):
            key = total - hashes[verts[f, q]]
            t = key & mask
            matched = False
            while tstate[t] != 0:
                if tstate[t] == 1 and tkey[t] == key:
                    g, r = tfac[t], tslot[t]
                    if _same_subridge(verts, f, q, g, r, D):
                        nbr[f, q], nbr[g, r] = g, f
                        tstate[t] = 2
                        open_entries -= 1
                        matched = True
                        break
                t = (t + 1) & mask
            if not matched:
                tstate[t], tkey[t], tfac[t], tslot[t] = 1, key, f, q
                open_entries += 1
    return open_entries == 0


@njit(cache=True)
def _pencil_plane(W, s, f, g, nf, ws, c):
    """Plane of ridge(f, g) + ``s`` from the planes of ``f`` and ``g``; (ok, side).

    Every hyperplane through the ridge has its normal in ``span(n_f, n_g)``;
    ``h_f n_g - h_g n_f`` (``h`` the heights of ``s``) is the one through
    ``s``.  O(D) instead of a Gram–Schmidt; not used (ok False) when ``f`` and
    ``g`` are nearly parallel, where it loses accuracy.
    """
    normal, offset, height = ws[1], ws[2], ws[12]
    D = W.shape[1]
    hf, hg = height[f], height[g]
    cos = 0.0
    for a in range(D):
        cos += normal[f, a] * normal[g, a]
    if not 1.0 - cos * cos >= PENCIL_TOL:
        return False, 0.0
    nrm = 0.0
    for a in range(D):
        x = hf * normal[g, a] - hg * normal[f, a]
        normal[nf, a] = x
        nrm += x * x
    nrm = math.sqrt(nrm)
    b, nc = 0.0, 0.0
    for a in range(D):
        normal[nf, a] /= nrm
        b += normal[nf, a] * W[s, a]
        nc += normal[nf, a] * c[a]
    return True, _orient(normal, offset, nf, b, nc)


@njit(cache=True)
def _cone(W, s, hor, nh, first, ws, c, scale, rin):
    """New facets joining the horizon ridges to point ``s``; returns a status."""
    verts, normal, offset, nbr, alive, mark = ws[0], ws[1], ws[2], ws[3], ws[4], ws[5]
    D = W.shape[1]
    for h in range(nh):
        f, k = hor[h, 0], hor[h, 1]
        g = nbr[f, k]
        nf = first + h
        j = 0
        for i in range(D):
            if i != k:
                verts[nf, j] = verts[f, i]
                j += 1
        verts[nf, D - 1] = s
        nbr[nf, D - 1] = g
        if not _relink(nbr, g, f, nf, D):
            return TOPOLOGY
        ok, side = False, 0.0
        if ws[12][f] >= ILL_TOL * scale:
            ok, side = _pencil_plane(W, s, f, g, nf, ws, c)
        if not ok:
            rmin, side = _plane(W, verts, nf, c, ws[6], normal, offset)
            if not rmin >= ILL_TOL * scale:
                return ILL
        if not side >= 0.5 * rin:
            return TOPOLOGY
        alive[nf] = True
        mark[nf] = -1
    if not _stitch(verts, nbr, first, nh, ws[7], ws[8], ws[9], ws[10], ws[11]):
        return TOPOLOGY
    return OK


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


@njit(cache=True)
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
