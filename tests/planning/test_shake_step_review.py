"""``time_step=None`` picks a step that resolves the shake's phases too.

A given ``time_step`` longer than a tenth of ``phase`` is refused
(``InvalidOptionError``); ``time_step=None``, the default, skipped that check
and shook short phases at 1 ms: ``phase=0.005`` ran at 1 ms, five steps a
phase, which a given step of 1 ms is refused for.  Checked in Drake: the step
the simulation ran at is ``ShakeResult.time_step``.
"""

from __future__ import annotations

import math

import pytest

from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning import plan_grasps, planning_scene, shake_test

BOX = "package://drakegrasp/objects/box.sdf"
FLAT = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
SHORT = {
    "phase": 0.005, "settle": 0.01, "seat": 0.05, "blend": 0.002,
    "directions": [[1.0, 0.0, 0.0]], "hydroelastic_modulus": 1e6,
}  # fmt: skip
pytestmark = pytest.mark.filterwarnings(
    "ignore::drakegrasp.plant.friction.FrictionMismatchWarning"
)


@pytest.fixture(scope="module")
def planned():
    scene = planning_scene(BOX, hand_url=FLAT)
    plan = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=10, seed=0, mu=0.5,
    )  # fmt: skip
    assert len(plan)
    return scene, plan[0]


def test_a_given_step_past_a_tenth_of_a_phase_is_refused(planned):
    scene, candidate = planned
    with pytest.raises(InvalidOptionError, match="a tenth of a phase"):
        shake_test(scene.add_models, candidate, time_step=1e-3, **SHORT)


def test_the_picked_step_is_within_a_tenth_of_a_phase(planned):
    scene, candidate = planned
    result = shake_test(scene.add_models, candidate, **SHORT)
    # compliant patches have no contact period to resolve, so the tenth of a
    # phase alone sets the step: neither the 1 ms default nor anything finer
    assert math.isinf(result.contact_period)
    assert result.time_step == SHORT["phase"] / 10


def test_the_default_phase_keeps_the_default_step(planned):
    scene, candidate = planned
    result = shake_test(scene.add_models, candidate, **{**SHORT, "phase": 0.05})
    assert result.time_step == 1e-3
