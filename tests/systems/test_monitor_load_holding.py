"""With a load section, the holding state judges a grip by it.

LP3 (the hand check of force closure) fails for fingers that touch at several
points each: Drake's Franka hand closing its pads on the YCB soup can, PD
fingers pressing 20 N, holds the can (it moves 2 mm in 1 s, read from the
plant apart from the monitor) while force closure says "no".  The state once
read ``touching`` throughout; with ``load="gravity"`` it reads ``holding``,
as the load section (the motors hold the weight at these contacts) says.
"""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.all import (
    AddMultibodyPlant,
    ConstantVectorSource,
    DiagramBuilder,
    MultibodyPlantConfig,
    Parser,
    PdControllerGains,
    Simulator,
    SpatialInertia,
    UnitInertia,
)

import drakegrasp as dg
from drakegrasp.planning import planning_scene

PANDA = "package://drake_models/franka_description/urdf/panda_hand.urdf"
SOUP = "package://drake_models/ycb/005_tomato_soup_can.sdf"
LOAD = dict(load="gravity", torque_limits="plant")


@pytest.fixture(scope="module")
def franka_can(drake_models_dir):
    scene = planning_scene(SOUP, hand_url=PANDA, models_dir=drake_models_dir)
    best = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=300, mu=1.0, seed=0,
    )[0]  # fmt: skip
    return scene, best


def _hold(scene, candidate, **monitor_options):
    """Weld the hand at the plan, press 10 mm past it for 1 s; (moved, sample)."""
    builder = DiagramBuilder()
    config = MultibodyPlantConfig(time_step=1e-3, discrete_contact_approximation="sap")
    plant, scene_graph = AddMultibodyPlant(config, builder)
    hand, body = scene.add_models(plant, Parser(plant))
    if isinstance(body, str):  # a scoped name
        body = plant.GetBodyByName(body.rpartition("::")[2])
    base = plant.GetBodyByName(candidate.hand_base.rpartition("::")[2])
    plant.WeldFrames(plant.world_frame(), base.body_frame(), candidate.X_WH)
    for index in plant.GetJointActuatorIndices():
        actuator = plant.get_joint_actuator(index)
        actuator.set_controller_gains(PdControllerGains(p=2000.0, d=50.0))
    plant.Finalize()
    names = [n.rpartition("::")[2] for n in candidate.joint_names]
    targets = []
    for index in plant.GetJointActuatorIndices():
        k = names.index(plant.get_joint_actuator(index).joint().name())
        targets.append(candidate.q_hand[k] + 0.01 * candidate.closing_signs[k])
    source = builder.AddSystem(
        ConstantVectorSource(np.r_[targets, np.zeros(len(targets))])
    )
    builder.Connect(source.get_output_port(), plant.get_desired_state_input_port(hand))
    monitor = dg.add_grasp_monitor(
        builder, plant, scene_graph, object_body=body, hand=hand, mu="plant",
        period=0.05, distance_tolerance=1e-3, **monitor_options,
    )  # fmt: skip
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant_context = plant.GetMyContextFromRoot(context)
    for name, q in zip(names, candidate.q_hand, strict=True):
        plant.GetJointByName(name).set_translation(plant_context, q)
    plant.SetFreeBodyPose(plant_context, body, candidate.X_WO)
    Simulator(diagram, context).AdvanceTo(1.0)
    moved = np.linalg.norm(
        plant.EvalBodyPoseInWorld(plant_context, body).translation()
        - candidate.X_WO.translation()
    )
    sample = monitor.GetOutputPort("report").Eval(monitor.GetMyContextFromRoot(context))
    return moved, sample


def test_a_multi_point_grip_that_holds_reads_holding_with_a_load(franka_can):
    scene, best = franka_can
    moved, plain = _hold(scene, best)
    assert moved < 5e-3  # it held (Drake's plant, apart from the monitor)
    assert plain.status == "ok" and not plain.report.is_force_closure  # LP3
    assert plain.holding == "touching"
    moved, loaded = _hold(scene, best, **LOAD)
    assert moved < 5e-3
    assert loaded.report.load.holds and not loaded.report.is_force_closure
    assert loaded.holding == "holding", str(loaded)


def test_the_world_or_a_body_without_geometry_is_refused_when_built():
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(
        MultibodyPlantConfig(time_step=1e-3), builder
    )
    ghost = plant.AddRigidBody(
        "ghost", SpatialInertia(1.0, np.zeros(3), UnitInertia.SolidSphere(0.1))
    )
    plant.Finalize()
    for body, words in (
        (plant.world_body(), "is the world body"),
        (ghost, "no collision"),
    ):
        with pytest.raises(dg.ModelError, match=words):
            dg.GraspMonitor(plant, object_body=body, mu=0.5)
