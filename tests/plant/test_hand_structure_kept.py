"""The hand structure kept per plant, and the planner's checked closing, give the
answers of the plain computation: a fresh structure, ``close_hand`` itself."""

from __future__ import annotations

import gc
import time
import weakref

import numpy as np
import pytest
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet

from drakegrasp import UnreachableError, close_hand
from drakegrasp.plant import fingers
from drakegrasp.plant.closing import close_checked_hand
from drakegrasp.plant.fingers import hand_structure
from drakegrasp.plant.validation import hand_bodies, query_object_of

from .conftest import ALLEGRO_URL, RealScene, structure_of

CAN_URL = "package://drake_models/ycb/005_tomato_soup_can.sdf"


def _scene(models_dir, p_WO=(0.08, 0.0, 0.1)):
    from pydrake.math import RigidTransform

    scene = RealScene(
        models_dir, ALLEGRO_URL, "hand_root", CAN_URL, RigidTransform(p_WO)
    )
    scene.plant.GetJointByName("joint_12").set_angle(scene.ctx, 1.0)
    return scene


def _summary(s) -> tuple:
    """Everything a structure says, as plain values."""
    return (
        tuple(int(j.index()) for j in s.joints),
        s.names,
        s.position_indices.tolist(),
        s.velocity_indices.tolist(),
        s.lower.tolist(),
        s.upper.tolist(),
        tuple(
            (
                f.name,
                f.joints,
                tuple(int(b.index()) for b in f.bodies),
                tuple((go, gf, int(b.index())) for go, gf, b in f.pairs),
                tuple((go, gf, int(b.index())) for go, gf, b in f.tip_pairs),
                f.max_step,
            )
            for f in s.fingers
        ),
        dict(s.coupling.follows),
    )


def _structures(scene):
    inspector = query_object_of(scene.plant, scene.ctx).inspector()
    bodies = hand_bodies(scene.plant, scene.object, scene.hand)
    kept = hand_structure(scene.plant, scene.object, bodies, inspector=inspector)
    fresh = fingers._build(scene.plant, scene.object, bodies, (), inspector)
    return kept, fresh


def test_the_kept_structure_equals_a_fresh_one(drake_models_dir):
    scene = _scene(drake_models_dir)
    first, fresh = _structures(scene)
    again, _ = _structures(scene)
    assert again is not first  # rebuilt from the kept recipe
    assert _summary(first) == _summary(fresh) == _summary(again)
    assert len(fresh.fingers) == 4 and all(f.pairs for f in fresh.fingers)


def test_the_kept_structure_follows_a_changed_collision_filter(drake_models_dir):
    scene = _scene(drake_models_dir)
    before, _ = _structures(scene)
    finger = before.fingers[0]
    _, gf, _ = finger.pairs[0]
    objects = scene.plant.GetCollisionGeometriesForBody(scene.object)
    sg_context = scene.scene_graph.GetMyMutableContextFromRoot(scene.root)
    scene.scene_graph.collision_filter_manager(sg_context).Apply(
        CollisionFilterDeclaration().ExcludeBetween(
            GeometrySet(objects), GeometrySet([gf])
        )
    )
    after, fresh = _structures(scene)
    assert _summary(after) == _summary(fresh)
    assert len(after.fingers[0].pairs) == len(finger.pairs) - len(objects)
    assert all(p[1] != gf for p in after.fingers[0].pairs)


def test_the_kept_structure_reads_changed_limits(drake_models_dir):
    scene = _scene(drake_models_dir)
    before, _ = _structures(scene)
    joint = before.joints[1]
    lower = joint.position_lower_limits()
    joint.set_position_limits(lower + 0.1, joint.position_upper_limits())
    after, fresh = _structures(scene)
    assert _summary(after) == _summary(fresh)
    assert after.lower[1] == before.lower[1] + 0.1


def test_the_kept_structure_does_not_keep_the_plant_alive(drake_models_dir):
    scene = _scene(drake_models_dir)
    _structures(scene)
    plant = weakref.ref(scene.plant)
    assert fingers._KEPT.get(plant()) is not None
    del scene
    gc.collect()
    assert plant() is None


def test_the_checked_closing_equals_close_hand(drake_models_dir):
    """The planner's entry, on a pre-shape it checked, is close_hand bitwise."""
    for p_WO in [(0.08, 0.0, 0.1), (0.07, 0.02, 0.09), (0.3, 0.0, 0.1)]:
        scene = _scene(drake_models_dir, p_WO)
        q0 = scene.plant.GetPositions(scene.ctx).copy()
        try:
            plain = close_hand(
                scene.plant, scene.ctx, scene.object, hand=scene.hand, min_fingers=1
            )
        except Exception as e:  # noqa: BLE001 - the same error is expected below
            plain = type(e)
        q_plain = scene.plant.GetPositions(scene.ctx).copy()
        scene.plant.SetPositions(scene.ctx, q0)
        structure = structure_of(scene)
        try:
            checked = close_checked_hand(
                scene.plant, scene.ctx, scene.object, structure,
                tol=plain.distance_tolerance if not isinstance(plain, type) else 1e-4,
                min_fingers=1, t0=time.perf_counter(),
            )  # fmt: skip
        except Exception as e:  # noqa: BLE001
            checked = type(e)
        np.testing.assert_array_equal(scene.plant.GetPositions(scene.ctx), q_plain)
        if isinstance(plain, type):
            assert checked is plain
            continue
        assert checked.q.tolist() == plain.q.tolist()
        assert checked.iterations == plain.iterations
        assert [(f.status, f.psi, f.iterations) for f in checked.fingers] == [
            (f.status, f.psi, f.iterations) for f in plain.fingers
        ]


def test_the_checked_closing_refuses_too_many_fingers_as_close_hand(drake_models_dir):
    """min_fingers above the hand's fingers: the same UnreachableError, same words."""
    scene = _scene(drake_models_dir)
    q0 = scene.plant.GetPositions(scene.ctx).copy()
    with pytest.raises(UnreachableError) as plain:
        close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand, min_fingers=9)
    structure = structure_of(scene)
    with pytest.raises(UnreachableError) as checked:
        close_checked_hand(
            scene.plant, scene.ctx, scene.object, structure, tol=1e-4, min_fingers=9,
            t0=time.perf_counter(),
        )  # fmt: skip
    assert str(checked.value) == str(plain.value)
    assert "exceeds the hand's 4 fingers" in str(plain.value)
    np.testing.assert_array_equal(scene.plant.GetPositions(scene.ctx), q0)
