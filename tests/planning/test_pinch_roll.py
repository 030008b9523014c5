"""A pinch is rolled so that its pads close along the object's normals.

A hand whose chains move on two sides (a Robotiq-style gripper) closes along
one axis.  Rolled at random about its approach, its flat pads met a box's
faces at an angle and touched with one corner each: two point contacts, no
candidate force closure, and in Drake the box turned out of the pads.  The
sampler now rolls it so that the axis leaves the object along the outward
normals on both sides (:func:`drakegrasp.planning.approach.sample_approaches`).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from coupled_hands import one_motor_pinch_urdf, spread_hand_urdf
from pydrake.math import RigidTransform, RollPitchYaw

from drakegrasp.planning import (
    object_surface,
    plan_grasps,
    planning_scene,
    shake_candidates,
)
from drakegrasp.planning.approach import multi_finger_hand, sample_approaches

BOX = "package://drakegrasp/objects/box.sdf"  # 50 x 50 x 100 mm, at the origin
THREE = "package://drakegrasp/hands/three_finger_hand.sdf"


def _hand(scene):
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    return multi_finger_hand(scene.plant, ctx, scene.object_body, scene.hand)


@pytest.fixture(scope="module", params=[False, True], ids=["pinch", "with bars"])
def pinch(request, tmp_path_factory):
    path = tmp_path_factory.mktemp("roll") / "pinch.urdf"
    path.write_text(one_motor_pinch_urdf(bars=request.param))
    scene = planning_scene(BOX, hand_url=str(path))
    return scene, _hand(scene)


def test_a_pinch_knows_its_closing_axis(pinch):
    # The pads close along the palm's x axis; their tips' midpoint at the
    # open hand is 4.5 cm past the knuckles (a bar beside a pad does not
    # count: it reaches less far).
    _, hand = pinch
    c_H = hand.X_HK.rotation().multiply(hand.closing_axis)
    np.testing.assert_allclose(np.abs(c_H), [1.0, 0.0, 0.0], atol=1e-9)
    mid_H = hand.X_HK.translation() + hand.pinch_reach * hand.X_HK.rotation().col(0)
    np.testing.assert_allclose(mid_H, [0.0, 0.0, 0.13], atol=1e-9)
    assert set(hand.to_dict()) >= {"closing_axis_K", "pinch_reach"}


def test_other_hands_have_no_closing_axis(tmp_path):
    path = tmp_path / "spread.urdf"
    path.write_text(spread_hand_urdf())
    for scene in (
        planning_scene(BOX, hand_url=THREE),
        planning_scene(BOX, hand_url=str(path)),
    ):
        hand = _hand(scene)
        assert hand.closing_axis is None and np.isnan(hand.pinch_reach)
        assert "closing_axis_K" not in hand.to_dict()


def _axes(scene, hand, X_WO, n=200, seed=0, tilt=0.0):
    """Per pose: the closing axis and the approach in frame O."""
    surface = object_surface(scene.plant, scene.context, scene.object_body)
    rng = np.random.default_rng(seed)
    poses = sample_approaches(surface, hand, X_WO, n, rng, tilt)
    R_OW = X_WO.rotation().inverse().matrix()
    R_HK = hand.X_HK.rotation().matrix()
    R_OH = R_OW @ poses["R_WH"]
    return R_OH @ R_HK @ hand.closing_axis, R_OH @ R_HK[:, 0]


def test_the_closing_axis_is_laid_along_a_face_normal_of_the_box(pinch):
    scene, hand = pinch
    c, u = _axes(scene, hand, RigidTransform())
    # approached square onto a face (tilt 0), the pads close along another
    # face's normal: one of the box's axes, to rounding
    aligned = np.max(np.abs(c), axis=1) > 1 - 1e-9
    assert np.all(np.abs(np.sum(c * u, axis=1)) < 1e-9)
    assert aligned.mean() > 0.9, aligned.mean()
    # rolled at random, as before, hardly any pose is
    drawn = dataclasses.replace(hand, closing_axis=None)
    R_HK = hand.X_HK.rotation().matrix()
    surface = object_surface(scene.plant, scene.context, scene.object_body)
    poses = sample_approaches(
        surface, drawn, RigidTransform(), 200, np.random.default_rng(0), 0.0
    )
    c_random = poses["R_WH"] @ R_HK @ hand.closing_axis
    assert (np.max(np.abs(c_random), axis=1) > 1 - 1e-9).mean() < 0.05


def test_the_pads_close_across_the_box_where_they_fit(pinch):
    # The box is 50 x 50 x 100 mm, the open pads' faces 85 mm apart (their
    # centres 93 mm): approached through a long side, they close across its
    # 50 mm, never along its 100 mm.
    scene, hand = pinch
    assert hand.pinch_width == pytest.approx(0.085, abs=1e-9)
    c, u = _axes(scene, hand, RigidTransform())
    side = np.abs(u[:, 2]) < 1e-9
    assert side.sum() > 50
    assert np.all(np.abs(c[side, 2]) < 0.99)  # never along the 100 mm
    # across the 50 mm, but for a few whose line runs along an edge
    assert (np.abs(c[side, 2]) < 1e-9).mean() > 0.9


def test_a_tilted_approach_turns_about_the_closing_axis(pinch):
    # tilted (up to 20 deg), the approach turns about the axis the roll laid
    # along the faces' normals: the pads still close square on them
    scene, hand = pinch
    c, u = _axes(scene, hand, RigidTransform(), tilt=np.radians(20.0))
    assert (np.max(np.abs(c), axis=1) > 1 - 1e-9).mean() > 0.9
    assert np.all(np.abs(np.sum(c * u, axis=1)) < 1e-9)
    tilted = np.degrees(np.arccos(np.clip(np.max(np.abs(u), axis=1), -1, 1)))
    assert tilted.max() <= 20.0 + 1e-6 and tilted.max() > 10.0


def test_the_roll_moves_with_the_object(pinch):
    # drawn in the object's frame: a rigid motion of the scene moves every
    # pose with it
    scene, hand = pinch
    X = RigidTransform(RollPitchYaw(0.3, -1.2, 2.5), [0.4, -0.2, 1.0])
    c0, u0 = _axes(scene, hand, RigidTransform())
    c1, u1 = _axes(scene, hand, X)
    np.testing.assert_allclose(c1, c0, atol=1e-9)
    np.testing.assert_allclose(u1, u0, atol=1e-9)


def test_a_pinch_plans_force_closure_on_a_box_that_holds_in_drake(pinch):
    # 60 samples: 0 of 14 candidates force closure before, each touching with
    # two pad corners; in Drake (hydroelastic pads) 4 of the first 8 held.
    scene, _ = pinch
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, mu=0.5, seed=0, robustness_samples=8,
    )  # fmt: skip
    closure = [c for c in result if c.is_closure]
    assert len(closure) >= 2
    assert all(len(c.contacts) >= 6 for c in closure)  # pads flat on faces
    shaken = shake_candidates(
        scene.add_models, closure, top=2, squeeze=5.0, hydroelastic_modulus=1e6,
        directions=[[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
    )  # fmt: skip
    assert all(s.held for s in shaken), str(shaken)
