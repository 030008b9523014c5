"""draw_grasp options for real hands: on_top, size, translucent (no browser)."""

import pytest
from pydrake.geometry import Meshcat, Sphere

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError
from drakegrasp.visualization import set_translucent, visualizer_paths


@pytest.fixture
def recorded(monkeypatch):
    """Every Meshcat.SetProperty call, {(path, name): value} (pydrake cannot
    read properties back)."""
    calls = {}
    original = Meshcat.SetProperty

    def record(self, path, name, value, *args, **kwargs):
        calls[(path, name)] = value
        return original(self, path, name, value, *args, **kwargs)

    monkeypatch.setattr(Meshcat, "SetProperty", record)
    return calls


@pytest.fixture(scope="module")
def grasp():
    return dg.examples.equator_fingers(mu=0.5)


def test_size_sets_the_scale_of_the_defaults(meshcat, grasp):
    base = dg.draw_grasp(meshcat, grasp)
    assert base.cone_height == pytest.approx(0.4 * grasp.characteristic_length)
    scaled = dg.draw_grasp(meshcat, grasp, size=0.2)
    assert scaled.cone_height == pytest.approx(0.08)
    with pytest.raises(InvalidOptionError, match="size"):
        dg.draw_grasp(meshcat, grasp, size=-1.0)


def test_on_top_marks_every_drawn_object(meshcat, grasp, recorded):
    result = dg.force_closure(grasp)
    drawing = dg.draw_grasp(meshcat, grasp, result=result, cone="both", on_top=True)
    leaves = [p for p in drawing.paths if not p.endswith("/force")]
    leaves += [
        f"{p}/{part}"
        for p in drawing.paths
        if p.endswith("/force")
        for part in ("shaft", "head")
    ]
    assert len(leaves) > 3 * grasp.num_contacts
    for path in leaves:
        assert recorded[(f"{path}/<object>", "material.depthTest")] is False
        assert recorded[(f"{path}/<object>", "renderOrder")] > 0
    assert len(recorded) == 2 * len(leaves)
    recorded.clear()
    dg.draw_grasp(meshcat, grasp, result=result, prefix="plain")
    assert recorded == {}


def test_set_translucent_checks_its_arguments(meshcat, recorded):
    meshcat.SetObject("thing", Sphere(0.1))
    set_translucent(meshcat, ["thing", "other"], 0.5)
    assert recorded == {
        ("thing", "modulated_opacity"): 0.5,
        ("other", "modulated_opacity"): 0.5,
    }
    for bad in (0.0, 1.5, float("nan"), "half"):
        with pytest.raises(InvalidOptionError, match="opacity"):
            set_translucent(meshcat, "thing", bad)
    with pytest.raises(InvalidOptionError, match="non-empty"):
        set_translucent(meshcat, ["thing", ""], 0.5)


def test_visualizer_paths_follow_the_visualizers_naming():
    scene = dg.load_scene("parallel_jaw_box")
    scene_graph = scene.diagram.GetSubsystemByName("scene_graph")
    paths = visualizer_paths(scene.plant, scene_graph, "gripper")
    assert "visualizer/gripper/left_finger/gripper/pad_visual" in paths
    assert len(paths) == 5  # palm, two bars, two pads
    with pytest.raises(InvalidOptionError, match="no model instance named 'claw'"):
        visualizer_paths(scene.plant, scene_graph, "claw")
