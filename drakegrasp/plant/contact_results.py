r"""Contacts read from a simulation's ``ContactResults`` instead of distances.

:func:`~drakegrasp.find_contacts` derives contacts from signed distances.  In a
running simulation the plant also reports the contacts its contact model used
(``MultibodyPlant.get_contact_results_output_port()``), and with hydroelastic
contact those are **contact surfaces**: the area over which two compliant
bodies press on each other.  :func:`contacts_from_results` turns them into the
same :class:`~drakegrasp.PlantContact` list that the analysis takes:

- **Hydroelastic surface** (object against a hand body): a patch, like a flat
  pad on a flat face (see :mod:`drakegrasp.plant.contacts`).  The surface's
  vertices are projected on the plane through its centroid normal to its
  area-weighted mean normal, and one contact is reported at each vertex of
  their convex hull (the patch polygon), all with that normal, oriented into the
  object; ``ψ = 0`` (the points lie on the contact surface, between the two
  bodies' undeformed shapes), ``normal_source = "hydroelastic"``.
- **Point pair** (point contact, or a pair that ``hydroelastic_with_fallback``
  computes as a point pair): one contact at the object's witness point, the
  normal into the object, ``ψ = −depth``, ``normal_source = "point pair"``.

Pairs between the object and bodies outside the hand (a table) are ignored.
"""

from __future__ import annotations

import numpy as np
from pydrake.geometry import ContactSurface, GeometryId, QueryObject
from pydrake.multibody.plant import ContactResults, MultibodyPlant
from pydrake.systems.framework import Context

from drakegrasp.core.calls import checked_call
from drakegrasp.core.validation import real_array, unit_vectors
from drakegrasp.errors import (
    InvalidContactError,
    InvalidOptionError,
    InvalidPoseError,
    NoContactsError,
)
from drakegrasp.plant._shapes import plane_basis
from drakegrasp.plant.contact_normals import clean_unit as _clean_unit
from drakegrasp.plant.contacts import (
    HandSpec,
    PlantContact,
    _scoped_name,
    resolve_object_body,
)
from drakegrasp.plant.validation import checked_query_object, hand_contact_bodies

__all__ = ["contacts_from_results", "patch_polygon"]

_HULL_TOL = 1e-9
"""Points closer than this (metres) count as one hull vertex."""


def patch_polygon(points: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Convex polygon of points projected on the plane normal to ``normal``.

    Parameters
    ----------
    points : (K, 3) float
        Points (metres, any frame).
    normal : (3,) float
        Normal of the plane, same frame (normalised here).

    Returns
    -------
    (V, 3) float
        Vertices of the convex hull of the projected points, counter-clockwise
        about ``normal``, on the plane through the points' mean.  Fewer than
        three vertices when the points are (nearly) collinear.

    Raises
    ------
    InvalidContactError
        Non-finite points, or a zero or non-finite normal (a zero-area contact
        surface has a NaN normal).
    """
    points = real_array("patch points", points, error=InvalidContactError)
    if points.size == 0 or points.size % 3 or not np.all(np.isfinite(points)):
        raise InvalidContactError(
            f"patch points must be a non-empty finite (K, 3) array, got shape "
            f"{points.shape}" + ("" if np.all(np.isfinite(points)) else " with NaN/inf")
        )
    points = points.reshape(-1, 3)
    # A zero-area hydroelastic surface reports a NaN normal: its plane is undefined.
    normal = unit_vectors("patch normal", normal, error=InvalidContactError)
    if normal.shape != (3,):
        raise InvalidContactError(f"patch normal must be a 3-vector, got {normal}")
    origin = points.mean(axis=0)
    u, w = plane_basis(normal)
    uv = np.column_stack([(points - origin) @ u, (points - origin) @ w])
    hull = _convex_hull_2d(uv)
    return origin + hull[:, :1] * u + hull[:, 1:] * w


def _convex_hull_2d(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise hull of 2-D points (Andrew's monotone chain)."""
    pts = sorted({(round(x / _HULL_TOL), round(y / _HULL_TOL)) for x, y in points})
    pts = [np.array(p, dtype=float) * _HULL_TOL for p in pts]
    if len(pts) <= 2:
        return np.array(pts).reshape(-1, 2)

    def half(seq):
        chain: list[np.ndarray] = []
        for p in seq:
            while len(chain) >= 2:
                a, b = chain[-2], chain[-1]
                if (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) > 0:
                    break
                chain.pop()
            chain.append(p)
        return chain[:-1]

    return np.array(half(pts) + half(pts[::-1]))


def _surface_points_and_normal(
    surface: ContactSurface,
) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (world) and area-weighted mean face normal (out of N, into M)."""
    mesh = surface.tri_mesh_W() if surface.is_triangle() else surface.poly_mesh_W()
    vertices = np.array([mesh.vertex(i) for i in range(mesh.num_vertices())])
    normal = sum(
        mesh.area(f) * np.asarray(mesh.face_normal(f)) for f in range(mesh.num_faces())
    )
    return vertices, np.asarray(normal, dtype=float)


@checked_call
def contacts_from_results(
    plant: MultibodyPlant,
    plant_context: Context,
    contact_results: ContactResults,
    query_object: QueryObject,
    *,
    object_body,
    hand: HandSpec = None,
) -> list[PlantContact]:
    """The hand–object contacts that a simulation step reported.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized, registered with a ``SceneGraph``.
    plant_context : Context
        A context of ``plant`` holding the configuration of the step (it gives
        the body poses that express the contacts in frame O).
    contact_results : pydrake.multibody.plant.ContactResults
        From the plant's contact-results output port.
    query_object : pydrake.geometry.QueryObject
        The scene graph's query object (its inspector names the geometries).
    object_body : RigidBody, BodyIndex or str
    hand : ModelInstanceIndex, str, iterable of RigidBody, or None
        As in :func:`drakegrasp.find_contacts`.

    Returns
    -------
    list of PlantContact
        Surfaces in the order of the results, a patch's vertices
        counter-clockwise about the normal; positions and normals in the object
        body frame O.

    Raises
    ------
    NoContactsError
        If no hand body touches the object in these results.
    InvalidPoseError
        If Drake cannot place the bodies at the context's state (a free
        body's quaternion of zeros).
    InvalidOptionError
        If ``contact_results`` or ``query_object`` has the wrong type, or the
        query object is not that of the plant's scene graph.
    ModelError
        If the plant is not registered with a SceneGraph.
    """
    if not isinstance(contact_results, ContactResults):
        raise InvalidOptionError(
            "contact_results must be pydrake ContactResults, got "
            f"{type(contact_results).__name__}"
        )
    if not isinstance(query_object, QueryObject):
        raise InvalidOptionError(
            "query_object must be a pydrake.geometry.QueryObject, got "
            f"{type(query_object).__name__}"
        )
    plant.ValidateContext(plant_context)
    body = resolve_object_body(plant, object_body)
    fingers = {b.index(): b for b in hand_contact_bodies(plant, body, hand)}
    try:  # every body's pose at once: a finite state can still be degenerate
        X_OW = plant.EvalBodyPoseInWorld(plant_context, body).inverse()
    except RuntimeError as e:
        raise InvalidPoseError(
            "Drake cannot compute the body poses of this plant context (a free "
            f"body's quaternion of zeros?): {' '.join(str(e).split())}"
        ) from None
    R_OW = X_OW.rotation().matrix()
    inspector = checked_query_object(plant, query_object)

    def body_of(gid: GeometryId):
        return plant.GetBodyFromFrameId(inspector.GetFrameId(gid))

    def contact(gid_obj, gid_fin, p_W, n_W, psi, source, vertex=None):
        finger = body_of(gid_fin)
        X_FW = plant.EvalBodyPoseInWorld(plant_context, finger).inverse()
        n_O = _clean_unit(R_OW @ n_W)
        p_OC = np.asarray(X_OW.multiply(p_W))
        return PlantContact(
            p_OC=p_OC,
            nhat_O=n_O,
            psi=psi,
            p_FC=np.asarray(X_FW.multiply(p_W - psi * n_W)),
            finger_body=_scoped_name(plant, finger),
            finger_body_index=finger.index(),
            object_geometry=gid_obj,
            finger_geometry=gid_fin,
            object_geometry_name=inspector.GetName(gid_obj),
            finger_geometry_name=inspector.GetName(gid_fin),
            normal_source=source,
            patch_vertex=vertex,
        )

    def pair(id_a, id_b):
        """(object id, finger id, sign turning an A-side normal inward) or None."""
        a, b = body_of(id_a), body_of(id_b)
        if a.index() == body.index() and b.index() in fingers:
            return id_a, id_b, 1.0
        if b.index() == body.index() and a.index() in fingers:
            return id_b, id_a, -1.0
        return None

    out: list[PlantContact] = []
    for i in range(contact_results.num_hydroelastic_contacts()):
        surface = contact_results.hydroelastic_contact_info(i).contact_surface()
        ids = pair(surface.id_M(), surface.id_N())
        if ids is None:
            continue
        go, gf, sign = ids
        points, normal = _surface_points_and_normal(surface)
        n_W = sign * normal / np.linalg.norm(normal)  # face normals point into M
        polygon = patch_polygon(points, n_W)
        if len(polygon) < 3:
            polygon = np.asarray(surface.centroid()).reshape(1, 3)
        single = len(polygon) == 1
        for k, p_W in enumerate(polygon):
            vertex = None if single else k
            out.append(contact(go, gf, p_W, n_W, 0.0, "hydroelastic", vertex))
    for i in range(contact_results.num_point_pair_contacts()):
        pp = contact_results.point_pair_contact_info(i).point_pair()
        ids = pair(pp.id_A, pp.id_B)
        if ids is None:
            continue
        go, gf, sign = ids
        n_W = sign * np.asarray(pp.nhat_BA_W)  # nhat_BA points into A
        p_W = np.asarray(pp.p_WCa if sign > 0 else pp.p_WCb)
        out.append(contact(go, gf, p_W, n_W, -float(pp.depth), "point pair"))
    if not out:
        raise NoContactsError(
            f"no hand body touches {_scoped_name(plant, body)!r} in the contact "
            f"results ({contact_results.num_hydroelastic_contacts()} hydroelastic "
            f"surfaces, {contact_results.num_point_pair_contacts()} point pairs)"
        )
    return out
