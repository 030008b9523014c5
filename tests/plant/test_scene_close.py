"""Closing from scene files and the command line; refused poses; ε (issue 20, 9).

Models of our own (:mod:`hand_models`): the two-finger hand with a welded palm
and a free ball 35 mm in radius resting 0.05 mm above the palm, written as a
scene whose directives hold the hand open.  ``close: true`` (or ``analyze
--close``) must close it exactly as :func:`drakegrasp.close_hand` does in
Python; a refused pose names the options of whoever called (Python keywords
or command-line flags); ``analyze`` prints Ferrari–Canny's ε with moments
divided by the object's radius, and says so.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hand_models import Rig, ball, box_object, palm_hand
from pydrake.math import RigidTransform, RollPitchYaw

from drakegrasp import (
    Contact,
    Grasp,
    JointLimitError,
    PenetrationError,
    SceneError,
    close_hand,
    ferrari_canny,
    load_scene,
)
from drakegrasp.cli import main
from drakegrasp.plant.scale import SCALE_NAME, object_radius

RADIUS = 0.035
GAP = 5e-5


def _scene(tmp_path: Path, *, close="", z=RADIUS + GAP, joints="") -> Path:
    (tmp_path / "hand.sdf").write_text(palm_hand())
    (tmp_path / "ball.sdf").write_text(ball(RADIUS))
    text = f"""directives:
- add_model:
    name: hand
    file: hand.sdf
{joints}- add_model:
    name: ball
    file: ball.sdf
    default_free_body_pose:
      ball:
        translation: [0.0, 0.0, {z!r}]
drakegrasp:
  description: two fingers and a welded palm around a ball
  object_body: ball::ball
  hand: hand
  mu: 0.5
{close}"""
    path = tmp_path / "palm_ball.yaml"
    path.write_text(text)
    return path


def _run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_close_true_closes_as_close_hand_does(tmp_path, tools):
    closed = load_scene(_scene(tmp_path, close="  close: true\n"))
    assert closed.closure is not None
    assert len(closed.closure.touching_fingers) == 2
    # The same scene left open, closed in Python: the same joint values.
    opened = load_scene(_scene(tmp_path))
    assert opened.closure is None
    q_open = opened.plant.GetPositions(opened.plant_context).copy()
    by_hand = close_hand(
        opened.plant, opened.plant_context, opened.object_body, hand=opened.hand
    )
    np.testing.assert_array_equal(
        closed.plant.GetPositions(closed.plant_context),
        opened.plant.GetPositions(opened.plant_context),
    )
    np.testing.assert_array_equal(by_hand.q_start, q_open[by_hand.position_indices])
    report = tools.analyze_scene(closed)
    assert report.grasp.num_contacts == 3 and report.force_closure.is_closure
    # load_scene(close=False) overrides the file.
    assert (
        load_scene(_scene(tmp_path, close="  close: true\n"), close=False).closure
        is None
    )


def test_close_along_a_direction(tmp_path):
    default = load_scene(_scene(tmp_path, close="  close: true\n")).closure
    names = default.joints
    direction = [
        {"hand::left_proximal_joint": 1.0, "hand::right_proximal_joint": -1.0}.get(
            n, 0.0
        )
        for n in names
    ]
    text = f"  close:\n    direction: {direction}\n"
    scene = load_scene(_scene(tmp_path, close=text))
    closure = scene.closure
    assert len(closure.touching_fingers) == 2
    moved = closure.q != closure.q_start
    for name, m, d in zip(names, moved, direction, strict=True):
        assert m == (d != 0.0), name  # distal joints stay where the file put them
    assert not np.allclose(closure.q, default.q)


@pytest.mark.parametrize(
    "close, fragment",
    [
        ("  close: yes\n", "drakegrasp.close must be"),
        ("  close: 1\n", "drakegrasp.close must be"),
        ("  close:\n    dir: [1, 0]\n", "drakegrasp.close must be"),
        ("  close:\n    direction: []\n", "drakegrasp.close must be"),
        ("  close:\n    direction: [1, .inf, 0, 0]\n", "every number finite"),
        ("  close:\n    direction: [1, a, 0, 0]\n", "must be a number"),
    ],
)
def test_bad_close_values_name_the_key(tmp_path, close, fragment):
    with pytest.raises(SceneError, match=fragment):
        load_scene(_scene(tmp_path, close=close))


def test_cli_close_flag(tmp_path, capsys):
    path = _scene(tmp_path)
    code, out, err = _run(capsys, "analyze", path)
    assert code == 0 and err == ""
    assert "1 contacts" in out and "Hand closed" not in out  # the palm only
    code, out, err = _run(capsys, "analyze", path, "--close")
    assert code == 0 and err == ""
    assert "Hand closed: 2 of 2 fingers touch" in out
    assert "3 contacts" in out and "force closure: YES" in out
    # --no-close overrides a scene's close: true
    code, out, _ = _run(
        capsys, "analyze", _scene(tmp_path, close="  close: true\n"), "--no-close"
    )
    assert code == 0 and "1 contacts" in out


def test_epsilon_uses_the_object_radius_and_says_so(tmp_path, capsys):
    code, out, _ = _run(capsys, "analyze", _scene(tmp_path), "--close", "--json")
    assert code == 0
    data = json.loads(out)
    eps = data["epsilon"]
    assert eps["torque_scale"] == pytest.approx(RADIUS, rel=1e-15)
    assert eps["scale"] == SCALE_NAME and eps["norm"] == "L1"
    # Independently: the grasp rebuilt from the JSON contacts, ε with b_s = r.
    grasp = Grasp(
        [Contact(c["p_OC"], c["nhat_O"], mu=0.5) for c in data["contacts"]],
        reference_point=np.zeros(3),
    )
    assert eps["epsilon"] > 0.0
    assert eps["epsilon"] == pytest.approx(
        ferrari_canny(grasp, torque_scale=RADIUS), rel=1e-9
    )
    code, out, _ = _run(capsys, "analyze", _scene(tmp_path), "--close")
    line = next(x for x in out.splitlines() if "epsilon (Ferrari-Canny, L1)" in x)
    assert f"{eps['epsilon']:.4g}" in line and "b_s = 35 mm" in line
    assert SCALE_NAME in line


def test_object_radius_closed_form_and_pose_invariance():
    size = (0.03, 0.05, 0.02)
    rig = Rig([(palm_hand(), "sdf"), (box_object(size), "sdf")], "box")
    r0 = object_radius(rig.plant, rig.ctx, rig.object)
    assert r0 == pytest.approx(0.5 * np.linalg.norm(size), rel=1e-15)
    X = RigidTransform(RollPitchYaw(0.3, -1.1, 2.0), [0.4, -0.2, 0.9])
    rig.plant.SetFreeBodyPose(rig.ctx, rig.object, X)
    assert object_radius(rig.plant, rig.root, rig.object) == r0


def test_refused_pose_names_python_options(tmp_path, tools):
    scene = load_scene(_scene(tmp_path, z=RADIUS - 1e-3))
    with pytest.raises(PenetrationError) as info:
        tools.analyze_scene(scene)
    message = str(info.value)
    assert "check_pose=False" in message and "allow_penetration=True" in message
    assert "--" not in message
    assert info.value.problem.startswith("impossible pose: ")


def test_refused_pose_names_cli_flags(tmp_path, capsys):
    path = _scene(tmp_path, z=RADIUS - 1e-3)
    code, out, err = _run(capsys, "analyze", path)
    assert code == 1 and out == ""
    assert "--allow-penetration or --no-check-pose" in err
    assert "check_pose=False" not in err and "penetrate" in err
    for flag in ("--allow-penetration", "--no-check-pose"):
        code, out, err = _run(capsys, "analyze", path, flag)
        assert code == 0 and err == "", flag
        assert "epsilon (Ferrari-Canny" in out


def test_joint_limit_hint_names_only_no_check_pose(tmp_path, capsys, tools):
    joints = "    default_joint_positions:\n      right_distal_joint: [0.5]\n"
    path = _scene(tmp_path, joints=joints)
    scene = load_scene(path)
    with pytest.raises(JointLimitError, match=r"pass check_pose=False to analyse"):
        tools.analyze_scene(scene)
    code, _, err = _run(capsys, "analyze", path)
    assert code == 1
    assert "add --no-check-pose to analyse it anyway" in err
    assert "--allow-penetration" not in err
    code, out, _ = _run(capsys, "analyze", path, "--no-check-pose")
    assert code == 0 and "pose: INVALID" in out
