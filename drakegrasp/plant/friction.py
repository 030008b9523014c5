r"""The friction a plant simulates, read from its geometries.

Drake stores a Coulomb friction per geometry (the proximity property
``material/coulomb_friction``) and combines the two of a contact pair as
``μ = 2 μ_a μ_b / (μ_a + μ_b)`` (``CalcContactFrictionFromSurfaceProperties``).

* :func:`pair_friction`: the combined coefficient of one geometry pair, as a
  step's contact results name them;
* :func:`plant_friction`: the same per contact of a grasp read from the plant
  (``mu="plant"`` in :func:`~drakegrasp.analyze_grasp` and the grasp monitor);
* :func:`hand_object_friction`: the coefficients of every pair of a hand and
  an object geometry, before any contact is known (``drakegrasp plan --mu
  plant``);
* :func:`friction_disagreement`: why a ``μ`` typed by hand is not the plant's
  (the load report's warning, the monitor's
  :class:`FrictionMismatchWarning`).

**Which coefficient** (:func:`friction_rule`): a discrete plant
(``time_step > 0``) uses the *dynamic* one — Drake's discrete solvers (TAMSI,
SAP) ignore the static coefficient — so that is the one a held object gets in
simulation; a continuous plant's Stribeck model lets a sticking contact reach
the *static* one, so that one is used there.
"""

from __future__ import annotations

import numpy as np
from pydrake.multibody.plant import (
    CalcContactFrictionFromSurfaceProperties,
    MultibodyPlant,
)

from drakegrasp.core.validation import describe, plain_str
from drakegrasp.errors import GraspWarning, InvalidOptionError, ModelError
from drakegrasp.plant.handles import local_geometry_id
from drakegrasp.plant.validation import (
    checked_query_object,
    hand_contact_bodies,
    plant_context_of,
    query_object_of,
    resolve_grasped_body,
)

__all__ = [
    "MU_RELATIVE_TOL",
    "FrictionMismatchWarning",
    "friction_disagreement",
    "friction_rule",
    "hand_object_friction",
    "pair_friction",
    "plant_friction",
]


class FrictionMismatchWarning(GraspWarning):
    """A given friction coefficient is not the one the plant simulates."""


MU_RELATIVE_TOL = 1e-6
"""A given ``μ`` that differs from the plant's by more than this (relative) is
reported as a disagreement."""


def friction_rule(plant: MultibodyPlant) -> str:
    """``"dynamic"`` for a discrete plant, ``"static"`` for a continuous one."""
    return "dynamic" if plant.time_step() > 0.0 else "static"


def _coulomb(inspector, geometry_id):
    props = inspector.GetProximityProperties(geometry_id)
    if props is None or not props.HasProperty("material", "coulomb_friction"):
        raise ModelError(
            f"geometry {inspector.GetName(geometry_id)!r} has no proximity property "
            "material/coulomb_friction; the plant's friction needs the friction of "
            "both geometries of every contact"
        )
    return props.GetProperty("material", "coulomb_friction")


def pair_friction(
    plant: MultibodyPlant, query_object, id_a, id_b, *, rule: str | None = None
) -> float:
    """The plant's combined friction coefficient of one geometry pair.

    Parameters
    ----------
    plant : MultibodyPlant
        Decides which coefficient (:func:`friction_rule`) unless ``rule``.
    query_object : QueryObject
        Holds the geometries' proximity properties.
    id_a, id_b : GeometryId
        The two geometries, in either order.
    rule : {"static", "dynamic"}, optional
        Which coefficient, whatever the plant simulates (default: the
        plant's rule).

    Returns
    -------
    float
        ``2 μ_a μ_b / (μ_a + μ_b)`` of the dynamic (discrete plant) or static
        (continuous plant) coefficients (dimensionless).

    Raises
    ------
    ModelError
        If either geometry has no ``material/coulomb_friction`` property.
    InvalidContactError
        Either is a :class:`~drakegrasp.plant.handles.ForeignGeometryId`, a
        geometry of another process (a contact unpickled here).
    """
    id_a = local_geometry_id(id_a, "the first geometry (id_a)")
    id_b = local_geometry_id(id_b, "the second geometry (id_b)")
    inspector = query_object.inspector()
    pair = CalcContactFrictionFromSurfaceProperties(
        _coulomb(inspector, id_a), _coulomb(inspector, id_b)
    )
    rule = friction_rule(plant) if rule is None else _check_rule(rule)
    if rule == "dynamic":
        return float(pair.dynamic_friction())
    return float(pair.static_friction())


def _check_rule(rule) -> str:
    rule = plain_str(rule)
    if type(rule) is not str or rule not in ("static", "dynamic"):
        raise InvalidOptionError(
            f"rule must be 'static', 'dynamic' or None, got {describe(rule)}"
        )
    return rule


def plant_friction(
    plant: MultibodyPlant,
    plant_context,
    contacts,
    *,
    query_object=None,
    rule: str | None = None,
) -> np.ndarray:
    """Per contact, the plant's combined friction coefficient (see the module).

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
    contacts : sequence of PlantContact
    query_object : QueryObject, optional
        Read the geometry from it instead of the plant's query port.
    rule : {"static", "dynamic"}, optional
        As in :func:`pair_friction` (default: the plant's rule).

    Returns
    -------
    (N,) float
        :func:`pair_friction` of each contact's object and finger geometries.

    Raises
    ------
    ModelError
        As :func:`pair_friction`.
    InvalidContactError
        A contact unpickled in another process than the one that found it
        (its geometries are :class:`~drakegrasp.plant.handles.ForeignGeometryId`).
    """
    contacts = list(contacts)
    pairs = [
        (
            local_geometry_id(c.object_geometry, f"contact {k}'s object_geometry"),
            local_geometry_id(c.finger_geometry, f"contact {k}'s finger_geometry"),
        )
        for k, c in enumerate(contacts)
    ]
    if query_object is None:
        ctx = plant_context_of(plant, plant_context)
        query_object = query_object_of(plant, ctx)
    else:
        checked_query_object(plant, query_object)
    return np.array(
        [pair_friction(plant, query_object, go, gf, rule=rule) for go, gf in pairs],
        dtype=float,
    )


def _differs(mu: np.ndarray, given: float) -> np.ndarray:
    """Where ``mu`` is not ``given`` (beyond :data:`MU_RELATIVE_TOL`, relative)."""
    return np.abs(mu - given) > MU_RELATIVE_TOL * np.maximum(mu, 1.0)


def hand_object_friction(
    plant: MultibodyPlant,
    plant_context,
    object_body,
    hand=None,
    *,
    rule: str | None = None,
) -> np.ndarray:
    """The plant's friction of every pair of a hand and an object geometry.

    What :func:`plant_friction` would give a contact between any collision
    geometry of the hand (every body that can touch,
    :func:`~drakegrasp.plant.validation.hand_contact_bodies`) and any of the
    object, before a grasp is known.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
    object_body : RigidBody, BodyIndex or str
        The object's body, or its scoped name: not the world body, nor a
        body of the hand.  A body welded to the world (a fixture) has the
        friction of its geometries like any other.
    hand : HandSpec, optional
        The hand as :func:`~drakegrasp.plant.validation.hand_bodies` takes it.
    rule : {"static", "dynamic"}, optional
        As in :func:`pair_friction` (default: the plant's rule).

    Returns
    -------
    (M,) float
        The distinct coefficients (dimensionless), ascending; empty when the
        hand or the object has no collision geometry.

    Raises
    ------
    InvalidOptionError
        If ``object_body`` is the world body, or a body of the hand (listed
        in ``hand`` or joined to its bodies), or for an unknown ``rule``.
    ModelError
        If a geometry has no ``material/coulomb_friction`` property, or for
        an unknown body or hand.
    """
    rule = None if rule is None else _check_rule(rule)
    ctx = plant_context_of(plant, plant_context)
    body = resolve_grasped_body(plant, object_body)
    query_object = query_object_of(plant, ctx)
    hand_ids = [
        g
        for b in hand_contact_bodies(plant, body, hand)
        for g in plant.GetCollisionGeometriesForBody(b)
    ]
    values = {
        pair_friction(plant, query_object, o, h, rule=rule)
        for o in plant.GetCollisionGeometriesForBody(body)
        for h in hand_ids
    }
    return np.array(sorted(values), dtype=float)


def friction_disagreement(
    plant: MultibodyPlant, mu_given: float | None, mu_plant, *, mu_dynamic=None
) -> str | None:
    """Why a given ``μ`` is not the plant's, or None when they agree.

    Parameters
    ----------
    plant : MultibodyPlant
        Names the friction rule in the message.
    mu_given : float or None
        The coefficient the caller typed (None: nothing to compare).
    mu_plant : (N,) float or None
        The plant's coefficient per contact (:func:`plant_friction`).
    mu_dynamic : (N,) float or None, optional
        For a continuous plant, the dynamic coefficient per contact
        (``plant_friction(..., rule="dynamic")``): where ``mu_given`` is that
        at every contact that differs (``drakegrasp plan --mu plant``'s, what
        a discrete simulation uses), the sentence says so instead of
        advising ``mu='plant'``.

    Returns
    -------
    str or None
        A sentence naming both values and the contacts where they differ by
        more than :data:`MU_RELATIVE_TOL` (relative), or None.
    """
    if mu_given is None or mu_plant is None:
        return None
    mu_plant = np.asarray(mu_plant, dtype=float)
    off = _differs(mu_plant, mu_given)
    if not np.any(off):
        return None
    if mu_dynamic is not None and friction_rule(plant) == "static":
        dynamic = np.asarray(mu_dynamic, dtype=float)
        if dynamic.shape == mu_plant.shape and not np.any(
            _differs(dynamic[off], mu_given)
        ):
            return (
                f"mu = {mu_given:g} is the models' dynamic friction at contacts "
                f"{np.flatnonzero(off).tolist()}, what a discrete simulation uses "
                "(and drakegrasp plan --mu plant); this continuous plant's rule "
                f"takes the static {np.round(np.unique(mu_plant[off]), 6).tolist()} "
                "(mu='plant'), which holds more"
            )
    return (
        f"mu = {mu_given:g} was given but the plant simulates "
        f"{np.round(np.unique(mu_plant[off]), 6).tolist()} "
        f"({friction_rule(plant)} friction) at contacts "
        f"{np.flatnonzero(off).tolist()}; pass mu='plant' to use it"
    )
