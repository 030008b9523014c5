"""close_hand on real hands (WSG-50, Allegro, Franka) from drake_models.

Every closed pose is checked by routes of its own: Drake's signed distances
over every hand/object geometry pair, the joint limits read from the plant,
a force-closure LP written here with scipy (not the library's programs), and
central finite differences of ψ for ∂ψ/∂v.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from closure_oracle import independent_force_closure
from drake_distances import hand_object_distances
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from drakegrasp import (
    InvalidOptionError,
    PenetrationError,
    UnreachableError,
    analyze_grasp,
    close_hand,
    grasp_from_plant,
)
from drakegrasp.plant.contacts import DEFAULT_DISTANCE_TOLERANCE as TOL


def all_pair_distances(scene):
    """ψ of every (hand-instance body geometry, object geometry) pair."""
    query = scene.plant.get_geometry_query_input_port().Eval(scene.ctx)
    name = query.inspector().GetName
    return {
        (body.name(), name(gh), go): d
        for body, gh, go, d in hand_object_distances(
            scene.plant, query, scene.hand, scene.object
        )
    }


def check_closed(scene, closure):
    """The closure's claims, each checked against the plant directly."""
    plant, ctx = scene.plant, scene.ctx
    q = plant.GetPositions(ctx)
    np.testing.assert_array_equal(q[closure.position_indices], closure.q)
    for name, qi in zip(closure.joints, closure.q, strict=True):
        joint = plant.GetJointByName(name.split("::")[-1], scene.hand)
        assert (
            joint.position_lower_limits()[0] <= qi <= joint.position_upper_limits()[0]
        )
    distances = all_pair_distances(scene)
    assert min(distances.values()) >= -TOL  # no hand body penetrates the object
    for finger in closure.fingers:
        mine = [
            d
            for (body, _, _), d in distances.items()
            if f"{plant.GetModelInstanceName(scene.hand)}::{body}" in finger.bodies
        ]
        if finger.status == "touching":
            assert 0.0 <= finger.psi <= TOL
            assert abs(min(mine) - finger.psi) < 1e-12
        else:
            assert min(mine) > TOL


def close_truthfully_or_say_why(scene):
    """Close the scene's hand; check the closure, or that the refusal is true.

    A penetrating start must really penetrate; an unreachable object must leave
    the context as it was with no finger touching.  Returns the checked
    closure, or None after a checked refusal.
    """
    q0 = scene.plant.GetPositions(scene.ctx).copy()
    try:
        closure = close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    except PenetrationError:
        assert min(all_pair_distances(scene).values()) < -TOL
        return None
    except UnreachableError as e:
        np.testing.assert_array_equal(scene.plant.GetPositions(scene.ctx), q0)
        assert all(f.status != "touching" for f in e.closure.fingers)
        return None
    check_closed(scene, closure)
    return closure


def test_wsg_closes_on_the_sugar_box(real_hands):
    scene = real_hands.wsg()
    X_WO = scene.plant.EvalBodyPoseInWorld(scene.ctx, scene.object)
    closure = close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    assert [f.status for f in closure.fingers] == ["touching", "touching"]
    assert closure.iterations < 20
    check_closed(scene, closure)
    # Symmetric: each pad at 39.1 / 2 mm from the box's mid-plane.
    np.testing.assert_allclose(closure.q, [-0.01705, 0.01705], atol=TOL)
    assert scene.plant.EvalBodyPoseInWorld(scene.ctx, scene.object).IsExactlyEqualTo(
        X_WO
    )
    report = analyze_grasp(
        scene.plant, scene.ctx, scene.object, hand=scene.hand, mu=0.5
    )
    assert report.pose.valid
    assert report.J.shape[1] == 2
    assert report.force_closure.frictional_closure == independent_force_closure(
        report.contacts, 0.5
    )
    assert report.force_closure.frictional_closure
    json.dumps(closure.to_dict())
    assert "2 of 2 fingers touch" in str(closure)


def test_allegro_closes_on_a_ball(real_hands):
    scene = real_hands.allegro()
    closure = close_hand(scene.plant, scene.root, scene.object, hand=scene.hand)
    assert len(closure.fingers) == 4
    assert all(len(f.joints) == 4 for f in closure.fingers)
    assert len(closure.touching_fingers) >= 3
    check_closed(scene, closure)
    data = grasp_from_plant(
        scene.plant, scene.ctx, scene.object, hand=scene.hand, mu=0.5
    )
    assert data.hand_jacobian.shape[1] == 16  # one column per hand velocity
    assert data.pose.valid
    for mu in (0.1, 0.5, 1.0):
        report = analyze_grasp(
            scene.plant, scene.ctx, scene.object, hand=scene.hand, mu=mu
        )
        assert report.force_closure.frictional_closure == independent_force_closure(
            report.contacts, mu
        )


def test_allegro_dpsi_dv_matches_central_differences(real_hands, tools):
    scene = real_hands.allegro()
    close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    plant, ctx = scene.plant, scene.ctx
    data = grasp_from_plant(plant, ctx, scene.object, hand=scene.hand, mu=0.5)
    q0 = plant.GetPositions(ctx)

    def psi_of(q):
        plant.SetPositions(ctx, q)
        query = plant.get_geometry_query_input_port().Eval(ctx)
        return np.array(
            [
                query.ComputeSignedDistancePairClosestPoints(
                    c.object_geometry, c.finger_geometry
                ).distance
                for c in data.contacts
            ]
        )

    h = 1e-6
    fd = np.zeros_like(data.dpsi_dv)
    for k in range(plant.num_velocities()):
        dv = np.zeros(plant.num_velocities())
        dv[k] = h
        plant.SetPositions(ctx, q0)
        q_plus = tools.step_q(plant, ctx, dv)
        q_minus = tools.step_q(plant, ctx, -dv)
        fd[:, k] = (psi_of(q_plus) - psi_of(q_minus)) / (2 * h)
    plant.SetPositions(ctx, q0)
    # Sphere tips on a sphere: Drake's distance is analytic, so FD is clean.
    np.testing.assert_allclose(data.dpsi_dv, fd, atol=1e-6)


def test_franka_hand_closes_each_finger(real_hands):
    scene = real_hands.franka()
    closure = close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    assert closure.touching_fingers == (
        "hand::panda_finger_joint1",
        "hand::panda_finger_joint2",
    )
    check_closed(scene, closure)
    # The box sits 5 mm off-centre: the fingers stop 10 mm apart in q.
    assert closure.q[0] - closure.q[1] == pytest.approx(0.01, abs=2 * TOL)


def test_mimic_coupled_franka_moves_as_one_finger(
    real_hands, drake_models_dir, tmp_path
):
    text = (drake_models_dir / "franka_description/urdf/hand.urdf").read_text()
    marker = '<joint name="panda_finger_joint2" type="prismatic">'
    assert marker in text
    coupled = text.replace(
        marker, marker + '<mimic joint="panda_finger_joint1" multiplier="1"/>'
    )
    path = tmp_path / "hand_mimic.urdf"
    path.write_text(coupled)
    scene = real_hands.franka(edit=path)
    assert scene.plant.num_constraints() == 1  # Drake made a coupler constraint
    with pytest.raises(InvalidOptionError, match="couplings="):
        close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    closure = close_hand(
        scene.plant,
        scene.ctx,
        scene.object,
        hand=scene.hand,
        couplings=[
            ("hand::panda_finger_joint2", "hand::panda_finger_joint1", 1.0, 0.0)
        ],
    )
    assert len(closure.fingers) == 1 and closure.fingers[0].status == "touching"
    assert closure.q[0] == closure.q[1]  # the coupling holds
    check_closed(scene, closure)
    # Off-centre: the rigidly coupled pair stops when the nearer finger touches.
    assert closure.fingers[0].touching_body == "hand::panda_leftfinger"


def test_direction_synergy_and_bad_directions(real_hands):
    scene = real_hands.wsg()
    closure = close_hand(
        scene.plant, scene.ctx, scene.object, hand=scene.hand, direction=[1.0, -1.0]
    )
    np.testing.assert_allclose(closure.q, [-0.01705, 0.01705], atol=TOL)
    scene = real_hands.wsg()
    closure = close_hand(
        scene.plant, scene.ctx, scene.object, hand=scene.hand, direction=[1.0, 0.0]
    )
    assert [f.status for f in closure.fingers] == ["touching", "fixed"]
    # Away from the object: the path ends at the limit.
    scene = real_hands.wsg()
    with pytest.raises(UnreachableError, match="at limit"):
        close_hand(
            scene.plant, scene.ctx, scene.object, hand=scene.hand, direction=[-1.0, 1.0]
        )
    for bad in ([1.0], [np.nan, 1.0], "up"):
        with pytest.raises(InvalidOptionError, match="direction"):
            close_hand(
                scene.plant, scene.ctx, scene.object, hand=scene.hand, direction=bad
            )


def test_out_of_reach_names_the_fingers_and_leaves_the_context(real_hands):
    scene = real_hands.allegro(p_ball=(0.3, 0.0, 0.1))
    q0 = scene.plant.GetPositions(scene.ctx)
    with pytest.raises(UnreachableError) as info:
        close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    message = str(info.value)
    for root in ("joint_0", "joint_4", "joint_8", "joint_12"):
        assert f"allegro_hand_right::{root}" in message
    assert "0 of 4 fingers" in message
    np.testing.assert_array_equal(scene.plant.GetPositions(scene.ctx), q0)
    closure = info.value.closure
    assert all(f.status in ("at limit", "not converged") for f in closure.fingers)
    assert all(f.iterations <= 100 for f in closure.fingers)


def test_bounded_iterations_and_min_fingers(real_hands):
    scene = real_hands.allegro()
    with pytest.raises(UnreachableError, match="not converged"):
        close_hand(
            scene.plant, scene.ctx, scene.object, hand=scene.hand, max_iterations=1
        )
    # Out of steps with min_fingers met: the stopped fingers stay clear.
    closure = close_hand(
        scene.plant, scene.ctx, scene.object, hand=scene.hand, max_iterations=10
    )
    assert "not converged" in [f.status for f in closure.fingers]
    assert closure.touching_fingers
    check_closed(scene, closure)
    scene = real_hands.allegro()
    with pytest.raises(UnreachableError, match="min_fingers = 5"):
        close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand, min_fingers=5)
    for bad in (0, 2.5, None):
        with pytest.raises(InvalidOptionError, match="max_iterations"):
            close_hand(
                scene.plant,
                scene.ctx,
                scene.object,
                hand=scene.hand,
                max_iterations=bad,
            )
    with pytest.raises(InvalidOptionError, match="distance_tolerance"):
        close_hand(
            scene.plant, scene.ctx, scene.object, hand=scene.hand, distance_tolerance=-1
        )


def test_pre_shape_penetration_is_refused(real_hands):
    # The sugar box sunk 20.6 mm into the WSG-50's (welded) palm.
    X = real_hands.rt([[0, 0, 1], [1, 0, 0], [0, 1, 0]], [0, 0.0590, 0])
    scene = real_hands.wsg(X_WO=X)
    with pytest.raises(PenetrationError, match=r"Schunk_Gripper::body .* 20\.6"):
        close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)


def test_shipped_gripper_closes_back_onto_its_closed_form_pose(scene_cache, tools):
    # The shipped scenes come from closed-form kinematics (|psi| < 1e-15 m):
    # opened and closed again, the gripper must come back to them.
    scene = scene_cache("parallel_jaw_box")
    root, ctx = tools.fresh_context(scene)
    q_star = scene.plant.GetPositions(ctx).copy()
    for name in ("left_finger_joint", "right_finger_joint"):
        scene.plant.GetJointByName(name).set_translation(ctx, 0.04)
    closure = close_hand(scene.plant, root, scene.object_body, hand=scene.hand)
    assert len(closure.touching_fingers) == 2
    # 0 <= psi <= tol of a pad moving along its normal: q* + psi, psi ~ tol / 2.
    np.testing.assert_allclose(scene.plant.GetPositions(ctx), q_star, atol=TOL)


def test_shipped_three_finger_hand_closes_along_a_synergy(scene_cache, tools):
    scene = scene_cache("three_finger_sphere")
    plant = scene.plant
    root, ctx = tools.fresh_context(scene)
    q_star = plant.GetPositions(ctx).copy()
    q = q_star.copy()
    proximal = [
        plant.GetJointByName(f"finger{k}_proximal_joint").position_start()
        for k in (1, 2, 3)
    ]
    q[proximal] -= 0.25  # open the proximal joints only
    plant.SetPositions(ctx, q)
    names = [n.split("::")[1] for n in _closing_names(plant, scene)]
    synergy = [1.0 if n.endswith("proximal_joint") else 0.0 for n in names]
    plant.SetPositions(ctx, q)
    closure = close_hand(
        plant, root, scene.object_body, hand=scene.hand, direction=synergy
    )
    assert len(closure.touching_fingers) == 3
    assert {f.touching_body for f in closure.fingers} == {
        f"hand::finger{k}_distal" for k in (1, 2, 3)
    }
    # Only the proximal joints moved, back to the closed-form pose (a 0.05 mm
    # gap on a ~0.1 m lever is well under 2 mrad).
    np.testing.assert_allclose(plant.GetPositions(ctx), q_star, atol=2e-3)
    moved = np.flatnonzero(plant.GetPositions(ctx) != q)
    assert set(moved) == set(proximal)


def _closing_names(plant, scene):
    from drakegrasp.plant.fingers import hand_structure
    from drakegrasp.plant.validation import hand_bodies

    ctx = scene.plant_context
    inspector = plant.get_geometry_query_input_port().Eval(ctx).inspector()
    bodies = hand_bodies(plant, scene.object_body, scene.hand)
    return hand_structure(plant, scene.object_body, bodies, inspector=inspector).names


# Both "anywhere" properties: fixed examples, few (each closes a real hand).
anywhere_examples = settings(
    derandomize=True,
    max_examples=8,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)


@anywhere_examples
@given(
    x=st.floats(-0.04, 0.04),
    y=st.floats(0.05, 0.16),
    yaw=st.floats(-0.6, 0.6),
)
def test_wsg_anywhere_either_closes_truthfully_or_says_why(real_hands, x, y, yaw):
    from pydrake.math import RigidTransform, RollPitchYaw

    R = RollPitchYaw(np.pi / 2, yaw, np.pi / 2).ToRotationMatrix()
    scene = real_hands.wsg(X_WO=RigidTransform(R, [x, y, 0.0]))
    closure = close_truthfully_or_say_why(scene)
    if closure is not None:
        assert all(f.status in ("touching", "at limit") for f in closure.fingers)


@anywhere_examples
@given(
    x=st.floats(0.06, 0.12),
    y=st.floats(-0.03, 0.03),
    z=st.floats(0.06, 0.16),
)
def test_allegro_anywhere_either_closes_truthfully_or_says_why(real_hands, x, y, z):
    close_truthfully_or_say_why(real_hands.allegro(p_ball=(x, y, z)))
