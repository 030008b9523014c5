"""Singular-value indices of G and of the hand-object matrix H."""

import numpy as np
import pytest
from grasp_builders import random_grasp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

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


def _hand_built_scaled_G(grasp, b):
    """``T G S`` written out: moment rows over ``b`` but the torsion columns.

    A soft finger's ``m_n`` in units of ``b`` newtons has the column
    ``[0; b n] / (1, b) = [0; n]``.
    """
    G = _hand_built_G(grasp)
    k = 0
    for c in grasp.contacts:
        for j in range(c.num_components):
            if j < 3:
                G[3:, k] /= b
            k += 1
    return G


def test_against_hand_built_matrix(helpers, rng):
    mixed = ["soft_finger", "hard_finger", "frictionless", "soft_finger"]
    for model in ("hard_finger", "frictionless", "soft_finger", mixed):
        if isinstance(model, list):
            contacts = [
                dg.Contact(
                    c.position,
                    c.normal,
                    mu=0.5,
                    contact_model=m,
                    torsional_friction=0.3,
                )
                for c, m in zip(
                    helpers.random_grasp(rng, 4, 3).contacts, model, strict=True
                )
            ]
        else:
            contacts = helpers.random_grasp(rng, 4, 3, mu=0.5, model=model).contacts
        g = dg.Grasp(contacts, reference_point=rng.normal(size=3))
        b = g.characteristic_length
        G = _hand_built_scaled_G(g, b)
        ref = np.linalg.svd(G, compute_uv=False)
        s = grasp_singular_values(g)
        assert s.shape == (6,)
        assert np.allclose(s[: ref.size], ref[:6], atol=1e-12)
        assert np.allclose(s[ref.size :], 0.0)
        assert wrench_ellipsoid_volume(g) == pytest.approx(
            np.sqrt(max(np.linalg.det(G @ G.T), 0.0)), rel=1e-9, abs=1e-12
        )


def test_soft_finger_equator_analytic(helpers):
    # Soft fingers add Σ n_i n_iᵀ = diag(1.5, 1.5, 0) to the moment block of
    # test_equator_analytic: G Gᵀ = 3 I, σ = √3 six times, whatever the unit.
    # (Dividing the torsion columns by b too gave √(1.5 + 1.5 / b²): 1224.7
    # at b = 1 mm.)
    for s in (1e-3, 1.0, 1e3):
        g = helpers.equator_grasp(
            0.5, radius=s, model="soft_finger", torsional_friction=0.1
        )
        assert g.characteristic_length == pytest.approx(s)
        sv = grasp_singular_values(g)
        np.testing.assert_allclose(sv, np.sqrt(3.0), rtol=1e-12)
        assert isotropy(g) == pytest.approx(1.0, abs=1e-12)
        assert wrench_ellipsoid_volume(g) == pytest.approx(27.0, rel=1e-12)
        assert min_singular_value(g) == pytest.approx(np.sqrt(3.0), rel=1e-12)
        q = dg.grasp_quality(g)
        assert (q.isotropy, q.wrench_ellipsoid_volume) == (
            isotropy(g),
            wrench_ellipsoid_volume(g),
        )
    # b_s = 2 R: force rows 3, the 6 tangential moment columns give
    # diag(1.5, 1.5, 3) / 4 and the torsion columns still diag(1.5, 1.5, 0).
    g = helpers.equator_grasp(0.5, model="soft_finger", torsional_friction=0.1)
    expected = np.sqrt([3, 3, 3, 1.5 / 4 + 1.5, 1.5 / 4 + 1.5, 3 / 4])
    np.testing.assert_allclose(
        grasp_singular_values(g, torque_scale=2.0), np.sort(expected)[::-1], rtol=1e-12
    )


def test_soft_finger_at_unit_length_is_the_unscaled_matrix(helpers, rng):
    # At b = 1 the old (torsion column over b) and the new (kept) matrices
    # coincide: both are G itself, to the bit.
    g = helpers.random_grasp(rng, 4, 3, model="soft_finger", nu=0.3)
    g = dg.Grasp(g.contacts, characteristic_length=1.0)
    G = dg.grasp_matrix(g)
    J = rng.normal(size=(g.num_components, 9))
    ref = np.linalg.svd(G, compute_uv=False)
    assert (grasp_singular_values(g) == ref).all()
    assert (grasp_singular_values(g, torque_scale=1.0) == ref).all()
    H = np.linalg.pinv(G, rcond=dg.quality._common.RANK_TOL).T @ J
    assert (hand_object_matrix(g, J) == H).all()


def _soft_grasp(seed, scale, models):
    """Contacts of ``models`` on a sphere of radius ``scale``; p, b and J scaled."""
    rng = np.random.default_rng(seed)
    unit = [
        dg.Contact(
            c.position, c.normal, mu=0.5, contact_model=m, torsional_friction=0.2
        )
        for c, m in zip(random_grasp(rng, len(models)).contacts, models, strict=True)
    ]
    p, b = 0.3 * rng.normal(size=3), rng.uniform(0.3, 3.0)
    J = rng.normal(size=(sum(c.num_components for c in unit), 8))
    contacts = [c.with_(position=scale * c.position) for c in unit]
    grasp = dg.Grasp(
        contacts, reference_point=scale * p, characteristic_length=scale * b
    )
    # The same hand in the new unit: contact velocities (m/s) scale, a soft
    # finger's spin about its normal (rad/s) does not.
    J = J.copy()
    k = 0
    for c in unit:
        J[k : k + min(c.num_components, 3)] *= scale
        k += c.num_components
    return grasp, J


MODELS = st.lists(
    st.sampled_from(["soft_finger", "soft_finger", "hard_finger", "frictionless"]),
    min_size=2,
    max_size=5,
).filter(lambda m: "soft_finger" in m)


@settings(derandomize=True, max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    exponent=st.floats(-4.0, 4.0),
    models=MODELS,
)
def test_soft_finger_metrics_do_not_depend_on_the_unit_of_length(
    seed, exponent, models
):
    # Positions, p and b (or torque_scale) given in a unit 10^exponent times
    # smaller: G's indices are dimensionless; H's rows are m/s, so its
    # singular values scale with the unit and its condition number does not.
    s = 10.0**exponent
    g1, J1 = _soft_grasp(seed, 1.0, models)
    gs, Js = _soft_grasp(seed, s, models)
    sv1 = grasp_singular_values(g1)
    np.testing.assert_allclose(grasp_singular_values(gs), sv1, rtol=1e-9, atol=1e-12)
    ts = 1.7 * g1.characteristic_length
    np.testing.assert_allclose(
        grasp_singular_values(gs, torque_scale=s * ts),
        grasp_singular_values(g1, torque_scale=ts),
        rtol=1e-9,
        atol=1e-12,
    )
    assert isotropy(gs) == pytest.approx(isotropy(g1), rel=1e-9, abs=1e-12)
    assert wrench_ellipsoid_volume(gs) == pytest.approx(
        wrench_ellipsoid_volume(g1), rel=1e-8, abs=1e-12
    )
    assert min_singular_value(gs) == pytest.approx(
        min_singular_value(g1), rel=1e-9, abs=1e-12
    )
    h1 = hand_object_singular_values(g1, J1)
    np.testing.assert_allclose(
        hand_object_singular_values(gs, Js) / s, h1, rtol=1e-8, atol=1e-12 * h1[0]
    )
    if h1[-1] > 1e-6 * h1[0]:  # else σ_min(H) is rounding and so is σ_max/σ_min
        u1 = uniformity_of_transformation(g1, J1)
        assert uniformity_of_transformation(gs, Js) == pytest.approx(u1, rel=1e-7)


@settings(
    derandomize=True,
    max_examples=25,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],  # stateless
)
@given(seed=st.integers(0, 2**32 - 1), exponent=st.floats(-3.0, 3.0), models=MODELS)
def test_soft_finger_metrics_invariant_under_rigid_motion(
    helpers, seed, exponent, models
):
    # blockdiag(R, R) G Q with Q turning each tangent plane: S touches only
    # the torsion columns, which Q leaves alone, so σ(T G S) is unchanged.
    g, _ = _soft_grasp(seed, 10.0**exponent, models)
    rng = np.random.default_rng(seed)
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    R = q * np.sign(np.diag(r))
    if np.linalg.det(R) < 0:
        R[:, 0] *= -1
    moved = helpers.moved_grasp(g, R, 10.0**exponent * rng.normal(size=3))
    np.testing.assert_allclose(
        grasp_singular_values(moved), grasp_singular_values(g), rtol=1e-9, atol=1e-12
    )
    assert isotropy(moved) == pytest.approx(isotropy(g), rel=1e-9, abs=1e-12)


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
