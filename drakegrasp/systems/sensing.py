"""Where a grasp monitor's contacts come from, and what each source can see.

One sample of :class:`~drakegrasp.GraspMonitor` first asks its contact
source which contacts the analysis gets and what each finger does to the
object (:class:`~drakegrasp.systems.holding.FingerLoad`):

- ``"geometry"``: signed distances (:func:`~drakegrasp.find_contacts`); a pair
  within the distance tolerance counts when its points are not moving apart
  faster than the separation speed.  Slip is seen, forces are not (NaN).
- ``"contact_results"``: the contacts the plant's contact model used in its
  last step (:func:`~drakegrasp.plant.contacts_from_results`), with the forces
  it applied, so friction in use with the plant's own μ.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from pydrake.geometry import QueryObject
from pydrake.multibody.plant import ContactResults, MultibodyPlant
from pydrake.systems.framework import Context

from drakegrasp.errors import NoContactsError
from drakegrasp.plant.contact_results import contacts_from_results
from drakegrasp.plant.contacts import PlantContact, _scoped_name, find_contacts
from drakegrasp.plant.options import AnalysisOptions
from drakegrasp.systems.holding import (
    FingerLoad,
    HoldingThresholds,
    finger_loads_from_results,
    finger_motion_from_contacts,
)

__all__ = ["Sensed", "no_loads", "sense_contacts"]


class Sensed(NamedTuple):
    """What one sample's contact source found.

    Attributes
    ----------
    contacts : list of PlantContact or None
        The contacts to analyse (frame O); None when there are none.
    loads : tuple of FingerLoad
        One per finger body, in the monitor's order.
    missing : NoContactsError or None
        Why there are no contacts (None when there are).
    """

    contacts: list[PlantContact] | None
    loads: tuple[FingerLoad, ...]
    missing: NoContactsError | None


def no_loads(
    plant: MultibodyPlant, fingers, *, forces_seen: bool
) -> tuple[FingerLoad, ...]:
    """Per finger, the load of a sample without contact.

    Forces and friction in use are 0 when the source sees forces, NaN when
    it cannot (geometry); μ and the normal are unknown (NaN).
    """
    value = 0.0 if forces_seen else np.nan
    return tuple(
        FingerLoad(_scoped_name(plant, f), False, value, value, np.nan, value, 0.0)
        for f in fingers
    )


def sense_contacts(
    plant: MultibodyPlant,
    plant_context: Context,
    query_object: QueryObject,
    *,
    object_body,
    fingers,
    analysis: AnalysisOptions,
    thresholds: HoldingThresholds,
    contact_results: ContactResults | None = None,
) -> Sensed:
    """The contacts of one sample and the fingers' loads.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
        Holds the sample's positions and velocities.
    query_object : QueryObject
        The scene graph's query object of the same instant.
    object_body : RigidBody
    fingers : sequence of RigidBody
        The hand bodies, in the order of the loads.
    analysis : AnalysisOptions
        Its distance tolerance, penetration flag and patch mode (geometry).
    thresholds : HoldingThresholds
        Its separation speed (geometry).
    contact_results : ContactResults, optional
        Read the contacts from the plant's results of its last step instead
        of from signed distances.

    Returns
    -------
    Sensed
    """
    if contact_results is not None:
        loads = tuple(
            finger_loads_from_results(
                plant,
                plant_context,
                contact_results,
                query_object,
                object_body=object_body,
                fingers=fingers,
            )
        )
        try:
            found = contacts_from_results(
                plant,
                plant_context,
                contact_results,
                query_object,
                object_body=object_body,
                hand=fingers,
            )
        except NoContactsError as e:
            return Sensed(None, loads, e)
        return Sensed(found, loads, None)
    try:
        candidates = find_contacts(
            plant,
            plant_context,
            object_body=object_body,
            hand=fingers,
            distance_tolerance=analysis.distance_tolerance,
            allow_penetration=analysis.allow_penetration,
            patches=analysis.patches,
            query_object=query_object,
        )
    except NoContactsError as e:
        return Sensed(None, no_loads(plant, fingers, forces_seen=False), e)
    found, loads = finger_motion_from_contacts(
        plant,
        plant_context,
        candidates,
        object_body=object_body,
        fingers=fingers,
        separation_speed=thresholds.separation_speed,
    )
    if found:
        return Sensed(found, tuple(loads), None)
    return Sensed(
        None,
        tuple(loads),
        NoContactsError(
            f"every hand contact with {_scoped_name(plant, object_body)!r} within "
            f"the tolerance is separating faster than "
            f"{thresholds.separation_speed:g} m/s"
        ),
    )
