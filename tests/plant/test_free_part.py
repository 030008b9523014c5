"""A finger group whose chains a coupling closes as one, but which have motors
of their own (a Barrett-style spread): the chain that touches stops, the
others close on (:func:`drakegrasp.plant.fingers.free_part`)."""

from __future__ import annotations

import numpy as np
import pytest
from coupled_hands import one_motor_pinch_urdf, spread_hand_urdf
from pydrake.math import RigidTransform, RotationMatrix

import drakegrasp as dg
from drakegrasp.planning import planning_scene
from drakegrasp.plant.couplings import plant_couplings
from drakegrasp.plant.fingers import free_part, hand_structure
from drakegrasp.plant.validation import hand_bodies

CYLINDER = "package://drakegrasp/objects/cylinder.sdf"  # r 30 mm, 120 mm long


@pytest.fixture(scope="module")
def spread(tmp_path_factory):
    """The hand's palm at the origin, the cylinder across its fingers (axis y)."""
    path = tmp_path_factory.mktemp("spread") / "spread_hand.urdf"
    path.write_text(spread_hand_urdf())
    X_WO = RigidTransform(RotationMatrix.MakeXRotation(np.pi / 2), [0, 0, 0.085])
    scene = planning_scene(CYLINDER, hand_url=str(path), X_WO=X_WO)
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    plant.SetFreeBodyPose(
        ctx, plant.GetBodyByName("palm", scene.hand), RigidTransform()
    )
    return scene, plant, ctx


def _q(plant, ctx, name):
    return plant.GetJointByName(name).get_angle(ctx)


def test_a_coupled_spread_does_not_hold_the_other_finger_open(spread):
    # f1 and f2 close as one group (their spreads are coupled).  Before, the
    # group stopped when f1 touched: f2's own flexion never moved and 2 of 3
    # fingers touched.
    scene, plant, ctx = spread
    saved = plant.GetPositions(ctx).copy()
    try:
        closure = dg.close_hand(plant, ctx, scene.object_body, hand=scene.hand)
        assert len(closure.touching_fingers) == 3, closure
        names = {f.name.split("::")[-1] for f in closure.fingers}
        assert "f2_proximal_joint" in names
        touching = {b.split("::")[-1] for b in closure.touching_bodies}
        assert {"f1_distal", "f2_distal", "f3_distal"} <= touching
        # the couplings hold where it stopped
        for k in (1, 2, 3):
            prox = _q(plant, ctx, f"f{k}_proximal_joint")
            assert prox > 0.05
            assert _q(plant, ctx, f"f{k}_distal_joint") == pytest.approx(0.5 * prox)
        assert _q(plant, ctx, "f2_spread") == pytest.approx(_q(plant, ctx, "f1_spread"))
        # and the analysis reads three fingers off the closed hand
        report = dg.analyze_grasp(
            plant, ctx, scene.object_body, hand=scene.hand, mu=0.5
        )
        labels = {c.finger_body.split("::")[-1][:2] for c in report.contacts}
        assert labels == {"f1", "f2", "f3"}
    finally:
        plant.SetPositions(ctx, saved)


def _structure(scene, plant, ctx):
    inspector = plant.get_geometry_query_input_port().Eval(ctx).inspector()
    bodies = hand_bodies(plant, scene.object_body, scene.hand)
    return hand_structure(
        plant, scene.object_body, bodies, plant_couplings(plant), inspector=inspector
    )


def _free(scene, plant, ctx, touching):
    s = _structure(scene, plant, ctx)
    (group,) = [f for f in s.fingers if len(f.joints) > 2]
    part = free_part(
        plant, s, group, [plant.GetBodyByName(b, scene.hand) for b in touching]
    )
    return None if part is None else {s.names[k].split("::")[-1] for k in part.joints}


def test_the_free_part_is_what_moves_no_touching_body_nor_its_couplings(spread):
    scene, plant, ctx = spread
    f2 = {"f2_proximal_joint", "f2_distal_joint"}
    f1 = {"f1_proximal_joint", "f1_distal_joint"}
    assert _free(scene, plant, ctx, ["f1_distal"]) == f2
    assert _free(scene, plant, ctx, ["f2_proximal"]) == f1
    # a chain that touches stops whole, whichever of its bodies touches
    assert _free(scene, plant, ctx, ["f1_knuckle"]) == f2
    assert _free(scene, plant, ctx, ["f1_distal", "f2_distal"]) is None


def test_a_finger_of_one_chain_has_no_free_part(spread):
    # f3 touching with its proximal link does not curl its distal joint on:
    # a finger stops where it touches, as before
    scene, plant, ctx = spread
    s = _structure(scene, plant, ctx)
    (f3,) = [f for f in s.fingers if "f3" in f.name]
    body = plant.GetBodyByName("f3_proximal", scene.hand)
    assert free_part(plant, s, f3, [body]) is None


def test_fingers_one_motor_closes_have_no_free_part(tmp_path):
    path = tmp_path / "pinch.urdf"
    path.write_text(one_motor_pinch_urdf())
    scene = planning_scene("package://drakegrasp/objects/box.sdf", hand_url=str(path))
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    s = _structure(scene, plant, ctx)
    (group,) = s.fingers
    pad = plant.GetBodyByName("left_pad", scene.hand)
    assert free_part(plant, s, group, [pad]) is None


def test_min_fingers_counts_what_can_close_on(spread):
    # the spread hand has two closing groups and can touch with three fingers:
    # min_fingers = 3 was refused before any search ("exceeds the hand's 2")
    scene, plant, ctx = spread
    saved = plant.GetPositions(ctx).copy()
    try:
        closure = dg.close_hand(
            plant, ctx, scene.object_body, hand=scene.hand, min_fingers=3
        )
        assert len(closure.touching_fingers) == 3
        with pytest.raises(dg.UnreachableError, match="at most 3 can touch"):
            dg.close_hand(plant, ctx, scene.object_body, hand=scene.hand, min_fingers=4)
    finally:
        plant.SetPositions(ctx, saved)


def test_free_part_refuses_what_is_not_a_touching_body_of_the_finger(spread):
    scene, plant, ctx = spread
    s = _structure(scene, plant, ctx)
    (group,) = [f for f in s.fingers if len(f.joints) > 2]
    body = plant.GetBodyByName
    for touching in (
        [],
        [None],
        body("f1_distal", scene.hand),  # a body, not a list of them
        ["spread_hand::f1_distal"],
        [body("palm", scene.hand)],
        [body("f3_distal", scene.hand)],  # another finger's
        [scene.object_body],
    ):
        with pytest.raises(dg.InvalidOptionError):
            free_part(plant, s, group, touching)
