r"""Plan multi-finger grasps: approach, pre-shape, ``close_hand``, rank.

The route :func:`~drakegrasp.planning.planner.plan_grasps` takes for a hand
that is not a parallel jaw (the Allegro hand, drakegrasp's three-finger hand,
a user's).  Every sampled pose becomes a candidate or is counted under one
rejection reason (:data:`REASONS`).

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

On a point cloud (:func:`plan_multifinger_cloud`), stages 2 and 3 are those
of :mod:`drakegrasp.planning.cloud_hand` (the hand against the cloud's points,
the fingers closed onto them); stage 1 is the same, and in stage 4 the weight
capacity of a candidate with a contact at an edge of the cloud is averaged
over the edge's normal fan (:func:`fan_capacity`); the torque needed (with
``object_mass``) takes each contact's finger point at its cloud point.
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from collections import Counter

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix

from drakegrasp.core.deprecation import keyword_only, renamed_keyword
from drakegrasp.core.validation import real_array, unit_vectors
from drakegrasp.errors import (
    InvalidContactError,
    InvalidOptionError,
    ModelError,
    NoContactsError,
    PenetrationError,
    UnreachableError,
)
from drakegrasp.planning.approach import (
    MultiFingerHand,
    multi_finger_hand,
    sample_approaches,
)
from drakegrasp.planning.candidates import (
    closing_order,
    planning_result,
)
from drakegrasp.planning.centring import CentredCloser, chain_groups
from drakegrasp.planning.checks import (
    checked_contacts,
    checked_fingers,
    checked_friction,
    checked_palm,
    checked_rng,
    checked_samples,
    checked_torque_scale,
)
from drakegrasp.planning.cloud import CONTACT_BAND, cloud_surface
from drakegrasp.planning.cloud_hand import FAN_SIGMAS, CloudHand
from drakegrasp.planning.motors import with_torques_needed
from drakegrasp.planning.ranking import (
    group_by_count,
    grouped_verdicts,
    ranked_candidates,
    robustness,
    tie_key,
)
from drakegrasp.planning.weight import centre_of_mass, weight_capacity
from drakegrasp.plant._closing_steps import closest
from drakegrasp.plant.closing import close_checked_hand
from drakegrasp.plant.contacts import find_contacts
from drakegrasp.plant.couplings import plant_couplings
from drakegrasp.plant.fingers import finger_chains, hand_structure, passive_joints
from drakegrasp.plant.validation import hand_bodies, scoped_name

__all__ = [
    "DEFAULT_TILT",
    "OPEN_HAND_HINT",
    "REASONS",
    "PassiveJointWarning",
    "close_candidates",
    "fan_capacity",
    "hand_is_parallel_jaw",
    "is_parallel_jaw",
    "plan_multifinger",
    "plan_multifinger_cloud",
    "rank_multifinger",
]


class PassiveJointWarning(UserWarning):
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


def hand_is_parallel_jaw(plant, plant_context, object_body, hand) -> bool:
    """Whether ``hand`` is two fingers of one prismatic joint each (in the plant)."""
    bodies = hand_bodies(plant, object_body, hand)
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


def _labels(found, label, palm) -> list[int]:
    return [label.get(c.finger_body, palm) for c in found]


def _has_fan(found) -> bool:
    return any(getattr(c, "fan", None) is not None for c in found)


def _fans(found) -> np.ndarray:
    """(N, 2, 3) fan ends per contact, NaN where a contact has none."""
    out = np.full((len(found), 2, 3), np.nan)
    for j, c in enumerate(found):
        if getattr(c, "fan", None) is not None:
            out[j] = c.fan
    return out


def _slerp(a: np.ndarray, b: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Unit vectors a fraction ``t`` along the great-circle arcs from ``a`` to ``b``.

    ``a``, ``b`` : (..., 3) unit; ``t`` : (...) in [0, 1].  Where ``a = b`` (or
    opposite: no unique arc) the result is ``a``.
    """
    cos = np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)
    omega = np.arccos(cos)
    sin = np.sin(omega)
    ok = sin > 1e-9
    safe = np.where(ok, sin, 1.0)
    wa = np.where(ok, np.sin((1.0 - t) * omega) / safe, 1.0)
    wb = np.where(ok, np.sin(t * omega) / safe, 0.0)
    return wa[..., None] * a + wb[..., None] * b


@keyword_only("mu", after=4)
@renamed_keyword("model", "contact_model")
def fan_capacity(
    positions, normals, fans, fingers, *, mu, samples, rng, torque_scale, contact_model,
    torsional_friction, palm=None,
):  # fmt: skip
    r"""(K,) weight capacity of grasps whose edge contacts' normals are unknown.

    On a point cloud a contact at an edge (a fold of the sampled surface,
    where the finger meets two faces) has no one normal the cloud can tell:
    the true contact normal lies between the faces' normals, set by where
    the finger sits on the edge to a fraction of a millimetre (on 3,000
    points of the YCB soup can, the true can's normal differed from the
    cloud's by more than 30° at 20 of 113 contacts, all within 3 mm of a
    rim).  Each such contact carries its *fan*, the arc of normals from
    ``a`` to ``b``
    (:class:`~drakegrasp.planning.cloud.CloudContact`); the capacity is the
    mean, over ``samples`` copies, of the worst-direction weight capacity
    (:func:`~drakegrasp.planning.weight.weight_capacity`) with each edge
    contact's normal drawn uniformly along its arc,
    :math:`\hat n = \mathrm{slerp}(a, b, t)`, :math:`t \sim U(0, 1)`, one
    draw per contact and copy (a copy that is not force closure holds 0).

    Parameters
    ----------
    positions, normals : (K, N, 3) float
        Contacts (m, finite) and inward normals (finite, non-zero; normalised
        here), frame O.
    fans : (K, N, 2, 3) float
        Each contact's fan ends (inward normals, finite and non-zero;
        normalised here), all NaN for a contact without one (its normal
        stays).
    fingers : (K, N) int
        Finger labels (the palm ``F``), as for ``weight_capacity``.
    mu : float
        0 or in ``[1e-12, 1e12]``, as for ``weight_capacity``.
    samples : int
        Copies per grasp (the robustness samples), an integer ``>= 0``; 0
        gives the nominal capacity.  The copies' points (``K * samples * N *
        3`` floats) at most :data:`~drakegrasp.planning.checks.MAX_COPY_BYTES`.
    rng : numpy.random.Generator
        Draws the fans' normals (only with ``samples > 0``).
    torque_scale, contact_model, torsional_friction, palm
        As for :func:`~drakegrasp.planning.weight.weight_capacity`.

    Returns
    -------
    (K,) float
        Newtons of weight held per newton of squeeze on each finger.

    Raises
    ------
    GraspError
        An argument out of its range, naming it (checked before any draw).
    """
    positions, normals = checked_contacts(positions, normals)
    K, N, _ = positions.shape
    fans = _checked_fans(fans, (K, N, 2, 3))
    fingers = checked_fingers(fingers, (K, N))
    mu, contact_model, torsional_friction = checked_friction(
        mu, contact_model, torsional_friction
    )
    samples = checked_samples(samples, K, N)
    rng = checked_rng(rng)
    torque_scale = checked_torque_scale(torque_scale, positions)  # before any draw
    palm = checked_palm(palm)
    S = max(samples, 1)
    has = np.all(np.isfinite(fans), axis=(2, 3))  # (K, N)
    t = rng.uniform(size=(K, S, N)) if samples else np.zeros((K, S, N))
    drawn = _slerp(fans[:, None, :, 0], fans[:, None, :, 1], t)  # (K, S, N, 3)
    Nrm = np.where(has[:, None, :, None], drawn, normals[:, None])
    if not samples:
        Nrm = np.broadcast_to(normals[:, None], Nrm.shape)
    alpha = weight_capacity(
        np.repeat(positions, S, axis=0), Nrm.reshape(K * S, N, 3),
        np.repeat(fingers, S, axis=0), mu=mu, torque_scale=torque_scale,
        contact_model=contact_model, torsional_friction=torsional_friction,
        palm=palm,
    ).min(axis=1)  # fmt: skip
    return np.where(np.isfinite(alpha), alpha, 0.0).reshape(K, S).mean(axis=1)


def _checked_fans(fans, shape: tuple) -> np.ndarray:
    """``fans`` of :func:`fan_capacity`: unit ends, or all NaN (no fan)."""
    a = real_array("fans", fans)
    if a.shape != shape:
        raise InvalidContactError(
            f"fans must have shape (K, N, 2, 3) = {shape}, two ends per contact, "
            f"got shape {a.shape}"
        )
    none = np.all(np.isnan(a), axis=(2, 3))[..., None, None]  # (K, N, 1, 1)
    try:  # each end a contact normal: the message names grasp, contact, end
        ends = unit_vectors("fans", np.where(none, 1.0, a))
    except InvalidContactError as err:
        raise InvalidContactError(
            f"{err}; a contact without a fan has both ends all NaN"
        ) from None
    return np.where(none, np.nan, ends)


@renamed_keyword("model", "contact_model")
def rank_multifinger(
    kept, *, label, hand: MultiFingerHand, plant, mu, contact_model, nu, torque_scale,
    samples, noise, rng, certify, workers, X_WO, weight, reference,
):  # fmt: skip
    """Stage 4: verdicts, ε, robustness, weight capacity, score; ranked candidates.

    ``label`` maps a finger body's scoped name to its finger; other hand
    bodies (the palm) are labelled ``F``, the number of fingers.  Moments are
    about ``reference`` ((3,) in O, metres), where the weight acts.
    """
    if not kept:
        return ()
    F = hand.num_fingers
    counts = np.array([len(k[4]) for k in kept])
    K = len(kept)
    rho = np.zeros(K)
    alpha = np.full(K, np.nan)
    verdict, groups = grouped_verdicts(
        kept, lambda found: _labels(found, label, F), mu=mu,
        torque_scale=torque_scale, contact_model=contact_model, nu=nu,
        workers=workers, reference=reference,
    )  # fmt: skip
    is_closure, d_star, rank, eps = verdict.values()
    for idx, P, Nrm, L, fc in groups:
        closed = idx[fc]
        if len(closed):
            rho[closed] = robustness(
                P[fc] - reference, Nrm[fc], L[fc], mu=mu, samples=samples,
                rng=rng, noise=noise, contact_model=contact_model,
                torsional_friction=nu, workers=workers, groups=tuple(range(F)),
            )  # fmt: skip
            alpha[closed] = weight_capacity(
                P[fc] - reference, Nrm[fc], L[fc], mu=mu,
                torque_scale=torque_scale, contact_model=contact_model,
                torsional_friction=nu, palm=F,
            ).min(axis=1)  # fmt: skip
    fanned = np.flatnonzero(
        np.isfinite(alpha) & (rho > 0) & [_has_fan(k[4]) for k in kept]
    )
    for idx in group_by_count(counts[fanned]).values():
        rows = fanned[idx]
        alpha[rows] = fan_capacity(
            np.array([[c.p_OC for c in kept[i][4]] for i in rows]) - reference,
            np.array([[c.nhat_O for c in kept[i][4]] for i in rows]),
            np.array([_fans(kept[i][4]) for i in rows]),
            np.array([_labels(kept[i][4], label, F) for i in rows]),
            mu=mu, samples=samples, rng=rng, torque_scale=torque_scale,
            contact_model=contact_model, torsional_friction=nu, palm=F,
        )  # fmt: skip
    score = np.where(np.isfinite(alpha), alpha * rho, 0.0)
    sample = np.array([k[0] for k in kept])
    order = np.lexsort((sample, -tie_key(d_star), -tie_key(eps * rho), -tie_key(score)))
    s = hand.structure
    base = scoped_name(plant, hand.base)
    scores = {
        "is_closure": is_closure, "d_star": d_star, "rank": rank, "eps": eps,
        "rho": rho, "score": score, "alpha": alpha,
    }  # fmt: skip

    def pose(i: int) -> dict:
        k, X_WH, q_pre, q, found = kept[i]
        return dict(
            sample=int(k), hand_base=base, X_WH=X_WH, X_WO=X_WO,
            q_hand=np.asarray(q, float), joint_names=s.names,
            closing_signs=tuple(float(v) for v in np.sign(q - q_pre)),
            opening=float("nan"), contacts=tuple(found),
            q_preshape=np.asarray(q_pre, float), reference_point=reference.copy(),
            torque_scale=float(torque_scale),
        )  # fmt: skip

    return ranked_candidates(
        order, scores, pose, weight=weight, certify=certify, mu=mu,
        contact_model=contact_model, nu=nu,
    )  # fmt: skip


def _ranked_result(
    kept, *, label, hand_model, plant, mu, settings, torque_scale, rng, certify,
    workers, X_WO, weight, rejections, num_sampled, object_body, started,
    reference,
):  # fmt: skip
    """Both routes' last stage: the kept closings ranked, as GraspCandidates."""
    candidates = rank_multifinger(
        kept, label=label, hand=hand_model, plant=plant, mu=mu,
        contact_model=settings["contact_model"], nu=settings["torsional_friction"],
        torque_scale=torque_scale, samples=settings["robustness_samples"],
        noise=settings["noise"], rng=rng, certify=certify, workers=workers,
        X_WO=X_WO, weight=weight, reference=reference,
    )  # fmt: skip
    result = planning_result(
        candidates,
        rejections=rejections,
        num_sampled=num_sampled,
        object_body=object_body,
        mu=mu,
        torque_scale=torque_scale,
        settings=settings,
        started=started,
    )
    collided = sum(n for why, n in rejections.items() if why in _OPEN_HAND_COLLIDES)
    if not candidates and num_sampled and collided == num_sampled:
        result = dataclasses.replace(result, reason=result.reason + OPEN_HAND_HINT)
    return result


_OPEN_HAND_COLLIDES = ("hand collides with the object", "hand collides with the cloud")

OPEN_HAND_HINT = (
    "; the open hand collides wherever it is placed: open it wider "
    "(preshape=) or move the palm back (standoff=)"
)
"""Added to an empty result's reason when every pose collided as placed."""


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
        stacklevel=4,
    )


def _checked_hand(
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


def plan_multifinger(
    plant, ctx, body, *, hand, n, mu, rng, surface, settings, t0, name,
    preshape=None, synergy=None, synergy_range=(0.0, 1.0), approach=None,
    standoff=None, tilt=DEFAULT_TILT, min_fingers=2, certify=10, workers=1,
    progress=False, weight=None, torque_limit=None,
):  # fmt: skip
    """The multi-finger route of :func:`~drakegrasp.planning.planner.plan_grasps`.

    Called by ``plan_grasps`` once the options are checked (``settings`` holds
    them); ``weight`` is the object's weight (N), ``torque_limit`` the
    torque applied (N·m, None: the effort limits).  Returns its
    :class:`~drakegrasp.planning.candidates.GraspCandidates`.
    """
    tilt, hand_model = _checked_hand(
        plant, ctx, body, hand, tilt=tilt, min_fingers=min_fingers,
        preshape=preshape, synergy=synergy, synergy_range=synergy_range,
        approach=approach, standoff=standoff,
    )  # fmt: skip
    settings = {**settings, "hand": hand_model.to_dict(), "tilt": tilt,
                "min_fingers": int(min_fingers)}  # fmt: skip
    X_WO = plant.EvalBodyPoseInWorld(ctx, body)
    reference = centre_of_mass(ctx, body, surface)
    torque_scale = surface.radius_about(reference)
    poses = sample_approaches(surface, hand_model, X_WO, n, rng, tilt)
    saved = plant.GetPositions(ctx).copy()
    try:
        kept, rejections, label = close_candidates(
            plant, ctx, body, hand, hand_model, poses, settings["distance_tolerance"],
            progress, min_fingers,
        )  # fmt: skip
    finally:
        plant.SetPositions(ctx, saved)
    result = _ranked_result(
        kept, label=label, hand_model=hand_model, plant=plant, mu=mu,
        settings=settings, torque_scale=torque_scale, rng=rng, certify=certify,
        workers=workers, X_WO=X_WO, weight=weight, rejections=rejections,
        num_sampled=n, object_body=name, started=t0, reference=reference,
    )  # fmt: skip
    return with_torques_needed(
        result, plant, ctx, body, weight=weight, top=certify, started=t0,
        torque_limit=torque_limit,
    )  # fmt: skip


def plan_multifinger_cloud(
    plant, ctx, *, hand, points, normals, viewpoint, n, mu, rng, settings, t0,
    preshape=None, synergy=None, synergy_range=(0.0, 1.0), approach=None,
    standoff=None, tilt=DEFAULT_TILT, min_fingers=2, certify=10, workers=1,
    progress=False, weight=float("nan"), complete=True, torque_limit=None,
):  # fmt: skip
    """The multi-finger cloud route of :func:`~drakegrasp.planning.planner.plan_grasps`.

    Called by ``plan_grasps`` with the cloud read
    (:func:`~drakegrasp.planning.cloud.read_cloud`: world frame, outward unit
    normals) and the options checked (``settings``); ``weight`` is the
    object's weight (N, NaN when unknown), ``torque_limit`` the torque
    applied (N·m, None: the effort limits).  With a ``viewpoint`` and
    ``complete`` the unseen side is the seen one reflected through the
    object's estimated centre (:func:`~drakegrasp.planning.cloud.complete_unseen`,
    an assumption: a centrally symmetric object), and the hand may reach
    around the object but not into it.  Returns its
    :class:`~drakegrasp.planning.candidates.GraspCandidates`.
    """
    tilt, hand_model = _checked_hand(
        plant, ctx, plant.world_body(), hand, tilt=tilt, min_fingers=min_fingers,
        preshape=preshape, synergy=synergy, synergy_range=synergy_range,
        approach=approach, standoff=standoff,
    )  # fmt: skip
    surface, completion = cloud_surface(points, normals, viewpoint, complete)
    X_WO = RigidTransform(surface.origin)
    settings = {
        **settings,
        "hand": hand_model.to_dict(),
        "tilt": tilt,
        "min_fingers": int(min_fingers),
        "cloud_points": len(points),
        "contact_band": CONTACT_BAND,
        "unseen_completion": completion,
    }
    torque_scale = surface.radius_about(np.zeros(3))
    poses = sample_approaches(surface, hand_model, X_WO, n, rng, tilt)
    saved = plant.GetPositions(ctx).copy()
    closer = CloudHand(
        plant, ctx, hand_model, surface, settings["distance_tolerance"], min_fingers,
        completed=surface.viewpoint is None and completion is not None,
        fan_reach=FAN_SIGMAS * settings["noise"]["position"],
    )  # fmt: skip
    try:
        kept, rejections, label = close_each(closer, poses, progress)
    finally:
        plant.SetPositions(ctx, saved)
    result = _ranked_result(
        kept, label=label, hand_model=hand_model, plant=plant, mu=mu,
        settings=settings, torque_scale=torque_scale, rng=rng, certify=certify,
        workers=workers, X_WO=X_WO, weight=weight, rejections=rejections,
        num_sampled=n, object_body="point cloud", started=t0,
        reference=np.zeros(3),
    )  # fmt: skip
    # no object body: each contact's finger point is its cloud point
    return with_torques_needed(
        result, plant, ctx, None, weight=weight, top=certify, started=t0,
        torque_limit=torque_limit,
    )  # fmt: skip
