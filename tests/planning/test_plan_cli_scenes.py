"""``drakegrasp plan`` on a shipped scene, with ``--mu plant`` and ``--progress``.

What its help promises: a shipped scene's name plans for the scene's hand and
object (the weld that places the hand for ``analyze`` is left out), a planar
scene is refused in one line, ``--mu plant`` reads the plant's friction as
``analyze --mu plant`` does, and ``--progress`` without tqdm is refused before
any work, as ``batch --progress`` is.
"""

from __future__ import annotations

import json
import sys

import pytest

import drakegrasp.planning
from drakegrasp.cli import build_parser, main
from drakegrasp.plant.scene import list_scenes, load_scene


def _help(*command: str) -> str:
    parser, sub = build_parser()
    return " ".join(sub.choices[command[0]].format_help().split())


def _plan_json(capsys, *argv: str) -> dict:
    assert main(["plan", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


# -- a shipped scene --------------------------------------------------------


def test_the_help_names_the_scenes_plan_takes():
    text = _help("plan")
    assert "a shipped scene's name" in text
    assert "not a planar one" in text
    assert "is left out" in text  # what becomes of the weld that places the hand


@pytest.mark.parametrize(
    "name",
    sorted(i.name for i in list_scenes() if i.plane is None and i.hand is not None),
)
def test_every_spatial_shipped_scene_welds_its_hand_yet_plans(name):
    """Each spatial shipped scene welds its hand to the world; freed, it plans."""
    welded = load_scene(name)
    freed = load_scene(name, free_hand=True)
    assert welded.plant.num_positions() < freed.plant.num_positions()
    # the freed hand's base is one free body: what the planner needs
    plant = freed.plant
    free = [
        i
        for i in plant.GetFloatingBaseBodies()
        if plant.get_body(i).model_instance() == freed.hand
    ]
    assert len(free) == 1


def test_a_shipped_scene_plans_with_its_hand_object_and_mu(capsys):
    data = _plan_json(capsys, "parallel_jaw_flat_box", "--num", "40", "--top", "3")
    assert data["object_body"] == "box::box" and data["mu"] == 0.5
    assert data["num_sampled"] == 40
    assert any(c["is_closure"] for c in data["candidates"])  # flat pads: patches
    # the same as planning the scene's object for its hand by name
    same = _plan_json(capsys, "box", "--hand", "flat", "--num", "40", "--top", "3")
    assert [c["is_closure"] for c in same["candidates"]] == [
        c["is_closure"] for c in data["candidates"]
    ]


def test_a_planar_shipped_scene_is_refused_in_one_line(capsys):
    assert main(["plan", "planar_gripper_brick", "--num", "5"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "planar" in err and "drakegrasp analyze planar_gripper_brick" in err


def test_a_scene_without_a_welded_hand_keeps_its_welds(tmp_path):
    """Only welds of the hand's instances to the world are left out."""
    scene = tmp_path / "s.yaml"
    scene.write_text(
        """
directives:
- add_model:
    name: gripper
    file: package://drakegrasp/hands/parallel_jaw_flat.sdf
- add_model:
    name: table
    file: package://drakegrasp/objects/box.sdf
- add_weld:
    parent: world
    child: table::box
- add_model:
    name: box
    file: package://drakegrasp/objects/box.sdf
drakegrasp:
  object_body: box::box
  hand: gripper
  mu: 0.5
"""
    )
    kept = load_scene(scene, free_hand=True).plant
    assert kept.num_positions() == load_scene(scene).plant.num_positions()


def test_a_soft_finger_scene_without_nu_is_refused_as_analyze_refuses_it(
    tmp_path, capsys
):
    """plan read ν = 0 from a file that gives none and planned soft fingers."""
    text = (load_scene().info.path).read_text()
    scene = tmp_path / "soft.yaml"
    scene.write_text(
        text.replace(
            "contact_model: hard_finger", "contact_model: soft_finger"
        ).replace("torsional_friction: 0.1", "")
    )
    for command in ("analyze", "plan"):
        extra = ["--num", "5"] if command == "plan" else []
        assert main([command, str(scene), *extra]) == 1
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "torsional_friction" in err, err


# -- --mu plant --------------------------------------------------------------


def test_mu_plant_is_the_plants_friction(capsys):
    # Drake's default friction (no material given) is 1 for every geometry
    for target in (["box"], ["parallel_jaw_box"]):
        data = _plan_json(capsys, *target, "--mu", "plant", "--num", "10")
        assert data["mu"] == 1.0
    assert "'plant'" in _help("plan")


_TWO_FRICTIONS = """<?xml version="1.0"?>
<sdf version="1.9" xmlns:drake="http://drake.mit.edu">
  <model name="slab">
    <link name="slab">
      <inertial><mass>0.2</mass></inertial>
      <collision name="low">
        <pose>0 0 -0.02 0 0 0</pose>
        <geometry><box><size>0.04 0.04 0.04</size></box></geometry>
        <drake:proximity_properties>
          <drake:mu_static>0.3</drake:mu_static>
          <drake:mu_dynamic>0.3</drake:mu_dynamic>
        </drake:proximity_properties>
      </collision>
      <collision name="high">
        <pose>0 0 0.02 0 0 0</pose>
        <geometry><box><size>0.04 0.04 0.04</size></box></geometry>
        <drake:proximity_properties>
          <drake:mu_static>0.6</drake:mu_static>
          <drake:mu_dynamic>0.6</drake:mu_dynamic>
        </drake:proximity_properties>
      </collision>
    </link>
  </model>
</sdf>
"""


def test_mu_plant_takes_the_smallest_pair_and_says_so(tmp_path, capsys):
    model = tmp_path / "slab.sdf"
    model.write_text(_TWO_FRICTIONS)
    assert main(["plan", str(model), "--mu", "plant", "--num", "10", "--json"]) == 0
    captured = capsys.readouterr()
    low, high = 2 * 0.3 / 1.3, 2 * 0.6 / 1.6  # Drake's combination with μ = 1
    assert json.loads(captured.out)["mu"] == pytest.approx(low)
    notes = [x for x in captured.err.splitlines() if x.startswith("drakegrasp: note")]
    assert len(notes) == 1  # (beside any notice of numba compiling)
    assert f"from {low:g} to {high:g}" in notes[0] and "smallest" in notes[0]


def test_mu_plant_is_the_dynamic_coefficient_a_simulation_uses(tmp_path, capsys):
    # The planning plant is continuous (its rule: static), but a grip is
    # checked in discrete simulations, which use the dynamic coefficient:
    # planned with the static 0.9, grasps fell at 1.2 x the squeeze needed.
    model = tmp_path / "slab.sdf"
    model.write_text(
        _TWO_FRICTIONS.replace("<drake:mu_static>0.3", "<drake:mu_static>0.9").replace(
            "<drake:mu_static>0.6", "<drake:mu_static>0.9"
        )
    )
    assert main(["plan", str(model), "--mu", "plant", "--num", "10", "--json"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["mu"] == pytest.approx(2 * 0.3 / 1.3)
    assert "dynamic" in captured.err


def test_the_friction_rule_can_be_chosen():
    from drakegrasp.planning.scenes import planning_scene
    from drakegrasp.plant.friction import hand_object_friction

    with pytest.raises(drakegrasp.InvalidOptionError, match="rule must be"):
        hand_object_friction(None, None, "box::box", rule="kinetic")
    scene = planning_scene(
        "package://drakegrasp/objects/box.sdf",
        hand_url="package://drakegrasp/hands/parallel_jaw.sdf",
    )
    args = (scene.plant, scene.context, scene.object_body)
    for rule in (None, "static", "dynamic"):
        assert hand_object_friction(*args, rule=rule).tolist() == [1.0]


def test_mu_still_refuses_a_bad_word(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["plan", "--mu", "plants"])
    assert exit_.value.code == 2
    assert "argument --mu" in capsys.readouterr().err


# -- --progress without tqdm -------------------------------------------------


def test_progress_help_names_the_extra():
    assert 'pip install "drakegrasp[progress]"' in _help("plan")


def test_progress_without_tqdm_is_refused_before_any_work(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm", None)  # import tqdm fails
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)

    def no_work(*args, **kwargs):
        raise AssertionError("planned without the progress bar it was asked for")

    monkeypatch.setattr(drakegrasp.planning, "planning_scene", no_work)
    assert main(["plan", "box", "--num", "5", "--progress"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "--progress needs the optional package tqdm" in err
    assert 'pip install "drakegrasp[progress]"' in err


def test_batch_progress_without_tqdm_says_the_same(monkeypatch, capsys, tmp_path):
    import numpy as np

    monkeypatch.setitem(sys.modules, "tqdm", None)
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    p = np.random.default_rng(0).normal(size=(4, 3, 3))
    np.savez(tmp_path / "in.npz", positions=p, normals=-p)
    out = tmp_path / "out.npz"
    argv = ["batch", str(tmp_path / "in.npz"), str(out), "--mu", "0.5", "--progress"]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--progress needs the optional package tqdm" in err
    assert not out.exists()
