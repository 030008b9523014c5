r"""What a hand's motors must apply to hold the object's weight: torque, squeeze.

A parallel jaw's motor sets a squeeze, so :mod:`~drakegrasp.planning.weight`
bounds each finger's normal forces.  A hand with revolute fingers sets joint
torques instead, each capped by its actuator's effort limit (the Allegro
hand's 0.7 N·m), and a fingertip far from its knuckles presses with less force
for the same torque.  For a candidate with hand Jacobian ``J`` (contact frames,
finger joints only: the hand's base is placed and held, so nothing bounds its
wrench) the **torque capacity** in a weight direction ``u`` is

.. math::

    \beta(u) = \max \beta \;\text{s.t.}\;
    G f + \beta \begin{bmatrix} u \\ 0 \end{bmatrix} = 0,\quad
    f \in \text{the polyhedral cones},\quad
    |(J^\top f)_j| \le 1 \;\text{(every finger joint } j\text{)},

the weight (N) held along ``u`` per N·m allowed at every finger joint, moments
about the candidate's ``reference_point`` (the object's centre of mass, where
its weight acts).  A hand whose joints are not each a motor is held to the
motors it has: with a ``<mimic>`` follower moving as ``v_h = C u``
(:func:`~drakegrasp.plant.couplings.coupling_map`) the rows are those of
``(J C)ᵀ f``, each within ``Σ_k |C_ki| a_k`` for ``a_k`` 1 at an actuated
joint and 0 at one without an actuator (a follower's torque then comes
through the coupling from its leader's motor, as Drake's coupler constraint
carries it); ``β`` is then per N·m at every actuator.  The **motors** are
these: the actuated closing joints, each driving its followers (the 2F-85's
one motor closes six joints), or, in a model that declares no actuators,
every closing joint but a hidden drive (whose followers count in its
stead).  By linearity the hand holds a weight ``m g`` in every one of the
directions :data:`~drakegrasp.planning.weight.WEIGHT_DIRECTIONS` when each
motor may apply :math:`m g / \min_u \beta(u)`: the **torque needed**.  Like the squeeze
needed, it is a lower bound for the planned contacts held still (rigid,
quasi-static): the program shares the torques among the contacts at will, and a
real finger presses as its controller dictates.  It is an estimate of what a
simulation needs, not a bound on it: an independent simulation of the Allegro
hand on the YCB soup can (SAP, 1 ms, PD joints capped at the torque, the weight
in each of the 14 directions; review r22) found the can settling 1-9 mm under
the squeeze and touching links the plan did not list, so that ranks 7-20 held
every direction at 0.8 times their torque needed while ranks 1-4 failed one to
four directions at 1.2 times theirs.  Confirm a choice with
:func:`~drakegrasp.planning.shake.shake_test`.

All directions of a candidate are one LP (through drakegrasp's solver
gateway), about 3 ms for the Allegro hand (5 ms with its Jacobian); the tests
check it against :func:`~drakegrasp.closure.payload.max_load`, direction by
direction.

On a point cloud there is no object body: each contact names its finger body
and carries its cloud point, which lies on the finger within the distance
tolerance, so the finger's point is that point seen from the finger with the
candidate applied to the hand (``object_body=None``; frame O is the
candidate's ``X_WO``).  On the same contacts given both ways the two routes
agree to 3 % (the finger's witness point and the object's lie up to the
tolerance apart), and exactly with the finger's points.

When the weight is known (an object body's mass, or ``object_mass=``),
:func:`with_torques_needed` computes it for the best :data:`TORQUE_CHECK`
candidates and ranks those the hand's actuators hold (``torque_needed`` at
most the smallest effort limit of the candidate's joints) ahead of the rest;
``plan_grasps(..., torque_limit=)`` puts the torque the user will apply (N·m,
capped by the effort limit) in the limit's place, and each checked candidate
records the limit its figure was held to (``torque_limit``).
:func:`with_squeeze_push` then gives the same head :func:`squeeze_push`, how
one way the hand's closing motions push the object
(:mod:`~drakegrasp.planning.opposition`), and ranks those that push one way
after every other force-closure candidate: the squeeze carries such a grasp
out of the hand before any load, whatever its torque.

**A parallel jaw** presses each finger with at most its actuator's effort
limit (N), so :func:`with_squeeze_limit` ranks the candidates whose
``squeeze_needed`` is within it first, in the same way, and says so when none
is; ``plan_grasps(..., squeeze_limit=)`` puts the squeeze the user will apply
in the limit's place.  Checked in Drake (``benchmarks/bench_jaw_squeeze.py``:
Drake's Franka hand, 20 N fingers, the top six on three YCB objects planned
at the plant's μ = 1, each shaken at a multiple of its own figure, capped at
20 N): at 0.5 times none of 18 held, at 0.8 times 1, at 1 times 11 and at 1.5
times 16.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.solvers import MathematicalProgram
from scipy.linalg import block_diag

from drakegrasp._solvers import require_solution, solve
from drakegrasp.closure.load_problem import effort_unit_of
from drakegrasp.closure.verdicts import force_closure
from drakegrasp.core.friction_cone import friction_cone_generators
from drakegrasp.core.grasp import grasp_matrix
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import check_flag, describe, real_scalar
from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning.candidates import GraspCandidate, GraspCandidates
from drakegrasp.planning.checks import checked_count, checked_directions
from drakegrasp.planning.needed import (
    beyond_float_range,
    needed_for,
    needed_text,
    per_motor,
)
from drakegrasp.planning.opposition import (
    SQUEEZE_PUSH_MAX,
    closing_directions,
    squeeze_push_of,
)
from drakegrasp.planning.weight import WEIGHT_DIRECTIONS, palm_faces, palm_rows
from drakegrasp.plant.couplings import coupling_map, motor_shares, plant_couplings
from drakegrasp.plant.fingers import effort_unit, find_joint, hidden_drives
from drakegrasp.plant.jacobians import contact_rows, hand_jacobian
from drakegrasp.plant.validation import (
    plant_context_of,
    resolve_body,
    resolve_object_body,
)

TORQUE_CHECK = 50
"""How many of the best candidates get ``torque_needed`` (the force-closure
ones) when the object's weight is known: enough that the re-ranking of
:func:`with_torques_needed` finds candidates the motors hold beyond the
``certify`` head (about 5 ms each for the Allegro hand)."""

BETA_CAP = 1e6
"""Bound on ``β(u)`` (N per N·m) that keeps the program bounded; reaching it
reads as ``inf`` (no finger joint bounds the load: contacts on the palm)."""

__all__ = [
    "BETA_CAP",
    "TORQUE_CHECK",
    "check_squeeze_limit",
    "check_torque_limit",
    "finger_jacobian",
    "motor_limit",
    "motor_names",
    "squeeze_push",
    "torque_capacity",
    "torque_needed",
    "with_squeeze_limit",
    "with_squeeze_push",
    "with_torques_needed",
]


def finger_jacobian(plant, plant_context, candidate: GraspCandidate, object_body):
    """``J`` of a candidate over its finger joints, at the candidate's pose.

    Parameters
    ----------
    plant : MultibodyPlant
        The plant the candidate was planned in.
    plant_context : Context
        Its context (or the diagram's root context); left as it was.
    candidate : GraspCandidate
    object_body : RigidBody, BodyIndex, str or None
        The object (frame O); put at the candidate's planned pose.  None for a
        candidate planned on a point cloud (frame O is then the candidate's
        ``X_WO``, the cloud's frame): each contact's point on its
        finger is the contact's point, ``p_FC = X_WF⁻¹ X_WO p_OC``, with the
        candidate applied to the hand.

    Returns
    -------
    (M, n_j) float
        Rows in the contact frames of ``candidate.grasp`` (its components),
        columns the candidate's joints (``candidate.joint_names``), m/s per
        rad/s (or per m/s for a prismatic finger).
    """
    if not isinstance(candidate, GraspCandidate):
        raise InvalidOptionError(
            f"candidate must be a GraspCandidate of plan_grasps, got "
            f"{type(candidate).__name__}"
        )
    ctx = plant_context_of(plant, plant_context)
    body = None if object_body is None else resolve_object_body(plant, object_body)
    joints = [find_joint(plant, name) for name in candidate.joint_names]
    columns = np.array([j.velocity_start() for j in joints], dtype=int)
    saved = plant.GetPositions(ctx).copy()
    try:
        candidate.apply(plant, ctx, object_body=body)
        if body is None:
            return _cloud_finger_jacobian(plant, ctx, candidate, columns)
        return hand_jacobian(
            plant, ctx, candidate.contacts, candidate.grasp, body,
            velocity_indices=columns,
        )  # fmt: skip
    finally:
        plant.SetPositions(ctx, saved)


def _cloud_finger_jacobian(plant, ctx, candidate: GraspCandidate, columns):
    """``J`` (M, n_j) of a point-cloud candidate, the candidate applied in ``ctx``.

    A cloud contact names its finger body and carries the cloud point
    ``p_OC`` (frame O = ``candidate.X_WO``), which lies on the finger within
    the distance tolerance: the finger's point ``C`` is taken there,
    ``p_FC = X_WF⁻¹ X_WO p_OC``.  Each row block is the translational velocity
    of ``C`` (fixed in F) in the world, expressed in O and then in the
    contact's frame ``[n, t1, t2]`` (a soft finger adds the normal component
    of F's angular velocity), as :func:`~drakegrasp.plant.jacobians.hand_jacobian`
    builds it on a body.
    """
    R_OW = candidate.X_WO.rotation().matrix().T
    blocks = []
    for pc, c in zip(candidate.contacts, candidate.grasp.contacts, strict=True):
        finger = resolve_body(plant, pc.finger_body)
        X_WF = plant.EvalBodyPoseInWorld(ctx, finger)
        p_FC = X_WF.inverse().multiply(candidate.X_WO.multiply(pc.p_OC))
        Jv = R_OW @ plant.CalcJacobianTranslationalVelocity(
            ctx, JacobianWrtVariable.kV, finger.body_frame(), p_FC,
            plant.world_frame(), plant.world_frame(),
        )[:, columns]  # fmt: skip

        def angular(finger=finger):
            return R_OW @ plant.CalcJacobianAngularVelocity(
                ctx, JacobianWrtVariable.kV, finger.body_frame(),
                plant.world_frame(), plant.world_frame(),
            )[:, columns]  # fmt: skip

        blocks.append(contact_rows(c, Jv, pc.nhat_O, angular))
    grasp = candidate.grasp
    return np.vstack(blocks).reshape(grasp.num_components, len(columns))


def torque_capacity(
    plant,
    plant_context,
    candidate: GraspCandidate,
    object_body,
    *,
    directions: np.ndarray = WEIGHT_DIRECTIONS,
) -> np.ndarray:
    """``β(u)`` per direction: weight held per N·m at every motor.

    Parameters
    ----------
    plant, plant_context, candidate, object_body
        As for :func:`finger_jacobian`.
    directions : (D, 3) float, optional
        Weight directions in frame O, ``D >= 1`` real, finite, non-zero rows
        of any magnitude (normalised here, as
        :func:`~drakegrasp.planning.weight.weight_capacity` does:
        :func:`~drakegrasp.planning.checks.checked_directions`); default the
        14 of the weight capacity.

    Returns
    -------
    (D,) float
        N per N·m (N per N for prismatic fingers); 0 where the grasp cannot
        hold a weight along the direction at all, ``inf`` where no joint bounds
        it (contacts on the palm alone, say).

    Raises
    ------
    InvalidOptionError
        ``directions`` not as above (not real, not ``(D, 3)``, a row not
        finite or zero), naming ``directions``; checked before the plant is
        read.

    Notes
    -----
    One program for all directions (their blocks share nothing, so maximising
    ``Σ β(u)`` maximises each): the contact forces are the cones' generators
    ``f = S λ``, ``λ >= 0`` (eight per Coulomb cone, the default of the
    verdicts), and :data:`BETA_CAP` keeps it bounded.

    A contact that no finger joint moves (its rows of ``J`` zero: the palm)
    is passive, as in :func:`~drakegrasp.planning.weight.weight_capacity`
    (``palm=``): each face of the palm pushes only while, and only as hard
    as, the load and the contacts' normal forces press the object into it
    (the best over the sets of faces that do); the friction of a finger
    cannot buy it a push.
    """
    u = checked_directions("directions", directions)
    J = finger_jacobian(plant, plant_context, candidate, object_body)
    grasp = candidate.grasp
    blocks = [
        friction_cone_generators(
            c, DEFAULT_NUM_GENERATORS, characteristic_length=grasp.characteristic_length
        )
        for c in grasp.contacts
    ]
    S = block_diag(*blocks)
    slices = grasp.component_slices()
    palm = np.array([not np.any(J[sl]) for sl in slices])
    motors = _motor_map(plant, candidate)
    bound = None
    if motors is not None:  # a coupled or partly passive hand: its motors' axes
        C, bound = motors
        J = J @ C
    GS, TS = grasp_matrix(grasp) @ S, J.T @ S
    if not palm.any():
        b = _torque_lp(GS, TS, u, bound=bound)
    else:
        # each generator's contact and normal force
        owner = np.repeat(np.arange(len(blocks)), [b.shape[1] for b in blocks])
        normal = S[grasp.normal_indices()].sum(axis=0)  # (n,)
        # one row per distinct palm normal e (a face), for the faces that
        # carry force: Σ_j (n_j·e) f_n,j + β (u·e) <= 0; the best over them
        a, c, face, _ = palm_rows(grasp.normals[None], palm[None].astype(int), 1, 1, u)
        per_generator = face[0][owner]
        b = np.zeros(len(u))
        for active in palm_faces(a.shape[1]):
            idle = (per_generator >= 0) & ~np.isin(per_generator, active)
            row = (a[0][active][:, owner] * normal, c[0][active]) if active else None
            b = np.maximum(b, _torque_lp(GS, TS, u, idle=idle, row=row, bound=bound))
    return np.where(b >= BETA_CAP * (1 - 1e-6), np.inf, b)


def _motor_map(plant, candidate: GraspCandidate):
    """``(C, w)`` of a hand whose joints are not each a motor, or None.

    ``C`` (n_j, n_u) maps the independent coordinates' velocities onto the
    candidate's joints (:func:`~drakegrasp.plant.couplings.coupling_map`: a
    ``<mimic>`` follower moves with its leader); ``w`` (n_u,) is how many N·m
    each coordinate's generalized force ``(J C)ᵀ f`` may carry per N·m allowed
    at every actuator: ``|C|ᵀ a``, ``a_k`` 1 for a joint with an actuator and
    0 for one without (a follower's torque comes through its coupling; an
    unactuated, uncoupled joint is passive).  A hand without any actuator on
    its joints (or on a leader of theirs) says nothing of its motors: each
    joint counts as one, but a hidden drive (its followers count in its
    stead, as in its twin whose motor sits on a finger), whatever actuators
    the plant's other models have (:func:`_motor_flags`).  None when every
    joint is its own motor (``C = I``, ``w = 1``).
    """
    joints = [find_joint(plant, name) for name in candidate.joint_names]
    columns = np.array([j.velocity_start() for j in joints], dtype=int)
    couplings = plant_couplings(plant)
    C, _ = coupling_map(plant, columns, couplings)
    a = _motor_flags(plant, candidate.joint_names, couplings).astype(float)
    if C.shape[0] == C.shape[1] and np.all(a == 1.0):
        return None
    return C, np.abs(C).T @ a


def _motor_flags(plant, joint_names, couplings=None) -> np.ndarray:
    """(n,) bool: which of ``joint_names`` the torque LP takes as a motor.

    A hand with an actuator on one of ``joint_names`` or on a joint that
    leads one of them (a jaw's hidden drive): the joints with one.  A hand
    without any says nothing of its motors (whatever the plant's other
    models have): each joint counts as one, but a hidden drive, whose
    followers count in its stead.  ``couplings``: the plant's
    (:func:`~drakegrasp.plant.couplings.plant_couplings`), read when None.
    """
    if couplings is None:
        couplings = plant_couplings(plant)
    names = tuple(joint_names)
    own = _actuated(plant, names)
    if own.any() or _actuated(plant, _outside_leaders(names, couplings)).any():
        return own
    drives = hidden_drives(plant, couplings)  # a hidden drive touches nothing
    return np.array([n not in drives for n in names], dtype=bool)


def _actuated(plant, names) -> np.ndarray:
    """(n,) bool: which of the joints ``names`` has an actuator."""
    return np.array(
        [bool(_actuators(plant, find_joint(plant, n))) for n in names], dtype=bool
    )


def _outside_leaders(names: tuple[str, ...], couplings) -> tuple[str, ...]:
    """The joints not in ``names`` that lead one of them, once each, in order.

    Any leader, one with geometry too, where :func:`motor_limit` reads the
    motors of a hidden drive alone: a candidate cut down to followers whose
    leaders' motors lie outside it is a hand with motors, its followers
    passive (``tests/planning/test_coupled_hand.py``), not a hand without
    actuators whose every joint counts as a motor.
    """
    inside = set(names)
    return tuple(
        dict.fromkeys(
            leader
            for follower, leader, _, _ in couplings
            if follower in inside and leader not in inside
        )
    )


def motor_names(plant, joint_names) -> tuple[str, ...]:
    """The motors of the hand whose closing joints are ``joint_names``.

    ``torque_needed`` and ``torque_limit`` are per motor: a joint with an
    actuator of ``plant``.  A ``<mimic>`` follower without an actuator of its
    own turns with its leader's motor and is not one (the Robotiq-2F-85's
    six closing joints have one motor); a leader outside ``joint_names``
    with an actuator is one (a jaw whose fingers follow a hidden drive).
    A hand none of whose joints has an actuator has no motor known: ()
    (its ``torque_needed`` then takes one at each joint but a hidden drive,
    :func:`torque_capacity`).

    Parameters
    ----------
    plant : MultibodyPlant
        The plant of the hand (finalized).
    joint_names : sequence of str
        Scoped names (``"model::joint"``) of one-dof joints of ``plant``: a
        candidate's ``joint_names``.

    Returns
    -------
    tuple of str
        The motors' scoped names: the leaders outside ``joint_names`` first,
        then those of ``joint_names``, in its order.

    Raises
    ------
    InvalidOptionError
        A name that is not a joint of ``plant``, or constraints drakegrasp
        was not told of (:func:`~drakegrasp.plant.couplings.plant_couplings`).
    """
    names = tuple(joint_names)
    every = (*_outside_leaders(names, plant_couplings(plant)), *names)
    return tuple(
        n for n, motor in zip(every, _actuated(plant, every), strict=True) if motor
    )


def _torque_lp(GS, TS, u, *, idle=None, row=None, bound=None) -> np.ndarray:
    """``β`` per direction of :func:`torque_capacity`'s program (clipped at 0).

    ``idle``: generators held at zero (the palm's); ``row``: ``(a, c)``
    ((R, n), (R, D)) adds ``a_r·λ <= c_rk β_k`` to direction ``k``'s block
    (the passive palm's rows); ``bound`` (n_u,): each row of ``TS`` within
    ``±bound`` instead of ``±1`` (:func:`_motor_map`).
    """
    D, n = len(u), GS.shape[1]
    prog = MathematicalProgram()
    lam = prog.NewContinuousVariables(n, D, "lambda")
    beta = prog.NewContinuousVariables(D, "beta")
    upper = np.full(n, np.inf) if idle is None else np.where(idle, 0.0, np.inf)
    prog.AddBoundingBoxConstraint(np.zeros(n * D), np.repeat(upper, D), lam.reshape(-1))
    prog.AddBoundingBoxConstraint(0.0, BETA_CAP, beta)
    limit = np.ones(len(TS)) if bound is None else np.asarray(bound, float)
    for k in range(D):
        load = np.concatenate([u[k], np.zeros(3)])
        prog.AddLinearEqualityConstraint(
            np.hstack([GS, load[:, None]]), np.zeros(6), np.append(lam[:, k], beta[k])
        )
        prog.AddLinearConstraint(TS, -limit, limit, lam[:, k])
        if row is not None:
            a, c = row
            prog.AddLinearConstraint(
                np.hstack([a, -c[:, k : k + 1]]), np.full(len(a), -np.inf),
                np.zeros(len(a)), np.append(lam[:, k], beta[k]),
            )  # fmt: skip
    prog.AddLinearCost(-np.ones(D), 0.0, beta)
    result = require_solution(
        prog, solve(prog, "lp", retry=True), "the torque-capacity LP"
    )
    return np.clip(result.GetSolution(beta), 0.0, None)


def torque_needed(
    plant, plant_context, candidate: GraspCandidate, object_body, *, weight: float
) -> float:
    """The torque (N·m per motor) that holds ``weight`` in every direction.

    Parameters
    ----------
    plant, plant_context, candidate, object_body
        As for :func:`finger_jacobian`.
    weight : float
        The object's weight ``m g`` (N).

    Returns
    -------
    float
        ``weight / min_u β(u)`` over the 14 weight directions
        (:func:`~drakegrasp.planning.needed.needed_for`): ``inf`` when some
        direction cannot be held, and where the quotient exceeds the largest
        float (``min_u β(u) > 0``: the candidate's ``torque_capacity`` tells
        the two apart); NaN for a NaN weight (a point cloud without
        ``object_mass``).
    """
    return _torque_figures(plant, plant_context, candidate, object_body, weight)[1]


def _torque_figures(
    plant, plant_context, candidate, object_body, weight
) -> tuple[float, float]:
    """``(min_u β(u), torque needed)`` of a candidate (see :func:`torque_needed`)."""
    weight = real_scalar("weight", weight)
    if math.isnan(weight):
        return math.nan, math.nan
    if not math.isfinite(weight) or weight < 0:
        raise InvalidOptionError(
            f"weight must be finite and >= 0 (N), got {describe(weight)}"
        )
    beta = float(np.min(torque_capacity(plant, plant_context, candidate, object_body)))
    return beta, needed_for(weight, beta)


def with_torques_needed(
    result: GraspCandidates,
    plant,
    plant_context,
    object_body,
    *,
    weight: float,
    top: int,
    started: float,
    check: int = TORQUE_CHECK,
    motors_first: bool = True,
    torque_limit: float | None = None,
) -> GraspCandidates:
    """``result`` with :func:`torque_needed` on its best candidates, re-ranked.

    Each checked candidate records the unit of its figures too
    (``torque_unit``: N·m, N where its closing joints slide).

    Parameters
    ----------
    result : GraspCandidates
        Ranked by score (:func:`~drakegrasp.planning.ranking.rank_multifinger`).
    plant, plant_context, object_body
        As for :func:`finger_jacobian` (``object_body`` None on a point cloud).
    weight : float
        The object's weight ``m g`` (N); NaN (a cloud without ``object_mass``)
        leaves ``result`` as it is.
    top : int
        The ``certify`` of the run: the best ``top`` candidates carry the
        single-grasp verdict (``closure``), after the
        re-ranking too.
    started : float
        The run's ``time.perf_counter()`` at its start, so ``result.time``
        counts this stage.
    check : int, optional
        The first ``max(top, check)`` candidates get ``torque_needed`` (the
        force-closure ones: the others hold no weight in some direction), about
        5 ms each for the Allegro hand.
    motors_first : bool, optional
        Put the checked candidates that the hand's actuators hold
        (``torque_needed <=`` the smallest effort limit of the candidate's
        joints, :func:`motor_limit`) ahead of all others, each group in its
        score order.  Nothing moves when the plant gives no finite limit.
    torque_limit : float or None, optional
        The torque (N·m per motor; N for a prismatic one) the user will
        apply, used instead of :func:`motor_limit` for ``motors_first`` and
        the ``reason``; capped by the effort limit (an actuator applies no
        more).  None (default): the effort limit.  Finite and > 0, else
        ``InvalidOptionError``.

    Returns
    -------
    GraspCandidates
        With ``reason`` saying so when no checked candidate is held by the
        actuators; each checked candidate records the limit its figure was
        held to (``torque_limit``, where a finite one is known).
    """
    if torque_limit is not None:
        torque_limit = check_torque_limit(torque_limit)
    if math.isnan(weight):
        return result
    n = max(int(top), int(check))

    def with_torque(c: GraspCandidate) -> GraspCandidate:
        beta, needed = _torque_figures(plant, plant_context, c, object_body, weight)
        unit = _unit_of_joints(plant, c.joint_names)  # what __str__ says it in
        return dataclasses.replace(
            c, torque_capacity=beta, torque_needed=needed, torque_unit=unit
        )

    head = [with_torque(c) if c.is_closure else c for c in result.candidates[:n]]
    ranked = [*head, *result.candidates[n:]]
    limit = motor_limit(plant, ranked[0]) if ranked else math.inf
    applied = torque_limit is not None and torque_limit < limit
    if applied:
        limit = torque_limit
    unit = _unit_of_joints(plant, ranked[0].joint_names) if ranked else "N·m"
    if math.isfinite(limit):  # what each checked candidate's figure was held to
        ranked = [
            c if math.isnan(c.torque_needed) else dataclasses.replace(
                c, torque_limit=float(limit)
            )
            for c in ranked
        ]  # fmt: skip
    reason = (
        result.reason
        or _too_weak(head, limit, applied, unit)
        or _no_limit(
            plant, ranked, limit, "torque_needed", "torque_limit", per_motor(unit)
        )
    )
    settings = result.settings
    if motors_first:
        ranked = _held_first(ranked, "torque_needed", limit, top)
        settings = _with_held_first(
            settings, ranked, "torque_needed", limit, unit, applied, torque_limit
        )
    return dataclasses.replace(
        result,
        candidates=tuple(ranked),
        reason=reason,
        time=time.perf_counter() - started,
        settings=settings,
    )


def _with_held_first(settings, ranked, needed, limit, unit, applied, given) -> dict:
    """``settings`` with ``"held_first"``: the limit the ranking put first.

    ``{"needed", "limit", "unit", "source", "held"}``: the figure compared,
    the limit it was compared with, whose limit it is ("effort limit", or the
    user's value, noting a cap), and how many candidates are within it.
    Nothing is added when no finite limit is known.
    """
    if not math.isfinite(limit):
        return settings
    if applied:
        source = f"{needed.replace('_needed', '_limit')} given"
    elif given is not None:
        source = (
            f"effort limit ({needed.replace('_needed', '_limit')} {given:g} "
            "capped at it)"
        )
    else:
        source = "effort limit"
    held = sum(1 for c in ranked if getattr(c, needed) <= limit)
    entry = dict(needed=needed, limit=float(limit), unit=unit, source=source,
                 held=held)  # fmt: skip
    return {**settings, "held_first": entry}


def squeeze_push(plant, plant_context, candidate: GraspCandidate, object_body) -> float:
    """How one way a candidate's closing motions push the object, in ``[0, 1]``.

    :func:`~drakegrasp.planning.opposition.squeeze_push_of` of the directions
    in which closing moves each contact's finger point
    (:func:`~drakegrasp.planning.opposition.closing_directions` of the hand
    Jacobian :func:`finger_jacobian` at the candidate's pose, each joint
    closing the way ``closing_signs`` says; a contact closing does not move
    pushes back along its normal).  0: the motions oppose one another; 1:
    all push one way, and the squeeze may push the object out of the hand.

    Parameters
    ----------
    plant, plant_context, candidate, object_body
        As for :func:`finger_jacobian` (``object_body`` None on a point
        cloud); the context is left as it was.

    Returns
    -------
    float

    Raises
    ------
    InvalidOptionError
        ``candidate`` is not a :class:`GraspCandidate`, or a planar one.
    """
    J = finger_jacobian(plant, plant_context, candidate, object_body)
    contacts = candidate.grasp.contacts
    frames = np.array([c.frame for c in contacts])
    counts = [c.num_components for c in contacts]
    return squeeze_push_of(
        closing_directions(J, frames, counts, candidate.closing_signs)
    )


def with_squeeze_push(
    result: GraspCandidates,
    plant,
    plant_context,
    object_body,
    *,
    top: int,
    started: float,
    check: int = TORQUE_CHECK,
    push_last: bool = True,
) -> GraspCandidates:
    """A multi-finger ``result`` with :func:`squeeze_push` on its best candidates.

    The force-closure candidates among the first ``max(top, check)`` (those
    :func:`with_torques_needed` checks) get ``squeeze_push``.  With
    ``push_last``, those above
    :data:`~drakegrasp.planning.opposition.SQUEEZE_PUSH_MAX` move after every
    other force-closure candidate, ahead of those that are not force
    closure, each group keeping its order (the motors-first order of
    :func:`with_torques_needed`, then the score): in Drake the squeeze
    pushed such grasps out of the hand while seating, before any load, at
    any torque (:mod:`~drakegrasp.planning.opposition`).  A candidate past
    the head is not checked, and stays in its group.

    Parameters
    ----------
    result : GraspCandidates
        A multi-finger hand's candidates, ranked.
    plant, plant_context, object_body
        As for :func:`finger_jacobian` (``object_body`` None on a point cloud).
    top : int
        The ``certify`` of the run: the first ``top`` candidates after the
        re-ranking carry the single-grasp verdict (``closure``).
    started : float
        The run's ``time.perf_counter()`` at its start (``result.time``
        counts this stage).
    check : int, optional
        How deep the head goes (default :data:`TORQUE_CHECK`).
    push_last : bool, optional
        Move the candidates that push one way after the rest of the head
        (default); False records the figure only.

    Returns
    -------
    GraspCandidates
        ``settings["pushed_last"]`` records ``bound``, ``checked`` (candidates
        given the figure) and ``count`` (above the bound); ``reason`` says so
        when every checked candidate pushes one way (and no other reason is
        given).

    Raises
    ------
    InvalidOptionError
        ``result`` is not a :class:`GraspCandidates`, ``top`` or ``check`` not
        an integer >= 0, ``started`` not a real number, or ``push_last`` not
        a bool.
    """
    if not isinstance(result, GraspCandidates):
        raise InvalidOptionError(
            f"result must be the GraspCandidates of plan_grasps, got {describe(result)}"
        )
    top, check = checked_count("top", top), checked_count("check", check)
    started = real_scalar("started", started)
    push_last = check_flag("push_last", push_last)
    n = max(top, check)
    head = [
        dataclasses.replace(
            c, squeeze_push=squeeze_push(plant, plant_context, c, object_body)
        )
        if c.is_closure
        else c
        for c in result.candidates[:n]
    ]
    ranked = [*head, *result.candidates[n:]]
    checked = [c for c in head if not math.isnan(c.squeeze_push)]
    pushing = [c for c in checked if c.squeeze_push > SQUEEZE_PUSH_MAX]
    if push_last and pushing:
        ranked = sorted(
            ranked,
            key=lambda c: (not c.is_closure, c.squeeze_push > SQUEEZE_PUSH_MAX),
        )
    ranked = _certified(ranked, top)
    reason = result.reason
    if not reason and checked and len(pushing) == len(checked):
        least = min(c.squeeze_push for c in pushing)
        reason = (
            f"the closing motions of every one of the {len(checked)} best "
            "force-closure candidates push the object one way (squeeze_push > "
            f"{SQUEEZE_PUSH_MAX:g}, at least {least:.2f}): "
            "the squeeze may push it out of the hand; try a pre-shape that "
            "opposes a finger to the others (a thumb), or more samples"
        )
    settings = result.settings
    if push_last:
        settings = {
            **settings,
            "pushed_last": dict(
                bound=SQUEEZE_PUSH_MAX, checked=len(checked), count=len(pushing)
            ),
        }
    return dataclasses.replace(
        result,
        candidates=tuple(ranked),
        reason=reason,
        settings=settings,
        time=time.perf_counter() - started,
    )


def with_squeeze_limit(
    result: GraspCandidates,
    plant,
    *,
    top: int,
    squeeze_limit: float | None = None,
) -> GraspCandidates:
    """A parallel jaw's ``result`` with the candidates its motors hold first.

    The jaw holds a candidate's object against its weight, in every direction
    of :data:`~drakegrasp.planning.weight.WEIGHT_DIRECTIONS`, only if each
    finger can press with ``squeeze_needed`` newtons (a lower bound for the
    planned contacts, see :class:`~drakegrasp.planning.candidates.GraspCandidate`).
    The candidates whose ``squeeze_needed`` is at most the limit keep their
    order and come first; those that need more (or whose weight is unknown,
    NaN) follow, in their order.  ``squeeze_needed`` bounds each finger's
    normal forces, an effort limit the force along the joint's axis: for
    normals off the axis the comparison is conservative (the joint presses
    less than the normal force it makes).

    Parameters
    ----------
    result : GraspCandidates
        A parallel jaw's candidates, ranked by score.
    plant : MultibodyPlant
        The plant they were planned in (for the actuators' effort limits).
    top : int
        The ``certify`` of the run: the first ``top`` candidates after the
        re-ranking carry the single-grasp verdict (``closure``).
    squeeze_limit : float or None, optional
        The squeeze per finger (N) the jaw will apply, capped by the smallest
        effort limit of the closing joints' actuators (:func:`motor_limit`),
        the default.  Finite and > 0, else ``InvalidOptionError``.

    Returns
    -------
    GraspCandidates
        Re-ranked (nothing moves when no limit is known: no actuator with a
        finite effort limit and no ``squeeze_limit``), with ``reason`` saying
        so when no force-closure candidate is held within the limit.
    """
    if squeeze_limit is not None:
        squeeze_limit = check_squeeze_limit(squeeze_limit)
    ranked = list(result.candidates)
    limit = motor_limit(plant, ranked[0], per_finger=True) if ranked else math.inf
    applied = squeeze_limit is not None and squeeze_limit < limit
    if applied:
        limit = squeeze_limit
    reason = (
        result.reason
        or _too_weak_jaw(ranked, limit, applied)
        or _no_limit(
            plant, ranked, limit, "squeeze_needed", "squeeze_limit", "N per finger"
        )
    )
    ranked = _held_first(ranked, "squeeze_needed", limit, top)
    return dataclasses.replace(
        result,
        candidates=tuple(ranked),
        reason=reason,
        settings=_with_held_first(
            result.settings, ranked, "squeeze_needed", limit, "N per finger",
            applied, squeeze_limit,
        ),
    )  # fmt: skip


def _held_first(ranked: list, needed: str, limit: float, top: int) -> list:
    """``ranked`` with the candidates whose ``needed`` is within ``limit`` first.

    A stable sort keeps each group's order (NaN compares False: not held);
    the first ``top`` get their single-grasp verdict if they lack it.
    Nothing moves when ``limit`` is not finite.
    """
    if not math.isfinite(limit):
        return ranked
    ranked = sorted(ranked, key=lambda c: not getattr(c, needed) <= limit)
    return _certified(ranked, top)


def _certified(ranked: list, top: int) -> list:
    """``ranked`` with its first ``top`` carrying the single-grasp verdict."""
    ranked = list(ranked)
    ranked[:top] = [
        c if c.closure is not None else dataclasses.replace(
            c, closure=force_closure(c.grasp)
        )
        for c in ranked[:top]
    ]  # fmt: skip
    return ranked


def check_torque_limit(torque_limit) -> float:
    """``torque_limit`` (N·m) checked: a finite number > 0.

    Raises
    ------
    InvalidOptionError
        Not a real number, or not finite and > 0; the message names
        ``torque_limit``.
    """
    return _positive_limit(
        "torque_limit", torque_limit, "N·m per motor, N at a prismatic one"
    )


def check_squeeze_limit(squeeze_limit) -> float:
    """``squeeze_limit`` (N per finger) checked: a finite number > 0.

    Raises
    ------
    InvalidOptionError
        Not a real number, or not finite and > 0; the message names
        ``squeeze_limit``.
    """
    return _positive_limit("squeeze_limit", squeeze_limit, "N per finger")


def _positive_limit(name: str, value, unit: str) -> float:
    """``value`` as a finite float > 0, else an error naming ``name`` and ``unit``."""
    number = real_scalar(name, value)
    if not 0 < number < math.inf:
        raise InvalidOptionError(
            f"{name} must be a finite number > 0 ({unit}), got {describe(value)}"
        )
    return number


def motor_limit(plant, candidate: GraspCandidate, *, per_finger: bool = False) -> float:
    """The smallest effort limit (N·m, N) of a candidate's joints' actuators.

    ``inf`` when the plant gives none of them an actuator (or no finite
    limit): then nothing says which torques the hand can apply.
    ``per_finger``: what each joint it drives gets of a motor that also
    drives ``<mimic>`` followers without actuators of their own, its limit
    over ``1 + Σ|ρ|`` (a parallel jaw whose one motor closes both fingers
    presses each with half its effort limit); a motor on a hidden drive that
    the fingers follow counts too, over ``Σ|ρ|``
    (:func:`~drakegrasp.plant.couplings.motor_shares`).
    """
    limits = [
        float(a.effort_limit()) / share
        for motors in _joint_motors(plant, candidate.joint_names, per_finger).values()
        for a, share in motors
    ]
    finite = [v for v in limits if math.isfinite(v) and v > 0]
    return min(finite, default=math.inf)


def _joint_motors(plant, names, per_finger: bool = True) -> dict:
    """Per closing joint, the actuators that press it and the share each gives.

    A joint's own actuators, and for a follower of a hidden drive that is no
    closing joint (a jaw's: :func:`~drakegrasp.plant.fingers.hidden_drives`)
    the drive's.  With ``per_finger`` each comes with its share over the
    joints it drives (:func:`~drakegrasp.plant.couplings.motor_shares`: a
    drive presses only through its followers, also where it is a closing
    joint, as a multi-finger candidate's is); without, with 1.  A leader with
    geometry that the candidate leaves out drives nothing of it.
    """
    own = {n: _actuators(plant, find_joint(plant, n)) for n in names}
    couplings = plant_couplings(plant)
    drives = hidden_drives(plant, couplings)
    hidden = {d: _actuators(plant, find_joint(plant, d)) for d in drives - own.keys()}
    motors = {**own, **hidden}
    actuated = [n for n in motors if motors[n]]
    driven, shares = motor_shares(couplings, names, actuated, drives=drives)
    return {
        n: [
            (a, shares.get(m, 1.0) if per_finger else 1.0)
            for m in [driven[n] if driven.get(n) in hidden else n]
            for a in motors[m]
        ]
        for n in names
    }


def _unit_of_joints(plant, joint_names) -> str:
    """The unit of the efforts of ``joint_names``' motors, for the messages.

    ``"N·m"`` when every joint turns, ``"N"`` when every one slides, and
    ``"N·m, N at prismatic joints"`` for a hand with both
    (:func:`~drakegrasp.closure.load_problem.effort_unit_of` of each one's
    :func:`~drakegrasp.plant.fingers.effort_unit`):
    ``torque_limit`` and ``torque_needed`` are per motor, in its own unit.
    """
    return effort_unit_of(
        effort_unit(find_joint(plant, n)) or "N·m" for n in joint_names
    )


def _too_weak(head, limit: float, applied: bool = False, unit: str = "N·m") -> str:
    """Why no candidate of ``head`` holds with actuators limited to ``limit``, or "".

    ``applied``: the limit is the user's ``torque_limit``, not the effort
    limit; ``unit``: :func:`_unit_of_joints` of the hand's joints.
    """
    needed = [
        (c.torque_needed, c.torque_capacity)
        for c in head
        if not np.isnan(c.torque_needed)
    ]
    who = (
        f"the hand at torque_limit {limit:.3g} {unit} holds"
        if applied
        else f"the hand's actuators (effort limits from {limit:.3g} {unit}) hold"
    )
    return _none_held(needed, limit, who, "best ", per_motor(unit), "torque_needed")


def _too_weak_jaw(candidates, limit: float, applied: bool) -> str:
    """Why no force-closure candidate is held by a jaw limited to ``limit`` (N), or "".

    ``applied``: the limit is the user's ``squeeze_limit``, not the effort limit.
    """
    needed = [
        (c.squeeze_needed, c.weight_capacity)
        for c in candidates
        if c.is_closure and not np.isnan(c.squeeze_needed)
    ]
    who = (
        f"the jaw at squeeze_limit {limit:.3g} N holds"
        if applied
        else f"the jaw's actuators (effort limits from {limit:.3g} N) hold"
    )
    return _none_held(needed, limit, who, "", "N per finger", "squeeze_needed")


def _none_held(
    needed: list, limit: float, who: str, best: str, unit: str, name: str
) -> str:
    """The sentence saying that none of ``needed`` is within ``limit``, or "".

    ``needed`` holds ``(figure, capacity)`` pairs (the capacity tells a figure
    beyond float range from none holding: :mod:`~drakegrasp.planning.needed`);
    ``name`` is the candidates' attribute the figures are.
    """
    if not needed or min(n for n, _ in needed) <= limit:
        return ""
    # the least figure; one beyond float range before inf where none holds
    least, capacity = min(needed, key=lambda nc: (nc[0], -nc[1]))
    text = f"{needed_text(least, capacity, unit)} ({name})"
    if len(needed) == 1:
        return (
            f"{who} not the one {best}force-closure candidate against the "
            f"object's weight in every direction: it needs {text}"
        )
    at_least = "" if beyond_float_range(least, capacity) else "at least "
    return (
        f"{who} none of the {len(needed)} {best}force-closure candidates against "
        f"the object's weight in every direction: they need {at_least}{text}"
    )


def _no_limit(
    plant, ranked: list, limit: float, needed: str, option: str, unit: str
) -> str:
    """Why the motors ranked nothing: no effort limit in the model; or "".

    Said when no finite limit is known and some of the candidates' joints
    have an actuator of infinite effort (Drake makes a missing ``<effort>``
    so), or none of them has an actuator at all; not when no candidate has
    a finite ``needed`` figure (a cloud planned without ``object_mass``),
    which no limit would rank.  ``unit``: the option's, as the advice
    gives it.
    """
    if not ranked or math.isfinite(limit):
        return ""
    if not any(math.isfinite(getattr(c, needed)) for c in ranked):
        return ""  # nothing to rank by whatever the limit (no mass known)
    names = ranked[0].joint_names
    motors = _joint_motors(plant, names, per_finger=needed == "squeeze_needed")
    unbounded = [
        n for n in names if any(math.isinf(a.effort_limit()) for a, _ in motors[n])
    ]
    if not unbounded:
        if any(motors.values()):
            return ""  # zero effort limits: nothing a motor could weigh
        listed = ", ".join(repr(n) for n in names)
        return (
            f"ranked by score alone: the model gives {listed} no actuator (a URDF "
            "joint gets one from a <transmission>), so nothing says which grasps "
            f"the motors hold, and a shake cannot squeeze; give them one, or pass "
            f"{option} ({unit})"
        )
    listed = ", ".join(repr(n) for n in unbounded)
    return (
        f"ranked by score alone: the actuators of {listed} have no effort "
        "limit in the model (Drake takes a missing <effort> as unbounded), so "
        "nothing says which grasps the motors hold; give them one, or pass "
        f"{option} ({unit})"
    )


def _actuators(plant, joint):
    return [
        plant.get_joint_actuator(i)
        for i in plant.GetJointActuatorIndices()
        if plant.get_joint_actuator(i).joint().index() == joint.index()
    ]
