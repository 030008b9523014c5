"""analyze_grasp computes its optional parts on first read: the same report as
computing everything at once, on every shipped scene and on real hands."""

from __future__ import annotations

import copy
import json
import pickle

import pytest

from drakegrasp.core.deferred import computed_eagerly, pending
from drakegrasp.plant import DEFAULT_SCENE, analyze_grasp, close_hand

from .conftest import SCENE_NAMES, fresh_context

RESULTS = ("form_closure", "force_closure", "force_closure_exact")
DEFERRABLE = (
    "d_star",
    "margin",
    "contact_forces",
    "solver",
    "status",
    "internal_forces",
    "certificate",
)


def _json(report) -> str:
    return json.dumps(report.to_dict(), sort_keys=True)


def _pending_parts(report) -> list[str]:
    names = [
        f"{r}.{name}"
        for r in RESULTS
        for name in DEFERRABLE
        if pending(getattr(report, r), name)
    ]
    return names + (["second_order"] if pending(report, "second_order") else [])


def _same_report(analyse) -> list[str]:
    """Lazy, eager, pickled-before-read and copied-before-read agree exactly."""
    with computed_eagerly():
        eager = analyse()
    assert _pending_parts(eager) == []
    lazy = analyse()
    deferred = _pending_parts(lazy)
    # Each result pickles, and pickling computes its pending parts.
    fresh = analyse()
    pickled = {
        name: pickle.loads(pickle.dumps(getattr(fresh, name)))
        for name in (*RESULTS, "second_order")
    }
    for name in RESULTS:
        assert [n for n in DEFERRABLE if pending(pickled[name], n)] == []
        assert json.dumps(pickled[name].to_dict(), sort_keys=True) == json.dumps(
            getattr(eager, name).to_dict(), sort_keys=True
        )
    assert str(pickled["second_order"]) == str(eager.second_order)
    fresh = analyse()
    shallow = copy.copy(fresh)  # shares the pending parts
    deep = {name: copy.deepcopy(getattr(fresh, name)) for name in RESULTS}
    text = _json(eager)
    assert _json(lazy) == text
    assert _json(shallow) == text
    for name in RESULTS:
        assert deep[name].to_dict() == getattr(shallow, name).to_dict()
    assert str(analyse()) == str(eager)  # str() alone computes what it shows
    assert _pending_parts(lazy) == []  # to_dict read everything
    return deferred


@pytest.mark.parametrize("name", SCENE_NAMES)
def test_lazy_and_eager_reports_are_identical_on_every_shipped_scene(name, scene_cache):
    scene = scene_cache(name)
    root, ctx = fresh_context(scene)
    options = scene.analysis_options()
    deferred = _same_report(lambda: analyze_grasp(scene.plant, ctx, **options))
    report = analyze_grasp(scene.plant, ctx, **options)
    # Every "no" leaves its certificate for later; verdicts are never deferred.
    for r in RESULTS:
        result = getattr(report, r)
        assert f"{r}.certificate" in deferred
        assert isinstance(result.is_closure, bool) and isinstance(result.rank, int)


def test_the_default_scene_defers_every_program_that_the_rank_decides(scene_cache):
    scene = scene_cache(DEFAULT_SCENE)
    root, ctx = fresh_context(scene)
    report = analyze_grasp(scene.plant, ctx, **scene.analysis_options())
    # two jaws in 3-D: rank 5 < 6 decides all three verdicts "no"
    for r in RESULTS:
        result = getattr(report, r)
        assert result.decided_by == "rank" and not result.is_closure
        assert pending(result, "d_star") and pending(result, "internal_forces") == (
            r != "form_closure"
        )
    assert pending(report, "second_order")
    # Reading d* solves the program then, and keeps its value.
    fc = report.force_closure
    first = fc.d_star
    assert not pending(fc, "d_star") and fc.d_star is first
    with computed_eagerly():
        eager = analyze_grasp(scene.plant, ctx, **scene.analysis_options())
    assert first == eager.force_closure.d_star
    # One LP3 serves both force-closure verdicts, lazily or not.
    assert report.force_closure.internal_forces is (
        report.force_closure_exact.internal_forces
    )


@pytest.mark.parametrize("name", [DEFAULT_SCENE, "parallel_jaw_cylinder"])
def test_a_deferred_part_never_reads_the_plant_after_the_call(
    name, scene_cache, monkeypatch
):
    """Curvatures and contacts are read at the call: a late read works with the
    plant's readers gone and the hand moved."""
    import drakegrasp.plant.analysis as analysis
    import drakegrasp.plant.curvature as curvature

    scene = scene_cache(name)
    root, ctx = fresh_context(scene)
    options = scene.analysis_options()
    with computed_eagerly():
        eager = analyze_grasp(scene.plant, ctx, **options)
    lazy = analyze_grasp(scene.plant, ctx, **options)
    assert pending(lazy, "second_order")

    def gone(*args, **kwargs):
        raise AssertionError("a deferred part read the plant")

    monkeypatch.setattr(analysis, "contact_curvatures", gone)
    monkeypatch.setattr(curvature, "contact_curvatures", gone)
    q = scene.plant.GetPositions(ctx)
    scene.plant.SetPositions(ctx, q + 0.01)  # every joint moves
    assert _json(lazy) == _json(eager)


def test_lazy_and_eager_agree_on_real_hands(real_hands):
    wsg = real_hands.wsg()
    close_hand(wsg.plant, wsg.ctx, wsg.object, hand=wsg.hand)
    _same_report(
        lambda: analyze_grasp(wsg.plant, wsg.ctx, wsg.object, hand=wsg.hand, mu=0.5)
    )
    allegro = real_hands.allegro()
    close_hand(allegro.plant, allegro.root, allegro.object, hand=allegro.hand)
    for mu in (0.1, 1.0):
        _same_report(
            lambda mu=mu: analyze_grasp(
                allegro.plant, allegro.ctx, allegro.object, hand=allegro.hand, mu=mu
            )
        )
