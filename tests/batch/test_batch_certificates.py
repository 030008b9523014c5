"""Witnesses of batch verdicts, re-verified by direct evaluation and a separate LP."""

import numpy as np
import pytest
from scipy.optimize import linprog

import drakegrasp as dg
from drakegrasp.batch.witnesses import batch_certificates, grasp_at


def _random_batch(rng, K, N, d, spread=1.5):
    P = rng.normal(size=(K, N, d))
    P /= np.linalg.norm(P, axis=2, keepdims=True)
    n = -P + spread * 0.6 * rng.normal(size=P.shape)
    return P, n


def _lp_max_power(grasp, y, num_generators=8):
    """max yᵀ G f over the polyhedral cones with Σ f_n <= 1 (HiGHS)."""
    G = dg.grasp_matrix(grasp)
    b = grasp.characteristic_length
    cols = []
    for s, c in zip(grasp.component_slices(), grasp.contacts, strict=True):
        S = dg.friction_cone_generators(c, num_generators, characteristic_length=b)
        cols.append(G[:, s] @ S)
    GS = np.hstack(cols)
    res = linprog(
        -(y @ GS), A_ub=np.ones((1, GS.shape[1])), b_ub=[1.0], bounds=(0, None)
    )
    assert res.status == 0
    return -res.fun / (np.linalg.norm(G, 2) * np.linalg.norm(y))


CASES = [
    (3, 3, "hard_finger", 0.3, 0.0),
    (3, 4, "soft_finger", 0.2, 0.1),
    (3, 4, "frictionless", 0.0, 0.0),
    (2, 3, "hard_finger", 0.15, 0.0),
    (2, 2, "frictionless", 0.0, 0.0),
]


@pytest.mark.parametrize("d, N, model, mu, nu", CASES)
def test_every_batch_no_has_a_witness_that_holds(d, N, model, mu, nu):
    rng = np.random.default_rng(31 + N + d)
    K = 130
    P, n = _random_batch(rng, K, N, d)
    p = rng.normal(size=d) * 0.5
    checked, worst = 0, 0.0
    form = dg.batch_form_closure(P, n, reference_points=p)
    certs = batch_certificates(P, n, form, reference_points=p)
    assert np.array_equal(certs.has_witness, ~form.is_closure)
    for k in np.flatnonzero(~form.is_closure):
        g = grasp_at(P, n, k, contact_model="frictionless", reference_points=p)
        G_n = dg.normal_grasp_matrix(g)
        v = certs.direction[k]
        rates = G_n.T @ v / (np.linalg.norm(G_n, 2) * np.linalg.norm(v))
        worst = max(
            worst, -rates.min(), np.abs(rates).max() if certs.two_sided[k] else 0
        )
        checked += 1
    force = dg.batch_force_closure(
        P, n, mu=mu, contact_model=model, torsional_friction=nu, reference_points=p
    )
    certs = batch_certificates(
        P,
        n,
        force,
        mu=mu,
        contact_model=model,
        torsional_friction=nu,
        reference_points=p,
    )
    assert np.array_equal(certs.has_witness, ~force.is_closure)
    for k in np.flatnonzero(~force.is_closure):
        g = grasp_at(
            P,
            n,
            k,
            mu=mu,
            contact_model=model,
            torsional_friction=nu,
            reference_points=p,
        )
        y, w = certs.separating_twist[k], certs.direction[k]
        assert y @ w > 0
        for x in (y, -y) if certs.two_sided[k] else (y,):
            worst = max(worst, _lp_max_power(g, x))
        assert certs.certificates[k].check(g).holds
        checked += 1
    print(f"{model} d={d}: {checked} batch witnesses, largest violation {worst:.1e}")
    assert checked >= 100 and worst < 1e-7


def test_a_yes_has_no_batch_witness_and_shapes_are_checked():
    g = dg.examples.planar_square_four_contacts()
    P = np.array([g.positions] * 2)
    n = np.array([g.normals] * 2)
    r = dg.batch_form_closure(P, n)
    c = batch_certificates(P, n, r)
    assert r.is_closure.all() and not c.has_witness.any()
    assert np.isnan(c.direction).all() and c.certificates == (None, None)
    with pytest.raises(dg.GraspError, match="2 grasps"):
        batch_certificates(P[:1], n[:1], r)


@pytest.mark.parametrize("form", [True, False])
def test_rank_deficient_witnesses_are_vectorised_and_span_the_single_paths(
    form, monkeypatch
):
    """Two fingers (rank 5 with friction, 1 without): no Grasp is built per row."""
    import drakegrasp.batch.witnesses as bc

    rng = np.random.default_rng(5)
    K = 60
    P, n = _random_batch(rng, K, 2, 3)
    p = rng.normal(size=3) * 0.3
    run = dg.batch_form_closure if form else dg.batch_force_closure
    friction = {} if form else {"mu": 0.4}
    result = run(P, n, reference_points=p, **friction)
    assert (result.rank < 6).all() and not result.is_closure.any()

    def no_grasps(*a, **k):
        raise AssertionError("the rank-deficient path built a Grasp")

    monkeypatch.setattr(bc, "grasp_at", no_grasps)
    kw = {} if form else {"mu": 0.4}
    certs = batch_certificates(P, n, result, reference_points=p, **kw)
    monkeypatch.undo()
    assert certs.has_witness.all() and certs.two_sided.all()
    for k in range(K):
        g = grasp_at(
            P,
            n,
            k,
            contact_model="frictionless" if form else "hard_finger",
            reference_points=p,
            **kw,
        )
        cert = certs.certificates[k]
        assert cert.check(g).holds
        single = (dg.form_closure(g) if form else dg.force_closure(g)).certificate
        B, S = cert.null_basis, single.null_basis
        assert B.shape == S.shape  # same dimension
        coef = np.linalg.lstsq(S, B, rcond=None)[0]
        assert np.allclose(S @ coef, B, atol=1e-8)  # same span
