"""BatchOptions: the batch engine's choices as one object, checked once.

The same run given as keywords or as ``options=`` is bitwise the same, in
every entry point; an option given both ways, or one an entry point cannot
use, is refused rather than dropped.
"""

from __future__ import annotations

import inspect
import pickle

import numpy as np
import pytest
from batch_support import random_grasps

import drakegrasp as dg
from drakegrasp.batch import (
    BatchOptions,
    batch_epsilon_l1,
    batch_force_closure,
    batch_form_closure,
    evaluate_file,
    stream_force_closure,
    stream_form_closure,
)
from drakegrasp.errors import InvalidContactError, InvalidOptionError

CHOICES = {
    "contact_model": "soft_finger",
    "num_generators": 6,
    "tol": 1e-5,
    "rank_tol": 1e-8,
    "metrics": ("sigma_min", "isotropy"),
    "chunk_size": 7,
    "workers": 1,
}


@pytest.fixture(scope="module")
def grasps():
    P, Nrm = random_grasps(np.random.default_rng(31), 40, 4, 3)
    return P, Nrm


def _same(a, b):
    a, b = a.to_arrays(), b.to_arrays()
    assert a.keys() == b.keys()
    for name in a:
        assert a[name].tobytes() == b[name].tobytes(), name


def test_options_and_keywords_give_bitwise_the_same(grasps):
    P, Nrm = grasps
    options = BatchOptions(**CHOICES)
    kw = {"mu": 0.4, "torsional_friction": 0.2}
    _same(
        batch_force_closure(P, Nrm, **kw, options=options),
        batch_force_closure(P, Nrm, **kw, **CHOICES),
    )
    form = {
        k: v for k, v in CHOICES.items() if k not in ("contact_model", "num_generators")
    }
    _same(
        batch_form_closure(P, Nrm, options=options), batch_form_closure(P, Nrm, **form)
    )
    a = list(stream_force_closure(P, Nrm, **kw, options=options))
    b = list(stream_force_closure(P, Nrm, **kw, **CHOICES))
    assert [s for s, _ in a] == [s for s, _ in b] and len(a) == 6  # chunk_size 7
    for (_, x), (_, y) in zip(a, b, strict=True):
        assert all(x[n].tobytes() == y[n].tobytes() for n in x)
    assert len(list(stream_form_closure(P, Nrm, options=options))) == 6
    eps = {k: CHOICES[k] for k in ("contact_model", "num_generators", "chunk_size")}
    assert np.array_equal(
        batch_epsilon_l1(P, Nrm, **kw, options=BatchOptions(**eps)),
        batch_epsilon_l1(P, Nrm, **kw, **eps),
    )


def test_ragged_input_takes_options_too(grasps):
    P, Nrm = grasps
    ragged_P = [P[0], P[1, :3], P[2]]
    ragged_N = [Nrm[0], Nrm[1, :3], Nrm[2]]
    options = BatchOptions(tol=1e-4, metrics=("sigma_min",))
    _same(
        batch_force_closure(ragged_P, ragged_N, mu=0.5, options=options),
        batch_force_closure(
            ragged_P, ragged_N, mu=0.5, tol=1e-4, metrics=("sigma_min",)
        ),
    )


def test_a_file_run_takes_options(grasps, tmp_path):
    P, Nrm = grasps
    path = tmp_path / "g.npz"
    np.savez(path, positions=P, normals=Nrm)
    options = BatchOptions(tol=1e-5, metrics=("isotropy",), chunk_size=9)
    a = evaluate_file(path, tmp_path / "a.npz", mu=0.5, options=options)
    b = evaluate_file(path, tmp_path / "b.npz", mu=0.5, tol=1e-5,
                      metrics=("isotropy",), chunk_size=9)  # fmt: skip
    _same(a, b)


def test_values_are_checked_when_the_object_is_made():
    o = BatchOptions(contact_model="Soft-Finger", metrics=["epsilon_l1"], workers=2)
    assert o.contact_model is dg.ContactModel.SOFT_FINGER
    assert o.metrics == ("epsilon_l1",) and o.workers == 2
    bad = {
        "contact_model": ("sticky", InvalidContactError, "unknown contact model"),
        "num_generators": (2, InvalidOptionError, "num_generators"),
        "tol": (0.0, InvalidOptionError, "tol"),
        "rank_tol": (float("nan"), InvalidOptionError, "rank_tol"),
        "metrics": (["nope"], InvalidOptionError, "unknown metric"),
        "kernel": ("fast", InvalidOptionError, "kernel"),
        "chunk_size": (0, InvalidOptionError, "chunk_size"),
        "workers": (True, InvalidOptionError, "workers"),
        "progress": ("yes", InvalidOptionError, "progress"),
    }
    for name, (value, error, words) in bad.items():
        with pytest.raises(error, match=words):
            BatchOptions(**{name: value})


def test_frozen_replace_keywords_and_pickle():
    o = BatchOptions(tol=1e-5)
    with pytest.raises(AttributeError):
        o.tol = 1.0
    p = o.replace(num_generators=4)
    assert (p.tol, p.num_generators, o.num_generators) == (1e-5, 4, 8)
    with pytest.raises(InvalidOptionError, match="unknown batch option"):
        o.replace(mu=0.5)
    with pytest.raises(InvalidOptionError, match="num_generators"):
        o.replace(num_generators=1)
    assert BatchOptions(**o.keywords()) == o
    assert pickle.loads(pickle.dumps(p)) == p  # shipped to Dask workers


def test_an_option_given_both_ways_is_refused(grasps):
    P, Nrm = grasps
    with pytest.raises(InvalidOptionError, match=r"\['tol'\] given both"):
        batch_force_closure(P, Nrm, mu=0.5, tol=1e-6, options=BatchOptions())
    with pytest.raises(InvalidOptionError, match="must be a drakegrasp.BatchOptions"):
        batch_force_closure(P, Nrm, mu=0.5, options={"tol": 1e-6})


def test_an_option_an_entry_point_cannot_use_is_refused_not_dropped(grasps, tmp_path):
    P, Nrm = grasps
    path = tmp_path / "g.npz"
    np.savez(path, positions=P, normals=Nrm)
    with pytest.raises(InvalidOptionError, match=r"does not take \['kernel'\]"):
        evaluate_file(path, tmp_path / "o.npz", mu=0.5,
                      options=BatchOptions(kernel="numpy"))  # fmt: skip
    with pytest.raises(InvalidOptionError, match=r"does not take \['tol'\]"):
        batch_epsilon_l1(P, Nrm, mu=0.5, options=BatchOptions(tol=1e-3))
    # defaults it does not take are fine; form closure has no friction options
    evaluate_file(path, tmp_path / "o.npz", mu=0.5, options=BatchOptions())
    batch_form_closure(P, Nrm, options=BatchOptions(contact_model="soft_finger"))


def test_every_entry_point_shows_options_in_its_signature():
    for f in (batch_force_closure, batch_form_closure, stream_force_closure,
              stream_form_closure, batch_epsilon_l1, evaluate_file,
              dg.batch.stream_file):  # fmt: skip
        p = inspect.signature(f).parameters["options"]
        assert p.kind is inspect.Parameter.KEYWORD_ONLY and p.default is None
    assert dg.BatchOptions is BatchOptions


def test_a_fork_bomb_of_workers_is_refused_before_any_fork():
    # The pool forks every worker at once: workers=100000 with chunk_size=1
    # forked one process per chunk, each a copy of the caller.
    from drakegrasp.batch.run.workers import MAX_WORKERS

    with pytest.raises(InvalidOptionError, match=r"workers must be at most \d+"):
        BatchOptions(workers=100_000)
    P, N = np.zeros((2, 3, 3)), np.tile([0.0, 0.0, 1.0], (2, 3, 1))
    with pytest.raises(InvalidOptionError, match="workers must be at most"):
        dg.batch_force_closure(P, N, mu=0.5, chunk_size=1, workers=10**9)
    assert BatchOptions(workers=MAX_WORKERS).workers == MAX_WORKERS
