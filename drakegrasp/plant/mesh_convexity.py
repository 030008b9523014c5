"""Whether a collision ``Mesh`` is its convex hull, as Drake's queries take it.

Drake's point contact and signed distances treat a ``Mesh`` as its convex
hull.  For a non-convex mesh (a torus, an L, a mug) the contacts that
:func:`~drakegrasp.analyze_grasp` reads from Drake, and the grasps the planner
finds, may then touch where the object has no surface: across a hole or a
hollow.  :func:`hull_share` measures how far a mesh is from its hull (its
volume over its hull's) and :func:`warn_if_not_convex` says so with a
:class:`NonConvexMeshWarning` when the share is below
:data:`NON_CONVEX_SHARE`.  Volumes are in cubic metres, in the mesh's own
frame with its scale.
"""

from __future__ import annotations

import os
import warnings

import numpy as np
from pydrake.geometry import CalcVolume, Mesh, ReadObjToTriangleSurfaceMesh, Shape

from drakegrasp.errors import GraspWarning

__all__ = [
    "NON_CONVEX_SHARE",
    "NonConvexMeshWarning",
    "hull_share",
    "hull_volume",
    "warn_if_not_convex",
]


class NonConvexMeshWarning(GraspWarning):
    """A collision ``Mesh`` is not convex: Drake, and drakegrasp, use its hull.

    The planner, like Drake's point-contact queries, treats a ``Mesh`` as its
    convex hull, so a grasp may touch where the object has no surface (across
    a torus's hole: all six best WSG-50 grasps of one put their contacts
    there, reported as force closure).
    """


NON_CONVEX_SHARE = 0.95
"""A collision ``Mesh`` whose volume is below this share of its hull's is
warned of (:class:`NonConvexMeshWarning`): a torus is 61 % of its hull."""

_SHARES: dict[tuple, float | None] = {}
""":func:`hull_share` per mesh file (path, size, modification time) and scale."""

_WARNED: set[tuple] = set()
"""Mesh files already warned of: each once per process."""


def hull_volume(hull) -> float:
    """The volume enclosed by a closed polygon mesh, m³.

    Parameters
    ----------
    hull : PolygonSurfaceMesh
        Drake's ``Shape.GetConvexHull()``: polygons over ``num_vertices()``
        vertices, wound either way (the sign is taken off).

    Returns
    -------
    float
        The divergence theorem over the polygons' triangle fans, about the
        vertices' centroid (so far-off meshes lose no digits).
    """
    vertices = np.array([hull.vertex(i) for i in range(hull.num_vertices())])
    if not len(vertices):
        return 0.0
    vertices = vertices - vertices.mean(axis=0)
    total = 0.0
    for e in range(hull.num_elements()):
        poly = hull.element(e)
        ring = vertices[[poly.vertex(k) for k in range(poly.num_vertices())]]
        for k in range(1, len(ring) - 1):
            total += float(np.dot(ring[0], np.cross(ring[k], ring[k + 1])))
    return abs(total) / 6.0


def _key(shape: Mesh) -> tuple | None:
    source = shape.source()
    if not source.is_path():
        return None  # an in-memory mesh: measured each time
    path = str(source.path())
    try:
        stat = os.stat(path)
    except OSError:
        return None
    scale = tuple(float(s) for s in shape.scale3())
    return (path, stat.st_size, stat.st_mtime_ns, scale)


def _own_volume(shape: Mesh) -> float | None:
    """The mesh's volume, m³, or None where it encloses none (open, not manifold).

    A Wavefront ``.obj`` is read with Drake's ``ReadObjToTriangleSurfaceMesh``
    and measured only when every edge bounds exactly two triangles: Drake's
    ``CalcVolume`` measures an open mesh too, by an amount that depends on
    where its origin is.  Another format is Drake's ``CalcVolume``.
    """
    source = shape.source()
    if source.is_path() and str(source.path()).lower().endswith(".obj"):
        try:
            mesh = ReadObjToTriangleSurfaceMesh(source.path(), shape.scale3())
        except Exception:  # noqa: BLE001 - Drake's refusal: nothing to measure
            return None
        tris = np.array([[t.vertex(k) for k in range(3)] for t in mesh.triangles()])
        if not len(tris):
            return None
        edges = np.sort(
            np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1
        )
        _, uses = np.unique(edges, axis=0, return_counts=True)
        if not np.all(uses == 2):
            return None
        v = np.array(mesh.vertices(), dtype=float)
        v = v - v.mean(axis=0)
        signed = np.einsum(
            "ij,ij->i", v[tris[:, 0]], np.cross(v[tris[:, 1]], v[tris[:, 2]])
        )
        return abs(float(np.sum(signed))) / 6.0
    try:
        return float(CalcVolume(shape))
    except Exception:  # noqa: BLE001 - Drake's refusal: nothing to compare
        return None


def hull_share(shape: Shape) -> float | None:
    """A ``Mesh``'s volume over its convex hull's, or None.

    Parameters
    ----------
    shape : pydrake.geometry.Shape

    Returns
    -------
    float or None
        In (0, 1] for a closed mesh (1 when convex, to round-off); None for
        another shape, or a mesh that encloses no volume to compare (an open
        ``.obj``, or a share above 1) or that Drake cannot read.
    """
    if not isinstance(shape, Mesh):
        return None
    return _share(shape, _key(shape))


def _share(shape: Mesh, key: tuple | None) -> float | None:
    """:func:`hull_share` of a mesh whose cache key (:func:`_key`) is known."""
    if key is not None and key in _SHARES:
        return _SHARES[key]
    own = _own_volume(shape)
    try:
        hull = hull_volume(shape.GetConvexHull())
    except Exception:  # noqa: BLE001 - Drake's refusal: nothing to compare
        hull = 0.0
    share = own / hull if own and hull > 0 else None
    if share is not None and share > 1.0 + 1e-9:  # no closed mesh exceeds its hull
        share = None
    if key is not None:
        _SHARES[key] = share
    return share


def warn_if_not_convex(
    shape: Shape, name: str = "", *, user: str = "the planner", stacklevel: int = 2
) -> None:
    """:class:`NonConvexMeshWarning` for a ``Mesh`` well inside its hull.

    Once per mesh file (and scale) in a process, whoever asks: a monitor
    that samples a grasp on it, an analysis run again, or the analysis of a
    grasp planned on it warns no more (an in-memory mesh each time).

    Parameters
    ----------
    shape : pydrake.geometry.Shape
        Any shape; only a ``Mesh`` whose :func:`hull_share` is below
        :data:`NON_CONVEX_SHARE` is warned of.
    name : str
        The geometry's name, for the message.
    user : str
        Who treats the mesh as its hull, for the message ("the planner",
        "this analysis").
    stacklevel : int
        As for ``warnings.warn``, counted from the caller.
    """
    if not isinstance(shape, Mesh):
        return
    key = _key(shape)  # one stat of the file for the share and the once-only
    share = _share(shape, key)
    if share is None or share >= NON_CONVEX_SHARE:
        return
    if key is not None:
        if key in _WARNED:
            return
        _WARNED.add(key)
    warnings.warn(
        f"the object's collision mesh {name!r} is not convex (its volume is "
        f"{100 * share:.0f}% of its hull's): {user}, like Drake's point "
        "contact, treats it as its hull, so a grasp may touch where the "
        "object has no surface (across a hole or a hollow); split it into "
        "convex pieces, one <collision> each, to use its true shape",
        NonConvexMeshWarning,
        stacklevel=stacklevel + 1,
    )
