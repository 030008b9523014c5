"""LP2 in verdict-only mode (``force_verdicts``) against the full solve's verdicts.

Robustness counts verdicts, so :func:`drakegrasp.batch.run.chunk.force_verdicts`
stops each LP once its verdict is proved (``solve_dstar_blocks``'s
``verdict_tol``).  Its verdicts must equal ``batch_force_closure``'s exactly, on
random grasps of every contact model, on degenerate ones (rank deficient, one
point, collinear, duplicated contacts, extreme μ) and on grasps whose ``d*``
was tuned next to the threshold.  The early exits must be proofs: a YES exit
returns a feasible point's value (a lower bound on ``t*``), a NO exit a dual
bound (an upper bound), which the tests check against the full solve, with
thresholds put just below and just above each grasp's own ``t*``.
"""

from __future__ import annotations

import numpy as np
import pytest
from batch_support import degenerate_families, random_grasps

from drakegrasp.batch import batch_force_closure
from drakegrasp.batch.build.construction import SPATIAL_HARD, kind_facets
from drakegrasp.batch.build.rowspace import normalised_positions, row_spaces
from drakegrasp.batch.inputs import numba_available
from drakegrasp.batch.lp.dstar import _verdict_band
from drakegrasp.batch.run.chunk import _grasp_matrices, force_chunk, force_verdicts
from drakegrasp.core.tolerances import DEFAULT_RANK_TOL, DEFAULT_TOL
from drakegrasp.core.validation import unit_vectors

KERNELS = [
    pytest.param(
        "auto",
        marks=pytest.mark.skipif(not numba_available(), reason="numba missing"),
    ),
    "numpy",
]

CASES = [
    # (contacts N, dimension d, model, grasps K, normal spread)
    (2, 3, "hard_finger", 300, 0.2),
    (3, 3, "hard_finger", 600, 0.4),
    (4, 3, "hard_finger", 600, 0.4),
    (6, 3, "hard_finger", 400, 0.6),
    (8, 3, "hard_finger", 300, 0.8),
    (3, 2, "hard_finger", 500, 0.4),
    (4, 2, "hard_finger", 400, 0.6),
    (2, 3, "soft_finger", 300, 0.2),
    (3, 3, "soft_finger", 300, 0.4),
    (7, 3, "frictionless", 300, 0.3),
]


def _mu(rng, K, N):
    """Per-contact μ, a fifth exactly zero (hard fingers acting frictionless)."""
    mu = rng.uniform(0.05, 1.2, (K, N))
    mu[rng.random((K, N)) < 0.2] = 0.0
    return mu


def _both(P, Nrm, *, kernel, **options):
    full = batch_force_closure(P, Nrm, kernel=kernel, workers=1, **options)
    fast = force_verdicts(P, Nrm, kernel=kernel, workers=1, **options)
    return np.asarray(full.is_closure), fast, full


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize(("N", "d", "model", "K", "spread"), CASES)
def test_verdicts_equal_the_full_solve_on_random_grasps(N, d, model, K, spread, kernel):
    rng = np.random.default_rng(7000 + 10 * N + d)
    P, Nrm = random_grasps(rng, K, N, d, spread=spread)
    mu = 0.0 if model == "frictionless" else _mu(rng, K, N)
    nu = 0.3 if model == "soft_finger" else None
    full, fast, res = _both(
        P, Nrm, mu=mu, contact_model=model, torsional_friction=nu, kernel=kernel
    )
    np.testing.assert_array_equal(fast, full)
    if N > 2 or model == "soft_finger":
        assert 0 < full.sum() < K  # both verdicts occur


def _degenerate(rng):
    families = degenerate_families(rng, 60, spread=0.3)
    pair_P, pair_N = random_grasps(rng, 60, 2, 3, spread=0.0)  # rank 5 < 6
    return [*families, ("two antipodal hard fingers", pair_P, pair_N, 0.8)]


@pytest.mark.parametrize("kernel", KERNELS)
def test_verdicts_equal_the_full_solve_on_degenerate_grasps(kernel):
    rng = np.random.default_rng(7100)
    for what, P, Nrm, mu in _degenerate(rng):
        full, fast, res = _both(P, Nrm, mu=mu, kernel=kernel)
        np.testing.assert_array_equal(fast, full, err_msg=what)
        if what == "two antipodal hard fingers":
            assert (res.rank < 6).all() and not full.any()


def _d_star(P, Nrm, mu, kernel):
    return np.asarray(
        batch_force_closure(P, Nrm, mu=mu[:, None], kernel=kernel, workers=1).d_star
    )


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("N", [3, 4, 6])
def test_verdicts_next_to_the_threshold(N, kernel):
    """μ tuned per grasp (bisection) so that ``d*`` sits just below or above tol."""
    rng = np.random.default_rng(7200 + N)
    P, Nrm = random_grasps(rng, 80, N, 3, spread=0.3)
    closes = _d_star(P, Nrm, np.full(len(P), 2.0), kernel) > 1e-3
    P, Nrm = P[closes], Nrm[closes]
    no, yes = np.array(_verdict_band(1.0, 1))  # the band's edges, per unit of tol
    factors = np.array([0.1, 0.99 * no, 1.01 * no, 0.9, 0.999, 1.001, 1.1])
    factors = np.concatenate([factors, [0.99 * yes, 1.01 * yes, 2 * yes]])
    P = np.repeat(P, len(factors), axis=0)
    Nrm = np.repeat(Nrm, len(factors), axis=0)
    target = DEFAULT_TOL * np.tile(factors, len(P) // len(factors))
    tune = "auto" if numba_available() else kernel  # only puts d* next to tol
    lo, hi = np.zeros(len(P)), np.full(len(P), 2.0)
    for _ in range(45):
        mid = 0.5 * (lo + hi)
        above = _d_star(P, Nrm, mid, tune) > target
        hi, lo = np.where(above, mid, hi), np.where(above, lo, mid)
    d = _d_star(P, Nrm, hi, kernel)
    near = (d > 0.05 * DEFAULT_TOL) & (d < 10 * DEFAULT_TOL)
    assert near.mean() > 0.8  # the bisection put most grasps next to tol
    assert ((d > DEFAULT_TOL) & (d < 1.01 * DEFAULT_TOL)).any()
    assert ((d <= DEFAULT_TOL) & (d > 0.99 * DEFAULT_TOL)).any()
    full, fast, _ = _both(P, Nrm, mu=hi[:, None], kernel=kernel)
    np.testing.assert_array_equal(fast, full)


def _single(P, Nrm, mu, tol, kernel, verdict_only):
    K, N, _ = P.shape
    Nrm = unit_vectors("normals", Nrm)  # force_chunk takes unit normals
    return force_chunk(
        P, Nrm, np.broadcast_to(mu, (K, N)).copy(), np.zeros((K, N)),
        np.zeros((K, 3)), None, contact_model="hard_finger", num_generators=8, tol=tol,
        rank_tol=DEFAULT_RANK_TOL, metrics=(), kernel=kernel,
        verdict_only=verdict_only,
    )  # fmt: skip


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("N", [3, 4, 6, 8])
def test_early_exits_return_bounds_on_the_right_side(N, kernel):
    """Thresholds just below and above each grasp's own ``d*`` and band edges.

    A wrong proof (a point that is not feasible, a bound that is not one, a
    band on the wrong side) returns a ``d_star`` on the wrong side of the
    full solve's, and a verdict that differs from it.
    """
    rng = np.random.default_rng(7300 + N)
    P, Nrm = random_grasps(rng, 30, N, 3, spread=0.5)
    mu = rng.uniform(0.2, 1.0, (30, 1))
    d_full = _single(P, Nrm, mu, DEFAULT_TOL, kernel, False)["d_star"]
    checked = 0
    no, yes = _verdict_band(1.0, 1)  # the band's edges, per unit of tol
    for k in np.flatnonzero(d_full > 1e-4):
        for edge in (no, 1.0, yes):
            for eps in (-1e-6, 1e-6):
                tol = d_full[k] / edge * (1 + eps)
                one = slice(k, k + 1)
                fast = _single(P[one], Nrm[one], mu[one], tol, kernel, True)
                full = _single(P[one], Nrm[one], mu[one], tol, kernel, False)
                # (not simply d* > tol: LP1's normal-force certificate may say Yes)
                assert fast["is_closure"][0] == full["is_closure"][0]
                d = fast["d_star"][0]
                if d > tol:  # a feasible point's value: at most d*
                    assert d <= d_full[k] + 1e-9
                else:  # a dual bound, or d* itself
                    assert d >= d_full[k] - 1e-9
                checked += 1
    assert checked >= 30


def _block_inputs(P, Nrm, mu):
    """The block IPM's inputs of hard-finger grasps (as dstar prepares them)."""
    K, N, _ = P.shape
    Pn, _ = normalised_positions(P)
    Nrm = unit_vectors("normals", Nrm)  # as the API gives them
    G, normal = _grasp_matrices(Pn, Nrm, None, (SPATIAL_HARD,) * N, None, False)
    rank, spaces = row_spaces(G, rank_tol=DEFAULT_RANK_TOL)
    assert (rank == 6).all()
    ((sel, Q),) = spaces
    c = -np.einsum("mrk,rk->mk", Q, Q[normal].sum(axis=0))
    c[normal] += 1.0
    f0 = (c / np.einsum("mk,mk->k", c, c)).T
    A = np.concatenate([np.transpose(Q, (2, 1, 0)), np.zeros((K, 1, G.shape[2]))], 1)
    A[:, -1, normal] = 1.0
    facets = [kind_facets(SPATIAL_HARD, mu, None, 8)] * N
    kappa = np.sqrt(1.0 + np.repeat(mu[:, None], N, axis=1) ** 2)
    return facets, A[np.argsort(sel)], kappa, f0[np.argsort(sel)]


@pytest.mark.skipif(not numba_available(), reason="numba missing")
def test_prove_above_stops_only_on_feasible_points():
    """The compiled IPM's YES exit, from ``f0`` and from iterates, at ``t*`` ± ε."""
    from drakegrasp.batch.lp.block_kernel import solve_block_stack

    rng = np.random.default_rng(7400)
    P, Nrm = random_grasps(rng, 400, 4, 3, spread=0.3)
    mu = rng.uniform(0.3, 1.0, 400)
    facets, A, kappa, f0 = _block_inputs(P, Nrm, mu)
    t, ok, _, _ = solve_block_stack(facets, A, kappa, f0)
    keep = np.flatnonzero(ok & (t > 1e-3))[:150]
    proofs = {"f0": 0, "iterate": 0}
    for k in keep:
        one = ([F[k : k + 1] for F in facets], A[k : k + 1], kappa[k : k + 1])
        start = f0[k : k + 1]
        below = t[k] * (1 - 1e-3)  # a proof can stop here
        v, ok, stopped, it = solve_block_stack(*one, start, prove_above=below)
        assert ok[0] and not stopped[0] and v[0] > below
        assert v[0] <= t[k] + 1e-12  # a lower bound: a feasible point's value
        proofs["f0" if it[0] == 0 else "iterate"] += 1
        t0 = min(
            (F[k] @ start[0, 3 * i : 3 * i + 3]).min() for i, F in enumerate(facets)
        )
        if t0 > 0.0:  # f0 is feasible: it proves anything below min C f0
            v0, _, _, it0 = solve_block_stack(*one, start, prove_above=t0 * 0.999)
            assert it0[0] == 0 and abs(v0[0] - t0) <= 1e-12 and v0[0] <= t[k]
            proofs["f0"] += 1
        past = t[k] + 1e-7  # no feasible point reaches past t*: a full solve
        v2, ok2, _, it2 = solve_block_stack(*one, start, prove_above=past)
        assert ok2[0] and not v2[0] > past and it2[0] > it[0]
        assert abs(v2[0] - t[k]) <= 1e-9
    assert proofs["f0"] and proofs["iterate"], proofs  # both exits are exercised


def test_two_workers_give_the_same_verdicts():
    """The verdict-only option reaches worker processes (chunks solved there)."""
    rng = np.random.default_rng(7500)
    P, Nrm = random_grasps(rng, 4000, 4, 3, spread=0.5)
    mu = rng.uniform(0.1, 1.0, (4000, 1))
    one = force_verdicts(P, Nrm, mu=mu, workers=1)
    np.testing.assert_array_equal(force_verdicts(P, Nrm, mu=mu, workers=2), one)
    full = batch_force_closure(P, Nrm, mu=mu, workers=1).is_closure
    np.testing.assert_array_equal(one, full)
    assert 0 < one.sum() < len(one)


def test_the_band_puts_proofs_away_from_tol():
    t_no, t_yes = _verdict_band(1e-6, 4)
    assert 4 * t_no <= 0.25e-6 and 4 * t_yes >= 4e-6
