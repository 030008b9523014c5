"""A free hand base (the floating gripper of grasp planning) is held, not passive.

The planner's scenes leave the hand's base free and place it by its pose.  The
load section must not count the base's floating joint as six passive joints
(torque limit 0): every grasp would then fail to hold any load.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.planning import planning_scene
from drakegrasp.plant.load import plant_torque_limits

SUGAR = "package://drake_models/ycb/004_sugar_box.sdf"


@pytest.fixture(scope="module")
def free_wsg_on_sugar(drake_models_dir):
    scene = planning_scene(SUGAR, models_dir=drake_models_dir)
    plan = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=1.0, seed=0, robustness_samples=0,
    )  # fmt: skip
    best = next(c for c in plan if c.is_closure)
    best.apply(scene.plant, scene.context)
    return scene


def test_floating_base_velocities_are_unbounded(free_wsg_on_sugar):
    s = free_wsg_on_sugar
    report = dg.analyze_grasp(
        s.plant, s.context, s.object_body, hand=s.hand, mu=1.0,
        load="gravity", torque_limits="plant",
    )  # fmt: skip
    v = report.data.hand_velocity_indices
    limits = plant_torque_limits(s.plant, v)
    floating = [
        s.plant.get_joint(j)
        for j in s.plant.GetJointIndices()
        if s.plant.get_joint(j).type_name() == "quaternion_floating"
        and s.plant.get_joint(j).child_body().model_instance()
        != s.object_body.model_instance()
    ]
    (base,) = floating
    on_base = np.isin(v, base.velocity_start() + np.arange(6))
    assert on_base.sum() == 6
    assert np.all(np.isinf(limits[on_base]))
    np.testing.assert_array_equal(limits[~on_base], [80.0, 80.0])  # the SDF's
    load = report.load
    assert load.holds
    assert load.payload.alpha > 1.0
    # Independent route: the same limits typed by hand give the same payload.
    given = dg.analyze_grasp(
        s.plant, s.context, s.object_body, hand=s.hand, mu=1.0, load="gravity",
        torque_limits=np.where(on_base, math.inf, 80.0),
    )  # fmt: skip
    assert given.load.payload.alpha == pytest.approx(load.payload.alpha, rel=1e-9)
    # and a passive base (0) is what made every grasp fail before
    passive = dg.analyze_grasp(
        s.plant, s.context, s.object_body, hand=s.hand, mu=1.0, load="gravity",
        torque_limits=np.where(on_base, 0.0, 80.0),
    )  # fmt: skip
    assert not passive.load.holds
