"""Review round 21: hostile wiring, contexts and states of the grasp monitor.

Every bad input gets a GraspError naming what is wrong, and a bad plant
state or query at sample time gets an "invalid" sample, never a raw Drake
RuntimeError: a scene graph that is not the plant's, a monitor context whose
inputs are not connected, a free body's quaternion of zeros in either contact
mode, numpy scalars in the holding thresholds, and the verdict vector's size
in the module's diagram.
"""

import numpy as np
import pytest
from pick_support import build_pick
from pydrake.geometry import QueryObject, SceneGraph
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import (
    AddMultibodyPlantSceneGraph,
    ContactResults,
    MultibodyPlant,
)
from pydrake.systems.framework import DiagramBuilder

import drakegrasp as dg
import drakegrasp.systems.grasp_monitor as grasp_monitor_module
import drakegrasp.systems.monitor as monitor_module
from drakegrasp.errors import InvalidOptionError, InvalidPoseError
from drakegrasp.plant.contact_results import contacts_from_results
from drakegrasp.systems.holding import HoldingThresholds
from drakegrasp.systems.monitor import GraspMonitor, add_grasp_monitor

pytestmark = pytest.mark.filterwarnings(
    "ignore::drakegrasp.plant.friction.FrictionMismatchWarning"
)

MODES = ("geometry", "contact_results")
ZERO_QUATERNION = "the quaternion of 'box::box' is zero"


def _add_models(plant) -> None:
    parser = Parser(plant)
    dg.register_models(parser)
    parser.AddModels(url="package://drakegrasp/hands/parallel_jaw.sdf")
    parser.AddModels(url="package://drakegrasp/objects/box.sdf")
    plant.Finalize()


def _two_plants():
    """A builder holding two plant / scene graph pairs of the same models."""
    builder = DiagramBuilder()
    p1, sg1 = AddMultibodyPlantSceneGraph(builder, 1e-3)
    p2, sg2 = AddMultibodyPlantSceneGraph(builder, 1e-3)
    p2.set_name("plant2")
    sg2.set_name("scene_graph2")
    for plant in (p1, p2):
        _add_models(plant)
    return builder, (p1, sg1), (p2, sg2)


def _one_plant():
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 1e-3)
    _add_models(plant)
    return builder, plant, scene_graph


def _box_away(plant, root) -> None:
    """Put the box 1 m above the hand (it starts inside it): no contact."""
    plant.SetFreeBodyPose(
        plant.GetMyMutableContextFromRoot(root),
        plant.GetBodyByName("box"),
        RigidTransform([0.0, 0.0, 1.0]),
    )


def _zero_box_quaternion(plant, root) -> None:
    """Set the box's quaternion to [0, 0, 0, 0] (finite, but no rotation)."""
    x = plant.GetMyMutableContextFromRoot(root).get_mutable_discrete_state_vector()
    k = plant.GetBodyByName("box").floating_positions_start()
    v = x.CopyToVector()
    v[k : k + 4] = 0.0
    x.SetFromVector(v)


# 1. A scene graph that is not the plant's -------------------------------------


def test_add_grasp_monitor_refuses_another_plants_scene_graph():
    builder, (p1, sg1), (p2, sg2) = _two_plants()
    with pytest.raises(InvalidOptionError, match="not registered with the scene "):
        add_grasp_monitor(builder, p1, sg2, object_body="box", mu=0.5)
    with pytest.raises(InvalidOptionError, match="'scene_graph2'"):
        add_grasp_monitor(builder, p1, sg2, object_body="box", mu=0.5)
    with pytest.raises(InvalidOptionError, match="'plant2'"):
        add_grasp_monitor(builder, p2, sg1, object_body="box", mu=0.5)
    # The right pairs are wired as before and sample.
    m1 = add_grasp_monitor(builder, p1, sg1, object_body="box", mu=0.5)
    m2 = add_grasp_monitor(builder, p2, sg2, object_body="box", mu=0.5)
    root = builder.Build().CreateDefaultContext()
    for plant in (p1, p2):
        _box_away(plant, root)
    for m in (m1, m2):
        assert m.evaluate(m.GetMyContextFromRoot(root)).status == "no contact"


def test_add_grasp_monitor_refuses_a_plant_without_a_scene_graph():
    builder = DiagramBuilder()
    plant = builder.AddSystem(MultibodyPlant(1e-3))
    scene_graph = builder.AddSystem(SceneGraph())
    _add_models(plant)
    with pytest.raises(InvalidOptionError, match="not registered with the scene"):
        add_grasp_monitor(builder, plant, scene_graph, object_body="box", mu=0.5)


@pytest.mark.parametrize("contacts", MODES)
def test_hand_wired_foreign_scene_graph_gives_an_invalid_sample(contacts):
    builder, (p1, _), (_, sg2) = _two_plants()
    monitor = builder.AddSystem(
        GraspMonitor(p1, object_body="box", mu=0.5, contacts=contacts)
    )
    builder.Connect(p1.get_state_output_port(), monitor.get_plant_state_input_port())
    builder.Connect(sg2.get_query_output_port(), monitor.get_query_object_input_port())
    if contacts == "contact_results":
        builder.Connect(
            p1.get_contact_results_output_port(),
            monitor.get_contact_results_input_port(),
        )
    root = builder.Build().CreateDefaultContext()
    sample = monitor.evaluate(monitor.GetMyContextFromRoot(root))
    assert sample.status == "invalid"
    assert "not registered with" in sample.message
    assert sample.verdicts[GraspMonitor.STATUS] == -1.0


def test_a_default_query_object_gives_an_invalid_sample():
    _, plant, _ = _one_plant()
    monitor = GraspMonitor(plant, object_body="box", mu=0.5)
    context = monitor.CreateDefaultContext()
    x = plant.GetPositionsAndVelocities(plant.CreateDefaultContext())
    monitor.get_plant_state_input_port().FixValue(context, x)
    monitor.get_query_object_input_port().FixValue(context, QueryObject())
    sample = monitor.evaluate(context)  # Drake's inspector would SystemExit
    assert sample.status == "invalid"
    assert "query_object input holds no scene graph's query" in sample.message


def test_a_drake_error_while_sensing_is_an_invalid_sample_with_its_text(
    monkeypatch,
):
    builder, plant, scene_graph = _one_plant()
    monitor = add_grasp_monitor(builder, plant, scene_graph, object_body="box", mu=0.5)
    root = builder.Build().CreateDefaultContext()
    context = monitor.GetMyContextFromRoot(root)

    def drake_fails(*args, **kwargs):
        raise RuntimeError("Can't report collision filter status\nbetween 1 and 2")

    monkeypatch.setattr(grasp_monitor_module, "sense_contacts", drake_fails)
    sample = monitor.evaluate(context)
    assert sample.status == "invalid"
    assert "Can't report collision filter status between 1 and 2" in sample.message

    def bug(*args, **kwargs):  # a programming error is not a sample
        raise NotImplementedError("not written yet")

    monkeypatch.setattr(grasp_monitor_module, "sense_contacts", bug)
    with pytest.raises(NotImplementedError):
        monitor.evaluate(context)


def test_contacts_from_results_refuses_a_query_of_another_scene_graph():
    builder, (p1, _), (_, sg2) = _two_plants()
    root = builder.Build().CreateDefaultContext()
    query = sg2.get_query_output_port().Eval(sg2.GetMyContextFromRoot(root))
    p1_context = p1.GetMyContextFromRoot(root)
    with pytest.raises(InvalidOptionError, match="not registered with"):
        contacts_from_results(
            p1, p1_context, ContactResults(), query, object_body="box"
        )
    with pytest.raises(InvalidOptionError, match="no scene graph's query"):
        contacts_from_results(
            p1, p1_context, ContactResults(), QueryObject(), object_body="box"
        )
    with pytest.raises(InvalidOptionError, match="QueryObject"):
        contacts_from_results(p1, p1_context, ContactResults(), "q", object_body="box")


# 2. A monitor context whose inputs are not connected --------------------------


@pytest.mark.parametrize("contacts", MODES)
def test_unconnected_input_ports_are_named(contacts):
    _, plant, scene_graph = _one_plant()
    monitor = GraspMonitor(plant, object_body="box", mu=0.5, contacts=contacts)
    context = monitor.CreateDefaultContext()
    names = "plant_state, query_object"
    if contacts == "contact_results":
        names += ", contact_results"
    with pytest.raises(InvalidOptionError, match=f"input ports {names} are") as e:
        monitor.evaluate(context)
    assert "FixValue" in str(e.value) and "add_grasp_monitor" in str(e.value)
    # Following the advice: fix the values, one port at a time.
    x = plant.GetPositionsAndVelocities(plant.CreateDefaultContext())
    monitor.get_plant_state_input_port().FixValue(context, x)
    with pytest.raises(InvalidOptionError, match="input ports? query_object"):
        monitor.evaluate(context)
    query = QueryObject()
    monitor.get_query_object_input_port().FixValue(context, query)
    if contacts == "contact_results":
        with pytest.raises(InvalidOptionError, match="input port contact_results is"):
            monitor.evaluate(context)
        monitor.get_contact_results_input_port().FixValue(context, ContactResults())
    assert monitor.evaluate(context).status == "invalid"  # a default QueryObject


def test_the_foreign_context_advice_is_correct():
    builder, plant, scene_graph = _one_plant()
    monitor = add_grasp_monitor(builder, plant, scene_graph, object_body="box", mu=0.5)
    diagram = builder.Build()
    root = diagram.CreateDefaultContext()
    _box_away(plant, root)
    with pytest.raises(InvalidOptionError, match="another system") as e:
        monitor.evaluate(root)
    assert "GetMyContextFromRoot" in str(e.value) and "FixValue" in str(e.value)
    # Both routes it gives work.
    assert monitor.evaluate(monitor.GetMyContextFromRoot(root)).status == "no contact"
    own = monitor.CreateDefaultContext()
    monitor.get_plant_state_input_port().FixValue(
        own, plant.GetPositionsAndVelocities(plant.GetMyContextFromRoot(root))
    )
    monitor.get_query_object_input_port().FixValue(
        own,
        scene_graph.get_query_output_port().Eval(
            scene_graph.GetMyContextFromRoot(root)
        ),
    )
    assert monitor.evaluate(own).status == "no contact"


# 3. A free body's quaternion of zeros -----------------------------------------


def test_a_zero_quaternion_is_the_same_invalid_sample_in_both_modes():
    builder, plant, scene_graph = _one_plant()
    monitors = {
        mode: add_grasp_monitor(
            builder, plant, scene_graph, object_body="box", mu=0.5, contacts=mode
        )
        for mode in MODES
    }
    root = builder.Build().CreateDefaultContext()
    _zero_box_quaternion(plant, root)
    samples = {
        mode: m.evaluate(m.GetMyContextFromRoot(root)) for mode, m in monitors.items()
    }
    for sample in samples.values():
        assert sample.status == "invalid"
        assert sample.verdicts[GraspMonitor.STATUS] == -1.0
        assert ZERO_QUATERNION in sample.message
        assert "QuaternionToRotationMatrix" in sample.message
    assert samples["geometry"].message == samples["contact_results"].message


@pytest.mark.parametrize(
    "contacts, plant_contact",
    [
        ("geometry", "point"),
        ("contact_results", "point"),
        ("contact_results", "hydroelastic_with_fallback"),
    ],
)
def test_a_zero_quaternion_during_a_grip_keeps_the_holding_state(
    contacts, plant_contact
):
    # With a grip, the holding state measures the object against the
    # fingers that touched it: a zero quaternion failed there in both modes.
    pick = build_pick(
        mu=0.5, distance_tolerance=1e-3, contacts=contacts, plant_contact=plant_contact
    )
    pick.run(1.0)  # the fingers are closed on the box
    root = pick.simulator.get_mutable_context()
    context = pick.monitor.GetMyContextFromRoot(root)
    before = pick.monitor.evaluate(context)
    assert before.status == "ok" and before.anchors
    _zero_box_quaternion(pick.plant, root)
    sample = pick.monitor.evaluate(context)
    assert sample.status == "invalid" and ZERO_QUATERNION in sample.message
    held = context.get_abstract_state(0).get_value()
    assert sample.holding == held.holding  # the state before it, kept


def test_contacts_from_results_with_a_zero_quaternion_is_an_invalid_pose():
    builder, plant, scene_graph = _one_plant()
    root = builder.Build().CreateDefaultContext()
    _zero_box_quaternion(plant, root)
    query = scene_graph.get_query_output_port().Eval(
        scene_graph.GetMyContextFromRoot(root)
    )
    with pytest.raises(InvalidPoseError, match="QuaternionToRotationMatrix"):
        contacts_from_results(
            plant,
            plant.GetMyContextFromRoot(root),
            ContactResults(),
            query,
            object_body="box",
        )


def test_contacts_from_results_with_a_query_of_a_bad_state_is_an_invalid_pose():
    # The plant context is sound, the query's scene graph reads a bad state.
    builder, plant, scene_graph = _one_plant()
    root = builder.Build().CreateDefaultContext()
    sound = plant.CreateDefaultContext()
    _zero_box_quaternion(plant, root)
    query = scene_graph.get_query_output_port().Eval(
        scene_graph.GetMyContextFromRoot(root)
    )
    with pytest.raises(InvalidPoseError, match="geometry poses of query_object"):
        contacts_from_results(plant, sound, ContactResults(), query, object_body="box")


# 4. numpy scalars in the holding thresholds -----------------------------------


@pytest.mark.parametrize(
    "value", [np.float32(0.5), np.float64(0.5), np.array(0.5), np.float16(0.5)]
)
@pytest.mark.parametrize("name", ["risk", "slip_speed", "separation_speed"])
def test_holding_thresholds_take_numpy_real_scalars(name, value):
    thresholds = HoldingThresholds(**{name: value})
    assert getattr(thresholds, name) == 0.5
    assert type(getattr(thresholds, name)) is float


def test_holding_thresholds_take_a_numpy_release_distance_and_integers():
    thresholds = HoldingThresholds(
        release_distance=np.float32(3e-3), risk=np.int64(1), slip_speed=1
    )
    assert thresholds.release_distance == pytest.approx(3e-3)
    assert thresholds.risk == 1.0 and thresholds.slip_speed == 1.0


@pytest.mark.parametrize(
    "value", [np.bool_(True), True, "0.5", np.complex64(0.5), np.array([0.5]), None]
)
def test_holding_thresholds_still_refuse_non_reals(value):
    with pytest.raises(InvalidOptionError, match="risk must be a real number"):
        HoldingThresholds(risk=value)


def test_a_monitor_takes_numpy_thresholds_and_period_alike():
    _, plant, _ = _one_plant()
    monitor = GraspMonitor(
        plant,
        object_body="box",
        mu=0.5,
        period=np.float32(0.1),
        offset=np.array(0.0),
        holding=HoldingThresholds(risk=np.float32(0.5)),
    )
    assert monitor.settings.thresholds.risk == 0.5
    assert monitor.period == pytest.approx(0.1)
    with pytest.raises(InvalidOptionError, match="period must be a real number"):
        GraspMonitor(plant, object_body="box", mu=0.5, period=np.bool_(True))


# 5. The diagram's verdict vector ----------------------------------------------


def test_the_diagram_gives_the_verdict_vectors_size():
    doc = monitor_module.__doc__
    assert "(vector, 7)" not in doc
    assert "verdicts (vector, 12 + 2 n)" in doc
    assert "18 entries for the parallel jaw" in doc
    _, plant, _ = _one_plant()
    monitor = GraspMonitor(plant, object_body="box", mu=0.5, hand="parallel_jaw")
    assert len(monitor.verdict_names) == 12 + 2 * 3 == 18
    assert monitor.get_verdicts_output_port().size() == 18
