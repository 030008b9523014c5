"""A hand or object that is a nested SDFormat ``<model>`` plans as the bare one.

A file whose models nest (``robot`` holding ``robot::hand``) adds the empty
outer instance first: ``planning_scene`` took it for the object and failed
with a bare ``IndexError`` (``drakegrasp plan``: "a bug in drakegrasp"), and
took it for the hand, which then had "no bodies that can move", with no way
on the command line to name the inner one.
"""

from __future__ import annotations

import numpy as np
import pytest

from drakegrasp.errors import ModelError
from drakegrasp.planning.grasp_scene import grasp_scene_text
from drakegrasp.planning.planner import plan_grasps
from drakegrasp.planning.scenes import planning_scene

JAW = "package://drakegrasp/hands/parallel_jaw.sdf"
BOX = "package://drakegrasp/objects/box.sdf"


def _nested(tmp_path, name: str, uri: str) -> str:
    path = tmp_path / f"{name}.sdf"
    path.write_text(
        f'<?xml version="1.0"?>\n<sdf version="1.9"><model name="{name}">'
        f"<include><uri>{uri}</uri></include></model></sdf>\n"
    )
    return str(path)


def _plan(scene):
    return plan_grasps(
        scene.plant,
        scene.context,
        scene.object_body,
        hand=scene.hand,
        num_candidates=30,
        mu=0.5,
        seed=0,
    )


def test_nested_models_plan_as_the_bare_ones(tmp_path):
    nested = planning_scene(
        _nested(tmp_path, "shelf", BOX), hand_url=_nested(tmp_path, "robot", JAW)
    )
    assert nested.object_body.scoped_name().get_full() == "shelf::box::box"
    assert nested.plant.GetModelInstanceName(nested.hand) == "robot::parallel_jaw"
    bare = planning_scene(BOX, hand_url=JAW)
    got, want = _plan(nested), _plan(bare)
    assert len(want) > 0
    assert len(got) == len(want)
    np.testing.assert_allclose(
        [c.score for c in got], [c.score for c in want], rtol=1e-9, atol=1e-12
    )


def test_a_nested_hand_scene_file_is_refused_for_what_it_is(tmp_path):
    # Drake's directives cannot set a nested model's joints: the writer said
    # the hand "spans the model instances ['robot', 'robot::parallel_jaw']".
    scene = planning_scene(BOX, hand_url=_nested(tmp_path, "robot", JAW))
    best = _plan(scene)[0]
    with pytest.raises(ModelError, match="'robot::parallel_jaw' is a <model> nested"):
        grasp_scene_text(
            scene.plant, scene.context, best, object_body=scene.object_body,
            hand_file=tmp_path / "robot.sdf", object_file=BOX, mu=0.5,
            folder=tmp_path,
        )  # fmt: skip
