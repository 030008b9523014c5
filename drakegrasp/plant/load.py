r"""Grasps under load, read from a plant: gravity, motor limits, the plant's friction.

What the plant already knows is read from it, never re-derived:

* :func:`gravity_wrench`: the object's weight as a wrench in its body frame O
  about O's origin, ``[R_OW m g_W; p_OBcm × (R_OW m g_W)]``, from its mass and
  centre of mass in the context and the plant's gravity field.
* :func:`plant_torque_limits`: per hand velocity, the effort limit of the
  joint actuator that drives it (``JointActuator.effort_limit()``; ``inf``
  when an actuator has none); a hand joint without an actuator is passive and
  gets 0 (it can carry no torque), except the floating joint of a free hand
  base, which is held where it is placed (``inf``).  In a coupled hand every
  actuator still pushes: the independent coordinate ``u_i`` carries
  ``τ_i + Σ_k ρ_k τ_k`` over the joints that follow it, so its limit is
  ``Σ_k |C_ki| τ_max,k`` (:func:`~drakegrasp.plant.couplings.coupled_torque_limits`).
* the plant's friction, per contact (:mod:`drakegrasp.plant.friction`).

:func:`analyze_load` puts them together for
:func:`~drakegrasp.analyze_grasp` (options ``load``, ``torque_limits`` and
``mu="plant"``): whether the hand holds the load, with which joint torques
and squeeze, the payload factor and the joint that limits it first, and a
warning where a given ``μ`` disagrees with the plant's.

**Held by the motors.**  Some contacts may hold a squeeze that loads no
joint: a force ``h != 0`` in the friction cones with ``G h = 0`` and ``Jᵀ h =
0`` (:func:`passive_preload`; a *defective* hand-object system in
Prattichizzo & Trinkle's terms, such as two jaws that a coupling moves the
same way).  A load balanced with such a squeeze is balanced by a preload that
the motors can neither create nor renew, and is not called held.  The load is
held by the motors when the contacts of some set of hand bodies (whole
fingers, or the palm) that admits no such squeeze hold it alone: the forces
there are the motors' to make.  The largest such sets are tried first (all
bodies but one, then all but two..., at most :data:`MAX_BODY_SETS`); the
report names the set whose payload is largest among them (``motor_bodies``),
and when none holds the load, ``holds`` is False and ``needs_preload`` True.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass, fields

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JointActuatorIndex
from pydrake.solvers import MathematicalProgram

from drakegrasp._solvers import require_solution, solve
from drakegrasp.closure.load_forces import GraspForceResult, grasp_forces
from drakegrasp.closure.payload import MaxLoadResult, max_load
from drakegrasp.core.friction_cone import friction_cone_generators
from drakegrasp.core.grasp import grasp_matrix
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import check_distance_tolerance, describe, real_array
from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.plant.couplings import coupled_torque_limits, split_coupled_torque
from drakegrasp.plant.fingers import effort_unit, limit_towards
from drakegrasp.plant.friction import (
    friction_disagreement,
    friction_rule,
    plant_friction,
)
from drakegrasp.plant.options import PLANES, check_object_mass, check_plane
from drakegrasp.plant.validation import (
    check_velocity_indices,
    plant_context_of,
    resolve_object_body,
)

__all__ = [
    "MAX_BODY_SETS",
    "MAX_LOAD",
    "TORQUE_RESOLUTION",
    "PRELOAD_TOL",
    "LoadReport",
    "analyze_load",
    "load_section",
    "pressing_on_limits",
    "gravity_wrench",
    "passive_preload",
    "plant_torque_limits",
    "unbounded_actuators",
]


MAX_LOAD = 1e300
"""Largest magnitude (N, N·m) of a given load's components: the load programs
multiply them (``analyze --load 0,0,-1e308,...`` printed ``-inf`` beside
numpy's overflow warnings); every load up to this resolves, with and without
torque limits, on the default scene."""

FLOATING_JOINTS = ("quaternion_floating", "rpy_floating")
"""Drake joint types of a free body: six velocities that no actuator drives."""


def gravity_wrench(
    plant: MultibodyPlant, plant_context, object_body, *, plane=None, mass=None
):
    """The object's weight as a wrench in its body frame O, about O's origin.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
        The plant's context (or the diagram's root context): pose and mass.
    object_body : RigidBody, BodyIndex or str
    plane : {"xy", "yz", "zx"}, optional
        Planar analysis: ``[f_a, f_b, m_c]`` in that plane of O.
    mass : float, optional
        The mass ``m`` to weigh (kg, finite and > 0), at the body's centre of
        mass; default: the body's own (``AnalysisOptions.object_mass``).

    Returns
    -------
    (6,) or (3,) float
        ``[f_O; m_O]`` (N, N·m): ``f_O = R_OW m g_W``,
        ``m_O = p_OBcm × f_O``.
    """
    ctx = plant_context_of(plant, plant_context)
    body = resolve_object_body(plant, object_body)
    plane = check_plane(plane)
    R_WO = plant.EvalBodyPoseInWorld(ctx, body).rotation().matrix()
    g_W = np.asarray(plant.gravity_field().gravity_vector(), dtype=float)
    own = float(body.get_mass(ctx))
    if mass is not None and not own > 0.0:
        raise InvalidOptionError(
            f"object_mass = {describe(mass)} kg: the model gives {body.name()!r} no "
            "mass, "
            "so no centre of mass to weigh it at; give the load as a wrench "
            "[f; m] in frame O about its origin"
        )
    mass = own if mass is None else check_object_mass(mass)
    p_OBcm = np.asarray(body.CalcCenterOfMassInBodyFrame(ctx), dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        f_O = R_WO.T @ (mass * g_W)
        m_O = np.cross(p_OBcm, f_O)
    w = np.concatenate([f_O, m_O])
    if not np.max(np.abs(w)) <= MAX_LOAD:  # NaN too: inf m g times a lever 0
        raise InvalidOptionError(
            f"the weight of {mass:g} kg ({body.name()!r}) is more than "
            f"{MAX_LOAD:g} (N, N·m): the programs' products of such numbers "
            "overflow"
        )
    if plane is None:
        return w
    a, b = PLANES[plane]
    c = ({0, 1, 2} - {a, b}).pop()
    return np.array([f_O[a], f_O[b], m_O[c]])


def plant_torque_limits(
    plant: MultibodyPlant, velocity_indices: np.ndarray
) -> np.ndarray:
    """Effort limits of the actuators driving the given plant velocities.

    Parameters
    ----------
    plant : MultibodyPlant
    velocity_indices : (n_h,) int
        The hand's velocities (``GraspFromPlant.hand_velocity_indices``).

    Returns
    -------
    (n_h,) float
        ``effort_limit()`` of the actuator on each velocity (N·m or N; ``inf``
        for an actuator without one), 0 for a velocity no actuator drives,
        ``inf`` for the velocities of a floating joint (a free hand base).

    Notes
    -----
    A hand whose base is a free body (the floating gripper of grasp planning)
    is placed by setting its pose: whatever holds it there (an arm, a weld in
    simulation) supplies the base's wrench, so no limit bounds it.  Counting
    the floating joint as passive would make every grasp of such a hand fail
    to hold any load.

    Raises
    ------
    InvalidOptionError
        ``velocity_indices`` that are not each a velocity of the plant, once
        (:func:`~drakegrasp.plant.validation.check_velocity_indices`).
    """
    velocity_indices = check_velocity_indices(plant, velocity_indices)
    limit_of = {}
    for index in plant.GetJointIndices():
        joint = plant.get_joint(index)
        if joint.type_name() in FLOATING_JOINTS:
            for j in range(joint.num_velocities()):
                limit_of[joint.velocity_start() + j] = math.inf
    for k in range(plant.num_actuators()):
        actuator = plant.get_joint_actuator(JointActuatorIndex(k))
        joint = actuator.joint()
        for j in range(joint.num_velocities()):
            limit_of[joint.velocity_start() + j] = float(actuator.effort_limit())
    return np.array([limit_of.get(int(v), 0.0) for v in velocity_indices], dtype=float)


def unbounded_actuators(
    plant: MultibodyPlant, velocity_indices: np.ndarray
) -> tuple[str, ...]:
    """The joints among ``velocity_indices`` whose actuator has no effort limit.

    Drake gives an actuator an infinite ``effort_limit()`` where the model
    states none (an SDFormat joint without ``<effort>``, a URDF ``<limit>``
    without ``effort``): :func:`plant_torque_limits` then bounds nothing
    there, and "holds" means with any torque.  A floating base's ``inf`` is
    not counted (it is held where placed, not driven).

    Parameters
    ----------
    plant : MultibodyPlant
    velocity_indices : (n,) int
        Plant velocities, as for :func:`plant_torque_limits`.

    Returns
    -------
    tuple of str
        Joint names, in the order of ``velocity_indices``, each once.

    Raises
    ------
    InvalidOptionError
        As :func:`plant_torque_limits`.
    """
    velocity_indices = check_velocity_indices(plant, velocity_indices)
    wanted = {int(v) for v in velocity_indices}
    found = {}
    for k in range(plant.num_actuators()):
        actuator = plant.get_joint_actuator(JointActuatorIndex(k))
        joint = actuator.joint()
        starts = range(
            joint.velocity_start(), joint.velocity_start() + joint.num_velocities()
        )
        if math.isinf(actuator.effort_limit()) and wanted.intersection(starts):
            found[min(wanted.intersection(starts))] = joint.name()
    return tuple(found[v] for v in sorted(found))


def _unactuated_warning(names: tuple[str, ...]) -> str:
    listed = ", ".join(repr(n) for n in names)
    return (
        f"{listed} {'has' if len(names) == 1 else 'have'} no actuator in the "
        "model (or an effort limit of 0), so torque_limits='plant' gives "
        f"{'it' if len(names) == 1 else 'them'} 0 (no torque: a passive joint); "
        "where a motor drives them, give the model its actuators (a URDF "
        "<transmission>, an SDFormat <effort>), or pass torque_limits"
    )


TORQUE_RESOLUTION = 1e-6
"""Joint torques below this fraction of the largest are the solver's noise
(:func:`pressing_on_limits`): an Allegro finger without contacts carried
5e-10-9e-10 N·m beside a 0.2 N·m peak."""


def pressing_on_limits(
    plant: MultibodyPlant, plant_context, data, joint_torques, distance_tolerance
) -> tuple[str, ...]:
    """The hand joints that would press the squeeze on their own limits.

    A one-dof joint ``j`` that moves a contact (``∂ψ_i/∂q_j ≠ 0``), whose
    torque ``τ_j`` (above :data:`TORQUE_RESOLUTION` of the largest) drives it
    towards a finite limit that its contacts reach within the contact
    tolerance: ``|q_limit -
    q_j| · max_i |∂ψ_i/∂q_j| <= distance_tolerance`` (the contacts' travel
    left).  On a coupled hand every joint, followers included, is driven
    the way ``C τ`` says (``τ`` per independent coordinate).  Its motor
    then presses on the limit, not on the object: Drake dropped a rod held
    by a jaw 0.05 mm from its closed limit at any squeeze up to its motors'
    8 N.

    Parameters
    ----------
    plant, plant_context
    data : GraspFromPlant
        ``hand_velocity_indices`` and ``dpsi_dv`` (``(N, nv)``).
    joint_torques : (n_h,) float
        The efforts the load needs, per hand velocity (N·m or N; a coupled
        hand's per independent coordinate).
    distance_tolerance : float
        Metres.

    Returns
    -------
    tuple of str
        The joints' names, in the order of the hand's velocities.
    """
    q_all = plant.GetPositions(plant_context_of(plant, plant_context))
    by_velocity = {}
    for index in plant.GetJointIndices():
        joint = plant.get_joint(index)
        if joint.num_velocities() == 1 and joint.num_positions() == 1:
            by_velocity[joint.velocity_start()] = joint
    distance_tolerance = check_distance_tolerance(distance_tolerance)
    dpsi = np.asarray(data.dpsi_dv, dtype=float)
    tau = real_array("joint_torques", joint_torques, error=InvalidOptionError)
    velocities = data.hand_velocity_indices
    if tau.shape != (len(velocities),) or not np.all(np.isfinite(tau)):
        raise InvalidOptionError(
            f"joint_torques must be {len(velocities)} finite numbers, one per hand "
            f"velocity, got shape {tau.shape}"
            + ("" if tau.shape != (len(velocities),) else " with a value not finite")
        )
    coupling = _coupling(data)
    if coupling is not None:  # every joint, followers too: each moves as C τ says
        C, velocities = coupling
        tau = np.asarray(C, dtype=float) @ tau
    scale = float(np.max(np.abs(tau), initial=0.0))
    found = []
    for v, t in zip(velocities, tau, strict=True):
        joint = by_velocity.get(int(v))
        reach = float(np.max(np.abs(dpsi[:, int(v)]), initial=0.0))
        if joint is None or not abs(t) > TORQUE_RESOLUTION * scale or reach == 0.0:
            continue  # a free base's velocity, no torque, or no contact it moves
        q = float(q_all[joint.position_start()])
        limit = limit_towards(joint, t)
        if np.isfinite(limit) and abs(limit - q) * reach <= distance_tolerance:
            found.append(joint.name())
    return tuple(found)


def _on_limits_warning(names: tuple[str, ...], tolerance: float) -> str:
    listed = ", ".join(repr(n) for n in names)
    return (
        f"{listed} {'presses' if len(names) == 1 else 'press'} towards "
        f"{'its limit' if len(names) == 1 else 'their limits'}, which the "
        f"contacts reach within the contact tolerance ({tolerance:g} m): the "
        "motor would press on the limit, not squeeze the object, so the hold "
        "rests on how the limit gives (open the hand a little, or grasp where "
        "the fingers have travel left)"
    )


def _unbounded_warning(names: tuple[str, ...]) -> str:
    listed = ", ".join(repr(n) for n in names)
    return (
        f"the actuators of {listed} have no effort limit in the model (Drake "
        "takes a missing <effort> as unbounded), so torque_limits='plant' "
        "bounds nothing there and 'holds' allows any torque; give the joints "
        "an <effort> (SDFormat) or effort= (URDF), or pass torque_limits"
    )


@dataclass(frozen=True, eq=False)
class LoadReport:
    """Whether the hand holds its load, and with what (``GraspReport.load``).

    Attributes
    ----------
    wrench : (6,) or (3,) float
        The external wrench on the object, frame O about its origin (N, N·m).
    source : str
        ``"gravity"`` or ``"given"``.
    object_mass : float or None
        With ``source == "gravity"``, the mass weighed (kg) when it is not
        the model's (``AnalysisOptions.object_mass``); None: the model's.
    holds : bool
        Forces in the (exact) cones and within the torque limits hold it.
    forces : GraspForceResult
        The least-squeeze forces and their joint torques (or the certificate
        that none exist).
    payload : MaxLoadResult or None
        The largest multiple of the load the hand holds (the payload factor
        ``payload.alpha``; ``>= 1`` when it holds); None for a zero load,
        which has no direction to grow along (and is held with no force).
    torque_limits : (n_h,) float or None
        The limits used, per hand velocity (``inf`` = none).
    torque_limits_source : str
        ``"plant"`` (actuator effort limits), ``"given"`` or ``"none"``.
    joint_names : tuple of str
        What each hand velocity is: its joint's name for a one-dof joint; for
        a free hand base's floating joint, ``"free base NAME mx"`` ...
        ``"free base NAME fz"`` (the moment about the base body's origin and
        the force, in world axes, that its six velocities carry: Drake names
        that joint after the body); another multi-dof joint's
        ``"NAME SUFFIX"`` with Drake's velocity suffix (``wx``, ``vy``...).
    first_saturating_joint : str or None
        The joint whose limit binds first as the load grows (at the payload).
    mu : (N,) float
        The friction used per contact.
    mu_plant : (N,) float or None
        The plant's combined coefficient per contact (``friction_rule``).
    friction_rule : str
        ``"dynamic"`` (discrete plant) or ``"static"`` (continuous plant).
    warnings : tuple of str
        E.g. a given ``μ`` that disagrees with the plant's.
    torque_units : tuple of str
        The unit of each hand velocity's torque: ``"N"`` along a prismatic
        joint or a linear velocity, ``"N·m"`` about a revolute joint or an
        angular velocity (empty: not known).
    actuator_names : tuple of str
        Coupled hand only (else empty): every hand velocity, followers of
        couplings included, each with its own actuator.  ``joint_torques``
        and ``torque_limits`` are then per *independent coordinate*: the
        generalized force ``Cᵀ τ`` its actuators and its followers' make
        together, bounded by ``Σ_k |C_ki| τ_max,k``.
    actuator_torque_limits : (n_a,) float or None
        Coupled hand: the effort limit of each of ``actuator_names``.
    actuator_torques : (n_a,) float or None
        Coupled hand, when held: efforts with ``Cᵀ τ = joint_torques``, each
        coordinate's force shared in proportion to the limits
        (:func:`~drakegrasp.plant.couplings.split_coupled_torque`).
    actuator_units : tuple of str
        The unit of each of ``actuator_names``' efforts.
    defective : bool
        Some contacts can hold a squeeze that loads no joint
        (:func:`passive_preload`); decided when the load is balanced and
        not zero (False otherwise).
    needs_preload : bool
        Forces in the cones and limits balance the load, but only with a
        squeeze the motors cannot create (``defective`` and no set of hand
        bodies that admits no such squeeze holds it): ``holds`` is False;
        ``forces`` are those a preload would need.
    motor_bodies : tuple of str or None
        ``defective`` and held: the hand bodies whose contacts hold the load
        alone (``forces`` are zero elsewhere): of the largest sets that do,
        the one with the largest ``payload`` (its certificate on their
        sub-grasp).  None otherwise.
    """

    wrench: np.ndarray
    source: str
    holds: bool
    forces: GraspForceResult
    payload: MaxLoadResult | None
    torque_limits: np.ndarray | None
    torque_limits_source: str
    joint_names: tuple[str, ...]
    first_saturating_joint: str | None
    mu: np.ndarray
    mu_plant: np.ndarray | None
    friction_rule: str
    warnings: tuple[str, ...] = ()
    torque_units: tuple[str, ...] = ()
    actuator_names: tuple[str, ...] = ()
    actuator_torque_limits: np.ndarray | None = None
    actuator_torques: np.ndarray | None = None
    actuator_units: tuple[str, ...] = ()
    defective: bool = False
    needs_preload: bool = False
    motor_bodies: tuple[str, ...] | None = None
    object_mass: float | None = None

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}

    def report_lines(self) -> list[str]:
        """The report's ``load`` section, one line per fact."""
        w = np.round(self.wrench, 4).tolist()
        weighed = (
            "" if self.object_mass is None else f" of {self.object_mass:g} kg given"
        )
        lines = [
            f"Load ({self.source}{weighed}, frame O about its origin): {w}",
            f"  holds: {'yes' if self.holds else 'NO'}",
        ]
        if self.needs_preload:
            lines.append(
                "  only with a preload: every balance found squeezes along "
                "N(G) ∩ N(Jᵀ), which loads no joint, so no motor can create it "
                "(a defective grasp); the forces below are what that preload "
                "would have to supply"
            )
        elif self.motor_bodies is not None:
            lines.append(
                "  held by the motors through "
                + ", ".join(self.motor_bodies)
                + " alone (some contacts can hold a squeeze no motor creates; "
                "no hold "
                "leans on one)"
            )
        f = self.forces
        if f.feasible:
            lines.append(f"  least squeeze {f.squeeze:.4g} N in all (Σ f_n)")
            if f.joint_torques is not None:
                tau = _named(self.joint_names, f.joint_torques, self.torque_units)
                lines.append(f"  joint torques: {tau}")
            if self.actuator_torques is not None:
                lines.append(self._actuator_line())
        elif f.certificate is not None:
            lines.append(f"  why not: {f.certificate}")
        alpha = math.nan if self.payload is None else self.payload.alpha
        if self.payload is None and self.needs_preload:
            lines.append("  payload factor: none without a preload")
        elif self.payload is None:
            lines.append("  payload factor: none (a zero load has no direction)")
        elif math.isfinite(alpha):
            lines.append(
                f"  payload factor {alpha:.4g} (largest multiple of the load held)"
            )
        else:
            lines.append("  payload factor unbounded (no limit binds along the load)")
        coupled = ""
        if self.actuator_torque_limits is not None and self.torque_limits is not None:
            per = _named(
                self.joint_names, self.torque_limits, self.torque_units, signed=False
            )
            coupled = f" (per coordinate, its followers' actuators added: {per})"
        lines.append(
            f"  torque limits: {self.torque_limits_source}{coupled}; first to "
            f"saturate: {self.first_saturating_joint or 'none'}"
        )
        lines.append(
            f"  friction: mu = {np.round(self.mu, 4).tolist()}"
            + (
                ""
                if self.mu_plant is None
                else f"; plant ({self.friction_rule}) "
                f"{np.round(self.mu_plant, 4).tolist()}"
            )
        )
        lines += [f"  WARNING: {w}" for w in self.warnings]
        return lines

    def _actuator_line(self) -> str:
        """The coupled hand's efforts, of the joints that have an actuator.

        A follower without one (limit 0: a linkage's driven joint) makes no
        effort by :func:`~drakegrasp.plant.couplings.split_coupled_torque`;
        it is named apart, not listed as an actuator at 0.
        """
        limits = self.actuator_torque_limits
        driven = [
            i
            for i in range(len(self.actuator_names))
            if limits is None or limits[i] != 0.0
        ]
        units = self.actuator_units or ("",) * len(self.actuator_names)
        tau = _named(
            [self.actuator_names[i] for i in driven],
            [self.actuator_torques[i] for i in driven],
            [units[i] for i in driven],
        )
        line = f"  actuator efforts (coupled, shared by limit): {tau or 'none'}"
        passive = [n for i, n in enumerate(self.actuator_names) if i not in driven]
        if passive:
            line += f" (no actuator, moved by their leaders: {', '.join(passive)})"
        return line

    def __str__(self) -> str:
        return "\n".join(self.report_lines())


def _velocity_labels(
    plant: MultibodyPlant, velocity_indices
) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(label, torque unit) of each hand velocity.

    A one-dof joint's label is its name; a floating joint (a free hand base,
    whose joint Drake names after its body) reads ``"free base NAME mx"``
    ... ``"free base NAME fz"``: Drake orders its velocities ``[w; v]``, so
    its generalized forces are a moment (N·m) and a force (N).  Another
    multi-dof joint's velocity is ``"NAME SUFFIX"`` (Drake's
    ``velocity_suffix``).  The unit follows the suffix: an angular velocity
    (``w...``) carries N·m, a linear one (``v...``) N.
    """
    labels, units = {}, {}
    for j in plant.GetJointIndices():
        joint = plant.get_joint(j)
        n = joint.num_velocities()
        for k in range(n):
            suffix = joint.velocity_suffix(k)
            if joint.type_name() in FLOATING_JOINTS:
                part = {"w": "m", "v": "f"}.get(suffix[:1], suffix[:1]) + suffix[1:]
                label = f"free base {joint.name()} {part}"
            elif n == 1:
                label = joint.name()
            else:
                label = f"{joint.name()} {suffix}"
            i = joint.velocity_start() + k
            labels[i] = label
            units[i] = effort_unit(joint, k)
    return (
        tuple(labels.get(int(v), f"v[{int(v)}]") for v in velocity_indices),
        tuple(units.get(int(v), "") for v in velocity_indices),
    )


def _named(names, values, units, *, signed: bool = True) -> str:
    """``"name +1.23 N, ..."``: each value with its name and unit (if known)."""
    units = units or ("",) * len(names)
    form = "+.3g" if signed else ".4g"
    return ", ".join(
        f"{n} {t + 0.0:{form}}" + (f" {u}" if u else "")  # -0.0 reads 0
        for n, t, u in zip(names, values, units, strict=True)
    )


def _load_wrench(plant, plant_context, data, load, object_mass=None):
    if isinstance(load, str):
        if load != "gravity":
            raise InvalidOptionError(
                f"load must be None, 'gravity' or a wrench [f; m] in frame O, got "
                f"{describe(load)}"
            )
        return gravity_wrench(
            plant,
            plant_context,
            data.object_body,
            plane=data.plane,
            mass=object_mass,
        )
    if object_mass is not None:
        raise InvalidOptionError(
            f"object_mass ({object_mass:g} kg) is weighed by load='gravity'; "
            "a given wrench carries its own weight"
        )
    w = real_array("load", load, error=InvalidOptionError).reshape(-1)
    if w.shape != (data.grasp.wrench_dim,) or not np.all(np.isfinite(w)):
        raise InvalidOptionError(
            f"load must be 'gravity' or a finite {data.grasp.wrench_dim}-vector "
            f"[f; m] in frame O about its origin, got {np.asarray(load).tolist()}"
        )
    if np.max(np.abs(w)) > MAX_LOAD:
        raise InvalidOptionError(
            f"load components must be at most {MAX_LOAD:g} (N, N·m) in magnitude, "
            f"got {np.asarray(load).tolist()}: the programs' products of "
            "such numbers overflow"
        )
    return w


def _coupling(data):
    """``(C, every hand velocity)`` of a coupled hand, or None."""
    C = getattr(data, "coupling_matrix", None)
    every = getattr(data, "all_hand_velocity_indices", None)
    if C is None or every is None or C.shape[0] == C.shape[1]:
        return None
    return C, every


def _torque_limits(plant, data, torque_limits):
    """``(per coordinate, source, per actuator or None)``.

    For a coupled hand the plant's limits are read per actuator, followers
    included, and mapped onto the independent coordinates by
    :func:`~drakegrasp.plant.couplings.coupled_torque_limits`; given limits
    may be either, told apart by their length.  One given limit is every
    actuator's (the one coordinate's, when the hand has one).
    """
    coupling = _coupling(data)
    if torque_limits is None:
        return None, "none", None
    n_u = len(data.hand_velocity_indices)
    if isinstance(torque_limits, str):
        if torque_limits != "plant":
            raise InvalidOptionError(
                "torque_limits must be None, 'plant' or one limit per hand "
                f"velocity, got {describe(torque_limits)}"
            )
        if coupling is None:
            return plant_torque_limits(plant, data.hand_velocity_indices), "plant", None
        C, every = coupling
        per_actuator = plant_torque_limits(plant, every)
        return coupled_torque_limits(C, per_actuator), "plant", per_actuator
    given = np.asarray(torque_limits, dtype=float)
    if given.size == 1 and n_u != 1:  # one limit for every actuator
        count = n_u if coupling is None else len(coupling[1])
        given = np.full(count, float(given.reshape(-1)[0]))
    if coupling is not None and given.ndim == 1 and given.size == len(coupling[1]):
        C, _ = coupling
        if np.any(given < 0.0) or np.any(np.isnan(given)):
            raise InvalidOptionError(
                f"torque_limits must be >= 0 (inf: none), got {given.tolist()}"
            )
        return coupled_torque_limits(C, given), "given", given
    if coupling is not None and not (given.ndim == 0 or given.size == n_u):
        raise InvalidOptionError(
            f"torque_limits of a coupled hand take one limit per actuated joint "
            f"({len(coupling[1])}, followers included) or one per independent "
            f"coordinate ({n_u}), got {given.size}"
        )
    return given, "given", None


def analyze_load(
    plant: MultibodyPlant,
    plant_context,
    data,
    *,
    load,
    torque_limits=None,
    mu_given: float | None,
    mu_plant: np.ndarray | None,
    mu_dynamic: np.ndarray | None = None,
    object_mass: float | None = None,
    distance_tolerance: float | None = None,
) -> LoadReport:
    """The load section of a grasp report (see :class:`LoadReport`).

    Parameters
    ----------
    plant, plant_context
    data : GraspFromPlant
        The grasp (frame O), contacts and hand Jacobian.
    load : "gravity" or (6,) / (3,) float
        The external wrench on the object in frame O about its origin.
    torque_limits : None, "plant" or (n_h,) float
    mu_given : float or None
        The ``μ`` the caller typed (None with ``mu="plant"``).
    mu_plant : (N,) float or None
        The plant's friction per contact (None when it cannot be read).
    mu_dynamic : (N,) float or None, optional
        A continuous plant's dynamic friction per contact, for the wording of
        a disagreement (:func:`~drakegrasp.plant.friction.friction_disagreement`).
    object_mass : float or None, optional
        The mass (kg) ``load="gravity"`` weighs; None: the model's.
    distance_tolerance : float or None, optional
        The contact tolerance (m) the grasp was read with: a joint whose
        limit lies within it of the contacts, in the direction its torque
        drives, is warned of (:func:`pressing_on_limits`).
    """
    if distance_tolerance is not None:
        distance_tolerance = check_distance_tolerance(distance_tolerance)
    w = _load_wrench(plant, plant_context, data, load, object_mass)
    limits, source, per_actuator = _torque_limits(plant, data, torque_limits)
    J = data.hand_jacobian
    forces = grasp_forces(data.grasp, w, hand_jacobian=J, torque_limits=limits)
    payload = (
        max_load(data.grasp, w, hand_jacobian=J, torque_limits=limits)
        if np.any(w != 0.0)
        else None
    )
    defective, needs_preload, motor_bodies = False, False, None
    if forces.feasible and np.any(w != 0.0):
        motors = _held_by_motors(data, w, limits)
        if motors is not None:
            defective = True
            if motors[0] is None:
                needs_preload, payload = True, None
            else:
                motor_bodies, forces, payload = motors
    names, units = _velocity_labels(plant, data.hand_velocity_indices)
    first = (
        names[payload.saturating_joints[0]]
        if payload is not None and payload.saturating_joints
        else None
    )
    disagreement = friction_disagreement(
        plant, mu_given, mu_plant, mu_dynamic=mu_dynamic
    )
    warnings = [] if disagreement is None else [disagreement]
    coupling = _coupling(data)
    if source == "plant":
        driven = data.hand_velocity_indices if coupling is None else coupling[1]
        unbounded = unbounded_actuators(plant, driven)
        if unbounded:
            warnings.append(_unbounded_warning(unbounded))
        if np.any(limits == 0.0):  # per coordinate: a follower moves with its leader
            passive = tuple(n for n, t in zip(names, limits, strict=True) if t == 0.0)
            warnings.append(_unactuated_warning(passive))
    if forces.joint_torques is not None and distance_tolerance is not None:
        on_limits = pressing_on_limits(
            plant, plant_context, data, forces.joint_torques, distance_tolerance
        )
        if on_limits:
            warnings.append(_on_limits_warning(on_limits, distance_tolerance))
    actuator_names, actuator_units, actuator_torques = (), (), None
    if coupling is not None and per_actuator is not None:
        C, every = coupling
        actuator_names, actuator_units = _velocity_labels(plant, every)
        if forces.joint_torques is not None:
            actuator_torques = split_coupled_torque(
                C, per_actuator, forces.joint_torques
            )
    return LoadReport(
        wrench=w,
        source="gravity" if isinstance(load, str) else "given",
        holds=forces.feasible and not needs_preload,
        forces=forces,
        payload=payload,
        torque_limits=limits,
        torque_limits_source=source,
        joint_names=names,
        first_saturating_joint=first,
        mu=np.array([c.mu for c in data.grasp.contacts]),
        mu_plant=mu_plant,
        friction_rule=friction_rule(plant),
        warnings=tuple(warnings),
        torque_units=units,
        actuator_names=actuator_names,
        actuator_torque_limits=per_actuator,
        actuator_torques=actuator_torques,
        actuator_units=actuator_units,
        defective=defective,
        object_mass=None if object_mass is None else float(object_mass),
        needs_preload=needs_preload,
        motor_bodies=motor_bodies,
    )


PRELOAD_TOL = 1e-7
"""A passive preload exists when the contact forces below, with their normal
components summing to 1 (N), meet ``G f = 0`` and ``Jᵀ f = 0`` to this
residual (N, N·m; an exact one meets them to about 1e-12)."""


def passive_preload(grasp, hand_jacobian: np.ndarray) -> bool:
    r"""Whether some contacts can hold a squeeze that no motor creates or renews.

    That is a force ``h != 0`` in the (polyhedral) friction cones with
    ``G h = 0`` and ``Jᵀ h = 0``: an internal force that loads no joint (a
    *defective* hand-object system in Prattichizzo & Trinkle's terms).  Unlike
    LP3, which asks for every ``f_n > 0``, some contacts may carry none, so
    an extra contact that cannot join such a squeeze does not hide it.  One
    LP: the least residual ``|G S λ|_1 + |Jᵀ S λ|_1`` over ``λ >= 0`` with the
    normal components summing to 1; a preload exists when it is at most
    :data:`PRELOAD_TOL`.

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_q) float
        Rows in the contact frames of ``grasp`` (its components).

    Returns
    -------
    bool
    """
    b = grasp.characteristic_length
    blocks = [
        friction_cone_generators(c, characteristic_length=b) for c in grasp.contacts
    ]
    S = np.zeros((sum(k.shape[0] for k in blocks), sum(k.shape[1] for k in blocks)))
    row = col = 0
    for block in blocks:  # block-diagonal (scipy stays out of analyze's imports)
        S[row : row + block.shape[0], col : col + block.shape[1]] = block
        row, col = row + block.shape[0], col + block.shape[1]
    A = np.vstack([grasp_matrix(grasp), np.asarray(hand_jacobian).T]) @ S
    prog = MathematicalProgram()
    lam = prog.NewContinuousVariables(S.shape[1], "lambda")
    slack = prog.NewContinuousVariables(A.shape[0], "slack")
    prog.AddBoundingBoxConstraint(0.0, np.inf, lam)
    normals = S[[sl.start for sl in grasp.component_slices()]].sum(axis=0)
    prog.AddLinearEqualityConstraint(normals.reshape(1, -1), [1.0], lam)
    eye = np.eye(A.shape[0])
    # -slack <= A lam <= slack
    prog.AddLinearConstraint(
        np.hstack([A, -eye]), np.full(A.shape[0], -np.inf), np.zeros(A.shape[0]),
        np.concatenate([lam, slack]),
    )  # fmt: skip
    prog.AddLinearConstraint(
        np.hstack([A, eye]), np.zeros(A.shape[0]), np.full(A.shape[0], np.inf),
        np.concatenate([lam, slack]),
    )  # fmt: skip
    prog.AddLinearCost(np.ones(A.shape[0]), 0.0, slack)
    result = require_solution(prog, solve(prog, "lp"), "the passive-preload LP")
    return bool(result.get_optimal_cost() <= PRELOAD_TOL)


MAX_BODY_SETS = 256
"""How many sets of hand bodies a defective grasp's load check tries (the
largest first: all bodies but one, then all but two...), so that a hand with
many touching bodies cannot hang it; past this, no set found reads as "not
held by the motors" (the conservative answer)."""


def _held_by_motors(data, w, limits):
    """None for a hand that controls every squeeze, else how the motors hold.

    Returns ``(bodies, forces, payload)`` for the largest set of hand bodies
    (then the largest payload) whose contacts admit no passive preload and
    hold ``w`` alone, with the forces spread back over every contact; ``(None,
    None, None)`` when no such set holds it among the first
    :data:`MAX_BODY_SETS` tried.
    """
    grasp, J = data.grasp, data.hand_jacobian
    if not passive_preload(grasp, J):
        return None
    bodies = list(dict.fromkeys(c.finger_body for c in data.contacts))
    slices = grasp.component_slices()
    best = None
    sets = itertools.chain.from_iterable(
        itertools.combinations(bodies, size) for size in range(len(bodies) - 1, 0, -1)
    )
    for chosen in itertools.islice(sets, MAX_BODY_SETS):
        if best is not None and len(chosen) < len(best[0]):
            break  # the largest sets come first: a smaller one is not wanted
        keep = [i for i, c in enumerate(data.contacts) if c.finger_body in chosen]
        rows = np.concatenate([np.arange(J.shape[0])[slices[i]] for i in keep])
        sub = grasp.with_contacts([grasp.contacts[i] for i in keep])
        J_sub = J[rows]
        if passive_preload(sub, J_sub):
            continue
        held = grasp_forces(sub, w, hand_jacobian=J_sub, torque_limits=limits)
        if not held.feasible:
            continue
        payload = max_load(sub, w, hand_jacobian=J_sub, torque_limits=limits)
        if best is None or payload.alpha > best[2].alpha:
            full = [np.zeros(s_.stop - s_.start) for s_ in slices]
            for i, f in zip(keep, held.contact_forces, strict=True):
                full[i] = f
            best = (
                chosen,
                dataclasses.replace(held, contact_forces=tuple(full)),
                payload,
            )
    return (None, None, None) if best is None else best


def load_section(
    plant,
    plant_context,
    data,
    *,
    mu,
    load,
    torque_limits,
    query_object=None,
    object_mass=None,
    distance_tolerance=None,
):
    """What :func:`~drakegrasp.analyze_grasp` adds for ``mu="plant"`` and a load.

    ``object_mass`` (kg; None: the model's) is what ``load="gravity"`` weighs;
    ``distance_tolerance`` (m), the contact tolerance, finds joints that would
    press on their limits (:func:`pressing_on_limits`).

    Returns
    -------
    data : GraspFromPlant
        ``data`` with each contact's ``μ`` read from the plant when
        ``mu == "plant"`` (the Jacobians do not depend on ``μ``).
    load : LoadReport or None
        The load section when ``load`` is given.
    """
    if isinstance(mu, str) and mu != "plant":
        raise InvalidOptionError(f"mu must be a number or 'plant', got {describe(mu)}")
    if load is None and not (isinstance(mu, str)):
        if torque_limits is not None:
            raise InvalidOptionError(
                "torque_limits are used by the load section: pass load='gravity' "
                "or a wrench"
            )
        return data, None
    mu_plant = None
    try:
        mu_plant = plant_friction(
            plant, plant_context, data.contacts, query_object=query_object
        )
    except ModelError:
        if isinstance(mu, str):
            raise
    mu_dynamic = None  # what plan --mu plant and a discrete simulation use
    if mu_plant is not None and not isinstance(mu, str) and plant.time_step() == 0:
        mu_dynamic = plant_friction(
            plant, plant_context, data.contacts, query_object=query_object,
            rule="dynamic",
        )  # fmt: skip
    if isinstance(mu, str):
        grasp = data.grasp.with_contacts(
            [c.with_(mu=m) for c, m in zip(data.grasp.contacts, mu_plant, strict=True)]
        )
        data = dataclasses.replace(data, grasp=grasp)
    if load is None:
        if torque_limits is not None:
            raise InvalidOptionError(
                "torque_limits are used by the load section: pass load='gravity' "
                "or a wrench"
            )
        return data, None
    report = analyze_load(
        plant,
        plant_context,
        data,
        load=load,
        torque_limits=torque_limits,
        mu_given=None if isinstance(mu, str) else float(mu),
        mu_plant=mu_plant,
        mu_dynamic=mu_dynamic,
        object_mass=object_mass,
        distance_tolerance=distance_tolerance,
    )
    return data, report
