"""Payload and grasp forces at friction coefficients down to 1e-12.

The closed forms of ``test_huge_friction``, at the other end of the range
``mu`` accepts: two antipodal hard fingers at ``x = ±a``, the load along a
tangent, held by friction alone.  With ``f_n <= f_max`` per finger the payload
is ``2 μ f_max``, with ``Σ f_n <= s`` it is ``μ s``, and a unit load needs a
squeeze of ``1 / μ``.  In newtons a solver's tolerance (1e-8 of the normal
force) is 1e4 times a tangential force of ``μ = 1e-12``: the payload came out
200 times too large at ``μ = 1e-12``, 10 times too small at ``1e-9``, and a
unit load was "refuted" (with a certificate that re-checked) at ``1e-10``.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import drakegrasp as dg

A = 0.05
MUS = [1e-12, 1e-11, 1e-10, 1e-9, 1e-6, 1e-4]


def _pinch(mu, planar=False):
    if planar:
        return dg.Grasp(
            [dg.Contact([-A, 0], [1, 0], mu=mu), dg.Contact([A, 0], [-1, 0], mu=mu)]
        ), np.array([0.0, -1.0, 0.0])
    return dg.Grasp(
        [
            dg.Contact([-A, 0, 0], [1, 0, 0], mu=mu),
            dg.Contact([A, 0, 0], [-1, 0, 0], mu=mu),
        ]
    ), np.array([0.0, 0.0, -1.0, 0.0, 0.0, 0.0])


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


@pytest.mark.parametrize("planar", [False, True])
@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize(
    "limit, expected",
    [({"max_normal_force": 3.0}, 6.0), ({"max_squeeze": 3.0}, 3.0)],
    ids=["f_max", "squeeze"],
)
def test_max_load_matches_the_closed_form_at_tiny_mu(mu, planar, limit, expected):
    g, d = _pinch(mu, planar)
    r = dg.max_load(g, d, **limit)
    assert r.alpha == pytest.approx(expected * mu, rel=1e-6, abs=0.0)
    assert r.upper_bound == pytest.approx(expected * mu, rel=1e-6, abs=0.0)
    assert r.certificate.check(g).holds


@pytest.mark.parametrize("limit", [{"max_normal_force": 1.0}, {"max_squeeze": 1.0}])
def test_max_load_at_mu_1e_minus_12_is_right(limit):
    # Refused until the friction-scaled program's balance rows were scaled
    # (LoadProblem.balanced): its friction rows had coefficients 1e-12.
    g, d = _pinch(1e-12)
    expected = 1e-12 * (2.0 if "max_normal_force" in limit else 1.0)
    r = dg.max_load(g, d, **limit)
    assert r.alpha == pytest.approx(expected, rel=1e-6, abs=0.0)
    assert r.upper_bound == pytest.approx(expected, rel=1e-6, abs=0.0)
    assert r.certificate.check(g).holds


@pytest.mark.parametrize("mu", MUS)
def test_grasp_forces_hold_a_unit_load_with_a_squeeze_of_one_over_mu(mu):
    g, d = _pinch(mu)
    r = dg.grasp_forces(g, d)
    assert r.feasible
    assert r.squeeze == pytest.approx(1.0 / mu, rel=1e-6, abs=0.0)
    assert dg.grasp_forces(g, d, max_squeeze=1.01 / mu).feasible
    assert not dg.grasp_forces(g, d, max_squeeze=0.5 / mu).feasible


def test_grasp_forces_at_mu_1e_minus_12_never_refute_a_held_load():
    g, d = _pinch(1e-12)
    for squeeze in (None, 1.01e12):
        r = dg.grasp_forces(g, d, max_squeeze=squeeze)
        assert r.feasible
        assert r.squeeze == pytest.approx(1e12, rel=1e-6, abs=0.0)
    r = dg.grasp_forces(g, d, max_squeeze=0.99e12)
    assert not r.feasible
    assert r.certificate.check(g).holds


# Mixed loads: a tangential force with moments (no force along the fingers'
# line, so the payload is mu times the one at mu = 1, see test_friction_range).
MIXED = [
    [0.0, 0.0, -1.0, 0.0, 0.02, 0.0],
    [0.0, 1.0, -1.0, 0.0, 0.02, 0.01],
    [0.0, 0.3, -1.0, 0.0, -0.01, 0.03],
]


@pytest.mark.parametrize("d", MIXED, ids=["fz_my", "fyz_myz", "fyz_myz2"])
@pytest.mark.parametrize("mu", [1e-12, 1e-11, 1e-10, 1e-9])
def test_a_mixed_payload_at_tiny_mu_is_right(mu, d):
    # At mu = 1e-12 the third load's payload came out 1.3 % high, with forces
    # that re-checked: the balance was measured against the normal forces'
    # terms, 1e12 times the rows that friction balances; then refused, until
    # the friction-scaled programs' rows were scaled (LoadProblem.balanced).
    g, _ = _pinch(mu)
    expected = mu * dg.max_load(_pinch(1.0)[0], d, max_normal_force=3.0).alpha
    r = dg.max_load(g, d, max_normal_force=3.0)
    assert r.alpha == pytest.approx(expected, rel=1e-6, abs=0.0)
