"""A hand whose distal joints follow their proximal ones (``<mimic>``), as a
real linkage does: loaded from a file by the planner, its torque capacity held
to the motors it has, and shaken in Drake with motors on the leaders only.

The hand is ``coupled_support.coupled_hand_sdf``: three two-link fingers, each
distal joint a follower (ratio 0.6) of its proximal one.
"""

from __future__ import annotations

import numpy as np
import pytest
from coupled_hands import one_motor_pinch_urdf, spread_hand_urdf
from coupled_support import MODEL, coupled_hand_sdf
from grasp_builders import generator_matrix
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from scipy.optimize import linprog

import drakegrasp as dg
from drakegrasp.cli import main
from drakegrasp.planning import (
    centring,
    object_surface,
    plan_grasps,
    planning_scene,
    shake_test,
)
from drakegrasp.planning.approach import multi_finger_hand
from drakegrasp.planning.centring import chain_sides
from drakegrasp.planning.motors import finger_jacobian, torque_capacity
from drakegrasp.planning.multifinger import close_candidates
from drakegrasp.planning.shake import DAMPING_TIME, REVOLUTE_AIM
from drakegrasp.planning.weight import WEIGHT_DIRECTIONS
from drakegrasp.plant.couplings import recorded_couplings
from drakegrasp.plant.models import register_models

RATIO = 0.6
CYLINDER = "package://drakegrasp/objects/cylinder.sdf"
OPEN = [-0.5, -0.3] * 3  # (prox, dist) per finger: dist = 0.6 prox
MU = 0.8
PARTS = ("prox", "dist", "tip")  # a chained finger's links, root first


def _hand_file(tmp_path, **kw):
    path = tmp_path / "coupled_hand.sdf"
    path.write_text(coupled_hand_sdf(ratio=RATIO, **kw))
    return path


def _plan(path, num=40):
    scene = planning_scene(CYLINDER, hand_url=str(path))
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=num, mu=MU, seed=0, robustness_samples=8,
        preshape=OPEN,
    )  # fmt: skip
    return scene, result


@pytest.fixture(scope="module")
def motors_on_leaders(tmp_path_factory):
    """Planned with actuators on the proximal joints only."""
    return _plan(_hand_file(tmp_path_factory.mktemp("leaders"), follower_effort=0))


def test_a_mimic_hand_from_a_file_is_planned_with_its_couplings(motors_on_leaders):
    # planning_scene read the file's <drake:mimic> elements: without them the
    # planner refused the plant (3 constraints, 0 known couplings).
    scene, result = motors_on_leaders
    found = {
        (c.follower, c.leader, c.gear_ratio) for c in recorded_couplings(scene.plant)
    }
    assert found == {
        (f"{MODEL}::f{k}_dist_joint", f"{MODEL}::f{k}_prox_joint", RATIO)
        for k in range(3)
    }
    closed = [c for c in result if c.is_closure]
    assert closed, result
    names = list(closed[0].joint_names)
    for c in result:
        for k in range(3):
            prox = c.q_hand[names.index(f"{MODEL}::f{k}_prox_joint")]
            dist = c.q_hand[names.index(f"{MODEL}::f{k}_dist_joint")]
            assert dist == pytest.approx(RATIO * prox, abs=1e-9)


def test_the_cli_plans_a_mimic_hand_from_a_file(tmp_path, capsys):
    path = _hand_file(tmp_path, follower_effort=0)
    args = ["plan", "cylinder", "--hand", str(path), "--num", "30", "--top", "2"]
    for k in range(3):
        args += ["--preshape", f"f{k}_prox_joint=-0.5"]
    assert main(args) == 0, capsys.readouterr().err
    assert "grasp candidates of" in capsys.readouterr().out


def _explicit_beta(candidate, J, C, actuated, u) -> float:
    """max β with the actuators' torques written out (scipy HiGHS).

    G S λ + β [u; 0] = 0, λ >= 0; the joints' statics Jᵀ S λ = τ + λ_c with
    the coupler's force λ_c doing no work along v = C w, i.e.
    Cᵀ (Jᵀ S λ − τ) = 0; |τ_k| <= 1 at an actuated joint, τ_k = 0 elsewhere.
    """
    grasp = candidate.grasp
    G = dg.grasp_matrix(grasp)
    S = generator_matrix(grasp)
    n, m = S.shape[1], J.shape[1]
    # variables: λ (n), τ (m), β
    A_eq = np.vstack([
        np.hstack([G @ S, np.zeros((6, m)), np.concatenate([u, np.zeros(3)])[:, None]]),
        np.hstack([C.T @ J.T @ S, -C.T, np.zeros((C.shape[1], 1))]),
    ])  # fmt: skip
    bounds = (
        [(0, None)] * n
        + [(-1.0, 1.0) if a else (0.0, 0.0) for a in actuated]
        + [(0, None)]
    )
    cost = np.zeros(n + m + 1)
    cost[-1] = -1.0
    res = linprog(cost, A_eq=A_eq, b_eq=np.zeros(len(A_eq)), bounds=bounds,
                  method="highs")  # fmt: skip
    assert res.status == 0
    return float(res.x[-1])


def _coupling_matrix(names):
    """C (6, 3): each distal joint moves RATIO times its proximal one."""
    C = np.zeros((len(names), 3))
    for k in range(3):
        C[names.index(f"{MODEL}::f{k}_prox_joint"), k] = 1.0
        C[names.index(f"{MODEL}::f{k}_dist_joint"), k] = RATIO
    return C


@pytest.mark.parametrize("follower_effort", [0.0, 2.0])
def test_the_torque_capacity_is_that_of_the_motors_the_hand_has(
    tmp_path, follower_effort
):
    scene, result = _plan(_hand_file(tmp_path, follower_effort=follower_effort))
    closed = [c for c in result if c.is_closure][:3]
    assert closed
    differs = False
    for candidate in closed:
        names = list(candidate.joint_names)
        J = finger_jacobian(scene.plant, scene.context, candidate, scene.object_body)
        actuated = ["prox" in name or follower_effort > 0 for name in names]
        C = _coupling_matrix(names)
        beta = torque_capacity(scene.plant, scene.context, candidate, scene.object_body)
        expected = [
            _explicit_beta(candidate, J, C, actuated, u) for u in WEIGHT_DIRECTIONS
        ]
        np.testing.assert_allclose(beta, expected, rtol=1e-6, atol=1e-9)
        # the joints taken as six free motors: what the capacity was
        free = [
            _explicit_beta(candidate, J, np.eye(6), [True] * 6, u)
            for u in WEIGHT_DIRECTIONS
        ]
        differs |= not np.allclose(beta, free, rtol=1e-4)
    assert differs  # the couplings change the answer on these grasps


def test_fewer_motors_hold_no_more(tmp_path):
    scene, result = _plan(_hand_file(tmp_path, follower_effort=0))
    (tmp_path / "every").mkdir()
    every = _plan(_hand_file(tmp_path / "every", follower_effort=2))[0]
    fewer = False
    for candidate in [c for c in result if c.is_closure][:3]:
        leaders = torque_capacity(
            scene.plant, scene.context, candidate, scene.object_body
        )
        both = torque_capacity(every.plant, every.context, candidate, every.object_body)
        assert np.all(leaders <= both * (1 + 1e-7) + 1e-9)
        fewer |= bool(np.any(leaders < both * (1 - 1e-6)))
    assert fewer  # (equal numbers would pass the bound with the motors ignored)


def test_a_hand_with_motors_on_its_leaders_only_is_shaken(motors_on_leaders):
    # Drake's coupler constraint moves the followers; shake_test refused the
    # hand ("closing joint ...f0_dist_joint has no actuator to squeeze with").
    scene, result = motors_on_leaders
    candidate = next(c for c in result if c.is_closure)
    shaken = shake_test(
        scene.add_models, candidate, squeeze=0.5, stiffness=20.0, damping=1.0,
        directions=[[0.0, 0.0, -1.0]], settle=0.1, phase=0.2, seat=0.2,
    )  # fmt: skip
    names = list(candidate.joint_names)
    q = np.asarray(shaken.seated_q_hand)
    for k in range(3):
        prox = q[names.index(f"{MODEL}::f{k}_prox_joint")]
        dist = q[names.index(f"{MODEL}::f{k}_dist_joint")]
        # exactly on the coupling: Drake's compliant coupler drifts micro-
        # radians, and analyze_grasp refused the seated grasp (CouplingError)
        assert dist == RATIO * prox
    ctx = scene.plant.GetMyContextFromRoot(scene.context.Clone())
    shaken.seated(candidate).apply(scene.plant, ctx, object_body=scene.object_body)
    report = dg.analyze_grasp(
        scene.plant, ctx, scene.object_body, hand=scene.hand, mu=MU,
        allow_penetration=True,
    )  # fmt: skip
    assert report.grasp.num_contacts >= 2


def test_a_follower_without_a_known_coupling_is_refused_with_its_remedy(
    motors_on_leaders,
):
    scene, result = motors_on_leaders
    candidate = next(c for c in result if c.is_closure)
    text = coupled_hand_sdf(ratio=RATIO, follower_effort=0)

    def bare(plant, parser):  # a <mimic> Drake reads and drakegrasp does not
        register_models(parser)
        (hand,) = parser.AddModelsFromString(text, "sdf")
        (obj,) = parser.AddModels(url=CYLINDER)
        body = plant.get_body(plant.GetBodyIndices(obj)[0])
        return hand, body

    with pytest.raises(dg.ModelError, match="no actuator to squeeze with.*mimic"):
        shake_test(bare, candidate, squeeze=0.5, stiffness=20.0, damping=1.0)


def test_a_revolute_hands_default_gains_keep_its_squeeze(motors_on_leaders):
    # A fixed 4000 N·m/rad, every joint's default once, aimed these 2 N·m
    # fingers 0.5 mrad past their place: the fingers took most of it up as
    # they closed on, and pressed with 0.7-0.9 N·m (on other candidates with
    # next to nothing, or Drake's solver stopped).  By default a revolute
    # finger is now aimed REVOLUTE_AIM = 0.1 rad past: 2 / 0.1 = 20 N·m/rad.
    scene, result = motors_on_leaders
    candidate = next(c for c in result if c.is_closure)
    quick = dict(squeeze=2.0, directions=[[0.0, 0.0, -1.0]], settle=0.1, phase=0.2)
    shaken = shake_test(scene.add_models, candidate, **quick)
    k = 2.0 / REVOLUTE_AIM
    assert shaken.gains == ((k, k * DAMPING_TIME),) * 3  # the three leaders
    assert np.mean(shaken.efforts) > 0.9 * 2.0 and shaken.held_from_seat
    stiff = shake_test(
        scene.add_models, candidate, stiffness=4000.0, damping=50.0, **quick
    )
    assert stiff.gains == ((4000.0, 50.0),) * 3
    assert np.mean(stiff.efforts) < 0.5 * 2.0


def test_followers_without_their_leaders_have_no_motor(motors_on_leaders):
    # A candidate cut down to the distal joints (review, round 27): their
    # leaders' motors are not among its joints.  The shake took an actuator
    # anywhere in the plant as the followers' driver and squeezed nothing,
    # silently; the torque capacity counted the followers as motors.
    import dataclasses

    scene, result = motors_on_leaders
    c = next(c for c in result if c.is_closure)
    keep = [k for k, name in enumerate(c.joint_names) if "dist" in name]
    sub = dataclasses.replace(
        c,
        joint_names=tuple(c.joint_names[k] for k in keep),
        q_hand=np.asarray(c.q_hand)[keep],
        closing_signs=tuple(c.closing_signs[k] for k in keep),
    )
    with pytest.raises(dg.ModelError, match="no actuator to squeeze with"):
        shake_test(scene.add_models, sub, squeeze=0.5)
    beta = torque_capacity(scene.plant, scene.context, sub, scene.object_body)
    assert np.all(beta == 0.0)  # passive joints hold no weight


def test_a_pre_shape_of_a_follower_is_refused_not_overwritten(tmp_path, capsys):
    # The follower's value was replaced from its leader's without a word
    # (a user's Barrett-like hand: --preshape f1_distal_joint=0.3 planned as
    # if not given; round 27).
    path = _hand_file(tmp_path, follower_effort=0)
    args = ["plan", "cylinder", "--hand", str(path), "--num", "5"]
    assert main([*args, "--preshape", "f0_dist_joint=-0.3"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "follows coupled_hand::f0_prox_joint" in err[0], err
    scene = planning_scene(CYLINDER, hand_url=str(path))
    bad = list(OPEN)
    bad[1] = -0.2  # f0's distal joint, whose coupling makes it 0.6 * -0.5 = -0.3
    with pytest.raises(dg.InvalidOptionError, match=r"preshape\[1\].*breaks its"):
        plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=5, mu=MU, seed=0, preshape=bad,
        )  # fmt: skip


def test_a_jaw_on_one_motor_is_planned_as_a_jaw_and_squeezed_per_finger(tmp_path):
    # Its <mimic> made the two fingers one, and the planner refused the hand
    # ("min_fingers = 2 exceeds the hand's 1 fingers": a user's one-motor jaw
    # and Robotiq-style gripper, round 27).  The motor closes both fingers:
    # each gets half its 40 N.
    from coupled_support import one_motor_jaw_urdf

    from drakegrasp.planning.motors import motor_limit

    path = tmp_path / "one_motor_jaw.urdf"
    path.write_text(one_motor_jaw_urdf(effort=40.0))
    scene = planning_scene("package://drakegrasp/objects/box.sdf", hand_url=str(path))
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=0.5, seed=0, robustness_samples=4,
    )  # fmt: skip
    assert result.settings["gripper"]["joints"] == ["left_slide", "right_slide"]
    best = result[0]
    assert best.is_closure and np.isfinite(best.opening)
    assert motor_limit(scene.plant, best) == 40.0
    assert motor_limit(scene.plant, best, per_finger=True) == 20.0
    assert result.settings["held_first"]["limit"] == 20.0
    shaken = shake_test(
        scene.add_models, best, squeeze=10.0, hydroelastic_modulus=1e6,
        directions=[[0.0, 0.0, -1.0]], settle=0.1, phase=0.2,
    )  # fmt: skip
    assert shaken.squeeze_caps == (10.0,)  # each finger, through the one motor
    assert shaken.efforts[0] == pytest.approx(20.0, rel=0.05)  # the motor: both
    assert shaken.held_from_seat


def test_a_follower_with_its_own_motor_is_not_pressed_through_its_leader(tmp_path):
    # Review, round 27: the shake counted every follower of an actuated leader
    # in the leader's share, its own motor or not, and aimed the leader at
    # 0.5 x 1.6 N·m where each joint presses with 0.5 by its own motor.
    scene, result = _plan(_hand_file(tmp_path, follower_effort=2.0))
    candidate = next(c for c in result if c.is_closure)
    shaken = shake_test(
        scene.add_models, candidate, squeeze=0.5,
        directions=[[0.0, 0.0, -1.0]], settle=0.1, phase=0.2,
    )  # fmt: skip
    k = 0.5 / REVOLUTE_AIM  # every joint its own motor: aimed at its own 0.5
    assert shaken.gains == ((k, k * DAMPING_TIME),) * 6
    assert shaken.squeeze_caps == (0.5,) * 6


# A Robotiq-style pinch: two revolute knuckles and their pads on one motor.

BOX = "package://drakegrasp/objects/box.sdf"  # 50 x 50 x 100 mm, at the origin


@pytest.fixture(scope="module")
def pinch_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("pinch") / "one_motor_pinch.urdf"
    path.write_text(one_motor_pinch_urdf())
    return str(path)


@pytest.fixture(scope="module")
def pinch(pinch_file):
    scene = planning_scene(BOX, hand_url=pinch_file)
    hand = multi_finger_hand(
        scene.plant, scene.plant.GetMyContextFromRoot(scene.context),
        scene.object_body, scene.hand,
    )  # fmt: skip
    return scene, hand


def _close_at(pinch, offsets):
    """Close the pinch from above the box, its palm moved by ``offsets`` (m) along x."""
    scene, hand = pinch
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    n = len(offsets)
    down = RotationMatrix.MakeXRotation(np.pi).matrix()  # the palm's +z down
    poses = {
        "R_WH": np.repeat(down[None], n, axis=0),
        "p_WH": np.array([[x, 0.0, 0.18] for x in offsets]),
        "q": np.zeros((n, len(hand.structure.names))),
    }
    saved = plant.GetPositions(ctx).copy()
    try:
        return close_candidates(
            plant, ctx, scene.object_body, scene.hand, hand, poses, 1e-4, False
        )
    finally:
        plant.SetPositions(ctx, saved)


def test_a_one_motor_pinch_is_centred_on_the_object(pinch):
    # The two knuckles close as one: where the hand is off the box's centre,
    # the near pad touches first and stops both.  The planner moves the hand
    # towards the far pad and closes again, as the box slides on a table when
    # such a gripper closes on it.  The pose it closes at does not depend on
    # where along the jaw it started.
    offsets = [-0.012, -0.004, 0.0, 0.007, 0.012]
    kept, rejections, _ = _close_at(pinch, offsets)
    assert not rejections and [k[0] for k in kept] == list(range(len(offsets)))
    for sample, X_WH, _, _, contacts in kept:
        np.testing.assert_allclose(X_WH.translation(), [0, 0, 0.18], atol=2e-4)
        pads = {c.finger_body.split("::")[-1] for c in contacts}
        assert pads == {"left_pad", "right_pad"}, (offsets[sample], pads)
        x = sorted(c.p_OC[0] for c in contacts)  # the box is at the origin
        np.testing.assert_allclose([x[0], x[-1]], [-0.025, 0.025], atol=2e-4)


def test_without_centring_a_one_motor_pinch_off_centre_touches_with_one_pad(
    pinch, monkeypatch
):
    monkeypatch.setattr(centring, "CENTRING_STEPS", 0)
    kept, rejections, _ = _close_at(pinch, [-0.012, 0.0, 0.012])
    assert [k[0] for k in kept] == [1]
    assert rejections == {"one finger touches": 2}


def test_a_one_motor_pinch_is_planned_on_both_pads(pinch):
    # Before the centring every sample that reached the box was rejected:
    # "one finger touches".
    scene, _ = pinch
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, mu=0.5, seed=0, robustness_samples=8,
    )  # fmt: skip
    assert len(result) >= 5
    assert result.rejections.get("one finger touches", 0) <= len(result) // 4
    for candidate in result:
        pads = {c.finger_body.split("::")[-1] for c in candidate.contacts}
        assert pads == {"left_pad", "right_pad"}


@pytest.fixture(scope="module")
def barred(tmp_path_factory):
    """The pinch with its four-bars' inner knuckles, as a Robotiq URDF has them."""
    path = tmp_path_factory.mktemp("barred") / "barred_pinch.urdf"
    path.write_text(one_motor_pinch_urdf(bars=True))
    scene = planning_scene(BOX, hand_url=str(path))
    hand = multi_finger_hand(
        scene.plant, scene.plant.GetMyContextFromRoot(scene.context),
        scene.object_body, scene.hand,
    )  # fmt: skip
    return scene, hand


def test_a_pinch_with_four_bar_links_is_centred_on_its_pads(barred):
    # The inner knuckles close with the pads but sit behind them: centred with
    # them, their gaps kept every move from evening the pads' (no move, "one
    # finger touches" at every offset).  Only the nearest chain on each side
    # is centred now.
    scene, hand = barred
    assert len(hand.chains) == 4 and len(hand.structure.fingers) == 1
    offsets = [-0.012, -0.004, 0.0, 0.007, 0.012]
    kept, rejections, _ = _close_at(barred, offsets)
    assert not rejections and [k[0] for k in kept] == list(range(len(offsets)))
    for _, X_WH, _, _, contacts in kept:
        np.testing.assert_allclose(X_WH.translation(), [0, 0, 0.18], atol=2e-4)
        pads = {c.finger_body.split("::")[-1] for c in contacts}
        assert pads == {"left_pad", "right_pad"}


def _sides(scene, hand, X_WH=None):
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context.Clone())
    if X_WH is not None:
        plant.SetFreeBodyPose(ctx, hand.base, X_WH)
    names = [c.name.split("::")[-1] for c in hand.chains]
    return dict(zip(names, chain_sides(ctx, hand.structure, hand.chains), strict=True))


def test_a_bar_shares_its_pads_side_and_opposed_fingers_do_not(barred, pinch, tmp_path):
    # A side: the chains of one closing group whose root joints turn alike
    # (the same world axis times the same mimic multiplier).
    sides = _sides(*barred)
    assert sides["left_bar_joint"] == sides["left_knuckle"]
    assert sides["right_bar_joint"] == sides["right_knuckle"]
    assert sides["left_knuckle"] != sides["right_knuckle"]
    # wherever the hand is: axes are compared in one frame
    X = RigidTransform(RollPitchYaw(0.4, -1.1, 2.0), [0.3, -1.0, 2.0])
    assert _sides(*barred, X) == sides
    assert sorted(_sides(*pinch).values()) == [0, 1]
    # an exported URDF's hinge a few 1e-8 rad off its twin's: still a bar
    text = one_motor_pinch_urdf(bars=True).replace(
        '<origin xyz="0.05 0 0.06"/>', '<origin xyz="0.05 0 0.06" rpy="4e-8 0 0"/>'
    )
    rounded = tmp_path / "rounded.urdf"
    rounded.write_text(text)
    scene = planning_scene(BOX, hand_url=str(rounded))
    assert _sides(scene, multi_finger_hand(
        scene.plant, scene.plant.GetMyContextFromRoot(scene.context),
        scene.object_body, scene.hand,
    )) == sides  # fmt: skip
    # the spread hand: f1, f2 on one spread motor turning opposite ways; f3
    path = tmp_path / "spread_hand.urdf"
    path.write_text(spread_hand_urdf())
    scene = planning_scene(CYLINDER, hand_url=str(path))
    hand = multi_finger_hand(
        scene.plant, scene.plant.GetMyContextFromRoot(scene.context),
        scene.object_body, scene.hand,
    )  # fmt: skip
    spread = _sides(scene, hand)
    assert len(set(spread.values())) == len(spread) == len(hand.chains)


def test_a_pinch_with_four_bar_links_is_planned(barred, pinch):
    # Before, every sample that reached the box was rejected, "one finger
    # touches"; now the pinch with its bars is planned as the pinch without.
    def plan(scene):
        return plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=60, mu=0.5, seed=0, robustness_samples=8,
        )  # fmt: skip

    with_bars, without = plan(barred[0]), plan(pinch[0])
    assert len(with_bars) >= max(5, len(without) // 2), (len(with_bars), len(without))
    assert with_bars.rejections.get("one finger touches", 0) <= len(with_bars) // 4
    for candidate in with_bars:  # a pad or its bar on each side (a power grasp)
        sides = {
            c.finger_body.split("::")[-1].split("_")[0] for c in candidate.contacts
        }
        assert sides == {"left", "right"}
    pads = {"left_pad", "right_pad"}
    assert sum({c.finger_body.split("::")[-1] for c in k.contacts} == pads
               for k in with_bars) >= len(with_bars) // 2  # fmt: skip


def _on_cloud(scene, hand_file):
    surface = object_surface(scene.plant, scene.context, scene.object_body)
    points, normals, _ = surface.sample(3000, np.random.default_rng(0))
    hand_only = planning_scene(None, hand_url=hand_file)
    return plan_grasps(
        hand_only.plant, hand_only.context, None, hand=hand_only.hand,
        num_candidates=100, mu=0.5, seed=0, robustness_samples=8,
        point_cloud=points, cloud_normals=normals, object_mass=0.2,
    )  # fmt: skip


def test_a_one_motor_pinch_is_planned_on_a_point_cloud(pinch, pinch_file):
    # On a cloud the pinch's one closing group had to count as two fingers
    # (min_fingers = 2 rejected every pose: "fingers miss the object"), and
    # its chains are centred as on a body.
    result = _on_cloud(pinch[0], pinch_file)
    assert len(result) >= 5
    for candidate in result:
        bodies = {c.finger_body.split("::")[-1] for c in candidate.contacts}
        # both pads; a knuckle too where it touches (sample 15's left one,
        # 0.02 mm from the true box: missed while the cloud hand's screen
        # left out the surfels' radius)
        assert {"left_pad", "right_pad"} <= bodies <= {
            "left_pad", "right_pad", "left_knuckle", "right_knuckle"
        }  # fmt: skip


def test_a_pinch_with_four_bar_links_is_planned_on_a_point_cloud(barred, tmp_path):
    # 1 candidate of 100 samples before (18 "one finger touches"), 10 now
    path = tmp_path / "barred.urdf"
    path.write_text(one_motor_pinch_urdf(bars=True))
    result = _on_cloud(barred[0], str(path))
    assert len(result) >= 5
    assert result.rejections.get("one finger touches", 0) <= len(result)


def test_a_hand_with_a_coupled_spread_closes_all_its_fingers(hand_file_scene):
    # f1 and f2 share a spread motor; each has its own flexion motor.  Before,
    # the group stopped when one of them touched: no candidate touched with
    # all three fingers, and none was force closure on the cylinder.
    scene = hand_file_scene(CYLINDER, spread_hand_urdf(), "spread_hand.urdf")
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, mu=0.5, seed=0, robustness_samples=8,
    )  # fmt: skip
    three = [
        c
        for c in result
        if {x.finger_body.split("::")[-1][:2] for x in c.contacts} == {"f1", "f2", "f3"}
    ]
    assert three and any(c.is_closure for c in three)


def test_a_hand_with_a_coupled_spread_closes_all_its_fingers_on_a_cloud(tmp_path):
    # as on a body: a structure without an object has no geometry pairs, and
    # the free part is read from the bodies its joints move
    path = tmp_path / "spread_hand.urdf"
    path.write_text(spread_hand_urdf())
    full = planning_scene(CYLINDER, hand_url=str(path))
    surface = object_surface(full.plant, full.context, full.object_body)
    points, normals, _ = surface.sample(3000, np.random.default_rng(0))
    hand_only = planning_scene(None, hand_url=str(path))
    result = plan_grasps(
        hand_only.plant, hand_only.context, None, hand=hand_only.hand,
        num_candidates=60, mu=0.5, seed=0, robustness_samples=8,
        point_cloud=points, cloud_normals=normals, object_mass=0.25,
    )  # fmt: skip
    three = [
        c
        for c in result
        if {x.finger_body.split("::")[-1][:2] for x in c.contacts} == {"f1", "f2", "f3"}
    ]
    assert len(three) >= len(result) // 2 and any(c.is_closure for c in three)


def _narrowed_pinch(tmp_path, right_upper: str, pad_lower: str):
    """The pinch with the right knuckle's and the left pad's ranges narrowed."""
    text = one_motor_pinch_urdf()
    axis = '<axis xyz="0 1 0"/><limit lower="-0.8"'
    knuckle = f'origin xyz="0.055 0 0.06"/>{axis} upper="0"'
    pad = f'child link="left_pad"/><origin xyz="0 0 0.05"/>{axis}'
    assert text.count(knuckle) == 1 and text.count(pad) == 1
    text = text.replace(knuckle, knuckle.replace('upper="0"', f'upper="{right_upper}"'))
    text = text.replace(pad, pad.replace('lower="-0.8"', f'lower="{pad_lower}"'))
    path = tmp_path / "narrowed_pinch.urdf"
    path.write_text(text)
    return planning_scene(BOX, hand_url=str(path))


def test_a_pre_shape_is_clipped_to_the_limits_before_its_couplings_are_applied(
    tmp_path,
):
    # The leader's range is cut to [0.1, 0.3] by its followers'.  The open
    # hand (every joint 0) was coupled, then clipped joint by joint: the
    # leader went to 0.1 while its followers stayed at 0, a pre-shape that
    # breaks its couplings; the search then coupled it again and could start
    # inside the box (found by the fuzz suite: a raw ValueError).
    scene = _narrowed_pinch(tmp_path, "-0.1", "-0.3")
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=30, mu=0.5, seed=0, robustness_samples=2,
    )  # fmt: skip
    for c in result:
        q = dict(zip(c.joint_names, c.q_preshape, strict=True))
        lead = q["one_motor_pinch::left_knuckle"]
        assert 0.1 - 1e-12 <= lead <= 0.3 + 1e-12
        assert q["one_motor_pinch::right_knuckle"] == pytest.approx(-lead)
        assert q["one_motor_pinch::left_pad_joint"] == pytest.approx(-lead)


def test_couplings_that_leave_a_hand_no_configuration_are_refused(tmp_path):
    scene = _narrowed_pinch(tmp_path, "-0.5", "-0.3")  # leader [0.5, 0.3]
    with pytest.raises(dg.ModelError, match="no position of .*left_knuckle"):
        plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=5, mu=0.5, seed=0,
        )  # fmt: skip


def test_a_chain_of_couplings_is_planned_and_holds_in_drake(tmp_path):
    # Each finger's tip follows its distal joint, which follows the proximal
    # one (tip -> distal -> proximal, motors on the proximal joints only): the
    # planner refused the hand ("takes one level of couplings").  Planned on
    # the chain resolved to its root, the best force-closure candidates hold
    # in Drake, whose coupler constraints keep the chain link by link.
    # Measured: 26 candidates of 40 poses, 4 of the 5 best held.
    path = tmp_path / "chained_hand.sdf"
    path.write_text(coupled_hand_sdf(ratio=RATIO, tip_ratio=0.8, follower_effort=0))
    scene = planning_scene(CYLINDER, hand_url=str(path))
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=MU, seed=0, robustness_samples=8,
        preshape=[-0.5, -0.3, -0.24] * 3,
    )  # fmt: skip
    best = [c for c in result if c.is_closure][:5]
    assert len(best) == 5, result
    held = 0
    for candidate in best:
        q = dict(zip(candidate.joint_names, candidate.q_hand, strict=True))
        for k in range(3):
            prox, dist, tip = (q[f"{MODEL}::f{k}_{p}_joint"] for p in PARTS)
            assert dist == pytest.approx(RATIO * prox, abs=1e-12)
            assert tip == pytest.approx(0.8 * dist, abs=1e-12)
        shaken = shake_test(
            scene.add_models, candidate, squeeze=0.5, stiffness=20.0, damping=1.0
        )
        seated = dict(zip(candidate.joint_names, shaken.seated_q_hand, strict=True))
        for k in range(3):
            prox, dist, tip = (seated[f"{MODEL}::f{k}_{p}_joint"] for p in PARTS)
            assert tip == pytest.approx(0.8 * dist, abs=1e-12)
        held += shaken.held
    assert held >= 3, held
