"""Scene-file mistakes a newcomer makes, each answered in our own words.

A file without ``directives:`` got Drake's "the top level element should be a
Mapping"; a soft finger without ``torsional_friction`` a message naming
neither the file nor the key; a hand short of the object no word of
``--close``; and ``object_body: box`` was taken although a file names bodies
``model::body``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import drakegrasp as dg
from drakegrasp.cli import main
from drakegrasp.errors import NoContactsError, SceneError
from drakegrasp.plant.scene import DEFAULT_SCENE, read_scene_info, scene_path

DEFAULT = scene_path(DEFAULT_SCENE).read_text()
SECTION = DEFAULT[DEFAULT.index("drakegrasp:") :]


def _write(tmp_path: Path, text: str, name: str = "scene.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _cli_error(capsys, *argv) -> str:
    assert main(list(argv)) == 1
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1
    return captured.err


@pytest.mark.parametrize(
    ("text", "said"),
    [
        (SECTION, "has no 'directives:' key"),
        ("directives:\n" + SECTION, "'directives:' must be a list"),
        (DEFAULT.replace("directives:", "directive:"), "unknown top-level key"),
    ],
)
def test_a_file_without_a_directives_list_is_refused_naming_file_and_key(
    tmp_path, capsys, text, said
):
    path = _write(tmp_path, text)
    with pytest.raises(SceneError) as info:
        dg.load_scene(path)
    message = str(info.value)
    assert str(path) in message and said in message
    assert "top level element" not in message and "did not match" not in message
    assert said in _cli_error(capsys, "analyze", str(path))


def test_a_soft_finger_file_without_nu_names_the_file_and_the_key(tmp_path, capsys):
    text = DEFAULT.replace("  torsional_friction: 0.1\n", "").replace(
        "contact_model: hard_finger", "contact_model: soft_finger"
    )
    path = _write(tmp_path, text, "soft.yaml")
    with pytest.raises(SceneError) as info:
        read_scene_info(path)
    for message in (
        str(info.value),
        _cli_error(capsys, "analyze", str(path)),
        _cli_error(capsys, "plan", str(path), "--num", "5"),
    ):
        assert str(path) in message
        assert "drakegrasp.torsional_friction is absent" in message
        assert "soft_finger" in message and "hard_finger" in message


def test_a_hand_short_of_the_object_is_told_about_closing(tmp_path, capsys):
    path = _write(tmp_path, DEFAULT.replace("[0.025]", "[0.04]"), "open.yaml")
    scene = dg.load_scene(path)
    with pytest.raises(NoContactsError) as info:
        dg.analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    message = str(info.value)
    assert message.startswith("the hand does not touch 'box::box'")
    assert "--close" in message and "close_hand" in message
    err = _cli_error(capsys, "analyze", str(path))
    assert "drakegrasp analyze SCENE --close" in err
    # and the flag named does close it
    assert main(["analyze", str(path), "--close"]) == 0
    assert "force closure" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("old", "new", "said"),
    [
        (
            "object_body: box::box",
            "object_body: box",
            "object_body 'box' has no model scope; a scene file names a body "
            "'model::body' (the bodies named 'box': ['box::box'])",
        ),
        (
            "object_body: box::box",
            "object_body: lid",
            "object_body 'lid' has no model scope; a scene file names a body "
            "'model::body' (no body is named 'lid'; the bodies are "
            "['gripper::palm', 'gripper::left_finger', 'gripper::right_finger', "
            "'box::box'])",
        ),
        (
            "  hand: gripper",
            "  hand: [left_finger, gripper::right_finger]",
            "hand 'left_finger' has no model scope",
        ),
    ],
)
def test_an_unscoped_body_name_is_refused_with_the_scoped_names(
    tmp_path, capsys, old, new, said
):
    path = _write(tmp_path, DEFAULT.replace(old, new))
    with pytest.raises(SceneError) as info:
        dg.load_scene(path)
    assert str(path) in str(info.value) and said in str(info.value)
    assert said in _cli_error(capsys, "analyze", str(path))
    if "hand" in old:  # the scoped name it shows is accepted
        fixed = DEFAULT.replace(old, new.replace("[left", "[gripper::left"))
        scene = dg.load_scene(_write(tmp_path, fixed, "fixed.yaml"))
        assert [b.name() for b in scene.hand] == ["left_finger", "right_finger"]


_NESTED_MOUNT = """<?xml version="1.0"?>
<sdf version="1.9">
<model name="mount">
  {base}
  <model name="gripper">
    <include><uri>package://drakegrasp/hands/parallel_jaw.sdf</uri><name>jaw</name>
    </include>
  </model>
  {joint}
</model>
</sdf>
"""

_NESTED_SCENE = """directives:
- add_model:
    name: rig
    file: file://{sdf}
- add_weld:
    parent: world
    child: {child}
- add_model:
    name: box
    file: package://drakegrasp/objects/box.sdf
    default_free_body_pose:
      box:
        translation: [0.0, 0.0, 0.065]
drakegrasp:
  object_body: box::box
  hand: rig
  mu: 0.5
"""


def test_a_weld_of_a_nested_model_is_refused_with_the_way_out(tmp_path, capsys):
    # Drake's directives record a weld by the model an add_model added and
    # demand to find it: a nested model's frame read "AddWeld(): condition
    # 'found' failed", naming neither the weld nor what to do instead.
    sdf = _write(tmp_path, _NESTED_MOUNT.format(base="", joint=""), "mount.sdf")
    scene = _write(
        tmp_path, _NESTED_SCENE.format(sdf=sdf, child="rig::gripper::jaw::palm")
    )
    with pytest.raises(SceneError) as e:
        dg.load_scene(scene)
    said = str(e.value)
    assert "'rig::gripper::jaw::palm'" in said and "nested in 'rig'" in said
    assert "condition 'found'" not in said
    assert "add_model of its own" in said
    assert "nested in 'rig'" in _cli_error(capsys, "analyze", str(scene))

    # An add_model whose own name is scoped under the outer model's
    # ("rig::extra") is no nested model: its weld is not the one named.
    extra = _NESTED_SCENE.format(sdf=sdf, child="rig::gripper::jaw::palm").replace(
        "- add_weld:",
        "- add_model:\n    name: rig::extra\n    file: "
        "package://drakegrasp/hands/parallel_jaw.sdf\n- add_weld:\n    parent: "
        "world\n    child: rig::extra::palm\n- add_weld:",
        1,
    )
    with pytest.raises(SceneError, match="'rig::gripper::jaw::palm' is a frame"):
        dg.load_scene(_write(tmp_path, extra, "extra.yaml"))

    # The way out the message gives loads: a link of the outer model itself,
    # fixed to the nested one in the model file, welded to the world.
    fixed = _NESTED_MOUNT.format(
        base='<link name="base"><inertial><mass>1</mass></inertial></link>',
        joint='<joint name="fix" type="fixed"><parent>base</parent>'
        "<child>gripper::jaw::palm</child></joint>",
    )
    _write(tmp_path, fixed, "mount.sdf")
    _write(tmp_path, _NESTED_SCENE.format(sdf=sdf, child="rig::base"))
    loaded = dg.load_scene(scene)
    assert loaded.plant.HasModelInstanceNamed("rig::gripper::jaw")


def test_a_nested_weld_in_a_scoped_add_model_names_that_model(tmp_path):
    # An add_model named rig::extra beside rig, whose own file nests the jaw:
    # its weld of rig::extra::gripper::jaw::palm is nested in rig::extra (the
    # model the directives weld by), not in rig, whose links it cannot reach.
    sdf = _write(tmp_path, _NESTED_MOUNT.format(base="", joint=""), "mount.sdf")
    scene = _NESTED_SCENE.format(sdf=sdf, child="rig::palm_of_nothing").replace(
        "- add_weld:\n    parent: world\n    child: rig::palm_of_nothing\n",
        f"- add_model:\n    name: rig::extra\n    file: file://{sdf}\n"
        "- add_weld:\n    parent: world\n    child: rig::extra::gripper::jaw::palm\n",
    )
    with pytest.raises(SceneError) as e:
        dg.load_scene(_write(tmp_path, scene, "scoped.yaml"))
    said = str(e.value)
    assert "nested in 'rig::extra'" in said, said
    assert "a link of 'rig::extra' itself" in said, said
