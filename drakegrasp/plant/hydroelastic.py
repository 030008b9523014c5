r"""Hydroelastic contact for a simulated grasp: compliant fingers, a rigid object.

Drake's point contact gives a pair of geometries one contact point, the
deepest.  A flat pad pressed on a flat face therefore touches it at one point
in the simulation, where the planner (and a real pad) has a patch: two such
points resist no turning about the line through them, and the object pivots
between the pads whatever the squeeze.  drakegrasp's flat-pad jaw on its box
(planned at ``mu=0.5``, squeezed with 20 N, nine times the ``squeeze_needed``
of 2.2 N): 1 of the top 6 candidates held in the shake test with point
contact, every one turning 8-112°; with hydroelastic pads, all 6 held within
0.3 mm and 0.0°, and at 0.5 N all 6 dropped.  Hydroelastic contact (Elandt et
al. 2019; Drake's ``ContactModel.kHydroelasticWithFallback``) presses each pair
over a patch, with friction over the patch's area.

:func:`use_hydroelastic_contact` gives every collision geometry of the hand's
bodies Drake's compliant hydroelastic properties (a modulus in pascals, their
friction kept) and the object's the rigid ones, and sets the plant's contact
model to hydroelastic with fallback (pairs of other bodies, and any geometry
Drake cannot make hydroelastic, keep point contact).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
from pydrake.geometry import (
    AddCompliantHydroelasticProperties,
    AddRigidHydroelasticProperties,
    Box,
    Capsule,
    Cylinder,
    Ellipsoid,
    ProximityProperties,
    RoleAssign,
    Sphere,
)
from pydrake.multibody.plant import ContactModel
from pydrake.multibody.tree import RigidBody

from drakegrasp.core.validation import describe, real_scalar
from drakegrasp.errors import InvalidOptionError, ModelError

__all__ = ["MODULI", "check_hydroelastic_modulus", "use_hydroelastic_contact"]

_GROUP = "hydroelastic"


MODULI = (1e4, 1e12)
"""Hydroelastic moduli taken, Pa: from a soft gel to five times steel's.

Outside, Drake's contact goes wrong without a word or stops: measured on the
flat jaw and the box, the object fell through the pads at 1e-3 Pa, SAP did not
converge at 1e15, Drake could not factorise at 1e20, and at 1e300 the contact
force vanished and the object fell, reported as an ordinary drop."""


def check_hydroelastic_modulus(value, name: str = "hydroelastic_modulus"):
    """``value`` as a modulus in pascals within :data:`MODULI`, or None for none.

    Parameters
    ----------
    value : float or None
    name : str
        The keyword named in the error.

    Returns
    -------
    float or None

    Raises
    ------
    InvalidOptionError
        Not None and not a real number within :data:`MODULI`.
    """
    if value is None:
        return None
    try:
        x = real_scalar(name, value)
    except InvalidOptionError:  # not a real number: refused with the range below
        x = float("nan")
    if not MODULI[0] <= x <= MODULI[1]:
        raise InvalidOptionError(
            f"{name} must be None (the models' own contact) or a number of "
            f"pascals in [{MODULI[0]:g}, {MODULI[1]:g}] (rubber pads: about "
            f"1e6), got {describe(value)}"
        )
    return x


def _bodies(plant, bodies, what: str) -> list:
    """``bodies`` as a list of this plant's ``RigidBody``; refused otherwise."""
    if isinstance(bodies, RigidBody) or not isinstance(bodies, Iterable):
        raise InvalidOptionError(
            f"{what} must be an iterable of RigidBody, got {type(bodies).__name__}"
        )
    out = list(bodies)
    for body in out:
        if not isinstance(body, RigidBody):
            raise InvalidOptionError(
                f"{what} must hold RigidBody objects, got {type(body).__name__}"
            )
        if body.GetParentPlant() is not plant:
            raise ModelError(f"body {body.name()!r} of {what} is of another plant")
    return out


def _resolution_hint(shape) -> float:
    """A mesh edge length (m) for Drake's tessellation of a curved shape.

    A quarter of the shape's smallest width, so a fingertip sphere gets a few
    dozen tetrahedra, not one; boxes and meshes ignore it.
    """
    if isinstance(shape, Sphere):
        width = 2.0 * shape.radius()
    elif isinstance(shape, Cylinder):
        width = min(2.0 * shape.radius(), shape.length())
    elif isinstance(shape, Capsule):
        width = 2.0 * shape.radius()
    elif isinstance(shape, Ellipsoid):
        width = 2.0 * min(shape.a(), shape.b(), shape.c())
    elif isinstance(shape, Box):
        width = float(np.min(shape.size()))
    else:
        return 0.01
    return max(width / 4.0, 1e-6)


def _assign(plant, scene_graph, geometry, add, *, keep_own: bool = False) -> bool:
    """Replace ``geometry``'s proximity properties by a copy that ``add`` extends.

    With ``keep_own``, a geometry the model makes hydroelastic itself keeps
    its values.  Returns False when Drake refuses them (the geometry keeps
    its own).
    """
    inspector = scene_graph.model_inspector()
    props = ProximityProperties(inspector.GetProximityProperties(geometry))
    if keep_own and props.HasProperty(_GROUP, "compliance_type"):
        return True
    if props.HasGroup(_GROUP):  # the model's own hydroelastic values: replaced
        for name in list(props.GetPropertiesInGroup(_GROUP)):
            props.RemoveProperty(_GROUP, name)
    add(props, _resolution_hint(inspector.GetShape(geometry)))
    try:
        scene_graph.AssignRole(
            plant.get_source_id(), geometry, props, RoleAssign.kReplace
        )
    except RuntimeError:
        return False
    return True


def use_hydroelastic_contact(
    plant,
    scene_graph,
    hand_bodies: Iterable,
    object_bodies: Iterable,
    *,
    modulus: float,
) -> int:
    """Make the hand's geometries compliant and the object's rigid hydroelastic.

    An object geometry the model makes hydroelastic itself (a soft object's
    ``<drake:compliant_hydroelastic>``) keeps its own properties: the shake
    then presses on the object as modelled (before, it was made rigid
    without a word).

    Parameters
    ----------
    plant : MultibodyPlant
        Not finalized, registered with ``scene_graph``, no context made yet.
    scene_graph : SceneGraph
    hand_bodies, object_bodies : iterable of RigidBody
        The bodies whose collision geometries become compliant (the hand's:
        pads, links, fingertips) and rigid (the object's).
    modulus : float
        The compliant geometries' hydroelastic modulus, Pa (rubber pads are
        about 1e6-1e7; the result barely depends on it where the pads hold).

    Returns
    -------
    int
        Collision geometries Drake refused to make hydroelastic: they keep
        point contact (a half-space cannot be compliant).

    Raises
    ------
    InvalidOptionError
        A modulus outside :data:`MODULI`, or bodies that are not an iterable
        of ``RigidBody``.
    ModelError
        The plant is already finalized (its contact model is fixed), is not
        registered with ``scene_graph``, or a body is of another plant.
    """
    if modulus is None:
        raise InvalidOptionError("modulus must be a number of pascals, got None")
    modulus = check_hydroelastic_modulus(modulus, "modulus")
    if plant.is_finalized():
        raise ModelError(
            "use_hydroelastic_contact needs a plant that is not finalized yet"
        )
    if not plant.geometry_source_is_registered() or not (
        scene_graph.model_inspector().SourceIsRegistered(plant.get_source_id())
    ):
        raise ModelError("the plant is not registered with this scene_graph")
    hand_bodies = _bodies(plant, hand_bodies, "hand_bodies")
    object_bodies = _bodies(plant, object_bodies, "object_bodies")
    plant.set_contact_model(ContactModel.kHydroelasticWithFallback)

    def compliant(props, hint):
        AddCompliantHydroelasticProperties(hint, modulus, props)

    def rigid(props, hint):
        AddRigidHydroelasticProperties(hint, props)

    refused = 0
    for bodies, add in ((hand_bodies, compliant), (object_bodies, rigid)):
        for body in bodies:
            for geometry in plant.GetCollisionGeometriesForBody(body):
                refused += not _assign(
                    plant, scene_graph, geometry, add, keep_own=add is rigid
                )
    return refused
