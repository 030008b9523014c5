r"""Close a hand onto an object: move each finger until it touches.

The hand's fingers and closing joints are those of
:mod:`drakegrasp.plant.fingers`: a finger is the chain under one root closing
joint; the palm does not move, nor does the object.

**The path.**  Each finger moves from its pre-shape in steps
``q ← clip(q + α d, lower, upper)``: a joint that reaches its limit stops
there while the others go on.  ``d`` is the finger's part of ``direction`` (a
vector over the closing joints, for instance a synergy), held fixed: the path
is a straight line in joint space.  By default ``d`` is re-aimed after every
accepted step along the steepest descent of the fingertip's distance,
``d = −∂ψ_tip/∂q`` with blocked joints dropped, scaled to a largest entry of 1
(a projected gradient path: fingers curl onto the object).

**The steps.**  ``ψ_f`` is the smallest signed distance between the finger's
collision geometries and the object's (Drake's
``ComputeSignedDistancePairClosestPoints`` over every pair that the scene
graph does not filter).  Each step is bounded by conservative advancement
(:mod:`drakegrasp.plant.advancement`): by the distance of *every* pair divided
by the fastest point speed of the finger's geometries along ``d``, less the
target ``ψ* = tol / 2``, so no step can carry a finger through anything on its
way, however thin; it is also capped at
:data:`~drakegrasp.plant.fingers.MAX_STEP` and at the end of the path.  The
steps shrink geometrically as the finger nears the object, as fast as the
closest point's approach speed is to that bound (in one step for a pad moving
along its normal).  A trial point that penetrates (which only an inaccurate
distance can produce) is cut back by regula falsi towards the last clear point.
All fingers step at once, one kinematics update per step.  A finger is
**touching** when ``0 <= ψ_f <= tol`` (no finger geometry penetrates), **at
limit** when every joint it would move is at a limit with ``ψ_f > tol``; the
loop is bounded by ``max_iterations`` steps per finger.  A re-aimed finger
that reaches a stationary point of its tip's distance away from the object
(it circles it: twenty steps without getting nearer and with little net
motion) stops there, **not converged**, as it would after
``max_iterations``.  Drake is asked only for the pairs whose distance can
matter: every pair's distance is bounded from below by conservative
advancement since it was last measured, and a pair whose bound shows it can
be neither the nearest nor bound the next step is not measured (the answers
are those of measuring every pair).  The loop itself is in
``drakegrasp.plant._closing_steps``.

**Coupled fingers.**  Fingers that a coupling closes as one (a
``<mimic>`` across them) are one finger here and stop when one of them
touches.  Its joints that move none of the touching bodies and are coupled
to none that does (a Barrett-style hand's other flexion, where only the
spread is shared) then close on from there as a finger of their own
(:func:`~drakegrasp.plant.fingers.free_part`), listed after the others in
``HandClosure.fingers``; with a ``direction`` they stay where they are.

**Parallel grippers.**  A hand whose closing joints are two prismatic jaws
facing each other (:mod:`drakegrasp.plant.jaws`) gets each jaw's distance in
``HandClosure.jaws``, and a warning when only one of them touches.
``symmetric=True`` couples the jaws to close at one speed, as the real
grippers' single motor does; an object off their midpoint then touches one
jaw.

**Re-seating.**  ``settle=True`` then lets a free object move
(:mod:`drakegrasp.plant.settle`: quasi-static, frictionless, no gravity)
while the fingers keep pushing, until they seat; the object's new pose is in
``HandClosure.settle`` and in the context.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context

from drakegrasp.core.calls import checked_call
from drakegrasp.core.tolerances import DEFAULT_DISTANCE_TOLERANCE
from drakegrasp.core.validation import check_distance_tolerance, check_flag, describe
from drakegrasp.errors import (
    InvalidOptionError,
    JointLimitError,
    ModelError,
    PenetrationError,
    UnreachableError,
)
from drakegrasp.plant._closing_steps import FingerState, Search, closest
from drakegrasp.plant.advancement import reach
from drakegrasp.plant.couplings import plant_couplings
from drakegrasp.plant.fingers import (
    HandStructure,
    free_part,
    hand_structure,
    most_fingers,
)
from drakegrasp.plant.jaws import JawContact, jaw_contacts, parallel_jaws
from drakegrasp.plant.pose import find_penetrations, joint_limit_violations
from drakegrasp.plant.settle import SettleResult, settle_object
from drakegrasp.plant.validation import (
    HandSpec,
    hand_bodies,
    hand_model_instances,
    plant_context_of,
    query_object_of,
    resolve_object_body,
    scoped_name,
)

__all__ = [
    "DEFAULT_MAX_ITERATIONS",
    "FingerClosure",
    "HandClosure",
    "close_checked_hand",
    "close_hand",
]

DEFAULT_MAX_ITERATIONS = 100
"""Default bound on the steps of each finger."""


@checked_call
@dataclass(frozen=True, eq=False)
class FingerClosure:
    """Where one finger stopped.

    Attributes
    ----------
    name : str
        ``model::root_joint``.
    joints : tuple of str
        The closing joints of the finger.
    bodies : tuple of str
        Scoped names of its bodies.
    status : str
        ``"touching"`` (``0 <= ψ <= tol``; ``-tol <= ψ`` for a finger that
        already touched at the pre-shape), ``"at limit"`` (the path ended
        with ``ψ > tol``), ``"not converged"`` (``max_iterations`` reached,
        or the finger's descent circles a point where its distance stopped
        shrinking, far from the object) or
        ``"fixed"`` (its direction is zero).
    psi : float
        Smallest signed distance from the finger to the object, metres.
    touching_body : str or None
        The body (``model::body``) of the closest finger geometry when touching.
    iterations : int
        Steps this finger took.
    """

    name: str
    joints: tuple[str, ...]
    bodies: tuple[str, ...]
    status: str
    psi: float
    touching_body: str | None
    iterations: int

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return dict(vars(self))


@checked_call
@dataclass(frozen=True, eq=False)
class HandClosure:
    """The result of :func:`close_hand`.

    Attributes
    ----------
    joints : tuple of str
        Scoped names of the closing joints, in the order of ``q``.
    position_indices : (n_h,) int
        Their indices in the plant's ``q``.
    q_start, q : (n_h,) float
        Pre-shape and final positions (metres or radians).
    fingers : tuple of FingerClosure
        One per finger, then one per free part of a coupled finger that
        closed on after it stopped (see the module docstring).
    iterations : int
        Steps of the search (each one update of the kinematics).
    time : float
        Wall-clock seconds.
    distance_tolerance : float
        Metres.
    symmetric : bool
        The jaws of a parallel gripper closed as one
        (:mod:`drakegrasp.plant.jaws`).
    jaws : tuple of JawContact
        A parallel gripper's two jaws where they stopped (empty for other
        hands).
    settle : SettleResult or None
        How the object moved to seat the fingers (``settle=True``), else None.
    """

    joints: tuple[str, ...]
    position_indices: np.ndarray
    q_start: np.ndarray
    q: np.ndarray
    fingers: tuple[FingerClosure, ...]
    iterations: int
    time: float
    distance_tolerance: float
    symmetric: bool = False
    jaws: tuple[JawContact, ...] = ()
    settle: SettleResult | None = None

    @property
    def psi(self) -> np.ndarray:
        """(n_fingers,) ψ of every finger, metres."""
        return np.array([f.psi for f in self.fingers])

    @property
    def touching_bodies(self) -> tuple[str, ...]:
        """Bodies of the touching fingers that touch the object."""
        return tuple(f.touching_body for f in self.fingers if f.touching_body)

    @property
    def touching_fingers(self) -> tuple[str, ...]:
        """Names of the fingers that touch the object."""
        return tuple(f.name for f in self.fingers if f.status == "touching")

    @property
    def one_jaw_only(self) -> bool:
        """True when exactly one jaw of a parallel gripper touches the object."""
        return sum(j.touching for j in self.jaws) == 1

    @property
    def X_WO(self) -> RigidTransform | None:
        """The object's pose after settling (``settle=True``), else None."""
        return None if self.settle is None else self.settle.X_WO

    @property
    def warnings(self) -> tuple[str, ...]:
        """What a user should know before trusting the grasp (may be empty)."""
        if not self.one_jaw_only:
            return ()
        on = next(j for j in self.jaws if j.touching)
        off = next(j for j in self.jaws if not j.touching)
        return (
            f"only one jaw touches the object: {on.body} touches, {off.body} is "
            f"{off.psi * 1e3:.4g} mm away (the object is off the jaws' midpoint; "
            "settle=True lets it move until both jaws touch)",
        )

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "joints": list(self.joints),
            "position_indices": self.position_indices.tolist(),
            "q_start": self.q_start.tolist(),
            "q": self.q.tolist(),
            "fingers": [f.to_dict() for f in self.fingers],
            "iterations": self.iterations,
            "time": self.time,
            "distance_tolerance": self.distance_tolerance,
            "symmetric": self.symmetric,
            "jaws": [j.to_dict() for j in self.jaws],
            "one_jaw_only": self.one_jaw_only,
            "settle": None if self.settle is None else self.settle.to_dict(),
            "warnings": list(self.warnings),
        }

    def __str__(self) -> str:
        n = len(self.touching_fingers)
        mode = ", jaws closed as one" if self.symmetric else ""
        if self.jaws:  # coupled jaws are one finger: say how many of them touch
            jaws = sum(j.touching for j in self.jaws)
            mode += f"; {jaws} of {len(self.jaws)} jaws touch"
        lines = [
            f"Hand closed: {n} of {len(self.fingers)} fingers touch "
            f"(tol {self.distance_tolerance * 1e3:g} mm{mode}), {self.iterations} "
            f"steps, {self.time * 1e3:.1f} ms",
        ]
        for f in self.fingers:
            where = f" ({f.touching_body})" if f.touching_body else ""
            lines.append(
                f"  {f.name:<34} {f.status:<13} psi = {f.psi * 1e3:+.4f} mm"
                f"{where}, {f.iterations} steps"
            )
        for j in self.jaws:
            state = "touches" if j.touching else "does not touch"
            lines.append(
                f"  jaw {j.joint:<30} {state:<14} psi = {j.psi * 1e3:+.4f} mm "
                f"({j.body})"
            )
        for name, q0, q in zip(self.joints, self.q_start, self.q, strict=True):
            lines.append(f"    {name:<40} {q0:+.5f} -> {q:+.5f}")
        if self.settle is not None:
            lines.append("  " + str(self.settle))
        lines += [f"  WARNING: {w}" for w in self.warnings]
        return "\n".join(lines)


@checked_call
def close_hand(
    plant: MultibodyPlant,
    plant_context: Context,
    object_body,
    *,
    hand: HandSpec,
    direction: Sequence[float] | np.ndarray | None = None,
    couplings: Sequence[tuple] | None = None,
    distance_tolerance: float = DEFAULT_DISTANCE_TOLERANCE,
    min_fingers: int = 1,
    max_iterations: int = DEFAULT_MAX_ITERATIONS,
    symmetric: bool = False,
    settle: bool = False,
) -> HandClosure:
    """Move the hand's fingers from their pre-shape until they touch the object.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized, registered with a ``SceneGraph``.
    plant_context : Context
        The plant's context or the diagram's root context.  The hand's joint
        values are the pre-shape; the object stays where it is.  The closed
        hand is written into it.
    object_body : RigidBody, BodyIndex or str
        The object; positional or keyword.
    hand : ModelInstanceIndex, str, iterable of RigidBody, or None
        The hand (see :func:`~drakegrasp.plant.validation.hand_bodies`).
    direction : (n_h,) float, optional
        Closing direction over the closing joints (order of
        ``HandClosure.joints``; followers of couplings are ignored): each
        finger moves along its part of it.  Default: each fingertip's steepest
        descent, re-aimed at every step.
    couplings : sequence of (joint_0, joint_1, gear_ratio, offset), optional
        ``q_0 = gear_ratio * q_1 + offset``, as in Drake's
        ``AddCouplerConstraint`` and a URDF ``<mimic>``; joints are ``Joint``
        objects or ``"model::joint"`` names.  Default: the couplings recorded
        on the plant (:func:`~drakegrasp.plant.couplings.plant_couplings`:
        models loaded with :func:`~drakegrasp.plant.couplings.add_models` or
        from a scene file); an explicit list overrides them (``()``: none).
    distance_tolerance : float, optional
        A finger touches when ``0 <= ψ <= distance_tolerance`` (metres,
        default 1e-4, at most 0.01, the contact tolerance of
        :func:`~drakegrasp.plant.contacts.find_contacts`).
    min_fingers : int, optional
        Fewest fingers that must touch (default 1).
    max_iterations : int, optional
        Bound on the steps of each finger (default 100).
    symmetric : bool, optional
        Close the two jaws of a parallel gripper as one, at one speed, as the
        real WSG-50 and Franka hand do (default False: each jaw closes on its
        own).  The jaws are coupled on top of ``couplings``
        (:meth:`~drakegrasp.plant.jaws.ParallelJaws.symmetric_coupling`);
        jaws already coupled stay as they are.  An object off the jaws'
        midpoint then touches one jaw: :attr:`HandClosure.warnings` says so.
    settle : bool, optional
        After closing, let the object move until the fingers seat
        (:func:`~drakegrasp.plant.settle.settle_object`: the fingers keep
        pushing, the object is free, quasi-statically and without gravity).
        Its new pose ``X_WO`` is in ``HandClosure.settle`` and written
        into the context with the fingers' positions.  The object must be a
        free body; without friction, it suits fingers that oppose each other
        across it (a parallel gripper).  Default False: the object does not
        move.

    Returns
    -------
    HandClosure
        Final positions, which fingers touch, ψ per finger, each jaw of a
        parallel gripper, steps, time, and the settled pose.

    Raises
    ------
    UnreachableError
        Fewer than ``min_fingers`` fingers touch (after settling, with
        ``settle=True``); names the others, their distance and why they
        stopped.  The context is left unchanged (the object's pose too).
    PenetrationError
        A body of the hand's model instances penetrates the object at the
        pre-shape (open the hand first).
    JointLimitError
        A joint of the hand's model instances is outside its limits at the
        pre-shape.
    InvalidOptionError, ModelError, InvalidContextError
        Bad options (``symmetric=True`` for a hand that is not a parallel
        gripper, ``settle=True`` for an object that is not a free body), a
        hand without closing joints, a bad context.
    """
    t0 = time.perf_counter()
    plant_context = plant_context_of(plant, plant_context)
    tol = check_distance_tolerance(distance_tolerance)
    for name, value in (
        ("max_iterations", max_iterations),
        ("min_fingers", min_fingers),
    ):
        if (
            isinstance(value, bool)
            or not isinstance(value, int | np.integer)
            or value < 1
        ):
            raise InvalidOptionError(
                f"{name} must be an integer >= 1, got {describe(value)}"
            )
    body = resolve_object_body(plant, object_body)
    bodies = hand_bodies(plant, body, hand)
    couplings = plant_couplings(plant, couplings)
    query = query_object_of(plant, plant_context)
    inspector = query.inspector()
    hand_ = hand_structure(plant, body, bodies, couplings, inspector=inspector)
    _refuse_branching_fingers(plant, hand_)
    instance_bodies = hand_model_instances(plant, bodies, body)
    found = find_penetrations(plant, plant_context, body, instance_bodies, tol)
    if found:
        raise PenetrationError(
            "the pre-shape already penetrates the object: "
            + "; ".join(map(str, found))
            + " (open the hand or move the object before closing)"
        )
    beyond = joint_limit_violations(plant, plant_context, instance_bodies)
    if beyond:  # it was accepted, and a finger that did not move stayed there
        raise JointLimitError(
            "the pre-shape is outside the joint limits: "
            + "; ".join(map(str, beyond))
            + " (set the hand's joints within their limits before closing)"
        )
    q_all = plant.GetPositions(plant_context)
    q0 = q_all[hand_.position_indices].copy()
    jaws = parallel_jaws(plant, plant_context, hand_, query)
    check_flag("symmetric", symmetric)
    check_flag("settle", settle)
    if symmetric:
        hand_ = _couple_jaws(plant, body, bodies, couplings, hand_, jaws, q0, inspector)
    if settle and not body.is_floating_base_body():
        raise InvalidOptionError(
            f"settle=True moves the object, and {scoped_name(plant, body)!r} is not "
            "a free body (it is welded or jointed); settle=False closes onto it "
            "where it is"
        )
    _check_min_fingers(plant, min_fingers, hand_)
    _check_coupled(hand_, q0)
    user_d = _user_direction(direction, len(q0), hand_)
    return _close(
        plant, plant_context, body, hand_, q_all, q0, tol=tol,
        min_fingers=min_fingers, user_d=user_d, max_iterations=max_iterations,
        inspector=inspector, jaws=jaws, symmetric=symmetric, settle=settle,
        instance_bodies=instance_bodies, t0=t0,
    )  # fmt: skip


def _check_min_fingers(plant, min_fingers: int, structure: HandStructure) -> None:
    """Refuse, before any search, more touching fingers than the hand has.

    A finger whose coupled chains can close on apart counts as many times
    (:func:`~drakegrasp.plant.fingers.most_fingers`).
    """
    n = len(structure.fingers)
    if min_fingers > n and min_fingers > (n := most_fingers(plant, structure)):
        raise UnreachableError(
            f"min_fingers = {min_fingers} exceeds the hand's {n} fingers "
            f"({', '.join(f.name for f in structure.fingers)}); at most {n} can touch"
        )


def close_checked_hand(
    plant, plant_context, body, structure: HandStructure, *, tol, min_fingers, t0
) -> HandClosure:
    """:func:`close_hand` for a caller that has checked what it checks.

    For a planner that closes one hand many times: ``structure`` is the hand's
    (with the plant's couplings), the tolerance and ``min_fingers`` are valid,
    the pre-shape in ``plant_context`` is within the limits and couplings and
    clear of the object, and the hand is not a parallel gripper closed as one.
    The fingers close along their steepest descent and the object does not
    move; the result and errors are those of :func:`close_hand`.
    """
    q_all = plant.GetPositions(plant_context)
    q0 = q_all[structure.position_indices].copy()
    _check_min_fingers(plant, min_fingers, structure)
    inspector = query_object_of(plant, plant_context).inspector()
    return _close(
        plant, plant_context, body, structure, q_all, q0, tol=tol,
        min_fingers=min_fingers, user_d=None, max_iterations=DEFAULT_MAX_ITERATIONS,
        inspector=inspector, jaws=None, symmetric=False, settle=False,
        instance_bodies=None, t0=t0,
    )  # fmt: skip


def _close(
    plant, plant_context, body, hand_, q_all, q0, *, tol, min_fingers, user_d,
    max_iterations, inspector, jaws, symmetric, settle, instance_bodies, t0,
):  # fmt: skip
    """The search, the settling and the result of :func:`close_hand`."""

    def split(st: FingerState, q: np.ndarray) -> FingerState | None:
        # a finger's free part closes on where a coupling stopped it with the
        # rest (not along a user's direction: it names the fingers it moves)
        if user_d is not None or st.closest_body is None:
            return None
        part = free_part(plant, hand_, st.finger, [st.closest_body])
        if part is None:
            return None
        return FingerState(
            part,
            q.copy(),
            q.copy(),
            reach(plant, plant_context, hand_, part, inspector),
        )

    search = Search(plant, plant_context, hand_, tol, user_d, max_iterations, split)
    states = [
        FingerState(
            f, q0.copy(), q0.copy(), reach(plant, plant_context, hand_, f, inspector)
        )
        for f in hand_.fingers
    ]
    steps = search.run(states, q_all, q0)
    touching = sum(st.status == "touching" for st in states)
    settled = None
    if settle and touching >= min_fingers:
        settled = settle_object(
            plant,
            plant_context,
            body,
            hand_,
            _pushing(search, states, len(q0)),
            bodies=instance_bodies,
            distance_tolerance=tol,
        )
        _reclassify(plant, plant_context, states, tol)
    query = query_object_of(plant, plant_context)
    closure = HandClosure(
        joints=hand_.names,
        position_indices=hand_.position_indices,
        q_start=q0,
        q=plant.GetPositions(plant_context)[hand_.position_indices].copy(),
        fingers=tuple(_finger_result(plant, st, hand_) for st in states),
        iterations=steps,
        time=time.perf_counter() - t0,
        distance_tolerance=tol,
        symmetric=bool(symmetric),
        jaws=() if jaws is None else jaw_contacts(plant, jaws, query, tol),
        settle=settled,
    )
    if len(closure.touching_fingers) < min_fingers:
        q_all[hand_.position_indices] = q0  # q_all holds the object's start pose
        plant.SetPositions(plant_context, q_all)
        others = [
            f"{f.name} ({f.status}, psi = {f.psi * 1e3:.4g} mm)"
            for f in closure.fingers
            if f.status != "touching"
        ]
        moved = ""
        if settled is not None:
            moved = (
                f" after settle=True moved it {settled.translation * 1e3:.4g} mm and "
                f"turned it {np.rad2deg(settled.rotation):.4g} deg (without "
                "friction, fingers that do not enclose an object squeeze it out; "
                "settle=False closes onto it where it is)"
            )
        raise UnreachableError(
            f"only {len(closure.touching_fingers)} of {len(states)} fingers reach "
            f"{scoped_name(plant, body)!r} (min_fingers = {min_fingers}){moved}; "
            f"could not reach it: {'; '.join(others)}",
            closure=closure,
        )
    return closure


def _refuse_branching_fingers(plant, hand: HandStructure) -> None:
    """Refuse a finger whose joints lie on separate branches: an arm, not a finger.

    A finger is one chain from its root joint out (fingers that a coupling
    closes as one are several chains, joined by ``+`` in their name).  A hand
    given with the arm or wrist that carries it (Drake's
    ``panda_arm_hand.urdf`` as one model instance) has one "finger" rooted at
    the arm's first joint, whose two finger joints branch off the same body:
    closing it moved the arm and left a finger open.
    """
    for finger in hand.fingers:
        if "+" in finger.name:
            continue
        joints = [hand.joints[i] for i in finger.joints]
        moved = {
            int(j.index()): {
                int(b) for b in plant.GetBodiesKinematicallyAffectedBy([j.index()])
            }
            for j in joints
        }
        for k, a in enumerate(joints):
            for b in joints[k + 1 :]:
                if int(b.child_body().index()) in moved[int(a.index())]:
                    continue
                if int(a.child_body().index()) in moved[int(b.index())]:
                    continue
                raise ModelError(
                    f"finger {finger.name} is not one chain: its joints "
                    f"{scoped_name(plant, a)} and {scoped_name(plant, b)} move "
                    "separate branches, so the hand given includes the arm or "
                    "wrist that carries the fingers, which closing would move; "
                    "give hand= the hand's own bodies (its palm and fingers), "
                    "or weld the arm's joints"
                )


def _couple_jaws(plant, body, bodies, couplings, hand, jaws, q0, inspector):
    """The hand structure with a parallel gripper's jaws coupled at one speed."""
    if jaws is None:
        kinds = ", ".join(
            f"{name} ({j.type_name()})"
            for name, j in zip(hand.names, hand.joints, strict=True)
        )
        raise InvalidOptionError(
            "symmetric=True closes the two jaws of a parallel gripper as one: it "
            "needs exactly two prismatic closing joints with parallel axes whose "
            f"jaws face each other; this hand closes with {kinds or 'no joint'}"
        )
    if len(hand.fingers) == 1:  # the jaws are coupled already
        return hand
    coupled = (*couplings, jaws.symmetric_coupling(q0))
    return hand_structure(plant, body, bodies, coupled, inspector=inspector)


def _pushing(search: Search, states: list[FingerState], n: int) -> np.ndarray:
    """(n_h,) the direction each finger's motor pushes (zero for idle fingers).

    A finger that closed pushes along its last closing direction; one that
    touched at its pre-shape along the direction it would have closed in.
    """
    tau = np.zeros(n)
    query = search.plant.get_geometry_query_input_port().Eval(search.context)
    for st in states:
        if st.status not in ("touching", "at limit"):
            continue
        d = st.d if st.d.size == n and np.any(st.d) else search.direction(st, query)
        mine = list(st.finger.joints)
        tau[mine] = d[mine]
    return tau


def _reclassify(plant, plant_context, states: list[FingerState], tol) -> None:
    """Each finger's distance and contact after the object settled."""
    query = query_object_of(plant, plant_context)
    for st in states:
        psi, _, body, _, _ = closest(query, plant, plant_context, st.finger.pairs)
        if body is None:
            continue
        st.psi, st.closest_body = psi, body
        if 0.0 <= psi <= tol:
            st.status = "touching"
        elif st.status == "touching":
            st.status = "at limit"


def _check_coupled(hand: HandStructure, q0: np.ndarray) -> None:
    for f, (lead, rho, off) in hand.coupling.follows.items():
        if abs(q0[f] - (rho * q0[lead] + off)) > 1e-6:
            raise InvalidOptionError(
                f"the pre-shape breaks the coupling {hand.names[f]} = {rho:g} * "
                f"{hand.names[lead]} + {off:g}: {q0[f]:.6g} != {rho:g} * "
                f"{q0[lead]:.6g} + {off:g}"
            )


def _user_direction(direction, n: int, hand: HandStructure) -> np.ndarray | None:
    if direction is None:
        return None
    try:
        d = np.asarray(direction, dtype=float)
    except (TypeError, ValueError):
        d = np.full(0, np.nan)
    if d.shape != (n,) or not np.all(np.isfinite(d)):
        raise InvalidOptionError(
            f"direction must be {n} finite numbers (one per closing joint, in "
            f"the order of HandClosure.joints {list(hand.names)}), got "
            f"{describe(direction)}"
        )
    scale = np.max(np.abs(d), initial=0.0)
    if scale > 0.0:  # a positive multiple closes alike (1e-13 was read as zero)
        d = d / scale
    return hand.coupling.project(d)


def _finger_result(plant, st: FingerState, hand: HandStructure) -> FingerClosure:
    touching = st.status == "touching"
    return FingerClosure(
        name=st.finger.name,
        joints=tuple(hand.names[k] for k in st.finger.joints),
        bodies=tuple(scoped_name(plant, b) for b in st.finger.bodies),
        status=st.status,
        psi=float(st.psi),
        touching_body=scoped_name(plant, st.closest_body) if touching else None,
        iterations=st.iterations,
    )
