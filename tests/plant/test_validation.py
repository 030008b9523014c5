"""Impossible poses, either context, and bad plants, contexts and indices.

The two poses of issue 8 are rebuilt with Drake's own WSG-50 and YCB boxes:
the sugar box sunk 20.6 mm into the welded palm, and the fingers at ±76.5 mm
on the cracker box (limits ±55 mm).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from pydrake.multibody.tree import BodyIndex, ModelInstanceIndex

import drakegrasp as dg
from drakegrasp import (
    GraspError,
    InvalidContextError,
    InvalidPoseError,
    JointLimitError,
    ModelError,
    NoContactsError,
    PenetrationError,
    analyze_grasp,
    close_hand,
    find_contacts,
    grasp_from_plant,
    hand_jacobian,
    signed_distance_jacobian,
)
from drakegrasp.plant.validation import plant_context_of

SUGAR_SIDEWAYS = [[0, 0, 1], [1, 0, 0], [0, 1, 0]]  # box z along the fingers' x


@pytest.fixture
def sunk_box(real_hands):
    """WSG-50 closed on the sugar box, then the box pushed 20.6 mm into the palm."""
    scene = real_hands.wsg()
    close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    # The palm's box ends at y = 36.25 mm; the box's half-depth is 43.35 mm.
    y = 0.03625 + 0.04335 - 0.0206
    scene.plant.SetFreeBodyPose(
        scene.ctx, scene.object, real_hands.rt(SUGAR_SIDEWAYS, [0, y, 0])
    )
    return scene


def test_penetration_of_the_welded_palm_is_refused(sunk_box):
    plant, ctx, box = sunk_box.plant, sunk_box.ctx, sunk_box.object
    for hand in (None, sunk_box.hand):  # welded palm checked either way
        for fn in (analyze_grasp, grasp_from_plant):
            with pytest.raises(PenetrationError) as info:
                fn(plant, ctx, box, hand=hand, mu=0.5)
            message = str(info.value)
            assert "Schunk_Gripper::body" in message and "20.6 mm" in message
            assert isinstance(info.value, InvalidPoseError)
            assert "check_pose=False" in message
    report = analyze_grasp(plant, ctx, box, mu=0.5, check_pose=False)
    assert not report.pose.valid and not report.pose.checked
    [pen] = report.pose.penetrations
    assert pen.hand_body == "Schunk_Gripper::body"
    assert pen.depth == pytest.approx(0.0206, abs=1e-6)
    assert "pose: INVALID" in str(report)
    assert json.loads(json.dumps(report.to_dict()))["pose"]["valid"] is False
    # allow_penetration accepts penetration but still records it.
    report = analyze_grasp(plant, ctx, box, mu=0.5, allow_penetration=True)
    assert not report.pose.valid


def test_joint_limits_are_refused(real_hands):
    X = real_hands.rt([[1, 0, 0], [0, 0, -1], [0, 1, 0]], [0, 0.073, 0])
    scene = real_hands.wsg("package://drake_models/ycb/003_cracker_box.sdf", X)
    q = 0.0765 - 0.00005  # pads 0.05 mm off the 158 mm wide box
    scene.set_hand([-q, q])
    with pytest.raises(JointLimitError) as info:
        analyze_grasp(scene.plant, scene.ctx, scene.object, hand=scene.hand, mu=0.5)
    message = str(info.value)
    assert "Schunk_Gripper::left_finger_sliding_joint = -0.07645" in message
    assert "[-0.055, 0]" in message and "right_finger_sliding_joint" in message
    assert isinstance(info.value, InvalidPoseError)
    report = analyze_grasp(
        scene.plant, scene.ctx, scene.object, hand=scene.hand, mu=0.5, check_pose=False
    )
    assert [v.joint for v in report.pose.joint_limit_violations] == [
        "Schunk_Gripper::left_finger_sliding_joint",
        "Schunk_Gripper::right_finger_sliding_joint",
    ]
    assert "pose: INVALID" in str(report) and "outside its limits" in str(report)
    # Inside the limits the same grasp is a valid pose.
    scene.set_hand([-0.055, 0.055])
    report_ok = analyze_grasp(
        scene.plant, scene.ctx, scene.object, hand=scene.hand, mu=0.5, check_pose=False
    )
    assert report_ok.pose is None or report_ok.pose.joint_limit_violations == ()


def test_a_simulated_overshoot_of_a_limit_is_no_violation(real_hands):
    # Drake holds a joint at its limit with a stiff constraint: a state read
    # off a simulation overshoots it a little (the Allegro hand's joint_13 by
    # 5e-6 rad in the shake test), which is not an impossible pose
    from drakegrasp.plant.pose import JOINT_LIMIT_TOL, joint_limit_violations

    scene = real_hands.wsg()
    bodies = [scene.plant.get_body(i) for i in scene.plant.GetBodyIndices(scene.hand)]
    for past, refused in [(5e-6, False), (0.5 * JOINT_LIMIT_TOL, False),
                          (2 * JOINT_LIMIT_TOL, True), (1e-2, True)]:  # fmt: skip
        scene.set_hand([-0.055 - past, 0.055])
        found = joint_limit_violations(scene.plant, scene.ctx, bodies)
        assert bool(found) is refused, (past, found)


def test_valid_pose_is_reported_valid(real_hands):
    scene = real_hands.wsg()
    close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    report = analyze_grasp(scene.plant, scene.ctx, scene.object, mu=0.5)
    assert report.pose.valid and report.pose.checked
    assert "pose: valid" in str(report)


def test_every_plant_function_takes_the_root_context(real_hands):
    scene = real_hands.wsg()
    plant, root, ctx, box, hand = (
        scene.plant,
        scene.root,
        scene.ctx,
        scene.object,
        scene.hand,
    )
    closure = close_hand(plant, root, box, hand=hand)  # writes into the root
    np.testing.assert_array_equal(
        plant.GetPositions(ctx)[closure.position_indices], closure.q
    )
    assert plant_context_of(plant, root) is not root
    by_root = find_contacts(plant, root, box, hand=hand)
    by_ctx = find_contacts(plant, ctx, box, hand=hand)
    assert [c.psi for c in by_root] == [c.psi for c in by_ctx]
    a = grasp_from_plant(plant, root, box, hand=hand, mu=0.5)
    b = grasp_from_plant(plant, ctx, box, hand=hand, mu=0.5)
    np.testing.assert_array_equal(a.hand_jacobian, b.hand_jacobian)
    np.testing.assert_array_equal(a.dpsi_dv, b.dpsi_dv)
    np.testing.assert_array_equal(
        signed_distance_jacobian(plant, root, b.contacts, box), b.dpsi_dv
    )
    J = hand_jacobian(
        plant, root, b.contacts, b.grasp, box, velocity_indices=b.hand_velocity_indices
    )
    np.testing.assert_array_equal(J, b.hand_jacobian)
    ra = analyze_grasp(plant, root, box, hand=hand, mu=0.5)
    assert (
        ra.force_closure.d_star
        == analyze_grasp(plant, ctx, box, hand=hand, mu=0.5).force_closure.d_star
    )


def test_a_context_of_another_plant_is_refused(real_hands):
    one, other = real_hands.wsg(), real_hands.wsg()
    for context in (other.ctx, other.root):
        for call in (
            lambda c: find_contacts(one.plant, c, one.object),
            lambda c: analyze_grasp(one.plant, c, one.object, mu=0.5),
            lambda c: close_hand(one.plant, c, one.object, hand=one.hand),
        ):
            with pytest.raises(InvalidContextError, match="neither to this plant"):
                call(context)
    with pytest.raises(InvalidContextError, match="must be a pydrake Context"):
        find_contacts(one.plant, None, one.object)
    # A body of the other plant is refused too.
    with pytest.raises(ModelError, match="does not belong to this plant"):
        find_contacts(one.plant, one.ctx, other.object)


def test_unfinalized_plant_and_non_plants(tools, real_hands):
    _, plant, _ = tools.make_plant()
    with pytest.raises(ModelError, match="not finalized"):
        find_contacts(plant, real_hands.wsg().ctx, BodyIndex(0))
    with pytest.raises(ModelError, match="MultibodyPlant"):
        analyze_grasp("plant", None, "box::box", mu=0.5)


def test_bad_indices_are_checked_before_drake(real_hands):
    scene = real_hands.wsg()
    plant, ctx, box = scene.plant, scene.ctx, scene.object
    for fn in (find_contacts, analyze_grasp, close_hand):
        kwargs = {"mu": 0.5} if fn is analyze_grasp else {}
        with pytest.raises(
            ModelError, match=r"ModelInstanceIndex\(99\).*valid indices"
        ):
            fn(plant, ctx, box, hand=ModelInstanceIndex(99), **kwargs)
    with pytest.raises(ModelError, match=r"BodyIndex\(999\)"):
        find_contacts(plant, ctx, BodyIndex(999))
    with pytest.raises(GraspError, match="no model instance named 'claw'"):
        find_contacts(plant, ctx, box, hand="claw")


def test_hand_of_only_welded_bodies(real_hands):
    # A welded palm touches (issue 20): analysing it alone is a question with
    # an answer (here: it does not touch), closing it is not.
    scene = real_hands.wsg()
    palm = scene.plant.GetBodyByName("body", scene.hand)
    with pytest.raises(NoContactsError, match=r"closest .* Schunk_Gripper::body"):
        analyze_grasp(scene.plant, scene.ctx, scene.object, hand=[palm], mu=0.5)
    with pytest.raises(ModelError, match="welded to the world.*Schunk_Gripper::body"):
        close_hand(scene.plant, scene.ctx, scene.object, hand=[palm])


def test_distance_tolerance_is_one_rule_for_every_plant_function(real_hands):
    scene = real_hands.wsg()
    plant, ctx, box, hand = scene.plant, scene.ctx, scene.object, scene.hand
    for bad in (0.0, -1e-4, np.inf, np.nan, "abc", None):
        for call in (
            lambda t: find_contacts(plant, ctx, box, distance_tolerance=t),
            lambda t: analyze_grasp(plant, ctx, box, mu=0.5, distance_tolerance=t),
            lambda t: close_hand(plant, ctx, box, hand=hand, distance_tolerance=t),
        ):
            with pytest.raises(GraspError, match="distance_tolerance must be finite"):
                call(bad)


@pytest.mark.parametrize("name", [None, 3, b"box::box", ["box"]])
def test_resolve_body_refuses_a_name_that_is_no_string(name):
    # It raised a raw TypeError ("argument of type 'int' is not iterable").
    from pydrake.multibody.plant import MultibodyPlant
    from pydrake.multibody.tree import SpatialInertia

    from drakegrasp.plant.validation import resolve_body

    plant = MultibodyPlant(0.0)
    plant.AddRigidBody("box", SpatialInertia.SolidBoxWithMass(1, 0.1, 0.1, 0.1))
    plant.Finalize()
    assert resolve_body(plant, "box").name() == "box"
    with pytest.raises(dg.InvalidOptionError, match="a body name must be a string"):
        resolve_body(plant, name)


@pytest.mark.parametrize("tol", [0.0100001, 0.02, 1.0, 1e9, 1e300])
def test_a_distance_tolerance_above_ten_mm_is_refused_in_metres_and_mm(tol):
    # A user thinking in millimetres: at 0.02 the default scene's palm, 15 mm
    # below the box, became 4 contacts and the verdict force closure, "pose:
    # valid", without a word.
    scene = dg.load_scene()
    plant, ctx, box, hand = (
        scene.plant, scene.plant_context, scene.object_body, scene.hand
    )  # fmt: skip
    for call in (
        lambda t: dg.AnalysisOptions(distance_tolerance=t),
        lambda t: find_contacts(plant, ctx, box, hand=hand, distance_tolerance=t),
        lambda t: analyze_grasp(plant, ctx, box, mu=0.5, distance_tolerance=t),
        lambda t: close_hand(plant, ctx, box, hand=hand, distance_tolerance=t),
    ):
        with pytest.raises(dg.InvalidOptionError) as info:
            call(tol)
        message = str(info.value)
        assert message.startswith(f"distance_tolerance {tol:g} m (")
        assert "mm) is above the largest accepted, 0.01 m (10 mm)" in message
        assert "would count as touching" in message and "metres" in message


def test_the_largest_distance_tolerance_is_taken():
    from drakegrasp.core.tolerances import MAX_DISTANCE_TOLERANCE

    assert MAX_DISTANCE_TOLERANCE == 0.01
    options = dg.AnalysisOptions(distance_tolerance=MAX_DISTANCE_TOLERANCE)
    assert options.distance_tolerance == 0.01
