"""Object surfaces: samples lie on the shapes, normals are the shapes', chords
enter and leave where an independent marching test says."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.geometry import Box, Capsule, Cylinder, Ellipsoid, HalfSpace, Sphere
from pydrake.math import RigidTransform, RollPitchYaw

from drakegrasp.errors import ModelError
from drakegrasp.planning.surface import ObjectSurface, piece_of_shape

# Independent implicit forms: f(x) <= 0 inside, with the analytic outward gradient.
SHAPES = {
    "sphere": (Sphere(0.03), lambda x: np.linalg.norm(x, axis=1) - 0.03),
    "ellipsoid": (
        Ellipsoid(0.04, 0.02, 0.03),
        lambda x: np.linalg.norm(x / [0.04, 0.02, 0.03], axis=1) - 1,
    ),
    "box": (
        Box(0.1, 0.06, 0.04),
        lambda x: np.max(np.abs(x) - [0.05, 0.03, 0.02], axis=1),
    ),
    "cylinder": (
        Cylinder(0.03, 0.1),
        lambda x: np.maximum(np.hypot(x[:, 0], x[:, 1]) - 0.03, np.abs(x[:, 2]) - 0.05),
    ),
    "capsule": (
        Capsule(0.02, 0.08),
        lambda x: (
            np.linalg.norm(
                x
                - np.column_stack(
                    [0 * x[:, 0], 0 * x[:, 0], np.clip(x[:, 2], -0.04, 0.04)]
                ),
                axis=1,
            )
            - 0.02
        ),
    ),
}


def _gradient(f, x, h=1e-7):
    g = np.column_stack([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(3)])
    return g / np.linalg.norm(g, axis=1, keepdims=True)


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_samples_lie_on_the_shape_with_its_normals(name):
    shape, f = SHAPES[name]
    piece = piece_of_shape(shape, RigidTransform(), name)
    p, n = piece.sample(400, np.random.default_rng(1))
    assert np.max(np.abs(f(p))) < 1e-12 + 1e-9
    g = _gradient(f, p)
    smooth = np.abs(f(p + 1e-4 * g)) > 0  # skip edges where the gradient jumps
    assert np.min(np.sum(g[smooth] * n[smooth], axis=1)) > 1 - 1e-6


def test_box_samples_are_area_uniform():
    piece = piece_of_shape(Box(0.1, 0.06, 0.04), RigidTransform())
    _, n = piece.sample(60000, np.random.default_rng(2))
    share = {ax: np.mean(np.abs(n[:, ax]) > 0.5) for ax in range(3)}
    areas = np.array([0.06 * 0.04, 0.1 * 0.04, 0.1 * 0.06])
    assert np.allclose([share[0], share[1], share[2]], areas / areas.sum(), atol=0.01)


def _march(f, p, d, t_max=0.2, steps=40001):
    t = np.linspace(-t_max, t_max, steps)
    inside = f(p[None, :] + t[:, None] * d[None, :]) <= 0
    if not inside.any():
        return np.nan, np.nan
    return t[inside][0], t[inside][-1]


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_chords_match_marching(name):
    shape, f = SHAPES[name]
    X = RigidTransform(RollPitchYaw(0.3, -0.5, 1.1), [0.01, -0.02, 0.03])
    surface = ObjectSurface.from_pieces([piece_of_shape(shape, X, name)])
    rng = np.random.default_rng(3)
    p = rng.uniform(-0.06, 0.06, (25, 3)) + X.translation()
    d = rng.standard_normal((25, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    t_in, t_out, n_out = surface.chord(p, d)
    R = X.rotation().matrix()
    for k in range(25):
        a, b = _march(lambda x: f((x - X.translation()) @ R), p[k], d[k])
        if np.isnan(a):
            assert np.isnan(t_in[k])
            continue
        assert abs(t_in[k] - a) < 2e-5 and abs(t_out[k] - b) < 2e-5
        x_out = ((p[k] + t_out[k] * d[k] - X.translation()) @ R)[None]
        g = _gradient(f, x_out) @ R.T
        assert g[0] @ n_out[k] > 1 - 1e-4 or f(x_out + 1e-4 * (n_out[k] @ R))[0] > 0


def test_union_chord_spans_the_outer_pieces():
    # two spheres 0.1 apart on x: a line along x enters the first and leaves the second
    s = ObjectSurface.from_pieces(
        [
            piece_of_shape(Sphere(0.02), RigidTransform([-0.05, 0, 0])),
            piece_of_shape(Sphere(0.02), RigidTransform([0.05, 0, 0])),
        ]
    )
    t_in, t_out, n = s.chord(np.array([[-0.07, 0, 0]]), np.array([[1.0, 0, 0]]))
    assert t_in[0] == pytest.approx(0.0, abs=1e-12)
    assert t_out[0] == pytest.approx(0.14)
    assert n[0] == pytest.approx([1, 0, 0])


@settings(max_examples=25, deadline=None, derandomize=True)
@given(
    st.floats(-np.pi, np.pi),
    st.floats(-1, 1),
    st.floats(-np.pi, np.pi),
    st.floats(-0.2, 0.2),
)
def test_chord_lengths_are_invariant_to_the_geometry_pose(r, p, y, x):
    shape = Cylinder(0.03, 0.1)
    a = ObjectSurface.from_pieces([piece_of_shape(shape, RigidTransform())])
    X = RigidTransform(RollPitchYaw(r, p, y), [x, -x, 2 * x])
    b = ObjectSurface.from_pieces([piece_of_shape(shape, X)])
    rng = np.random.default_rng(4)
    q, n, _ = a.sample(50, rng)
    R = X.rotation().matrix()
    la = np.subtract(*a.chord(q, -n)[1::-1])
    lb = np.subtract(*b.chord(q @ R.T + X.translation(), -n @ R.T)[1::-1])
    assert np.allclose(la, lb, atol=1e-12)


def test_mesh_hull_and_radius(own_scene):
    from drakegrasp.planning import object_surface

    scene = own_scene("hex_prism")
    surface = object_surface(scene.plant, scene.context, scene.object_body)
    assert [p.kind for p in surface.pieces] == ["hull"]
    p, n, _ = surface.sample(200, np.random.default_rng(5))
    piece = surface.pieces[0]
    # every sample on some face plane, inside all others
    slack = p @ piece.normals.T - piece.offsets
    assert np.max(slack) < 1e-12
    assert np.all(np.min(np.abs(slack), axis=1) < 1e-12)
    assert surface.radius_about(np.zeros(3)) >= np.max(np.linalg.norm(p, axis=1))


def test_halfspace_is_refused():
    with pytest.raises(ModelError, match="HalfSpace"):
        piece_of_shape(HalfSpace(), RigidTransform(), "floor")
