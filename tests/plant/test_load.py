"""Grasps under load from a plant: gravity, actuator limits, the plant's friction."""

import json
import warnings

import numpy as np
import pytest
from pydrake.multibody.tree import JointActuatorIndex

import drakegrasp as dg
from drakegrasp.plant.friction import plant_friction
from drakegrasp.plant.load import gravity_wrench, plant_torque_limits


@pytest.fixture
def wsg_closed(real_hands):
    scene = real_hands.wsg()
    dg.close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    return scene


def _analyze(s, **options):
    """``analyze_grasp`` of scene ``s``'s object and hand."""
    return dg.analyze_grasp(s.plant, s.ctx, s.object, hand=s.hand, **options)


def test_gravity_wrench_matches_the_plants_generalized_gravity(wsg_closed):
    s = wsg_closed
    w = gravity_wrench(s.plant, s.ctx, s.object)
    mass = s.object.get_mass(s.ctx)
    assert mass == pytest.approx(0.514, rel=1e-3)  # the YCB sugar box
    assert np.linalg.norm(w[:3]) == pytest.approx(mass * 9.81, rel=1e-9)
    # Independent route: Drake's generalized gravity forces on the free body's
    # velocities are [torque; force] in W about the body origin.
    tau_g = s.plant.CalcGravityGeneralizedForces(s.ctx)
    v0 = s.object.floating_velocities_start_in_v()
    R_WO = s.plant.EvalBodyPoseInWorld(s.ctx, s.object).rotation().matrix()
    expected = np.concatenate(
        [R_WO.T @ tau_g[v0 + 3 : v0 + 6], R_WO.T @ tau_g[v0 : v0 + 3]]
    )
    np.testing.assert_allclose(w, expected, atol=1e-12)


def test_wsg_holds_the_sugar_box_with_its_motors(wsg_closed):
    s = wsg_closed
    report = _analyze(s, mu=0.5, load="gravity", torque_limits="plant")
    load = report.load
    np.testing.assert_array_equal(load.torque_limits, [80.0, 80.0])  # the SDF's
    assert load.torque_limits_source == "plant"
    assert load.holds
    f = load.forces
    assert f.joint_torques == pytest.approx(report.J.T @ f.stacked_forces())
    # The pads squeeze along O's z; the weight lies in their plane: friction
    # alone carries it, so Σ f_n >= m g / μ.
    assert f.squeeze >= np.linalg.norm(load.wrench[:3]) / 0.5 * (1 - 1e-7)
    assert load.payload.alpha > 1.0
    assert load.payload.certificate.check(report.grasp, hand_jacobian=report.J)
    assert load.first_saturating_joint in load.joint_names
    assert load.joint_names == (
        "left_finger_sliding_joint",
        "right_finger_sliding_joint",
    )
    # the model's pads have μ = 1 (continuous plant: the static coefficient)
    assert load.friction_rule == "static"
    np.testing.assert_allclose(load.mu_plant, 1.0)
    assert any("mu = 0.5 was given" in w for w in load.warnings)
    text = str(report)
    assert "Load (gravity" in text and "payload factor" in text
    json.dumps(report.to_dict())


def test_mu_from_the_plant_and_weak_motors(wsg_closed):
    s = wsg_closed
    weak = _analyze(s, mu="plant", load="gravity", torque_limits=[1.0, 1.0])
    assert [c.mu for c in weak.grasp.contacts] == pytest.approx([1.0] * 8)
    assert not weak.load.warnings
    assert not weak.load.holds
    cert = weak.load.forces.certificate
    assert cert.check(weak.grasp, hand_jacobian=weak.J).holds
    assert weak.load.payload.alpha < 1.0
    strong = _analyze(s, mu="plant", load="gravity", torque_limits="plant")
    # payload scales with the motors while they are what binds
    if strong.load.payload.saturating_joints:
        assert strong.load.payload.alpha == pytest.approx(
            80.0 * weak.load.payload.alpha, rel=1e-4
        )
    with pytest.raises(dg.InvalidOptionError, match="load"):
        _analyze(s, mu=0.5, torque_limits="plant")
    with pytest.raises(dg.InvalidOptionError, match="mu"):
        _analyze(s, mu="model")


def test_torque_limits_and_friction_read_from_the_models(real_hands):
    s = real_hands.allegro()
    dg.close_hand(s.plant, s.root, s.object, hand=s.hand)
    report = _analyze(s, mu=0.8, load="gravity", torque_limits="plant")
    limits = report.load.torque_limits
    assert limits.shape == (16,)
    # every Allegro joint has an actuator with the SDF's 0.7 N·m effort limit
    np.testing.assert_allclose(limits, 0.7)
    for k in range(s.plant.num_actuators()):
        a = s.plant.get_joint_actuator(JointActuatorIndex(k))
        assert a.effort_limit() == pytest.approx(0.7)
    mu = plant_friction(s.plant, s.ctx, report.contacts)
    assert mu.shape == (report.grasp.num_contacts,)
    assert np.all(mu > 0)
    assert plant_torque_limits(s.plant, report.data.hand_velocity_indices) == (
        pytest.approx(limits)
    )
    f = report.load.forces
    if f.feasible:
        assert np.all(np.abs(f.joint_torques) <= 0.7 * (1 + 1e-6))
    else:
        assert f.certificate.check(report.grasp, hand_jacobian=report.J).holds
    json.dumps(report.load.to_dict())


def test_a_zero_load_is_held_and_has_no_payload_factor():
    # A zero wrench was refused with "direction must be a non-zero wrench",
    # naming an argument of max_load the caller never gave.
    s = dg.load_scene("three_finger_sphere")
    r = dg.analyze_grasp(
        s.plant, s.plant_context, s.object_body, hand=s.hand, mu=0.5, load=[0.0] * 6
    )
    assert r.load.holds and r.load.payload is None
    assert r.load.forces.squeeze == pytest.approx(0.0, abs=1e-8)
    assert "payload factor: none" in str(r.load)
    assert json.loads(json.dumps(r.to_dict()))["load"]["payload"] is None


def _jaw_box_scene(tmp_path, effort: str):
    """The default scene with its jaw's ``<effort>`` replaced by ``effort``."""
    from drakegrasp.plant.models import models_dir

    root = models_dir()
    hand = (root / "hands" / "parallel_jaw.sdf").read_text()
    assert hand.count("<effort>140.0</effort>") == 2
    (tmp_path / "jaw.sdf").write_text(hand.replace("<effort>140.0</effort>", effort))
    scene = (root / "scenes" / "parallel_jaw_box.yaml").read_text()
    scene = scene.replace("package://drakegrasp/hands/parallel_jaw.sdf", "jaw.sdf")
    (tmp_path / "scene.yaml").write_text(scene)
    return dg.load_scene(tmp_path / "scene.yaml")


@pytest.mark.parametrize("effort", ["", "<effort>-1</effort>"])
def test_actuators_without_an_effort_limit_are_named(tmp_path, effort):
    # Drake gives an SDFormat joint without <effort> (or with -1) an actuator
    # of infinite effort: the plant's limits bound nothing, and the report
    # said "payload factor unbounded" as if the motors were that strong.
    s = _jaw_box_scene(tmp_path, effort)
    report = dg.analyze_grasp(
        s.plant, s.plant_context, s.object_body, hand=s.hand, mu=0.5,
        load="gravity", torque_limits="plant",
    )  # fmt: skip
    assert np.all(np.isinf(report.load.torque_limits))
    said = [w for w in report.load.warnings if "no effort limit" in w]
    assert len(said) == 1
    assert "'left_finger_joint', 'right_finger_joint'" in said[0]
    assert "no effort limit" in str(report)
    # given limits, or the model's own, are not warned of
    given = dg.analyze_grasp(
        s.plant, s.plant_context, s.object_body, hand=s.hand, mu=0.5,
        load="gravity", torque_limits=[50.0, 50.0],
    )  # fmt: skip
    assert not any("no effort limit" in w for w in given.load.warnings)
    own = _jaw_box_scene(tmp_path, "<effort>140.0</effort>")
    report = dg.analyze_grasp(
        own.plant, own.plant_context, own.object_body, hand=own.hand, mu=0.5,
        load="gravity", torque_limits="plant",
    )  # fmt: skip
    np.testing.assert_array_equal(report.load.torque_limits, [140.0, 140.0])
    assert not any("no effort limit" in w for w in report.load.warnings)


@pytest.mark.parametrize("size, held", [(1e300, True), (1e301, None), (1e308, None)])
def test_a_load_too_large_to_compute_with_is_refused(size, held):
    # 1e308 printed "-inf" beside numpy's overflow warnings and a verdict
    s = dg.load_scene("parallel_jaw_box")
    load = [0.0, 0.0, -size, 0.0, 0.0, 0.0]
    if held is None:
        with pytest.raises(dg.InvalidOptionError, match="at most 1e\\+300"):
            dg.analyze_grasp(
                s.plant, s.plant_context, s.object_body, hand=s.hand, mu=0.5, load=load
            )
        return
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # no overflow on the way
        report = dg.analyze_grasp(
            s.plant, s.plant_context, s.object_body, hand=s.hand, mu=0.5, load=load
        )
    assert report.load.holds is held
    assert np.all(np.isfinite(report.load.wrench))


def test_joints_without_an_actuator_are_named(tmp_path):
    # "holds: NO ... (bound 0)" never said that the model had no motors
    s = _jaw_box_scene(tmp_path, "<effort>0</effort>")
    assert s.plant.num_actuators() == 0  # Drake adds none for a zero effort
    report = dg.analyze_grasp(
        s.plant, s.plant_context, s.object_body, hand=s.hand, mu=0.5,
        load="gravity", torque_limits="plant",
    )  # fmt: skip
    np.testing.assert_array_equal(report.load.torque_limits, [0.0, 0.0])
    said = [w for w in report.load.warnings if "no actuator" in w]
    assert len(said) == 1
    assert "'left_finger_joint', 'right_finger_joint' have no actuator" in said[0]


def test_object_mass_weighs_that_mass_at_the_models_centre_of_mass(tmp_path):
    """``object_mass`` scales the model's weight; the report equals a given wrench.

    Independent routes: the gravity wrench is linear in the mass (the
    model's weight times m / m_model), and the load section of
    ``load="gravity", object_mass=m`` is that of the same wrench given.
    """
    s = dg.load_scene("parallel_jaw_box")
    own = gravity_wrench(s.plant, s.plant_context, s.object_body)
    m_model = s.object_body.get_mass(s.plant_context)
    for m in (1e-6, 0.3, 2.0, 1e4):
        w = gravity_wrench(s.plant, s.plant_context, s.object_body, mass=m)
        np.testing.assert_allclose(w, own * (m / m_model), rtol=1e-14, atol=0)
    common = dict(hand=s.hand, mu=0.5, torque_limits=[3.0, 3.0])
    heavy = dg.analyze_grasp(
        s.plant, s.plant_context, s.object_body, load="gravity", object_mass=2.0,
        **common,
    )  # fmt: skip
    given = dg.analyze_grasp(
        s.plant, s.plant_context, s.object_body, load=own * (2.0 / m_model),
        **common,
    )  # fmt: skip
    np.testing.assert_allclose(heavy.load.wrench, given.load.wrench, rtol=1e-14)
    assert heavy.load.holds is given.load.holds
    assert heavy.load.payload.alpha == pytest.approx(given.load.payload.alpha, rel=1e-9)
    # the payload factor scales as 1 / m: a load twice as heavy, half the factor
    light = dg.analyze_grasp(
        s.plant, s.plant_context, s.object_body, load="gravity", object_mass=1.0,
        **common,
    )  # fmt: skip
    assert light.load.payload.alpha == pytest.approx(
        2.0 * heavy.load.payload.alpha, rel=1e-6
    )
    assert heavy.load.object_mass == 2.0 and given.load.object_mass is None
    assert "Load (gravity of 2 kg given" in str(heavy)
    assert json.loads(json.dumps(heavy.to_dict()))["load"]["object_mass"] == 2.0
    assert heavy.options.object_mass == 2.0


@pytest.mark.parametrize(
    "options, words",
    [
        ({"object_mass": 2.0}, "needs load 'gravity', got None"),
        ({"object_mass": 2.0, "load": [0.0] * 6}, "needs load 'gravity'"),
        ({"object_mass": 0.0, "load": "gravity"}, "finite mass > 0"),
        ({"object_mass": float("nan"), "load": "gravity"}, "finite mass > 0"),
        ({"object_mass": 1e308, "load": "gravity"}, "is more than 1e+300"),
    ],
)
def test_an_object_mass_without_gravity_or_out_of_range_is_refused(options, words):
    s = dg.load_scene("parallel_jaw_box")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # no overflow on the way
        with pytest.raises(dg.InvalidOptionError, match=words.replace("+", "\\+")):
            dg.analyze_grasp(
                s.plant, s.plant_context, s.object_body, hand=s.hand, mu=0.5,
                **options,
            )  # fmt: skip


def _jaw_limits_scene(tmp_path, lower, *, flipped=False, mimic=False):
    """The default scene, its jaw's closed limits at ``lower`` (m).

    ``flipped``: the joints' axes and values negated, so that the fingers
    close towards their *upper* limits (``-lower``).  ``mimic``: the right
    finger follows the left (one independent coordinate).
    """
    from drakegrasp.plant.models import models_dir

    root = models_dir()
    hand = (root / "hands" / "parallel_jaw.sdf").read_text()
    old = "<lower>0.0</lower><upper>0.0425</upper>"
    assert hand.count(old) == 2
    new = f"<lower>{lower}</lower><upper>0.0425</upper>"
    if flipped:
        new = f"<lower>-0.0425</lower><upper>{-lower}</upper>"
        hand = hand.replace("<xyz>0.0 1.0 0.0</xyz>", "<xyz>@0.0 -1.0 0.0</xyz>")
        hand = hand.replace("<xyz>0.0 -1.0 0.0</xyz>", "<xyz>0.0 1.0 0.0</xyz>")
        hand = hand.replace("<xyz>@", "<xyz>")
    hand = hand.replace(old, new)
    if mimic:
        j = hand.index("</joint>", hand.index('name="right_finger_joint"'))
        follow = "<drake:mimic joint='left_finger_joint' multiplier='1' offset='0'/>"
        hand = hand[:j] + follow + hand[j:]
    (tmp_path / "jaw.sdf").write_text(hand)
    scene = (root / "scenes" / "parallel_jaw_box.yaml").read_text()
    scene = scene.replace("package://drakegrasp/hands/parallel_jaw.sdf", "jaw.sdf")
    if flipped:
        scene = scene.replace("_finger_joint: [0.025]", "_finger_joint: [-0.025]")
    (tmp_path / "scene.yaml").write_text(scene)
    return dg.load_scene(tmp_path / "scene.yaml")


@pytest.mark.parametrize("flipped", [False, True])
@pytest.mark.parametrize("mimic", [False, True])
@pytest.mark.parametrize(
    "lower, warned", [(0.0, False), (0.02496, True), (0.025, True)]
)
def test_joints_that_would_press_on_their_limits_are_warned_of(
    tmp_path, lower, warned, mimic, flipped
):
    # A jaw 0.05 mm from its closed limit read "holds: yes, payload 10.9",
    # and Drake dropped the rod at any squeeze up to the motors' 8 N.  The
    # default scene's fingers sit 25 mm from their closed limits: a limit
    # within the contact tolerance (0.1 mm) of that is warned of, whether
    # the fingers close towards their lower or (axes flipped) upper limits,
    # and for a follower of a coupling (review: the leaders alone were read).
    s = _jaw_limits_scene(tmp_path, lower, flipped=flipped, mimic=mimic)
    report = dg.analyze_grasp(
        s.plant, s.plant_context, s.object_body, hand=s.hand, mu=0.5, load="gravity"
    )
    said = [w for w in report.load.warnings if "press on the limit" in w]
    assert bool(said) is warned
    if warned:
        assert "'left_finger_joint', 'right_finger_joint'" in said[0]
        assert "press on the limit" in str(report)
    # no torque towards a limit, no warning: a zero load needs none
    free = dg.analyze_grasp(
        s.plant, s.plant_context, s.object_body, hand=s.hand, mu=0.5, load=[0.0] * 6
    )
    assert not any("press on the limit" in w for w in free.load.warnings)


def test_a_joint_that_moves_no_contact_is_not_warned_of(tmp_path):
    # a lift joint 0.1 m from its limits, carrying the weight by friction,
    # read "presses towards its limit": moving no contact (dψ/dq = 0), its
    # reach was 0 and any distance passed the test (fuzzer)
    from drakegrasp.plant.models import models_dir

    root = models_dir()
    hand = (root / "hands" / "parallel_jaw.sdf").read_text()
    i = hand.index('<link name="palm">')
    lift = (
        '<link name="base"><inertial><mass>0.1</mass><inertia><ixx>1e-4</ixx>'
        "<ixy>0</ixy><ixz>0</ixz><iyy>1e-4</iyy><iyz>0</iyz><izz>1e-4</izz>"
        '</inertia></inertial></link><joint name="lift_joint" type="prismatic">'
        "<parent>base</parent><child>palm</child><axis><xyz>0 0 1</xyz><limit>"
        "<lower>-0.1</lower><upper>0.1</upper><effort>100</effort></limit></axis>"
        "</joint>"
    )
    (tmp_path / "jaw.sdf").write_text(hand[:i] + lift + hand[i:])
    scene = (root / "scenes" / "parallel_jaw_box.yaml").read_text()
    scene = scene.replace("package://drakegrasp/hands/parallel_jaw.sdf", "jaw.sdf")
    scene = scene.replace("child: gripper::palm", "child: gripper::base")
    (tmp_path / "scene.yaml").write_text(scene)
    s = dg.load_scene(tmp_path / "scene.yaml")
    report = dg.analyze_grasp(
        s.plant, s.plant_context, s.object_body, hand=s.hand, mu=0.5, load="gravity"
    )
    names = report.load.joint_names
    tau = dict(zip(names, report.load.forces.joint_torques, strict=True))
    assert abs(tau["lift_joint"]) > 1.0  # it carries the weight
    assert not any("press on the limit" in w for w in report.load.warnings)


@pytest.mark.parametrize(
    "torques, tolerance, words",
    [
        ([1.0], 1e-4, "2 finite numbers"),
        ([1.0, float("nan")], 1e-4, "not finite"),
        (None, 1e-4, "joint_torques"),
        ([1.0, 1.0], "x", "distance_tolerance"),
        ([1.0, 1.0], -1.0, "distance_tolerance"),
        ([1.0, 1.0], float("nan"), "distance_tolerance"),
    ],
)
def test_pressing_on_limits_checks_its_inputs(torques, tolerance, words):
    from drakegrasp.plant.load import pressing_on_limits

    s = dg.load_scene("parallel_jaw_box")
    data = dg.grasp_from_plant(
        s.plant, s.plant_context, s.object_body, hand=s.hand, mu=0.5
    )
    with pytest.raises(dg.InvalidOptionError, match=words):
        pressing_on_limits(s.plant, s.plant_context, data, torques, tolerance)


@pytest.mark.parametrize("plane", [None, "yz"])
def test_gravity_wrench_refuses_a_weight_beyond_the_programs(plane):
    # mass=1e308 returned [nan, nan, -inf, ...] with a numpy warning (fuzzer)
    s = dg.load_scene("parallel_jaw_box")
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(dg.InvalidOptionError, match="is more than 1e\\+300"):
            gravity_wrench(
                s.plant, s.plant_context, s.object_body, mass=1e308, plane=plane
            )
        w = gravity_wrench(s.plant, s.plant_context, s.object_body, mass=1e29)
    assert np.all(np.isfinite(w))
