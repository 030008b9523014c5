"""A simulated pick with real models: the WSG-50 lifts the YCB sugar box (0.514 kg).

Drake's ``schunk_wsg_50_with_tip.sdf`` hangs from the world on a vertical
prismatic joint ``lift``, fingers pointing down; the sugar box stands on the
ground between the open fingers, its 39.1 mm side across them.  Each pad
touches the box with four 1 mm spheres (eight point contacts); the plant's
friction is μ = 1 on both models.  The plant's own PD controllers (discrete
plant, SAP, 1 ms) track a schedule: open, close, settle, lift 5 cm, hold.
The fingers' target is ``squeeze`` metres past the box faces: the PD
(1000 N/m) presses each pad with about ``1000 * squeeze`` newtons, and two
pads with μ = 1 carry the box's 5.04 N weight only above ~2.5 N each.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import AddContactMaterial, Box, ProximityProperties
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
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

from drakegrasp.plant.models import use_local_drake_models
from drakegrasp.systems.monitor import add_grasp_monitor

WSG_URL = "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf"
SUGAR_URL = "package://drake_models/ycb/004_sugar_box.sdf"
TOUCH = 0.01705  # finger opening q (left -q, right +q) where the pads touch, m
OPEN = 0.03  # m: 13 mm clear of each face
LIFT = 0.08  # m: the pads (16-36 mm above the ground) slide off a box left behind
LIFT_START = 0.9  # s
BOX_IN_BODY = 0.09  # box centre along the gripper body's y (towards the tips), m
BOX_HALF_HEIGHT = 0.04385  # its corner spheres above its centre, m
# (time s, opening: "open" or "closed", lift m)
SCHEDULE = [
    (0.0, "open", 0.0),
    (0.2, "open", 0.0),
    (0.6, "closed", 0.0),
    (LIFT_START, "closed", 0.0),
    (1.4, "closed", LIFT),
    (2.0, "closed", LIFT),
]
DURATION = SCHEDULE[-1][0]
FIRM, WEAK = 0.010, 0.0015  # squeeze: metres past the box faces


@dataclass
class WsgPick:
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


def build_wsg_pick(
    models_dir, *, squeeze: float, period: float = 0.01, **monitor_options
) -> WsgPick:
    """The pick, a GraspMonitor (``monitor_options``) and logs at ``period``."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(
        MultibodyPlantConfig(
            time_step=1e-3, contact_model="point", discrete_contact_approximation="sap"
        ),
        builder,
    )
    parser = Parser(plant)
    use_local_drake_models(parser, models_dir)
    (gripper,) = parser.AddModels(url=WSG_URL)
    (box,) = parser.AddModels(url=SUGAR_URL)
    ground = ProximityProperties()
    AddContactMaterial(friction=CoulombFriction(0.5, 0.5), properties=ground)
    plant.RegisterCollisionGeometry(
        plant.world_body(),
        RigidTransform([0, 0, -0.05]),
        Box(1, 1, 0.1),
        "ground",
        ground,
    )
    # The body's y (towards the finger tips) points down: a rotation of -90 deg
    # about x.  The box centre is BOX_IN_BODY below the body origin.
    R_WB = RollPitchYaw(-np.pi / 2, 0.0, 0.0).ToRotationMatrix()
    p_WB = [0.0, 0.0, BOX_HALF_HEIGHT + BOX_IN_BODY]
    base = plant.AddFrame(
        FixedOffsetFrame("lift_base", plant.world_frame(), RigidTransform(R_WB, p_WB))
    )
    body = plant.GetBodyByName("body", gripper)
    lift = plant.AddJoint(PrismaticJoint("lift", base, body.body_frame(), [0, -1, 0]))
    plant.AddJointActuator("lift", lift, 200.0)
    plant.Finalize()
    for index in plant.GetJointActuatorIndices(gripper):
        actuator = plant.get_mutable_joint_actuator(index)
        gains = (20000.0, 400.0) if actuator.name() == "lift" else (1000.0, 20.0)
        actuator.set_controller_gains(PdControllerGains(p=gains[0], d=gains[1]))
    closed = TOUCH - squeeze
    opening = {"open": OPEN, "closed": closed}
    columns = {
        "left_finger_sliding_joint": [-opening[w] for _, w, _ in SCHEDULE],
        "right_finger_sliding_joint": [opening[w] for _, w, _ in SCHEDULE],
        "lift": [z for _, _, z in SCHEDULE],
    }
    names = [
        plant.get_joint_actuator(i).joint().name()
        for i in plant.GetJointActuatorIndices(gripper)
    ]
    q_desired = PiecewisePolynomial.FirstOrderHold(
        [t for t, _, _ in SCHEDULE], np.array([columns[n] for n in names])
    )
    source = builder.AddSystem(TrajectorySource(q_desired, output_derivative_order=1))
    builder.Connect(
        source.get_output_port(), plant.get_desired_state_input_port(gripper)
    )
    sugar = plant.get_body(plant.GetBodyIndices(box)[0])
    monitor = add_grasp_monitor(
        builder,
        plant,
        scene_graph,
        object_body=sugar,
        hand=gripper,
        period=period,
        **monitor_options,
    )
    state_log = LogVectorOutput(plant.get_state_output_port(), builder, period)
    verdict_log = LogVectorOutput(monitor.get_verdicts_output_port(), builder, period)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    plant_context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    plant.GetJointByName("left_finger_sliding_joint", gripper).set_translation(
        plant_context, -OPEN
    )
    plant.GetJointByName("right_finger_sliding_joint", gripper).set_translation(
        plant_context, OPEN
    )
    # Box x up, its z (39.1 mm) across the fingers (world x).
    R_WO = RotationMatrix(np.array([[0.0, 0, 1], [0, -1, 0], [1, 0, 0]]))
    plant.SetFreeBodyPose(
        plant_context, sugar, RigidTransform(R_WO, [0, 0, BOX_HALF_HEIGHT])
    )
    simulator.Initialize()
    return WsgPick(
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
