"""Scene paths that exist but are no files: a named pipe, a device.

``drakegrasp analyze /dev/null`` (or a FIFO) said "scene ... not found: no
such file" of a path that exists, and reading a pipe as a scene file would
block until a writer came.  Both are named for what they are, by ``stat``,
without being opened.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from special_files import needs_mkfifo, watched_fifo

import drakegrasp as dg
from drakegrasp.errors import ModelError, SceneError
from drakegrasp.plant.scene import read_scene_info, scene_path


@needs_mkfifo
def test_a_named_pipe_is_named_not_missing(tmp_path):
    with watched_fifo(tmp_path / "scene.yaml") as pipe:
        for find in (scene_path, dg.load_scene):
            with pytest.raises(ModelError, match="named pipe") as err:
                find(pipe.path)
            assert "not found" not in str(err.value)
            assert "not a scene file" in str(err.value)
        with pytest.raises(SceneError, match=r"scene\.yaml.*named pipe"):
            read_scene_info(pipe.path)
    assert pipe.opened == 0


def test_a_device_is_named_not_missing():
    if not os.path.exists(os.devnull) or os.path.isfile(os.devnull):
        pytest.skip("no null device")
    with pytest.raises(ModelError, match="is a character device, not a scene file"):
        scene_path(os.devnull)
    with pytest.raises(SceneError, match="character device"):
        read_scene_info(os.devnull)


def test_a_missing_file_is_still_not_found(tmp_path):
    with pytest.raises(ModelError, match="not found: no such file"):
        scene_path(tmp_path / "nowhere.yaml")


@needs_mkfifo
def test_the_command_names_a_pipe_in_one_line(tmp_path):
    with watched_fifo(tmp_path / "scene.yaml") as pipe:
        run = subprocess.run(
            [sys.executable, "-m", "drakegrasp", "analyze", str(pipe.path)],
            capture_output=True, text=True, timeout=300,
        )  # fmt: skip
    assert pipe.opened == 0
    assert run.returncode != 0
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1, run.stderr
    assert "named pipe" in lines[0] and "not found" not in lines[0]


@needs_mkfifo
def test_a_model_file_that_is_a_pipe_is_refused_unopened(tmp_path):
    # a scene's add_model file, or add_models' file_name, that is a named
    # pipe blocked the joint-limit read and Drake's parser for good (fuzzer)
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    from drakegrasp.plant.models import models_dir

    scene = (models_dir() / "scenes" / "parallel_jaw_box.yaml").read_text()
    scene = scene.replace("package://drakegrasp/objects/box.sdf", "model.sdf")
    (tmp_path / "scene.yaml").write_text(scene)
    with watched_fifo(tmp_path / "model.sdf") as pipe:
        with pytest.raises(SceneError, match=r"model\.sdf' is a named pipe"):
            dg.load_scene(tmp_path / "scene.yaml")
        plant = MultibodyPlant(0.0)
        parser = Parser(plant)
        with pytest.raises(ModelError, match=r"model\.sdf' is a named pipe"):
            dg.plant.add_models(parser, file_name=pipe.path)
        del parser, plant
    assert pipe.opened == 0
