r"""Close a hand onto an object: move each finger until it touches.

**Fingers.**  The *closing joints* are the hand's one-dof joints (revolute,
prismatic) that have an actuator (all its one-dof joints when none has one),
plus the followers of ``couplings``.  A *finger* is the chain that one closing
joint drives: its **root joint** is a closing joint whose parent body no other
closing joint moves; the finger holds every closing joint and every hand body
below it (``plant.GetBodiesKinematicallyAffectedBy``).  The WSG-50 has two
fingers (one prismatic joint each), the Allegro hand four (four revolute
joints each).  Coupled joints in different fingers make one finger, as the
rigid mimic link of a real gripper does.  Bodies no closing joint moves (the
palm) stay where they are.

**The path.**  Each finger ``f`` follows the straight line
``q_f(s) = clip(q_f^0 + s d_f, lower, upper)`` from its pre-shape ``q_f^0``:
a joint that reaches its limit stops there while the others go on.  ``d_f`` is
the finger's part of ``direction`` (a vector over the closing joints, e.g. a
synergy), by default the steepest descent of the finger's distance to the
object at the pre-shape, ``d_f = −∂ψ_f/∂q_f`` scaled to a largest entry of 1
(so ``s`` is the travel of the fastest joint, metres or radians).

**The search.**  ``ψ_f(s)`` is the smallest signed distance between the
finger's collision geometries and the object's (Drake's
``ComputeSignedDistancePairClosestPoints``).  Every finger takes safeguarded
Newton steps on ``ψ_f(s) = tol / 2`` at the same time, with the slope

.. math:: \frac{d\psi_f}{ds} = -\hat n^T J_{v,C_b}\, \frac{dq}{ds}

from the translational Jacobian of the finger's witness point ``Cb`` (the
object stays still), each step capped at :data:`MAX_STEP`; once a step
penetrates, the root is bracketed and steps stay inside the bracket
(bisection when Newton leaves it).  A finger is **touching** when
``0 <= ψ_f <= tol`` (so no finger geometry penetrates), **at limit** when the
path ends (every moving joint at a limit) with ``ψ_f > tol``.  The loop is
bounded by ``max_iterations``.

**Couplings.**  Drake parses a URDF ``<mimic>`` (or SDFormat
``<drake:mimic>``) into a coupler constraint ``q_0 = ρ q_1 + Δq``, which its
Python API does not expose for reading.  Pass the same numbers as
``couplings=[(joint_0, joint_1, ρ, Δq)]`` (``plant.AddCouplerConstraint``'s
arguments); a plant with constraints and no ``couplings`` is refused rather
than closed against its constraints (``couplings=()`` closes it anyway).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable, Joint, JointIndex
from pydrake.systems.framework import Context

from drakegrasp.errors import (
    InvalidOptionError,
    ModelError,
    PenetrationError,
    UnreachableError,
)
from drakegrasp.plant.contacts import DEFAULT_DISTANCE_TOLERANCE
from drakegrasp.plant.validation import (
    HandSpec,
    hand_bodies,
    hand_model_instances,
    plant_context_of,
    resolve_object_body,
    scoped_name,
)

__all__ = ["FingerClosure", "HandClosure", "MAX_STEP", "close_hand"]

MAX_STEP = {"revolute": 0.2, "prismatic": 0.01}
"""Largest change of any joint in one step: radians, metres."""

DEFAULT_MAX_ITERATIONS = 100
"""Default bound on the number of steps (each: one kinematics update)."""

_STATUSES = ("touching", "at limit", "not converged", "fixed")


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
        ``"touching"`` (``0 <= ψ <= tol``), ``"at limit"`` (the path ended
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
class _Finger:
    """Working state of one finger during the search."""

    name: str
    joints: list[int]  # positions in the closing-joint list
    bodies: list  # RigidBody
    pairs: list  # (object GeometryId, finger GeometryId, RigidBody)
    tip_pairs: list  # the pairs of the fingertip (the most distal bodies)
    d: np.ndarray = field(default_factory=lambda: np.zeros(0))  # over all joints
    q_good: np.ndarray = field(default_factory=lambda: np.zeros(0))  # ψ > tol here
    q_trial: np.ndarray = field(default_factory=lambda: np.zeros(0))
    psi_good: float = np.inf
    alpha: float = 0.0
    max_step: float = 0.2
    status: str = ""
    psi: float = np.inf
    closest_body: object = None
    iterations: int = 0


def _joint_name(plant: MultibodyPlant, joint: Joint) -> str:
    return f"{plant.GetModelInstanceName(joint.model_instance())}::{joint.name()}"


def _find_joint(plant: MultibodyPlant, spec) -> Joint:
    if isinstance(spec, Joint):
        return spec
    if isinstance(spec, str):
        model, _, name = spec.rpartition("::")
        for i in range(plant.num_joints()):
            j = plant.get_joint(JointIndex(i))
            if j.name() == name and (
                not model or plant.GetModelInstanceName(j.model_instance()) == model
            ):
                return j
    raise InvalidOptionError(
        f"coupling joint {spec!r} is not a joint of the plant (give a Joint or "
        "a 'model::joint' name)"
    )


def _closing_joints(plant, bodies, couplings):
    """Closing joints and the coupling map follower -> (leader, ρ, Δq)."""
    wanted = {int(b.index()) for b in bodies}
    one_dof = [
        plant.get_joint(JointIndex(i))
        for i in range(plant.num_joints())
        if plant.get_joint(JointIndex(i)).num_positions() == 1
        and int(plant.get_joint(JointIndex(i)).child_body().index()) in wanted
    ]
    actuated = {
        int(plant.get_joint_actuator(a).joint().index())
        for a in plant.GetJointActuatorIndices()
    }
    joints = [j for j in one_dof if int(j.index()) in actuated] or one_dof
    follows = {}
    for entry in couplings:
        if len(entry) != 4:
            raise InvalidOptionError(
                "each coupling is (joint_0, joint_1, gear_ratio, offset) with "
                f"q_0 = gear_ratio * q_1 + offset, got {entry!r}"
            )
        j0, j1 = _find_joint(plant, entry[0]), _find_joint(plant, entry[1])
        follows[int(j0.index())] = (int(j1.index()), float(entry[2]), float(entry[3]))
        for j in (j0, j1):
            if int(j.index()) not in {int(k.index()) for k in joints}:
                if j.num_positions() != 1 or int(j.child_body().index()) not in wanted:
                    raise InvalidOptionError(
                        f"coupled joint {_joint_name(plant, j)} is not a one-dof "
                        "joint of the hand"
                    )
                joints.append(j)
    joints.sort(key=lambda j: j.position_start())
    return joints, follows


def _fingers(plant, object_body, bodies, joints, follows, inspector) -> list[_Finger]:
    """Group the closing joints and hand bodies into fingers (see module doc)."""
    hand = {int(b.index()) for b in bodies}
    moved = {
        int(j.index()): {
            int(i) for i in plant.GetBodiesKinematicallyAffectedBy([j.index()])
        }
        & hand
        for j in joints
    }
    position = {int(j.index()): k for k, j in enumerate(joints)}
    # Union-find over joints: a joint joins the finger of the joint that moves
    # its parent body; a follower joins its leader.
    parent = {k: k for k in position}

    def find(k):
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    for j in joints:
        for k in joints:
            if k is not j and int(j.parent_body().index()) in moved[int(k.index())]:
                parent[find(int(j.index()))] = find(int(k.index()))
    for follower, (leader, _, _) in follows.items():
        parent[find(follower)] = find(leader)
    groups: dict[int, list[Joint]] = {}
    for j in joints:
        groups.setdefault(find(int(j.index())), []).append(j)
    object_geometries = plant.GetCollisionGeometriesForBody(object_body)
    out = []
    for members in groups.values():
        roots = [
            j
            for j in members
            if not any(
                int(j.parent_body().index()) in moved[int(k.index())]
                for k in members
                if k is not j
            )
        ]
        body_ids = sorted(set().union(*(moved[int(j.index())] for j in members)))
        finger_bodies = [b for b in bodies if int(b.index()) in body_ids]
        pairs = [
            (go, gf, b)
            for b in finger_bodies
            for gf in plant.GetCollisionGeometriesForBody(b)
            for go in object_geometries
            if not inspector.CollisionFiltered(go, gf)
        ]
        # The fingertip: the bodies that the most of the finger's joints move.
        depth = {
            int(b.index()): sum(
                int(b.index()) in moved[int(j.index())] for j in members
            )
            for b in finger_bodies
        }
        deepest = max((depth[int(b.index())] for _, _, b in pairs), default=0)
        tip = [p for p in pairs if depth[int(p[2].index())] == deepest]
        out.append(
            _Finger(
                name=" + ".join(_joint_name(plant, j) for j in roots),
                joints=sorted(position[int(j.index())] for j in members),
                bodies=finger_bodies,
                pairs=pairs,
                tip_pairs=tip,
                max_step=min(
                    MAX_STEP["revolute" if j.type_name() == "revolute" else "prismatic"]
                    for j in members
                ),
            )
        )
    return out


def _closest(query, finger: _Finger, plant, context, *, tip: bool = False):
    """ψ, the unit normal n (finger -> object, world) and the witness on the finger.

    Returns (psi, n_W, body, p_BCb) for the finger's closest pair (of its tip
    with ``tip=True``), or (inf, None, None, None) when it has no pair.
    """
    best = (np.inf, None, None, None, None)
    for go, gf, body in finger.tip_pairs if tip else finger.pairs:
        r = query.ComputeSignedDistancePairClosestPoints(go, gf)
        if r.distance < best[0]:
            if r.id_A == go:
                n_W, p_GC = np.asarray(r.nhat_BA_W), r.p_BCb
            else:
                n_W, p_GC = -np.asarray(r.nhat_BA_W), r.p_ACa
            best = (float(r.distance), n_W, body, gf, p_GC)
    psi, n_W, body, gf, p_GC = best
    if body is None:
        return psi, None, None, None
    p_WC = query.GetPoseInWorld(gf).multiply(p_GC)
    p_BC = plant.EvalBodyPoseInWorld(context, body).inverse().multiply(p_WC)
    return psi, n_W, body, np.asarray(p_BC)


def _dpsi_dq(plant, context, n_W, body, p_BC, v_indices) -> np.ndarray:
    """``∂ψ/∂q`` of the closing joints (object fixed; one-dof joints, q̇ = v)."""
    J = plant.CalcJacobianTranslationalVelocity(
        context,
        JacobianWrtVariable.kV,
        body.body_frame(),
        p_BC,
        plant.world_frame(),
        plant.world_frame(),
    )
    return -(n_W @ J[:, v_indices])


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
        The plant's context or the diagram's root context; the hand's current
        joint values are the pre-shape, the object stays where it is.  The
        closed hand is written into it.
    object_body : RigidBody, BodyIndex or str
        The object; positional or keyword.
    hand : ModelInstanceIndex, str or iterable of RigidBody
        The hand (see :func:`drakegrasp.plant.hand_bodies`); None picks every
        movable body outside the object's model instance.
    direction : (n_h,) float, optional
        Closing direction over the closing joints (order of
        ``HandClosure.joints``; the followers of couplings are ignored).
        Default: steepest descent of each finger's distance at the pre-shape.
    couplings : sequence of (joint_0, joint_1, gear_ratio, offset), optional
        Joints coupled as ``q_0 = gear_ratio * q_1 + offset`` (Drake's
        ``AddCouplerConstraint`` and URDF ``<mimic>``); joints are ``Joint``
        objects or ``"model::joint"`` names.  Required (``()`` for none) when
        the plant has constraints, which Drake does not let us read.
    distance_tolerance : float, optional
        A finger touches when ``0 <= ψ <= distance_tolerance`` (metres,
        default 1e-4, the contact tolerance of :func:`find_contacts`).
    min_fingers : int, optional
        Fewest fingers that must touch (default 1); fewer raise
        :class:`~drakegrasp.UnreachableError`.
    max_iterations : int, optional
        Bound on the steps of the search (default 100).

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
        A hand body penetrates the object at the pre-shape (open the hand).
    InvalidOptionError, ModelError, InvalidContextError
        Bad options, a hand without closing joints, a bad context.
    """
    t0 = time.perf_counter()
    plant_context = plant_context_of(plant, plant_context)
    tol = _positive(distance_tolerance, "distance_tolerance")
    if not isinstance(max_iterations, int | np.integer) or max_iterations < 1:
        raise InvalidOptionError(
            f"max_iterations must be an integer >= 1, got {max_iterations!r}"
        )
    body = resolve_object_body(plant, object_body)
    bodies = hand_bodies(plant, body, hand)
    if couplings is None:
        if plant.num_constraints() > 0:
            raise InvalidOptionError(
                f"the plant has {plant.num_constraints()} constraints (a URDF "
                "<mimic> becomes a coupler constraint) and Drake's Python API does "
                "not let drakegrasp read them: pass couplings=[(joint_0, joint_1, "
                "gear_ratio, offset)], or couplings=() to close without them"
            )
        couplings = ()
    joints, follows = _closing_joints(plant, bodies, couplings)
    if not joints:
        raise ModelError(
            "the hand has no one-dof joint to close: "
            f"{[scoped_name(plant, b) for b in bodies]}"
        )
    if not plant.geometry_source_is_registered():
        raise ModelError("the plant is not registered with a SceneGraph; no geometry")
    q_idx = np.array([j.position_start() for j in joints])
    v_idx = np.array([j.velocity_start() for j in joints])
    lower = np.array([j.position_lower_limits()[0] for j in joints])
    upper = np.array([j.position_upper_limits()[0] for j in joints])
    q_all = plant.GetPositions(plant_context)
    q0 = q_all[q_idx].copy()
    coupled = _coupling_matrix(joints, follows, q0, lower, upper)
    lower, upper = coupled.leader_limits(lower, upper)
    query = plant.get_geometry_query_input_port().Eval(plant_context)
    fingers = _fingers(plant, body, bodies, joints, follows, query.inspector())
    _refuse_penetration(plant, plant_context, body, bodies, query, tol)
    user_d = _user_direction(direction, len(joints), coupled)
    ctx = _Search(plant, plant_context, v_idx, lower, upper, coupled, tol)
    for f in fingers:
        f.q_good, f.q_trial = q0.copy(), q0.copy()
    steps = 0
    while True:
        q = q0.copy()
        for f in fingers:
            q[f.joints] = f.q_trial[f.joints]
        q_all[q_idx] = coupled.apply(q)
        plant.SetPositions(plant_context, q_all)
        query = plant.get_geometry_query_input_port().Eval(plant_context)
        for f in fingers:
            if not f.status:
                ctx.advance(f, query, user_d, max_iterations)
        steps += 1
        if all(f.status for f in fingers):
            break
    closure = HandClosure(
        joints=tuple(_joint_name(plant, j) for j in joints),
        position_indices=q_idx,
        q_start=q0,
        q=plant.GetPositions(plant_context)[q_idx].copy(),
        fingers=tuple(_finger_result(plant, f, joints) for f in fingers),
        iterations=steps,
        time=time.perf_counter() - t0,
        distance_tolerance=tol,
    )
    touching = closure.touching_fingers
    if len(touching) < min_fingers:
        q_all[q_idx] = q0
        plant.SetPositions(plant_context, q_all)
        others = [
            f"{f.name} ({f.status}, psi = {f.psi * 1e3:.4g} mm)"
            for f in closure.fingers
            if f.status != "touching"
        ]
        raise UnreachableError(
            f"only {len(touching)} of {len(fingers)} fingers reach "
            f"{scoped_name(plant, body)!r} (min_fingers = {min_fingers}); could not "
            f"reach it: {'; '.join(others)}",
            closure=closure,
        )
    return closure


def _positive(value, name: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = np.nan
    if not np.isfinite(x) or x <= 0:
        raise InvalidOptionError(f"{name} must be finite and > 0, got {value!r}")
    return x


def _path_end(q0, d, lower, upper) -> float:
    """Smallest s at which every joint with d != 0 has reached a limit (≤ 1e3)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(d > 0, (upper - q0) / d, np.where(d < 0, (lower - q0) / d, 0.0))
    t = np.where(np.isfinite(t), t, 1e3)
    return float(max(np.max(t, initial=0.0), 0.0))


def _finger_result(plant, f: _Finger, joints) -> FingerClosure:
    touching = f.status == "touching"
    return FingerClosure(
        name=f.name,
        joints=tuple(_joint_name(plant, joints[k]) for k in f.joints),
        bodies=tuple(scoped_name(plant, b) for b in f.bodies),
        status=f.status,
        psi=float(f.psi),
        touching_body=scoped_name(plant, f.closest_body) if touching else None,
        iterations=f.iterations,
    )


def _refuse_penetration(plant, context, body, bodies, query, tol) -> None:
    """The pre-shape must not penetrate the object (palm included)."""
    inspector = query.inspector()
    found = []
    for b in hand_model_instances(plant, bodies, body):
        for gh in plant.GetCollisionGeometriesForBody(b):
            for go in plant.GetCollisionGeometriesForBody(body):
                if inspector.CollisionFiltered(go, gh):
                    continue
                psi = query.ComputeSignedDistancePairClosestPoints(go, gh).distance
                if psi < -tol:
                    found.append(
                        f"{scoped_name(plant, b)} ({inspector.GetName(gh)}) by "
                        f"{-psi * 1e3:.4g} mm"
                    )
    if found:
        raise PenetrationError(
            "the pre-shape already penetrates the object: "
            + "; ".join(found)
            + " (open the hand or move the object before closing)"
        )


def _user_direction(direction, n: int, coupled) -> np.ndarray | None:
    if direction is None:
        return None
    try:
        d = np.asarray(direction, dtype=float)
    except (TypeError, ValueError):
        d = np.full(0, np.nan)
    if d.shape != (n,) or not np.all(np.isfinite(d)):
        raise InvalidOptionError(
            f"direction must be {n} finite numbers (one per closing joint, in "
            f"the order of HandClosure.joints), got shape {d.shape}"
        )
    return coupled.project(d)


class _Search:
    """One step of every finger's search (see the module docstring)."""

    def __init__(self, plant, context, v_idx, lower, upper, coupled, tol):
        self.plant, self.context, self.v_idx = plant, context, v_idx
        self.lower, self.upper, self.coupled = lower, upper, coupled
        self.tol, self.target = tol, 0.5 * tol

    def advance(self, f: _Finger, query, user_d, max_iterations: int) -> None:
        plant, context = self.plant, self.context
        psi, n_W, body, p_BC = _closest(query, f, plant, context)
        f.psi, f.closest_body = psi, body
        first = f.iterations == 0
        if body is None:  # no collision geometry that can touch the object
            f.status = "fixed"
        elif 0.0 <= psi <= self.tol or (first and -self.tol <= psi <= self.tol):
            f.status = "touching"
        elif f.iterations >= max_iterations:
            f.status = "not converged"
            f.q_trial = f.q_good.copy()
        elif psi < 0.0:  # the step went in: regula falsi back to the surface
            alpha = f.alpha * (f.psi_good - self.target) / (f.psi_good - psi)
            f.alpha = float(np.clip(alpha, 0.1 * f.alpha, 0.9 * f.alpha))
            f.q_trial = self._at(f, f.alpha)
            f.iterations += 1
        else:  # clear of the object: accept the point, aim the next step
            f.q_good, f.psi_good = f.q_trial.copy(), psi
            f.d = self._direction(f, query, user_d)
            alpha_end = _path_end(f.q_good, f.d, self.lower, self.upper)
            if alpha_end <= 1e-12:
                unmoved = user_d is not None and not np.any(user_d[f.joints])
                f.status = "fixed" if unmoved else "at limit"
                return
            slope = float(self._dpsi(n_W, body, p_BC) @ self.coupled.tangent(f.d))
            newton = (psi - self.target) / -slope if slope < 0 else np.inf
            f.alpha = min(newton, f.max_step, alpha_end)
            f.q_trial = self._at(f, f.alpha)
            f.iterations += 1

    def _at(self, f: _Finger, alpha: float) -> np.ndarray:
        return np.clip(f.q_good + alpha * f.d, self.lower, self.upper)

    def _dpsi(self, n_W, body, p_BC) -> np.ndarray:
        return _dpsi_dq(self.plant, self.context, n_W, body, p_BC, self.v_idx)

    def _direction(self, f: _Finger, query, user_d) -> np.ndarray:
        """The finger's direction, zero on joints blocked by a limit."""
        mine = np.isin(np.arange(len(self.lower)), f.joints)
        if user_d is not None:
            d = np.where(mine, user_d, 0.0)
        else:  # steepest descent of the fingertip's distance, here
            psi, n_W, body, p_BC = _closest(
                query, f, self.plant, self.context, tip=True
            )
            g = self.coupled.pull_back(self._dpsi(n_W, body, p_BC))
            d = np.where(mine, -g, 0.0)
        q = f.q_good
        blocked = ((d > 0) & (q >= self.upper)) | ((d < 0) & (q <= self.lower))
        d = np.where(blocked, 0.0, d)
        scale = np.max(np.abs(d), initial=0.0)
        return d / scale if scale > 1e-12 else np.zeros_like(d)


class _Coupling:
    """Followers move with their leaders: ``q_f = ρ q_l + Δq``."""

    def __init__(self, follows: dict[int, tuple[int, float, float]]):
        self.follows = follows  # position -> (leader position, ρ, Δq)

    def apply(self, q: np.ndarray) -> np.ndarray:
        q = q.copy()
        for f, (lead, rho, off) in self.follows.items():
            q[f] = rho * q[lead] + off
        return q

    def tangent(self, d: np.ndarray) -> np.ndarray:
        d = d.copy()
        for f, (lead, rho, _) in self.follows.items():
            d[f] = rho * d[lead]
        return d

    def project(self, d: np.ndarray) -> np.ndarray:
        d = d.copy()
        for f in self.follows:
            d[f] = 0.0
        return d

    def pull_back(self, g: np.ndarray) -> np.ndarray:
        """Gradient over the free joints (a follower's part goes to its leader)."""
        g = g.copy()
        for f, (lead, rho, _) in self.follows.items():
            g[lead] += rho * g[f]
            g[f] = 0.0
        return g

    def leader_limits(self, lower, upper):
        lower, upper = lower.copy(), upper.copy()
        for f, (lead, rho, off) in self.follows.items():
            a, b = sorted(((lower[f] - off) / rho, (upper[f] - off) / rho))
            lower[lead], upper[lead] = max(lower[lead], a), min(upper[lead], b)
        return lower, upper


def _coupling_matrix(joints, follows, q0, lower, upper) -> _Coupling:
    position = {int(j.index()): k for k, j in enumerate(joints)}
    out = {}
    for follower, (leader, rho, off) in follows.items():
        if rho == 0 or not np.isfinite(rho) or not np.isfinite(off):
            raise InvalidOptionError(
                f"coupling gear_ratio must be finite and non-zero, got {rho!r}"
            )
        f, lead = position[follower], position[leader]
        if f in {v[0] for v in out.values()} or lead in out:
            raise InvalidOptionError("a joint may not both lead and follow a coupling")
        if abs(q0[f] - (rho * q0[lead] + off)) > 1e-6:
            raise InvalidOptionError(
                f"the pre-shape breaks the coupling of {joints[f].name()} to "
                f"{joints[lead].name()}: {q0[f]:.6g} != {rho:g} * {q0[lead]:.6g} "
                f"+ {off:g}"
            )
        out[f] = (lead, rho, off)
    return _Coupling(out)
