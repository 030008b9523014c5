r"""Contacts between a hand and an object, read from a ``MultibodyPlant``.

For every pair (object collision geometry, hand collision geometry) the plant's
scene-graph query port gives the signed distance ``ψ`` and the witness points
``Ca`` (on the object) and ``Cb`` (on the finger), with
``p_Ca − p_Cb = ψ n̂`` and ``n̂`` pointing from the finger into the object.  A
pair is a contact when ``|ψ| <= distance_tolerance``.

The query loop lives here; the points of one touching pair in
:mod:`drakegrasp.plant.contact_pair`, which draws on the exact contact of
:mod:`drakegrasp.plant.exact_contact` (on the point queries of
:mod:`drakegrasp.plant.shape_queries`), the name of the normal's source and the
fallback choice in :mod:`drakegrasp.plant.contact_normals`, and the corners of
a flat pad's patch in :mod:`drakegrasp.plant.contact_patches`.

**Exact contacts.**  Drake decides which pairs touch (its ``ψ`` within the
tolerance, the rule :func:`~drakegrasp.plant.closing.close_hand` closes to),
but its GJK/EPA witness points on curved shapes and convex hulls can be
0.1–0.4 mm off, and a normal taken there a degree or more off.  Each touching
pair is therefore recomputed from Drake's witness by an exact, certified route
(:mod:`drakegrasp.plant.exact_contact`): the reported ``p_OC``, ``nhat_O``, ``ψ``
and ``p_FC`` are exact to round-off (``PlantContact.exact``), and
``PlantContact.normal_source`` names the surface the normal belongs to.  Only
a pair that no route certifies keeps Drake's witness points, with the normal
chosen as :mod:`~drakegrasp.plant.contact_normals` describes.  The guide's
*Contacts* page lists the accuracy of every shape pair.

**Many configurations at once.**  :func:`contacts_of_distances` is three
steps, which a planner runs apart: :func:`stage_contacts` reads the touching
pairs of one configuration from Drake, :func:`resolve_staged` computes the
points of any number of staged configurations in one batch (a spherical
finger tip on a box, cylinder, sphere or convex hull over arrays,
:mod:`~drakegrasp.plant.sphere_tips`; every other pair by
:func:`~drakegrasp.plant.contact_pair.pair_points` as it is read), and
:func:`staged_contacts` gives each configuration's contacts.

**Flat patches.**  A flat pad on a flat face is reported as one contact at
**each vertex** of its patch polygon (same normal; ``ψ`` the gap at the
vertex), see :mod:`~drakegrasp.plant.contact_patches`.  A square pad on a box
face thus gives four contacts, and a flat face along a cylinder's or
capsule's side two, the ends of its line of contact.  ``patches="witness"``
turns patch handling off.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, fields, replace

import numpy as np
from pydrake.geometry import GeometryId, QueryObject
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import (
    BodyIndex,
    RigidBody,
    default_model_instance,
    world_model_instance,
)
from pydrake.systems.framework import Context

from drakegrasp.core.calls import checked_call
from drakegrasp.core.tolerances import DEFAULT_DISTANCE_TOLERANCE
from drakegrasp.core.validation import (
    check_distance_tolerance,
    check_flag,
    describe,
    integer_or_none,
    items_of,
    plain_str,
)
from drakegrasp.errors import (
    InvalidContactError,
    InvalidOptionError,
    ModelError,
)
from drakegrasp.plant.contact_pair import (
    StagedContacts,
    dedupe_contacts,
    pending_pair,
    resolve_pairs,
)
from drakegrasp.plant.contact_patches import PATCH_ANGLE_TOL
from drakegrasp.plant.handles import ForeignGeometryId, pickled_handle
from drakegrasp.plant.mesh_convexity import warn_if_not_convex
from drakegrasp.plant.validation import (
    HandSpec,
    _per_plant,
    checked_query_object,
    hand_bodies,
    hand_contact_bodies,
    plant_context_of,
    query_object_of,
    resolve_object_body,
    scoped_name,
)

__all__ = [
    "DEFAULT_DISTANCE_TOLERANCE",
    "PATCH_ANGLE_TOL",
    "PlantContact",
    "StagedContacts",
    "check_plant_contacts",
    "contacts_of_distances",
    "find_contacts",
    "hand_bodies",
    "resolve_object_body",
    "resolve_staged",
    "stage_contacts",
    "staged_contacts",
]


_scoped_name = scoped_name  # the name other modules of the plant layer import


@checked_call
@dataclass(frozen=True, eq=False)
class PlantContact:
    """One contact between a finger geometry and the object.

    Attributes
    ----------
    p_OC : (3,) float
        Contact point on the object's surface, metres, in the object body frame O.
    nhat_O : (3,) float
        Unit contact normal pointing into the object, in frame O.
    psi : float
        Signed distance ``ψ`` (metres): > 0 separated, < 0 penetrating.
    p_FC : (3,) float
        The finger's witness point in the finger body's frame F: the material
        point of the finger that touches the object (``centre + r nhat`` for a
        spherical tip; ``p_OC − ψ nhat`` at a patch vertex).  When ``exact``,
        ``p_OC − p_FC`` (in a common frame) equals ``ψ nhat``; otherwise it is
        Drake's witness point, which need not lie on the normal.
    finger_body : str
        Scoped name ``model::body`` of the finger body.
    finger_body_index : BodyIndex
    object_geometry, finger_geometry : GeometryId
        The geometry pair (a
        :class:`~drakegrasp.plant.handles.ForeignGeometryId` in a process the
        contact was pickled to: see the notes).
    object_geometry_name, finger_geometry_name : str
        Their names in the scene graph.
    normal_source : str
        Which surface the normal belongs to: ``"object"``, ``"finger"`` (a
        finger's face on an edge or corner of the object), ``"patch"`` (a
        corner of a flat patch), ``"line"`` (an end of the line along which a
        flat face touches a cylinder's or capsule's side; the object's
        normal), ``"edge"`` or ``"corner"`` (a curved finger on an edge or
        corner of the object, a cylinder's rim included), and, for a contact
        that is not
        ``exact``, ``"witness points"`` or ``"drake"`` (see
        :mod:`~drakegrasp.plant.contact_normals`).
    patch_vertex : int or None
        Index of this contact among the vertices of a flat patch or the two
        ends of a line, or None for a point contact.
    exact : bool
        True when the point, normal and ``ψ`` were computed exactly (to
        round-off) and certified (:mod:`drakegrasp.plant.exact_contact`; the
        accuracy of each shape pair is listed in the guide's *Contacts* page);
        False when they come from Drake's witness points.
    finger_geometry_index, object_geometry_index : int or None
        Place of each geometry among its body's collision geometries (None
        when not known, e.g. contacts read from contact results); they make
        the labels ``finger_geometry_label``/``object_geometry_label`` unique.

    Notes
    -----
    A contact pickles (and so crosses to another process) with its handles
    as numbers: ``finger_body_index`` comes back as the same ``BodyIndex``;
    ``object_geometry`` and ``finger_geometry`` as the same ``GeometryId`` in
    the process that found the contact, and in any other as a
    :class:`~drakegrasp.plant.handles.ForeignGeometryId`, since a
    ``GeometryId`` names a geometry only in the process that made it (see
    :mod:`drakegrasp.plant.handles`).
    """

    p_OC: np.ndarray
    nhat_O: np.ndarray
    psi: float
    p_FC: np.ndarray
    finger_body: str
    finger_body_index: BodyIndex
    object_geometry: GeometryId
    finger_geometry: GeometryId
    object_geometry_name: str
    finger_geometry_name: str
    normal_source: str
    patch_vertex: int | None = None
    finger_geometry_index: int | None = None
    object_geometry_index: int | None = None
    exact: bool = False

    @property
    def finger_geometry_label(self) -> str:
        """``model::body/geometry#k``: unique, though URDF collision names repeat.

        ``k`` is the geometry's place among its body's collision geometries
        (``plant.GetCollisionGeometriesForBody``), which, unlike a
        ``GeometryId``, is the same in every process.
        """
        return _label(
            self.finger_body, self.finger_geometry_name, self.finger_geometry_index
        )

    @property
    def object_geometry_label(self) -> str:
        """``geometry#k`` of the object's geometry (see ``finger_geometry_label``)."""
        return _label("", self.object_geometry_name, self.object_geometry_index)

    def __reduce__(self):
        values = {f.name: pickled_handle(getattr(self, f.name)) for f in fields(self)}
        return (_unpickled_contact, (type(self), values))

    def __copy__(self) -> PlantContact:
        # copy.copy takes __reduce__ but, unlike pickle and deepcopy, does not
        # rebuild its arguments: the handles' stand-ins would stay
        return replace(self)

    def to_dict(self) -> dict:
        """JSON-ready dictionary.

        ``finger_geometry_label`` and ``object_geometry_label`` name each
        geometry uniquely and the same in every process (body and the
        geometry's index in its body); the ``*_geometry`` names are the scene
        graph's, which can repeat across bodies.
        """
        return {
            "p_OC": self.p_OC.tolist(),
            "nhat_O": self.nhat_O.tolist(),
            "psi": self.psi,
            "p_FC": self.p_FC.tolist(),
            "finger_body": self.finger_body,
            "object_geometry": self.object_geometry_name,
            "finger_geometry": self.finger_geometry_name,
            "object_geometry_label": self.object_geometry_label,
            "finger_geometry_label": self.finger_geometry_label,
            "normal_source": self.normal_source,
            "patch_vertex": self.patch_vertex,
            "exact": self.exact,
        }

    def __repr__(self) -> str:
        patch = (
            "" if self.patch_vertex is None else f", patch vertex {self.patch_vertex}"
        )
        return (
            f"PlantContact({self.finger_body}: p_OC={np.round(self.p_OC, 6).tolist()}, "
            f"nhat_O={np.round(self.nhat_O, 6).tolist()}, psi={self.psi:.3g}{patch})"
        )


def _unpickled_contact(cls: type, values: dict) -> PlantContact:
    """A pickled :class:`PlantContact` (its handles already unpickled)."""
    return cls(**values)


def check_plant_contacts(
    plant: MultibodyPlant, contacts, object_body: RigidBody, *, reads_geometry=True
) -> list[PlantContact]:
    """``contacts`` as a list, once each is a :class:`PlantContact` of this plant.

    A contact belongs to ``plant`` and ``object_body`` when

    - its ``finger_body_index`` is a body of the plant whose scoped name is its
      ``finger_body`` (an index alone names some body in many plants);
    - each of its two geometry ids is a collision geometry of the plant,
      the finger's on that finger body and the object's on ``object_body``.
      Drake draws every ``GeometryId`` of a process from one counter, so an id
      registered with this plant was found in it, and one that is not was
      found in another plant (the same scene loaded twice has other ids).
      An id pickled in another process
      (:class:`~drakegrasp.plant.handles.ForeignGeometryId`) says nothing
      here: the body's name and index are checked, and the functions that
      read the geometry refuse it (:func:`~drakegrasp.plant.handles.local_geometry_id`).

    Each geometry's name must be scoped by its body's model instance
    (Drake names a plant's geometries ``model::name``, but for the default
    and world instances, whose names it leaves bare).  A caller that reads
    only the bodies and points (the Jacobians: ``reads_geometry=False``)
    takes a contact whose geometry ids this plant does not hold once its
    finger body and those names check out: a candidate's contacts
    applied to the same scene loaded again (the ids differ, the bodies and
    points do not).  A geometry id this plant holds on another body is
    refused either way.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized.
    contacts : sequence of PlantContact
    object_body : RigidBody
        The object, a body of ``plant`` (resolved by the caller).
    reads_geometry : bool, optional
        Whether the caller reads the contacts' geometries (default True).

    Returns
    -------
    list of PlantContact

    Raises
    ------
    InvalidContactError
        ``contacts`` is not a sequence, or holds what is not a
        ``PlantContact`` (the message names its place).
    ModelError
        A contact of another plant or of another object (the message names
        the contact, and its body or geometry).
    """
    if isinstance(contacts, str | bytes | dict) or not isinstance(contacts, Iterable):
        raise InvalidContactError(
            "contacts must be a sequence of PlantContact (from find_contacts), "
            f"got {describe(contacts)}"
        )
    contacts = items_of(
        "contacts",
        contacts,
        "a sequence of PlantContact (from find_contacts)",
        error=InvalidContactError,
    )
    owners = _collision_owners(plant)
    for k, c in enumerate(contacts):
        if not isinstance(c, PlantContact):
            raise InvalidContactError(
                f"contacts[{k}] must be a PlantContact (from find_contacts), got "
                f"{type(c).__name__} {describe(c)}"
            )
        finger = _finger_of(plant, c, k)
        for what, body in (("finger", finger), ("object", object_body)):
            gid = getattr(c, f"{what}_geometry")
            name = getattr(c, f"{what}_geometry_name")
            instance = body.model_instance()
            model = plant.GetModelInstanceName(instance)
            scoped = instance not in (default_model_instance(), world_model_instance())
            if scoped and not str(name).startswith(f"{model}::"):  # Drake's names
                raise ModelError(
                    f"contacts[{k}]'s {what} geometry {name!r} is not of model "
                    f"{model!r}, the {what} {scoped_name(plant, body)}'s: the "
                    f"contact is not one of this {what}"
                )
            if isinstance(gid, ForeignGeometryId):
                continue
            value = gid.get_value() if isinstance(gid, GeometryId) else None
            owner = owners.get(value)
            if owner is None and not reads_geometry:
                continue  # the same scene loaded again: its bodies are checked
            if owner is None:
                raise ModelError(
                    f"contacts[{k}]'s {what} geometry {name!r} ({describe(gid)}) "
                    "is not a collision geometry of this plant: the contact was "
                    "found in another plant; find the contacts in this one"
                )
            if owner != int(body.index()):
                raise ModelError(
                    f"contacts[{k}]'s {what} geometry {name!r} belongs to "
                    f"{scoped_name(plant, plant.get_body(BodyIndex(owner)))}, not "
                    f"to the {what} {scoped_name(plant, body)}: the contact is "
                    f"not one of this {what}"
                )
    return contacts


def _finger_of(plant: MultibodyPlant, c: PlantContact, k: int) -> RigidBody:
    """The finger body contact ``k`` names, once its index and name agree."""
    n = plant.num_bodies()
    i = integer_or_none(c.finger_body_index)
    if i is None or not 0 <= i < n:
        raise ModelError(
            f"contacts[{k}] names finger body {c.finger_body!r} at "
            f"{describe(c.finger_body_index)}, which is no body of this plant "
            f"(its bodies are 0..{n - 1}): the contact was found in another "
            "plant; find the contacts in this one"
        )
    body = plant.get_body(BodyIndex(i))
    if scoped_name(plant, body) != c.finger_body:
        raise ModelError(
            f"contacts[{k}] names finger body {c.finger_body!r} at BodyIndex({i}),"
            f" which is {scoped_name(plant, body)!r} in this plant: the contact "
            "was found in another plant; find the contacts in this one"
        )
    return body


def _collision_owners(plant: MultibodyPlant) -> dict[int, int]:
    """Per collision geometry of the plant (its id's number): its body's index."""

    def compute():
        return {
            g.get_value(): b
            for b in range(plant.num_bodies())
            for g in plant.GetCollisionGeometriesForBody(plant.get_body(BodyIndex(b)))
        }

    return _per_plant(plant, ("collision owners",), compute)


def _label(body: str, name: str, index: int | None) -> str:
    short = name.rpartition("::")[2]
    where = f"{body}/{short}" if body else name
    return where if index is None else f"{where}#{index}"


@checked_call
def find_contacts(
    plant: MultibodyPlant,
    plant_context: Context,
    object_body,
    *,
    hand: HandSpec = None,
    distance_tolerance: float = DEFAULT_DISTANCE_TOLERANCE,
    allow_penetration: bool = False,
    patches: str = "vertices",
    query_object: QueryObject | None = None,
) -> list[PlantContact]:
    """Contacts between the hand and the object in the plant's configuration.

    Parameters
    ----------
    plant : MultibodyPlant
        A finalized plant registered with a ``SceneGraph``.
    plant_context : Context
        The plant's context, or the root context of the diagram holding the
        plant (see :func:`~drakegrasp.plant.validation.plant_context_of`).
    object_body : RigidBody, BodyIndex or str
        The grasped object (a ``"model::body"`` name is accepted); positional
        or keyword, like every option-free argument of the plant layer.
    hand : ModelInstanceIndex, str, iterable of RigidBody, or None, optional
        See :func:`~drakegrasp.plant.validation.hand_contact_bodies`: every
        body of the hand touches, a palm welded to the world included.
    distance_tolerance : float, optional
        A pair is a contact when ``|ψ| <= distance_tolerance`` (metres, default
        1e-4, at most
        :data:`~drakegrasp.core.tolerances.MAX_DISTANCE_TOLERANCE`, 0.01).
    allow_penetration : bool, optional
        If False (default), a pair with ``ψ < -distance_tolerance`` raises
        :class:`~drakegrasp.PenetrationError`; if True it is reported as a contact.
    patches : {"vertices", "witness"}, optional
        How a flat-on-flat patch is reported: one contact per patch vertex
        (default) or Drake's single witness point.
    query_object : pydrake.geometry.QueryObject, optional
        The scene-graph query object to read distances and geometry poses
        from.  Default: evaluate the plant's geometry query input port in
        ``plant_context``.  Pass one when ``plant_context`` is not connected to
        a scene graph (e.g. a private context inside a Drake ``System`` such as
        :class:`drakegrasp.GraspMonitor`, fed by a query-object input port); a
        query whose bodies stand elsewhere than ``plant_context`` puts them is
        refused.

    Returns
    -------
    list of PlantContact
        Ordered by finger body index, then by geometry registration order, then
        by patch vertex.  Positions and normals are in the object body frame.

    Raises
    ------
    NoContactsError
        If no pair is within the tolerance; names the object, the closest
        finger geometry and its distance.
    PenetrationError
        If a pair penetrates deeper than the tolerance (unless allowed); names
        the pair and its depth.
    ModelError
        If the plant has no scene graph, or a geometry's shape is unsupported.
    InvalidOptionError
        An option out of range, or a ``query_object`` that is not a query of
        the plant's scene graph at ``plant_context``'s state
        (:func:`~drakegrasp.plant.validation.checked_query_object`).
    """
    plant_context = plant_context_of(plant, plant_context)
    tol = check_distance_tolerance(distance_tolerance)
    allow_penetration = check_flag("allow_penetration", allow_penetration)
    patches = plain_str(patches)
    if type(patches) is not str or patches not in ("vertices", "witness"):
        raise InvalidOptionError(
            f"patches must be 'vertices' or 'witness', got {describe(patches)}"
        )
    body = resolve_object_body(plant, object_body)
    fingers = hand_contact_bodies(plant, body, hand)
    if not plant.geometry_source_is_registered():
        raise ModelError("the plant is not registered with a SceneGraph; no geometry")
    if query_object is None:
        query = query_object_of(plant, plant_context)
        inspector = query.inspector()
    else:
        query = query_object
        inspector = checked_query_object(plant, query, plant_context, [body, *fingers])
    object_geometries = plant.GetCollisionGeometriesForBody(body)
    object_name = _scoped_name(plant, body)
    if not object_geometries:
        raise ModelError(f"the object body {object_name!r} has no collision geometry")
    results = []
    for finger in fingers:
        for kf, gf in enumerate(plant.GetCollisionGeometriesForBody(finger)):
            for ko, go in enumerate(object_geometries):
                if inspector.CollisionFiltered(go, gf):
                    continue
                try:
                    r = query.ComputeSignedDistancePairClosestPoints(go, gf)
                except RuntimeError as e:
                    shapes = [type(inspector.GetShape(g)).__name__ for g in (go, gf)]
                    raise ModelError(
                        "Drake cannot compute the signed distance between "
                        f"{inspector.GetName(go)!r} ({shapes[0]}) and "
                        f"{inspector.GetName(gf)!r} ({shapes[1]}): {e}"
                    ) from None
                results.append((finger, kf, ko, r))
    return contacts_of_distances(
        plant,
        plant_context,
        body,
        query,
        results,
        distance_tolerance=tol,
        allow_penetration=allow_penetration,
        patches=patches,
    )


def contacts_of_distances(
    plant: MultibodyPlant,
    plant_context: Context,
    body,
    query: QueryObject,
    results,
    *,
    distance_tolerance: float,
    allow_penetration: bool = False,
    patches: str = "vertices",
) -> list[PlantContact]:
    """The contacts of :func:`find_contacts` from signed distances already computed.

    :func:`find_contacts` computes one ``SignedDistancePair`` per (hand
    geometry, object geometry) pair and reads them here; a caller that already
    holds them (a planner's ``ComputeSignedDistancePairwiseClosestPoints``
    with ``max_distance >= distance_tolerance``, whose pairs are bitwise those
    of the pair query) passes them instead of querying again.  Pairs farther
    than the tolerance may be left out; they only name the closest geometry in
    :class:`~drakegrasp.NoContactsError`.

    Parameters
    ----------
    plant, plant_context : MultibodyPlant, Context
        As in :func:`find_contacts` (the plant's own context).
    body : RigidBody
        The object.
    query : QueryObject
        The query object the distances were computed with (geometry poses).
    results : iterable of (RigidBody, int, int, SignedDistancePair)
        ``(hand body, k_f, k_o, pair)``: the body holding the hand geometry,
        its geometry's and the object geometry's place among their bodies'
        collision geometries, and Drake's pair (either order of ids), in the
        order of :func:`find_contacts` (hand body index, ``k_f``, ``k_o``).
    distance_tolerance : float, metres
    allow_penetration : bool, optional
    patches : {"vertices", "witness"}, optional

    Returns
    -------
    list of PlantContact
        As :func:`find_contacts` returns.

    Raises
    ------
    NoContactsError, PenetrationError
        As :func:`find_contacts`.
    """
    staged = stage_contacts(
        plant,
        plant_context,
        body,
        query,
        results,
        distance_tolerance=distance_tolerance,
        allow_penetration=allow_penetration,
        patches=patches,
    )
    resolve_staged([staged])
    return staged_contacts(staged)


def staged_contacts(staged: StagedContacts) -> list[PlantContact]:
    """The contacts of resolved staged pairs, as :func:`find_contacts` returns them.

    ``staged`` is a :class:`~drakegrasp.plant.contact_pair.StagedContacts`
    that :func:`resolve_staged` resolved.

    Raises
    ------
    NoContactsError, PenetrationError
        As :func:`find_contacts`.
    """
    return dedupe_contacts(
        [
            PlantContact(
                p_OC=pp.p_OC,
                nhat_O=pp.nhat_O,
                psi=pp.psi,
                p_FC=np.asarray(X_FO.multiply(pp.p_OF)),
                normal_source=pp.normal_source,
                patch_vertex=pp.patch_vertex,
                exact=pp.exact,
                **common,
            )
            for pp, X_FO, common in staged.rows()
        ]
    )


def resolve_staged(staged) -> None:
    """Compute the contact points of every staged configuration, in one batch."""
    resolve_pairs([p for s in staged for p in s.pending()])


def stage_contacts(
    plant: MultibodyPlant,
    plant_context: Context,
    body,
    query: QueryObject,
    results,
    *,
    distance_tolerance: float,
    allow_penetration: bool = False,
    patches: str = "vertices",
    cache: dict | None = None,
) -> StagedContacts:
    """Read the touching pairs of :func:`contacts_of_distances` from Drake now.

    The arguments are those of :func:`contacts_of_distances`; the query and
    the context may change once this returns: :func:`resolve_staged` and
    :func:`staged_contacts` finish the work.  ``cache`` is a dict the caller
    keeps across calls on one plant and scene graph (names and shapes are
    then read once).  A touching object geometry that is a non-convex
    ``Mesh`` is warned of
    (:class:`~drakegrasp.plant.mesh_convexity.NonConvexMeshWarning`: Drake's
    distances are to its hull), once per mesh file in a process.
    """
    tol = distance_tolerance
    cache = {} if cache is None else cache
    inspector = query.inspector()
    key = ("object", int(body.index()))
    if key not in cache:
        cache[key] = (
            _scoped_name(plant, body),
            set(plant.GetCollisionGeometriesForBody(body)),
        )
    object_name, object_geometries = cache[key]
    X_WO = RigidTransform(plant.EvalBodyPoseInWorld(plant_context, body))  # a copy
    X_OW = X_WO.inverse()
    frame = {"X_OW": X_OW, "R_OW": X_OW.rotation().matrix()}  # this call's
    items: list[tuple] = []
    closest: tuple[float, str] | None = None

    def name(gid):  # one look-up when cached (hashing an id calls into Drake)
        found = cache.get(("name", gid))
        if found is None:
            found = cache["name", gid] = inspector.GetName(gid)
        return found

    fingers = {}
    for finger, kf, ko, r in results:
        index = finger.index()
        finger_name = cache.get(("body", index))
        if finger_name is None:
            finger_name = cache["body", index] = _scoped_name(plant, finger)
        id_A = r.id_A
        swapped = id_A not in object_geometries  # the normal points into the finger
        go, gf = (r.id_B, id_A) if swapped else (id_A, r.id_B)
        psi = float(r.distance)
        if closest is None or psi < closest[0]:
            closest = (psi, finger_name, gf)
        if psi < -tol and not allow_penetration:
            items.append(
                (
                    "penetration",
                    f"{object_name} ({name(go)}) and {finger_name} ({name(gf)}) "
                    f"penetrate by {-psi * 1e3:.4g} mm",
                )
            )
            continue
        if abs(psi) > tol and not (allow_penetration and psi < 0):
            continue
        if ("hull", go) not in cache:  # measured once per geometry and cache
            cache["hull", go] = True
            warn_if_not_convex(inspector.GetShape(go), name(go), user="this analysis")
        if index not in fingers:
            X_WF = plant.EvalBodyPoseInWorld(plant_context, finger)
            fingers[index] = X_WF.inverse().multiply(X_WO)
        X_FO = fingers[index]
        common = {
            "finger_body": finger_name,
            "finger_body_index": index,
            "object_geometry": go,
            "finger_geometry": gf,
            "object_geometry_name": name(go),
            "finger_geometry_name": name(gf),
            "finger_geometry_index": kf,
            "object_geometry_index": ko,
        }
        pending = pending_pair(
            query=query,
            inspector=inspector,
            go=go,
            gf=gf,
            pair=r,
            swapped=swapped,
            X_OW=X_OW,
            tol=tol,
            patches=patches,
            cache=cache,
            frame=frame,
        )
        items.append(("pair", pending, X_FO, common, (go, finger_name, gf)))
    return StagedContacts(
        object_name, tol, allow_penetration, closest, items, inspector
    )
