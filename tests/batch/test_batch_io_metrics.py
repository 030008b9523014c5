"""File round trip, metrics against the quality module, and the building blocks."""

from __future__ import annotations

import numpy as np
import pytest
from batch_support import make_grasp, random_grasps
from reference_lp import null_spaces
from scipy.optimize import linprog

from drakegrasp import grasp_matrix
from drakegrasp.batch import batch_force_closure, batch_form_closure, evaluate_file
from drakegrasp.batch.build.construction import (
    KIND_COMPONENTS,
    batched_grasp_matrix,
    contact_kinds,
    kind_facets,
)
from drakegrasp.batch.lp.ipm import solve_max_last
from drakegrasp.core.friction_cone import effective_cone
from drakegrasp.errors import InvalidOptionError

# ----------------------------------------------------------------- files


def test_npz_round_trip(tmp_path):
    rng = np.random.default_rng(21)
    K = 120
    P, Nrm = random_grasps(rng, K, 3, 3)
    mu = rng.uniform(0.1, 0.9, (K, 3))
    p = rng.normal(scale=0.1, size=(K, 3))
    src = tmp_path / "grasps.npz"
    np.savez(src, positions=P, normals=Nrm, mu=mu, reference_points=p)
    out = tmp_path / "verdicts.npz"
    res = evaluate_file(src, out, metrics=["isotropy"], chunk_size=50)
    direct = batch_force_closure(
        P, Nrm, mu=mu, reference_points=p, metrics=["isotropy"]
    )
    with np.load(out) as data:
        for name in ("is_closure", "d_star", "rank", "margin", "converged", "isotropy"):
            np.testing.assert_array_equal(data[name], direct[name])
            np.testing.assert_array_equal(data[name], res[name])
        assert str(data["kind"]) == "force" and float(data["tol"]) == 1e-6
        assert int(data["required_rank"]) == 6
    # mu on the command line overrides the file; form closure needs no mu
    over = evaluate_file(src, tmp_path / "o2.npz", mu=0.0)
    form = batch_form_closure(P, Nrm, reference_points=p)
    np.testing.assert_allclose(over.d_star, form.d_star, atol=1e-8)
    form_file = evaluate_file(src, tmp_path / "o3.npz", kind="form")
    np.testing.assert_array_equal(form_file.d_star, form.d_star)


def test_file_errors(tmp_path):
    P = np.zeros((2, 3, 3))
    src = tmp_path / "g.npz"
    np.savez(src, positions=P, normals=P + 1)
    with pytest.raises(InvalidOptionError, match="no array 'mu' and no mu was given"):
        evaluate_file(src, tmp_path / "o.npz")
    with pytest.raises(InvalidOptionError, match="kind must be 'force' or 'form'"):
        evaluate_file(src, tmp_path / "o.npz", kind="shape", mu=0.5)
    with pytest.raises(InvalidOptionError, match=r"must end in \.npz"):
        evaluate_file(src, tmp_path / "o.csv", mu=0.5)
    bad = tmp_path / "bad.npz"
    np.savez(bad, positions=P, normal=P)
    with pytest.raises(InvalidOptionError, match=r"no array\(s\) \['normals'\]"):
        evaluate_file(bad, tmp_path / "o.npz", mu=0.5)
    with pytest.raises(InvalidOptionError, match="must be a .npz archive"):
        evaluate_file(tmp_path / "g.json", tmp_path / "o.npz", mu=0.5)


def test_parquet_output(tmp_path):
    P = np.random.default_rng(22).normal(size=(5, 3, 3))
    src = tmp_path / "g.npz"
    np.savez(src, positions=P, normals=-P, mu=0.5)
    try:
        import pyarrow.parquet as pq
    except ImportError:
        with pytest.raises(
            InvalidOptionError, match="needs the optional package pyarrow"
        ):
            evaluate_file(src, tmp_path / "o.parquet")
        return
    res = evaluate_file(src, tmp_path / "o.parquet")
    table = pq.read_table(tmp_path / "o.parquet")
    np.testing.assert_array_equal(table.column("d_star").to_numpy(), res.d_star)


# --------------------------------------------------------------- metrics


def test_singular_value_metrics_match_the_quality_module():
    quality = pytest.importorskip("drakegrasp.quality")
    rng = np.random.default_rng(23)
    K = 40
    for d, model in ((3, "hard_finger"), (2, "hard_finger"), (3, "soft_finger")):
        P, Nrm = random_grasps(rng, K, 3, d)
        mu = rng.uniform(0, 1, (K, 3))
        mu[:, 0] = 0.0  # the metrics keep every column of the model
        nu = 0.2 if model == "soft_finger" else 0.0
        names = ["sigma_min", "isotropy", "ellipsoid_volume"]
        res = batch_force_closure(
            P, Nrm, mu=mu, contact_model=model, torsional_friction=nu, metrics=names
        )
        for k in range(K):
            g = make_grasp(P[k], Nrm[k], mu[k], model=model, nu=nu)
            want = _single_metrics(quality, g)
            got = [res.metrics[n][k] for n in names]
            np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-14)


def _single_metrics(quality, g) -> tuple[float, float, float]:
    """The single-grasp route of the batch's sigma_min, isotropy, ellipsoid_volume."""
    return (
        quality.min_singular_value(g),
        quality.isotropy(g),
        quality.wrench_ellipsoid_volume(g),
    )


@pytest.mark.parametrize("exponent", [-4, -1, 0, 2, 5])
def test_soft_finger_metrics_batch_equal_single_at_any_unit(exponent):
    # b far from 1 (the test above sits at b = 1, where a soft finger's
    # torsion column is the same kept or divided by b), p off the origin.
    quality = pytest.importorskip("drakegrasp.quality")
    rng = np.random.default_rng(29)
    K, N, s = 20, 4, 10.0**exponent
    P, Nrm = random_grasps(rng, K, N, 3)
    p = 0.3 * rng.normal(size=(K, 3))
    b = rng.uniform(0.4, 2.5, K)
    names = ["sigma_min", "isotropy", "ellipsoid_volume"]
    res = batch_force_closure(
        s * P,
        Nrm,
        mu=0.5,
        contact_model="soft_finger",
        torsional_friction=0.2,
        reference_points=s * p,
        characteristic_lengths=s * b,
        metrics=names,
    )
    unit = batch_force_closure(
        P,
        Nrm,
        mu=0.5,
        contact_model="soft_finger",
        torsional_friction=0.2,
        reference_points=p,
        characteristic_lengths=b,
        metrics=names,
    )
    np.testing.assert_array_equal(res.is_closure, unit.is_closure)
    for k in range(K):
        g = make_grasp(
            s * P[k], Nrm[k], 0.5, model="soft_finger", nu=0.2, p=s * p[k], b=s * b[k]
        )
        want = _single_metrics(quality, g)
        got = [res.metrics[n][k] for n in names]
        np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-14)
        # and the unit of length changes none of them
        got1 = [unit.metrics[n][k] for n in names]
        np.testing.assert_allclose(got, got1, rtol=1e-9, atol=1e-12)


def test_soft_finger_metrics_of_the_equator_grasp():
    # Three soft fingers on a sphere's equator: G Gᵀ = 3 I once the torsion
    # columns stay [0; n] (tests/quality/test_quality_singular_values.py), in
    # any unit: σ = √3, isotropy 1, volume 27 (1224.7, 0.0014 and 1.35e7 in
    # millimetres while those columns were divided by b).
    t = np.deg2rad([0.0, 120.0, 240.0])
    c = np.stack([np.cos(t), np.sin(t), np.zeros(3)], axis=-1)
    for s in (1e-3, 1.0, 1e3):
        res = batch_force_closure(
            s * c[None],
            -c[None],
            mu=0.5,
            contact_model="soft_finger",
            torsional_friction=0.1,
            metrics=["sigma_min", "isotropy", "ellipsoid_volume"],
        )
        assert res.metrics["sigma_min"][0] == pytest.approx(np.sqrt(3.0), rel=1e-12)
        assert res.metrics["isotropy"][0] == pytest.approx(1.0, abs=1e-12)
        assert res.metrics["ellipsoid_volume"][0] == pytest.approx(27.0, rel=1e-12)


def test_epsilon_metric_calls_ferrari_canny():
    quality = pytest.importorskip("drakegrasp.quality")
    rng = np.random.default_rng(24)
    P, Nrm = random_grasps(rng, 6, 3, 3, spread=0.1)
    res = batch_force_closure(P, Nrm, mu=0.5, metrics=["epsilon_l1"])
    want = [quality.ferrari_canny(make_grasp(P[k], Nrm[k], 0.5)) for k in range(6)]
    np.testing.assert_allclose(res.metrics["epsilon_l1"], want, rtol=1e-12)
    assert (res.metrics["epsilon_l1"][res.is_closure] > 0).all()


# --------------------------------------------------------- building blocks


@pytest.mark.parametrize("model", ["hard_finger", "soft_finger", "frictionless"])
def test_construction_matches_single_grasp_objects(model):
    rng = np.random.default_rng(25)
    K, N, d = 30, 3, 3
    P, Nrm = random_grasps(rng, K, N, d)
    Nrm /= np.linalg.norm(Nrm, axis=-1, keepdims=True)
    mu = rng.uniform(0, 1, (K, N)) * (rng.random((K, N)) > 0.3)
    nu = rng.uniform(0, 0.5, (K, N)) * (rng.random((K, N)) > 0.3)
    kinds = contact_kinds(mu, nu, contact_model=model, dim=d)
    b = 1.3
    for k in range(K):
        g = make_grasp(P[k], Nrm[k], mu[k], model=model, nu=nu[k], b=b)
        layout = tuple(int(x) for x in kinds[k])
        G, normal_cols = batched_grasp_matrix(
            P[k : k + 1], Nrm[k : k + 1], np.zeros((1, d)), layout
        )
        cols = []
        for c, s in zip(g.contacts, g.component_slices(), strict=True):
            cols.extend(s.start + j for j in c.effective_components())
        np.testing.assert_allclose(G[0], grasp_matrix(g)[:, cols], atol=1e-14)
        for i, c in enumerate(g.contacts):
            assert c.effective_components() == KIND_COMPONENTS[layout[i]]
            F = kind_facets(layout[i], mu[k : k + 1, i], b * nu[k : k + 1, i], 8)[0]
            want = effective_cone(c, 8, characteristic_length=b).facets
            # same facet set (row order may differ)
            assert F.shape == want.shape
            dist = np.abs(F[:, None, :] - want[None, :, :]).max(axis=2)
            assert dist.min(axis=1).max() < 1e-12 and dist.min(axis=0).max() < 1e-12


def test_null_spaces_fast_path_and_fallback():
    rng = np.random.default_rng(26)
    G = rng.normal(size=(200, 6, 9))
    G[:50, :, 8] = G[:50, :, 7]  # still full row rank
    G[50:80, 5] = G[50:80, 4]  # rank 5
    G[80:90] = G[80:90] * np.r_[1, 1, 1, 1, 1, 1e-12][None, :, None]  # nearly 5
    rank, groups = null_spaces(G, rank_tol=1e-9)
    want = np.array(
        [np.sum((s := np.linalg.svd(g, compute_uv=False)) > 1e-9 * s[0]) for g in G]
    )
    np.testing.assert_array_equal(rank, want)
    seen = np.zeros(200, dtype=int)
    for rows, Z in groups:
        seen[rows] += 1
        assert Z.shape[2] == 9 - rank[rows[0]] and (rank[rows] == rank[rows[0]]).all()
        ZtZ = Z.transpose(0, 2, 1) @ Z
        np.testing.assert_allclose(
            ZtZ, np.broadcast_to(np.eye(Z.shape[2]), ZtZ.shape), atol=1e-12
        )
        GZ = G[rows] @ Z
        scale = np.linalg.norm(G[rows], axis=(1, 2))[:, None, None]
        assert np.abs(GZ / scale).max() < 1e-9
    assert (seen == 1).all()


def test_ipm_matches_highs_and_certificates_are_sound():
    rng = np.random.default_rng(27)
    K, r, n = 300, 20, 4
    B = rng.normal(size=(K, r, n))
    B[:, :, -1] = np.abs(B[:, :, -1]) + 0.2  # rows bound the last variable above
    h = rng.normal(size=(K, r)) + rng.uniform(-1.0, 3.0, (K, 1))
    exact = solve_max_last(B, h)
    early = solve_max_last(B, h, stop_below=0.0)
    want = []
    for k in range(K):
        c = np.zeros(n)
        c[-1] = -1
        res = linprog(
            c, A_ub=B[k], b_ub=h[k], bounds=[(None, None)] * n, method="highs"
        )
        assert res.status == 0
        want.append(-res.fun)
    want = np.array(want)
    assert exact.converged.all() and early.converged.all()
    np.testing.assert_allclose(exact.value, want, atol=1e-8)
    # stop_below: exact where the optimum is >= 0, a valid negative bound elsewhere
    pos = want >= 1e-9
    np.testing.assert_allclose(early.value[pos], want[pos], atol=1e-8)
    assert (early.value[~pos] < 1e-9).all() and (early.value >= want - 1e-8).all()
    assert early.iterations[~pos].mean() < exact.iterations[~pos].mean()
    assert 0 < pos.sum() < K


def test_lps_that_hit_the_iteration_cap_are_finished_by_highs(monkeypatch):
    import drakegrasp.batch.lp.dstar as margin
    import drakegrasp.batch.run.chunk as chunks

    rng = np.random.default_rng(28)
    P, Nrm = random_grasps(rng, 150, 4, 3)
    ref = batch_force_closure(P, Nrm, mu=0.5)
    calls = []
    real_highs = margin._highs

    def counting(*args):
        calls.append(1)
        return real_highs(*args)

    def capped(*args, **kwargs):
        return margin.solve_dstar_blocks(*args, ipm_max_iter=2, **kwargs)

    monkeypatch.setattr(margin, "_highs", counting)
    monkeypatch.setattr(chunks, "solve_dstar_blocks", capped)
    res = batch_force_closure(P, Nrm, mu=0.5)
    assert len(calls) > 50  # most LPs need more than two iterations
    assert res.converged.all()
    np.testing.assert_allclose(res.d_star, ref.d_star, atol=1e-8)
    np.testing.assert_array_equal(res.is_closure, ref.is_closure)
