"""Thin cones: batch proves closure with normal forces, as the single path does."""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.core import examples as ex


def _perturbed(base, rng, count):
    P = np.repeat(base.positions[None], count, axis=0)
    N = np.repeat(base.normals[None], count, axis=0) + 0.4 * rng.normal(
        size=(count, *base.normals.shape)
    )
    return P, N


@pytest.mark.parametrize("mu", [1e-12, 1e-8, 3e-7])
@pytest.mark.parametrize("planar", [True, False])
def test_verdicts_and_certificates_match_the_single_path(mu, planar):
    rng = np.random.default_rng(11)
    base = ex.planar_square_four_contacts() if planar else ex.cube_seven_contacts()
    P, N = _perturbed(base, rng, 40)
    batch = dg.batch_force_closure(P, N, mu=mu)
    certified = 0
    for k in range(len(P)):
        grasp = dg.Grasp(
            [dg.Contact(P[k, i], N[k, i], mu=mu) for i in range(len(N[k]))]
        )
        single = dg.force_closure(grasp)
        assert batch.is_closure[k] == single.is_closure
        assert batch.normal_certificate[k] == (single.decided_by == "normal forces")
        if single.decided_by == "normal forces":
            certified += 1
            assert batch.margin[k] == pytest.approx(single.margin, rel=1e-5)
    assert 2 <= certified < len(P)  # both outcomes occur


def test_frictionless_contacts_need_no_certificate():
    base = ex.cube_seven_contacts()
    r = dg.batch_force_closure(base.positions[None], base.normals[None], mu=0.0)
    assert r.is_closure[0] and not r.normal_certificate[0]
    assert "normal_certificate" in r.to_arrays()


def _rotated(P, N, rng):
    d = P.shape[-1]
    Q, R = np.linalg.qr(rng.normal(size=(len(P), d, d)))
    Q = Q * np.sign(np.diagonal(R, axis1=1, axis2=2))[:, None, :]
    t = rng.normal(size=(len(P), 1, d))
    return P @ np.swapaxes(Q, 1, 2) + t, N @ np.swapaxes(Q, 1, 2)


@pytest.mark.parametrize("mu", [1e-8, 1e-12])
def test_few_contacts_with_rank_deficient_normals(mu):
    # Two antipodal planar fingers (N = 2 <= 3) and three equator fingers (N = 3
    # <= 6): G_n is rank deficient to round-off in every pose, and only normal
    # forces can prove closure at such thin cones.
    rng = np.random.default_rng(5)
    two = dg.Grasp([dg.Contact([-1, 0], [1, 0]), dg.Contact([1, 0], [-1, 0])])
    for base in (two, ex.equator_fingers(0.0)):
        P, N = _rotated(
            np.repeat(base.positions[None], 60, 0),
            np.repeat(base.normals[None], 60, 0),
            rng,
        )
        batch = dg.batch_force_closure(P, N, mu=mu)
        single = [
            dg.force_closure(
                dg.Grasp(
                    [dg.Contact(p, n, mu=mu) for p, n in zip(P[k], N[k], strict=True)]
                )
            )
            for k in range(len(P))
        ]
        assert np.array_equal(batch.is_closure, [s.is_closure for s in single])
        assert batch.normal_certificate.sum() == sum(
            s.decided_by == "normal forces" for s in single
        )
    assert batch.is_closure.all() and batch.normal_certificate.all()


def test_one_dimensional_mu_is_not_guessed_when_k_equals_n():
    base = ex.equator_fingers(0.5)
    P, N = np.repeat(base.positions[None], 3, 0), np.repeat(base.normals[None], 3, 0)
    with pytest.raises(
        dg.InvalidOptionError, match=r"ambiguous .* \(3, 1\) .* \(1, 3\)"
    ):
        dg.batch_force_closure(P, N, mu=[0.0, 0.0, 0.9])
    per_contact = dg.batch_force_closure(P, N, mu=[[0.0, 0.0, 0.9]])
    per_grasp = dg.batch_force_closure(P, N, mu=[[0.0], [0.0], [0.9]])
    assert per_contact.d_star[0] == per_contact.d_star[2]
    assert per_grasp.d_star[0] != per_grasp.d_star[2]


def test_tol_must_be_positive_as_in_the_single_path():
    base = ex.equator_fingers(0.5)
    with pytest.raises(dg.InvalidOptionError, match="tol must be finite and > 0"):
        dg.batch_force_closure(base.positions[None], base.normals[None], mu=0.5, tol=0)
