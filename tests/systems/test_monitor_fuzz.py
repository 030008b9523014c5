"""Issue 21's GraspMonitor rows: hostile options, contexts and states.

Every case gets a clear GraspError or a right answer, never a raw Drake or
Python exception, a hang or a silent wrong answer.
"""

import numpy as np
import pytest
from pick_support import build_pick
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError
from drakegrasp.systems.holding import HoldingThresholds
from drakegrasp.systems.monitor import GraspMonitor, add_grasp_monitor

BOX = "box::box"


@pytest.fixture(scope="module")
def pick():
    return build_pick(mu=0.5, distance_tolerance=1e-3)


@pytest.mark.parametrize("name", ["period", "offset"])
@pytest.mark.parametrize(
    "value", [None, "0.05", 0.05 + 0j, [0.05], True, float("nan"), float("inf"), -1]
)
def test_period_and_offset_must_be_real_seconds(pick, name, value):
    with pytest.raises(InvalidOptionError, match=name):
        GraspMonitor(pick.plant, object_body=BOX, mu=0.5, **{name: value})


@pytest.mark.parametrize("period", [1e-300, 1e-9, 0.0])
def test_a_period_too_short_to_advance_is_refused(pick, period):
    with pytest.raises(InvalidOptionError, match="period must be finite and >= 1e-06"):
        GraspMonitor(pick.plant, object_body=BOX, mu=0.5, period=period)


def test_integer_seconds_are_accepted(pick):
    monitor = GraspMonitor(pick.plant, object_body=BOX, mu=0.5, period=1, offset=0)
    assert monitor.period == 1.0


@pytest.mark.parametrize("b", [-1, 0, float("nan"), "1", True])
def test_bad_characteristic_length_is_refused_at_construction(pick, b):
    with pytest.raises(InvalidOptionError, match="characteristic_length"):
        GraspMonitor(pick.plant, object_body=BOX, mu=0.5, characteristic_length=b)


@pytest.mark.parametrize("flag", ["compute_epsilon", "check_pose", "allow_penetration"])
@pytest.mark.parametrize("value", [1, 0, "yes", None, [True], np.float64(1.0)])
def test_flags_must_be_bools(pick, flag, value):
    if flag == "allow_penetration" and value is None:  # its default: allowed
        monitor = GraspMonitor(pick.plant, object_body=BOX, mu=0.5, **{flag: value})
        assert monitor.settings.analysis.allow_penetration is True
        return
    with pytest.raises(InvalidOptionError, match=flag):
        GraspMonitor(pick.plant, object_body=BOX, mu=0.5, **{flag: value})


@pytest.mark.parametrize(
    "kwargs",
    [
        {"risk": 0.0},
        {"risk": 1.5},
        {"slip_speed": -1.0},
        {"slip_speed": "1"},
        {"separation_speed": float("nan")},
        {"hold_samples": -1},
        {"hold_samples": 1.5},
        {"hold_samples": True},
    ],
)
def test_bad_holding_thresholds_are_refused(kwargs):
    with pytest.raises(InvalidOptionError):
        HoldingThresholds(**kwargs)


def test_holding_must_be_thresholds(pick):
    with pytest.raises(InvalidOptionError, match="HoldingThresholds"):
        GraspMonitor(pick.plant, object_body=BOX, mu=0.5, holding={"risk": 0.5})


def test_release_distance_must_exceed_the_distance_tolerance(pick):
    # A gap at which a contact still counts cannot mean the object has left.
    holding = HoldingThresholds(release_distance=1e-3)
    with pytest.raises(InvalidOptionError, match="release_distance"):
        GraspMonitor(
            pick.plant,
            object_body=BOX,
            mu=0.5,
            distance_tolerance=1e-3,
            holding=holding,
        )
    GraspMonitor(  # just above it is fine
        pick.plant, object_body=BOX, mu=0.5, distance_tolerance=9e-4, holding=holding
    )


def test_two_monitors_in_one_diagram_have_unique_names():
    pick = build_pick(mu=0.5, distance_tolerance=1e-3)  # one monitor already
    builder = DiagramBuilder()
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph

    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 1e-3)
    parser = Parser(plant)
    dg.register_models(parser)
    parser.AddModels(url="package://drakegrasp/objects/box.sdf")
    (hand,) = parser.AddModels(url="package://drakegrasp/hands/parallel_jaw.sdf")
    plant.Finalize()
    options = dict(object_body=BOX, hand=hand, mu=0.5)
    first = add_grasp_monitor(builder, plant, scene_graph, **options)
    second = add_grasp_monitor(builder, plant, scene_graph, **options)
    third = add_grasp_monitor(builder, plant, scene_graph, name="mine", **options)
    diagram = builder.Build()  # crashed with two "grasp_monitor"s
    assert [first.get_name(), second.get_name(), third.get_name()] == [
        "grasp_monitor",
        "grasp_monitor_2",
        "mine",
    ]
    Simulator(diagram).AdvanceTo(0.1)
    assert pick.monitor.get_name() == "grasp_monitor"


def test_foreign_builder_plant_and_scene_graph_are_refused(pick):
    with pytest.raises(InvalidOptionError, match="not in this builder"):
        add_grasp_monitor(
            DiagramBuilder(), pick.plant, pick.scene_graph, mu=0.5, object_body=BOX
        )
    with pytest.raises(InvalidOptionError, match="builder must be"):
        add_grasp_monitor(None, pick.plant, pick.scene_graph, mu=0.5, object_body=BOX)
    from pydrake.systems.primitives import ConstantVectorSource

    built = DiagramBuilder()
    built.AddSystem(ConstantVectorSource([0.0]))
    built.Build()
    with pytest.raises(InvalidOptionError, match="already built"):
        add_grasp_monitor(built, pick.plant, pick.scene_graph, mu=0.5, object_body=BOX)


def test_foreign_context_is_refused(pick):
    root = pick.diagram.CreateDefaultContext()
    with pytest.raises(InvalidOptionError, match="another system") as e:
        pick.monitor.evaluate(root)
    assert "\n" not in str(e.value)  # Drake's multi-line text, on one line
    with pytest.raises(InvalidOptionError, match="another system"):
        pick.monitor.evaluate(pick.plant.CreateDefaultContext())
    with pytest.raises(InvalidOptionError, match="Context"):
        pick.monitor.evaluate("context")


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("index", [3, -1])
def test_non_finite_state_is_an_invalid_sample(pick, bad, index):
    # Drake's own setters refuse (SystemExit) a non-finite state, so it is fed
    # to the monitor's input port, as a diverging upstream system would.
    root = pick.diagram.CreateDefaultContext()
    plant_context = pick.plant.GetMyContextFromRoot(root)
    x = pick.plant.GetPositionsAndVelocities(plant_context)
    x[index] = bad
    own = pick.monitor.CreateDefaultContext()
    pick.monitor.get_plant_state_input_port().FixValue(own, x)
    query = pick.scene_graph.get_query_output_port().Eval(
        pick.scene_graph.GetMyContextFromRoot(root)
    )
    pick.monitor.get_query_object_input_port().FixValue(own, query)
    sample = pick.monitor.evaluate(own)
    assert sample.status == "invalid"
    assert "non-finite" in sample.message and f"[{index % len(x)}]" in sample.message
    assert sample.verdicts[GraspMonitor.STATUS] == -1.0
    assert sample.holding == "no contact"  # the state before it, kept
    assert sample.report is None
