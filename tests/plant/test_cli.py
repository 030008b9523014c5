"""The drakegrasp command: analyze, scenes, and one-line errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from drakegrasp.cli import build_parser, main
from drakegrasp.plant import DEFAULT_SCENE, list_scenes
from drakegrasp.plant.scene import scene_path


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_analyze_default_scene(capsys):
    code, out, err = run(capsys, "analyze")
    assert code == 0 and err == ""
    assert f"scene {DEFAULT_SCENE}" in out
    for text in (
        "2 contacts",
        "form closure: no",
        "force closure: no",
        "LP3",
        "antipodal (geometric test): YES",
        "rank 5/6",
    ):
        assert text in out


def test_analyze_options_change_the_verdict(capsys):
    code, out, _ = run(capsys, "analyze", "--contact-model", "soft_finger")
    assert code == 0 and "force closure: YES" in out
    code, out, _ = run(capsys, "analyze", "three_finger_sphere", "--mu", "0")
    assert code == 0 and "mu = 0\n" in out and "force closure: no" in out


def test_analyze_json(capsys):
    code, out, _ = run(capsys, "analyze", "planar_gripper_brick", "--json")
    assert code == 0
    data = json.loads(out)
    assert data["scene"] == "planar_gripper_brick"
    assert data["plane"] == "yz"
    assert data["force_closure"]["is_closure"] is True
    assert len(data["contacts"]) == 3


def test_analyze_a_scene_file_by_path(capsys):
    code, out, _ = run(capsys, "analyze", str(scene_path("three_finger_sphere")))
    assert code == 0 and "sphere::sphere" in out


def test_scenes_lists_every_shipped_scene(capsys):
    code, out, _ = run(capsys, "scenes")
    assert code == 0
    for info in list_scenes():
        assert info.name in out
    assert f"* {DEFAULT_SCENE}" in out


def _bad_scene(tmp_path, old, new):
    text = scene_path(DEFAULT_SCENE).read_text().replace(old, new)
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize(
    "make_args, fragment",
    [
        (lambda tmp: ["analyze", "no_such_scene"], "not found"),
        (lambda tmp: ["analyze", str(tmp / "missing.yaml")], "not found"),
        (
            lambda tmp: ["analyze", _bad_scene(tmp, "directives:", "directives: [")],
            "not valid YAML",
        ),
        (
            lambda tmp: ["analyze", _bad_scene(tmp, "box::box", "box::lid")],
            "no body named 'box::lid'",
        ),
        (
            lambda tmp: ["analyze", _bad_scene(tmp, "joint: [0.025]", "joint: [0.04]")],
            "does not touch 'box::box'",
        ),
        (
            lambda tmp: ["analyze", _bad_scene(tmp, "joint: [0.025]", "joint: [0.02]")],
            "penetrates the object",
        ),
        (
            lambda tmp: [
                "analyze",
                "planar_gripper_brick",
                "--contact-model",
                "soft_finger",
            ],
            "no soft fingers",
        ),
    ],
)
def test_errors_are_one_line_on_stderr(capsys, tmp_path, make_args, fragment):
    code, out, err = run(capsys, *make_args(tmp_path))
    assert code == 1
    assert out == ""
    assert err.startswith("drakegrasp: error: ")
    assert err.count("\n") == 1
    assert fragment in err
    assert "Traceback" not in err


def test_bad_command_line_exits_2(capsys):
    with pytest.raises(SystemExit) as info:
        main(["analyze", "--mu", "-3"])
    assert info.value.code == 2
    with pytest.raises(SystemExit):
        main([])


def test_parser_has_every_subcommand():
    parser, _ = build_parser()
    for command in (["analyze"], ["scenes"], ["batch", "in.npz", "out.npz"]):
        assert callable(parser.parse_args(command).func)


def test_module_and_console_script_run_from_another_directory(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "drakegrasp", "scenes"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    assert DEFAULT_SCENE in result.stdout
    script = Path(sys.executable).with_name("drakegrasp")
    if not script.exists():
        pytest.skip("the drakegrasp console script is not installed in this env")
    result = subprocess.run(
        [str(script), "analyze", "no_such_scene"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 1
    assert result.stderr.startswith("drakegrasp: error:")
    assert "Traceback" not in result.stderr


def test_every_analysis_option_is_a_flag_of_analyze_with_its_help():
    # AnalysisOptions gained coupling_tolerance without a flag: the command
    # line is to reach every option the library has, helped by its own words.
    from dataclasses import fields

    from drakegrasp.plant.options import OPTION_HELP, AnalysisOptions

    _, sub = build_parser()
    flags = {a.dest: a for a in sub.choices["analyze"]._actions}
    missing = [f.name for f in fields(AnalysisOptions) if f.name not in flags]
    assert missing == []
    for f in fields(AnalysisOptions):
        assert OPTION_HELP[f.name] in flags[f.name].help, f.name


def test_the_coupling_tolerance_flag_reaches_the_analysis(capsys):
    code, out, _ = run(capsys, "analyze", "--coupling-tolerance", "0.001", "--json")
    assert code == 0
    assert json.loads(out)["options"]["coupling_tolerance"] == 0.001
    code, out, err = run(capsys, "analyze", "--coupling-tolerance", "0.5")
    assert (code, out) == (1, "")
    assert "--coupling-tolerance" in err and err.count("\n") == 1
