"""Surface normals and flat faces of Drake shapes at a point on their surface.

Drake guarantees the witness normal of a signed-distance pair at distance 0 only
for a few shape pairs, so drakegrasp derives normals from the shapes themselves:
given a point on a shape's surface (in the shape's geometry frame ``G``) this
module returns the outward normals of the surface pieces that contain the point
— one for a smooth point, several at an edge or a corner — and, for a flat face
of a box or a convex hull, the face's polygon.  numpy only, plus the shape
classes of ``pydrake.geometry``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import (
    Box,
    Capsule,
    Convex,
    Cylinder,
    Ellipsoid,
    HalfSpace,
    Mesh,
    Shape,
    Sphere,
)

from drakegrasp.errors import ModelError

ON_SURFACE_TOL = 1e-5
"""A point within this distance (m) of a face's plane lies on that face.

Generous because Drake's GJK-based witness points (convex meshes, cylinders)
are accurate to about 1e-5 m only: a witness that close to an edge is taken to
be on the edge, where :func:`drakegrasp.plant.contacts.find_contacts` then uses
the other surface's normal.
"""

EXACT_SURFACE_TOL = 1e-9
"""A point within this distance (m) of a surface touches it, for exact points.

For points computed in closed form on a primitive (the exact closest pairs of
:mod:`~drakegrasp.plant.exact_contact`, fingertip spheres), where round-off,
not GJK's 1e-5 m, is the error: a core this near the other shape touches it,
and the faces within it meet at the point (edge, corner).
"""


@dataclass(frozen=True)
class SurfacePiece:
    """One smooth piece of a shape's surface through a point.

    Attributes
    ----------
    normal_G : (3,) float
        Outward unit normal of the piece at the point, in the geometry frame.
    polygon_G : (k, 3) float or None
        Vertices of the flat face, counter-clockwise about ``normal_G``, in the
        geometry frame; None for a curved piece or an unbounded/disc face.
    """

    normal_G: np.ndarray
    polygon_G: np.ndarray | None = None


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


_BOX_CACHE: dict[tuple[float, float, float], list] = {}
"""Faces of a box by its half extents (read-only arrays, shared)."""


def _box_faces(half: np.ndarray) -> list[tuple[np.ndarray, float, np.ndarray]]:
    key = (float(half[0]), float(half[1]), float(half[2]))
    faces = _BOX_CACHE.get(key)
    if faces is None:
        if len(_BOX_CACHE) >= 4096:  # many box sizes (a generated dataset)
            _BOX_CACHE.clear()
        faces = _BOX_CACHE[key] = _box_faces_of(np.array(key))
    return faces


def _box_faces_of(half: np.ndarray) -> list[tuple[np.ndarray, float, np.ndarray]]:
    faces = []
    for axis in range(3):
        for sign in (1.0, -1.0):
            n = np.zeros(3)
            n[axis] = sign
            u, w = (axis + 1) % 3, (axis + 2) % 3
            corners = []
            for a, b in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
                p = np.zeros(3)
                p[axis] = sign * half[axis]
                p[u] = a * half[u]
                p[w] = b * half[w]
                corners.append(p)
            poly = np.array(corners)
            if sign < 0:
                poly = poly[::-1]
            n.flags.writeable = poly.flags.writeable = False
            faces.append((n, float(half[axis]), poly))
    return faces


def _convex_hull_2d(points: np.ndarray) -> np.ndarray:
    """Indices of the 2-D convex hull, counter-clockwise (monotone chain)."""
    order = np.lexsort((points[:, 1], points[:, 0]))

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[int] = []
    for i in order:
        while (
            len(lower) >= 2
            and cross(points[lower[-2]], points[lower[-1]], points[i]) <= 1e-15
        ):
            lower.pop()
        lower.append(int(i))
    upper: list[int] = []
    for i in order[::-1]:
        while (
            len(upper) >= 2
            and cross(points[upper[-2]], points[upper[-1]], points[i]) <= 1e-15
        ):
            upper.pop()
        upper.append(int(i))
    return np.array(lower[:-1] + upper[:-1], dtype=int)


def plane_basis(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors ``u, w`` with ``(u, w, n)`` right-handed."""
    a = np.zeros(3)
    a[int(np.argmin(np.abs(n)))] = 1.0
    u = _unit(np.cross(a, n))
    return u, np.cross(n, u)


def _hull_faces(vertices: np.ndarray, triangles) -> list:
    """Merge coplanar hull triangles into polygon faces (normal, offset, polygon).

    Triangles join the first group whose normal is within ``1e-9`` and whose
    offset within ``1e-9 · scale``; the comparison against every group at once
    keeps a hull of thousands of faces (a finely meshed plate) to a second.
    """
    scale = float(np.max(np.linalg.norm(vertices - vertices.mean(axis=0), axis=1)))
    tris = np.asarray(triangles, dtype=int).reshape(-1, 3)
    a, b, c = (vertices[tris[:, k]] for k in range(3))
    cr = np.cross(b - a, c - a)
    size = np.linalg.norm(cr, axis=1)
    keep = size >= 1e-14 * scale * scale
    tris, a, cr, size = tris[keep], a[keep], cr[keep], size[keep]
    normals = cr / size[:, None]
    offsets = np.einsum("ij,ij->i", normals, a)
    group_n = np.empty((len(tris), 3))
    group_d = np.empty(len(tris))
    members: list[set] = []
    for n, d, tri in zip(normals, offsets, tris, strict=True):
        g = len(members)
        same = np.flatnonzero(
            (group_n[:g] @ n > 1 - 1e-9)
            & (np.abs(group_d[:g] - d) < 1e-9 * max(scale, 1.0))
        )
        if same.size:
            members[same[0]].update(tri.tolist())
        else:
            group_n[g], group_d[g] = n, d
            members.append(set(tri.tolist()))
    faces = []
    for n, d, idx in zip(group_n, group_d, members, strict=False):
        pts = vertices[sorted(idx)]
        u, w = plane_basis(n)
        hull = _convex_hull_2d(np.column_stack([pts @ u, pts @ w]))
        faces.append((n.copy(), float(d), pts[hull]))
    return faces


_HULL_CACHE: dict[tuple, list] = {}


def _convex_faces(shape: Convex | Mesh) -> list:
    """Polygon faces of a mesh's convex hull, cached per file and scale."""
    source = shape.source()
    key = (
        str(source.path()) if source.is_path() else source.description(),
        tuple(np.asarray(shape.scale3()).tolist()),
    )
    faces = _HULL_CACHE.get(key)
    if faces is None:
        hull = shape.GetConvexHull()
        vertices = np.array([hull.vertex(i) for i in range(hull.num_vertices())])
        triangles = []
        for e in range(hull.num_elements()):
            poly = hull.element(e)
            idx = [poly.vertex(k) for k in range(poly.num_vertices())]
            triangles += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
        faces = _hull_faces(vertices, triangles)
        _HULL_CACHE[key] = faces
    return faces


def flat_faces(shape: Shape) -> list[tuple[np.ndarray, float, np.ndarray]] | None:
    """Planar faces ``(normal_G, offset, polygon_G)`` of a box or convex hull."""
    if isinstance(shape, Box):
        return _box_faces(
            0.5 * np.array([shape.width(), shape.depth(), shape.height()])
        )
    if isinstance(shape, (Convex, Mesh)):
        return _convex_faces(shape)
    return None


_FACE_ARRAYS: dict[int, tuple] = {}


def face_arrays(faces: list) -> tuple:
    """Face normals and offsets, and every face's edges with their face index.

    Cached by the (cached, hence long-lived) face list of a hull.
    """
    hit = _FACE_ARRAYS.get(id(faces))
    if hit is not None and hit[0] is faces:
        return hit[1]
    N = np.array([n for n, _, _ in faces])
    D = np.array([d for _, d, _ in faces])
    EA = np.vstack([poly for _, _, poly in faces])
    EB = np.vstack([np.roll(poly, -1, axis=0) for _, _, poly in faces])
    EF = np.concatenate([np.full(len(poly), k) for k, (_, _, poly) in enumerate(faces)])
    arrays = (N, D, EA, EB, EF)
    if len(_FACE_ARRAYS) >= 256:
        _FACE_ARRAYS.clear()
    _FACE_ARRAYS[id(faces)] = (faces, arrays)
    return arrays


def _hull_vertices(shape: Convex | Mesh) -> np.ndarray:
    hull = shape.GetConvexHull()
    return np.array([hull.vertex(i) for i in range(hull.num_vertices())])


def bounding_sphere(shape: Shape) -> tuple[np.ndarray, float]:
    """A sphere that contains the shape: centre (geometry frame G) and radius.

    Parameters
    ----------
    shape : pydrake.geometry.Shape
        Box, Sphere, Cylinder, Capsule, Ellipsoid, Convex or Mesh (its convex
        hull, which is what Drake's distance queries see).

    Returns
    -------
    centre_G : (3,) float
        Metres, in the geometry frame.
    radius : float
        Metres; ``inf`` for a half space.

    Raises
    ------
    ModelError
        For a shape type drakegrasp cannot bound.
    """
    origin = np.zeros(3)
    if isinstance(shape, Sphere):
        return origin, float(shape.radius())
    if isinstance(shape, Box):
        return origin, 0.5 * float(np.linalg.norm(shape.size()))
    if isinstance(shape, Cylinder):
        return origin, float(np.hypot(shape.radius(), 0.5 * shape.length()))
    if isinstance(shape, Capsule):
        return origin, float(shape.radius() + 0.5 * shape.length())
    if isinstance(shape, Ellipsoid):
        return origin, float(max(shape.a(), shape.b(), shape.c()))
    if isinstance(shape, HalfSpace):
        return origin, float("inf")
    if isinstance(shape, (Convex, Mesh)):
        v = _hull_vertices(shape)
        centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
        return centre, float(np.max(np.linalg.norm(v - centre, axis=1)))
    raise ModelError(
        f"drakegrasp cannot bound a {type(shape).__name__} geometry; use Box, "
        "Sphere, Cylinder, Capsule, Ellipsoid or Convex"
    )


def surface_pieces(
    shape: Shape, p_GQ: np.ndarray, *, tol: float = ON_SURFACE_TOL
) -> list[SurfacePiece]:
    """Outward normals (and flat faces) of ``shape`` at the surface point ``Q``.

    Parameters
    ----------
    shape : pydrake.geometry.Shape
        Box, Sphere, Cylinder, Capsule, Ellipsoid, HalfSpace, Convex or Mesh
        (a Mesh is treated as its convex hull, as Drake's distance queries do).
    p_GQ : (3,) float
        A point on the surface, metres, in the geometry frame ``G``.
    tol : float, optional
        Metres: the point lies on every face whose plane is this near
        (default :data:`ON_SURFACE_TOL`, the accuracy of GJK witnesses).

    Returns
    -------
    list of SurfacePiece
        One piece at a smooth point; two or three at an edge or corner of a box,
        a cylinder's rim or a convex hull's edge.  Never empty: a point that is
        numerically off every face gets the face it is closest to.

    Raises
    ------
    ModelError
        For a shape type drakegrasp cannot take normals of.
    """
    p = np.asarray(p_GQ, dtype=float)
    if isinstance(shape, Sphere):
        return [SurfacePiece(_unit(p))]
    if isinstance(shape, Ellipsoid):
        abc = np.array([shape.a(), shape.b(), shape.c()])
        return [SurfacePiece(_unit(p / abc**2))]
    if isinstance(shape, Capsule):
        half = 0.5 * shape.length()
        axis_point = np.array([0.0, 0.0, np.clip(p[2], -half, half)])
        return [SurfacePiece(_unit(p - axis_point))]
    if isinstance(shape, HalfSpace):
        return [SurfacePiece(np.array([0.0, 0.0, 1.0]))]
    if isinstance(shape, Cylinder):
        r, half = shape.radius(), 0.5 * shape.length()
        rho = float(np.hypot(p[0], p[1]))
        pieces = []
        if abs(rho - r) < tol and rho > 0:
            pieces.append(SurfacePiece(np.array([p[0] / rho, p[1] / rho, 0.0])))
        for sign in (1.0, -1.0):
            if abs(p[2] - sign * half) < tol:
                pieces.append(SurfacePiece(np.array([0.0, 0.0, sign])))
        if not pieces:  # off the surface numerically: nearest piece
            if r - rho < half - abs(p[2]) and rho > 0:
                pieces.append(SurfacePiece(np.array([p[0] / rho, p[1] / rho, 0.0])))
            else:
                pieces.append(SurfacePiece(np.array([0.0, 0.0, np.sign(p[2]) or 1.0])))
        return pieces
    faces = flat_faces(shape)
    if faces is None:
        raise ModelError(
            f"drakegrasp cannot compute surface normals of a {type(shape).__name__} "
            "geometry; use Box, Sphere, Cylinder, Capsule, Ellipsoid or Convex"
        )
    N, D = face_arrays(faces)[:2]
    gaps = N @ p - D
    on = np.flatnonzero(np.abs(gaps) < tol)
    if on.size == 0:
        on = np.array([int(np.argmax(gaps))])
    return [SurfacePiece(faces[i][0], faces[i][2]) for i in on]
