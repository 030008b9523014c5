"""A planning run in which no candidate is force closure says why.

Drake's Franka hand touches a flat face with one fingertip sphere per finger:
two hard point contacts, rank G = 5, never force closure (the torque about the
line through them meets no contact force).  The run must say so and point at
what changes it; with soft fingers the same poses are force closure.
"""

from __future__ import annotations

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.planning import plan_grasps, planning_scene

FRANKA = "package://drake_models/franka_description/urdf/hand.urdf"
SUGAR = "package://drake_models/ycb/004_sugar_box.sdf"


@pytest.fixture(scope="module")
def franka_on_sugar(drake_models_dir):
    return planning_scene(SUGAR, hand_url=FRANKA, models_dir=drake_models_dir)


def _plan(scene, **kw):
    options = dict(hand=scene.hand, num_candidates=60, mu=1.0, seed=0)
    return plan_grasps(scene.plant, scene.context, scene.object_body, **options, **kw)


def test_two_point_contacts_are_explained(franka_on_sugar):
    result = _plan(franka_on_sugar, robustness_samples=4)
    assert len(result) > 0
    assert not any(c.is_closure for c in result)
    # Independent route: the ranks the reason quotes are those of G itself.
    ranks = {np.linalg.matrix_rank(dg.grasp_matrix(c.grasp), tol=1e-9) for c in result}
    assert max(ranks) <= 5
    assert f"rank <= {max(ranks)} < 6" in result.reason
    assert "two point contacts" in result.reason
    assert "soft_finger" in result.reason
    assert result.reason in str(result)
    assert result.to_dict()["reason"] == result.reason


def test_soft_fingers_close_the_same_poses(franka_on_sugar):
    hard = _plan(franka_on_sugar, robustness_samples=0)
    soft = _plan(
        franka_on_sugar,
        robustness_samples=0,
        contact_model="soft_finger",
        torsional_friction=0.5,
    )
    assert {c.sample for c in soft} == {c.sample for c in hard}
    assert all(c.is_closure for c in soft)
    assert soft.reason == ""


def test_soft_fingers_need_torsional_friction(franka_on_sugar):
    with pytest.raises(dg.InvalidOptionError, match="torsional_friction"):
        _plan(franka_on_sugar, contact_model="soft_finger")
