"""Hydroelastic fingers in the shake test: a flat pad presses over a patch.

Drake's point contact gives a pad on a face one point, and the object pivots
between two such points; hydroelastic pads hold it.  The properties are
checked in the plant Drake builds (an independent route: SceneGraph's
inspector), and the physics in the simulation itself.
"""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.geometry import Role
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, ContactModel
from pydrake.systems.framework import DiagramBuilder

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.plant.hydroelastic import (
    check_hydroelastic_modulus,
    use_hydroelastic_contact,
)

JAW = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
BOX = "package://drakegrasp/objects/box.sdf"


@pytest.fixture(scope="module")
def jaw_on_box():
    scene = dg.planning_scene(BOX, hand_url=JAW)
    result = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=300, mu=0.5, seed=0,
    )  # fmt: skip
    return scene, result


def _built(scene, modulus):
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=1e-3)
    hand, name = scene.add_models(plant, Parser(plant))
    model, _, body_name = name.rpartition("::")
    body = plant.GetBodyByName(body_name, plant.GetModelInstanceByName(model))
    hand_bodies = [plant.get_body(i) for i in plant.GetBodyIndices(hand)]
    inspector = scene_graph.model_inspector()
    friction = {}  # copied out: the properties are replaced below
    for b in hand_bodies + [body]:
        for g in plant.GetCollisionGeometriesForBody(b):
            mu = inspector.GetProximityProperties(g).GetProperty(
                "material", "coulomb_friction"
            )
            friction[g] = (mu.static_friction(), mu.dynamic_friction())
    refused = use_hydroelastic_contact(
        plant, scene_graph, hand_bodies, [body], modulus=modulus
    )
    return plant, scene_graph, hand_bodies, body, friction, refused


def test_the_hand_becomes_compliant_and_the_object_rigid_friction_kept(jaw_on_box):
    scene, _ = jaw_on_box
    plant, sg, hand_bodies, body, friction, refused = _built(scene, 2.5e6)
    assert refused == 0
    assert plant.get_contact_model() == ContactModel.kHydroelasticWithFallback
    inspector = sg.model_inspector()
    for b, kind in [(b, "compliant") for b in hand_bodies] + [(body, "rigid")]:
        for g in plant.GetCollisionGeometriesForBody(b):
            props = inspector.GetProximityProperties(g)
            assert props.HasGroup("hydroelastic"), inspector.GetName(g)
            # only a compliant geometry has a modulus (pydrake cannot read the
            # compliance type itself)
            has_modulus = props.HasProperty("hydroelastic", "hydroelastic_modulus")
            assert has_modulus is (kind == "compliant"), inspector.GetName(g)
            if has_modulus:
                modulus = props.GetProperty("hydroelastic", "hydroelastic_modulus")
                assert modulus == 2.5e6
            same = props.GetProperty("material", "coulomb_friction")
            assert (same.static_friction(), same.dynamic_friction()) == friction[g]
            assert inspector.GetProperties(g, Role.kProximity) is not None


def test_a_finalized_plant_is_refused(jaw_on_box):
    scene, _ = jaw_on_box
    builder = DiagramBuilder()
    plant, sg = AddMultibodyPlantSceneGraph(builder, time_step=1e-3)
    scene.add_models(plant, Parser(plant))
    plant.Finalize()
    with pytest.raises(ModelError, match="not finalized"):
        use_hydroelastic_contact(plant, sg, [], [], modulus=1e6)


@pytest.mark.parametrize(
    "value",
    [0.0, -1.0, np.nan, np.inf, "1e6", True, [1e6], 1e-3, 9e3, 2e12, 1e300, 10**30],
)
def test_a_modulus_outside_the_physical_range_is_refused(value):
    """Measured on the flat jaw: at 1e-3 Pa the box fell through the pads, at
    1e15 SAP did not converge, at 1e300 the contact force vanished and the box
    fell as if dropped: each was reported as a result, not an error."""
    with pytest.raises(InvalidOptionError, match=r"hydroelastic_modulus .*\[10000, "):
        check_hydroelastic_modulus(value)


@pytest.mark.parametrize("value", [1e4, 1e6, np.float32(1e6), 10**12])
def test_a_modulus_within_the_range_is_taken(value):
    assert check_hydroelastic_modulus(value) == float(value)


def test_bodies_and_scene_graph_are_checked(jaw_on_box):
    scene, _ = jaw_on_box
    builder = DiagramBuilder()
    plant, sg = AddMultibodyPlantSceneGraph(builder, time_step=1e-3)
    hand, _ = scene.add_models(plant, Parser(plant))
    body = plant.get_body(plant.GetBodyIndices(hand)[0])
    with pytest.raises(InvalidOptionError, match="hand_bodies must be an iterable"):
        use_hydroelastic_contact(plant, sg, body, [], modulus=1e6)
    with pytest.raises(InvalidOptionError, match="object_bodies must hold RigidBody"):
        use_hydroelastic_contact(plant, sg, [], [body.index()], modulus=1e6)
    other = DiagramBuilder()
    plant2, sg2 = AddMultibodyPlantSceneGraph(other, time_step=1e-3)
    scene.add_models(plant2, Parser(plant2))
    stranger = plant2.get_body(plant2.GetBodyIndices(hand)[0])
    with pytest.raises(ModelError, match="of another plant"):
        use_hydroelastic_contact(plant, sg, [stranger], [], modulus=1e6)
    with pytest.raises(ModelError, match="not registered with this scene_graph"):
        use_hydroelastic_contact(plant, sg2, [body], [], modulus=1e6)
    with pytest.raises(InvalidOptionError, match="modulus must be"):
        use_hydroelastic_contact(plant, sg, [body], [], modulus=1e20)


def test_flat_pads_pivot_in_point_contact_and_hold_as_patches(jaw_on_box):
    """The physics, in Drake: at 20 N (nine times ``squeeze_needed``) point
    contact lets the box pivot between the pads (most of the top 4 turn past
    10 degrees); hydroelastic pads hold all four within a millimetre.  Below the
    planner's ``squeeze_needed`` (0.5 N against 2.2 N) hydroelastic pads drop
    every one: the patch does not hold what the squeeze cannot."""
    scene, result = jaw_on_box
    quick = dict(settle=0.2, phase=0.3, directions=[(1, 0, 0), (0, 1, 0)])
    point = dg.shake_candidates(scene.add_models, result, top=4, **quick)
    patch = dg.shake_candidates(
        scene.add_models, result, top=4, hydroelastic_modulus=1e6, **quick
    )
    weak = dg.shake_candidates(
        scene.add_models, result, top=4, hydroelastic_modulus=1e6, squeeze=0.5, **quick
    )
    assert max(c.squeeze_needed for c in result[:4]) < 20.0 / 5
    assert min(c.squeeze_needed for c in result[:4]) > 0.5
    assert sum(s.held for s in point) <= 2
    assert all(s.held for s in patch)
    assert max(s.result.max_displacement for s in patch) < 1e-3
    assert not any(s.held for s in weak)
    assert all(s.result.hydroelastic_modulus == 1e6 for s in patch)
    assert all(s.result.hydroelastic_modulus is None for s in point)
    assert "hydroelastic fingers (1e+06 Pa)" in str(patch[0].result)


SOFT_BOX = """<?xml version="1.0"?>
<sdf version="1.9" xmlns:drake="http://drake.mit.edu"><model name="soft">
<link name="soft"><inertial><mass>0.2</mass><inertia><ixx>1e-4</ixx><iyy>1e-4</iyy>
<izz>1e-4</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
<collision name="c"><geometry><box><size>0.05 0.05 0.1</size></box></geometry>
<drake:proximity_properties><drake:compliant_hydroelastic/>
<drake:hydroelastic_modulus>5e5</drake:hydroelastic_modulus>
<drake:mu_dynamic>0.8</drake:mu_dynamic></drake:proximity_properties></collision>
</link></model></sdf>"""


def test_an_object_the_model_makes_compliant_keeps_its_compliance(tmp_path):
    # A soft object's own <drake:compliant_hydroelastic> was replaced by rigid
    # properties, and the shake pressed on another object than the modelled
    path = tmp_path / "soft.sdf"
    path.write_text(SOFT_BOX)
    scene = dg.planning_scene(str(path), hand_url=JAW)
    plant, sg, hand_bodies, body, friction, refused = _built(scene, 2.5e6)
    assert refused == 0
    inspector = sg.model_inspector()
    (g,) = plant.GetCollisionGeometriesForBody(body)
    props = inspector.GetProximityProperties(g)
    assert props.GetProperty("hydroelastic", "hydroelastic_modulus") == 5e5
    for b in hand_bodies:  # the hand is made compliant as before
        for h in plant.GetCollisionGeometriesForBody(b):
            modulus = inspector.GetProximityProperties(h).GetProperty(
                "hydroelastic", "hydroelastic_modulus"
            )
            assert modulus == 2.5e6
