"""GraspMonitor in a running simulation, checked against a second route.

The pick of ``pick_support.py`` (the shipped parallel-jaw gripper closes on a free box
under gravity, lifts it 5 cm, lowers it and opens) runs in a ``Simulator``.
The monitor's logged verdicts must go "no contact" -> "force closure" ->
"no contact", and every sample must equal what ``analyze_grasp`` says on the
logged plant state, evaluated through the diagram's own scene graph (not the
monitor's private context and query input).

Drake's sample-and-hold: a log taken at a sample time t_k shows the value held
before the update at t_k, so the verdict logged at t_{k+1} is the sample of
the state logged at t_k.
"""

import json

import numpy as np
import pytest
from pick_support import DURATION, LIFT, build_pick
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError
from drakegrasp.systems.monitor import VERDICT_NAMES, GraspMonitor, GraspSample

# The monitors analyse with mu = 0.5, half what the plant simulates (a
# conservative check), and say so once per monitor: that warning is expected.
pytestmark = pytest.mark.filterwarnings(
    "ignore::drakegrasp.plant.friction.FrictionMismatchWarning"
)

SOFT = {"contact_model": "soft_finger", "torsional_friction": 0.1}
OPTIONS = {"mu": 0.5, "distance_tolerance": 1e-3}
EPS = {"compute_epsilon": True}


def _runs(values: np.ndarray) -> list[float]:
    """The sequence of distinct consecutive values."""
    out: list[float] = []
    for v in values:
        if not out or v != out[-1]:
            out.append(float(v))
    return out


def _not_separating(plant, plant_context, box, contacts, speed=5e-3):
    """Contacts whose points do not move apart faster than ``speed`` (m/s).

    A second route to the monitor's filter: velocities from translational
    Jacobians (J_v v), not from the bodies' spatial velocities.  The pick's
    plant is SAP, which opens a sliding contact at ``μ ‖v_t‖`` while it
    pushes: that much opening is allowed too, with ``μ`` the pair's dynamic
    coefficient combined by Drake (``CalcContactFrictionFromSurfaceProperties``).
    """
    from pydrake.multibody.plant import CalcContactFrictionFromSurfaceProperties
    from pydrake.multibody.tree import JacobianWrtVariable

    world = plant.world_frame()
    v = plant.GetVelocities(plant_context)
    R_WO = plant.EvalBodyPoseInWorld(plant_context, box).rotation().matrix()
    kept = []
    for c in contacts:
        finger = plant.get_body(c.finger_body_index)
        J = [
            plant.CalcJacobianTranslationalVelocity(
                plant_context, JacobianWrtVariable.kV, frame, p, world, world
            )
            for frame, p in ((box.body_frame(), c.p_OC), (finger.body_frame(), c.p_FC))
        ]
        v_rel = (J[0] - J[1]) @ v
        n = R_WO @ c.nhat_O
        apart = v_rel @ n
        tangential = np.linalg.norm(v_rel - apart * n)
        query = plant.get_geometry_query_input_port().Eval(plant_context)
        props = [
            query.inspector()
            .GetProximityProperties(g)
            .GetProperty("material", "coulomb_friction")
            for g in (c.object_geometry, c.finger_geometry)
        ]
        mu = CalcContactFrictionFromSurfaceProperties(*props).dynamic_friction()
        if apart <= speed + mu * tangential:
            kept.append(c)
    return kept


def _second_route(pick, x, **options) -> np.ndarray:
    """Verdicts of analyze_grasp on state x, in a fresh diagram context."""
    context = pick.diagram.CreateDefaultContext()
    plant_context = pick.plant.GetMyMutableContextFromRoot(context)
    pick.plant.SetPositionsAndVelocities(plant_context, x)
    box = pick.plant.GetBodyByName("box", pick.box)
    try:
        found = dg.find_contacts(
            pick.plant,
            plant_context,
            object_body=box,
            hand=pick.gripper,
            distance_tolerance=options["distance_tolerance"],
        )
        found = _not_separating(pick.plant, plant_context, box, found)
        if not found:
            raise dg.NoContactsError("all separating")
        r = dg.analyze_grasp(
            pick.plant,
            plant_context,
            object_body=box,
            hand=pick.gripper,
            contacts=found,
            **options,
        )
    except dg.NoContactsError:
        return np.zeros(len(VERDICT_NAMES))
    eps = dg.ferrari_canny(r.grasp) if r.is_force_closure else 0.0
    antipodal = r.antipodal is not None and r.antipodal.is_antipodal
    return np.array(
        [
            1.0,
            r.force_closure.is_closure,
            r.form_closure.is_closure,
            antipodal,
            r.grasp.num_contacts,
            r.force_closure.d_star,
            eps,
        ],
        dtype=float,
    )


@pytest.fixture(scope="module")
def point_pick():
    pick = build_pick(plant_contact="point", **OPTIONS, **SOFT, **EPS)
    pick.run()
    return pick


def test_point_contact_pick_timeline(point_pick):
    context = point_pick.simulator.get_context()
    log = point_pick.verdict_log.FindLog(context)
    times, verdicts = log.sample_times(), log.data()
    status = verdicts[GraspMonitor.STATUS]
    closure = verdicts[GraspMonitor.FORCE_CLOSURE]
    print(
        "verdict timeline:",
        [
            (round(float(times[k]), 3), int(status[k]), int(closure[k]))
            for k in range(len(times))
            if k == 0 or status[k] != status[k - 1] or closure[k] != closure[k - 1]
        ],
    )
    assert _runs(status) == [0.0, 1.0, 0.0]
    # While the hand opens (2.3 - 2.6 s) a finger whose points separate faster
    # than the separation speed is no contact, so closure may flicker there.
    assert _runs(closure[times <= 2.3]) == [0.0, 1.0]
    assert np.all(closure[times > 2.65] == 0.0)
    held = times[closure == 1.0]
    # Closing starts at 0.3 s (contact near 0.55 s); opening at 2.3 s.
    assert 0.4 < held[0] < 0.75 and 2.3 < held[-1] < 2.65
    # While held, two antipodal soft-finger contacts with a positive margin.
    assert np.all(verdicts[GraspMonitor.NUM_CONTACTS][closure == 1.0] == 2)
    assert np.all(verdicts[GraspMonitor.ANTIPODAL][closure == 1.0] == 1)
    assert np.all(verdicts[GraspMonitor.D_STAR][closure == 1.0] > 1e-3)
    assert np.all(verdicts[GraspMonitor.EPSILON][closure == 1.0] > 0)
    # The box really was lifted while in force closure.
    states = point_pick.state_log.FindLog(context)
    plant = point_pick.plant
    plant_context = plant.CreateDefaultContext()
    box = plant.GetBodyByName("box", point_pick.box)
    heights = []
    for x in states.data().T:
        plant.SetPositionsAndVelocities(plant_context, x)
        heights.append(plant.EvalBodyPoseInWorld(plant_context, box).translation()[2])
    heights = np.array(heights)
    lifted = np.isclose(times, 1.6)
    assert heights[lifted][0] > 0.05 + 0.9 * LIFT
    assert np.all(heights[:5] < 0.0505) and np.all(heights[-5:] < 0.0505)
    # Every sample while the box hung in the air was force closure (the log
    # lags the state by one sample).
    airborne = np.flatnonzero(heights > 0.052)
    assert len(airborne) > 10 and np.all(closure[airborne + 1] == 1.0)


def test_point_contact_monitor_matches_analyze_grasp(point_pick):
    context = point_pick.simulator.get_context()
    states = point_pick.state_log.FindLog(context)
    verdicts = point_pick.verdict_log.FindLog(context)
    np.testing.assert_array_equal(states.sample_times(), verdicts.sample_times())
    X, V = states.data(), verdicts.data()
    assert X.shape[1] == round(DURATION / point_pick.monitor.period) + 1
    for k in range(X.shape[1] - 1):
        expected = _second_route(point_pick, X[:, k], **OPTIONS, **SOFT)
        gap = int(V[GraspMonitor.CONTACT_GAP, k + 1])
        if gap > 0:  # a bridged gap: the analysis of the last sample with contact
            expected = _second_route(point_pick, X[:, k - gap], **OPTIONS, **SOFT)
        np.testing.assert_allclose(
            V[: len(VERDICT_NAMES), k + 1],
            expected,
            rtol=1e-9,
            atol=1e-12,
            err_msg=f"sample {k}",
        )


def test_report_port_holds_the_last_sample(point_pick):
    context = point_pick.simulator.get_context()
    monitor_context = point_pick.monitor.GetMyContextFromRoot(context)
    sample = point_pick.monitor.get_report_output_port().Eval(monitor_context)
    assert isinstance(sample, GraspSample)
    period = point_pick.monitor.period
    assert sample.time == pytest.approx(DURATION - period)
    assert sample.status == "no contact" and sample.report is None
    assert "does not touch" in sample.message
    assert json.loads(json.dumps(sample.to_dict()))["status"] == "no contact"
    np.testing.assert_array_equal(
        sample.verdicts,
        point_pick.monitor.get_verdicts_output_port().Eval(monitor_context),
    )


@pytest.fixture(scope="module")
def hydro_pick():
    """Flat pads, hydroelastic contact, contacts from the contact results.

    Also returns the live sample while the box is lifted (t = 1.6 s): a
    discrete plant's contact results come from its last step, so they exist
    only in the simulator's own context, not in a fresh one.
    """
    pick = build_pick(
        plant_contact="hydroelastic_with_fallback",
        flat=True,
        contacts="contact_results",
        **OPTIONS,
    )
    pick.run(1.6)
    context = pick.monitor.GetMyContextFromRoot(pick.simulator.get_context())
    lifted = pick.monitor.evaluate(context)
    pick.run()
    return pick, lifted


def test_hydroelastic_pick_timeline(hydro_pick):
    pick, _ = hydro_pick
    log = pick.verdict_log.FindLog(pick.simulator.get_context())
    V = log.data()
    closure = V[GraspMonitor.FORCE_CLOSURE]
    assert _runs(V[GraspMonitor.STATUS]) == [0.0, 1.0, 0.0]
    assert _runs(closure) == [0.0, 1.0, 0.0]
    # Hard fingers: two flat patches (a 4-vertex polygon each) resist torsion.
    assert set(V[GraspMonitor.NUM_CONTACTS][closure == 1.0]) == {8.0}


@pytest.mark.parametrize("fixture", ["point_pick", "hydro_pick"])
def test_opening_the_hand_is_a_release_not_a_drop(fixture, request):
    # The box is set down (1.8 - 2.3 s) and the hand opens (2.3 - 2.6 s): the
    # grip ends in "no contact", never "dropped" (the box did not fall).
    pick = request.getfixturevalue(fixture)
    pick = pick[0] if isinstance(pick, tuple) else pick
    log = pick.verdict_log.FindLog(pick.simulator.get_context())
    times, codes = log.sample_times(), log.data()[GraspMonitor.HOLDING]
    states = [dg.HOLDING_STATES[int(c)] for c in codes]
    assert "dropped" not in states
    assert "holding" in states
    assert {s for t, s in zip(times, states, strict=True) if t > 2.7} == {"no contact"}


def test_hydroelastic_patches_match_the_geometry(hydro_pick):
    pick, sample = hydro_pick
    assert sample.status == "ok", sample.message
    report = sample.report
    normals = np.array([c.nhat_O for c in report.contacts])
    np.testing.assert_allclose(np.abs(normals[:, 1]), 1.0, atol=1e-6)
    assert sorted(np.sign(normals[:, 1])) == [-1] * 4 + [1] * 4
    p = np.array([c.p_OC for c in report.contacts])
    np.testing.assert_allclose(np.abs(p[:, 1]), 0.025, atol=1e-3)  # box faces
    assert np.all(np.abs(p[:, 0]) <= 0.0101)  # inside the 20 x 20 mm pads
    assert {c.normal_source for c in report.contacts} == {"hydroelastic"}
    as_json = json.loads(json.dumps(sample.to_dict()))
    assert as_json["verdicts"]["num_contacts"] == 8
    assert len(as_json["report"]["contacts"]) == 8
    assert "8 contacts, force closure YES" in str(sample)
    # ε was not asked for: 0 on the port, but not printed as a measured 0.
    if sample.epsilon == 0.0:
        assert "eps not computed" in str(sample)
    # Signed distances on the same state find the same two patches.
    geometric = _second_route(pick, sample.state, **OPTIONS)
    assert geometric[GraspMonitor.FORCE_CLOSURE] == 1.0
    assert geometric[GraspMonitor.NUM_CONTACTS] == 8
    assert report.force_closure.d_star == pytest.approx(
        geometric[GraspMonitor.D_STAR], rel=0.05
    )


def _squeezed(pick, depth: float):
    """A sample of ``pick``'s monitor with the pads ``depth`` (m) into the box."""
    return _squeezed_in(pick, pick.diagram.CreateDefaultContext(), depth)


def _squeezed_in(pick, context, depth: float):
    """:func:`_squeezed` in a root ``context`` of ``pick``'s diagram."""
    plant = pick.plant
    plant_context = plant.GetMyMutableContextFromRoot(context)
    for name in ("left_finger_joint", "right_finger_joint"):
        plant.GetJointByName(name, pick.gripper).set_translation(
            plant_context,
            0.025 - depth,  # the 50 mm box between pads at ±25 mm
        )
    box = plant.GetBodyByName("box", pick.box)
    plant.SetFreeBodyPose(plant_context, box, RigidTransform([0.0, 0.0, 0.05]))
    return pick.monitor.evaluate(pick.monitor.GetMyContextFromRoot(context))


def test_deep_penetration_is_an_invalid_sample_when_refused():
    pick = build_pick(plant_contact="point", allow_penetration=False, **OPTIONS)
    sample = _squeezed(pick, 3e-3)
    assert sample.status == "invalid"
    assert "penetrat" in sample.message
    assert sample.verdicts[GraspMonitor.STATUS] == -1.0


def test_a_firm_grip_that_penetrates_is_analysed_by_default():
    # The WSG-50 squeezing with 20 N sinks 0.145 mm into a box in point
    # contact; at the default 0.1 mm tolerance every such sample was
    # "invalid" (force closure 0, no contacts) while the object was held.
    pick = build_pick(plant_contact="point", mu=0.5, **SOFT)  # rounded pads
    sample = _squeezed(pick, 0.15e-3)
    assert sample.status != "invalid", sample.message
    assert sample.verdicts[GraspMonitor.FORCE_CLOSURE] == 1.0
    assert sample.verdicts[GraspMonitor.NUM_CONTACTS] > 0


def test_bad_options_fail_at_construction(point_pick):
    plant, box = point_pick.plant, "box::box"
    with pytest.raises(InvalidOptionError, match="period"):
        GraspMonitor(plant, object_body=box, mu=0.5, period=0.0)
    with pytest.raises(InvalidOptionError, match="contacts must be"):
        GraspMonitor(plant, object_body=box, mu=0.5, contacts="magic")
    with pytest.raises(InvalidOptionError, match="torsional_friction"):
        GraspMonitor(plant, object_body=box, mu=0.5, contact_model="soft_finger")
    with pytest.raises(dg.GraspError, match="mu"):
        GraspMonitor(plant, object_body=box, mu=-1.0)
    with pytest.raises(InvalidOptionError, match="finalized"):
        GraspMonitor(MultibodyPlant(0.0), object_body=box, mu=0.5)
    with pytest.raises(dg.ModelError, match="no body named"):
        GraspMonitor(plant, object_body="box::nothing", mu=0.5)
    geometric = GraspMonitor(plant, object_body=box, mu=0.5)
    with pytest.raises(InvalidOptionError, match="contact_results"):
        geometric.get_contact_results_input_port()


def test_joint_off_its_limits_is_an_invalid_sample(point_pick):
    context = point_pick.diagram.CreateDefaultContext()
    plant = point_pick.plant
    plant_context = plant.GetMyMutableContextFromRoot(context)
    plant.GetJointByName("left_finger_joint", point_pick.gripper).set_translation(
        plant_context,
        0.05,  # upper limit 0.0425
    )
    monitor_context = point_pick.monitor.GetMyContextFromRoot(context)
    sample = point_pick.monitor.evaluate(monitor_context)
    assert sample.status == "invalid"
    assert "left_finger_joint" in sample.message
    # With check_pose=False the same pose is analysed, and marked invalid.
    unchecked = GraspMonitor(
        plant,
        object_body="box::box",
        hand=point_pick.gripper,
        mu=0.5,
        check_pose=False,
    )
    own = unchecked.CreateDefaultContext()
    unchecked.get_plant_state_input_port().FixValue(
        own, plant.GetPositionsAndVelocities(plant_context)
    )
    scene_graph = point_pick.scene_graph
    query = scene_graph.get_query_output_port().Eval(
        scene_graph.GetMyContextFromRoot(context)
    )
    unchecked.get_query_object_input_port().FixValue(own, query)
    analysed = unchecked.evaluate(own)
    assert analysed.status == "ok"
    assert not analysed.report.pose.valid
    assert "left_finger_joint" in str(analysed.report)


def test_epsilon_at_a_length_out_of_scale_is_nan_and_said_not_a_crash():
    """``characteristic_length=1e-15`` with ``compute_epsilon``: the ε of every
    force-closure sample is refused (contacts ~3 cm apart), which ended the
    simulation with an ``InvalidOptionError`` at the first grip; now the sample
    carries ε = NaN and says why, and the rest of the analysis is unchanged."""
    pick = build_pick(
        plant_contact="point", **OPTIONS, **SOFT, **EPS, characteristic_length=1e-15
    )
    pick.run(1.2)  # gripped and lifting
    context = pick.monitor.GetMyContextFromRoot(pick.simulator.get_context())
    sample = pick.monitor.evaluate(context)
    assert sample.status == "ok"
    assert sample.report.is_force_closure
    assert np.isnan(sample.epsilon)
    assert "epsilon not computed: characteristic_length = 1e-15 m" in sample.message
    log = pick.verdict_log.FindLog(pick.simulator.get_context()).data()
    closed = log[GraspMonitor.FORCE_CLOSURE] == 1
    assert closed.any() and np.isnan(log[GraspMonitor.EPSILON][closed]).all()


def test_a_mass_set_in_the_simulation_is_used_once_copied():
    # The monitor analyses in a plant context of its own: a mass set in the
    # simulation's context (mass randomisation) reached no port, and the
    # gravity load kept the model's 0.2 kg
    pick = build_pick(plant_contact="point", mu=1.0, load="gravity", **SOFT)
    box = pick.plant.GetBodyByName("box", pick.box)

    def weight(mass: float | None) -> float:
        context = pick.diagram.CreateDefaultContext()
        plant_context = pick.plant.GetMyMutableContextFromRoot(context)
        box.SetMass(plant_context, 3.0)
        if mass is not None:
            pick.monitor.use_parameters_of(context)
        sample = _squeezed_in(pick, context, 1e-4)
        return float(np.linalg.norm(sample.report.load.wrench[:3]))

    assert weight(None) == pytest.approx(0.2 * 9.81, rel=1e-9)
    assert weight(3.0) == pytest.approx(3.0 * 9.81, rel=1e-9)
