"""The linear-in-N batch engine: agreement across N, invariance, kernels, workers.

Agreement: on 10,000+ seeded grasps across N = 2…32 (hard, planar, soft,
frictionless) the batch d* agrees with the single MathematicalProgram path
within ``agreement_bound`` (10 · 1e-10 · N · κ · (1 + d*)) and the verdicts
agree exactly.  Invariance: verdicts and d* do not change
when a grasp is scaled from 1e-9 m to 1e9 m or its reference point moves 1e6 b
away (issue 9, finding 1).  Second formulations: the numba kernel against the
numpy block IPM, and both against the old null-space reduction.  Workers: the
results are bitwise the same for 1 and 2 worker processes.
"""

from __future__ import annotations

import inspect
import time

import numpy as np
import pytest
from batch_support import make_grasp, random_grasps
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from reference_lp import solve_margin_lp

from drakegrasp.batch import batch_force_closure, batch_form_closure
from drakegrasp.batch.build.construction import (
    FRICTIONLESS,
    PLANAR_HARD,
    SPATIAL_HARD,
    batched_grasp_matrix,
    kind_facets,
)
from drakegrasp.batch.build.rowspace import normalised_positions
from drakegrasp.batch.lp import block_kernel
from drakegrasp.batch.lp.block_ipm import solve_block_lp
from drakegrasp.batch.lp.dstar import solve_dstar_blocks
from drakegrasp.closure.verdicts import force_closure, form_closure
from drakegrasp.core.grasp import invariant_grasp_matrix
from drakegrasp.errors import InvalidContactError

needs_numba = pytest.mark.skipif(
    not block_kernel.AVAILABLE, reason="numba (extra 'fast') is not installed"
)

# (N, d, model, K): 10,200 grasps in all, most at the contact counts hands make.
AGREEMENT = [
    (2, 3, "hard_finger", 600),
    (3, 3, "hard_finger", 1620),
    (4, 3, "hard_finger", 1200),
    (6, 3, "hard_finger", 1000),
    (8, 3, "hard_finger", 900),
    (12, 3, "hard_finger", 600),
    (16, 3, "hard_finger", 400),
    (24, 3, "hard_finger", 250),
    (32, 3, "hard_finger", 100),
    (3, 2, "hard_finger", 800),
    (8, 2, "hard_finger", 500),
    (4, 3, "soft_finger", 600),
    (12, 3, "soft_finger", 200),
    (7, 3, "frictionless", 800),
    (16, 3, "frictionless", 300),
    (5, 2, "frictionless", 400),
]


IPM_TOL = inspect.signature(solve_block_lp).parameters["tol"].default


def agreement_bound(grasp, d_star: float) -> float:
    """How far the batch d* may lie from the single path's, for this grasp.

    The batch interior-point method stops when its primal and dual residuals and
    its relative gap are below ``IPM_TOL`` (1e-10); the single path's simplex
    (Clp) ends on a vertex, exact up to round-off.  By weak duality the gap
    bounds the objective's error by ``IPM_TOL (1 + d*)``; a residual ``r``
    moves it by at most ``r ‖y‖``, where the multipliers ``y`` of the balance
    rows grow with the contact count ``N`` (the normal forces sum to ``N``) and
    with the conditioning ``κ`` of the normalised grasp matrix.  The bound is
    ``10 IPM_TOL N κ (1 + d*)``, a factor 10 over that first-order estimate for
    the constants it leaves out; it does not depend on the machine's BLAS
    (measured: at N = 32, κ <= 1.9, differences up to 1.6e-8 against a bound
    of 9e-8; the former fixed 1e-8 failed on one machine).
    """
    s = np.linalg.svd(invariant_grasp_matrix(grasp), compute_uv=False)
    kappa = s[0] / s[-1] if s[-1] > 0 else np.inf
    return 10.0 * IPM_TOL * grasp.num_contacts * kappa * (1.0 + abs(d_star))


@pytest.mark.parametrize(("N", "d", "model", "K"), AGREEMENT)
def test_agrees_with_the_single_path_across_n(N, d, model, K):
    rng = np.random.default_rng(7000 + 37 * N + d)
    P, Nrm = random_grasps(rng, K, N, d, spread=0.3 + 0.4 * (N <= 4))
    mu = rng.uniform(0.05, 0.9, (K, 1))
    nu = rng.uniform(0.0, 0.3, (K, 1)) if model == "soft_finger" else np.zeros((K, 1))
    batch = batch_force_closure(
        P, Nrm, mu=mu, contact_model=model, torsional_friction=nu
    )
    d_ref = np.empty(K)
    bound = np.empty(K)
    v_ref = np.empty(K, dtype=bool)
    for k in range(K):
        g = make_grasp(P[k], Nrm[k], mu[k, 0], model=model, nu=nu[k, 0])
        r = force_closure(g)
        d_ref[k], v_ref[k] = r.d_star, r.is_closure
        bound[k] = agreement_bound(g, r.d_star)
    assert np.all(np.abs(batch.d_star - d_ref) <= bound)
    np.testing.assert_array_equal(batch.is_closure, v_ref)
    assert batch.converged.all()
    if 3 <= N <= 8 and model != "frictionless":
        assert 0 < v_ref.sum() < K  # a mix, so the agreement is not vacuous


def test_form_closure_agrees_with_the_single_path_at_many_contacts():
    rng = np.random.default_rng(7100)
    K, N = 300, 20
    P, Nrm = random_grasps(rng, K, N, 3, spread=0.6)
    batch = batch_form_closure(P, Nrm)
    grasps = [make_grasp(P[k], Nrm[k], 0.0, model="frictionless") for k in range(K)]
    refs = [form_closure(g) for g in grasps]
    bound = [agreement_bound(g, r.d_star) for g, r in zip(grasps, refs, strict=True)]
    assert np.all(np.abs(batch.d_star - [r.d_star for r in refs]) <= bound)
    np.testing.assert_array_equal(batch.is_closure, [r.is_closure for r in refs])


_GRASPS = {}


def _well_scaled(d, N, seed):
    key = (d, N, seed)
    if key not in _GRASPS:
        rng = np.random.default_rng(seed)
        _GRASPS[key] = random_grasps(rng, 60, N, d, spread=0.5)
    return _GRASPS[key]


@settings(
    max_examples=25,
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    log_scale=st.floats(-9.0, 9.0),
    offset=st.floats(-1e6, 1e6),
    direction=st.integers(0, 2),
    d=st.sampled_from([2, 3]),
    N=st.sampled_from([3, 4, 8]),
    form=st.booleans(),
)
def test_verdicts_do_not_depend_on_units_or_reference_point(
    log_scale, offset, direction, d, N, form
):
    """Scaling by 1e-9…1e9 and a reference point up to 1e6 b away change nothing."""
    P, Nrm = _well_scaled(d, N, 7200 + N + d)
    scale = 10.0**log_scale
    p = np.zeros(d)
    p[direction % d] = offset  # |p| up to 1e6 b (b ~ 1 for the well-scaled copy)
    p = scale * (p + 0.1)
    if form:
        ref = batch_form_closure(P, Nrm)
        res = batch_form_closure(scale * P, Nrm, reference_points=p)
    else:
        ref = batch_force_closure(P, Nrm, mu=0.4)
        res = batch_force_closure(scale * P, Nrm, mu=0.4, reference_points=p)
    np.testing.assert_array_equal(res.rank, ref.rank)
    np.testing.assert_array_equal(res.is_closure, ref.is_closure)
    np.testing.assert_allclose(res.d_star, ref.d_star, atol=1e-8, rtol=0)


def test_the_well_scaled_copy_has_a_mix_of_verdicts():
    """The invariance test above is not vacuous: both verdicts occur."""
    for d in (2, 3):
        for N in (3, 4, 8):
            P, Nrm = _well_scaled(d, N, 7200 + N + d)
            v = batch_force_closure(P, Nrm, mu=0.4).is_closure
            assert 0 < v.sum() < v.size or (d, N) == (3, 8)


def test_rank_uses_the_normalised_matrix():
    """Three equator fingers, p = (1e5, 3e4, -2e4): rank 6 and closure (issue 9)."""
    angles = 2 * np.pi * np.arange(3) / 3
    P = np.stack([np.cos(angles), np.sin(angles), np.zeros(3)], axis=1)[None]
    res = batch_force_closure(P, -P, mu=0.5, reference_points=[1e5, 3e4, -2e4])
    assert res.rank[0] == 6 and res.is_closure[0]
    assert abs(res.d_star[0] - 0.4194) < 1e-3


def _stack(N, K, seed):
    rng = np.random.default_rng(seed)
    P, Nrm = random_grasps(rng, K, N, 3)
    Nrm /= np.linalg.norm(Nrm, axis=-1, keepdims=True)
    Pn, _ = normalised_positions(P)
    layout = (SPATIAL_HARD,) * N
    G, nc = batched_grasp_matrix(Pn, Nrm, np.zeros((K, 3)), layout)
    F = kind_facets(SPATIAL_HARD, np.array([0.5]), np.array([0.0]), 8)
    return G, [F] * N, [slice(3 * i, 3 * i + 3) for i in range(N)], nc


@pytest.mark.parametrize("N", [3, 6, 12])
def test_block_ipm_matches_the_null_space_reduction(N):
    G, F, sl, nc = _stack(N, 400, 7300 + N)
    kappa = np.full((G.shape[0], N), np.sqrt(1.25))
    ref = solve_margin_lp(G, F, sl, nc, rank_tol=1e-9)
    new = solve_dstar_blocks(G, F, sl, nc, kappa, rank_tol=1e-9, kernel="numpy")
    np.testing.assert_array_equal(new.rank, ref.rank)
    np.testing.assert_allclose(new.d_star, ref.d_star, atol=1e-8, rtol=0)
    assert new.converged.all() and 0 < (ref.d_star > 1e-6).sum()


@needs_numba
@pytest.mark.parametrize("N", [2, 3, 8, 24])
def test_numba_kernel_matches_the_numpy_reference(N):
    G, F, sl, nc = _stack(N, 300, 7400 + N)
    kappa = np.full((G.shape[0], N), np.sqrt(1.25))
    ref = solve_dstar_blocks(G, F, sl, nc, kappa, rank_tol=1e-9, kernel="numpy")
    new = solve_dstar_blocks(G, F, sl, nc, kappa, rank_tol=1e-9, kernel="numba")
    # both stop at 1e-10 on t = d*/N, in a different summation order
    np.testing.assert_allclose(new.d_star, ref.d_star, atol=1e-8, rtol=0)
    np.testing.assert_array_equal(new.converged, ref.converged)


def test_results_are_bitwise_the_same_for_any_number_of_workers():
    rng = np.random.default_rng(7500)
    K, N = 3000, 6
    P, Nrm = random_grasps(rng, K, N, 3)
    mu = rng.uniform(0.1, 0.8, (K, N))
    one = batch_force_closure(P, Nrm, mu=mu, chunk_size=500, workers=1)
    two = batch_force_closure(P, Nrm, mu=mu, chunk_size=500, workers=2)
    for name, a in one.to_arrays().items():
        b = two.to_arrays()[name]
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), name
    form1 = batch_form_closure(P, Nrm, chunk_size=700, workers=1)
    form2 = batch_form_closure(P, Nrm, chunk_size=700, workers=2)
    assert form1.d_star.tobytes() == form2.d_star.tobytes()


def _mixed_stack(rng, K, N, d, layout_kind):
    """Random grasps with rank-deficient ones mixed in (collinear, coincident)."""
    P, Nrm = random_grasps(rng, K, N, d, spread=0.4)
    P[::5, :, 1:] = 0.0  # contacts on a line
    P[1::7] = P[1::7, :1]  # all contacts at one point
    Nrm /= np.linalg.norm(Nrm, axis=-1, keepdims=True)
    Pn, _ = normalised_positions(P)
    G, nc = batched_grasp_matrix(Pn, Nrm, np.zeros((K, d)), (layout_kind,) * N)
    return G, nc


@needs_numba
@pytest.mark.parametrize(
    ("N", "d", "kind", "mu"),
    [
        (3, 3, SPATIAL_HARD, 0.5),  # 3-D null space: the block IPM
        (8, 3, SPATIAL_HARD, 0.3),
        (2, 2, PLANAR_HARD, 0.6),  # M - w = 1: the closed form
        (7, 3, FRICTIONLESS, 0.0),  # M - w = 1
        (5, 3, FRICTIONLESS, 0.0),  # M < w: never full rank
    ],
)
def test_fused_pass_matches_the_numpy_reference_on_mixed_ranks(N, d, kind, mu):
    """The compiled preparation (fused_kernel) against numpy QR + block IPM."""
    rng = np.random.default_rng(7600 + 10 * N + d)
    K = 350
    G, nc = _mixed_stack(rng, K, N, d, kind)
    F = kind_facets(kind, np.array([mu]), np.array([0.0]), 8)
    k_i = F.shape[2]
    sl = [slice(k_i * i, k_i * i + k_i) for i in range(N)]
    kappa = np.full((K, N), np.sqrt(1.0 + mu**2))
    ref = solve_dstar_blocks(G, [F] * N, sl, nc, kappa, rank_tol=1e-9, kernel="numpy")
    new = solve_dstar_blocks(G, [F] * N, sl, nc, kappa, rank_tol=1e-9, kernel="numba")
    np.testing.assert_array_equal(new.rank, ref.rank)
    np.testing.assert_allclose(new.d_star, ref.d_star, atol=1e-8, rtol=0)
    np.testing.assert_array_equal(new.converged, ref.converged)
    full = 6 if d == 3 else 3
    if N * k_i >= full:  # not vacuous: both full-rank and deficient grasps
        assert 0 < (ref.rank == full).sum() < K
        assert (ref.d_star > 1e-6).any()


@needs_numba
def test_fused_rank_certificate_is_the_numpy_one():
    """full_column_rank_certain against the vectorised QR test it replaces."""
    from drakegrasp.batch.build.rowspace import _householder, _inverse_frobenius
    from drakegrasp.batch.lp.fused_kernel import full_column_rank_certain

    rng = np.random.default_rng(7700)
    Gn = rng.normal(size=(500, 6, 4))
    Gn[::3, :, 3] = Gn[::3, :, 0] + Gn[::3, :, 1]  # exactly dependent columns
    # nearly dependent, with σ_min spread log-uniformly across the threshold
    scale = 10.0 ** rng.uniform(-11.0, -6.0, size=(167, 1))
    Gn[1::3, :, 3] = Gn[1::3, :, 0] + scale * rng.normal(size=(167, 6))
    R, _ = _householder(np.ascontiguousarray(np.transpose(Gn, (1, 2, 0))))
    norm = np.sqrt(np.einsum("kij,kij->k", Gn, Gn))
    ref = _inverse_frobenius(R) * 1e-9 * norm < 1.0
    new = full_column_rank_certain(Gn, 1e-9)
    np.testing.assert_array_equal(new, ref)
    assert 0 < new[1::3].sum() < new[1::3].size  # the threshold is exercised
    assert not new[::3].any() and new[2::3].all()


def test_the_worker_pool_is_kept_and_replaced_when_a_worker_dies():
    """Calls reuse the worker processes; a killed worker's chunks run again."""
    import os
    import signal

    from drakegrasp.batch.run import workers as parallel

    rng = np.random.default_rng(7800)
    P, Nrm = random_grasps(rng, 1200, 4, 3)
    one = batch_force_closure(P, Nrm, mu=0.5, chunk_size=200, workers=1)
    first = batch_force_closure(P, Nrm, mu=0.5, chunk_size=200, workers=2)
    pids = set(parallel._POOL["pool"]._processes)
    again = batch_force_closure(P, Nrm, mu=0.5, chunk_size=200, workers=2)
    assert set(parallel._POOL["pool"]._processes) == pids
    for res in (first, again):
        assert res.d_star.tobytes() == one.d_star.tobytes()
    victim = next(iter(pids))
    process = parallel._POOL["pool"]._processes[victim]
    os.kill(victim, signal.SIGKILL)
    # SIGKILL is delivered asynchronously: wait until the worker has exited
    # (a call that starts first may finish on the survivor alone, CI saw it)
    deadline = time.monotonic() + 10.0
    while process.exitcode is None and time.monotonic() < deadline:
        time.sleep(0.01)
    assert process.exitcode is not None
    fresh = batch_force_closure(P, Nrm, mu=0.5, chunk_size=200, workers=2)
    assert set(parallel._POOL["pool"]._processes).isdisjoint(pids)
    assert fresh.d_star.tobytes() == one.d_star.tobytes()
    bad = Nrm.copy()
    bad[777, 2] = 0.0  # checked in the worker, raised here with its index
    with pytest.raises(InvalidContactError, match="grasp 777, contact 2"):
        batch_force_closure(P, bad, mu=0.5, chunk_size=200, workers=2)
    parallel.shutdown_pool()
    assert "pool" not in parallel._POOL
