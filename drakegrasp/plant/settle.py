r"""Re-seating: the object moves under the closed fingers until they seat.

:func:`~drakegrasp.plant.closing.close_hand` moves the fingers against an
object that stands still, so an object tilted by a few degrees between two
pads touches each pad at one corner.  A real gripper squeezes it straight.
:func:`settle_object` models that quasi-statically, without gravity and
without friction: the fingers' motors push with constant effort ``τ`` along
their closing directions and the object is free, so the configuration
(closing joints ``q``, object pose ``X_WO``) goes down the motors' potential
``−τᵀq`` among the poses where nothing penetrates, to a local minimum: the
object turns and slides until the pads seat, the fingers follow it.

**The steps** (sequential linear programming with a trust region).  With the
free closing joints ``u`` (followers of couplings move with their leaders,
``δq = T δu``) and the object's small motion ``δξ = (δω, δp)`` (rotation vector
and translation of its origin, world frame; ``R_WO ← exp(δω) R_WO``,
``p_WO ← p_WO + δp``), every hand/object geometry pair ``k`` (the palm's
included) has

.. math::
    \delta\psi_k = \hat n_k \cdot \big(\delta p + \delta\omega \times
    (p_{W,O_k} - p_{WO}) - J_{H_k}\, T\, \delta u\big),

with ``n̂_k`` the pair's unit normal from the hand to the object, ``p_{W,O_k}``
and ``p_{W,H_k}`` its witness points and ``J_{H_k}`` the translational
Jacobian of the hand's witness point over the closing joints.  Each step
solves the LP (:func:`build_settle_step`)

.. math::
    \max_{\delta u, \delta\xi}\; \tau^T T \delta u
      - w_p \|\delta p\|_1 - w_\omega \|\delta\omega\|_1
    \quad\text{s.t.}\quad \psi_k + \delta\psi_k \ge \psi^*,\;
    \text{joint limits},\; |\delta u_j|, |\delta p_i| \le r,\;
    |\delta\omega_i| \le r / L,

``ψ* = tol / 2``, ``L`` the object's bounding radius; a revolute joint's bound
is ``r / 0.05 m`` per radian.  When no motion meets ``ψ*`` (the object wedged
against the palm), the floor is ``min(ψ*, ψ_k)``, which ``δ = 0`` meets.  The
small weights ``w_p = w_ω / L =`` :data:`MOTION_WEIGHT` leave the object where
it is along the motions that do no work (an object between two independent
jaws slides freely along their axis).  A step after which a pair is at
``ψ_k < min(0, ψ_k^{before})`` (a linearisation error) is refused and ``r``
halved; an accepted one doubles it (up to its start, 2 mm).  The object is
seated when the LP predicts less gain than ``1e-3 tol`` or ``r`` falls below
``1e-3 tol``.

**Scope.**  Only the hand's geometries count: other bodies of the scene (a
table) do not stop the object.  Without friction the object goes wherever the
pushes send it, so settling suits fingers that oppose each other across the
object (a parallel gripper's jaws; a thumb opposite fingers that enclose the
object).  Fingers that push a frictionless object from one side squeeze it out
of the hand; :func:`~drakegrasp.plant.closing.close_hand` then finds fewer
fingers touching and says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.common.eigen_geometry import AngleAxis
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable, RigidBody
from pydrake.solvers import MathematicalProgram, SolutionResult
from pydrake.systems.framework import Context

from drakegrasp._solvers import require_solution, solve
from drakegrasp.core.calls import checked_call
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import (
    check_distance_tolerance,
    describe,
    integer_or_none,
    real_array,
)
from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant._shapes import bounding_sphere
from drakegrasp.plant.fingers import HandStructure, check_hand_structure
from drakegrasp.plant.validation import (
    check_bodies,
    plant_context_of,
    query_object_of,
    resolve_object_body,
    scoped_name,
)

__all__ = [
    "DEFAULT_SETTLE_ITERATIONS",
    "MOTION_WEIGHT",
    "SettleResult",
    "build_settle_step",
    "settle_object",
]

DEFAULT_SETTLE_ITERATIONS = 200
"""Default bound on the LP steps of :func:`settle_object`."""

MOTION_WEIGHT = 1e-3
"""Cost of moving the object, per metre of its points, against a motor's unit gain."""

_START_RADIUS = 2e-3  # metres: the first trust region
_LEVER = 0.05  # metres per radian: a revolute joint's trust region is r / _LEVER


@checked_call
@dataclass(frozen=True, eq=False)
class SettleResult:
    """How the object moved to seat the fingers.

    Attributes
    ----------
    object_body : str
        ``model::body``.
    X_WO_start, X_WO : RigidTransform
        The object's pose before and after, in the world.
    iterations : int
        LP steps taken (accepted and refused).
    converged : bool
        True when the object is seated; False when ``max_iterations`` ran out.
    min_psi : float
        Smallest signed distance between the hand and the object at the end,
        metres (``>= 0`` unless a pair started deeper).
    """

    object_body: str
    X_WO_start: RigidTransform
    X_WO: RigidTransform
    iterations: int
    converged: bool
    min_psi: float

    @property
    def translation(self) -> float:
        """Distance (metres) the object's origin moved."""
        d = self.X_WO.translation() - self.X_WO_start.translation()
        return float(np.linalg.norm(d))

    @property
    def rotation(self) -> float:
        """Angle (radians) the object turned."""
        R = self.X_WO_start.rotation().inverse().multiply(self.X_WO.rotation())
        return float(R.ToAngleAxis().angle())

    def to_dict(self) -> dict:
        """JSON-ready dictionary (poses as 4 x 4 matrices)."""
        return {
            "object_body": self.object_body,
            "X_WO_start": jsonable(self.X_WO_start.GetAsMatrix4()),
            "X_WO": jsonable(self.X_WO.GetAsMatrix4()),
            "translation": self.translation,
            "rotation": self.rotation,
            "iterations": self.iterations,
            "converged": self.converged,
            "min_psi": self.min_psi,
        }

    def __str__(self) -> str:
        state = "seated" if self.converged else "NOT seated (out of steps)"
        p = self.X_WO.translation()
        return (
            f"object {self.object_body} {state} after {self.iterations} steps: moved "
            f"{self.translation * 1e3:.3f} mm, turned "
            f"{np.rad2deg(self.rotation):.3f} deg; p_WO = "
            f"[{p[0]:+.5f}, {p[1]:+.5f}, {p[2]:+.5f}] m"
        )


@dataclass(frozen=True)
class _Pairs:
    """Every unfiltered (object geometry, hand geometry, hand body) pair."""

    pairs: tuple

    @classmethod
    def of(cls, plant, inspector, object_body, bodies) -> _Pairs:
        objects = plant.GetCollisionGeometriesForBody(object_body)
        return cls(
            tuple(
                (go, gh, b)
                for b in bodies
                for gh in plant.GetCollisionGeometriesForBody(b)
                for go in objects
                if not inspector.CollisionFiltered(go, gh)
            )
        )

    def distances(self, query) -> np.ndarray:
        return np.array(
            [
                query.ComputeSignedDistancePairClosestPoints(go, gh).distance
                for go, gh, _ in self.pairs
            ]
        )


def _object_radius(plant, inspector, object_body) -> float:
    radius = 0.0
    for g in plant.GetCollisionGeometriesForBody(object_body):
        centre, r = bounding_sphere(inspector.GetShape(g))
        p = inspector.GetPoseInFrame(g).multiply(centre)
        radius = max(radius, float(np.linalg.norm(p)) + r)
    return radius if np.isfinite(radius) and radius > 0 else 0.1


def _free_map(hand: HandStructure) -> tuple[list[int], np.ndarray]:
    """The free closing joints and ``T`` (n_h, n_free) with ``δq = T δu``."""
    free = [k for k in range(len(hand.joints)) if k not in hand.coupling.follows]
    T = np.zeros((len(hand.joints), len(free)))
    for i, k in enumerate(free):
        e = np.zeros(len(hand.joints))
        e[k] = 1.0
        T[:, i] = hand.coupling.tangent(e)
    return free, T


def _rows(plant, context, query, pairs, hand, T, p_WO):
    """ψ of every pair and its gradient over (δu, δp, δω)."""
    n_free = T.shape[1]
    psi = np.empty(len(pairs))
    A = np.zeros((len(pairs), n_free + 6))
    world = plant.world_frame()
    for k, (go, gh, body) in enumerate(pairs):
        r = query.ComputeSignedDistancePairClosestPoints(go, gh)
        psi[k] = r.distance
        X_WA, X_WB = query.GetPoseInWorld(r.id_A), query.GetPoseInWorld(r.id_B)
        n_BA = np.asarray(r.nhat_BA_W)
        if r.id_A == go:  # A the object, B the hand: n̂ from B to A
            n, p_obj, p_hand = n_BA, X_WA.multiply(r.p_ACa), X_WB.multiply(r.p_BCb)
        else:
            n, p_obj, p_hand = -n_BA, X_WB.multiply(r.p_BCb), X_WA.multiply(r.p_ACa)
        p_BH = plant.EvalBodyPoseInWorld(context, body).inverse().multiply(p_hand)
        J = plant.CalcJacobianTranslationalVelocity(
            context, JacobianWrtVariable.kV, body.body_frame(), p_BH, world, world
        )
        A[k, :n_free] = -n @ J[:, hand.velocity_indices] @ T
        A[k, n_free : n_free + 3] = n
        A[k, n_free + 3 :] = np.cross(np.asarray(p_obj) - p_WO, n)
    return psi, A


def build_settle_step(
    psi: np.ndarray,
    A: np.ndarray,
    gain: np.ndarray,
    *,
    floor: np.ndarray,
    du_lower: np.ndarray,
    du_upper: np.ndarray,
    radius: float,
    object_radius: float,
) -> tuple[MathematicalProgram, np.ndarray]:
    """The LP of one settling step (see the module docstring).

    Parameters
    ----------
    psi : (n_pairs,) float
        Signed distance of every hand/object pair, metres.
    A : (n_pairs, n_free + 6) float
        ``∂ψ/∂(δu, δp, δω)``: metres per unit joint motion, per metre, per
        radian.
    gain : (n_free,) float
        ``Tᵀ τ``: the motors' work per unit motion of each free joint.
    floor : (n_pairs,) float
        The distance each pair must keep after the step (linearised), metres:
        ``ψ*``, or ``min(ψ*, ψ_k)`` when that cannot be met.
    du_lower, du_upper : (n_free,) float
        Bounds on ``δu`` (joint limits, trust region; equal for a joint that
        must not move).
    radius : float
        Trust region ``r``, metres.
    object_radius : float
        ``L``, metres.

    Returns
    -------
    prog : MathematicalProgram
    x : (n_free + 6,) Variable
        ``(δu, δp, δω)``.
    """
    n_free = len(gain)
    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(n_free + 6, "x")
    s = prog.NewContinuousVariables(6, "s")  # |δp|, |δω| (L1)
    weights = MOTION_WEIGHT * np.r_[np.ones(3), np.full(3, object_radius)]
    prog.AddLinearCost(np.r_[-np.asarray(gain), np.zeros(6), weights], 0.0, [*x, *s])
    if len(psi):
        prog.AddLinearConstraint(
            A, np.asarray(floor) - psi, np.full(len(psi), np.inf), x
        )
    xi = x[n_free:]
    eye, none, zero = np.eye(6), np.full(6, np.inf), np.zeros(6)
    both = np.r_[xi, s]
    prog.AddLinearConstraint(np.hstack([eye, -eye]), -none, zero, both)  # ξ <= s
    prog.AddLinearConstraint(np.hstack([eye, eye]), zero, none, both)  # -ξ <= s
    prog.AddBoundingBoxConstraint(du_lower, du_upper, x[:n_free])
    bound = np.r_[np.full(3, radius), np.full(3, radius / object_radius)]
    prog.AddBoundingBoxConstraint(-bound, bound, xi)
    return prog, x


@checked_call
def settle_object(
    plant: MultibodyPlant,
    plant_context: Context,
    object_body: RigidBody,
    hand: HandStructure,
    pushing: np.ndarray,
    *,
    bodies,
    distance_tolerance: float,
    max_iterations: int = DEFAULT_SETTLE_ITERATIONS,
) -> SettleResult:
    """Let a free object move under the pushing fingers until they seat.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
        The plant's context, fingers closed on the object; the settled pose
        and finger positions are written into it.
    object_body : RigidBody
        A free body.
    hand : HandStructure
        The closing joints and couplings.
    pushing : (n_h,) float
        ``τ``: the direction each closing joint's motor pushes (order of
        ``hand.joints``, followers zero); joints of fingers with ``τ = 0``
        hold still.
    bodies : sequence of RigidBody
        Every body of the hand's model instances (their geometries keep the
        object out, welded palm included).
    distance_tolerance : float
        ``tol``, metres.
    max_iterations : int, optional
        Bound on the LP steps.

    Returns
    -------
    SettleResult

    Raises
    ------
    InvalidOptionError
        For an object that is not a free body, a ``hand`` that is not a
        ``HandStructure``, a ``pushing`` of the wrong shape, ``bodies`` that
        are not the plant's, or a bad ``distance_tolerance`` or
        ``max_iterations``.
    ModelError, InvalidContextError
        For what is not a finalized plant, or a context of another system.
    """
    plant_context = plant_context_of(plant, plant_context)
    object_body = resolve_object_body(plant, object_body)
    check_hand_structure(hand)
    bodies = check_bodies(plant, bodies)
    n = integer_or_none(max_iterations)
    if n is None or n < 1:
        raise InvalidOptionError(
            f"max_iterations must be an integer >= 1, got {describe(max_iterations)}"
        )
    if not object_body.is_floating_base_body():
        raise InvalidOptionError(
            f"settling moves the object: {scoped_name(plant, object_body)!r} is "
            "not a free body"
        )
    n_h = len(hand.joints)
    tau = real_array("pushing", pushing, error=InvalidOptionError)
    if tau.shape != (n_h,) or not np.all(np.isfinite(tau)):
        raise InvalidOptionError(
            f"pushing must be {n_h} finite numbers, got {describe(pushing)}"
        )
    tol = check_distance_tolerance(distance_tolerance)
    inspector = query_object_of(plant, plant_context).inspector()
    pairs = _Pairs.of(plant, inspector, object_body, bodies)
    L = _object_radius(plant, inspector, object_body)
    free, T = _free_map(hand)
    still = np.ones(n_h, dtype=bool)  # joints of fingers that do not push
    for finger in hand.fingers:
        if np.any(tau[list(finger.joints)]):
            still[list(finger.joints)] = False
    gain = T.T @ tau
    still_u = still[free]
    lever = np.array(
        [1.0 if hand.joints[k].type_name() == "prismatic" else _LEVER for k in free]
    )
    X_start = plant.EvalBodyPoseInWorld(plant_context, object_body)
    q_all = plant.GetPositions(plant_context)
    q = q_all[hand.position_indices].copy()
    radius, iterations, converged = _START_RADIUS, 0, False
    while iterations < max_iterations:
        iterations += 1
        query = query_object_of(plant, plant_context)
        X_WO = plant.EvalBodyPoseInWorld(plant_context, object_body)
        psi, A = _rows(
            plant, plant_context, query, pairs.pairs, hand, T, X_WO.translation()
        )
        lo, hi = _joint_room(hand, q, T, radius / lever, still_u)
        step = None
        for floor in (np.full(len(psi), 0.5 * tol), np.minimum(0.5 * tol, psi)):
            prog, x = build_settle_step(
                psi,
                A,
                gain,
                floor=floor,
                du_lower=lo,
                du_upper=hi,
                radius=radius,
                object_radius=L,
            )
            result = solve(prog, "lp")
            if result.get_solution_result() == SolutionResult.kSolutionFound:
                step = result.GetSolution(x)
                break
        if step is None:  # the second LP is feasible (δ = 0): a numerical failure
            require_solution(prog, result, "the settling LP")
        if gain @ step[: len(free)] < 1e-3 * tol or radius < 1e-3 * tol:
            converged = True
            break
        q_new = q + T @ step[: len(free)]
        X_new = _moved(X_WO, step[len(free) :])
        _write(plant, plant_context, object_body, hand, q_all, q_new, X_new)
        after = pairs.distances(query_object_of(plant, plant_context))
        if np.all(after >= np.minimum(psi, 0.0)):
            q, radius = q_new, min(2.0 * radius, _START_RADIUS)
        else:  # linearisation error: back, and a smaller step
            _write(plant, plant_context, object_body, hand, q_all, q, X_WO)
            radius *= 0.5
    final = pairs.distances(query_object_of(plant, plant_context))
    return SettleResult(
        object_body=scoped_name(plant, object_body),
        X_WO_start=X_start,
        X_WO=plant.EvalBodyPoseInWorld(plant_context, object_body),
        iterations=iterations,
        converged=converged,
        min_psi=float(np.min(final, initial=np.inf)),
    )


def _joint_room(hand, q, T, trust, still_u):
    """Bounds on δu: the trust region, zero for still joints, the joint limits."""
    lo, hi = -trust.copy(), trust.copy()
    lo[still_u] = hi[still_u] = 0.0
    # Limits on every closing joint: lower - q <= T δu <= upper - q.  T maps a
    # free joint to itself and its followers; bound each free joint so that
    # it and its followers stay in range.
    for i in range(T.shape[1]):
        for k in np.flatnonzero(T[:, i]):
            a, b = sorted(
                ((hand.lower[k] - q[k]) / T[k, i], (hand.upper[k] - q[k]) / T[k, i])
            )
            lo[i], hi[i] = max(lo[i], min(a, 0.0)), min(hi[i], max(b, 0.0))
    return lo, hi


def _moved(X_WO: RigidTransform, xi: np.ndarray) -> RigidTransform:
    """``X_WO`` after the small motion ``(δp, δω)``."""
    dp, dw = xi[:3], xi[3:]
    angle = float(np.linalg.norm(dw))
    R = RotationMatrix()
    if angle > 0:
        R = RotationMatrix(AngleAxis(angle, dw / angle))
    return RigidTransform(R.multiply(X_WO.rotation()), X_WO.translation() + dp)


def _write(plant, context, body, hand, q_all, q, X_WO) -> None:
    q_all = q_all.copy()
    q_all[hand.position_indices] = hand.coupling.apply(q)
    plant.SetPositions(context, q_all)
    plant.SetFreeBodyPose(context, body, X_WO)
