r"""Conservative advancement: how far a finger may move before it can touch.

A finger closes along a path ``q(α) = clip(q_0 + α d, lower, upper)`` in its
joint space (:mod:`drakegrasp.plant.closing`); followers of couplings move with
their leaders, so the rates of all closing joints are ``t = T d`` (``T`` the
coupling's tangent map) and ``|dq_j/dα| <= |t_j|``.

**Speed bound.**  A point ``x`` of a finger geometry ``g`` moves with

.. math:: \Big|\frac{dx}{d\alpha}\Big| \le V_g(d) = \sum_j |t_j|\, \rho_{j,g},

where ``ρ_{j,g}`` is the *reach* of joint ``j`` to ``g``: for a revolute joint
an upper bound on the distance from the joint's axis to any point of ``g`` over
every configuration of the path, for a prismatic joint 1 (a screw joint adds
its pitch per radian).  The reach is bounded without knowing the
configuration: the distance from joint ``j``'s origin (on its axis) to ``g`` is
at most the sum, along the kinematic chain from ``j`` to ``g``'s body, of the
fixed distances between successive joint origins in each body, the travel of
every prismatic closing joint in between (its largest ``|q|``), the current
offset of every joint that does not move while closing, and the radius of a
sphere that bounds ``g`` (``bounding_sphere`` of its shape)
around its centre.

**Step bound.**  The distance between two sets changes no faster than the
fastest point of either moves, and the object stands still, so every pair
``p = (object geometry, g)`` keeps ``ψ_p(α) >= ψ_p(0) − α V_g(d)``.  A step

.. math:: \alpha \le \alpha_{CA} = \min_p \frac{\psi_p(0) - \psi^*}{V_g(d)}

therefore ends with every pair at ``ψ_p >= ψ^* > 0`` and no pair can have
touched on the way, however thin the geometry it passes: nothing is skipped.
``ψ^*`` is the closing's target distance (half the contact tolerance).  Every
geometry pair of the finger counts, not only the closest, so a thin wire
behind a bead bounds the step as much as the bead does.

**Kept per plant.**  The reach depends on the plant's kinematic tree (fixed
after ``Finalize``), the closing joints' limits, the finger geometries' shapes
and poses (the scene graph's proximity version) and, only when a joint that
does not close sits between two closing joints of a chain, the context.
:func:`reach` keeps its answer per finalized plant and finger, checked against
the limits and the proximity version at every call, and recomputes it every
time for a finger whose reach reads the context.
"""

from __future__ import annotations

import copy
import weakref

import numpy as np
from pydrake.geometry import Role
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JointIndex
from pydrake.systems.framework import Context

from drakegrasp.errors import ModelError
from drakegrasp.plant._shapes import bounding_sphere
from drakegrasp.plant.fingers import Finger, HandStructure, joint_name

__all__ = ["advancement_bound", "finger_speed_bound", "geometry_reach", "reach"]

_KEPT: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
"""Finalized plant -> {finger key: (proximity version, reach rows)}.

Values hold ids, indices and arrays only, never a body or joint (that would
keep the plant alive)."""


def _inboard_joints(plant: MultibodyPlant) -> dict[int, object]:
    """Body index -> the joint whose child it is."""
    out = {}
    for i in range(plant.num_joints()):
        joint = plant.get_joint(JointIndex(i))
        out[int(joint.child_body().index())] = joint
    return out


def _closing_rate(joint) -> tuple[float, float]:
    """(rotation per unit joint rate, translation per unit joint rate)."""
    kind = joint.type_name()
    if kind == "revolute":
        return 1.0, 0.0
    if kind == "prismatic":
        return 0.0, 1.0
    if kind == "screw":
        return 1.0, abs(float(joint.screw_pitch())) / (2.0 * np.pi)
    raise ModelError(
        f"closing joint {joint.name()!r} is a {kind} joint; conservative "
        "advancement knows revolute, prismatic and screw joints"
    )


def reach(
    plant: MultibodyPlant,
    plant_context: Context,
    hand: HandStructure,
    finger: Finger,
    inspector,
) -> np.ndarray:
    """Reach ``ρ_{j,g}`` of every closing joint to every geometry of a finger.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
        The plant's context; the joints that do not close keep their offsets.
    hand : HandStructure
        The closing joints (columns) and their limits.
    finger : Finger
        Its ``pairs`` are the rows.
    inspector : SceneGraphInspector
        For the geometries' shapes and poses in their bodies.

    Returns
    -------
    (n_pairs, n_h) float
        Row ``p``: ``V_g(d) = ρ[p] @ |t|`` bounds the speed (metres per unit
        ``α``) of every point of the pair's finger geometry.  Zero for a joint
        that does not move the geometry.

    Raises
    ------
    ModelError
        For a closing joint of another type than revolute, prismatic or screw.
    """
    key = (
        tuple(
            (go.get_value(), gf.get_value(), int(body.index()))
            for go, gf, body in finger.pairs
        ),
        tuple(int(j.index()) for j in hand.joints),
        hand.lower.tobytes(),
        hand.upper.tobytes(),
    )
    version = inspector.geometry_version()
    kept = _KEPT.get(plant) if plant.is_finalized() else None
    if kept is not None and key in kept:
        old_version, rows = kept[key]
        if old_version.IsSameAs(version, Role.kProximity):
            return rows.copy()
    rows, reads_context = _reach(plant, plant_context, hand, finger, inspector)
    if plant.is_finalized() and not reads_context:
        # A copy: the inspector's version is a live reference that changes
        # with the context it came from.
        _KEPT.setdefault(plant, {})[key] = (copy.copy(version), rows.copy())
    return rows


def geometry_reach(
    plant: MultibodyPlant,
    plant_context: Context,
    hand: HandStructure,
    geometries,
    inspector,
) -> np.ndarray:
    """:func:`reach` of given geometries (not kept): rows ``(gf, body)``.

    For a finger that closes on something other than a body's geometry (a
    point cloud): every collision geometry ``gf`` of the finger's ``body``.
    """
    return _reach_rows(plant, plant_context, hand, list(geometries), inspector)[0]


def _reach(plant, plant_context, hand, finger, inspector):
    """:func:`reach`, and whether it read the context."""
    geometries = [(gf, body) for _, gf, body in finger.pairs]
    return _reach_rows(plant, plant_context, hand, geometries, inspector)


def _reach_rows(plant, plant_context, hand, geometries, inspector):
    """:func:`reach` of ``(gf, body)`` rows, and whether it read the context."""
    inboard = _inboard_joints(plant)
    column = {int(j.index()): k for k, j in enumerate(hand.joints)}
    rows = np.zeros((len(geometries), len(hand.joints)))
    reads_context = False  # a row set after a context-dependent offset
    for p, (gf, body) in enumerate(geometries):
        offset_read = False
        centre_G, radius = bounding_sphere(inspector.GetShape(gf))
        point = np.asarray(inspector.GetPoseInFrame(gf).multiply(centre_G))
        bound = radius  # every point x of g has |x - point| <= bound
        b = int(body.index())
        while b in inboard:
            joint = inboard[b]
            o_child = np.asarray(
                joint.frame_on_child().GetFixedPoseInBodyFrame().translation()
            )
            bound += float(np.linalg.norm(point - o_child))  # |x - o_J| <= bound
            k = column.get(int(joint.index()))
            if k is not None:
                turn, slide = _closing_rate(joint)
                rows[p, k] = turn * bound + slide
                reads_context |= offset_read
                travel = max(abs(hand.lower[k]), abs(hand.upper[k]))
                if slide and not np.isfinite(travel):
                    raise ModelError(
                        f"closing joint {joint_name(plant, joint)} translates "
                        "without finite limits; conservative advancement "
                        "cannot bound its travel"
                    )
                bound += slide * travel
            else:  # fixed while the hand closes: its present offset
                X_PC = joint.frame_on_child().CalcPose(
                    plant_context, joint.frame_on_parent()
                )
                bound += float(np.linalg.norm(X_PC.translation()))
                offset_read = True
            point = np.asarray(
                joint.frame_on_parent().GetFixedPoseInBodyFrame().translation()
            )
            b = int(joint.parent_body().index())
    return rows, reads_context


def finger_speed_bound(reach_rows: np.ndarray, rates: np.ndarray) -> np.ndarray:
    """``V_g(d)`` of every pair: the fastest point speed per unit ``α``.

    Parameters
    ----------
    reach_rows : (n_pairs, n_h) float
        From :func:`reach`.
    rates : (n_h,) float
        ``t = T d``: the rates of every closing joint along the path.

    Returns
    -------
    (n_pairs,) float
        Metres per unit ``α``.
    """
    return reach_rows @ np.abs(rates)


def advancement_bound(psi: np.ndarray, speed: np.ndarray, target: float) -> float:
    """``α_CA``: the largest step after which no pair can be nearer than ``target``.

    Parameters
    ----------
    psi : (n_pairs,) float
        Signed distance of every pair at the start of the step, metres.
    speed : (n_pairs,) float
        :func:`finger_speed_bound` of every pair.
    target : float
        Distance (metres) no pair may go below.

    Returns
    -------
    float
        ``min_p (ψ_p − target) / V_p`` over the pairs that move (``inf`` when
        none does); 0 when a moving pair is already at or below ``target``.
    """
    moving = speed > 0
    if not np.any(moving):
        return float("inf")
    gaps = np.maximum(psi[moving] - target, 0.0)
    return float(np.min(gaps / speed[moving]))
