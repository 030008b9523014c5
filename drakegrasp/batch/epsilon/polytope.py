r"""The polytope updates of the ε kernel, compiled with numba (numpy only).

Facets of a simplicial polytope in ``D`` dimensions, stored as arrays: vertex
indices ``verts (F, D)``, unit outward normals ``normal (F, D)``, offsets
``offset (F,)`` (``n·x = b`` on the facet) and ``nbr (F, D)``, the facet
across the ridge opposite each vertex slot.  The functions here are the steps
of one beneath–beyond insertion used by :mod:`drakegrasp.batch.epsilon.kernel`:
the planes of new facets (from their vertices by Gram–Schmidt, or O(D) from
the planes of the two facets that meet at their ridge), the facets a point
sees and their horizon, the cone of new facets over the horizon and the
matching of its sub-ridges, and a binary heap of facets keyed by offset.

The work arrays travel as one tuple ``ws``: ``(verts, normal, offset, nbr,
alive, mark, Q, hashes, table keys, table facets, table slots, table states,
height)``.
"""

from __future__ import annotations

import math

from drakegrasp.batch.compiled import AVAILABLE, njit

__all__ = ["AVAILABLE", "ILL", "OK", "TOPOLOGY", "njit"]

OK, ILL, TOPOLOGY = 0, 2, 3
"""Statuses of an insertion (the kernel's ``OK``, ``ILL``, ``TOPOLOGY``)."""

ILL_TOL = 1e-6
"""A simplex height or facet edge residual below this times the scale is ILL."""

PENCIL_TOL = 1e-4
"""Facets whose normals have ``1 - cos² < PENCIL_TOL`` get planes from vertices."""


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
