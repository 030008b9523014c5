"""Analytic cases with known answers, from the grasping chapter and Somov's counts."""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.core import examples as ex


def _null_vector_is_one_signed(Gn):
    """Independent route for a 1-D null space: positive spanning <=> one sign."""
    _, s, vt = np.linalg.svd(Gn)
    z = vt[-1]
    return np.all(z > 1e-9) or np.all(z < -1e-9)


def test_hand_built_planar_four_contacts_are_in_form_closure():
    grasp = ex.planar_square_four_contacts()
    result = dg.form_closure(grasp)
    assert result.is_closure and result.rank == 3 and not result.near_boundary
    assert _null_vector_is_one_signed(dg.normal_grasp_matrix(grasp))
    # The optimal forces balance: G_n f_n = 0 with every f_n >= d*.
    f = np.concatenate(result.contact_forces)
    assert np.allclose(dg.normal_grasp_matrix(grasp) @ f, 0, atol=1e-9)
    assert f.min() >= result.d_star - 1e-9


def test_hand_built_seven_contacts_on_a_cube_are_in_form_closure():
    grasp = ex.cube_seven_contacts()
    assert dg.form_closure(grasp).is_closure
    assert _null_vector_is_one_signed(dg.normal_grasp_matrix(grasp))
    # Removing any one contact destroys it (seven is the minimum).
    for i in range(7):
        fewer = grasp.with_contacts(grasp.contacts[:i] + grasp.contacts[i + 1 :])
        assert not dg.form_closure(fewer).is_closure


@pytest.mark.parametrize(("dim", "num"), [(2, 3), (3, 6)])
def test_too_few_contacts_never_give_form_closure(rng, make_contacts, dim, num):
    for _ in range(40):
        grasp = dg.Grasp(make_contacts(rng, num, dim=dim, tilt=0.9))
        result = dg.form_closure(grasp)
        assert not result.is_closure
        assert result.d_star <= 1e-9  # N(G_n) = {0}: not even a near miss


@pytest.mark.parametrize("dim", [2, 3])
def test_disk_and_sphere_are_never_in_form_closure(rng, dim):
    for num in (4, 7, 12):
        p = rng.normal(size=(num, dim))
        p /= np.linalg.norm(p, axis=1, keepdims=True)
        grasp = dg.Grasp([dg.Contact(x, -x, contact_model="frictionless") for x in p])
        result = dg.form_closure(grasp)
        assert not result.is_closure
        assert result.rank <= dim  # no moment about the centre


@pytest.mark.parametrize(("mu", "expected"), [(0.45, False), (0.55, True)])
def test_two_planar_fingers_on_a_square_need_mu_above_one_half(mu, expected):
    grasp = ex.planar_two_finger_square(mu)
    assert dg.force_closure(grasp).is_closure is expected
    assert dg.force_closure_exact(grasp).is_closure is expected
    assert dg.is_antipodal(grasp).is_antipodal is expected
    assert dg.is_antipodal(grasp).min_mu == pytest.approx(0.5)


@pytest.mark.parametrize("mu", [0.1, 0.5, 2.0])
def test_two_spatial_hard_fingers_never_give_force_closure(mu):
    grasp = ex.spatial_two_fingers(mu)
    result = dg.force_closure(grasp)
    assert result.rank == 5 and not result.is_closure
    assert not dg.force_closure_exact(grasp).is_closure


def test_two_soft_fingers_can_give_force_closure():
    soft = ex.spatial_two_fingers(
        0.5, contact_model="soft_finger", torsional_friction=0.3
    )
    assert dg.force_closure(soft).is_closure
    assert dg.force_closure_exact(soft).is_closure
    # ... but not without torsional friction (then they are hard fingers).
    assert not dg.force_closure(
        ex.spatial_two_fingers(0.5, contact_model="soft_finger")
    )


def test_three_fingers_on_the_equator():
    assert dg.force_closure(ex.equator_fingers(0.5)).is_closure
    assert dg.force_closure_exact(ex.equator_fingers(0.5)).is_closure
    frictionless = dg.force_closure(ex.equator_fingers(0.0))
    # normals through the centre, in one plane: only f_x, f_y can be made
    assert not frictionless.is_closure and frictionless.rank == 2


def test_optimal_forces_satisfy_the_program(make_contacts, rng):
    grasp = ex.equator_fingers(0.5)
    r = dg.force_closure(grasp)
    f = np.concatenate(r.contact_forces)
    assert np.allclose(dg.grasp_matrix(grasp) @ f, 0, atol=1e-8)
    for c, fi in zip(grasp.contacts, r.contact_forces, strict=True):
        assert np.all(dg.friction_cone_facets(c) @ fi >= r.d_star - 1e-8)
    assert sum(fi[0] for fi in r.contact_forces) <= grasp.num_contacts + 1e-8
    # Exact: each force sits at distance >= d* inside its Lorentz cone.
    e = dg.force_closure_exact(grasp)
    for fi in e.contact_forces:
        dist = (0.5 * fi[0] - np.linalg.norm(fi[1:])) / np.hypot(1, 0.5)
        assert dist >= e.d_star - 1e-6


def test_hard_finger_with_zero_friction_is_exactly_frictionless(rng, make_contacts):
    for num, dim in [(4, 2), (5, 2), (7, 3), (9, 3)]:
        for _ in range(5):
            hard = dg.Grasp(make_contacts(rng, num, dim=dim, mu=0.0, tilt=0.72))
            smooth = hard.with_friction(contact_model="frictionless")
            a, b = dg.force_closure(hard), dg.force_closure(smooth)
            assert a.is_closure == b.is_closure and a.rank == b.rank
            assert a.d_star == pytest.approx(b.d_star, abs=1e-9)
            e = dg.force_closure_exact(hard)
            assert e.is_closure == b.is_closure
            assert e.d_star == pytest.approx(b.d_star, abs=1e-6)
            # LP2 on frictionless contacts is LP1.
            assert dg.form_closure(hard).d_star == pytest.approx(b.d_star, abs=1e-9)
            assert all(np.allclose(f[1:], 0) for f in a.contact_forces)


def test_generator_formulation_reports_forces_in_the_cones():
    grasp = ex.equator_fingers(0.5)
    r = dg.force_closure(grasp, formulation="generators")
    assert r.is_closure and r.formulation == "generators"
    f = np.concatenate(r.contact_forces)
    assert np.allclose(dg.grasp_matrix(grasp) @ f, 0, atol=1e-8)
    for c, fi in zip(grasp.contacts, r.contact_forces, strict=True):
        assert np.all(dg.friction_cone_facets(c) @ fi >= -1e-9)


def test_result_serialises_and_prints():
    r = dg.force_closure(ex.equator_fingers(0.5), hand_jacobian=np.eye(9))
    d = r.to_dict()
    assert d["is_closure"] is True and d["rank"] == 6
    assert d["internal_forces"]["passes"] is True
    assert len(d["contact_forces"]) == 3 and len(d["contact_forces"][0]) == 3
    text = str(r)
    assert "force closure: YES" in text and "LP3" in text and "Clp" in text


@pytest.mark.parametrize("mu", [1e-12, 1e-10, 1e-7])
def test_thin_cones_keep_the_frictionless_verdict(mu):
    # d* of LP2 is a distance to the cone boundaries and vanishes with μ, yet a
    # grasp in form closure is in force closure for every μ >= 0.  (1e-12 is
    # the smallest non-zero μ drakegrasp.core.validation accepts.)
    for base in (ex.cube_seven_contacts(), ex.planar_square_four_contacts()):
        grasp = base.with_friction(mu, contact_model="hard_finger")
        for solve in (dg.force_closure, dg.force_closure_exact):
            r = solve(grasp)
            assert r.is_closure and r.decided_by == "normal forces"
            assert r.d_star < 1e-6 < r.margin
            f = np.concatenate(r.contact_forces)
            assert np.allclose(dg.grasp_matrix(grasp) @ f, 0, atol=1e-9)
    # Three equator fingers: normal forces (1, 1, 1) balance and G has rank 6
    # for any μ > 0, so closure holds however thin the cones.
    r = dg.force_closure(ex.equator_fingers(mu))
    assert r.is_closure and r.decided_by == "normal forces"
    # Without such a certificate, a thin cone is an honest "no": the offset
    # fingers' normal forces cannot balance the moment between them.
    r = dg.force_closure(ex.planar_two_finger_square(mu))
    assert not r.is_closure and r.decided_by == "d*"


@pytest.mark.parametrize("eps", [1e-8, 3e-8, 1e-7, 1e-6, 1e-3, 0.2])
def test_d_star_matches_the_closed_form_down_to_the_boundary(eps):
    # Square, fingers offset at atan(1/2): the best internal force is the squeeze
    # along the line between the contacts, whose distance to the nearer cone
    # facet is (μ - 1/2) / sqrt(1 + μ²) per unit normal force.
    mu = 0.5 + eps
    expected = (mu - 0.5) / np.hypot(1.0, mu)
    for solve in (dg.force_closure, dg.force_closure_exact):
        r = solve(ex.planar_two_finger_square(mu))
        assert r.d_star == pytest.approx(expected, rel=1e-3, abs=3e-10)
        assert r.near_boundary == (expected < 2 * r.tol)
