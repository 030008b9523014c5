r"""The shake test's default squeeze: newtons at the fingers, in each motor's terms.

A parallel jaw's finger slides: the force its motor applies is the force with
which it presses, so a squeeze in newtons is the motor's aim.  A revolute
finger's motor applies a torque, and what that presses with depends on where
the finger touches: the same 20 N·m presses a link touching 2 cm from its
axis with 1000 N and one touching 20 cm away with 100.  A squeeze given in N·m
is thus a different grip on every hand (a Robotiq-2F-85-like hand, whose one
motor drives six joints, was aimed at 120 N·m and threw its best grasps 4 m
out of the hand), so :func:`~drakegrasp.planning.shake.shake_test`'s default
asks for newtons at the contacts and works out each motor's torque here.

By virtual work, a motor ``m`` turning at ``q̇_m`` moves the finger point
``C`` of a contact at ``v_C = J_C ∂q/∂q_m q̇_m`` (``J_C`` (3, n_v) its
translational Jacobian, ``∂q/∂q_m`` 1 at ``m`` and ``ρ`` at each ``<mimic>``
follower without a motor of its own that it drives), so the torque that
presses ``C`` along the contact normal ``n`` (into the object) with ``f``
newtons is ``τ = f nᵀ J_C ∂q/∂q_m`` (``τ = Jᵀ f``).  Each finger body that
touches the object presses with the squeeze at the mean of its contacts' lever
arms, ``ℓ_b = mean_C  s nᵀ J_C ∂q/∂q_m`` (``s`` the sign that closes ``m``),
and the motor's aim is the squeeze times ``Σ_b ℓ_b`` (metres: N·m per N),
or nothing where that sum is not positive: a motor is only aimed to close.  A
body that closing pulls away counts against the others (a spread joint that
turns one finger towards the object and another away from it); motors that
share a body's motion share its press, as ``Jᵀ f`` splits it.  For a one-link
finger touching at ``r`` from its axis, square to it, the arm is ``r``: the
torque is ``f r``.

The motor's reach ``Σ_b mean_C ‖J_C ∂q/∂q_m‖`` sets how stiffly it holds
(with the shake's default stiffness): as stiffly as deflects it
:data:`~drakegrasp.planning.shake.REVOLUTE_AIM` under the squeeze at its
contacts, in whatever direction they push.  A finger that presses square on
(press = reach) is then aimed 0.1 rad past its place; a spread joint, whose
closing moves its contacts sideways, presses little but holds as stiffly as
its reach asks; a geared drive's stiffness scales with its gearing.
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Callable, Mapping, Sequence
from typing import NamedTuple

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import DiagramBuilder

from drakegrasp.core.validation import describe, plain_str
from drakegrasp.errors import InvalidGraspError, InvalidOptionError, ModelError
from drakegrasp.plant.couplings import coupling_map
from drakegrasp.plant.fingers import find_joint
from drakegrasp.plant.models import new_parser
from drakegrasp.plant.validation import check_rigid_transform, resolve_body

__all__ = [
    "DEFAULT_SQUEEZE",
    "HOLD_LEVER",
    "LEVER_TOL",
    "Arms",
    "checked_contacts",
    "contact_levers",
]

DEFAULT_SQUEEZE = 20.0
"""The shake test's default squeeze, N: what each finger body that touches
the object presses with at its contacts (a prismatic finger's motor applies
it, times the fingers it drives; a revolute one's the torque that presses
them with it: :func:`contact_levers`)."""

HOLD_LEVER = 0.05
"""Lever arm (m) of a revolute joint's hold at the default squeeze where it
moves no contact (a finger that touches nothing, an actuator that does not
squeeze): with the default stiffness it holds its place as stiffly as one
that presses the squeeze at 5 cm (10 N·m/rad at 20 N, within the effort
limit)."""

LEVER_TOL = 1e-9
"""Lever arms (m) below this are zero: a joint they would aim a nanometre
past its place presses with nothing that round-off leaves."""


class Arms(NamedTuple):
    """A squeezer's arms at the candidate's contacts (m, or N per N for a slide).

    Attributes
    ----------
    press : float
        ``Σ_b mean_C s nᵀ J_C ∂q/∂q_m`` (the module docstring): the torque per
        newton with which closing presses the touching bodies along their
        normals; 0 where that is not above :data:`LEVER_TOL`.
    reach : float
        ``Σ_b mean_C ‖J_C ∂q/∂q_m‖``: how fast the contacts' finger points
        move per unit of the motor, whatever the direction; the torque per
        newton that a force on them in any direction exerts at the most (a
        spread joint reaches far and presses little).  0 for a joint that
        moves no contact.
    """

    press: float
    reach: float


_CANDIDATE = ("apply", "contacts", "hand_base", "X_WH", "X_WO")
"""What :func:`contact_levers` reads of a candidate (its type lives a layer up)."""


def contact_levers(
    add_models: Callable,
    candidate,
    squeezers: Mapping[str, float],
    couplings: Sequence,
    *,
    X_WO: RigidTransform | None = None,
) -> dict[str, Arms]:
    """Per squeezing joint, its :class:`Arms`: torque per newton at the contacts.

    Parameters
    ----------
    add_models : callable
        As :func:`~drakegrasp.planning.shake.shake_test` takes it; called once
        more, on a plant of its own, to read the hand's kinematics at the
        candidate's pose.
    candidate : GraspCandidate
        Its hand base is welded at ``X_WH`` and its joints set
        (``apply``); its contacts (``p_OC``, ``nhat_O`` in the frame of its
        ``X_WO``, each naming its finger body) are where the fingers press.
    squeezers : mapping of str to float
        Scoped name of each joint whose actuator squeezes, to the sign
        (±1) that closes it, or 0 for one that closing leaves still (a
        candidate's ``closing_signs``: a spread joint); its arm is 0.
    couplings : sequence of (follower, leader, gear_ratio, offset)
        The couplings through which the squeezers drive followers (scoped
        names): a follower moves ``ρ`` per unit of its leader.  Leave out a
        follower with a motor of its own: it presses with that one.
    X_WO : RigidTransform, optional
        The frame the contacts are in (default ``candidate.X_WO``): the one
        planned on, where a shake puts the object elsewhere (a candidate of a
        point cloud shaken at the true object's pose).

    Returns
    -------
    dict of str to Arms
        Per squeezer, ``press`` = ``Σ_b ℓ_b`` (module docstring) over the
        finger bodies that touch, and ``reach``: m (N·m per N) for a revolute
        joint, N per N for a prismatic one; each 0 where not above
        :data:`LEVER_TOL` (closing presses no contact; the joint moves none).

    Raises
    ------
    InvalidGraspError
        A contact of the candidate that is not a finite point and unit normal
        naming its finger body, or no contacts.
    InvalidOptionError
        ``add_models`` not callable, ``candidate`` not a candidate of
        ``plan_grasps``, ``squeezers`` not a mapping or a sign other than ±1
        or 0,
        ``couplings`` not 4-tuples, ``X_WO`` not a rigid transform.
    ModelError
        ``add_models`` did not build the hand again (a body or joint of the
        candidate is missing on its second call), or welded its base (the
        shake welds it at ``X_WH``).
    """
    if not callable(add_models):
        raise InvalidOptionError(
            "add_models must be a function add_models(plant, parser), got "
            f"{type(add_models).__name__}"
        )
    if not all(hasattr(candidate, a) for a in _CANDIDATE):
        raise InvalidOptionError(
            "candidate must be a GraspCandidate of plan_grasps, got "
            f"{type(candidate).__name__}"
        )
    if not isinstance(squeezers, Mapping):
        raise InvalidOptionError(
            "squeezers must map joint names to the sign that closes each, got "
            f"{type(squeezers).__name__}"
        )
    try:
        read = [(str(f), str(leader), float(rho)) for f, leader, rho, _ in couplings]
    except (TypeError, ValueError):
        read = None
    if read is None or not all(math.isfinite(c[2]) for c in read):
        raise InvalidOptionError(
            "couplings must be (follower, leader, gear_ratio, offset) tuples with "
            "a finite ratio, as plant_couplings gives them, got "
            f"{reprlib.repr(couplings)}"
        )
    for name, sign in squeezers.items():
        if not (
            isinstance(sign, int | float | np.integer | np.floating)
            and not isinstance(sign, bool)
            and sign in (1, 0, -1)
        ):
            raise InvalidOptionError(
                f"the sign that closes joint {name!r} must be 1, -1 or 0 (closing "
                f"leaves it still), got {describe(sign)}"
            )
    contacts = checked_contacts(candidate)
    X_WO = candidate.X_WO if X_WO is None else check_rigid_transform("X_WO", X_WO)
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    add_models(plant, new_parser(plant, "the shake test's lever-arm plant"))
    base = resolve_body(plant, candidate.hand_base)
    try:
        plant.WeldFrames(plant.world_frame(), base.body_frame(), candidate.X_WH)
    except RuntimeError as e:  # add_models welded it: the shake welds it at X_WH
        raise ModelError(
            f"add_models must leave the hand's base {candidate.hand_base} free (the "
            f"shake welds it at the candidate's X_WH); Drake: {str(e)[:160]}"
        ) from None
    plant.Finalize()
    ctx = plant.CreateDefaultContext()
    candidate.apply(plant, ctx)
    # C (v_h = C u): each squeezer's motion and its followers' rho per unit
    # of it, as the hand Jacobian's coupled columns J C (docs/conventions.md)
    own = {name: find_joint(plant, name).velocity_start() for name in squeezers}
    joints = dict.fromkeys(
        [*squeezers, *(f for f, leader, _ in read if leader in squeezers)]
    )
    velocities = np.array([find_joint(plant, j).velocity_start() for j in joints])
    C, independent = coupling_map(plant, velocities, couplings)
    column = {int(u): k for k, u in enumerate(independent)}
    motion = {}  # (n_v,) per squeezer: dq/dq_m
    for name, v in own.items():
        if v not in column:
            raise InvalidOptionError(
                f"squeezer {name} follows another through couplings: leave that "
                "coupling out (a follower with a motor of its own presses with it)"
            )
        motion[name] = np.zeros(plant.num_velocities())
        motion[name][velocities] = C[:, column[v]]
    R_WO = X_WO.rotation().matrix()
    # per finger body, per contact: (n_W, J_C (3, n_v))
    jacobians: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
    for name, p_OC, nhat_O in contacts:
        finger = resolve_body(plant, name)
        p_WC = X_WO.multiply(p_OC)
        p_FC = plant.EvalBodyPoseInWorld(ctx, finger).inverse().multiply(p_WC)
        J = plant.CalcJacobianTranslationalVelocity(
            ctx, JacobianWrtVariable.kV, finger.body_frame(), p_FC,
            plant.world_frame(), plant.world_frame(),
        )  # fmt: skip
        jacobians.setdefault(name, []).append((R_WO @ nhat_O, J))
    arms = {}
    for name, sign in squeezers.items():
        press = reach = 0.0
        for body in jacobians.values():
            # each contact's finger point's velocity per unit of the motor
            moves = [(n, J @ motion[name]) for n, J in body]
            press += float(np.mean([sign * (n @ v) for n, v in moves]))
            reach += float(np.mean([np.linalg.norm(v) for _, v in moves]))
        arms[name] = Arms(
            press if press > LEVER_TOL else 0.0,  # a motor is aimed only to close
            reach if reach > LEVER_TOL else 0.0,
        )
    return arms


def checked_contacts(candidate) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """``(finger body, p_OC, nhat_O)`` of each of ``candidate``'s contacts, checked.

    Raises
    ------
    InvalidGraspError
        No contacts, or one whose point or normal is not a finite 3-vector
        (the normal of unit length), or that names no finger body.
    """
    try:
        contacts = list(candidate.contacts)
    except TypeError:
        contacts = []
    if not contacts:
        raise InvalidGraspError(
            "the candidate has no contacts: the default squeeze presses the "
            "fingers at theirs (give squeeze= to press without them)"
        )
    out = []
    for k, pc in enumerate(contacts):
        try:
            name = plain_str(pc.finger_body)  # a key: its own __hash__ may lie
            p = np.asarray(pc.p_OC, dtype=float)
            n = np.asarray(pc.nhat_O, dtype=float)
        except (AttributeError, TypeError, ValueError):
            name, p, n = None, np.zeros(0), np.zeros(0)
        if not (
            type(name) is str
            and p.shape == n.shape == (3,)
            and np.all(np.isfinite(p))
            and np.all(np.isfinite(n))
            and abs(float(np.linalg.norm(n)) - 1.0) < 1e-6
        ):
            raise InvalidGraspError(
                f"the candidate's contact {k} must name its finger body and have "
                "a finite point p_OC and unit normal nhat_O, 3-vectors in frame O"
            )
        out.append((name, p, n))
    return out
