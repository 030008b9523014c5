"""plan_grasps: every sample accounted for, candidates valid in the plant,
verdicts equal to analyze_grasp's, reproducible, invariant to moving the scene,
hostile inputs refused or answered with a reason."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.math import RigidTransform, RollPitchYaw

from drakegrasp import analyze_grasp, find_contacts
from drakegrasp.errors import InvalidGraspError, InvalidOptionError, ModelError
from drakegrasp.planning import REASONS, plan_grasps, planning_scene
from drakegrasp.planning.planner import MAX_CANDIDATES
from drakegrasp.plant.contacts import DEFAULT_DISTANCE_TOLERANCE
from drakegrasp.plant.validation import scoped_name


def plan(scene, n=120, seed=7, **kw):
    kw.setdefault("mu", 0.5)
    kw.setdefault("robustness_samples", 8)
    return plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=n, seed=seed, **kw,
    )  # fmt: skip


@pytest.fixture(scope="module")
def wsg_result(wsg_scene):
    scene = wsg_scene()
    return scene, plan(scene)


def test_every_sample_is_a_candidate_or_a_counted_rejection(wsg_result):
    _, result = wsg_result
    assert len(result) + sum(result.rejections.values()) == result.num_sampled == 120
    assert set(result.rejections) <= set(REASONS)
    assert len(result) > 20 and result.reason == ""


def test_ranked_best_first(wsg_result):
    scene, result = wsg_result
    scores = [c.score for c in result]
    assert scores == sorted(scores, reverse=True)
    weight = scene.object_body.default_mass() * 9.81
    checked = [c for c in result if np.isfinite(c.weight_capacity)]
    assert len(checked) == sum(c.is_closure for c in result)
    for c in result:
        assert (c.epsilon > 0) == c.is_closure
        if np.isfinite(c.weight_capacity):
            assert c.score == pytest.approx(c.robustness * c.weight_capacity)
            assert c.squeeze_needed == pytest.approx(weight / c.weight_capacity)
        else:
            assert c.score == 0
    assert result[0].closure is not None and result[0].closure.is_closure


def test_weight_check_limits_the_scored_candidates(wsg_scene):
    result = plan(wsg_scene(), n=60, weight_check=3)
    assert sum(np.isfinite(c.weight_capacity) for c in result) == 3
    assert all(c.score > 0 for c in result[:3]) and result[3].score == 0
    with pytest.raises(InvalidOptionError, match="weight_check"):
        plan(wsg_scene(), n=5, weight_check=-1)


def test_candidates_are_valid_and_agree_with_analyze_grasp(wsg_result):
    scene, result = wsg_result
    plant, obj = scene.plant, scene.object_body
    ctx = scene.context.Clone()
    pctx = plant.GetMyContextFromRoot(ctx)
    picks = list(result[:4]) + list(result[-3:])
    for c in picks:
        c.apply(plant, ctx, object_body=obj)
        q = plant.GetPositions(pctx)
        for name, v in zip(c.joint_names, c.q_hand, strict=True):
            j = plant.GetJointByName(name.rpartition("::")[2])
            assert j.position_lower_limits()[0] <= v <= j.position_upper_limits()[0]
            assert q[j.position_start()] == v
        query = plant.get_geometry_query_input_port().Eval(pctx)
        for pair in query.ComputeSignedDistancePairwiseClosestPoints(0.0):
            assert pair.distance >= -DEFAULT_DISTANCE_TOLERANCE
        report = analyze_grasp(plant, ctx, obj, hand=scene.hand, mu=0.5)
        assert report.pose.valid
        assert len(report.contacts) == c.num_contacts
        assert report.force_closure.is_closure == c.is_closure
        assert np.allclose(report.grasp.positions, c.grasp.positions)


def test_contacts_are_bitwise_those_of_find_contacts(wsg_result):
    # the planner reads contacts from its closing query's pairs, not pair by pair
    scene, result = wsg_result
    ctx = scene.context.Clone()
    for c in result:
        c.apply(scene.plant, ctx, object_body=scene.object_body)
        found = find_contacts(scene.plant, ctx, scene.object_body, hand=scene.hand)
        assert [k.finger_geometry_label for k in found] == [
            k.finger_geometry_label for k in c.contacts
        ]
        assert np.array_equal([k.p_OC for k in found], [k.p_OC for k in c.contacts])
        assert np.array_equal([k.nhat_O for k in found], [k.nhat_O for k in c.contacts])


def test_batched_contacts_equal_the_scalar_route(wsg_result, monkeypatch):
    # the planner's contacts (spherical tips resolved over arrays, all
    # candidates at once) against pair_points pair by pair, to 1e-12
    from drakegrasp.plant import contact_pair, contacts

    def scalar(pending):
        for p in pending:
            if p.points is None:
                p.points = contact_pair.pair_points(**p.args)

    scene, result = wsg_result
    ctx = scene.context.Clone()
    monkeypatch.setattr(contacts, "resolve_pairs", scalar)
    batched = 0
    for c in result:
        c.apply(scene.plant, ctx, object_body=scene.object_body)
        ref = find_contacts(scene.plant, ctx, scene.object_body, hand=scene.hand)
        assert len(ref) == len(c.contacts)
        for a, b in zip(c.contacts, ref, strict=True):
            assert (a.finger_geometry, a.object_geometry) == (
                b.finger_geometry,
                b.object_geometry,
            )
            assert (a.normal_source, a.exact) == (b.normal_source, b.exact)
            for f in ("p_OC", "nhat_O", "p_FC"):
                np.testing.assert_allclose(
                    getattr(a, f), getattr(b, f), rtol=0, atol=1e-12
                )
            assert abs(a.psi - b.psi) <= 1e-12
            batched += a.finger_geometry_name.rpartition("::")[2] != "collision"
    assert batched > 100  # the WSG's tip spheres took the batched route


def test_epsilon_uses_one_torque_scale(wsg_result):
    from drakegrasp.quality import ferrari_canny

    _, result = wsg_result
    for c in result[:3]:
        assert c.epsilon == pytest.approx(
            ferrari_canny(c.grasp, torque_scale=result.torque_scale), rel=1e-6
        )


def test_same_seed_same_candidates(wsg_scene, wsg_result):
    scene, result = wsg_result
    again = plan(scene)
    assert [c.sample for c in again] == [c.sample for c in result]
    assert [c.score for c in again] == [c.score for c in result]
    other = plan(scene, seed=8)
    assert [c.sample for c in other] != [c.sample for c in result]


def test_planning_is_invariant_to_a_rigid_motion_of_the_scene(wsg_scene, wsg_result):
    _, result = wsg_result
    X = RigidTransform(RollPitchYaw(0.4, -0.3, 1.2), [0.3, -0.2, 0.5])
    moved = plan(wsg_scene(X_WO=X))
    assert [c.sample for c in moved] == [c.sample for c in result]
    for a, b in zip(result, moved, strict=True):
        assert a.is_closure == b.is_closure and a.num_contacts == b.num_contacts
        assert b.epsilon == pytest.approx(a.epsilon, rel=1e-6, abs=1e-9)
        assert (X @ a.X_WH).IsNearlyEqualTo(b.X_WH, 1e-9)
        assert np.allclose(b.q_hand, a.q_hand, atol=1e-7)


def test_json_and_table(wsg_result):
    _, result = wsg_result
    data = json.loads(result.to_json())
    assert data["num_sampled"] == 120 and len(data["candidates"]) == len(result)
    table = result.table()
    assert {len(v) for v in table.values()} == {len(result)}
    assert "grasp candidates" in str(result)


@pytest.fixture(scope="module")
def own_best(own_scene):
    scene = own_scene()
    return scene, plan(scene, n=8, seed=0, robustness_samples=4)[0]


def test_apply_takes_the_object_body_as_everywhere_else(own_best):
    scene, best = own_best
    plant, body = scene.plant, scene.object_body
    moved = dataclasses.replace(best, X_WO=RigidTransform([0.01, 0.02, 0.03]))
    for spec in (body, body.index(), scoped_name(plant, body)):
        ctx = scene.context.Clone()
        moved.apply(plant, ctx, object_body=spec)
        X_WO = plant.EvalBodyPoseInWorld(plant.GetMyContextFromRoot(ctx), body)
        np.testing.assert_allclose(X_WO.translation(), [0.01, 0.02, 0.03])
    with pytest.raises(ModelError, match="no body named 'box::nope'"):
        best.apply(plant, scene.context.Clone(), object_body="box::nope")
    with pytest.raises(InvalidOptionError, match="object_body must be"):
        best.apply(plant, scene.context.Clone(), object_body=3.5)


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("q_hand", np.array([np.nan, np.nan]), "q_hand must be 2 finite numbers"),
        ("q_hand", np.array([0.01, np.inf]), "q_hand must be 2 finite numbers"),
        ("q_hand", np.array([0.01]), "q_hand must be 2 finite numbers"),
        ("q_hand", "abc", "q_hand must be an array of real numbers"),
        ("X_WH", RigidTransform([np.nan, 0.0, 0.0]), "X_WH must be a pose"),
        ("X_WO", RigidTransform(np.diag([2.0, 2.0, 2.0, 1.0])), "X_WO must be a pose"),
        ("X_WH", np.eye(4), "X_WH must be a pydrake RigidTransform"),
    ],
)
def test_apply_refuses_a_candidate_drake_cannot_take(own_best, field, value, match):
    # An edited or deserialised candidate: a NaN joint value once reached
    # plant.SetPositions (SystemExit), a short q_hand a bare ValueError.
    scene, best = own_best
    plant = scene.plant
    ctx = scene.context.Clone()
    before = plant.GetPositions(plant.GetMyContextFromRoot(ctx)).copy()
    edited = dataclasses.replace(best, **{field: value})
    with pytest.raises(InvalidGraspError, match=match):
        edited.apply(plant, ctx, object_body=scene.object_body)
    np.testing.assert_array_equal(
        plant.GetPositions(plant.GetMyContextFromRoot(ctx)), before
    )


def test_planning_scene_refuses_a_pose_drake_cannot_take():
    with pytest.raises(InvalidOptionError, match="X_WO must be a pose"):
        planning_scene(
            "package://drakegrasp/objects/box.sdf",
            hand_url="package://drakegrasp/hands/parallel_jaw_flat.sdf",
            X_WO=RigidTransform([np.nan, 0.0, 0.0]),
        )


def test_own_flat_jaw_on_own_objects(own_scene):
    for name in ("box", "hex_prism"):  # flat pads on flat faces: patches of 4+
        result = plan(own_scene(name), n=80)
        assert len(result) > 0, (name, result.rejections)
        assert result[0].is_closure and result[0].num_contacts >= 6, name
    # a flat pad along a cylinder's side touches along a line, reported as its
    # two ends (it was one point per pad, never hard-finger closure): hard
    # fingers now give closure, as the pads hold it in Drake with patches
    scene = own_scene("cylinder")
    hard = plan(scene, n=60)
    assert hard[0].is_closure and hard[0].num_contacts >= 4
    assert sum(k.normal_source == "line" for k in hard[0].contacts) >= 4
    soft = plan(scene, n=60, contact_model="soft_finger", torsional_friction=0.1)
    assert soft[0].is_closure


@pytest.mark.parametrize("bad", [-1, 1.5, True, "10", MAX_CANDIDATES + 1])
def test_bad_num_candidates(own_scene, bad):
    with pytest.raises(InvalidOptionError, match="num_candidates"):
        plan(own_scene(), n=bad)


def test_zero_candidates_is_empty_with_a_reason(own_scene):
    result = plan(own_scene(), n=0)
    assert len(result) == 0 and result.reason == "num_candidates is 0"


def test_an_empty_result_has_the_columns_of_a_full_one(own_scene):
    # reshape(0, -1) of the pose and joint columns once raised ValueError
    scene = own_scene()
    table = plan(scene, n=8, seed=0, robustness_samples=4).table()
    empty = plan(scene, n=0).table()
    assert empty.keys() == table.keys()
    for name, column in table.items():
        assert empty[name].dtype == column.dtype, name
        assert empty[name].shape == (0, *column.shape[1:]), name
    assert empty["p_WH"].shape == (0, 3) and empty["q_hand"].shape == (0, 2)


def test_unreachable_object_gives_an_empty_result_that_says_why(tmp_path, own_scene):
    big = tmp_path / "big.sdf"
    big.write_text(
        '<?xml version="1.0"?><sdf version="1.9"><model name="big"><link name="big">'
        "<collision name='c'><geometry><box><size>0.3 0.3 0.3</size></box></geometry>"
        "</collision></link></model></sdf>"
    )
    scene = planning_scene(
        str(big), hand_url="package://drakegrasp/hands/parallel_jaw.sdf"
    )
    result = plan(scene, n=50)
    assert len(result) == 0
    assert result.rejections == {"wider than the stroke": 50}
    assert "rejected" in result.reason


def test_hand_that_is_not_a_free_parallel_jaw(own_scene, fingerless_scene):
    scene = own_scene()
    with pytest.raises(ModelError, match="free"):
        plan_grasps(
            scene.plant, scene.context, scene.object_body,
            hand=[scene.plant.GetBodyByName("left_finger")], num_candidates=5, mu=0.5,
        )  # fmt: skip
    with pytest.raises(ModelError, match="one-dof joint"):
        plan(fingerless_scene, n=5)


def test_bad_mu_and_noise(own_scene):
    scene = own_scene()
    with pytest.raises(InvalidOptionError):
        plan(scene, n=5, mu=-1)
    with pytest.raises(InvalidOptionError, match="noise"):
        plan(scene, n=5, noise={"wobble": 1})
    # A string is not a flag ("no" would read as True).
    with pytest.raises(InvalidOptionError, match="complete_unseen must be True or"):
        plan(scene, n=5, complete_unseen="no")


@settings(max_examples=4, deadline=None, derandomize=True)
@given(
    st.floats(-np.pi, np.pi),
    st.floats(-1.5, 1.5),
    st.floats(-np.pi, np.pi),
    st.tuples(*[st.floats(-1.0, 1.0)] * 3),
)
def test_rigid_motion_invariance_property(own_scene, roll, pitch, yaw, p):
    X = RigidTransform(RollPitchYaw(roll, pitch, yaw), list(p))
    a = plan(own_scene("hex_prism"), n=40, seed=3)
    b = plan(own_scene("hex_prism", X_WO=X), n=40, seed=3)
    assert a.rejections == b.rejections
    assert [c.sample for c in a] == [c.sample for c in b]
    for ca, cb in zip(a, b, strict=True):
        assert (X @ ca.X_WH).IsNearlyEqualTo(cb.X_WH, 1e-8)
        assert cb.score == pytest.approx(ca.score, rel=1e-6, abs=1e-9)


def test_progress_bar(own_scene, capsys):
    pytest.importorskip("tqdm")
    result = plan(own_scene(), n=10, progress=True)
    assert len(result) + sum(result.rejections.values()) == 10
    assert "closing" in capsys.readouterr().err


def test_rank_order_breaks_rounding_ties_by_the_next_key():
    # symmetric grasps tie in exact arithmetic; their LPs' last bits (which a
    # rigid motion of the scene changes) must not order them: d*, then the sample
    from drakegrasp.planning.ranking import TIE_DECIMALS, rank_order

    tiny = 10.0 ** -(TIE_DECIMALS + 4)
    score = np.array([0.5, 0.5 + tiny, 0.5 - tiny, 0.7, 0.5 + 10.0**-TIE_DECIMALS * 5])
    d_star = np.array([0.2, 0.1, 0.2, 0.0, 0.0])
    sample = np.array([4, 1, 2, 3, 0])
    assert list(rank_order(score, d_star, sample)) == [3, 4, 2, 0, 1]
    assert list(rank_order(score[[2, 0, 1]], d_star[[2, 0, 1]], sample[[2, 0, 1]])) == [
        0,
        1,
        2,
    ]
