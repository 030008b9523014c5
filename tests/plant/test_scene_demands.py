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


def test_a_refusal_drops_what_the_reader_said_it_was_doing(caplog):
    # offline, Drake logs "Downloading <url>" at INFO and then refuses with an
    # error naming that url: the INFO line came before the CLI's one line
    drake = logging.getLogger("drake")

    def downloads():
        drake.info("PackageMap: Downloading https://example.invalid/models.tar.gz")
        drake.warning("a mesh has no normals")
        raise RuntimeError("when downloading 'drake_models' ... failed")

    with caplog.at_level(logging.INFO, logger="drake"):
        with pytest.raises(RuntimeError, match="downloading 'drake_models'"):
            drake_reading(downloads)
    assert [r.getMessage() for r in caplog.records] == ["a mesh has no normals"]
    caplog.clear()

    def reads():  # the same lines from a reader that does not refuse: kept
        drake.info("PackageMap: Downloading https://example.invalid/models.tar.gz")
        return 3

    with caplog.at_level(logging.INFO, logger="drake"):
        assert drake_reading(reads) == 3
    assert [r.levelno for r in caplog.records] == [logging.INFO]


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


ROTATION = "rotation: !Rpy {deg: [0.0, 0.0, 0.0]}"
TRANSLATION = "translation: [0.0, 0.0, 0.065]"
BOX_POSE = "directives[2].add_model.default_free_body_pose.box"


@pytest.mark.parametrize(
    "old, new, says",
    [
        # Drake read these without a word and dropped the rotation
        (ROTATION, "rotation: !AngleAxis {angle_deg: 90, axis: [0, 0, 0]}",
         "!AngleAxis axis [0.0, 0.0, 0.0] is zero: the axis must be a non-zero"),
        (ROTATION, "rotation: !AngleAxis {angle_deg: 90, axis: [1e-300, 0, 0]}",
         "is too short to normalise in double precision"),
        (ROTATION, "rotation: !AngleAxis {angle_deg: 90, axis: [1e200, 0, 0]}",
         "is too long to normalise in double precision"),
        # Drake: "NaN is detected during Symbolic computation.", no key named
        (ROTATION, "rotation: !Rpy {deg: [.nan, 0.0, 0.0]}",
         "rotation !Rpy deg [nan, 0.0, 0.0] must be finite (degrees)"),
        (ROTATION, "rotation: !Rpy {deg: [0.0, -.inf, 0.0]}",
         "rotation !Rpy deg [0.0, -inf, 0.0] must be finite (degrees)"),
        (ROTATION, "rotation: !AngleAxis {angle_deg: .nan, axis: [0, 0, 1]}",
         "rotation !AngleAxis angle_deg nan must be finite (degrees)"),
        # Drake took these, and turned the box by whatever the rounding left
        (ROTATION, "rotation: !Rpy {deg: [1e300, 0.0, 0.0]}",
         "!Rpy deg [1e+300, 0.0, 0.0] is beyond ±1e+08 degrees"),
        (ROTATION, "rotation: !AngleAxis {angle_deg: -2e8, axis: [0, 0, 1]}",
         "!AngleAxis angle_deg -200000000.0 is beyond ±1e+08 degrees"),
        # refused later, as a body's position, without the key
        (TRANSLATION, "translation: [.nan, 0.0, 0.065]",
         "translation [nan, 0.0, 0.065] must be finite (metres)"),
        (TRANSLATION, "translation: [0.0, .inf, 0.065]",
         "translation [0.0, inf, 0.065] must be finite (metres)"),
    ],
)  # fmt: skip
def test_a_pose_drake_would_drop_or_fail_on_is_refused_by_line_and_key(
    tmp_path, old, new, says
):
    assert old in DEFAULT
    path = tmp_path / "scene.yaml"
    path.write_text(DEFAULT.replace(old, new, 1))
    with pytest.raises(SceneError) as info:
        dg.load_scene(path)
    message = str(info.value)
    line = next(k for k, t in enumerate(DEFAULT.splitlines(), 1) if old in t)
    assert message.startswith(f"scene {str(path)!r}: line {line}, column "), message
    key = old.split(":")[0]  # rotation or translation
    assert f"{BOX_POSE}.{key} " in message and says in message, message


def test_angles_of_a_few_turns_either_way_are_taken(tmp_path):
    path = tmp_path / "scene.yaml"
    for rotation in (
        "rotation: !Rpy {deg: [720.0, -1e8, 0.0]}",
        "rotation: !AngleAxis {angle_deg: -1e8, axis: [0, 0, 1]}",
    ):
        path.write_text(DEFAULT.replace(ROTATION, rotation, 1))
        scene = dg.load_scene(path)  # the check refuses nothing here
        assert scene.object_body.name() == "box"


def test_the_poses_of_frames_welds_and_included_files_are_checked(tmp_path):
    zero = "!AngleAxis {angle_deg: 90, axis: [0, 0, 0]}"
    frame = (
        "- add_frame:\n    name: tilted\n    X_PF:\n      base_frame: world\n"
        f"      rotation: {zero}\n"
    )
    path = tmp_path / "frame.yaml"
    path.write_text(DEFAULT.replace(WELD, WELD + frame))
    with pytest.raises(SceneError, match=r"directives\[2\]\.add_frame\.X_PF\.rotation"):
        dg.load_scene(path)
    weld = WELD + f"    X_PC:\n      rotation: {zero}\n"
    path.write_text(DEFAULT.replace(WELD, weld))
    with pytest.raises(SceneError, match=r"directives\[1\]\.add_weld\.X_PC\.rotation"):
        dg.load_scene(path)
    inner = tmp_path / "inner.yaml"
    inner.write_text("directives:\n" + frame)
    path.write_text(
        DEFAULT.replace(
            "directives:\n",
            f"directives:\n- add_directives:\n    file: file://{inner}\n",
        )
    )
    with pytest.raises(SceneError) as info:
        dg.load_scene(path)
    assert str(info.value).startswith(f"scene {str(inner)!r}: line 6, column ")
    assert "add_frame.X_PF.rotation !AngleAxis axis [0.0, 0.0, 0.0] is zero" in str(
        info.value
    )


def test_an_axis_of_any_normalisable_length_still_rotates(tmp_path):
    path = tmp_path / "scene.yaml"
    path.write_text(
        DEFAULT.replace(
            ROTATION, "rotation: !AngleAxis {angle_deg: 90, axis: [0, 0, 5]}"
        )
    )
    scene = dg.load_scene(path)
    R = scene.object_body.EvalPoseInWorld(scene.plant_context).rotation().matrix()
    assert abs(R[1, 0] - 1.0) < 1e-12 and abs(R[0, 1] + 1.0) < 1e-12
