"""The compiled IPM agrees with the numpy one and with HiGHS, problem by problem."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

from drakegrasp.batch.compiled import AVAILABLE
from drakegrasp.batch.lp.ipm import solve_max_last
from drakegrasp.errors import InvalidOptionError

pytestmark = pytest.mark.skipif(not AVAILABLE, reason="numba is not installed")


def _random_lps(seed, K, r, n):
    rng = np.random.default_rng(seed)
    B = rng.normal(size=(K, r, n))
    B[:, :, -1] = np.abs(B[:, :, -1]) + 0.2  # rows bound the last variable above
    h = rng.normal(size=(K, r)) + rng.uniform(-1.0, 3.0, (K, 1))
    return B, h


def _highs(B, h):
    n = B.shape[2]
    out = []
    for k in range(len(B)):
        res = linprog(
            np.r_[np.zeros(n - 1), -1.0],
            A_ub=B[k],
            b_ub=h[k],
            bounds=[(None, None)] * n,
            method="highs",
        )
        out.append(-res.fun if res.status == 0 else np.nan)
    return np.array(out)


@pytest.mark.parametrize(("r", "n"), [(20, 4), (30, 6), (40, 9)])
def test_compiled_equals_numpy_and_highs(r, n):
    B, h = _random_lps(r * n, 80, r, n)
    want = _highs(B, h)
    keep = np.isfinite(want)  # bounded, feasible: the method's assumptions
    assert keep.sum() > 40
    B, h, want = B[keep], h[keep], want[keep]
    fast = solve_max_last(B, h, kernel="compiled")
    slow = solve_max_last(B, h, kernel="numpy")
    assert fast.converged.all() and slow.converged.all()
    np.testing.assert_allclose(fast.value, want, atol=1e-8)
    np.testing.assert_allclose(slow.value, want, atol=1e-8)
    # the same iteration: the same count but where round-off near the stopping
    # threshold (or a hard problem's long path) tips it by a step or a few
    assert np.mean(fast.iterations == slow.iterations) >= 0.9
    # the multipliers certify the optimum: Bᵀλ = e, λ >= 0, hᵀλ = value
    e = np.zeros(n)
    e[-1] = 1.0
    np.testing.assert_allclose(
        np.einsum("krn,kr->kn", B, fast.dual), np.tile(e, (len(B), 1)), atol=1e-8
    )
    assert (fast.dual >= 0).all()
    np.testing.assert_allclose(np.einsum("kr,kr->k", h, fast.dual), want, atol=1e-7)


def test_a_capped_problem_is_flagged_alike():
    B, h = _random_lps(3, 40, 24, 5)
    keep = np.isfinite(_highs(B, h))
    B, h = B[keep], h[keep]
    fast = solve_max_last(B, h, kernel="compiled", max_iter=3)
    slow = solve_max_last(B, h, kernel="numpy", max_iter=3)
    np.testing.assert_array_equal(fast.converged, slow.converged)
    assert not fast.converged.all()
    assert (fast.iterations == 3).all()


def test_kernel_option():
    B, h = _random_lps(27, 3, 20, 4)
    auto = solve_max_last(B, h, kernel="auto")
    np.testing.assert_allclose(auto.value, solve_max_last(B, h).value, atol=1e-12)
    with pytest.raises(InvalidOptionError, match="kernel"):
        solve_max_last(B, h, kernel="gpu")
    with pytest.raises(InvalidOptionError, match="stop_below"):
        solve_max_last(B, h, kernel="compiled", stop_below=0.0)


def _degenerate_stack(rng, K=40):
    """Dual weight LPs (two groups) with coplanar, duplicated generators."""
    rows = []
    for _ in range(K):
        n = 8
        gen = rng.normal(size=(12, n - 3))
        gen[6:] = gen[:6] * rng.choice([1.0, 2.0], size=(6, 1))  # parallel rows
        B = np.zeros((12 + 3, n))
        B[:12, : n - 3] = -gen
        B[:6, n - 3] = -1.0
        B[6:12, n - 2] = -1.0
        B[12, n - 3] = B[13, n - 2] = -1.0
        B[14, n - 3 : n - 1] = 1.0
        B[14, n - 1] = 1.0
        h = np.r_[rng.uniform(-1, 1, 12), 0.0, 0.0, 0.0]
        rows.append((B, h))
    B = np.array([b for b, _ in rows])
    h = np.array([c for _, c in rows])
    x0 = np.zeros((K, B.shape[2]))
    x0[:, -3] = np.maximum(0, (-h[:, :6]).max(axis=1))
    x0[:, -2] = np.maximum(0, (-h[:, 6:12]).max(axis=1))
    x0[:, -1] = -x0[:, -3:-1].sum(axis=1)
    return B, h, x0


def test_the_active_set_method_equals_highs_on_degenerate_lps():
    from drakegrasp.batch.lp.ipm import solve_max_last_active

    B, h, x0 = _degenerate_stack(np.random.default_rng(5))
    assert (np.einsum("krn,kn->kr", B, x0) <= h + 1e-15).all()
    sol = solve_max_last_active(B, h, x0)
    ref = _highs(B, h)
    bounded = np.isfinite(ref)
    assert sol.converged[bounded].all()
    np.testing.assert_allclose(sol.value[bounded], ref[bounded], rtol=0, atol=1e-9)
    # its certificate: λ >= 0, Bᵀλ = e, and hᵀλ (an upper bound) = the value
    lam = sol.dual[bounded]
    assert (lam >= 0).all()
    e = np.zeros(B.shape[2])
    e[-1] = 1.0
    np.testing.assert_allclose(
        np.einsum("krn,kr->kn", B[bounded], lam),
        np.broadcast_to(e, lam.shape[:1] + e.shape),
        atol=1e-9,
    )
    np.testing.assert_allclose(
        np.einsum("kr,kr->k", h[bounded], lam), sol.value[bounded], atol=1e-9
    )
