"""The load section of a coupled hand (Franka hand review, items 1-3).

1. every actuator of a coupled hand still pushes: the independent coordinate
   carries ``Cᵀ τ``, bounded by ``|C|ᵀ τ_max`` (hand calculation and the
   uncoupled hand);
2. a hold that rests on a squeeze no motor can create (LP3 fails) is not
   called held by the motors;
3. a configuration that breaks a coupling is an invalid pose.
"""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.plant.couplings import coupled_torque_limits, split_coupled_torque

J1 = "franka::panda_finger_joint1"
J2 = "franka::panda_finger_joint2"
FRANKA_LIMIT = 20.0
"""Effort limit of each finger joint in Drake's panda_hand.urdf, N."""

SCENE = """\
directives:
- add_model:
    name: franka
    file: package://drake_models/franka_description/urdf/panda_hand.urdf
    default_joint_positions:
      panda_finger_joint1: [{q1}]
      panda_finger_joint2: [{q2}]
- add_weld:
    parent: world
    child: franka::panda_hand
- add_model:
    name: sugar
    file: package://drake_models/ycb/004_sugar_box.sdf
    default_free_body_pose:
      base_link_sugar:
        translation: [0.0, 0.0, 0.1034]
        rotation: !Rpy {{ deg: [0.0, 0.0, 90.0] }}
drakegrasp:
  description: Franka panda_hand pads across the sugar box's 86.7 mm width
  object_body: sugar::base_link_sugar
  hand: franka
  mu: 0.5
"""
Q_CLOSED = 0.04385
"""Each pad's travel at which both touch the sugar box (its 86.7 mm width)."""


@pytest.fixture
def franka_sugar(drake_models_dir, tmp_path):
    path = tmp_path / "franka_sugar.yaml"
    path.write_text(SCENE.format(q1=-Q_CLOSED, q2=Q_CLOSED))
    return dg.load_scene(path)


def _analyze(scene, **kw):
    kw = {**scene.analysis_options(), "load": "gravity", "torque_limits": "plant", **kw}
    return dg.analyze_grasp(scene.plant, scene.plant_context, **kw)


def test_the_box_image_under_c_transpose_is_its_vertices_extreme():
    # Independent route: the largest |u_i| over the box's vertices.
    rng = np.random.default_rng(3)
    C = np.zeros((5, 3))
    C[[0, 1, 2], [0, 1, 2]] = 1.0
    C[3, 0], C[4, 2] = -0.7, 2.5
    limits = rng.uniform(0.5, 3.0, 5)
    vertices = np.array(list(itertools.product((-1.0, 1.0), repeat=5))) * limits
    extreme = np.max(np.abs(vertices @ C), axis=0)
    np.testing.assert_allclose(coupled_torque_limits(C, limits), extreme)
    g = np.array([1.0, -0.5, 2.0])
    tau = split_coupled_torque(C, limits, g)
    np.testing.assert_allclose(C.T @ tau, g)
    assert np.all(np.abs(tau) <= limits)


def test_a_coupled_actuator_adds_its_effort_to_its_leaders(franka_sugar):
    s = franka_sugar
    free = _analyze(s, couplings=())
    coupled = _analyze(s, couplings=[(J2, J1, -1.0, 0.0)])
    # Hand calculation: the weight lies in the pads' plane, so friction carries
    # it: each pad presses m g / (2 μ), and each finger's motor gives 20 N.
    weight = float(np.linalg.norm(free.load.wrench[:3]))
    per_finger = weight / (2 * 0.5)
    alpha = FRANKA_LIMIT / per_finger
    np.testing.assert_array_equal(free.load.torque_limits, [20.0, 20.0])
    np.testing.assert_array_equal(coupled.load.torque_limits, [40.0])
    np.testing.assert_array_equal(coupled.load.actuator_torque_limits, [20.0, 20.0])
    assert free.load.payload.alpha == pytest.approx(alpha, rel=1e-4)
    assert coupled.load.payload.alpha == pytest.approx(alpha, rel=1e-4)
    assert coupled.load.holds and free.load.holds
    # The two motors share the coordinate's force: as the free hand's joints.
    np.testing.assert_allclose(
        coupled.load.actuator_torques, free.load.forces.joint_torques, rtol=1e-5
    )
    np.testing.assert_allclose(
        coupled.load.actuator_torques, [per_finger, -per_finger], rtol=1e-5
    )
    text = str(coupled.load)
    assert "panda_finger_joint2 -5.04 N" in text and "panda_finger_joint1 40 N" in text
    d = coupled.load.to_dict()
    assert d["actuator_torque_limits"] == [20.0, 20.0]
    json.dumps(coupled.to_dict())


def test_a_follower_without_an_actuator_is_not_listed_among_the_actuators(
    franka_sugar,
):
    # A linkage's follower has no motor (limit 0): the report listed it among
    # the "actuator efforts" at "-0 N".  The leader's motor now carries the
    # coordinate alone, and the follower is named apart.
    report = _analyze(
        franka_sugar, couplings=[(J2, J1, -1.0, 0.0)], torque_limits=[20.0, 0.0]
    )
    load = report.load
    np.testing.assert_array_equal(load.torque_limits, [20.0])
    np.testing.assert_array_equal(load.actuator_torques[1], 0.0)
    (line,) = [x for x in str(load).splitlines() if "actuator efforts" in x]
    assert "panda_finger_joint2 " not in line.split("(no actuator")[0]
    assert line.endswith("(no actuator, moved by their leaders: panda_finger_joint2)")
    assert "-0 N" not in str(load)
    # The joint torque the follower's share carried is its leader's now.
    assert load.actuator_torques[0] == pytest.approx(
        load.forces.joint_torques[0], rel=1e-9
    )


def test_given_limits_per_actuator_or_per_coordinate(franka_sugar):
    s = franka_sugar
    per_actuator = _analyze(
        s, couplings=[(J2, J1, -1.0, 0.0)], torque_limits=[5.0, 15.0]
    )
    per_coordinate = _analyze(s, couplings=[(J2, J1, -1.0, 0.0)], torque_limits=[20.0])
    assert per_actuator.load.payload.alpha == pytest.approx(
        per_coordinate.load.payload.alpha, rel=1e-6
    )
    np.testing.assert_array_equal(per_actuator.load.torque_limits, [20.0])
    with pytest.raises(dg.InvalidOptionError, match="one limit per actuated joint"):
        _analyze(s, couplings=[(J2, J1, -1.0, 0.0)], torque_limits=[1.0, 2.0, 3.0])


SAME_WAY = [(J2, J1, 1.0, 2 * Q_CLOSED)]
"""Both fingers move the same way (franka_ros's mimic multiplier on Drake's
panda_hand, whose joint 1 is flipped), with the offset the closed pose needs."""


def test_a_squeeze_no_motor_creates_does_not_hold_the_load(franka_sugar):
    s = franka_sugar
    report = _analyze(s, couplings=SAME_WAY)
    assert not report.force_closure.is_closure  # LP3: no control of the squeeze
    load = report.load
    assert load.defective and load.needs_preload and not load.holds
    assert load.payload is None and load.motor_bodies is None
    # Independent check of why: the forces balance the weight with no joint
    # force at all, so every newton of their squeeze is uncontrollable.
    f = load.forces.stacked_forces()
    np.testing.assert_allclose(report.G @ f, -load.wrench, atol=1e-9)
    assert np.max(np.abs(report.J.T @ f)) < 1e-9 * load.forces.squeeze
    assert load.forces.squeeze > 10.0
    text = str(load)
    assert "holds: NO" in text and "only with a preload" in text
    assert load.to_dict()["needs_preload"] is True
    # The same hand with the motors' own coupling holds it (unchanged).
    mirrored = _analyze(s, couplings=[(J2, J1, -1.0, 0.0)])
    assert mirrored.load.holds and not mirrored.load.defective
    assert mirrored.load.motor_bodies is None


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_push_into_one_finger_is_held_by_its_motors(franka_sugar, sign):
    s = franka_sugar
    probe = _analyze(s, couplings=SAME_WAY, load=None, torque_limits=None)
    n = probe.contacts[0].nhat_O
    F = 3.0
    w = np.concatenate([sign * F * n, np.zeros(3)])
    report = _analyze(s, couplings=SAME_WAY, load=w)
    load = report.load
    assert load.defective and not load.needs_preload and load.holds
    (body,) = load.motor_bodies
    # Hand calculation: one pad pushes F along the joint axis; its coordinate
    # carries both motors' 20 N, so the payload factor is 40 N / F.
    assert abs(load.forces.joint_torques[0]) == pytest.approx(F, rel=1e-5)
    assert load.payload.alpha == pytest.approx(2 * FRANKA_LIMIT / F, rel=1e-4)
    touching = {
        c.finger_body
        for c, fc in zip(report.contacts, load.forces.contact_forces, strict=True)
        if fc[0] > 1e-9
    }
    assert touching == {body}
    assert "held by the motors through" in str(load)


def test_a_pose_that_breaks_a_given_coupling_is_invalid(franka_sugar):
    s = franka_sugar
    broken = [(J2, J1, 1.0, 0.0)]  # q2 = q1, but q1 = -q2 in the scene
    with pytest.raises(dg.CouplingError) as err:
        _analyze(s, couplings=broken)
    message = str(err.value)
    assert (
        f"breaks the coupling {J2} = 1 * {J1} + 0: 0.04385 != 1 * -0.04385 + 0"
        in message
    )
    assert "check_pose=False" in message
    # Independent route: the joints' positions read from the plant.
    q1 = s.plant.GetJointByName("panda_finger_joint1").GetOnePosition(s.plant_context)
    q2 = s.plant.GetJointByName("panda_finger_joint2").GetOnePosition(s.plant_context)
    assert abs(q2 - q1) > 1e-6 and abs(q2 + q1) < 1e-12
    report = _analyze(s, couplings=broken, check_pose=False)
    assert not report.pose.valid
    assert "pose: INVALID" in str(report) and "breaks the coupling" in str(report)
    (v,) = report.to_dict()["pose"]["coupling_violations"]
    assert (v["follower"], v["leader"]) == (J2, J1)
    assert v["follower_value"] == pytest.approx(q2)
    assert v["leader_value"] == pytest.approx(q1)
    # The coupling the scene keeps is no violation.
    assert _analyze(s, couplings=[(J2, J1, -1.0, 0.0)]).pose.valid


def test_a_pose_that_breaks_a_models_mimic_is_invalid():
    from hand_models import Rig, box_object, mimic_gripper_urdf
    from pydrake.math import RigidTransform

    rig = Rig(
        [(mimic_gripper_urdf(), "urdf"), (box_object(), "sdf")],
        "box",
        RigidTransform([0.0, 0.0, 0.05]),
        weld_hand="palm",
        record_couplings=True,
    )
    dg.close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    left = rig.plant.GetJointByName("left_jaw_joint", rig.hand)
    right = rig.plant.GetJointByName("right_jaw_joint", rig.hand)
    q = left.GetOnePosition(rig.ctx)
    ok = dg.analyze_grasp(rig.plant, rig.ctx, rig.object, hand=rig.hand, mu=0.5)
    assert ok.pose.valid
    right.set_translation(rig.ctx, q - 0.002)  # opens the right jaw 2 mm
    # close_hand refuses the same state, in the same words
    with pytest.raises(dg.GraspError, match="breaks the coupling") as closing:
        dg.close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    for kw in ({}, {"couplings": ()}):  # Drake's constraint holds whatever J uses
        with pytest.raises(dg.CouplingError, match="breaks the coupling") as err:
            dg.analyze_grasp(
                rig.plant, rig.ctx, rig.object, hand=rig.hand, mu=0.5, **kw
            )
        assert "mimic_gripper::right_jaw_joint = 1 * mimic_gripper::left_jaw_joint" in (
            str(err.value)
        )
        assert f"{q - 0.002:.6g} != 1 * {q:.6g} + 0" in str(err.value)
    assert f"{q - 0.002:.6g} != 1 * {q:.6g} + 0" in str(closing.value)


def _fork(with_top: bool):
    """Two fixed contacts pinching a box along x (no joint moves them), and
    optionally a third pressing down from above on a prismatic joint along z."""
    import types

    contacts = [
        dg.Contact([-0.05, 0, 0], [1, 0, 0], mu=0.5),
        dg.Contact([0.05, 0, 0], [-1, 0, 0], mu=0.5),
    ]
    bodies = ["fork_left", "fork_right"]
    if with_top:
        contacts.append(dg.Contact([0, 0, 0.05], [0, 0, -1], mu=0.5))
        bodies.append("top")
    grasp = dg.Grasp(contacts)
    J = np.zeros((3 * len(contacts), 1))
    if with_top:  # the top contact's frame components of a motion along +z
        J[6:9, 0] = np.asarray(contacts[2].frame).T @ np.array([0.0, 0.0, 1.0])
    data = types.SimpleNamespace(
        grasp=grasp,
        hand_jacobian=J,
        contacts=[types.SimpleNamespace(finger_body=b) for b in bodies],
    )
    return grasp, J, data


@pytest.mark.parametrize("with_top", [False, True])
def test_a_pinch_no_motor_makes_is_a_preload_whatever_else_touches(with_top):
    # Independent route, by hand: the fork's squeeze (+1 N at each fork
    # contact, along its normal) has G h = 0 (equal and opposite on one line)
    # and J^T h = 0 (no joint moves the fork).  A third contact that cannot
    # join that squeeze once hid it: LP3 needs every f_n > 0.
    from drakegrasp.closure.verdicts import internal_forces
    from drakegrasp.plant.load import _held_by_motors, passive_preload

    grasp, J, data = _fork(with_top)
    h = np.zeros(3 * grasp.num_contacts)
    h[[0, 3]] = 1.0
    np.testing.assert_allclose(dg.grasp_matrix(grasp) @ h, 0.0, atol=1e-15)
    np.testing.assert_allclose(J.T @ h, 0.0, atol=1e-15)
    assert passive_preload(grasp, J)
    if with_top:  # LP3 passes here: the old test saw no defect
        assert internal_forces(grasp, J).passes
    weight = np.array([0.0, 0.0, -4.905, 0.0, 0.0, 0.0])
    assert dg.grasp_forces(
        grasp, weight, hand_jacobian=J, torque_limits=[10.0]
    ).feasible
    bodies, _, _ = _held_by_motors(data, weight, np.array([10.0]))
    assert bodies is None  # only the fork's preload holds the weight


def test_a_squeeze_that_loads_the_joints_is_no_preload():
    # Two jaws on their own prismatic joints: their squeeze loads both joints
    grasp = dg.Grasp(
        [dg.Contact([-0.05, 0, 0], [1, 0, 0], mu=0.5),
         dg.Contact([0.05, 0, 0], [-1, 0, 0], mu=0.5)]
    )  # fmt: skip
    J = np.zeros((6, 2))
    J[0:3, 0] = np.asarray(grasp.contacts[0].frame).T @ np.array([1.0, 0.0, 0.0])
    J[3:6, 1] = np.asarray(grasp.contacts[1].frame).T @ np.array([-1.0, 0.0, 0.0])
    from drakegrasp.plant.load import passive_preload

    assert not passive_preload(grasp, J)
