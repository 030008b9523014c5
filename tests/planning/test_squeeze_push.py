"""The squeeze push: whether a candidate's closing motions oppose each other
(``drakegrasp.planning.opposition``)."""

from __future__ import annotations

import numpy as np
import pytest

from drakegrasp.core.contact import contact_frame
from drakegrasp.core.linalg import rotations_about
from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning.opposition import (
    PASSIVE_SPEED,
    closing_directions,
    squeeze_push_of,
)


def _cone(theta: float, k: int = 3, axis=(0.0, 0.0, 1.0)) -> np.ndarray:
    """``k`` unit vectors at angle ``theta`` about ``axis``, evenly around it."""
    a = 2 * np.pi * np.arange(k) / k
    d = np.c_[
        np.sin(theta) * np.cos(a), np.sin(theta) * np.sin(a), np.full(k, np.cos(theta))
    ]
    R = contact_frame(np.asarray(axis, float))  # columns [axis, t1, t2]
    return d @ np.c_[R[:, 1], R[:, 2], R[:, 0]].T


def _brute_force(D: np.ndarray, n: int = 40_000) -> float:
    """``max(0, max_u min_i d_i·u)`` over a Fibonacci sphere of ``n`` points."""
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = np.pi * (1 + 5**0.5) * k
    U = np.c_[np.sqrt(1 - z**2) * np.cos(phi), np.sqrt(1 - z**2) * np.sin(phi), z]
    return max(0.0, float(np.max(np.min(U @ D.T, axis=1))))


# --- the figure: analytic cases, invariances, a second formulation -----------


def test_opposite_directions_push_nowhere():
    # a parallel jaw's fingers close towards each other
    assert squeeze_push_of([[1, 0, 0], [-1, 0, 0]]) == 0.0
    tetrahedron = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]]) / 3**0.5
    assert squeeze_push_of(tetrahedron) == 0.0


@pytest.mark.parametrize("theta_deg", [0.0, 10.0, 30.0, 45.0, 60.0, 85.0])
def test_directions_within_a_cone_push_along_its_axis_by_its_cosine(theta_deg):
    theta = np.radians(theta_deg)
    assert squeeze_push_of(_cone(theta)) == pytest.approx(np.cos(theta), abs=1e-9)
    assert squeeze_push_of(_cone(theta, k=7, axis=(1, -2, 0.5))) == pytest.approx(
        np.cos(theta), abs=1e-9
    )


def test_one_direction_pushes_fully():
    assert squeeze_push_of([[0.0, 0.6, 0.8]]) == pytest.approx(1.0)


def test_the_push_is_unchanged_by_a_rotation_and_an_order():
    rng = np.random.default_rng(7)
    for _ in range(20):
        D = rng.standard_normal((5, 3)) + [0.0, 0.0, 2.5]  # leaning along +z
        D /= np.linalg.norm(D, axis=1, keepdims=True)
        axis = rng.standard_normal((1, 3))
        R = rotations_about(axis / np.linalg.norm(axis), rng.uniform(0, np.pi, 1))[0]
        r = squeeze_push_of(D)
        assert squeeze_push_of(D @ R.T) == pytest.approx(r, abs=1e-9)
        assert squeeze_push_of(D[rng.permutation(5)]) == pytest.approx(r, abs=1e-9)


def test_the_push_is_the_best_common_direction_found_by_search():
    # max_u min_i d_i·u, searched over 40,000 directions, is within the grid's
    # resolution of the hull's distance from the origin (and never above it)
    rng = np.random.default_rng(3)
    for lean in (0.0, 0.5, 1.5, 4.0):
        D = rng.standard_normal((4, 3)) + [lean, 0.0, 0.0]
        D /= np.linalg.norm(D, axis=1, keepdims=True)
        r, searched = squeeze_push_of(D), _brute_force(D)
        assert searched <= r + 1e-9
        assert r == pytest.approx(searched, abs=0.02)


@pytest.mark.parametrize(
    "bad", [np.zeros((0, 3)), np.ones((3, 2)), [[np.nan, 0, 1]], "abc", [[1, 0, 0j]]]
)
def test_what_is_not_directions_is_refused(bad):
    with pytest.raises(InvalidOptionError, match="directions"):
        squeeze_push_of(bad)


# --- which way each contact is pushed ----------------------------------------


def test_closing_directions_read_each_contacts_rows():
    n = np.array([0.0, 0.0, 1.0])
    R = contact_frame(n)
    # hard finger (3 rows): moves along t1 and n; frictionless (1 row): pulled
    # back along n; soft finger (4 rows): its torsion row is no translation; a
    # palm contact (zero rows): pushes back along its normal
    J = np.zeros((3 + 1 + 4 + 3, 2))
    J[0:3, 0] = [1.0, 1.0, 0.0]  # [n, t1, t2] per unit of joint 0
    J[3, 1] = -2.0
    J[4:8, 0] = [0.0, 0.0, 3.0, 100.0]
    out = closing_directions(np.asarray(J), np.array([R] * 4), [3, 1, 4, 3], [1.0, 1.0])
    assert out[0] == pytest.approx((R[:, 0] + R[:, 1]) / 2**0.5)
    assert out[1] == pytest.approx(-n)
    assert out[2] == pytest.approx(R[:, 2])
    assert out[3] == pytest.approx(n)
    # the sign that closed a joint turns its push; 0 leaves the joint still
    flipped = closing_directions(J, np.array([R] * 4), [3, 1, 4, 3], [-1.0, 0.0])
    assert flipped[0] == pytest.approx(-out[0]) and flipped[1] == pytest.approx(n)
    slow = closing_directions(
        J * PASSIVE_SPEED / 10, np.array([R] * 4), [3, 1, 4, 3], [1, 1]
    )
    assert slow == pytest.approx(np.tile(n, (4, 1)))


def test_closing_directions_refuse_what_does_not_fit():
    R = np.eye(3)[None]
    with pytest.raises(InvalidOptionError, match="closing_directions"):
        closing_directions(np.zeros((3, 2)), R, [3], [1.0])  # 2 joints, 1 sign
    with pytest.raises(InvalidOptionError, match="closing_directions"):
        closing_directions(np.zeros((2, 1)), R, [2], [1.0])  # no such contact
    with pytest.raises(InvalidOptionError, match="finite"):
        closing_directions(np.full((3, 1), np.nan), R, [3], [1.0])
