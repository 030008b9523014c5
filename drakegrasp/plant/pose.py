"""Pose validity: is the configuration one a real hand could be in.

Two facts make a pose impossible for a grasp analysis:

- **penetration**: a collision geometry of any body of the hand's model
  instances (the moving fingers *and* the palm, welded to the world or not)
  overlaps the object by more than the distance tolerance (``ψ < −tol``);
- **joint limits**: a joint of the hand's model instances sits outside its
  position limits by more than :data:`JOINT_LIMIT_TOL`.

:func:`check_pose` collects both into a :class:`PoseCheck`;
:meth:`PoseCheck.raise_if_invalid` turns the first kind found into a
:class:`~drakegrasp.PenetrationError` or :class:`~drakegrasp.JointLimitError`
(both :class:`~drakegrasp.InvalidPoseError`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JointIndex, RigidBody
from pydrake.systems.framework import Context

from drakegrasp.core.calls import checked_call
from drakegrasp.errors import (
    CouplingError,
    InvalidPoseError,
    JointLimitError,
    ModelError,
    PenetrationError,
)
from drakegrasp.plant.validation import pair_distance, query_object_of, scoped_name

__all__ = [
    "JOINT_LIMIT_REMEDY",
    "JOINT_LIMIT_TOL",
    "PENETRATION_REMEDY",
    "JointLimitViolation",
    "Penetration",
    "PoseCheck",
    "check_pose",
    "find_penetrations",
]

JOINT_LIMIT_TOL = 1e-4
"""A joint this far (metres or radians) outside a limit violates it.

Drake keeps a joint at its limit with a stiff constraint, not an exact one, so
a simulated state overshoots by a little: the Allegro hand seated on the YCB
soup can in the shake test had ``joint_13`` 5e-6 rad below its lower limit,
and a tolerance of 1e-8 refused the state as an impossible pose.  1e-4, the
size of the default ``distance_tolerance`` (the penetration a contact may
have), is 20 times that, and far below the mistakes the check is for (degrees
given as radians, a wrong sign, another joint's value)."""


@dataclass(frozen=True)
class Penetration:
    """A hand geometry that overlaps the object.

    Attributes
    ----------
    hand_body, hand_geometry, object_geometry : str
        Scoped body name and the two geometries' names.
    depth : float
        ``−ψ`` in metres (> the distance tolerance).
    """

    hand_body: str
    hand_geometry: str
    object_geometry: str
    depth: float

    def __str__(self) -> str:
        return (
            f"{self.hand_body} ({self.hand_geometry}) penetrates the object "
            f"({self.object_geometry}) by {self.depth * 1e3:.4g} mm"
        )


@dataclass(frozen=True)
class JointLimitViolation:
    """A joint position outside its limits.

    Attributes
    ----------
    joint : str
        Scoped joint name ``model::joint`` (with ``[k]`` for multi-dof joints).
    value, lower, upper : float
        The position and its limits (metres or radians).
    """

    joint: str
    value: float
    lower: float
    upper: float

    def __str__(self) -> str:
        return (
            f"{self.joint} = {self.value:.6g} is outside its limits "
            f"[{self.lower:.6g}, {self.upper:.6g}]"
        )


PENETRATION_REMEDY = (
    "pass check_pose=False, or allow_penetration=True, to analyse it anyway"
)
"""The remedy of a :class:`PenetrationError` raised by a pose check (Python)."""

JOINT_LIMIT_REMEDY = "pass check_pose=False to analyse it anyway"
"""The remedy of a :class:`JointLimitError` raised by a pose check (Python)."""


@checked_call
@dataclass(frozen=True)
class PoseCheck:
    """What :func:`check_pose` found.

    Attributes
    ----------
    penetrations : tuple of Penetration
    joint_limit_violations : tuple of JointLimitViolation
    checked : bool
        False when the caller skipped the refusal (``check_pose=False``); the
        findings are still listed.
    coupling_violations : tuple of CouplingViolation
        Joint couplings (a ``<mimic>``'s coupler constraint, ``couplings=``)
        that the configuration breaks
        (:func:`~drakegrasp.plant.couplings.coupling_violations`).
    """

    penetrations: tuple[Penetration, ...] = ()
    joint_limit_violations: tuple[JointLimitViolation, ...] = ()
    checked: bool = True
    coupling_violations: tuple = ()

    @property
    def valid(self) -> bool:
        """True without penetration, a joint off limits or a broken coupling."""
        return (
            not self.penetrations
            and not self.joint_limit_violations
            and not self.coupling_violations
        )

    def raise_if_invalid(self) -> None:
        """Raise an :class:`~drakegrasp.errors.InvalidPoseError` if invalid.

        :class:`PenetrationError`, :class:`JointLimitError` or
        :class:`CouplingError`, in that order.

        The message's remedy names the Python options (:data:`PENETRATION_REMEDY`,
        :data:`JOINT_LIMIT_REMEDY`); the command line swaps in its flags with
        :meth:`~drakegrasp.errors.InvalidPoseError.with_remedy`.
        """
        if self.penetrations:
            raise PenetrationError(
                "impossible pose: " + "; ".join(map(str, self.penetrations)),
                remedy=PENETRATION_REMEDY,
            )
        if self.joint_limit_violations:
            raise JointLimitError(
                "impossible pose: " + "; ".join(map(str, self.joint_limit_violations)),
                remedy=JOINT_LIMIT_REMEDY,
            )
        if self.coupling_violations:
            raise CouplingError(
                "impossible pose: " + "; ".join(map(str, self.coupling_violations)),
                remedy=JOINT_LIMIT_REMEDY,
            )

    def summary(self) -> str:
        """One line for a report."""
        if self.valid:
            return "pose: valid (no penetration, joints within limits)"
        found = [str(p) for p in self.penetrations]
        found += [str(v) for v in self.joint_limit_violations]
        found += [str(v) for v in self.coupling_violations]
        return "pose: INVALID (analysed with check_pose=False): " + "; ".join(found)

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "valid": self.valid,
            "checked": self.checked,
            "penetrations": [vars(p) for p in self.penetrations],
            "joint_limit_violations": [vars(v) for v in self.joint_limit_violations],
            "coupling_violations": [vars(v) for v in self.coupling_violations],
        }


RESOLUTION_MARGIN = 1e3
"""Position round-off must be this many times finer than the distance tolerance."""


def _check_resolvable(plant, plant_context, bodies, tol: float) -> None:
    """Refuse bodies so far from the origin that ``tol`` is below round-off.

    Drake computes signed distances in the world frame: at ``|p_WB| = 1e300`` m
    one unit in the last place is ``1e284`` m, its distances overflow, and two
    bodies 1e300 m apart were reported "penetrating by 6 mm".  A pose check
    with tolerance ``tol`` needs ``|p_WB| ε RESOLUTION_MARGIN <= tol`` for every
    body (``ε`` the double precision's 2.2e-16): 4.5e8 m at the default 1e-4 m.
    """
    eps = float(np.finfo(float).eps)
    for body in bodies:
        p = np.asarray(plant.EvalBodyPoseInWorld(plant_context, body).translation())
        size = float(np.max(np.abs(p)))
        if not np.isfinite(size):
            raise InvalidPoseError(
                f"body {scoped_name(plant, body)!r} is at {p.tolist()} in the world: "
                "not finite (set the plant's positions to finite values)"
            )
        if size * eps * RESOLUTION_MARGIN > tol:
            raise InvalidPoseError(
                f"body {scoped_name(plant, body)!r} is {size:.3g} m from the world "
                f"origin, where double precision resolves positions only to "
                f"{size * eps:.2g} m: too coarse to tell contact from penetration "
                f"at distance_tolerance = {tol:g} m (valid: |p_WB| <= "
                f"{tol / (eps * RESOLUTION_MARGIN):.3g} m); move the scene near the "
                "origin"
            )


def find_penetrations(
    plant: MultibodyPlant,
    plant_context: Context,
    object_body: RigidBody,
    bodies: Sequence[RigidBody],
    tol: float,
    query_object=None,
) -> list[Penetration]:
    """Every (body geometry, object geometry) pair with ``ψ < −tol``, unfiltered."""
    if not plant.geometry_source_is_registered():
        raise ModelError("the plant is not registered with a SceneGraph; no geometry")
    query = query_object
    if query is None:
        query = query_object_of(plant, plant_context)
    inspector = query.inspector()
    _check_resolvable(plant, plant_context, [object_body, *bodies], tol)
    object_geometries = plant.GetCollisionGeometriesForBody(object_body)
    out = []
    for body in bodies:
        for gh in plant.GetCollisionGeometriesForBody(body):
            for go in object_geometries:
                psi = pair_distance(query, inspector, go, gh)
                if psi is not None and psi < -tol:
                    out.append(
                        Penetration(
                            hand_body=scoped_name(plant, body),
                            hand_geometry=inspector.GetName(gh),
                            object_geometry=inspector.GetName(go),
                            depth=float(-psi),
                        )
                    )
    return out


def joint_limit_violations(
    plant: MultibodyPlant, plant_context: Context, bodies: Sequence[RigidBody]
) -> list[JointLimitViolation]:
    """Every position of a joint of the bodies' model instances off its limits.

    A position counts when it is more than ``JOINT_LIMIT_TOL`` outside
    ``[lower, upper]`` as the plant's joints state them.
    """
    instances = {int(b.model_instance()) for b in bodies}
    q = plant.GetPositions(plant_context)
    out = []
    for i in range(plant.num_joints()):
        joint = plant.get_joint(JointIndex(i))
        if int(joint.model_instance()) not in instances or joint.num_positions() == 0:
            continue
        lo, hi = joint.position_lower_limits(), joint.position_upper_limits()
        start = joint.position_start()
        for k in range(joint.num_positions()):
            value = float(q[start + k])
            if value < lo[k] - JOINT_LIMIT_TOL or value > hi[k] + JOINT_LIMIT_TOL:
                name = f"{plant.GetModelInstanceName(joint.model_instance())}::"
                name += joint.name() + (f"[{k}]" if joint.num_positions() > 1 else "")
                out.append(JointLimitViolation(name, value, float(lo[k]), float(hi[k])))
    return out


def check_pose(
    plant: MultibodyPlant,
    plant_context: Context,
    object_body: RigidBody,
    hand_instance_bodies: Sequence[RigidBody],
    *,
    distance_tolerance: float,
    query_object=None,
) -> PoseCheck:
    """Penetrations and joint-limit violations of the hand in this pose.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
        The plant's own context (already resolved).
    object_body : RigidBody
    hand_instance_bodies : sequence of RigidBody
        Every body of the hand's model instances, welded ones included (see
        :func:`~drakegrasp.plant.validation.hand_model_instances`).
    distance_tolerance : float
        Penetration deeper than this (metres) is reported.
    query_object : pydrake.geometry.QueryObject, optional
        Read distances from this query object instead of the plant's query
        input port in ``plant_context`` (a System's private plant context).

    Returns
    -------
    PoseCheck
    """
    pens = find_penetrations(
        plant,
        plant_context,
        object_body,
        hand_instance_bodies,
        distance_tolerance,
        query_object,
    )
    joints = joint_limit_violations(plant, plant_context, hand_instance_bodies)
    return PoseCheck(tuple(pens), tuple(joints))
