r"""Plan parallel-jaw grasps on an object body: sample, filter, close, rank.

:func:`plan_grasps` runs four stages; every sampled pose either becomes a
candidate or is counted under one rejection reason.

1. **Antipodal sampling** (numpy, all samples at once).  Surface points of the
   object's collision geometry with their outward normals ``n``, area-uniform
   (:mod:`drakegrasp.planning.surface`); the grasp axis runs along ``−n`` through
   the object, whose chord gives the opposite point and the width ``w``.  The
   axis is kept when ``w`` fits the gripper's stroke and the exit normal lies in
   the friction cone about the axis (the angle between them at most
   ``atan μ``).  A rotation about the axis, uniform in ``[0, 2π)``, sets the
   approach.  The gripper's grasp frame K (:mod:`drakegrasp.planning.gripper`)
   is put at the chord's midpoint with its x axis along the axis, and
   ``X_WH = X_WK X_HK⁻¹``; the pre-grasp opening is ``w`` plus twice
   ``clearance``, at most the stroke.
2. **Collision filter** (Drake).  The hand is placed open at ``X_WH``; any
   pair of a hand geometry and another geometry with signed distance below
   ``−distance_tolerance`` rejects the pose (object or rest of the scene).
3. **Closing** (Drake).  Each finger moves along the grasp axis by conservative
   advancement: by its smallest signed distance ``ψ`` to the geometry outside
   the hand minus ``tol / 2`` (a translation by ``ψ`` cannot penetrate), until
   ``ψ <= tol``; a finger that reaches its joint limit misses, one stopped by
   anything but the object is blocked.  The contacts are then those of
   :func:`~drakegrasp.find_contacts` (the same as :func:`~drakegrasp.analyze_grasp`
   reads on the applied candidate), and both fingers must touch.
4. **Ranking**: verdicts, ε and robustness in the batch engine
   (:mod:`drakegrasp.planning.ranking`), weight capacity in one LP per grasp
   (:mod:`drakegrasp.planning.weight`); the squeeze (or torque) that holds
   the weight ``m |g|``, ``|g|`` the magnitude of the plant's own gravity
   field, as :func:`~drakegrasp.analyze_grasp` weighs the object; for a
   multi-finger hand, whether its closing motions push the object one way
   (:mod:`drakegrasp.planning.opposition`).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import replace

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.tree import RigidBody

from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import ContactModel, missing_torsional_friction
from drakegrasp.core.tolerances import DEFAULT_DISTANCE_TOLERANCE
from drakegrasp.core.validation import (
    check_coefficient,
    check_distance_tolerance,
    check_flag,
    describe,
    real_scalar,
)
from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.planning.approach import sample_approaches
from drakegrasp.planning.candidates import (
    GraspCandidates,
    closing_order,
    planning_result,
)
from drakegrasp.planning.checks import (
    checked_count,
    checked_nonnegative,
    checked_samples,
)
from drakegrasp.planning.cloud import (
    CONTACT_BAND,
    PAD_CONTACT_BAND,
    CloudFingers,
    FittedCloud,
    cloud_surface,
    read_cloud_fit,
)
from drakegrasp.planning.cloud_hand import FAN_SIGMAS, CloudHand
from drakegrasp.planning.gripper import free_base, parallel_jaw
from drakegrasp.planning.motors import (
    _unit_of_joints,
    check_squeeze_limit,
    check_torque_limit,
    motor_names,
    with_squeeze_limit,
    with_squeeze_push,
    with_torques_needed,
)
from drakegrasp.planning.multifinger import (
    DEFAULT_TILT,
    checked_hand,
    close_candidates,
    close_each,
    hand_is_parallel_jaw,
)
from drakegrasp.planning.placement import (
    MAX_CLOSING_STEPS,
    BodyCloser,
    onto_coupling,
    sample_poses,
)
from drakegrasp.planning.ranking import (
    DEFAULT_NOISE,
    checked_noise,
    rank_candidates,
    rank_multifinger,
)
from drakegrasp.planning.surface import ObjectSurface, piece_of_shape
from drakegrasp.planning.turned_gravity import plant_gravity
from drakegrasp.planning.weight import centre_of_mass
from drakegrasp.plant.attachment import free_carrier, how_held
from drakegrasp.plant.couplings import plant_couplings
from drakegrasp.plant.fingers import find_joint, joint_name
from drakegrasp.plant.mesh_convexity import warn_if_not_convex
from drakegrasp.plant.validation import (
    HandSpec,
    hand_bodies,
    plant_context_of,
    resolve_grasped_body,
    resolve_object_body,
    scoped_name,
)

__all__ = [
    "MAX_CANDIDATES",
    "MAX_PLAN_MU",
    "OPEN_HAND_HINT",
    "OPEN_HAND_SHARE",
    "REASONS",
    "object_surface",
    "plan_grasps",
    "plan_multifinger",
    "plan_multifinger_cloud",
]

MAX_CANDIDATES = 1_000_000
"""Most poses one call samples (memory grows with it; call again for more)."""

MAX_PLAN_MU = 1e6
"""Largest friction coefficient a plan takes: its weight-capacity program
failed in the solver at 1e12 (a WSG-50 plan of the box), and plans at 100,
1e3, 1e4 and 1e6 gave the same best candidate."""


REASONS = {
    "occluded": "another part of the object lies outside the sampled point on the axis",
    "no opposite surface": "the axis leaves the object (cloud) without a far side",
    "wider than the stroke": "the object's chord is wider than the open gripper",
    "narrower than the stroke": "the chord is narrower than the closed gripper",
    "outside the friction cone": "the opposite normal leaves the cone about the axis",
    "hand collides with the object": "the open hand penetrates the object",
    "hand collides with the scene": "the open hand penetrates another body",
    "finger misses the object": "a finger reached its joint limit without touching",
    "finger blocked by the scene": "a finger touched another body first",
    "finger at its closed limit": "a finger touches within the contact "
    "tolerance of its joint's closed limit: it would press on the limit, not "
    "squeeze the object",
    "closing did not converge": f"more than {MAX_CLOSING_STEPS} closing steps",
    "one finger touches": "only one finger's geometry touches the object",
    "hand collides with the cloud": "a cloud point lies inside the open hand",
    "hand enters the unseen side": "the hand reaches behind a one-sided cloud",
    "coupled fingers out of their stroke": "a one-motor jaw's fingers, put back "
    "on their coupling, leave a joint's limits",
}
"""Every rejection reason, with what it means."""


def _mass_of(ctx, body, object_mass) -> float:
    """The mass planned for (kg): ``object_mass``, else the body's; NaN for none.

    A massless body (a URDF link without ``<inertial>``) has no weight to
    hold: its ``squeeze_needed`` and ``torque_needed`` are not computed (NaN,
    as on a point cloud without ``object_mass``), not 0.
    """
    if object_mass is not None:
        return float(object_mass)
    mass = body.get_mass(ctx)
    return mass if mass > 0 else float("nan")


def _weight(mass: float, g: float) -> float:
    """The weight planned for, ``m |g|`` (N); NaN for an unknown mass (NaN).

    ``g``: the magnitude of the plant's gravity field
    (:func:`~drakegrasp.planning.turned_gravity.plant_gravity`); 0 in a plant
    without gravity, whose weight is then 0 (nothing to hold).

    Raises
    ------
    ModelError
        The body's own mass weighs more than a float holds in the plant's
        gravity (a given ``object_mass`` is refused so before any work).
    """
    weight = mass * g
    if math.isinf(weight):
        raise ModelError(
            f"the object's mass, {mass:g} kg, weighs more than a float holds in "
            f"the plant's gravity, {g:g} m/s² (m g = inf N)"
        )
    return weight


@checked_call
def object_surface(plant, plant_context, object_body) -> ObjectSurface:
    """The object's collision geometry as convex pieces in its body frame O."""
    ctx = plant_context_of(plant, plant_context)
    body = resolve_object_body(plant, object_body)
    inspector = plant.get_geometry_query_input_port().Eval(ctx).inspector()
    pieces = []
    for g in plant.GetCollisionGeometriesForBody(body):
        shape, name = inspector.GetShape(g), inspector.GetName(g)
        pieces.append(piece_of_shape(shape, inspector.GetPoseInFrame(g), name))
        warn_if_not_convex(shape, name)
    return ObjectSurface.from_pieces(pieces)


def _check_count(value) -> int:
    n = checked_count("num_candidates", value)
    if n > MAX_CANDIDATES:
        raise InvalidOptionError(
            f"num_candidates must be in [0, {MAX_CANDIDATES}] (one call; call again "
            f"with another seed for more), got {value}"
        )
    return n


def _check_noise(noise) -> dict:
    """:data:`DEFAULT_NOISE` updated by ``noise`` (a dict of finite values >= 0)."""
    if noise is not None and not isinstance(noise, dict):
        raise InvalidOptionError(
            f"noise must be a dict of {sorted(DEFAULT_NOISE)} or None, got "
            f"{type(noise).__name__}"
        )
    noise = {**DEFAULT_NOISE, **(noise or {})}
    if set(noise) != set(DEFAULT_NOISE):
        raise InvalidOptionError(
            f"noise takes non-negative {sorted(DEFAULT_NOISE)}, got {noise!r}"
        )
    return checked_noise(noise, "noise[{!r}]")


def _check_positive(name: str, value, unit: str) -> float:
    value = real_scalar(name, value)
    if not 0 < value < np.inf:
        raise InvalidOptionError(
            f"{name} must be a finite number > 0 {unit}, got {value}"
        )
    return value


@checked_call
def plan_grasps(
    plant,
    plant_context,
    object_body,
    *,
    hand: HandSpec,
    num_candidates: int,
    mu: float,
    seed: int | None = None,
    contact_model: ContactModel | str = ContactModel.HARD_FINGER,
    torsional_friction: float | None = None,
    clearance: float = 5e-3,
    distance_tolerance: float = DEFAULT_DISTANCE_TOLERANCE,
    robustness_samples: int = 32,
    noise: dict | None = None,
    certify: int = 10,
    weight_check: int | None = None,
    workers: int | None = 1,
    progress: bool = False,
    point_cloud=None,
    cloud_normals=None,
    viewpoint=None,
    complete_unseen: bool = True,
    object_mass: float | None = None,
    torque_limit: float | None = None,
    squeeze_limit: float | None = None,
    preshape=None,
    synergy=None,
    synergy_range=(0.0, 1.0),
    approach=None,
    standoff=None,
    tilt: float = DEFAULT_TILT,
    min_fingers: int = 2,
) -> GraspCandidates:
    """Sample, filter, close and rank grasps of an object body.

    A parallel jaw (two prismatic fingers) gets antipodal grasps (this
    module); any other hand (the Allegro hand, a three-finger hand) takes the
    multi-finger route of :mod:`drakegrasp.planning.multifinger`: approach
    directions and palm stand-offs over the surface, a pre-shape, then
    :func:`~drakegrasp.close_hand`, ranked alike.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized, registered with a ``SceneGraph``; holds the hand (its base a
        free body), the object and anything else (a table, other objects).
        The magnitude ``|g|`` of its gravity field
        (``plant.gravity_field().gravity_vector()``, read once per call:
        :func:`~drakegrasp.planning.turned_gravity.plant_gravity`) weighs the
        object: ``squeeze_needed`` and ``torque_needed`` hold ``m |g|``, the
        weight :func:`~drakegrasp.analyze_grasp` (``load="gravity"``) puts on
        the same plant.  Its direction plays no part (the weight is held in
        every direction of
        :data:`~drakegrasp.planning.weight.WEIGHT_DIRECTIONS`).  A plant
        without gravity weighs nothing: every candidate's ``squeeze_needed``
        and ``torque_needed`` are 0 (no weight needs no effort), so none is
        ranked behind the others for needing more than the motors give; the
        scores (per newton of weight) are those of any other gravity.
        ``result.settings["gravity"]`` records it (m/s²).
    plant_context : Context
        The plant's context or its diagram's root.  The object's pose (and the
        scene's) is read from it; the hand's configuration is used as scratch
        and restored on return.
    object_body : RigidBody, BodyIndex, str or None
        The object to grasp (frame O): a body free to move in space (a free
        body, or one carried by a free body), apart from the hand; None with
        ``point_cloud``.
    hand : ModelInstanceIndex, str or iterable of RigidBody
        The hand, its base a free body: a parallel jaw (two prismatic
        fingers, see :mod:`drakegrasp.planning.gripper`) or a multi-finger
        hand (:mod:`drakegrasp.planning.approach`).
    num_candidates : int
        Poses to sample, ``0 <= num_candidates <= MAX_CANDIDATES``; each
        becomes a candidate or a counted rejection.
    mu : float
        Coulomb friction coefficient of the verdicts (and of the sampler's
        cone test); at most :data:`MAX_PLAN_MU`.
    seed : int, optional
        Seed of every random draw (sampling and robustness noise).  The same
        seed gives the same candidates.
    contact_model : {"hard_finger", "soft_finger", "frictionless"}, optional
    torsional_friction : float, optional
        ``ν`` of soft fingers.
    clearance : float, optional
        Gap (m) left on each side of the object by the pre-grasp opening.
    distance_tolerance : float, optional
        Contact and penetration tolerance (m), as in
        :func:`~drakegrasp.find_contacts`.
    robustness_samples : int, optional
        Perturbed copies per force-closure candidate (0: robustness 0).  The
        copies' points are bounded by
        :data:`~drakegrasp.planning.checks.MAX_COPY_BYTES`: a count over it
        for one candidate of two contacts (about 11 million) is refused here,
        and one over it for the candidates that close is refused when they
        are ranked.
    noise : dict, optional
        ``{"position": m, "angle_deg": deg, "friction": relative}``, each in
        ``[0, 1e6]`` (:data:`~drakegrasp.planning.checks.NOISE_MAX`); default
        :data:`~drakegrasp.planning.ranking.DEFAULT_NOISE`.  On an object body
        the object's pose error (translation, and rotation about the grasp
        axis), the jaws closing again on the moved object
        (:mod:`drakegrasp.planning.reclose`); on a cloud too, on the cloud's
        surface fitted where the jaws meet it
        (:class:`~drakegrasp.planning.cloud.FittedCloud`).
    certify : int, optional
        The best ``certify`` candidates also get the single-grasp verdict with
        its certificate (``GraspCandidate.closure``).
    weight_check : int or None, optional
        How many force-closure candidates get their weight capacity and a
        score: None (default) all of them with robustness > 0 (the score is
        robustness times capacity); a number limits the LPs (one per
        grasp) to the best by ``ε × robustness``, which is faster but may miss
        good grasps (see :mod:`drakegrasp.planning.ranking`).
    workers : int, optional
        Worker processes of the batch engine (default 1).
    progress : bool, optional
        A tqdm bar over the Drake stages (needs ``tqdm``).
    point_cloud : pydrake.perception.PointCloud or (M, 3) float, optional
        The object as a cloud in the world frame, with ``object_body=None``
        (:mod:`drakegrasp.planning.cloud`); the plant then holds the hand and
        the surroundings only.  The time grows with the cloud's size: on the
        shipped jaw and a box's cloud, 100 poses took 0.8 s at 30,000 points,
        2.9 s at 100,000 and 36 s at 1,000,000 (half of it estimating the
        normals; ``benchmarks/bench_cloud_size.py``).  A camera's cloud of
        several 100,000 points can be voxel-downsampled first
        (``PointCloud.VoxelizedDownSample``): the tests plan YCB objects from
        3,000-20,000 points.  So can scans merged as they are: each spot is
        then seen several times, and the cloud is planned on each spot's
        mean point, with a ``PointCloudWarning``
        (:data:`~drakegrasp.planning.cloud_spacing.TWIN_JUMP`).
    cloud_normals : (M, 3) float, optional
        Outward normals of the cloud's points; default the cloud's own, else
        estimated from the flattest nearby patch, plane or quadric, grown with
        the cloud's noise (:func:`~drakegrasp.planning.cloud_normals.estimate_normals`;
        the result's ``settings["cloud_normals"]`` says how: points a patch,
        the noise read, the normals' expected error; None when given).
    viewpoint : (3,) float, optional
        Where the cloud was seen from (normals are turned towards it); default
        normals point away from the cloud's centroid.
    complete_unseen : bool, optional
        With a ``viewpoint``: assume the object centrally symmetric and
        complete its unseen side by reflecting the seen one through the point
        its seen normals aim at
        (:func:`~drakegrasp.planning.cloud.complete_unseen`, reported in
        ``settings["unseen_completion"]``), so a multi-finger hand may wrap
        around it and parallel jaws may pinch across it, and plan on the
        whole cloud, its frame O (``X_WO``: the centre of mass of the weight
        capacity, ``squeeze_needed`` and the torque scale) at that centre of
        symmetry.  ``False`` keeps the hand
        on the seen side, O at the seen points' centroid, which lies towards
        the camera (by ``2r/π`` on a can of radius ``r``).  A face seen
        head-on gives no depth: nothing is completed, and an empty result's
        ``reason`` says so.
    object_mass : float, optional
        The object's mass (kg) for ``squeeze_needed`` and (multi-finger hands)
        ``torque_needed`` and the ranking by it; default the body's mass (a
        cloud has none, nor has a massless body: NaN, and neither is
        computed).  Finite and > 0, with
        a finite weight ``m |g|`` in the plant's gravity, else
        ``InvalidOptionError``.  A figure it
        makes that exceeds the largest float (``--mass 1.7e307``: 1.67e308 N
        over a capacity below 1) is ``inf`` beside a capacity > 0, and said
        "beyond float range" (:mod:`~drakegrasp.planning.needed`).
    torque_limit : float, optional
        Multi-finger hands with a known weight: the torque (N·m per motor; N
        for a prismatic one) you will apply when grasping.  The
        candidates whose ``torque_needed`` is at most this are ranked first
        (:func:`~drakegrasp.planning.motors.with_torques_needed`); capped by the
        actuators' effort limits, the default (an actuator applies no more).
        Give it when the hand will squeeze with less than its motors allow (a
        gentler controller, or the shake test's ``squeeze`` on a hand whose
        every joint is a motor), so the ranking
        assumes the torque actually applied.  Finite and > 0, else
        ``InvalidOptionError``, which a parallel jaw (no ``torque_needed``:
        its ``squeeze_needed`` is in N) and a point cloud without
        ``object_mass`` (no weight, no ``torque_needed``) raise too.
    squeeze_limit : float, optional
        Parallel jaws: the squeeze per finger (N) the jaw will apply.  The
        candidates whose ``squeeze_needed`` is at most this are ranked first,
        each group in score order
        (:func:`~drakegrasp.planning.motors.with_squeeze_limit`), and the
        result's ``reason`` says so when no force-closure candidate is;
        capped by the closing joints' effort limits, the default.  Finite and
        > 0, else ``InvalidOptionError``, which a multi-finger hand (give
        ``torque_limit``) and a point cloud without ``object_mass`` raise too.
    preshape, synergy, synergy_range, approach, standoff : optional
        Multi-finger hands only
        (:func:`~drakegrasp.planning.approach.multi_finger_hand`): the
        pre-shape over the closing joints (default the context's open hand;
        ``"open"``: the hand opened from there, each joint turned the way
        that parts the fingertips, to its limit or as far as that parts
        them: an angular gripper whose model's zero is nearly shut), a
        synergy direction and the range of
        its amount drawn per pose, the approach in the base frame H, the
        palm stand-off range (m).
    tilt : float, optional
        Multi-finger hands: largest tilt (rad) of the approach from the
        surface's inward normal.
    min_fingers : int, optional
        Multi-finger hands: fingers that must touch (at least 2).

    Returns
    -------
    GraspCandidates
        Ranked best first; ``rejections`` counts the other samples by reason
        (:data:`REASONS`); ``reason`` says why when it is empty.  A
        multi-finger hand's best force-closure candidates also carry
        ``squeeze_push``, and those whose closing motions all push the object
        one way come after the other checked ones
        (:func:`~drakegrasp.planning.motors.with_squeeze_push`); each
        candidate's ``concerns`` say what the plan expects to keep it from
        holding.

    Raises
    ------
    InvalidOptionError
        Bad options (``num_candidates`` negative, not an integer or above
        :data:`MAX_CANDIDATES`; ``mu`` negative...); ``object_body`` the world
        body or a body of the hand.
    ModelError
        A hand without a free base (welded or jointed to the world or to
        another body, its base not among ``hand``'s bodies, or bodies of
        several free bodies) or without fingers; an object without graspable
        collision geometry, one that is not free to move (welded or jointed
        to the world: it cannot be lifted), or one attached to the hand; a
        plant whose gravity is not finite, or in which the body's own mass
        weighs more than a float holds.
    """
    t0 = time.perf_counter()
    n = _check_count(num_candidates)
    mu = check_coefficient("mu", mu, error=InvalidOptionError)
    if mu > MAX_PLAN_MU:
        raise InvalidOptionError(
            f"mu = {mu:g} is above {MAX_PLAN_MU:g}, the largest friction the "
            "planner's programs resolve (at 1e12 its weight-capacity program "
            f"fails in the solver): plan with mu at most {MAX_PLAN_MU:g}"
        )
    tol = check_distance_tolerance(distance_tolerance)
    clearance = checked_nonnegative("clearance", clearance, "metres")
    complete_unseen = check_flag("complete_unseen", complete_unseen)
    progress = check_flag("progress", progress)
    seed = None if seed is None else checked_count("seed", seed)
    # a force-closure candidate has two contacts or more: copies that would
    # not fit for one are refused before any sampling
    robustness_samples = checked_samples(
        robustness_samples, 1, 2, name="robustness_samples"
    )
    certify = checked_count("certify", certify)
    min_fingers = checked_count("min_fingers", min_fingers, minimum=2)
    tilt = real_scalar("tilt", tilt)
    if not 0 <= tilt <= np.pi / 2:
        raise InvalidOptionError(f"tilt must be in [0, pi/2] radians, got {tilt!r}")
    if object_mass is not None:
        object_mass = _check_positive("object_mass", object_mass, "kg")
    if squeeze_limit is not None:
        squeeze_limit = check_squeeze_limit(squeeze_limit)
    if torque_limit is not None:
        torque_limit = check_torque_limit(torque_limit)
    for name, value, needed in (
        ("squeeze_limit", squeeze_limit, "squeeze_needed"),
        ("torque_limit", torque_limit, "torque_needed"),
    ):
        if value is not None and point_cloud is not None and object_mass is None:
            raise InvalidOptionError(
                f"{name} ranks by {needed}, which needs the object's weight: "
                "give object_mass= (kg) with a point_cloud"
            )
    noise = _check_noise(noise)
    if weight_check is not None:
        weight_check = checked_count("weight_check", weight_check)
    contact_model = ContactModel.parse(contact_model).value
    if torsional_friction is not None:  # checked, recorded as given
        check_coefficient(
            "torsional_friction", torsional_friction, error=InvalidOptionError
        )
    if contact_model == ContactModel.SOFT_FINGER.value and torsional_friction is None:
        raise missing_torsional_friction(InvalidOptionError)
    ctx = plant_context_of(plant, plant_context)
    g = plant_gravity(plant)  # |g|, m/s²: the weight per kg, as analyze_grasp's
    if object_mass is not None and not math.isfinite(object_mass * g):
        raise InvalidOptionError(  # every figure would be inf
            f"object_mass = {object_mass:g} kg weighs more than a float holds "
            f"(m g = inf N at the plant's gravity, {g:g} m/s²)"
        )
    q_planned = plant.GetPositions(ctx).copy()  # the joints not closed stay here
    if (object_body is None) == (point_cloud is None):
        raise InvalidOptionError(
            "give the object either as object_body or as point_cloud= with "
            "object_body=None (got "
            + ("neither" if object_body is None else "both")
            + ")"
        )
    settings = {
        "seed": seed,
        "contact_model": contact_model,
        "torsional_friction": torsional_friction,
        "clearance": clearance,
        "distance_tolerance": tol,
        "robustness_samples": robustness_samples,
        "noise": noise,
        "gravity": g,  # |g| (m/s²) the weight was taken at, for the shake to match
    }
    if object_mass is not None:
        settings["object_mass"] = object_mass  # the weight planned for, to shake
    if torque_limit is not None:
        settings["torque_limit"] = torque_limit
    if squeeze_limit is not None:
        settings["squeeze_limit"] = squeeze_limit
    multi = dict(
        preshape=preshape, synergy=synergy, synergy_range=synergy_range,
        approach=approach, standoff=standoff, tilt=tilt, min_fingers=min_fingers,
        torque_limit=torque_limit,
    )  # fmt: skip
    if point_cloud is None:
        body = _graspable(plant, object_body, hand)
        if not hand_is_parallel_jaw(plant, ctx, body, hand):
            _jaw_only(squeeze_limit)
            mass = _mass_of(ctx, body, object_mass)
            result = plan_multifinger(
                plant, ctx, body, hand=hand, n=n, mu=mu,
                rng=np.random.default_rng(seed),
                surface=object_surface(plant, ctx, body), settings=settings, t0=t0,
                name=scoped_name(plant, body), certify=certify, workers=workers,
                progress=progress, weight=_weight(mass, g), **multi,
            )  # fmt: skip
            closing = result.settings["hand"]["joints"]
            return _finished(mass, result, plant, q_planned, body, hand, closing)
        _multifinger_only(multi)
        gripper = parallel_jaw(plant, ctx, body, hand)
        surface = object_surface(plant, ctx, body)
        X_WO = plant.EvalBodyPoseInWorld(ctx, body)
        reference = centre_of_mass(ctx, body, surface)
        name = scoped_name(plant, body)
        mass = _mass_of(ctx, body, object_mass)
        weight = _weight(mass, g)
    else:
        body = None
        # a hand that cannot be placed is refused before the cloud is read
        free_base(plant, hand_bodies(plant, plant.world_body(), hand), hand=hand)
        points, normals, dropped, fit = read_cloud_fit(
            point_cloud, cloud_normals, viewpoint=viewpoint
        )
        settings.update(cloud_normals=fit)
        if not hand_is_parallel_jaw(plant, ctx, plant.world_body(), hand):
            _jaw_only(squeeze_limit)
            mass = np.nan if object_mass is None else float(object_mass)
            settings.update(cloud_dropped=dropped)
            result = plan_multifinger_cloud(
                plant, ctx, hand=hand, points=points, normals=normals,
                viewpoint=viewpoint, n=n, mu=mu, rng=np.random.default_rng(seed),
                settings=settings, t0=t0, certify=certify, workers=workers,
                progress=progress, weight=_weight(mass, g), complete=complete_unseen,
                **multi,
            )  # fmt: skip
            closing = result.settings["hand"]["joints"]
            world = plant.world_body()
            return _finished(mass, result, plant, q_planned, world, hand, closing)
        _multifinger_only(multi)
        gripper = parallel_jaw(plant, ctx, plant.world_body(), hand)
        surface, completion = cloud_surface(points, normals, viewpoint, complete_unseen)
        X_WO = RigidTransform(surface.origin)
        reference = np.zeros(3)  # the cloud's centre, the assumed centre of mass
        name = "point cloud"
        mass = np.nan if object_mass is None else float(object_mass)
        weight = _weight(mass, g)
        settings.update(
            cloud_points=len(points),
            cloud_dropped=dropped,
            line_radius=surface.line_radius,
            contact_band=PAD_CONTACT_BAND,
            unseen_completion=completion,
        )
    settings["gripper"] = gripper.to_dict()
    torque_scale = surface.radius_about(reference)
    rng = np.random.default_rng(seed)
    poses, rejections = sample_poses(
        surface, gripper, X_WO, n, mu=mu, clearance=clearance, rng=rng, tol=tol
    )
    saved = plant.GetPositions(ctx).copy()
    closer = BodyCloser(plant, ctx, body, hand, gripper, tol)
    cloud = None
    if body is None:
        cloud = CloudFingers(
            plant,
            ctx,
            gripper,
            closer.hand_instance_bodies,
            surface,
            tol,
            PAD_CONTACT_BAND,
        )
    sure = np.zeros(len(poses["sample"]), bool)
    if cloud is None:  # penetrations certain without Drake: rejected at once
        sure = closer.sure_collisions(poses, surface, X_WO)
        if sure.any():
            rejections["hand collides with the object"] += int(sure.sum())
    order = closing_order(len(poses["sample"]), progress)
    kept = []
    try:
        for k in order:
            if sure[k]:
                continue
            X_WH = RigidTransform(RotationMatrix(poses["R_WH"][k]), poses["p_WH"][k])
            opening = float(poses["opening"][k])
            if cloud is None:
                found, q, reason, X_WH = _close_on_body(closer, X_WH, opening)
            else:
                found, q, reason, X_WH = _close_on_cloud(closer, cloud, X_WH, opening)
            if reason is not None:
                rejections[reason] += 1
                continue
            kept.append((int(poses["sample"][k]), X_WH, q, opening, found))
    finally:
        plant.SetPositions(ctx, saved)
    kept = closer.finish(kept, rejections)  # every closed pose's contacts at once
    candidates = rank_candidates(
        kept, finger_names=closer.finger_names, gripper=gripper, plant=plant, mu=mu,
        contact_model=contact_model, nu=torsional_friction, torque_scale=torque_scale,
        samples=robustness_samples, noise=noise, rng=rng, certify=certify,
        workers=workers, X_WO=X_WO, weight=weight, weight_check=weight_check,
        surface=FittedCloud(surface) if body is None else surface, tol=tol,
        reference=reference,
    )  # fmt: skip
    result = planning_result(
        candidates,
        rejections=rejections,
        num_sampled=n,
        object_body=name,
        mu=mu,
        torque_scale=torque_scale,
        settings=settings,
        started=t0,
    )
    result = with_squeeze_limit(result, plant, top=certify, squeeze_limit=squeeze_limit)
    anchor = plant.world_body() if body is None else body
    closing = [joint_name(plant, j) for j in gripper.joints]
    result = _finished(mass, result, plant, q_planned, anchor, hand, closing)
    return replace(result, time=time.perf_counter() - t0)


def _finished(
    mass: float, result: GraspCandidates, plant, q_planned, anchor, hand, closing
) -> GraspCandidates:
    """``result`` whose candidates record their mass and the hand's held joints.

    The held joints are the one-dof joints that move a body of the hand
    (:func:`~drakegrasp.plant.validation.hand_bodies`) and are not closed.

    ``mass``: the kg planned for; ``q_planned``: the plant's positions when
    the plan began (the planner keeps the joints it does not close there);
    ``anchor``: the object body, or the world body on a cloud; ``closing``:
    the scoped names of the hand's closing joints (each candidate's
    ``joint_names``, whose kinds set each one's ``torque_unit``, a jaw's
    too, and its ``motors``).  A joint that a coupling ties to a closing
    joint moved with it: it is not held.  The names of the joints held with
    ``closing`` go to ``settings["held_joints"]``, so that a result without
    candidates still knows its table's held-joint columns.
    """
    bodies = {int(b.index()) for b in hand_bodies(plant, anchor, hand)}
    joints = [plant.get_joint(j) for j in plant.GetJointIndices()]
    values = [
        (scoped_name(plant, j), float(q_planned[j.position_start()]))
        for j in joints
        if j.num_positions() == 1 and int(j.child_body().index()) in bodies
    ]

    links = _coupling_links(plant)
    moved: dict[tuple[str, ...], set[str]] = {}

    def held(names: tuple[str, ...]) -> tuple[tuple[str, float], ...]:
        if names not in moved:  # the closing joints and their couplings'
            moved[names] = _linked(set(names), links)
        return tuple(pair for pair in values if pair[0] not in moved[names])

    found: dict[tuple[str, ...], tuple[str, ...]] = {}

    def motors(names: tuple[str, ...]) -> tuple[str, ...]:
        if names not in found:
            try:
                found[names] = motor_names(plant, names)
            except InvalidOptionError:  # constraints drakegrasp was not told of
                found[names] = ()
        return found[names]

    mass = float(mass)
    return replace(
        result,
        candidates=tuple(
            replace(
                c,
                object_mass=mass,
                held_joints=held(c.joint_names),
                torque_unit=_unit_of_joints(plant, c.joint_names),
                motors=motors(c.joint_names),
            )
            for c in result.candidates
        ),
        settings={
            **result.settings,
            "held_joints": [name for name, _ in held(tuple(closing))],
        },
    )


def _coupling_links(plant) -> dict[str, set[str]]:
    """Each coupled joint's scoped name → the joints a coupling ties it to."""
    try:
        couplings = plant_couplings(plant)
    except InvalidOptionError:  # couplings drakegrasp was not told of: none
        return {}
    links: dict[str, set[str]] = {}
    for entry in couplings:
        a, b = (scoped_name(plant, find_joint(plant, j)) for j in entry[:2])
        links.setdefault(a, set()).add(b)
        links.setdefault(b, set()).add(a)
    return links


def _linked(names: set[str], links: dict[str, set[str]]) -> set[str]:
    """``names`` and every joint their couplings tie them to, however far."""
    found, todo = set(names), list(names)
    while todo:
        for other in links.get(todo.pop(), ()):
            if other not in found:
                found.add(other)
                todo.append(other)
    return found


def _graspable(plant, object_body, hand) -> RigidBody:
    """The object's body, once it is known that the hand can pick it up.

    The object must be free to move in space (a free body, or carried by
    one), apart from the hand, and the hand a free base that carries its
    fingers (:func:`~drakegrasp.planning.gripper.free_base`): a planner that
    ranks grasps by the weight they lift and by how they survive the
    object's pose error has nothing to say about an object welded to the
    world or jointed to it (a fixture, a drawer), nor about one the hand
    carries already.
    """
    body = resolve_grasped_body(plant, object_body)
    bodies = hand_bodies(plant, body, hand)  # refuses an object of the hand
    name = scoped_name(plant, body)
    carrier = free_carrier(plant, body)
    if carrier is None:
        held = how_held(plant, body)
        what = "weld" if held.startswith("welded") else "joint"
        raise ModelError(
            f"object_body {name} is {held}: no grasp can lift it, so the "
            "planner's holds (weight held, robustness to the object's pose) would "
            f"mean nothing; plan on a free object: load it without that {what} "
            "(in a scene, default_free_body_pose instead of add_weld)"
        )
    base = free_base(plant, bodies, hand=hand)
    if carrier.index() == base.index():
        raise ModelError(
            f"object_body {name} is attached to the hand: it rides on the hand's "
            f"base {scoped_name(plant, base)}; plan on a free object, apart from "
            "the hand"
        )
    return body


_MULTI_FINGER_DEFAULTS = {
    "preshape": None,
    "synergy": None,
    "synergy_range": (0.0, 1.0),
    "approach": None,
    "standoff": None,
    "tilt": DEFAULT_TILT,
    "min_fingers": 2,
    "torque_limit": None,
}
"""The options of :func:`plan_grasps` that only a multi-finger hand reads, and
their defaults (a parallel jaw refuses any other value)."""


def _multifinger_only(given: dict) -> None:
    """A parallel jaw takes none of the multi-finger options: say so.

    ``given`` maps each option of :data:`_MULTI_FINGER_DEFAULTS` to its
    value; one that is not its default is refused (a parallel jaw opens fully
    along its stroke and approaches along the chord: a pre-shape, synergy,
    approach, stand-off, tilt or finger count would be ignored without a
    word).
    """
    for name, default in _MULTI_FINGER_DEFAULTS.items():
        value = given[name]
        if not _is_default(value, default):
            remedy = (
                "a parallel jaw's squeeze_needed is in N per finger: give "
                "squeeze_limit instead"
                if name == "torque_limit"
                else f"a parallel jaw opens fully and closes along its chord: "
                f"leave {name} out"
            )
            raise InvalidOptionError(
                f"{name} applies to multi-finger hands; {remedy} (got "
                f"{describe(value)})"
            )


def _jaw_only(squeeze_limit) -> None:
    """A multi-finger hand takes no ``squeeze_limit``: say so."""
    if squeeze_limit is not None:
        raise InvalidOptionError(
            "squeeze_limit applies to parallel jaws (N per finger); a "
            "multi-finger hand's fingers apply joint torques: give torque_limit "
            "(N·m per motor, N at a prismatic one) instead (got "
            f"{squeeze_limit!r})"
        )


def _is_default(value, default) -> bool:
    """Whether ``value`` is ``default`` (None, or equal numbers)."""
    if default is None or value is None:
        return value is default
    try:
        return bool(np.array_equal(np.asarray(value, float), np.asarray(default)))
    except Exception:  # noqa: BLE001 - unreadable (a raising dunder): not the default
        return False


def _close_on_body(closer: BodyCloser, X_WH, opening):
    """Stages 2-3 on the object body: (contacts, q, reason, X_WH)."""
    return closer.close_on_body(X_WH, opening)


def _close_on_cloud(closer: BodyCloser, cloud: CloudFingers, X_WH, opening):
    """Stages 2-3 on a cloud: (contacts, q, reason, X_WH).

    A coupled jaw's fingers are put back on their coupling as on a body
    (:func:`~drakegrasp.planning.placement.onto_coupling`): the pads, and so
    the cloud points they touch, stay where they stopped.
    """
    q_open = closer.g.q_for_opening(opening)
    reason = closer.clear_at(X_WH, q_open)
    if reason is not None:
        return None, None, reason, X_WH
    if cloud.collides():
        return None, None, "hand collides with the cloud", X_WH
    if cloud.in_shadow():
        return None, None, "hand enters the unseen side", X_WH
    q, travel_hits, reason = cloud.close(X_WH, q_open)
    if reason is not None:
        return None, None, reason, X_WH
    coupled = closer.g.coupling is not None
    if coupled:
        X_WH, q = onto_coupling(closer.g, X_WH, q)
        if q is None:
            return None, None, "coupled fingers out of their stroke", X_WH
    if np.min(closer.g.travel_left(q)) <= closer.tol:
        return None, None, "finger at its closed limit", X_WH
    if closer.clear_at(X_WH, q) is not None:  # puts the hand at X_WH, q
        return None, None, "finger blocked by the scene", X_WH
    if coupled and cloud.collides():  # the palm moved along the axis
        return None, None, "hand collides with the cloud", X_WH
    if cloud.in_shadow():
        return None, None, "hand enters the unseen side", X_WH
    found = cloud.contacts(travel_hits)
    if found is None:
        return None, None, "one finger touches", X_WH
    return found, q, None, X_WH


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
    if not candidates and _opens_too_little(rejections, num_sampled):
        result = dataclasses.replace(result, reason=result.reason + OPEN_HAND_HINT)
    return result


_OPEN_HAND_COLLIDES = ("hand collides with the object", "hand collides with the cloud")

OPEN_HAND_SHARE = 0.9
"""Share of the sampled poses that must collide as placed for
:data:`OPEN_HAND_HINT` (a hand shut at its pre-shape also misses the object
from a few poses: 94 collided and 6 missed of an SDH-like hand's 100)."""

OPEN_HAND_HINT = (
    "; the open hand collides nearly wherever it is placed: open it "
    "(preshape='open', or joint values) or move the palm back (standoff=)"
)
"""Added to an empty result's reason when nearly every pose collided as placed."""


def _opens_too_little(rejections: dict, num_sampled: int) -> bool:
    """True when at least :data:`OPEN_HAND_SHARE` of the poses collided as placed."""
    collided = sum(n for why, n in rejections.items() if why in _OPEN_HAND_COLLIDES)
    return num_sampled > 0 and collided >= OPEN_HAND_SHARE * num_sampled


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
    tilt, hand_model = checked_hand(
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
    result = with_torques_needed(
        result, plant, ctx, body, weight=weight, top=certify, started=t0,
        torque_limit=torque_limit,
    )  # fmt: skip
    return with_squeeze_push(result, plant, ctx, body, top=certify, started=t0)


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
    tilt, hand_model = checked_hand(
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
    result = with_torques_needed(
        result, plant, ctx, None, weight=weight, top=certify, started=t0,
        torque_limit=torque_limit,
    )  # fmt: skip
    return with_squeeze_push(result, plant, ctx, None, top=certify, started=t0)
