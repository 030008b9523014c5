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


def _jaw_closing_at(tmp_path, closed: float):
    """The flat jaw with its fingers' closed limit at ``closed`` (m) each."""
    import drakegrasp as dg
    from drakegrasp.plant.models import models_dir

    text = (models_dir() / "hands" / "parallel_jaw_flat.sdf").read_text()
    old = "<lower>0.0</lower><upper>0.0425</upper>"
    assert text.count(old) == 2
    hand = tmp_path / f"jaw_{closed}.sdf"
    hand.write_text(text.replace(old, f"<lower>{closed}</lower><upper>0.0425</upper>"))
    return dg.planning_scene("package://drakegrasp/objects/box.sdf", hand_url=str(hand))


@pytest.mark.parametrize("closed, at_limit", [(0.02495, True), (0.0245, False)])
def test_a_finger_closed_on_its_limit_is_rejected(tmp_path, closed, at_limit):
    # A jaw whose pads meet the 50 mm box 0.05 mm before their closed limit
    # was planned as holding (the fuzzer's rod: "squeeze 1.6 N per finger"),
    # yet its motors press on the limits: Drake drops the object at any squeeze.
    from drakegrasp.planning import plan_grasps
    from drakegrasp.plant.contacts import DEFAULT_DISTANCE_TOLERANCE as tol

    scene = _jaw_closing_at(tmp_path, closed)
    plant = scene.plant
    g = parallel_jaw(
        plant, plant.GetMyContextFromRoot(scene.context), scene.object_body, scene.hand
    )
    # independent route: the two pads' travel is the opening above the closed one
    q = g.q_for_opening(0.06)
    assert np.sum(g.travel_left(q)) == pytest.approx(
        g.opening(q) - g.opening([closed, closed]), abs=1e-15
    )
    result = plan_grasps(
        plant, scene.context, scene.object_body, hand=scene.hand, mu=0.5,
        num_candidates=60, seed=0, robustness_samples=4,
    )  # fmt: skip
    assert len(result) > 0  # wider chords, across the box's corners
    assert (result.rejections.get("finger at its closed limit", 0) > 0) is at_limit
    for c in result:
        assert np.min(g.travel_left(c.q_hand)) > tol
