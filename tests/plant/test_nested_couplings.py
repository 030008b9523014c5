"""Couplings of nested and included SDFormat models, named as Drake scopes them.

A hand whose fingers are nested ``<model>`` s (or ``<include>`` d files) gets
model instances ``hand::finger``.  Its ``<drake:mimic>`` s were recorded with
the top model's name and the joint's local one (``quadn::j2``, no such joint)
or, for an include, not at all; planning then refused the hand, telling the
user to load it with ``add_models``, which they had.
"""

from __future__ import annotations

import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from drakegrasp.plant.couplings import add_models, couplings_in_model
from drakegrasp.plant.fingers import find_joint
from drakegrasp.plant.validation import hand_bodies

DRAKE = 'xmlns:drake="http://drake.mit.edu"'


def _finger(name: str, ratio: float) -> str:
    """A two-joint finger model whose distal joint follows the proximal one."""
    link = "<link name='{0}'><inertial><mass>0.05</mass></inertial></link>"
    return (
        f"<model name='{name}'>{link.format('base')}{link.format('prox')}"
        f"{link.format('dist')}<joint name='j1' type='revolute'><parent>base"
        "</parent><child>prox</child><axis><xyz>1 0 0</xyz><limit><lower>-1"
        "</lower><upper>1</upper></limit></axis></joint><joint name='j2' "
        "type='revolute'><parent>prox</parent><child>dist</child><axis><xyz>1 0 "
        "0</xyz><limit><lower>-1</lower><upper>1</upper></limit></axis>"
        f"<drake:mimic joint='j1' multiplier='{ratio}' offset='0'/></joint></model>"
    )


def _nested() -> str:
    return (
        f"<sdf version='1.9' {DRAKE}><model name='hand'><link name='palm'>"
        "<inertial><mass>0.2</mass></inertial></link>"
        f"{_finger('f0', 0.5)}{_finger('f1', 0.8)}"
        "<joint name='w0' type='fixed'><parent>palm</parent><child>f0::base</child>"
        "</joint><joint name='w1' type='fixed'><parent>palm</parent><child>f1::base"
        "</child></joint></model></sdf>"
    )


def _plant():
    plant = MultibodyPlant(0.001)
    return plant, Parser(plant)


def test_nested_mimics_are_named_under_their_models():
    assert couplings_in_model(_nested(), "sdf") == [
        [("f0::j2", "f0::j1", 0.5, 0.0), ("f1::j2", "f1::j1", 0.8, 0.0)]
    ]


def test_a_nested_hands_couplings_name_joints_drake_has(tmp_path):
    plant, parser = _plant()
    add_models(parser, text=_nested(), kind="sdf")
    plant.Finalize()
    from drakegrasp.plant.couplings import plant_couplings

    couplings = plant_couplings(plant)
    assert [(c.follower, c.leader) for c in couplings] == [
        ("hand::f0::j2", "hand::f0::j1"),
        ("hand::f1::j2", "hand::f1::j1"),
    ]
    for c in couplings:  # each resolves to the joint Drake coupled
        assert find_joint(plant, c.follower).name() == "j2"
    # the hand's model instance holds its nested fingers' bodies
    ball = plant.GetBodyByName("palm")  # any body apart from the fingers
    names = {b.name() for b in hand_bodies(plant, ball, "hand::f0")}
    assert names == {"base", "prox", "dist"}


@pytest.mark.parametrize(
    "uri", ["package://mine/finger.sdf", "file://{folder}/finger.sdf"]
)
def test_an_included_models_couplings_are_recorded(tmp_path, uri):
    from drakegrasp.plant.couplings import plant_couplings

    (tmp_path / "finger.sdf").write_text(
        f"<sdf version='1.9' {DRAKE}>{_finger('finger', 2.0)}</sdf>"
    )
    wrapper = tmp_path / "wrapper.sdf"
    wrapper.write_text(
        "<sdf version='1.9'><model name='wrapper'><link name='mount'><inertial>"
        "<mass>0.1</mass></inertial></link><include><uri>"
        f"{uri.format(folder=tmp_path)}</uri><name>g</name></include></model></sdf>"
    )
    plant, parser = _plant()
    parser.package_map().Add("mine", str(tmp_path))
    add_models(parser, wrapper)
    plant.Finalize()
    (c,) = plant_couplings(plant)
    assert (c.follower, c.leader, c.gear_ratio) == (
        "wrapper::g::j2",
        "wrapper::g::j1",
        2.0,
    )
    assert find_joint(plant, c.leader).name() == "j1"


def test_a_merged_include_keeps_its_parents_scope(tmp_path):
    from drakegrasp.plant.couplings import model_resolver, plant_couplings

    (tmp_path / "finger.sdf").write_text(
        f"<sdf version='1.9' {DRAKE}>{_finger('finger', 2.0)}</sdf>"
    )
    text = (
        "<sdf version='1.9'><model name='hand'><link name='palm'><inertial><mass>"
        f"0.1</mass></inertial></link><include merge='true'><uri>file://{tmp_path}"
        "/finger.sdf</uri></include></model></sdf>"
    )
    plant, parser = _plant()
    resolve = model_resolver(parser.package_map(), tmp_path)
    assert couplings_in_model(text, "sdf", resolve=resolve) == [
        [("j2", "j1", 2.0, 0.0)]
    ]
    add_models(parser, text=text, kind="sdf")
    plant.Finalize()
    (c,) = plant_couplings(plant)
    assert find_joint(plant, c.follower).name() == "j2"  # hand::j2: Drake's name


def test_a_namespaced_model_not_joined_to_the_hand_is_no_part_of_it():
    # a scene's model_namespace names other models `hand::...` too
    plant, parser = _plant()
    add_models(parser, text=_nested(), kind="sdf")
    from pydrake.multibody.tree import SpatialInertia

    cup = plant.AddModelInstance("hand::cup")  # as model_namespace: hand makes
    plant.AddRigidBody("cup", cup, SpatialInertia.SolidSphereWithMass(0.1, 0.03))
    plant.Finalize()
    palm = plant.GetBodyByName("palm")
    names = {b.name() for b in hand_bodies(plant, plant.GetBodyByName("cup"), "hand")}
    assert "cup" not in names and {"palm", "prox", "dist"} <= names
    assert palm.name() in names
