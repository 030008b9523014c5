"""A candidate is shaken with the object it was planned on, or refused.

A candidate planned on the box and shaken with an ``add_models`` that builds
a cylinder was reported "held": the shake checked the hand, not the object.
The second route is the geometry: the fingers' distance to the shaken object
at the candidate's poses.
"""

from __future__ import annotations

import pytest

import drakegrasp as dg

FLAT = "package://drakegrasp/hands/parallel_jaw_flat.sdf"


@pytest.fixture(scope="module")
def box_candidate():
    box = dg.planning_scene("package://drakegrasp/objects/box.sdf", hand_url=FLAT)
    result = dg.plan_grasps(
        box.plant, box.context, box.object_body, hand=box.hand,
        num_candidates=20, mu=0.5, seed=0,
    )  # fmt: skip
    return box, result[0]


def test_another_object_is_refused(box_candidate):
    _, candidate = box_candidate
    cylinder = dg.planning_scene(
        "package://drakegrasp/objects/cylinder.sdf", hand_url=FLAT
    )
    with pytest.raises(
        dg.ModelError, match="shake it with the object and the hand it was planned with"
    ):
        dg.shake_test(
            cylinder.add_models, candidate, squeeze=10.0, directions=[(0.0, 0.0, -1.0)]
        )


def test_the_same_object_is_shaken(box_candidate):
    box, candidate = box_candidate
    result = dg.shake_test(
        box.add_models, candidate, squeeze=10.0, directions=[(0.0, 0.0, -1.0)]
    )
    assert result.held
