"""The closing loop's shortcuts give the answers of the plain loop.

``close_hand`` asks Drake only for the pairs whose distance can matter (a
lower bound from conservative advancement rules the others out), keeps the
reach per plant, and stops a re-aimed finger that circles a stationary point
far from the object.  Each is checked against the plain computation: every
pair measured, the reach computed afresh, the finger left to run out of steps.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pydrake.geometry import Box
from pydrake.math import RigidTransform

from drakegrasp import UnreachableError, close_hand
from drakegrasp.plant import _closing_steps as steps
from drakegrasp.plant.advancement import _reach, advancement_bound, reach
from drakegrasp.plant.fingers import hand_structure
from drakegrasp.plant.validation import hand_bodies, query_object_of

from .conftest import ALLEGRO_URL, RealScene

CAN_URL = "package://drake_models/ycb/005_tomato_soup_can.sdf"
"""Nine collision geometries: about forty pairs per Allegro finger."""


@pytest.fixture
def allegro_can(drake_models_dir):
    def make(p_WO=(0.08, 0.0, 0.1)):
        scene = RealScene(
            drake_models_dir, ALLEGRO_URL, "hand_root", CAN_URL, RigidTransform(p_WO)
        )
        scene.plant.GetJointByName("joint_12").set_angle(scene.ctx, 1.0)
        return scene

    return make


def _structure(scene):
    query = query_object_of(scene.plant, scene.ctx)
    bodies = hand_bodies(scene.plant, scene.object, scene.hand)
    hand = hand_structure(
        scene.plant, scene.object, bodies, inspector=query.inspector()
    )
    return hand, query


def _summary(closure):
    return (
        closure.q.tolist(),
        [(f.status, f.psi, f.iterations, f.touching_body) for f in closure.fingers],
        closure.iterations,
    )


@settings(
    derandomize=True,
    max_examples=15,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(seed=st.integers(0, 2**16))
def test_measuring_only_what_can_matter_answers_as_measuring_every_pair(
    seed, allegro_can
):
    """Lower bounds below the true distances: nearest pairs and α_CA unchanged."""
    rng = np.random.default_rng(seed)
    scene = allegro_can()
    hand, _ = _structure(scene)
    q = scene.plant.GetPositions(scene.ctx)
    q[hand.position_indices] = rng.uniform(hand.lower, hand.upper)
    scene.plant.SetPositions(scene.ctx, q)
    query = query_object_of(scene.plant, scene.ctx)
    margin, target = 1e-4, 5e-5
    asked = total = 0
    for finger in hand.fingers:
        _, every = steps.pair_distances(query, finger.pairs)
        n = len(every)
        slack = rng.exponential(0.01, n) * (rng.random(n) < 0.8)
        speed = rng.uniform(0.0, 0.2, n) * (rng.random(n) < 0.9)
        tips = np.array(
            [k for k, p in enumerate(finger.pairs) if p in finger.tip_pairs], int
        )
        seen = steps.Measured(query, finger.pairs, every - slack, margin)
        assert seen.nearest() == steps.nearest(every)
        assert seen.nearest(tips) == steps.nearest(every, tips)
        assert seen.advancement(speed, target) == advancement_bound(
            every, speed, target
        )
        np.testing.assert_array_equal(seen.every[seen.known], every[seen.known])
        assert np.all(seen.lower_bounds() <= every)
        asked, total = asked + seen.known.sum(), total + n
    assert asked < total  # bounds do rule pairs out


@pytest.mark.parametrize("p_WO", [(0.08, 0.0, 0.1), (0.1, 0.05, 0.1), (0.3, 0.0, 0.1)])
def test_the_closing_equals_the_closing_that_measures_every_pair(
    p_WO, allegro_can, monkeypatch
):
    """Same q, statuses, ψ and steps; and every kept bound is below the truth."""
    scene = allegro_can(p_WO)
    q0 = scene.plant.GetPositions(scene.ctx)

    def close():
        scene.plant.SetPositions(scene.ctx, q0)
        try:
            return close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
        except UnreachableError as e:
            return e.closure

    checked = []

    class Checked(steps.Measured):
        def __init__(self, query, pairs, lower, margin):
            super().__init__(query, pairs, lower, margin)
            if lower is not None:  # the bound conservative advancement promises
                _, every = steps.pair_distances(query, pairs)
                assert np.all(every >= lower - 1e-12)
                checked.append(len(pairs))

    class Eager(steps.Measured):
        def __init__(self, query, pairs, lower, margin):
            super().__init__(query, pairs, None, margin)

    monkeypatch.setattr(steps, "Measured", Checked)
    lazy = close()
    assert checked
    monkeypatch.setattr(steps, "Measured", Eager)
    eager = close()
    assert _summary(lazy) == _summary(eager)


def test_a_finger_circling_far_from_the_object_stops_where_it_would_have_stayed(
    allegro_can, monkeypatch
):
    """Out of reach: each finger stops early, no nearer had it gone on to the end."""
    scene = allegro_can((0.3, 0.0, 0.1))
    q0 = scene.plant.GetPositions(scene.ctx)
    with pytest.raises(UnreachableError) as info:
        close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    stopped = info.value.closure
    monkeypatch.setattr(steps, "STALL_STEPS", 10**9)
    scene.plant.SetPositions(scene.ctx, q0)
    with pytest.raises(UnreachableError) as info:
        close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    ran_out = info.value.closure
    for early, late in zip(stopped.fingers, ran_out.fingers, strict=True):
        assert early.status == late.status == "not converged"
        assert early.iterations < late.iterations == 100
        assert early.psi > steps.STALL_DISTANCE * stopped.distance_tolerance
        assert late.psi > 0.9 * early.psi
    np.testing.assert_array_equal(scene.plant.GetPositions(scene.ctx), q0)


def test_kept_reach_equals_a_fresh_one_and_follows_a_changed_shape(allegro_can):
    scene = allegro_can()
    hand, query = _structure(scene)
    inspector = query.inspector()
    for finger in hand.fingers:
        first = reach(scene.plant, scene.ctx, hand, finger, inspector)
        again = reach(scene.plant, scene.ctx, hand, finger, inspector)
        fresh, reads_context = _reach(scene.plant, scene.ctx, hand, finger, inspector)
        assert not reads_context
        np.testing.assert_array_equal(first, fresh)
        np.testing.assert_array_equal(again, fresh)
        again[:] = -1.0  # a caller's copy, not the kept rows
        np.testing.assert_array_equal(
            reach(scene.plant, scene.ctx, hand, finger, inspector), fresh
        )
    # A finger geometry grows in this context: the kept rows are stale.
    finger = hand.fingers[0]
    _, gf, _ = finger.tip_pairs[0]
    sg_context = scene.scene_graph.GetMyMutableContextFromRoot(scene.root)
    before = reach(scene.plant, scene.ctx, hand, finger, inspector)
    scene.scene_graph.ChangeShape(
        sg_context, scene.plant.get_source_id(), gf, Box(0.2, 0.2, 0.2)
    )
    inspector = query_object_of(scene.plant, scene.ctx).inspector()
    after = reach(scene.plant, scene.ctx, hand, finger, inspector)
    fresh, _ = _reach(scene.plant, scene.ctx, hand, finger, inspector)
    np.testing.assert_array_equal(after, fresh)
    assert np.any(after > before)
