r"""A multi-finger hand's approach, learnt from the plant, and sampled hand poses.

Stage 1 of the multi-finger route of :func:`~drakegrasp.planning.planner.plan_grasps`
(:mod:`drakegrasp.planning.multifinger`).  Nothing here is a constant of one
hand: the fingers, the pre-shape, the palm and the approach direction are read
from the hand's joints and collision geometry (Drake's Allegro hand,
drakegrasp's ``three_finger_hand`` or a user's model).

**The hand.**  Its base ``H`` is a free body placed by its pose ``X_WH``; its
fingers and closing joints are those of :mod:`drakegrasp.plant.fingers`.

**Pre-shape.**  The closing joints' values from which ``close_hand`` starts:
the *open hand* (the joint values in the context given to the planner), a
user's ``preshape`` vector, or either moved along a *synergy* direction ``s``
by an amount drawn per pose, ``q = clip(q_0 + σ s)``, ``σ ~ U[σ_lo, σ_hi]``
(``synergy="curl"`` takes ``s = q_c − q_0``, the curl below).  Couplings are
applied and the result is clipped to the joint limits.

**The curl** ``q_c``: the fingers drawn together from ``q_0`` by projected
gradient descent of the fingertips' spread ``Σ_f |t_f(q) − t̄|²`` (``t_f`` the
mean centre of finger ``f``'s tip collision geometries in H), within the
limits: where the fingers meet when the hand closes on nothing, whatever the
signs of its joints.

**The grasp frame K** (fixed in H): its x axis is the *approach* ``u``, from
the palm towards the *grasp centre* ``c`` (the fingertips' mean at the curl;
a user may give ``u``); its origin the point of the palm's centre line
through ``c`` (``c`` minus its reach ``L = (c − p_palm)·u`` along ``u``).
``p_palm`` is the mean centre of the palm's collision geometries: the
base's, or for a base without any (a bare mount) those of the bodies welded
to it (:func:`~drakegrasp.planning.gripper.palm_geometries`; the base
origin without any).  For the Allegro hand with its thumb opposed, ``u``
leans from the fingers' direction towards the palm's face; for a hand whose
fingers surround an axis (drakegrasp's three-finger hand), it is that axis.

**Poses.**  For a surface point ``p`` with outward normal ``n`` (area-uniform
over the object's collision geometry, :mod:`drakegrasp.planning.surface`), the
approach is ``d = −n`` tilted by an angle uniform in ``[0, tilt]`` about a
random axis across it; the palm's centre line is put through ``p`` along
``d``, with the palm's front face a *stand-off* ``s`` from ``p``
(``s ~ U[s_lo, s_hi]``, default from 0 to the reach ``L``: from the palm
touching the surface to the grasp centre on it), and the hand is rolled about
``d`` by an angle uniform in ``[0, 2π)``.  Everything is drawn in the object
frame O, so a rigid motion of the scene moves every pose with it.

**A pinch** (a hand whose chains move on two sides,
:func:`~drakegrasp.planning.centring.chain_sides`: a Robotiq-style gripper,
two revolute fingers) closes along one axis, from one side's tip to the
other's.  Rolled at random, its pads met a box's faces at an angle and
touched with a corner each: two point contacts, never force closure.  Its
roll is the best of :data:`PINCH_ROLLS` turns of the drawn one spread over a
half turn: the one whose closing axis, through the pads' midpoint, leaves
the object on both sides most nearly along the outward normals (the least of
the two cosines, from :meth:`ObjectSurface.chord
<drakegrasp.planning.surface.ObjectSurface.chord>`), across a width the open
pads span; then turned to lay the axis along the difference of those two
normals (exact on flat faces).  The drawn roll stays where no line meets the
object.  The tilt turns the approach about that axis, so the pads still
close square on the faces.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.tree import RigidBody

from drakegrasp.core.calls import checked_call
from drakegrasp.core.validation import describe, plain_str
from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.planning.centring import chain_sides
from drakegrasp.planning.gripper import free_base, palm_geometries
from drakegrasp.planning.placement import axis_frames
from drakegrasp.planning.surface import piece_of_shape
from drakegrasp.plant.couplings import plant_couplings
from drakegrasp.plant.fingers import (
    HandStructure,
    finger_chains,
    hand_structure,
    is_hidden_drive,
    tip_bodies,
)
from drakegrasp.plant.pose import JOINT_LIMIT_TOL
from drakegrasp.plant.validation import (
    HandSpec,
    hand_bodies,
    plant_context_of,
    resolve_object_body,
)

__all__ = [
    "OPEN",
    "PINCH_ROLLS",
    "MultiFingerHand",
    "multi_finger_hand",
    "sample_approaches",
]

PINCH_ROLLS = 8
"""Rolls tried per pose of a pinch (evenly over half a turn from the drawn
one: the two sides swap over the other half): one every 22.5°."""

_MIN_REACH = 1e-3
"""The grasp centre must lie this far (m) in front of the palm."""

_PINCH_AXIS_STEPS = 20
"""Most refinements of a pinch's closing axis (:func:`_pinch`): each box about
the tips is taken again along the axis found, until the axis stays."""

_CURL_STEPS = 15
_CURL_STEP = (0.1, 0.005)
"""Steps, and largest change of a revolute (rad) and a prismatic (m) joint per
step, of the curl (:func:`_curl`)."""

OPEN = "open"
"""``preshape=OPEN``: the context's hand, its fingertips drawn apart
(:func:`multi_finger_hand`)."""

_OPEN_MAX_STEPS = 400
"""Most steps of the opening (:func:`_opened`): 40 rad of a revolute joint."""

_OPEN_SHARES = (1.0, 0.5, 0.25, 0.125, 0.0625)
"""Shares of a curl step (:data:`_CURL_STEP`) the opening tries, longest
first, before it stops: it ends within 1/16 of a step of the most spread."""


@checked_call
@dataclass(frozen=True, eq=False)
class MultiFingerHand:
    """A multi-finger hand as the planner sees it, in its base frame H.

    Attributes
    ----------
    base : RigidBody
        The free base (frame H).
    structure : HandStructure
        Closing joints, limits, fingers and couplings
        (:func:`~drakegrasp.plant.fingers.hand_structure`).
    chains : tuple of Finger
        The fingers as kinematic chains
        (:func:`~drakegrasp.plant.fingers.finger_chains`): two fingers that a
        ``<mimic>`` closes as one are two here, each with its own contacts.
    preshape : (n_h,) float
        The base pre-shape ``q_0`` over the closing joints (radians or
        metres), within the limits and the couplings.
    synergy : (n_h,) float or None
        The synergy direction the pre-shape moves along per pose.
    synergy_range : (2,) float
        ``(σ_lo, σ_hi)`` of the synergy amount.
    X_HK : RigidTransform
        The grasp frame K in H (x axis the approach ``u``; see the module
        docstring).
    reach : float
        ``L``, metres from K's origin to the grasp centre along ``u``.
    palm_depth : float
        Support of the base's collision geometry along ``u`` beyond K's
        origin (the palm's front face), metres.
    standoff : (2,) float
        ``(s_lo, s_hi)``, metres from the sampled surface point to the palm's
        front face.
    sides : tuple of int
        :func:`~drakegrasp.planning.centring.chain_sides` of ``chains``: the
        chains of a closing group whose root joints turn alike share one
        (empty: each chain a side of its own).
    closing_axis : (3,) float or None
        A pinch's closing axis in K (unit, across the approach: from one
        side's tip to the other's at the pre-shape, each side's tip the
        centre of the box about the tip geometries of its chains that reach
        furthest along ``u``, to a millimetre); None for another hand.
    pinch_reach : float
        Metres from K's origin along ``u`` to a pinch's tips' midpoint (NaN
        for another hand).
    pinch_width : float
        Metres between a pinch's two tips' collision geometries along its
        closing axis at the pre-shape (NaN for another hand): no object
        wider than this fits between them.
    """

    base: RigidBody
    structure: HandStructure
    chains: tuple
    preshape: np.ndarray
    synergy: np.ndarray | None
    synergy_range: np.ndarray
    X_HK: RigidTransform
    reach: float
    palm_depth: float
    standoff: np.ndarray
    sides: tuple[int, ...] = ()
    closing_axis: np.ndarray | None = None
    pinch_reach: float = float("nan")
    pinch_width: float = float("nan")

    @property
    def num_fingers(self) -> int:
        """Number of fingers: kinematic chains (``chains``), coupled or not."""
        return len(self.chains)

    def preshapes(self, amounts: np.ndarray) -> np.ndarray:
        """(K, n_h) pre-shapes at synergy amounts ``amounts`` (K,)."""
        s = self.structure
        if self.synergy is None:
            return np.tile(self.preshape, (len(amounts), 1))
        q = self.preshape + np.asarray(amounts, float)[:, None] * self.synergy
        # the leaders clipped to their ranges (cut to keep their followers in
        # theirs), then the followers set from them: clipping after the
        # couplings would break them where a follower's range is narrow
        q = np.clip(q, s.lower, s.upper)
        return np.array([s.coupling.apply(row) for row in q])

    def to_dict(self) -> dict:
        """JSON-ready summary."""
        return {
            "base": self.base.name(),
            "joints": list(self.structure.names),
            "fingers": [f.name for f in self.chains],
            "preshape": self.preshape.tolist(),
            "synergy": None if self.synergy is None else self.synergy.tolist(),
            "synergy_range": self.synergy_range.tolist(),
            "approach_H": self.X_HK.rotation().matrix()[:, 0].tolist(),
            "p_HK": self.X_HK.translation().tolist(),
            "reach": self.reach,
            "palm_depth": self.palm_depth,
            "standoff": self.standoff.tolist(),
        } | (
            {}
            if self.closing_axis is None
            else {
                "closing_axis_K": self.closing_axis.tolist(),
                "pinch_reach": self.pinch_reach,
                "pinch_width": self.pinch_width,
            }
        )


def _check_preshape_limits(q: np.ndarray, structure) -> None:
    """Refuse a given pre-shape that leaves a joint's limits.

    By more than :data:`~drakegrasp.plant.pose.JOINT_LIMIT_TOL`, naming the
    joint (it was clipped silently, and a pre-shape all beyond its limits was
    rejected sample by sample as colliding fingers).
    """
    lo, hi = np.asarray(structure.lower), np.asarray(structure.upper)
    out = np.flatnonzero((q < lo - JOINT_LIMIT_TOL) | (q > hi + JOINT_LIMIT_TOL))
    if out.size:
        k = int(out[0])
        raise InvalidOptionError(
            f"preshape[{k}] ({structure.names[k]}) = {q[k]:g} is outside the "
            f"joint's limits [{lo[k]:g}, {hi[k]:g}]"
            + ("" if out.size == 1 else f", and {out.size - 1} more joints are")
        )


def _check_preshape_couplings(given: np.ndarray, q: np.ndarray, structure) -> None:
    """Refuse a pre-shape whose follower's value its coupling would overwrite.

    ``q`` is ``given`` with every follower set from its leader; a value given
    for a follower that differs from that (beyond
    :data:`~drakegrasp.plant.pose.JOINT_LIMIT_TOL`) was silently replaced.
    """
    off = np.flatnonzero(np.abs(q - given) > JOINT_LIMIT_TOL)
    if off.size:
        k = int(off[0])
        lead, rho, offset = structure.coupling.follows[k]
        raise InvalidOptionError(
            f"preshape[{k}] ({structure.names[k]}) = {given[k]:g} breaks its "
            f"coupling {structure.names[k]} = {rho:g} * {structure.names[lead]} "
            f"+ {offset:g}, which sets it to {q[k]:g}: give the leader's value "
            "and the follower's that follows from it"
        )


def _vector(name, value, n) -> np.ndarray:
    try:
        v = np.asarray(value, dtype=float)
    except Exception:  # noqa: BLE001 - not numbers, or a hostile __array__
        v = np.full(0, np.nan)
    if v.shape != (n,) or not np.all(np.isfinite(v)):
        raise InvalidOptionError(
            f"{name} must be {n} finite numbers, got {describe(value)}"
        )
    return v


def _range(name, value) -> np.ndarray:
    r = _vector(name, value, 2)
    if not r[0] <= r[1]:
        raise InvalidOptionError(
            f"{name} must be (low, high) with low <= high, got {describe(value)}"
        )
    return r


def _centres(plant, ctx, inspector, H, bodies) -> list[np.ndarray]:
    """Centres in H of the collision geometries of ``bodies``."""
    out = []
    for body in bodies:
        X_HB = plant.CalcRelativeTransform(ctx, H, body.body_frame())
        out.extend(
            (X_HB @ inspector.GetPoseInFrame(g)).translation()
            for g in plant.GetCollisionGeometriesForBody(body)
        )
    return out


def _curl(tips, q0, structure, moves, steps=_CURL_STEPS) -> np.ndarray:
    """The closed hand: ``q0`` moved to draw the fingertips together.

    Projected gradient descent of the fingertips' spread
    ``Σ_f |t_f(q) − t̄|²`` (central differences), within the joint limits and
    couplings.  Each joint moves at most :data:`_CURL_STEP` a step: a leader
    steps within its followers' caps over their ratios, a hidden drive
    (``moves`` False) within those alone (:meth:`Coupling.leader_steps
    <drakegrasp.plant.fingers.Coupling.leader_steps>`), so that a hand on a
    drive curls as its twin with the motor on a finger does.
    """
    lower, upper = structure.lower, structure.upper
    cap = _steps_of(structure, moves)
    q = q0.copy()
    for _ in range(steps):
        grad = _spread_gradient(tips, q, structure)
        scale = np.max(np.abs(grad), initial=0.0)
        if scale <= 1e-12:
            break
        q = np.clip(q - cap * grad / scale, lower, upper)
    return q


def _steps_of(structure, moves) -> np.ndarray:
    """Each closing joint's largest move a step of the curl or the opening.

    :data:`_CURL_STEP` by the joint's kind, a leader's within its followers'
    caps over their ratios, a hidden drive's (``moves`` False) within those
    alone (:meth:`Coupling.leader_steps
    <drakegrasp.plant.fingers.Coupling.leader_steps>`).
    """
    own = np.array([_CURL_STEP[j.type_name() == "prismatic"] for j in structure.joints])
    return structure.coupling.leader_steps(own, moves)


def _spread_gradient(tips, q, structure, h: float = 1e-4) -> np.ndarray:
    """∂/∂q of the fingertips' spread ``Σ_f |t_f(q) − t̄(q)|²`` at ``q``.

    Central differences of ``h`` (clipped to the limits) about the mean
    ``t̄`` at ``q`` (the same derivative there), pulled back onto the
    leaders (:meth:`Coupling.pull_back
    <drakegrasp.plant.fingers.Coupling.pull_back>`).
    """
    lower, upper = structure.lower, structure.upper
    t = tips(q)
    grad = np.zeros_like(q)
    for j in range(len(q)):
        e = np.zeros_like(q)
        e[j] = h
        tp, tm = (
            tips(np.clip(q + e, lower, upper)),
            tips(np.clip(q - e, lower, upper)),
        )
        spread_p = np.sum((tp - t.mean(axis=0)) ** 2)
        spread_m = np.sum((tm - t.mean(axis=0)) ** 2)
        grad[j] = (spread_p - spread_m) / (2 * h)
    return structure.coupling.pull_back(grad)


def _opened(tips, q0, structure, moves) -> np.ndarray:
    """The open hand (``preshape="open"``): the fingertips drawn apart from ``q0``.

    Projected gradient *ascent* of the fingertips' spread ``Σ_f |t_f(q) − t̄|²``
    (the curl's measure, :func:`_curl`) from the context's hand ``q0``, by
    the curl's steps, until the spread stops growing: each joint turns the
    way that parts the fingertips until it reaches its limit, so an angular
    gripper's jaws open fully and a joint that does not part them stays
    where it is.  A joint at the limit it is pushed against drops out of the
    step (else it would hold the others to a crawl); a step that would not
    part them is shortened (:data:`_OPEN_SHARES`) before the ascent stops.
    The steps are enough to cross every joint's range twice, and
    :data:`_OPEN_MAX_STEPS` with a joint that has no limit.  The ascent is
    local: a finger curled shut past the others' tips spreads them further
    by curling on, and stays.
    """
    cap = _steps_of(structure, moves)
    span = (structure.upper - structure.lower)[cap > 0]
    if np.all(np.isfinite(span)):
        crossings = int(np.ceil(np.max(span / cap[cap > 0], initial=0.0)))
        steps = min(2 * crossings + 2, _OPEN_MAX_STEPS)
    else:  # a joint without limits turns as far as that parts the fingertips
        steps = _OPEN_MAX_STEPS
    lower, upper = structure.lower, structure.upper

    def spread(q) -> float:
        t = tips(q)
        return float(np.sum((t - t.mean(axis=0)) ** 2))

    q = structure.coupling.apply(np.clip(q0, lower, upper))
    current = spread(q)
    for _ in range(steps):
        grad = _spread_gradient(tips, q, structure)
        pinned = ((grad > 0) & (q >= upper)) | ((grad < 0) & (q <= lower))
        grad = np.where(pinned, 0.0, grad)
        scale = np.max(np.abs(grad), initial=0.0)
        if scale <= 1e-12:
            break
        for share in _OPEN_SHARES:  # a shorter step where a full one overshoots
            step = share * cap * grad / scale
            trial = structure.coupling.apply(np.clip(q + step, lower, upper))
            grown = spread(trial)
            if grown > current:
                break
        else:
            break
        q, current = trial, grown
    return q


@checked_call
def multi_finger_hand(
    plant,
    plant_context,
    object_body: RigidBody,
    hand: HandSpec,
    *,
    preshape=None,
    synergy=None,
    synergy_range=(0.0, 1.0),
    approach=None,
    standoff=None,
) -> MultiFingerHand:
    """Learn a multi-finger hand's pre-shape and grasp frame from the plant.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized, registered with a ``SceneGraph``.
    plant_context : Context
        The plant's context: its hand joint values are the open hand (used
        when ``preshape`` is None); not changed.
    object_body : RigidBody
        The object (the fingers' geometry pairs are read against it).
    hand : HandSpec
    preshape : (n_h,) float or "open", optional
        The pre-shape over the closing joints (order of
        ``structure.names``); default the context's.  :data:`OPEN`: the
        context's hand with its fingertips drawn apart, each joint turned the
        way that parts them, to its limit or as far as that parts them (an
        angular gripper whose model's zero is nearly shut opened fully, as
        the parallel-jaw route opens a jaw's stroke); a joint that does not
        part them keeps the context's value.  The opening is a local ascent
        of the fingertips' spread: a finger curled shut past the others'
        tips stays shut (give joint values then).
    synergy : (n_h,) float or "curl", optional
        A direction the pre-shape moves along by an amount drawn in
        ``synergy_range`` per pose (``"curl"``: towards the curl).
    synergy_range : (2,) float, optional
    approach : (3,) float, optional
        The approach direction in H; default from the palm to the grasp
        centre.
    standoff : (2,) float, optional
        Palm stand-off range (m); default ``(0, reach)``.

    Raises
    ------
    ModelError
        A hand without a free base, without fingers (closing joints), or
        whose fingertips do not lie in front of the palm along the approach.
    InvalidOptionError
        A malformed pre-shape, synergy, approach or stand-off.
    """
    plant_context = plant_context_of(plant, plant_context)  # the diagram's too
    bodies = hand_bodies(plant, object_body, hand)
    object_body = resolve_object_body(plant, object_body)
    base = free_base(plant, bodies, hand=hand)
    inspector = plant.get_geometry_query_input_port().Eval(plant_context).inspector()
    structure = hand_structure(
        plant, object_body, bodies, plant_couplings(plant), inspector=inspector
    )
    if not structure.fingers:
        raise ModelError("the hand has no fingers (no closing joint moves a body)")
    if not np.any(structure.upper > structure.lower):
        limits = ", ".join(
            f"{name} [{lo:g}, {hi:g}]"
            for name, lo, hi in zip(
                structure.names, structure.lower, structure.upper, strict=True
            )
        )
        raise ModelError(
            f"no closing joint of the hand has any range: {limits}; the "
            "fingers cannot open or close (give the joints limits lower < upper)"
        )
    # a finger is a kinematic chain, though a <mimic> closes two as one
    chains = finger_chains(plant, structure)
    n = len(structure.names)
    # each read once as the plain str it holds: a subclass's == may raise or lie
    preshape, synergy = plain_str(preshape), plain_str(synergy)
    opened = type(preshape) is str
    if opened and preshape != OPEN:
        raise InvalidOptionError(
            f"preshape must be n_h = {n} numbers or {OPEN!r}, got {describe(preshape)}"
        )
    if preshape is None or opened:
        q0 = plant.GetPositions(plant_context)[structure.position_indices]
        q0 = structure.coupling.apply(q0)
    else:
        given = _vector("preshape", preshape, n)
        _check_preshape_limits(given, structure)  # the values given, as --preshape
        q0 = structure.coupling.apply(given)
        _check_preshape_couplings(given, q0, structure)
    q0 = structure.coupling.apply(np.clip(q0, structure.lower, structure.upper))
    curl_synergy = type(synergy) is str
    if curl_synergy and synergy != "curl":
        raise InvalidOptionError(
            f"synergy must be n_h = {n} numbers or 'curl', got {describe(synergy)}"
        )
    syn = (
        None
        if synergy is None or curl_synergy
        else structure.coupling.project(_vector("synergy", synergy, n))
    )
    if syn is not None and not np.any(syn):
        raise InvalidOptionError("synergy must move at least one closing joint")
    ctx = plant.CreateDefaultContext()
    H = base.body_frame()
    finger_tips = [
        list({id(b): b for _, _, b in f.tip_pairs}.values())
        or tip_bodies(plant, structure, f)  # no object geometry (a cloud)
        for f in chains
    ]
    if not any(finger_tips):
        raise ModelError("the hand's fingers have no collision geometry to grasp with")

    def tips(q):  # (F', 3) fingertip centres in H at closing-joint values q
        q_all = plant.GetPositions(ctx)
        q_all[structure.position_indices] = structure.coupling.apply(q)
        plant.SetPositions(ctx, q_all)
        return np.array(
            [
                np.mean(_centres(plant, ctx, inspector, H, b), axis=0)
                for b in finger_tips
                if b
            ]
        )

    moves = np.array([not is_hidden_drive(plant, j) for j in structure.joints])
    if opened:
        q0 = _opened(tips, q0, structure, moves)
    q_curled = _curl(tips, q0, structure, moves)
    centre = tips(q_curled).mean(axis=0)
    if curl_synergy:
        syn = q_curled - q0
        if not np.any(syn):
            raise ModelError("the hand's fingertips cannot move towards each other")
    palm_shapes = palm_geometries(plant, inspector, base)  # a mount's palm too
    palm = [X_HG.translation() for _, X_HG in palm_shapes]
    p_palm = np.mean(palm, axis=0) if palm else np.zeros(3)
    if approach is None:
        u = centre - p_palm
    else:
        u = _vector("approach", approach, 3)
    if np.linalg.norm(u) < _MIN_REACH:
        raise ModelError(
            "cannot tell the hand's approach: its grasp centre "
            f"{np.round(centre, 4).tolist()} lies within {_MIN_REACH * 1e3:g} mm of "
            f"its palm's {np.round(p_palm, 4).tolist()} (give approach=)"
        )
    u = u / np.linalg.norm(u)
    reach = float((centre - p_palm) @ u)
    if reach < _MIN_REACH:
        raise ModelError(
            f"the fingertips lie {reach * 1e3:.1f} mm along the approach "
            f"{np.round(u, 3).tolist()} from the palm: they must lie in front of it"
        )
    origin = centre - reach * u
    helper = np.eye(3)[np.argmin(np.abs(u))]
    e1 = np.cross(helper, u)
    e1 /= np.linalg.norm(e1)
    X_HK = RigidTransform(
        RotationMatrix(np.column_stack([u, e1, np.cross(u, e1)])), origin
    )
    depth = 0.0
    for g, X_HG in palm_shapes:
        piece = piece_of_shape(inspector.GetShape(g), X_HG, inspector.GetName(g))
        u_G = X_HG.rotation().inverse().multiply(u)
        depth = max(depth, (X_HG.translation() - origin) @ u + piece.support(u_G))
    span = np.array([0.0, reach]) if standoff is None else _range("standoff", standoff)
    if span[0] < 0:
        raise InvalidOptionError(
            f"standoff must be >= 0 metres, got {describe(standoff)}"
        )
    q_all = plant.GetPositions(ctx)
    q_all[structure.position_indices] = structure.coupling.apply(q0)
    plant.SetPositions(ctx, q_all)  # the pre-shape, where the pinch is learnt
    sides = tuple(chain_sides(ctx, structure, chains))
    pinch = _pinch(plant, ctx, inspector, H, sides, finger_tips, u)
    closing_axis, pinch_reach, pinch_width = None, float("nan"), float("nan")
    if pinch is not None:
        c_H, mid, pinch_width = pinch
        closing_axis = X_HK.rotation().inverse().multiply(c_H)
        pinch_reach = float((mid - origin) @ u)
    return MultiFingerHand(
        base=base,
        structure=structure,
        chains=chains,
        preshape=q0,
        synergy=syn,
        synergy_range=_range("synergy_range", synergy_range),
        X_HK=X_HK,
        reach=reach,
        palm_depth=float(depth),
        standoff=span,
        sides=sides,
        closing_axis=closing_axis,
        pinch_reach=pinch_reach,
        pinch_width=pinch_width,
    )


def _pinch(plant, ctx, inspector, H, sides, finger_tips, u):
    """``(c_H, mid_H, width)`` of a hand whose chains move on two sides, else None.

    Each side's tip is the centre of the box about its chains' tip
    geometries (in ``ctx``, at the pre-shape; a mesh's frame may lie
    anywhere), of those of its chains that reach furthest along ``u``, to a
    millimetre (a pad, not the bar beside it), the box first along H's axes,
    then along ``u``, ``c_H`` and ``u × c_H`` until ``c_H`` stays (so that it
    does not depend on how the base frame is turned);
    ``c_H`` the unit line from the first side's tip to the second's with its
    part along ``u`` removed, ``mid_H`` their midpoint, ``width`` the gap
    between the two tips' collision geometries along ``c_H`` (m: the
    widest object the open pinch spans).
    """
    if len(set(sides)) != 2:
        return None
    found: dict[int, list] = {}
    for side, bodies in zip(sides, finger_tips, strict=True):
        if bodies:
            reach = _support(plant, ctx, inspector, H, bodies, u)
            found.setdefault(side, []).append((reach, bodies))
    if len(found) != 2:
        return None
    on = {}
    for side, entries in found.items():
        furthest = max(r for r, _ in entries)
        on[side] = [b for r, bs in entries if r >= furthest - _MIN_REACH for b in bs]
    on_a, on_b = on[min(on)], on[max(on)]

    def centre(bodies, axes):  # the centre of the box about bodies along axes
        return sum(
            0.5
            * (
                _support(plant, ctx, inspector, H, bodies, e)
                - _support(plant, ctx, inspector, H, bodies, -e)
            )
            * e
            for e in axes
        )

    def axis(axes):  # the unit line from side a's box centre to side b's, across u
        d = centre(on_b, axes) - centre(on_a, axes)
        d = d - (d @ u) * u
        n = np.linalg.norm(d)
        return (d / n if n >= _MIN_REACH else None), d

    c, _ = axis(np.eye(3))
    if c is None:  # the tips lie one behind the other
        return None
    # The boxes again along (u, c, u x c), until c stays: along H's axes
    # they depend on how the model's base frame is turned (a pivoting jaw
    # under a turned mount: 0.46 deg off, so that one of each pad's two tip
    # spheres stayed 0.13 mm off the face and 4 of 63 candidates were force
    # closure, against 43 of 61 with the mount square).
    for _ in range(_PINCH_AXIS_STEPS):
        turned, _ = axis((u, c, np.cross(u, c)))
        if turned is None or np.linalg.norm(turned - c) <= 1e-12:
            break
        c = turned
    a, b = centre(on_a, (u, c, np.cross(u, c))), centre(on_b, (u, c, np.cross(u, c)))
    reach_a = _support(plant, ctx, inspector, H, on_a, c)
    reach_b = _support(plant, ctx, inspector, H, on_b, -c)
    return c, (a + b) / 2, float(-reach_b - reach_a)


def _support(plant, ctx, inspector, H, bodies, v_H) -> float:
    """``max x·v`` over the collision geometries of ``bodies`` (frame H, m)."""
    out = -np.inf
    for body in bodies:
        X_HB = plant.CalcRelativeTransform(ctx, H, body.body_frame())
        for g in plant.GetCollisionGeometriesForBody(body):
            X_HG = X_HB @ inspector.GetPoseInFrame(g)
            piece = piece_of_shape(inspector.GetShape(g), X_HG, inspector.GetName(g))
            v_G = X_HG.rotation().inverse().multiply(v_H)
            out = max(out, float(X_HG.translation() @ v_H + piece.support(v_G)))
    return out


def _pinch_poses(surface, p_O, d0, across, angle, s, roll, hand: MultiFingerHand):
    """``(d_O, roll)`` of a pinch's poses: rolled to meet the object, then tilted.

    The roll is chosen about the inward normal ``d0`` (:func:`_aligned_rolls`),
    with the tips' midpoint where the stand-off ``s`` puts it, kept within the
    object along ``d0`` (a tenth of the reach inside its surfaces, or at its
    middle if it is thinner: pads whose midpoint stops short of it or passes
    it still reach into it).  The approach is then tilted by ``angle`` about
    the closing axis, to the side ``across`` leans to, so that the axis stays
    where the roll laid it; the roll is re-expressed about the tilted
    approach.
    """
    depth = hand.pinch_reach - s - hand.palm_depth
    _, through, _ = surface.chord(p_O, d0)
    inset = np.fmin(0.1 * abs(hand.pinch_reach), through / 2)
    depth = np.where(np.isnan(through), depth, np.clip(depth, inset, through - inset))
    roll = _aligned_rolls(surface, p_O + depth[:, None] * d0, d0, roll, hand)
    c = axis_frames(d0, roll) @ hand.closing_axis
    side = np.cross(c, d0)  # unit: c is across d0
    sign = np.where(np.sum(across * side, axis=1) < 0, -1.0, 1.0)
    d_O = np.cos(angle)[:, None] * d0 + (sign * np.sin(angle))[:, None] * side
    return d_O, _roll_along(d_O, c, hand.closing_axis)


def _roll_along(d_O, c_O, c_K) -> np.ndarray:
    """The rolls about ``d_O`` (n, 3) that lay the closing axis ``c_K`` along ``c_O``.

    ``c_O`` (n, 3) lies across ``d_O``.  A roll is the angle of
    :func:`~drakegrasp.planning.placement.axis_frames`, at which ``c_K`` (in
    K, across K's x axis) sits at ``atan2(c_z, c_y)``.
    """
    frame = axis_frames(d_O, np.zeros(len(d_O)))  # y: e1, z: e2 of roll 0
    alpha = np.arctan2(
        np.sum(c_O * frame[:, :, 2], axis=1), np.sum(c_O * frame[:, :, 1], axis=1)
    )
    return alpha - np.arctan2(c_K[2], c_K[1])


def _aligned_rolls(surface, mid_O, d_O, roll, hand: MultiFingerHand) -> np.ndarray:
    """Per pose, the roll of :data:`PINCH_ROLLS` whose axis best meets the object.

    ``mid_O`` (n, 3): where the pinch's tips' midpoint goes, frame O.  A roll
    scores the least of ``n_+·c`` and ``n_-·(-c)``, the outward normals where
    the line through ``mid_O`` along the closing axis ``±c`` leaves the
    object; the drawn ``roll`` is kept where no roll's line meets it on both
    sides.
    """
    n, m = len(roll), PINCH_ROLLS
    rolls = roll[:, None] + np.arange(m)[None, :] * (np.pi / m)  # (n, m)
    score, n_p, n_m = _roll_scores(surface, np.repeat(mid_O, m, axis=0),
                                   np.repeat(d_O, m, axis=0), rolls.reshape(-1),
                                   hand)  # fmt: skip
    score = score.reshape(n, m)
    best = np.argmax(score, axis=1)  # the first of equal ones: the drawn roll
    top = score[np.arange(n), best]
    rows = np.arange(n) * m + best
    chosen = np.where(np.isfinite(top), rolls[np.arange(n), best], roll)
    # Refined: the roll that lays the axis along n_+ - n_- across d (exact
    # for flat faces; 22.5 deg apart, the coarse rolls left a pad's corner
    # touching), kept where it scores no worse.
    target = n_p[rows] - n_m[rows]
    target -= np.sum(target * d_O, axis=1, keepdims=True) * d_O
    refined = _roll_along(d_O, target, hand.closing_axis)
    better, _, _ = _roll_scores(surface, mid_O, d_O, refined, hand)
    return np.where(np.isfinite(top) & (better >= top), refined, chosen)


def _roll_scores(surface, mid_O, d_O, rolls, hand: MultiFingerHand):
    """``(score, n_+, n_-)`` of each roll: see :func:`_aligned_rolls`.

    -inf where a line misses the object or the object is as wide as the
    pinch's tips are apart along it.
    """
    c = axis_frames(d_O, rolls) @ hand.closing_axis  # frame O
    _, out_p, n_p = surface.chord(mid_O, c)
    _, out_m, n_m = surface.chord(mid_O, -c)
    score = np.minimum(np.sum(n_p * c, axis=1), -np.sum(n_m * c, axis=1))
    with np.errstate(invalid="ignore"):  # NaN: a miss
        fits = out_p + out_m < hand.pinch_width
    return np.where(fits, score, -np.inf), n_p, n_m


def sample_approaches(surface, hand: MultiFingerHand, X_WO, n, rng, tilt):
    """Stage 1: ``n`` hand poses and pre-shapes over the object's surface.

    Parameters
    ----------
    surface : ObjectSurface
        ``sample(n, rng) -> (p_O, nout_O, piece)`` in frame O.
    hand : MultiFingerHand
    X_WO : RigidTransform
    n : int
    rng : numpy.random.Generator
    tilt : float
        Largest tilt (radians) of the approach from the inward normal.

    Returns
    -------
    dict of arrays
        ``R_WH`` (n, 3, 3), ``p_WH`` (n, 3), ``q`` (n, n_h) pre-shapes,
        ``standoff`` (n,) metres.
    """
    p_O, nout_O, _ = surface.sample(n, rng)
    # tilt: rotate -n about a random axis across it by an angle in [0, tilt]
    across = axis_frames(-nout_O, rng.uniform(0.0, 2 * np.pi, n))[:, :, 1]
    angle = rng.uniform(0.0, tilt, n)
    d_O = np.cos(angle)[:, None] * -nout_O + np.sin(angle)[:, None] * np.cross(
        across, -nout_O
    )
    roll = rng.uniform(0.0, 2 * np.pi, n)
    s = rng.uniform(hand.standoff[0], hand.standoff[1], n)
    amounts = rng.uniform(hand.synergy_range[0], hand.synergy_range[1], n)
    if hand.closing_axis is not None and n:
        d_O, roll = _pinch_poses(surface, p_O, -nout_O, across, angle, s, roll, hand)
    R_OK = axis_frames(d_O, roll)  # x along d
    # K's origin: the palm's front face (palm_depth ahead of it) s before p
    p_OK = p_O - (s + hand.palm_depth)[:, None] * d_O
    R_WO = X_WO.rotation().matrix()
    R_WK = R_WO @ R_OK
    p_WK = p_OK @ R_WO.T + X_WO.translation()
    X_KH = hand.X_HK.inverse()
    return {
        "R_WH": R_WK @ X_KH.rotation().matrix(),
        "p_WH": p_WK + R_WK @ X_KH.translation(),
        "q": hand.preshapes(amounts),
        "standoff": s,
    }
