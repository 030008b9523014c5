"""How a point cloud samples its surface: its spacing, its twins, each point's area.

A cloud merged from several scans holds near twins: points a fraction of the
spacing apart that sample the same spot of the surface.  Counted as they are,
they halve the spacing a line's radius is drawn from and double the weight of
the surface where scans overlap.  Here a cloud's *spots* are measured
(:data:`TWIN_JUMP`: the jump in the distances to the nearest neighbours that
sets twins apart from the next spot), the points gathered into them, and each
point weighted by its share of the surface (:data:`AREA_NEIGHBOURS`), as
:func:`.complete_unseen` needs to find a one-sided
cloud's centre.  The spots of the last clouds measured are kept, by the
points' hash: a plan reads its cloud, then completes it.
"""

from __future__ import annotations

import hashlib
import threading
import warnings
from typing import NamedTuple

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from drakegrasp.planning.cloud_tips import FIT_FACE_COS

__all__ = [
    "AREA_EDGE_OFFSET",
    "AREA_FACE_ANGLE",
    "AREA_NEIGHBOURS",
    "AREA_SMOOTHING",
    "DISTINCT",
    "SPACING_DENSITY_FLOOR",
    "SPACING_NEIGHBOURS",
    "SPACING_REACH",
    "SPOT_LINKS",
    "SPOT_NEIGHBOURS",
    "TWIN_JUMP",
    "TWIN_MIN_POINTS",
    "TWIN_MIN_SPOTS",
    "TWIN_RADIUS",
    "TWIN_SHARE",
    "TWIN_TIGHT",
]


DISTINCT = 1e-9
"""Points closer than this (m) are one point repeated, for the spacing."""

TWIN_JUMP = 3.0
"""How many times farther the next spot lies than a spot's own points.

Scans merged without downsampling see each spot of the surface several
times, a registration error apart.  The distances from a point to its
nearest ones then jump, past its own spot's twins, by the ratio of the
spots' spacing to the error: 4-125 for 2-100 scans 0.01-0.1 mm apart on a
2 mm cloud.  Each point's jump is its own, so spots of different counts
(scans that overlap in part, or of different densities) are told alike.  A
single scan's points show such a jump now and then (a point whose nearest
happens to be near): the cloud has *sharp twins* when most of its points
do (:data:`TWIN_SHARE`).  Scans blurred by a larger error (a standard
deviation near a tenth of their spacing) show none, and are told by their
density instead (:data:`SPACING_DENSITY_FLOOR`)."""

TWIN_SHARE = 0.5
"""Share of the points whose neighbour distances jump by :data:`TWIN_JUMP`
for a cloud to have sharp twins (a single scan at random: about 0.1)."""

TWIN_MIN_SPOTS = 256
"""Fewest spots a cloud of sharp twins has: a spot holds at most this
fraction of its points (clusters of points far apart are not twins of one
surface: 200 cubes of 20 points each are not; 300 are)."""

SPOT_NEIGHBOURS = 1024
"""Neighbours looked through for a point's jump: the most scans merged whose
sharp twins are told."""

SPACING_NEIGHBOURS = 64
"""Neighbours whose farthest sets a point's density spacing (see
:data:`SPACING_DENSITY_FLOOR`)."""

SPACING_DENSITY_FLOOR = 0.4
"""The spacing of scans merged as they were, blurred, in spot spacings.

A point's density spacing, ``sqrt(pi / k) r_k`` with ``r_k`` the distance to
its ``k``-th neighbour (``k`` = :data:`SPACING_NEIGHBOURS`), is the side of
the square it has on the surface; the cloud's is the median.  On a randomly
sampled surface the median nearest-neighbour distance is 0.46-0.52 of it (on
a grid, 1).

Scans merged with a registration error too large for a jump
(:data:`TWIN_JUMP`) but below their spacing still see each spot several
times: the nearest-neighbour median is the error.  The points within
:data:`TWIN_RADIUS` density spacings of a point are one spot; with ``m`` the
median count, a spot has ``m`` times a point's square, ``sqrt(m)`` times its
side, and such a cloud's spacing is this fraction of a spot's side (about 0.8
of one scan's nearest-neighbour median).  Other clouds keep that median."""

SPACING_REACH = 20.0
"""The density spacing is a surface's when a point's
:data:`SPACING_NEIGHBOURS`-th neighbour lies at most this many times farther
than its quarter of them (on a surface about 2; up to 10 for blurred twins): not
in another piece of the cloud (70 cubes of 30 points 0.5 m apart read as
twins of 30, a line radius of 0.6 m)."""

TWIN_RADIUS = 0.25
"""Points this many density spacings apart are one spot seen twice (a
randomly sampled surface has another point that near one point in five)."""

TWIN_TIGHT = 0.75
"""Blurred twins lie this close: a point's nearest (the median) within this
fraction of :data:`TWIN_RADIUS`.  Scans merged 0.01-0.1 mm apart put it at
0.05-0.5 of it; a single scan with a dense patch that happens to put a second
point in the radius, at 0.8-1."""

TWIN_MIN_POINTS = 4 * SPACING_NEIGHBOURS
"""Fewest distinct points for blurred twins to be told: in a smaller cloud
the :data:`SPACING_NEIGHBOURS`-th neighbour lies across the object, and its
spots are no spots (a 58-point face read as twins of three)."""

_SPOT_QUERIES = 512
"""Points, evenly spread over the cloud, whose own jumps are measured."""

_SPOT_SPACING_QUERIES = 16384
"""Points, evenly strided, whose distance past their twins is the spacing
(the median of 512 can be 10 % off all of them; of 16,384, 1 %); fewer where
a spot holds hundreds (4 million distances at most)."""

_SPACING_QUERIES = 4096
"""Points, evenly strided, whose density spacing and blurred spot are
measured (the median of 4,096 is within a few per cent of all of them)."""


class _Spots(NamedTuple):
    """A cloud's spacing and the spots its points gather in (:func:`_spots`)."""

    nearest: float
    """The median distance (m) from a point to its nearest distinct one."""
    spacing: float
    """The gap (m) between neighbouring spots: ``nearest`` unless ``seen > 1``."""
    seen: int
    """Points per spot (the median): 1 unless scans were merged as they were."""
    radius: float
    """Points this close (m) are one spot: :data:`DISTINCT` unless ``seen > 1``."""
    sharp: bool = False
    """Twins told by their jump (:data:`TWIN_JUMP`): each spot can be
    gathered into its mean.  Blurred twins (told by their density) are not."""


def _cells(points: np.ndarray, size: float) -> tuple[np.ndarray, np.ndarray]:
    """The cells of a grid of ``size`` (m) that hold ``points``.

    Returns each cell's first point (index) and each point's cell, (M,).
    """
    _, first, cell = np.unique(
        np.round(points / size), axis=0, return_index=True, return_inverse=True
    )
    return first, cell.reshape(-1)


def _distinct(points: np.ndarray) -> np.ndarray:
    """``points`` taken once each, on a grid of :data:`DISTINCT`, in their order."""
    return points[np.sort(_cells(points, DISTINCT)[0])]


SPOT_LINKS = 16
"""Twins a point is linked to when scans merged as they were are gathered
into spots (each spot one share of the surface in the completion's centre):
a spot of up to a hundred points is one connected piece."""


def _gathered(
    points: np.ndarray, spots: _Spots, normals: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The spots ``points`` gather in, as :func:`_cells` gives cells.

    Repeats (:data:`DISTINCT`) are one spot.  For near twins (``seen > 1``) a
    spot is a connected piece of the graph linking each distinct point to its
    :data:`SPOT_LINKS` nearest within ``spots.radius``, wherever it lies (a
    grid of cells would split a spot across a cell's side and count it
    twice), and, given oriented unit ``normals``, only where they agree
    (:data:`.FIT_FACE_COS`: the two faces of a plate thinner than the radius
    stay apart).  Repeats are taken once first: a point's nearest would
    otherwise be its own copies, and its twins left unlinked.
    """
    first, cell = _cells(points, DISTINCT)
    if spots.seen == 1:
        return first, cell
    distinct = points[first]
    M = len(distinct)
    k = min(SPOT_LINKS, M - 1) + 1  # within the radius: a spot of more links too
    tree = cKDTree(distinct)
    rows, cols = [], []
    for lo in range(0, M, _AREA_CHUNK):  # memory ~ 16 k bytes per point
        d, j = tree.query(
            distinct[lo : lo + _AREA_CHUNK], k=k, distance_upper_bound=spots.radius
        )
        linked = np.isfinite(d)
        r, c = np.nonzero(linked)[0] + lo, j[linked]
        if normals is not None:
            n = normals[first]
            agree = np.einsum("ij,ij->i", n[r], n[c]) >= FIT_FACE_COS
            r, c = r[agree], c[agree]
        rows.append(r.astype(np.int32))
        cols.append(c.astype(np.int32))
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    graph = coo_matrix((np.ones(len(rows), bool), (rows, cols)), shape=(M, M))
    _, piece = connected_components(graph, directed=False)
    spot = piece[cell]
    _, first = np.unique(spot, return_index=True)
    return first, spot


_SPOTS_KEPT = 2
"""Clouds whose spots are kept: a plan reads its cloud, then completes it."""

_spots_lock = threading.Lock()

_spots_kept: dict[tuple, _Spots] = {}


def _spots(points: np.ndarray) -> _Spots:
    """:func:`_measured_spots`, kept for the last clouds by their contents.

    A one-sided cloud's plan measures its spots when it reads the cloud
    (:func:`.read_cloud_fit`) and again when it completes it
    (:func:`.complete_unseen`, public and callable alone), on the same
    points: 2.1 s at 10⁶ points.  The key is the points' bytes (a 16-byte
    BLAKE2 digest with the shape and dtype), so a cloud changed in place or
    equal to another one is never confused.
    """
    points = np.ascontiguousarray(points)
    key = (
        points.shape,
        points.dtype.str,
        hashlib.blake2b(points.tobytes(), digest_size=16).digest(),
    )
    with _spots_lock:
        spots = _spots_kept.pop(key, None)
        if spots is not None:  # the last used is the last evicted
            _spots_kept[key] = spots
    if spots is None:
        spots = _measured_spots(points)
        with _spots_lock:
            _spots_kept[key] = spots
            while len(_spots_kept) > _SPOTS_KEPT:
                del _spots_kept[next(iter(_spots_kept))]
    return spots


def _measured_spots(points: np.ndarray) -> _Spots:
    """A cloud's spacing, telling scans merged as they were (near twins).

    The points are taken once each (on a grid of :data:`DISTINCT`: merged
    camera frames repeat the points they share).  The spacing is the median
    distance from a point to its nearest, unless

    - most points' distances to their nearest ones jump by :data:`TWIN_JUMP`
      (:data:`TWIN_SHARE`), in a cloud of at least :data:`TWIN_MIN_SPOTS`
      spots: *sharp twins*.  ``seen`` is the median count of a point's spot
      (itself and the neighbours before its jump), the spacing the median
      distance past each point's own jump (its nearest point of another
      spot; a point without a jump counts its nearest), and the spot radius
      halfway (geometrically) between a spot's farthest twin and that;
    - else, the points come in blurred twins (:func:`_blurred`): the spacing
      is :data:`SPACING_DENSITY_FLOOR` of a spot's side.
    """
    distinct = _distinct(points)
    if len(distinct) < 2:
        return _Spots(0.0, 0.0, 1, DISTINCT)
    tree = cKDTree(distinct)
    nearest = float(np.median(tree.query(distinct, k=2)[0][:, 1]))
    if len(distinct) >= 2 * TWIN_MIN_SPOTS:
        K = min(SPOT_NEIGHBOURS, len(distinct) // TWIN_MIN_SPOTS)
        at = np.linspace(0, len(distinct) - 1, _SPOT_QUERIES).astype(int)
        own = _own_spots(tree.query(distinct[at], k=K + 1)[0][:, 1:])
        seen = int(np.ceil(np.median(own)))
        if np.mean(own > 1) >= TWIN_SHARE and seen >= 2:
            # the distances past each point's jump, of every point strided
            K = min(K, 2 * int(np.max(own)) + 2)
            count = max(1024, min(_SPOT_SPACING_QUERIES, 4_000_000 // K))
            many = distinct[:: max(1, len(distinct) // count)]
            d = tree.query(many, k=K + 1)[0][:, 1:]
            mine = _own_spots(d)
            rows = np.arange(len(d))
            past = d[rows, np.minimum(mine - 1, K - 1)]
            farthest = d[rows, np.maximum(mine - 2, 0)]
            twinned = mine > 1
            spacing = float(np.median(past))
            spread = np.median(farthest[twinned]) if twinned.any() else 0.0
            radius = float(np.sqrt(spread * spacing)) or spacing / TWIN_JUMP
            return _Spots(nearest, spacing, seen, radius, sharp=True)
    blurred = _blurred(tree, distinct, nearest)
    return blurred or _Spots(nearest, nearest, 1, DISTINCT)


def _own_spots(d: np.ndarray) -> np.ndarray:
    """Each point's spot count: 1 + the neighbours before its jump.

    ``d`` (n, K) are the sorted distances to its ``K`` nearest others; the
    jump is the first step of :data:`TWIN_JUMP` or more (none: 1).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        step = d[:, 1:] / d[:, :-1]
    jump = np.isfinite(step) & (step >= TWIN_JUMP)
    has = jump.any(axis=1)
    return np.where(has, np.argmax(jump, axis=1) + 2, 1)


def _blurred(tree, distinct: np.ndarray, nearest: float) -> _Spots | None:
    """Scans merged as they were whose twins show no jump, told by density.

    The median number ``m`` of distinct points within :data:`TWIN_RADIUS`
    density spacings of a point (its spot) is 2 or more (the density a
    surface's, :data:`SPACING_REACH`), a point's nearest
    lies well inside that (:data:`TWIN_TIGHT`), and the nearest-neighbour
    median is below :data:`SPACING_DENSITY_FLOOR` of a spot's side (the
    density spacing times ``sqrt(m)``); at least :data:`TWIN_MIN_POINTS`
    distinct points.  None otherwise.
    """
    if len(distinct) < TWIN_MIN_POINTS:  # k reaches across the object: no spots
        return None
    k = min(SPACING_NEIGHBOURS, len(distinct) - 1)
    queries = distinct[:: max(1, len(distinct) // _SPACING_QUERIES)]
    reach = np.median(tree.query(queries, k=k + 1)[0], axis=0)
    if reach[k] > SPACING_REACH * reach[k // 4]:  # across to other pieces
        return None
    density = float(np.sqrt(np.pi / k) * reach[k])
    near = tree.query_ball_point(queries, TWIN_RADIUS * density, return_length=True)
    seen = max(1, int(np.median(near)))
    side = density * np.sqrt(seen)
    radius = TWIN_RADIUS * density
    if seen < 2 or nearest > TWIN_TIGHT * radius:
        return None
    if not nearest < SPACING_DENSITY_FLOOR * side:
        return None
    return _Spots(nearest, SPACING_DENSITY_FLOOR * side, seen, radius)


def _gather(points: np.ndarray, normals, spots: _Spots):
    """Each spot of ``points`` (:func:`_gathered`) as its mean point, in order.

    ``normals`` (or None): oriented unit normals, which link only twins that
    agree; each spot's is the sum of its points'.
    """
    first, spot = _gathered(points, spots, normals)
    order = np.argsort(first, kind="stable")  # spots in their first point's order
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    spot = rank[spot]
    count = np.bincount(spot).astype(float)

    def summed(values: np.ndarray) -> np.ndarray:
        return np.stack(
            [np.bincount(spot, weights=values[:, i]) for i in range(3)], axis=1
        )

    means = summed(points) / count[:, None]
    return means, None if normals is None else summed(normals)


AREA_NEIGHBOURS = 8
"""A point's raw share of the surface is the square of the distance to this
neighbour on its own face (:func:`.complete_unseen` weighs each point by its
share)."""

AREA_SMOOTHING = 16
"""A point's share of the surface is the median of the raw shares of the
nearest points of its face, this many with itself: a raw share (one distance
squared) scatters by tens of per cent from point to point."""

AREA_FACE_ANGLE = np.radians(30.0)
"""Neighbours whose normals turn more than this from a point's lie on another
face (across a box's edge): they do not count in its share."""

AREA_EDGE_OFFSET = 0.25
"""A point whose :data:`AREA_SMOOTHING` nearest points of its face lie, on
average, more than this many times the farthest one's distance off it is on
the edge of what was seen of that face (half a disc of neighbours: 0.42; a
whole one of 16 random points: 0.16 on average).  Half its neighbourhood is
missing, so its raw share is about double: it is left out of the medians."""

_AREA_CANDIDATES = 48
"""Nearest points searched for a point's neighbours on its own face."""

_AREA_CHUNK = 20_000
"""Points whose neighbourhoods are measured at once (memory: chunk × 48 × 3)."""


def _areas(points: np.ndarray, normals: np.ndarray, spots=None) -> np.ndarray:
    """(M,) each point's share of the surface, up to a common factor.

    Where a camera's points crowd (a face seen near or head-on) each stands
    for less of the surface.  The points are first gathered into spots:
    repeats (:data:`DISTINCT`) and, for scans merged as they were, near twins
    (:data:`TWIN_JUMP`, :data:`SPOT_LINKS`); each spot's share is
    split among its points.  A spot's raw share is ``r_k²``, with ``r_k`` the
    distance to the :data:`AREA_NEIGHBOURS`-th spot of its own face (normals
    within :data:`AREA_FACE_ANGLE`), and its share the median of the raw
    shares of its :data:`AREA_SMOOTHING` nearest spots of the face (itself
    included) that are not on the edge of the view
    (:data:`AREA_EDGE_OFFSET`), or of all of them where every one is.
    Fewer than ``AREA_NEIGHBOURS + 1`` spots: equal shares.

    Parameters
    ----------
    points, normals : (M, 3) float
        Any frame and unit of length; unit normals.
    spots : optional
        The spots of ``points`` (see :data:`TWIN_JUMP`), if already at hand.
    """
    M = len(points)
    first, spot = _gathered(points, _spots(points) if spots is None else spots, normals)
    if len(first) <= AREA_NEIGHBOURS:
        return np.ones(M)
    share = _spot_areas(points[first], normals[first])
    return share[spot] / np.bincount(spot)[spot]


def _spot_areas(points: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """:func:`_areas` of distinct spots, in chunks of rows (memory ~ 50 per row)."""
    M = len(points)
    K = min(_AREA_CANDIDATES, M - 1)
    tree = cKDTree(points)
    raw, reach, face_near = np.empty(M), np.empty(M), []
    inner = np.empty(M, dtype=bool)
    for lo in range(0, M, _AREA_CHUNK):
        rows = slice(lo, min(lo + _AREA_CHUNK, M))
        d, near = tree.query(points[rows], k=K + 1)
        cos = np.einsum("ij,ikj->ik", normals[rows], normals[near])
        same = cos >= np.cos(AREA_FACE_ANGLE)
        same[:, 0] = True  # the point itself (d = 0, first)
        rank = np.cumsum(same, axis=1) - 1  # each neighbour's place on the face

        def distance_to(k, same=same, rank=rank, d=d):
            at = same & (rank == k)
            where = np.argmax(at, axis=1)
            return np.where(at.any(axis=1), d[np.arange(len(d)), where], np.nan)

        raw[rows] = distance_to(AREA_NEIGHBOURS)
        reach[rows] = distance_to(AREA_SMOOTHING - 1)
        face = same & (rank < AREA_SMOOTHING)
        centroid = (
            np.einsum("ik,ikj->ij", face, points[near]) / face.sum(axis=1)[:, None]
        )
        offset = np.linalg.norm(centroid - points[rows], axis=1)
        inner[rows] = offset <= AREA_EDGE_OFFSET * reach[rows]  # False if NaN
        face_near.append(np.where(face, near, -1).astype(np.int32))
    face_near = np.concatenate(face_near)
    scale = np.nanmedian(raw) if np.any(np.isfinite(raw)) else 1.0
    raw = (raw / (scale or 1.0)) ** 2  # in units of the cloud: no underflow
    share = np.empty(M)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN rows
        for lo in range(0, M, _AREA_CHUNK):
            member = face_near[lo : lo + _AREA_CHUNK] >= 0
            at = np.where(member, face_near[lo : lo + _AREA_CHUNK], 0)
            mine = np.nanmedian(np.where(member & inner[at], raw[at], np.nan), 1)
            every = np.nanmedian(np.where(member, raw[at], np.nan), axis=1)
            share[lo : lo + _AREA_CHUNK] = np.where(np.isnan(mine), every, mine)
        if np.all(np.isnan(share)):  # too few points on any face
            return np.ones(M)
        share = np.where(np.isnan(share), np.nanmedian(share), share)
    return np.maximum(share, np.finfo(float).tiny)
