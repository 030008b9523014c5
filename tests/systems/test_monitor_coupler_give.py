"""A coupled hand holding an object in Drake reads "holding", not "invalid".

Drake's coupler constraint (a ``<mimic>``, under SAP) gives under load, as a
contact penetrates: a pivoting jaw on one motor squeezing a box holds its
follower a few µrad off its leader.  The monitor checked the pose with an
analysis's coupling tolerance (1e-6) and every sample of the grip was
"invalid (impossible pose: the configuration breaks the coupling ...)"; its
default is now :data:`~drakegrasp.core.tolerances.MONITOR_COUPLING_TOL`.
"""

from __future__ import annotations

import numpy as np
import pytest
from coupled_hands import pivot_jaw_urdf
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import (
    AddMultibodyPlantSceneGraph,
    DiscreteContactApproximation,
)
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

import drakegrasp as dg
from drakegrasp.core.tolerances import COUPLING_TOL, MONITOR_COUPLING_TOL
from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant.couplings import coupling_violations, recorded_couplings
from drakegrasp.systems.monitor import add_grasp_monitor

BOX = "package://drakegrasp/objects/box.sdf"
BOX_AT = RigidTransform([0.0, 0.0, 0.075])  # between the jaws' tips


def _squeeze(**monitor_options):
    """(plant, context, monitor, box) after 0.3 s of a 1 N·m squeeze."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 1e-3)
    plant.set_discrete_contact_approximation(DiscreteContactApproximation.kLagged)
    parser = Parser(plant)
    dg.register_models(parser)
    (jaw,) = dg.plant.add_models(parser, text=pivot_jaw_urdf(), kind="urdf")
    (box_model,) = parser.AddModels(url=BOX)
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("palm", jaw))
    plant.Finalize()
    motor = builder.AddSystem(ConstantVectorSource(np.array([1.0])))
    builder.Connect(motor.get_output_port(), plant.get_actuation_input_port(jaw))
    box = plant.GetBodyByName("box", box_model)
    monitor = add_grasp_monitor(
        builder, plant, scene_graph, object_body=box, hand=jaw, mu="plant",
        load="gravity", torque_limits="plant", **monitor_options,
    )  # fmt: skip
    simulator = Simulator(builder.Build())
    context = simulator.get_mutable_context()
    plant_context = plant.GetMyMutableContextFromRoot(context)
    plant.SetFreeBodyPose(plant_context, box, BOX_AT)
    dg.close_hand(plant, plant_context, box, hand=jaw)
    simulator.Initialize()
    simulator.AdvanceTo(0.3)
    return plant, context, monitor, box


def test_a_squeezing_coupled_jaw_is_holding():
    plant, context, monitor, box = _squeeze()
    plant_context = plant.GetMyContextFromRoot(context)
    # the box stayed, and Drake's coupler gave: more than an analysis accepts
    moved = plant.EvalBodyPoseInWorld(plant_context, box).translation()
    assert np.linalg.norm(moved - BOX_AT.translation()) < 1e-3
    given = coupling_violations(plant, plant_context, recorded_couplings(plant))
    assert given, "the coupler held exactly: nothing to test"
    assert all(
        COUPLING_TOL < abs(v.follower_value - v.leader_value) < MONITOR_COUPLING_TOL
        for v in given
    )
    sample = monitor.evaluate(monitor.GetMyContextFromRoot(context))
    assert sample.status == "ok", sample.message
    assert sample.report.load.holds
    assert sample.holding == "holding"


def test_the_analysis_tolerance_is_still_there_to_ask_for():
    plant, context, monitor, _ = _squeeze(coupling_tolerance=COUPLING_TOL)
    sample = monitor.evaluate(monitor.GetMyContextFromRoot(context))
    assert sample.status == "invalid"
    assert "breaks the coupling" in sample.message


@pytest.mark.parametrize("bad", [0.0, -1e-3, 0.2, float("nan"), "1e-3"])
def test_a_coupling_tolerance_out_of_range_is_refused(bad):
    with pytest.raises(InvalidOptionError, match="coupling_tolerance must be"):
        dg.AnalysisOptions(mu=0.5, coupling_tolerance=bad)
