"""A grasp under load from a scene file and from the command line.

``load:`` and ``torque_limits:`` in a scene's ``drakegrasp:`` section, and
``analyze --load`` / ``--torque-limits``, give the load section of
``analyze_grasp``; checked against the Python call with the same keywords
(the report's load section, figure for figure) and against a hand
calculation: two hard fingers squeezing the default scene's box sideways hold
its weight with a least squeeze of ``m g / μ``.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from drakegrasp import analyze_grasp, load_scene
from drakegrasp.cli import main
from drakegrasp.errors import SceneError
from drakegrasp.plant.scene import DEFAULT_SCENE, scene_path

DEFAULT = scene_path(DEFAULT_SCENE).read_text()
LOADED = DEFAULT.replace(
    "  mu: 0.5", "  mu: 0.5\n  load: gravity\n  torque_limits: plant"
)


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scene.yaml"
    path.write_text(text)
    return path


def test_a_scenes_load_is_the_python_calls(tmp_path):
    scene = load_scene(_write(tmp_path, LOADED))
    assert (scene.info.load, scene.info.torque_limits) == ("gravity", "plant")
    report = analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    plain = load_scene(DEFAULT_SCENE)
    direct = analyze_grasp(
        plain.plant, plain.plant_context, **plain.analysis_options(),
        load="gravity", torque_limits="plant",
    )  # fmt: skip
    assert report.load is not None and report.load.holds
    assert report.load.to_dict() == direct.load.to_dict()
    ctx = scene.plant_context
    weight = scene.object_body.get_mass(ctx) * 9.81
    squeeze = report.load.to_dict()["forces"]["squeeze"]  # both fingers, N
    assert squeeze == pytest.approx(weight / 0.5, rel=1e-6)


def test_analyze_reads_the_scene_and_the_flags(tmp_path, capsys):
    path = str(_write(tmp_path, LOADED))
    assert main(["analyze", path]) == 0
    assert "Load (gravity" in capsys.readouterr().out
    # the flags override the scene: twice the weight, straight down in O
    assert main(["analyze", path, "--json", "--load", "0,0,-2,0,0,0"]) == 0
    load = json.loads(capsys.readouterr().out)["load"]
    assert load["wrench"] == [0.0, 0.0, -2.0, 0.0, 0.0, 0.0]
    assert main(["analyze", "--load", "gravity", "--torque-limits", "plant"]) == 0
    assert "holds: yes" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv, words",
    [
        (["--torque-limits", "plant"], "--torque-limits are the motors of the load"),
        (["--load", "1,2"], "--load must be 'gravity' or a spatial wrench"),
        (["--load", "gravity", "--torque-limits", "1,nan"], "--torque-limits"),
    ],
)
def test_bad_load_flags_are_one_line(capsys, argv, words):
    assert main(["analyze", *argv]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0], err


def test_a_load_flag_that_is_no_number_is_an_argument_error(capsys):
    with pytest.raises(SystemExit) as info:
        main(["analyze", "--load", "heavy"])
    assert info.value.code == 2
    assert "expected 'gravity' or comma-separated numbers" in capsys.readouterr().err


@pytest.mark.parametrize(
    "keys, fragment",
    [
        ("  load: weight", "drakegrasp.load must be 'gravity'"),
        ("  load: [1, 2]", "drakegrasp.load must be 'gravity' or a spatial wrench"),
        ("  load: [0, 0, .nan, 0, 0, 0]", "load must be a 1-D sequence of one or"),
        ("  load: [0, 0, true, 0, 0, 0]", "drakegrasp.load must be 'gravity', numbers"),
        ("  load: []", "drakegrasp.load must be"),
        ("  load: gravity\n  torque_limits: [-1, 1]", "numbers >= 0 (inf: no limit)"),
        ("  load: gravity\n  torque_limits: motors", "torque_limits must be 'plant'"),
        ("  torque_limits: plant", "torque_limits without drakegrasp.load"),
    ],
)
def test_bad_load_keys_name_the_key(tmp_path, keys, fragment):
    path = _write(tmp_path, DEFAULT.replace("  mu: 0.5", "  mu: 0.5\n" + keys))
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert fragment in str(info.value) and str(path) in str(info.value)


def test_a_planar_scene_takes_a_planar_load(tmp_path):
    planar = scene_path("planar_gripper_brick").read_text()
    assert "  plane: yz" in planar
    good = planar.replace("  plane: yz", "  plane: yz\n  load: [0, -1, 0]")
    assert load_scene(_write(tmp_path, good)).info.load == (0.0, -1.0, 0.0)
    bad = planar.replace("  plane: yz", "  plane: yz\n  load: [0, 0, -1, 0, 0, 0]")
    with pytest.raises(SceneError, match="a planar wrench"):
        load_scene(_write(tmp_path, bad))


def test_one_torque_limit_for_all_in_a_scene_and_in_python(tmp_path):
    # "one for all" (docs/scene_format.md): `torque_limits: 100` and
    # torque_limits=100.0 were refused, where [100] was taken.
    scalar = DEFAULT.replace(
        "  mu: 0.5", "  mu: 0.5\n  load: gravity\n  torque_limits: 100"
    )
    scene = load_scene(_write(tmp_path, scalar))
    assert scene.info.torque_limits == (100.0,)
    report = analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    plain = load_scene(DEFAULT_SCENE)
    args = (plain.plant, plain.plant_context)
    listed = analyze_grasp(
        *args, **plain.analysis_options(), load="gravity", torque_limits=[100.0]
    )
    direct = analyze_grasp(
        *args, **plain.analysis_options(), load="gravity", torque_limits=100.0
    )
    assert report.load.to_dict() == listed.load.to_dict() == direct.load.to_dict()
    assert list(report.load.torque_limits) == [100.0] * len(report.load.torque_limits)
