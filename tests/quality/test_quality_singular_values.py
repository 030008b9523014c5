"""Singular-value indices of G and of the hand-object matrix H."""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.quality import (
    distance_to_singularity,
    grasp_singular_values,
    hand_object_matrix,
    hand_object_singular_values,
    isotropy,
    manipulability_volume,
    min_singular_value,
    uniformity_of_transformation,
    wrench_ellipsoid_volume,
)


def _hand_built_G(grasp):
    """G from the formula [R_i; (c_i - p) × R_i] written out with np.cross."""
    cols = []
    for c in grasp.contacts:
        r = c.position - grasp.reference_point
        for k in range(c.num_components):
            if k < 3:
                u = c.frame[:, k]
                cols.append(np.concatenate([u, np.cross(r, u)]))
            else:  # soft finger: a pure moment about the normal
                cols.append(np.concatenate([np.zeros(3), c.frame[:, 0]]))
    return np.array(cols).T


def test_equator_analytic(helpers):
    # G Gᵀ = Σ_i [[I, S(r_i)ᵀ], [S(r_i), S(r_i) S(r_i)ᵀ]] (orthonormal frames).
    # On the unit equator Σ r_i = 0 and Σ (|r|² I - r rᵀ) = diag(1.5, 1.5, 3),
    # so G Gᵀ = diag(3, 3, 3, 1.5, 1.5, 3): σ = (√3 ×4, √1.5 ×2).
    g = helpers.equator_grasp(0.5)
    s = grasp_singular_values(g)
    assert np.allclose(s, np.sqrt([3, 3, 3, 3, 1.5, 1.5]), atol=1e-12)
    assert min_singular_value(g) == pytest.approx(np.sqrt(1.5))
    assert isotropy(g) == pytest.approx(np.sqrt(0.5))
    assert wrench_ellipsoid_volume(g) == pytest.approx(np.sqrt(3**4 * 1.5**2))
    # Torque scale b_s divides the moment block's eigenvalues by b_s².
    s2 = grasp_singular_values(g, torque_scale=2.0)
    expected = np.sort(np.sqrt([3, 3, 3, 1.5 / 4, 1.5 / 4, 3 / 4]))[::-1]
    assert np.allclose(s2, expected, atol=1e-12)
    # A mu = 0 hard finger keeps its tangential columns (geometry, not friction).
    assert np.allclose(grasp_singular_values(g.with_friction(0.0)), s)


def test_against_hand_built_matrix(helpers, rng):
    for model in ("hard_finger", "frictionless", "soft_finger"):
        g = helpers.random_grasp(rng, 4, 3, mu=0.5, model=model)
        g = dg.Grasp(g.contacts, reference_point=rng.normal(size=3))
        b = g.characteristic_length
        G = _hand_built_G(g)
        G[3:] /= b
        ref = np.linalg.svd(G, compute_uv=False)
        s = grasp_singular_values(g)
        assert s.shape == (6,)
        assert np.allclose(s[: ref.size], ref[:6], atol=1e-12)
        assert np.allclose(s[ref.size :], 0.0)
        assert wrench_ellipsoid_volume(g) == pytest.approx(
            np.sqrt(max(np.linalg.det(G @ G.T), 0.0)), rel=1e-9, abs=1e-12
        )


def test_invariance_under_rigid_motion(helpers, rng):
    # G' = blockdiag(R, R) G Q with Q orthogonal (frame changes), so the
    # singular values do not change under any rotation and translation.
    g = helpers.random_grasp(rng, 3, 3, mu=0.5)
    s = grasp_singular_values(g)
    for _ in range(3):
        q, r = np.linalg.qr(rng.normal(size=(3, 3)))
        R = q * np.sign(np.diag(r))
        if np.linalg.det(R) < 0:
            R[:, 0] *= -1
        moved = helpers.moved_grasp(g, R, rng.normal(size=3))
        assert np.allclose(grasp_singular_values(moved), s, atol=1e-12)


def test_planar(rng):
    # Planar frames are [n, t]: G Gᵀ = Σ [[I, J r], [(J r)ᵀ, |r|²]] with
    # J r = (-r_y, r_x).  Three contacts at unit radius 120° apart:
    # Σ r = 0, Σ |r|² = 3, so G Gᵀ = diag(3, 3, 3).
    contacts = []
    for t in np.deg2rad([10.0, 130.0, 250.0]):
        c = np.array([np.cos(t), np.sin(t)])
        contacts.append(dg.Contact(c, -c + 0.2 * rng.normal(size=2), mu=0.4))
    g = dg.Grasp(contacts)
    s = grasp_singular_values(g)
    assert s.shape == (3,)
    assert np.allclose(s, np.sqrt(3.0), atol=1e-12)
    assert isotropy(g) == pytest.approx(1.0)


def test_rank_deficient():
    one = dg.Grasp([dg.Contact([1.0, 0, 0], [-1.0, 0, 0], mu=0.5)])
    s = grasp_singular_values(one)
    assert s.shape == (6,) and np.all(s[3:] == 0.0)
    assert min_singular_value(one) == 0.0
    assert isotropy(one) == 0.0
    assert wrench_ellipsoid_volume(one) == 0.0


# ------------------------------------------------------------ H = (G⁺)ᵀ J


def _planar_gripper():
    """Two planar hard fingers at (±1, 0) squeezing; each fingertip an x-y stage.

    q̇ = [ẋ1, ẏ1, ẋ2, ẏ2].  The contact velocity of finger i in its contact
    frame is R_iᵀ [ẋ_i, ẏ_i], so J = blockdiag(R_1ᵀ, R_2ᵀ).
    """
    g = dg.Grasp(
        [
            dg.Contact([1.0, 0.0], [-1.0, 0.0], mu=0.5),
            dg.Contact([-1.0, 0.0], [1.0, 0.0], mu=0.5),
        ]
    )
    J = np.zeros((4, 4))
    J[:2, :2] = g.contacts[0].frame.T
    J[2:, 2:] = g.contacts[1].frame.T
    return g, J


def test_hand_built_planar_gripper():
    # Both tips moving +x (or +y) translate the object with them; opposite
    # y-motions of tips at x = ±1 turn it at ω = (ẏ1 - ẏ2) / 2; a squeeze
    # (ẋ1 = -ẋ2) is an internal motion and moves nothing (least squares).
    g, J = _planar_gripper()
    H = hand_object_matrix(g, J)
    expected = np.array(
        [[0.5, 0.0, 0.5, 0.0], [0.0, 0.5, 0.0, 0.5], [0.0, 0.5, 0.0, -0.5]]
    )
    assert np.allclose(H, expected, atol=1e-12)
    assert np.allclose(H @ [-1.0, 0.0, 1.0, 0.0], 0.0, atol=1e-12)
    s = hand_object_singular_values(g, J)
    assert np.allclose(s, np.sqrt(0.5))
    assert distance_to_singularity(g, J) == pytest.approx(np.sqrt(0.5))
    assert uniformity_of_transformation(g, J) == pytest.approx(1.0)
    assert manipulability_volume(g, J) == pytest.approx(np.sqrt(0.5) ** 3)


def test_hand_built_gripper_singular_when_a_stage_is_missing():
    # Without the y stages the object cannot be turned or moved in y.
    g, J = _planar_gripper()
    J_x = J[:, [0, 2]]
    assert distance_to_singularity(g, J_x) == 0.0
    assert uniformity_of_transformation(g, J_x) == np.inf
    assert manipulability_volume(g, J_x) == 0.0


def test_h_recovers_a_chosen_twist_map(helpers, rng):
    # If J = Gᵀ A (every hand motion moves the contacts rigidly with the object
    # twist A q̇), then H = (G⁺)ᵀ Gᵀ A = A when G has full row rank.  With torque
    # scaling b_s the twist is reported as [v; b_s ω], i.e. H = S⁻¹ A.
    g = helpers.random_grasp(rng, 3, 3, mu=0.5)
    n_q = 9
    U, _ = np.linalg.qr(rng.normal(size=(6, 6)))
    V, _ = np.linalg.qr(rng.normal(size=(n_q, n_q)))
    sv = np.array([3.0, 2.0, 1.5, 1.0, 0.7, 0.2])
    A = U @ np.hstack([np.diag(sv), np.zeros((6, n_q - 6))]) @ V.T
    J = _hand_built_G(g).T @ A
    H = hand_object_matrix(g, J, torque_scale=1.0)
    assert np.allclose(H, A, atol=1e-10)
    assert distance_to_singularity(g, J, torque_scale=1.0) == pytest.approx(0.2)
    assert uniformity_of_transformation(g, J, torque_scale=1.0) == pytest.approx(15.0)
    assert manipulability_volume(g, J, torque_scale=1.0) == pytest.approx(np.prod(sv))
    b = 2.5
    Hs = hand_object_matrix(g, J, torque_scale=b)
    assert np.allclose(Hs[:3], A[:3], atol=1e-10)
    assert np.allclose(Hs[3:], b * A[3:], atol=1e-10)


def test_bad_jacobian(helpers):
    g, J = _planar_gripper()
    with pytest.raises(dg.InvalidGraspError, match=r"shape \(4, n_v\)"):
        hand_object_matrix(g, J[:3])
    with pytest.raises(dg.InvalidGraspError, match=r"shape \(4, n_v\)"):
        hand_object_matrix(g, J.ravel())
    bad = J.copy()
    bad[0, 0] = np.nan
    with pytest.raises(dg.InvalidGraspError, match="non-finite"):
        distance_to_singularity(g, bad)
    with pytest.raises(dg.InvalidOptionError, match="torque_scale"):
        grasp_singular_values(g, torque_scale=-2.0)
