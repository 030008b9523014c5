"""The geometry the pictures draw, checked without a renderer."""

import numpy as np
import pytest

from drakegrasp import Contact, Grasp, InvalidOptionError, grasp_matrix
from drakegrasp.core.friction_cone import friction_cone_generators
from drakegrasp.visualization import (
    cone_edge_directions,
    contact_forces_in_grasp_frame,
    contact_pose_3d,
    exact_cone_mesh,
    normalize_contact_forces,
    pyramid_mesh,
)
from drakegrasp.visualization.geometry import pyramid_generators


def _spatial_grasp():
    rng = np.random.default_rng(7)
    contacts = []
    for model in ("hard_finger", "soft_finger", "frictionless", "hard_finger"):
        c = rng.normal(size=3)
        n = rng.normal(size=3)
        contacts.append(
            Contact(c, n, mu=0.4, contact_model=model, torsional_friction=0.2)
            if model == "soft_finger"
            else Contact(c, n, mu=0.4, contact_model=model)
        )
    return Grasp(contacts, reference_point=[0.1, -0.2, 0.3])


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_exact_cone_rim_lies_on_the_coulomb_cone(sign):
    mu, h = 0.7, 0.3
    v, f = exact_cone_mesh(mu, h, num_segments=24, sign=sign)
    assert v.shape == (25, 3) and f.shape == (24, 3)
    np.testing.assert_array_equal(v[0], 0.0)
    rim = v[1:]
    # Along the axis: sign * h; radially: mu times that (‖f_t‖ = μ f_n).
    np.testing.assert_allclose(rim[:, 0], sign * h)
    np.testing.assert_allclose(np.linalg.norm(rim[:, 1:], axis=1), mu * h)
    # Every face is (apex, k, k+1) and the rim points go once around.
    assert np.all(f[:, 0] == 0)
    assert sorted(f[:, 1]) == list(range(1, 25))
    angles = np.unwrap(np.arctan2(rim[:, 2], rim[:, 1]))
    assert np.all(np.diff(angles) > 0)


def test_pyramid_edges_are_the_cone_generators():
    contact = Contact([0, 0, 0], [0, 0, 1], mu=0.5)
    S = pyramid_generators(contact, 6, characteristic_length=1.0)
    np.testing.assert_allclose(S, friction_cone_generators(contact, 6))
    for sign in (1.0, -1.0):
        v, f = pyramid_mesh(S, 0.2, sign=sign)
        np.testing.assert_allclose(v[1:], sign * 0.2 * S.T)
        assert f.shape == (6, 3)


def test_pyramid_of_soft_finger_drops_the_pure_moment_generators():
    contact = Contact(
        [0, 0, 0],
        [1, 0, 0],
        mu=0.3,
        contact_model="soft_finger",
        torsional_friction=0.1,
    )
    S = pyramid_generators(contact, 5, characteristic_length=2.0)
    assert S.shape == (3, 5)
    np.testing.assert_allclose(np.linalg.norm(S[1:], axis=0), 0.3)
    frictionless = Contact([0, 0, 0], [1, 0, 0], mu=0.3, contact_model="frictionless")
    assert pyramid_generators(frictionless, 5, characteristic_length=1.0).shape == (
        3,
        0,
    )


def test_contact_pose_3d_is_a_rotation_with_the_normal_first():
    for contact in [
        Contact([1.0, 2.0], [0.3, -1.0], mu=0.2),
        Contact([1.0, 2.0, 3.0], [0.3, -1.0, 0.5], mu=0.2),
    ]:
        R, p = contact_pose_3d(contact)
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0)
        n3 = np.zeros(3)
        n3[: contact.dim] = contact.normal
        np.testing.assert_allclose(R[:, 0], n3)
        np.testing.assert_allclose(p[: contact.dim], contact.position)
    # A planar contact stays in the z = 0 plane and keeps t = (-n_y, n_x).
    R, p = contact_pose_3d(Contact([1.0, 2.0], [0.0, 1.0]))
    np.testing.assert_allclose(R[:, 1], [-1.0, 0.0, 0.0])
    assert p[2] == 0.0


def test_forces_in_grasp_frame_reproduce_the_grasp_matrix():
    """Σ R_i f_i and Σ (c_i - p) × R_i f_i are the rows of G f (second route)."""
    grasp = _spatial_grasp()
    rng = np.random.default_rng(3)
    f = rng.normal(size=grasp.num_components)
    per_contact = [f[s] for s in grasp.component_slices()]
    f_G = contact_forces_in_grasp_frame(grasp, per_contact)
    w = grasp_matrix(grasp) @ f
    np.testing.assert_allclose(f_G.sum(axis=0), w[:3], atol=1e-12)
    moments = np.cross(grasp.positions - grasp.reference_point, f_G).sum(axis=0)
    # The soft finger's m_n adds a pure moment along its normal.
    soft = grasp.contacts[1]
    moments += per_contact[1][3] * soft.normal
    np.testing.assert_allclose(moments, w[3:], atol=1e-12)


def test_planar_forces_in_grasp_frame_reproduce_the_grasp_matrix():
    grasp = Grasp(
        [
            Contact([1.0, 0.2], [-1.0, 0.1], mu=0.5),
            Contact([-0.3, 1.0], [0.2, -1.0], mu=0.5, contact_model="frictionless"),
        ],
        reference_point=[0.1, 0.1],
    )
    f = np.array([2.0, -0.4, 1.5])
    per_contact = [f[s] for s in grasp.component_slices()]
    f_G = contact_forces_in_grasp_frame(grasp, per_contact)
    w = grasp_matrix(grasp) @ f
    np.testing.assert_allclose(f_G.sum(axis=0), w[:2], atol=1e-12)
    r = grasp.positions - grasp.reference_point
    mz = np.sum(r[:, 0] * f_G[:, 1] - r[:, 1] * f_G[:, 0])
    assert mz == pytest.approx(w[2], abs=1e-12)


def test_normalize_contact_forces_pads_and_accepts_results():
    grasp = _spatial_grasp()

    class FakeResult:
        contact_forces = (np.array([1.0]), [2.0], [3.0], np.array([4.0, 0.1]))

    out = normalize_contact_forces(grasp, FakeResult())
    assert [a.size for a in out] == [3, 4, 1, 3]
    np.testing.assert_allclose(out[2], [3.0])
    np.testing.assert_allclose(out[3], [4.0, 0.1, 0.0])
    np.testing.assert_allclose(out[0], [1.0, 0.0, 0.0])
    np.testing.assert_allclose(out[1], [2.0, 0.0, 0.0, 0.0])
    assert normalize_contact_forces(grasp, None) is None
    assert normalize_contact_forces(grasp, ()) is None


def test_normalize_contact_forces_rejects_mismatches():
    grasp = _spatial_grasp()
    with pytest.raises(InvalidOptionError, match="4 contacts"):
        normalize_contact_forces(grasp, [[1.0]] * 3)
    with pytest.raises(InvalidOptionError, match="frictionless"):
        normalize_contact_forces(grasp, [[1.0], [1.0], [1.0, 0.5], [1.0]])
    with pytest.raises(InvalidOptionError, match="not finite"):
        normalize_contact_forces(grasp, [[np.nan], [1.0], [1.0], [1.0]])


def test_planar_cone_edges_make_angle_atan_mu_with_the_normal():
    """Edge rays R[1, ±μ] are the normal rotated by ±atan μ (independent route)."""
    mu = 0.6
    n = np.array([np.cos(2.0), np.sin(2.0)])
    U = cone_edge_directions(Contact([0.0, 0.0], n, mu=mu))
    a = np.arctan(mu)
    for row, angle in zip(U, (a, -a), strict=True):
        rot = np.array(
            [[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]
        )
        np.testing.assert_allclose(row, rot @ n, atol=1e-12)
    U0 = cone_edge_directions(
        Contact([0.0, 0.0], n, mu=mu, contact_model="frictionless")
    )
    np.testing.assert_allclose(U0, [n, n])
    with pytest.raises(InvalidOptionError, match="planar"):
        cone_edge_directions(Contact([0, 0, 0], [1, 0, 0], mu=0.1))
