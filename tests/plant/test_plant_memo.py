"""What the plant layer keeps per finalized plant: never another plant's answer."""

from __future__ import annotations

import pytest
from pydrake.multibody.tree import SpatialInertia, UnitInertia

from drakegrasp import NoContactsError
from drakegrasp.plant import DEFAULT_SCENE, analyze_grasp
from drakegrasp.plant.jacobians import hand_velocity_indices
from drakegrasp.plant.validation import (
    _TOPOLOGY,
    hand_bodies,
    hand_model_instances,
    resolve_object_body,
    scoped_name,
)

from .conftest import SCENE_NAMES


def _names(plant, bodies):
    return [scoped_name(plant, b) for b in bodies]


def test_hand_bodies_are_kept_per_plant_and_equal_a_fresh_computation(scene_cache):
    scenes = [scene_cache(n) for n in SCENE_NAMES]
    expected, expected_v = {}, {}
    for scene in scenes:  # fresh: nothing kept yet for this plant
        _TOPOLOGY.pop(scene.plant, None)
        body = resolve_object_body(scene.plant, scene.object_body)
        bodies = hand_bodies(scene.plant, body, scene.hand)
        everyone = hand_bodies(scene.plant, body, None)
        palm = hand_model_instances(scene.plant, bodies, body)
        expected_v[scene.name] = hand_velocity_indices(scene.plant, bodies).tolist()
        expected[scene.name] = (
            _names(scene.plant, bodies),
            _names(scene.plant, everyone),
            _names(scene.plant, palm),
        )
    for _ in range(2):  # now from the memo, plants taking turns
        for scene in scenes:
            body = resolve_object_body(scene.plant, scene.object_body)
            bodies = hand_bodies(scene.plant, body, scene.hand)
            got = (
                _names(scene.plant, bodies),
                _names(scene.plant, hand_bodies(scene.plant, body, None)),
                _names(scene.plant, hand_model_instances(scene.plant, bodies, body)),
            )
            assert got == expected[scene.name]
            velocities = hand_velocity_indices(scene.plant, bodies).tolist()
            assert velocities == expected_v[scene.name]
            assert all(b.GetParentPlant() is scene.plant for b in bodies)
            bodies.clear()  # a caller's list is its own copy
            assert hand_bodies(scene.plant, body, scene.hand)


def test_nothing_is_kept_before_finalize(tools):
    builder, plant, _ = tools.make_plant()
    inertia = SpatialInertia(1.0, [0, 0, 0], UnitInertia.SolidSphere(0.1))
    a = plant.AddRigidBody("a", plant.AddModelInstance("object"), inertia)
    b = plant.AddRigidBody("b", plant.AddModelInstance("hand"), inertia)
    assert _names(plant, hand_bodies(plant, a, None)) == ["hand::b"]
    assert plant not in _TOPOLOGY
    plant.Finalize()
    assert _names(plant, hand_bodies(plant, a, None)) == ["hand::b"]
    assert plant in _TOPOLOGY
    assert _names(plant, hand_bodies(plant, b, None)) == ["object::a"]
    assert _names(plant, hand_bodies(plant, a, "hand")) == ["hand::b"]


def test_two_copies_of_a_scene_in_other_poses_get_their_own_answers(scene_cache):
    """The memo holds topology only: each context's contacts are its own."""
    from .conftest import fresh_context

    scene = scene_cache("three_finger_sphere")
    options = scene.analysis_options()
    _, ctx_a = fresh_context(scene)
    _, ctx_b = fresh_context(scene)
    X = scene.plant.GetFreeBodyPose(ctx_b, scene.plant.GetBodyByName("sphere"))
    a1 = analyze_grasp(scene.plant, ctx_a, **options)
    scene.plant.SetFreeBodyPose(
        ctx_b,
        scene.plant.GetBodyByName("sphere"),
        X.__class__(X.rotation(), X.translation() + [0.0, 0.0, 0.5]),
    )
    with pytest.raises(NoContactsError, match="does not touch"):
        analyze_grasp(scene.plant, ctx_b, **options)  # the sphere left the hand
    a2 = analyze_grasp(scene.plant, ctx_a, **options)
    assert a1.to_dict() == a2.to_dict()


def _plain(value) -> bool:
    if isinstance(value, tuple | frozenset):
        return all(_plain(v) for v in value)
    return isinstance(value, int | str | type(None))


def test_the_memo_holds_plain_numbers_only(scene_cache):
    """A RigidBody would keep its plant alive through the weak memo: the memo
    keeps indices, and callers get the plant's bodies back."""
    scene = scene_cache(DEFAULT_SCENE)
    body = resolve_object_body(scene.plant, scene.object_body)
    bodies = hand_bodies(scene.plant, body, scene.hand)
    hand_model_instances(scene.plant, bodies, body)
    hand_velocity_indices(scene.plant, bodies)
    store = _TOPOLOGY[scene.plant]
    assert len(store) >= 4
    assert all(_plain(k) and _plain(v) for k, v in store.items())
