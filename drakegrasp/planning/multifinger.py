r"""The multi-finger route's hand and closings: approach, pre-shape, ``close_hand``.

The route :func:`~drakegrasp.planning.planner.plan_grasps` takes for a hand
that is not a parallel jaw (the Allegro hand, drakegrasp's three-finger hand,
a user's): :func:`~drakegrasp.planning.planner.plan_multifinger` runs the
stages below, this module holds the hand's checks and stages 2 and 3, and
stage 4 is :func:`~drakegrasp.planning.ranking.rank_multifinger`, beside the
parallel jaw's ranking.  Every sampled pose becomes a candidate or is counted
under one rejection reason (:data:`REASONS`).

1. **Approach and pre-shape** (numpy, all samples at once,
   :mod:`drakegrasp.planning.approach`): a surface point, the approach along
   its inward normal (tilted), a palm stand-off, a roll, and a pre-shape (the
   open hand, a user's, or a synergy direction).
2. **Collision filter** (Drake): the hand at ``X_WH`` in its pre-shape; a
   hand geometry with signed distance below ``−distance_tolerance`` to the
   object or anything else rejects the pose.
3. **Closing**: :func:`~drakegrasp.close_hand` (couplings read from the
   plant) from the pre-shape.  Fingers that a ``<mimic>`` closes as one stop
   when one touches: the hand is then moved so that their gaps to the object
   are equal and closed again (:mod:`drakegrasp.planning.centring`), the
   candidate keeping the pose it closed at.  Fewer than ``min_fingers`` fingers touching
   rejects it, and so does a closed finger that penetrates the rest of the
   scene or another finger (``close_hand`` watches the object only).  The
   contacts are those of :func:`~drakegrasp.find_contacts`, which
   :func:`~drakegrasp.analyze_grasp` reads on the applied candidate.
4. **Ranking** as for the parallel jaw (:mod:`drakegrasp.planning.ranking`):
   LP2 verdicts and ε with the object's torque scale, robustness under noise
   that moves each finger's contacts rigidly (the palm's stay), the weight
   capacity with one squeeze bound per finger and one for the palm
   (:mod:`drakegrasp.planning.weight`), ``score = robustness × capacity``.
   With the object's weight, the best force-closure candidates get the
   joint torque that holds it (:mod:`drakegrasp.planning.motors`), and those
   the actuators' effort limits allow are ranked first.

On a point cloud (:func:`~drakegrasp.planning.planner.plan_multifinger_cloud`),
stages 2 and 3 are those of :mod:`drakegrasp.planning.cloud_hand` (the hand
against the cloud's points, the fingers closed onto them); stage 1 is the
same, and in stage 4 the weight capacity of a candidate with a contact at an
edge of the cloud is averaged over the edge's normal fan
(:func:`~drakegrasp.planning.weight.fan_capacity`); the torque needed (with
``object_mass``) takes each contact's finger point at its cloud point.
"""

from __future__ import annotations

import time
import warnings
from collections import Counter

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix

from drakegrasp.core.calls import checked_call
from drakegrasp.core.deprecation import outside_stacklevel
from drakegrasp.errors import (
    GraspWarning,
    InvalidOptionError,
    ModelError,
    NoContactsError,
    PenetrationError,
    UnreachableError,
)
from drakegrasp.planning.approach import (
    MultiFingerHand,
    multi_finger_hand,
)
from drakegrasp.planning.candidates import (
    closing_order,
)
from drakegrasp.planning.centring import CentredCloser, chain_groups
from drakegrasp.plant._closing_steps import closest
from drakegrasp.plant.closing import close_checked_hand
from drakegrasp.plant.contacts import find_contacts
from drakegrasp.plant.couplings import plant_couplings
from drakegrasp.plant.fingers import finger_chains, hand_structure, passive_joints
from drakegrasp.plant.validation import (
    hand_bodies,
    plant_context_of,
    resolve_object_body,
    scoped_name,
)

__all__ = [
    "DEFAULT_TILT",
    "REASONS",
    "PassiveJointWarning",
    "checked_hand",
    "close_candidates",
    "hand_is_parallel_jaw",
    "is_parallel_jaw",
]


class PassiveJointWarning(GraspWarning):
    """A hand has joints no motor moves, which the planner treats as driven.

    A one-dof joint without an actuator that follows no driven joint (no
    ``<mimic>`` of a joint with a motor) is passive: in Drake it turns freely
    between its limits.  The planner closes the motors' joints (and those
    coupled to them) and holds the others where the context puts them, as if
    welded; its torque figures leave them out.
    :func:`~drakegrasp.analyze_grasp`'s load check gives a passive joint no
    torque, and :func:`~drakegrasp.planning.shake_test` lets it turn.  A grasp
    that loads it may fold: on a three-finger hand with passive distal joints
    (damped, at 0.2 rad of [0, 1.2]) 2 of the 4 best planned box grasps
    dropped in Drake, and all 4 held with those joints welded.
    """


DEFAULT_TILT = np.radians(20.0)
"""Default largest tilt of the approach from the surface's inward normal."""

REASONS = {
    "hand collides with the object": "the pre-shaped hand penetrates the object",
    "hand collides with the scene": "the pre-shaped hand penetrates another body",
    "fingers miss the object": "fewer than min_fingers fingers reach the object",
    "finger blocked by the scene": "a closed finger penetrates another body",
    "one finger touches": "the contacts come from fewer than two fingers",
    "fingers collide with each other": "two fingers (or a finger and the palm) "
    "penetrate each other, in the pre-shape or after closing",
}
"""Every rejection reason of the multi-finger route, with what it means."""


@checked_call
def hand_is_parallel_jaw(plant, plant_context, object_body, hand) -> bool:
    """Whether ``hand`` is two fingers of one prismatic joint each (in the plant)."""
    plant_context = plant_context_of(plant, plant_context)  # the diagram's too
    bodies = hand_bodies(plant, object_body, hand)
    object_body = resolve_object_body(plant, object_body)
    inspector = plant.get_geometry_query_input_port().Eval(plant_context).inspector()
    try:
        structure = hand_structure(
            plant, object_body, bodies, plant_couplings(plant), inspector=inspector
        )
    except ModelError:  # no closing joint: the multi-finger route says why
        return False
    return is_parallel_jaw(structure, finger_chains(plant, structure))


def is_parallel_jaw(structure, chains=None) -> bool:
    """Whether a hand is two fingers of one prismatic joint each.

    ``chains``: its fingers as kinematic chains
    (:func:`~drakegrasp.plant.fingers.finger_chains`: a jaw whose second
    finger follows the first by a ``<mimic>``, one motor for both, is two);
    default ``structure.fingers``.
    """
    fingers = structure.fingers if chains is None else chains
    return len(fingers) == 2 and all(
        len(f.joints) == 1 and structure.joints[f.joints[0]].type_name() == "prismatic"
        for f in fingers
    )


class _Placer(CentredCloser):
    """Stages 2-3 for one hand and object in a plant context (scratch)."""

    def __init__(
        self, plant, ctx, body, hand_spec, hand: MultiFingerHand, tol, min_fingers
    ):
        self.plant, self.ctx, self.body, self.spec = plant, ctx, body, hand_spec
        self.hand, self.tol = hand, tol
        self.port = plant.get_geometry_query_input_port()
        instances = {hand.base.model_instance()} | {
            j.model_instance() for j in hand.structure.joints
        }
        self.hand_geoms = {
            g
            for i in instances
            for b in plant.GetBodyIndices(i)
            for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))
        }
        self.object_geoms = set(plant.GetCollisionGeometriesForBody(body))
        self.label = {}
        for f, finger in enumerate(hand.chains):
            for b in finger.bodies:
                self.label[scoped_name(plant, b)] = f
        self.group = chain_groups(hand.structure, hand.chains)
        self.side = list(hand.sides) or None
        self.min_fingers = int(min_fingers)
        self.X_WH = None

    def _penetration(self):
        """None, or what a hand geometry penetrates.

        ``"object"``, ``"scene"`` or ``"hand"`` (two hand geometries whose pair
        the scene graph does not filter: fingers that cross each other).
        """
        query = self.port.Eval(self.ctx)
        found = None
        for pair in query.ComputeSignedDistancePairwiseClosestPoints(0.0):
            a, b = pair.id_A, pair.id_B
            in_a, in_b = a in self.hand_geoms, b in self.hand_geoms
            if not (in_a or in_b) or pair.distance >= -self.tol:
                continue
            if in_a and in_b:
                found = "hand"  # reported unless the hand hits something else
                continue
            other = b if in_a else a
            return "object" if other in self.object_geoms else "scene"
        return found

    def _gaps(self, chains):
        """The chains' gaps to the object and lines towards it (world frame)."""
        query = self.port.Eval(self.ctx)
        psi, lines = np.full(len(chains), np.nan), np.full((len(chains), 3), np.nan)
        for i, c in enumerate(chains):
            d, n_W, *_ = closest(query, self.plant, self.ctx, self.hand.chains[c].pairs)
            if n_W is not None:  # else no geometry to measure: NaN
                psi[i], lines[i] = d, n_W
        return psi, lines

    def _close(self, X_WH, q_pre):
        """One closing at ``X_WH``: (contacts, q, reason, chains touching)."""
        plant, ctx, s = self.plant, self.ctx, self.hand.structure
        plant.SetFreeBodyPose(ctx, self.hand.base, X_WH)
        q_all = plant.GetPositions(ctx)
        q_all[s.position_indices] = q_pre
        plant.SetPositions(ctx, q_all)
        hit = self._penetration()
        if hit == "hand":
            return None, None, "fingers collide with each other", set()
        if hit is not None:
            return None, None, f"hand collides with the {hit}", set()
        try:  # the pre-shape is clear, within the limits and the couplings
            closure = close_checked_hand(
                plant, ctx, self.body, s, tol=self.tol,
                # the chains that close as one count once here; below, each
                min_fingers=min(self.min_fingers, len(s.fingers)),
                t0=time.perf_counter(),
            )  # fmt: skip
        except UnreachableError:
            return None, None, "fingers miss the object", set()
        except PenetrationError:  # only an inaccurate distance gets here
            return None, None, "hand collides with the object", set()
        hit = self._penetration()
        if hit == "scene":
            return None, None, "finger blocked by the scene", set()
        if hit == "object":  # only an inaccurate distance gets here
            return None, None, "hand collides with the object", set()
        if hit == "hand":  # close_hand watches the object only
            return None, None, "fingers collide with each other", set()
        try:
            found = find_contacts(
                plant, ctx, self.body, hand=self.spec, distance_tolerance=self.tol
            )
        except (NoContactsError, PenetrationError):
            return None, None, "one finger touches", set()
        fingers = {self.label.get(c.finger_body, -1) for c in found} - {-1}
        if len(fingers) < 2:
            return None, None, "one finger touches", fingers
        if len(fingers) < self.min_fingers:  # chains that closed as one finger
            return None, None, "fingers miss the object", fingers
        return found, closure.q.copy(), None, fingers


def close_candidates(
    plant, ctx, body, hand_spec, hand, poses, tol, progress, min_fingers=2
):
    """Stages 2-3 over sampled poses: (kept, rejection counts).

    ``kept`` holds ``(sample, X_WH, q_pre, q, contacts)``.
    """
    placer = _Placer(plant, ctx, body, hand_spec, hand, tol, min_fingers)
    return close_each(placer, poses, progress)


def close_each(closer, poses, progress):
    """Close the hand at every sampled pose: (kept, rejection counts, labels).

    ``closer.run(X_WH, q_pre)`` gives ``(contacts, q, reason)`` (a body's
    placer or a cloud's :class:`~drakegrasp.planning.cloud_hand.CloudHand`)
    and leaves the pose the hand closed at in ``closer.X_WH`` (centred, for
    fingers a coupling closes as one); ``kept`` holds ``(sample, X_WH, q_pre,
    q, contacts)``.
    """
    rejections = Counter()
    kept = []
    for k in closing_order(len(poses["q"]), progress):
        X_WH = RigidTransform(RotationMatrix(poses["R_WH"][k]), poses["p_WH"][k])
        found, q, reason = closer.run(X_WH, poses["q"][k])
        if reason is not None:
            rejections[reason] += 1
            continue
        kept.append((k, closer.X_WH, poses["q"][k], q, found))
    return kept, rejections, closer.label


def _warn_passive(plant, body, hand, structure) -> None:
    """:class:`PassiveJointWarning` naming the hand's passive joints, if any."""
    passive = passive_joints(plant, hand_bodies(plant, body, hand), structure)
    if not passive:
        return
    names = ", ".join(scoped_name(plant, j) for j in passive)
    warnings.warn(
        f"no motor moves joint(s) {names} (no actuator, and no <mimic> of a "
        "joint with one): in Drake they turn freely between their limits, but "
        "the planner closes or holds them as if driven or welded and ranks "
        "torque without them, so a planned grasp that loads them may fold "
        "(shake_test simulates them as they are); give them a <transmission>, "
        "couple them with a <mimic> to a driven joint, or weld them, to plan "
        "the hand Drake simulates",
        PassiveJointWarning,
        stacklevel=outside_stacklevel(),
    )


def checked_hand(
    plant, ctx, body, hand, *, tilt, min_fingers, preshape, synergy,
    synergy_range, approach, standoff,
):  # fmt: skip
    """The hand read and checked against ``min_fingers``: ``(tilt, MultiFingerHand)``.

    ``tilt`` and ``min_fingers`` arrive checked by
    :func:`~drakegrasp.planning.planner.plan_grasps` (a float in ``[0, π/2]``,
    an integer ``>= 2``); what needs the hand is checked here.
    """
    hand_model = multi_finger_hand(
        plant, ctx, body, hand, preshape=preshape, synergy=synergy,
        synergy_range=synergy_range, approach=approach, standoff=standoff,
    )  # fmt: skip
    _warn_passive(plant, body, hand, hand_model.structure)
    if min_fingers > hand_model.num_fingers:
        fingers = [f.name for f in hand_model.chains]
        joints = len(hand_model.structure.names)
        arm = (
            f"; its one finger {fingers[0]} moves all {joints} closing joints "
            "from the base: an arm that carries a hand is not a hand (the "
            "planner places the hand's base and closes its fingers): load the "
            "hand's own model, or weld the arm's joints"
            if hand_model.num_fingers == 1 and joints > 2
            else ""
        )
        if hand_model.num_fingers == 1 and not arm:
            raise ModelError(
                f"the hand has one moving finger {fingers}: the planner closes "
                "two or more fingers onto the object, and a single-acting jaw "
                "(one finger pressing the object against a jaw fixed to the "
                "palm) is not planned; place such a grasp yourself and judge it "
                "with analyze_grasp"
            )
        raise InvalidOptionError(
            f"min_fingers = {min_fingers} exceeds the hand's "
            f"{hand_model.num_fingers} fingers {fingers}{arm}"
        )
    return tilt, hand_model
