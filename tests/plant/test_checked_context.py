"""One analysis checks its plant and context once, and nothing else is trusted.

``analyze_grasp`` used to validate the same context five times (contacts,
both Jacobians, curvatures, the call itself); inside
:func:`~drakegrasp.plant.validation.checked_context` the steps reuse the check.
"""

from __future__ import annotations

import sys

import pytest

import drakegrasp as dg
from drakegrasp.plant.validation import checked_context, plant_context_of


def _count_validations(call) -> int:
    count = 0

    def profile(frame, event, arg):
        nonlocal count
        if event == "c_call" and getattr(arg, "__name__", "") == "ValidateContext":
            count += 1

    sys.setprofile(profile)
    try:
        call()
    finally:
        sys.setprofile(None)
    return count


@pytest.fixture(scope="module")
def scene():
    return dg.load_scene()


def test_one_analysis_validates_the_context_once(scene):
    def analyze():
        report = dg.analyze_grasp(
            scene.plant, scene.plant_context, scene.object_body, hand=scene.hand,
            mu=0.5,
        )  # fmt: skip
        str(report)  # reading every section (second order, load) included

    # the root context is resolved to the plant's: at most two checks there
    assert _count_validations(analyze) == 1
    root = lambda: dg.analyze_grasp(  # noqa: E731
        scene.plant, scene.context, scene.object_body, hand=scene.hand, mu=0.5
    )
    assert _count_validations(root) <= 2


def test_each_step_alone_still_checks_its_context(scene):
    contacts = lambda: dg.plant.find_contacts(  # noqa: E731
        scene.plant, scene.plant_context, object_body=scene.object_body,
        hand=scene.hand,
    )  # fmt: skip
    assert _count_validations(contacts) == 1


def test_another_context_is_checked_inside_the_block(scene):
    other = dg.load_scene()
    with checked_context(scene.plant, scene.plant_context) as ctx:
        assert ctx is scene.plant_context
        assert plant_context_of(scene.plant, ctx) is ctx
        with pytest.raises(dg.InvalidContextError, match="belongs neither"):
            plant_context_of(scene.plant, other.plant_context)
        with pytest.raises(dg.InvalidContextError, match="pydrake Context"):
            plant_context_of(scene.plant, "not a context")
    # outside the block the pair is checked again
    assert _count_validations(lambda: plant_context_of(scene.plant, ctx)) == 1


def test_a_bad_context_is_refused_before_the_block(scene):
    other = dg.load_scene()
    with pytest.raises(dg.InvalidContextError, match="belongs neither"):
        dg.analyze_grasp(
            scene.plant, other.plant_context, scene.object_body, hand=scene.hand,
            mu=0.5,
        )  # fmt: skip
