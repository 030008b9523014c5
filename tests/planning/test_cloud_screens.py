"""The screens that spare a dense cloud's chords leave every answer as it was.

A jaw's closing measures, per finger piece, the cloud points of a ball that
holds the piece's whole sweep, and the collision test every point of a hand
piece's bounding ball by three chords.  ``CloudFingers._in_sweep`` keeps the
points near the sweep's line and ``_maybe_inside`` those inside a hull's box
and faces; both must drop only points whose answer cannot count.
"""

from __future__ import annotations

import numpy as np
import pytest
from cloud_support import box_points
from hypothesis import example, given, settings
from hypothesis import strategies as st
from pydrake.geometry import Box, Convex
from pydrake.math import RigidTransform, RollPitchYaw

from drakegrasp.planning import cloud, plan_grasps, planning_scene
from drakegrasp.planning.surface import piece_of_shape
from drakegrasp.plant.models import models_dir

JAW = "package://drakegrasp/hands/parallel_jaw.sdf"


def _fingerprint(result) -> list:
    rows = []
    for c in result.candidates:
        rows.append(
            (
                c.sample,
                c.X_WH.GetAsMatrix4().tobytes(),
                np.asarray(c.q_hand).tobytes(),
                c.d_star,
                c.epsilon,
                c.robustness,
                tuple(k.p_OC.tobytes() for k in c.contacts),
                tuple(k.psi for k in c.contacts),
            )
        )
    return [result.rejections, rows]


def _compare(scene, monkeypatch):
    def plan():
        return plan_grasps(
            scene.plant, scene.context, None, hand=scene.hand, num_candidates=40,
            mu=0.5, seed=3, robustness_samples=4, point_cloud=box_points(6000, 1),
        )  # fmt: skip

    screened = plan()
    assert len(screened) > 5
    monkeypatch.setattr(cloud.CloudFingers, "_in_sweep", lambda _s, idx, *_: idx)
    monkeypatch.setattr(cloud, "_maybe_inside", lambda _piece, q_G: q_G)
    assert _fingerprint(plan()) == _fingerprint(screened)


@pytest.mark.parametrize(
    "hand", [JAW, "package://drakegrasp/hands/parallel_jaw_flat.sdf"]
)
def test_a_plan_is_bitwise_that_of_every_point_measured(hand, monkeypatch):
    _compare(planning_scene(None, hand_url=hand), monkeypatch)


def test_tip_spheres_fit_the_same_points(drake_models_dir, monkeypatch):
    # the WSG-50's tip spheres meet a quadric fitted to nearby points
    _compare(planning_scene(None, models_dir=drake_models_dir), monkeypatch)


def _pieces():
    box = piece_of_shape(Box(0.02, 0.04, 0.01), RigidTransform([0.01, 0.0, 0.03]))
    mesh = models_dir() / "objects" / "hex_prism.obj"
    prism = piece_of_shape(Convex(str(mesh), 0.5), RigidTransform([0, 0.01, 0]))
    assert box.kind == prism.kind == "hull"
    return [box, prism]


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    rpy=st.tuples(*[st.floats(-3.2, 3.2)] * 3),
    spread=st.sampled_from([0.005, 0.03, 0.1]),
)
@example(seed=2423, rpy=(2.5, 2.25, -0.25), spread=0.1)  # an ulp apart alone
def test_points_dropped_as_outside_have_no_depth(seed, rpy, spread):
    rng = np.random.default_rng(seed)
    R = RollPitchYaw(np.array(rpy)).ToRotationMatrix().matrix()
    for piece in _pieces():
        centre = piece.X_OG.translation()
        q = centre + rng.normal(scale=spread, size=(3000, 3)) @ R
        kept = cloud._maybe_inside(piece, q)
        depth = cloud._depth_inside(piece, q)
        kept_rows = {r.tobytes() for r in kept}
        dropped = np.array([r.tobytes() not in kept_rows for r in q])
        assert np.all(depth[dropped] < 0.0)
        # the same depths: BLAS may round a product in a batch of another
        # size by an ulp (one point alone, 0.00641811 either way, differed)
        np.testing.assert_allclose(
            cloud._depth_inside(piece, kept), depth[~dropped], rtol=1e-12, atol=1e-15
        )


def test_a_nan_point_does_not_blind_the_screen_to_the_deep_ones():
    # the slack is sized from finite coordinates: a NaN one made it NaN,
    # and every point was dropped, the deep ones too
    box = _pieces()[0]  # points in its frame G, whose origin is its centre
    q = np.array([[0.0, 0.0, 0.0], [0.001, 0.0, 0.0], [np.nan, 0.0, 0.0]])
    kept = cloud._maybe_inside(box, q)
    np.testing.assert_array_equal(kept, q[:2])
    assert np.all(cloud._depth_inside(box, kept) > 0.0)
