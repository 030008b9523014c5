"""Point queries on posed shapes: projection and support, by independent routes.

- The projection's normal is the gradient of its signed distance (central
  finite differences), the closest point is ``p − sd n`` and lies on the
  surface (each shape's implicit equation, written here).
- A support point lies on the surface and no sampled surface point lies
  further along the direction.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.geometry import Box, Capsule, Convex, Cylinder, Ellipsoid, Sphere
from pydrake.math import RollPitchYaw

from drakegrasp.plant import models_dir
from drakegrasp.plant.shape_queries import PosedShape

HEX = str(models_dir() / "objects" / "hex_prism.obj")
SHAPES = {
    "sphere": Sphere(0.03),
    "box": Box(0.08, 0.05, 0.03),
    "cylinder": Cylinder(0.025, 0.07),
    "capsule": Capsule(0.015, 0.05),
    "ellipsoid": Ellipsoid(0.05, 0.03, 0.02),
    "hex": Convex(HEX),
}


def surface_residual(name, x):
    """How far ``x`` (frame G) is from the shape's surface, by its own equation."""
    s = SHAPES[name]
    if name == "sphere":
        return abs(np.linalg.norm(x) - s.radius())
    if name == "box":
        h = 0.5 * np.array([s.width(), s.depth(), s.height()])
        return abs(np.max(np.abs(x) - h))
    if name == "cylinder":
        side = math.hypot(x[0], x[1]) - s.radius()
        cap = abs(x[2]) - 0.5 * s.length()
        return abs(max(side, cap))
    if name == "capsule":
        z = np.clip(x[2], -0.5 * s.length(), 0.5 * s.length())
        return abs(np.linalg.norm(x - [0, 0, z]) - s.radius())
    if name == "ellipsoid":
        abc = np.array([s.a(), s.b(), s.c()])
        return abs(np.linalg.norm(x / abc) - 1.0) * abc.min()
    # The hex prism: 50 mm across flats (flats at ±y), 80 mm tall (the
    # model's own description).
    apothem, half = 0.025, 0.04
    angles = np.pi / 2 + np.pi / 3 * np.arange(6)
    flats = max(x[0] * math.cos(a) + x[1] * math.sin(a) for a in angles) - apothem
    return abs(max(flats, abs(x[2]) - half))


def posed(name, rpy):
    R = RollPitchYaw(*rpy).ToRotationMatrix().matrix()
    return PosedShape(SHAPES[name], R, np.array([0.1, -0.2, 0.3]))


def test_hex_reference_matches_the_model():
    """The reference equation of the hex prism holds at its hull vertices."""
    P = PosedShape(SHAPES["hex"], np.eye(3), np.zeros(3))
    for v in P.vertices_G:
        assert surface_residual("hex", v) < 1e-9


@settings(derandomize=True, max_examples=120, deadline=None)
@given(
    name=st.sampled_from(sorted(SHAPES)),
    rpy=st.tuples(*[st.floats(-math.pi, math.pi)] * 3),
    direction=st.tuples(*[st.floats(-1, 1)] * 3).filter(
        lambda v: np.linalg.norm(v) > 0.1
    ),
    offset=st.floats(-0.004, 0.01),
)
def test_projection_is_the_signed_distance_and_its_gradient(
    name, rpy, direction, offset
):
    X = posed(name, rpy)
    # A point near the surface: along a direction from the centre, then moved.
    d = np.asarray(direction) / np.linalg.norm(direction)
    _, q0, n0 = X.project(X.to_O(0.2 * (X.R.T @ d)))
    p = q0 + offset * n0
    sd, q, n = X.project(p)
    assert abs(np.linalg.norm(n) - 1) < 1e-12
    np.testing.assert_allclose(q, p - sd * n, atol=1e-12)
    assert surface_residual(name, X.to_G(q)) < 1e-12
    if abs(sd) > 1e-5:  # away from the surface
        # A step small against |sd|: near an edge the distance curves at 1/sd,
        # so a central difference is off by up to h/(2|sd|) where the point is
        # on the border of a face's and an edge's regions (C1, not C2).
        h = 1e-4 * abs(sd)
        grad = [
            (X.project(p + h * e)[0] - X.project(p - h * e)[0]) / (2 * h)
            for e in np.eye(3)
        ]
        if sd > 0 or np.allclose(grad, n, atol=1e-4):
            # Outside a convex shape the distance is differentiable.
            np.testing.assert_allclose(grad, n, atol=1e-4)
        else:
            # Inside, on the set of points with two nearest faces (hypothesis
            # found one at a hex prism's vertex) sd has a kink: n must then be
            # the gradient of one nearest face, along which sd grows at rate 1.
            assert (X.project(p + h * n)[0] - sd) / h == pytest.approx(1, abs=1e-6)


def _surface_samples(X, name, k=4000, seed=0):
    """Surface points (frame O) by projecting random far points."""
    rng = np.random.default_rng(seed)
    dirs = rng.normal(size=(k, 3))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    return np.array([X.project(X.t + 0.5 * d)[1] for d in dirs])


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_support_point_is_farthest_along_the_direction(name):
    X = posed(name, (0.4, -0.7, 1.1))
    samples = _surface_samples(X, name)
    rng = np.random.default_rng(1)
    for _ in range(25):
        v = rng.normal(size=3)
        v /= np.linalg.norm(v)
        s = X.support(v)
        assert surface_residual(name, X.to_G(s)) < 1e-12
        assert np.max(samples @ v) <= s @ v + 1e-12
        assert X.support_value(v) == pytest.approx(s @ v, abs=1e-15)
