"""Bad input to the plant layer's public functions is a GraspError.

A fuzzer of the plant-side API found Drake's and Python's own errors escaping
(and one ``SystemExit`` from a Drake assertion), and answers computed
silently from contacts or bodies of another plant.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

import drakegrasp as dg
from drakegrasp.plant.jacobians import hand_velocity_indices
from drakegrasp.plant.load import gravity_wrench


@pytest.fixture(scope="module")
def jaw():
    return dg.load_scene("parallel_jaw_box")


@pytest.fixture(scope="module")
def three():
    return dg.load_scene("three_finger_sphere")


@pytest.fixture(scope="module")
def jaw_found(jaw):
    g = dg.grasp_from_plant(jaw.plant, jaw.plant_context, jaw.object_body, mu=0.5)
    return g, list(g.contacts)


def _contacts(scene):
    return dg.find_contacts(scene.plant, scene.plant_context, scene.object_body)


def _hand(scene, instance):
    plant = scene.plant
    found = plant.GetBodyIndices(plant.GetModelInstanceByName(instance))
    return [plant.get_body(i) for i in found]


# -- signed_distance_jacobian ----------------------------------------------


def test_no_contacts_give_an_empty_signed_distance_jacobian(jaw):
    J = dg.signed_distance_jacobian(jaw.plant, jaw.plant_context, [], jaw.object_body)
    assert J.shape == (0, jaw.plant.num_velocities())


@pytest.mark.parametrize("item", [1, "contact", None])
def test_a_signed_distance_jacobian_refuses_what_is_no_contact(jaw, jaw_found, item):
    contacts = [jaw_found[1][0], item]
    with pytest.raises(dg.InvalidContactError, match=r"contacts\[1\]"):
        dg.signed_distance_jacobian(
            jaw.plant, jaw.plant_context, contacts, jaw.object_body
        )


# -- hand_jacobian ---------------------------------------------------------


BAD_INDICES = [
    ([-1], "-1"),
    ([0.5], "0.5"),
    ([100], "100"),
    ([0, 0], "more than once"),
    ([True], "True"),
    ("ab", "'ab'"),
    ([[0, 1]], "one-dimensional"),
]
"""Velocity indices every taker refuses, and a word of each message."""


@pytest.mark.parametrize(("indices", "words"), BAD_INDICES)
def test_torque_limit_readers_refuse_bad_velocity_indices(jaw, indices, words):
    # plant_torque_limits read -1 as the last velocity, 0.5 as 0, and 100 as
    # a velocity no actuator drives (limit 0): a silent answer
    from drakegrasp.plant.load import plant_torque_limits, unbounded_actuators

    for read in (plant_torque_limits, unbounded_actuators):
        with pytest.raises(dg.InvalidOptionError) as e:
            read(jaw.plant, indices)
        assert words in str(e.value)
    np.testing.assert_array_equal(plant_torque_limits(jaw.plant, [0, 1]), [140, 140])


@pytest.mark.parametrize(("indices", "words"), BAD_INDICES)
def test_hand_jacobian_refuses_bad_velocity_indices(jaw, jaw_found, indices, words):
    g, contacts = jaw_found
    with pytest.raises(dg.InvalidOptionError, match="velocity_indices") as e:
        dg.hand_jacobian(
            jaw.plant, jaw.plant_context, contacts, g.grasp, jaw.object_body,
            velocity_indices=indices,
        )  # fmt: skip
    assert words in str(e.value)


def test_hand_jacobian_takes_integral_indices_of_any_integer_type(jaw, jaw_found):
    g, contacts = jaw_found
    for indices in ([], np.array([1, 0], dtype=np.int32), (g.hand_velocity_indices)):
        J = dg.hand_jacobian(
            jaw.plant, jaw.plant_context, contacts, g.grasp, jaw.object_body,
            velocity_indices=indices,
        )  # fmt: skip
        assert J.shape == (g.grasp.num_components, len(indices))


def test_hand_jacobian_refuses_a_bad_plane(jaw, jaw_found):
    g, contacts = jaw_found
    call = dict(velocity_indices=[0])
    with pytest.raises(dg.InvalidOptionError, match="plane must be one of"):
        dg.hand_jacobian(
            jaw.plant, jaw.plant_context, contacts, g.grasp, jaw.object_body,
            plane="ab", **call,
        )  # fmt: skip
    with pytest.raises(dg.InvalidGraspError, match="spatial"):
        dg.hand_jacobian(
            jaw.plant, jaw.plant_context, contacts, g.grasp, jaw.object_body,
            plane="xy", **call,
        )  # fmt: skip


def test_hand_jacobian_refuses_contacts_not_of_the_grasp(jaw, jaw_found):
    g, contacts = jaw_found
    with pytest.raises(dg.InvalidGraspError, match=r"1 contact.*2 contacts"):
        dg.hand_jacobian(
            jaw.plant, jaw.plant_context, contacts[:1], g.grasp, jaw.object_body,
            velocity_indices=[0],
        )  # fmt: skip


# -- contacts of another plant ---------------------------------------------


def test_analyze_grasp_refuses_contacts_of_another_plant(jaw, three):
    for scene, other in ((jaw, three), (three, jaw)):
        with pytest.raises(dg.ModelError, match="another plant") as e:
            dg.analyze_grasp(
                scene.plant, scene.plant_context, scene.object_body, mu=0.5,
                contacts=_contacts(other),
            )  # fmt: skip
        assert "contacts[0]" in str(e.value)


def test_analyze_grasp_refuses_contacts_of_a_copy_of_the_plant(jaw):
    # the same scene loaded again: same body names and indices, other geometry
    copy = dg.load_scene("parallel_jaw_box")
    with pytest.raises(dg.ModelError, match="geometry"):
        dg.analyze_grasp(
            jaw.plant, jaw.plant_context, jaw.object_body, mu=0.5,
            contacts=_contacts(copy),
        )  # fmt: skip


def test_analyze_grasp_refuses_contacts_of_another_object(jaw, jaw_found):
    _, contacts = jaw_found
    finger = contacts[0].finger_body
    with pytest.raises(dg.ModelError, match="object"):
        dg.analyze_grasp(
            jaw.plant, jaw.plant_context, finger, mu=0.5, contacts=contacts,
            check_pose=False,
        )  # fmt: skip


def test_analyze_grasp_refuses_a_renamed_finger(jaw, jaw_found):
    _, contacts = jaw_found
    renamed = [dataclasses.replace(contacts[0], finger_body="gripper::palm")]
    with pytest.raises(dg.ModelError, match="gripper::palm"):
        dg.analyze_grasp(
            jaw.plant, jaw.plant_context, jaw.object_body, mu=0.5, contacts=renamed
        )


def test_analyze_grasp_refuses_what_is_no_contact(jaw):
    with pytest.raises(dg.InvalidContactError, match=r"contacts\[0\].*int"):
        dg.analyze_grasp(
            jaw.plant, jaw.plant_context, jaw.object_body, mu=0.5, contacts=[1, 2]
        )


def test_analyze_grasp_takes_its_own_contacts(jaw, jaw_found):
    _, contacts = jaw_found
    report = dg.analyze_grasp(
        jaw.plant, jaw.plant_context, jaw.object_body, mu=0.5, contacts=contacts
    )
    assert report.grasp.num_contacts == len(contacts)


def test_jacobians_refuse_contacts_of_another_plant(jaw, three, jaw_found):
    g, _ = jaw_found
    foreign = _contacts(three)
    with pytest.raises(dg.ModelError, match="another plant"):
        dg.signed_distance_jacobian(
            jaw.plant, jaw.plant_context, foreign, jaw.object_body
        )
    with pytest.raises(dg.ModelError, match="another plant"):
        dg.hand_jacobian(
            jaw.plant, jaw.plant_context, foreign[:2], g.grasp, jaw.object_body,
            velocity_indices=[0],
        )  # fmt: skip


def test_grasp_from_plant_takes_contacts_of_the_same_scene_loaded_again(jaw):
    # with a number for mu it reads bodies and points only (review: refused
    # since the contact check came in, though it worked before); mu="plant"
    # reads the geometries' friction, which this plant does not hold
    theirs = _contacts(dg.load_scene("parallel_jaw_box"))
    given = dg.grasp_from_plant(
        jaw.plant, jaw.plant_context, jaw.object_body, mu=0.5, contacts=theirs
    )
    own = dg.grasp_from_plant(jaw.plant, jaw.plant_context, jaw.object_body, mu=0.5)
    np.testing.assert_array_equal(given.hand_jacobian, own.hand_jacobian)
    with pytest.raises(dg.ModelError, match="geometry"):
        dg.grasp_from_plant(
            jaw.plant, jaw.plant_context, jaw.object_body, mu="plant",
            contacts=theirs,
        )  # fmt: skip


def test_contacts_of_another_object_are_refused_where_ids_are_not_read(jaw):
    # the box scene's contacts on the cylinder scene (same hand, same body
    # names and indices) were taken by grasp_from_plant with a number for mu
    # and by the Jacobians: points 5 mm inside the cylinder's surface (fuzzer)
    cylinder = dg.load_scene("parallel_jaw_cylinder")
    theirs = _contacts(jaw)
    with pytest.raises(dg.ModelError, match="not of model 'cylinder'"):
        dg.grasp_from_plant(
            cylinder.plant, cylinder.plant_context, cylinder.object_body, mu=0.5,
            contacts=theirs,
        )  # fmt: skip
    with pytest.raises(dg.ModelError, match="not of model 'cylinder'"):
        dg.signed_distance_jacobian(
            cylinder.plant, cylinder.plant_context, theirs, cylinder.object_body
        )


def test_jacobians_take_contacts_of_the_same_scene_loaded_again(jaw):
    # a candidate's contacts applied to another load of its scene (a second
    # plant of the same models: torque_capacity across plants) read only the
    # bodies and points, which agree; the geometry ids differ
    copy = dg.load_scene("parallel_jaw_box")
    theirs = _contacts(copy)
    np.testing.assert_array_equal(
        dg.signed_distance_jacobian(
            jaw.plant, jaw.plant_context, theirs, jaw.object_body
        ),
        dg.signed_distance_jacobian(
            jaw.plant, jaw.plant_context, _contacts(jaw), jaw.object_body
        ),
    )


# -- hand_velocity_indices -------------------------------------------------


def test_hand_velocity_indices_refuse_bodies_of_another_plant(jaw, three):
    with pytest.raises(dg.ModelError, match="palm.*does not belong to this plant"):
        hand_velocity_indices(jaw.plant, _hand(three, "hand"))


@pytest.mark.parametrize("bodies", [[1, 2], "abc", 3, None])
def test_hand_velocity_indices_refuse_what_is_no_body(jaw, bodies):
    with pytest.raises(dg.InvalidOptionError, match="bodies"):
        hand_velocity_indices(jaw.plant, bodies)


def test_hand_velocity_indices_of_own_bodies(jaw):
    assert hand_velocity_indices(jaw.plant, _hand(jaw, "gripper")).tolist() == [0, 1]


# -- contact_curvatures ----------------------------------------------------


def test_contact_curvatures_refuse_contacts_of_another_plant(jaw, three):
    with pytest.raises(dg.ModelError, match="another plant"):
        dg.plant.contact_curvatures(
            jaw.plant, jaw.plant_context, _contacts(three), object_body=jaw.object_body
        )


def test_contact_curvatures_refuse_a_bad_plane(jaw, jaw_found):
    with pytest.raises(dg.InvalidOptionError, match="plane must be one of"):
        dg.plant.contact_curvatures(
            jaw.plant, jaw.plant_context, jaw_found[1],
            object_body=jaw.object_body, plane="ab",
        )  # fmt: skip


# -- add_models ------------------------------------------------------------


@pytest.fixture
def parser():
    # pydrake's Parser does not keep its plant alive: a Parser of a temporary
    # MultibodyPlant reads freed memory (a crash, or Drake asserting)
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    dg.register_models(parser)
    yield parser
    del parser, plant


@pytest.mark.parametrize(
    ("given", "words"),
    [
        ({"file_name": "/nonexistent/hand.urdf"}, "/nonexistent/hand.urdf"),
        ({"url": "package://nopkg/hand.sdf"}, "nopkg"),
        ({"text": "garbage", "kind": "urdf"}, "the model text"),
    ],
)
def test_add_models_refusals_are_model_errors(parser, given, words):
    with pytest.raises(dg.ModelError, match="cannot load") as e:
        dg.plant.add_models(parser, **given)
    assert words in str(e.value)


# -- the plane of a planar analysis ------------------------------------------


def test_gravity_wrench_refuses_a_bad_plane(jaw):
    with pytest.raises(dg.InvalidOptionError, match="plane must be one of"):
        gravity_wrench(jaw.plant, jaw.plant_context, jaw.object_body, plane="ab")


def test_every_add_models_call_reaches_drake():
    # load_models once carried models_dir's functools.cache: a second add of
    # the same file on the same parser returned the first's instances without
    # calling Drake (no auto-renamed copy), and every plant stayed referenced
    import gc
    import weakref

    from drakegrasp.plant.models import models_dir

    box = str(models_dir() / "objects" / "box.sdf")
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    parser.SetAutoRenaming(True)
    dg.register_models(parser)
    first = dg.plant.add_models(parser, file_name=box)
    second = dg.plant.add_models(parser, file_name=box)
    assert list(map(int, first)) != list(map(int, second))
    assert plant.HasModelInstanceNamed("box_1")
    refs = []
    for _ in range(2):
        scene = dg.load_scene("parallel_jaw_box")
        refs.append(weakref.ref(scene.plant))
        del scene
    gc.collect()
    assert not any(r() is not None for r in refs)


def test_velocity_indices_of_a_billion_rows_are_refused_unread(jaw, jaw_found):
    # The broad fuzz: np.asarray(indices, dtype=object) of a broadcast
    # (10**9, 3) array asked for 24 GB (a raw MemoryError); a 1-D one of 10**9
    # entries cannot be distinct indices of a plant's few velocities.
    g, contacts = jaw_found
    for indices, words in (
        (np.broadcast_to(0.5, (10**9, 3)), "one-dimensional"),
        (np.broadcast_to(1, (10**9,)), "1000000000 of them"),
    ):
        test_hand_jacobian_refuses_bad_velocity_indices(jaw, jaw_found, indices, words)

    # An iterable that raises as it is read is named with what it raised
    # (items_of's words), not as a sequence of the wrong shape.
    def broken():
        yield 0
        raise RuntimeError("sensor unplugged")

    test_hand_jacobian_refuses_bad_velocity_indices(
        jaw, jaw_found, broken(), "sensor unplugged"
    )
    # A generator of indices is read once, as a sequence of them.
    J = dg.hand_jacobian(
        jaw.plant, jaw.plant_context, contacts, g.grasp, jaw.object_body,
        velocity_indices=(i for i in g.hand_velocity_indices),
    )  # fmt: skip
    assert J.shape[1] == len(g.hand_velocity_indices)


# -- names that Drake cannot read ------------------------------------------


@pytest.mark.parametrize(
    "name",
    ["\ud800", "hand::\udfff", "\udfff::base_link"],
    ids=["lone", "scoped-lone", "lone-model"],
)
def test_a_name_drake_cannot_read_is_no_body_and_no_model_instance(jaw, name):
    # pybind11 cannot pass a lone surrogate: Drake's HasBodyNamed and
    # HasModelInstanceNamed raised a bare TypeError for it (report_public).
    plant = jaw.plant
    with pytest.raises(dg.ModelError, match="no body named"):
        dg.object_radius(plant, jaw.plant_context, name)
    with pytest.raises(dg.ModelError, match="no body named"):
        dg.plant.hand_bodies(plant, name)
    with pytest.raises(dg.ModelError, match="no model instance named"):
        dg.plant.hand_bodies(plant, jaw.object_body, hand=name)
