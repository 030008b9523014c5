"""G against independent routes: kinematic duality, moment transport, planar slice."""

import numpy as np
import pytest

import drakegrasp as dg


def _contact_velocity_route(grasp, twist):
    """Velocity of each contact point, in its contact frame, under a body twist.

    Twist = [v_p; ω] of the object about p.  By virtual work, G^T maps the twist
    to the velocity components conjugate to the contact forces.
    """
    v, w = twist[:3], twist[3:]
    out = []
    for c in grasp.contacts:
        vc = v + np.cross(w, c.position - grasp.reference_point)
        local = c.frame.T @ vc
        comps = list(local[: min(c.num_components, 3)])
        if c.num_components == 4:
            comps.append(c.normal @ w)  # angular velocity about n meets m_n
        out.extend(comps)
    return np.array(out)


@pytest.mark.parametrize("model", ["frictionless", "hard_finger", "soft_finger"])
def test_transpose_maps_twists_to_contact_velocities(rng, model, make_contacts):
    contacts = make_contacts(rng, 4, mu=0.5, model=model, nu=0.2)
    grasp = dg.Grasp(contacts, reference_point=rng.normal(size=3))
    G = dg.grasp_matrix(grasp)
    assert G.shape == (6, grasp.num_components)
    for _ in range(5):
        twist = rng.normal(size=6)
        assert np.allclose(G.T @ twist, _contact_velocity_route(grasp, twist))


def test_moving_the_reference_point_transports_the_moment(rng, make_contacts):
    contacts = make_contacts(rng, 3, mu=0.3)
    p, q = rng.normal(size=3), rng.normal(size=3)
    Gp = dg.grasp_matrix(dg.Grasp(contacts, reference_point=p))
    Gq = dg.grasp_matrix(dg.Grasp(contacts, reference_point=q))
    f = rng.normal(size=Gp.shape[1])
    wp, wq = Gp @ f, Gq @ f
    assert np.allclose(wq[:3], wp[:3])
    assert np.allclose(wq[3:], wp[3:] + np.cross(p - q, wp[:3]))


def test_planar_matrix_is_the_planar_slice_of_the_spatial_one(rng, make_contacts):
    for _ in range(10):
        c2 = make_contacts(rng, 3, dim=2, mu=0.4)
        g2 = dg.Grasp(c2, reference_point=rng.normal(size=2))
        f2 = rng.normal(size=g2.num_components)
        w2 = dg.grasp_matrix(g2) @ f2
        # The same physical forces applied to the 3-D embedding of the contacts.
        total = np.zeros(6)
        p3 = np.append(g2.reference_point, 0.0)
        for c, s in zip(c2, g2.component_slices(), strict=True):
            force = np.append(c.frame @ f2[s], 0.0)
            r = np.append(c.position, 0.0) - p3
            total += np.concatenate([force, np.cross(r, force)])
        assert np.allclose(w2, total[[0, 1, 5]])


def test_hand_computed_example():
    # Finger at (0, 0, 1) pushing down (-z), p at the origin.
    c = dg.Contact(
        [0, 0, 1],
        [0, 0, -1],
        mu=0.5,
        contact_model="soft_finger",
        torsional_friction=0.0,
    )
    G = dg.grasp_matrix(dg.Grasp([c]))
    n, t1, t2 = c.frame.T
    expected = np.zeros((6, 4))
    expected[:3, 0], expected[:3, 1], expected[:3, 2] = n, t1, t2
    expected[3:, 0] = np.cross([0, 0, 1], n)  # = 0
    expected[3:, 1] = np.cross([0, 0, 1], t1)
    expected[3:, 2] = np.cross([0, 0, 1], t2)
    expected[3:, 3] = n
    assert np.allclose(G, expected)
    # by hand: t1 = x (|n_x| = |n_y| = 0, first axis), and z × x = y
    assert np.allclose(t1, [1, 0, 0]) and np.allclose(G[3:, 1], [0, 1, 0])


def test_normal_grasp_matrix_is_the_normal_columns_of_G(rng, make_contacts):
    grasp = dg.Grasp(make_contacts(rng, 5, mu=0.5))
    G = dg.grasp_matrix(grasp)
    assert np.allclose(dg.normal_grasp_matrix(grasp), G[:, grasp.normal_indices()])


def test_default_characteristic_length_is_the_farthest_contact():
    g = dg.Grasp([dg.Contact([0, 2, 0], [0, -1, 0]), dg.Contact([1, 0, 0], [-1, 0, 0])])
    assert g.characteristic_length == pytest.approx(2.0)
    g = dg.Grasp([dg.Contact([0, 0], [1, 0])])
    assert g.characteristic_length == 1.0
