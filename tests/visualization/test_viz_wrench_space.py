"""Wrench space of planar grasps: primitive wrenches, hull, origin inside."""

import itertools

import numpy as np
import pytest

from drakegrasp import Contact, Grasp, InvalidOptionError, grasp_matrix
from drakegrasp.closure.verdicts import force_closure
from drakegrasp.core.friction_cone import friction_cone_generators
from drakegrasp.visualization import plot_wrench_space, wrench_hull, wrench_space_points

pytest.importorskip("scipy", reason="scipy not installed")


def _antipodal_disc(mu, radius=1.0):
    return Grasp(
        [
            Contact([radius, 0.0], [-1.0, 0.0], mu=mu),
            Contact([-radius, 0.0], [1.0, 0.0], mu=mu),
        ]
    )


def _brute_force_facets(P):
    """Facet planes of conv(P) in 3-D by trying every triple (no Qhull).

    Returns the signed distances of the origin to every facet plane (positive
    on the hull's side).
    """
    dists = []
    for i, j, k in itertools.combinations(range(len(P)), 3):
        n = np.cross(P[j] - P[i], P[k] - P[i])
        if np.linalg.norm(n) < 1e-12:
            continue
        n /= np.linalg.norm(n)
        side = (P - P[i]) @ n
        if np.all(side <= 1e-9):
            dists.append(float(P[i] @ n))  # hull is on the -n side
        elif np.all(side >= -1e-9):
            dists.append(float(-(P[i] @ n)))
    return np.array(dists)


def test_points_are_grasp_matrix_times_generators():
    """Second route: column blocks of G times each contact's generators."""
    rng = np.random.default_rng(11)
    contacts = [
        Contact(rng.normal(size=3), rng.normal(size=3), mu=0.3),
        Contact(
            rng.normal(size=3),
            rng.normal(size=3),
            mu=0.6,
            contact_model="soft_finger",
            torsional_friction=0.3,
        ),
        Contact(rng.normal(size=3), rng.normal(size=3), contact_model="frictionless"),
    ]
    grasp = Grasp(contacts, reference_point=[0.2, 0.0, -0.1])
    W, owner = wrench_space_points(grasp, num_generators=5, scale_moments=False)
    G = grasp_matrix(grasp)
    expected = np.hstack(
        [
            G[:, sl]
            @ friction_cone_generators(
                c, 5, characteristic_length=grasp.characteristic_length
            )
            for c, sl in zip(contacts, grasp.component_slices(), strict=True)
        ]
    )
    np.testing.assert_allclose(W, expected, atol=1e-12)
    assert owner.tolist() == [0] * 5 + [1] * 7 + [2]
    scaled, _ = wrench_space_points(grasp, num_generators=5)
    np.testing.assert_allclose(scaled[:3], W[:3])
    np.testing.assert_allclose(scaled[3:], W[3:] / grasp.characteristic_length)


@pytest.mark.parametrize("mu", [0.2, 0.5, 1.5])
def test_antipodal_disc_has_the_origin_inside_with_the_analytic_margin(mu):
    """Two antipodal fingers on a unit disc: a tetrahedron whose four faces are
    all at distance μ / sqrt(μ² + 2) from the origin (worked out by hand)."""
    W, _ = wrench_space_points(_antipodal_disc(mu))
    expected = np.array(
        [[-1, -mu, -mu], [-1, mu, mu], [1, mu, -mu], [1, -mu, mu]], dtype=float
    )
    # Same set of points (order within a contact follows the generators).
    assert sorted(map(tuple, np.round(W.T, 12))) == sorted(
        map(tuple, np.round(expected, 12))
    )
    info = wrench_hull(W)
    assert info.origin_inside and info.rank == 3
    assert sorted(info.hull.vertices.tolist()) == [0, 1, 2, 3]
    assert info.margin == pytest.approx(mu / np.sqrt(mu**2 + 2.0))
    assert info.margin == pytest.approx(_brute_force_facets(W.T).min())


def test_no_closure_cases():
    # Frictionless antipodal pair: two opposite wrenches, no interior.
    info = wrench_hull(wrench_space_points(_antipodal_disc(0.0))[0])
    assert info.hull is None and not info.origin_inside and info.margin == 0.0
    # Two fingers 90° apart with a little friction: origin outside.
    grasp = Grasp(
        [Contact([1.0, 0.0], [-1.0, 0.0], mu=0.3), Contact([0, 1.0], [0, -1.0], mu=0.3)]
    )
    W, _ = wrench_space_points(grasp)
    info = wrench_hull(W)
    assert info.hull is not None and not info.origin_inside
    assert info.margin < 0
    assert info.margin == pytest.approx(_brute_force_facets(W.T).min())


def test_origin_inside_agrees_with_lp2_force_closure():
    """The hull test and the force-closure LP are independent routes."""
    rng = np.random.default_rng(2024)
    agree, closures = 0, 0
    for _ in range(25):
        k = int(rng.integers(2, 5))
        angles = rng.uniform(0, 2 * np.pi, size=k)
        tilt = rng.uniform(-0.6, 0.6, size=k)
        contacts = [
            Contact(
                [np.cos(a), np.sin(a)],
                [-np.cos(a + t), -np.sin(a + t)],
                mu=float(rng.uniform(0.05, 0.8)),
            )
            for a, t in zip(angles, tilt, strict=True)
        ]
        grasp = Grasp(contacts)
        info = wrench_hull(wrench_space_points(grasp)[0])
        if abs(info.margin) < 1e-4 and info.hull is not None:
            continue  # too close to the boundary for either verdict
        result = force_closure(grasp)
        if result.near_boundary:
            continue
        assert info.origin_inside == result.is_closure, grasp
        agree += 1
        closures += result.is_closure
    assert agree >= 20
    assert 3 <= closures <= agree - 3  # both verdicts were exercised


def test_plot_wrench_space_artists(plt):
    grasp = _antipodal_disc(0.5)
    out = plot_wrench_space(grasp)
    assert out.origin_inside
    out.ax.figure.canvas.draw()
    assert out.wrenches.shape == (3, 4)
    assert len(out.rays.get_segments()) == 4
    assert len(out.hull_artist.get_paths()) == len(out.hull.hull.simplices) == 4
    from matplotlib.colors import to_rgba

    np.testing.assert_allclose(out.origin.get_facecolor()[0], to_rgba("tab:green"))
    assert "inside" in out.ax.get_title() and "NOT" not in out.ax.get_title()

    fig = plt.figure()
    ax = fig.add_subplot(projection="3d")
    outside = Grasp(
        [Contact([1.0, 0.0], [-1.0, 0.0], mu=0.3), Contact([0, 1.0], [0, -1.0], mu=0.3)]
    )
    out = plot_wrench_space(outside, ax=ax, hull=False, rays=False)
    assert out.ax is ax and not out.origin_inside
    assert out.hull_artist is None and out.rays is None
    np.testing.assert_allclose(out.origin.get_facecolor()[0], to_rgba("tab:red"))
    assert "NOT inside" in ax.get_title()


def test_plot_wrench_space_rejects_spatial_grasps_and_2d_axes(plt):
    with pytest.raises(InvalidOptionError, match="spatial"):
        plot_wrench_space(Grasp([Contact([0, 0, 1], [0, 0, -1], mu=0.1)]))
    _, ax = plt.subplots()
    with pytest.raises(InvalidOptionError, match="3-D axes"):
        plot_wrench_space(_antipodal_disc(0.5), ax=ax)
