"""A model path that is no file is refused before any model loads.

``planning_scene("nosuch")`` loaded Drake's WSG first, so offline the wrong
object name came back as the hand's failed download of drake_models.
"""

from __future__ import annotations

import pytest

from drakegrasp.errors import ModelError
from drakegrasp.planning.scenes import planning_scene
from drakegrasp.plant.models import models_dir

JAW = "package://drakegrasp/hands/parallel_jaw.sdf"


@pytest.mark.parametrize("name", ["nosuch", "x.npz", "no/such/dir/box.sdf"])
def test_an_object_path_that_is_no_file_is_named(monkeypatch, name):
    # No local drake_models: the default hand would have to be downloaded.
    monkeypatch.delenv("DRAKEGRASP_DRAKE_MODELS", raising=False)
    with pytest.raises(ModelError, match=rf"object_url '{name}' is not a file"):
        planning_scene(name)


def test_a_directory_is_named_as_one(tmp_path):
    with pytest.raises(ModelError, match="object_url .* is a directory"):
        planning_scene(tmp_path, hand_url=JAW)
    with pytest.raises(ModelError, match="hand_url .* is a directory"):
        planning_scene(None, hand_url=tmp_path)


def test_files_and_urls_still_load(tmp_path):
    scene = planning_scene("package://drakegrasp/objects/box.sdf", hand_url=JAW)
    assert scene.object_body is not None


def test_a_pathlib_path_loads_as_its_string(tmp_path):
    # The check let a Path through, then `"://" in url` raised a bare TypeError.
    box = models_dir() / "objects" / "box.sdf"
    jaw = models_dir() / "hands" / "parallel_jaw.sdf"
    scene = planning_scene(box, hand_url=jaw)
    assert scene.object_body.name() == "box"
    assert scene.plant.GetModelInstanceName(scene.hand) == "parallel_jaw"
