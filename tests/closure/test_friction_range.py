"""Payloads, forces and their certificates for μ anywhere in [1e-12, 1e12].

Three independent routes fix the answers:

* the exact rational simplex of ``exact_lp`` (no solver, no units, no
  tolerance) for polyhedral cones;
* the μ-dependence of a pinch: two antipodal fingers on the x axis, normals
  ±x, and a load with no x force.  The normal forces then only squeeze
  (``f_n1 = f_n2``), every wrench the load needs is friction's, and writing
  ``f_t = μ g_t`` turns the problem at μ into the one at μ = 1, so
  ``α*(μ) = μ α*(1)`` exactly, exact or polyhedral cones alike;
* monotonicity in μ (larger cones hold more) and invariance to the unit of
  length.

At μ = 1e-12 the rows that only friction balances have coefficients 1e-12;
the solvers read them as 0 and a mixed load's payload came out 1.3 % high
with forces that re-checked, while most others were refused.
"""

from __future__ import annotations

import dataclasses
import warnings

import exact_lp
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import drakegrasp as dg
from drakegrasp.core import examples as ex

A = 0.05
TINY = [1e-12, 1e-11, 1e-10, 1e-9, 1e-6]
EVERY = [1e-12, 1e-10, 1e-9, 1e-6, 1e-3, 0.5, 1e3, 1e6, 1e9, 1e12]
# Mixed loads on the pinch: a force along the tangents with moments.
MIXED = [
    [0.0, 0.0, -1.0, 0.0, 0.02, 0.0],
    [0.0, 1.0, -1.0, 0.0, 0.02, 0.01],
    [0.0, 0.3, -1.0, 0.0, -0.01, 0.03],
]
LIMITS = [{"max_normal_force": 3.0}, {"max_squeeze": 3.0}]

SETTINGS = settings(
    derandomize=True,
    max_examples=25,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


def _pinch(mu, scale=1.0):
    return dg.Grasp(
        [
            dg.Contact([-A * scale, 0, 0], [1, 0, 0], mu=mu),
            dg.Contact([A * scale, 0, 0], [-1, 0, 0], mu=mu),
        ]
    )


# ---------------------------------------------------------------- payloads


@pytest.mark.parametrize("cones", ["exact", "polyhedral"])
@pytest.mark.parametrize("limit", LIMITS, ids=["f_max", "squeeze"])
@pytest.mark.parametrize("d", MIXED, ids=["fz_my", "fyz_myz", "fyz_myz2"])
@pytest.mark.parametrize("mu", TINY)
def test_a_mixed_payload_is_mu_times_the_one_at_mu_1(mu, d, limit, cones):
    ref = dg.max_load(_pinch(1.0), d, cones=cones, **limit).alpha
    r = dg.max_load(_pinch(mu), d, cones=cones, **limit)
    assert r.alpha == pytest.approx(mu * ref, rel=1e-6, abs=0.0)
    assert r.upper_bound == pytest.approx(mu * ref, rel=1e-6, abs=0.0)
    assert r.certificate.check(_pinch(mu)).holds


def _equator_direction(seed):
    d = np.random.default_rng(seed).normal(size=6)
    d[3:] *= 0.3
    return d


@pytest.mark.parametrize("limit", LIMITS, ids=["f_max", "squeeze"])
@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("mu", [1e-12, 1e-9, 1e-6, 1.0, 1e6, 1e12])
def test_polyhedral_payload_matches_the_exact_rational_lp(mu, seed, limit):
    # Three fingers on a sphere's equator: the normal forces hold the load's
    # horizontal force, friction the rest, so α* is no multiple of μ here.
    g = ex.equator_fingers(mu=mu)
    d = _equator_direction(seed)
    expected = exact_lp.polyhedral_max_load(g, d, num_generators=4, **limit)
    r = dg.max_load(g, d, cones="polyhedral", num_generators=4, **limit)
    assert r.alpha == pytest.approx(expected, rel=1e-6, abs=0.0)
    assert r.upper_bound == pytest.approx(expected, rel=1e-6, abs=0.0)


def _pinch_hand(c):
    # Joint j presses finger j on: tau_j = f_n + c f_z (as test_huge_friction).
    J = np.zeros((6, 2))
    J[0, 0], J[2, 0], J[3, 1], J[5, 1] = 1.0, c, 1.0, -c
    return J


@pytest.mark.parametrize("c", [0.0, 1.0])
@pytest.mark.parametrize("mu", [1e-12, 1e-9, 1.0, 1e8, 1e12])
def test_payload_with_motors_matches_the_exact_rational_lp(mu, c):
    g, J = _pinch(mu), _pinch_hand(c)
    d = np.array([0.0, 0.3, -1.0, 0.0, 0.01, 0.02])
    expected = exact_lp.polyhedral_max_load(
        g, d, num_generators=4, hand_jacobian=J, torque_limits=2.0
    )
    r = dg.max_load(
        g, d, hand_jacobian=J, torque_limits=2.0, cones="polyhedral", num_generators=4
    )
    assert r.alpha == pytest.approx(expected, rel=1e-6, abs=0.0)


@pytest.mark.parametrize("mu", [1e6, 1e8, 1e10, 1e12])
def test_exact_payload_with_motors_binding_friction_at_huge_mu(mu):
    # The motors bind the tangential forces (c = 1), the normal forces are
    # nearly free: an interior point squeezed 80 units of them, 1e-6 of a
    # motor's row, and the friction-scaled payload fell 1.3e-6 short of its
    # dual bound (SolverError at mu = 1e8).  The exact cone holds at least
    # the inscribed one's payload and, at these mu, no more than 1e-6 above.
    g, J = _pinch(mu), _pinch_hand(1.0)
    d = np.array([0.0, 0.3, -1.0, 0.0, 0.01, 0.02])
    poly = exact_lp.polyhedral_max_load(
        g, d, num_generators=4, hand_jacobian=J, torque_limits=2.0
    )
    r = dg.max_load(g, d, hand_jacobian=J, torque_limits=2.0)
    assert poly * (1 - 1e-6) <= r.alpha <= r.upper_bound * (1 + 1e-9)
    assert r.alpha == pytest.approx(poly, rel=1e-6, abs=0.0)
    assert r.upper_bound == pytest.approx(r.alpha, rel=1e-6, abs=0.0)


@pytest.mark.parametrize("limit", LIMITS, ids=["f_max", "squeeze"])
@pytest.mark.parametrize("mu", [1e-12, 1e-9, 1e-6])
def test_grasp_forces_agree_with_the_payload_at_tiny_mu(mu, limit):
    # Just below α* the load is held within every limit; just above it is
    # refuted by a certificate that re-checks.
    g, d = _pinch(mu), np.array(MIXED[2])
    alpha = mu * dg.max_load(_pinch(1.0), d, **limit).alpha
    held = dg.grasp_forces(g, (1 - 1e-4) * alpha * d, **limit)
    assert held.feasible
    f = held.stacked_forces()
    residual = dg.grasp_matrix(g) @ f + (1 - 1e-4) * alpha * d
    # Friction's rows to 1e-6 of the load; the x row, where a squeeze up to
    # 1e12 times the load cancels, to the solvers' accuracy on the squeeze.
    assert np.linalg.norm(residual[1:]) <= 1e-6 * alpha
    assert abs(residual[0]) <= 1e-9 * f[0]
    for fc in held.contact_forces:
        assert np.linalg.norm(fc[1:]) <= mu * fc[0] * (1 + 1e-6)
    refuted = dg.grasp_forces(g, (1 + 1e-4) * alpha * d, **limit)
    assert not refuted.feasible
    assert refuted.certificate.check(g).holds


@pytest.mark.parametrize("mu", EVERY)
def test_a_torsion_about_the_fingers_line_is_refuted_at_any_mu(mu):
    # No force has a moment about the x axis: the row is zeros, and at
    # mu = 1e-12 the friction-scaled program's load there was 1e-12, under
    # the solvers' tolerance: "held" with forces that failed the re-check.
    g, torsion = _pinch(mu), [0.0, 0.0, 0.0, 1.0, 0.0, 0.0]
    r = dg.grasp_forces(g, torsion)
    assert not r.feasible
    assert r.certificate.check(g).holds
    assert dg.max_load(g, torsion).alpha == 0.0


@SETTINGS
@given(
    lo=st.floats(-12.0, 12.0),
    gap=st.floats(0.05, 6.0),
    seed=st.integers(0, 2**16),
    polyhedral=st.booleans(),
)
def test_a_payload_grows_with_mu(lo, gap, seed, polyhedral):
    # Larger friction cones hold at least as much, at every pair of μ.
    rng = np.random.default_rng(seed)
    d = np.array([0.0, *rng.normal(size=2), 0.0, *(0.02 * rng.normal(size=2))])
    cones = "polyhedral" if polyhedral else "exact"
    small, large = 10.0**lo, 10.0 ** min(lo + gap, 12.0)
    a1 = dg.max_load(_pinch(small), d, max_normal_force=3.0, cones=cones).alpha
    a2 = dg.max_load(_pinch(large), d, max_normal_force=3.0, cones=cones).alpha
    assert a1 <= a2 * (1 + 1e-6)
    # And the pinch's payload is μ times the one at μ = 1 (see the module).
    ref = dg.max_load(_pinch(1.0), d, max_normal_force=3.0, cones=cones).alpha
    assert a1 == pytest.approx(small * ref, rel=1e-6, abs=0.0)


@SETTINGS
@given(log_mu=st.floats(-12.0, 12.0), seed=st.integers(0, 2**16))
def test_a_payload_does_not_depend_on_the_unit_of_length(log_mu, seed):
    # The same pinch in metres and in millimetres (moments x 1000).
    rng = np.random.default_rng(seed)
    d = np.array([0.0, *rng.normal(size=2), 0.0, *(0.02 * rng.normal(size=2))])
    mu = 10.0**log_mu
    metres = dg.max_load(_pinch(mu), d, max_squeeze=3.0)
    d_mm = d.copy()
    d_mm[3:] *= 1000.0
    millimetres = dg.max_load(_pinch(mu, scale=1000.0), d_mm, max_squeeze=3.0)
    assert millimetres.alpha == pytest.approx(metres.alpha, rel=1e-6, abs=0.0)


# ----------------------------------------------------------- certificates


def _forged(cert, **changes):
    return dataclasses.replace(cert, **changes)


def _payload_cases():
    """(id, grasp, direction, options, hand Jacobian) over every kind of limit."""
    d = np.array(MIXED[1])
    weight = np.array([0.0, 0.0, -9.81, 0.0, 0.0, 0.0])
    for mu in EVERY:
        for cones in ("exact", "polyhedral"):
            g = _pinch(mu)
            if mu < 1.0:
                yield f"{mu:g}-{cones}-f_max", g, d, {"max_normal_force": 3.0}, cones
                yield f"{mu:g}-{cones}-squeeze", g, d, {"max_squeeze": 3.0}, cones
            yield f"{mu:g}-{cones}-motors", g, weight, {"torque_limits": 2.0}, cones


CASES = list(_payload_cases())


@pytest.mark.parametrize(
    "grasp, direction, options, cones",
    [c[1:] for c in CASES],
    ids=[c[0] for c in CASES],
)
def test_a_true_payload_bound_passes_and_a_low_one_fails(
    grasp, direction, options, cones
):
    J = _pinch_hand(0.0) if "torque_limits" in options else None
    r = dg.max_load(grasp, direction, hand_jacobian=J, cones=cones, **options)
    cert = r.certificate
    assert cert.check(grasp, hand_jacobian=J).holds
    # A bound 1e-5 low, three ways: smaller multipliers (with the bound
    # they give), a larger twist (the same), or only a smaller claim.
    k = 1.0 - 1e-5
    low = [
        _forged(
            cert,
            joint_multipliers=k * cert.joint_multipliers,
            normal_multipliers=k * cert.normal_multipliers,
            squeeze_multiplier=k * cert.squeeze_multiplier,
            bound=k * cert.bound,
        ),
        _forged(cert, twist=cert.twist / k, bound=k * cert.bound),
        _forged(cert, bound=k * cert.bound),
    ]
    for forged in low:
        check = forged.check(grasp, hand_jacobian=J)
        assert not check.holds, check


@pytest.mark.parametrize("tiny", [1e-9, 1e-12])
def test_forces_that_leave_the_load_unbalanced_are_never_held(tiny):
    # A pinch with μ = 0.5 on one finger and a tiny μ on the other and on a
    # third: the z load needs equal friction at both pinch fingers, so normal
    # forces of 0.1 / μ.  Clarabel returned forces of 3e8 N that balanced
    # only two thirds of the 0.2 N load; the balance check weighed the
    # residual against a solver's noise on 3e8 N (1e-6 of it) and said
    # "held".  Held forces now balance the load to 1e-3 of it, or no answer
    # is claimed.
    g = dg.Grasp(
        [
            dg.Contact([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], mu=0.5),
            dg.Contact([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], mu=tiny),
            dg.Contact([0.0, -1.0, 0.0], [0.0, 1.0, 0.0], mu=tiny),
        ]
    )
    w = np.array([0.0, 0.0, 0.2, 0.0, 0.0, 0.0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            r = dg.grasp_forces(g, w)
        except dg.SolverError:
            return
    if r.feasible:
        f = np.concatenate(r.contact_forces)
        residual = np.abs(dg.grasp_matrix(g) @ f + w)
        assert residual.max() <= 1e-3 * 0.2, residual


def _two_fingers(mu1, mu2):
    return dg.Grasp(
        [
            dg.Contact([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], mu=mu1),
            dg.Contact([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], mu=mu2),
        ]
    )


def test_a_load_of_1e300_newtons_warns_of_no_overflow():
    # The result's balance residual took np.linalg.norm of 1e300-sized
    # vectors (RuntimeWarning: overflow in dot), and at μ = 1e12 the check
    # multiplied μ by the load before dividing.
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        r = dg.grasp_forces(_two_fingers(1e12, 1e12), [0.0, 0.0, 1e300, 0.0, 0.0, 0.0])
    assert r.feasible and np.isfinite(r.squeeze)
    assert np.isfinite(r.balance_residual) and r.balance_residual < 1e-6


def test_forces_past_the_largest_float_are_refused_not_held():
    # 1e300 N at μ = 1e-12 needs normal forces of 5e311 N: once "held" with
    # forces inf and nan (or a RuntimeWarning before that).
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(dg.SolverError, match="largest float"):
            dg.grasp_forces(
                _two_fingers(1e-12, 1e-12), [0.0, 0.0, 1e300, 0.0, 0.0, 0.0]
            )


def test_a_limit_past_the_largest_float_in_load_units_warns_of_no_overflow():
    # 1 N over a force unit of 1e-312 N (a load of 1e-300 N at μ = 1e12)
    # overflowed the dual's cost (RuntimeWarning) on its way to a weight inf.
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            result = dg.grasp_forces(
                _two_fingers(1e-12, 1e12),
                [0.0, 0.0, 1e-300, 0.0, 0.0, 0.0],
                max_normal_force=1.0,
            )
        except dg.SolverError as e:  # undecided, never "not held"
            assert "undecided" in str(e)
        else:
            # held (f_n <= 1 N and mu = 1e-12 carry 1e-300 N); "not held"
            # came with a refutation that proves nothing (power 1e-312 W
            # against a budget of 1.9e-17 W)
            assert result.feasible


@pytest.mark.parametrize("mus", [(1e-12, 1e12), (0.5, 1e-12)])
def test_a_planar_pinch_at_mixed_mu_is_never_said_not_held(mus):
    # Moments make both fingers' friction equal, so 1 N needs f_n = 0.5 /
    # min(mu) per finger: held (f = [5e11, -0.5, 5e11, 0.5] balances it
    # exactly, on the tiny cone's edge).  grasp_forces said "not held" with a
    # certificate that re-checks only for forces below 5e11 N (its reach).
    # Held, or undecided (SolverError): never "not held".
    g = dg.Grasp(
        [
            dg.Contact([-1.0, 0.0], [1.0, 0.0], mu=mus[0]),
            dg.Contact([1.0, 0.0], [-1.0, 0.0], mu=mus[1]),
        ]
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            result = dg.grasp_forces(g, [0.0, 1.0, 0.0])
        except dg.SolverError as e:
            assert "undecided" in str(e)
        else:
            assert result.feasible
