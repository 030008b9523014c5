"""draw_grasp frames the grasp (issue 20, point 11) and reads X_WO from a plant.

Headless, with a local Meshcat (no browser, no network).  The camera pose is
checked three ways: the SetCameraPose call recorded, the camera position
Meshcat holds (decoded from its packed scene state), and a geometric check
written here that every contact lies inside the camera's field of view.
"""

from __future__ import annotations

import struct

import numpy as np
import pytest
from pydrake.geometry import Meshcat
from pydrake.math import RigidTransform, RollPitchYaw

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError
from drakegrasp.visualization.view import MESHCAT_FOV

CAMERA_PROPERTY = ("/Cameras/default/rotated/<object>", "position")


@pytest.fixture
def camera_calls(monkeypatch):
    """Every Meshcat.SetCameraPose call: a list of (camera_W, target_W)."""
    calls = []
    original = Meshcat.SetCameraPose

    def record(self, camera, target):
        calls.append((np.array(camera, float), np.array(target, float)))
        return original(self, camera, target)

    monkeypatch.setattr(Meshcat, "SetCameraPose", record)
    return calls


def held_camera_position(meshcat) -> np.ndarray:
    """The camera position Meshcat holds, back in Drake's z-up world frame.

    Meshcat stores it as a msgpack ``set_property`` message whose value is
    three float64 (``0xcb`` + 8 big-endian bytes) in three.js's y-up frame:
    ``(x, z, −y)``.
    """
    packed = meshcat._GetPackedProperty(*CAMERA_PROPERTY)
    start = packed.index(b"\xa5value\x93") + 7
    x, y_up, minus_y = (
        struct.unpack(">d", packed[start + 9 * k + 1 : start + 9 * k + 9])[0]
        for k in range(3)
    )
    assert all(packed[start + 9 * k] == 0xCB for k in range(3))
    return np.array([x, -minus_y, y_up])


def contacts_in_world(grasp, X_WG):
    return np.array([X_WG.multiply(c.position) for c in grasp.contacts])


def in_view(points_W, camera, target) -> bool:
    """Every point within half the vertical field of view of the view axis."""
    axis = (target - camera) / np.linalg.norm(target - camera)
    rays = points_W - camera
    cos = rays @ axis / np.linalg.norm(rays, axis=1)
    return bool(np.all(cos > np.cos(0.5 * MESHCAT_FOV)))


def test_a_drawing_far_from_the_origin_is_framed(meshcat, camera_calls):
    grasp = dg.examples.equator_fingers(mu=0.5)
    X_WG = RigidTransform(RollPitchYaw(0.3, -0.2, 1.0), [10.0, -4.0, 2.5])
    drawing = dg.draw_grasp(meshcat, grasp, X_WG=X_WG)
    (camera, target), *_ = camera_calls
    view = drawing.camera
    np.testing.assert_array_equal(view.position_W, camera)
    np.testing.assert_array_equal(view.target_W, target)
    np.testing.assert_allclose(held_camera_position(meshcat), camera, atol=1e-12)
    points = contacts_in_world(grasp, X_WG)
    np.testing.assert_allclose(
        target, 0.5 * (points.min(axis=0) + points.max(axis=0)), atol=1e-12
    )
    assert in_view(points, camera, target)
    # Not a speck: the grasp spans a good part of the view.
    spread = np.max(np.linalg.norm(points - target, axis=1))
    assert spread / np.linalg.norm(camera - target) > 0.1
    # The cones (0.4 b high) fit too: the framed sphere holds them.
    assert view.radius >= drawing.cone_height


def test_keep_camera_leaves_it_where_it_was(meshcat, camera_calls):
    meshcat.SetCameraPose([0.3, -0.4, 0.5], [0.0, 0.0, 0.1])
    before = held_camera_position(meshcat)
    drawing = dg.draw_grasp(
        meshcat, dg.examples.equator_fingers(mu=0.5), keep_camera=True
    )
    assert drawing.camera is None
    assert len(camera_calls) == 1  # only the call above
    np.testing.assert_array_equal(held_camera_position(meshcat), before)
    with pytest.raises(InvalidOptionError, match="keep_camera"):
        dg.draw_grasp(meshcat, dg.examples.equator_fingers(mu=0.5), keep_camera="yes")


def test_the_object_pose_comes_from_the_plant_and_context(meshcat):
    scene = dg.load_scene("parallel_jaw_box")
    X_WO = scene.plant.EvalBodyPoseInWorld(scene.plant_context, scene.object_body)
    assert not X_WO.IsExactlyIdentity()
    report = dg.analyze_grasp(
        scene.plant,
        scene.context,
        scene.object_body,
        hand=scene.hand,
        mu=0.5,
        check_pose=False,
    )
    by_hand = dg.draw_grasp(meshcat, report.grasp, X_WG=X_WO, prefix="by_hand")
    from_plant = dg.draw_grasp(
        meshcat,
        report.grasp,
        plant=scene.plant,
        plant_context=scene.context,  # the root context is accepted
        object_body=scene.object_body.name(),
        prefix="from_plant",
    )
    assert (
        meshcat._GetPackedTransform("from_plant")[-16 * 9 :]
        == (meshcat._GetPackedTransform("by_hand")[-16 * 9 :])
    )
    np.testing.assert_array_equal(from_plant.camera.target_W, by_hand.camera.target_W)
    # The contacts drawn where the plant has them: within ψ of the finger's
    # witness point, placed by the finger body's own pose.
    points = contacts_in_world(report.grasp, X_WO)
    for c, p in zip(report.data.contacts, points, strict=True):
        X_WF = scene.plant.EvalBodyPoseInWorld(
            scene.plant_context, scene.plant.get_body(c.finger_body_index)
        )
        assert np.linalg.norm(p - X_WF.multiply(c.p_FC)) <= abs(c.psi) + 1e-9
    assert in_view(points, from_plant.camera.position_W, from_plant.camera.target_W)


def test_plant_arguments_go_together_and_exclude_x_wg(meshcat):
    scene = dg.load_scene("parallel_jaw_box")
    grasp = dg.examples.equator_fingers(mu=0.5)
    with pytest.raises(InvalidOptionError, match="not both"):
        dg.draw_grasp(
            meshcat,
            grasp,
            X_WG=RigidTransform(),
            plant=scene.plant,
            plant_context=scene.context,
            object_body=scene.object_body,
        )
    with pytest.raises(InvalidOptionError, match="missing: object_body"):
        dg.draw_grasp(meshcat, grasp, plant=scene.plant, plant_context=scene.context)
    with pytest.raises(InvalidOptionError, match="points_W"):
        dg.visualization.frame_points(meshcat, np.zeros((0, 3)))
