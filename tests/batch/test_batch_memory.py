"""Grasps of many contacts: memory that grows linearly in N, within the chunk budget.

One grasp of ``N`` contacts needs ``O(N)`` numbers on every route to ``d*``;
a grasp too large for any chunk is refused before anything is allocated.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from scipy import sparse

from drakegrasp.batch import batch_force_closure, batch_form_closure
from drakegrasp.batch.lp import block_kernel, dstar
from drakegrasp.batch.lp.dstar import _facet_block
from drakegrasp.batch.lp.tolerances import (
    HIGHS_MAX_COLUMNS,
    IPM_MAX_ITER,
    IPM_MAX_ITER_LARGE,
)
from drakegrasp.batch.run.stream import (
    GRASP_BYTES_MAX,
    chunk_size_for,
    cone_generators,
    grasp_bytes,
)
from drakegrasp.errors import InvalidContactError


def _ellipsoid(N, K=1, seed=3):
    """``K`` grasps of ``N`` contacts on a triaxial ellipsoid, normals inward.

    Frictionless contacts all over it hold it in form closure.
    """
    axes = np.array([1.0, 0.7, 0.5])
    rng = np.random.default_rng(seed)
    u = rng.normal(size=(K, N, 3))
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    return u * axes, -u / axes


needs_numba = pytest.mark.skipif(
    not block_kernel.AVAILABLE, reason="numba (extra 'fast') is not installed"
)


@needs_numba
def test_one_grasp_of_twenty_thousand_contacts_is_solved():
    # The fused pass allocated the active set's null-space arrays for every
    # null space: 8 (27 + 3 n_g) N² bytes, 163 GB here (a MemoryError),
    # where only null spaces of at most 7 dimensions use them.
    P, Nrm = _ellipsoid(20_000)
    res = batch_force_closure(P, Nrm, mu=0.5, kernel="numba")
    assert res.is_closure.all() and res.converged.all()


@needs_numba
def test_a_huge_lp_past_highs_is_solved_with_the_longer_cap():
    # LP1 of 20,000 frictionless contacts needs more than IPM_MAX_ITER
    # iterations.  HiGHS took a dense (20,000 x 20,000) block (3 GiB, 10 GB at
    # its peak) and then more than 10 minutes, so an LP past
    # HIGHS_MAX_COLUMNS is never handed to it; it gets IPM_MAX_ITER_LARGE
    # iterations instead (at IPM_MAX_ITER it ended unconverged, d* off by 6e-4).
    P, Nrm = _ellipsoid(20_000)
    start = time.perf_counter()
    form = batch_form_closure(P, Nrm, kernel="numba")
    assert time.perf_counter() - start < 60
    assert form.is_closure.all() and form.converged.all()
    assert 0.9 < form.d_star[0] < 1.0


@needs_numba
def test_the_longer_cap_converges_to_the_reference_and_highs():
    # 8,000 contacts: the compiled IPM needed 158 iterations.  The numpy
    # reference IPM is a second implementation; HiGHS, on the textbook LP
    # max N min_i f_i s.t. G f = 0, sum f = 1 (dense G, no normalisation),
    # gave 0.979115676030914 in 138 s, too slow to run here.
    P, Nrm = _ellipsoid(8_000)
    fast = batch_form_closure(P, Nrm, kernel="numba")
    reference = batch_form_closure(P, Nrm, kernel="numpy")
    assert fast.converged.all() and reference.converged.all()
    assert abs(fast.d_star[0] - reference.d_star[0]) < 1e-8
    assert abs(fast.d_star[0] - 0.979115676030914) < 1e-8


def test_lps_within_highs_reach_keep_the_short_cap(monkeypatch):
    # Below HIGHS_MAX_COLUMNS the cap stays IPM_MAX_ITER (HiGHS follows it),
    # so the answers there are unchanged; past it the cap is the longer one.
    seen = []
    real = dstar.solve_block_lp

    def spy(*args, **kwargs):
        seen.append(kwargs["max_iter"])
        return real(*args, **kwargs)

    monkeypatch.setattr(dstar, "solve_block_lp", spy)
    for n in (200, HIGHS_MAX_COLUMNS + 1):
        P, Nrm = _ellipsoid(n, seed=5)
        batch_form_closure(P, Nrm, kernel="numpy")
    assert seen == [IPM_MAX_ITER, IPM_MAX_ITER_LARGE]


def test_highs_gets_the_dense_facet_block_as_sparse():
    rng = np.random.default_rng(5)
    mu = 0.4
    planar = np.array([[mu, 1.0], [mu, -1.0]]) / np.hypot(1.0, mu)
    hard = rng.normal(size=(8, 3))
    hard[0, 1] = 0.0
    facets = [planar, np.ones((1, 1)), hard, planar]
    widths = [F.shape[1] for F in facets]
    starts = np.concatenate([[0], np.cumsum(widths)[:-1]])
    slices = [slice(a, a + b) for a, b in zip(starts, widths, strict=True)]
    M = sum(widths)
    dense = np.zeros((sum(F.shape[0] for F in facets), M))
    row = 0
    for F, s in zip(facets, slices, strict=True):
        dense[row : row + F.shape[0], s] = F
        row += F.shape[0]
    want = sparse.csc_array(np.hstack([-dense, np.ones((row, 1))]))
    got = _facet_block(facets, slices, M)
    np.testing.assert_array_equal(got.indptr, want.indptr)
    np.testing.assert_array_equal(got.indices, want.indices)
    np.testing.assert_array_equal(got.data, want.data)


@pytest.mark.parametrize("kind", ["force", "form"])
def test_a_grasp_too_large_for_any_chunk_is_refused_at_once(kind):
    # 10**7 contacts: about 30 GB of working memory (more with the facets);
    # refused before a chunk is read, not after gigabytes were allocated.
    P = np.broadcast_to(np.array([1.0, 0.0, 0.0]), (1, 10**7, 3))
    Nrm = np.broadcast_to(np.array([-1.0, 0.0, 0.0]), (1, 10**7, 3))
    start = time.perf_counter()
    with pytest.raises(InvalidContactError) as err:
        if kind == "force":
            batch_force_closure(P, Nrm, mu=0.5, num_generators=8)
        else:
            batch_form_closure(P, Nrm)
    assert time.perf_counter() - start < 1.0
    text = str(err.value)
    assert "one grasp of 10000000 contacts" in text
    assert str(grasp_bytes(10**7, 8 if kind == "force" else 1)) in text
    assert ("num_generators=8" in text) == (kind == "force")


def test_the_largest_grasp_admitted_fits_the_bound():
    most = GRASP_BYTES_MAX // grasp_bytes(1, 8)
    assert grasp_bytes(most, 8) <= GRASP_BYTES_MAX < grasp_bytes(most + 1, 8)
    assert chunk_size_for(most, 3, None, 8, 10) == 1
    with pytest.raises(InvalidContactError, match=f"at most {most} contacts"):
        chunk_size_for(most + 1, 3, None, 8, 10)


# Cones that num_generators does not shape: a planar cone has its 2 edges, a
# frictionless contact its normal.  Measured (peak RSS, one grasp of 800,000
# contacts, num_generators=8): planar hard fingers 1,081 bytes a contact in
# 14 s, frictionless 1,076 in 22 s, both about 0.86 GB; the bound at 8
# generators (5,504 bytes a contact) said 4.1 GiB and refused both, advising
# "fewer generators", which changes nothing for them.
@pytest.mark.parametrize(
    ("d", "model"), [(2, "hard_finger"), (2, "frictionless"), (3, "frictionless")]
)
def test_cones_without_generators_are_not_bounded_as_eight(d, model):
    N = 800_000
    bound = grasp_bytes(N, cone_generators(8, d, model))
    assert 1081 * N <= bound <= GRASP_BYTES_MAX  # still an upper bound
    assert chunk_size_for(N, d, None, 8, 1, contact_model=model) == 1


def test_a_planar_grasp_too_large_names_no_generators():
    P = np.broadcast_to(np.array([1.0, 0.0]), (1, 10**7, 2))
    Nrm = np.broadcast_to(np.array([-1.0, 0.0]), (1, 10**7, 2))
    with pytest.raises(InvalidContactError) as err:
        batch_force_closure(P, Nrm, mu=0.5, num_generators=8)
    text = str(err.value)
    assert str(grasp_bytes(10**7, 2)) in text
    assert "generators" not in text


def test_soft_and_hard_spatial_cones_keep_their_generators():
    assert cone_generators(8, 3, "hard_finger") == 8
    assert cone_generators(16, 3, "soft_finger") == 16
    assert cone_generators(8, 3, None) == 8
