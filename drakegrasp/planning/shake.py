r"""The check against physics: squeeze a planned grasp and turn gravity around it.

:func:`shake_test` builds a fresh discrete-time ``MultibodyPlant`` from the
user's own model function (the same one that built the planning plant), welds
the hand's base at the candidate's ``X_WH``, sets the fingers and the object
where the candidate put them, and simulates with Drake's ``Simulator``:

- the fingers are position-controlled by Drake's PD-controlled actuators
  (``JointActuator.set_controller_gains``, stiffness ``k``) aimed
  ``squeeze / k`` past the place where they touch, so each presses with
  ``squeeze`` newtons, or N·m for a revolute joint (within its effort
  limit), and resists being pushed open with stiffness ``k``, as a
  position-controlled gripper does (two
  force-controlled fingers would let gravity along the grasp axis carry
  object and fingers to a joint limit).  Where they touch is found in
  Drake, not taken from the plan: for ``seat`` seconds without gravity the
  fingers close on the object and, half-way, are re-aimed from where they
  stopped.  (Aimed from the planned joint values instead, a finger planned
  0.5 mm inside the object would press ``0.5 mm · k`` harder: 2 N more at
  the WSG-50's default gains);
- the object is free; gravity (``9.81 m/s²``, the plant's own gravity field is
  set to zero) acts on the object only, as an external force at its centre of
  mass, zero while the fingers seat, whose direction is then held for
  ``settle`` seconds along the world's ``−z`` and then turned through
  ``directions`` (each held for ``phase`` seconds; over the first ``blend``
  seconds of a phase gravity turns from the previous direction to the next
  at a constant rate along the great circle through them, about an axis
  perpendicular to both when they are opposite, so its magnitude stays
  ``m g``);
- contact, friction and stiffness are the plant's (the models' proximity
  properties: point contact where they declare no hydroelastic ones), or with
  ``hydroelastic_modulus`` the hand's geometries are made compliant
  hydroelastic and the object's rigid (:mod:`drakegrasp.plant.hydroelastic`),
  so that a flat pad presses over a patch instead of at one point.

The object *holds* when its pose in the hand frame never moves more than
``max_displacement`` (metres) or ``max_rotation`` (radians) from the planned
one.  Gravity acting on the fingers is left out: the hand is held by its base
weld and actuators, and the grasp is what is tested.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import (
    AddMultibodyPlantSceneGraph,
    ExternallyAppliedSpatialForce,
)
from pydrake.multibody.tree import PdControllerGains
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import unit_vectors
from drakegrasp.errors import GraspError, InvalidOptionError, ModelError, SolverError
from drakegrasp.planning.candidates import GraspCandidate, check_candidate
from drakegrasp.plant.fingers import effort_unit
from drakegrasp.plant.hydroelastic import (
    check_hydroelastic_modulus,
    use_hydroelastic_contact,
)
from drakegrasp.plant.validation import (
    check_rigid_transform,
    resolve_body,
    resolve_object_body,
)

__all__ = ["DEFAULT_DIRECTIONS", "ShakeResult", "check_shake_options", "shake_test"]

GRAVITY = 9.81
"""Magnitude of the turned gravity, m/s²."""

DEFAULT_DIRECTIONS = (
    (1.0, 0.0, 0.0),
    (0.0, -1.0, 0.0),
    (0.0, 0.0, 1.0),
    (-1.0, 0.0, 0.0),
    (0.0, 1.0, 0.0),
    (0.0, 0.0, -1.0),
)
"""World directions gravity turns through after settling along −z (each
consecutive pair orthogonal: every blend turns gravity by 90°)."""


@dataclass(frozen=True, eq=False)
class ShakeResult:
    """What the shake test saw.

    Attributes
    ----------
    held : bool
        Whether the object stayed within both bounds for the whole run.
    max_displacement : float
        Largest distance (m) of the object's origin from its planned place in
        the hand frame.
    max_rotation : float
        Largest rotation angle (rad) of the object from its planned
        orientation in the hand frame.
    phases : tuple of dict
        Per gravity direction: ``direction`` (world), ``displacement`` and
        ``rotation`` at the end of the phase.
    squeeze : float
        What each closing joint's actuator presses with: a force in newtons
        for a prismatic joint (a parallel jaw), a torque in N·m for a revolute
        one (a multi-finger hand); see ``effort_units``.
    efforts : tuple of float
        The magnitude of what each closing joint's actuator applied once the
        fingers had seated (newtons, or N·m for a revolute joint), in
        actuator order,
        read at the end of seating (with ``seat=0``, of settling).  A
        parallel jaw's fingers press with ``squeeze`` (within their effort
        limits).  A multi-finger hand's joints share each finger's contact
        force through its chain (``τ = Jᵀ f``), so theirs differ: a joint
        the contact pushes back presses harder, up to its effort limit, and
        one whose link moves freely presses with none.
    time_step, duration : float
        Seconds (simulated).
    wall_time : float
        Seconds.
    bounds : tuple of float
        ``(max_displacement, max_rotation)`` allowed.
    effort_units : tuple of str
        The unit of ``squeeze`` and of each entry of ``efforts``, per closing
        joint in actuator order: ``"N"`` for a prismatic joint, ``"N·m"`` for
        a revolute one (empty: newtons assumed).
    seat_displacement, seat_rotation : float
        Where seating left the object, before any gravity: distance (m) of
        its origin from its planned place and rotation angle (rad) from its
        planned orientation, in the hand frame (NaN with ``seat=0``).
    seat_speed : float
        Speed (m/s) of the object's origin at the end of seating.  An object
        the squeeze holds has settled there; one the fingers' closing motions
        push out of the hand is still moving (the Allegro hand's thumbless
        grasps of the YCB sugar box at 0.7 N·m: 0.17-0.53 m/s here, against
        0.012 and 0.045 m/s for its two best grasps with the thumb; see the
        planning guide).  NaN with ``seat=0``.
    max_displacement_from_seat, max_rotation_from_seat : float
        Largest distance (m) and rotation angle (rad) of the object, in the
        hand frame, from where seating left it, over settling and the turned
        gravity (NaN with ``seat=0``).  ``held`` counts from the planned pose,
        so a multi-finger hand that seats the object 10 mm away from it is
        "dropped" whatever follows; these say whether the seated grasp then
        held still.
    hydroelastic_modulus : float or None
        The modulus (Pa) of the hand's compliant hydroelastic geometries, or
        None: the contact the models declare.
    hydroelastic_refused : int
        Collision geometries of the hand and the object that Drake refused to
        make hydroelastic (they kept point contact; a half-space, say).
    """

    held: bool
    max_displacement: float
    max_rotation: float
    phases: tuple
    squeeze: float
    efforts: tuple[float, ...]
    time_step: float
    duration: float
    wall_time: float
    bounds: tuple[float, float]
    effort_units: tuple[str, ...] = ()
    seat_displacement: float = float("nan")
    seat_rotation: float = float("nan")
    seat_speed: float = float("nan")
    max_displacement_from_seat: float = float("nan")
    max_rotation_from_seat: float = float("nan")
    hydroelastic_modulus: float | None = None
    hydroelastic_refused: int = 0

    @property
    def held_from_seat(self) -> bool:
        """Whether the object stayed within both bounds of where seating left it.

        Over settling and the turned gravity: whether the seated grasp held.

        A multi-finger hand's fingers do not stop where the plan put them: they
        seat the object a few millimetres and degrees away (5-20 mm and up to
        35° for the Allegro hand on YCB objects) and then hold it there, or
        push it on out of the hand.  ``held`` counts from the plan and calls
        the first "dropped"; this tells the two apart.  An object the squeeze
        keeps pushing is not held: it is still moving when the fingers have
        seated and goes on past the bounds (the Allegro hand's thumbless grasps
        of the sugar box, moving at 0.15-0.5 m/s when seated, end up metres
        away under the turned gravity).  With ``seat=0`` (nothing to seat) it
        is ``held``.
        """
        if np.isnan(self.max_displacement_from_seat):
            return self.held
        return bool(
            self.max_displacement_from_seat <= self.bounds[0]
            and self.max_rotation_from_seat <= self.bounds[1]
        )

    def to_dict(self) -> dict:
        """JSON-ready dictionary (``held_from_seat`` included)."""
        return jsonable(dict(vars(self), held_from_seat=self.held_from_seat))

    def __str__(self) -> str:
        seated = (
            ""
            if np.isnan(self.seat_displacement)
            else (
                f"; seated {self.seat_displacement * 1e3:.2f} mm and "
                f"{np.degrees(self.seat_rotation):.2f} deg from the plan, "
                f"moving at {self.seat_speed * 1e3:.3g} mm/s"
                + (
                    ""
                    if np.isnan(self.max_displacement_from_seat)  # an older record
                    else (
                        f", then at most {self.max_displacement_from_seat * 1e3:.2f}"
                        f" mm and {np.degrees(self.max_rotation_from_seat):.2f} deg "
                        "from there"
                    )
                )
            )
        )
        return (
            f"{'held' if self.held else 'dropped'}: moved at most "
            f"{self.max_displacement * 1e3:.2f} mm and "
            f"{np.degrees(self.max_rotation):.2f}"
            f" deg (bounds {self.bounds[0] * 1e3:g} mm, "
            f"{np.degrees(self.bounds[1]):g} deg)"
            f" over {self.duration:g} s, squeeze {self.squeeze:g} "
            f"{_squeeze_unit(self.effort_units)}, "
            f"{len(self.phases)} gravity directions"
            + (
                ""
                if self.hydroelastic_modulus is None
                else f", hydroelastic fingers ({self.hydroelastic_modulus:g} Pa"
                + (
                    f"; {self.hydroelastic_refused} geometries kept point contact)"
                    if self.hydroelastic_refused
                    else ")"
                )
            )
            + f"; {self.wall_time:.2f} s wall{seated}"
        )


def _squeeze_unit(units: tuple[str, ...]) -> str:
    """The squeeze's unit for a summary line: one unit, or both when mixed."""
    kinds = set(units) or {"N"}
    if len(kinds) == 1:
        return kinds.pop()
    return "(N on prismatic, N·m on revolute joints)"


class _TurnedGravity(LeafSystem):
    """Outputs ``m g(t)`` on one body at its centre of mass (world frame)."""

    def __init__(self, body_index, mass, p_BoBcm_B, schedule):
        super().__init__()
        self._body, self._mass, self._com = body_index, mass, np.asarray(p_BoBcm_B)
        self._schedule = schedule
        self.DeclareAbstractOutputPort(
            "spatial_forces",
            lambda: AbstractValue.Make([ExternallyAppliedSpatialForce()]),
            self._calc,
        )

    def _calc(self, context, output):
        force = ExternallyAppliedSpatialForce()
        force.body_index = self._body
        force.p_BoBq_B = self._com
        g = self._schedule(context.get_time())
        force.F_Bq_W = SpatialForce(np.zeros(3), self._mass * GRAVITY * g)
        output.set_value([force])


def _turned(a: np.ndarray, b: np.ndarray, s: float) -> np.ndarray:
    """Unit vector ``a`` turned towards unit ``b`` by the fraction ``s`` of the angle.

    Along the great circle through both (spherical linear interpolation), at a
    constant rate; for opposite vectors, about an axis perpendicular to ``a``
    (the world axis least aligned with ``a``, made perpendicular).  The result
    is a unit vector for every ``s`` in [0, 1], never the zero vector that a
    linear blend of opposite vectors passes through.
    """
    if s >= 1.0:
        return b
    cos = float(np.clip(a @ b, -1.0, 1.0))
    across = b - cos * a  # b's part perpendicular to a, of length sin(angle)
    sin = float(np.linalg.norm(across))
    if sin > 1e-8:
        u = across / sin
    elif cos > 0.0:
        return b  # the same direction
    else:  # opposite: any perpendicular turns a onto b
        e = np.zeros(3)
        e[int(np.argmin(np.abs(a)))] = 1.0
        u = e - (e @ a) * a
        u /= np.linalg.norm(u)
    angle = s * float(np.arctan2(sin, cos))
    v = np.cos(angle) * a + np.sin(angle) * u
    return v / np.linalg.norm(v)


def _schedule(seat, settle, phase, blend, directions):
    """Gravity's unit direction at time t (zero while the fingers seat).

    ``directions`` are unit vectors; from each to the next, gravity turns over
    ``blend`` seconds along the great circle (:func:`_turned`), so its
    magnitude stays ``m g`` throughout.
    """
    dirs = [np.array([0.0, 0.0, -1.0]), *np.asarray(directions, float)]

    def g(t: float) -> np.ndarray:
        if t < seat:
            return np.zeros(3)  # the fingers seat on the object first
        t -= seat
        if t < settle:
            return dirs[0]
        k = min(int((t - settle) // phase), len(dirs) - 2)
        s = min((t - settle - k * phase) / blend, 1.0) if blend > 0 else 1.0
        return _turned(dirs[k], dirs[k + 1], s)

    return g


def _scoped(plant, joint) -> str:
    return f"{plant.GetModelInstanceName(joint.model_instance())}::{joint.name()}"


def _speed(plant, context, body) -> float:
    """Speed (m/s) of ``body``'s origin in the world (the hand's base is welded)."""
    V = plant.EvalBodySpatialVelocityInWorld(context, body)
    return float(np.linalg.norm(V.translational()))


def _angle(R: np.ndarray) -> float:
    return float(np.arccos(np.clip((np.trace(R) - 1) / 2, -1.0, 1.0)))


def _stopped(
    error: RuntimeError, t: float, stiffness: float, modulus: float | None = None
) -> GraspError:
    """The one-line error of a simulation Drake could not advance past ``t``.

    A contact solver that did not converge (SAP, TAMSI) is a ``SolverError``
    that names the gains; anything else Drake refused there (a contact model
    the geometries do not support, say) is a ``ModelError`` with Drake's first
    sentence.
    """
    lines = str(error).split("Reasons for")[0].strip().splitlines()  # then advice
    first = " ".join(lines[0].split()).rstrip(".") if lines else type(error).__name__
    where = f"the shake test's simulation stopped at t = {t:.3g} s ({first})"
    if modulus is not None:
        where += f" with hydroelastic fingers of {modulus:g} Pa"
    if "converge" not in first.lower():
        return ModelError(
            f"{where}: the model that add_models built cannot be simulated"
        )
    return SolverError(
        f"{where}: the fingers' position control (stiffness = {stiffness:g}) is "
        "likely too stiff for their inertia: light revolute fingers need far "
        "lower gains (the Allegro hand: squeeze=0.7, stiffness=10, damping=0.1, "
        "as plan --shake uses); "
        "a smaller time_step also helps"
    )


def _finite(value) -> bool:
    """Whether a real number is finite (a Python int too large for a float is not)."""
    try:
        return math.isfinite(float(value))
    except OverflowError:
        return False


def check_shake_options(
    *,
    squeeze,
    stiffness,
    damping,
    directions,
    settle,
    phase,
    seat,
    blend,
    time_step,
    max_displacement,
    max_rotation,
    hydroelastic_modulus=None,
) -> np.ndarray:
    """Check :func:`shake_test`'s options before anything is simulated.

    Parameters
    ----------
    squeeze, stiffness, damping, directions, settle, phase, seat, blend
        As :func:`shake_test` takes them.
    time_step, max_displacement, max_rotation, hydroelastic_modulus
        As :func:`shake_test` takes them.

    Returns
    -------
    (k, 3) ndarray of float
        The gravity directions (world frame) scaled to unit length.

    Raises
    ------
    InvalidOptionError
        The first option that is not a finite number in its range (naming it
        and its unit), a time step longer than a tenth of a phase, or
        directions that are not finite non-zero 3-vectors, or a
        ``hydroelastic_modulus`` that is neither None nor a finite number > 0.
    """
    check_hydroelastic_modulus(hydroelastic_modulus)
    for name, value, low, unit in (
        ("squeeze", squeeze, 0.0, "N, or N·m for revolute joints"),
        ("stiffness", stiffness, 0.0, "N/m or N·m/rad"),
        ("damping", damping, None, "N·s/m or N·m·s/rad"),
        ("time_step", time_step, 0.0, "s"),
        ("phase", phase, 0.0, "s"),
        ("settle", settle, None, "s"),
        ("blend", blend, None, "s"),
        ("seat", seat, None, "s"),
        ("max_displacement", max_displacement, None, "m"),
        ("max_rotation", max_rotation, None, "rad"),
    ):
        # low 0.0: must be > 0; None: must be >= 0.
        if not (
            isinstance(value, int | float | np.floating | np.integer)
            and not isinstance(value, bool)
            and _finite(value)
            and (value > 0 if low is not None else value >= 0)
        ):
            relation = "> 0" if low is not None else ">= 0"
            raise InvalidOptionError(
                f"{name} must be a finite number {relation} ({unit}), got {value!r}"
            )
    if time_step > phase / 10:
        raise InvalidOptionError(
            f"time_step must be at most a tenth of a phase ({phase / 10:g} s) to "
            f"resolve the shake, got {time_step!r}"
        )
    try:
        dirs = np.asarray(directions, dtype=float)
        if dirs.shape == (3,):
            dirs = dirs[None]  # one direction
    except (TypeError, ValueError):
        dirs = np.zeros((0, 0))
    if (
        dirs.ndim != 2
        or dirs.shape[0] == 0
        or dirs.shape[1] != 3
        or not np.all(np.isfinite(dirs))
        or not np.all(np.any(dirs != 0.0, axis=1))
    ):
        raise InvalidOptionError(
            "directions must be one or more finite non-zero 3-vectors, got "
            f"{directions!r}"
        )
    # Only their directions count, whatever their length (no overflow).
    dirs = unit_vectors("directions", dirs, error=InvalidOptionError)
    return dirs


def shake_test(
    add_models: Callable,
    candidate: GraspCandidate,
    *,
    squeeze: float = 20.0,
    stiffness: float = 4000.0,
    damping: float = 50.0,
    directions: Sequence[Sequence[float]] = DEFAULT_DIRECTIONS,
    settle: float = 0.3,
    phase: float = 0.4,
    seat: float = 0.1,
    blend: float = 0.1,
    time_step: float = 1e-3,
    max_displacement: float = 0.01,
    max_rotation: float = np.radians(10.0),
    object_body=None,
    X_WO: RigidTransform | None = None,
    hydroelastic_modulus: float | None = None,
) -> ShakeResult:
    """Simulate a planned grasp in Drake and report whether the object stays put.

    Parameters
    ----------
    add_models : callable
        ``add_models(plant, parser) -> (hand, object_body)``: adds the hand (its
        base not welded) and the object to a fresh plant, as for planning;
        ``hand`` a model instance, ``object_body`` a body or its scoped name.
        Leave out supports such as a table: the test turns gravity around.
    candidate : GraspCandidate
        From :func:`~drakegrasp.planning.planner.plan_grasps`.
    squeeze : float, optional
        Force with which each finger presses, newtons (default 20 N; at most
        the actuator's effort limit); for a revolute joint (a multi-finger
        hand) the torque on each closing joint that closing moved, N·m.
    stiffness, damping : float, optional
        Gains of the fingers' position control (N/m, N·s/m; per radian for
        revolute joints): each finger is aimed ``squeeze / stiffness`` past
        where it touches.  Light revolute fingers need far lower gains than
        the default (the Allegro hand: ``squeeze=0.5, stiffness=20,
        damping=1``; at the defaults Drake's SAP solver diverges).
    directions : sequence of (3,) float, optional
        World gravity directions after the settling phase along −z (any
        finite, non-zero length: only the direction counts; consecutive ones
        may be opposite).
    settle, phase, blend : float, optional
        Seconds: settling under −z gravity, each direction's hold, the blend
        between directions (gravity turns along the great circle from one
        direction to the next, its magnitude constant).
    seat : float, optional
        Seconds without gravity, before settling, in which the fingers close
        on the object: each is aimed ``squeeze / k`` past where it stands
        (the candidate's joint values), and after ``seat / 2`` re-aimed from
        where it stopped, so that it presses with
        ``squeeze`` whether the plan left it short of the surface or inside
        it.  0: aimed from the candidate's joint values.
    time_step : float, optional
        The discrete plant's step, seconds.
    max_displacement, max_rotation : float, optional
        Bounds on the object's motion in the hand frame: metres, radians.
    object_body : optional
        Overrides the object that ``add_models`` returns.
    X_WO : RigidTransform, optional
        The object's pose in the world at the start (default the candidate's
        ``X_WO``).  A candidate planned on a point cloud has the cloud's frame
        there (its centroid or, completed, its centre of symmetry, with the
        world's axes), not the object's: give the true pose of the object the
        cloud was taken from.
    hydroelastic_modulus : float or None, optional
        None (default): the contact the models declare (Drake's point contact
        where they declare no hydroelastic properties: one point per pair of
        geometries, so a flat pad on a flat face touches at one point and the
        object pivots between two such pads).  A modulus (Pa, finite > 0):
        the hand's collision geometries are made compliant hydroelastic with
        it and the object's rigid, so each pad presses over a patch, as it
        does on a real object (:mod:`drakegrasp.plant.hydroelastic`; 1e6 suits
        rubber pads).

    Returns
    -------
    ShakeResult

    Raises
    ------
    InvalidOptionError
        Bad options (non-positive time step or squeeze, a zero direction, an
        ``X_WO`` that is not a finite rigid pose...).
    SolverError
        Drake's contact solver did not converge during the simulation (gains
        too stiff for the fingers' inertia, or too long a ``time_step``); the
        message gives the time and what to lower.
    ModelError
        ``add_models`` did not add the candidate's hand base or closing joints,
        or Drake refused to advance the model for another reason (its first
        sentence is in the message).
    InvalidGraspError
        The candidate's joint values or poses are not finite or do not match
        its closing joints (:func:`~drakegrasp.planning.candidates.check_candidate`).
    """
    if not callable(add_models):
        raise InvalidOptionError(
            "add_models must be a function add_models(plant, parser) -> (hand, "
            f"object_body), got {type(add_models).__name__}"
        )
    if not isinstance(candidate, GraspCandidate):
        raise InvalidOptionError(
            "candidate must be a GraspCandidate from plan_grasps, got "
            f"{type(candidate).__name__}"
        )
    if X_WO is not None:
        candidate = replace(candidate, X_WO=check_rigid_transform("X_WO", X_WO))
    check_candidate(candidate)
    dirs = check_shake_options(
        squeeze=squeeze, stiffness=stiffness, damping=damping,
        directions=directions, settle=settle, phase=phase, seat=seat,
        blend=blend, time_step=time_step, max_displacement=max_displacement,
        max_rotation=max_rotation, hydroelastic_modulus=hydroelastic_modulus,
    )  # fmt: skip
    modulus = check_hydroelastic_modulus(hydroelastic_modulus)
    t0 = time.perf_counter()
    from pydrake.multibody.parsing import Parser

    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(
        builder, time_step=float(time_step)
    )
    made = add_models(plant, Parser(plant))
    if not (isinstance(made, tuple | list) and len(made) == 2):
        raise ModelError(
            f"add_models must return (hand, object_body), got {type(made).__name__}"
        )
    hand, obj = made
    if object_body is not None:
        obj = object_body
    base = resolve_body(plant, candidate.hand_base)
    actuators = [plant.get_joint_actuator(a) for a in plant.GetJointActuatorIndices()]
    by_name = {_scoped(plant, a.joint()): a for a in actuators}
    targets = {}
    for name, sign in zip(candidate.joint_names, candidate.closing_signs, strict=True):
        actuator = by_name.get(name)
        if actuator is None:
            raise ModelError(f"closing joint {name} has no actuator to squeeze with")
        push = min(squeeze, actuator.effort_limit())
        targets[int(actuator.joint().index())] = sign * push / stiffness
    for actuator in actuators:  # every actuator position-controlled (Drake's PD)
        actuator.set_controller_gains(PdControllerGains(p=stiffness, d=damping))
    plant.WeldFrames(plant.world_frame(), base.body_frame(), candidate.X_WH)
    plant.mutable_gravity_field().set_gravity_vector(np.zeros(3))
    body = resolve_object_body(plant, obj)
    refused = 0
    if modulus is not None:
        # the hand: its base's model instance and those of its closing joints
        instances = {base.model_instance()} | {
            a.joint().model_instance()
            for a in actuators
            if int(a.joint().index()) in targets
        }
        hand_bodies = [
            plant.get_body(i)
            for instance in sorted(instances, key=int)
            for i in plant.GetBodyIndices(instance)
            if i != body.index()
        ]
        refused = use_hydroelastic_contact(
            plant, scene_graph, hand_bodies, [body], modulus=modulus
        )
    plant.Finalize()
    schedule = _schedule(seat, settle, phase, blend, dirs)
    gravity = builder.AddSystem(
        _TurnedGravity(body.index(), body.default_mass(), body.default_com(), schedule)
    )
    builder.Connect(
        gravity.get_output_port(), plant.get_applied_spatial_force_input_port()
    )
    diagram = builder.Build()
    simulator = Simulator(diagram)
    root = simulator.get_mutable_context()
    ctx = plant.GetMyContextFromRoot(root)
    candidate.apply(plant, ctx, object_body=body)
    q_held = plant.GetPositions(ctx)

    def aim() -> None:
        # closing joints squeeze/k past where they stand now; others hold
        q_now = plant.GetPositions(ctx)
        desired = {}
        for actuator in actuators:
            joint = actuator.joint()
            i, start = int(joint.index()), joint.position_start()
            q_d = q_now[start] + targets[i] if i in targets else q_held[start]
            desired.setdefault(joint.model_instance(), []).append(
                (int(actuator.index()), q_d)
            )
        for instance, entries in desired.items():
            entries.sort()
            q_d = np.array([q for _, q in entries])
            plant.get_desired_state_input_port(instance).FixValue(
                ctx, np.concatenate([q_d, np.zeros_like(q_d)])
            )

    aim()
    plant.get_actuation_input_port().FixValue(ctx, np.zeros(plant.num_actuated_dofs()))
    H = base.body_frame()
    X_HO0 = plant.CalcRelativeTransform(ctx, H, body.body_frame())
    ends = [seat + settle + (k + 1) * phase for k in range(len(dirs))]
    duration = ends[-1]
    max_d = max_r = 0.0
    phases = []
    t, dt_check = 0.0, 0.01

    X_HO_seat = None  # where seating left the object, once it has
    max_ds = max_rs = float("nan")

    def advance(to: float) -> tuple[float, float]:
        nonlocal t, max_d, max_r, max_ds, max_rs
        d = r = 0.0
        while t < to - 1e-12:
            t = min(t + dt_check, to)
            try:
                simulator.AdvanceTo(t)
            except RuntimeError as e:  # Drake could not advance (see _stopped)
                if type(e) is not RuntimeError:  # RecursionError, NotImplemented...
                    raise
                t_now = simulator.get_context().get_time()
                raise _stopped(e, t_now, stiffness, modulus) from e
            X_HO = plant.CalcRelativeTransform(ctx, H, body.body_frame())
            d = float(np.linalg.norm(X_HO.translation() - X_HO0.translation()))
            r = _angle(X_HO0.rotation().matrix().T @ X_HO.rotation().matrix())
            if not (math.isfinite(d) and math.isfinite(r)):  # max() would skip NaN
                raise SolverError(
                    f"the shake test's simulation went unstable at t = {t:.3g} s: "
                    "the object's pose is no longer finite; lower the gains or "
                    "the time_step"
                )
            max_d, max_r = max(max_d, d), max(max_r, r)
            if X_HO_seat is not None:
                ds = float(np.linalg.norm(X_HO.translation() - X_HO_seat.translation()))
                rs = _angle(X_HO_seat.rotation().matrix().T @ X_HO.rotation().matrix())
                max_ds, max_rs = max(max_ds, ds), max(max_rs, rs)
        return d, r

    seated = (float("nan"),) * 3
    if seat > 0:
        advance(seat / 2)
        aim()  # from where the fingers stopped on the object
        seated = (*advance(seat), _speed(plant, ctx, body))
        X_HO_seat = plant.CalcRelativeTransform(ctx, H, body.body_frame())
        max_ds = max_rs = 0.0
    else:
        advance(settle)  # efforts are read once something has been simulated
    u = plant.get_net_actuation_output_port().Eval(ctx)
    squeezing = [a for a in actuators if int(a.joint().index()) in targets]
    efforts = tuple(abs(float(u[a.input_start()])) for a in squeezing)
    effort_units = tuple(effort_unit(a.joint()) for a in squeezing)
    for end in ends:
        d, r = advance(end)
        phases.append(
            {
                "direction": schedule(end - 1e-9).tolist(),
                "displacement": d,
                "rotation": r,
            }
        )
    return ShakeResult(
        held=bool(max_d <= max_displacement and max_r <= max_rotation),
        max_displacement=max_d,
        max_rotation=max_r,
        phases=tuple(phases),
        squeeze=float(squeeze),
        efforts=efforts,
        time_step=float(time_step),
        duration=duration,
        wall_time=time.perf_counter() - t0,
        bounds=(float(max_displacement), float(max_rotation)),
        effort_units=effort_units,
        seat_displacement=seated[0],
        seat_rotation=seated[1],
        seat_speed=seated[2],
        max_displacement_from_seat=max_ds,
        max_rotation_from_seat=max_rs,
        hydroelastic_modulus=modulus,
        hydroelastic_refused=refused,
    )
