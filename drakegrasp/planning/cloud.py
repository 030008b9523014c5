r"""Planning on a point cloud: the object is points with normals, not a body.

The perception route: the plant holds the gripper and the surroundings, and
the object is a cloud, a pydrake ``PointCloud`` or an ``(M, 3)`` array in the
world frame, with normals given or estimated from the flattest nearby patch
(:func:`.estimate_normals`) and turned outwards (away from the cloud's
centroid, or towards a ``viewpoint``: the camera, for a one-sided cloud).
Points that are not finite (Drake marks missing depth with NaN) are dropped,
with a :class:`PointCloudWarning` that counts them (the result's
``settings["cloud_dropped"]`` counts every point left out); so is a cloud
too large to be in metres (:data:`CLOUD_UNITS_EXTENT`).

**Frame O** of a cloud is the world frame moved to the cloud's centroid, or
to the centre of symmetry of a completed one-sided cloud (:func:`complete_unseen`):
moments are about it, the best guess of the centre of mass.

**Chords.**  A grasp line through a sampled point ``p`` along its inward normal
``d`` (with a ``viewpoint``, the inward normal turned across the line of sight,
and the approach drawn from the camera's side: the seen side of a one-sided
cloud) gathers the cloud points within ``line_radius`` of it; the farthest of
them along ``d`` is the opposite contact (none: ``"no opposite surface"``, as
on the unseen side of a one-sided cloud), and a point clearly before ``p``
(more than ``line_radius``) occludes it.

**Hand and cloud.**  The gripper's collision shapes are the convex pieces of
:mod:`drakegrasp.planning.surface`.  A pose whose open hand has a cloud point
deeper than the distance tolerance inside any hand shape collides.  Each
finger closes along the grasp axis by the smallest travel at which one of its
shapes reaches a cloud point (a point moving against the closing direction
enters a convex piece at its chord's entry; a spherical fingertip, often smaller
than the cloud's spacing, meets a quadric fitted to the points of the face
around its line: :func:`.sphere_entry`), and its contacts are the points its
shapes touch within ``band``: the point nearest the line for a sphere (a
fingertip), the corners of the touched set's convex hull across the axis for
a flat pad.  The contact normals are the cloud's.

**Robustness.**  The jaws close again on the moved cloud as on a moved object
body, meeting a quadric fitted at each point (:class:`FittedCloud`).

**The unseen side.**  With a ``viewpoint``, space behind the seen surface
(along the camera's rays) may hold the object: a hand whose shapes reach there
(probe points on their surfaces) is rejected, open and closed.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy.spatial import ConvexHull, cKDTree

from drakegrasp.core.deprecation import outside_stacklevel
from drakegrasp.core.tolerances import DEFAULT_DISTANCE_TOLERANCE
from drakegrasp.core.validation import describe, real_array, unit_vectors
from drakegrasp.errors import GraspWarning, InvalidOptionError
from drakegrasp.planning import cloud_normals, cloud_spacing, cloud_tips
from drakegrasp.planning.cloud_normals import _estimate_normals
from drakegrasp.planning.cloud_spacing import (
    _areas,
    _distinct,
    _gather,
    _Spots,
    _spots,
)
from drakegrasp.planning.cloud_tips import _basis_across
from drakegrasp.planning.gripper import ParallelJaw
from drakegrasp.planning.surface import piece_of_shape
from drakegrasp.plant.validation import scoped_name

__all__ = [
    "CLOUD_SMALL_EXTENT",
    "CLOUD_STRAY_RATIO",
    "CLOUD_UNITS_EXTENT",
    "MAX_COORDINATE",
    "CONTACT_BAND",
    "EDGE_LINES",
    "FACING_NEIGHBOURS",
    "FIT_NEIGHBOURS",
    "LINE_RADIUS_SPACINGS",
    "PAD_CONTACT_BAND",
    "UNSEEN_DEPTH_ANGLE",
    "UNSEEN_WEAK",
    "VOXEL_SPACINGS",
    "CloudContact",
    "CloudFingers",
    "CloudSurface",
    "FittedCloud",
    "PointCloudWarning",
    "cloud_surface",
    "complete_unseen",
    "read_cloud",
    "read_cloud_fit",
]

_MOVED_OUT = {
    name: module
    for module in (cloud_normals, cloud_spacing, cloud_tips)
    for name in module.__all__
}
"""Public names that moved to :mod:`.cloud_normals`, :mod:`.cloud_spacing` and
:mod:`.cloud_tips`: still read here, with a ``DeprecationWarning``."""


def __getattr__(name: str):
    module = _MOVED_OUT.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    warnings.warn(
        f"drakegrasp.planning.cloud.{name} moved to {module.__name__}.{name}",
        DeprecationWarning,
        stacklevel=2,
    )
    return getattr(module, name)


CONTACT_BAND = 1e-3
"""A finger shape touches the cloud points within this travel (m) of its first."""

PAD_CONTACT_BAND = DEFAULT_DISTANCE_TOLERANCE
"""A parallel jaw's band (m): its pad's other shapes touch within this travel
of its first touch, the default distance tolerance within which the body
route counts contacts.

A rigid pad stops where it first touches; another of its tip shapes presses
only if the surface lies within the contacts' give.  Fingertips meet the
cloud's fitted surface (:func:`.sphere_entry`, within 20 µm on a sampled can),
so the band can be the body route's: with 0.25 mm the ten best of six clouds
of the YCB soup can (whole, side and oblique views, seeds 0 and 1) held 41
of 60 times at the predicted squeeze, with 0.1 mm 45 (before re-closing on
the cloud, :class:`FittedCloud`, which brought it to 59;
``benchmarks/bench_cloud_jaw.py``)."""


LINE_RADIUS_SPACINGS = 2.5
"""Default line radius in median nearest-neighbour spacings: a disc of that
radius on a randomly sampled surface holds about six points, so a far side
that is there is found (at 1.5 spacings one line in five found none)."""

SHADOW_PROBES = 64
"""Surface points per hand shape tested against a one-sided cloud's shadow."""

UNSEEN_WEAK = 0.05
"""A direction along which the cloud's normal lines fix the centre less than
this (an eigenvalue of ``Σ a_i (I − n nᵀ) / Σ a_i``, with ``a_i`` each point's
share of the surface, at most 1) is undetermined."""

UNSEEN_DEPTH_ANGLE = np.radians(60.0)
"""The completion is skipped when an undetermined direction lies within this
angle of the line of sight (a face seen head-on tells nothing of the depth)."""

_CHUNK = 64
"""Sampled lines processed at once (memory: a few chunk × points floats)."""


@dataclass(frozen=True, eq=False)
class CloudContact:
    """A contact between a finger shape and a cloud point.

    Attributes
    ----------
    p_OC : (3,) float
        The cloud point, metres, frame O (:class:`CloudSurface`'s).
    nhat_O : (3,) float
        Inward unit normal (the cloud's normal, negated).
    psi : float
        Gap left between the shape and the point along the closing direction, m.
    finger_body : str
        Scoped name of the finger body.
    fan : (2, 3) float or None
        At an edge of the cloud, the ends of the arc of inward normals the
        finger may meet there (:data:`~drakegrasp.planning.cloud_hand.FAN_SIGMAS`),
        frame O; None on a smooth patch.
    """

    p_OC: np.ndarray
    nhat_O: np.ndarray
    psi: float
    finger_body: str
    fan: np.ndarray | None = None

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "p_OC": self.p_OC.tolist(),
            "nhat_O": self.nhat_O.tolist(),
            "psi": self.psi,
            "finger_body": self.finger_body,
            "fan": None if self.fan is None else self.fan.tolist(),
        }


MAX_COORDINATE = 1e6
"""Largest cloud coordinate (metres) accepted: a million metres is no object a
hand grasps, and a larger one would overflow the squared distances the route
sums."""

CLOUD_UNITS_EXTENT = 5.0
"""A cloud whose bounding box (its finite points', world axes) is more than this
many metres long on a side gets a :class:`PointCloudWarning` that it may be in
millimetres.

The largest things a robot hand grasps (a long pipe, a ladder's rail) are a
few metres long; in millimetres, anything more than 5 mm across exceeds 5
"metres" (the YCB sugar box, 0.19 m, reads 194), and the planner then finds
every chord "wider than the stroke".  Only a warning: a long thin object is
graspable across its thickness."""

CLOUD_SMALL_EXTENT = 1e-3
"""A cloud whose bounding box is less than this many metres long on its longest
side gets a :class:`PointCloudWarning` that it may have been scaled twice.

A robot hand's smallest objects (a bead, a screw's head) are a few millimetres
across; a cloud in metres divided by 1000 once more reads the YCB sugar box
as 0.19 mm, and the planner then rejects every pose ("no opposite surface":
the cloud is a few distance tolerances across)."""


CLOUD_STRAY_RATIO = 1e3
"""Most times its median point's distance from the cloud's centre (the median
point) that its farthest point may lie.

The cloud is the object: a stray point (a depth camera's spurious return)
makes it as large as that point is far, and the planner's torque scale (the
radius about the centre holding every point) with it.  A 2 mm cube's cloud
with one point 30 m away had that scale at 30 m, 3e4 times its grasps' size,
and the ranking was refused for a "characteristic length out of scale",
which named an argument of the batch engine.  A rod, a plate or a one-sided
view stays within a few times its median."""


class PointCloudWarning(GraspWarning):
    """Planning went on with a point cloud that may not be what was meant.

    Points left out (not finite: a depth camera's missing depth), or an
    extent too large for metres (:data:`CLOUD_UNITS_EXTENT`) or too small
    for an object a hand grasps (:data:`CLOUD_SMALL_EXTENT`), or points in
    near twins (scans merged without downsampling: see :data:`.TWIN_JUMP`).
    Silence it
    with ``warnings.simplefilter("ignore", PointCloudWarning)``.
    """


def read_cloud(point_cloud, normals=None, *, viewpoint=None):
    """Points and outward unit normals of a cloud, world frame, finite only.

    Parameters
    ----------
    point_cloud : pydrake.perception.PointCloud or (M, 3) array
    normals : (M, 3) array, optional
        Overrides the cloud's; estimated when neither gives them.  Only
        their directions count (any finite length, however large or small);
        points whose normal is zero or not finite are dropped.
    viewpoint : (3,) array, optional
        Normals are turned towards it (the camera); default away from the
        centroid.

    Returns
    -------
    points, normals : (M', 3) float
        For scans merged as they were (near twins, :data:`.TWIN_JUMP`), each
        spot's mean point, and its points' normals summed.
    dropped : int
        Points left out (not finite, or no normal could be estimated); a
        spot's twins gathered into its mean are not.

    Raises
    ------
    InvalidOptionError
        An empty cloud, one with no finite point, malformed arrays, or a
        point more than :data:`CLOUD_STRAY_RATIO` times as far from the
        cloud's centre as its median point (a stray point).

    Warns
    -----
    PointCloudWarning
        When points that are not finite were left out (how many), the
        cloud is more than :data:`CLOUD_UNITS_EXTENT` across (millimetres?)
        or less than :data:`CLOUD_SMALL_EXTENT` (scaled twice?), or its
        points come in near twins (gathered into their spots' means).
    """
    return read_cloud_fit(point_cloud, normals, viewpoint=viewpoint)[:3]


def read_cloud_fit(point_cloud, normals=None, *, viewpoint=None):
    """:func:`read_cloud`, and how the normals were estimated.

    Returns
    -------
    points, normals, dropped
        As :func:`read_cloud` returns them.
    fit : dict or None
        None when the normals were given; else ``neighbours`` (points a
        patch), ``noise`` (metres: the RMS residual of the patches' quadric
        fits, the cloud's noise across its surface) and ``error_deg`` (the
        normals' expected standard error, degrees); see
        :func:`.estimate_normals`.
    """
    from pydrake.perception import PointCloud

    source = "cloud_normals"  # where the normals came from, for the messages
    if isinstance(point_cloud, PointCloud):
        points = np.asarray(point_cloud.xyzs(), float).T.copy()
        if normals is None and point_cloud.has_normals():
            normals = np.asarray(point_cloud.normals(), float).T.copy()
            source = "point_cloud's normals field"
            if not np.isfinite(normals).all(axis=1).any():
                warnings.warn(
                    "point_cloud has a normals field with no finite normal "
                    "(Drake fills a new field with NaN: never set?); estimating "
                    "the normals from the points, as for a cloud without one",
                    PointCloudWarning,
                    stacklevel=outside_stacklevel(),
                )
                normals = None
    else:
        points = real_array("point_cloud", point_cloud, error=InvalidOptionError)
    if points.ndim != 2 or points.shape[1] != 3:
        raise InvalidOptionError(
            f"point_cloud must be a PointCloud or an (M, 3) array, got shape "
            f"{points.shape}"
        )
    if viewpoint is not None:
        viewpoint = real_array("viewpoint", viewpoint, error=InvalidOptionError)
        if viewpoint.shape != (3,) or not np.all(np.abs(viewpoint) < MAX_COORDINATE):
            raise InvalidOptionError(
                f"viewpoint must be a point (3,) in metres, each coordinate "
                f"finite and within {MAX_COORDINATE:g} m, got {describe(viewpoint)}"
            )
    if normals is not None:
        normals = real_array("cloud_normals", normals, error=InvalidOptionError)
        if normals.shape != points.shape:
            raise InvalidOptionError(
                f"cloud_normals must have the cloud's shape {points.shape}, got "
                f"{normals.shape}"
            )
    if len(points) == 0:
        raise InvalidOptionError("point_cloud is empty: there is nothing to grasp")
    total = len(points)
    far = np.any(np.abs(points) >= MAX_COORDINATE, axis=1) & np.all(
        np.isfinite(points), axis=1
    )
    if far.any():
        raise InvalidOptionError(
            f"point_cloud has {int(far.sum())} points farther than "
            f"{MAX_COORDINATE:g} m along an axis (a cloud is in metres: divide "
            "one in millimetres by 1000)"
        )
    finite_points = np.all(np.isfinite(points), axis=1)
    finite = finite_points.copy()
    if normals is not None:
        finite &= np.all(np.isfinite(normals), axis=1)
    points = points[finite]
    normals = None if normals is None else normals[finite]
    if len(points) < 3:
        bad_normals = int(np.sum(finite_points & ~finite))
        if bad_normals:  # the points are there: their normals are not
            raise InvalidOptionError(
                f"point_cloud has {len(points)} points of {total} with a finite "
                f"normal: {bad_normals} of its {int(finite_points.sum())} finite "
                f"points have a {source} row that is not finite; too few "
                "to grasp"
            )
        raise InvalidOptionError(
            f"point_cloud has {len(points)} finite points of {total}: too few to "
            "grasp (NaN marks missing points)"
        )
    if not np.any(np.ptp(points, axis=0) > 0.0):
        raise InvalidOptionError(
            f"point_cloud's {len(points)} finite points all lie at one place "
            f"({points[0].tolist()}): there is no surface to grasp"
        )
    _warn_of(points, total)
    _refuse_strays(points)
    spots = _spots(points)
    merged = 0  # points gathered into their spots' means: not dropped
    if spots.sharp:  # scans merged as they were: one point per spot
        if normals is not None:  # unit and oriented, for twins to agree
            points, normals = _oriented(points, normals, viewpoint)
        read = len(points)
        points, normals = _gather(points, normals, spots)
        merged = read - len(points)
        if merged:  # none: twins whose normals disagree (a plate's two faces)
            _warn_of_twins(spots, (read, len(points)))
    fit = None
    if normals is None:
        normals, fit = _estimate_normals(points)
        ok = np.all(np.isfinite(normals), axis=1)
        points, normals = points[ok], normals[ok]
    # Only the direction of a normal counts: ``unit_vectors`` divides each by
    # its largest |component| before its norm, so a normal of any finite
    # length (1e200 or subnormal) keeps its direction; ``np.linalg.norm``
    # overflowed to inf there and turned the normal into a zero vector.
    ok = np.any(normals != 0.0, axis=1)
    points = points[ok]
    normals = unit_vectors("cloud_normals", normals[ok], error=InvalidOptionError)
    if len(points) < 3:
        raise InvalidOptionError(
            f"point_cloud has {len(points)} points of {total} with a finite, "
            "non-zero normal: too few to grasp"
        )
    points, normals = _oriented(points, normals, viewpoint, checked=True)
    return points, normals, total - merged - len(points), fit


def _oriented(points, normals, viewpoint, checked: bool = False):
    """Points with a normal, and their unit normals turned to the viewpoint.

    ``checked``: the normals are already unit and non-zero.  Without a
    viewpoint, away from the points' centroid.
    """
    if not checked:
        ok = np.any(normals != 0.0, axis=1)
        points = points[ok]
        normals = unit_vectors("cloud_normals", normals[ok], error=InvalidOptionError)
    towards = points - points.mean(axis=0) if viewpoint is None else viewpoint - points
    flip = np.sum(normals * towards, axis=1) < 0
    normals[flip] *= -1
    return points, normals


def _refuse_strays(points: np.ndarray) -> None:
    """Refuse a cloud whose farthest point makes it another object's size.

    Raises
    ------
    InvalidOptionError
        The farthest point from the median point is more than
        :data:`CLOUD_STRAY_RATIO` times the median point's distance (of the
        distinct points, :data:`.DISTINCT` apart: a spot repeated many times
        counts once).
    """
    distinct = _distinct(points)  # a spot seen many times counts once
    centre = np.median(distinct, axis=0)
    r = np.linalg.norm(points - centre, axis=1)
    typical = float(np.median(np.linalg.norm(distinct - centre, axis=1)))
    far = int(np.argmax(r))
    if typical > 0.0 and r[far] > CLOUD_STRAY_RATIO * typical:
        stray = int(np.count_nonzero(r > CLOUD_STRAY_RATIO * typical))
        raise InvalidOptionError(
            f"point_cloud has {stray} point(s) more than {CLOUD_STRAY_RATIO:g} "
            f"times as far from its centre as its median point ({typical:.3g} m): "
            f"the farthest, {points[far].tolist()}, is {r[far]:.4g} m away; the "
            "cloud is the object, so crop it to the object (a stray point, a "
            "depth camera's spurious return, makes the object that large)"
        )


def _warn_of(points: np.ndarray, total: int) -> None:
    """Warn of the non-finite points left out and of an extent unlike metres."""
    left_out = total - len(points)
    if left_out:
        warnings.warn(
            f"point_cloud: left out {left_out} of {total} points that are not "
            "finite (NaN marks missing depth; with cloud_normals, a point whose "
            f"normal is not finite too); planning on the other {len(points)}",
            PointCloudWarning,
            stacklevel=outside_stacklevel(),
        )
    extent = float(np.max(np.ptp(points, axis=0)))
    if extent > CLOUD_UNITS_EXTENT:
        warnings.warn(
            f"point_cloud is {extent:.4g} m across (its bounding box's longest side), "
            f"more than {CLOUD_UNITS_EXTENT:g} m: a cloud is in metres; if this "
            f"one is in millimetres, divide it by 1000 ({extent / 1000:.4g} m)",
            PointCloudWarning,
            stacklevel=outside_stacklevel(),
        )
    if extent < CLOUD_SMALL_EXTENT:
        warnings.warn(
            f"point_cloud is {extent * 1e3:.4g} mm across (its bounding box's "
            f"longest side), less than {CLOUD_SMALL_EXTENT * 1e3:g} mm, smaller "
            "than what a hand grasps: a cloud is in metres; if this one was "
            f"divided by 1000 twice, multiply it by 1000 ({extent * 1e3:.4g} m)",
            PointCloudWarning,
            stacklevel=outside_stacklevel(),
        )


def complete_unseen(points, normals, viewpoint):
    r"""The unseen side of a one-sided cloud, by point symmetry: an assumption.

    **Assumption** (``plan_grasps(..., complete_unseen=False)`` turns it
    off): the object is centrally symmetric about a centre ``c`` (a can, a
    box, a bottle's body, a ball), so its unseen surface is the seen one
    reflected through ``c``: points ``2c − p`` with normals ``−n``.  ``c`` is
    the point nearest, in least squares, to every normal line ``p + t n``,
    each point weighted by its share ``a_i`` of the surface (:data:`.AREA_NEIGHBOURS`):

    .. math::

        c = \arg\min_c \sum_i a_i \lVert (I - n_i n_i^\top)(c - p_i) \rVert^2,

    the axis of a cylinder (its seen half's normals all cross it; along the
    axis the points' area-weighted mean), the centre of a sphere, and of a box seen
    with two faces.  Along a direction the normals leave undetermined
    (eigenvalue of ``Σ a_i (I − n nᵀ) / Σ a_i`` below :data:`UNSEEN_WEAK`)
    ``c`` takes the points' area-weighted mean; when such a direction lies within
    :data:`UNSEEN_DEPTH_ANGLE` of the line of sight (one face seen head-on:
    its depth is unknown), nothing is completed.  Reflected points within one
    spacing of a seen point (where the two halves meet) are dropped.

    Parameters
    ----------
    points, normals : (M, 3) float
        The seen cloud, world frame, outward unit normals (towards the camera).
    viewpoint : (3,) float
        The camera, world frame.

    Returns
    -------
    added_points, added_normals : (K, 3) float
        The reflected points and their outward normals, world frame (K = 0
        when skipped).
    info : dict
        ``centre`` (3,) world frame or None, ``added`` K, and ``skipped``: the
        reason it was skipped, or None.

    Raises
    ------
    InvalidOptionError
        Points and normals not both (M, 3), finite, with M >= 3.
    """
    points = real_array("points", points, error=InvalidOptionError)
    normals = real_array("normals", normals, error=InvalidOptionError)
    if (
        points.ndim != 2
        or points.shape[1:] != (3,)
        or normals.shape != points.shape
        or len(points) < 3
        or not (np.all(np.isfinite(points)) and np.all(np.isfinite(normals)))
    ):
        raise InvalidOptionError(
            f"complete_unseen needs (M, 3) finite points and normals, M >= 3, got "
            f"shapes {points.shape} and {normals.shape}"
        )
    spots = _spots(points)  # for the shares and the seam alike
    w = _areas(points, normals, spots)
    w = w / w.sum()
    mean = w @ points
    A = np.eye(3) - (normals * w[:, None]).T @ normals
    b = mean - (normals * w[:, None]).T @ np.sum(normals * points, axis=1)
    evals, V = np.linalg.eigh(A)
    strong = evals >= UNSEEN_WEAK
    y = V.T @ b
    centre = V @ np.where(strong, y / np.where(strong, evals, 1.0), V.T @ mean)
    sight = centre - np.asarray(viewpoint, float)
    sight /= np.linalg.norm(sight)
    if np.any(~strong & (np.abs(V.T @ sight) > np.cos(UNSEEN_DEPTH_ANGLE))):
        empty = np.zeros((0, 3))
        info = {"centre": None, "added": 0, "skipped": "depth undetermined"}
        return empty, empty, info
    mirrored = 2 * centre - points
    spacing = spots.spacing  # only whether a seen point is that near counts:
    gap = cKDTree(points).query(mirrored, distance_upper_bound=spacing)[0]
    keep = gap > spacing  # (inf beyond the bound: a far query stops early)
    info = {"centre": centre, "added": int(keep.sum()), "skipped": None}
    return mirrored[keep], -normals[keep], info


def cloud_surface(points, normals, viewpoint=None, complete: bool = True):
    """The surface a hand is planned on: the cloud, completed when it can be.

    With a ``viewpoint`` and ``complete``, the unseen side is reflected in
    (:func:`complete_unseen`) and the whole cloud is planned on, frame O at the
    centre of symmetry; otherwise (no viewpoint, ``complete`` False, or a face
    seen head-on) the cloud as given, O at its centroid, the viewpoint kept.

    Parameters
    ----------
    points, normals : (M, 3) float
        World frame, metres; outward unit normals.
    viewpoint : (3,) float or None
        The camera, world frame.
    complete : bool
        Whether to complete a one-sided cloud.

    Returns
    -------
    surface : CloudSurface
    completion : dict or None
        :func:`complete_unseen`'s ``info``; None when it was not tried.
    """
    completion = None
    if viewpoint is not None and complete:
        added, added_normals, completion = complete_unseen(points, normals, viewpoint)
    if completion is not None and completion["skipped"] is None:
        surface = CloudSurface(
            np.vstack([points, added]),
            np.vstack([normals, added_normals]),
            origin=completion["centre"],
        )
    else:
        surface = CloudSurface(points, normals, viewpoint=viewpoint)
    return surface, completion


VOXEL_SPACINGS = 2.0
"""The voxel a twin warning suggests, in spot spacings: few spots are split
across voxels' sides (at 1.5 spacings, 50 scans 0.1 mm apart still came in
twins), at the price of a coarser cloud (on the sugar box, 2,000-2,750
points of 3,000 spots, their spacing 1.0-1.5 times theirs)."""


def _warn_of_twins(spots: _Spots, gathered: tuple[int, int] | None = None) -> None:
    """Warn that a cloud's points come in near twins (scans merged as they were).

    ``gathered``: (points, spots) when each spot was gathered into its mean.
    """
    if gathered is None:
        doing = f"planning with a spacing of {spots.spacing * 1e3:.3g} mm, the spots'"
    else:
        doing = (
            f"planning on each spot's mean ({gathered[1]} of {gathered[0]} points), "
            f"{spots.spacing * 1e3:.3g} mm apart"
        )
    warnings.warn(
        f"point_cloud's points come in near twins (scans merged without "
        f"downsampling?): a point has {spots.seen} within "
        f"{spots.radius * 1e3:.3g} mm (median, itself included) and its "
        f"nearest {spots.nearest * 1e3:.3g} mm away; {doing}; downsample the "
        f"merged cloud to read it faster, for instance with "
        f"PointCloud.VoxelizedDownSample(voxel_size="
        f"{VOXEL_SPACINGS * spots.spacing:.2g})",
        PointCloudWarning,
        stacklevel=outside_stacklevel(),
    )


class CloudSurface:
    """A cloud in its frame O (at its centroid or a given origin), sampled and cut.

    The sample/chord interface of
    :class:`~drakegrasp.planning.surface.ObjectSurface`.

    Parameters
    ----------
    points, normals : (M, 3) float
        World frame, outward unit normals.
    line_radius : float, optional
        Points this close (m) to a grasp line are on it; default
        :data:`LINE_RADIUS_SPACINGS` times the cloud's spacing (the median
        distance from a point to its nearest distinct neighbour; for near
        twins, as scans merged as they were give, to the nearest point of
        another spot, :data:`.TWIN_JUMP`, or for blurred ones
        :data:`.SPACING_DENSITY_FLOOR` of a spot's side), at least 1 mm.
    viewpoint : (3,) float, optional
        The camera, world frame (a one-sided cloud).
    origin : (3,) float, optional
        The origin of O, world frame, metres: the object's assumed centre of
        mass, about which weight capacity, ``squeeze_needed`` and the torque
        scale are taken; default the points' centroid (which a one-sided
        cloud moves towards the camera).

    Attributes
    ----------
    spacing : float
        The gap between neighbouring points on the surface, metres: the
        median distance from a point to its nearest distinct one, or for
        scans merged as they were to the nearest point of another spot
        (:data:`.TWIN_JUMP`; blurred: :data:`.SPACING_DENSITY_FLOOR` of a
        spot's side).
    seen : int
        Points per spot: 1, or for scans merged as they were the median
        count of a spot's near twins; point-count thresholds
        (:data:`.FIT_MIN_POINTS`, :data:`FIT_NEIGHBOURS`) are multiplied by it.
    centroid : (3,) float
        The points' mean, world frame.
    origin : (3,) float
        O's origin, world frame (``centroid`` unless ``origin`` was given).
    """

    def __init__(self, points, normals, line_radius=None, viewpoint=None, origin=None):
        self.centroid = points.mean(axis=0)
        self.origin = (
            self.centroid.copy() if origin is None else np.asarray(origin, float)
        )
        self.points = points - self.origin
        self.normals = normals
        self.viewpoint = (
            None if viewpoint is None else np.asarray(viewpoint, float) - self.origin
        )
        spots = _spots(self.points)
        self.seen, self.spacing = spots.seen, spots.spacing
        if self.seen > 1:
            _warn_of_twins(spots)
        if line_radius is None:
            line_radius = max(LINE_RADIUS_SPACINGS * self.spacing, 1e-3)
        self.line_radius = float(line_radius)

    def sample(self, n: int, rng: np.random.Generator):
        """``n`` cloud points (with replacement), their normals and indices."""
        idx = rng.integers(len(self.points), size=n)
        return self.points[idx], self.normals[idx], idx

    def _views(self, p_O: np.ndarray) -> np.ndarray:
        v = self.viewpoint[None, :] - p_O
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    def axes(self, p_O: np.ndarray, nout_O: np.ndarray) -> np.ndarray:
        """Grasp axes: the inward normals, across the line of sight with a view.

        A one-sided cloud shows no far side along an inward normal; across the
        line of sight the axis meets the cloud again on the seen side (for a
        convex object), so with a viewpoint the axis is the inward normal with
        its component along the line of sight removed.
        """
        if self.viewpoint is None:
            return -nout_O
        v = self._views(p_O)
        d = -nout_O + np.sum(nout_O * v, axis=1, keepdims=True) * v
        norm = np.linalg.norm(d, axis=1, keepdims=True)
        return np.where(norm > 1e-9, d / np.where(norm > 0, norm, 1.0), -nout_O)

    def approach_hint(self, p_O: np.ndarray, d_O: np.ndarray):
        """With a viewpoint, approach from the camera (the seen side); else None."""
        if self.viewpoint is None:
            return None
        v = -self._views(p_O)
        return v - np.sum(v * d_O, axis=1, keepdims=True) * d_O

    def chord(self, p_O: np.ndarray, d_O: np.ndarray):
        """Entry (0, or negative when occluded), exit and exit normal of lines.

        A point is on a line when its distance from it is at most
        ``line_radius``.  The few such points of each line are found by a
        screen of every point (one matrix product per chunk of lines, with
        a margin far above its rounding), then measured exactly.
        """
        K = len(p_O)
        t_in = np.zeros(K)
        t_out = np.full(K, np.nan)
        n_out = np.zeros((K, 3))
        rho = self.line_radius
        P = self.points
        F = self._features(P)
        scale = float(np.max(np.sum(P * P, axis=1), initial=0.0))
        for s in range(0, K, _CHUNK):
            p, d = p_O[s : s + _CHUNK], d_O[s : s + _CHUNK]
            k, m = self._near_pairs(F, scale, p, d, rho)
            v = P[m] - p[k]
            t = np.einsum("ni,ni->n", v, d[k])
            perp = np.linalg.norm(v - t[:, None] * d[k], axis=1)
            on = perp <= rho
            k, m, t = k[on], m[on], t[on]
            before = np.zeros(len(p))
            back = t < -rho
            np.minimum.at(before, k[back], t[back])
            ahead = t > rho
            k, m, t = k[ahead], m[ahead], t[ahead]
            # the farthest point of each line, the first of equal ones
            order = np.lexsort((m, -t, k))
            first = np.ones(len(order), bool)
            first[1:] = k[order[1:]] != k[order[:-1]]
            line, point, far = k[order[first]], m[order[first]], t[order[first]]
            t_in[s : s + _CHUNK] = before
            t_out[s + line] = far
            j = np.zeros(len(p), np.intp)  # argmax of an all -inf row: point 0
            j[line] = point
            n_out[s : s + _CHUNK] = self.normals[j]
        return t_in, t_out, n_out

    @staticmethod
    def _near_pairs(F, scale, p, d, rho):
        """``(line, point)`` index pairs of points that may lie within ``rho``.

        The squared distance ``vᵀ (I - d dᵀ) v`` (``v = P - p``) of every
        point from every line is one matrix product of the points' quadratic
        features ``F`` with each line's coefficients.  Its rounding (about
        ``1e-15`` of the squared size ``scale`` of points and lines) is
        covered by a margin of ``1e-9 scale``, so no point within ``rho`` is
        missed; the pairs are measured exactly afterwards.
        """
        A = np.eye(3)[None] - d[:, :, None] * d[:, None, :]  # (k, 3, 3)
        Ap = np.einsum("kij,kj->ki", A, p)
        C = np.concatenate(
            [
                A[:, [0, 1, 2], [0, 1, 2]],
                2.0 * A[:, [0, 0, 1], [1, 2, 2]],
                -2.0 * Ap,
                np.einsum("ki,ki->k", p, Ap)[:, None],
            ],
            axis=1,
        )  # (k, 10): the features' coefficients
        limit = rho * rho * (1.0 + 1e-6) + 1e-9 * (scale + np.sum(p * p, axis=1))
        m, k = np.nonzero(F @ C.T <= limit)  # per line: a NaN line blinds only itself
        return k, m

    @staticmethod
    def _features(P):
        """``(M, 10)`` features of points: x², y², z², xy, xz, yz, x, y, z, 1."""
        x, y, z = P.T
        return np.stack([x * x, y * y, z * z, x * y, x * z, y * z, x, y, z,
                         np.ones(len(P))], axis=1)  # fmt: skip

    def radius_about(self, p_O) -> float:
        """Largest distance of a point from ``p_O``, metres."""
        return float(np.max(np.linalg.norm(self.points - np.asarray(p_O), axis=1)))


def _depth_inside(piece, q_G: np.ndarray) -> np.ndarray:
    """How deep points lie inside a piece (negative outside), frame G.

    The smallest distance to the boundary along ±x, ±y, ±z: exact for a box,
    an upper bound of the true depth otherwise (so a point deeper than a
    tolerance is always caught).
    """
    depth = np.full(len(q_G), np.inf)
    for axis in np.eye(3):
        t_in, t_out, _ = piece.chord(q_G, np.tile(axis, (len(q_G), 1)))
        inside = (t_in <= 0) & (t_out >= 0)
        depth = np.minimum(depth, np.where(inside, np.minimum(-t_in, t_out), -1.0))
    return depth


def _maybe_inside(piece, q_G: np.ndarray) -> np.ndarray:
    """The rows of ``q_G`` (frame G, m) that may lie inside a hull piece.

    A point inside a convex hull is within its bounding box and on the inner
    side of every face; one outside either by more than round-off (a
    relative 1e-9 of the coordinates and 1e-12 m) has no depth, so
    :func:`_depth_inside` (three chords per point) need not measure it.  The
    box test, then one matrix product against the faces, drop most of the
    points of a piece's bounding ball; the depths kept are those of the
    whole ball (each is per point, up to the last bit BLAS may round a
    product to in a batch of another size).  Other pieces' chords are
    closed-form: all rows.
    """
    if piece.kind != "hull" or not len(q_G):
        return q_G
    corners = piece.triangles.reshape(-1, 3)
    size = np.max(np.abs(q_G), initial=0.0, where=np.isfinite(q_G))  # NaN: out
    slack = 1e-9 * (np.max(np.abs(corners)) + size) + 1e-12
    lo, hi = corners.min(axis=0) - slack, corners.max(axis=0) + slack
    q_G = q_G[np.all((q_G >= lo) & (q_G <= hi), axis=1)]  # the hull's box first
    gap = piece.offsets[None, :] - q_G @ piece.normals.T  # (K, F), >= 0 inside
    return q_G[np.min(gap, axis=1, initial=np.inf) >= -slack]


class CloudFingers:
    """Stages 2 and 3 on a cloud: hand-cloud collisions, closing, contacts.

    Parameters
    ----------
    plant, ctx : MultibodyPlant, Context
        The plant (hand and surroundings) and its own context (scratch).
    gripper : ParallelJaw
    hand_bodies : sequence of RigidBody
        Every body of the hand's model instance (palm included).
    surface : CloudSurface
    tol : float
        Distance tolerance, metres.
    band : float
        Contact band, metres (:data:`PAD_CONTACT_BAND`).
    """

    def __init__(
        self, plant, ctx, gripper: ParallelJaw, hand_bodies, surface, tol, band
    ):
        self.plant, self.ctx, self.g = plant, ctx, gripper
        self.surface, self.tol, self.band = surface, tol, band
        self.points_W = surface.points + surface.origin
        self.tree = cKDTree(self.points_W)
        inspector = plant.get_geometry_query_input_port().Eval(ctx).inspector()

        def pieces_of(body):
            return [
                piece_of_shape(
                    inspector.GetShape(g),
                    inspector.GetPoseInFrame(g),
                    inspector.GetName(g),
                )
                for g in plant.GetCollisionGeometriesForBody(body)
            ]

        self.hand = [(b, pieces_of(b)) for b in hand_bodies]
        rng = np.random.default_rng(0)  # fixed: the same probe points every call
        self.probes = [
            (b, piece, piece.sample(SHADOW_PROBES, rng)[0])
            for b, pieces in self.hand
            for piece in pieces
            if piece.area > 0
        ]
        self.fingers = [
            [(b, pieces_of(b)) for b in bodies] for bodies in gripper.finger_bodies
        ]
        self.names = [
            [scoped_name(plant, b) for b in bodies] for bodies in gripper.finger_bodies
        ]

    def _world(self, body, piece):
        X_WG = self.plant.EvalBodyPoseInWorld(self.ctx, body) @ piece.X_OG
        return X_WG.rotation().matrix(), X_WG.translation()

    def _near(self, centre, radius) -> np.ndarray:
        return np.asarray(self.tree.query_ball_point(centre, radius), dtype=int)

    def collides(self) -> bool:
        """Whether a cloud point lies deeper than ``tol`` inside a hand shape."""
        for body, pieces in self.hand:
            for piece in pieces:
                R, p = self._world(body, piece)
                idx = self._near(p, piece.radius_about(piece.X_OG.translation()))
                q_G = _maybe_inside(piece, (self.points_W[idx] - p) @ R)
                if len(q_G) and np.any(_depth_inside(piece, q_G) > self.tol):
                    return True
        return False

    def in_shadow(self) -> bool:
        """Whether the hand reaches into the unseen side of a one-sided cloud.

        With a viewpoint, space behind the seen surface (farther along a ray
        from the camera than a cloud point within one spacing of the ray) may
        be the object's: a probe point of a hand shape deeper there than two
        spacings plus the distance tolerance collides with it (the margin
        keeps a fingertip that grazes the seen surface clear).
        """
        view = self.surface.viewpoint
        if view is None:
            return False
        camera = view + self.surface.origin
        rho = self.surface.spacing
        for body, piece, probes_G in self.probes:
            R, p = self._world(body, piece)
            h = probes_G @ R.T + p - camera  # (P, 3) from the camera
            dist = np.linalg.norm(h, axis=1)
            u = h / dist[:, None]
            idx = self._near(p, piece.radius_about(piece.X_OG.translation()) + rho)
            if not len(idx):
                continue
            q = self.points_W[idx] - camera  # (Q, 3)
            along = u @ q.T  # (P, Q)
            perp2 = np.sum(q * q, axis=1)[None, :] - along**2
            shadowed = (perp2 <= rho * rho) & (
                along < dist[:, None] - self.tol - 2 * rho
            )
            if np.any(shadowed):
                return True
        return False

    def close(self, X_WH, q_open):
        """Travel of each finger to the cloud: (q, hits per finger, reason)."""
        g = self.g
        a_W = (X_WH.rotation() @ g.X_HK.rotation()).matrix()[:, 0].copy()
        toward = np.array([1.0, -1.0])
        closed_limit = np.where(toward / g.pad_rate > 0, g.upper, g.lower)
        reach = np.abs((closed_limit - q_open) * g.pad_rate)
        travel = np.full(2, np.inf)
        hits = [[], []]
        for f in (0, 1):
            c_W = toward[f] * a_W
            for body, pieces in self.fingers[f]:
                for piece in pieces:
                    R, p = self._world(body, piece)
                    r = piece.radius_about(piece.X_OG.translation())
                    idx = self._near(p + 0.5 * reach[f] * c_W, r + 0.5 * reach[f])
                    idx = self._in_sweep(idx, p, c_W, self._lateral_reach(piece, r))
                    if not len(idx):
                        continue
                    q_G = (self.points_W[idx] - p) @ R
                    t_in = self._entry(piece, q_G, -c_W @ R, idx, R)
                    ok = np.isfinite(t_in) & (t_in >= -self.tol) & (t_in <= reach[f])
                    if np.any(ok):
                        hits[f].append((body, piece, idx[ok], t_in[ok], c_W))
                        travel[f] = min(travel[f], float(t_in[ok].min()))
        if not np.all(np.isfinite(travel)):
            return None, None, "finger misses the object"
        step = np.maximum(travel - 0.5 * self.tol, 0.0)
        q = q_open + toward * step / g.pad_rate
        return q, (travel, hits), None

    def _lateral_reach(self, piece, r: float) -> float:
        """Farthest from a piece's sweep line (m) a point can count in :meth:`_entry`.

        A chord enters the piece only within its bounding radius ``r`` of
        the line; a fingertip sphere also fits the points of its face within
        :data:`.FIT_RADIUS_LINES` line radii of it (:func:`.sphere_entry`).
        """
        if piece.kind == "ellipsoid" and np.ptp(piece.semi_axes) == 0:
            return r + max(cloud_tips.FIT_RADIUS_LINES, 1.0) * self.surface.line_radius
        return r

    def _in_sweep(self, idx, p, c_W, lateral: float) -> np.ndarray:
        """The points of ``idx`` within ``lateral`` of the line ``p + t c_W``.

        The ball that gathered ``idx`` holds the whole sweep of a piece (its
        bounding ball along its closing travel), several times the volume of
        the capsule the piece can meet; the rest cannot change
        :meth:`_entry`'s answer, which is per point (a sphere's fit reads
        only points within ``lateral``), so leaving them out keeps every
        figure (up to the last bit BLAS may round a product to in a batch of
        another size) and spares the chords of most of a dense cloud.  The
        test is loose by a relative 1e-9 and 1e-12 m, beyond round-off.
        """
        if not len(idx):
            return idx
        w = self.points_W[idx] - p
        along = w @ c_W
        gap2 = np.einsum("ij,ij->i", w, w) - along * along
        loose = lateral * (1.0 + 1e-9) + 1e-12
        return idx[gap2 <= loose * loose]

    def _entry(self, piece, q_G, u_G, idx, R) -> np.ndarray:
        """Travel at which each point, moving along ``u_G``, meets the piece.

        A sphere (a fingertip, often smaller than the cloud's spacing) meets
        the surface that runs between the points: see :func:`.sphere_entry`.
        Other shapes meet a point where it enters them (the chord's entry).
        """
        if piece.kind == "ellipsoid" and np.ptp(piece.semi_axes) == 0:
            n_G = self.surface.normals[idx] @ R  # the points' normals, frame G
            return cloud_tips.sphere_entry(
                piece.semi_axes[0], q_G, u_G, n_G, self.surface.line_radius,
                cloud_tips.FIT_MIN_POINTS * self.surface.seen,
            )  # fmt: skip
        return piece.chord(q_G, np.tile(u_G, (len(q_G), 1)))[0]

    def contacts(self, travel_hits) -> list[CloudContact] | None:
        """The cloud points each finger touches (None unless both fingers do)."""
        travel, hits = travel_hits
        out = []
        for f in (0, 1):
            mine = []
            for body, piece, idx, t_in, c_W in hits[f]:
                close = t_in <= travel[f] + self.band
                if not np.any(close):
                    continue
                idx, t_in = idx[close], t_in[close]
                if piece.kind == "ellipsoid":  # a fingertip: its nearest point
                    keep = [int(np.argmin(t_in))]
                else:  # a pad: the corners of what it touches
                    keep = _hull_corners(self.points_W[idx], c_W)
                name = scoped_name(self.plant, body)
                for k in keep:
                    i = idx[k]
                    mine.append(
                        CloudContact(
                            p_OC=self.surface.points[i].copy(),
                            nhat_O=-self.surface.normals[i],
                            psi=float(t_in[k] - travel[f] + 0.5 * self.tol),
                            finger_body=name,
                        )
                    )
            if not mine:
                return None
            out += mine
        return out


FACING_NEIGHBOURS = 8
"""A re-closing probe meets the quadric of the nearest of this many points whose
normal faces it (:class:`FittedCloud`)."""

EDGE_LINES = 1.5
"""A re-closing probe that meets the surface farther than this many line radii
from every point has slid past the cloud's edge (on a random sample, a disc of
one line radius holds no point 0.7 % of the time, of 1.5 once in 60,000)."""

FIT_NEIGHBOURS = 64
"""A point's quadric fits at most this many of its nearest neighbours (within
its radius): about three times what a random sample puts there, and a bound
on memory where a cloud is far denser (10,000 points in one spot)."""

_FIT_CHUNK = 1 << 20
"""Neighbours fitted at once, over all rows (the 300 scans of a 3,000-point
cloud fitted in one batch asked for 4.8 GiB)."""


class FittedCloud:
    """A cloud's surface as the jaws re-close on it: a quadric at every point.

    Robustness re-closes each perturbed copy of a grasp
    (:func:`~drakegrasp.planning.reclose.reclosed_copies`): every probe travels
    along its finger's closing direction until it meets the surface, and the
    finger's contacts are the probes within the distance tolerance of its
    first touch.  A tolerance of 0.1 mm asks more of the surface than sampled
    points give (between points 1.5 mm apart the can's side sags 0.3 mm).  So
    each point carries a quadric ``h(u, v)`` along its normal, fitted to the
    points of its face (normals within 45°) within ``ρ =``
    :data:`.FIT_RADIUS_LINES` line radii, and a probe meets the quadric of the
    facing point nearest it, then of the point nearest that meeting (where a
    face has fewer than :data:`.FIT_MIN_POINTS` points, times the points a
    spot holds, ``CloudSurface.seen``, its tangent plane).
    A point's quadric is fitted when a probe first meets it (a cloud of
    200,000 points fits only those near the grasps), on at most
    :data:`FIT_NEIGHBOURS` neighbours (times ``seen``).

    Parameters
    ----------
    surface : CloudSurface
    """

    def __init__(self, surface: CloudSurface):
        self.surface = surface
        self.tree = cKDTree(surface.points)
        self.fit = cloud_tips.FIT_RADIUS_LINES * surface.line_radius
        M = len(surface.points)
        self.coef = np.zeros((M, 6))  # too few points: the tangent plane h = 0
        self._done = np.zeros(M, bool)  # fitted when first met (big clouds)

    def _quadrics(self, j: np.ndarray) -> np.ndarray:
        """``(L, 6)`` quadric coefficients of points ``j``, fitted once each."""
        todo = np.unique(j[~self._done[j]])
        if len(todo):
            self.coef[todo] = self._fit(todo)
            self._done[todo] = True
        return self.coef[j]

    def _fit(self, rows: np.ndarray) -> np.ndarray:
        k = min(FIT_NEIGHBOURS * self.surface.seen, len(self.surface.points))
        step = max(1, _FIT_CHUNK // k)  # memory ~ 150 bytes per neighbour
        parts = [
            self._fit_rows(rows[i : i + step], k) for i in range(0, len(rows), step)
        ]
        return np.concatenate(parts) if parts else np.zeros((0, 6))

    def _fit_rows(self, rows: np.ndarray, k: int) -> np.ndarray:
        points, normals = self.surface.points, self.surface.normals
        fit, L = self.fit, len(rows)
        seen = self.surface.seen  # points per spot: merged scans' twins
        dist, idx = self.tree.query(points[rows], k=k, distance_upper_bound=fit)
        dist, idx = dist.reshape(L, k), idx.reshape(L, k)
        valid = np.isfinite(dist)
        idx = np.where(valid, idx, 0)
        a, b = _basis_across(normals[rows])  # (a, b, n) right-handed
        n = normals[rows]
        v = points[idx] - points[rows][:, None, :]
        u = np.einsum("lwi,li->lw", v, a) / fit  # in units of ρ
        w = np.einsum("lwi,li->lw", v, b) / fit
        z = np.einsum("lwi,li->lw", v, n)
        face = valid & (
            np.einsum("lwi,li->lw", normals[idx], n) >= cloud_tips.FIT_FACE_COS
        )
        A = np.stack([np.ones_like(u), u, w, u * u, u * w, w * w], axis=2)
        weight = face.astype(float)
        AtA = np.einsum("lw,lwi,lwj->lij", weight, A, A)
        Atb = np.einsum("lw,lwi,lw->li", weight, A, z)
        eig = np.linalg.eigvalsh(AtA)
        ok = (face.sum(axis=1) >= cloud_tips.FIT_MIN_POINTS * seen) & (
            eig[:, 0] > 1e-9 * np.maximum(eig[:, -1], 1e-300)
        )
        coef = np.zeros((L, 6))
        if np.any(ok):
            coef[ok] = np.linalg.solve(AtA[ok], Atb[ok][..., None])[..., 0]
        return coef

    def _meet(self, p: np.ndarray, d: np.ndarray, j: np.ndarray):
        """Travel along ``d`` from ``p`` to point ``j``'s quadric, and its normal."""
        fit, c = self.fit, self._quadrics(j).T
        x, n = self.surface.points[j], self.surface.normals[j]
        a, b = _basis_across(n)
        w0 = p - x
        u0, v0, z0 = (
            np.einsum("li,li->l", w0, a) / fit,
            np.einsum("li,li->l", w0, b) / fit,
            np.einsum("li,li->l", w0, n),
        )
        u1, v1, z1 = (
            np.einsum("li,li->l", d, a) / fit,
            np.einsum("li,li->l", d, b) / fit,
            np.einsum("li,li->l", d, n),
        )
        # h(u0 + t u1, v0 + t v1) = z0 + t z1:  A t² + B t + C = 0
        A = c[3] * u1 * u1 + c[4] * u1 * v1 + c[5] * v1 * v1
        B = (
            c[1] * u1 + c[2] * v1 + 2 * c[3] * u0 * u1
            + c[4] * (u0 * v1 + u1 * v0) + 2 * c[5] * v0 * v1 - z1
        )  # fmt: skip
        C = (
            c[0] + c[1] * u0 + c[2] * v0 + c[3] * u0 * u0 + c[4] * u0 * v0
            + c[5] * v0 * v0 - z0
        )  # fmt: skip
        # the root nearest the tangent-plane answer −C/B (stable for A → 0;
        # a line that misses the quadric gets its closest approach)
        root = np.sqrt(np.maximum(B * B - 4 * A * C, 0.0))
        q = -0.5 * (B + np.where(B < 0, -root, root))
        t = np.where(q != 0, C / np.where(q != 0, q, 1.0), np.nan)
        u, v = u0 + t * u1, v0 + t * v1
        h_u = (c[1] + 2 * c[3] * u + c[4] * v) / fit
        h_v = (c[2] + c[4] * u + 2 * c[5] * v) / fit
        normal = n - h_u[:, None] * a - h_v[:, None] * b
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        return t, normal

    def chord(self, p_O: np.ndarray, d_O: np.ndarray):
        """Where probes at ``p_O`` moving along ``−d_O`` meet the surface.

        The interface of :meth:`ObjectSurface.chord` as
        :func:`~drakegrasp.planning.reclose.reclosed_copies` reads it: only
        the exit along ``d_O`` (minus the travel along ``−d_O``) and the
        outward normal there.

        Returns
        -------
        t_in : (L,) float
            NaN (not used).
        t_out : (L,) float
            Minus the travel along ``−d_O`` (metres) at which each probe meets
            the surface; NaN where no facing point lies within
            :data:`FACING_NEIGHBOURS` of it, where its first meeting (with
            the nearest facing point's quadric) is more than
            :data:`EDGE_LINES` line radii from every point (the probe slid
            past the cloud's edge), or where its meeting with the quadric of
            the facing point nearest that is farther from that point than
            the radius the quadric was fitted in (:data:`.FIT_RADIUS_LINES`
            line radii: the line grazed it).
        n_out : (L, 3) float
            Outward unit normal there, frame O.
        """
        surf = self.surface
        p = np.asarray(p_O, float)
        d = -np.asarray(d_O, float)  # the probes' travel
        L = len(p)
        t_out = np.full(L, np.nan)
        n_out = np.zeros((L, 3))
        if L == 0:
            return np.full(L, np.nan), t_out, n_out
        k = min(FACING_NEIGHBOURS, len(surf.points))
        _, near = self.tree.query(p, k=k)
        near = near.reshape(L, k)
        facing = np.einsum("lki,li->lk", surf.normals[near], d) < 0.0
        found = facing.any(axis=1)
        j = near[np.arange(L), np.argmax(facing, axis=1)]
        t, _ = self._meet(p, d, j)
        found &= np.isfinite(t)
        hit = p + np.nan_to_num(t)[:, None] * d
        gap, j2 = self.tree.query(hit)
        facing2 = np.einsum("li,li->l", surf.normals[j2], d) < 0.0
        j = np.where(facing2, j2, j)
        t, normal = self._meet(p, d, j)
        found &= np.isfinite(t) & (gap <= EDGE_LINES * surf.line_radius)
        # that quadric holds only within the radius it was fitted in, about
        # its point: a line grazing it there (a box's edge) met it 4.7e26 m
        # away, or 20 mm off the box where it ran on into the next face
        hit = p + np.where(found, t, 0.0)[:, None] * d
        off = np.linalg.norm(hit - surf.points[j], axis=1)
        found &= np.isfinite(hit).all(axis=1) & (off <= self.fit)
        t_out[found] = -t[found]
        n_out[found] = normal[found]
        return np.full(L, np.nan), t_out, n_out


def _hull_corners(points: np.ndarray, axis: np.ndarray) -> list[int]:
    """Indices of the corners of the points' convex hull across ``axis``."""
    if len(points) <= 2:
        return list(range(len(points)))
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    u = np.cross(axis, helper)
    u /= np.linalg.norm(u)
    w = np.cross(axis, u)
    flat = np.column_stack([points @ u, points @ w])
    try:
        return [int(i) for i in ConvexHull(flat).vertices]
    except Exception:  # noqa: BLE001 - collinear or repeated points (Qhull refuses)
        order = np.argsort(flat[:, 0] + 1e-3 * flat[:, 1])
        return [int(order[0]), int(order[-1])]
