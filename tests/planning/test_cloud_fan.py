"""The normal fans of cloud contacts at edges and the capacity averaged over
them (drakegrasp.planning.weight.fan_capacity): the arc's draws against a
rotation about the arc's axis, the capacity against weight_capacity on the
same drawn normals, and fans that change nothing (none, or of one normal)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from drakegrasp.core.linalg import rotations_about
from drakegrasp.planning.weight import _slerp, fan_capacity, weight_capacity

MU = 0.8
SCALE = 0.05


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def _box_grasp():
    """Four contacts on a 6 cm cube's faces ±x, ±y (inward normals), one per
    finger: force closure."""
    P = np.array(
        [[0.03, 0.01, 0.0], [-0.03, -0.01, 0.0], [0.0, 0.03, 0.01], [0.0, -0.03, -0.01]]
    )
    N = -np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0, -1.0, 0]])
    return P[None], N[None], np.arange(4)[None]


def _nominal(P, N, L):
    return weight_capacity(P, N, L, mu=MU, torque_scale=SCALE).min(axis=1)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    a=st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: np.linalg.norm(v) > 0.1),
    b=st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: np.linalg.norm(v) > 0.1),
    t=st.floats(0, 1),
)
def test_arc_draws_are_rotations_of_one_end_about_the_arcs_axis(a, b, t):
    a, b = _unit(a), _unit(b)
    axis = np.cross(a, b)
    if np.linalg.norm(axis) < 1e-6:  # no unique arc: the first end
        assert np.allclose(_slerp(a, b, np.array(t)), a)
        return
    omega = np.arccos(np.clip(a @ b, -1, 1))
    R = rotations_about(_unit(axis), np.array(t * omega))
    n = _slerp(a, b, np.array(t))
    assert np.allclose(n, R @ a, atol=1e-9)
    assert np.isclose(np.linalg.norm(n), 1.0)


def test_without_fans_the_capacity_is_the_nominal_one():
    P, N, L = _box_grasp()
    nominal = _nominal(P, N, L)
    assert nominal[0] > 0
    none = np.full((1, 4, 2, 3), np.nan)
    one = np.stack([N, N], axis=2)  # arcs of a single normal each
    for fans in (none, one):
        got = fan_capacity(
            P, N, fans, L, mu=MU, samples=6, rng=np.random.default_rng(0),
            torque_scale=SCALE, contact_model="hard_finger", torsional_friction=None,
        )  # fmt: skip
        assert np.allclose(got, nominal, rtol=1e-9, atol=1e-12)
    zero = fan_capacity(
        P, N, none, L, mu=MU, samples=0, rng=np.random.default_rng(0),
        torque_scale=SCALE, contact_model="hard_finger", torsional_friction=None,
    )  # fmt: skip
    assert np.allclose(zero, nominal)


def test_the_capacity_is_the_mean_over_normals_drawn_along_the_arcs():
    """Contact 0 sits on the cube's edge between faces +x and +z: its normal
    is drawn along the arc between them; the mean of weight_capacity on the
    same draws (turned about the arc's axis, in this test) is the answer, and
    it lies below the nominal capacity (the +x face's normal, the best)."""
    P, N, L = _box_grasp()
    P = P.copy()
    P[0, 0] = [0.03, 0.01, 0.03]
    fans = np.full((1, 4, 2, 3), np.nan)
    a, b = -np.array([1.0, 0, 0]), -np.array([0, 0, 1.0])
    fans[0, 0] = [a, b]
    S = 12
    got = fan_capacity(
        P, N, fans, L, mu=MU, samples=S, rng=np.random.default_rng(3),
        torque_scale=SCALE, contact_model="hard_finger", torsional_friction=None,
    )  # fmt: skip
    t = np.random.default_rng(3).uniform(size=(1, S, 4))[0, :, 0]
    R = rotations_about(np.tile(_unit(np.cross(a, b)), (S, 1)), t * np.pi / 2)
    Nrm = np.repeat(N, S, axis=0)
    Nrm[:, 0] = R @ a
    alpha = _nominal(np.repeat(P, S, axis=0), Nrm, np.repeat(L, S, axis=0))
    expected = np.where(np.isfinite(alpha), alpha, 0.0).mean()
    assert np.isclose(got[0], expected, rtol=1e-9, atol=1e-12)
    assert got[0] < _nominal(P, N, L)[0]
