"""A plan says when the hand's motors have no effort limit to rank by.

Drake gives an SDFormat joint without ``<effort>`` an actuator of infinite
effort.  The motor re-ranking (``squeeze_needed``/``torque_needed`` within
the effort limit first) then had nothing to compare with and the plan read
as if any candidate were held; it now says why it ranks by score alone.
"""

from __future__ import annotations

import numpy as np
import pytest

from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.plant.models import models_dir

BOX = "package://drakegrasp/objects/box.sdf"
SPHERE = "package://drakegrasp/objects/sphere.sdf"
FLAT = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
THREE_FINGER = "package://drakegrasp/hands/three_finger_hand.sdf"


def _hand(tmp_path, name: str, effort: str, replacement: str):
    text = (models_dir() / "hands" / name).read_text()
    assert effort in text
    path = tmp_path / name
    path.write_text(text.replace(effort, replacement))
    return str(path)


def _plan(tmp_path, name, effort, replacement, obj, **options):
    hand = _hand(tmp_path, name, effort, replacement)
    scene = planning_scene(obj, hand_url=hand)
    return plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=0.5, seed=0, robustness_samples=4, **options,
    )  # fmt: skip


JAW = ("parallel_jaw_flat.sdf", "<effort>140.0</effort>", BOX)
THREE = ("three_finger_hand.sdf", "<effort>2.0</effort>", SPHERE)


@pytest.mark.parametrize("name, effort, obj", [JAW, THREE])
def test_actuators_without_effort_are_said(tmp_path, name, effort, obj):
    result = _plan(tmp_path, name, effort, "", obj)
    assert len(result) > 0
    assert result.reason.startswith("ranked by score alone")
    assert "no effort limit in the model" in result.reason
    assert "held_first" not in result.settings
    assert "ranked by score alone" in str(result)


@pytest.mark.parametrize("name, effort, obj", [JAW, THREE])
def test_a_model_with_limits_says_nothing_of_it(tmp_path, name, effort, obj):
    result = _plan(tmp_path, name, effort, effort, obj)
    assert "ranked by score alone" not in result.reason
    assert result.settings["held_first"]["source"] == "effort limit"


def test_a_given_squeeze_limit_ranks_instead(tmp_path):
    name, effort, obj = JAW
    result = _plan(tmp_path, name, effort, "", obj, squeeze_limit=5.0)
    assert "ranked by score alone" not in result.reason
    assert result.settings["held_first"]["source"] == "squeeze_limit given"


def test_the_command_line_names_its_option(tmp_path, capsys):
    from drakegrasp.cli import main

    name, effort, _ = JAW
    hand = _hand(tmp_path, name, effort, "")
    assert main(["plan", "box", "--hand", hand, "--num", "30", "--top", "1"]) == 0
    out = capsys.readouterr().out
    assert "no effort limit in the model" in out
    assert "or pass --squeeze-limit LIMIT (N per finger)" in out


def test_a_hand_without_actuators_is_said(tmp_path):
    name, effort, obj = JAW
    result = _plan(tmp_path, name, effort, "<effort>0</effort>", obj)
    assert result.reason.startswith("ranked by score alone")
    assert "no actuator" in result.reason


def test_plan_shake_of_a_hand_without_motors_is_refused_up_front(tmp_path, capsys):
    # it planned, printed, then failed in the shake
    from drakegrasp.cli import main

    name, effort, _ = JAW
    hand = _hand(tmp_path, name, effort, "<effort>0</effort>")
    assert main(["plan", "box", "--hand", hand, "--num", "30", "--shake", "2"]) != 0
    captured = capsys.readouterr()
    assert captured.out == ""  # nothing planned
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and "--shake squeezes with the hand's motors" in err[0]


def test_friction_beyond_what_the_programs_resolve_is_refused():
    # --mu 1e12, inside the coefficients' range, failed the whole plan in Clp
    from drakegrasp.errors import InvalidOptionError
    from drakegrasp.planning.planner import MAX_PLAN_MU

    scene = planning_scene(BOX, hand_url=FLAT)
    for mu, ok in ((MAX_PLAN_MU, True), (1e12, False)):
        run = lambda mu=mu: plan_grasps(  # noqa: E731
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=10, mu=mu, seed=0, robustness_samples=2,
        )  # fmt: skip
        if ok:
            assert len(run()) > 0
        else:
            with pytest.raises(InvalidOptionError, match="at most 1e\\+06"):
                run()


def test_a_cloud_without_a_mass_gets_no_advice_it_cannot_follow(tmp_path):
    # no object_mass: every squeeze_needed is NaN, and squeeze_limit is
    # refused on a cloud without one: advising it was a dead end
    from cloud_support import sample_cloud

    name, effort, _ = JAW
    hand = _hand(tmp_path, name, effort, "")
    p, n = sample_cloud(planning_scene(BOX, hand_url=hand), 3000)
    alone = planning_scene(None, hand_url=hand)
    result = plan_grasps(
        alone.plant, alone.context, None, hand=alone.hand, num_candidates=60,
        mu=0.5, seed=0, point_cloud=p, cloud_normals=n, robustness_samples=2,
    )  # fmt: skip
    assert len(result) > 0
    assert all(np.isnan(c.squeeze_needed) for c in result)
    assert "ranked by score alone" not in result.reason


def test_the_advice_gives_the_unit_of_the_hands_joints(tmp_path, capsys):
    from drakegrasp.cli import main

    name, effort, obj = THREE
    result = _plan(tmp_path, name, effort, "", obj)
    assert result.reason.endswith("or pass torque_limit (N·m per motor)"), result.reason
    hand = _hand(tmp_path, name, effort, "")
    argv = ["plan", "sphere", "--hand", hand, "--num", "40", "--top", "1"]
    assert main(argv) == 0
    assert "or pass --torque-limit LIMIT (N·m per motor)" in capsys.readouterr().out


def _three_finger_plant(tmp_path, prismatic: tuple[str, ...]):
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    text = (models_dir() / "hands" / "three_finger_hand.sdf").read_text()
    for joint in prismatic:
        old = f'<joint name="{joint}" type="revolute">'
        assert old in text
        text = text.replace(old, f'<joint name="{joint}" type="prismatic">')
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModelsFromString(text, "sdf")
    plant.Finalize()
    return plant


@pytest.mark.parametrize(
    "prismatic, unit",
    [
        ((), "N·m"),
        (("finger1_proximal_joint", "finger2_proximal_joint"), "N"),
        (("finger1_proximal_joint",), "N·m, N at prismatic joints"),
    ],
)
def test_the_unit_follows_the_joint_types(tmp_path, prismatic, unit):
    from drakegrasp.planning.motors import _unit_of_joints

    plant = _three_finger_plant(tmp_path, prismatic)
    joints = [
        plant.get_joint(i).name()
        for i in plant.GetJointIndices()
        if plant.get_joint(i).name() in prismatic or not prismatic
    ]
    scoped = [f"three_finger_hand::{j}" for j in joints]
    if prismatic and unit.startswith("N·m"):
        scoped.append("three_finger_hand::finger2_proximal_joint")
    assert _unit_of_joints(plant, scoped) == unit


def test_a_prismatic_hand_too_weak_is_told_in_newtons():
    from types import SimpleNamespace

    from drakegrasp.planning.motors import _too_weak

    head = [SimpleNamespace(torque_needed=3.0, torque_capacity=1.0)]
    text = _too_weak(head, 1.0, True, "N")
    assert "torque_limit 1 N holds" in text and "3 N per motor" in text, text
    assert "N·m" not in text
    mixed = _too_weak(head, 1.0, False, "N·m, N at prismatic joints")
    assert "(effort limits from 1 N·m, N at prismatic joints) hold" in mixed
    assert "3 N·m per motor, N at prismatic joints" in mixed, mixed


def _chuck_sdf() -> str:
    """A three-jaw chuck: three capsule fingers 120° apart, each sliding 55 mm
    towards the palm's axis on a prismatic joint with a 20 N motor."""
    inertia = (
        "<inertial><mass>0.05</mass><inertia><ixx>1e-5</ixx><iyy>1e-5</iyy>"
        "<izz>1e-6</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>"
    )
    parts = []
    for k in range(3):
        a = 2 * np.pi * k / 3
        parts.append(
            f"<link name='f{k}'><pose>{0.065 * np.cos(a)} {0.065 * np.sin(a)} 0 0 "
            f"0 {a}</pose>{inertia}<collision name='c'><pose>0 0 0.045 0 0 0</pose>"
            "<geometry><capsule><radius>0.008</radius><length>0.06</length>"
            "</capsule></geometry></collision></link>"
            f"<joint name='f{k}_slide' type='prismatic'><parent>palm</parent>"
            f"<child>f{k}</child><axis><xyz>-1 0 0</xyz><limit><lower>0</lower>"
            "<upper>0.055</upper><effort>20</effort></limit></axis></joint>"
        )
    return (
        '<?xml version="1.0"?><sdf version="1.9"><model name="chuck">'
        f"<link name='palm'>{inertia}<collision name='c'><pose>0 0 -0.01 0 0 0"
        "</pose><geometry><cylinder><radius>0.08</radius><length>0.02</length>"
        "</cylinder></geometry></collision></link>" + "".join(parts) + "</model></sdf>"
    )


def _chuck_plan(hand_file_scene):
    """The three-jaw chuck's plan on the sphere (20 samples, seed 0)."""
    scene = hand_file_scene(SPHERE, _chuck_sdf(), "chuck.sdf")
    return plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=20, mu=0.5, seed=0, robustness_samples=2,
    )  # fmt: skip


def test_a_sliding_hands_torque_needed_is_printed_in_newtons(hand_file_scene):
    # the plan's head said "torque_needed <= 20 N (effort limit)" and each
    # candidate below it "torque 1.18 N·m per motor"
    import dataclasses
    import pickle

    result = _chuck_plan(hand_file_scene)
    assert "<= 20 N (effort limit)" in str(result)
    checked = [c for c in result if np.isfinite(c.torque_needed)]
    assert checked
    for c in checked:
        assert f", torque {c.torque_needed:.3g} N per motor, p_WH" in str(c), str(c)
        assert "N·m" not in str(c)
        assert c.torque_unit == "N" and c.to_dict()["torque_unit"] == "N"
    c = checked[0]
    mixed = dataclasses.replace(c, torque_unit="N·m, N at prismatic joints")
    words = f"torque {c.torque_needed:.3g} N·m per motor, N at prismatic joints, "
    assert words in str(mixed)
    # a turning hand's words as before; a candidate pickled before the unit
    # was recorded reads as one
    turning = dataclasses.replace(c, torque_unit="N·m")
    assert f", torque {c.torque_needed:.3g} N·m per motor, p_WH" in str(turning)
    state = pickle.loads(pickle.dumps(turning)).__dict__
    state.pop("torque_unit")
    old = object.__new__(type(c))
    old.__dict__.update(state)
    assert old.torque_unit == "N·m" and str(old) == str(turning)


def test_a_turning_hand_records_newton_metres():
    scene = planning_scene(SPHERE, hand_url=THREE_FINGER)
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=20, mu=0.5, seed=0, robustness_samples=2,
    )  # fmt: skip
    checked = [c for c in result if np.isfinite(c.torque_needed)]
    assert checked
    assert {c.torque_unit for c in checked} == {"N·m"}
    assert all(" N·m per motor, p_WH" in str(c) for c in checked)
