"""``plan``'s contact model, squeeze limit and the Franka alias, as flags."""

from __future__ import annotations

import json

import pytest

from drakegrasp.cli import main

ROUNDED = ["plan", "box", "--hand", "rounded", "--num", "40", "--top", "2"]
SOFT = ["--contact-model", "soft_finger", "--torsional-friction", "0.05"]


def test_soft_fingers_are_flags_and_the_hint_names_them(capsys):
    assert main(ROUNDED) == 0
    hard = capsys.readouterr().out
    assert "no closure" in hard
    assert "(--contact-model soft_finger --torsional-friction NU)" in hard
    assert main([*ROUNDED, *SOFT, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["settings"]["contact_model"] == "soft_finger"
    assert data["settings"]["torsional_friction"] == 0.05
    assert data["candidates"][0]["is_closure"]


def test_soft_fingers_without_nu_are_refused_in_flag_words(capsys):
    assert main([*ROUNDED, "--contact-model", "soft_finger"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "give --torsional-friction NU" in err[0]


def test_the_flags_override_a_scenes_contact_model(capsys):
    argv = ["plan", "parallel_jaw_box", "--num", "30", "--json", *SOFT]
    assert main(argv) == 0
    settings = json.loads(capsys.readouterr().out)["settings"]
    assert (settings["contact_model"], settings["torsional_friction"]) == (
        "soft_finger",
        0.05,
    )


def test_a_squeeze_limit_below_every_need_says_so(capsys):
    assert main([*ROUNDED, *SOFT, "--squeeze-limit", "1"]) == 0
    out = capsys.readouterr().out
    assert "the jaw at --squeeze-limit 1 N holds none of the" in out
    assert "N per finger (squeeze_needed)" in out


@pytest.mark.parametrize(
    "argv, code, words",
    [
        (["--squeeze-limit", "-1"], 2, "--squeeze-limit: must be finite and > 0"),
        (["--squeeze-limit", "nan"], 2, "--squeeze-limit: must be finite and > 0"),
        (["--torque-limit", "1"], 1, "give --squeeze-limit instead"),
        (["--contact-model", "rubber"], 2, "invalid choice: 'rubber'"),
        (["--torsional-friction", "-0.1"], 2, "--torsional-friction"),
    ],
)
def test_bad_flags_are_one_line(capsys, argv, code, words):
    try:
        status = main([*ROUNDED, *argv])
    except SystemExit as e:  # argparse's refusals
        status = e.code
    assert status == code
    err = capsys.readouterr().err.strip().splitlines()
    assert words in err[-1]


def test_a_multi_finger_hand_refuses_the_squeeze_limit(capsys):
    argv = [
        "plan",
        "sphere",
        "--hand",
        "package://drakegrasp/hands/three_finger_hand.sdf",
    ]
    assert main([*argv, "--num", "2", "--squeeze-limit", "5"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert (
        len(err) == 1
        and "give --torque-limit (N·m per motor, N at a prismatic one)" in err[0]
    )


def test_the_franka_alias_plans_with_its_pads(capsys, drake_models_dir, monkeypatch):
    monkeypatch.setenv("DRAKEGRASP_DRAKE_MODELS", str(drake_models_dir))
    argv = ["plan", "package://drake_models/ycb/004_sugar_box.sdf", "--hand"]
    assert main([*argv, "franka", "--num", "100", "--top", "3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    best = data["candidates"][0]
    # the four 1 mm pad spheres and the 9 mm sphere of a finger: more than
    # one contact each, so hard fingers reach force closure
    assert best["is_closure"] and best["num_contacts"] > 2
    assert data["reason"] == ""


def test_an_arm_with_a_hand_is_named_as_such(capsys, drake_models_dir, monkeypatch):
    monkeypatch.setenv("DRAKEGRASP_DRAKE_MODELS", str(drake_models_dir))
    arm = "package://drake_models/franka_description/urdf/panda_arm_hand.urdf"
    argv = ["plan", "package://drake_models/ycb/004_sugar_box.sdf", "--hand", arm]
    assert main([*argv, "--num", "5"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert "an arm that carries a hand is not a hand" in err[0]
    assert "load the hand's own model" in err[0]


def test_a_soft_finger_scene_without_nu_takes_the_flag(tmp_path, capsys):
    # as analyze does: the file's soft fingers without nu, nu from the flag
    from drakegrasp.plant.scene import DEFAULT_SCENE, scene_path

    text = scene_path(DEFAULT_SCENE).read_text()
    text = text.replace("contact_model: hard_finger", "contact_model: soft_finger")
    text = text.replace("  torsional_friction: 0.1\n", "")
    path = tmp_path / "soft.yaml"
    path.write_text(text)
    assert main(["plan", str(path), "--num", "20"]) == 1
    err = capsys.readouterr().err
    assert "torsional_friction is absent" in err
    assert "give --torsional-friction NU" in err
    argv = ["plan", str(path), "--num", "20", "--json", "--torsional-friction", "0.05"]
    assert main(argv) == 0
    settings = json.loads(capsys.readouterr().out)["settings"]
    assert (settings["contact_model"], settings["torsional_friction"]) == (
        "soft_finger",
        0.05,
    )
