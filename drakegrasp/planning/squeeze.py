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
follower it drives), so the torque that presses ``C`` along the contact normal
``n`` (into the object) with ``f`` newtons is ``τ = f nᵀ J_C ∂q/∂q_m``.  Each
finger body that touches the object presses with the squeeze at the mean of
its contacts' lever arms ``ℓ_b = mean_C  s nᵀ J_C ∂q/∂q_m`` (``s`` the
sign that closes ``m``; a body the closing motion pulls away counts 0), and
the motor's aim is the squeeze times ``Σ_b ℓ_b`` (metres: N·m per N).  For a
one-link finger touching at ``r`` from its axis, square to it, that is
``r``: the torque is ``f r``.
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Callable, Mapping, Sequence

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import DiagramBuilder

from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant.fingers import find_joint
from drakegrasp.plant.models import new_parser
from drakegrasp.plant.validation import check_rigid_transform, resolve_body

__all__ = ["DEFAULT_SQUEEZE", "HOLD_LEVER", "contact_levers"]

DEFAULT_SQUEEZE = 20.0
"""The shake test's default squeeze, N: what each finger body that touches
the object presses with at its contacts (a prismatic finger's motor applies
it, times the fingers it drives; a revolute one's the torque that presses
them with it: :func:`contact_levers`)."""

HOLD_LEVER = 0.05
"""Lever arm (m) of a revolute joint's hold where none of the candidate's
revolute motors presses a contact: a joint that holds still (a spread joint,
a finger that touches nothing) is as stiff as one that presses the default
squeeze at 5 cm."""


_CANDIDATE = ("apply", "contacts", "hand_base", "X_WH", "X_WO")
"""What :func:`contact_levers` reads of a candidate (its type lives a layer up)."""


def contact_levers(
    add_models: Callable,
    candidate,
    squeezers: Mapping[str, float],
    couplings: Sequence,
    *,
    X_WO: RigidTransform | None = None,
) -> dict[str, float]:
    """Per squeezing joint, ``Σ_b ℓ_b``: its torque per newton at the contacts.

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
        (±1) that closes it.
    couplings : sequence of (follower, leader, gear_ratio, offset)
        The plant's couplings (scoped names): a follower moves ``ρ`` per unit
        of its leader.
    X_WO : RigidTransform, optional
        The frame the contacts are in (default ``candidate.X_WO``): the one
        planned on, where a shake puts the object elsewhere (a candidate of a
        point cloud shaken at the true object's pose).

    Returns
    -------
    dict of str to float
        Per squeezer, ``Σ_b ℓ_b`` (module docstring) over the finger bodies
        that touch: m (N·m per N) for a revolute joint, 1 per touching body
        for a prismatic one along the normals; >= 0, 0 for a joint that
        presses no contact when it closes.

    Raises
    ------
    InvalidOptionError
        ``add_models`` not callable, ``candidate`` not a candidate of
        ``plan_grasps``, ``squeezers`` not a mapping or a sign other than ±1,
        ``couplings`` not 4-tuples, ``X_WO`` not a rigid transform.
    ModelError
        ``add_models`` did not build the hand again (a body or joint of the
        candidate is missing on its second call).
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
        couplings = [
            (str(f), str(leader), float(rho)) for f, leader, rho, _ in couplings
        ]
    except (TypeError, ValueError):
        raise InvalidOptionError(
            "couplings must be (follower, leader, gear_ratio, offset) tuples, "
            f"as plant_couplings gives them, got {reprlib.repr(couplings)}"
        ) from None
    for name, sign in squeezers.items():
        if isinstance(sign, bool) or sign not in (1, -1):
            raise InvalidOptionError(
                f"the sign that closes joint {name!r} must be 1 or -1, got {sign!r}"
            )
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    add_models(plant, new_parser(plant, "the shake test's lever-arm plant"))
    base = resolve_body(plant, candidate.hand_base)
    plant.WeldFrames(plant.world_frame(), base.body_frame(), candidate.X_WH)
    plant.Finalize()
    ctx = plant.CreateDefaultContext()
    candidate.apply(plant, ctx)
    followers: dict[str, list[tuple[str, float]]] = {}
    for follower, leader, rho in couplings:
        followers.setdefault(leader, []).append((follower, rho))
    columns = {
        name: [
            (find_joint(plant, joint).velocity_start(), rho)
            for joint, rho in [(name, 1.0), *followers.get(name, [])]
        ]
        for name in squeezers
    }
    X_WO = candidate.X_WO if X_WO is None else check_rigid_transform("X_WO", X_WO)
    R_WO = X_WO.rotation().matrix()
    rows: dict[str, list[np.ndarray]] = {}  # per finger body: n_Wᵀ J_C per contact
    for pc in candidate.contacts:
        finger = resolve_body(plant, pc.finger_body)
        p_WC = X_WO.multiply(np.asarray(pc.p_OC, dtype=float))
        p_FC = plant.EvalBodyPoseInWorld(ctx, finger).inverse().multiply(p_WC)
        J = plant.CalcJacobianTranslationalVelocity(
            ctx, JacobianWrtVariable.kV, finger.body_frame(), p_FC,
            plant.world_frame(), plant.world_frame(),
        )  # fmt: skip
        n_W = R_WO @ np.asarray(pc.nhat_O, dtype=float)
        rows.setdefault(pc.finger_body, []).append(n_W @ J)
    levers = {}
    for name, sign in squeezers.items():
        total = 0.0
        for body_rows in rows.values():
            arms = [
                sign * sum(rho * float(row[v]) for v, rho in columns[name])
                for row in body_rows
            ]
            total += max(0.0, float(np.mean(arms)))
        levers[name] = total if math.isfinite(total) else 0.0
    return levers
