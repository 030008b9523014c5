"""The gripper's geometry read from the plant, checked against Drake's own
kinematics and distance queries."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.math import RigidTransform

from drakegrasp.planning.gripper import parallel_jaw


def _pads_gap(scene, g, q):
    """Distance between the two fingers' pads along the axis, measured with
    Drake's signed distance between the fingers' tip geometries (an
    independent route: the two fingers face each other, nothing between)."""
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context.Clone())
    plant.SetFreeBodyPose(ctx, g.base, RigidTransform())
    for j, v in zip(g.joints, q, strict=True):
        j.set_translation(ctx, float(v))
    query = plant.get_geometry_query_input_port().Eval(ctx)
    return min(
        query.ComputeSignedDistancePairClosestPoints(a, b).distance
        for a in g.pad_geometries[0]
        for b in g.pad_geometries[1]
    )


def test_wsg_geometry(wsg_scene):
    scene = wsg_scene()
    plant = scene.plant
    g = parallel_jaw(
        plant, plant.GetMyContextFromRoot(scene.context), scene.object_body, scene.hand
    )
    assert [len(p) for p in g.pad_geometries] == [4, 4]  # the tip spheres
    axis = g.X_HK.rotation().matrix()[:, 0]
    assert abs(abs(axis[0]) - 1) < 1e-6  # the WSG's fingers slide along its x
    assert 0.10 < g.max_opening < 0.12 and g.min_opening < 0.01
    for w in (0.02, 0.05, 0.09):
        q = g.q_for_opening(w)
        assert g.opening(q) == pytest.approx(w)
        # the tips of a pad face each other: their gap is the opening
        assert _pads_gap(scene, g, q) == pytest.approx(w, abs=1e-9)


def test_own_jaw_geometry(own_scene):
    scene = own_scene()
    plant = scene.plant
    g = parallel_jaw(
        plant, plant.GetMyContextFromRoot(scene.context), scene.object_body, scene.hand
    )
    q = g.q_for_opening(0.06)
    assert np.all((g.lower <= q) & (q <= g.upper))
    assert _pads_gap(scene, g, q) == pytest.approx(0.06, abs=1e-9)
    # the approach runs from the palm to the pads, across the axis
    R = g.X_HK.rotation().matrix()
    assert abs(R[:, 0] @ R[:, 1]) < 1e-12
