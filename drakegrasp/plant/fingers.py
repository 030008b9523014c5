"""A hand's fingers: which joints close it and which bodies each one moves.

**Closing joints.**  The hand's one-dof joints (revolute, prismatic) that have
an actuator (all its one-dof joints when none has one), plus both joints of
every coupling.

**Fingers.**  A *finger* is the chain that one closing joint drives.  Its
**root joint** is a closing joint whose parent body no other closing joint
moves; the finger holds every closing joint and every hand body that the root
moves (``plant.GetBodiesKinematicallyAffectedBy``).  Its **tip** is the set of
its bodies (with collision geometry) that the most of its joints move.  The
WSG-50 has two fingers (one prismatic joint each), the Allegro hand four (four
revolute joints each).  Joints coupled across fingers make those fingers one,
as the rigid mimic linkage of a real gripper does.  Bodies that no closing
joint moves (the palm) stay where they are.

**Couplings.**  Drake parses a URDF ``<mimic>`` (or SDFormat
``<drake:mimic>``) into a coupler constraint ``q_0 = ρ q_1 + Δq``
(``MultibodyPlant.AddCouplerConstraint(joint_0, joint_1, ρ, Δq)``); a
*coupling* is the same four numbers ``(joint_0, joint_1, ρ, Δq)``:
``joint_0`` follows ``joint_1``.  They are read where the models enter the
plant (:mod:`drakegrasp.plant.couplings`).

**Kept per plant.**  The structure depends on the plant's kinematic tree and
actuators (fixed after ``Finalize``), the hand's bodies, the object, the
couplings and the collision filters (the scene graph's proximity version).
:func:`hand_structure` keeps what it found per finalized plant and reads it
again while the proximity version is the same; the joint limits are read
afresh at every call.
"""

from __future__ import annotations

import copy
import numbers
import weakref
from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from pydrake.geometry import Role
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex, Joint, JointIndex, RigidBody

from drakegrasp.core.validation import describe, items_of, plain_str
from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.plant.validation import scoped_name

__all__ = [
    "Coupling",
    "Finger",
    "HandStructure",
    "MAX_STEP",
    "effort_unit",
    "find_joint",
    "finger_chains",
    "free_part",
    "hand_structure",
    "hidden_drives",
    "is_hidden_drive",
    "limit_towards",
    "most_fingers",
    "passive_joints",
    "tip_bodies",
]

MAX_STEP = {"revolute": 0.2, "prismatic": 0.01}
"""Largest change of any joint of a finger in one closing step: radians, metres."""


def limit_towards(joint, direction: float) -> float:
    """A one-dof joint's position limit on the side ``direction`` moves it to.

    Parameters
    ----------
    joint : Joint
        A one-dof joint (revolute or prismatic).
    direction : float
        A velocity, torque or aim along the joint; only its sign counts.

    Returns
    -------
    float
        The upper limit for ``direction > 0``, else the lower one (rad or m;
        ``±inf`` where the model gives none).
    """
    if direction > 0:
        return float(joint.position_upper_limits()[0])
    return float(joint.position_lower_limits()[0])


def effort_unit(joint, k: int = 0) -> str:
    """Unit of the generalized force along ``joint``'s velocity ``k``.

    Drake names each velocity by its kind (``velocity_suffix``): an angular
    one (``w``, ``wx``...: a revolute joint, a floating base's rotation)
    carries a torque in N·m, a linear one (``v``, ``vx``...: a prismatic
    joint, a floating base's translation) a force in N; "" for another.
    """
    return {"w": "N·m", "v": "N"}.get(joint.velocity_suffix(k)[:1], "")


_KEPT: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
"""Finalized plant -> {(object, bodies, couplings): (proximity version, recipe)}.

A recipe holds indices, names, geometry id values and numbers only, never a
body, a joint or a ``GeometryId`` (each would keep the plant alive);
:func:`_rebuild` turns it back into a :class:`HandStructure`."""


@dataclass(frozen=True, eq=False)
class Finger:
    """One finger of a hand (see the module docstring).

    Attributes
    ----------
    name : str
        ``model::root_joint`` (roots joined by ``+`` for coupled fingers).
    joints : tuple of int
        Positions of its joints in ``HandStructure.joints``.
    bodies : tuple of RigidBody
    pairs : tuple of (GeometryId, GeometryId, RigidBody)
        (object geometry, finger geometry, finger body) for every pair that
        the scene graph does not filter.
    tip_pairs : tuple
        The pairs of the finger's tip.
    max_step : float
        :data:`MAX_STEP` of its joints (the smallest).
    """

    name: str
    joints: tuple[int, ...]
    bodies: tuple[RigidBody, ...]
    pairs: tuple
    tip_pairs: tuple
    max_step: float


class Coupling:
    """Followers move with their leaders, ``q_f = ρ q_l + Δq`` (closing-joint order)."""

    def __init__(self, follows: dict[int, tuple[int, float, float]]):
        self.follows = follows  # follower position -> (leader position, ρ, Δq)

    def apply(self, q: np.ndarray) -> np.ndarray:
        """Positions with every follower set from its leader."""
        q = q.copy()
        for f, (lead, rho, off) in self.follows.items():
            q[f] = rho * q[lead] + off
        return q

    def tangent(self, d: np.ndarray) -> np.ndarray:
        """A direction over the free joints extended to the followers."""
        d = d.copy()
        for f, (lead, rho, _) in self.follows.items():
            d[f] = rho * d[lead]
        return d

    def project(self, d: np.ndarray) -> np.ndarray:
        """A direction with the followers' entries dropped (they are derived)."""
        d = d.copy()
        d[list(self.follows)] = 0.0
        return d

    def pull_back(self, g: np.ndarray) -> np.ndarray:
        """A gradient over the free joints (a follower's part goes to its leader)."""
        g = g.copy()
        for f, (lead, rho, _) in self.follows.items():
            g[lead] += rho * g[f]
            g[f] = 0.0
        return g

    def leader_steps(self, cap: np.ndarray, moves: np.ndarray) -> np.ndarray:
        """Each joint's largest step that moves no joint past its own ``cap``.

        Parameters
        ----------
        cap : (n_h,) float
            Largest change of each closing joint per step (its own unit).
        moves : (n_h,) bool
            False for a hidden drive (:func:`is_hidden_drive`): its motion
            moves nothing, so only its followers bound its step.

        Returns
        -------
        (n_h,) float
            A leader's step within ``cap_f / |ρ|`` of each follower ``f`` (and
            its own cap where it ``moves``); a follower's own cap.
        """
        step = np.where(moves, cap, np.inf)
        for f, (lead, rho, _) in self.follows.items():
            step[f] = cap[f]
            if rho != 0.0:
                step[lead] = min(step[lead], cap[f] / abs(rho))
        return np.where(np.isfinite(step), step, cap)

    def leader_limits(self, lower: np.ndarray, upper: np.ndarray):
        """Limits with each leader's range cut to keep its follower in range."""
        lower, upper = lower.copy(), upper.copy()
        for f, (lead, rho, off) in self.follows.items():
            a, b = sorted(((lower[f] - off) / rho, (upper[f] - off) / rho))
            lower[lead], upper[lead] = max(lower[lead], a), min(upper[lead], b)
        return lower, upper


@dataclass(frozen=True, eq=False)
class HandStructure:
    """The closing joints of a hand, their limits, its fingers and couplings.

    Attributes
    ----------
    joints : tuple of Joint
        Closing joints, in the order of the plant's positions.
    names : tuple of str
        Their scoped names ``model::joint``.
    position_indices, velocity_indices : (n_h,) int
        Their indices in the plant's ``q`` and ``v``.
    lower, upper : (n_h,) float
        Position limits (a leader's cut to keep its follower in range).
    fingers : tuple of Finger
    coupling : Coupling
    """

    joints: tuple[Joint, ...]
    names: tuple[str, ...]
    position_indices: np.ndarray
    velocity_indices: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    fingers: tuple[Finger, ...]
    coupling: Coupling


def check_hand_structure(hand) -> HandStructure:
    """``hand`` itself, once it is a :class:`HandStructure` (InvalidOptionError)."""
    if not isinstance(hand, HandStructure):
        raise InvalidOptionError(
            "hand must be a HandStructure (from hand_structure), got "
            f"{type(hand).__name__}"
        )
    return hand


def joint_name(plant: MultibodyPlant, joint: Joint) -> str:
    """``model::joint`` of a joint."""
    return f"{plant.GetModelInstanceName(joint.model_instance())}::{joint.name()}"


def find_joint(plant: MultibodyPlant, spec) -> Joint:
    """The joint ``spec`` names: a Joint of ``plant``, or ``"model::joint"``."""
    if isinstance(spec, Joint) and spec.GetParentPlant() is plant:
        return spec
    text = plain_str(spec)  # compared in Python: a subclass's methods may lie
    if type(text) is str:
        model, _, name = text.rpartition("::")
        for i in range(plant.num_joints()):
            j = plant.get_joint(JointIndex(i))
            if j.name() == name and (
                not model or plant.GetModelInstanceName(j.model_instance()) == model
            ):
                return j
    raise InvalidOptionError(
        f"coupling joint {describe(spec)} is not a joint of the plant (give a Joint or "
        "a 'model::joint' name)"
    )


def chain_root(
    follows: Mapping[Hashable, tuple[Hashable, float, float]],
    joint: Hashable,
    name: Callable[[Hashable], str] = str,
) -> tuple[Hashable, float, float, list]:
    """Where ``joint``'s chain of couplings ends: ``(root, ρ, Δ, path)``.

    ``q_joint = ρ q_root + Δ``, composed link by link from ``joint`` up:
    ``(ρ, Δ) ← (ρ ρ_l, ρ Δ_l + Δ)`` for each link ``q_f = ρ_l q_l + Δ_l``.  A
    joint that follows none is its own root (``ρ = 1``, ``Δ = 0``).

    Parameters
    ----------
    follows : mapping
        Follower -> ``(leader, ρ_l, Δ_l)``, one link each (joints by any
        hashable key: index, velocity index, scoped name).
    joint : hashable
        A key of ``follows`` or any other joint.
    name : callable, optional
        A key's name in the error message.

    Returns
    -------
    root : hashable
        The chain's last leader, which follows none.
    rho : float
        The product of the gear ratios along the chain.
    offset : float
        Position offset (m or rad, the follower's unit).
    path : list
        ``joint``, then each leader up to ``root``.

    Raises
    ------
    InvalidOptionError
        For a chain that closes a loop, named.
    """
    rho, offset, path = 1.0, 0.0, [joint]
    while joint in follows:
        joint, rho_l, offset_l = follows[joint]
        if joint in path:
            loop = " -> ".join(name(k) for k in (*path[path.index(joint) :], joint))
            raise InvalidOptionError(
                f"the couplings close a loop ({loop}, each following the next): "
                "a chain of couplings must end at a joint that follows none"
            )
        path.append(joint)
        rho, offset = rho * rho_l, rho * offset_l + offset
    return joint, rho, offset, path


def coupling_entries(couplings) -> tuple:
    """``couplings`` as a tuple of entries, refusing what is not a sequence."""
    if isinstance(couplings, str | bytes | dict) or not isinstance(
        couplings, Sequence | np.ndarray
    ):
        raise InvalidOptionError(
            "couplings must be a sequence of (joint_0, joint_1, gear_ratio, offset) "
            f"entries (() for none), got {describe(couplings)}"
        )
    return tuple(
        items_of(
            "couplings",
            couplings,
            "a sequence of (joint_0, joint_1, gear_ratio, offset) entries",
        )
    )


def coupling_entry(plant: MultibodyPlant, entry) -> tuple[Joint, Joint, float, float]:
    """One coupling ``(joint_0, joint_1, gear_ratio, offset)``, checked.

    ``q_0 = gear_ratio * q_1 + offset`` joins two different joints; the gear
    ratio is a finite non-zero real number, the offset a finite real number.

    Raises
    ------
    InvalidOptionError
        For an entry that is not a 4-sequence, an unknown joint, a joint
        coupled to itself, or a gear ratio or offset that is not a finite real
        number (``None``, complex, strings, bools included).
    """
    if (
        isinstance(entry, str | bytes)
        or not isinstance(entry, Sequence)
        or len(entry) != 4
    ):
        raise InvalidOptionError(
            "each coupling is (joint_0, joint_1, gear_ratio, offset) with "
            f"q_0 = gear_ratio * q_1 + offset, got {describe(entry)}"
        )
    j0, j1 = find_joint(plant, entry[0]), find_joint(plant, entry[1])
    if j0.index() == j1.index():
        raise InvalidOptionError(
            f"coupling {describe(entry)} couples joint {joint_name(plant, j0)} to "
            "itself; "
            "a coupling joins two different joints"
        )
    values = []
    for value in entry[2:]:
        if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
            value = np.nan
        values.append(float(value))
    rho, off = values
    if rho == 0 or not np.isfinite(rho) or not np.isfinite(off):
        raise InvalidOptionError(
            f"coupling of {joint_name(plant, j0)} to {joint_name(plant, j1)}: "
            "gear_ratio must be a finite non-zero real number and offset a finite "
            f"real number, got {describe(entry[2])}, {describe(entry[3])}"
        )
    return j0, j1, rho, off


def _one_dof_and_actuated(plant, bodies) -> tuple[list[Joint], set[int]]:
    """The one-dof joints that move one of ``bodies``, and the plant's actuated joints.

    Returns the joints in the plant's joint order, and the set of joint
    indices that carry an actuator (anywhere in the plant).
    """
    wanted = {int(b.index()) for b in bodies}
    joints = [plant.get_joint(JointIndex(i)) for i in range(plant.num_joints())]
    one_dof = [
        j
        for j in joints
        if j.num_positions() == 1 and int(j.child_body().index()) in wanted
    ]
    actuated = {
        int(plant.get_joint_actuator(a).joint().index())
        for a in plant.GetJointActuatorIndices()
    }
    return one_dof, actuated


def _closing_joints(plant, bodies, couplings):
    """The closing joints and the couplings as joint index -> (leader, ρ, Δq)."""
    one_dof, actuated = _one_dof_and_actuated(plant, bodies)
    of_hand = {int(j.index()) for j in one_dof}
    joints = [j for j in one_dof if int(j.index()) in actuated] or one_dof
    follows = {}
    for entry in coupling_entries(couplings):
        j0, j1, rho, off = coupling_entry(plant, entry)
        follows[int(j0.index())] = (int(j1.index()), rho, off)
        for j in (j0, j1):
            if int(j.index()) not in of_hand:
                raise InvalidOptionError(
                    f"coupled joint {joint_name(plant, j)} is not a one-dof joint "
                    "of the hand"
                )
            if all(j.index() != k.index() for k in joints):
                joints.append(j)
    joints.sort(key=lambda j: j.position_start())
    return joints, follows


def _group(joints, follows, moved) -> list[list[Joint]]:
    """Union-find: a joint joins the finger of the joint that moves its parent."""
    parent = {int(j.index()): int(j.index()) for j in joints}

    def find(k):
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    for j in joints:
        for k in joints:
            if k is not j and int(j.parent_body().index()) in moved[int(k.index())]:
                parent[find(int(j.index()))] = find(int(k.index()))
    for follower, (leader, _, _) in follows.items():
        parent[find(follower)] = find(leader)
    groups: dict[int, list[Joint]] = {}
    for j in joints:
        groups.setdefault(find(int(j.index())), []).append(j)
    return list(groups.values())


def _roots(members, moved) -> list:
    """The joints of ``members`` whose parent body no other member moves."""
    return [
        j
        for j in members
        if not any(
            int(j.parent_body().index()) in moved[int(k.index())]
            for k in members
            if k is not j
        )
    ]


def _finger(plant, members, moved, bodies, position, object_geometries, inspector):
    roots = _roots(members, moved)
    ids = set().union(*(moved[int(j.index())] for j in members))
    finger_bodies = tuple(b for b in bodies if int(b.index()) in ids)
    pairs = tuple(
        (go, gf, b)
        for b in finger_bodies
        for gf in plant.GetCollisionGeometriesForBody(b)
        for go in object_geometries
        if not inspector.CollisionFiltered(go, gf)
    )
    paired = list({int(b.index()): b for _, _, b in pairs}.values())
    tip = {
        int(b.index())
        for b in _deepest(paired, [moved[int(j.index())] for j in members])
    }
    return Finger(
        name=" + ".join(joint_name(plant, j) for j in roots),
        joints=tuple(sorted(position[int(j.index())] for j in members)),
        bodies=finger_bodies,
        pairs=pairs,
        tip_pairs=tuple(p for p in pairs if int(p[2].index()) in tip),
        max_step=min(
            MAX_STEP["revolute" if j.type_name() == "revolute" else "prismatic"]
            for j in members
        ),
    )


def passive_joints(
    plant: MultibodyPlant, bodies: Sequence[RigidBody], structure: HandStructure
) -> tuple[Joint, ...]:
    """The hand's one-dof joints that no motor moves.

    A joint is driven when it has an actuator, or follows (through its
    couplings, a ``<mimic>``) a driven joint; the others turn freely in Drake
    between their limits.  A hand none of whose joints has an actuator (a
    model that describes no motors) has none.

    Parameters
    ----------
    plant : MultibodyPlant
    bodies : sequence of RigidBody
        The hand's movable bodies, as for :func:`hand_structure`.
    structure : HandStructure
        What :func:`hand_structure` learnt of them (its couplings).

    Returns
    -------
    tuple of Joint
        In the order of the plant's positions.
    """
    joints, actuated = _one_dof_and_actuated(plant, bodies)
    if not any(int(j.index()) in actuated for j in joints):
        return ()
    leader = {
        int(structure.joints[f].index()): int(structure.joints[lead].index())
        for f, (lead, _, _) in structure.coupling.follows.items()
    }

    def driven(i: int) -> bool:
        seen = set()
        while i not in actuated:
            if i not in leader or i in seen:
                return False
            seen.add(i)
            i = leader[i]
        return True

    passive = [j for j in joints if not driven(int(j.index()))]
    return tuple(sorted(passive, key=lambda j: j.position_start()))


def hand_structure(
    plant: MultibodyPlant,
    object_body: RigidBody,
    bodies: Sequence[RigidBody],
    couplings: Sequence[tuple] = (),
    *,
    inspector,
) -> HandStructure:
    """Closing joints, fingers and couplings of a hand (see the module docstring).

    Parameters
    ----------
    plant : MultibodyPlant
    object_body : RigidBody
        The object the fingers close on (its geometries make the pairs).
    bodies : sequence of RigidBody
        The hand's movable bodies (:func:`~drakegrasp.plant.validation.hand_bodies`).
    couplings : sequence of (joint_0, joint_1, gear_ratio, offset), optional
    inspector : SceneGraphInspector
        For the collision filters (``query_object.inspector()``).

    Returns
    -------
    HandStructure

    Raises
    ------
    ModelError
        If the hand has no one-dof joint.
    InvalidOptionError
        For a malformed coupling.
    """
    kept = _KEPT.get(plant) if plant.is_finalized() else None
    key = None
    if plant.is_finalized():
        key = (
            int(object_body.index()),
            tuple(int(b.index()) for b in bodies),
            _couplings_key(plant, couplings),
        )
        version = inspector.geometry_version()
        if kept is not None and key in kept:
            old_version, recipe = kept[key]
            if old_version.IsSameAs(version, Role.kProximity):
                return _rebuild(plant, key[0], recipe)
    structure = _build(plant, object_body, bodies, couplings, inspector)
    if key is not None:
        # A copy: the inspector's version is a live reference that changes
        # with the context it came from.
        _KEPT.setdefault(plant, {})[key] = (copy.copy(version), _recipe(structure))
    return structure


def tip_bodies(
    plant: MultibodyPlant, structure: HandStructure, finger: Finger
) -> list[RigidBody]:
    """A finger's tip from the plant alone: no object to pair its geometry with.

    Parameters
    ----------
    plant : MultibodyPlant
        The finalized plant ``structure`` was found in.
    structure : HandStructure
    finger : Finger
        One of ``structure.fingers``.

    Returns
    -------
    list of RigidBody
        The finger's bodies with collision geometry that the most of its joints
        move (the module docstring's tip), in ``finger.bodies`` order.
        ``finger.tip_pairs`` holds the same bodies' pairs with an object's
        geometry; this is the tip where there is none (a point cloud).
    """
    joints = [structure.joints[k].index() for k in finger.joints]
    moved = [set(map(int, plant.GetBodiesKinematicallyAffectedBy([j]))) for j in joints]
    shaped = [b for b in finger.bodies if plant.GetCollisionGeometriesForBody(b)]
    return _deepest(shaped, moved)


def _deepest(bodies: list, moved: list[set[int]]) -> list:
    """A finger's tip: the ``bodies`` that the most of the joints move, in order.

    ``moved`` holds, per joint, the indices of the bodies that joint moves.
    """
    depth = [sum(int(b.index()) in m for m in moved) for b in bodies]
    top = max(depth, default=0)
    return [b for b, d in zip(bodies, depth, strict=True) if d == top]


def is_hidden_drive(plant: MultibodyPlant, joint: Joint) -> bool:
    """True when nothing ``joint`` moves can touch: no collision geometry.

    A hidden drive: a slide or a linkage (the bodies below ``joint``, welded
    or jointed) with no collision geometry, that the fingers follow through
    their ``<mimic>`` (its motor closes them).  The same test leaves such a
    chain out of :func:`finger_chains`.  Read from the model's joints alone,
    so a plant that is not finalized yet (a shake's) answers too.
    """
    return not any(
        plant.GetCollisionGeometriesForBody(plant.get_body(b))
        for b in _below(plant, joint.child_body().index())
    )


def hidden_drives(plant: MultibodyPlant, couplings) -> set[str]:
    """The leaders of ``couplings`` that are hidden drives (:func:`is_hidden_drive`).

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized or not (a shake's plant is read before it is).
    couplings : sequence of (follower, leader, gear_ratio, offset)
        Scoped joint names (:func:`~drakegrasp.plant.couplings.plant_couplings`).

    Returns
    -------
    set of str
        Scoped names of the leaders that touch nothing: their motors press
        only through the joints that follow them.
    """
    leaders = {leader for _, leader, _, _ in couplings}
    return {n for n in leaders if is_hidden_drive(plant, find_joint(plant, n))}


def _drives_only(plant, structure: HandStructure, group, moved, position) -> bool:
    """True when a chain is a hidden drive: it touches nothing, others follow it.

    A chain without geometry that follows another (a parallelogram's bare bar)
    stays a chain, as before: only a leader is a drive.
    """
    own = {position[int(j.index())] for j in group}
    leads = {
        lead
        for follower, (lead, _, _) in structure.coupling.follows.items()
        if follower not in own
    }
    return bool(own & leads) and all(
        is_hidden_drive(plant, j) for j in _roots(group, moved)
    )


def _below(plant: MultibodyPlant, body) -> set:
    """``body`` and every body a joint hangs below it (welds too), by index."""
    children: dict = {}
    for k in plant.GetJointIndices():
        j = plant.get_joint(k)
        children.setdefault(j.parent_body().index(), []).append(j.child_body().index())
    found, todo = set(), [body]
    while todo:
        b = todo.pop()
        if b not in found:
            found.add(b)
            todo.extend(children.get(b, ()))
    return found


def finger_chains(plant: MultibodyPlant, structure: HandStructure) -> tuple:
    """The hand's fingers as kinematic chains: coupled fingers split apart.

    A ``<mimic>`` across fingers makes them one :class:`Finger` of ``structure``
    (they close as one: a Robotiq-style gripper's two fingers on one motor); a
    grasp is still held by each chain's own contacts.  Each chain is a
    :class:`Finger` over its own joints (positions in ``structure.joints``),
    bodies, pairs and tip; a finger of one chain is returned as it is.  A
    chain with no collision geometry that other chains follow through their
    ``<mimic>`` (a drive slide or a linkage's hidden link) touches nothing and
    is no finger: it is left out (a bare chain that follows, such as a
    parallelogram's bar, is kept).
    """
    position = {int(j.index()): k for k, j in enumerate(structure.joints)}
    out = []
    for finger in structure.fingers:
        members = [structure.joints[k] for k in finger.joints]
        hand = {int(b.index()) for b in finger.bodies}
        moved = {i: ids & hand for i, ids in _affected(plant, members).items()}
        groups = _group(members, {}, moved)
        if len(groups) == 1:
            out.append(finger)
            continue
        for group in groups:
            ids = set().union(*(moved[int(j.index())] for j in group))
            if _drives_only(plant, structure, group, moved, position):
                continue  # it touches nothing and others follow it: no finger
            pairs = tuple(p for p in finger.pairs if int(p[2].index()) in ids)
            paired = list({int(b.index()): b for _, _, b in pairs}.values())
            tip = {
                int(b.index())
                for b in _deepest(paired, [moved[int(j.index())] for j in group])
            }
            out.append(
                Finger(
                    name=" + ".join(joint_name(plant, j) for j in _roots(group, moved)),
                    joints=tuple(sorted(position[int(j.index())] for j in group)),
                    bodies=tuple(b for b in finger.bodies if int(b.index()) in ids),
                    pairs=pairs,
                    tip_pairs=tuple(p for p in pairs if int(p[2].index()) in tip),
                    max_step=finger.max_step,
                )
            )
    return tuple(out)


def free_part(
    plant: MultibodyPlant, structure: HandStructure, finger: Finger, touching
) -> Finger | None:
    """What of a finger can close on once some of its bodies touch.

    A finger whose chains a coupling closes as one (a Barrett-style spread
    joint coupling two fingers, each with its own flexion motor) stops where
    one chain touches.  The joints of its other chains that are coupled to
    none of a touching chain's can go on and close them.  A chain that
    touches stops whole, as a finger of one chain does.

    Parameters
    ----------
    plant : MultibodyPlant
    structure : HandStructure
    finger : Finger
        One of ``structure.fingers``, or a part of one.
    touching : iterable of RigidBody
        The finger's bodies that touch.

    Raises
    ------
    InvalidOptionError
        ``touching`` empty, or holding anything but bodies of ``finger``.

    Returns
    -------
    Finger or None
        A :class:`Finger` over the free joints (positions in
        ``structure.joints``), the finger's bodies they move, and those
        bodies' pairs and tip pairs (none where the structure has no object,
        a point cloud's); None when no joint is free or moves a body.
    """
    touched = _touching_bodies(plant, finger, touching)
    joints = [structure.joints[k] for k in finger.joints]
    by_joint = _affected(plant, joints)
    position = {int(j.index()): k for j, k in zip(joints, finger.joints, strict=True)}
    moved = {k: by_joint[i] for i, k in position.items()}  # by closing position
    # a chain (the joints under one root, couplings aside) stops whole when a
    # body of it touches: a finger of one chain has no free part
    chains = _group(joints, {}, by_joint)
    frozen = set()
    for chain in chains:
        mine = [position[int(j.index())] for j in chain]
        if any(moved[k] & touched for k in mine):
            frozen.update(mine)
    follows = structure.coupling.follows
    grown = True
    while grown:  # a follower moves with its leader: both go, or neither
        grown = False
        for f, (lead, _, _) in follows.items():
            if f in moved and lead in moved and (f in frozen) != (lead in frozen):
                frozen |= {f, lead}
                grown = True
    free = [k for k in finger.joints if k not in frozen]
    if not free:
        return None
    ids = set().union(*(moved[k] for k in free)) & {
        int(b.index()) for b in finger.bodies
    }
    if not ids:
        return None
    pairs = tuple(p for p in finger.pairs if int(p[2].index()) in ids)
    paired = list({int(b.index()): b for _, _, b in pairs}.values())
    tip = {int(b.index()) for b in _deepest(paired, [moved[k] for k in free])}
    roots = _roots([structure.joints[k] for k in free], by_joint)
    return Finger(
        name=" + ".join(joint_name(plant, j) for j in roots),
        joints=tuple(free),
        bodies=tuple(b for b in finger.bodies if int(b.index()) in ids),
        pairs=pairs,
        tip_pairs=tuple(p for p in pairs if int(p[2].index()) in tip),
        max_step=finger.max_step,
    )


def most_fingers(plant: MultibodyPlant, structure: HandStructure) -> int:
    """The most fingers that can touch: each finger, and its free parts.

    A finger of several chains that a coupling closes as one counts once,
    and once more for each free part (:func:`free_part`) that can close on
    after one of its chains touches, in the best order.
    """
    return sum(_most(plant, structure, f) for f in structure.fingers)


def _most(plant, structure: HandStructure, finger: Finger) -> int:
    joints = [structure.joints[k] for k in finger.joints]
    moved = _affected(plant, joints)
    mine = {int(b.index()): b for b in finger.bodies}
    best = 1
    for chain in _group(joints, {}, moved):
        ids = set().union(*(moved[int(j.index())] for j in chain)) & set(mine)
        if not ids:
            continue
        part = free_part(plant, structure, finger, [mine[min(ids)]])
        if part is not None:
            best = max(best, 1 + _most(plant, structure, part))
    return best


def _affected(plant: MultibodyPlant, joints) -> dict[int, set[int]]:
    """Each joint's index to the indices of the bodies it moves."""
    return {
        int(j.index()): {
            int(i) for i in plant.GetBodiesKinematicallyAffectedBy([j.index()])
        }
        for j in joints
    }


def _touching_bodies(plant, finger: Finger, touching) -> set[int]:
    """The indices of ``touching``, bodies of ``finger``, or a clear refusal."""
    mine = {int(b.index()) for b in finger.bodies}
    try:
        bodies = list(touching)
    except TypeError:
        raise InvalidOptionError(
            f"touching must be a list of the finger's bodies, got {describe(touching)}"
        ) from None
    if not bodies:
        raise InvalidOptionError(
            f"touching names no body: what of {finger.name} closes on depends on "
            "which of its bodies touch"
        )
    out = set()
    for b in bodies:
        if not isinstance(b, RigidBody) or int(b.index()) not in mine:
            what = scoped_name(plant, b) if isinstance(b, RigidBody) else repr(b)
            raise InvalidOptionError(
                f"touching holds {what}, which is not a body of {finger.name}"
            )
        out.add(int(b.index()))
    return out


def _couplings_key(plant, couplings) -> tuple:
    """The couplings as ``(joint_0 index, joint_1 index, ρ, Δq)``, checked."""
    out = []
    for entry in coupling_entries(couplings):
        j0, j1, rho, off = coupling_entry(plant, entry)
        out.append((int(j0.index()), int(j1.index()), rho, off))
    return tuple(out)


def _recipe(s: HandStructure) -> tuple:
    """What :func:`_rebuild` needs, holding no body or joint."""
    fingers = tuple(
        (
            f.name,
            f.joints,
            tuple(int(b.index()) for b in f.bodies),
            tuple(
                (go.get_value(), gf.get_value(), int(b.index()))
                for go, gf, b in f.pairs
            ),
            tuple(k for k, p in enumerate(f.pairs) if any(p is t for t in f.tip_pairs)),
            f.max_step,
        )
        for f in s.fingers
    )
    return (
        tuple(int(j.index()) for j in s.joints),
        s.names,
        s.position_indices.copy(),
        s.velocity_indices.copy(),
        dict(s.coupling.follows),
        fingers,
    )


def _rebuild(plant, object_index: int, recipe) -> HandStructure:
    """The :class:`HandStructure` of a recipe, its limits read afresh."""
    joint_ids, names, position, velocity, follows, fingers = recipe
    joints = tuple(plant.get_joint(JointIndex(i)) for i in joint_ids)
    body, geometry = {}, {}

    def get(i):
        if i not in body:
            body[i] = plant.get_body(BodyIndex(i))
            for g in plant.GetCollisionGeometriesForBody(body[i]):
                geometry[g.get_value()] = g
        return body[i]

    get(object_index)
    built = []
    for name, members, body_ids, pairs, tips, max_step in fingers:
        bodies = tuple(get(b) for b in body_ids)  # and their geometries
        pairs = tuple((geometry[go], geometry[gf], get(b)) for go, gf, b in pairs)
        built.append(
            Finger(
                name=name,
                joints=members,
                bodies=bodies,
                pairs=pairs,
                tip_pairs=tuple(pairs[k] for k in tips),
                max_step=max_step,
            )
        )
    coupling = Coupling(dict(follows))
    return HandStructure(
        joints=joints,
        names=names,
        position_indices=position.copy(),
        velocity_indices=velocity.copy(),
        **_limits(joints, coupling),
        fingers=tuple(built),
        coupling=coupling,
    )


def _limits(joints, coupling: Coupling) -> dict:
    lower = np.array([j.position_lower_limits()[0] for j in joints])
    upper = np.array([j.position_upper_limits()[0] for j in joints])
    lower, upper = coupling.leader_limits(lower, upper)
    return {"lower": lower, "upper": upper}


def _build(plant, object_body, bodies, couplings, inspector) -> HandStructure:
    """:func:`hand_structure` from the plant (not kept)."""
    joints, follows = _closing_joints(plant, bodies, couplings)
    if not joints:
        raise ModelError(
            "the hand has no one-dof joint to close: "
            f"{[scoped_name(plant, b) for b in bodies]}"
        )
    hand = {int(b.index()) for b in bodies}
    moved = {i: ids & hand for i, ids in _affected(plant, joints).items()}
    position = {int(j.index()): k for k, j in enumerate(joints)}
    object_geometries = plant.GetCollisionGeometriesForBody(object_body)
    fingers = tuple(
        _finger(plant, members, moved, bodies, position, object_geometries, inspector)
        for members in _group(joints, follows, moved)
    )
    mapped = {}
    for follower, (leader, rho, off) in follows.items():
        f, lead = position[follower], position[leader]
        if lead in mapped or f in {v[0] for v in mapped.values()}:
            names = [joint_name(plant, j) for j in joints]
            both = names[lead] if lead in mapped else names[f]
            raise InvalidOptionError(
                f"joint {both} may not both lead and follow a coupling; the planner "
                "takes one level of couplings (each joint following a joint that "
                "follows none)"
            )
        mapped[f] = (lead, rho, off)
    coupling = Coupling(mapped)
    limits = _limits(joints, coupling)
    empty = np.flatnonzero(~(limits["lower"] <= limits["upper"]))
    if len(empty):
        k = int(empty[0])
        followers = [
            joint_name(plant, joints[f])
            for f, (lead, _, _) in mapped.items()
            if lead == k
        ]
        raise ModelError(
            f"no position of {joint_name(plant, joints[k])} keeps it and its "
            f"followers {followers} within their limits (the couplings leave "
            f"[{limits['lower'][k]:g}, {limits['upper'][k]:g}]): the hand has "
            "no configuration; widen the limits or mend the <mimic>"
        )
    return HandStructure(
        joints=tuple(joints),
        names=tuple(joint_name(plant, j) for j in joints),
        position_indices=np.array([j.position_start() for j in joints]),
        velocity_indices=np.array([j.velocity_start() for j in joints]),
        **limits,
        fingers=fingers,
        coupling=coupling,
    )
