import numpy as np
import pytest

import drakegrasp as dg


def test_spatial_generators_follow_the_convention():
    c = dg.Contact([0, 0, 1], [0, 0, -1], mu=0.3)
    S = dg.friction_cone_generators(c, 8)
    k = np.arange(1, 9)
    expected = np.vstack(
        [np.ones(8), 0.3 * np.cos(2 * np.pi * k / 8), 0.3 * np.sin(2 * np.pi * k / 8)]
    )
    assert np.allclose(S, expected)


@pytest.mark.parametrize("n_g", [3, 4, 8, 13])
@pytest.mark.parametrize("mu", [0.05, 0.5, 2.0])
def test_spatial_facets_are_unit_rows_through_consecutive_generators(mu, n_g):
    c = dg.Contact([0, 0, 1], [0, 0, -1], mu=mu)
    S = dg.friction_cone_generators(c, n_g)
    F = dg.friction_cone_facets(c, n_g)
    assert F.shape == (n_g, 3)
    assert np.allclose(np.linalg.norm(F, axis=1), 1.0)
    assert np.all(F[:, 0] > 0)  # positive on the axis [1, 0, 0]
    FS = F @ S
    assert np.all(FS > -1e-12)
    for k in range(n_g):  # facet k contains generators k and k+1, no other
        on = np.flatnonzero(np.abs(FS[k]) < 1e-12)
        assert set(on) == {k, (k + 1) % n_g}


def test_polyhedral_cone_is_inscribed_in_the_exact_one(rng):
    mu = 0.7
    c = dg.Contact([0, 0, 1], [0, 0, -1], mu=mu)
    F = dg.friction_cone_facets(c, 8)
    f = np.column_stack([np.ones(20000), rng.uniform(-1, 1, size=(20000, 2))])
    inside_poly = np.all(f @ F.T >= 0, axis=1)
    inside_exact = np.linalg.norm(f[:, 1:], axis=1) <= mu
    assert inside_poly.any() and (inside_exact & ~inside_poly).any()
    assert not np.any(inside_poly & ~inside_exact)
    # and contains the cone of half-angle atan(mu cos(pi/8)): the inscribed circle
    inner = np.linalg.norm(f[:, 1:], axis=1) <= mu * np.cos(np.pi / 8) - 1e-9
    assert not np.any(inner & ~inside_poly)


def test_planar_cone_matches_the_formula():
    mu = 0.4
    c = dg.Contact([0, 1], [0, -1], mu=mu)
    F = dg.friction_cone_facets(c)
    assert np.allclose(F, np.array([[mu, 1], [mu, -1]]) / np.hypot(1, mu))
    assert np.allclose(dg.friction_cone_generators(c), [[1, 1], [mu, -mu]])


def test_frictionless_and_degenerate_cones():
    c = dg.Contact([0, 0, 1], [0, 0, -1], contact_model="frictionless", mu=0.9)
    assert np.allclose(dg.friction_cone_facets(c), [[1.0]])
    assert np.allclose(dg.friction_cone_generators(c), [[1.0]])
    ray = dg.Contact([0, 0, 1], [0, 0, -1], mu=0.0)
    S = dg.friction_cone_generators(ray)
    assert np.allclose(S, [[1], [0], [0]])
    F = dg.friction_cone_facets(ray)
    # The ray's H-form: f_n >= 0 and f_t1 = f_t2 = 0 as pairs of rows.
    assert np.allclose(F @ [1, 0, 0], [1, 0, 0, 0, 0])
    assert np.any(F @ [1, 1e-3, 0] < 0)


def _soft_finger_on_top():
    """A soft finger at (0, 0, 1) pushing down, μ = 0.5, ν = 0.2."""
    return dg.Contact(
        [0, 0, 1], [0, 0, -1], mu=0.5, contact_model="soft_finger",
        torsional_friction=0.2,
    )  # fmt: skip


def test_soft_finger_cone_is_the_hull_of_its_generators():
    c = _soft_finger_on_top()
    b = 0.1
    S = dg.friction_cone_generators(c, 8, characteristic_length=b)
    F = dg.friction_cone_facets(c, 8, characteristic_length=b)
    assert S.shape == (4, 10) and F.shape == (16, 4)
    assert np.allclose(S[:, -2:].T, [[1, 0, 0, b * 0.2], [1, 0, 0, -b * 0.2]])
    assert np.all(F[:, 0] > 0)
    # Not unit rows: on the m_n = 0 slice each row is the hard finger's unit row
    # (so a soft finger's d* is never below a hard finger's).
    hard = dg.friction_cone_facets(c.with_(contact_model="hard_finger"), 8)
    assert np.allclose(F[:8, :3], hard) and np.allclose(F[8:, :3], hard)
    assert np.allclose(F[:8, 3], -F[8:, 3]) and np.all(F[:8, 3] < 0)
    FS = F @ S
    assert np.all(FS > -1e-12)
    # Every facet of a 4-D cone is spanned by exactly three generators here.
    assert np.all(np.sum(np.abs(FS) < 1e-12, axis=1) == 3)
    # Inscribed in the exact soft-finger cone |f_t|/mu + |m|/(b nu) <= f_n.
    rng = np.random.default_rng(0)
    f = np.column_stack(
        [
            np.ones(5000),
            rng.uniform(-0.6, 0.6, (5000, 2)),
            rng.uniform(-0.03, 0.03, 5000),
        ]
    )
    poly = np.all(f @ F.T >= 0, axis=1)
    exact = np.linalg.norm(f[:, 1:3], axis=1) / 0.5 + np.abs(f[:, 3]) / (b * 0.2) <= 1
    assert poly.any() and not np.any(poly & ~exact)


def test_soft_finger_needs_the_characteristic_length():
    c = _soft_finger_on_top()
    with pytest.raises(dg.InvalidOptionError, match="characteristic_length"):
        dg.friction_cone_facets(c)


def test_cone_membership_is_invariant_to_force_scaling(rng):
    c = dg.Contact([0, 0, 1], [0, 0, -1], mu=0.6)
    F = dg.friction_cone_facets(c)
    f = np.column_stack([np.ones(100), rng.uniform(-1, 1, (100, 2))])
    for alpha in (1e-3, 2.0, 1e4):
        assert np.array_equal(np.all(f @ F.T >= 0, 1), np.all(alpha * f @ F.T >= 0, 1))
