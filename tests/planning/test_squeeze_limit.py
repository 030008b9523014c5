"""A parallel jaw's motors: candidates held within the squeeze rank first.

``with_squeeze_limit`` is checked against a partition written here (stable,
those within the limit first), on real plans; the claim behind it, that a jaw
pressing with less than ``squeeze_needed`` drops the object, against Drake:
Drake's Franka (Panda) hand on the YCB sugar box drops every one of its best
candidates at half their squeeze needed and holds every one at 1.5 times.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning import plan_grasps, planning_scene, shake_test
from drakegrasp.planning.motors import motor_limit, with_squeeze_limit

PANDA = "package://drake_models/franka_description/urdf/panda_hand.urdf"
SUGAR = "package://drake_models/ycb/004_sugar_box.sdf"
ROUNDED = "package://drakegrasp/hands/parallel_jaw.sdf"
SOFT = dict(contact_model="soft_finger", torsional_friction=0.05)


@pytest.fixture(scope="module")
def rounded_on_box():
    """The shipped rounded jaw on the box, soft fingers: squeezes of 4-20 N."""
    scene = planning_scene("package://drakegrasp/objects/box.sdf", hand_url=ROUNDED)
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=0.5, seed=0, robustness_samples=8, **SOFT,
    )  # fmt: skip
    return scene, result


def _partition(candidates, limit):
    """Those with squeeze_needed <= limit, then the rest, each in its order."""
    within = [c for c in candidates if c.squeeze_needed <= limit]
    return within + [c for c in candidates if not c.squeeze_needed <= limit]


def _samples(candidates):
    return [c.sample for c in candidates]


def test_the_shipped_jaw_is_limited_by_its_effort_limits(rounded_on_box):
    scene, result = rounded_on_box
    assert motor_limit(scene.plant, result[0]) == 140.0  # the SDF's <effort>
    # the default plan is already ranked with that limit: a larger
    # squeeze_limit is capped by it and moves nothing
    again = with_squeeze_limit(result, scene.plant, top=10, squeeze_limit=1e6)
    assert _samples(again) == _samples(result)
    assert again.reason == result.reason == ""


@settings(max_examples=25, deadline=None, derandomize=True)
@given(fraction=st.floats(0.0, 1.0))
def test_candidates_within_the_limit_come_first_in_order(rounded_on_box, fraction):
    scene, result = rounded_on_box
    needed = sorted(c.squeeze_needed for c in result if np.isfinite(c.squeeze_needed))
    # a limit between the smallest and the largest squeeze needed (never 0)
    limit = max(needed[0] * 0.5, needed[0] + fraction * (needed[-1] - needed[0]))
    shuffled = dataclasses.replace(result, candidates=tuple(result)[::-1])
    ranked = with_squeeze_limit(shuffled, scene.plant, top=3, squeeze_limit=limit)
    assert _samples(ranked) == _samples(_partition(shuffled.candidates, limit))
    assert all(c.closure is not None for c in ranked[:3])  # certified after
    if limit < needed[0]:
        assert f"squeeze_limit {limit:.3g} N holds none" in ranked.reason
        assert f"at least {needed[0]:.3g} N per finger" in ranked.reason
    else:
        assert ranked.reason == ""


def test_plan_grasps_takes_squeeze_limit(rounded_on_box):
    scene, result = rounded_on_box
    limit = result[3].squeeze_needed
    limited = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=0.5, seed=0, robustness_samples=8,
        squeeze_limit=limit, **SOFT,
    )  # fmt: skip
    assert _samples(limited) == _samples(_partition(result.candidates, limit))
    assert limited.settings["squeeze_limit"] == limit
    assert all(c.squeeze_needed <= limit for c in limited[:4])
    # the planner applies the limit, not only records it: below every need,
    # its result says so (the order alone could agree by chance)
    least = min(c.squeeze_needed for c in result if c.is_closure)
    weak = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=0.5, seed=0, robustness_samples=8,
        squeeze_limit=least / 2, **SOFT,
    )  # fmt: skip
    assert f"the jaw at squeeze_limit {least / 2:.3g} N holds none" in weak.reason
    # the summary says which limit ranked the candidates, and how many hold
    first = limited.settings["held_first"]
    held = sum(c.squeeze_needed <= limit for c in limited)
    assert first == dict(needed="squeeze_needed", limit=limit, unit="N per finger",
                         source="squeeze_limit given", held=held)  # fmt: skip
    assert f"ranked first: the {held} with squeeze_needed <= {limit:g} N" in str(
        limited
    )
    assert result.settings["held_first"]["source"] == "effort limit"
    assert "ranked first" not in str(weak)  # none held: the reason says it
    capped = with_squeeze_limit(result, scene.plant, top=10, squeeze_limit=1e6)
    assert capped.settings["held_first"]["source"] == (
        "effort limit (squeeze_limit 1e+06 capped at it)"
    )
    assert capped.settings["held_first"]["limit"] == 140.0


@pytest.mark.parametrize(
    "value", [0, -1.0, math.nan, math.inf, "20", True, [20.0], 10**400]
)
def test_bad_squeeze_limits_are_named(rounded_on_box, value):
    scene, _ = rounded_on_box
    with pytest.raises(InvalidOptionError, match="squeeze_limit"):
        plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=2, mu=0.5, squeeze_limit=value,
        )  # fmt: skip


def test_the_two_limits_name_each_other(rounded_on_box):
    scene, _ = rounded_on_box
    with pytest.raises(InvalidOptionError, match="give squeeze_limit instead"):
        plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=2, mu=0.5, torque_limit=1.0,
        )  # fmt: skip
    with pytest.raises(InvalidOptionError, match="object_mass"):
        plan_grasps(
            scene.plant, scene.context, None, hand=scene.hand, num_candidates=2,
            mu=0.5, squeeze_limit=5.0, point_cloud=np.zeros((10, 3)),
        )  # fmt: skip


def test_a_multi_finger_hand_refuses_squeeze_limit():
    scene = planning_scene(
        "package://drakegrasp/objects/sphere.sdf",
        hand_url="package://drakegrasp/hands/three_finger_hand.sdf",
    )
    with pytest.raises(InvalidOptionError, match="give torque_limit"):
        plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=2, mu=0.5, squeeze_limit=5.0,
        )  # fmt: skip


def test_a_jaw_below_its_squeeze_needed_drops_the_object(drake_models_dir):
    # Drake's Franka hand: 20 N effort limits, four 1 mm pad spheres and a
    # 9 mm sphere per finger; mu = 1 is the plant's (what Drake simulates)
    scene = planning_scene(SUGAR, hand_url=PANDA, models_dir=drake_models_dir)
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=300, mu=1.0, seed=0,
    )  # fmt: skip
    best = list(result[:3])
    needed = np.array([c.squeeze_needed for c in best])
    assert np.all(needed < 20.0) and result.reason == ""
    weak = with_squeeze_limit(
        result, scene.plant, top=3, squeeze_limit=needed.min() / 2
    )
    assert "holds none" in weak.reason
    for candidate, squeeze in zip(best, needed, strict=True):
        low = shake_test(scene.add_models, candidate, squeeze=0.5 * squeeze)
        high = shake_test(scene.add_models, candidate, squeeze=1.5 * squeeze)
        assert not low.held_from_seat, (candidate.sample, str(low))
        assert high.held_from_seat, (candidate.sample, str(high))


def test_a_palm_contact_does_not_lower_the_squeeze_needed(drake_models_dir):
    # Drake's Franka hand on the cracker box: one of the best candidates
    # rests an edge of the box on the welded palm.  Counted as a third
    # squeezed finger, the palm made it hold at 11.8 N a finger and rank
    # first; in Drake it drops at the fingers' full 20 N.  A passive palm
    # (weight_capacity(palm=2)) asks for more than 20 N, as Drake does.
    scene = planning_scene(
        "package://drake_models/ycb/003_cracker_box.sdf", hand_url=PANDA,
        models_dir=drake_models_dir,
    )  # fmt: skip
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=300, mu=1.0, seed=0,
    )  # fmt: skip
    palm = "panda_hand::panda_hand"
    on_palm = [c for c in result[:10] if any(k.finger_body == palm for k in c.contacts)]
    assert on_palm, [c.sample for c in result[:10]]
    limit = motor_limit(scene.plant, result[0])
    for candidate in on_palm:
        assert candidate.squeeze_needed > limit, candidate.sample
        shaken = shake_test(scene.add_models, candidate, squeeze=limit)
        assert not shaken.held_from_seat, (candidate.sample, str(shaken))
    # and those within the limit rank ahead of it
    first = [c.squeeze_needed <= limit for c in result[:10]]
    assert first == sorted(first, reverse=True)
