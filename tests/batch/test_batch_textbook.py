"""Textbook grasps with known answers, second formulations and invariances."""

from __future__ import annotations

import numpy as np
import pytest
from batch_support import random_grasps

from drakegrasp.batch import batch_force_closure, batch_form_closure


def _ring_grasp(num, *, dim=3, radius=1.0, phase=0.0):
    theta = phase + 2 * np.pi * np.arange(num) / num
    P = np.zeros((num, dim))
    P[:, 0], P[:, 1] = radius * np.cos(theta), radius * np.sin(theta)
    return P, -P / radius


def _pyramid_axis_margin(mu, n_g):
    """Value of a unit facet row of the n_g-pyramid on the axis [1, 0, 0]."""
    delta = 2 * np.pi / n_g
    return (
        mu
        * np.sin(delta)
        / np.sqrt((mu * np.sin(delta)) ** 2 + 4 * np.sin(delta / 2) ** 2)
    )


@pytest.mark.parametrize("num", [3, 4, 5])
@pytest.mark.parametrize("n_g", [4, 8, 12])
def test_fingers_evenly_spaced_on_the_equator(num, n_g):
    # Pure squeezing (unit normal forces) balances and puts every contact on its
    # cone axis; no null-space force does better, since on a regular pyramid the
    # facet values average to f_n times the axis value.  Hence d* is the axis value.
    mu = 0.5
    P, Nrm = _ring_grasp(num, phase=0.3)
    res = batch_force_closure(P[None], Nrm[None], mu=mu, num_generators=n_g)
    assert res.is_closure[0] and res.rank[0] == 6
    np.testing.assert_allclose(res.d_star[0], _pyramid_axis_margin(mu, n_g), atol=1e-8)


def test_three_fingers_120_degrees_mu_half_closure():
    P, Nrm = _ring_grasp(3)
    res = batch_force_closure(P[None], Nrm[None], mu=0.5)
    assert bool(res.is_closure[0])
    np.testing.assert_allclose(res.d_star[0], 0.41935, atol=1e-5)


@pytest.mark.parametrize("mu", [0.1, 0.5, 2.0])
def test_planar_fingers_on_a_circle(mu):
    P, Nrm = _ring_grasp(3, dim=2)
    res = batch_force_closure(P[None], Nrm[None], mu=mu)
    assert res.is_closure[0] and res.rank[0] == 3
    np.testing.assert_allclose(res.d_star[0], mu / np.hypot(1, mu), atol=1e-8)


def test_two_spatial_hard_fingers_never_close():
    rng = np.random.default_rng(5)
    P, Nrm = random_grasps(rng, 200, 2, 3, spread=0.2)
    P[:100, 1] = -P[:100, 0]  # first half exactly antipodal
    Nrm[:100] = -P[:100]
    res = batch_force_closure(P, Nrm, mu=0.8)
    assert not res.is_closure.any()
    assert (res.rank <= 5).all()
    # the antipodal ones squeeze: d* > 0 is reported although rank is short
    assert (res.d_star[:100] > 0.1).all() and (res.rank[:100] == 5).all()


def test_two_planar_antipodal_fingers_close_with_friction():
    P = np.array([[[1.0, 0.0], [-1.0, 0.0]]])
    res = batch_force_closure(P, -P, mu=0.3)
    assert res.is_closure[0] and res.rank[0] == 3
    res0 = batch_force_closure(P, -P, mu=0.0)
    assert not res0.is_closure[0] and res0.rank[0] == 1  # opposite pushes


def _square_form_closure():
    P = np.array([[-1.0, 0.5], [1.0, -0.5], [0.5, -1.0], [-0.5, 1.0]])
    Nrm = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    return P, Nrm


def test_planar_square_form_closure_with_four_contacts():
    # G_n has the one-dimensional null space spanned by (1, 1, 1, 1): d* = 1.
    P, Nrm = _square_form_closure()
    res = batch_form_closure(P[None], Nrm[None])
    assert res.is_closure[0] and res.rank[0] == 3
    np.testing.assert_allclose(res.d_star[0], 1.0, atol=1e-9)
    three = batch_form_closure(P[None, :3], Nrm[None, :3])
    assert not three.is_closure[0] and three.d_star[0] == 0.0


def test_cube_form_closure_with_twelve_contacts():
    # Two contacts per face, offset along the next axis; equal forces balance,
    # so d* = 1 (the mean normal force under the budget).
    P, Nrm = [], []
    for a in range(3):
        for side in (1.0, -1.0):
            for s in (0.5, -0.5):
                p = np.zeros(3)
                p[a], p[(a + 1) % 3] = side, s
                P.append(p)
                Nrm.append(-side * np.eye(3)[a])
    P, Nrm = np.array(P)[None], np.array(Nrm)[None]
    res = batch_form_closure(P, Nrm)
    assert res.is_closure[0] and res.rank[0] == 6
    np.testing.assert_allclose(res.d_star[0], 1.0, atol=1e-9)
    # Frictionless force closure is the same LP.
    frc = batch_force_closure(P, Nrm, mu=0.7, contact_model="frictionless")
    np.testing.assert_allclose(frc.d_star, res.d_star, atol=1e-9)


def test_zero_friction_hard_fingers_are_form_closure():
    rng = np.random.default_rng(6)
    P, Nrm = random_grasps(rng, 300, 7, 3, spread=0.3)
    hard = batch_force_closure(P, Nrm, mu=0.0)
    form = batch_form_closure(P, Nrm)
    np.testing.assert_allclose(hard.d_star, form.d_star, atol=1e-8)
    np.testing.assert_array_equal(hard.rank, form.rank)
    np.testing.assert_array_equal(hard.is_closure, form.is_closure)
    assert form.is_closure.any() and not form.is_closure.all()


@pytest.mark.parametrize("d", [2, 3])
def test_translation_scaling_and_permutation_invariance(d):
    rng = np.random.default_rng(7 + d)
    K, N = 300, 4
    P, Nrm = random_grasps(rng, K, N, d)
    mu = rng.uniform(0.1, 0.9, (K, N))
    base = batch_force_closure(P, Nrm, mu=mu)
    assert 0 < base.is_closure.sum() < K
    shift = rng.normal(size=(K, 1, d)) * 3
    moved = batch_force_closure(P + shift, Nrm, mu=mu, reference_points=shift[:, 0])
    scaled = batch_force_closure(2.5 * P, Nrm, mu=mu)
    perm = rng.permutation(N)
    permuted = batch_force_closure(P[:, perm], Nrm[:, perm], mu=mu[:, perm])
    for other in (moved, scaled, permuted):
        np.testing.assert_allclose(other.d_star, base.d_star, atol=1e-8)
        np.testing.assert_array_equal(other.is_closure, base.is_closure)
        np.testing.assert_array_equal(other.rank, base.rank)


def test_normals_are_normalised():
    rng = np.random.default_rng(8)
    P, Nrm = random_grasps(rng, 100, 3, 3)
    scale = rng.uniform(0.01, 100, (100, 3, 1))
    a = batch_force_closure(P, Nrm, mu=0.4)
    b = batch_force_closure(P, Nrm * scale, mu=0.4)
    np.testing.assert_allclose(a.d_star, b.d_star, atol=1e-9)


def test_balanced_forces_that_do_not_push_give_zero():
    # Two equal pushes on one line of action: N(G_n) is spanned by (1, -1), whose
    # normal forces sum to zero, so no balanced force pushes (d* = 0 exactly).
    P = np.array([[[0.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [2.0, 0.0]]])
    Nrm = np.array([[[1.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [1.0, 0.0]]])
    res = batch_form_closure(P, Nrm)
    np.testing.assert_array_equal(res.d_star, [0.0, 0.0])
    np.testing.assert_array_equal(res.rank, [1, 1])  # same line of action
    assert res.converged.all() and not res.is_closure.any()
