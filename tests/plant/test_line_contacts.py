"""A flat face along a cylinder's side touches along a line: its two ends.

``line_vertices`` is checked against the closed form (a square face over a
cylinder lying along x), for invariance under rigid motion (hypothesis), and
through ``find_contacts`` on drakegrasp's flat jaw closed on its cylinder.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import drakegrasp as dg
from drakegrasp.plant.contact_patches import line_vertices

R, H = 0.02, 0.05  # radius and half length of the cylinder (axis x)


def _face(x0, x1, y0, y1, z):
    """A rectangle in the plane ``z``, its outward normal -z (down, at the cylinder)."""
    return np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]])


def _ends(poly, *, normal=(0.0, 0.0, -1.0), tol=1e-3, axis=(1.0, 0.0, 0.0)):
    return line_vertices(
        face_normal_O=np.array(normal),
        poly_face_O=poly,
        axis_O=np.array(axis),
        centre_O=np.zeros(3),
        radius=R,
        half_length=H,
        tol=tol,
    )


def test_a_face_over_the_side_gives_the_ends_under_it():
    gap = 2e-4
    ends = _ends(_face(-0.01, 0.03, -0.01, 0.01, R + gap))
    points = np.array([p for p, _ in ends])
    np.testing.assert_allclose(points, [[-0.01, 0, R], [0.03, 0, R]], atol=1e-15)
    np.testing.assert_allclose([g for _, g in ends], [gap, gap], atol=1e-15)


def test_the_line_stops_where_the_cylinder_does():
    ends = _ends(_face(-0.2, 0.3, -0.01, 0.01, R))
    np.testing.assert_allclose([p[0] for p, _ in ends], [-H, H], atol=1e-15)


def test_a_face_pressed_in_has_negative_gaps():
    ends = _ends(_face(-0.01, 0.01, -0.01, 0.01, R - 1e-4))
    np.testing.assert_allclose([g for _, g in ends], [-1e-4, -1e-4], atol=1e-15)


def test_a_tilted_face_keeps_the_part_within_the_tolerance():
    """Tilted by 1° about y: the gap grows along x; the line ends where it
    reaches ``tol`` (closed form: the plane's height over the line)."""
    theta, tol = np.radians(1.0), 1e-4
    n = np.array([np.sin(theta), 0.0, -np.cos(theta)])  # outward, tilted
    # the face's plane passes through (0, 0, R): gap(x) = -n . (x, 0, R) + n . q
    u = np.array([np.cos(theta), 0.0, np.sin(theta)])  # in the plane, along x
    v = np.array([0.0, 1.0, 0.0])
    q = np.array([0.0, 0.0, R])
    corners = [(-0.04, -0.01), (0.04, -0.01), (0.04, 0.01), (-0.04, 0.01)]
    poly = np.array([q + a * u + b * v for a, b in corners])
    ends = _ends(poly, normal=n, tol=tol)
    # gap at x along the line (x, 0, R): n . ((x, 0, R) - q) = x sin(theta);
    # the face's edge a = -0.04 seen from the line (normal to the face): where
    # (x, 0, R) - q has the component -0.04 along u, x cos(theta) = -0.04
    x_end = tol / np.sin(theta)
    np.testing.assert_allclose(
        [p[0] for p, _ in ends], [-0.04 / np.cos(theta), x_end], rtol=1e-12
    )
    np.testing.assert_allclose(ends[1][1], tol, rtol=1e-12)


@pytest.mark.parametrize(
    ("poly", "normal"),
    [
        (_face(0.06, 0.08, -0.01, 0.01, R), (0, 0, -1)),  # beyond the cylinder's end
        (_face(-0.01, 0.01, 0.03, 0.05, R), (0, 0, -1)),  # beside the line
        (_face(-0.01, 0.01, -0.01, 0.01, R + 0.01), (0, 0, -1)),  # too far
        (_face(-0.01, 0.01, -0.01, 0.01, R), (np.sin(0.1), 0, -np.cos(0.1))),  # 5.7°
    ],
)
def test_no_line_where_the_face_is_not_along_the_side(poly, normal):
    assert _ends(poly, normal=np.array(normal, float)) == []


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3),
    st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3),
)
def test_rigid_motion_moves_the_ends_with_it(angles, shift):
    Q = Rotation.from_euler("xyz", angles).as_matrix()
    t = np.array(shift)
    poly = _face(-0.01, 0.03, -0.01, 0.01, R + 2e-4)
    here = _ends(poly)
    there = line_vertices(
        face_normal_O=Q @ np.array([0.0, 0.0, -1.0]),
        poly_face_O=poly @ Q.T + t,
        axis_O=Q @ np.array([1.0, 0.0, 0.0]),
        centre_O=t,
        radius=R,
        half_length=H,
        tol=1e-3,
    )
    assert len(there) == 2
    for (p, g), (p2, g2) in zip(here, there, strict=True):
        np.testing.assert_allclose(p2, Q @ p + t, atol=1e-12)
        assert abs(g2 - g) < 1e-12


def test_the_flat_jaw_touches_the_cylinder_along_two_lines():
    """The planner's best grasp of drakegrasp's cylinder (radius 30 mm) with
    its flat jaw (20 mm square pads): each pad's contacts are the two ends of
    a line on the cylinder's side, parallel to the axis, one normal each, at
    most a pad's diagonal long; hard fingers are force closure (one point per
    pad never is)."""
    scene = dg.planning_scene(
        "package://drakegrasp/objects/cylinder.sdf",
        hand_url="package://drakegrasp/hands/parallel_jaw_flat.sdf",
    )
    result = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, mu=0.5, seed=0, robustness_samples=4,
    )  # fmt: skip
    best = result[0]
    assert best.is_closure
    by_pad: dict[str, list] = {}
    for c in best.contacts:
        if c.normal_source == "patch":
            by_pad.setdefault(c.finger_body, []).append(c)
    assert len(by_pad) == 2
    for pad in by_pad.values():
        assert len(pad) == 2
        p0, p1 = (np.asarray(c.p_OC) for c in pad)
        along = p1 - p0
        assert abs(abs(along[2]) - np.linalg.norm(along)) < 1e-9  # along z (axis)
        assert 0.02 - 1e-9 <= np.linalg.norm(along) <= 0.02 * np.sqrt(2) + 1e-9
        for c in pad:
            p = np.asarray(c.p_OC)
            assert abs(np.hypot(p[0], p[1]) - 0.03) < 1e-9  # on the side
            assert abs(c.nhat_O[2]) < 1e-12
            np.testing.assert_allclose(c.nhat_O, pad[0].nhat_O, atol=1e-15)
