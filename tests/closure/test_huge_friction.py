"""Payload and grasp forces at friction coefficients up to 1e12, in closed form.

Two antipodal hard fingers at ``x = ±a`` on a box, gravity ``m g`` along -z.
Joint ``j`` presses its finger on with ``τ_j = f_n + c f_z`` (``f_z`` the
finger's upward force).  Each finger carries ``α m g / 2``, needs
``f_n >= α m g / (2 μ)``, so ``|τ_j| <= τ_max`` gives

.. math:: \\alpha^* = \\frac{2 \\mu \\tau_{\\max}}{m g (1 + c \\mu)}

for ``1 + c μ > 0`` and ``α* = inf`` otherwise (``τ = 0`` along a ray).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import drakegrasp as dg

A, MG, TAU = 0.05, 9.81, 2.0
MUS = [0.1, 1.0, 1e4, 1e8, 1e9, 1e10, 1e12]


def _setup(mu, c, planar):
    if planar:
        g = dg.Grasp(
            [dg.Contact([-A, 0], [1, 0], mu=mu), dg.Contact([A, 0], [-1, 0], mu=mu)]
        )
        # Contact frames [n, t]: t = (0, 1) at the first, (0, -1) at the second.
        J = np.zeros((4, 2))
        J[0, 0], J[1, 0], J[2, 1], J[3, 1] = 1.0, c, 1.0, -c
        return g, J, np.array([0.0, -MG, 0.0])
    g = dg.Grasp(
        [
            dg.Contact([-A, 0, 0], [1, 0, 0], mu=mu),
            dg.Contact([A, 0, 0], [-1, 0, 0], mu=mu),
        ]
    )
    # Second tangent: +z at the first contact, -z at the second.
    J = np.zeros((6, 2))
    J[0, 0], J[2, 0], J[3, 1], J[5, 1] = 1.0, c, 1.0, -c
    return g, J, np.array([0.0, 0.0, -MG, 0.0, 0.0, 0.0])


def _closed_form(mu, c):
    den = 1.0 + c * mu
    return 2.0 * mu * TAU / (MG * den) if den > 0.0 else np.inf


@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize("c", [0.0, 1.0, -3e-10])
def test_max_load_matches_the_closed_form_at_any_mu(mu, c):
    # ALPHA_CAP = 1e8 in program units read the finite 4e7 .. 4e11 at
    # mu >= 1e8 as inf, and Clp answered 0 at mu = 1e12.
    g, J, w = _setup(mu, c, planar=True)
    r = dg.max_load(g, w, hand_jacobian=J, torque_limits=TAU)
    expected = _closed_form(mu, c)
    if np.isinf(expected):
        assert r.alpha == np.inf
    else:
        assert r.alpha == pytest.approx(expected, rel=1e-6, abs=0.0)
        assert r.upper_bound == pytest.approx(expected, rel=1e-6, abs=0.0)
        tau = np.abs(r.joint_torques)
        assert np.all(tau <= TAU * (1 + 1e-6))


@pytest.mark.parametrize("mu", [0.1, 1.0, 1e4, 1e8, 1e10, 1e12])
def test_max_load_spatial_matches_the_closed_form_where_the_limit_binds_f_t(mu):
    g, J, w = _setup(mu, 1.0, planar=False)
    r = dg.max_load(g, w, hand_jacobian=J, torque_limits=TAU)
    assert r.alpha == pytest.approx(_closed_form(mu, 1.0), rel=1e-6, abs=0.0)


@pytest.mark.parametrize("mu", [1e8, 1e9, 1e10, 1e12])
@pytest.mark.parametrize("c", [0.0, -3e-10])
def test_max_load_spatial_past_the_cap_matches_the_closed_form(mu, c):
    # The motors bind the normal forces (tau = f_n): the exact-cone dual's
    # multipliers were mu times its twist, Clarabel and SCS missed it from
    # mu = 1e8 on, and max_load raised SolverError for the finite 4e7 .. 4e11.
    g, J, w = _setup(mu, c, planar=False)
    r = dg.max_load(g, w, hand_jacobian=J, torque_limits=TAU)
    expected = _closed_form(mu, c)
    if np.isinf(expected):
        assert r.alpha == np.inf
        return
    assert r.alpha == pytest.approx(expected, rel=1e-6, abs=0.0)
    assert r.upper_bound == pytest.approx(expected, rel=1e-6, abs=0.0)
    assert r.certificate.check(g, hand_jacobian=J).holds
    # The polyhedral cones have a generator along the load (the contact
    # frames' second tangent is ±z): the same payload by an LP.
    poly = dg.max_load(g, w, hand_jacobian=J, torque_limits=TAU, cones="polyhedral")
    assert poly.alpha == pytest.approx(expected, rel=1e-6, abs=0.0)


def _check_forces(g, J, w, r):
    G = dg.grasp_matrix(g)
    f = r.stacked_forces()
    assert np.linalg.norm(G @ f + w) <= 1e-6 * np.linalg.norm(w)
    assert np.all(np.abs(J.T @ f) <= TAU * (1 + 1e-6))
    for contact, fc in zip(g.contacts, r.contact_forces, strict=True):
        ft = np.linalg.norm(fc[1:])
        assert ft <= contact.mu * fc[0] * (1 + 1e-6) + 1e-9 * np.linalg.norm(w)


@pytest.mark.parametrize("planar", [False, True])
@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize("c", [0.0, 1.0, -3e-10])
@pytest.mark.parametrize("objective", ["min_squeeze", "min_torque"])
def test_grasp_forces_stay_in_the_cones_and_limits_at_any_mu(planar, mu, c, objective):
    # At mu = 1e9 the solver's forces used 1.97x the torque limits and were
    # reported feasible; at mu = 1e12 the planar LP left the cones entirely.
    g, J, w = _setup(mu, c, planar)
    alpha = _closed_form(mu, c)
    finite = np.isfinite(alpha)
    for frac in (0.5, 0.99, 2.0):
        load = frac * (alpha if finite else 1e6) * w
        r = dg.grasp_forces(
            g, load, hand_jacobian=J, torque_limits=TAU, objective=objective
        )
        assert r.feasible == (frac < 1.0 or not finite), frac
        if r.feasible:
            _check_forces(g, J, load, r)


@pytest.mark.parametrize("limits", [100.0, 0.0])
def test_a_subnormal_load_computes_no_overflow(helpers, limits):
    # torque_limits / (jscale * F0) overflowed (RuntimeWarning) at F0 = 1e-320;
    # a passive joint (0) made it 0 / 0 when c_j F0 underflowed to 0.
    g = helpers.equator_grasp(0.5, radius=0.04)
    J = np.random.default_rng(7).normal(size=(g.num_components, 4)) * 0.04
    w = np.array([0.0, 0.0, -0.3 * 9.81, 0.0, 0.0, 0.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        r = dg.grasp_forces(
            g,
            1e-320 * w,
            hand_jacobian=J,
            torque_limits=[limits, np.inf, np.inf, np.inf],
            objective="min_torque",
            cones="polyhedral",
        )
    assert r.feasible
    assert np.all(np.isfinite(r.joint_torques))
    assert abs(r.joint_torques[0]) <= limits + 1e-300


@pytest.mark.parametrize("mu", [0.5, 1e4, 1e8, 1e10, 1e12])
def test_max_load_without_limits_is_unbounded_at_any_mu(mu):
    # No limit at all: the payload is 0 or inf.  At mu = 1e12 the friction-
    # scaled program stopped at 4e15 below its cap, and the fallback first
    # raised SolverError, then (trusting an infeasible-looking homogeneous
    # program) reported 4.2e7 -- below the inf it gives at every smaller mu.
    from drakegrasp.core import examples as ex

    g = ex.equator_fingers(mu=mu)
    r = dg.max_load(g, [0.0, 0.0, -MG, 0.0, 0.0, 0.0])
    assert r.alpha == np.inf
    assert r.status.startswith("unbounded")


@pytest.mark.parametrize("mu", [1e4, 1e6, 1e12])
def test_max_load_without_limits_at_huge_mu(mu):
    # A torque about the line through two hard fingers is never held (α = 0);
    # a push along a finger's normal is held without bound.  Both raised
    # ZeroDivisionError: a dual bound of 0 became the unit of a re-solve (and
    # at 1e12 the push got a "bound" of 0 whose certificate did not re-check).
    g, _, _ = _setup(mu, 0.0, planar=False)
    r = dg.max_load(g, [0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    assert r.alpha == 0.0
    assert dg.max_load(g, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]).alpha == np.inf
