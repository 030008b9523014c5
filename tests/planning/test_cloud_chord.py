"""A cloud's chords: the screened search against every point measured directly."""

from __future__ import annotations

import numpy as np
import pytest

from drakegrasp.planning.cloud import CloudSurface


def _direct(surface: CloudSurface, p, d):
    """Entry, exit and exit normal of each line, each point measured on its own."""
    rho = surface.line_radius
    t_in, t_out, n_out = (
        np.zeros(len(p)),
        np.full(len(p), np.nan),
        np.zeros((len(p), 3)),
    )
    for i in range(len(p)):
        v = surface.points - p[i]
        # the same arithmetic as the library's, point by point: only the
        # screen that picks the points to measure differs
        t = np.einsum("ni,ni->n", v, np.broadcast_to(d[i], v.shape))
        on = np.linalg.norm(v - t[:, None] * d[i], axis=1) <= rho
        t_in[i] = min(0.0, np.min(t[on & (t < -rho)], initial=0.0))
        ahead = np.flatnonzero(on & (t > rho))
        j = ahead[np.argmax(t[ahead])] if len(ahead) else 0  # first of equals
        t_out[i] = t[j] if len(ahead) else np.nan
        n_out[i] = surface.normals[j]
    return t_in, t_out, n_out


def _unit(x):
    return x / np.linalg.norm(x, axis=-1, keepdims=True)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("where", ["centred", "far"])
def test_the_screen_misses_no_point_of_a_line(seed, where):
    rng = np.random.default_rng(seed)
    points = _unit(rng.normal(size=(3000, 3))) * rng.uniform(0.02, 0.3)
    points = np.round(points, 3)  # a grid: repeated points, equal exits
    origin = np.zeros(3) if where == "centred" else np.array([40.0, -7.0, 3.0])
    surface = CloudSurface(points + origin, _unit(points), origin=origin)
    k = 200
    idx = rng.integers(0, len(points), k)
    p = surface.points[idx] + rng.normal(size=(k, 3)) * 0.02
    d = _unit(rng.normal(size=(k, 3)))
    d[:40] = [1.0, 0.0, 0.0]  # along the grid: ties
    got = surface.chord(p, d)
    want = _direct(surface, p, d)
    for a, b in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("where", ["centred", "far"])
def test_a_point_just_within_the_line_radius_is_on_the_line(where):
    rng = np.random.default_rng(7)
    points = rng.uniform(-0.1, 0.1, (40, 3))
    origin = np.zeros(3) if where == "centred" else np.array([40.0, -7.0, 3.0])
    rho = 1e-3
    surface = CloudSurface(points + origin, _unit(points), line_radius=rho,
                           origin=origin)  # fmt: skip
    d = _unit(rng.normal(size=(3, 40, 3)))
    side = _unit(np.cross(d, rng.normal(size=(3, 40, 3))))
    gap = rho * np.array([1.0 - 1e-12, 1.0, 1.0 + 1e-9])[:, None, None]
    p = surface.points + gap * side - 0.5 * d  # each point 0.5 m ahead
    t_in, t_out, n_out = surface.chord(p.reshape(-1, 3), d.reshape(-1, 3))
    want = _direct(surface, p.reshape(-1, 3), d.reshape(-1, 3))
    for a, b in zip((t_in, t_out, n_out), want, strict=True):
        np.testing.assert_array_equal(a, b)
    met = (t_out >= 0.5 - 1e-9).reshape(3, 40)  # the point, or one beyond it
    assert met[0].all()  # within the radius by 1e-12 of it: on the line
    assert not met[2].all()  # beyond it by 1e-9: off (unless another is on)


def test_a_line_that_meets_no_point_has_no_exit():
    surface = CloudSurface(np.eye(3) * 0.05, np.eye(3), origin=np.zeros(3))
    t_in, t_out, _ = surface.chord(np.array([[0.0, 0.0, 1.0]]), np.array([[1.0, 0, 0]]))
    assert t_in[0] == 0.0 and np.isnan(t_out[0])
