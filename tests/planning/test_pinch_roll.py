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
    assert set(hand.to_dict()) >= {"closing_axis_K", "pinch_reach", "pinch_width"}


def _side_by_side_urdf(y: float = 0.02, bars: bool = False) -> str:
    """Two fingers side by side on one hinge line and one opposed, one motor.

    f1 and f2 hinge about y at x = -50 mm, y = ±``y`` (coaxial: they turn
    alike, but lie apart along their axis, not in its plane); f3 at x = +50
    mm turns the other way (``<mimic>`` -1).  Only f1's hinge has a motor.
    ``bars``: beside f1 and f2 a bar each, 25 mm inwards in their plane,
    turning with them.
    """
    text = one_motor_pinch_urdf()
    head, tail = text.split("<transmission", 1)
    link = (
        '<link name="{0}"><inertial><origin xyz="0 0 0.03"/><mass value="0.05"/>'
        '<inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/>'
        '</inertial><collision><origin xyz="0 0 0.03"/><geometry><box size='
        '"0.012 0.012 0.06"/></geometry></collision></link>'
    )
    joint = (
        '<joint name="{0}_joint" type="revolute"><parent link="palm"/><child '
        'link="{0}"/><origin xyz="{1}"/><axis xyz="0 1 0"/><limit lower="{2}" '
        'upper="{3}" effort="5" velocity="2"/>{4}</joint>'
    )
    mimic = '<mimic joint="f1_joint" multiplier="{0}" offset="0"/>'
    fingers = [
        ("f1", f"-0.05 {y} 0.06", 0, 0.8, ""),
        ("f2", f"-0.05 {-y} 0.06", 0, 0.8, mimic.format(1)),
        ("f3", "0.05 0 0.06", -0.8, 0, mimic.format(-1)),
    ]
    if bars:
        fingers += [
            ("b1", f"-0.025 {y} 0.06", 0, 0.8, mimic.format(1)),
            ("b2", f"-0.025 {-y} 0.06", 0, 0.8, mimic.format(1)),
        ]
    body = "".join(
        link.format(f) + joint.format(f, at, lo, hi, m) for f, at, lo, hi, m in fingers
    )
    palm = head[: head.index('<link name="left_knuckle"')]
    return (
        palm + body + '<transmission name="t"><type>transmission_interface/'
        'SimpleTransmission</type><joint name="f1_joint"/><actuator name="m">'
        "<mechanicalReduction>1</mechanicalReduction></actuator></transmission>"
        "</robot>"
    )


def test_other_hands_have_no_closing_axis(tmp_path):
    # not pinches: a three-finger hand, the spread hand, and two fingers side
    # by side on one hinge line facing a third (they turn alike but lie apart
    # along their axis: not a bar and its finger)
    path = tmp_path / "spread.urdf"
    path.write_text(spread_hand_urdf())
    beside = tmp_path / "side_by_side.urdf"
    beside.write_text(_side_by_side_urdf())
    # with a bar beside each of them (a bar 25 mm across its finger's axis
    # is not beside the other finger, 24 mm along it)
    barred = tmp_path / "side_by_side_bars.urdf"
    barred.write_text(_side_by_side_urdf(y=0.012, bars=True))
    for scene in (
        planning_scene(BOX, hand_url=THREE),
        planning_scene(BOX, hand_url=str(path)),
        planning_scene(BOX, hand_url=str(beside)),
        planning_scene(BOX, hand_url=str(barred)),
    ):
        hand = _hand(scene)
        assert hand.closing_axis is None and np.isnan(hand.pinch_reach)
        assert "closing_axis_K" not in hand.to_dict()


def test_bars_on_their_fingers_pins_share_their_sides(tmp_path):
    # the inner knuckles hinged on the knuckles' own pins: they turn as the
    # knuckles do about one line, a side each with them (before: every chain
    # a side, not a pinch, and no candidate)
    text = one_motor_pinch_urdf(bars=True)
    for bar, pin in (
        ("-0.05 0 0.06", "-0.055 0 0.06"),
        ("0.05 0 0.06", "0.055 0 0.06"),
    ):
        assert text.count(f'<origin xyz="{bar}"/>') == 1
        text = text.replace(f'<origin xyz="{bar}"/>', f'<origin xyz="{pin}"/>')
    path = tmp_path / "pinned.urdf"
    path.write_text(text)
    scene = planning_scene(BOX, hand_url=str(path))
    assert _hand(scene).closing_axis is not None
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, mu=0.5, seed=0, robustness_samples=4,
    )  # fmt: skip
    assert len(result) >= 5 and sum(c.is_closure for c in result) >= 5


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


def test_a_pinch_plan_moves_with_the_object(tmp_path):
    # the whole plan (the hand learnt, sampled, closed and centred in the
    # world) in a scene moved rigidly: the same candidates in the object's
    # frame
    path = tmp_path / "barred.urdf"
    path.write_text(one_motor_pinch_urdf(bars=True))
    X = RigidTransform(RollPitchYaw(0.3, -1.2, 2.5), [0.4, -0.2, 1.0])
    plans = []
    for X_WO in (RigidTransform(), X):
        scene = planning_scene(BOX, hand_url=str(path), X_WO=X_WO)
        result = plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=40, mu=0.5, seed=0, robustness_samples=4,
        )  # fmt: skip
        plans.append(
            [(c.sample, X_WO.inverse() @ c.X_WH, c.is_closure) for c in result]
        )
    assert len(plans[0]) >= 5 and [p[0] for p in plans[0]] == [p[0] for p in plans[1]]
    for (_, X0, f0), (_, X1, f1) in zip(*plans, strict=True):
        assert f0 == f1
        np.testing.assert_allclose(X1.GetAsMatrix4(), X0.GetAsMatrix4(), atol=1e-7)


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
