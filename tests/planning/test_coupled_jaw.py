"""A parallel jaw whose fingers one motor drives plans grasps on its coupling.

A ``<mimic>`` ties the two prismatic fingers, ``q_1 = m q_0 + b``.  Each
finger closes on its own and stops on the object; the planner then puts them
back on the coupling and moves the hand along the grasp axis so that each
pad stays where it stopped.  Before, a candidate broke the coupling by up to
48 µm on the soup can and :func:`~drakegrasp.analyze_grasp` refused it.
"""

from __future__ import annotations

import numpy as np
import pytest
from coupled_hands import coupled_jaw_urdf
from hypothesis import given, settings
from hypothesis import strategies as st

import drakegrasp as dg
from drakegrasp.errors import ModelError
from drakegrasp.planning import object_surface, plan_grasps, planning_scene
from drakegrasp.planning.gripper import parallel_jaw
from drakegrasp.planning.placement import onto_coupling

BOX = "package://drakegrasp/objects/box.sdf"
CYLINDER = "package://drakegrasp/objects/cylinder.sdf"
SOUP = "package://drake_models/ycb/005_tomato_soup_can.sdf"


def _scene(tmp_path, url=BOX, models_dir=None, **jaw):
    path = tmp_path / f"jaw_{abs(hash(repr(sorted(jaw.items()))))}.urdf"
    path.write_text(coupled_jaw_urdf(**jaw))
    return planning_scene(url, hand_url=str(path), models_dir=models_dir)


def _jaw(scene):
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    return parallel_jaw(scene.plant, ctx, scene.object_body, scene.hand)


def _on_coupling(jaw, q) -> float:
    m, b = jaw.coupling
    return abs(q[1] - (m * q[0] + b))


@pytest.mark.parametrize(
    "jaw, want",
    [
        ({}, (-1.0, 0.0)),
        ({"follower": "left"}, (-1.0, 0.0)),
        ({"offset": -0.005}, (-1.0, -0.005)),
        ({"follower": "left", "offset": 0.004}, (-1.0, 0.004)),
    ],
)
def test_the_jaw_knows_its_coupling(tmp_path, jaw, want):
    # q_right = m q_left + b, read back whichever joint follows and whichever
    # finger the jaw calls finger 0
    g = _jaw(_scene(tmp_path, **jaw))
    names = [j.name() for j in g.joints]
    m, b = g.coupling
    if names[0] == "right_slide":  # the jaw's coupling is q_l = m q_r + b
        m, b = 1.0 / m, -b / m
    np.testing.assert_allclose((m, b), want, atol=1e-15)
    assert g.to_dict()["coupling"] == list(g.coupling)


def test_an_uncoupled_jaw_has_no_coupling(wsg_scene):
    assert _jaw(wsg_scene()).coupling is None


JAWS = [(-1.0, 0.0), (-1.0, -0.004), (-1.0, 0.003), (-2.0, 0.0), (-0.5, -0.005)]


@settings(max_examples=80, deadline=None)
@given(
    q=st.tuples(st.floats(0.0, 0.045), st.floats(-0.045, 0.0)),
    jaw=st.sampled_from(JAWS),
)
def test_coupled_keeps_each_pad_where_it_stopped(tmp_path_factory, q, jaw):
    # second route: the pads' coordinates along the axis, x_f = z_f + r_f q_f,
    # and the pads' world positions, the hand moved by the shift
    g = _jaws(tmp_path_factory)[jaw]
    q = np.array(q) if g.joints[0].name() == "left_slide" else np.array(q[::-1])
    qc, shift = g.coupled(q)
    assert _on_coupling(g, qc) <= 1e-15
    before = g.pad_at_zero + g.pad_rate * q
    after = g.pad_at_zero + g.pad_rate * qc + shift
    np.testing.assert_allclose(after, before, atol=1e-15)
    # in the world: the hand at X_WH, then moved along its grasp axis
    from pydrake.math import RigidTransform, RollPitchYaw

    X_WH = RigidTransform(RollPitchYaw(0.3, -0.7, 1.1), [0.1, -0.2, 0.3])
    moved, qm = onto_coupling(g, X_WH, q)
    if qm is None:  # off the limits: refused, not kept
        return
    a_W = X_WH.rotation().multiply(g.X_HK.rotation().col(0))
    for f in range(2):
        p_W = X_WH.multiply(g.X_HK.multiply(before[f] * np.eye(3)[0]))
        p_moved = moved.multiply(g.X_HK.multiply((after[f] - shift) * np.eye(3)[0]))
        np.testing.assert_allclose(p_moved, p_W, atol=1e-15)
    np.testing.assert_allclose(
        moved.translation() - X_WH.translation(), shift * a_W, atol=1e-15
    )


_JAWS: dict = {}


def _jaws(tmp_path_factory):
    if not _JAWS:
        for ratio, offset in JAWS:
            d = tmp_path_factory.mktemp("jaw")
            _JAWS[ratio, offset] = _jaw(_scene(d, ratio=ratio, offset=offset))
    return _JAWS


def _jaw_q(jaw, candidate) -> list[float]:
    """The candidate's finger joint values in the jaw's finger order."""
    q = {
        n.split("::")[-1]: v
        for n, v in zip(candidate.joint_names, candidate.q_hand, strict=True)
    }
    return [q[j.name()] for j in jaw.joints]


def _check_plan(scene, result):
    """Every candidate on the coupling, analysed as planned."""
    g = _jaw(scene)
    assert len(result) >= 5
    for c in result:
        assert _on_coupling(g, _jaw_q(g, c)) <= 1e-12
        c.apply(scene.plant, scene.context, object_body=scene.object_body)
        report = dg.analyze_grasp(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            mu=result.mu,
        )  # fmt: skip
        assert report.force_closure.is_closure == c.is_closure
        assert len(report.contacts) == len(c.contacts)


@pytest.mark.parametrize("pad", ["capsule", "sphere", "box"])
def test_planned_grasps_are_on_the_coupling_and_analyse_as_planned(tmp_path, pad):
    scene = _scene(tmp_path, url=CYLINDER, pad=pad)
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=120, mu=1.0, seed=0,
    )  # fmt: skip
    _check_plan(scene, result)


def test_on_the_soup_can_too(tmp_path, drake_models_dir):
    scene = _scene(tmp_path, url=SOUP, models_dir=drake_models_dir, offset=-0.003)
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=150, mu=1.0, seed=0,
    )  # fmt: skip
    _check_plan(scene, result)


def test_on_a_cloud_the_grasps_are_on_the_coupling(tmp_path):
    scene = _scene(tmp_path, url=CYLINDER)
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    surface = object_surface(scene.plant, ctx, scene.object_body)
    p, n, _ = surface.sample(3000, np.random.default_rng(0))
    hand_only = _scene(tmp_path, url=None)
    result = plan_grasps(
        hand_only.plant, hand_only.context, None, hand=hand_only.hand,
        num_candidates=120, mu=1.0, seed=0, point_cloud=p, cloud_normals=n,
    )  # fmt: skip
    g = _jaw(scene)
    assert len(result) >= 5
    for c in result:
        assert _on_coupling(g, _jaw_q(g, c)) <= 1e-12


def test_a_coupling_that_moves_both_pads_one_way_is_refused(tmp_path):
    scene = _scene(tmp_path, ratio=1.0, offset=-0.045)
    with pytest.raises(ModelError, match="moves both pads the same way"):
        _jaw(scene)


def test_a_finger_without_stroke_is_refused(tmp_path):
    scene = _scene(tmp_path, stroke=0.0)
    with pytest.raises(ModelError, match="has no stroke"):
        _jaw(scene)


def test_on_a_cloud_the_shifted_hand_is_checked_against_the_cloud(
    tmp_path, monkeypatch
):
    # The cloud check after the shift onto the coupling looked at the hand's
    # pose before the shift (the context was moved only later)
    from drakegrasp.planning.cloud import CloudFingers

    seen = []
    check = CloudFingers.collides

    def collides(self):
        base = self.g.base
        seen.append(self.plant.EvalBodyPoseInWorld(self.ctx, base).translation())
        return check(self)

    monkeypatch.setattr(CloudFingers, "collides", collides)
    jaw = {"ratio": -0.5, "offset": -0.005, "stroke": 0.06}
    scene = _scene(tmp_path, url=CYLINDER, **jaw)
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    surface = object_surface(scene.plant, ctx, scene.object_body)
    p, n, _ = surface.sample(3000, np.random.default_rng(0))
    hand_only = _scene(tmp_path, url=None, **jaw)
    result = plan_grasps(
        hand_only.plant, hand_only.context, None, hand=hand_only.hand,
        num_candidates=60, mu=1.0, seed=0, point_cloud=p, cloud_normals=n,
    )  # fmt: skip
    assert len(result) >= 3
    for c in result:
        assert min(np.linalg.norm(s - c.X_WH.translation()) for s in seen) < 1e-12


@pytest.mark.parametrize(
    ("ratio", "offset", "left", "right"),
    [
        (-2.0, 0.0, (0.0, 0.0225), (-0.045, 0.0)),  # the follower stops the leader
        (-0.5, 0.0, (0.0, 0.045), (-0.0225, 0.0)),  # the leader stops the follower
        (-2.0, 0.01, (0.005, 0.0275), (-0.045, 0.0)),
        (-1.0, -0.002, (0.0, 0.043), (-0.045, -0.002)),
    ],
)
def test_each_finger_reaches_only_what_its_coupling_allows(
    tmp_path, ratio, offset, left, right
):
    # q_right = ratio q_left + offset, both within their own limits: the
    # fingers reach the image of the leader's positions that keep both within
    # theirs.  Read without the coupling, a follower at ratio -2 opened the
    # jaw to 76 mm where it reaches 53.5 mm, and a jaw on a hidden drive (the
    # same jaw) reached less than its twin.
    jaws = {
        hidden: _jaw(_scene(tmp_path, ratio=ratio, offset=offset, hidden_drive=hidden))
        for hidden in (False, True)
    }
    for jaw in jaws.values():
        np.testing.assert_allclose(jaw.lower, [left[0], right[0]], atol=1e-15)
        np.testing.assert_allclose(jaw.upper, [left[1], right[1]], atol=1e-15)
    twin, hidden = jaws[False], jaws[True]
    assert hidden.min_opening == twin.min_opening
    assert hidden.max_opening == twin.max_opening
    # open, the capsules' inner sides (7 mm radius) are the fingers' less 14 mm
    assert twin.max_opening == pytest.approx(left[1] - right[0] - 0.014, abs=1e-12)
