"""Directives that Drake refuses by ending the program, refused as scene errors.

Drake checks a directive list with ``DRAKE_DEMAND`` (a list item that names no
kind, or two; ``file: ''``, ``name: ''``, an empty weld frame), which pydrake
raises as ``SystemExit`` after logging why: ``load_scene`` ended the caller's
program past any ``except Exception``, and the command printed Drake's two
lines instead of one.
"""

from __future__ import annotations

import logging
import subprocess
import sys

import pytest

import drakegrasp as dg
from drakegrasp.cli import main
from drakegrasp.errors import SceneError
from drakegrasp.plant.models import drake_reading
from drakegrasp.plant.scene import DEFAULT_SCENE, scene_path

DEFAULT = scene_path(DEFAULT_SCENE).read_text()
WELD = "- add_weld:\n    parent: world\n    child: gripper::palm\n"
assert WELD in DEFAULT

EDITS = {
    "an item of no kind": (
        lambda t: t.replace(WELD, "- {}\n" + WELD),
        "Specify one of",
    ),
    "two kinds in one item": (
        lambda t: t.replace(WELD, WELD + "  add_frame:\n    name: f\n"),
        "Specify one of",
    ),
    "an empty file": (
        lambda t: t.replace("package://drakegrasp/objects/box.sdf", "''"),
        "`file` must be non-empty",
    ),
    "an empty model name": (
        lambda t: t.replace("name: box", "name: ''"),
        "`name` must be non-empty",
    ),
    "an empty weld parent": (
        lambda t: t.replace("parent: world", "parent: ''"),
        "`parent` must be non-empty",
    ),
    "an empty included file": (
        lambda t: t.replace(WELD, "- add_directives:\n    file: ''\n" + WELD),
        "`file` must be non-empty",
    ),
}


@pytest.mark.parametrize("case", sorted(EDITS))
def test_a_directive_drake_demands_otherwise_is_a_scene_error(tmp_path, case):
    edit, said = EDITS[case]
    path = tmp_path / "scene.yaml"
    path.write_text(edit(DEFAULT))
    with pytest.raises(SceneError, match="bad model directives") as info:
        dg.load_scene(path)
    assert said in str(info.value) and str(path) in str(info.value)


def test_an_included_file_drake_refuses_names_that_file(tmp_path):
    (tmp_path / "more.yaml").write_text("directives:\n- {}\n")
    path = tmp_path / "scene.yaml"
    path.write_text(
        DEFAULT.replace(WELD, WELD + "- add_directives:\n    file: more.yaml\n")
    )
    with pytest.raises(SceneError, match="Specify one of") as info:
        dg.load_scene(path)
    assert "more.yaml" in str(info.value)


def test_the_command_prints_one_line(tmp_path, capsys):
    path = tmp_path / "scene.yaml"
    path.write_text(EDITS["an item of no kind"][0](DEFAULT))
    assert main(["analyze", str(path)]) == 1
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1
    assert "bad model directives" in captured.err


def test_in_a_fresh_process_stderr_has_one_line(tmp_path):
    # Drake's logger writes its reason to stderr itself when nothing handles it.
    path = tmp_path / "scene.yaml"
    path.write_text(EDITS["an empty weld parent"][0](DEFAULT))
    run = subprocess.run(
        [sys.executable, "-m", "drakegrasp", "analyze", str(path)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 1 and run.stdout == ""
    assert run.stderr.count("\n") == 1, run.stderr
    assert "`parent` must be non-empty" in run.stderr


def test_what_drake_logs_without_refusing_reaches_its_logger(caplog):
    def warns():
        logging.getLogger("drake").warning("a mesh has no normals")
        return 7

    with caplog.at_level(logging.WARNING, logger="drake"):
        assert drake_reading(warns) == 7
    assert [r.getMessage() for r in caplog.records] == ["a mesh has no normals"]


def test_a_refusal_keeps_its_reason():
    def demands():
        logging.getLogger("drake").error("directive: Specify one of")
        raise SystemExit("Failure at ...: condition 'directives.IsValid()' failed.")

    with pytest.raises(RuntimeError, match="^directive: Specify one of$"):
        drake_reading(demands)
    logger = logging.getLogger("drake")
    assert logger.propagate and not any(
        type(h).__name__ == "_Collected" for h in logger.handlers
    )


@pytest.mark.parametrize(
    "rotation, says",
    [
        ("!Rpy { rad: [0.0, 0.0, 1.0] }", "unknown key 'rad' in an !Rpy rotation"),
        ("!AngleAxis { angle: 1.0, axis: [0, 0, 1] }", "angle_deg: a, axis"),
    ],
)
def test_a_rotation_in_radians_is_told_degrees(tmp_path, rotation, says):
    # Drake's own text named the key, then nine enclosing schemas
    path = tmp_path / "scene.yaml"
    assert "rotation: !Rpy {deg: [0.0, 0.0, 0.0]}" in DEFAULT
    path.write_text(DEFAULT.replace("!Rpy {deg: [0.0, 0.0, 0.0]}", rotation, 1))
    with pytest.raises(SceneError, match="bad model directives") as info:
        dg.load_scene(path)
    message = str(info.value)
    assert says in message and "degrees" in message and "while visiting" not in message
    line = next(k for k, t in enumerate(DEFAULT.splitlines(), 1) if "!Rpy" in t)
    assert f"line {line}, column" in message
