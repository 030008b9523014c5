"""A test rig of free bodies: one object and free fingertips of given shapes.

Shared by the contact, normal, curvature and second-order tests of the plant
layer: a continuous plant (no time step) whose object and fingers are free
bodies with one collision geometry each, so a test places them wherever its
answer says and asks Drake and drakegrasp about the same configuration.
"""

from __future__ import annotations

from collections.abc import Sequence

from pydrake.geometry import ProximityProperties
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.multibody.tree import SpatialInertia
from pydrake.systems.framework import DiagramBuilder

X_WO = RigidTransform(RollPitchYaw(0.3, -0.2, 0.5), [0.1, 0.2, 0.3])
"""The object's pose in the world in the rigs: a generic one (no axis aligned)."""


class FreeRig:
    """An object and free fingers (one model instance ``hand``), finalised.

    Parameters
    ----------
    object_shape : pydrake.geometry.Shape
        The object's collision geometry, at its body origin.
    finger_shapes : sequence of pydrake.geometry.Shape
        One free finger body ``{finger_name}{k}`` (geometry ``tip{k}``) each.
    object_name : str, optional
        Name of the object's model instance, body and geometry.
    finger_name : str, optional
        Prefix of the finger bodies' names.

    Attributes
    ----------
    plant, diagram, root, ctx
        The plant, its diagram, the diagram's default context and the plant's
        context in it.
    object : RigidBody
        The object's body.
    fingers : list of RigidBody
        The finger bodies, in the order of ``finger_shapes``.
    """

    def __init__(
        self,
        object_shape,
        finger_shapes: Sequence,
        *,
        object_name: str = "object",
        finger_name: str = "finger",
    ):
        builder = DiagramBuilder()
        plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
        inertia = SpatialInertia.SolidSphereWithMass(0.1, 0.01)
        self.object = plant.AddRigidBody(
            object_name, plant.AddModelInstance(object_name), inertia
        )
        plant.RegisterCollisionGeometry(
            self.object, RigidTransform(), object_shape, object_name,
            ProximityProperties(),
        )  # fmt: skip
        hand = plant.AddModelInstance("hand")
        self.fingers = []
        for k, shape in enumerate(finger_shapes):
            body = plant.AddRigidBody(f"{finger_name}{k}", hand, inertia)
            plant.RegisterCollisionGeometry(
                body, RigidTransform(), shape, f"tip{k}", ProximityProperties()
            )
            self.fingers.append(body)
        plant.Finalize()
        self.plant = plant
        self.diagram = builder.Build()
        self.root = self.diagram.CreateDefaultContext()
        self.ctx = plant.GetMyContextFromRoot(self.root)

    def place(self, X_WO: RigidTransform, X_OF: Sequence[RigidTransform]) -> None:
        """Put the object at ``X_WO`` and finger ``k`` at ``X_WO X_OF[k]``."""
        self.plant.SetFreeBodyPose(self.ctx, self.object, X_WO)
        for body, X in zip(self.fingers, X_OF, strict=True):
            self.plant.SetFreeBodyPose(self.ctx, body, X_WO.multiply(X))
