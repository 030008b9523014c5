"""Batch ε L1 (expanding polytope) against Qhull's ferrari_canny, grasp by grasp.

About 15,000 seeded grasps in all, N = 2 … 12: random spatial and planar hard
fingers, soft fingers, frictionless contacts, mixed μ = 0, and symmetric
grasps (antipodal pairs, contacts evenly spaced on a circle or at the vertices
of a regular solid, repeated contacts, non-closed ones).  The reference is
:func:`drakegrasp.quality.ferrari_canny` through the per-grasp loop
(``kernel="numpy"``), which builds one :class:`~drakegrasp.Grasp` per grasp.
"""

from __future__ import annotations

import numpy as np
import pytest
from batch_support import random_grasps

from drakegrasp.batch import batch_epsilon_l1
from drakegrasp.batch.build.construction import batched_characteristic_lengths
from drakegrasp.batch.build.wrenches import batched_primitive_wrenches
from drakegrasp.batch.epsilon import kernel as epsilon_kernel
from drakegrasp.batch.epsilon.routes import epsilon_l1_per_grasp, epsilon_l1_routes

pytestmark = pytest.mark.skipif(
    not epsilon_kernel.AVAILABLE, reason="the compiled ε kernel needs numba"
)

REL, ABS = 1e-9, 1e-12


def _reference(P, Nrm, mu, nu, p, b, model, n_g=8):
    return epsilon_l1_per_grasp(
        P, Nrm, mu, nu, p, b, contact_model=model, num_generators=n_g
    )


def _check(P, Nrm, mu, *, model="hard_finger", nu=0.0, p=None, n_g=8):
    """Kernel vs Qhull on one family; returns (grasps, kernel-route fraction)."""
    K, N, d = P.shape
    Nrm = Nrm / np.linalg.norm(Nrm, axis=-1, keepdims=True)
    mu = np.broadcast_to(np.asarray(mu, dtype=float), (K, N)).copy()
    nu = np.broadcast_to(np.asarray(nu, dtype=float), (K, N)).copy()
    p = np.zeros((K, d)) if p is None else p
    b = batched_characteristic_lengths(P, p)
    eps, qhull = epsilon_l1_routes(
        P, Nrm, mu, nu, p, b, contact_model=model, num_generators=n_g, kernel="numba"
    )
    want = _reference(P, Nrm, mu, nu, p, b, model, n_g)
    err = np.abs(eps - want)
    bad = np.flatnonzero(~(err <= np.maximum(REL * want, ABS)))
    assert bad.size == 0, (bad[:5], eps[bad[:5]], want[bad[:5]])
    assert (eps[want == 0.0] == 0.0).all()
    assert (eps >= 0.0).all()
    return K, 1.0 - qhull.mean()


RANDOM = [
    # (model, d, N, K, mu)
    ("hard_finger", 3, 2, 600, 0.5),
    ("hard_finger", 3, 3, 2000, 0.5),
    ("hard_finger", 3, 4, 1200, 0.5),
    ("hard_finger", 3, 5, 500, 0.5),
    ("hard_finger", 3, 6, 60, 0.5),
    ("hard_finger", 3, 8, 40, 0.5),
    ("hard_finger", 3, 4, 800, 0.05),
    ("hard_finger", 3, 3, 800, 1.5),
    ("hard_finger", 2, 2, 800, 0.5),
    ("hard_finger", 2, 3, 800, 0.5),
    ("hard_finger", 2, 5, 500, 0.3),
    ("hard_finger", 2, 8, 400, 0.5),
    ("frictionless", 3, 7, 400, 0.0),
    ("frictionless", 3, 12, 300, 0.0),
    ("frictionless", 2, 4, 400, 0.0),
]


@pytest.mark.parametrize(("model", "d", "N", "K", "mu"), RANDOM)
def test_random_grasps_agree_with_qhull(model, d, N, K, mu):
    rng = np.random.default_rng(1000 * N + K + d)
    P, Nrm = random_grasps(rng, K, N, d, spread=0.5)
    p = 0.2 * rng.normal(size=(K, d))
    n, share = _check(P, Nrm, mu, model=model, p=p)
    assert n == K
    assert share > 0.95  # the kernel, not Qhull, answers almost every grasp


@pytest.mark.parametrize(("N", "K"), [(3, 500), (4, 300)])
def test_soft_fingers_agree_with_qhull(N, K):
    rng = np.random.default_rng(7 + N)
    P, Nrm = random_grasps(rng, K, N, 3, spread=0.5)
    mu = rng.choice([0.0, 0.3, 0.8], size=(K, N))
    nu = rng.choice([0.0, 0.05, 0.5], size=(K, N))
    _check(P, Nrm, mu, model="soft_finger", nu=nu)


def test_mixed_zero_friction_agrees_with_qhull():
    rng = np.random.default_rng(11)
    K, N = 600, 5
    P, Nrm = random_grasps(rng, K, N, 3, spread=0.3)
    mu = np.where(rng.random((K, N)) < 0.4, 0.0, 0.6)
    _check(P, Nrm, mu)
    _check(P[:, :, :2], Nrm[:, :, :2], mu)


def _rotations(rng, K):
    q, r = np.linalg.qr(rng.normal(size=(K, 3, 3)))
    q *= np.sign(np.diagonal(r, axis1=1, axis2=2))[:, None, :]
    q[np.linalg.det(q) < 0, :, 0] *= -1.0
    return q


def _regular(name):
    if name == "tetrahedron":
        return np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]]) / 3**0.5
    if name == "octahedron":
        return np.vstack([np.eye(3), -np.eye(3)])
    cube = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)])
    return cube / 3**0.5


def _circle(N, d):
    t = 2 * np.pi * np.arange(N) / N
    P = np.zeros((N, d))
    P[:, 0], P[:, 1] = np.cos(t), np.sin(t)
    return P


@pytest.mark.parametrize("name", ["tetrahedron", "octahedron", "cube"])
@pytest.mark.parametrize("mu", [0.0, 0.2, 0.5, 1.0])
def test_regular_solids_agree_with_qhull(name, mu):
    """Contacts at a regular solid's vertices, inward normals: exact symmetry."""
    rng = np.random.default_rng(len(name))
    V = _regular(name)
    K = {"tetrahedron": 40, "octahedron": 20, "cube": 10}[name]
    R = _rotations(rng, K)
    R[0] = np.eye(3)  # one in axis-aligned coordinates
    P = np.einsum("kij,nj->kni", R, V)
    _check(P, -P, mu)


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("N", [2, 3, 4, 5, 6, 8])
def test_evenly_spaced_contacts_agree_with_qhull(N, d):
    rng = np.random.default_rng(N + 10 * d)
    K = 30 if N < 6 else 12
    P = np.broadcast_to(_circle(N, d), (K, N, d)).copy()
    if d == 3:
        P = np.einsum("kij,knj->kni", _rotations(rng, K), P)
        P[:3] = _circle(N, d)  # a few exactly in the x-y plane
    tilt = np.linspace(0.0, 0.6, K)[:, None, None]
    Nrm = -P + tilt * np.roll(P, 1, axis=1)  # from inward to skewed
    for mu in (0.0, 0.3, 0.7):
        _check(P, Nrm, mu)


@pytest.mark.parametrize("d", [2, 3])
def test_antipodal_pairs_agree_with_qhull(d):
    rng = np.random.default_rng(3 + d)
    for pairs, K in ((1, 150), (2, 150), (3, 20), (4, 10)):
        A = rng.normal(size=(K, pairs, d))
        A /= np.linalg.norm(A, axis=-1, keepdims=True)
        P = np.concatenate([A, -A], axis=1)
        _check(P, -P, 0.5)
        _check(P, -P + 0.05 * rng.normal(size=P.shape), 0.3)


def test_repeated_and_non_closed_contacts_agree_with_qhull():
    rng = np.random.default_rng(5)
    K, N = 400, 5
    P, Nrm = random_grasps(rng, K, N, 3, spread=0.4)
    P[:, -1], Nrm[:, -1] = P[:, 0], Nrm[:, 0]  # a repeated contact
    P[:, -2], Nrm[:, -2] = P[:, 1], Nrm[:, 1]
    _check(P, Nrm, 0.5)
    same = np.broadcast_to(np.array([0.0, 0.0, 1.0]), P.shape)  # all push one way
    eps_K, _ = _check(P, same, 0.5)
    assert eps_K == K


def test_two_hard_fingers_are_flat_and_zero():
    """Two spatial hard fingers cannot resist torque about their axis: ε = 0."""
    rng = np.random.default_rng(2)
    P, Nrm = random_grasps(rng, 200, 2, 3, spread=0.0)
    eps = batch_epsilon_l1(P, Nrm, mu=1.0)
    assert (eps == 0.0).all()
    W = batched_primitive_wrenches(
        P, Nrm / np.linalg.norm(Nrm, axis=-1, keepdims=True), np.ones((200, 2)),
        np.zeros((200, 2)), np.zeros((200, 3)), batched_characteristic_lengths(
            P, np.zeros((200, 3))), contact_model="hard_finger", num_generators=8,
    )  # fmt: skip
    _, status = epsilon_kernel.epsilon_l1_stack(W)
    assert (status == epsilon_kernel.FLAT).all()
