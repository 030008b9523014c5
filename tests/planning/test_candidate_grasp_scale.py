"""A candidate's grasp answers as the ranking did: one length for ε and torsion.

The planner divides moments by the object's torque scale and bounds a soft
finger's torsion by ``torque_scale · ν · f_n``; ``GraspCandidate.grasp`` once
took the grasp's default length (its farthest contact), so the same soft
finger's torsion was bounded differently: on Drake's Franka hand the planner's
``squeeze_needed`` (14.7 N) was within the 20 N limit and ``grasp_forces`` on
``candidate.grasp`` needed 24.9 N.  Checked here against independent routes:
the single-grasp closure verdict, ``ferrari_canny`` and ``grasp_forces``
(exact per-contact bounds, a second program) in each of the 14 directions.
"""

from __future__ import annotations

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.planning.turned_gravity import plant_gravity
from drakegrasp.planning.weight import WEIGHT_DIRECTIONS

ROUNDED = "package://drakegrasp/hands/parallel_jaw.sdf"


@pytest.fixture(scope="module")
def soft_plan():
    scene = planning_scene("package://drakegrasp/objects/box.sdf", hand_url=ROUNDED)
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=0.5, seed=0, robustness_samples=4,
        contact_model="soft_finger", torsional_friction=0.05,
    )  # fmt: skip
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    return result, scene.object_body.get_mass(ctx) * plant_gravity(scene.plant)


def test_the_grasp_carries_the_runs_torque_scale(soft_plan):
    result, _ = soft_plan
    for candidate in result[:3]:
        grasp = candidate.grasp
        assert candidate.torque_scale == result.torque_scale
        assert grasp.characteristic_length == result.torque_scale
        assert candidate.closure.is_closure == candidate.is_closure
        eps = dg.ferrari_canny(grasp)
        assert eps == pytest.approx(candidate.epsilon, rel=1e-6, abs=1e-9)
    assert result[0].to_dict()["torque_scale"] == result.torque_scale


def test_grasp_forces_on_the_grasp_need_the_planned_squeeze(soft_plan):
    # two contacts, one per finger: the squeeze per finger bounds each
    # contact's normal force.  At squeeze_needed every weight direction is
    # held; a little below, some direction is not.
    result, weight = soft_plan
    candidate = result[0]
    assert candidate.num_contacts == 2 and np.isfinite(candidate.squeeze_needed)
    grasp, squeeze = candidate.grasp, candidate.squeeze_needed

    def held(bound: float) -> list[bool]:
        return [
            dg.grasp_forces(
                grasp, np.r_[weight * u / np.linalg.norm(u), 0.0, 0.0, 0.0],
                cones="polyhedral", max_normal_force=bound,
            ).feasible
            for u in WEIGHT_DIRECTIONS
        ]  # fmt: skip

    assert all(held(1.001 * squeeze))
    assert not all(held(0.99 * squeeze))
