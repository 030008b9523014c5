"""Ranks, null spaces and verdicts do not depend on units, the reference point,
where the grasp sits, or the scale of J (the normalised G of grasp.py).

Each case below failed before the normalisation: the rank test counted singular
values of an unscaled G, whose moment rows grow with the distance to the
reference point and with the unit of length.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from random_grasps import random_inward_contacts

import drakegrasp as dg
from drakegrasp.core import examples as ex

SETTINGS = settings(
    max_examples=30,
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)

SCALES = [1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e6, 1e9]


def _scaled(grasp: dg.Grasp, scale: float, offset=None, reference_point=None):
    """The same grasp with lengths times ``scale``, moved by ``offset``."""
    offset = np.zeros(grasp.dim) if offset is None else np.asarray(offset)
    contacts = [c.with_(position=scale * c.position + offset) for c in grasp.contacts]
    p = scale * grasp.reference_point + offset
    if reference_point is not None:
        p = np.asarray(reference_point, dtype=float)
    b = scale * grasp.characteristic_length
    return dg.Grasp(contacts, reference_point=p, characteristic_length=b)


def test_normalised_matrix_has_the_null_space_of_g():
    grasp = ex.equator_fingers(mu=0.5)
    G, G_bar = dg.grasp_matrix(grasp), dg.invariant_grasp_matrix(grasp)
    # Same null space: G_bar = T G with T invertible, so T = G_bar G⁺ maps G
    # onto G_bar exactly when G has full row rank.
    T = G_bar @ np.linalg.pinv(G)
    np.testing.assert_allclose(T @ G, G_bar, atol=1e-12)
    assert abs(np.linalg.det(T)) > 1e-6


def test_normalised_matrix_ignores_reference_point_and_units():
    grasp = ex.equator_fingers(mu=0.5)
    reference = dg.invariant_grasp_matrix(grasp)
    for scale in SCALES:
        for p in ([0, 0, 0], [1e5, 3e4, -2e4]):
            moved = _scaled(grasp, scale, reference_point=p)
            np.testing.assert_allclose(
                dg.invariant_grasp_matrix(moved), reference, atol=1e-9
            )


@pytest.mark.parametrize("p", [[1e5, 3e4, -2e4], [-3e6, 1e6, 2e6]])
def test_far_reference_point_keeps_equator_grasp_closed(p):
    # The case: rank 4 and "no" with p = [1e5, 3e4, -2e4] (b = 1 m).
    grasp = ex.equator_fingers(mu=0.5)
    far = dg.Grasp(grasp.contacts, reference_point=p, characteristic_length=1.0)
    for result in (dg.force_closure(far), dg.force_closure_exact(far)):
        assert result.is_closure and result.rank == 6
    assert dg.force_closure(far).d_star == pytest.approx(0.4194, abs=1e-4)


@pytest.mark.parametrize("scale", SCALES)
def test_units_do_not_change_force_closure(scale):
    grasp = ex.equator_fingers(mu=0.5)
    base = dg.force_closure(grasp)
    result = dg.force_closure(_scaled(grasp, scale))
    assert (result.is_closure, result.rank) == (True, 6)
    assert result.d_star == pytest.approx(base.d_star, abs=1e-8)
    exact = dg.force_closure_exact(_scaled(grasp, scale))
    assert exact.is_closure and exact.rank == 6


def test_planar_pinwheel_far_reference_point_keeps_form_closure():
    # The case: rank 2 and "no" with p = (6e4, -8e4).
    square = ex.planar_square_four_contacts()
    far = dg.Grasp(square.contacts, reference_point=[6e4, -8e4])
    base, result = dg.form_closure(square), dg.form_closure(far)
    assert base.is_closure and result.is_closure and result.rank == 3
    assert result.d_star == pytest.approx(base.d_star, abs=1e-8)


@pytest.mark.parametrize("scale", SCALES)
def test_units_do_not_change_form_closure(scale):
    cube = ex.cube_seven_contacts()
    base = dg.form_closure(cube)
    result = dg.form_closure(_scaled(cube, scale))
    assert result.is_closure and result.rank == 6
    assert result.d_star == pytest.approx(base.d_star, abs=1e-8)


def _equator_hand_jacobian(grasp: dg.Grasp) -> np.ndarray:
    """Each finger a 3-DoF Cartesian finger: J is the identity on its forces."""
    return np.eye(grasp.num_components)


@pytest.mark.parametrize("scale", [1e-9, 1e-3, 1.0, 1e3, 1e9])
def test_jacobian_scale_does_not_change_lp3(scale):
    grasp = ex.equator_fingers(mu=0.5)
    J = _equator_hand_jacobian(grasp)
    base = dg.internal_forces(grasp, J)
    result = dg.internal_forces(grasp, scale * J)
    assert result.null_space_dim == base.null_space_dim == 0
    assert result.passes and base.passes
    # Only finger 0 driven: N(Jᵀ) = {f : f_0 = 0}, and the two other hard
    # fingers (rank 5 of 6 columns) balance along the line between them, so
    # dim N(G) ∩ N(Jᵀ) = 1 at every scale of J.
    J_one = np.zeros_like(J)
    J_one[:3, :3] = np.eye(3)
    dims = {dg.internal_forces(grasp, s * J_one).null_space_dim for s in (1e-9, 1, 1e9)}
    assert dims == {1}


def test_jacobian_columns_in_mixed_units_do_not_change_lp3():
    grasp = ex.equator_fingers(mu=0.5)
    rng = np.random.default_rng(3)
    J = rng.normal(size=(grasp.num_components, 4))
    base = dg.internal_forces(grasp, J)
    mixed = J * np.array([1e-8, 1.0, 1e6, 180 / np.pi])
    result = dg.internal_forces(grasp, mixed)
    assert result.null_space_dim == base.null_space_dim
    assert result.passes == base.passes
    assert result.d_star == pytest.approx(base.d_star, abs=1e-8)


def _random_grasp(seed: int, num: int, dim: int, model: str) -> dg.Grasp:
    rng = np.random.default_rng(seed)
    contacts = random_inward_contacts(rng, num, dim, model=model, nu=0.3)
    return dg.Grasp(contacts, characteristic_length=1.0)


def _check_same_verdicts(grasp, moved, *, compare_d_star=True):
    for decide in (dg.force_closure, dg.form_closure):
        a, b = decide(grasp), decide(moved)
        assert a.rank == b.rank
        if compare_d_star or decide is dg.form_closure:
            assert a.d_star == pytest.approx(b.d_star, abs=1e-7)
            if not (a.near_boundary or b.near_boundary):
                assert a.is_closure == b.is_closure


def _far_and_scaled(grasp, seed, log_scale, far):
    scale = 10.0**log_scale
    rng = np.random.default_rng(seed + 1)
    direction = rng.normal(size=grasp.dim)
    p = far * scale * direction / np.linalg.norm(direction)  # up to 1e6 b away
    return _scaled(grasp, scale, reference_point=p)


CASES = dict(
    seed=st.integers(0, 2**32 - 1),
    num=st.integers(2, 6),
    log_scale=st.sampled_from([-9, -6, -3, 0, 3, 6, 9]),
    far=st.sampled_from([0.0, 1e3, 1e6]),
)


@SETTINGS
@given(planar=st.booleans(), **CASES)
def test_verdicts_invariant_to_units_and_reference_point(
    seed, num, planar, log_scale, far
):
    grasp = _random_grasp(seed, num, 2 if planar else 3, "hard_finger")
    _check_same_verdicts(grasp, _far_and_scaled(grasp, seed, log_scale, far))


@SETTINGS
@given(**CASES)
def test_soft_finger_ranks_invariant_to_units_and_reference_point(
    seed, num, log_scale, far
):
    grasp = _random_grasp(seed, num, 3, "soft_finger")
    moved = _far_and_scaled(grasp, seed, log_scale, far)
    _check_same_verdicts(grasp, moved, compare_d_star=False)


def test_soft_finger_d_star_invariant_to_units():
    # Soft-finger rows measure m_n in units of b nu (friction_cone.soft_finger_facets),
    # so d* no longer changes with the unit of length.
    grasp = _random_grasp(95389, 3, 3, "soft_finger")
    moved = _scaled(grasp, 1e-9)
    assert dg.force_closure(moved).d_star == pytest.approx(
        dg.force_closure(grasp).d_star, abs=1e-7
    )
