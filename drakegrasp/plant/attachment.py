"""How a body is held in a plant: the joints from it up to the world.

Every body but the world has one inboard joint, from a parent body (Drake
adds a free joint for a body left floating when the plant is finalized).  The
chain of inboard joints from a body up to the world says how it can move:

* **free**: a joint of the chain has six velocities (a floating base's
  quaternion or roll-pitch-yaw joint): the body moves freely in space with
  the body that joint carries (:func:`free_carrier`), as an object a hand
  picks up does;
* **held**: no joint of the chain is free: the body is welded to the world
  (directly, or through a table it is welded to), or joined to it by joints
  (a drawer's slide, a door's hinge, an arm); :func:`how_held` says how, in
  words for a message.

Two bodies are **joined** (:func:`joined`) when their chains meet below the
world: each moves with the other through joints of their own (a palm and its
fingers), not only through the world.
"""

from __future__ import annotations

from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import Joint, RigidBody

__all__ = [
    "FREE_VELOCITIES",
    "chain_to_world",
    "free_carrier",
    "how_held",
    "inboard_joint",
    "joined",
]

FREE_VELOCITIES = 6
"""A joint with this many velocities lets its child move freely in space."""


def inboard_joint(plant: MultibodyPlant, body: RigidBody) -> Joint | None:
    """The joint whose child is ``body``; None for the world body.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized (Drake has then given every floating body its free joint).
    body : RigidBody
        A body of ``plant``.
    """
    for index in plant.GetJointIndices():
        joint = plant.get_joint(index)
        if joint.child_body().index() == body.index():
            return joint
    return None


def chain_to_world(plant: MultibodyPlant, body: RigidBody) -> list[Joint]:
    """The inboard joints from ``body`` up to the world, ``body``'s own first.

    Empty for the world body.
    """
    chain = []
    joint = inboard_joint(plant, body)
    while joint is not None:
        chain.append(joint)
        joint = inboard_joint(plant, joint.parent_body())
    return chain


def free_carrier(plant: MultibodyPlant, body: RigidBody) -> RigidBody | None:
    """The body whose free joint carries ``body``; None when ``body`` is held.

    ``body`` itself when it is a free body, an ancestor when it is welded or
    jointed to a free body (a finger to a floating palm), None when no joint
    from it up to the world is free (see the module docstring).
    """
    for joint in chain_to_world(plant, body):
        if joint.num_velocities() == FREE_VELOCITIES:
            return joint.child_body()
    return None


def _ancestors(plant: MultibodyPlant, body: RigidBody) -> list[int]:
    """Indices of ``body`` and the bodies above it, the world left out."""
    return [int(body.index())] + [
        int(j.parent_body().index())
        for j in chain_to_world(plant, body)
        if int(j.parent_body().index()) != 0
    ]


def joined(plant: MultibodyPlant, a: RigidBody, b: RigidBody) -> bool:
    """Whether ``a`` and ``b`` move together through joints below the world.

    True when one hangs from the other, or both from a third body (a palm and
    its fingers, welded to the world or free); False when they meet only at
    the world (two bodies welded to the world, a free object and a hand).
    """
    return bool(set(_ancestors(plant, a)) & set(_ancestors(plant, b)))


def _scoped(plant: MultibodyPlant, body: RigidBody) -> str:
    # validation.scoped_name's twin: validation reads this module, not the reverse
    return f"{plant.GetModelInstanceName(body.model_instance())}::{body.name()}"


def _joint_words(joint: Joint) -> str:
    return f"{joint.name()} ({joint.type_name()})"


def how_held(plant: MultibodyPlant, body: RigidBody) -> str:
    """What holds a body to the world, in words, e.g. ``"welded to the world"``.

    For a held body (:func:`free_carrier` is None): ``"welded to the world"``,
    ``"welded to table::top, which is welded to the world"``, or ``"joined to
    the world by joints hinge (revolute)"`` (with ``"through B"`` for the
    bodies between); for a free one, ``"carried by the free body B"``.
    """
    carrier = free_carrier(plant, body)
    if carrier is not None:
        if carrier.index() == body.index():
            return "a free body"
        return f"carried by the free body {_scoped(plant, carrier)}"
    chain = chain_to_world(plant, body)
    if not chain:
        return "the world body"
    parent = chain[0].parent_body()
    if all(j.type_name() == "weld" for j in chain):
        if int(parent.index()) == 0:
            return "welded to the world"
        tail = "which is welded to the world"
        return f"welded to {_scoped(plant, parent)}, {tail}"
    moving = [j for j in chain if j.type_name() != "weld"]
    between = [
        _scoped(plant, j.parent_body())
        for j in chain
        if int(j.parent_body().index()) != 0
    ]
    through = f" through {', '.join(between)}" if between else ""
    return (
        f"joined to the world{through} by joint"
        f"{'s' if len(moving) > 1 else ''} "
        f"{', '.join(_joint_words(j) for j in moving)}"
    )
