"""The shake test's default squeeze: 20 N at the contacts, a revolute motor's
torque from its fingers' lever arms (:mod:`drakegrasp.planning.squeeze`).

It once was 20 per joint in the joint's own unit: 20 N·m on every revolute
joint a motor drives, so a one-motor pinch whose knuckles and pads follow it
(four joints) was aimed at 80 N·m, which its effort limit of 1000 let through,
and the squeeze threw boxes metres out of the hand that 20 N at the pads
holds.  A parallel jaw's sliding fingers keep their 20 N.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from coupled_hands import (
    coupled_jaw_urdf,
    one_motor_pinch_urdf,
    plan_on_box,
    spread_hand_urdf,
    transmissions,
)
from numpy.linalg import norm
from pydrake.math import RigidTransform, RollPitchYaw

from drakegrasp import GraspError, InvalidGraspError, ModelError
from drakegrasp.planning import (
    plan_grasps,
    planning_scene,
    shake_candidates,
    shake_test,
)
from drakegrasp.planning.shake import REVOLUTE_AIM
from drakegrasp.planning.squeeze import DEFAULT_SQUEEZE, HOLD_LEVER, contact_levers
from drakegrasp.plant.couplings import plant_couplings
from drakegrasp.plant.fingers import find_joint

BOX = "package://drakegrasp/objects/box.sdf"
FLAT_JAW = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
QUICK = dict(settle=0.2, phase=0.3, object_mass=0.2)
pytestmark = pytest.mark.filterwarnings(
    "ignore::drakegrasp.plant.friction.FrictionMismatchWarning"  # plan 0.5, Drake 1
)


def _planned(tmp_path, name, **pinch):
    path = tmp_path / f"{name}.urdf"
    scene, result = plan_on_box(path, one_motor_pinch_urdf(**pinch))
    assert len(result) > 5, result.reason
    return scene, result


@pytest.fixture(scope="module")
def strong(tmp_path_factory):
    """The pinch with motors of 1000 N·m, planned on the box."""
    return _planned(tmp_path_factory.mktemp("strong"), "strong", effort=1000.0)


def _cross_product_arms(scene, candidate, motor, sign):
    """``(press, reach)``: ``max(0, Σ_b mean_C s n·v_C)`` and ``Σ_b mean_C ‖v_C‖``
    with ``v_C = Σ_j ρ_j a_j × (p_C − o_j)``, each joint's axis ``a_j``
    through ``o_j`` at the candidate's pose, for the joints that move the
    contact's body (an independent route to Drake's Jacobian)."""
    plant = scene.plant
    ctx = plant.CreateDefaultContext()
    candidate.apply(plant, ctx, object_body=scene.object_body)
    group = [(motor, 1.0)] + [
        (follower, rho) for follower, leader, rho, _ in plant_couplings(plant)
        if leader == motor
    ]  # fmt: skip
    per_body = {}
    for pc in candidate.contacts:
        body = plant.GetBodyByName(pc.finger_body.split("::")[-1])
        p = candidate.X_WO.multiply(pc.p_OC)
        n = candidate.X_WO.rotation().matrix() @ pc.nhat_O
        v = np.zeros(3)
        for name, rho in group:
            joint = find_joint(plant, name)
            moved = plant.GetBodiesKinematicallyAffectedBy([joint.index()])
            if body.index() not in moved:
                continue
            X_WJ = joint.frame_on_child().CalcPoseInWorld(ctx)
            a = X_WJ.rotation().matrix() @ joint.revolute_axis()
            v += rho * np.cross(a, p - X_WJ.translation())
        per_body.setdefault(pc.finger_body, []).append((sign * n @ v, norm(v)))
    press = sum(np.mean([a for a, _ in arms]) for arms in per_body.values())
    reach = sum(np.mean([r for _, r in arms]) for arms in per_body.values())
    return max(0.0, float(press)), float(reach)


def _cross_product_levers(scene, candidate, motor, sign):
    """The press of :func:`_cross_product_arms`."""
    return _cross_product_arms(scene, candidate, motor, sign)[0]


def test_the_lever_arms_are_the_cross_products_of_the_axes(strong):
    scene, result = strong
    motor = "one_motor_pinch::left_knuckle"
    for candidate in result.candidates[:4]:
        sign = candidate.closing_signs[candidate.joint_names.index(motor)]
        levers = contact_levers(
            scene.add_models, candidate, {motor: sign}, plant_couplings(scene.plant)
        )
        press, reach = _cross_product_arms(scene, candidate, motor, sign)
        # two pads, each some 47 mm from the knuckle axes it turns about,
        # pressed as they swing (moving a little along the face too)
        assert 0.08 < press < 0.11 and press <= reach < 1.1 * press
        assert levers[motor].press == pytest.approx(press, rel=1e-9)
        assert levers[motor].reach == pytest.approx(reach, rel=1e-9)
        # opening presses nothing, and reaches as far
        opened = contact_levers(
            scene.add_models, candidate, {motor: -sign}, plant_couplings(scene.plant)
        )
        assert opened[motor].press == 0.0
        assert opened[motor].reach == pytest.approx(reach, rel=1e-12)


def test_a_hidden_drive_presses_as_its_twin_does(tmp_path, strong):
    """The drive moves the fingers as the twin's knuckle does: the same arms."""
    hidden_scene, hidden = _planned(
        tmp_path, "hidden", effort=1000.0, hidden_drive=True
    )
    scene, twin = strong
    for a, b in zip(hidden.candidates[:3], twin.candidates[:3], strict=True):
        drive = contact_levers(
            hidden_scene.add_models, a, {"one_motor_pinch::drive": 1.0},
            plant_couplings(hidden_scene.plant),
        )  # fmt: skip
        knuckle = contact_levers(
            scene.add_models, b, {"one_motor_pinch::left_knuckle": 1.0},
            plant_couplings(scene.plant),
        )  # fmt: skip
        assert list(drive["one_motor_pinch::drive"]) == pytest.approx(
            list(knuckle["one_motor_pinch::left_knuckle"]), rel=1e-9
        )


def test_strong_motors_hold_at_the_default_where_20_nm_per_joint_threw_the_box(
    strong,
):
    """Drake's simulation, hydroelastic pads: the candidates ranked 4 and 5,
    which 20 N·m per joint (the old default: 80 N·m at the motor, 1000
    allowed) pushed 4.2 and 4.5 m out of the hand, hold at 20 N at the pads
    (1.87 N·m at the motor), as do the four above them."""
    scene, result = strong
    motor = "one_motor_pinch::left_knuckle"
    for candidate in result.candidates[4:6]:
        at_contacts = shake_test(
            scene.add_models, candidate, hydroelastic_modulus=1e6, **QUICK
        )
        per_joint = shake_test(
            scene.add_models, candidate, squeeze=20.0, hydroelastic_modulus=1e6,
            **QUICK,
        )  # fmt: skip
        assert at_contacts.held and at_contacts.squeeze_at_contacts
        assert not per_joint.held and per_joint.max_displacement > 1.0
        assert not per_joint.squeeze_at_contacts
        sign = candidate.closing_signs[candidate.joint_names.index(motor)]
        lever, reach = _cross_product_arms(scene, candidate, motor, sign)
        # the motor seated with 20 N times its arms, as stiff as its reach asks
        ((k, _),) = at_contacts.gains
        assert k * REVOLUTE_AIM == pytest.approx(DEFAULT_SQUEEZE * reach, rel=1e-9)
        assert at_contacts.efforts == (
            pytest.approx(DEFAULT_SQUEEZE * lever, rel=1e-2),
        )
        assert at_contacts.squeeze == DEFAULT_SQUEEZE
        assert at_contacts.squeeze_caps == (DEFAULT_SQUEEZE,)
        assert "squeeze 20 N at the contacts" in str(at_contacts)
        assert per_joint.efforts[0] > 40.0  # of 80 N·m aimed


def test_a_weak_motor_caps_the_newtons_at_the_contacts(tmp_path):
    """Effort 0.5 N·m: below 20 N at the pads; the cap says the newtons."""
    scene, result = _planned(tmp_path, "weak", effort=0.5)
    candidate = result.candidates[0]
    shaken = shake_test(scene.add_models, candidate, hydroelastic_modulus=1e6, **QUICK)
    motor = "one_motor_pinch::left_knuckle"
    sign = candidate.closing_signs[candidate.joint_names.index(motor)]
    lever = _cross_product_levers(scene, candidate, motor, sign)
    assert shaken.squeeze_caps == (pytest.approx(0.5 / lever, rel=1e-9),)
    assert shaken.squeeze_capped
    assert f"capped at the effort limit: {0.5 / lever:g} N at the contacts" in str(
        shaken
    )


def test_a_parallel_jaws_default_is_its_20_n(tmp_path):
    """Sliding fingers: the default is the explicit 20 N, to the bit."""
    scene = planning_scene(BOX, hand_url=FLAT_JAW)  # shipped: offline too
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=0.5, seed=0,
    )  # fmt: skip
    default = shake_test(scene.add_models, result.candidates[0], **QUICK)
    given = shake_test(scene.add_models, result.candidates[0], squeeze=20.0, **QUICK)
    assert not default.squeeze_at_contacts
    for field in ("held", "max_displacement", "efforts", "gains", "squeeze_caps"):
        assert getattr(default, field) == getattr(given, field), field
    assert default.seated_q_hand == given.seated_q_hand


def test_the_lever_arms_move_with_the_grasp_and_stay_in_the_planned_frame(strong):
    """A rigid motion of hand and object together keeps every arm; a shake
    that puts the object elsewhere (``X_WO=``, a point cloud's true pose)
    reads the contacts in the frame they were planned in."""
    scene, result = strong
    candidate = result.candidates[0]
    motor = {"one_motor_pinch::left_knuckle": 1.0}
    couplings = plant_couplings(scene.plant)
    (planned,) = contact_levers(scene.add_models, candidate, motor, couplings).values()
    T = RigidTransform(RollPitchYaw(0.3, -1.1, 2.0), [0.4, -0.2, 1.5])
    moved = replace(
        candidate, X_WH=T.multiply(candidate.X_WH), X_WO=T.multiply(candidate.X_WO)
    )
    (turned,) = contact_levers(scene.add_models, moved, motor, couplings).values()
    assert list(turned) == pytest.approx(list(planned), rel=1e-9)
    away = replace(candidate, X_WO=T.multiply(candidate.X_WO))
    (kept,) = contact_levers(
        scene.add_models, away, motor, couplings, X_WO=candidate.X_WO
    ).values()
    assert list(kept) == pytest.approx(list(planned), rel=1e-12)


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("not callable", "candidate", {}), "add_models must be a function"),
        ((None, object(), {}), "candidate must be a GraspCandidate"),
        ((None, "candidate", {"one_motor_pinch::left_knuckle": 0.5}), "1, -1 or 0"),
        ((None, "candidate", {"one_motor_pinch::left_knuckle": True}), "1, -1 or 0"),
        ((None, "candidate", {"one_motor_pinch::left_knuckle": np.nan}), "1, -1 or 0"),
        ((None, "candidate", {"no_such_joint": 1.0}), "no_such_joint"),
    ],
)
def test_hostile_arguments_are_refused_by_name(strong, args, words):
    scene, result = strong
    add_models, candidate, squeezers = args
    add_models = scene.add_models if add_models is None else add_models
    candidate = result.candidates[0] if candidate == "candidate" else candidate
    with pytest.raises(GraspError, match=words):
        contact_levers(add_models, candidate, squeezers, plant_couplings(scene.plant))


@pytest.mark.parametrize(
    ("couplings", "X_WO", "words"),
    [
        ("x", None, "couplings must be"),
        ([(1, 2)], None, "couplings must be"),
        ((), "x", "X_WO"),
        ((), np.eye(4), "X_WO"),
    ],
)
def test_hostile_couplings_and_frames_are_refused(strong, couplings, X_WO, words):
    scene, result = strong
    with pytest.raises(GraspError, match=words):
        contact_levers(
            scene.add_models, result.candidates[0],
            {"one_motor_pinch::left_knuckle": 1.0}, couplings, X_WO=X_WO,
        )  # fmt: skip


# ------------------------------------------------------------- a review's finds


def test_a_slide_that_turns_the_fingers_presses_them_with_20_n(tmp_path):
    """A hidden drive that slides (a linkage's input slider, 20 rad/m to the
    knuckles) turns the fingers: it is aimed at 20 N × its arms (N per N),
    not at its own 20 N times the four joints it drives (it applied 1000 N,
    its effort limit: some 530 N at each pad)."""
    text = one_motor_pinch_urdf(effort=1000.0, hidden_drive=True, drive_ratio=20.0)
    text = text.replace(
        '<joint name="drive" type="revolute">', '<joint name="drive" type="prismatic">'
    )
    scene, result = plan_on_box(tmp_path / "slide.urdf", text)
    candidate = result.candidates[0]
    drive = "one_motor_pinch::drive"
    sign = candidate.closing_signs[candidate.joint_names.index(drive)]
    arms = _cross_product_levers(scene, candidate, drive, sign)
    assert 1.5 < arms < 2.2  # 20 × the knuckles' arms, N per N
    shaken = shake_test(scene.add_models, candidate, hydroelastic_modulus=1e6, **QUICK)
    assert shaken.squeeze_at_contacts and shaken.held
    assert shaken.efforts == (pytest.approx(DEFAULT_SQUEEZE * arms, rel=1e-2),)


def test_a_follower_with_its_own_motor_presses_with_that_motor(tmp_path, strong):
    """The right knuckle given a motor of its own: the two motors share the
    pads' press (τ = Jᵀ f), their torques along the coupled motion summing
    to the one motor's.  Counted in both, it came to 3.21 N·m for 1.87."""
    scene, result = strong
    text = one_motor_pinch_urdf(effort=1000.0).replace(
        "</robot>", transmissions(["right_knuckle"]) + "</robot>"
    )
    path = tmp_path / "two_motors.urdf"
    path.write_text(text)
    two = planning_scene(BOX, hand_url=str(path))
    candidate = result.candidates[0]
    one = shake_test(scene.add_models, candidate, hydroelastic_modulus=1e6, **QUICK)
    both = shake_test(two.add_models, candidate, hydroelastic_modulus=1e6, **QUICK)
    assert len(both.efforts) == 2 and both.held
    # q_right = -q_left, each closing its own way: both torques add
    assert sum(both.efforts) == pytest.approx(one.efforts[0], rel=2e-2)


def _with_contacts(candidate, **fields):
    return replace(
        candidate,
        contacts=tuple(replace(pc, **fields) for pc in candidate.contacts),
    )


def test_contacts_the_default_cannot_press_are_refused(strong):
    """No contacts, a NaN or misshapen contact, or normals that closing moves
    away from: the default squeeze would press nothing (each shook with no
    force at all and the box fell 3.64 m, the result reading "20 N")."""
    scene, result = strong
    c = result.candidates[0]
    for bad, words in (
        (replace(c, contacts=()), "no contacts"),
        (_with_contacts(c, nhat_O=np.full(3, np.nan)), "unit normal nhat_O"),
        (_with_contacts(c, p_OC=np.zeros(2)), "finite point p_OC"),
    ):
        with pytest.raises(InvalidGraspError, match=words):
            shake_test(scene.add_models, bad, **QUICK)
    outward = replace(
        c, contacts=tuple(replace(pc, nhat_O=-pc.nhat_O) for pc in c.contacts)
    )
    with pytest.raises(InvalidGraspError, match="presses nothing: give squeeze="):
        shake_test(scene.add_models, outward, **QUICK)
    # shaking several, a candidate the default cannot press is recorded and
    # the rest are shaken; a bad contact is refused before any simulation
    ranked = shake_candidates(scene.add_models, [outward, c], top=2, **QUICK)
    assert [s.planned_rank for s in ranked] == [1, 0]
    assert ranked[1].result is None and "presses nothing" in ranked[1].error
    nan = _with_contacts(c, nhat_O=np.full(3, np.nan))
    with pytest.raises(InvalidGraspError, match=r"candidates\[1\]: .*unit normal"):
        shake_candidates(scene.add_models, [c, nan], top=2, **QUICK)


def test_a_hand_welded_by_add_models_is_refused_by_name(strong):
    scene, result = strong
    candidate = result.candidates[0]

    def welded(plant, parser):
        hand, body = scene.add_models(plant, parser)
        base = plant.GetBodyByName("palm")
        plant.WeldFrames(plant.world_frame(), base.body_frame())
        return hand, body

    for squeeze in (None, 20.0):
        with pytest.raises(ModelError, match="must leave the hand's base"):
            shake_test(welded, candidate, squeeze=squeeze, **QUICK)


@pytest.fixture(scope="module")
def spread(tmp_path_factory):
    path = tmp_path_factory.mktemp("spread") / "spread.urdf"
    path.write_text(spread_hand_urdf())
    scene = planning_scene(BOX, hand_url=str(path))
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=80, mu=0.5, seed=0, object_mass=0.2,
    )  # fmt: skip
    return scene, result


def test_each_motor_holds_as_stiffly_as_its_reach_asks(spread):
    """With the default stiffness a turning motor is as stiff as deflects it
    0.1 rad under 20 N at its contacts in any direction (its reach), within
    its 1.5 N·m: a spread whose closing barely presses (arms of 1.3 mm) but
    moves its contacts sideways is not left limp (it had 0.27 N·m/rad)."""
    scene, result = spread
    plant = scene.plant
    motors = {
        f"spread_hand::{plant.get_joint_actuator(a).joint().name()}"
        for a in plant.GetJointActuatorIndices()
    }
    moved = [c for c in plant_couplings(plant) if c[0] not in motors]
    for candidate in result.candidates[:2]:
        signs = dict(zip(candidate.joint_names, candidate.closing_signs, strict=True))
        squeezers = {n: signs[n] for n in sorted(motors) if n in signs}
        arms = contact_levers(scene.add_models, candidate, squeezers, moved)
        shaken = shake_test(scene.add_models, candidate, **QUICK)
        # gains in actuator order, as the motors are declared
        names = [
            f"spread_hand::{plant.get_joint_actuator(a).joint().name()}"
            for a in plant.GetJointActuatorIndices()
        ]
        turning = [n for n in names if n in squeezers]
        stiffness = dict(zip(turning, shaken.gains, strict=True))
        for name, arm in arms.items():
            aim = DEFAULT_SQUEEZE * max(arm.press, arm.reach)
            expected = min(aim if arm.reach else DEFAULT_SQUEEZE * HOLD_LEVER, 1.5)
            k, _ = stiffness[name]
            assert k * REVOLUTE_AIM == pytest.approx(expected, rel=1e-9), name


def test_a_geared_drive_holds_as_stiffly_as_its_gearing_asks(tmp_path):
    """A hidden drive geared 20:1 (the knuckles turn 0.05 rad a radian): a
    fixed floor of 10 N·m/rad aimed it 0.47 mrad at the knuckles, which the
    pads took up, and the box fell 3.64 m; its reach asks 0.94 N·m/rad."""
    scene, result = _planned(
        tmp_path, "geared", effort=1000.0, hidden_drive=True, drive_ratio=0.05
    )
    candidate = result.candidates[0]
    shaken = shake_test(scene.add_models, candidate, hydroelastic_modulus=1e6, **QUICK)
    assert shaken.held
    drive = "one_motor_pinch::drive"
    sign = candidate.closing_signs[candidate.joint_names.index(drive)]
    (arm,) = contact_levers(
        scene.add_models, candidate, {drive: sign}, plant_couplings(scene.plant)
    ).values()
    assert 0.004 < arm.press < 0.006  # the knuckles' 94 mm, geared 20:1
    ((k, _),) = shaken.gains
    assert k * REVOLUTE_AIM == pytest.approx(DEFAULT_SQUEEZE * arm.reach, rel=1e-9)
    assert shaken.efforts[0] == pytest.approx(DEFAULT_SQUEEZE * arm.press, rel=0.2)


def test_an_uncapped_squeeze_reads_exactly_the_squeeze(spread):
    """0.7 N·m on a motor of share 1.5: its cap came out 0.6999999999999998,
    and the summary said "capped" where no effort limit capped anything."""
    scene, result = spread
    shaken = shake_test(scene.add_models, result.candidates[0], squeeze=0.7, **QUICK)
    assert not shaken.squeeze_capped
    assert 0.7 in shaken.squeeze_caps and "capped" not in str(shaken)


def test_the_allegro_hands_joints_that_closing_leaves_still_hold(drake_models_dir):
    """A multi-finger candidate's closing sign is 0 for a joint closing leaves
    still (the Allegro hand's spreads): it presses nothing and holds where it
    stands, as stiffly as its reach asks within its 0.7 N·m; the default
    shake of such a candidate was refused, the sign read as a hostile one."""
    scene = planning_scene(
        "package://drake_models/ycb/005_tomato_soup_can.sdf",
        hand_url="package://drake_models/allegro_hand_description/sdf/"
        "allegro_hand_description_right.sdf",
        models_dir=drake_models_dir,
    )
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    scene.plant.GetJointByName("joint_12").set_angle(ctx, 1.0)  # thumb opposed
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=100, mu=0.5, seed=0,
    )  # fmt: skip
    still = [c for c in result.candidates[:10] if 0.0 in c.closing_signs]
    assert still, [c.closing_signs for c in result.candidates[:10]]
    candidate = still[0]
    shaken = shake_test(scene.add_models, candidate, hydroelastic_modulus=1e6, **QUICK)
    assert shaken.squeeze_at_contacts
    # every joint as stiff as its reach asks, within its 0.7 N·m
    assert all(0 < k * REVOLUTE_AIM <= 0.7 for k, _ in shaken.gains)
    joints = dict(zip(candidate.joint_names, shaken.seated_q_hand, strict=True))
    for name, sign, q in zip(
        candidate.joint_names, candidate.closing_signs, candidate.q_hand, strict=True
    ):
        if sign == 0.0:  # held where it stood, within what the contacts push
            assert joints[name] == pytest.approx(q, abs=0.05), name


def test_a_cranks_arms_are_its_ratios(tmp_path):
    """A jaw whose sliding fingers follow a revolute crank at ±5 mm/rad: on
    the box's faces, square to the slides, each pad's arm is the crank's
    ratio, and the shake at the default aims the crank at 20 N × 10 mm, as
    20 per joint over its followers' Σ|ρ| did."""
    rho = 0.005
    text = coupled_jaw_urdf(ratio=-1.0, hidden_drive=True)
    text = text.replace(
        '<mimic joint="drive" multiplier="-1.0" offset="0.0"/>',
        f'<mimic joint="drive" multiplier="{-rho}" offset="0.0"/>',
    ).replace(
        '<mimic joint="drive" multiplier="1" offset="0"/>',
        f'<mimic joint="drive" multiplier="{rho}" offset="0"/>',
    )
    slide = (
        '<joint name="drive" type="prismatic"><parent link="palm"/><child '
        'link="drive_link"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit '
        'lower="0.0" upper="0.045"'
    )
    assert slide in text
    text = text.replace(
        slide,
        slide.replace("prismatic", "revolute").replace("0.045", f"{0.045 / rho:g}"),
    )
    scene, result = plan_on_box(
        tmp_path / "crank.urdf", text, num_candidates=200, seed=4, object_mass=0.3
    )
    candidate = result.candidates[0]
    couplings = plant_couplings(scene.plant)
    # the crank closes a finger turning the way its ratio's sign and the
    # finger's closing sign give
    follower, _, ratio, _ = couplings[0]
    sign = candidate.closing_signs[candidate.joint_names.index(follower)]
    (arm,) = contact_levers(
        scene.add_models, candidate, {"coupled_jaw::drive": sign * np.sign(ratio)},
        couplings,
    ).values()  # fmt: skip
    assert arm.press == pytest.approx(2 * rho, rel=1e-6)
    assert arm.reach == pytest.approx(2 * rho, rel=1e-6)
    shaken = shake_test(scene.add_models, candidate, hydroelastic_modulus=1e6, **QUICK)
    assert shaken.squeeze_at_contacts and shaken.held
    ((k, _),) = shaken.gains
    assert k * REVOLUTE_AIM == pytest.approx(DEFAULT_SQUEEZE * 2 * rho, rel=1e-6)
