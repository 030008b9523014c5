"""The planner weighs the object with the plant's own gravity, as analyze_grasp does.

``plan_grasps`` multiplied the mass by a hard-coded 9.81 m/s², while
``analyze_grasp(load="gravity")`` reads ``plant.gravity_field()``: on a moon
plant (1.62 m/s²) the plan's ``squeeze_needed`` and ``torque_needed`` were
those of the Earth, six times the weight the analysis of the same grasp puts
on it.  Both now use ``|g|`` of the plant's field.

The relation, derived: ``squeeze_needed = m |g| / α_min`` and ``torque_needed
= m |g| / β_min``, where the capacities ``α`` and ``β`` are LPs over unit
weight directions (no ``g`` in them), so between two plants that differ only
in gravity the candidates, capacities and scores are the same and both figures
scale by ``|g_1| / |g_2|``.  The analysis' load ``m g_W`` scales alike, so its
payload factor (the multiple of the load held at given limits) scales by the
inverse ratio, and the planner's figure over the squeeze the analysis needs
for the same weight is the same on both plants.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drakegrasp import analyze_grasp
from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.planning.turned_gravity import GRAVITY, plant_gravity

FLAT = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
THREE = "package://drakegrasp/hands/three_finger_hand.sdf"
THREE_OPEN = [-0.4, 0.0, 0.0] * 3  # as tests/planning/test_multifinger.py
MOON = (0.0, 0.0, -1.62)


def _scene(obj="box", hand=FLAT, gravity=None):
    scene = planning_scene(f"package://drakegrasp/objects/{obj}.sdf", hand_url=hand)
    if gravity is not None:  # a finalized plant's field can still be set
        scene.plant.mutable_gravity_field().set_gravity_vector(gravity)
    return scene


def _plan(scene, **kw):
    kw = {"num_candidates": 40, "mu": 0.5, "robustness_samples": 4, **kw}
    return plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand, seed=0, **kw
    )


@pytest.fixture(scope="module")
def jaw_plans():
    """The flat jaw on the box: (scene, plan) at the default gravity and the moon's."""
    earth, moon = _scene(), _scene(gravity=MOON)
    return (earth, _plan(earth)), (moon, _plan(moon))


def test_plant_gravity_is_the_fields_magnitude():
    assert plant_gravity(_scene().plant) == GRAVITY == 9.81  # to the bit
    assert plant_gravity(_scene(gravity=MOON).plant) == 1.62
    assert plant_gravity(_scene(gravity=(3.0, 0.0, -4.0)).plant) == 5.0
    assert plant_gravity(_scene(gravity=(0.0, 0.0, 0.0)).plant) == 0.0
    assert plant_gravity(_scene(gravity=(1e200, 1e200, 0.0)).plant) == pytest.approx(
        math.sqrt(2) * 1e200
    )
    for bad in ((0.0, 0.0, math.inf), (math.nan, 0.0, -9.81)):
        with pytest.raises(ModelError, match=r"gravity field \[.*\] m/s²"):
            plant_gravity(_scene(gravity=bad).plant)


def test_squeeze_needed_scales_with_the_plants_gravity(jaw_plans):
    (_, earth), (_, moon) = jaw_plans
    assert [c.sample for c in moon] == [c.sample for c in earth]
    closed = 0
    for e, m in zip(earth, moon, strict=True):
        # the capacities and the ranking hold no g
        assert np.array_equal(m.weight_capacity, e.weight_capacity, equal_nan=True)
        assert m.score == e.score
        if not np.isfinite(e.weight_capacity) or e.weight_capacity <= 0:
            continue
        closed += 1
        ratio = m.squeeze_needed / e.squeeze_needed
        assert ratio == pytest.approx(1.62 / 9.81, rel=1e-14)
    assert closed >= 5
    print(f"moon/earth squeeze_needed of {closed} candidates: {ratio!r}")


def test_the_plan_holds_the_weight_analyze_grasp_puts_on_the_same_plant(jaw_plans):
    """On each plant, the weight behind ``squeeze_needed`` is the norm of the
    analysis' gravity load, and at ``squeeze_needed`` per finger the analysis
    holds that load; the planner's figure over the squeeze the analysis needs
    (for the plant's own gravity direction) is the same on both plants."""
    over = []
    for scene, result in jaw_plans:
        candidate = result[0]
        ctx = scene.context.Clone()
        candidate.apply(scene.plant, ctx, object_body=scene.object_body)
        mass = scene.object_body.default_mass()

        def load(limit, candidate=candidate, ctx=ctx, scene=scene):
            report = analyze_grasp(
                scene.plant, ctx, scene.object_body, hand=scene.hand, mu=0.5,
                load="gravity", torque_limits="plant",
            ).load  # fmt: skip
            limits = [
                math.inf if name.startswith("free base") else limit
                for name in report.joint_names
            ]
            return analyze_grasp(
                scene.plant, ctx, scene.object_body, hand=scene.hand, mu=0.5,
                load="gravity", torque_limits=limits,
            ).load  # fmt: skip

        g = plant_gravity(scene.plant)
        at_one = load(1.0)  # 1 N per finger
        weight = float(np.linalg.norm(at_one.wrench[:3]))
        assert weight == pytest.approx(mass * g, rel=1e-12)
        planned = candidate.squeeze_needed * candidate.weight_capacity
        assert planned == pytest.approx(weight, rel=1e-12)
        assert load(1.001 * candidate.squeeze_needed).holds
        needed_by_analysis = 1.0 / at_one.payload.alpha  # N per finger
        assert candidate.squeeze_needed >= needed_by_analysis * (1 - 1e-6)
        over.append(candidate.squeeze_needed / needed_by_analysis)
    assert over[1] == pytest.approx(over[0], rel=1e-6)
    print(f"squeeze_needed over the analysis' squeeze, earth and moon: {over}")


def test_torque_needed_scales_with_the_plants_gravity():
    plans = []
    for gravity in (None, MOON):
        scene = _scene("cylinder", THREE, gravity)
        plans.append(_plan(scene, preshape=THREE_OPEN, mu=1.0, robustness_samples=8))
    earth, moon = plans
    # the same candidates; those whose torque the motors give come first,
    # which on the moon are more of them: compare sample by sample
    by_sample = {c.sample: c for c in earth}
    assert sorted(by_sample) == sorted(c.sample for c in moon)
    figures = [
        (by_sample[m.sample].torque_needed, m.torque_needed)
        for m in moon
        if np.isfinite(m.torque_needed) and m.torque_needed > 0
    ]
    assert len(figures) >= 3
    for e, m in figures:
        assert m / e == pytest.approx(1.62 / 9.81, rel=1e-14)
    print(f"moon/earth torque_needed of {len(figures)} candidates: {m / e!r}")


def test_a_plant_without_gravity_needs_no_squeeze(jaw_plans):
    """Weight 0 is a legitimate answer: no weight needs no squeeze.  The
    capacities, scores and ranking are the default plant's."""
    (_, earth), _ = jaw_plans
    scene = _scene(gravity=(0.0, 0.0, 0.0))
    result = _plan(scene)
    assert [c.sample for c in result] == [c.sample for c in earth]
    assert all(c.squeeze_needed == 0.0 for c in result)
    for c, e in zip(result, earth, strict=True):
        assert np.array_equal(c.weight_capacity, e.weight_capacity, equal_nan=True)
        assert c.score == e.score
    ctx = scene.context.Clone()
    result[0].apply(scene.plant, ctx, object_body=scene.object_body)
    report = analyze_grasp(
        scene.plant, ctx, scene.object_body, hand=scene.hand, mu=0.5, load="gravity"
    )
    assert not np.any(report.load.wrench) and report.load.holds
    three = _scene("cylinder", THREE, (0.0, 0.0, 0.0))
    hand = _plan(three, preshape=THREE_OPEN, mu=1.0, num_candidates=20)
    known = [c.torque_needed for c in hand if not np.isnan(c.torque_needed)]
    assert known and all(t == 0.0 for t in known)


def test_a_mass_is_weighed_in_the_plants_gravity_before_planning():
    # 1e307 kg weighs 9.81e307 N here, a float; in 20 m/s², 2e308 N, none
    assert len(_plan(_scene(), num_candidates=2, object_mass=1e307)) >= 0
    with pytest.raises(InvalidOptionError, match=r"1e\+307 kg.*gravity, 20 m/s²"):
        _plan(_scene(gravity=(0.0, 0.0, -20.0)), object_mass=1e307)
    with pytest.raises(ModelError, match="gravity field"):
        _plan(_scene(gravity=(0.0, math.inf, 0.0)))
    # the body's own 10 kg in 1.7e308 m/s²: refused before the closing, too
    scene = _scene(gravity=(0.0, 0.0, -1.7e308))
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    scene.object_body.SetMass(ctx, 10.0)
    with pytest.raises(ModelError, match=r"10 kg, weighs more.*1\.7e\+308 m/s²"):
        _plan(scene)
