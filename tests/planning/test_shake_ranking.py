"""Ranking by physics: ``shake_candidates`` shakes the planner's best and puts
those that held first; ``ShakeResult.held_from_seat`` counts from the seat."""

from __future__ import annotations

import dataclasses
import itertools
import json

import numpy as np
import pytest
from allegro_support import allegro_scene, has_thumb

import drakegrasp as dg
from drakegrasp.errors import (
    InvalidGraspError,
    InvalidOptionError,
    ModelError,
    SolverError,
)
from drakegrasp.planning.shake import ShakeResult

JAW = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
THREE = "package://drakegrasp/hands/three_finger_hand.sdf"
THREE_OPEN = [-0.4, 0.0, 0.0] * 3
SHORT = dict(settle=0.05, phase=0.05, blend=0.02, seat=0.05, directions=[(1, 0, 0)])


def _result(**kw) -> ShakeResult:
    base = dict(
        held=False, max_displacement=0.02, max_rotation=0.3, phases=(), squeeze=1.0,
        efforts=(), time_step=1e-3, duration=1.0, wall_time=0.1, bounds=(0.01, 0.1),
    )  # fmt: skip
    return ShakeResult(**{**base, **kw})


@pytest.mark.parametrize(
    ("kw", "held"),
    [
        # seated 20 mm off the plan (held: False), then still: held once seated
        (dict(max_displacement_from_seat=0.004, max_rotation_from_seat=0.05), True),
        # on the bounds: held (the bounds are inclusive, as ``held``'s)
        (dict(max_displacement_from_seat=0.01, max_rotation_from_seat=0.1), True),
        (dict(max_displacement_from_seat=0.0101, max_rotation_from_seat=0.0), False),
        (dict(max_displacement_from_seat=0.0, max_rotation_from_seat=0.11), False),
        # seat=0: nothing seated, it is ``held``
        (dict(), False),
        (dict(held=True, max_displacement=0.001, max_rotation=0.01), True),
    ],
)
def test_held_from_seat_counts_from_where_seating_left_the_object(kw, held):
    result = _result(**kw)
    assert result.held_from_seat is held
    assert result.to_dict()["held_from_seat"] is held


@pytest.fixture(scope="module")
def jaw():
    """The flat jaw on the shipped box: planned, best first."""
    scene = dg.planning_scene("package://drakegrasp/objects/box.sdf", hand_url=JAW)
    result = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, mu=1.0, seed=0, robustness_samples=4,
    )  # fmt: skip
    assert len(result) >= 6
    return scene, result


def test_each_verdict_is_the_shake_tests_and_held_ones_come_first(jaw):
    """An independent route: each candidate shaken alone with ``shake_test``.
    The ranking is a stable partition of the given order: held, then dropped.
    The list mixes the planner's best with grasps from its tail, so that both
    groups are present (at this squeeze, the second best and the second last
    turn past 10 degrees)."""
    scene, result = jaw
    given = [result[0], result[-1], result[1], result[-2], result[2]]
    opts = dict(squeeze=5.0, **SHORT)
    ranked = dg.shake_candidates(scene.add_models, given, top=5, **opts)
    alone = [dg.shake_test(scene.add_models, c, **opts) for c in given]
    assert len(ranked) == 5
    by_rank = {s.planned_rank: s for s in ranked}
    assert sorted(by_rank) == list(range(5))
    for k, result_alone in enumerate(alone):
        s = by_rank[k]
        assert s.candidate is given[k]
        assert s.held is result_alone.held_from_seat
        assert s.result.max_displacement == result_alone.max_displacement
        assert s.result.max_rotation_from_seat == result_alone.max_rotation_from_seat
    held = [s.planned_rank for s in ranked if s.held]
    dropped = [s.planned_rank for s in ranked if not s.held]
    assert held and dropped, "the case must mix held and dropped grasps"
    assert [s.planned_rank for s in ranked] == held + dropped
    assert held == sorted(held) and dropped == sorted(dropped)
    assert ranked.held == tuple(given[k] for k in held)
    assert ranked.best is given[held[0]]
    text = str(ranked)
    assert text.startswith(f"{len(held)} of 5 shaken candidates held")
    assert json.loads(json.dumps(ranked.to_dict()))["options"]["squeeze"] == 5.0


def test_held_from_plan_uses_held(jaw):
    scene, result = jaw
    ranked = dg.shake_candidates(
        scene.add_models, result, top=2, held_from="plan", squeeze=5.0, **SHORT
    )
    assert [s.held for s in ranked] == [s.result.held for s in ranked]
    assert ranked.held_from == "plan"


def test_top_takes_the_first_candidates_and_reads_an_iterator_no_further(jaw):
    scene, result = jaw
    ranked = dg.shake_candidates(scene.add_models, result, top=2, **SHORT)
    assert {s.candidate.sample for s in ranked} == {result[0].sample, result[1].sample}
    endless = itertools.repeat(result[0])
    ranked = dg.shake_candidates(scene.add_models, endless, top=1, **SHORT)
    assert len(ranked) == 1
    assert next(endless) is result[0]  # still usable: read one deep


def test_a_candidate_drake_cannot_simulate_is_recorded_and_the_rest_are_shaken():
    """Gains far too stiff for the three-finger hand (Drake's SAP solver
    diverges): each such candidate is recorded with its one-line error, last,
    and the run goes on."""
    scene = dg.planning_scene(
        "package://drakegrasp/objects/cylinder.sdf", hand_url=THREE
    )
    result = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=20, mu=1.0, seed=3, robustness_samples=4, preshape=THREE_OPEN,
    )  # fmt: skip
    assert len(result) >= 2
    ranked = dg.shake_candidates(
        scene.add_models, result, top=2, stiffness=1e7, damping=1e4, **SHORT
    )
    assert len(ranked) == 2
    for s in ranked:
        assert s.result is None and not s.held
        assert "converge" in s.error and "\n" not in s.error
        assert "not simulated" in str(s)
    assert ranked.best is None
    with pytest.raises(SolverError):  # the same candidate, alone
        dg.shake_test(scene.add_models, result[0], stiffness=1e7, damping=1e4, **SHORT)


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        (dict(top=0), "top must be"),
        (dict(top=True), "top must be"),
        (dict(top=2.0), "top must be"),
        (dict(top=10_001), "top must be"),
        (dict(held_from="object"), "held_from must be"),
        (dict(held_from=np.array(["seat"])), "held_from must be"),
        (dict(squeeze=10**400), "squeeze must be"),
        (dict(hydroelastic_modulus=1e20), "hydroelastic_modulus must be"),
        (dict(stifness=10.0), "unknown option stifness="),
        (dict(squeeze=-1.0), "squeeze must be"),
        (dict(directions=[(0, 0, 0)]), "directions must be"),
        (dict(X_WO=np.eye(4)), "X_WO"),
    ],
)
def test_bad_options_are_refused_before_anything_is_simulated(jaw, kw, match):
    scene, _ = jaw

    def models(plant, parser):  # never called: nothing is simulated
        raise AssertionError("simulated")

    with pytest.raises(InvalidOptionError, match=match):
        dg.shake_candidates(models, [], **kw)


@pytest.mark.parametrize("candidates", ["abc", None, 3, [object()]])
def test_what_is_not_candidates_is_refused(jaw, candidates):
    scene, _ = jaw
    with pytest.raises(InvalidOptionError, match="candidates"):
        dg.shake_candidates(scene.add_models, candidates)


def test_one_candidate_is_pointed_to_shake_test(jaw):
    scene, result = jaw
    with pytest.raises(InvalidOptionError, match="shake_test"):
        dg.shake_candidates(scene.add_models, result[0])


def test_the_allegro_hands_thumbless_grasps_drop_and_its_best_holder_has_the_thumb(
    drake_models_dir,
):
    """The YCB soup can, Allegro hand (thumb opposed), ``mu=1``, seed 0: three
    thumbless force-closure grasps, whose squeeze pushes the can out of the
    hand (a seat-only simulation measured it in round 23), were ranked among
    the planner's first 20 (13, 14 and 18) until their ``squeeze_push`` put
    them after every other force-closure candidate (now 25-33).  Shaken at
    the hand's own limit of 0.7 N·m, each still drops; the best that held has
    the thumb, and most of the first 20, all with the thumb, hold (14; 10 of
    the 17 with the thumb before).  A short shake (two gravity directions)
    keeps the test to about 10 s."""
    from drakegrasp.planning.opposition import SQUEEZE_PUSH_MAX

    scene = allegro_scene("005_tomato_soup_can", drake_models_dir)
    result = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=150, mu=1.0, seed=0,
    )  # fmt: skip
    gains = dict(
        squeeze=0.7, stiffness=10.0, damping=0.1, settle=0.2, phase=0.3,
        directions=[(1, 0, 0), (0, 0, 1)],
    )  # fmt: skip
    ranked = dg.shake_candidates(scene.add_models, result, top=20, **gains)
    assert all(has_thumb(s.candidate) for s in ranked)  # none is thumbless now
    thumbless = [c for c in result if c.is_closure and not has_thumb(c)]
    assert len(thumbless) >= 2
    assert all(c.squeeze_push > SQUEEZE_PUSH_MAX for c in thumbless[:3])
    assert all(result.candidates.index(c) >= 20 for c in thumbless)
    pushed = dg.shake_candidates(scene.add_models, thumbless, top=3, **gains)
    assert not any(s.held for s in pushed)
    assert ranked.best is not None and has_thumb(ranked.best)
    assert len(ranked.held) >= 5


def test_an_edited_candidate_is_refused_by_place_before_any_is_simulated(jaw):
    _, result = jaw
    edited = dataclasses.replace(result[2], q_hand=np.array([np.nan, 0.01]))

    def models(plant, parser):  # never called: nothing is simulated
        raise AssertionError("simulated")

    with pytest.raises(InvalidGraspError, match=r"candidates\[2\]: .*q_hand"):
        dg.shake_candidates(models, [result[0], result[1], edited])


def test_a_model_error_past_the_first_candidate_is_recorded_not_raised(jaw):
    """A candidate of another hand among the jaw's: the first is shaken, the
    stranger recorded as not simulated with its one line, and a stranger
    first raises (the models and the candidates do not match)."""
    scene, result = jaw
    three = dg.planning_scene(
        "package://drakegrasp/objects/cylinder.sdf", hand_url=THREE
    )
    stranger = dg.plan_grasps(
        three.plant, three.context, three.object_body, hand=three.hand,
        num_candidates=20, mu=1.0, seed=3, robustness_samples=4, preshape=THREE_OPEN,
    )[0]  # fmt: skip
    ranked = dg.shake_candidates(scene.add_models, [result[0], stranger], **SHORT)
    assert len(ranked) == 2
    last = ranked[-1]
    assert last.candidate is stranger and last.result is None and not last.held
    assert last.error and "\n" not in last.error
    assert ranked[0].result is not None
    with pytest.raises(ModelError):
        dg.shake_candidates(scene.add_models, [stranger, result[0]], **SHORT)


def test_add_models_that_returns_no_pair_is_a_model_error(jaw):
    _, result = jaw
    with pytest.raises(
        ModelError, match=r"add_models must return \(hand, object_body\)"
    ):
        dg.shake_test(lambda plant, parser: None, result[0], **SHORT)


def test_held_from_chooses_the_count_and_the_groups_keep_the_plans_order(
    jaw, monkeypatch
):
    """Results where the two counts disagree (dropped from the plan, still once
    seated) and one Drake could not simulate, without simulating: the jaw's
    real shakes agree in both counts, so they cannot tell the two apart."""
    import drakegrasp.planning.shake_ranking as ranking

    scene, result = jaw
    given = list(result[:5])

    def fake(add_models, candidate, **options):
        k = given.index(candidate)
        if k == 3:
            raise SolverError("stopped at t = 0.1 s (did not converge)")
        return _result(
            held=k == 4,
            max_displacement_from_seat=0.001 if k in (1, 2) else 0.05,
            max_rotation_from_seat=0.0,
        )

    monkeypatch.setattr(ranking, "shake_test", fake)
    seat = dg.shake_candidates(scene.add_models, given, top=5)
    plan = dg.shake_candidates(scene.add_models, given, top=5, held_from="plan")
    assert [(s.planned_rank, s.held) for s in seat] == [
        (1, True), (2, True), (0, False), (4, False), (3, False)
    ]  # fmt: skip
    assert [(s.planned_rank, s.held) for s in plan] == [
        (4, True), (0, False), (1, False), (2, False), (3, False)
    ]  # fmt: skip
    assert seat.best is given[1] and plan.best is given[4]
    assert seat[-1].result is None and "converge" in seat[-1].error
