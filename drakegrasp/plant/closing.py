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
loop is bounded by ``max_iterations`` steps per finger.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import Context

from drakegrasp.core.tolerances import DEFAULT_DISTANCE_TOLERANCE
from drakegrasp.core.validation import check_distance_tolerance
from drakegrasp.errors import (
    InvalidOptionError,
    JointLimitError,
    PenetrationError,
    UnreachableError,
)
from drakegrasp.plant.advancement import (
    advancement_bound,
    finger_speed_bound,
    reach,
)
from drakegrasp.plant.couplings import plant_couplings
from drakegrasp.plant.fingers import Finger, HandStructure, hand_structure
from drakegrasp.plant.pose import find_penetrations, joint_limit_violations
from drakegrasp.plant.validation import (
    HandSpec,
    hand_bodies,
    hand_model_instances,
    plant_context_of,
    query_object_of,
    resolve_object_body,
    scoped_name,
)

__all__ = ["DEFAULT_MAX_ITERATIONS", "FingerClosure", "HandClosure", "close_hand"]

DEFAULT_MAX_ITERATIONS = 100
"""Default bound on the steps of each finger."""


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
        with ``ψ > tol``), ``"not converged"`` (``max_iterations`` reached) or
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
    iterations : int
        Steps of the search (each one update of the kinematics).
    time : float
        Wall-clock seconds.
    distance_tolerance : float
        Metres.
    """

    joints: tuple[str, ...]
    position_indices: np.ndarray
    q_start: np.ndarray
    q: np.ndarray
    fingers: tuple[FingerClosure, ...]
    iterations: int
    time: float
    distance_tolerance: float

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
        }

    def __str__(self) -> str:
        n = len(self.touching_fingers)
        lines = [
            f"Hand closed: {n} of {len(self.fingers)} fingers touch "
            f"(tol {self.distance_tolerance * 1e3:g} mm), {self.iterations} "
            f"steps, {self.time * 1e3:.1f} ms",
        ]
        for f in self.fingers:
            where = f" ({f.touching_body})" if f.touching_body else ""
            lines.append(
                f"  {f.name:<34} {f.status:<13} psi = {f.psi * 1e3:+.4f} mm"
                f"{where}, {f.iterations} steps"
            )
        for name, q0, q in zip(self.joints, self.q_start, self.q, strict=True):
            lines.append(f"    {name:<40} {q0:+.5f} -> {q:+.5f}")
        return "\n".join(lines)


@dataclass
class _State:
    """Working state of one finger during the search."""

    finger: Finger
    q_good: np.ndarray  # ψ > tol here (the last accepted point)
    q_trial: np.ndarray
    reach: np.ndarray  # (n_pairs, n_h), see drakegrasp.plant.advancement
    d: np.ndarray = field(default_factory=lambda: np.zeros(0))
    psi_good: float = np.inf
    alpha: float = 0.0
    status: str = ""
    psi: float = np.inf
    closest_body: object = None
    iterations: int = 0


def _closest(query, plant, context, pairs):
    """The closest pair and the distance of every pair.

    Returns
    -------
    (ψ, n̂_W from finger to object, finger body, witness p_BCb, ψ of every pair)
        ``(inf, None, None, None, ψs)`` when there is no pair.
    """
    best = (np.inf, None, None, None, None)
    every = np.empty(len(pairs))
    for k, (go, gf, body) in enumerate(pairs):
        r = query.ComputeSignedDistancePairClosestPoints(go, gf)
        every[k] = r.distance
        if r.distance < best[0]:
            if r.id_A == go:
                n_W, p_GC = np.asarray(r.nhat_BA_W), r.p_BCb
            else:  # Drake swapped the pair
                n_W, p_GC = -np.asarray(r.nhat_BA_W), r.p_ACa
            best = (float(r.distance), n_W, body, gf, p_GC)
    psi, n_W, body, gf, p_GC = best
    if body is None:
        return psi, None, None, None, every
    p_WC = query.GetPoseInWorld(gf).multiply(p_GC)
    p_BC = plant.EvalBodyPoseInWorld(context, body).inverse().multiply(p_WC)
    return psi, n_W, body, np.asarray(p_BC), every


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
        default 1e-4, the contact tolerance of
        :func:`~drakegrasp.plant.contacts.find_contacts`).
    min_fingers : int, optional
        Fewest fingers that must touch (default 1).
    max_iterations : int, optional
        Bound on the steps of each finger (default 100).

    Returns
    -------
    HandClosure
        Final positions, which fingers touch, ψ per finger, steps, time.

    Raises
    ------
    UnreachableError
        Fewer than ``min_fingers`` fingers touch; names the others, their
        distance and why they stopped.  The context is left unchanged.
    PenetrationError
        A body of the hand's model instances penetrates the object at the
        pre-shape (open the hand first).
    JointLimitError
        A joint of the hand's model instances is outside its limits at the
        pre-shape.
    InvalidOptionError, ModelError, InvalidContextError
        Bad options, a hand without closing joints, a bad context.
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
            raise InvalidOptionError(f"{name} must be an integer >= 1, got {value!r}")
    body = resolve_object_body(plant, object_body)
    bodies = hand_bodies(plant, body, hand)
    couplings = plant_couplings(plant, couplings)
    query = query_object_of(plant, plant_context)
    hand_ = hand_structure(plant, body, bodies, couplings, inspector=query.inspector())
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
    if min_fingers > len(hand_.fingers):  # unreachable before any search
        raise UnreachableError(
            f"min_fingers = {min_fingers} exceeds the hand's {len(hand_.fingers)} "
            f"fingers ({', '.join(f.name for f in hand_.fingers)}); at most "
            f"{len(hand_.fingers)} can touch"
        )
    q_all = plant.GetPositions(plant_context)
    q0 = q_all[hand_.position_indices].copy()
    _check_coupled(hand_, q0)
    user_d = _user_direction(direction, len(q0), hand_)
    search = _Search(plant, plant_context, hand_, tol, user_d, max_iterations)
    inspector = query.inspector()
    states = [
        _State(
            f, q0.copy(), q0.copy(), reach(plant, plant_context, hand_, f, inspector)
        )
        for f in hand_.fingers
    ]
    steps = search.run(states, q_all, q0)
    closure = HandClosure(
        joints=hand_.names,
        position_indices=hand_.position_indices,
        q_start=q0,
        q=plant.GetPositions(plant_context)[hand_.position_indices].copy(),
        fingers=tuple(_finger_result(plant, st, hand_) for st in states),
        iterations=steps,
        time=time.perf_counter() - t0,
        distance_tolerance=tol,
    )
    if len(closure.touching_fingers) < min_fingers:
        q_all[hand_.position_indices] = q0
        plant.SetPositions(plant_context, q_all)
        others = [
            f"{f.name} ({f.status}, psi = {f.psi * 1e3:.4g} mm)"
            for f in closure.fingers
            if f.status != "touching"
        ]
        raise UnreachableError(
            f"only {len(closure.touching_fingers)} of {len(states)} fingers reach "
            f"{scoped_name(plant, body)!r} (min_fingers = {min_fingers}); could not "
            f"reach it: {'; '.join(others)}",
            closure=closure,
        )
    return closure


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
            f"the order of HandClosure.joints {list(hand.names)}), got {direction!r}"
        )
    scale = np.max(np.abs(d), initial=0.0)
    if scale > 0.0:  # a positive multiple closes alike (1e-13 was read as zero)
        d = d / scale
    return hand.coupling.project(d)


def _path_end(q, d, lower, upper) -> float:
    """Largest α at which a joint with d != 0 still moves (capped at 1e3)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t = np.where(d > 0, (upper - q) / d, np.where(d < 0, (lower - q) / d, 0.0))
    t = np.where(np.isfinite(t), t, 1e3)
    return float(max(np.max(t, initial=0.0), 0.0))


def _finger_result(plant, st: _State, hand: HandStructure) -> FingerClosure:
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


class _Search:
    """The steps of every finger (see the module docstring)."""

    def __init__(self, plant, context, hand: HandStructure, tol, user_d, max_it):
        self.plant, self.context, self.hand = plant, context, hand
        self.tol, self.target = tol, 0.5 * tol
        self.user_d, self.max_iterations = user_d, max_it

    def run(self, states: list[_State], q_all: np.ndarray, q0: np.ndarray) -> int:
        """Step until every finger has a status; the number of steps."""
        hand, steps = self.hand, 0
        while not all(st.status for st in states):
            q = q0.copy()
            for st in states:
                q[list(st.finger.joints)] = st.q_trial[list(st.finger.joints)]
            q_all[hand.position_indices] = hand.coupling.apply(q)
            self.plant.SetPositions(self.context, q_all)
            query = self.plant.get_geometry_query_input_port().Eval(self.context)
            for st in states:
                if not st.status:
                    self.advance(st, query)
            steps += 1
        # Where each finger stopped (a finger that ran out of steps goes back
        # to its last point clear of the object).
        q = q0.copy()
        for st in states:
            q[list(st.finger.joints)] = st.q_trial[list(st.finger.joints)]
        q_all[hand.position_indices] = hand.coupling.apply(q)
        self.plant.SetPositions(self.context, q_all)
        return steps

    def advance(self, st: _State, query) -> None:
        """Classify the finger's trial point, then aim its next one."""
        psi, _, body, _, every = _closest(
            query, self.plant, self.context, st.finger.pairs
        )
        st.psi, st.closest_body = psi, body
        first = st.iterations == 0
        if body is None:  # no collision geometry that can touch the object
            st.status = "fixed"
        elif 0.0 <= psi <= self.tol or (first and -self.tol <= psi <= self.tol):
            st.status = "touching"
        elif st.iterations >= self.max_iterations:  # back to the last clear point
            st.status = "not converged"
            st.q_trial, st.psi = st.q_good.copy(), st.psi_good
        elif psi < 0.0:  # the step went in: regula falsi back to the surface
            alpha = st.alpha * (st.psi_good - self.target) / (st.psi_good - psi)
            st.alpha = float(np.clip(alpha, 0.1 * st.alpha, 0.9 * st.alpha))
            st.q_trial = self._at(st, st.alpha)
            st.iterations += 1
        else:  # clear of the object: accept the point, aim the next step
            st.q_good, st.psi_good = st.q_trial.copy(), psi
            st.d = self._direction(st, query)
            alpha_end = _path_end(st.q_good, st.d, self.hand.lower, self.hand.upper)
            if alpha_end <= 1e-12:
                mine = list(st.finger.joints)
                unmoved = self.user_d is not None and not np.any(self.user_d[mine])
                st.status = "fixed" if unmoved else "at limit"
                return
            speed = finger_speed_bound(st.reach, self.hand.coupling.tangent(st.d))
            alpha_ca = advancement_bound(every, speed, self.target)
            st.alpha = min(alpha_ca, st.finger.max_step, alpha_end)
            st.q_trial = self._at(st, st.alpha)
            st.iterations += 1

    def _at(self, st: _State, alpha: float) -> np.ndarray:
        return np.clip(st.q_good + alpha * st.d, self.hand.lower, self.hand.upper)

    def _dpsi(self, n_W, body, p_BC) -> np.ndarray:
        """``∂ψ/∂q`` over the closing joints (object fixed; one-dof, q̇ = v)."""
        J = self.plant.CalcJacobianTranslationalVelocity(
            self.context,
            JacobianWrtVariable.kV,
            body.body_frame(),
            p_BC,
            self.plant.world_frame(),
            self.plant.world_frame(),
        )
        return -(n_W @ J[:, self.hand.velocity_indices])

    def _direction(self, st: _State, query) -> np.ndarray:
        """The finger's direction, zero on joints blocked by a limit."""
        hand = self.hand
        mine = np.isin(np.arange(len(hand.lower)), st.finger.joints)
        if self.user_d is not None:
            d = np.where(mine, self.user_d, 0.0)
        else:  # steepest descent of the fingertip's distance, here
            tip = _closest(query, self.plant, self.context, st.finger.tip_pairs)
            if tip[2] is None:
                return np.zeros(len(mine))
            d = np.where(mine, -hand.coupling.pull_back(self._dpsi(*tip[1:4])), 0.0)
        q = st.q_good
        blocked = ((d > 0) & (q >= hand.upper)) | ((d < 0) & (q <= hand.lower))
        d = np.where(blocked, 0.0, d)
        scale = np.max(np.abs(d), initial=0.0)
        if scale <= 1e-12:
            return np.zeros_like(d)
        d = d / scale
        return np.where(np.abs(d) < 1e-9, 0.0, d)  # round-off, not a motion
