"""GraspMonitor's options: one AnalysisOptions or keywords, and the plant's friction.

The monitor takes the object :func:`drakegrasp.analyze_grasp` takes
(``options=AnalysisOptions(...)``) or the same keywords, never both; it reads
μ from the plant with ``mu="plant"`` and warns once when a typed μ is not the
plant's.  The plant's friction is checked against Drake's combination rule
written out here, ``2 μ_a μ_b / (μ_a + μ_b)`` of the geometries' dynamic
coefficients (the plant is discrete).
"""

import warnings

import numpy as np
import pytest
from pick_support import build_pick

import drakegrasp as dg
from drakegrasp.core.tolerances import MONITOR_COUPLING_TOL
from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant.friction import (
    FrictionMismatchWarning,
    pair_friction,
    plant_friction,
)
from drakegrasp.systems.grasp_monitor import GraspMonitor
from drakegrasp.systems.monitor_options import MonitorSettings

BOX = "box::box"
GRIPPED = 1.2  # s: the fingers are closed on the box, before the lift


@pytest.fixture(scope="module")
def gripped():
    """A pick run until the fingers squeeze the box; warnings of the run kept."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pick = build_pick(mu=0.5, distance_tolerance=1e-3)
        pick.run(GRIPPED)
    pick.caught = caught
    return pick


def _evaluate(pick, monitor):
    """One sample of a standalone ``monitor`` at the pick's current state."""
    root = pick.simulator.get_context()
    own = monitor.CreateDefaultContext()
    x = pick.plant.GetPositionsAndVelocities(pick.plant.GetMyContextFromRoot(root))
    monitor.get_plant_state_input_port().FixValue(own, x)
    query = pick.scene_graph.get_query_output_port().Eval(
        pick.scene_graph.GetMyContextFromRoot(root)
    )
    monitor.get_query_object_input_port().FixValue(own, query)
    return monitor.evaluate(own)


def _combined(inspector, id_a, id_b):
    """Drake's rule, written out: the harmonic mean of the dynamic coefficients."""
    a, b = (
        inspector.GetProximityProperties(g)
        .GetProperty("material", "coulomb_friction")
        .dynamic_friction()
        for g in (id_a, id_b)
    )
    return 2 * a * b / (a + b)


def test_options_object_and_keywords_give_the_same_samples(gripped):
    keywords = GraspMonitor(
        gripped.plant, object_body=BOX, mu=1.0, distance_tolerance=1e-3
    )
    # a monitor allows penetration and a simulation's coupler give unless
    # told otherwise; an options object says it itself (AnalysisOptions'
    # defaults are an analysis's: False, COUPLING_TOL)
    options = dg.AnalysisOptions(
        mu=1.0,
        distance_tolerance=1e-3,
        allow_penetration=True,
        coupling_tolerance=MONITOR_COUPLING_TOL,
    )
    given = GraspMonitor(gripped.plant, object_body=BOX, options=options)
    assert given.settings.analysis == options == keywords.settings.analysis
    a, b = _evaluate(gripped, keywords), _evaluate(gripped, given)
    assert a.status == b.status == "ok"
    np.testing.assert_array_equal(a.verdicts, b.verdicts)
    assert a.report.options == b.report.options == options


def test_options_and_a_differing_keyword_are_refused(gripped):
    options = dg.AnalysisOptions(mu=0.5)
    with pytest.raises(InvalidOptionError, match=r"distance_tolerance.*not both"):
        GraspMonitor(
            gripped.plant, object_body=BOX, options=options, distance_tolerance=1e-3
        )
    with pytest.raises(InvalidOptionError, match="options must be an AnalysisOptions"):
        GraspMonitor(gripped.plant, object_body=BOX, options={"mu": 0.5})


def test_a_monitor_needs_mu_and_a_soft_fingers_nu(gripped):
    with pytest.raises(InvalidOptionError, match="needs mu"):
        GraspMonitor(gripped.plant, object_body=BOX)
    with pytest.raises(InvalidOptionError, match="needs mu"):
        GraspMonitor(gripped.plant, object_body=BOX, options=dg.AnalysisOptions())
    with pytest.raises(InvalidOptionError, match="torsional_friction"):
        GraspMonitor(
            gripped.plant, object_body=BOX, mu=0.5, contact_model="soft_finger"
        )


def test_the_simulators_contacts_take_the_plants_mu_when_none_is_given(gripped):
    # Review r22: mu was required in contact_results mode too, where the
    # contacts and their forces are the plant's own.
    monitor = GraspMonitor(gripped.plant, object_body=BOX, contacts="contact_results")
    assert monitor.settings.analysis.mu == "plant"
    given = GraspMonitor(
        gripped.plant, object_body=BOX, contacts="contact_results", mu=0.4
    )
    assert given.settings.analysis.mu == 0.4
    options = GraspMonitor(
        gripped.plant,
        object_body=BOX,
        contacts="contact_results",
        options=dg.AnalysisOptions(),
    )
    assert options.settings.analysis.mu == "plant"
    with pytest.raises(InvalidOptionError, match="torsional_friction"):
        GraspMonitor(
            gripped.plant,
            object_body=BOX,
            contacts="contact_results",
            contact_model="soft_finger",
        )


def test_settings_say_what_the_monitor_does(gripped):
    monitor = GraspMonitor(
        gripped.plant, object_body=BOX, mu="plant", period=0.02, offset=0.01
    )
    s = monitor.settings
    assert isinstance(s, MonitorSettings)
    assert (s.period, s.offset, s.contacts, s.compute_epsilon) == (
        0.02,
        0.01,
        "geometry",
        False,
    )
    d = s.to_dict()
    assert d["analysis"]["mu"] == "plant" and d["thresholds"]["risk"] == 0.8
    assert "mu=plant" in str(s) and "every 0.02 s" in str(s)
    with pytest.raises(Exception):  # noqa: B017 - frozen
        s.period = 1.0


def test_plant_friction_is_drakes_rule_per_pair(gripped):
    sample = _evaluate(
        gripped,
        GraspMonitor(gripped.plant, object_body=BOX, mu=1.0, distance_tolerance=1e-3),
    )
    contacts = sample.report.contacts
    assert len(contacts) >= 2
    root = gripped.simulator.get_context()
    query = gripped.scene_graph.get_query_output_port().Eval(
        gripped.scene_graph.GetMyContextFromRoot(root)
    )
    inspector = query.inspector()
    expected = [
        _combined(inspector, c.object_geometry, c.finger_geometry) for c in contacts
    ]
    mus = plant_friction(gripped.plant, None, contacts, query_object=query)
    np.testing.assert_allclose(mus, expected, rtol=1e-12)
    for c, mu in zip(contacts, expected, strict=True):  # either order of the pair
        pair = (c.object_geometry, c.finger_geometry)
        assert pair_friction(gripped.plant, query, *pair) == pytest.approx(mu)
        assert pair_friction(gripped.plant, query, *pair[::-1]) == pytest.approx(mu)


def test_mu_plant_analyses_with_the_plants_friction(gripped):
    monitor = GraspMonitor(
        gripped.plant, object_body=BOX, mu="plant", distance_tolerance=1e-3
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrictionMismatchWarning)
        sample = _evaluate(gripped, monitor)
    assert sample.status == "ok"
    assert monitor.friction_warning is None
    root = gripped.simulator.get_context()
    query = gripped.scene_graph.get_query_output_port().Eval(
        gripped.scene_graph.GetMyContextFromRoot(root)
    )
    expected = [
        _combined(query.inspector(), c.object_geometry, c.finger_geometry)
        for c in sample.report.contacts
    ]
    used = [c.mu for c in sample.report.grasp.contacts]
    np.testing.assert_allclose(used, expected, rtol=1e-12)
    assert not np.allclose(used, 0.5)  # the plant's, not the typed default


def test_a_typed_mu_that_is_not_the_plants_is_warned_once(gripped):
    mismatch = [w for w in gripped.caught if w.category is FrictionMismatchWarning]
    assert len(mismatch) == 1, [str(w.message) for w in mismatch]
    text = str(mismatch[0].message)
    assert "mu = 0.5 was given but the plant simulates [1.0]" in text
    assert "mu='plant'" in text and "grasp_monitor" in text
    assert gripped.monitor.friction_warning in text
    agreeing = GraspMonitor(
        gripped.plant, object_body=BOX, mu=1.0, distance_tolerance=1e-3
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrictionMismatchWarning)
        assert _evaluate(gripped, agreeing).status == "ok"
    assert agreeing.friction_warning is None


def test_no_warning_before_contact():
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrictionMismatchWarning)
        pick = build_pick(mu=0.5, distance_tolerance=1e-3)
        pick.run(0.3)  # the fingers are still open
    assert pick.monitor.friction_warning is None


def test_a_plant_without_a_scene_graph_is_named():
    # it said the box "has no collision geometry", which its file gives it
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    dg.register_models(parser)
    parser.AddModels(url="package://drakegrasp/objects/box.sdf")
    plant.Finalize()
    with pytest.raises(dg.ModelError, match="not registered with a SceneGraph"):
        dg.GraspMonitor(plant, object_body=plant.GetBodyByName("box"), mu=0.5)


def _jaw_box(**keywords):
    """The default jaw welded at its palm, the box free at 65 mm, a monitor.

    Returns the diagram, its root context, the plant, the hand's instance
    and the monitor; ``keywords`` go to ``add_grasp_monitor``.
    """
    from pydrake.math import RigidTransform
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.framework import DiagramBuilder

    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=1e-3)
    parser = Parser(plant)
    dg.register_models(parser)
    hand = parser.AddModels(url="package://drakegrasp/hands/parallel_jaw.sdf")[0]
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("palm", hand))
    parser.AddModels(url="package://drakegrasp/objects/box.sdf")
    plant.Finalize()
    monitor = dg.add_grasp_monitor(
        builder, plant, scene_graph, object_body=plant.GetBodyByName("box"),
        **keywords,
    )  # fmt: skip
    diagram = builder.Build()
    root = diagram.CreateDefaultContext()
    ctx = plant.GetMyContextFromRoot(root)
    plant.SetFreeBodyPose(
        ctx, plant.GetBodyByName("box"), RigidTransform([0, 0, 0.065])
    )
    return diagram, root, plant, hand, monitor


def _jaw_box_monitor(**keywords):
    _, root, plant, hand, monitor = _jaw_box(mu=0.5, **keywords)

    def sample(q):
        plant.SetPositions(plant.GetMyContextFromRoot(root), hand, q)
        return monitor.evaluate(monitor.GetMyContextFromRoot(root))

    return sample


@pytest.mark.parametrize("q, status", [(0.0249, "ok"), (0.01, "invalid")])
def test_fingers_deep_in_the_object_are_no_grip(q, status):
    # 15 mm inside the box read "holding, force closure 1" (penetration is
    # allowed in a monitor by default: a simulation's contacts sink a little)
    sample = _jaw_box_monitor()([q, q])
    assert sample.status == status
    if status == "invalid":
        assert "15 mm: deeper than max_penetration (5 mm)" in sample.message
        assert sample.holding == "no contact"  # the grip before it is kept
    deeper = _jaw_box_monitor(holding=dg.HoldingThresholds(max_penetration=0.02))
    assert deeper([q, q]).status == "ok"


def test_a_falling_box_reads_as_sliding():
    # the box falls between jaws that press with nothing: the sample said
    # "slip 0 mm/s" beside its own sliding speed of 0.49 m/s, and "no contact
    # in this sample ()" with empty parentheses
    from pydrake.systems.analysis import Simulator

    diagram, root, plant, hand, monitor = _jaw_box(
        mu="plant", load="gravity", torque_limits="plant"
    )
    plant.SetPositions(plant.GetMyContextFromRoot(root), hand, [0.025, 0.025])
    simulator = Simulator(diagram, root)
    simulator.AdvanceTo(0.051)
    sample = monitor.get_output_port(1).Eval(monitor.GetMyContextFromRoot(root))
    assert sample.sliding_speed > 0.1
    line = str(sample).splitlines()[0]
    assert f"sliding {1e3 * sample.sliding_speed:.3g} mm/s along the fingers" in line
    assert "()" not in line


def test_max_penetration_must_exceed_the_distance_tolerance():
    # depths within the tolerance are contacts: 5-8 mm went unjudged at 8 mm
    with pytest.raises(InvalidOptionError, match="max_penetration = 0.005 m must"):
        _jaw_box_monitor(
            distance_tolerance=0.008,
            holding=dg.HoldingThresholds(release_distance=0.01),
        )
    _jaw_box_monitor(
        distance_tolerance=0.008,
        holding=dg.HoldingThresholds(max_penetration=0.01, release_distance=0.01),
    )
