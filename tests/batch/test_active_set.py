"""The exact active-set method of small null spaces (drakegrasp.batch.lp.active_set).

Its answers are checked against HiGHS on the same reduced LP, against the
general n-dimensional route (the planar form of n = 3 is a second
formulation), against the block IPM inside the fused pass on real grasp
stacks, and for the invariances of the LP value (basis of v, scale, facet
order).
"""

from __future__ import annotations

import numpy as np
import pytest
from batch_support import random_grasps
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from drakegrasp.batch.build.construction import (
    FRICTIONLESS,
    PLANAR_HARD,
    SPATIAL_HARD,
    batched_grasp_matrix,
    kind_facets,
)
from drakegrasp.batch.build.rowspace import normalised_positions
from drakegrasp.batch.compiled import AVAILABLE
from drakegrasp.errors import InvalidOptionError

pytestmark = pytest.mark.skipif(not AVAILABLE, reason="numba is not installed")


def _solve(a, c, **kw):
    from drakegrasp.batch.lp.active_set import solve_reduced_lp

    return solve_reduced_lp(a, c, **kw)


def _highs(a, c):
    """max t s.t. cᵀv = 1, a_jᵀv >= t, by HiGHS (None when not optimal)."""
    R, n = a.shape
    res = linprog(
        np.r_[np.zeros(n), -1.0],
        A_ub=np.c_[-a, np.ones(R)],
        b_ub=np.zeros(R),
        A_eq=np.r_[c, 0.0][None],
        b_eq=[1.0],
        bounds=[(None, None)] * (n + 1),
        method="highs",
    )
    return -res.fun if res.status == 0 else None


def _stacks(rng, K, n, R):
    """Reduced LPs: generic, repeated rows, integer data (ties), ±pairs.

    With few facets some are unbounded (no optimum), the rest have one.
    """
    a = rng.normal(size=(K, R, n))
    c = rng.normal(size=(K, n))
    c_hat = c / np.linalg.norm(c, axis=1, keepdims=True)
    a[0::8] += 1.5 * c_hat[0::8, None, :]  # a cloud off the origin: t* > 0
    a[1::4, 1] = a[1::4, 0]  # a repeated facet
    a[2::4] = np.round(2 * a[2::4])  # small integers: many ties and degenerate vertices
    c[2::4] = np.round(2 * c[2::4]) + 0.5
    half = R // 2
    a[3::4, half : 2 * half] = -a[3::4, :half]  # facets in ± pairs: t* <= 0
    return a, c


@pytest.mark.parametrize(
    ("n", "R"), [(2, 8), (3, 6), (3, 24), (4, 10), (5, 32), (7, 28)]
)
def test_reduced_lp_matches_highs(n, R):
    rng = np.random.default_rng(8100 + 10 * n + R)
    K = 240
    a, c = _stacks(rng, K, n, R)
    t, ok, steps = _solve(a, c)
    ref = np.array([_highs(a[k], c[k]) for k in range(K)], dtype=float)  # NaN: none
    # certified exactly where the LP has an optimum (few facets: some are unbounded)
    np.testing.assert_array_equal(ok, np.isfinite(ref))
    tol = 1e-9 * (1 + np.abs(ref[ok])).max()
    np.testing.assert_allclose(t[ok], ref[ok], rtol=0, atol=tol)
    assert (ref > 0).any() and (ref < 0).any()  # both verdicts are exercised
    assert ok.mean() > 0.8 and steps.max() >= n  # and full vertices


def test_planar_form_matches_the_general_method():
    """n = 3: the planar form (auto) against the n-dimensional one, a second route."""
    rng = np.random.default_rng(8200)
    a, c = _stacks(rng, 2000, 3, 24)
    t_auto, ok_auto, _ = _solve(a, c)
    t_gen, ok_gen, _ = _solve(a, c, method="general")
    assert ok_auto.all() and ok_gen.all()
    np.testing.assert_allclose(t_auto, t_gen, rtol=0, atol=1e-12)


@pytest.mark.parametrize("method", ["auto", "general"])
@pytest.mark.parametrize("n", [2, 3, 5])
def test_an_unbounded_lp_is_left_to_the_fallback(method, n):
    """All a_j on one side of a direction u ⊥ c: t grows without bound; never ok."""
    rng = np.random.default_rng(8300 + n)
    c = np.zeros((50, n))
    c[:, 0] = 1.0
    a = rng.normal(size=(50, 12, n))
    a[:, :, 1] = np.abs(a[:, :, 1]) + 0.1  # a_jᵀ e_1 > 0 for every j, e_1 ⊥ c
    _, ok, _ = _solve(a, c, method=method)
    assert not ok.any()


def test_an_unknown_method_is_refused():
    with pytest.raises(InvalidOptionError, match="method"):
        _solve(np.ones((1, 4, 3)), np.ones((1, 3)), method="simplex")


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(2, 6),
    scale=st.sampled_from([1e-3, 1.0, 1e3]),
)
def test_the_value_does_not_depend_on_basis_scale_or_order(seed, n, scale):
    """t* of (a Q, Qᵀc) is t*; of (s a, c) is s t*; of permuted facets is t*."""
    rng = np.random.default_rng(seed)
    R = 4 * n
    a, c = _stacks(rng, 8, n, R)
    Q, _ = np.linalg.qr(rng.normal(size=(n, n)))
    t, ok, _ = _solve(a, c)
    t_rot, ok_rot, _ = _solve(a @ Q, c @ Q)
    t_scl, ok_scl, _ = _solve(scale * a, c)
    perm = rng.permutation(R)
    t_prm, ok_prm, _ = _solve(a[:, perm], c)
    # bounded or not is invariant too; the values are compared where bounded
    for other in (ok_rot, ok_scl, ok_prm):
        np.testing.assert_array_equal(other, ok)
    tol = 1e-10 * (1 + np.abs(t[ok]).max(initial=0.0))
    np.testing.assert_allclose(t_rot[ok], t[ok], rtol=0, atol=tol)
    np.testing.assert_allclose(t_scl[ok], scale * t[ok], rtol=0, atol=scale * tol)
    np.testing.assert_allclose(t_prm[ok], t[ok], rtol=0, atol=tol)


def _grasp_stack(rng, K, N, d, kind, mu):
    P, Nrm = random_grasps(rng, K, N, d, spread=0.5)
    Nrm /= np.linalg.norm(Nrm, axis=-1, keepdims=True)
    # exact symmetric grasps (many tied facets): contacts evenly on the
    # equator (circle) with exactly inward normals, turned about the z axis
    angles = 2 * np.pi * np.arange(N) / N + rng.uniform(0, 2 * np.pi, (K // 5, 1))
    ring = np.zeros((K // 5, N, d))
    ring[..., 0], ring[..., 1] = np.cos(angles), np.sin(angles)
    P[: K // 5], Nrm[: K // 5] = ring, -ring
    Pn, _ = normalised_positions(P)
    G, nc = batched_grasp_matrix(Pn, Nrm, np.zeros((K, d)), (kind,) * N)
    F = kind_facets(kind, np.array([mu]), np.array([0.0]), 8)
    kappa = np.full((K, N), np.sqrt(1.0 + mu**2))
    return G, [F] * N, nc, kappa


@pytest.mark.parametrize(
    ("N", "d", "kind", "mu"),
    [
        (3, 3, SPATIAL_HARD, 0.5),  # nz = 3: the planar form
        (3, 3, SPATIAL_HARD, 0.05),  # thin cones
        (3, 3, SPATIAL_HARD, 2.0),  # wide cones
        (3, 2, PLANAR_HARD, 0.4),  # nz = 3, R = 6
        (4, 2, PLANAR_HARD, 0.4),  # nz = 5: the general method
        (8, 3, FRICTIONLESS, 0.0),  # nz = 2
        (12, 3, FRICTIONLESS, 0.0),  # nz = 6, R = 12
    ],
)
def test_fused_active_set_matches_the_ipm_on_grasps(N, d, kind, mu):
    """The fused pass with the active-set method against the same pass, IPM only."""
    from drakegrasp.batch.lp.fused_kernel import solve_full_rank_stack

    rng = np.random.default_rng(8400 + 10 * N + d)
    G, F, nc, kappa = _grasp_stack(rng, 600, N, d, kind, mu)
    opts = {"rank_tol": 1e-9, "tol": 1e-10 * min(1.0, 4.0 / N), "max_iter": 60}
    d_as, done_as = solve_full_rank_stack(G, F, nc, kappa, **opts)
    d_ipm, done_ipm = solve_full_rank_stack(G, F, nc, kappa, active_set=False, **opts)
    both = done_as & done_ipm
    assert both.mean() > 0.75  # most grasps are solved by both routes
    np.testing.assert_allclose(d_as[both], d_ipm[both], rtol=0, atol=1e-8)
    assert (d_ipm[both] > 1e-6).any() and (d_ipm[both] == 0).any()
