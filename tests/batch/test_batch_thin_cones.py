"""Thin cones: batch proves closure with normal forces, as the single path does."""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp import examples as ex


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
    batch = dg.batch_force_closure(P, N, mu)
    certified = 0
    for k in range(len(P)):
        grasp = dg.Grasp(
            [dg.Contact(P[k, i], N[k, i], mu=mu) for i in range(len(N[k]))]
        )
        single = dg.force_closure(grasp)
        assert batch.is_closure[k] == single.is_closure
        assert batch.normal_certificate[k] == (single.certificate == "normal forces")
        if single.certificate == "normal forces":
            certified += 1
            assert batch.margin[k] == pytest.approx(single.margin, rel=1e-5)
    assert 2 <= certified < len(P)  # both outcomes occur


def test_frictionless_contacts_need_no_certificate():
    base = ex.cube_seven_contacts()
    r = dg.batch_force_closure(base.positions[None], base.normals[None], 0.0)
    assert r.is_closure[0] and not r.normal_certificate[0]
    assert "normal_certificate" in r.to_arrays()
