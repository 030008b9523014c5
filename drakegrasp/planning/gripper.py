"""A parallel-jaw gripper's geometry, learnt from the plant that holds it.

Nothing here is a constant of one gripper: the grasp axis, the opening, the
pads and the approach direction are read from the hand's joints and collision
geometry (the WSG-50 of ``drake_models``, drakegrasp's ``parallel_jaw``, or a
user's model).

**The hand.**  Its base ``H`` is a free body (a floating gripper): a planner
places it by setting its pose ``X_WH``.  Its fingers are those of
:mod:`drakegrasp.plant.fingers`; a parallel jaw has two, each driven by one
prismatic joint, the two joints' axes parallel.

**The grasp frame K** (fixed in ``H``): its x axis is the *grasp axis* ``a``,
from finger 0's pad towards finger 1's; its y axis the *approach* direction,
from the palm's collision geometry towards the pads, perpendicular to ``a``;
its origin halfway between the pads at the open stroke and at the pads'
lateral centre.

**Pads.**  A finger's pad is the part of its collision geometry that faces the
other finger: the geometries whose support along the closing direction is
within :data:`PAD_DEPTH` of the innermost one (the WSG's four 1 mm tip
spheres, a flat pad, a rounded dome).  The pad's coordinate along ``a`` is
affine in its joint's value (a prismatic joint), which gives the opening
``w(q) = c_1(q_1) − c_0(q_0)`` and its inverse.

**One motor.**  When a ``<mimic>`` (or another recorded coupling) ties one
finger's joint to the other's, ``q_1 = m q_0 + b``, the jaw keeps it:
:meth:`ParallelJaw.coupled` puts closed fingers back on the coupling and
moves the hand along ``a`` so that each pad stays where it closed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex, Joint, RigidBody

from drakegrasp.core.calls import checked_call
from drakegrasp.errors import ModelError
from drakegrasp.planning.surface import piece_of_shape
from drakegrasp.plant.attachment import chain_to_world, free_carrier, how_held
from drakegrasp.plant.couplings import plant_couplings
from drakegrasp.plant.fingers import chain_root, finger_chains, hand_structure
from drakegrasp.plant.validation import (
    HandSpec,
    hand_bodies,
    plant_context_of,
    resolve_object_body,
    scoped_name,
)

__all__ = ["PAD_DEPTH", "ParallelJaw", "free_base", "palm_geometries", "parallel_jaw"]

PAD_DEPTH = 5e-4
"""Geometries this close (m) to a finger's innermost support make its pad."""

_LATERAL_MIN = 1e-3
"""The pads' centre must lie this far (m) from the palm's across the axis."""


@checked_call
@dataclass(frozen=True, eq=False)
class ParallelJaw:
    """Geometry of a two-finger prismatic gripper, in its base frame H.

    Attributes
    ----------
    base : RigidBody
        The hand's free base body (frame H).
    joints : tuple of Joint
        Finger 0's and finger 1's prismatic joints.
    finger_bodies : tuple of tuple of RigidBody
        Each finger's bodies.
    position_indices : (2,) int
        The joints' indices in the plant's ``q``.
    lower, upper : (2,) float
        Joint limits, metres.
    X_HK : RigidTransform
        The grasp frame K in H (see the module docstring).
    pad_at_zero, pad_rate : (2,) float
        Finger ``f``'s pad sits at ``x_K = pad_at_zero[f] + pad_rate[f] q_f``
        (metres along the grasp axis).
    pad_geometries : tuple of tuple of GeometryId
        Each finger's pad geometries.
    min_opening, max_opening : float
        The symmetric opening's range over the joint limits, metres.
    coupling : (2,) float or None
        ``(m, b)`` when one motor drives both fingers, ``q_1 = m q_0 + b``
        (``b`` in metres); None when each finger has its own.
    """

    base: RigidBody
    joints: tuple[Joint, Joint]
    finger_bodies: tuple[tuple[RigidBody, ...], tuple[RigidBody, ...]]
    position_indices: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    X_HK: RigidTransform
    pad_at_zero: np.ndarray
    pad_rate: np.ndarray
    pad_geometries: tuple
    min_opening: float
    max_opening: float
    coupling: tuple[float, float] | None = None

    def q_for_opening(self, width) -> np.ndarray:
        """(…, 2) joint values that put the pads at ``x_K = ∓ width / 2``."""
        w = np.asarray(width, dtype=float)[..., None]
        target = np.concatenate([-w / 2, w / 2], axis=-1)
        return (target - self.pad_at_zero) / self.pad_rate

    def opening(self, q) -> np.ndarray:
        """The distance between the pads at joint values ``q`` (…, 2), metres."""
        x = self.pad_at_zero + self.pad_rate * np.asarray(q, dtype=float)
        return x[..., 1] - x[..., 0]

    def travel_left(self, q) -> np.ndarray:
        """(2,) how far (m) each pad can still close past joint values ``q``.

        Finger 0 closes along ``+a`` and finger 1 along ``-a`` (the grasp
        axis of K); each stops at its joint's closed limit.  A pad with no
        travel left presses on its limit, not on the object.
        """
        q = np.asarray(q, dtype=float)
        r = self.pad_rate
        rises = np.array([r[0] > 0, r[1] < 0])  # q grows while closing
        closed = np.where(rises, self.upper, self.lower)
        return np.abs(closed - q) * np.abs(r)

    def coupled(self, q) -> tuple[np.ndarray, float]:
        """Joint values on the coupling that leave both pads where ``q`` puts them.

        Parameters
        ----------
        q : (2,) float
            Closed joint values, each finger stopped on its own, metres.

        Returns
        -------
        q_coupled : (2,) float
            ``q_1 = m q_0 + b``; ``q`` itself without a coupling.
        shift : float
            How far (m) the hand moves along the grasp axis ``a`` so that
            each pad sits where ``q`` put it: ``x_f(q_coupled) + shift =
            x_f(q)`` for both fingers; 0 without a coupling.
        """
        q = np.asarray(q, dtype=float)
        if self.coupling is None:
            return q, 0.0
        m, b = self.coupling
        r0, r1 = (float(r) for r in self.pad_rate)
        q0 = (r0 * q[0] - r1 * (q[1] - b)) / (r0 - r1 * m)
        return np.array([q0, m * q0 + b]), r0 * (float(q[0]) - q0)

    def to_dict(self) -> dict:
        """JSON-ready summary."""
        return {
            "base": self.base.name(),
            "joints": [j.name() for j in self.joints],
            "grasp_axis_H": self.X_HK.rotation().matrix()[:, 0].tolist(),
            "approach_H": self.X_HK.rotation().matrix()[:, 1].tolist(),
            "p_HK": self.X_HK.translation().tolist(),
            "min_opening": self.min_opening,
            "max_opening": self.max_opening,
            "coupling": None if self.coupling is None else list(self.coupling),
        }


def free_base(plant: MultibodyPlant, bodies, *, hand: HandSpec = None) -> RigidBody:
    """The hand's base: the one free body of ``bodies`` that carries them all.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized.
    bodies : sequence of RigidBody
        The hand's bodies (:func:`~drakegrasp.plant.validation.hand_bodies`).
    hand : HandSpec, optional
        How the caller named the hand, for the message.

    Returns
    -------
    RigidBody
        The free body (its floating joint places the hand) among ``bodies``.

    Raises
    ------
    ModelError
        Naming why there is none: the hand's base is welded or jointed to
        the world or to another body (a table, an arm), the free base is not
        among ``bodies``, or ``bodies`` ride on several free bodies (other
        objects taken for the hand).
    """
    carriers: dict[int | None, list[RigidBody]] = {}
    for b in bodies:
        c = free_carrier(plant, b)
        carriers.setdefault(None if c is None else int(c.index()), []).append(b)
    if len(carriers) == 1 and None not in carriers:
        base = plant.get_body(BodyIndex(next(iter(carriers))))
        if any(b.index() == base.index() for b in bodies):
            return base
    raise ModelError(_why_not_free(plant, bodies, carriers, hand))


def _why_not_free(plant, bodies, carriers, hand) -> str:
    """One line: why ``bodies`` (grouped by their free carrier) have no free base."""
    names = [scoped_name(plant, b) for b in bodies]
    if None in carriers:  # held by the world: say by what, at the hand's base
        base = _held_base(plant, carriers[None])
        return (
            f"the hand is not free to place: its base {scoped_name(plant, base)} "
            f"is {how_held(plant, base)}; plan_grasps places a free-floating hand "
            "by its base's pose X_WH: add the hand without attaching it "
            "(load_scene(..., free_hand=True) and `drakegrasp plan` leave out a "
            "scene's welds of its hand, those of its included directive files "
            "too, but not the fixed joints inside model files)"
        )
    free = [plant.get_body(BodyIndex(i)) for i in carriers]
    if len(free) == 1:
        base = scoped_name(plant, free[0])
        instance = plant.GetModelInstanceName(free[0].model_instance())
        return (
            f"the hand's bodies {names} ride on the free body {base}, which is "
            f"not one of them: name the hand's model instance ({instance!r}) or "
            "list its base too"
        )
    shown = [scoped_name(plant, b) for b in free]
    hint = (
        "hand=None takes every body that can move outside the object's model "
        "instance, other objects too: name the hand's model instance"
        if hand is None
        else "name the hand's model instance, or list the bodies of one hand"
    )
    return (
        f"the hand's bodies move with {len(free)} free bodies {shown}, not one "
        f"free base: {hint}"
    )


def _held_base(plant, held) -> RigidBody:
    """The topmost body of the hand's model instances above a held body."""
    instances = {int(b.model_instance()) for b in held}
    base = held[0]
    for joint in chain_to_world(plant, base):
        parent = joint.parent_body()
        if int(parent.index()) == 0 or int(parent.model_instance()) not in instances:
            break
        base = parent
    return base


def _finger_supports(plant, ctx, inspector, finger, base, a_H, sign):
    """Innermost support along ``sign·a`` of each collision geometry of a finger.

    Returns (geometry ids, supports (G,), p_HG (G, 3)).
    """
    H = base.body_frame()
    ids, supports, centres = [], [], []
    for body in finger.bodies:
        X_HB = plant.CalcRelativeTransform(ctx, H, body.body_frame())
        for g in plant.GetCollisionGeometriesForBody(body):
            X_HG = X_HB @ inspector.GetPoseInFrame(g)
            piece = piece_of_shape(inspector.GetShape(g), X_HG, inspector.GetName(g))
            u_G = X_HG.rotation().inverse().multiply(sign * a_H)
            ids.append(g)
            supports.append(sign * (X_HG.translation() @ a_H) + piece.support(u_G))
            centres.append(X_HG.translation())
    if not ids:
        raise ModelError(f"finger {finger.name} has no collision geometry")
    return ids, np.array(supports), np.array(centres)


@checked_call
def parallel_jaw(
    plant: MultibodyPlant, plant_context, object_body: RigidBody, hand: HandSpec
) -> ParallelJaw:
    """Learn a parallel-jaw gripper's geometry from the plant.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized, registered with a ``SceneGraph``.
    plant_context : Context
        The plant's context (for the scene graph's inspector; not changed).
    object_body : RigidBody
        The object (the fingers' pairs are read against it).
    hand : HandSpec
        The hand (see :func:`~drakegrasp.plant.validation.hand_bodies`).

    Raises
    ------
    ModelError
        A hand without a free base, without two prismatic fingers with parallel
        axes and finite limits, or whose pads cannot be told from its palm.
    """
    plant_context = plant_context_of(plant, plant_context)  # the diagram's too
    base, fingers, joints, coupling, (lower, upper) = _two_prismatic_fingers(
        plant, plant_context, object_body, hand
    )
    inspector = plant.get_geometry_query_input_port().Eval(plant_context).inspector()
    ctx = plant.CreateDefaultContext()

    def finger_origins(q):  # finger body origins in H at joint values q
        for j, v in zip(joints, q, strict=True):
            j.set_translation(ctx, float(v))
        return [
            plant.CalcRelativeTransform(
                ctx, base.body_frame(), f.bodies[0].body_frame()
            ).translation()
            for f in fingers
        ]

    a_H = _grasp_axis(finger_origins, lower, upper)

    def supports(q):  # per finger: (ids, supports towards the other, centres)
        finger_origins(q)
        return [
            _finger_supports(plant, ctx, inspector, f, base, a_H, sign)
            for f, sign in zip(fingers, (1.0, -1.0), strict=True)
        ]

    # pad coordinate along a, affine in q: finger 0's max of a·x, finger 1's min
    pad = np.array(
        [[s0[1].max(), -s1[1].max()] for s0, s1 in map(supports, (lower, upper))]
    )
    rate = (pad[1] - pad[0]) / (upper - lower)
    if coupling is not None and not abs(rate[0] - rate[1] * coupling[0]) > 1e-9 * (
        abs(rate[0]) + abs(rate[1] * coupling[0])
    ):
        raise ModelError(
            f"the coupling q({joints[1].name()}) = {coupling[0]:g} "
            f"q({joints[0].name()}) + {coupling[1]:g} moves both pads the same "
            "way: the jaw cannot close on anything"
        )
    at_zero = pad[0] - rate * lower
    pad_ids, pad_lateral = _pads(supports(0.5 * (lower + upper)), a_H)
    approach = _approach(plant, inspector, base, pad_lateral, a_H)
    # open-stroke pad positions along a decide the origin of K along the axis
    closing = rate * np.array([-1.0, 1.0]) > 0  # where q opens: upper
    x_open = at_zero + rate * np.where(closing, upper, lower)
    x_closed = at_zero + rate * np.where(closing, lower, upper)
    centre = 0.5 * (x_open[0] + x_open[1])
    R_HK = RotationMatrix(np.column_stack([a_H, approach, np.cross(a_H, approach)]))
    return ParallelJaw(
        base=base,
        joints=joints,
        finger_bodies=tuple(tuple(f.bodies) for f in fingers),
        position_indices=np.array([j.position_start() for j in joints]),
        lower=lower,
        upper=upper,
        X_HK=RigidTransform(R_HK, pad_lateral + centre * a_H),
        pad_at_zero=at_zero - centre,
        pad_rate=rate,
        pad_geometries=pad_ids,
        min_opening=float(max(2 * max(centre - x_closed[0], x_closed[1] - centre), 0)),
        max_opening=float(2 * min(centre - x_open[0], x_open[1] - centre)),
        coupling=coupling,
    )


def _two_prismatic_fingers(plant, plant_context, object_body, hand):
    """(free base, fingers, their prismatic joints, coupling, limits), or a ModelError.

    The coupling is ``(m, b)``, ``q_1 = m q_0 + b``, when one joint follows
    the other (or both follow one leader), else None.  The limits are
    ``(lower, upper)``, (2,) each: the joints' own, within what their
    couplings let them reach (:func:`_coupled_limits`).
    """
    bodies = hand_bodies(plant, object_body, hand)
    object_body = resolve_object_body(plant, object_body)
    base = free_base(plant, bodies, hand=hand)
    inspector = plant.get_geometry_query_input_port().Eval(plant_context).inspector()
    structure = hand_structure(
        plant, object_body, bodies, plant_couplings(plant), inspector=inspector
    )
    # a jaw whose fingers a <mimic> couples (one motor) has two chains
    fingers = finger_chains(plant, structure)
    if len(fingers) != 2 or any(len(f.joints) != 1 for f in fingers):
        raise ModelError(
            "plan_grasps samples parallel-jaw grasps: the hand needs two fingers, "
            f"each driven by one prismatic joint; it has {len(fingers)} finger(s) "
            f"({[f.name for f in fingers]})"
        )
    joints = tuple(structure.joints[f.joints[0]] for f in fingers)
    follows = structure.coupling.follows
    limits = _coupled_limits(structure.joints, follows, [f.joints[0] for f in fingers])
    for j, (lo, hi) in zip(joints, limits, strict=True):
        if j.type_name() != "prismatic" or not (np.isfinite(lo) and np.isfinite(hi)):
            raise ModelError(
                f"finger joint {j.name()} must be prismatic with finite limits to "
                f"make a parallel jaw (it is {j.type_name()}, limits [{lo}, {hi}])"
            )
        if not hi > lo:
            raise ModelError(
                f"finger joint {j.name()} has no stroke: its limits [{lo}, {hi}] "
                "(within what its coupling to the other finger or to a drive "
                "lets it reach, if any) leave the finger no room to close"
            )
    coupling = _jaw_coupling(follows, *(f.joints[0] for f in fingers))
    lower, upper = (np.array(v, dtype=float) for v in zip(*limits, strict=True))
    return base, fingers, joints, coupling, (lower, upper)


def _coupled_limits(joints, follows, fingers: list) -> list[tuple[float, float]]:
    """The finger joints' limits, within what their couplings let them reach.

    ``q_i = a_i q_root + c_i`` along each finger's chain of leaders
    (``follows``: index -> ``(leader, ρ, Δq)``).  The fingers tied to one root
    (a hidden drive, or one finger the other follows) move as one: the
    root's positions that keep the root and every one of them within its
    limits are those of the jaw, and each finger reaches only their image.
    (The planner read each joint's own limits, and a hidden drive's, so a
    follower at ratio -2 opened past where its leader can go.)

    Parameters
    ----------
    joints : sequence of Joint
        The hand's joints, indexed as ``follows`` and ``fingers`` are.
    follows : dict
        :class:`~drakegrasp.plant.fingers.Coupling`'s follower -> ``(leader,
        ρ, Δq)``.
    fingers : list of int
        The finger joints, in the jaw's order.

    Returns
    -------
    list of (float, float)
        Per finger, ``(lower, upper)`` in its own unit (m); ``upper < lower``
        when the couplings leave it no position.
    """

    def own(i: int) -> tuple[float, float]:
        j = joints[i]
        return float(j.position_lower_limits()[0]), float(j.position_upper_limits()[0])

    roots: dict[int, list] = {}
    for i in fingers:
        k, a, c, _ = chain_root(follows, i)
        roots.setdefault(k, []).append((i, a, c))
    out = {}
    for k, members in roots.items():
        lo, hi = own(k)
        for i, a, c in members:
            if a != 0.0:
                ends = sorted(((own(i)[0] - c) / a, (own(i)[1] - c) / a))
                lo, hi = max(lo, ends[0]), min(hi, ends[1])
        for i, a, c in members:
            mapped = sorted((a * lo + c, a * hi + c)) if a != 0.0 else own(i)
            out[i] = (float(mapped[0]), float(mapped[1]))
    return [out[i] for i in fingers]


def _jaw_coupling(follows, i0: int, i1: int) -> tuple[float, float] | None:
    """``(m, b)`` with ``q_1 = m q_0 + b`` when joints ``i0``, ``i1`` share a leader.

    ``follows``: :class:`~drakegrasp.plant.fingers.Coupling`'s follower ->
    ``(leader, ρ, Δq)``.  Each joint is written as ``a q_root + c`` of the
    joint at the end of its chain of leaders
    (:func:`~drakegrasp.plant.fingers.chain_root`).
    """
    r0, a0, c0, _ = chain_root(follows, i0)
    r1, a1, c1, _ = chain_root(follows, i1)
    if r0 != r1:
        return None
    return float(a1 / a0), float(c1 - a1 / a0 * c0)


def _grasp_axis(finger_origins, lower, upper) -> np.ndarray:
    """Unit axis in H along which the fingers slide, from finger 0 to finger 1."""
    lo0, lo1 = finger_origins(lower)
    hi0, hi1 = finger_origins(upper)
    u = [(hi0 - lo0) / (upper[0] - lower[0]), (hi1 - lo1) / (upper[1] - lower[1])]
    a_H = u[0] / np.linalg.norm(u[0])
    if abs(abs(a_H @ u[1]) / np.linalg.norm(u[1]) - 1) > 1e-6:
        raise ModelError(
            "the two finger joints of a parallel jaw must move along parallel axes; "
            f"they move along {np.round(u[0], 6).tolist()} and "
            f"{np.round(u[1], 6).tolist()}"
        )
    m0, m1 = finger_origins(0.5 * (lower + upper))
    return -a_H if (m1 - m0) @ a_H < 0 else a_H


def _pads(supports, a_H):
    """Each finger's pad geometries and the pads' mean centre across the axis."""
    pad_ids, lateral = [], []
    for ids, sup, centres in supports:
        on_pad = sup >= sup.max() - PAD_DEPTH
        pad_ids.append(tuple(g for g, k in zip(ids, on_pad, strict=True) if k))
        c = centres[on_pad].mean(axis=0)
        lateral.append(c - (c @ a_H) * a_H)
    return tuple(pad_ids), 0.5 * (lateral[0] + lateral[1])


def palm_geometries(plant: MultibodyPlant, inspector, base: RigidBody) -> list:
    """The palm's collision geometries, each posed in the base frame H.

    The base's own; a base without any (a bare mount: many URDFs root a hand
    at a link without geometry, fixed to the palm link elsewhere and turned)
    takes those of the bodies welded to it.  Read from the base alone, such
    a palm was the mount's origin, and a pivoting jaw under a turned mount
    approached the object from there (1 candidate of 150 samples, 61 without
    the mount).  A base with geometry keeps its own: a finger's knuckle
    welded to the palm is no palm.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized.
    inspector : SceneGraphInspector
    base : RigidBody
        The hand's base (frame H).

    Returns
    -------
    list of (GeometryId, RigidTransform)
        ``(g, X_HG)``: the base's geometries, else those of the bodies welded
        to it in body order (empty: none has any).
    """
    own = plant.GetCollisionGeometriesForBody(base)
    if own:
        return [(g, inspector.GetPoseInFrame(g)) for g in own]
    ctx = plant.CreateDefaultContext()  # welds: the same in every state
    welded = sorted(
        (b for b in plant.GetBodiesWeldedTo(base) if b.index() != base.index()),
        key=lambda b: int(b.index()),
    )
    out = []
    for body in welded:
        X_HB = plant.CalcRelativeTransform(ctx, base.body_frame(), body.body_frame())
        out.extend(
            (g, X_HB @ inspector.GetPoseInFrame(g))
            for g in plant.GetCollisionGeometriesForBody(body)
        )
    return out


def _approach(plant, inspector, base, pad_lateral, a_H) -> np.ndarray:
    """Unit direction in H from the palm's collision geometry to the pads."""
    palm = [X_HG.translation() for _, X_HG in palm_geometries(plant, inspector, base)]
    palm_centre = np.mean(palm, axis=0) if palm else np.zeros(3)
    palm_lateral = palm_centre - (palm_centre @ a_H) * a_H
    approach = pad_lateral - palm_lateral
    if np.linalg.norm(approach) < _LATERAL_MIN:
        raise ModelError(
            "cannot tell the gripper's approach direction: its pads' centre "
            f"{np.round(pad_lateral, 4).tolist()} is within {_LATERAL_MIN * 1e3:g} mm "
            f"of its palm's {np.round(palm_lateral, 4).tolist()} across the grasp axis"
        )
    return approach / np.linalg.norm(approach)
