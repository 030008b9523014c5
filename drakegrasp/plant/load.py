r"""Grasps under load, read from a plant: gravity, motor limits, the plant's friction.

What the plant already knows is read from it, never re-derived:

* :func:`gravity_wrench`: the object's weight as a wrench in its body frame O
  about O's origin, ``[R_OW m g_W; p_OBcm × (R_OW m g_W)]``, from its mass and
  centre of mass in the context and the plant's gravity field.
* :func:`plant_torque_limits`: per hand velocity, the effort limit of the
  joint actuator that drives it (``JointActuator.effort_limit()``; ``inf``
  when an actuator has none); a hand joint without an actuator is passive and
  gets 0 (it can carry no torque), except the floating joint of a free hand
  base, which is held where it is placed (``inf``).
* the plant's friction, per contact (:mod:`drakegrasp.plant.friction`).

:func:`analyze_load` puts them together for
:func:`~drakegrasp.analyze_grasp` (options ``load``, ``torque_limits`` and
``mu="plant"``): whether the hand holds the load, with which joint torques
and squeeze, the payload factor and the joint that limits it first, and a
warning where a given ``μ`` disagrees with the plant's.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, fields

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JointActuatorIndex

from drakegrasp.closure.grasp_forces import GraspForceResult, grasp_forces
from drakegrasp.closure.payload import MaxLoadResult, max_load
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import real_array
from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.plant.fingers import effort_unit
from drakegrasp.plant.friction import (
    friction_disagreement,
    friction_rule,
    plant_friction,
)
from drakegrasp.plant.options import PLANES
from drakegrasp.plant.validation import (
    plant_context_of,
    resolve_object_body,
)

__all__ = [
    "LoadReport",
    "analyze_load",
    "load_section",
    "gravity_wrench",
    "plant_torque_limits",
]


FLOATING_JOINTS = ("quaternion_floating", "rpy_floating")
"""Drake joint types of a free body: six velocities that no actuator drives."""


def gravity_wrench(plant: MultibodyPlant, plant_context, object_body, *, plane=None):
    """The object's weight as a wrench in its body frame O, about O's origin.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
        The plant's context (or the diagram's root context): pose and mass.
    object_body : RigidBody, BodyIndex or str
    plane : {"xy", "yz", "zx"}, optional
        Planar analysis: ``[f_a, f_b, m_c]`` in that plane of O.

    Returns
    -------
    (6,) or (3,) float
        ``[f_O; m_O]`` (N, N·m): ``f_O = R_OW m g_W``,
        ``m_O = p_OBcm × f_O``.
    """
    ctx = plant_context_of(plant, plant_context)
    body = resolve_object_body(plant, object_body)
    R_WO = plant.EvalBodyPoseInWorld(ctx, body).rotation().matrix()
    g_W = np.asarray(plant.gravity_field().gravity_vector(), dtype=float)
    mass = float(body.get_mass(ctx))
    p_OBcm = np.asarray(body.CalcCenterOfMassInBodyFrame(ctx), dtype=float)
    f_O = R_WO.T @ (mass * g_W)
    m_O = np.cross(p_OBcm, f_O)
    if plane is None:
        return np.concatenate([f_O, m_O])
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
    """
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


@dataclass(frozen=True, eq=False)
class LoadReport:
    """Whether the hand holds its load, and with what (``GraspReport.load``).

    Attributes
    ----------
    wrench : (6,) or (3,) float
        The external wrench on the object, frame O about its origin (N, N·m).
    source : str
        ``"gravity"`` or ``"given"``.
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

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}

    def report_lines(self) -> list[str]:
        """The report's ``load`` section, one line per fact."""
        w = np.round(self.wrench, 4).tolist()
        lines = [
            f"Load ({self.source}, frame O about its origin): {w}",
            f"  holds: {'yes' if self.holds else 'NO'}",
        ]
        f = self.forces
        if f.feasible:
            lines.append(f"  least squeeze {f.squeeze:.4g} N")
            if f.joint_torques is not None:
                units = self.torque_units or ("",) * len(self.joint_names)
                tau = ", ".join(
                    f"{n} {t:+.3g}" + (f" {u}" if u else "")
                    for n, t, u in zip(
                        self.joint_names, f.joint_torques, units, strict=True
                    )
                )
                lines.append(f"  joint torques: {tau}")
        elif f.certificate is not None:
            lines.append(f"  why not: {f.certificate}")
        alpha = math.nan if self.payload is None else self.payload.alpha
        if self.payload is None:
            lines.append("  payload factor: none (a zero load has no direction)")
        elif math.isfinite(alpha):
            lines.append(
                f"  payload factor {alpha:.4g} (largest multiple of the load held)"
            )
        else:
            lines.append("  payload factor unbounded (no limit binds along the load)")
        lines.append(
            f"  torque limits: {self.torque_limits_source}; first to saturate: "
            f"{self.first_saturating_joint or 'none'}"
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


def _load_wrench(plant, plant_context, data, load):
    if isinstance(load, str):
        if load != "gravity":
            raise InvalidOptionError(
                f"load must be None, 'gravity' or a wrench [f; m] in frame O, got "
                f"{load!r}"
            )
        return gravity_wrench(plant, plant_context, data.object_body, plane=data.plane)
    w = real_array("load", load, error=InvalidOptionError).reshape(-1)
    if w.shape != (data.grasp.wrench_dim,) or not np.all(np.isfinite(w)):
        raise InvalidOptionError(
            f"load must be 'gravity' or a finite {data.grasp.wrench_dim}-vector "
            f"[f; m] in frame O about its origin, got {np.asarray(load).tolist()}"
        )
    return w


def _torque_limits(plant, data, torque_limits):
    if torque_limits is None:
        return None, "none"
    if isinstance(torque_limits, str):
        if torque_limits != "plant":
            raise InvalidOptionError(
                "torque_limits must be None, 'plant' or one limit per hand "
                f"velocity, got {torque_limits!r}"
            )
        return plant_torque_limits(plant, data.hand_velocity_indices), "plant"
    return np.asarray(torque_limits, dtype=float), "given"


def analyze_load(
    plant: MultibodyPlant,
    plant_context,
    data,
    *,
    load,
    torque_limits=None,
    mu_given: float | None,
    mu_plant: np.ndarray | None,
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
    """
    w = _load_wrench(plant, plant_context, data, load)
    limits, source = _torque_limits(plant, data, torque_limits)
    J = data.hand_jacobian
    forces = grasp_forces(data.grasp, w, hand_jacobian=J, torque_limits=limits)
    payload = (
        max_load(data.grasp, w, hand_jacobian=J, torque_limits=limits)
        if np.any(w != 0.0)
        else None
    )
    names, units = _velocity_labels(plant, data.hand_velocity_indices)
    first = (
        names[payload.saturating_joints[0]]
        if payload is not None and payload.saturating_joints
        else None
    )
    disagreement = friction_disagreement(plant, mu_given, mu_plant)
    warnings = [] if disagreement is None else [disagreement]
    return LoadReport(
        wrench=w,
        source="gravity" if isinstance(load, str) else "given",
        holds=forces.feasible,
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
    )


def load_section(
    plant, plant_context, data, *, mu, load, torque_limits, query_object=None
):
    """What :func:`~drakegrasp.analyze_grasp` adds for ``mu="plant"`` and a load.

    Returns
    -------
    data : GraspFromPlant
        ``data`` with each contact's ``μ`` read from the plant when
        ``mu == "plant"`` (the Jacobians do not depend on ``μ``).
    load : LoadReport or None
        The load section when ``load`` is given.
    """
    if isinstance(mu, str) and mu != "plant":
        raise InvalidOptionError(f"mu must be a number or 'plant', got {mu!r}")
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
    )
    return data, report
