"""A parallel jaw whose motor sits on a hidden drive that both fingers follow.

Some grippers are modelled with the motor on a third slide (or a linkage's
hidden link) that carries no geometry, both fingers following it through a
``<mimic>``.  Such a jaw is the one-motor jaw whose leader finger stands where
the drive is (``coupled_jaw_urdf(hidden_drive=True)`` against its twin without
the drive), so everything the planner says of one it must say of the other:
the fingers, the coupling, the candidates, the squeeze the motor gives each
finger (its effort limit over ``Σ|ρ|`` = 2), the pose a candidate puts in a
context, and what Drake's simulation of a shake finds.

A multi-finger hand on a hidden drive (``one_motor_pinch_urdf(hidden_drive=
True)``: the knuckles and pads of a pinch follow a bare hinge) keeps the drive
among its closing joints; its motor presses only through the fingers, so it
too squeezes as its twin's does (the effort limit over ``Σ|ρ|`` = 4).
"""

from __future__ import annotations

import numpy as np
import pytest
from coupled_hands import coupled_jaw_urdf, one_motor_pinch_urdf, plan_on_box
from hypothesis import given, settings
from hypothesis import strategies as st

import drakegrasp as dg
from drakegrasp.planning import plan_grasps, planning_scene, shake_test
from drakegrasp.planning.approach import multi_finger_hand
from drakegrasp.planning.gripper import parallel_jaw
from drakegrasp.planning.motors import motor_limit
from drakegrasp.plant.couplings import coupled_positions, motor_shares

BOX = "package://drakegrasp/objects/box.sdf"
CYLINDER = "package://drakegrasp/objects/cylinder.sdf"
QUICK = dict(settle=0.2, phase=0.3)


def _scene(tmp_path, name, **jaw):
    path = tmp_path / f"{name}.urdf"
    path.write_text(coupled_jaw_urdf(**jaw))
    return planning_scene(BOX, hand_url=str(path))


@pytest.fixture(scope="module")
def twins(tmp_path_factory):
    """The hidden-drive jaw and its twin, each planned on the box (same seed)."""
    tmp = tmp_path_factory.mktemp("hidden_drive")
    out = {}
    for name, hidden in (("twin", False), ("hidden", True)):
        scene = _scene(tmp, name, ratio=-1.0, offset=-0.002, hidden_drive=hidden)
        ctx = scene.plant.GetMyContextFromRoot(scene.context)
        result = plan_grasps(
            scene.plant, ctx, scene.object_body, hand=scene.hand,
            num_candidates=200, mu=0.5, seed=4, object_mass=0.3,
        )  # fmt: skip
        out[name] = (scene, ctx, result)
    return out


def test_the_drive_is_no_finger(twins):
    jaws = {}
    for name, (scene, ctx, _) in twins.items():
        jaws[name] = parallel_jaw(scene.plant, ctx, scene.object_body, scene.hand)
    hidden, twin = jaws["hidden"], jaws["twin"]
    assert [j.name() for j in hidden.joints] == [j.name() for j in twin.joints]
    np.testing.assert_allclose(hidden.coupling, twin.coupling, atol=1e-15)
    assert hidden.min_opening == twin.min_opening
    assert hidden.max_opening == twin.max_opening


def test_the_plans_are_the_same(twins):
    hidden, twin = twins["hidden"][2], twins["twin"][2]
    assert len(hidden.candidates) == len(twin.candidates) > 10
    for a, b in zip(hidden.candidates, twin.candidates, strict=True):
        assert a.sample == b.sample
        np.testing.assert_array_equal(a.q_hand, b.q_hand)
        assert a.score == b.score
        assert a.squeeze_needed == b.squeeze_needed
        assert a.held_joints == b.held_joints  # the drive is tied, not held


def test_the_drives_motor_squeezes_each_finger_with_half_its_limit(twins):
    hidden, twin = twins["hidden"][2], twins["twin"][2]
    assert not hidden.reason, hidden.reason  # was: "the model gives ... no actuator"
    assert hidden.settings["held_first"] == twin.settings["held_first"]
    assert hidden.settings["held_first"]["limit"] == pytest.approx(40.0 / 2)
    # the motor's own limit: the drive's (it said inf, reading the fingers')
    (scene, _, result), (twin_scene, _, twin_result) = twins["hidden"], twins["twin"]
    limit = motor_limit(scene.plant, result.candidates[0])
    assert limit == motor_limit(twin_scene.plant, twin_result.candidates[0]) == 40.0


def test_a_candidate_puts_the_drive_where_the_couplings_do(twins):
    scene, ctx, result = twins["hidden"]
    plant = scene.plant
    best = result.candidates[0]
    best.apply(plant, ctx, object_body=scene.object_body)
    lead = plant.GetJointByName("left_slide").get_translation(ctx)
    follow = plant.GetJointByName("right_slide").get_translation(ctx)
    drive = plant.GetJointByName("drive").get_translation(ctx)
    assert drive == lead  # the leader finger follows the drive with ratio 1
    assert follow == pytest.approx(-1.0 * drive - 0.002, abs=1e-15)
    # the pose holds the coupler constraints: the analysis takes it as it is
    report = dg.analyze_grasp(plant, ctx, scene.object_body, hand=scene.hand, mu=0.5)
    twin_scene, twin_ctx, twin_result = twins["twin"]
    twin_result.candidates[0].apply(
        twin_scene.plant, twin_ctx, object_body=twin_scene.object_body
    )
    twin_report = dg.analyze_grasp(
        twin_scene.plant, twin_ctx, twin_scene.object_body, hand=twin_scene.hand,
        mu=0.5,
    )  # fmt: skip
    assert report.force_closure.is_closure == twin_report.force_closure.is_closure
    assert report.force_closure.d_star == pytest.approx(
        twin_report.force_closure.d_star, rel=1e-9
    )


@pytest.mark.filterwarnings(
    "ignore::drakegrasp.plant.friction.FrictionMismatchWarning"  # plan 0.5, Drake 1
)
def test_a_shake_squeezes_through_the_drive(twins):
    """Drake's simulation: the drive's motor holds what the twin's motor holds.

    At the motor's limit (20 N per finger) the first candidate the twin holds
    is held by the hidden drive too, moved as far within 25 %; at 1 N per
    finger both drop it (the drive does squeeze: without it nothing would
    tell the two apart).
    """
    (hidden_scene, _, hidden), (twin_scene, _, twin) = twins["hidden"], twins["twin"]
    for k in range(4):
        held = shake_test(
            twin_scene.add_models, twin.candidates[k], squeeze=20.0, **QUICK
        )
        if held.held:
            break
    else:
        pytest.fail("the twin holds none of its first 4 candidates")
    same = shake_test(
        hidden_scene.add_models, hidden.candidates[k], squeeze=20.0, **QUICK
    )
    assert same.held
    assert same.efforts == pytest.approx(held.efforts, rel=1e-3)  # 40 N: 2 x 20
    assert same.max_displacement == pytest.approx(held.max_displacement, rel=0.25)
    for scene, result in ((twin_scene, twin), (hidden_scene, hidden)):
        weak = shake_test(scene.add_models, result.candidates[k], squeeze=1.0, **QUICK)
        assert not weak.held


def test_a_drive_that_opens_one_finger_as_it_closes_the_other_is_refused(tmp_path):
    # both fingers follow the drive with ratio +1: the pads move the same way,
    # and the right finger's [-45, 0] mm meets the drive's [0, 45] mm at 0:
    # the drive reaches only 0, and neither finger has a stroke
    scene = _scene(tmp_path, "same_way", ratio=1.0, hidden_drive=True)
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    with pytest.raises(dg.ModelError, match="left_slide has no stroke"):
        parallel_jaw(scene.plant, ctx, scene.object_body, scene.hand)


def test_the_drives_limits_bound_the_fingers(tmp_path):
    # A drive whose stroke is cut to [0, 10] mm: the leader finger (ratio 1)
    # reaches [0, 10] mm of its own [0, 45], the follower (ratio -2) [-20, 0]
    # of its [-45, 0].  The planner read the fingers' limits alone, so a pose
    # beyond broke the drive's, and analyze_grasp refused it (the fuzz suite).
    text = coupled_jaw_urdf(ratio=-2.0, hidden_drive=True).replace(
        '<joint name="drive" type="prismatic"><parent link="palm"/><child '
        'link="drive_link"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit '
        'lower="0.0" upper="0.045"',
        '<joint name="drive" type="prismatic"><parent link="palm"/><child '
        'link="drive_link"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit '
        'lower="0.0" upper="0.01"',
    )
    assert 'upper="0.01"' in text
    path = tmp_path / "short.urdf"
    path.write_text(text)
    scene = planning_scene(BOX, hand_url=str(path))
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    jaw = parallel_jaw(scene.plant, ctx, scene.object_body, scene.hand)
    limits = {
        j.name(): (lo, hi)
        for j, lo, hi in zip(jaw.joints, jaw.lower, jaw.upper, strict=True)
    }
    assert limits == {"left_slide": (0.0, 0.01), "right_slide": (-0.02, 0.0)}


def test_motor_shares_of_a_hidden_leader():
    couplings = [("a", "d", 1.0, 0.0), ("b", "d", -0.5, 0.01), ("c", "a", 2.0, 0.0)]
    driven, shares = motor_shares(couplings, ["a", "b"], ["d"])
    assert driven == {"a": "d", "b": "d"}
    assert shares == {"d": 1.5}  # Σ|ρ|: the drive presses nothing itself
    driven, shares = motor_shares(couplings, ["a", "c"], ["a"])
    assert driven == {"c": "a"}
    assert shares == {"a": 3.0}  # 1 + |ρ|: the leader presses too
    # a drive among the joints (a multi-finger hand's) still presses nothing
    driven, shares = motor_shares(couplings, ["d", "a", "b"], ["d"], drives=["d"])
    assert driven == {"a": "d", "b": "d"}
    assert shares == {"d": 1.5}
    assert motor_shares(couplings, ["d", "a", "b"], ["d"])[1] == {"d": 2.5}


@settings(max_examples=60, deadline=None)
@given(
    q=st.floats(-1.0, 1.0),
    rho=st.lists(
        st.floats(0.1, 3.0).flatmap(lambda r: st.sampled_from([r, -r])),
        min_size=3,
        max_size=3,
    ),
    offsets=st.lists(st.floats(-0.1, 0.1), min_size=3, max_size=3),
)
def test_coupled_positions_hold_every_coupling(q, rho, offsets):
    # a chain d <- a <- c and a second follower b of d; only a is known
    couplings = [
        ("a", "d", rho[0], offsets[0]),
        ("b", "d", rho[1], offsets[1]),
        ("c", "a", rho[2], offsets[2]),
    ]
    found = coupled_positions(couplings, {"a": q})
    assert set(found) == {"b", "c", "d"}
    values = {"a": q, **found}
    for follower, leader, r, off in couplings:
        assert values[follower] == pytest.approx(r * values[leader] + off, abs=1e-12)


def test_a_drive_with_a_link_welded_to_it_is_still_a_drive(tmp_path):
    # a marker (or a linkage's second link) welded below the drive, no
    # collision geometry either: the chain was left out of the fingers, but
    # the drive's motor was not found (no squeeze limit, a shake refused)
    from drakegrasp.planning.motors import motor_limit

    text = coupled_jaw_urdf(ratio=-1.0, hidden_drive=True).replace(
        "</robot>",
        '<link name="drive_marker"><inertial><mass value="0.001"/><inertia '
        'ixx="1e-8" iyy="1e-8" izz="1e-8" ixy="0" ixz="0" iyz="0"/></inertial>'
        '</link><joint name="marker_weld" type="fixed"><parent link="drive_link"/>'
        '<child link="drive_marker"/></joint></robot>',
    )
    path = tmp_path / "marked.urdf"
    path.write_text(text)
    scene = planning_scene(BOX, hand_url=str(path))
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    result = plan_grasps(
        scene.plant, ctx, scene.object_body, hand=scene.hand,
        num_candidates=60, mu=0.5, seed=4, object_mass=0.3,
    )  # fmt: skip
    assert result.candidates and not result.reason, result.reason
    assert motor_limit(scene.plant, result.candidates[0], per_finger=True) == 20.0


@pytest.fixture(scope="module")
def pinch_twins(tmp_path_factory):
    """The pinch on a hidden drive and its twin, each planned on the box."""
    tmp = tmp_path_factory.mktemp("hidden_pinch")
    out = {}
    for name, hidden in (("twin", False), ("hidden", True)):
        out[name] = plan_on_box(
            tmp / f"{name}.urdf", one_motor_pinch_urdf(hidden_drive=hidden)
        )
    return out


def test_a_pinch_on_a_hidden_drive_plans_as_its_twin(pinch_twins):
    (scene, hidden), (twin_scene, twin) = pinch_twins["hidden"], pinch_twins["twin"]
    assert len(hidden) == len(twin) > 10
    drive = "one_motor_pinch::drive"
    for a, b in zip(hidden, twin, strict=True):
        assert a.joint_names == (drive, *b.joint_names)
        assert a.sample == b.sample and a.score == b.score
        np.testing.assert_array_equal(a.q_hand[1:], b.q_hand)
        assert a.q_hand[0] == a.q_hand[1]  # the left knuckle follows at 1
        assert a.torque_needed == pytest.approx(b.torque_needed, rel=1e-6)
        assert a.torque_capacity == pytest.approx(b.torque_capacity, rel=1e-6)
        # one motor closes all five joints: the drive's, the twin's knuckle's
        assert a.motors == (drive,)
        assert b.motors == ("one_motor_pinch::left_knuckle",)
        if not np.isnan(a.torque_needed):
            words = (
                f"5 closing joints, 1 motor, torque {a.torque_needed:.3g} N·m per motor"
            )
            assert words in str(a), str(a)
            assert f"4 closing joints, 1 motor, torque {b.torque_needed:.3g}" in str(b)
    assert any(not np.isnan(a.torque_needed) for a in hidden)
    assert hidden.settings["held_first"] == twin.settings["held_first"]
    for per_finger in (False, True):  # 5 N·m; 5 / 4 through the four followers
        limit = motor_limit(scene.plant, hidden[0], per_finger=per_finger)
        assert limit == motor_limit(twin_scene.plant, twin[0], per_finger=per_finger)
    assert limit == pytest.approx(5.0 / 4)


def test_a_pinch_without_actuators_counts_its_drive_as_no_motor(tmp_path):
    # With effort 0 Drake gives no joint an actuator, and each joint counts as
    # a motor: the drive, touching nothing, counted too (its column bound
    # 1 + Σ|ρ| = 5 where the twin's knuckle has 1 + 3 = 4), so the hidden
    # drive's torque_needed came out 4/5 of the twin's.
    needed = {}
    for name, hidden in (("twin", False), ("hidden", True)):
        path = tmp_path / f"{name}.urdf"
        path.write_text(one_motor_pinch_urdf(effort=0.0, hidden_drive=hidden))
        scene = planning_scene(BOX, hand_url=str(path))
        assert scene.plant.num_actuators() == 0
        result = plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=30, mu=0.5, seed=0, robustness_samples=4,
            object_mass=0.2,
        )  # fmt: skip
        needed[name] = [(c.sample, c.torque_needed) for c in result]
        # no actuator: no motor known, and the line counts none
        assert {c.motors for c in result} == {()}
        assert "motor," not in str(result[0]).split("torque")[0]
    assert len(needed["twin"]) > 5
    for (s_h, t_h), (s_t, t_t) in zip(needed["hidden"], needed["twin"], strict=True):
        assert s_h == s_t and t_h == pytest.approx(t_t, rel=1e-6)


@pytest.mark.filterwarnings(
    "ignore::drakegrasp.plant.friction.FrictionMismatchWarning"  # plan 0.5, Drake 1
)
def test_a_pinchs_hidden_drive_squeezes_through_its_followers(pinch_twins):
    """Drake's simulation: the drive's motor holds what the twin's holds.

    The drive touches nothing: its motor's squeeze is shared by the four
    joints it drives, as the twin's knuckle motor's is.  It counted itself as
    a fifth: its cap said 1 N·m per joint where the twin's says 1.25, and
    below the effort limit it pressed with 5 × the squeeze where the twin
    presses with 4 × (at 1 N·m: 4.96 N·m against 3.99).  The pads press over
    patches (hydroelastic): with Drake's point contact a flat pad on the box's
    face touches at one point, and whether the box pivots out turns on how
    square the pads stand (seated, Drake's compliant couplers leave the
    knuckles 1.3 mrad off the light drive, the twin's right knuckle 0.012
    mrad off its left: the twin held its first candidate there and the drive
    dropped it).  Both drop it at 0.01 N·m.
    """
    shaken = {
        (name, squeeze): shake_test(
            scene.add_models,
            result[0],
            object_mass=0.2,
            squeeze=squeeze,
            hydroelastic_modulus=1e6,
            **QUICK,
        )  # fmt: skip
        for name, (scene, result) in pinch_twins.items()
        for squeeze in (20.0, 1.0, 0.01)
    }
    hidden, twin = shaken["hidden", 20.0], shaken["twin", 20.0]
    assert hidden.squeeze_caps == twin.squeeze_caps == (pytest.approx(5.0 / 4),)
    assert hidden.efforts == pytest.approx(twin.efforts, rel=1e-2)  # at 5 N·m
    assert hidden.held and twin.held
    assert hidden.max_displacement == pytest.approx(twin.max_displacement, abs=2e-5)
    hidden, twin = shaken["hidden", 1.0], shaken["twin", 1.0]
    assert twin.efforts == (pytest.approx(4.0, rel=1e-2),)  # 1 N·m per joint
    assert hidden.efforts == pytest.approx(twin.efforts, rel=1e-2)
    assert hidden.held and twin.held
    assert not shaken["hidden", 0.01].held and not shaken["twin", 0.01].held


def test_a_drive_at_any_ratio_curls_the_hand_as_its_twin(tmp_path):
    # The curl that sizes the hand capped each step of the drive at 0.1 rad,
    # its own joint's cap: at ratio 0.5 its fingers moved 0.05 rad a step,
    # the curl stopped short, and the hand's reach came out 91.6 mm against
    # the twin's 89.8 (44 candidates on the cylinder against 46).
    plans = {}
    for ratio in (None, 0.5, 2.0):
        path = tmp_path / f"pinch_{ratio}.urdf"
        path.write_text(
            one_motor_pinch_urdf(hidden_drive=ratio is not None, drive_ratio=ratio or 1)
        )
        scene = planning_scene(CYLINDER, hand_url=str(path))
        ctx = scene.plant.GetMyContextFromRoot(scene.context)
        hand = multi_finger_hand(scene.plant, ctx, scene.object_body, scene.hand)
        result = plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=60, mu=0.5, seed=0, robustness_samples=8,
        )  # fmt: skip
        plans[ratio] = (hand.reach, [(c.sample, c.score) for c in result])
    twin_reach, twin = plans.pop(None)
    assert len(twin) > 30
    for reach, candidates in plans.values():
        assert reach == pytest.approx(twin_reach, rel=1e-9)
        assert [s for s, _ in candidates] == [s for s, _ in twin]
        np.testing.assert_allclose([v for _, v in candidates], [v for _, v in twin])
