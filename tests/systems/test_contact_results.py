"""The patch polygon of a contact surface: analytic cases."""

import numpy as np
import pytest
from pydrake.multibody.plant import MultibodyPlant

from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant.contact_results import contacts_from_results, patch_polygon


def _ccw_area(P: np.ndarray, n: np.ndarray) -> float:
    return 0.5 * sum(np.cross(P[i], P[(i + 1) % len(P)]) @ n for i in range(len(P)))


def test_square_with_interior_points_gives_its_four_corners():
    rng = np.random.default_rng(0)
    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    inside = np.column_stack([rng.uniform(0.1, 0.9, (30, 2)), np.zeros(30)])
    points = np.vstack([inside, corners, corners[:2]])  # duplicates too
    n = np.array([0.0, 0.0, 1.0])
    P = patch_polygon(points, n)
    assert len(P) == 4
    for c in corners:
        assert np.min(np.linalg.norm(P - c, axis=1)) < 1e-8
    assert _ccw_area(P - P.mean(axis=0), n) == pytest.approx(1.0)


def test_tilted_plane_and_rigid_motion():
    rng = np.random.default_rng(1)
    a = rng.normal(size=3)
    a /= np.linalg.norm(a)
    Q, _ = np.linalg.qr(np.column_stack([a, rng.normal(size=(3, 2))]))
    n = Q[:, 0]
    hexagon = np.array(
        [[np.cos(t), np.sin(t)] for t in np.linspace(0, 2 * np.pi, 7)[:-1]]
    )
    points = 0.02 * hexagon @ Q[:, 1:].T + np.array([0.3, -0.1, 0.5])
    P = patch_polygon(points, n)
    assert len(P) == 6
    np.testing.assert_allclose((P - P.mean(axis=0)) @ n, 0.0, atol=1e-12)
    area = 6 * np.sqrt(3) / 4 * 0.02**2
    assert _ccw_area(P - P.mean(axis=0), n) == pytest.approx(area, rel=1e-6)


def test_collinear_points_give_no_polygon():
    points = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], float)
    assert len(patch_polygon(points, np.array([0.0, 0.0, 1.0]))) < 3


def test_contact_results_of_the_wrong_type():
    plant = MultibodyPlant(0.0)
    plant.Finalize()
    with pytest.raises(InvalidOptionError, match="ContactResults"):
        contacts_from_results(
            plant, plant.CreateDefaultContext(), None, None, object_body="x"
        )
