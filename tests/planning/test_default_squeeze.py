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
from coupled_hands import one_motor_pinch_urdf
from pydrake.math import RigidTransform, RollPitchYaw

from drakegrasp import GraspError
from drakegrasp.planning import plan_grasps, planning_scene, shake_test
from drakegrasp.planning.shake import REVOLUTE_AIM
from drakegrasp.planning.squeeze import DEFAULT_SQUEEZE, contact_levers
from drakegrasp.plant.couplings import plant_couplings
from drakegrasp.plant.fingers import find_joint

BOX = "package://drakegrasp/objects/box.sdf"
QUICK = dict(settle=0.2, phase=0.3, object_mass=0.2)
pytestmark = pytest.mark.filterwarnings(
    "ignore::drakegrasp.plant.friction.FrictionMismatchWarning"  # plan 0.5, Drake 1
)


def _planned(tmp_path, name, **pinch):
    path = tmp_path / f"{name}.urdf"
    path.write_text(one_motor_pinch_urdf(**pinch))
    scene = planning_scene(BOX, hand_url=str(path))
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, mu=0.5, seed=0, robustness_samples=8,
        object_mass=0.2,
    )  # fmt: skip
    assert len(result) > 5, result.reason
    return scene, result


@pytest.fixture(scope="module")
def strong(tmp_path_factory):
    """The pinch with motors of 1000 N·m, planned on the box."""
    return _planned(tmp_path_factory.mktemp("strong"), "strong", effort=1000.0)


def _cross_product_levers(scene, candidate, motor, sign):
    """``Σ_b max(0, mean_C s n·Σ_j ρ_j a_j × (p_C − o_j))``: each joint's axis
    ``a_j`` through ``o_j`` at the candidate's pose, for the joints that move
    the contact's body (an independent route to Drake's Jacobian)."""
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
        per_body.setdefault(pc.finger_body, []).append(sign * n @ v)
    return sum(max(0.0, float(np.mean(arms))) for arms in per_body.values())


def test_the_lever_arms_are_the_cross_products_of_the_axes(strong):
    scene, result = strong
    motor = "one_motor_pinch::left_knuckle"
    for candidate in result.candidates[:4]:
        sign = candidate.closing_signs[candidate.joint_names.index(motor)]
        levers = contact_levers(
            scene.add_models, candidate, {motor: sign}, plant_couplings(scene.plant)
        )
        expected = _cross_product_levers(scene, candidate, motor, sign)
        # two pads, each some 47 mm from the knuckle axes it turns about
        assert 0.08 < expected < 0.11
        assert levers[motor] == pytest.approx(expected, rel=1e-9)
        # opening presses nothing: each pad's arm counts 0
        opened = contact_levers(
            scene.add_models, candidate, {motor: -sign}, plant_couplings(scene.plant)
        )
        assert opened == {motor: 0.0}


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
        assert drive["one_motor_pinch::drive"] == pytest.approx(
            knuckle["one_motor_pinch::left_knuckle"], rel=1e-9
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
        lever = _cross_product_levers(scene, candidate, motor, sign)
        # the motor aimed at, and seated with, 20 N times its arms
        ((k, _),) = at_contacts.gains
        assert k * REVOLUTE_AIM == pytest.approx(DEFAULT_SQUEEZE * lever, rel=1e-9)
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
    scene = planning_scene(BOX)
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
    planned = contact_levers(scene.add_models, candidate, motor, couplings)
    T = RigidTransform(RollPitchYaw(0.3, -1.1, 2.0), [0.4, -0.2, 1.5])
    moved = replace(
        candidate, X_WH=T.multiply(candidate.X_WH), X_WO=T.multiply(candidate.X_WO)
    )
    assert contact_levers(scene.add_models, moved, motor, couplings) == pytest.approx(
        planned, rel=1e-9
    )
    away = replace(candidate, X_WO=T.multiply(candidate.X_WO))
    kept = contact_levers(scene.add_models, away, motor, couplings, X_WO=candidate.X_WO)
    assert kept == pytest.approx(planned, rel=1e-12)


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("not callable", "candidate", {}), "add_models must be a function"),
        ((None, object(), {}), "candidate must be a GraspCandidate"),
        ((None, "candidate", {"one_motor_pinch::left_knuckle": 0.0}), "1 or -1"),
        ((None, "candidate", {"one_motor_pinch::left_knuckle": True}), "1 or -1"),
        ((None, "candidate", {"one_motor_pinch::left_knuckle": np.nan}), "1 or -1"),
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
