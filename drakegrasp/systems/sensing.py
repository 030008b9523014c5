r"""What one sample of a grasp monitor senses: contacts, finger loads, clearance.

One sample of :class:`~drakegrasp.GraspMonitor` first asks its contact
source which contacts the analysis gets and what each finger does to the
object (:class:`~drakegrasp.systems.finger_loads.FingerLoad`):

- ``"geometry"``: signed distances (:func:`~drakegrasp.find_contacts`); a pair
  within the distance tolerance counts when its points are not moving apart
  faster than the separation speed, and its finger presses on the object only
  where the geometries touch (``ψ <= 0``).  Slip is seen, forces are not (NaN).
- ``"contact_results"``: the contacts the plant's contact model used in its
  last step (:func:`~drakegrasp.plant.contacts_from_results`), with the forces
  it applied, so friction in use with the plant's own μ.

The holding state also needs the object's motion against the fingers that
touch it, or last touched it (:func:`anchor_fingers`, :func:`motion_against`),
and, once contact is lost, how far the object is from the hand
(:func:`hand_clearance`): the evidence that
:func:`~drakegrasp.systems.holding.next_holding_state` judges.
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
from drakegrasp.plant.validation import pair_distance
from drakegrasp.systems.finger_loads import (
    FingerLoad,
    finger_loads_from_results,
    finger_motion_from_contacts,
    point_velocity,
    split_along,
)
from drakegrasp.systems.holding import HoldingThresholds

__all__ = [
    "FingerAnchor",
    "Motion",
    "Sensed",
    "anchor_fingers",
    "hand_clearance",
    "motion_against",
    "no_loads",
    "sense_contacts",
]


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
        query_object=query_object,
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


class FingerAnchor(NamedTuple):
    """Where the object sat on a finger at the last sample with contact.

    Attributes
    ----------
    finger : int
        Index of the finger in the monitor's hand bodies.
    p_FScm : (3,) float
        The object's centre of mass in the finger's frame F, m.
    nhat_F : (3,) float
        The finger's unit contact normal (into the object), in F.
    """

    finger: int
    p_FScm: np.ndarray
    nhat_F: np.ndarray


class Motion(NamedTuple):
    """How the object moves against the fingers that touch (or last touched) it.

    Attributes
    ----------
    relative : float
        Largest speed of the centre of mass measured in a finger's frame
        (its velocity minus that of the finger's material point there), m/s;
        NaN without fingers.
    sliding : float
        Largest such speed with its component along the finger's normal
        removed, m/s; 0 without fingers.
    along : float
        Largest sliding speed over the fingers against which the object moves
        more along the finger than away from it (tangential speed at least
        the normal one): the object sliding out, not the hand opening, which
        moves its fingers away along their normals.  m/s, 0 without fingers.
    slid : float
        Largest displacement of the centre of mass along a finger (normal
        component removed), in the finger's frame, since the anchors were
        taken, m; 0 without fingers.
    """

    relative: float
    sliding: float
    along: float
    slid: float


def _com_W(plant, plant_context, object_body) -> np.ndarray:
    return np.asarray(
        plant.EvalBodyPoseInWorld(plant_context, object_body).multiply(
            object_body.CalcCenterOfMassInBodyFrame(plant_context)
        )
    )


def anchor_fingers(
    plant: MultibodyPlant, plant_context: Context, object_body, fingers, touching
) -> tuple[FingerAnchor, ...]:
    """The object's place on each touching finger, in the finger's frame.

    Parameters
    ----------
    fingers : sequence of RigidBody
        The hand bodies.
    touching : sequence of (int, (3,) float)
        Index into ``fingers`` and unit contact normal in W of each finger
        that touches.
    """
    p_WScm = _com_W(plant, plant_context, object_body)
    anchors = []
    for k, n_W in touching:
        X_FW = plant.EvalBodyPoseInWorld(plant_context, fingers[k]).inverse()
        anchors.append(
            FingerAnchor(
                k,
                np.asarray(X_FW.multiply(p_WScm)),
                X_FW.rotation().matrix() @ np.asarray(n_W),
            )
        )
    return tuple(anchors)


def motion_against(
    plant: MultibodyPlant,
    plant_context: Context,
    object_body,
    fingers,
    anchors: tuple[FingerAnchor, ...],
) -> Motion:
    """How the object's centre of mass moves against the anchored fingers.

    Normals turn with their fingers (kept in the finger's frame), so a finger
    that swings open still measures sliding along itself.

    Parameters
    ----------
    fingers : sequence of RigidBody
        The hand bodies (``FingerAnchor.finger`` indexes them).
    anchors : tuple of FingerAnchor
        From :func:`anchor_fingers`, now or at the last sample with contact.
    """
    if not anchors:
        return Motion(np.nan, 0.0, 0.0, 0.0)
    p_WScm = _com_W(plant, plant_context, object_body)
    v_W = point_velocity(plant, plant_context, object_body, p_WScm)
    relative, sliding, along, slid = [], [], [], []
    for k, p_FScm, nhat_F in anchors:
        X_WF = plant.EvalBodyPoseInWorld(plant_context, fingers[k])
        v_rel = v_W - point_velocity(plant, plant_context, fingers[k], p_WScm)
        relative.append(float(np.linalg.norm(v_rel)))
        normal, tangential = split_along(v_rel, X_WF.rotation().matrix() @ nhat_F)
        sliding.append(tangential)
        along.append(tangential if tangential >= abs(normal) else 0.0)
        moved_F = np.asarray(X_WF.inverse().multiply(p_WScm)) - p_FScm
        slid.append(split_along(moved_F, nhat_F)[1])
    return Motion(max(relative), max(sliding), max(along), max(slid))


def hand_clearance(
    plant: MultibodyPlant,
    query_object: QueryObject,
    *,
    object_body,
    fingers,
    horizon: float,
) -> float:
    """Distance from the object to the nearest hand body, up to ``horizon``.

    The smallest signed distance between a collision geometry of
    ``object_body`` and one of ``fingers``' (pairs that a collision filter
    excludes are skipped), found with Drake's broad phase
    (``ComputeSignedDistancePairwiseClosestPoints`` with ``max_distance =
    horizon``), so its cost does not grow with the hand's far geometry; pair
    by pair when the scene holds a pair of shapes the broad phase refuses.

    Parameters
    ----------
    plant : MultibodyPlant
    query_object : QueryObject
        The scene graph's query object of the sample.
    object_body : RigidBody
    fingers : sequence of RigidBody
        The hand bodies.
    horizon : float
        Metres, > 0: farther pairs are not measured.

    Returns
    -------
    float
        Metres (negative when penetrating); ``inf`` when no pair is within
        ``horizon``.

    Raises
    ------
    ModelError
        If Drake cannot measure a pair within the horizon (an unsupported
        pair of shapes).
    """
    inspector = query_object.inspector()
    object_geometries = set(plant.GetCollisionGeometriesForBody(object_body))
    hand_geometries = {
        g for b in fingers for g in plant.GetCollisionGeometriesForBody(b)
    }
    try:  # the broad phase skips far pairs
        pairs = query_object.ComputeSignedDistancePairwiseClosestPoints(horizon)
    except RuntimeError:  # an unsupported pair elsewhere in the scene
        pairs = None
    nearest = np.inf
    if pairs is not None:
        for pair in pairs:
            ids = {pair.id_A, pair.id_B}
            if ids & object_geometries and ids & hand_geometries:
                nearest = min(nearest, float(pair.distance))
        return nearest
    for go in object_geometries:
        for gh in hand_geometries:
            d = pair_distance(query_object, inspector, go, gh)
            if d is not None and d <= horizon:
                nearest = min(nearest, float(d))
    return nearest
