"""LP3: internal forces the hand can or cannot control."""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.core import examples as ex


def _jacobian(grasp, rows_per_contact):
    """J with one hand joint per contact, moving it along the given local rows."""
    J = np.zeros((grasp.num_components, grasp.num_contacts))
    for i, s in enumerate(grasp.component_slices()):
        J[s, i] = rows_per_contact
    return J


def test_fingers_that_push_along_their_normals_control_the_squeeze():
    grasp = ex.equator_fingers(0.5)
    J = _jacobian(grasp, [1.0, 0.0, 0.0])
    r = dg.force_closure(grasp, hand_jacobian=J)
    assert r.is_closure and r.internal_forces.passes
    assert r.internal_forces.null_space_dim == 0


def test_fingers_that_only_slide_tangentially_cannot_squeeze():
    grasp = ex.equator_fingers(0.5)
    J = _jacobian(grasp, [0.0, 1.0, 0.0])  # joints move the tips along t1
    r = dg.force_closure(grasp, hand_jacobian=J)
    assert r.frictional_closure and not r.is_closure
    lp3 = r.internal_forces
    assert not lp3.passes and lp3.d_star > 0.1 and lp3.null_space_dim > 0
    # The reported force is an uncontrollable internal force with f_n >= d*.
    f = np.concatenate(lp3.contact_forces)
    assert np.allclose(dg.grasp_matrix(grasp) @ f, 0, atol=1e-8)
    assert np.allclose(J.T @ f, 0, atol=1e-8)
    assert min(fi[0] for fi in lp3.contact_forces) >= lp3.d_star - 1e-9


def test_one_actuator_closing_both_jaws_controls_the_squeeze():
    grasp = ex.spatial_two_fingers(
        0.5, contact_model="soft_finger", torsional_friction=0.3
    )
    closing = np.zeros((8, 1))
    closing[[0, 4], 0] = 1.0  # both fingers move along their normals together
    assert dg.force_closure(grasp, hand_jacobian=closing).is_closure
    # A joint that translates both jaws sideways together cannot squeeze.
    sideways = np.zeros((8, 1))
    sideways[[0, 4], 0] = [1.0, -1.0]
    r = dg.force_closure(grasp, hand_jacobian=sideways)
    assert r.frictional_closure and not r.is_closure


def test_exact_cones_with_a_hand_jacobian():
    grasp = ex.equator_fingers(0.5)
    good = dg.force_closure_exact(grasp, hand_jacobian=_jacobian(grasp, [1, 0, 0]))
    bad = dg.force_closure_exact(grasp, hand_jacobian=_jacobian(grasp, [0, 1, 0]))
    assert good.is_closure and not bad.is_closure


def test_null_space_dimension_matches_an_independent_count():
    grasp = ex.equator_fingers(0.5)
    J = _jacobian(grasp, [0.0, 1.0, 0.0])
    G = dg.grasp_matrix(grasp)
    # dim(N(G) ∩ N(J^T)) = dim N([G; J^T]) by SVD of the stacked matrix.
    s = np.linalg.svd(np.vstack([G, J.T]), compute_uv=False)
    expected = G.shape[1] - np.sum(s > 1e-9 * s[0])
    assert dg.internal_forces(grasp, J).null_space_dim == expected


def test_wrong_jacobian_shape_names_the_expected_shape():
    grasp = ex.equator_fingers(0.5)
    with pytest.raises(dg.InvalidGraspError, match=r"\(9, n_v\).*\(6, 3\)"):
        dg.force_closure(grasp, hand_jacobian=np.zeros((6, 3)))


def test_lp3_and_the_null_space_count_agree_on_noisy_jacobians(rng):
    # Contacts measured to ~1e-7 make [G; J^T] full rank only by round-off.  LP3
    # must then see the same numerical null space that null_space_dim counts.
    grasp = ex.equator_fingers(0.5)
    J = _jacobian(grasp, [0.0, 1.0, 0.0])
    clean = dg.internal_forces(grasp, J)
    for scale in (1e-12, 1e-11, 3e-10):
        noisy = J + scale * rng.normal(size=J.shape)
        s = np.linalg.svd(np.vstack([dg.grasp_matrix(grasp), noisy.T]), compute_uv=0)
        assert s[-1] < 1e-9 * s[0]  # still rank deficient at the default rank_tol
        r = dg.internal_forces(grasp, noisy)
        assert r.null_space_dim == clean.null_space_dim > 0
        assert not r.passes and r.d_star == pytest.approx(clean.d_star, abs=1e-6)
    # Above rank_tol the noise is a real change of J: the squeeze is controlled.
    r = dg.internal_forces(grasp, J + 1e-3 * rng.normal(size=J.shape))
    assert r.null_space_dim == 0 and r.passes


def test_a_squeeze_whose_normals_are_round_off_does_not_fail_lp3(monkeypatch):
    # A nearly degenerate WSG-50 grasp of the sugar box (pads and palm
    # touching) gave, on one machine, LP3's optimum with tangential components
    # of 1.7e11 and normals of 1.29e-6: d* above tol by round-off of a force
    # 1e17 times larger, and the verdict flipped between machines.  Normals
    # below rank_tol of the force's size are not a squeeze.
    from drakegrasp.closure import verdicts

    grasp = ex.equator_fingers(0.5)
    J = _jacobian(grasp, [1.0, 0.0, 0.0])
    real = verdicts._solve_margin

    def pathological(prog, variables, *, conic):
        d, f, solver, status = real(prog, variables, conic=conic)
        f = f.copy()
        f[grasp.normal_indices()] = 1.29e-6
        f[1] = 1.7e11  # a tangential component
        return 1.29e-6, f, solver, status

    monkeypatch.setattr(verdicts, "_solve_margin", pathological)
    lp3 = dg.internal_forces(grasp, J)
    assert lp3.d_star > lp3.tol and lp3.passes and lp3.certificate is None
    assert lp3.resolution == pytest.approx(1.7e11 * 1e-9)
    assert lp3.threshold == lp3.resolution and not lp3.near_boundary
    assert "round-off, not a squeeze" in str(lp3)
    # a real failure is resolved: its normals are a fair part of its size
    monkeypatch.setattr(verdicts, "_solve_margin", real)
    bad = dg.internal_forces(grasp, _jacobian(grasp, [0.0, 1.0, 0.0]))
    assert not bad.passes and bad.resolution < 1e-8 < 0.1 < bad.d_star
