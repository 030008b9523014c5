"""Deferred result fields: computed once on first read, identical to eager results."""

from __future__ import annotations

import copy
import json
import pickle

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from random_grasps import random_inward_contacts

import drakegrasp as dg
from drakegrasp.closure.results import ClosureResult
from drakegrasp.core import examples as ex
from drakegrasp.core.deferred import (
    Deferred,
    computed_eagerly,
    defer,
    parts,
    pending,
    replace,
    resolve,
)

SETTINGS = settings(
    max_examples=30,
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)


class Counter:
    def __init__(self, value=2.5):
        self.calls = 0
        self.value = value

    def __call__(self):
        self.calls += 1
        return self.value


def _result(d_star) -> ClosureResult:
    return ClosureResult(
        kind="force closure",
        is_closure=False,
        d_star=d_star,
        rank=5,
        required_rank=6,
        margin=0.0,
        contact_forces=(),
        solver="Clp",
        status="kSolutionFound",
        tol=1e-6,
        formulation="facets",
        frictional_closure=False,
        decided_by="rank",
    )


def test_a_deferred_field_is_computed_once_on_first_read():
    count = Counter()
    r = _result(Deferred(count))
    assert count.calls == 0 and pending(r, "d_star")
    assert r.d_star == 2.5 and r.d_star == 2.5
    assert count.calls == 1 and not pending(r, "d_star")
    assert not pending(r, "rank")  # a plain field is never pending


def test_replace_keeps_pending_fields_pending_and_dataclasses_replace_computes():
    import dataclasses

    count = Counter()
    r = _result(Deferred(count))
    kept = replace(r, is_closure=False, decided_by="rank")
    assert pending(kept, "d_star") and count.calls == 0
    assert kept.d_star == 2.5 and count.calls == 1
    assert r.d_star == 2.5 and count.calls == 1  # the same Deferred, shared
    computed = dataclasses.replace(_result(Deferred(Counter(1.0))))
    assert not pending(computed, "d_star") and computed.d_star == 1.0
    with pytest.raises(TypeError, match="no fields"):
        replace(r, nonsense=1)


def test_pickle_and_copies_compute_pending_values():
    count = Counter()
    r = _result(Deferred(count))
    back = pickle.loads(pickle.dumps(r))
    assert count.calls == 1 and not pending(back, "d_star") and back.d_star == 2.5
    deep = copy.deepcopy(_result(Deferred(Counter(3.0))))
    assert not pending(deep, "d_star") and deep.d_star == 3.0


def test_an_exception_is_raised_at_each_read_and_never_kept():
    calls = []

    def failing():
        calls.append(1)
        raise dg.SolverError("boom")

    r = _result(Deferred(failing))
    for _ in range(2):
        with pytest.raises(dg.SolverError, match="boom"):
            _ = r.d_star
    assert len(calls) == 2 and pending(r, "d_star")


def test_defer_parts_and_resolve():
    d = defer(lambda: (1, 2, 3))
    a, b, c = parts(d, 3)
    assert isinstance(a, Deferred) and not d.done
    assert resolve(b) == 2 and d.done and resolve(c) == 3
    assert parts((4, 5), 2) == (4, 5) and resolve(7) == 7
    with pytest.raises(ValueError, match="expected 3"):
        parts((1, 2), 3)
    with computed_eagerly():
        assert defer(lambda: 9) == 9
    assert isinstance(defer(lambda: 9), Deferred)
    assert "pending" in repr(Deferred(int)) and repr(d) == "Deferred((1, 2, 3))"


def _grasp(seed, num, model, mu, dim=3):
    rng = np.random.default_rng(seed)
    contacts = random_inward_contacts(rng, num, dim, mu=mu, model=model, nu=0.3)
    return dg.Grasp(contacts, reference_point=0.2 * rng.normal(size=dim))


def _verdicts(grasp, J):
    return {
        "form": dg.form_closure(grasp),
        "poly": dg.force_closure(grasp, hand_jacobian=J),
        "exact": dg.force_closure_exact(grasp, hand_jacobian=J),
    }


def _text(results) -> dict:
    return {k: json.dumps(r.to_dict(), sort_keys=True) for k, r in results.items()}


@SETTINGS
@given(
    seed=st.integers(0, 2**32 - 1),
    num=st.integers(2, 5),
    model=st.sampled_from(["hard_finger", "soft_finger", "frictionless"]),
    mu=st.sampled_from([0.0, 0.3, 1.0]),
    dim=st.sampled_from([2, 3]),
)
def test_lazy_and_eager_verdicts_are_identical(seed, num, model, mu, dim):
    if dim == 2 and model == "soft_finger":
        model = "hard_finger"
    grasp = _grasp(seed, num, model, mu, dim)
    rng = np.random.default_rng(seed + 1)
    J = rng.normal(size=(grasp.num_components, int(rng.integers(1, 4))))
    with computed_eagerly():
        eager = _verdicts(grasp, J)
    lazy = _verdicts(grasp, J)
    for name, r in lazy.items():
        e = eager[name]
        assert (r.is_closure, r.rank, r.decided_by, r.frictional_closure) == (
            e.is_closure,
            e.rank,
            e.decided_by,
            e.frictional_closure,
        )
        if r.rank < r.required_rank:  # the rank decided: its program waits
            assert pending(r, "d_star") and not r.is_closure
    assert _text(lazy) == _text(eager)
    assert str(lazy["poly"]) == str(eager["poly"])


def test_textbook_grasps_lazy_and_eager():
    grasps = [
        ex.spatial_two_fingers(0.5),
        ex.equator_fingers(0.5, num_fingers=3),
        ex.cube_seven_contacts(),
        ex.planar_square_four_contacts(),
        ex.planar_two_finger_square(0.5),
    ]
    for g in grasps:
        J = np.eye(g.num_components)[:, :2]
        with computed_eagerly():
            eager = _verdicts(g, J)
        assert _text(_verdicts(g, J)) == _text(eager)


def test_a_bad_hand_jacobian_is_refused_at_once_even_when_lp3_waits():
    g = ex.spatial_two_fingers(0.5)  # rank 5: LP3 would wait
    with pytest.raises(dg.GraspError, match="hand_jacobian must have shape"):
        dg.force_closure(g, hand_jacobian=np.ones((2, 2)))


def test_a_result_pickled_before_deferred_fields_still_reads():
    """Older pickles stored every field under its own name in ``__dict__``."""
    plain = dg.force_closure(ex.equator_fingers(0.5, num_fingers=3))
    state = {f: getattr(plain, f) for f in plain.__dataclass_fields__}
    old = object.__new__(ClosureResult)
    old.__dict__.update(state)
    assert old.d_star == plain.d_star and old.certificate is not None
    assert old.to_dict() == plain.to_dict()
    assert replace(old, decided_by="d*").to_dict() == plain.to_dict()


def test_what_the_programs_share_per_grasp_goes_with_the_grasp():
    import gc

    import drakegrasp.closure.programs as programs

    gc.collect()
    before = len(programs.PER_GRASP)
    g = ex.equator_fingers(0.5, num_fingers=3)
    r = dg.force_closure(g)
    e = dg.force_closure_exact(g)
    assert len(programs.PER_GRASP) == before + 1
    assert r.rank == e.rank == 6
    del g, r, e
    gc.collect()
    assert len(programs.PER_GRASP) == before


def test_weak_memo_computes_once_per_key_and_never_keeps_an_exception():
    from drakegrasp.core.deferred import WeakMemo

    class Owner:
        pass

    memo, owner, calls = WeakMemo(), Owner(), []

    def compute(value):
        calls.append(value)
        if value is None:
            raise ValueError("no value")
        return value

    assert memo.value(owner, "a", lambda: compute(1)) == 1
    assert memo.value(owner, "a", lambda: compute(2)) == 1  # kept
    assert memo.value(owner, "b", lambda: compute(3)) == 3
    for _ in range(2):
        with pytest.raises(ValueError, match="no value"):
            memo.value(owner, "c", lambda: compute(None))
    assert calls == [1, 3, None, None]
    del owner
    import gc

    gc.collect()
    assert len(memo) == 0
