"""A hand's passive joints are named when the planner holds them locked.

A one-dof joint without an actuator that follows no other turns freely in
Drake; the planner keeps it where the context puts it.  On a three-finger
hand whose distal joints were passive, 2 of the 4 best box grasps dropped in
Drake and all 4 held with those joints welded, without a word from the plan.
"""

from __future__ import annotations

import warnings

import pytest
from coupled_hands import spread_hand_urdf

from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.planning.approach import multi_finger_hand
from drakegrasp.planning.multifinger import PassiveJointWarning
from drakegrasp.plant.fingers import passive_joints
from drakegrasp.plant.validation import hand_bodies

CYLINDER = "package://drakegrasp/objects/cylinder.sdf"
MIMIC = '<mimic joint="f1_proximal_joint" multiplier="0.5" offset="0"/>'


def _scene(tmp_path, passive: bool):
    text = spread_hand_urdf()
    assert text.count(MIMIC) == 1
    path = tmp_path / f"hand_{passive}.urdf"
    path.write_text(text.replace(MIMIC, "") if passive else text)
    return planning_scene(CYLINDER, hand_url=str(path))


def _plan(scene):
    return plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=10, mu=0.5, seed=0, robustness_samples=4,
    )  # fmt: skip


@pytest.mark.parametrize("passive", [False, True])
def test_passive_joints_are_the_hands_joints_no_motor_moves(tmp_path, passive):
    scene = _scene(tmp_path, passive)
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    hand = multi_finger_hand(scene.plant, ctx, scene.object_body, scene.hand)
    bodies = hand_bodies(scene.plant, scene.object_body, scene.hand)
    found = passive_joints(scene.plant, bodies, hand.structure)
    assert [j.name() for j in found] == (["f1_distal_joint"] if passive else [])
    assert not set(found) & set(hand.structure.joints)


def test_planning_a_hand_with_a_passive_joint_names_it(tmp_path):
    with pytest.warns(PassiveJointWarning, match=r"spread_hand::f1_distal_joint"):
        _plan(_scene(tmp_path, passive=True))


def test_a_hand_whose_joints_all_move_with_motors_plans_without_it(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("error", PassiveJointWarning)
        _plan(_scene(tmp_path, passive=False))


def test_an_open_hand_that_collides_everywhere_is_told_to_open(tmp_path, capsys):
    # the spread hand curled shut (its flexion joints at their upper limits)
    # penetrates the cylinder at every sampled pose
    from drakegrasp.cli import main
    from drakegrasp.planning.multifinger import OPEN_HAND_HINT

    shut = [f"f{k}_proximal_joint" for k in (1, 2, 3)]
    scene = _scene(tmp_path, passive=False)
    ctx = scene.plant.GetMyMutableContextFromRoot(scene.context)
    for name in shut:
        scene.plant.GetJointByName(name).set_angle(ctx, 2.0)
    result = _plan(scene)
    assert len(result) == 0
    assert set(result.rejections) == {"hand collides with the object"}
    assert result.reason.endswith(OPEN_HAND_HINT)
    argv = ["plan", "cylinder", "--hand", str(tmp_path / "hand_False.urdf")]
    argv += ["--num", "10", *(f"--preshape={name}=2.0" for name in shut)]
    assert main(argv) == 0
    assert "open it wider (--preshape JOINT=VALUE)" in capsys.readouterr().out


def test_a_joint_without_a_motor_that_others_follow_is_passive_with_them(tmp_path):
    # f1's flexion loses its transmission: it and the distal joint that
    # follows it (<mimic> 0.5) are moved by no motor
    text = spread_hand_urdf()
    motor = '<transmission name="t_f1_proximal_joint">'
    start = text.index(motor)
    end = text.index("</transmission>", start) + len("</transmission>")
    path = tmp_path / "hand.urdf"
    path.write_text(text[:start] + text[end:])
    scene = planning_scene(CYLINDER, hand_url=str(path))
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    hand = multi_finger_hand(scene.plant, ctx, scene.object_body, scene.hand)
    bodies = hand_bodies(scene.plant, scene.object_body, scene.hand)
    found = passive_joints(scene.plant, bodies, hand.structure)
    assert [j.name() for j in found] == ["f1_proximal_joint", "f1_distal_joint"]
    with pytest.warns(PassiveJointWarning, match="f1_proximal_joint"):
        _plan(scene)
