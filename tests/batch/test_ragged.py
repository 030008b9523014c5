"""Ragged batches: grasps with different numbers of contacts in one call.

Independent routes: each grasp's stacked group call (bitwise), and the
single-grasp ``MathematicalProgram`` path (``d*`` to 1e-8, verdicts equal).
"""

from __future__ import annotations

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.batch import (
    batch_epsilon_l1,
    batch_force_closure,
    batch_form_closure,
    stream_form_closure,
)


def _ragged(seed: int, counts, d: int = 3):
    rng = np.random.default_rng(seed)
    P, Nrm = [], []
    for n in counts:
        u = rng.normal(size=(n, d))
        u /= np.linalg.norm(u, axis=1, keepdims=True)
        P.append(0.05 * u + 0.002 * rng.normal(size=(n, d)))
        Nrm.append(-u + 0.3 * rng.normal(size=(n, d)))  # roughly inward
    return P, Nrm


COUNTS = (2, 3, 4, 3, 5, 2, 4, 1, 3)


def _fields(result, k):
    arrays = result.to_arrays()
    return {name: a[k] for name, a in arrays.items()}


def _assert_same(a, b):
    assert a.keys() == b.keys()
    for name in a:
        assert np.array_equal(a[name], b[name], equal_nan=True), name


@pytest.mark.parametrize(
    "contact_model", ["hard_finger", "soft_finger", "frictionless"]
)
def test_each_grasp_gets_bitwise_what_its_own_stacked_call_gives(contact_model):
    P, Nrm = _ragged(0, COUNTS)
    rng = np.random.default_rng(1)
    mu = [rng.uniform(0.2, 1.0, size=len(p)) for p in P]
    nu = [0.3] * len(P) if contact_model == "soft_finger" else None
    ref = rng.normal(scale=0.01, size=(len(P), 3))
    b = rng.uniform(0.03, 0.08, size=len(P))
    options = dict(contact_model=contact_model, metrics=("epsilon_l1", "sigma_min"))
    result = batch_force_closure(
        P, Nrm, mu=mu, torsional_friction=nu, reference_points=ref,
        characteristic_lengths=b, **options,
    )  # fmt: skip
    assert len(result) == len(P)
    eps = batch_epsilon_l1(
        P, Nrm, mu=mu, torsional_friction=nu, reference_points=ref,
        characteristic_lengths=b, contact_model=contact_model,
    )  # fmt: skip
    for k, (p, n) in enumerate(zip(P, Nrm, strict=True)):
        alone = batch_force_closure(
            p[None], n[None], mu=mu[k][None],
            torsional_friction=None if nu is None else nu[k],
            reference_points=ref[k][None], characteristic_lengths=b[k:k + 1],
            **options,
        )  # fmt: skip
        _assert_same(_fields(result, k), _fields(alone, 0))
        assert eps[k] == alone.metrics["epsilon_l1"][0]


def test_verdicts_and_d_star_match_the_single_grasp_programs():
    P, Nrm = _ragged(2, COUNTS)
    result = batch_force_closure(P, Nrm, mu=0.6)
    form = batch_form_closure(P, Nrm)
    for k, (p, n) in enumerate(zip(P, Nrm, strict=True)):
        grasp = dg.Grasp([dg.Contact(c, m, mu=0.6) for c, m in zip(p, n, strict=True)])
        single = dg.force_closure(grasp)
        assert result.is_closure[k] == single.is_closure
        assert result.d_star[k] == pytest.approx(single.d_star, abs=1e-8)
        first = dg.form_closure(grasp)
        assert form.is_closure[k] == first.is_closure
        assert form.d_star[k] == pytest.approx(first.d_star, abs=1e-8)
    assert result.is_closure.any() and not result.is_closure.all()


def test_planar_ragged_batches_and_per_grasp_mu():
    P, Nrm = _ragged(3, (2, 3, 2, 4), d=2)
    mu = np.array([0.3, 0.5, 0.8, 0.2])
    result = batch_force_closure(P, Nrm, mu=mu)
    assert result.required_rank == 3
    for k in range(4):
        alone = batch_force_closure(P[k][None], Nrm[k][None], mu=mu[k])
        _assert_same(_fields(result, k), _fields(alone, 0))


def test_equal_counts_in_a_list_run_as_the_stacked_array():
    P, Nrm = _ragged(4, (3, 3, 3))
    listed = batch_force_closure(P, Nrm, mu=0.5)
    stacked = batch_force_closure(np.stack(P), np.stack(Nrm), mu=0.5)
    for k in range(3):
        _assert_same(_fields(listed, k), _fields(stacked, k))


def test_contact_order_within_a_grasp_and_grasp_order_do_not_matter():
    P, Nrm = _ragged(5, COUNTS)
    result = batch_force_closure(P, Nrm, mu=0.7)
    rng = np.random.default_rng(6)
    order = rng.permutation(len(P))
    shuffled = [rng.permutation(len(p)) for p in P]
    P2 = [P[k][shuffled[k]] for k in order]
    N2 = [Nrm[k][shuffled[k]] for k in order]
    again = batch_force_closure(P2, N2, mu=0.7)
    assert np.array_equal(again.is_closure, result.is_closure[order])
    np.testing.assert_allclose(again.d_star, result.d_star[order], atol=1e-9)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda P, N, kw: (P, N[:-1], kw), "normals must be a list of as many"),
        (lambda P, N, kw: (P, np.zeros(3), kw), "normals must be a list"),
        (lambda P, N, kw: (P, [*N[:-1], N[-1][:1]], kw), r"normals\[8\] must have"),
        (lambda P, N, kw: ([*P[:2], P[2][:, :2], *P[3:]], N, kw), r"positions\[2\]"),
        (
            lambda P, N, kw: ([*P[:4], np.full((5, 3), np.nan), *P[5:]], N, kw),
            "grasp 4, contact 0",
        ),
        (
            lambda P, N, kw: (P, [*N[:3], np.zeros((3, 3)), *N[4:]], kw),
            "normal of grasp 3, contact 0",
        ),
        (lambda P, N, kw: (P, N, {"mu": [0.5] * 8}), "mu must be a scalar, one"),
        (lambda P, N, kw: (P, N, {"mu": [np.ones(2)] * 9}), r"mu\[1\] must be"),
        (
            lambda P, N, kw: (P, N, {"mu": [*[0.5] * 6, -1.0, 0.5, 0.5]}),
            "mu of grasp 6",
        ),
        (
            lambda P, N, kw: (P, N, {"mu": 0.5, "reference_points": np.zeros((8, 3))}),
            "reference_points",
        ),
        (
            lambda P, N, kw: (P, N, {"mu": 0.5, "characteristic_lengths": -np.ones(9)}),
            "characteristic length of grasp 0",
        ),
        (
            lambda P, N, kw: ([*P[:5], [[0.0, 1.0], [2.0]], *P[6:]], N, kw),
            r"positions\[5\]",
        ),
    ],
)
def test_bad_ragged_input_names_the_grasp(change, message):
    P, Nrm = _ragged(7, COUNTS)
    P2, N2, kw = change(P, Nrm, {"mu": 0.5})
    with pytest.raises(dg.GraspError, match=message):
        batch_force_closure(P2, N2, **kw)


def test_an_uneven_nested_list_is_refused_clearly_where_only_stacks_go():
    uneven = [[[0.0, 0.0, 1.0]], [[1.0, 2.0]]]
    with pytest.raises(dg.InvalidContactError, match="uneven shape"):
        next(stream_form_closure(uneven, uneven))


class _LenRaises(list):
    def __len__(self):
        raise RuntimeError("no length")


class _IterRaises(list):
    def __iter__(self):
        raise RuntimeError("no items")


def test_ragged_normals_whose_length_or_items_raise_are_named():
    # The fuzz's last raw kind: len() of a list whose __len__ raises, on the
    # ragged route's normals.  They are read as every caller's sequence is.
    P = [np.zeros((1, 3)), np.array([[0.1, 0, 0], [0, 0.1, 0]])]
    n = [np.array([[0, 0, 1.0]]), np.array([[0, 0, 1.0], [0, 0, -1.0]])]
    expected = dg.batch_force_closure(P, n, mu=0.5)
    got = dg.batch_force_closure(P, _LenRaises(n), mu=0.5)  # read by its items
    np.testing.assert_array_equal(got.d_star, expected.d_star)
    with pytest.raises(dg.InvalidContactError, match="as many per-grasp arrays"):
        dg.batch_force_closure(P, _LenRaises(n[:1]), mu=0.5)
    with pytest.raises(dg.InvalidContactError, match="normals.*RuntimeError: no items"):
        dg.batch_force_closure(P, _IterRaises(n), mu=0.5)
