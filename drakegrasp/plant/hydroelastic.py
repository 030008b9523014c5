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

from drakegrasp.errors import InvalidOptionError, ModelError

__all__ = ["check_hydroelastic_modulus", "use_hydroelastic_contact"]

_GROUP = "hydroelastic"


def check_hydroelastic_modulus(value) -> float | None:
    """``value`` as a modulus in pascals (finite, > 0), or None for none.

    Raises
    ------
    InvalidOptionError
        Not None and not a finite real number > 0.
    """
    if value is None:
        return None
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float | np.integer | np.floating)
        or not np.isfinite(value)
        or value <= 0
    ):
        raise InvalidOptionError(
            "hydroelastic_modulus must be None (the models' own contact) or a "
            f"finite number > 0 (Pa), got {value!r}"
        )
    return float(value)


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


def _assign(plant, scene_graph, geometry, add) -> bool:
    """Replace ``geometry``'s proximity properties by a copy that ``add`` extends.

    Returns False when Drake refuses them (the geometry keeps its own).
    """
    inspector = scene_graph.model_inspector()
    props = ProximityProperties(inspector.GetProximityProperties(geometry))
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
        point contact (0 for Drake's shapes and convex meshes).

    Raises
    ------
    ModelError
        The plant is already finalized (its contact model is fixed).
    """
    modulus = check_hydroelastic_modulus(modulus)
    if modulus is None:
        raise InvalidOptionError("modulus must be a number of pascals, got None")
    if plant.is_finalized():
        raise ModelError(
            "use_hydroelastic_contact needs a plant that is not finalized yet"
        )
    plant.set_contact_model(ContactModel.kHydroelasticWithFallback)

    def compliant(props, hint):
        AddCompliantHydroelasticProperties(hint, modulus, props)

    def rigid(props, hint):
        AddRigidHydroelasticProperties(hint, props)

    refused = 0
    for bodies, add in ((hand_bodies, compliant), (object_bodies, rigid)):
        for body in bodies:
            for geometry in plant.GetCollisionGeometriesForBody(body):
                refused += not _assign(plant, scene_graph, geometry, add)
    return refused
