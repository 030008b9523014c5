"""Couplings read from the model (issue 20, point 5): close_hand, J and LP3 use them.

Own models: a parallel gripper whose right jaw follows the left by a URDF
``<mimic>`` and the same gripper with an SDFormat ``<drake:mimic>``.  ``J C``
is checked against the uncoupled ``J`` times the coupling written here, and
against finite differences of the finger points along the coupled motion.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from hand_models import (
    JAW_PAD,
    JAW_Y0,
    Rig,
    box_object,
    mimic_gripper_sdf,
    mimic_gripper_urdf,
)
from pydrake.math import RigidTransform

from drakegrasp import InvalidOptionError, analyze_grasp, close_hand, load_scene
from drakegrasp.plant import JointCoupling, add_coupler_constraint, plant_couplings
from drakegrasp.plant.contacts import DEFAULT_DISTANCE_TOLERANCE as TOL

GRIPPERS = {
    "urdf": lambda **k: (mimic_gripper_urdf(**k), "urdf", "palm"),
    "sdf": lambda **k: (mimic_gripper_sdf(**k), "sdf", None),
}
FOLLOWER = "mimic_gripper::right_jaw_joint"
LEADER = "mimic_gripper::left_jaw_joint"


def gripper_rig(kind, *, y=0.0, record=True, **mimic):
    text, fmt, weld = GRIPPERS[kind](**mimic)
    return Rig(
        [(text, fmt), (box_object(), "sdf")],
        "box",
        RigidTransform([0.0, y, 0.05]),
        weld_hand=weld,
        record_couplings=record,
    )


@pytest.mark.parametrize("kind", sorted(GRIPPERS))
def test_the_mimic_element_is_read_with_its_numbers(kind):
    rig = gripper_rig(kind, multiplier=2.0, offset=-0.01)
    assert rig.plant.num_constraints() == 1  # Drake made its coupler constraint
    assert plant_couplings(rig.plant) == (JointCoupling(FOLLOWER, LEADER, 2.0, -0.01),)


@pytest.mark.parametrize("kind", sorted(GRIPPERS))
def test_coupled_jaws_close_as_one_and_j_has_one_column(kind):
    rig = gripper_rig(kind)
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    (finger,) = closure.fingers
    assert finger.status == "touching"
    assert closure.q[0] == closure.q[1]  # the coupling holds
    # Centred 30 mm box: both pads at 15 mm from the middle, within the tolerance.
    q_star = JAW_Y0 - 0.015 - 0.5 * JAW_PAD[1]
    np.testing.assert_allclose(closure.q, q_star, atol=TOL)
    distances = rig.pair_distances()
    for pad in ("left_jaw_pad", "right_jaw_pad"):
        (psi,) = [d for (g, _), d in distances.items() if g.endswith(pad)]
        assert 0.0 <= psi <= TOL

    report = analyze_grasp(rig.plant, rig.ctx, rig.object, hand=rig.hand, mu=0.5)
    coupled = report.J
    assert coupled.shape == (report.grasp.num_components, 1)
    assert report.data.couplings == (JointCoupling(FOLLOWER, LEADER, 1.0, 0.0),)
    left = rig.plant.GetJointByName("left_jaw_joint", rig.hand)
    assert report.data.hand_velocity_indices.tolist() == [left.velocity_start()]
    # An explicit couplings=() overrides the model: the free jaws' J.
    free = analyze_grasp(
        rig.plant, rig.ctx, rig.object, hand=rig.hand, mu=0.5, couplings=()
    )
    assert free.J.shape[1] == 2
    np.testing.assert_allclose(coupled[:, 0], free.J @ [1.0, 1.0], atol=1e-15)
    # Finite differences of the finger points along the coupled motion.
    plant, ctx = rig.plant, rig.ctx
    q0 = plant.GetPositions(ctx).copy()
    right = rig.plant.GetJointByName("right_jaw_joint", rig.hand)
    h = 1e-6

    def finger_points(dq):
        q = q0.copy()
        q[left.position_start()] += dq
        q[right.position_start()] += dq
        plant.SetPositions(ctx, q)
        X_WO = plant.EvalBodyPoseInWorld(ctx, rig.object)
        out = []
        for c in report.contacts:
            body = plant.get_body(c.finger_body_index)
            p_W = plant.EvalBodyPoseInWorld(ctx, body).multiply(c.p_FC)
            out.append(X_WO.inverse().multiply(p_W))
        return np.array(out)

    velocity = (finger_points(h) - finger_points(-h)) / (2 * h)
    plant.SetPositions(ctx, q0)
    fd = np.concatenate(
        [c.frame.T @ v for c, v in zip(report.grasp.contacts, velocity, strict=True)]
    )
    np.testing.assert_allclose(coupled[:, 0], fd, atol=1e-8)
    json.dumps(report.data.to_dict())


def test_an_off_centre_object_is_touched_by_one_coupled_jaw():
    rig = gripper_rig("urdf", y=0.004)
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    assert closure.fingers[0].touching_body == "mimic_gripper::right_jaw"
    distances = rig.pair_distances()
    (left,) = [d for (g, _), d in distances.items() if g.endswith("left_jaw_pad")]
    assert left == pytest.approx(0.008, abs=2 * TOL)


def test_a_plant_parsed_without_drakegrasp_must_be_told(tmp_path):
    rig = gripper_rig("urdf", record=False)
    for call in (
        lambda: close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand),
        lambda: analyze_grasp(rig.plant, rig.ctx, rig.object, hand=rig.hand, mu=0.5),
    ):
        with pytest.raises(InvalidOptionError, match="add_models.*couplings="):
            call()
    closure = close_hand(
        rig.plant,
        rig.ctx,
        rig.object,
        hand=rig.hand,
        couplings=[(FOLLOWER, LEADER, 1.0, 0.0)],
    )
    assert closure.q[0] == closure.q[1]


def test_a_coupler_added_in_code_is_recorded():
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    plant = MultibodyPlant(0.001)
    text = (
        mimic_gripper_sdf()
        .replace("<drake:mimic", "<!-- ")
        .replace('offset="0.0"/>', "-->")
    )
    (hand,) = Parser(plant).AddModelsFromString(text, "sdf")
    assert plant.num_constraints() == 0
    add_coupler_constraint(
        plant,
        plant.GetJointByName("right_jaw_joint", hand),
        plant.GetJointByName("left_jaw_joint", hand),
        -1.0,
        0.02,
    )
    assert plant_couplings(plant) == (JointCoupling(FOLLOWER, LEADER, -1.0, 0.02),)


def test_a_scene_file_records_its_models_couplings(tmp_path):
    (tmp_path / "gripper.urdf").write_text(mimic_gripper_urdf())
    (tmp_path / "box.sdf").write_text(box_object())
    q = JAW_Y0 - 0.015 - 0.5 * JAW_PAD[1] - 3e-5
    (tmp_path / "scene.yaml").write_text(
        f"""directives:
- add_model:
    name: mimic_gripper
    file: gripper.urdf
    default_joint_positions:
      left_jaw_joint: [{q!r}]
      right_jaw_joint: [{q!r}]
- add_weld:
    parent: world
    child: mimic_gripper::palm
- add_model:
    name: box
    file: box.sdf
    default_free_body_pose:
      box:
        translation: [0.0, 0.0, 0.05]
drakegrasp:
  object_body: box::box
  hand: mimic_gripper
  mu: 0.5
"""
    )
    scene = load_scene(tmp_path / "scene.yaml")
    assert plant_couplings(scene.plant) == (JointCoupling(FOLLOWER, LEADER, 1.0, 0.0),)
    report = analyze_grasp(
        scene.plant, scene.plant_context, scene.object_body, hand=scene.hand, mu=0.5
    )
    assert report.J.shape[1] == 1


def test_repeated_urdf_collision_names_get_unique_labels():
    # Both jaws' collisions are called "Box", as both PR2 pads are (issue 20, 11).
    text = (
        mimic_gripper_urdf()
        .replace("left_jaw_pad", "Box")
        .replace("right_jaw_pad", "Box")
    )
    rig = Rig(
        [(text, "urdf"), (box_object(), "sdf")],
        "box",
        RigidTransform([0.0, 0.0, 0.05]),
        weld_hand="palm",
    )
    close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    report = analyze_grasp(rig.plant, rig.ctx, rig.object, hand=rig.hand, mu=0.5)
    entries = report.to_dict()["contacts"]
    assert {e["finger_geometry"] for e in entries} == {"mimic_gripper::Box"}
    labels = {(e["finger_body"], e["finger_geometry_label"]) for e in entries}
    assert len({label for _, label in labels}) == 2  # one per jaw
    for body, label in labels:
        assert label == body + "/Box#0"
    assert {e["object_geometry_label"] for e in entries} == {"box::box#0"}


@pytest.mark.parametrize("kind", sorted(GRIPPERS))
def test_a_mimic_drake_ignores_is_not_recorded(kind):
    # A discrete TAMSI plant drops the <mimic> (Drake warns, adds no
    # constraint): its jaws move freely in the simulation, so drakegrasp must
    # not analyse, pose-check or load-check them as coupled.
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig
    from pydrake.systems.framework import DiagramBuilder

    from drakegrasp.plant import add_models

    text, fmt, _ = GRIPPERS[kind]()
    plants = {}
    for approximation in ("tamsi", "sap"):
        builder = DiagramBuilder()
        config = MultibodyPlantConfig(
            time_step=1e-3, discrete_contact_approximation=approximation
        )
        plant, _ = AddMultibodyPlant(config, builder)
        add_models(Parser(plant), text=text, kind=fmt)
        plant.Finalize()
        plants[approximation] = plant
    assert plants["tamsi"].num_constraints() == 0
    assert plant_couplings(plants["tamsi"]) == ()
    assert plants["sap"].num_constraints() == 1
    assert plant_couplings(plants["sap"]) == (
        JointCoupling(FOLLOWER, LEADER, 1.0, 0.0),
    )


_MIMIC_BODY = (
    "<model name='m'><link name='a'/><link name='b'/><link name='c'/>"
    "<joint name='j1' type='revolute'><parent>a</parent><child>b</child>"
    "<axis><xyz>0 0 1</xyz></axis></joint>"
    "<joint name='j2' type='revolute'><parent>b</parent><child>c</child>"
    "<axis><xyz>0 0 1</xyz></axis>"
    "<drake:mimic joint='j1' multiplier='2' offset='0'/></joint></model>"
)


@pytest.mark.parametrize(
    "text",
    [
        f"<sdf version='1.9'>{_MIMIC_BODY}</sdf>",
        f"<?xml version='1.0'?>\n<sdf version='1.9'>{_MIMIC_BODY}</sdf>",
        # a comment before the root that names an element, or the namespace
        f"<!-- see <model> --><sdf version='1.9'>{_MIMIC_BODY}</sdf>",
        f"<!-- no xmlns:drake here --><sdf version='1.9'>{_MIMIC_BODY}</sdf>",
        f"<?xml version='1.0'?><!DOCTYPE sdf><sdf version='1.9'>{_MIMIC_BODY}</sdf>",
        f"\ufeff<sdf version='1.9'>{_MIMIC_BODY}</sdf>",
        # another prefix Drake ignores, beside the mimic
        f"<sdf version='1.9'>{_MIMIC_BODY[:-8]}<gz:plugin/></model></sdf>",
    ],
)  # fmt: skip
def test_a_prefix_the_file_does_not_declare_is_read_as_drake_reads_it(text):
    # Drake's parser takes <drake:mimic> (or <gz:plugin>) in a file without
    # the xmlns declaration; XML does not, and planning_scene, now loading
    # through add_models, refused such models ("unbound prefix").
    from drakegrasp.plant.couplings import couplings_in_model

    assert couplings_in_model(text, "sdf") == [[("j2", "j1", 2.0, 0.0)]]


def test_a_model_without_a_mimic_is_not_read_as_xml(tmp_path):
    # A URDF's <gazebo><sensor:camera/> (an undeclared prefix): Drake loads it,
    # and add_models, which has no coupling to read there, loads it too.
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    from drakegrasp.plant.couplings import add_models

    path = tmp_path / "r.urdf"
    path.write_text(
        "<?xml version='1.0'?><robot name='r'><link name='a'/><link name='b'/>"
        "<joint name='j' type='revolute'><parent link='a'/><child link='b'/>"
        "<axis xyz='0 0 1'/><limit effort='1' lower='-1' upper='1' velocity='1'/>"
        "</joint><gazebo><sensor:camera name='c'/></gazebo></robot>"
    )
    plant = MultibodyPlant(0.001)
    assert len(add_models(Parser(plant), path)) == 1
    assert plant_couplings(plant) == ()


def test_a_drake_prefix_the_file_does_not_declare_is_read_as_drake_reads_it():
    # Drake's parser takes <drake:mimic> (or <drake:proximity_properties>) in a
    # file without xmlns:drake; XML does not, and planning_scene, now loading
    # through add_models, refused such an object ("unbound prefix").
    from drakegrasp.plant.couplings import couplings_in_model

    text, _, _ = GRIPPERS["sdf"](multiplier=2.0, offset=-0.01)
    bare = text.replace(' xmlns:drake="http://drake.mit.edu"', "").replace(
        " xmlns:drake='http://drake.mit.edu'", ""
    )
    assert "xmlns:drake" not in bare and "drake:mimic" in bare
    assert couplings_in_model(bare, "sdf") == couplings_in_model(text, "sdf")
    assert couplings_in_model(bare, "sdf")[0][0][2:] == (2.0, -0.01)


def _chain_plant(ratios=(1.0, 0.5), offsets=(0.0, 0.0)):
    """Three hinges on a palm, ``b`` following ``a`` and ``c`` following ``b``."""
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    from drakegrasp.plant.couplings import add_models

    link = (
        '<link name="{0}"><inertial><mass value="0.05"/><inertia ixx="1e-5" '
        'iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>'
    )
    hinge = (
        '<joint name="{0}" type="revolute"><parent link="palm"/><child link="l{0}"/>'
        '<axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
        "{1}</joint>"
    )
    mimic = '<mimic joint="{0}" multiplier="{1}" offset="{2}"/>'
    urdf = (
        '<?xml version="1.0"?><robot name="chain">'
        + "".join(link.format(n) for n in ("palm", "la", "lb", "lc"))
        + hinge.format("a", "")
        + hinge.format("b", mimic.format("a", ratios[0], offsets[0]))
        + hinge.format("c", mimic.format("b", ratios[1], offsets[1]))
        + "</robot>"
    )
    plant = MultibodyPlant(0.0)
    add_models(Parser(plant), text=urdf, kind="urdf")
    plant.Finalize()
    return plant


def test_a_chain_of_couplings_is_resolved_to_its_root():
    # A joint following a follower was refused ("may not both lead and
    # follow"), though Drake's coupler constraints take chains.  Resolved, c
    # follows a: checked against the recorded chain applied link by link.
    from drakegrasp.plant.couplings import coupling_map, recorded_couplings

    plant = _chain_plant(ratios=(2.0, -0.5), offsets=(0.1, 0.03))
    raw = recorded_couplings(plant)
    resolved = plant_couplings(plant)
    assert {c.follower: c.leader for c in resolved} == {
        "chain::b": "chain::a",
        "chain::c": "chain::a",
    }
    rho = {c.follower: (c.gear_ratio, c.offset) for c in resolved}
    for q_a in (-0.7, 0.0, 0.4):
        q = {"chain::a": q_a}
        for follower, leader, ratio, offset in raw:  # b before c, as recorded
            q[follower] = ratio * q[leader] + offset
        for follower, (ratio, offset) in rho.items():
            assert ratio * q_a + offset == pytest.approx(q[follower], abs=1e-15)
    # given couplings resolve alike, in any order, and a chain-free list is
    # returned as it was given (the same objects)
    assert set(plant_couplings(plant, couplings=raw[::-1])) == set(resolved)
    assert plant_couplings(plant, couplings=raw[:1]) == raw[:1]
    # the velocity map: v_b = 2 v_a, v_c = -0.5 v_b = -v_a
    columns = [plant.GetJointByName(n).velocity_start() for n in "abc"]
    C, independent = coupling_map(plant, columns, resolved)
    np.testing.assert_array_equal(C, [[1.0], [2.0], [-1.0]])
    assert list(independent) == columns[:1]
    # the chain as recorded maps alike
    C_raw, independent_raw = coupling_map(plant, columns, raw)
    np.testing.assert_array_equal(C_raw, C)
    assert list(independent_raw) == list(independent)


def test_a_chain_whose_root_is_outside_the_hand_keeps_its_followers_tied():
    # hand= bodies that leave the chain's root out (c -> b -> a, a outside):
    # c still follows b, as before chains were resolved; resolved to the root,
    # both couplings named a joint outside the map and were left out, and
    # J C gained a motion the coupler constraints do not allow (a reviewer's
    # finding).
    from drakegrasp.plant.couplings import coupling_map, recorded_couplings

    plant = _chain_plant(ratios=(2.0, -0.5))
    columns = [plant.GetJointByName(n).velocity_start() for n in "bc"]
    for couplings in (plant_couplings(plant), recorded_couplings(plant)):
        C, independent = coupling_map(plant, columns, couplings)
        np.testing.assert_array_equal(C, [[1.0], [-0.5]])  # v_c = -0.5 v_b
        assert list(independent) == columns[:1]
    # a loop given to the map directly is named
    b_c = [("chain::b", "chain::c", 1.0, 0.0), ("chain::c", "chain::b", 1.0, 0.0)]
    with pytest.raises(InvalidOptionError, match="close a loop"):
        coupling_map(plant, columns, b_c)


def test_couplings_that_loop_or_a_joint_with_two_leaders_are_refused():
    plant = _chain_plant()
    loop = [("chain::b", "chain::a", 1.0, 0.0), ("chain::a", "chain::b", 1.0, 0.0)]
    with pytest.raises(InvalidOptionError, match=r"close a loop \(chain::b -> "):
        plant_couplings(plant, couplings=loop)
    two = [("chain::c", "chain::a", 1.0, 0.0), ("chain::c", "chain::b", 2.0, 0.0)]
    with pytest.raises(InvalidOptionError, match="chain::c follows two joints"):
        plant_couplings(plant, couplings=two)
    same = [("chain::c", "chain::a", 1.0, 0.0)] * 2  # a repeated coupling is one
    assert plant_couplings(plant, couplings=same) == tuple(same)


def test_a_zero_ratio_names_the_joints_it_couples():
    from drakegrasp.plant.fingers import coupling_entry

    plant = _chain_plant()
    with pytest.raises(InvalidOptionError, match="coupling of chain::b to chain::a"):
        coupling_entry(plant, ("chain::b", "chain::a", 0.0, 0.0))
