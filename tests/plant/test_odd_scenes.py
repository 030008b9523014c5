"""Odd scenes at the plant layer: what a hand, an object and a free hand are.

A fuzz pass found these answered wrongly or refused with a misleading cause:

- ``hand_object_friction(..., object_body="world")`` returned ``[]`` (the
  world has no geometry here), which ``plan --mu plant`` read as "no collision
  geometry"; now the world body is refused: it is no object.  A body welded to
  the world (a fixture) still answers, with its geometries' friction;
- an object that is a body of the hand (its palm, a finger) was silently left
  out of the hand, and the hand read without it (friction of the palm against
  its own fingers; "the hand does not touch 'gripper::left_finger'");
- ``hand: box`` (the object's own model instance) said "the hand has no
  bodies that can move (hand=ModelInstanceIndex(3))";
- ``hand: gripper::left_finger`` (a body written where a model instance goes)
  said only "no model instance named ...".
"""

from __future__ import annotations

import numpy as np
import pytest
from odd_scenes import (
    BOX,
    GRIPPER,
    PALM_ON_WORLD,
    TABLE_AND_PALM,
    jaw_scene,
)
from pydrake.multibody.tree import BodyIndex

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.plant.friction import hand_object_friction
from drakegrasp.plant.scene import load_scene
from drakegrasp.plant.validation import hand_bodies, hand_contact_bodies, resolve_body


@pytest.fixture(scope="module")
def shipped():
    return load_scene("parallel_jaw_box")


def _body(scene, name):
    return resolve_body(scene.plant, name)


# -- hand_object_friction ------------------------------------------------------


@pytest.mark.parametrize("world", ["world", "WorldModelInstance::world", "index"])
def test_the_world_body_is_no_object_for_the_friction(shipped, world):
    """It returned [] silently: the world of this scene has no geometry."""
    if world == "index":
        world = BodyIndex(0)
    for hand in (shipped.hand, None, "gripper"):
        with pytest.raises(InvalidOptionError, match="is the world body") as e:
            hand_object_friction(shipped.plant, shipped.plant_context, world, hand)
        assert "which is not an object" in str(e.value)
        assert "box::box" in str(e.value)  # the bodies one may name
    with pytest.raises(InvalidOptionError, match="is the world body"):
        hand_object_friction(
            shipped.plant, shipped.plant_context, shipped.plant.world_body()
        )


@pytest.mark.parametrize("body", ["gripper::palm", "gripper::left_finger"])
def test_a_body_of_the_hand_is_no_object_for_the_friction(shipped, body):
    """It answered [1.0]: the palm's (or a finger's) friction with the hand."""
    with pytest.raises(InvalidOptionError, match="is part of the hand 'gripper'"):
        hand_object_friction(shipped.plant, shipped.plant_context, body, "gripper")


def test_an_object_listed_in_the_hand_is_refused(shipped):
    hand = ["box::box", "gripper::left_finger"]
    with pytest.raises(InvalidOptionError, match="also listed as a body of the hand"):
        hand_object_friction(shipped.plant, shipped.plant_context, "box::box", hand)
    with pytest.raises(InvalidOptionError, match="also listed as a body of the hand"):
        hand_bodies(shipped.plant, shipped.object_body, hand)


def test_a_welded_fixture_has_its_geometries_friction(tmp_path):
    """A body welded to the world answers as the same body free does."""
    from hand_models import box_object

    (tmp_path / "fixture.sdf").write_text(box_object((0.05, 0.05, 0.1), mu=0.3))
    model = "- add_model:\n    name: fixture\n    file: fixture.sdf\n"
    weld = "- add_weld:\n    parent: world\n    child: fixture::box\n"
    free = jaw_scene(
        tmp_path, "free", object_body="fixture::box", directives=GRIPPER + model
    )
    welded = jaw_scene(
        tmp_path,
        "welded",
        object_body="fixture::box",
        directives=GRIPPER + PALM_ON_WORLD + model + weld,
    )
    want = [2 * 0.3 * 1.0 / 1.3]  # Drake's combination with the hand's default 1
    for path in (free, welded):
        s = load_scene(path)
        got = hand_object_friction(s.plant, s.plant_context, s.object_body, s.hand)
        np.testing.assert_allclose(got, want, rtol=1e-12)


# -- the object apart from the hand -----------------------------------------


@pytest.mark.parametrize("body", ["gripper::palm", "gripper::left_finger"])
def test_an_object_of_the_hand_is_refused_not_left_out(shipped, body):
    obj = _body(shipped, body)
    for check in (hand_bodies, hand_contact_bodies):
        with pytest.raises(InvalidOptionError, match="is part of the hand") as e:
            check(shipped.plant, obj, "gripper")
        assert f"object_body {body}" in str(e.value)
    with pytest.raises(InvalidOptionError, match="is part of the hand"):
        dg.analyze_grasp(
            shipped.plant, shipped.plant_context, obj, hand="gripper", mu=1
        )


def test_an_object_sharing_the_hands_instance_but_free_is_not_part_of_it():
    """One model file may hold a hand and a free object: they are apart."""
    from hand_models import Rig, palm_hand

    cube = (
        '<link name="cube"><pose>0 0 0.1 0 0 0</pose><inertial><mass>0.1</mass>'
        "</inertial><collision name='cube'><geometry><box><size>0.03 0.03 0.03"
        "</size></box></geometry></collision></link>"
    )
    rig = Rig([(palm_hand().replace("</model>", cube + "</model>"), "sdf")], "hand")
    cube = rig.plant.GetBodyByName("cube", rig.hand)
    assert cube.is_floating_base_body()
    bodies = hand_bodies(rig.plant, cube, rig.hand)
    assert bodies and cube.index() not in [b.index() for b in bodies]
    assert hand_contact_bodies(rig.plant, cube, rig.hand)


def test_the_objects_own_instance_as_the_hand_says_so(shipped):
    for check in (hand_bodies, hand_contact_bodies):
        with pytest.raises(ModelError, match="is the model instance of the object"):
            check(shipped.plant, shipped.object_body, "box")


def test_a_body_given_as_a_model_instance_hints_the_list(shipped):
    with pytest.raises(ModelError, match="no model instance named") as e:
        hand_bodies(shipped.plant, shipped.object_body, "gripper::left_finger")
    assert "'gripper::left_finger' is a body" in str(e.value)
    assert "its model instance is 'gripper'" in str(e.value)


# -- attachment ---------------------------------------------------------------


def test_attachment_reads_how_each_body_is_held(tmp_path):
    from drakegrasp.plant.attachment import (
        chain_to_world,
        free_carrier,
        how_held,
        inboard_joint,
        joined,
    )

    s = load_scene(jaw_scene(tmp_path, "t", directives=GRIPPER + TABLE_AND_PALM + BOX))
    plant = s.plant
    palm, finger = _body(s, "gripper::palm"), _body(s, "gripper::left_finger")
    table, box = _body(s, "table::box"), s.object_body
    assert inboard_joint(plant, plant.world_body()) is None
    assert [j.type_name() for j in chain_to_world(plant, finger)] == [
        "prismatic", "weld", "weld"
    ]  # fmt: skip
    assert free_carrier(plant, box).index() == box.index()
    assert free_carrier(plant, finger) is None
    assert how_held(plant, table) == "welded to the world"
    assert how_held(plant, palm) == "welded to table::box, which is welded to the world"
    assert how_held(plant, finger).startswith("joined to the world through")
    assert how_held(plant, box) == "a free body"
    assert joined(plant, palm, finger) and joined(plant, table, finger)
    assert not joined(plant, box, finger)
    freed = load_scene(
        jaw_scene(tmp_path, "t", directives=GRIPPER + BOX), free_hand=True
    )
    f = _body(freed, "gripper::left_finger")
    assert free_carrier(freed.plant, f).name() == "palm"
    assert how_held(freed.plant, f) == "carried by the free body gripper::palm"
