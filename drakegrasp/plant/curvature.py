r"""Curvatures of Drake's shapes at the contacts that ``find_contacts`` reports.

For each :class:`~drakegrasp.PlantContact` this module reads the principal
curvatures and directions of the object's and the finger's surface at the
contact point, in the object body frame O, for the second-order test of
:func:`drakegrasp.second_order_form_closure`.  The curvatures come from the
shapes themselves, never from finite differences of Drake's distances (GJK is
noisy at ~5e-7 m for ellipsoids).

* Sphere: ``1/R``.  Ellipsoid, cylinder side, capsule: the second fundamental
  form ``∇²F / |∇F|`` of the implicit surface ``F = 0`` (``F < 0`` inside).
* Box, convex mesh and half-space faces: 0.  An edge (two faces meet): 0 along
  it, ``inf`` across.  A corner: ``inf``.  A cylinder's rim: ``inf`` across,
  and along it the rim circle's curvature ``(1/r) m·ρ̂`` (``m`` the outward
  contact normal, ``ρ̂`` the radial direction).
* A vertex of a flat patch (two flat faces): the feature that makes the
  vertex — a corner of the finger's face on the object's face (finger ``inf``,
  object flat), a corner of the object's face on the finger's face, or an
  edge of each crossing (both sharp across their own edge).

Planar analyses use the normal curvature along the in-plane tangent.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from pydrake.geometry import (
    Box,
    Capsule,
    Convex,
    Cylinder,
    Ellipsoid,
    HalfSpace,
    Mesh,
    QueryObject,
    Shape,
    Sphere,
)
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context

from drakegrasp.core.calls import checked_call
from drakegrasp.core.curvature import ContactCurvature, SurfaceCurvature
from drakegrasp.errors import ModelError
from drakegrasp.plant._shapes import flat_faces, surface_pieces
from drakegrasp.plant.contacts import (
    PlantContact,
    check_plant_contacts,
    resolve_object_body,
)
from drakegrasp.plant.handles import local_geometry_id
from drakegrasp.plant.options import PLANES, check_plane
from drakegrasp.plant.validation import (
    checked_query_object,
    plant_context_of,
    query_object_of,
)

__all__ = [
    "EDGE_TILT_TOL",
    "SECOND_ORDER_RANK_TOL",
    "contact_curvatures",
    "shape_curvature",
]

SECOND_ORDER_RANK_TOL = 1e-4
"""Relative singular-value threshold of the second-order test on plant grasps.

Equilibrium (``G_n λ = 0`` with ``W ≠ {0}``) is a measure-zero condition, and
contacts read with GJK (ellipsoids, meshes) carry errors of ~1e-6 m in their
points and normals: six fingers at an ellipsoid's axis ends give singular
values of ``G_n`` of ~1e-6 relative where they are exactly 0.  The test treats
singular values below this fraction of the largest as zero.
"""

VERTEX_TOL = 1e-8
"""A patch vertex this close (m) to a face polygon's corner is that corner."""


EDGE_TILT_TOL = 0.05
"""How far (cosine) a sharp edge may lean out of the contact's tangent plane
and still be taken as lying in it.  An edge that touches a surface lies in its
tangent plane; in a simulated state the bodies interpenetrate by a fraction of
a millimetre and Drake's contact normal leans off it (by 3.5e-3 for an
Allegro fingertip seated on the YCB soup can), and the second-order analysis
said "not decided".  Within this tolerance the edge is projected on the
tangent plane; beyond it (an edge that crosses the surface) it is left as it
is, and the analysis refuses it."""


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _edge(direction_O: np.ndarray, n_O: np.ndarray, curvature: float = 0.0):
    """A sharp edge along ``direction_O``, in the tangent plane of ``n_O``.

    See :data:`EDGE_TILT_TOL`.
    """
    d = _unit(np.asarray(direction_O, dtype=float))
    n = _unit(np.asarray(n_O, dtype=float))
    lean = float(d @ n)
    if abs(lean) <= EDGE_TILT_TOL:
        d = _unit(d - lean * n)
    return SurfaceCurvature.edge(d, curvature)


def _implicit(form_G: np.ndarray, grad_G: np.ndarray, R_OG, n_O) -> SurfaceCurvature:
    form_O = R_OG @ (form_G / np.linalg.norm(grad_G)) @ R_OG.T
    return SurfaceCurvature.from_shape_form(form_O, n_O)


def _sharp(normals_G: list[np.ndarray], R_OG: np.ndarray, n_O) -> SurfaceCurvature:
    """Where several flat faces meet: an edge (two) or a corner (three)."""
    if len(normals_G) == 2:
        edge = np.cross(normals_G[0], normals_G[1])
        if np.linalg.norm(edge) > 1e-9:
            return _edge(R_OG @ _unit(edge), n_O)
    return SurfaceCurvature.point()


def shape_curvature(
    shape: Shape, p_GC: np.ndarray, R_OG: np.ndarray, n_O: np.ndarray
) -> SurfaceCurvature:
    """Principal curvatures of ``shape`` at its surface point ``C``.

    Parameters
    ----------
    shape : pydrake.geometry.Shape
        Sphere, Ellipsoid, Cylinder, Capsule, Box, HalfSpace, Convex or Mesh
        (as its convex hull).
    p_GC : (3,) float
        The point, metres, in the shape's geometry frame G.
    R_OG : (3, 3) float
        Orientation of G in the frame O the result is expressed in.
    n_O : (3,) float
        The contact normal in O (either sign); directions are returned in its
        tangent plane.

    Returns
    -------
    SurfaceCurvature
        Spatial; convex positive; ``inf`` across sharp features.

    Raises
    ------
    ModelError
        For a shape type without a curvature model.
    """
    p = np.asarray(p_GC, dtype=float)
    if isinstance(shape, Sphere):
        return SurfaceCurvature.convex(shape.radius())
    if isinstance(shape, Ellipsoid):
        inv = 1.0 / np.array([shape.a(), shape.b(), shape.c()]) ** 2
        return _implicit(np.diag(2 * inv), 2 * inv * p, R_OG, n_O)
    if isinstance(shape, HalfSpace):
        return SurfaceCurvature.flat()
    if isinstance(shape, Capsule):
        r, half = shape.radius(), 0.5 * shape.length()
        if abs(p[2]) > half:
            return SurfaceCurvature.convex(r)
        return _implicit(np.diag([2.0, 2.0, 0.0]), 2 * p * [1, 1, 0], R_OG, n_O)
    pieces = surface_pieces(shape, p)
    if isinstance(shape, Cylinder):
        r = shape.radius()
        side = [q for q in pieces if abs(q.normal_G[2]) < 0.5]
        if len(pieces) == 1 and side:
            return _implicit(np.diag([2.0, 2.0, 0.0]), 2 * p * [1, 1, 0], R_OG, n_O)
        if len(pieces) == 1:
            return SurfaceCurvature.flat()
        rho = _unit(p * [1, 1, 0])
        along = np.array([-rho[1], rho[0], 0.0])
        m_G = R_OG.T @ np.asarray(n_O)  # the contact normal, in G
        kappa = abs(m_G @ rho) / r  # the rim circle's curvature along m
        return _edge(R_OG @ along, n_O, kappa)
    if isinstance(shape, (Box, Convex, Mesh)):
        if len(pieces) == 1:
            return SurfaceCurvature.flat()
        return _sharp([q.normal_G for q in pieces], R_OG, n_O)
    raise ModelError(
        f"drakegrasp has no curvature model for a {type(shape).__name__}; use "
        "Sphere, Ellipsoid, Cylinder, Capsule, Box, HalfSpace or Convex"
    )


def _face_polygon(shape: Shape, m_G: np.ndarray) -> np.ndarray | None:
    """Polygon (k, 3) of the flat face whose outward normal is ``m_G``."""
    faces = flat_faces(shape)
    if not faces:
        return None
    n, _, poly = max(faces, key=lambda f: f[0] @ m_G)
    return poly if n @ m_G > 1 - 1e-6 else None


def _patch_feature(poly: np.ndarray, p: np.ndarray, R_OG: np.ndarray):
    """``"corner"``, an edge direction in O, or None (inside the face)."""
    if np.min(np.linalg.norm(poly - p, axis=1)) < VERTEX_TOL:
        return "corner"
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        e = b - a
        s = np.clip((p - a) @ e / (e @ e), 0.0, 1.0)
        if np.linalg.norm(a + s * e - p) < 1e-7:
            return R_OG @ _unit(e)
    return None


def _patch_curvatures(shape_o, p_o, R_OGo, shape_f, p_f, R_OGf, n_O):
    """Curvatures at a vertex of a flat-on-flat patch (see module docstring)."""
    poly_o = _face_polygon(shape_o, R_OGo.T @ -n_O)
    poly_f = _face_polygon(shape_f, R_OGf.T @ n_O)
    if poly_o is None or poly_f is None:
        raise ModelError("a patch contact whose faces cannot be found")
    feat_o = _patch_feature(poly_o, p_o, R_OGo)
    feat_f = _patch_feature(poly_f, p_f, R_OGf)
    flat = SurfaceCurvature.flat()
    if isinstance(feat_f, str) and not isinstance(feat_o, str):
        return ContactCurvature(flat, SurfaceCurvature.point())
    if isinstance(feat_o, str) and not isinstance(feat_f, str):
        return ContactCurvature(SurfaceCurvature.point(), flat)
    if isinstance(feat_o, np.ndarray) and isinstance(feat_f, np.ndarray):
        return ContactCurvature(_edge(feat_o, n_O), _edge(feat_f, n_O))
    # Corner on corner (or a vertex inside both faces): the core rejects it.
    return ContactCurvature(SurfaceCurvature.point(), SurfaceCurvature.point())


def _in_plane(k: SurfaceCurvature, n_O: np.ndarray, axes) -> SurfaceCurvature:
    """Normal curvature along the in-plane tangent of a planar analysis."""
    n2 = n_O[list(axes)]
    t = np.zeros(3)
    t[axes[0]], t[axes[1]] = -n2[1], n2[0]
    t /= np.linalg.norm(t)
    d1 = t if k.direction is None else np.asarray(k.direction)
    d2 = np.cross(n_O, d1)
    total = 0.0
    for kappa, d in zip(k.curvatures, (d1, d2), strict=True):
        w = float(t @ d) ** 2
        if math.isinf(kappa):
            if w > 1e-12:
                return SurfaceCurvature.point(planar=True)
        else:
            total += kappa * w
    return SurfaceCurvature((total,))


@checked_call
def contact_curvatures(
    plant: MultibodyPlant,
    plant_context: Context,
    contacts: Sequence[PlantContact],
    *,
    object_body,
    plane: str | None = None,
    query_object: QueryObject | None = None,
) -> tuple[ContactCurvature, ...]:
    """Curvatures of object and finger at each contact, in the object frame O.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized, with a ``SceneGraph``.
    plant_context : Context
        The configuration in which ``contacts`` were found.
    contacts : sequence of PlantContact
        From :func:`~drakegrasp.find_contacts` (or ``grasp_from_plant``).
    object_body : RigidBody, BodyIndex or str
        The object; O is its body frame.
    plane : {"xy", "yz", "zx"}, optional
        For a planar analysis: one curvature per surface, in that plane.
    query_object : pydrake.geometry.QueryObject, optional
        Read geometry poses from this query object instead of the plant's query
        input port (a System's private plant context).

    Returns
    -------
    tuple of ContactCurvature
        In contact order, ready for :func:`~drakegrasp.second_order_form_closure`.

    Raises
    ------
    ModelError
        For a shape without a curvature model, or a contact of another plant
        or object (:func:`~drakegrasp.plant.contacts.check_plant_contacts`).
    InvalidContactError
        A contact unpickled in another process than the one that found it
        (its geometries are :class:`~drakegrasp.plant.handles.ForeignGeometryId`),
        or an item of ``contacts`` that is not a ``PlantContact``.
    InvalidOptionError
        An unknown ``plane``, or a ``query_object`` that is not a
        ``QueryObject`` of the plant's scene graph.
    """
    plant_context = plant_context_of(plant, plant_context)
    body = resolve_object_body(plant, object_body)
    contacts = check_plant_contacts(plant, contacts, body)
    plane = check_plane(plane)
    query = query_object
    if query is None:
        query = query_object_of(plant, plant_context)
        inspector = query.inspector()
    else:
        inspector = checked_query_object(plant, query)
    X_OW = plant.EvalBodyPoseInWorld(plant_context, body).inverse()
    out = []
    for k, pc in enumerate(contacts):
        go = local_geometry_id(pc.object_geometry, f"contact {k}'s object_geometry")
        gf = local_geometry_id(pc.finger_geometry, f"contact {k}'s finger_geometry")
        n_O = np.asarray(pc.nhat_O)
        X_OGo = X_OW.multiply(query.GetPoseInWorld(go))
        X_OGf = X_OW.multiply(query.GetPoseInWorld(gf))
        R_OGo, R_OGf = X_OGo.rotation().matrix(), X_OGf.rotation().matrix()
        p_Go = np.asarray(X_OGo.inverse().multiply(pc.p_OC))
        p_Gf = np.asarray(X_OGf.inverse().multiply(pc.p_OC - pc.psi * n_O))
        shape_o = inspector.GetShape(go)
        shape_f = inspector.GetShape(gf)
        if pc.normal_source == "patch":
            cc = _patch_curvatures(shape_o, p_Go, R_OGo, shape_f, p_Gf, R_OGf, n_O)
        else:
            cc = ContactCurvature(
                shape_curvature(shape_o, p_Go, R_OGo, n_O),
                shape_curvature(shape_f, p_Gf, R_OGf, n_O),
            )
        if plane is not None:
            axes = PLANES[plane]
            cc = ContactCurvature(
                _in_plane(cc.object, n_O, axes), _in_plane(cc.finger, n_O, axes)
            )
        out.append(cc)
    return tuple(out)
