"""Planned grasps: one candidate, and a ranked sequence of them with rejections.

A :class:`GraspCandidate` is a hand pose (``X_WH``, the free base's pose in the
world, and ``q_hand``, the closing joints' values) with the contacts the
closed hand makes and what drakegrasp says about them.  A
:class:`GraspCandidates` is the ranked result of
:func:`~drakegrasp.planning.planner.plan_grasps`, best first, with every
sampled pose accounted for: ``len(candidates) + sum(rejections.values()) ==
num_sampled``.
"""

from __future__ import annotations

import json
import math
import reprlib
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from pydrake.math import RigidTransform

from drakegrasp.batch.run.stream import progress_bar
from drakegrasp.closure.results import ClosureResult
from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import Contact
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import describe, plain_str, real_array, real_scalar
from drakegrasp.errors import InvalidGraspError, InvalidOptionError, ModelError
from drakegrasp.planning.needed import needed_text, per_motor
from drakegrasp.planning.opposition import push_text
from drakegrasp.plant.contacts import PlantContact
from drakegrasp.plant.couplings import coupled_positions, recorded_couplings
from drakegrasp.plant.fingers import find_joint
from drakegrasp.plant.validation import (
    check_rigid_transform,
    plant_context_of,
    resolve_body,
    resolve_object_body,
    scoped_name,
)

__all__ = [
    "HELD_JOINT_COLUMN",
    "GraspCandidate",
    "GraspCandidates",
    "check_candidate",
    "closing_order",
    "planning_result",
    "pose_dict",
]


HELD_JOINT_COLUMN = "held_joints:"
"""Prefix of :meth:`GraspCandidates.table`'s held-joint columns.

One column per joint the candidates held, named this prefix and the joint's
scoped name, ``"held_joints:model::joint"``: a name of ``held_joints``.
"""


def pose_dict(X: RigidTransform) -> dict:
    """A pose as ``{"translation": [3], "rotation": [[3]*3]}`` (JSON-ready)."""
    return {
        "translation": X.translation().tolist(),
        "rotation": X.rotation().matrix().tolist(),
    }


@checked_call
@dataclass(frozen=True, eq=False)
class GraspCandidate:
    """One planned grasp.

    Attributes
    ----------
    sample : int
        Index of the sampled pose this candidate came from (stable for a seed).
    hand_base : str
        Scoped name ``model::body`` of the hand's free base (frame H).
    X_WH : RigidTransform
        Pose of the hand's base frame H in the world.
    X_WO : RigidTransform
        Pose of the object's body frame O when the grasp was planned.
    q_hand : (n_h,) float
        Closing joints' values of the closed hand (metres or radians), in the
        order of ``joint_names`` (two for a parallel jaw).
    joint_names : tuple of str
        Scoped names ``model::joint`` of the closing joints.
    closing_signs : tuple of float
        The sign of each joint's motion that closes the gripper (±1; 0 for a
        joint of a multi-finger hand that closing did not move).
    opening : float
        Pad-to-pad width of the pre-grasp (open) hand, metres (NaN for a
        multi-finger hand: see ``q_preshape``).
    contacts : tuple of PlantContact
        Contacts of the closed hand (object frame O).
    reference_point : (3,) float
        The point of frame O (metres) that every moment of the candidate is
        taken about: ``grasp``, ``epsilon``, ``weight_capacity`` and
        ``torque_needed``.  The object's centre of mass, where its weight
        acts (a massless model's, planned with ``object_mass``: its collision
        surface's centroid; on a point cloud, the cloud's centre: O's origin).
    contact_options : dict
        ``mu``, ``contact_model`` and ``torsional_friction`` of the contacts.
    is_closure : bool
        Frictional force closure on the polyhedral cones (LP2).
    d_star : float
        LP2's ``d*`` (dimensionless).
    rank : int
        Rank of ``G`` over the contacts' force components.
    epsilon : float
        Ferrari–Canny L1 ε with the object's torque scale (see
        ``GraspCandidates.torque_scale``).
    robustness : float
        Fraction of perturbed copies of the grasp that stay force closure.
    score : float
        ``robustness * weight_capacity``; 0 when no weight capacity was
        computed (see :mod:`~drakegrasp.planning.ranking`).
    weight_capacity : float
        Newtons of the object's weight held per newton of squeeze on each
        finger, in the worst of the directions of
        :data:`~drakegrasp.planning.weight.WEIGHT_DIRECTIONS` (at ``mu``); NaN
        when not computed.
    squeeze_needed : float
        The squeeze per finger (N) that holds the object's weight in all those
        directions, ``m g / weight_capacity``
        (:func:`~drakegrasp.planning.needed.needed_for`; inf: none does, or,
        with a ``weight_capacity`` > 0, more than the largest float, about
        1.8e308 N: an absurd ``object_mass``; NaN: not computed).  A lower
        bound for fingers that each press with a set force: the LP shares
        each finger's force among its contacts at will, while a rigid pad
        shares it as its geometry and compliance dictate (in
        the shake test, grasps of cylinders with two tip spheres per finger
        needed up to twice this).  A position-controlled finger that the
        object pushes back presses harder, up to its effort limit, so such a
        hand may hold with less (the shake test's PD fingers: Drake's Franka
        hand held 1 of 18 YCB candidates at 0.8 times it, none at 0.5 times;
        ``benchmarks/bench_jaw_squeeze.py``).
    closure : ClosureResult or None
        The single-grasp verdict with its certificate (witness), for the top
        candidates (``certify`` of ``plan_grasps``); None for the rest.
    q_preshape : (n_h,) float or None
        A multi-finger hand's pre-shape, from which ``close_hand`` closed it
        (None for a parallel jaw, whose pre-grasp is ``opening``).
    torque_needed : float
        A multi-finger hand's torque at every motor (in ``torque_unit``: N·m,
        N at a prismatic joint; a motor is an actuated closing joint, and a
        ``<mimic>`` follower turns with its leader's) that holds the object's
        weight in all the weight directions
        (:func:`~drakegrasp.planning.motors.torque_needed`; a lower bound for
        the planned contacts held still, an estimate of what a simulation
        needs: see there),
        for the best force-closure candidates (the first
        ``max(certify, TORQUE_CHECK)``,
        :data:`~drakegrasp.planning.motors.TORQUE_CHECK`) when the weight is
        known: planned on a body, or on a point cloud with ``object_mass``;
        ``m g / torque_capacity``; inf: none does, or, with a
        ``torque_capacity`` > 0, more than the largest float; NaN: not
        computed.  Compare it with the actuators' effort limits.  As
        ``shake_test``'s squeeze it is per joint, not per motor: the shake
        presses every joint a motor drives with the squeeze, so a motor with
        ``<mimic>`` followers applies it once per joint it closes (a
        one-motor jaw: twice, ``ShakeResult.efforts``).  Give a hand whose
        every closing joint is a motor ``torque_needed``, and a coupled one
        ``torque_needed`` over the number of joints its motor closes.
    torque_scale : float
        The length (m) the planner divided moments by and bounded a soft
        finger's torsion with (``GraspCandidates.torque_scale``), and so the
        characteristic length of ``grasp``; NaN for a candidate built without
        one (``grasp`` then takes the grasp's default).
    torque_capacity : float
        Newtons of the object's weight held per N·m (per N at a prismatic
        joint: ``torque_unit``) at every motor, in the worst weight
        direction (``min_u β(u)`` of
        :func:`~drakegrasp.planning.motors.torque_capacity`), for the
        candidates that got a ``torque_needed``; 0: none holds it; NaN: not
        computed.
    object_mass : float
        The object's mass (kg) the candidate was planned for, whose weight
        ``squeeze_needed`` and ``torque_needed`` hold: ``plan_grasps``'
        ``object_mass``, or the body's (NaN on a point cloud without one,
        and for a massless body).
        :func:`~drakegrasp.planning.shake.shake_test` shakes this mass.
    held_joints : tuple of (str, float)
        The hand's other one-dof joints, ``("model::joint", value)`` (metres
        or radians), where the plan held them: the joints that move a body
        of the hand and are neither in ``joint_names`` nor tied to one of
        those by a coupling (joints no motor moves, which the planner keeps
        where the context puts them, and any other it did not close).
        :meth:`apply` sets them too, so that a shake or an analysis starts
        from the hand that was planned; () for a candidate built without
        them.  ``to_dict()`` has them, and :meth:`GraspCandidates.table` a
        column for each (:data:`HELD_JOINT_COLUMN`).
    torque_unit : str
        The unit of ``torque_needed`` at the closing joints, from their kinds:
        ``"N·m"`` when every one turns, ``"N"`` when every one slides
        (prismatic), ``"N·m, N at prismatic joints"`` for a hand with both;
        set by the planner for every candidate, a jaw's too (whose
        ``torque_needed`` is NaN), and ``"N·m"`` for a candidate built or
        pickled without it.
    motors : tuple of str
        The hand's joints that carry an actuator's motor, which
        ``torque_needed`` is per (:func:`~drakegrasp.planning.motors.motor_names`:
        a ``<mimic>`` follower turns with its leader's, so a
        Robotiq-2F-85-like hand's six closing joints have one; a jaw's
        hidden drive is one); set by the planner for every candidate on a
        plant.  () when none is known: a model that gives the hand no
        actuator (``torque_needed`` then takes one motor at each joint but
        a hidden drive), a plant whose constraints drakegrasp was not told
        of, or a candidate built or pickled without them.  Distinct str,
        else ``InvalidGraspError``.  ``num_motors`` counts them.
    torque_limit : float
        The torque per motor (in ``torque_unit``) that the ranking held
        ``torque_needed`` against, one for the whole plan: the smallest
        effort limit of the first-ranked candidate's motors (each candidate's
        own where the hand's motors share one limit, as the Allegro hand's
        do), or ``plan_grasps``' ``torque_limit`` where that is smaller
        (:func:`~drakegrasp.planning.motors.with_torques_needed`);
        NaN where no finite limit is known or ``torque_needed`` was not
        computed.  ``torque_needed > torque_limit`` is one of the
        ``concerns``.
    squeeze_push : float
        How one way the hand's closing motions push the object, in ``[0,
        1]``: 0 where they oppose one another (a jaw, a thumb against
        fingers), towards 1 where every contact's closing motion leans one
        way and the squeeze may push the object out of the hand
        (:mod:`~drakegrasp.planning.opposition`); for a multi-finger hand's
        best force-closure candidates
        (:func:`~drakegrasp.planning.motors.with_squeeze_push`, which ranks
        those above :data:`~drakegrasp.planning.opposition.SQUEEZE_PUSH_MAX`
        after the other force-closure candidates), NaN where not computed
        (a parallel jaw's, whose fingers close towards each other).

    Notes
    -----
    A candidate pickles, so that candidates can be sent to other processes
    (``multiprocessing``, ``concurrent.futures``, Dask) and back: every
    attribute comes back equal, its contacts' geometry ids too in the
    process that planned it.  In any other process those two ids of each
    contact are :class:`~drakegrasp.plant.handles.ForeignGeometryId`, which
    name no geometry there (:mod:`drakegrasp.plant.handles`); nothing else
    of the candidate depends on them.  ``grasp`` is not pickled: it is built
    again on first access.
    """

    sample: int
    hand_base: str
    X_WH: RigidTransform
    X_WO: RigidTransform
    q_hand: np.ndarray
    joint_names: tuple[str, ...]
    closing_signs: tuple[float, ...]
    opening: float
    contacts: tuple[PlantContact, ...]
    reference_point: np.ndarray
    contact_options: dict
    is_closure: bool
    d_star: float
    rank: int
    epsilon: float
    robustness: float
    score: float
    weight_capacity: float = float("nan")
    squeeze_needed: float = float("nan")
    closure: ClosureResult | None = None
    q_preshape: np.ndarray | None = None
    torque_needed: float = float("nan")
    torque_scale: float = float("nan")
    torque_capacity: float = float("nan")
    object_mass: float = float("nan")
    held_joints: tuple[tuple[str, float], ...] = ()
    torque_unit: str = "N·m"
    motors: tuple[str, ...] = ()
    torque_limit: float = float("nan")
    squeeze_push: float = float("nan")

    def __post_init__(self) -> None:
        object.__setattr__(self, "motors", _checked_motors(self.motors))
        # joint names, each read once as the plain str it holds: they are
        # hashed and compared, where a subclass's own methods may raise or lie
        object.__setattr__(self, "joint_names", _plain_names(self.joint_names))
        object.__setattr__(
            self, "held_joints", _plain_names(self.held_joints, pairs=True)
        )

    def __getstate__(self) -> dict:
        # ``grasp`` (a cached_property, in __dict__ once read) is rebuilt from
        # the fields on first access: not pickled
        state = dict(self.__dict__)
        state.pop("grasp", None)
        return state

    @cached_property
    def grasp(self) -> Grasp:
        """The core grasp of the contacts (frame O, moments about ``reference_point``).

        Its characteristic length is the run's ``torque_scale``, the length
        the planner ranked with (ε, and a soft finger's torsion bound
        ``b ν f_n``), so that an analysis of this grasp (``force_closure``,
        ``epsilon_l1``, ``grasp_forces``) answers as the ranking did; NaN
        (a candidate built by hand): the grasp's default length.  Built on
        first access (thousands of candidates rarely need it).
        """
        return Grasp(
            [Contact(c.p_OC, c.nhat_O, **self.contact_options) for c in self.contacts],
            reference_point=self.reference_point,
            characteristic_length=(
                None if np.isnan(self.torque_scale) else self.torque_scale
            ),
        )

    @property
    def num_contacts(self) -> int:
        """Number of contacts."""
        return len(self.contacts)

    @property
    def num_motors(self) -> int:
        """Number of ``motors`` (0: none known)."""
        return len(self.motors)

    @property
    def concerns(self) -> tuple[str, ...]:
        """What the plan itself says against this candidate holding, in words.

        Empty when the plan knows nothing against it.  Otherwise one sentence
        each, in this order: not force closure; a ``torque_needed`` above
        ``torque_limit`` (the motors apply less than the weight needs, by
        the plan's own lower bound); a ``squeeze_push`` above
        :data:`~drakegrasp.planning.opposition.SQUEEZE_PUSH_MAX` (the
        squeeze may push the object out of the hand).  A figure not computed
        (NaN) raises no concern.  ``shake_candidates`` names them beside a
        dropped candidate.
        """
        out = []
        if not self.is_closure:
            out.append(
                "not force closure: some wrench on the object meets no contact force"
            )
        if self.torque_needed > self.torque_limit:  # False where either is NaN
            unit = per_motor(str(self.torque_unit))
            needed = needed_text(self.torque_needed, self.torque_capacity, unit)
            out.append(
                f"it needs {needed} (torque_needed), more than the "
                f"{self.torque_limit:.3g} its motors apply (torque_limit)"
            )
        push = push_text(float(self.squeeze_push))
        if push:
            out.append(push)
        return tuple(out)

    def apply(self, plant, context, *, object_body=None) -> None:
        """Put the candidate's hand pose (and the planned object pose) in a context.

        The closing joints take ``q_hand``, the held joints their values, and a
        joint that the plant's couplings tie to them but that neither names
        (a hidden drive that the fingers follow through their ``<mimic>``)
        the value the couplings give it
        (:func:`~drakegrasp.plant.couplings.coupled_positions`), so that the
        pose holds Drake's coupler constraints.

        Parameters
        ----------
        plant : MultibodyPlant
            The plant the candidate was planned in (or one with the same hand;
            a hand base welded there is left where the weld puts it).
        context : Context
            The plant's context or its diagram's root context; changed.
        object_body : RigidBody, BodyIndex or str, optional
            The object body (or its scoped name ``"model::body"``); when given
            (and free), set to the planned pose ``X_WO`` too.

        Raises
        ------
        InvalidGraspError
            The candidate's ``q_hand`` (its length or a non-finite value),
            ``X_WH`` or ``X_WO`` is not what Drake can be given
            (:func:`check_candidate`); the context is unchanged.
        ModelError, InvalidOptionError
            ``object_body`` is not a body of the plant, or a joint of
            ``joint_names`` or ``held_joints`` not a one-dof joint of it.
        """
        q_hand = check_candidate(self)
        ctx = plant_context_of(plant, context)
        if object_body is not None:
            object_body = resolve_object_body(plant, object_body)
        joints = [find_joint(plant, n) for n in self.joint_names]
        held = _held_joints(plant, self.held_joints)
        base = resolve_body(plant, self.hand_base)
        if base.is_floating_base_body():  # else welded (at X_WH, the caller's word)
            plant.SetFreeBodyPose(ctx, base, self.X_WH)
        set_ = [*zip(joints, q_hand, strict=True), *held]  # one-dof joints
        tied = coupled_positions(
            recorded_couplings(plant), {scoped_name(plant, j): q for j, q in set_}
        )
        set_ += [(find_joint(plant, name), q) for name, q in tied.items()]
        q_all = plant.GetPositions(ctx)
        for j, q in set_:
            q_all[j.position_start()] = q
        plant.SetPositions(ctx, q_all)
        if object_body is not None and object_body.is_floating_base_body():
            plant.SetFreeBodyPose(ctx, object_body, self.X_WO)

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "sample": self.sample,
            "hand_base": self.hand_base,
            "X_WH": pose_dict(self.X_WH),
            "X_WO": pose_dict(self.X_WO),
            "q_hand": jsonable(self.q_hand),
            "joint_names": list(self.joint_names),
            "opening": jsonable(self.opening),
            "num_contacts": self.num_contacts,
            "reference_point": jsonable(self.reference_point),
            "contacts": [
                {
                    "finger_body": c.finger_body,
                    "p_OC": jsonable(c.p_OC),
                    "nhat_O": jsonable(c.nhat_O),
                    "psi": c.psi,
                    # Which geometries touch, and whose surface the normal is
                    # (None on a point cloud): what tells a contact on a tiny
                    # marker sphere of a model from one on its faces.
                    "finger_geometry": getattr(c, "finger_geometry_name", None),
                    "object_geometry": getattr(c, "object_geometry_name", None),
                    "normal_source": getattr(c, "normal_source", None),
                }
                for c in self.contacts
            ],
            "is_closure": bool(self.is_closure),
            "d_star": jsonable(self.d_star),
            "rank": int(self.rank),
            "epsilon": jsonable(self.epsilon),
            "robustness": jsonable(self.robustness),
            "score": jsonable(self.score),
            "weight_capacity": jsonable(self.weight_capacity),
            "squeeze_needed": jsonable(self.squeeze_needed),
            "closure": None if self.closure is None else self.closure.to_dict(),
            "q_preshape": None
            if self.q_preshape is None
            else jsonable(self.q_preshape),
            "torque_needed": jsonable(self.torque_needed),
            "torque_scale": jsonable(self.torque_scale),
            "torque_capacity": jsonable(self.torque_capacity),
            "object_mass": jsonable(self.object_mass),
            "held_joints": {name: float(q) for name, q in self.held_joints},
            "torque_unit": self.torque_unit,
            "motors": list(self.motors),
            "torque_limit": jsonable(self.torque_limit),
            "squeeze_push": jsonable(self.squeeze_push),
            "concerns": list(self.concerns),
        }

    def __str__(self) -> str:
        p = self.X_WH.translation() * 1e3
        if np.isfinite(self.opening):
            shape = f"opening {self.opening * 1e3:.1f} mm"
        else:
            shape = f"{len(self.q_hand)} closing joints"
            if self.motors:
                shape += f", {_counted(self.num_motors, 'motor')}"
        if not np.isnan(self.torque_needed):
            torque = needed_text(
                self.torque_needed,
                self.torque_capacity,
                per_motor(str(self.torque_unit)),
            )
            shape += f", torque {torque}"
        if np.isnan(self.weight_capacity):
            holds = "weight not checked"
        else:
            holds = f"holds {self.weight_capacity:.3f} N/N"
            if not np.isnan(self.squeeze_needed):  # NaN: the weight is unknown
                squeeze = needed_text(
                    self.squeeze_needed, self.weight_capacity, "N per finger", ".1f"
                )
                holds += f" (squeeze {squeeze})"
        return (
            f"sample {self.sample}: "
            f"{'force closure' if self.is_closure else 'no closure'}"
            f", {self.num_contacts} contacts, eps = {self.epsilon:.4f}, robustness "
            f"{self.robustness:.2f}, {holds}, score {self.score:.4f}; {shape}, "
            f"p_WH = ({p[0]:.1f}, {p[1]:.1f}, {p[2]:.1f}) mm"
        ) + "".join(f"; {c}" for c in self.concerns[0 if self.is_closure else 1 :])


def _counted(n: int, noun: str) -> str:
    """``"1 motor"``, ``"16 motors"``."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def _held_joints(plant, held_joints) -> list:
    """``(Joint, value)`` of a candidate's ``held_joints`` in ``plant``.

    Raises
    ------
    ModelError
        A name that is not a one-dof joint of ``plant``.
    """
    out = []
    for name, q in held_joints:
        try:
            joint = find_joint(plant, name)
        except InvalidOptionError:
            joint = None
        if joint is None or joint.num_positions() != 1:
            raise ModelError(
                f"the candidate's held joint {describe(name)} is not a one-dof joint "
                "of this plant (held_joints records the hand's other joints as "
                "planned): apply the candidate to the hand it was planned with, "
                "or leave them as this plant has them: "
                "dataclasses.replace(candidate, held_joints=())"
            )
        out.append((joint, float(q)))
    return out


def _plain_names(items, *, pairs: bool = False):
    """``items`` (a tuple or list) with its names read as plain ``str`` s.

    Each item, or with ``pairs`` the first of each ``(name, value)`` pair, is
    read as the plain ``str`` it holds when it is a ``str``.  Anything else is
    returned as it is, for the checks that refuse it.
    """
    if not isinstance(items, tuple | list):
        return items
    try:
        if pairs:
            plain = [
                (plain_str(p[0]), p[1]) if type(p) in (tuple, list) and len(p) == 2
                else p
                for p in items
            ]  # fmt: skip
        else:
            plain = [plain_str(item) for item in items]
    except Exception:  # noqa: BLE001 - a hostile sequence: its checks refuse it
        return items
    return tuple(plain) if isinstance(items, tuple) else plain


def _named_pairs(held) -> bool:
    """Whether ``held`` is a tuple or list of (str, value) pairs."""
    return isinstance(held, tuple | list) and all(
        isinstance(pair, tuple | list) and len(pair) == 2 and isinstance(pair[0], str)
        for pair in held
    )


def _held_values(k: int, candidate: GraspCandidate) -> dict[str, float]:
    """Candidate ``k``'s ``held_joints`` as ``{name: value}``, for the table.

    Raises
    ------
    InvalidGraspError
        ``held_joints`` is not (joint name, value) pairs, or a value is not a
        real number (NaN passes: the table records what the candidate says).
    """
    held = candidate.held_joints
    if not _named_pairs(held):
        raise InvalidGraspError(
            f"candidate {k}'s held_joints must be (joint name, value) pairs, "
            f"got {reprlib.repr(held)}"
        )
    values = {}
    for name, value in held:
        try:
            values[name] = real_scalar(name, value, error=InvalidGraspError)
        except InvalidGraspError:
            raise InvalidGraspError(
                f"candidate {k}'s held joint {describe(name)} has the value "
                f"{reprlib.repr(value)}, not a real number (metres or radians)"
            ) from None
    return values


def _checked_motors(motors) -> tuple[str, ...]:
    """``GraspCandidate.motors`` as a tuple of distinct joint names.

    Raises
    ------
    InvalidGraspError
        Not a tuple or list of str (a string would count its letters), or a
        name twice.
    """
    names = _plain_names(motors)  # hashed below: a subclass's __hash__ may raise
    if not isinstance(names, tuple | list) or not all(
        type(name) is str for name in names
    ):
        raise InvalidGraspError(
            "the candidate's motors must be a tuple of joint names, got "
            f"{reprlib.repr(motors)}"
        )
    if len(set(names)) != len(names):
        raise InvalidGraspError(
            f"the candidate's motors name a joint twice: {reprlib.repr(names)}"
        )
    return tuple(names)


def _finite_number(value) -> bool:
    """Whether ``value`` is a real, finite number (not a bool) a float holds."""
    try:
        return math.isfinite(real_scalar("value", value, error=InvalidGraspError))
    except InvalidGraspError:  # not a real number, or an int beyond a double
        return False


def check_candidate(candidate: GraspCandidate) -> np.ndarray:
    """Check what :meth:`GraspCandidate.apply` gives Drake; return ``q_hand``.

    A planned candidate always passes; one edited or read back from a file may
    not, and Drake would end the program (``SystemExit``) on a NaN position.

    Parameters
    ----------
    candidate : GraspCandidate

    Returns
    -------
    (n_h,) float
        ``q_hand`` as floats, one per joint of ``joint_names``.

    Raises
    ------
    InvalidGraspError
        ``q_hand`` or ``closing_signs`` is not ``len(joint_names)`` finite real
        numbers, ``held_joints`` not (name, finite number) pairs or naming
        a closing joint, or
        ``X_WH`` / ``X_WO`` is not a pydrake ``RigidTransform`` with a finite
        translation and a proper rotation
        (:func:`~drakegrasp.plant.validation.check_rigid_transform`).
    """
    names = list(candidate.joint_names)
    values = {}
    for field_name in ("q_hand", "closing_signs"):
        value = getattr(candidate, field_name)
        a = real_array(field_name, value, error=InvalidGraspError)
        if a.shape != (len(names),) or not np.all(np.isfinite(a)):
            raise InvalidGraspError(
                f"the candidate's {field_name} must be {len(names)} finite "
                f"numbers, one per closing joint {names}, got {reprlib.repr(value)}"
            )
        values[field_name] = a
    held = candidate.held_joints
    if not (_named_pairs(held) and all(_finite_number(v) for _, v in held)):
        raise InvalidGraspError(
            "the candidate's held_joints must be (joint name, finite number) "
            f"pairs, got {reprlib.repr(held)}"
        )
    twice = sorted({name for name, _ in held} & set(names))
    if twice:
        raise InvalidGraspError(
            f"the candidate's held_joints name closing joint(s) {twice}, whose "
            "values are q_hand's: a joint is either closed or held"
        )
    for field_name in ("X_WH", "X_WO"):
        check_rigid_transform(
            f"the candidate's {field_name}",
            getattr(candidate, field_name),
            error=InvalidGraspError,
        )
    return values["q_hand"]


@checked_call
@dataclass(frozen=True, eq=False)
class GraspCandidates(Sequence):
    """Ranked planned grasps, best first, and why the other samples were dropped.

    Attributes
    ----------
    candidates : tuple of GraspCandidate
        Best first (highest score, then ``ε × robustness``, ``d*`` and the
        sample index); for a multi-finger hand with a known weight, the
        candidates whose ``torque_needed`` is within the hand's smallest
        effort limit come first, in that order
        (:func:`~drakegrasp.planning.motors.with_torques_needed`); and for a
        multi-finger hand, the force-closure candidates whose closing motions
        all push the object one way (``squeeze_push`` above
        :data:`~drakegrasp.planning.opposition.SQUEEZE_PUSH_MAX`, checked for
        the best of them) come after the other force-closure ones
        (:func:`~drakegrasp.planning.motors.with_squeeze_push`).
    rejections : dict of str to int
        Sampled poses dropped, by reason.
    num_sampled : int
        Poses sampled: ``len(self) + sum(rejections.values())``.
    object_body : str
        Scoped name of the object body (frame O).
    mu : float
        Friction coefficient of the verdicts.
    torque_scale : float
        Length (m) dividing moments in ε: the radius of a ball about the
        candidates' ``reference_point`` (the centre of mass) that holds the
        object, the same for every candidate.
    reason : str
        Why the result is empty, or why none of its candidates is force
        closure or (multi-finger hands) held by the hand's actuators (empty
        string otherwise).
    settings : dict
        The options of the run (noise, seed, tolerances), for the record.
    time : float
        Wall-clock seconds.
    """

    candidates: tuple[GraspCandidate, ...]
    rejections: dict[str, int]
    num_sampled: int
    object_body: str
    mu: float
    torque_scale: float
    reason: str = ""
    settings: dict = field(default_factory=dict)
    time: float = 0.0

    def __getitem__(self, index):
        if isinstance(index, slice):
            return self.candidates[index]
        return self.candidates[index]

    def __len__(self) -> int:
        return len(self.candidates)

    @property
    def closure_rate(self) -> float:
        """Fraction of the returned candidates that are force closure."""
        if not self.candidates:
            return 0.0
        return float(np.mean([c.is_closure for c in self.candidates]))

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "object_body": self.object_body,
            "mu": self.mu,
            "torque_scale": self.torque_scale,
            "num_sampled": self.num_sampled,
            "rejections": dict(self.rejections),
            "reason": self.reason,
            "settings": jsonable(self.settings),
            "time": self.time,
            "candidates": [c.to_dict() for c in self.candidates],
        }

    def to_json(self, **kwargs) -> str:
        """``json.dumps(self.to_dict())``."""
        return json.dumps(self.to_dict(), **kwargs)

    def table(self) -> dict[str, np.ndarray]:
        """One row per candidate (columns of equal length), for Parquet or pandas.

        Each column is an (n,) array of the candidates' attribute of that
        name (``rank_in_result``: the row's rank), but ``p_WH`` (n, 3) and
        ``R_WH`` (n, 9, row-major) of ``X_WH``, and ``q_hand`` (n, n_h).
        ``torque_unit``, after ``torque_capacity``, holds str (dtype object):
        the unit of the row's ``torque_needed`` (``"N·m"``, ``"N"``, or both
        named for a hand whose closing joints turn and slide), and of the
        motor effort that ``torque_capacity`` is newtons per.

        An empty result has the same columns, dtypes and widths with zero
        rows: ``p_WH`` is (0, 3), ``R_WH`` (0, 9) and ``q_hand`` (0, n_h), with
        n_h the closing joints of the hand in ``settings`` (0 if it names
        none).

        The candidates' ``held_joints`` follow, one (n,) float column per
        joint some candidate held, named :data:`HELD_JOINT_COLUMN` and the
        joint's scoped name (``"held_joints:model::joint"``), in the order the
        candidates list them: the joint's value as planned (metres or
        radians), NaN in the row of a candidate that did not hold it.  Being
        one-dimensional and named, they reach a file as they are (``plan
        --out``, where ``p_WH`` becomes ``p_WH_0`` ... and ``q_hand``
        ``q_hand_0`` ...).  A result whose candidates held no joint (each
        joint of the hand closed, or tied to one by a coupling) has no such
        column.  An empty result has the columns of the joints the planner
        held for its hand (``settings["held_joints"]``, recorded by
        :func:`~drakegrasp.planning.planner.plan_grasps`), so that its
        table has a full one's schema; none if ``settings`` names none.

        ``num_motors`` (int64), after ``torque_unit``, counts each row's
        ``motors`` (0: none known); ``torque_limit`` and ``squeeze_push``
        follow it (NaN where not computed).

        Raises
        ------
        InvalidGraspError
            A candidate's ``held_joints`` is not (joint name, real number)
            pairs (one edited by hand); the message names the candidate's
            index in the result, the joint and the value.
        """
        rows = self.candidates
        n = len(rows)

        def column(value, dtype=float) -> np.ndarray:
            return np.array([value(c) for c in rows], dtype=dtype)

        return {
            "rank_in_result": np.arange(n, dtype=np.int64),
            "sample": column(lambda c: c.sample, np.int64),
            "score": column(lambda c: c.score),
            "weight_capacity": column(lambda c: c.weight_capacity),
            "squeeze_needed": column(lambda c: c.squeeze_needed),
            "torque_needed": column(lambda c: c.torque_needed),
            "torque_capacity": column(lambda c: c.torque_capacity),
            "torque_unit": column(lambda c: c.torque_unit, object),
            "num_motors": column(lambda c: c.num_motors, np.int64),
            "torque_limit": column(lambda c: c.torque_limit),
            "squeeze_push": column(lambda c: c.squeeze_push),
            "epsilon": column(lambda c: c.epsilon),
            "robustness": column(lambda c: c.robustness),
            "is_closure": column(lambda c: c.is_closure, bool),
            "d_star": column(lambda c: c.d_star),
            "num_contacts": column(lambda c: c.num_contacts, np.int64),
            "opening": column(lambda c: c.opening),
            # explicit widths: reshape(0, -1) cannot infer them for no rows
            "p_WH": column(lambda c: c.X_WH.translation()).reshape(n, 3),
            "R_WH": column(lambda c: c.X_WH.rotation().matrix()).reshape(n, 9),
            "q_hand": column(lambda c: c.q_hand).reshape(n, self._q_hand_width()),
            **self._held_joint_columns(),
        }

    def _held_joint_columns(self) -> dict[str, np.ndarray]:
        """``table``'s held-joint columns: each value, NaN where not held.

        Without candidates, the joints ``settings`` says the plan held.
        """
        held = [_held_values(k, c) for k, c in enumerate(self.candidates)]
        names = dict.fromkeys(name for row in held for name in row)  # first met
        if not self.candidates:
            names = dict.fromkeys(self.settings.get("held_joints", ()))
        return {
            HELD_JOINT_COLUMN + name: np.array(
                [row.get(name, np.nan) for row in held], dtype=float
            )
            for name in names
        }

    def _q_hand_width(self) -> int:
        """Columns of ``q_hand``: -1 (the candidates'), or for none the hand's."""
        if self.candidates:
            return -1
        hand = self.settings.get("gripper") or self.settings.get("hand") or {}
        return len(hand.get("joints", ()))

    def __str__(self) -> str:
        head = (
            f"{len(self)} grasp candidates of {self.object_body} from "
            f"{self.num_sampled} samples ({self.time:.2f} s), mu = {self.mu:g}, "
            f"torque scale {self.torque_scale * 1e3:.1f} mm"
        )
        lines = [head]
        fit = self.settings.get("cloud_normals")
        if fit:
            lines.append(
                f"  cloud normals estimated over {fit['neighbours']} points a patch "
                f"(noise {fit['noise'] * 1e3:.3g} mm, about "
                f"{fit['error_deg']:.2g} deg off)"
            )
        first = self.settings.get("held_first")
        if first and first["held"] and self:  # none held: the reason says so
            rest = ", then the rest, each" if first["held"] < len(self) else ","
            lines.append(
                f"  ranked first: the {first['held']} with {first['needed']} <= "
                f"{first['limit']:g} {first['unit']} ({first['source']}){rest} in "
                "score order"
            )
        last = self.settings.get("pushed_last")
        if last and last["count"] and self:
            lines.append(
                f"  ranked after the other force-closure candidates: the "
                f"{last['count']} of the {last['checked']} checked whose closing "
                "motions push the object one way (squeeze_push > "
                f"{last['bound']:g}), in the order above"
            )
        if self.reason:
            lines.append(f"  {self.reason}" if self else f"  empty: {self.reason}")
        for reason, n in sorted(self.rejections.items(), key=lambda kv: -kv[1]):
            lines.append(f"  rejected {n:>6}  {reason}")
        for k, c in enumerate(self.candidates[:10]):
            lines.append(f"  #{k:<3} {c}")
        if len(self) > 10:
            lines.append(f"  ... {len(self) - 10} more")
        return "\n".join(lines)


def closing_order(n: int, progress: bool):
    """The indices of ``n`` sampled poses, under a tqdm bar when ``progress``.

    The closing stage (Drake's distance queries, pose by pose) is the long one
    of every route, so the bar counts its poses.

    Raises
    ------
    InvalidOptionError
        ``progress`` with the optional package tqdm not installed.
    """
    if not progress:
        return range(n)
    return progress_bar(range(n), desc="closing", unit="pose")


def planning_result(
    candidates: Sequence[GraspCandidate],
    *,
    rejections,
    num_sampled: int,
    object_body: str,
    mu: float,
    torque_scale: float,
    settings: dict,
    started: float,
) -> GraspCandidates:
    """The ranked result of one planning run, saying why it is empty when it is.

    ``started`` is the run's ``time.perf_counter()`` at its start (seconds).
    """
    reason = ""
    if not candidates:
        reason = (
            "num_candidates is 0"
            if num_sampled == 0
            else f"all {num_sampled} sampled poses were rejected (see rejections)"
        )
        completion = settings.get("unseen_completion") or {}
        if num_sampled and completion.get("skipped"):
            reason += (
                f"; the cloud's unseen side was not completed: "
                f"{completion['skipped']} (a face seen head-on; a view of two "
                "or more faces gives the object's depth)"
            )
    elif not any(c.is_closure for c in candidates):
        reason = _why_no_closure(candidates, settings.get("contact_model"))
    return GraspCandidates(
        candidates=candidates,
        rejections=dict(rejections),
        num_sampled=num_sampled,
        object_body=object_body,
        mu=mu,
        torque_scale=torque_scale,
        reason=reason,
        settings=settings,
        time=time.perf_counter() - started,
    )


def _why_no_closure(
    candidates: Sequence[GraspCandidate], contact_model: str | None
) -> str:
    """Why no candidate is force closure, from their ranks and contact counts.

    A grasp matrix of rank below 6 leaves a wrench that no contact force
    meets; with hard fingers, two point contacts (one per finger of a
    parallel jaw whose fingertips are spheres) leave the torque about the line
    through them.
    """
    n = len(candidates)
    rank = max(c.rank for c in candidates)
    most = max(c.num_contacts for c in candidates)
    if rank >= 6:
        best = max(
            (c.d_star for c in candidates if np.isfinite(c.d_star)), default=np.nan
        )
        return (
            f"none of the {n} candidates is force closure: their grasp matrices "
            f"have full rank, but no internal force lies inside every friction "
            f"cone (best d* {best:.3g}); a larger mu or other poses may help"
        )
    why = (
        f"none of the {n} candidates is force closure: every grasp matrix has "
        f"rank <= {rank} < 6 (at most {most} contacts per candidate), so some "
        "wrench on the object meets no contact force"
    )
    if contact_model == "hard_finger" and most <= 2:
        why += (
            "; two point contacts never resist a torque about the line through "
            "them: contact_model='soft_finger' with torsional_friction models "
            "fingertips that do, or give the fingers pads that touch at more "
            "points"
        )
    return why
