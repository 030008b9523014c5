r"""How much joint torque a multi-finger grasp needs to hold the object's weight.

A parallel jaw's motor sets a squeeze, so :mod:`~drakegrasp.planning.weight`
bounds each finger's normal forces.  A hand with revolute fingers sets joint
torques instead, each capped by its actuator's effort limit (the Allegro
hand's 0.7 N·m), and a fingertip far from its knuckles presses with less force
for the same torque.  For a candidate with hand Jacobian ``J`` (contact frames,
finger joints only: the hand's base is placed and held, so nothing bounds its
wrench) the **torque capacity** in a weight direction ``u`` is

.. math::

    \beta(u) = \max \beta \;\text{s.t.}\;
    G f + \beta \begin{bmatrix} u \\ 0 \end{bmatrix} = 0,\quad
    f \in \text{the polyhedral cones},\quad
    |(J^\top f)_j| \le 1 \;\text{(every finger joint } j\text{)},

the weight (N) held along ``u`` per N·m allowed at every finger joint, moments
about O's origin (the centre of mass of the shipped objects).  By linearity
the hand holds a weight ``m g`` in every one of the directions
:data:`~drakegrasp.planning.weight.WEIGHT_DIRECTIONS` when each joint may
apply :math:`m g / \min_u \beta(u)`: the **torque needed**.  Like the squeeze
needed, it is a lower bound: the program shares the torques among the
contacts at will, and a real finger presses as its controller dictates.

All directions of a candidate are one LP (through drakegrasp's solver
gateway), about 3 ms for the Allegro hand (5 ms with its Jacobian); the tests
check it against :func:`~drakegrasp.closure.payload.max_load`, direction by
direction.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
from pydrake.solvers import MathematicalProgram
from scipy.linalg import block_diag

from drakegrasp._solvers import require_solution, solve
from drakegrasp.core.friction_cone import (
    DEFAULT_NUM_GENERATORS,
    friction_cone_generators,
)
from drakegrasp.core.grasp import grasp_matrix
from drakegrasp.core.validation import real_scalar
from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning.candidates import GraspCandidate, GraspCandidates
from drakegrasp.planning.weight import WEIGHT_DIRECTIONS
from drakegrasp.plant.fingers import find_joint
from drakegrasp.plant.jacobians import hand_jacobian
from drakegrasp.plant.validation import plant_context_of, resolve_object_body

BETA_CAP = 1e6
"""Bound on ``β(u)`` (N per N·m) that keeps the program bounded; reaching it
reads as ``inf`` (no finger joint bounds the load: contacts on the palm)."""

__all__ = [
    "BETA_CAP",
    "finger_jacobian",
    "torque_capacity",
    "torque_needed",
    "with_torques_needed",
]


def finger_jacobian(plant, plant_context, candidate: GraspCandidate, object_body):
    """``J`` of a candidate over its finger joints, at the candidate's pose.

    Parameters
    ----------
    plant : MultibodyPlant
        The plant the candidate was planned in.
    plant_context : Context
        Its context (or the diagram's root context); left as it was.
    candidate : GraspCandidate
    object_body : RigidBody, BodyIndex or str
        The object (frame O); put at the candidate's planned pose.

    Returns
    -------
    (M, n_j) float
        Rows in the contact frames of ``candidate.grasp`` (its components),
        columns the candidate's joints (``candidate.joint_names``), m/s per
        rad/s (or per m/s for a prismatic finger).
    """
    if not isinstance(candidate, GraspCandidate):
        raise InvalidOptionError(
            f"candidate must be a GraspCandidate of plan_grasps, got "
            f"{type(candidate).__name__}"
        )
    ctx = plant_context_of(plant, plant_context)
    body = resolve_object_body(plant, object_body)
    joints = [find_joint(plant, name) for name in candidate.joint_names]
    columns = np.array([j.velocity_start() for j in joints], dtype=int)
    saved = plant.GetPositions(ctx).copy()
    try:
        candidate.apply(plant, ctx, object_body=body)
        return hand_jacobian(
            plant, ctx, candidate.contacts, candidate.grasp, body,
            velocity_indices=columns,
        )  # fmt: skip
    finally:
        plant.SetPositions(ctx, saved)


def torque_capacity(
    plant,
    plant_context,
    candidate: GraspCandidate,
    object_body,
    *,
    directions: np.ndarray = WEIGHT_DIRECTIONS,
) -> np.ndarray:
    """``β(u)`` per direction: weight held per N·m at every finger joint.

    Parameters
    ----------
    plant, plant_context, candidate, object_body
        As for :func:`finger_jacobian`.
    directions : (D, 3) float, optional
        Weight directions in frame O (normalised; default the 14 of the weight
        capacity).

    Returns
    -------
    (D,) float
        N per N·m (N per N for prismatic fingers); 0 where the grasp cannot
        hold a weight along the direction at all, ``inf`` where no joint bounds
        it (contacts on the palm alone, say).

    Notes
    -----
    One program for all directions (their blocks share nothing, so maximising
    ``Σ β(u)`` maximises each): the contact forces are the cones' generators
    ``f = S λ``, ``λ >= 0`` (eight per Coulomb cone, the default of the
    verdicts), and :data:`BETA_CAP` keeps it bounded.
    """
    u = np.asarray(directions, dtype=float)
    if u.ndim != 2 or u.shape[1] != 3 or not np.all(np.isfinite(u)):
        raise InvalidOptionError(
            f"directions must be finite 3-vectors in frame O, got shape {u.shape}"
        )
    norms = np.linalg.norm(u, axis=1, keepdims=True)
    if np.any(norms == 0):
        raise InvalidOptionError("directions must be nonzero 3-vectors")
    u = u / norms
    J = finger_jacobian(plant, plant_context, candidate, object_body)
    grasp = candidate.grasp
    S = block_diag(
        *(
            friction_cone_generators(
                c,
                DEFAULT_NUM_GENERATORS,
                characteristic_length=grasp.characteristic_length,
            )  # fmt: skip
            for c in grasp.contacts
        )
    )
    GS, TS = grasp_matrix(grasp) @ S, J.T @ S
    D, n = len(u), S.shape[1]
    prog = MathematicalProgram()
    lam = prog.NewContinuousVariables(n, D, "lambda")
    beta = prog.NewContinuousVariables(D, "beta")
    prog.AddBoundingBoxConstraint(0.0, np.inf, lam.reshape(-1))
    prog.AddBoundingBoxConstraint(0.0, BETA_CAP, beta)
    ones = np.ones(len(TS))
    for k in range(D):
        load = np.concatenate([u[k], np.zeros(3)])
        prog.AddLinearEqualityConstraint(
            np.hstack([GS, load[:, None]]), np.zeros(6), np.append(lam[:, k], beta[k])
        )
        prog.AddLinearConstraint(TS, -ones, ones, lam[:, k])
    prog.AddLinearCost(-np.ones(D), 0.0, beta)
    result = require_solution(
        prog, solve(prog, "lp", retry=True), "the torque-capacity LP"
    )
    b = np.clip(result.GetSolution(beta), 0.0, None)
    return np.where(b >= BETA_CAP * (1 - 1e-6), np.inf, b)


def torque_needed(
    plant, plant_context, candidate: GraspCandidate, object_body, *, weight: float
) -> float:
    """The torque (N·m per finger joint) that holds ``weight`` in every direction.

    Parameters
    ----------
    plant, plant_context, candidate, object_body
        As for :func:`finger_jacobian`.
    weight : float
        The object's weight ``m g`` (N).

    Returns
    -------
    float
        ``weight / min_u β(u)`` over the 14 weight directions: ``inf`` when
        some direction cannot be held, NaN for a NaN weight (a point cloud
        without ``object_mass``).
    """
    weight = real_scalar("weight", weight)
    if math.isnan(weight):
        return math.nan
    if not math.isfinite(weight) or weight < 0:
        raise InvalidOptionError(f"weight must be finite and >= 0 (N), got {weight!r}")
    beta = float(np.min(torque_capacity(plant, plant_context, candidate, object_body)))
    return math.inf if beta <= 0 else weight / beta


def with_torques_needed(
    result: GraspCandidates,
    plant,
    plant_context,
    object_body,
    *,
    weight: float,
    top: int,
    started: float,
) -> GraspCandidates:
    """``result`` with :func:`torque_needed` set on its best ``top`` candidates.

    Only force-closure candidates get it (the others hold no weight in some
    direction: inf would say nothing new).  ``started`` is the run's
    ``time.perf_counter()`` at its start, so ``result.time`` counts this stage.
    """
    if math.isnan(weight):
        return result
    head = [
        dataclasses.replace(
            c,
            torque_needed=torque_needed(
                plant, plant_context, c, object_body, weight=weight
            ),
        )
        if c.is_closure
        else c
        for c in result.candidates[:top]
    ]
    reason = result.reason or _too_weak(plant, head)
    return dataclasses.replace(
        result,
        candidates=(*head, *result.candidates[top:]),
        reason=reason,
        time=time.perf_counter() - started,
    )


def _too_weak(plant, head) -> str:
    """Why no candidate of ``head`` holds with the actuators, or ""."""
    needed = [c.torque_needed for c in head if not np.isnan(c.torque_needed)]
    if not needed:
        return ""
    limits = [
        float(a.effort_limit())
        for name in head[0].joint_names
        for a in _actuators(plant, find_joint(plant, name))
    ]
    if not limits or min(needed) <= min(limits):
        return ""
    return (
        f"the hand's actuators (effort limits from {min(limits):.3g} N·m) hold "
        f"none of the {len(needed)} best force-closure candidates against the "
        f"object's weight in every direction: they need at least "
        f"{min(needed):.3g} N·m per joint (torque_needed)"
    )


def _actuators(plant, joint):
    return [
        plant.get_joint_actuator(i)
        for i in plant.GetJointActuatorIndices()
        if plant.get_joint_actuator(i).joint().index() == joint.index()
    ]
