"""draw_scene_geometry: every geometry once, at the pose the plant gives it."""

from __future__ import annotations

import struct

import numpy as np
import pytest
from pydrake.geometry import Role

import drakegrasp as dg
from drakegrasp.plant import load_scene


def _matrix(meshcat, path: str) -> np.ndarray:
    """The 4x4 transform Meshcat holds at ``path`` (msgpack: 16 float64, by column)."""
    packed = meshcat._GetPackedTransform(path)
    head = b"\xa6matrix\xdc\x00\x10"
    start = packed.index(head) + len(head)
    values = [
        struct.unpack(">d", packed[start + 9 * k + 1 : start + 9 * k + 9])[0]
        for k in range(16)
    ]
    assert all(packed[start + 9 * k] == 0xCB for k in range(16))
    return np.array(values).reshape(4, 4).T


@pytest.fixture(scope="module")
def scene():
    return load_scene("parallel_jaw_box")


def test_each_geometry_is_drawn_at_its_body_pose_times_its_frame_pose(scene, meshcat):
    scene_graph = scene.diagram.GetSubsystemByName("scene_graph")
    paths = dg.draw_scene_geometry(meshcat, scene_graph, scene.context)
    plant = scene.plant
    ctx = scene.plant_context
    inspector = scene_graph.model_inspector()
    ids = inspector.GetAllGeometryIds(Role.kIllustration)
    assert sorted(paths) == sorted(f"scene/{g.get_value()}" for g in ids)
    for gid in ids:
        body = plant.GetBodyFromFrameId(inspector.GetFrameId(gid))
        X_WG = plant.EvalBodyPoseInWorld(ctx, body).multiply(
            inspector.GetPoseInFrame(gid)
        )  # a second route: the plant's body pose and the geometry's frame pose
        np.testing.assert_allclose(
            _matrix(meshcat, f"scene/{gid.get_value()}"),
            X_WG.GetAsMatrix4(),
            atol=1e-12,
        )


def test_a_second_call_replaces_the_first_and_proximity_shapes_can_be_drawn(
    scene, meshcat
):
    scene_graph = scene.diagram.GetSubsystemByName("scene_graph")
    sg_context = scene_graph.GetMyContextFromRoot(scene.context)
    first = dg.draw_scene_geometry(meshcat, scene_graph, sg_context, prefix="snap")
    second = dg.draw_scene_geometry(
        meshcat, scene_graph, scene.context, prefix="snap", role="proximity",
        opacity=0.4,
    )  # fmt: skip
    proximity = scene_graph.model_inspector().GetAllGeometryIds(Role.kProximity)
    assert len(second) == len(proximity)
    assert all(meshcat.HasPath(p) for p in second)
    assert not any(meshcat.HasPath(p) for p in set(first) - set(second))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"opacity": 0.0}, "opacity"),
        ({"opacity": 1.5}, "opacity"),
        ({"opacity": float("nan")}, "opacity"),
        ({"opacity": True}, "opacity"),
        ({"opacity": "half"}, "opacity"),
        ({"role": "perception"}, "role"),
        ({"prefix": ""}, "prefix"),
        ({"prefix": 3}, "prefix"),
    ],
)
def test_bad_options_are_refused(scene, meshcat, kwargs, message):
    scene_graph = scene.diagram.GetSubsystemByName("scene_graph")
    with pytest.raises(dg.InvalidOptionError, match=message):
        dg.draw_scene_geometry(meshcat, scene_graph, scene.context, **kwargs)


def test_wrong_objects_are_refused(scene, meshcat):
    scene_graph = scene.diagram.GetSubsystemByName("scene_graph")
    with pytest.raises(dg.InvalidOptionError, match="meshcat"):
        dg.draw_scene_geometry(None, scene_graph, scene.context)
    with pytest.raises(dg.InvalidOptionError, match="SceneGraph"):
        dg.draw_scene_geometry(meshcat, scene.plant, scene.context)
    other = load_scene("parallel_jaw_box")
    with pytest.raises(dg.InvalidOptionError, match="context"):
        dg.draw_scene_geometry(meshcat, scene_graph, other.plant_context)
