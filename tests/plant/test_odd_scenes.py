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
  said only "no model instance named ...";
- ``load_scene(..., free_hand=True)`` left a hand welded to a table (only welds
  to the world were dropped), left a scene without ``hand:`` welded, and kept a
  ``hand:`` of finger bodies as it was (the planner then found no free base).
"""

from __future__ import annotations

import numpy as np
import pytest
from odd_scenes import (
    BOX,
    BOX_ON_WORLD,
    GRIPPER,
    PALM_ON_WORLD,
    SECOND_BOX,
    TABLE_AND_PALM,
    jaw_scene,
)
from pydrake.multibody.tree import BodyIndex, ModelInstanceIndex

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError, ModelError, SceneError
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


# -- load_scene(..., free_hand=True) -------------------------------------------


def _free_hand_positions(scene) -> int:
    """Positions of the hand's free base (7) and fingers, and of the object."""
    return scene.plant.num_positions()


def test_a_hand_welded_to_a_table_is_freed(tmp_path):
    """Only welds to the world were left out: the palm stayed on the table."""
    path = jaw_scene(tmp_path, "table", directives=GRIPPER + TABLE_AND_PALM + BOX)
    freed = load_scene(path, free_hand=True)
    palm = _body(freed, "gripper::palm")
    assert palm.is_floating_base_body()
    table = _body(freed, "table::box")  # the table stays where it was
    assert table in freed.plant.GetBodiesWeldedTo(freed.plant.world_body())
    shipped = load_scene("parallel_jaw_box", free_hand=True)
    assert _free_hand_positions(freed) == _free_hand_positions(shipped)


def _included(tmp_path, text: str, namespace: str | None = None) -> str:
    """Directives that include ``text`` from a file, under ``namespace``."""
    inner = tmp_path / "inner.yaml"
    inner.write_text("directives:\n" + text)
    include = f"- add_directives:\n    file: file://{inner}\n"
    if namespace is None:
        return include
    return (
        f"- add_model_instance:\n    name: {namespace}\n"
        + include
        + f"    model_namespace: {namespace}\n"
    )


@pytest.mark.parametrize("namespace", [None, "left"])
@pytest.mark.parametrize("named", [True, False], ids=["hand named", "no hand:"])
def test_a_hand_welded_in_an_included_file_is_freed(tmp_path, namespace, named):
    """The weld that placed the hand sat in an add_directives file, and stayed."""
    gripper = "gripper" if namespace is None else f"{namespace}::gripper"
    directives = _included(tmp_path, GRIPPER + PALM_ON_WORLD, namespace) + BOX
    path = jaw_scene(
        tmp_path, "outer", hand=gripper if named else None, directives=directives
    )
    kept = load_scene(path)
    assert not _body(kept, f"{gripper}::palm").is_floating_base_body()
    freed = load_scene(path, free_hand=True)
    assert _body(freed, f"{gripper}::palm").is_floating_base_body()
    assert freed.hand == freed.plant.GetModelInstanceByName(gripper)
    shipped = load_scene("parallel_jaw_box", free_hand=True)
    assert _free_hand_positions(freed) == _free_hand_positions(shipped)


def test_a_namespace_shared_with_the_hand_keeps_its_other_welds(tmp_path):
    """Welds were matched by the first part of a scoped name: ``left::gripper``
    freed ``left::stand`` too, another model of the same include."""
    stand = (
        "- add_model:\n    name: stand\n    file: package://drakegrasp/objects/"
        "box.sdf\n- add_weld:\n    parent: world\n    child: stand::box\n"
        "    X_PC:\n      translation: [0.3, 0.0, 0.0]\n"
    )
    directives = _included(tmp_path, GRIPPER + PALM_ON_WORLD + stand, "left") + BOX
    path = jaw_scene(tmp_path, "outer", hand="left::gripper", directives=directives)
    freed = load_scene(path, free_hand=True)
    world = freed.plant.GetBodiesWeldedTo(freed.plant.world_body())
    assert _body(freed, "left::stand::box") in world
    assert _body(freed, "left::gripper::palm").is_floating_base_body()


def test_welds_inside_the_hand_and_onto_it_stay(tmp_path):
    """A camera welded onto the palm rides with the freed hand."""
    camera = (
        "- add_model:\n    name: camera\n    file: package://drakegrasp/objects/"
        "sphere.sdf\n- add_weld:\n    parent: gripper::palm\n    child: "
        "camera::sphere\n    X_PC:\n      translation: [0.0, 0.1, 0.0]\n"
    )
    path = jaw_scene(tmp_path, "cam", directives=GRIPPER + PALM_ON_WORLD + camera + BOX)
    freed = load_scene(path, free_hand=True)
    palm = _body(freed, "gripper::palm")
    assert palm.is_floating_base_body()
    assert _body(freed, "camera::sphere") in freed.plant.GetBodiesWeldedTo(palm)


def test_a_scene_without_hand_frees_the_one_instance_that_moves(tmp_path):
    path = jaw_scene(tmp_path, "nohand", hand=None)
    freed = load_scene(path, free_hand=True)
    assert freed.info.hand is None
    assert freed.hand == freed.plant.GetModelInstanceByName("gripper")
    assert _body(freed, "gripper::palm").is_floating_base_body()
    # without free_hand the file is read as before: hand None, palm welded
    kept = load_scene(path)
    assert kept.hand is None
    assert not _body(kept, "gripper::palm").is_floating_base_body()


def test_a_scene_without_hand_and_two_moving_instances_is_refused(tmp_path):
    path = jaw_scene(
        tmp_path,
        "two",
        hand=None,
        directives=GRIPPER + PALM_ON_WORLD + BOX + SECOND_BOX,
    )
    with pytest.raises(SceneError, match="names no hand") as e:
        load_scene(path, free_hand=True)
    assert "2 model instances ['gripper', 'box2']" in str(e.value)
    assert "'hand: gripper'" in str(e.value)
    load_scene(path)  # analyze reads it as before


def test_a_scene_without_hand_where_nothing_moves_is_refused(tmp_path):
    path = jaw_scene(tmp_path, "still", hand=None, directives=BOX)
    with pytest.raises(SceneError, match="no body besides the object can move"):
        load_scene(path, free_hand=True)


def test_a_hand_of_finger_bodies_is_freed_as_its_instance(tmp_path):
    path = jaw_scene(
        tmp_path, "fingers", hand="[gripper::left_finger, gripper::right_finger]"
    )
    freed = load_scene(path, free_hand=True)
    assert isinstance(freed.hand, ModelInstanceIndex)
    assert freed.plant.GetModelInstanceName(freed.hand) == "gripper"
    assert _body(freed, "gripper::palm").is_floating_base_body()
    kept = load_scene(path)
    assert [b.name() for b in kept.hand] == ["left_finger", "right_finger"]


def test_a_freed_hand_listing_the_object_is_refused(tmp_path):
    """Widened to its instances, the list once dropped the object silently."""
    path = jaw_scene(tmp_path, "listed", hand="[gripper::palm, box::box]")
    with pytest.raises(InvalidOptionError, match="also listed as a body of the hand"):
        load_scene(path, free_hand=True)


def test_an_object_welded_to_the_world_loads(tmp_path):
    """Loading is not planning: analyze may read a fixture; plan refuses it."""
    path = jaw_scene(
        tmp_path, "fixed", directives=GRIPPER + PALM_ON_WORLD + BOX_ON_WORLD
    )
    s = load_scene(path, free_hand=True)
    assert s.object_body in s.plant.GetBodiesWeldedTo(s.plant.world_body())


@pytest.mark.parametrize(
    "key, value, match",
    [
        ("object_body", "nope::x", "object_body: no body named 'nope::x'"),
        ("hand", "nope", "hand: no model instance named 'nope'"),
        ("hand", "[gripper::nope]", "hand: no body named 'gripper::nope'"),
    ],
)
def test_an_unknown_name_is_refused_naming_the_file_and_key(
    tmp_path, key, value, match
):
    kwargs = {key: value}
    path = jaw_scene(tmp_path, "unknown", **kwargs)
    for free in (False, True):
        with pytest.raises(ModelError, match=match) as e:
            load_scene(path, free_hand=free)
        assert str(e.value).startswith(f"scene {str(path)!r}: ")
