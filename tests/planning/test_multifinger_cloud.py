"""plan_grasps with multi-finger hands on point clouds: Drake's Allegro hand on
full and one-sided clouds of the YCB soup can, and a coupled three-finger hand
of our own on a cylinder's cloud.  Every candidate is clear of the cloud
(checked with Drake's point distances, not the planner's closed forms), within
its joint limits, touches the true object where its contacts say, is
reproducible and moves with the cloud; hostile clouds are refused or answered
with a reason."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from cloud_support import sample_cloud
from coupled_support import coupled_hand_sdf
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.geometry import Box, Capsule, Cylinder, Sphere
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, CoulombFriction
from pydrake.systems.framework import DiagramBuilder

from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.planning import plan_grasps, planning_scene, shake_test
from drakegrasp.planning.cloud import PointCloudWarning, complete_unseen
from drakegrasp.planning.cloud_hand import (
    OPEN_END_OFFSET,
    REASONS,
    _open_end,
    signed_distances,
)
from drakegrasp.planning.motors import TORQUE_CHECK, torque_needed
from drakegrasp.plant.contacts import DEFAULT_DISTANCE_TOLERANCE as TOL
from drakegrasp.plant.contacts import find_contacts
from drakegrasp.plant.couplings import add_models
from drakegrasp.plant.models import register_models

ALLEGRO = (
    "package://drake_models/allegro_hand_description/sdf/"
    "allegro_hand_description_right.sdf"
)
THREE = "package://drakegrasp/hands/three_finger_hand.sdf"
CAN = "package://drake_models/ycb/005_tomato_soup_can.sdf"
VIEW = [0.5, 0.0, 0.0]  # a camera on +x sees the near half of the can's side
MU = 1.0


def _cloud(full, n=3000, seed=0, view=None):
    return sample_cloud(full, n, seed, view)


def _allegro(models_dir, object_url=None):
    scene = planning_scene(object_url, hand_url=ALLEGRO, models_dir=models_dir)
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    scene.plant.GetJointByName("joint_12").set_angle(ctx, 1.0)  # thumb opposed
    return scene


def _plan(scene, cloud, normals=None, n=40, seed=0, **kw):
    return plan_grasps(
        scene.plant, scene.context, None, hand=scene.hand, num_candidates=n,
        mu=MU, seed=seed, robustness_samples=8, point_cloud=cloud,
        cloud_normals=normals, **kw,
    )  # fmt: skip


@pytest.fixture(scope="module")
def can(drake_models_dir):
    """(the can with the hand, the hand alone, the full cloud, a one-sided one)."""
    full = _allegro(drake_models_dir, CAN)
    return full, _allegro(drake_models_dir), _cloud(full), _cloud(full, view=VIEW)


@pytest.fixture(scope="module")
def full_result(can):
    _, hand, (p, nrm), _ = can
    return _plan(hand, p, nrm)


@pytest.fixture(scope="module")
def partial_result(can):
    _, hand, _, (p, nrm) = can
    return _plan(hand, p, nrm, n=100, viewpoint=VIEW)


def _deepest_cloud_point(scene, candidate, points) -> float:
    """Deepest signed distance (m) of a cloud point inside a hand geometry,
    by Drake's ComputeSignedDistanceToPoint on the applied candidate."""
    ctx = scene.context.Clone()
    candidate.apply(scene.plant, ctx)
    pctx = scene.plant.GetMyContextFromRoot(ctx)
    query = scene.plant.get_geometry_query_input_port().Eval(pctx)
    deepest = np.inf
    for p in points:
        for r in query.ComputeSignedDistanceToPoint(p, 0.0):
            deepest = min(deepest, r.distance)
    return deepest


def _check_valid(scene, result, points):
    plant = scene.plant
    for c in result:
        assert _deepest_cloud_point(scene, c, points) >= -TOL - 1e-9
        for name, q in zip(c.joint_names, c.q_hand, strict=True):
            joint = plant.GetJointByName(name.split("::")[-1])
            lo, hi = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
            assert lo - 1e-9 <= q <= hi + 1e-9, (name, q)
        fingers = {k.finger_body for k in c.contacts}
        assert len(fingers) >= 2


def _check_on_the_true_can(full, result, band):
    """Each contact's finger body lies within ``band`` of the true can, and no
    hand geometry penetrates it deeper than ``band``."""
    plant, obj = full.plant, full.object_body
    object_geoms = set(plant.GetCollisionGeometriesForBody(obj))
    for c in result:
        ctx = full.context.Clone()
        c.apply(plant, ctx)
        pctx = plant.GetMyContextFromRoot(ctx)
        query = plant.get_geometry_query_input_port().Eval(pctx)
        inspector = query.inspector()
        psi = {}
        for pair in query.ComputeSignedDistancePairwiseClosestPoints(0.05):
            for a, b in ((pair.id_A, pair.id_B), (pair.id_B, pair.id_A)):
                if a in object_geoms and b not in object_geoms:
                    body = plant.GetBodyFromFrameId(inspector.GetFrameId(b))
                    name = f"allegro_hand_right::{body.name()}"
                    psi[name] = min(psi.get(name, np.inf), pair.distance)
        assert min(psi.values()) >= -band, psi
        for k in c.contacts:
            assert psi.get(k.finger_body, np.inf) <= band, (k.finger_body, psi)


def test_every_sample_is_a_candidate_or_a_counted_rejection(full_result):
    result = full_result
    assert len(result) + sum(result.rejections.values()) == result.num_sampled == 40
    assert set(result.rejections) <= set(REASONS)
    assert len(result) >= 8 and result[0].is_closure
    scores = [c.score for c in result]
    assert scores == sorted(scores, reverse=True)
    assert result.object_body == "point cloud"
    assert np.isnan(result[0].squeeze_needed)  # a cloud has no mass


def test_full_cloud_candidates_are_clear_of_the_cloud_and_within_limits(
    can, full_result
):
    _, hand, (p, _), _ = can
    _check_valid(hand, full_result[:6], p)


def test_full_cloud_contacts_lie_on_the_true_can(can, full_result):
    full, _, (p, _), _ = can
    spacing = np.sqrt(0.0276 / len(p))  # the can's area over its points
    _check_on_the_true_can(full, full_result[:6], band=max(spacing, 2e-3))
    for c in full_result[:6]:  # the contacts are cloud points
        p_W = np.array([k.p_OC for k in c.contacts]) + c.X_WO.translation()
        assert (
            np.min(np.linalg.norm(p_W[:, None] - p[None], axis=2), axis=1).max() < 1e-12
        )


CAN_RADIUS, CAN_HALF_LENGTH = 0.03185, 0.04995  # its collision cylinder (axis y)


def _can_normal(p_W):
    """The true can's outward unit normal at a surface point (the can at the
    world origin, axis y), or None within 3 mm of a rim (no single normal)."""
    r = np.hypot(p_W[0], p_W[2])
    side = abs(p_W[1]) < CAN_HALF_LENGTH - 3e-3
    cap = r < CAN_RADIUS - 3e-3
    if side and not cap:
        return np.array([p_W[0], 0.0, p_W[2]]) / r
    if cap and not side:
        return np.array([0.0, np.sign(p_W[1]), 0.0])
    return None


def test_one_contact_per_touching_geometry_as_on_the_true_can(can, full_result):
    """Each touching geometry gives one contact (a box flat on the cap its
    patch's corners), as find_contacts on the true can gives one per touching
    geometry pair, with the true surface's normal: the band's every point
    made 11-28 contacts where the true can's analysis finds 3-7."""
    full, _, _, _ = can
    plant, obj = full.plant, full.object_body
    flat = 0
    for c in full_result:
        ctx = full.context.Clone()
        c.apply(plant, ctx)
        pctx = plant.GetMyContextFromRoot(ctx)
        on_body = find_contacts(
            plant, pctx, obj, hand=full.hand, distance_tolerance=2e-3
        )
        per_body = Counter(k.finger_body for k in c.contacts)
        normals = {}
        for k in c.contacts:
            p_W = k.p_OC + c.X_WO.translation()
            n = _can_normal(p_W)
            if n is not None:  # the patch's mean normal is the surface's
                assert np.degrees(np.arccos(np.clip(-k.nhat_O @ n, -1, 1))) < 5.0
            normals.setdefault(k.finger_body, []).append(k.nhat_O)
        for body, count in per_body.items():
            geometries = plant.GetCollisionGeometriesForBody(
                plant.GetBodyByName(body.split("::")[-1])
            )
            if count > len(geometries):  # only a pad flat on the flat cap
                nrm = np.array(normals[body])
                assert np.all(np.abs(nrm[:, 1]) > np.cos(np.radians(2.0))), body
                flat += 1
        if not flat:
            assert len(c.contacts) <= len(on_body)
    assert np.mean([len(c.contacts) for c in full_result]) < 5


def test_contacts_at_a_rim_carry_the_cap_and_side_normals_as_their_fan(
    full_result,
):
    """A contact within 1 mm of a rim of the can's cloud carries a normal fan
    whose ends are the cap's inward normal and the side's (the side turns
    under the finger, so within 35° of the side's normal at the contact): the
    two faces the finger may meet there.  Contacts of a fan turn more than
    EDGE_ANGLE end to end."""
    at_rim = 0
    for c in full_result:
        for k in c.contacts:
            if k.fan is not None:
                cos = k.fan[0] @ k.fan[1]
                assert np.degrees(np.arccos(np.clip(cos, -1, 1))) > 20.0
            p_W = k.p_OC + c.X_WO.translation()
            r = np.hypot(p_W[0], p_W[2])
            if np.hypot(r - CAN_RADIUS, abs(p_W[1]) - CAN_HALF_LENGTH) > 1e-3:
                continue
            at_rim += 1
            assert k.fan is not None
            cap = np.array([0.0, -np.sign(p_W[1]), 0.0])
            side = -np.array([p_W[0], 0.0, p_W[2]]) / r
            to_cap = np.degrees(np.arccos(np.clip(k.fan @ cap, -1, 1)))
            to_side = np.degrees(np.arccos(np.clip(k.fan @ side, -1, 1)))
            j = int(np.argmin(to_cap))
            assert to_cap[j] < 1.0 and to_side[1 - j] < 35.0, (to_cap, to_side)
    assert at_rim >= 5


def test_one_sided_cloud_of_the_can(can, partial_result):
    full, hand, (p_full, _), (p, _) = can
    assert len(p) < 0.7 * len(p_full)
    result = partial_result
    assert len(result) + sum(result.rejections.values()) == 100
    assert result.rejections["hand enters the unseen side"] > 0
    assert len(result) > 0 and result[0].is_closure
    _check_valid(hand, result[:4], p)
    _check_on_the_true_can(full, result[:4], band=3e-3)


def test_a_known_mass_gives_cloud_candidates_their_torque_needed(can, full_result):
    """With object_mass the best force-closure candidates carry torque_needed
    (computed from the cloud contacts' finger bodies and points), and those
    within the Allegro's 0.7 N·m come first; without it nothing is computed
    and the candidates are the same."""
    full, hand, (p, nrm), _ = can
    mass = full.object_body.get_mass(full.plant.GetMyContextFromRoot(full.context))
    result = _plan(hand, p, nrm, object_mass=mass)
    checked = [c for c in result if not np.isnan(c.torque_needed)]
    assert checked and all(c.is_closure for c in checked)
    assert len(checked) == sum(c.is_closure for c in result[:TORQUE_CHECK])
    for c in checked[:3]:
        assert c.torque_needed == pytest.approx(
            torque_needed(hand.plant, hand.context, c, None, weight=mass * 9.81),
            rel=1e-9,
        )
    held = [c.torque_needed <= 0.7 for c in result]
    assert 0 < sum(held) and held == sorted(held, reverse=True)
    assert all(c.closure is not None for c in result[:10])
    assert all(np.isnan(c.torque_needed) for c in full_result)
    assert sorted(c.sample for c in result) == sorted(c.sample for c in full_result)


def test_same_seed_same_candidates(can, full_result):
    _, hand, (p, nrm), _ = can
    again = _plan(hand, p, nrm)
    assert len(again) == len(full_result)
    for a, b in zip(again, full_result, strict=True):
        assert a.sample == b.sample and a.score == b.score
        np.testing.assert_array_equal(a.q_hand, b.q_hand)
        np.testing.assert_array_equal(a.X_WH.GetAsMatrix4(), b.X_WH.GetAsMatrix4())


def test_planning_moves_with_a_translated_cloud(can, full_result):
    """The same poses, moved; the same closed hands, but for round-off that
    can tip a discrete decision of a finger (the nearest point it aims at, a
    stop far from the cloud) at most once in ten candidates."""
    _, hand, (p, nrm), _ = can
    t = np.array([0.25, -0.5, 0.125])
    moved = _plan(hand, p + t, nrm)
    by_sample = {c.sample: c for c in full_result}
    assert {c.sample for c in moved} == set(by_sample)
    same = 0
    for a in moved:
        b = by_sample[a.sample]
        np.testing.assert_allclose(
            a.X_WH.translation(), b.X_WH.translation() + t, atol=1e-9
        )
        np.testing.assert_allclose(
            a.X_WH.rotation().matrix(), b.X_WH.rotation().matrix(), atol=1e-12
        )
        np.testing.assert_array_equal(a.q_preshape, b.q_preshape)
        if np.allclose(a.q_hand, b.q_hand, atol=1e-3):
            same += 1
            assert a.is_closure == b.is_closure
    assert same >= 0.9 * len(moved)


def test_a_rotated_cloud_gives_valid_candidates(can):
    """The cloud's frame O has the world's axes, so a rotated cloud gives
    other draws: as many valid candidates, not the same ones."""
    _, hand, (p, nrm), _ = can
    R = RollPitchYaw(0.3, -0.5, 1.1).ToRotationMatrix().matrix()
    result = _plan(hand, p @ R.T, nrm @ R.T, n=20, seed=5)
    assert len(result) > 0 and result[0].is_closure
    _check_valid(hand, result[:3], p @ R.T)


def test_hostile_clouds(can):
    _, hand, (p, nrm), _ = can
    with pytest.raises(InvalidOptionError, match="empty"):
        _plan(hand, np.zeros((0, 3)))
    with pytest.raises(InvalidOptionError, match="finite"):
        _plan(hand, np.full((50, 3), np.nan))
    holes = p.copy()
    holes[::10] = np.nan  # missing depth, as Drake marks it
    with pytest.warns(PointCloudWarning, match=f"left out {len(p[::10])} of"):
        result = _plan(hand, holes, nrm, n=10)
    assert result.settings["cloud_dropped"] == len(p[::10])
    assert len(result) + sum(result.rejections.values()) == 10
    # every point twice (a merged scan): spacing 0, surfels of radius 0
    doubled = _plan(hand, np.vstack([p, p]), np.vstack([nrm, nrm]), n=10)
    assert len(doubled) + sum(doubled.rejections.values()) == 10
    empty = _plan(hand, p, nrm, n=0)
    assert len(empty) == 0 and "num_candidates is 0" in empty.reason
    # the palm held 0.3-0.4 m off the can: no finger reaches it
    result = _plan(hand, p, nrm, n=15, standoff=(0.3, 0.4))
    assert len(result) == 0 and "rejected" in result.reason
    assert result.rejections == {"fingers miss the object": 15}
    assert set(result.rejections) <= set(REASONS)


def _drake_point_distances(shape, X, p_W):
    """Drake's ComputeSignedDistanceToPoint of points to one posed shape."""
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    plant.RegisterCollisionGeometry(
        plant.world_body(), X, shape, "g", CoulombFriction(1.0, 1.0)
    )
    plant.Finalize()
    diagram = builder.Build()
    ctx = plant.GetMyContextFromRoot(diagram.CreateDefaultContext())
    query = plant.get_geometry_query_input_port().Eval(ctx)
    return [query.ComputeSignedDistanceToPoint(p, np.inf)[0].distance for p in p_W]


@pytest.mark.parametrize(
    "shape, inside, outside",
    [
        (Sphere(0.02), [0.01, 0, 0], [0, 0.03, 0]),
        (Box(0.02, 0.04, 0.06), [0.009, 0.0, 0.0], [0.02, 0.03, 0.0]),
        (Cylinder(0.02, 0.1), [0.0, 0.0, 0.049], [0.03, 0.0, 0.06]),
        (Capsule(0.01, 0.05), [0.0, 0.0, 0.03], [0.0, 0.0, 0.045]),
    ],
)
def test_closed_form_distances_match_drakes(shape, inside, outside):
    """The planner's signed distances equal Drake's ComputeSignedDistanceToPoint."""
    X = RigidTransform(RollPitchYaw(0.2, 0.4, -0.3), [0.1, -0.05, 0.2])
    rng = np.random.default_rng(0)
    q_G = np.vstack([inside, outside, rng.uniform(-0.06, 0.06, (200, 3))])
    ours = signed_distances(shape, q_G)
    p_W = q_G @ X.rotation().matrix().T + X.translation()
    np.testing.assert_allclose(ours, _drake_point_distances(shape, X, p_W), atol=1e-12)
    assert ours[0] < 0 < ours[1]


@settings(derandomize=True, max_examples=25, deadline=None)
@given(
    kind=st.sampled_from(["sphere", "box", "cylinder", "capsule"]),
    size=st.tuples(*[st.floats(0.002, 0.08)] * 3),
    rpy=st.tuples(*[st.floats(-3.0, 3.0)] * 3),
    seed=st.integers(0, 2**16),
)
def test_closed_form_distances_match_drakes_for_any_shape_and_pose(
    kind, size, rpy, seed
):
    a, b, c = size
    shape = {
        "sphere": lambda: Sphere(a),
        "box": lambda: Box(a, b, c),
        "cylinder": lambda: Cylinder(a, b),
        "capsule": lambda: Capsule(a, b),
    }[kind]()
    X = RigidTransform(RollPitchYaw(*rpy), [0.3, -0.1, 0.05])
    q_G = np.random.default_rng(seed).uniform(-0.1, 0.1, (60, 3))
    p_W = q_G @ X.rotation().matrix().T + X.translation()
    np.testing.assert_allclose(
        signed_distances(shape, q_G), _drake_point_distances(shape, X, p_W), atol=1e-12
    )


@pytest.fixture(scope="module")
def coupled():
    """(the coupled hand alone in a plant, root context, hand, cylinder cloud)."""
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    parser = Parser(plant)
    register_models(parser)
    (hand,) = add_models(parser, text=coupled_hand_sdf(), kind="sdf")
    plant.Finalize()
    root = builder.Build().CreateDefaultContext()
    cylinder = planning_scene(
        "package://drakegrasp/objects/cylinder.sdf", hand_url=THREE
    )
    p, nrm = _cloud(cylinder, n=2000)
    return plant, root, hand, p + [0.0, 0.0, 0.3], nrm, cylinder


def _plan_coupled(coupled, p, nrm, n=30, seed=0, **kw):
    plant, root, hand = coupled[:3]
    return plan_grasps(
        plant, root, None, hand=hand, num_candidates=n, mu=MU, seed=seed,
        robustness_samples=8, point_cloud=p, cloud_normals=nrm,
        preshape=[-0.5] * 6, **kw,
    )  # fmt: skip


def test_a_coupled_three_finger_hand_on_a_cylinder_cloud(coupled):
    plant, root, hand, p, nrm, _ = coupled
    result = _plan_coupled(coupled, p, nrm)
    assert len(result) + sum(result.rejections.values()) == 30
    assert set(result.rejections) <= set(REASONS)
    assert len(result) > 0 and result[0].is_closure
    ctx = plant.GetMyContextFromRoot(root)
    query = plant.get_geometry_query_input_port().Eval(ctx)
    for c in result[:5]:
        # every follower follows its leader (ratio 1, offset 0)
        q = dict(zip(c.joint_names, c.q_hand, strict=True))
        for k in range(3):
            lead = q[f"coupled_hand::f{k}_prox_joint"]
            assert q[f"coupled_hand::f{k}_dist_joint"] == pytest.approx(lead)
        assert len(c.contacts) >= 2
    scene = type("S", (), {"plant": plant, "context": root})
    _check_valid(scene, result[:5], p)
    again = _plan_coupled(coupled, p, nrm)
    assert [c.sample for c in again] == [c.sample for c in result]
    assert query is not None


def test_a_cloud_the_coupled_hand_cannot_reach_is_an_empty_result(coupled):
    # the palm held 0.2-0.3 m off a ball 0.5 m across: no finger reaches it
    rng = np.random.default_rng(2)
    u = rng.standard_normal((3000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    result = _plan_coupled(coupled, 0.25 * u, u, n=15, standoff=(0.2, 0.3))
    assert len(result) == 0 and "rejected" in result.reason
    assert result.rejections == {"fingers miss the object": 15}


def test_a_table_under_the_cloud_is_an_obstacle(coupled):
    """The plant's other geometry (a table the cylinder stands on) is checked
    with Drake's distances: no candidate's hand goes into it."""
    _, _, _, p, nrm, _ = coupled
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    parser = Parser(plant)
    register_models(parser)
    (hand,) = add_models(parser, text=coupled_hand_sdf(), kind="sdf")
    top = p[:, 2].min()  # the cylinder's bottom cap
    plant.RegisterCollisionGeometry(
        plant.world_body(), RigidTransform([0.0, 0.0, top - 0.01]),
        Box(1.0, 1.0, 0.02), "table", CoulombFriction(1.0, 1.0),
    )  # fmt: skip
    plant.Finalize()
    root = builder.Build().CreateDefaultContext()
    result = _plan_coupled((plant, root, hand), p, nrm, n=40)
    assert len(result) + sum(result.rejections.values()) == 40
    assert result.rejections.get("hand collides with the scene", 0) > 0
    assert len(result) > 0
    table = plant.GetCollisionGeometriesForBody(plant.world_body())
    for c in result:
        ctx = root.Clone()
        c.apply(plant, ctx)
        query = plant.get_geometry_query_input_port().Eval(
            plant.GetMyContextFromRoot(ctx)
        )
        for pair in query.ComputeSignedDistancePairwiseClosestPoints(0.0):
            if pair.id_A in table or pair.id_B in table:
                assert pair.distance >= -TOL - 1e-9


def test_a_hand_without_fingers_is_refused_on_a_cloud(tmp_path, coupled):
    _, _, _, p, nrm, _ = coupled
    paddle = tmp_path / "paddle.sdf"
    paddle.write_text(
        '<?xml version="1.0"?><sdf version="1.9"><model name="paddle">'
        "<link name='palm'><collision name='c'><geometry><box>"
        "<size>0.05 0.05 0.05</size></box></geometry></collision></link>"
        "</model></sdf>"
    )
    scene = planning_scene(None, hand_url=str(paddle))
    with pytest.raises(ModelError, match="one-dof joint"):
        _plan(scene, p, nrm, n=5)


@pytest.mark.parametrize(
    "bad, match",
    [
        ({"min_fingers": 1}, "min_fingers"),
        ({"min_fingers": 4}, "min_fingers"),
        ({"tilt": 2.0}, "tilt"),
        ({"preshape": [0.0] * 4}, "preshape"),
        ({"num_candidates": -1}, "num_candidates"),
        ({"object_mass": float("nan")}, "object_mass"),
        ({"object_mass": -0.3}, "object_mass"),
        ({"object_mass": float("inf")}, "object_mass"),
        ({"object_mass": 0.0}, "object_mass"),
    ],
)
def test_bad_options_on_a_cloud(coupled, bad, match):
    plant, root, hand, p, nrm, _ = coupled
    kw = {"num_candidates": 5, "preshape": [-0.5] * 6, **bad}
    with pytest.raises(InvalidOptionError, match=match):
        plan_grasps(
            plant, root, None, hand=hand, mu=MU, point_cloud=p, cloud_normals=nrm,
            **kw,
        )  # fmt: skip


# Revolute fingers: the squeeze is a joint torque (N·m) and the gains per radian.
ALLEGRO_SHAKE = dict(squeeze=0.5, stiffness=20.0, damping=1.0)


def _true_pose(full):
    """The true can's pose in the world (the cloud's frame O is its centroid)."""
    ctx = full.plant.GetMyContextFromRoot(full.context)
    return full.plant.EvalBodyPoseInWorld(ctx, full.object_body)


def test_one_sided_cloud_grasps_hold_the_true_can(can):
    """The five best of a one-sided cloud's candidates hold the true can in
    Drake (shake_test at the can's real pose).  Measured
    (benchmarks/bench_cloud_hold.py, 300 samples, seed 0): the ten best held
    8/10 and ten random candidates 1/10 (seeds 1 and 2: 5/10 and 9/10); 6/10,
    3/10 and 8/10 before contacts at the cloud's open ends (the rims) took the
    finger's normal, 7/10, 2/10 and 7/10 without the edge fans.  Before the
    unseen side was completed (the hand kept on the seen side) none of the
    ten best held at seed 0."""
    full, hand, _, (p, nrm) = can
    result = plan_grasps(
        hand.plant, hand.context, None, hand=hand.hand, num_candidates=300,
        mu=MU, seed=0, point_cloud=p, cloud_normals=nrm, viewpoint=VIEW,
    )  # fmt: skip
    completion = result.settings["unseen_completion"]
    assert completion["skipped"] is None and completion["added"] > 0
    # the centre the normal lines meet is the can's axis (x = z = 0)
    assert np.hypot(completion["centre"][0], completion["centre"][2]) < 1e-3
    held = [
        shake_test(full.add_models, c, X_WO=_true_pose(full), **ALLEGRO_SHAKE).held
        for c in result[:5]
    ]
    assert sum(held) >= 4, held


def test_full_cloud_grasps_hold_the_true_can(can):
    """The ten best of a full cloud's candidates, planned with the can's mass
    (torque_needed, those within the Allegro's 0.7 N·m first), hold the true
    can at least 8 times in 10 (issue 18's target).  Measured
    (benchmarks/bench_cloud_hold.py, 600 samples): 10/10, 8/10, 10/10 at
    seeds 0-2 (9, 8, 10 without the mass; at 300 samples 7, 2, 7 and 7, 5, 7:
    the planning guide's table).  A regression guard on one draw."""
    full, hand, (p, nrm), _ = can
    mass = full.object_body.get_mass(full.plant.GetMyContextFromRoot(full.context))
    result = plan_grasps(
        hand.plant, hand.context, None, hand=hand.hand, num_candidates=600,
        mu=MU, seed=0, point_cloud=p, cloud_normals=nrm, object_mass=mass,
    )  # fmt: skip
    assert result.settings["unseen_completion"] is None  # no viewpoint
    held = [
        shake_test(full.add_models, c, X_WO=_true_pose(full), **ALLEGRO_SHAKE).held
        for c in result[:10]
    ]
    assert sum(held) >= 8, held


def test_one_sided_cloud_grasps_with_the_mass_hold_the_true_can(can):
    """Issue 18 on the one-sided cloud: with the can's mass, the ten best hold
    the true can at least 8 times in 10.  Measured
    (benchmarks/bench_cloud_hold.py, 600 samples, seeds 0-2): 9, 9, 6 of 10
    since a contact at an open end of the completed cloud (the can's rim: the
    caps were never seen) takes the finger's normal; 3, 7, 2 before, when
    those contacts kept the side's normal and the torque they needed was
    underestimated (on the true can the rim pushed along the axis).  A
    regression guard on seed 0."""
    full, hand, _, (p, nrm) = can
    mass = full.object_body.get_mass(full.plant.GetMyContextFromRoot(full.context))
    result = plan_grasps(
        hand.plant, hand.context, None, hand=hand.hand, num_candidates=600,
        mu=MU, seed=0, point_cloud=p, cloud_normals=nrm, viewpoint=VIEW,
        object_mass=mass,
    )  # fmt: skip
    held = [
        shake_test(full.add_models, c, X_WO=_true_pose(full), **ALLEGRO_SHAKE).held
        for c in result[:10]
    ]
    assert sum(held) >= 8, held


def test_open_end_is_where_the_cloud_stops():
    """A point of a flat square cloud: inside it the neighbours' centroid is
    the point (no open end), on its border it lies about 4/(3π) radii inside."""
    g = np.linspace(-0.02, 0.02, 41)
    xy = np.array([(x, y) for x in g for y in g])
    cloud = np.column_stack([xy, np.zeros(len(xy))])
    n = np.array([0.0, 0.0, 1.0])
    radius = 0.006

    def at(point):
        near = cloud[np.linalg.norm(cloud - point, axis=1) <= radius] - point
        return _open_end(near, n, radius)

    assert not at(np.array([0.0, 0.0, 0.0]))
    assert at(np.array([0.02, 0.0, 0.0]))  # the border x = 2 cm
    assert at(np.array([0.02, 0.02, 0.0]))  # a corner
    assert not _open_end(np.zeros((0, 3)), n, radius)
    assert 0.25 == OPEN_END_OFFSET < 4 / (3 * np.pi)


def test_contacts_at_the_rim_of_a_completed_cloud_take_the_fingers_normal(
    can, partial_result
):
    """The completed one-sided cloud of the can has no caps (never seen), so its
    side stops at the rims.  A finger touching there meets the rim's corner on
    the true can and pushes along its own normal, turned from the side's
    radial normal towards the can's middle: the contact takes it (without
    the open-end test every contact there kept the side's normal, axial
    component 0)."""
    tilted = 0
    for c in partial_result:
        for k in c.contacts:
            p_W = k.p_OC + c.X_WO.translation()
            if abs(p_W[1]) < CAN_HALF_LENGTH - 2e-3:
                continue
            # an inward normal there turns into the can, away from the rim (a
            # rounded finger meeting the rim point off its tip may turn it a
            # few degrees the other way: 7° seen, 15° allowed)
            assert k.nhat_O[1] * np.sign(p_W[1]) < np.sin(np.radians(15.0)), (
                p_W,
                k.nhat_O,
            )
            tilted += bool(np.degrees(np.arcsin(abs(k.nhat_O[1]))) > 20.0)
    assert tilted >= 3


def _hemisphere(centre, n=800, seed=0):
    u = np.random.default_rng(seed).standard_normal((n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    u[:, 0] = np.abs(u[:, 0])  # the half facing a camera on +x
    return centre + 0.04 * u, u


@pytest.mark.parametrize("centre", [[0.0, 0.0, 0.0], [0.3, -0.2, 0.5]])
def test_completion_reflects_a_hemisphere_through_the_sphere_centre(centre):
    """Every normal line of a sphere meets its centre: the completion finds it
    (to round-off) wherever the sphere is, and adds the far half."""
    centre = np.array(centre)
    p, n = _hemisphere(centre)
    added, added_n, info = complete_unseen(p, n, centre + [0.5, 0.0, 0.0])
    assert info["skipped"] is None
    np.testing.assert_allclose(info["centre"], centre, atol=1e-12)
    assert len(added) > 0.9 * len(p) and np.all(added[:, 0] <= centre[0] + 1e-3)
    # the added points lie on the sphere, with its outward normals
    r = added - centre
    np.testing.assert_allclose(np.linalg.norm(r, axis=1), 0.04, atol=1e-12)
    np.testing.assert_allclose(added_n, r / 0.04, atol=1e-12)


def test_completion_is_skipped_for_a_face_seen_head_on():
    """A flat face seen head-on tells nothing of the depth: nothing is added."""
    g = np.random.default_rng(1).uniform(-0.03, 0.03, (400, 2))
    p = np.column_stack([np.full(len(g), 0.02), g])
    n = np.tile([1.0, 0.0, 0.0], (len(g), 1))
    added, _, info = complete_unseen(p, n, [0.5, 0.0, 0.0])
    assert len(added) == 0 and info["skipped"] == "depth undetermined"


def test_completion_can_be_turned_off(can, partial_result):
    """complete_unseen=False keeps the hand on the seen side (the shadow test)."""
    _, hand, _, (p, nrm) = can
    off = _plan(hand, p, nrm, n=100, viewpoint=VIEW, complete_unseen=False)
    assert off.settings["unseen_completion"] is None
    assert partial_result.settings["unseen_completion"]["added"] > 0
    assert off.rejections["hand enters the unseen side"] > 0
    assert {c.sample for c in off} != {c.sample for c in partial_result}


def test_a_contact_measured_on_surfels_finds_its_fan_on_a_sparse_cloud():
    # A 200-point sphere: a contact's ψ, measured on the points' tangent discs
    # (0.09 mm), was below the bound the screen took from the points alone
    # (0.56 mm), so the fan's query measured nothing and the plan raised
    # TypeError ('>=' between float and None); the screen now allows for the
    # discs' radius.  Every seed of 12 failed with this noise.
    scene = planning_scene(
        None, hand_url="package://drakegrasp/hands/three_finger_hand.sdf"
    )
    rng = np.random.default_rng(0)
    v = rng.normal(size=(200, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    result = plan_grasps(
        scene.plant, scene.context, None, hand=scene.hand, num_candidates=60,
        mu=0.5, seed=0, robustness_samples=8, point_cloud=0.03 * v,
        cloud_normals=v, noise={"position": 1e-4},
    )  # fmt: skip
    assert len(result) > 0
    for c in result:
        assert np.isfinite([c.d_star, c.epsilon, c.robustness, c.score]).all()
