"""A simulated pick: the shipped parallel-jaw gripper lifts a box off the ground.

The palm hangs from the world on a vertical prismatic joint ``lift`` (fingers
pointing down); the box rests on the ground between the open fingers.  The
plant's own PD controllers (discrete plant, SAP) track a piecewise-linear
desired state of the three actuated joints: open, close, lift 5 cm, lower,
open.  The verdict of a monitor must follow: no contact, force closure while
the fingers hold the box, no contact after they open.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from pydrake.geometry import (
    AddContactMaterial,
    AddRigidHydroelasticProperties,
    Box,
    ProximityProperties,
    SceneGraphConfig,
)
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    CoulombFriction,
    MultibodyPlantConfig,
)
from pydrake.multibody.tree import FixedOffsetFrame, PdControllerGains, PrismaticJoint
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

import drakegrasp as dg
from drakegrasp.systems.monitor import add_grasp_monitor

OPEN, CLOSED = 0.035, 0.015  # finger joint values, m (the box is 50 mm wide)
LIFT = 0.05  # m
PALM_HEIGHT = 0.125  # palm face above the ground at lift = 0, m
# (time s, finger joint m, lift m): open, close, hold, lift, hold, lower, open.
SCHEDULE = [
    (0.0, OPEN, 0.0),
    (0.3, OPEN, 0.0),
    (0.7, CLOSED, 0.0),
    (1.0, CLOSED, 0.0),
    (1.5, CLOSED, LIFT),
    (1.8, CLOSED, LIFT),
    (2.3, CLOSED, 0.0),
    (2.6, OPEN, 0.0),
    (3.0, OPEN, 0.0),
]
DURATION = SCHEDULE[-1][0]


@dataclass
class Pick:
    diagram: object
    plant: object
    scene_graph: object
    gripper: object
    box: object
    monitor: object
    state_log: object
    verdict_log: object
    simulator: Simulator

    def run(self, duration: float = DURATION) -> None:
        self.simulator.AdvanceTo(duration)


def add_ground(plant, *, hydroelastic: bool = False) -> None:
    """Weld a 1 m x 1 m ground slab (top face at z = 0, μ = 0.5) to the world."""
    ground = ProximityProperties()
    AddContactMaterial(friction=CoulombFriction(0.5, 0.5), properties=ground)
    if hydroelastic:
        AddRigidHydroelasticProperties(properties=ground)  # cheaper than compliant
    plant.RegisterCollisionGeometry(
        plant.world_body(),
        RigidTransform([0.0, 0.0, -0.05]),
        Box(1.0, 1.0, 0.1),
        "ground",
        ground,
    )


def add_lift(plant, body, X_WB: RigidTransform, axis) -> None:
    """Hang ``body`` from the world on an actuated prismatic joint ``lift``.

    ``X_WB`` places the joint's parent frame ``lift_base``; ``axis`` is the
    joint axis in that frame.
    """
    base = plant.AddFrame(FixedOffsetFrame("lift_base", plant.world_frame(), X_WB))
    lift = plant.AddJoint(PrismaticJoint("lift", base, body.body_frame(), axis))
    plant.AddJointActuator("lift", lift, 200.0)


def drive(builder, plant, gripper, times, columns, *, finger_gains) -> None:
    """Track ``columns`` (joint name -> desired positions at ``times``) by PD.

    The ``lift`` actuator gets stiff gains (20000, 400), every other actuator
    of ``gripper`` ``finger_gains`` ``(p, d)``.  Call after ``Finalize``.
    """
    for index in plant.GetJointActuatorIndices(gripper):
        actuator = plant.get_mutable_joint_actuator(index)
        gains = (20000.0, 400.0) if actuator.name() == "lift" else finger_gains
        actuator.set_controller_gains(PdControllerGains(p=gains[0], d=gains[1]))
    names = [
        plant.get_joint_actuator(i).joint().name()
        for i in plant.GetJointActuatorIndices(gripper)
    ]
    q_desired = PiecewisePolynomial.FirstOrderHold(
        times, np.array([columns[n] for n in names])
    )
    source = builder.AddSystem(TrajectorySource(q_desired, output_derivative_order=1))
    builder.Connect(
        source.get_output_port(), plant.get_desired_state_input_port(gripper)
    )


def monitored_pick(
    builder,
    plant,
    scene_graph,
    gripper,
    box,
    object_body,
    *,
    period: float,
    initial_state: Callable[[object], None],
    **monitor_options,
) -> Pick:
    """Add a GraspMonitor on ``object_body`` and logs at ``period``; build.

    ``initial_state(plant_context)`` sets the plant's state before the
    simulator is initialised.
    """
    monitor = add_grasp_monitor(
        builder,
        plant,
        scene_graph,
        object_body=object_body,
        hand=gripper,
        period=period,
        **monitor_options,
    )
    state_log = LogVectorOutput(plant.get_state_output_port(), builder, period)
    verdict_log = LogVectorOutput(monitor.get_verdicts_output_port(), builder, period)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    initial_state(plant.GetMyMutableContextFromRoot(simulator.get_mutable_context()))
    simulator.Initialize()
    return Pick(
        diagram,
        plant,
        scene_graph,
        gripper,
        box,
        monitor,
        state_log,
        verdict_log,
        simulator,
    )


def build_pick(
    *,
    flat: bool = False,
    plant_contact: str = "point",
    period: float = 0.05,
    closed: float = CLOSED,
    **monitor_options,
) -> Pick:
    builder = DiagramBuilder()
    plant_config = MultibodyPlantConfig(
        time_step=1e-3,
        contact_model=plant_contact,
        discrete_contact_approximation="sap",
    )
    sg_config = SceneGraphConfig()
    if plant_contact != "point":
        sg_config.default_proximity_properties.compliance_type = "compliant"
        sg_config.default_proximity_properties.hydroelastic_modulus = 1e6
        sg_config.default_proximity_properties.resolution_hint = 0.005
    plant, scene_graph = AddMultibodyPlant(plant_config, sg_config, builder)
    parser = Parser(plant)
    dg.register_models(parser)
    hand = "parallel_jaw_flat" if flat else "parallel_jaw"
    (gripper,) = parser.AddModels(url=f"package://drakegrasp/hands/{hand}.sdf")
    (box,) = parser.AddModels(url="package://drakegrasp/objects/box.sdf")
    add_ground(plant, hydroelastic=plant_contact != "point")
    add_lift(
        plant,
        plant.GetBodyByName("palm", gripper),
        RigidTransform(RollPitchYaw(np.pi, 0.0, 0.0), [0.0, 0.0, PALM_HEIGHT]),
        [0, 0, -1],
    )
    plant.Finalize()
    fingers = [closed if f == CLOSED else f for _, f, _ in SCHEDULE]
    columns = {
        "left_finger_joint": fingers,
        "right_finger_joint": fingers,
        "lift": [z for _, _, z in SCHEDULE],
    }
    times = [t for t, _, _ in SCHEDULE]
    drive(builder, plant, gripper, times, columns, finger_gains=(300.0, 10.0))

    def initial_state(plant_context):
        for name in ("left_finger_joint", "right_finger_joint"):
            plant.GetJointByName(name, gripper).set_translation(plant_context, OPEN)
        plant.SetFreeBodyPose(
            plant_context, plant.GetBodyByName("box", box), RigidTransform([0, 0, 0.05])
        )

    return monitored_pick(
        builder,
        plant,
        scene_graph,
        gripper,
        box,
        plant.GetBodyByName("box", box),
        period=period,
        initial_state=initial_state,
        **monitor_options,
    )
