"""The compiled chunk construction against its numpy reference and the single path.

:mod:`drakegrasp.batch.build.construction_kernel` builds normalised positions, grasp
matrices and the normal-certificate rank test per grasp; it promises the same
floating-point operations in the same order as the numpy route, so the two are
compared bitwise here, on seeded stacks with degenerate grasps mixed in
(coincident and collinear contacts, axis-aligned normals and ties in the
tangent rule, tiny and large scales, a row subset), and against the
single-grasp :func:`drakegrasp.grasp_matrix`.  A second group checks that the
chunk functions give bitwise the same results whichever route built the arrays.
"""

from __future__ import annotations

import numpy as np
import pytest
from batch_support import make_grasp, random_grasps

from drakegrasp import grasp_matrix
from drakegrasp.batch.build.construction import (
    FRICTIONLESS,
    PLANAR_HARD,
    SOFT_FULL,
    SOFT_TORSION,
    SPATIAL_HARD,
    batched_grasp_matrix,
    batched_normal_grasp_matrix,
    contact_kinds,
)
from drakegrasp.batch.build.rowspace import normalised_positions
from drakegrasp.batch.compiled import AVAILABLE
from drakegrasp.batch.run import chunk as chunks
from drakegrasp.core.validation import unit_vectors
from drakegrasp.errors import InvalidContactError

pytestmark = pytest.mark.skipif(
    not AVAILABLE, reason="numba (extra 'fast') is not installed"
)

if AVAILABLE:
    from drakegrasp.batch.build.construction_kernel import (
        grasp_matrix_stack,
        normal_rank_certain,
        normalised_positions_stack,
    )
    from drakegrasp.batch.lp.fused_kernel import full_column_rank_certain


def hostile_stack(rng, K, N, d):
    """Seeded grasps with degenerate ones mixed in (rows 0-79)."""
    scale = 10.0 ** rng.uniform(-9, 3, (K, 1, 1))
    P = rng.normal(size=(K, N, d)) * scale + rng.normal(size=(K, 1, d))
    Nrm = rng.normal(size=(K, N, d))
    P[:10] = P[:10, :1]  # every contact at one point
    P[10:20] = 0.0  # ... at the origin
    t = rng.normal(size=(10, N, 1))
    P[20:30] = t * rng.normal(size=(10, 1, d))  # collinear contacts
    Nrm[30:40] = Nrm[30:40, :1]  # one normal for all contacts
    axes = np.eye(d)[rng.integers(0, d, (10, N))]
    Nrm[40:50] = axes * rng.choice([-1.0, 1.0], (10, N, 1))  # axis-aligned
    Nrm[50:60] = rng.choice([-1.0, 1.0], (10, N, d))  # |n_j| all tied
    Nrm[60:70, :, 0] = 0.0  # a zero component (ties in the tangent rule)
    Nrm[60:70, :, 1] += 1.0
    P[70:80] *= 1e-300  # tiny but not zero spreads
    return P, unit_vectors("normals", Nrm)


LAYOUTS_3D = [
    (SPATIAL_HARD,),
    (FRICTIONLESS,),
    (SOFT_FULL,),
    (SOFT_TORSION,),
    (SPATIAL_HARD, FRICTIONLESS, SOFT_FULL, SOFT_TORSION),
]


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("N", [1, 2, 3, 7, 24])
def test_normalised_positions_are_bitwise_the_numpy_route(d, N):
    rng = np.random.default_rng(100 + 10 * N + d)
    P, _ = hostile_stack(rng, 400, N, d)
    Pn, spread = normalised_positions_stack(P)
    want_Pn, want_spread = normalised_positions(P)
    np.testing.assert_array_equal(Pn, want_Pn)
    np.testing.assert_array_equal(spread, want_spread)
    assert np.isfinite(Pn).all() and (spread > 0).all()


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("N", [1, 2, 3, 8, 24])
def test_grasp_matrices_are_bitwise_the_numpy_route(d, N):
    rng = np.random.default_rng(200 + 10 * N + d)
    K = 400
    P, Nrm = hostile_stack(rng, K, N, d)
    Pn, _ = normalised_positions(P)
    p = rng.normal(size=(K, d))
    rows = rng.permutation(K)[: K // 3]
    bases = LAYOUTS_3D if d == 3 else [(PLANAR_HARD,), (FRICTIONLESS,)]
    layouts = [tuple(base[i % len(base)] for i in range(N)) for base in bases] + [
        tuple(int(x) for x in rng.choice([b[0] for b in bases], N))
    ]
    for layout in layouts:
        for X, ref in ((Pn, None), (P, p)):
            ref0 = np.zeros((K, d)) if ref is None else ref
            want, want_cols = batched_grasp_matrix(X, Nrm, ref0, layout)
            G, cols = grasp_matrix_stack(X, Nrm, layout, reference_points=ref)
            np.testing.assert_array_equal(G, want)
            np.testing.assert_array_equal(cols, want_cols)
            Gr, _ = grasp_matrix_stack(X, Nrm, layout, reference_points=ref, rows=rows)
            np.testing.assert_array_equal(Gr, want[rows])
    # The all-frictionless layout is the normal grasp matrix.
    Gn, _ = grasp_matrix_stack(P, Nrm, (FRICTIONLESS,) * N, reference_points=p)
    np.testing.assert_array_equal(Gn, batched_normal_grasp_matrix(P, Nrm, p))


@pytest.mark.parametrize("model", ["hard_finger", "soft_finger", "frictionless"])
def test_compiled_grasp_matrix_matches_single_grasp_objects(model):
    rng = np.random.default_rng(31)
    K, N, d = 40, 4, 3
    P, Nrm = hostile_stack(rng, 100, N, d)
    P, Nrm = P[25 : 25 + K], Nrm[25 : 25 + K]  # collinear, shared, axis-aligned, ties
    mu = rng.uniform(0, 1, (K, N)) * (rng.random((K, N)) > 0.3)
    nu = rng.uniform(0, 0.5, (K, N)) * (rng.random((K, N)) > 0.3)
    kinds = contact_kinds(mu, nu, contact_model=model, dim=d)
    for k in range(K):
        g = make_grasp(P[k], Nrm[k], mu[k], model=model, nu=nu[k], b=1.0)
        layout = tuple(int(x) for x in kinds[k])
        G, _ = grasp_matrix_stack(P, Nrm, layout, rows=np.array([k]))
        cols = []
        for c, s in zip(g.contacts, g.component_slices(), strict=True):
            cols.extend(s.start + j for j in c.effective_components())
        want = grasp_matrix(g)[:, cols]
        np.testing.assert_allclose(
            G[0], want, atol=1e-14 * max(1.0, np.abs(P[k]).max())
        )


@pytest.mark.parametrize(
    ("d", "N"),  # the certificate is for N <= w (6 spatial, 3 planar)
    [(3, 1), (3, 2), (3, 3), (3, 4), (3, 6), (2, 1), (2, 2), (2, 3)],
)
def test_normal_rank_certificate_agrees_with_the_svd_rule(d, N):
    rng = np.random.default_rng(300 + 10 * N + d)
    K = 400
    P, Nrm = hostile_stack(rng, K, N, d)
    Nrm[:10] = Nrm[:10, :1]  # coincident contacts, one normal: G_n of rank 1
    Pn, _ = normalised_positions(P)
    rows = np.flatnonzero(rng.random(K) < 0.7)
    Gn = batched_normal_grasp_matrix(Pn[rows], Nrm[rows], np.zeros((rows.size, d)))
    got = normal_rank_certain(Pn, Nrm, rows, 1e-9)
    sv = np.linalg.svd(Gn, compute_uv=False)
    ratio = sv[:, -1] / sv[:, 0]
    assert (ratio[got] > 1e-9).all()  # "certain" is never wrong
    assert got[ratio > 1e-6].all()  # and not shy
    if N > 1:
        assert not got[rows < 10].any()
    # The QR certificate of the fused kernel is sound on the same stacks.
    assert (ratio[full_column_rank_certain(Gn, 1e-9)] > 1e-9).all()


@pytest.mark.parametrize("w", [3, 6])
def test_gram_certificate_on_prescribed_singular_values(w):
    """Soundness at the threshold: ``σ_min / σ_max <= rank_tol`` is never certified."""
    from drakegrasp.batch.build.construction_kernel import _gram_certain

    rng = np.random.default_rng(40 + w)
    for N in range(1, w + 1):
        for ratio in [1.0, 1e-3, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-13, 0.0]:
            for _ in range(30):
                U, _ = np.linalg.qr(rng.normal(size=(w, N)))
                V, _ = np.linalg.qr(rng.normal(size=(N, N)))
                s = np.geomspace(1.0, max(ratio, 1e-300), N) if N > 1 else [1.0]
                if N > 1 and ratio == 0.0:
                    s[-1] = 0.0
                X = (U * s) @ V.T * 10.0 ** rng.uniform(-100, 100)
                ok = _gram_certain(
                    np.ascontiguousarray(X.T), N, w, np.empty((N, N)), np.empty(N),
                    2.0 * (1e-18 + 4.0 * (w + N + 2) * 2.0**-52),
                )  # fmt: skip
                true = np.linalg.svd(X, compute_uv=False)
                if true[-1] <= 1e-9 * true[0]:
                    assert not ok, (N, ratio)
                if N == 1 or ratio >= 1e-6:
                    assert ok, (N, ratio)


def _chunk(P, Nrm, mu, nu, model, kernel, metrics=()):
    # force_chunk takes unit normals (the API normalises them before it)
    Nrm = unit_vectors("normals", Nrm)
    K = P.shape[0]
    return chunks.force_chunk(
        P, Nrm, mu, nu, np.zeros((K, P.shape[2])), None, contact_model=model,
        num_generators=8, tol=1e-9, rank_tol=1e-9, metrics=metrics, kernel=kernel,
    )  # fmt: skip


@pytest.mark.parametrize("model", ["hard_finger", "soft_finger", "frictionless"])
@pytest.mark.parametrize("N", [2, 3, 5, 9])
def test_force_chunk_is_bitwise_the_same_whichever_route_builds_the_arrays(
    model, N, monkeypatch
):
    """Same LP kernel; only the construction route differs between the runs."""
    rng = np.random.default_rng(400 + N)
    K = 300
    P, Nrm = random_grasps(rng, K, N, 3)
    H, Hn = hostile_stack(rng, 70, N, 3)  # (not the 1e-300 spreads: κ overflows)
    P, Nrm = np.concatenate([P, H]), np.concatenate([Nrm, Hn])
    mu = rng.choice([0.0, 0.3, 0.8], (K + 70, N))
    nu = rng.choice([0.0, 0.05], (K + 70, N))
    metrics = ("sigma_min",)
    compiled = _chunk(P, Nrm, mu, nu, model, "numba", metrics)
    monkeypatch.setattr(chunks, "_compiled", lambda kernel: False)
    reference = _chunk(P, Nrm, mu, nu, model, "numba", metrics)
    assert compiled.keys() == reference.keys()
    for name in compiled:
        np.testing.assert_array_equal(compiled[name], reference[name], err_msg=name)


@pytest.mark.parametrize("N", [3, 8])
def test_form_chunk_is_bitwise_the_same_whichever_route_builds_the_arrays(
    N, monkeypatch
):
    rng = np.random.default_rng(500 + N)
    P, Nrm = random_grasps(rng, 300, N, 3)
    K = P.shape[0]

    def run():
        return chunks.form_chunk(
            P, Nrm, np.zeros((K, 3)), None, tol=1e-9, rank_tol=1e-9,
            metrics=("isotropy",), kernel="numba",
        )  # fmt: skip

    compiled = run()
    monkeypatch.setattr(chunks, "_compiled", lambda kernel: False)
    reference = run()
    for name in compiled:
        np.testing.assert_array_equal(compiled[name], reference[name], err_msg=name)


# ------------------------------------------------------------- unit_vectors


def test_unit_vectors_are_the_scaled_quotient_and_reject_as_before():
    rng = np.random.default_rng(7)
    a = rng.normal(size=(500, 3)) * 10.0 ** rng.uniform(-300, 300, (500, 1))
    a[:20, 1:] = 0.0
    a[20:40] = rng.choice([-1.0, 1.0], (20, 3))
    m = np.max(np.abs(a), axis=-1, keepdims=True)
    want = (a / m) / np.linalg.norm(a / m, axis=-1, keepdims=True)
    got = unit_vectors("normals", a)
    np.testing.assert_array_equal(got, want)
    np.testing.assert_allclose(np.linalg.norm(got, axis=-1), 1.0, rtol=1e-15)
    planar = rng.normal(size=(4, 5, 2))
    np.testing.assert_allclose(
        unit_vectors("normals", planar),
        planar / np.linalg.norm(planar, axis=-1, keepdims=True),
        rtol=1e-15,
    )
    for bad, what in [
        ([[1.0, 0, 0], [np.nan, 0, 0]], r"index \(1,\).*not finite"),
        ([[1.0, 0, 0], [0, -np.inf, 0]], r"index \(1,\).*not finite"),
        ([[1.0, 0, 0], [np.inf, np.nan, 1.0]], r"index \(1,\).*not finite"),
        ([[0.0, -0.0, 0.0]], r"index \(0,\).*zero length"),
        (5.0, "last axis"),
        (np.zeros((3, 0)), "last axis"),
    ]:
        with pytest.raises(InvalidContactError, match=what):
            unit_vectors("normals", bad)
    assert unit_vectors("normals", np.zeros((0, 3))).shape == (0, 3)


# ------------------------------------- the numpy reference kernel, mixed cones


@pytest.mark.parametrize("N", [3, 5])
def test_numpy_kernel_takes_friction_that_differs_between_grasps_and_contacts(N):
    """Facets that are not shared by the stack (μ per grasp / per contact).

    The numpy block IPM once failed on them (an einsum over the per-contact
    axis scale); it must agree with the compiled kernel.
    """
    from drakegrasp.batch import batch_force_closure

    rng = np.random.default_rng(600 + N)
    K = 150
    P, Nrm = random_grasps(rng, K, N, 3)
    for mu in (rng.uniform(0.2, 0.9, (K, 1)), rng.choice([0.3, 0.6, 1.0], (1, N))):
        ref = batch_force_closure(P, Nrm, mu=mu, workers=1, kernel="numpy")
        fast = batch_force_closure(P, Nrm, mu=mu, workers=1, kernel="numba")
        np.testing.assert_array_equal(ref.is_closure, fast.is_closure)
        np.testing.assert_allclose(ref.d_star, fast.d_star, rtol=0, atol=1e-8)
        assert 0 < ref.is_closure.sum() < K
