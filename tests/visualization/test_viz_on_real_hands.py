"""draw_grasp options for real hands: on_top, size, translucent (no browser)."""

import pytest
from pydrake.geometry import Meshcat, MeshcatParams, Sphere

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError
from drakegrasp.visualization import set_translucent, visualizer_paths


@pytest.fixture(scope="module")
def meshcat():
    params = MeshcatParams()
    params.show_stats_plot = False
    return Meshcat(params)


class Recording:
    """A Meshcat that records SetProperty calls (pydrake cannot read them)."""

    def __init__(self, meshcat):
        self._meshcat = meshcat
        self.properties = {}

    def SetProperty(self, path, name, value):  # noqa: N802 (Drake's name)
        self.properties[(path, name)] = value
        self._meshcat.SetProperty(path, name, value)

    def __getattr__(self, name):
        return getattr(self._meshcat, name)


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


def test_on_top_marks_every_drawn_object(meshcat, grasp):
    result = dg.force_closure(grasp)
    recording = Recording(meshcat)
    drawing = dg.draw_grasp(recording, grasp, result=result, cone="both", on_top=True)
    leaves = [p for p in drawing.paths if not p.endswith("/force")]
    leaves += [
        f"{p}/{part}"
        for p in drawing.paths
        if p.endswith("/force")
        for part in ("shaft", "head")
    ]
    assert len(leaves) > 3 * grasp.num_contacts
    for path in leaves:
        assert recording.properties[(f"{path}/<object>", "material.depthTest")] is False
        assert recording.properties[(f"{path}/<object>", "renderOrder")] > 0
    assert len(recording.properties) == 2 * len(leaves)
    plain = Recording(meshcat)
    dg.draw_grasp(plain, grasp, result=result, prefix="plain")
    assert plain.properties == {}


def test_set_translucent_checks_its_arguments(meshcat):
    meshcat.SetObject("thing", Sphere(0.1))
    recording = Recording(meshcat)
    set_translucent(recording, ["thing", "other"], 0.5)
    assert recording.properties == {
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
