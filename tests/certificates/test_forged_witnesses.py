"""``Certificate.check`` refuses forged and foreign witnesses (issue 21, part 3).

A witness whose components are NaN or infinite, or so large that their norm
overflows, must not "hold": every case below is built on a grasp where an
independent route (a closed form, a direct evaluation of the inequalities on a
rescaled copy, or scipy's LP written here) proves the witness false.  A
certificate checked on a grasp with another number of contacts, dimension or
contact models says it belongs to another grasp, and ``tol`` must be in (0, 1).
"""

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

import drakegrasp as dg
from drakegrasp.certificates.certificate import (
    BALANCE,
    ESCAPE_TWIST,
    UNCONTROLLABLE,
    UNRESISTED_WRENCH,
    Certificate,
)
from drakegrasp.core import examples as ex

SCALES = [1e-300, 1e-150, 1.0, 1e154, 1e200, 1e300]


def _cube():
    g = ex.cube_seven_contacts()
    assert dg.form_closure(g).is_closure
    return g


def _lp1_feasible(grasp) -> bool:
    """Independent LP1: strictly positive normal forces that balance (scipy)."""
    G_n = dg.normal_grasp_matrix(grasp)
    n = G_n.shape[1]
    # max t s.t. G_n f = 0, f_i >= t, Σ f = n, t <= 1
    c = np.zeros(n + 1)
    c[-1] = -1.0
    A_eq = np.vstack([np.hstack([G_n, np.zeros((G_n.shape[0], 1))]), np.ones(n + 1)])
    A_eq[-1, -1] = 0.0
    b_eq = np.r_[np.zeros(G_n.shape[0]), n]
    A_ub = np.hstack([-np.eye(n), np.ones((n, 1))])
    res = linprog(
        c,
        A_ub=A_ub,
        b_ub=np.zeros(n),
        A_eq=A_eq,
        b_eq=b_eq,
        bounds=[(0, None)] * n + [(None, 1)],
        method="highs",
    )
    return res.status == 0 and -res.fun > 1e-6


def _twist(v, **kw):
    return Certificate(
        ESCAPE_TWIST, "normals", direction=np.asarray(v, dtype=float), **kw
    )


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_an_escape_twist_with_a_non_finite_component_fails(bad):
    g = _cube()
    assert _lp1_feasible(g)  # no escape twist exists: every forged one is false
    v = np.zeros(6)
    v[3] = bad
    check = _twist(v).check(g)
    assert not check.holds and check.violation == np.inf
    assert "not finite" in check.detail


@pytest.mark.parametrize("scale", SCALES)
def test_the_twist_check_reads_a_huge_or_tiny_twist_as_its_direction(scale):
    # 1e154 squared overflows: the old check divided by an infinite norm and
    # read every rate as 0, a "witness" of violation 0.
    g = _cube()
    rng = np.random.default_rng(4)
    for _ in range(20):
        v = rng.normal(size=6)
        expected = _twist(v).check(g)
        G_n = dg.normal_grasp_matrix(g)
        rates = G_n.T @ v / (np.linalg.norm(G_n, axis=0) * np.linalg.norm(v))
        assert expected.violation == pytest.approx(max(0.0, -rates.min()), rel=1e-12)
        assert not expected.holds  # the cube is in form closure
        got = _twist(v * scale).check(g)
        assert not got.holds
        assert got.violation == pytest.approx(expected.violation, rel=1e-12)


def _unresisted(g, y, w, basis=None):
    k = {} if basis is None else {"null_basis": basis[0], "separating_basis": basis[1]}
    return Certificate(
        UNRESISTED_WRENCH,
        "polyhedral",
        direction=np.asarray(w, dtype=float),
        separating_twist=np.asarray(y, dtype=float),
        **k,
    )


@pytest.mark.parametrize(
    "y",
    [
        [np.inf, 0, 0, 0, 0, 0],
        [np.nan, 1, 0, 0, 0, 0],
        [1e154, 1e154, 0, 0, 0, 0],
        [0, 0, 1e300, 0, 0, 1e300],
    ],
)
def test_a_forged_unresisted_wrench_fails_on_a_force_closure_grasp(y):
    g = ex.equator_fingers(0.5)
    assert dg.force_closure(g).is_closure
    y = np.asarray(y, dtype=float)
    w = np.where(np.isfinite(y), y, 1.0)
    check = _unresisted(g, y, w).check(g)
    assert not check.holds
    assert check.violation > 1e-3


def test_the_wrench_check_is_scale_invariant():
    g = ex.equator_fingers(0.3)
    rng = np.random.default_rng(5)
    for _ in range(10):
        y = rng.normal(size=6)
        w = y + 0.1 * rng.normal(size=6)
        base = _unresisted(g, y, w).check(g)
        for s in SCALES:
            got = _unresisted(g, s * y, s * w).check(g)
            assert got.holds == base.holds
            assert got.violation == pytest.approx(base.violation, rel=1e-9, abs=1e-15)


def _forces(g, value):
    return tuple(np.full(c.num_components, value, dtype=float) for c in g.contacts)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_a_balancing_force_with_a_non_finite_component_fails(bad):
    # Two frictionless fingers are never in force closure (rank of G is 1).
    g = ex.spatial_two_fingers(mu=0.0, contact_model="frictionless")
    assert not dg.force_closure(g).is_closure
    forces = list(_forces(g, 1.0))
    forces[0] = forces[0].copy()
    forces[0][0] = bad
    cert = Certificate(BALANCE, "normals", contact_forces=tuple(forces))
    check = cert.check(g)
    assert not check.holds and check.violation == np.inf


def test_the_balance_check_is_scale_invariant():
    g = ex.equator_fingers(0.5)
    r = dg.force_closure(g)
    cert = r.certificate
    assert cert.kind == BALANCE and cert.check(g).holds
    base = cert.check(g)
    for s in SCALES:
        scaled = dataclasses.replace(
            cert, contact_forces=tuple(s * f for f in cert.contact_forces)
        )
        got = scaled.check(g)
        assert got.holds
        assert got.violation == pytest.approx(base.violation, rel=1e-9, abs=1e-15)
        assert got.slack == pytest.approx(base.slack, rel=1e-9)


@pytest.mark.parametrize("bad", [np.nan, np.inf, 1e300])
def test_an_uncontrollable_force_with_a_forged_component_fails(bad):
    g = ex.equator_fingers(0.5)
    J = np.eye(g.num_components)  # every force is controllable: N(Jᵀ) = {0}
    forces = list(_forces(g, 0.0))
    for f in forces:
        f[0] = 1.0
    forces[1] = forces[1].copy()
    forces[1][1] = bad
    cert = Certificate(UNCONTROLLABLE, "polyhedral", contact_forces=tuple(forces))
    check = cert.check(g, hand_jacobian=J)
    assert not check.holds


@pytest.mark.parametrize(
    "tol", [np.inf, np.nan, 0.0, -1e-7, 1.0, 5.0, "1e-7", None, True, 1e-7 + 0j]
)
def test_tol_is_validated(tol):
    g = _cube()
    cert = _twist(np.ones(6))
    with pytest.raises(dg.InvalidOptionError, match="tol"):
        cert.check(g, tol=tol)


def test_tol_inf_no_longer_passes_anything():
    g = _cube()
    with pytest.raises(dg.InvalidOptionError):
        _twist(-np.ones(6)).check(g, tol=np.inf)


def _other_grasps():
    return {
        "planar": ex.planar_square_four_contacts(),
        "three contacts": dg.Grasp(ex.equator_fingers(0.5).contacts[:2]),
        "soft fingers": ex.equator_fingers(0.5).with_friction(
            contact_model="soft_finger", torsional_friction=0.1
        ),
    }


@pytest.mark.parametrize("other", sorted(_other_grasps()))
@pytest.mark.parametrize("kind", ["form", "force", "balance"])
def test_a_certificate_checked_on_another_grasp_says_so(other, kind):
    g = ex.equator_fingers(0.5) if kind != "form" else ex.spatial_two_fingers(0.5)
    if kind == "form":
        cert = dg.form_closure(g).certificate
        assert cert.kind == ESCAPE_TWIST
    elif kind == "force":
        g = ex.spatial_two_fingers(mu=0.0, contact_model="frictionless")
        cert = dg.force_closure(g).certificate
        assert cert.kind == UNRESISTED_WRENCH
    else:
        cert = dg.force_closure(g).certificate
        assert cert.kind == BALANCE
    h = _other_grasps()[other]
    same_shapes = (
        kind != "balance"
        and h.wrench_dim == g.wrench_dim
        and cert.null_basis.shape[0] in (0, h.wrench_dim)
    )
    if same_shapes:  # a twist or wrench is a valid question on any spatial grasp
        assert isinstance(cert.check(h).holds, bool)
        return
    with pytest.raises(dg.InvalidOptionError, match="belongs to another grasp"):
        cert.check(h)


@pytest.mark.parametrize(
    "field, value",
    [
        ("direction", None),
        ("direction", np.zeros(5)),
        ("direction", np.ones(6, dtype=complex)),
        ("direction", "abc"),
        ("null_basis", np.ones((3, 2))),
        ("num_generators", 10**9),
        ("num_generators", 2),
    ],
)
def test_malformed_twist_fields_are_refused(field, value):
    g = _cube()
    cert = dataclasses.replace(_twist(np.ones(6)), **{field: value})
    with pytest.raises(dg.GraspError):
        cert.check(g)


@pytest.mark.parametrize(
    "forces",
    [None, "abc", 3, (np.ones(3),), (np.ones(3), np.ones(2), np.ones(3))],
)
def test_malformed_forces_are_refused(forces):
    g = ex.equator_fingers(0.5)
    cert = Certificate(BALANCE, "polyhedral", contact_forces=forces)
    with pytest.raises(dg.InvalidOptionError):
        cert.check(g)


def test_a_non_grasp_is_refused():
    with pytest.raises(dg.InvalidGraspError):
        _twist(np.ones(6)).check("grasp")


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    st.lists(
        st.one_of(
            st.floats(allow_nan=True, allow_infinity=True),
            st.sampled_from([1e154, -1e154, 1e308, 5e-324]),
        ),
        min_size=6,
        max_size=6,
    )
)
def test_no_generated_twist_escapes_a_form_closure_grasp(v):
    g = _cube()
    v = np.asarray(v, dtype=float)
    if not np.any(v):
        return
    check = _twist(v).check(g)
    assert not check.holds
    assert np.isfinite(check.slack) or check.violation == np.inf


@pytest.mark.parametrize("model", ["hard_finger", "soft_finger"])
def test_a_form_closure_yes_checks_on_a_grasp_with_friction(model):
    # form closure reports [f_n] per contact; the check reads the other
    # components as zero (it read the normal indices of the full layout)
    g = _cube().with_friction(0.5, contact_model=model, torsional_friction=0.1)
    r = dg.form_closure(g)
    assert r.is_closure and all(len(f) == 1 for f in r.certificate.contact_forces)
    check = r.certificate.check(g)
    assert check.holds, check
