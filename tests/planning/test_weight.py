"""Weight capacity: closed forms for two opposed contacts, a second formulation
(scipy's HiGHS on the primal written out here), and invariance to units."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

from drakegrasp.core.contact import Contact
from drakegrasp.core.grasp import Grasp
from drakegrasp.planning import weight
from drakegrasp.planning.weight import WEIGHT_DIRECTIONS, weight_capacity
from drakegrasp.quality import primitive_wrenches


def _stack_sizes(monkeypatch) -> list[int]:
    """The number of LPs of each call to the active-set method, as it runs."""
    sizes, solve = [], weight.solve_max_last_active
    monkeypatch.setattr(
        weight,
        "solve_max_last_active",
        lambda B, *a, **k: sizes.append(len(B)) or solve(B, *a, **k),
    )
    return sizes


@pytest.mark.parametrize("solver", ["batch", "drake"])
def test_two_opposed_contacts_closed_form(solver):
    mu, r = 0.4, 0.03
    P = np.array([[[-r, 0, 0], [r, 0, 0]]])
    N = np.array([[[1.0, 0, 0], [-1.0, 0, 0]]])
    dirs = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, 0, -1]])
    a = weight_capacity(
        P, N, np.array([[0, 1]]), mu=mu, torque_scale=r, directions=dirs, solver=solver
    )
    # along the axis one finger's normal force (<= 1); across it both frictions
    assert a[0] == pytest.approx([1.0, 1.0, 2 * mu, 2 * mu], abs=1e-7)


def _scipy_capacity(grasp, fingers, u, b):
    per_contact = primitive_wrenches(grasp, torque_scale=b)
    W = np.vstack(per_contact)  # (M, 6), contact-major
    g = np.concatenate(
        [np.full(len(w), f) for w, f in zip(per_contact, fingers, strict=True)]
    )
    M = len(W)
    A_eq = np.hstack([W.T, np.r_[u, 0, 0, 0][:, None]])
    A_ub = np.array([np.r_[(g == f).astype(float), 0.0] for f in (0, 1)])
    res = linprog(
        np.r_[np.zeros(M), -1.0], A_ub=A_ub, b_ub=np.ones(2), A_eq=A_eq,
        b_eq=np.zeros(6), bounds=(0, None), method="highs",
    )  # fmt: skip
    assert res.status == 0
    return -res.fun


@pytest.mark.parametrize("solver", ["batch", "drake"])
def test_agrees_with_a_second_formulation(solver):
    rng = np.random.default_rng(11)
    for _ in range(4):
        # two pads of three contacts each, facing each other across x
        pad = rng.normal(0, 0.01, (3, 3)) * [0, 1, 1]
        P = np.vstack([pad + [-0.03, 0, 0], pad * [1, -1, 1] + [0.03, 0, 0]])
        P += rng.normal(0, 0.01, 3)  # off the centre of mass
        tilt = rng.normal(0, 0.1, (6, 3))
        N = np.vstack([np.tile([1.0, 0, 0], (3, 1)), np.tile([-1.0, 0, 0], (3, 1))])
        N = (N + tilt) / np.linalg.norm(N + tilt, axis=1, keepdims=True)
        fingers = np.array([0, 0, 0, 1, 1, 1])
        a = weight_capacity(
            P[None], N[None], fingers[None], mu=0.5, torque_scale=0.05, solver=solver
        )[0]
        grasp = Grasp([Contact(p, n, mu=0.5) for p, n in zip(P, N, strict=True)])
        ref = [_scipy_capacity(grasp, fingers, u, 0.05) for u in WEIGHT_DIRECTIONS]
        assert a == pytest.approx(ref, rel=1e-6, abs=1e-8)


def test_independent_of_units_and_torque_scale():
    rng = np.random.default_rng(12)
    P = rng.normal(0, 0.02, (1, 6, 3))
    N = -P / np.linalg.norm(P, axis=2, keepdims=True)
    F = np.array([[0, 0, 0, 1, 1, 1]])
    a = weight_capacity(P, N, F, mu=0.6, torque_scale=0.05)
    b = weight_capacity(P * 1000, N, F, mu=0.6, torque_scale=3.0)
    assert a == pytest.approx(b, rel=1e-6, abs=1e-9)


def test_the_batch_dual_and_the_primal_program_agree_on_many_grasps():
    rng = np.random.default_rng(13)
    P = rng.normal(0, 0.03, (30, 8, 3))
    N = -P / np.linalg.norm(P, axis=2, keepdims=True) + rng.normal(0, 0.3, P.shape)
    N /= np.linalg.norm(N, axis=2, keepdims=True)
    F = np.repeat([[0, 0, 0, 0, 1, 1, 1, 2]], 30, axis=0)  # one palm contact
    a = weight_capacity(P, N, F, mu=0.7, torque_scale=0.05)
    b = weight_capacity(P, N, F, mu=0.7, torque_scale=0.05, solver="drake")
    assert a == pytest.approx(b, rel=1e-6, abs=1e-8)


# a WSG grasp of the shipped box (two tip spheres per pad on opposite faces)
# whose dual the interior-point method does not converge on (its normal
# matrices grow too ill-conditioned): the exact active-set method settles it
STUCK_P = np.array(
    [
        [0.0081496997684664, -0.01291709425002098, -0.05],
        [-0.00595025839012233, -0.01400850614570803, -0.05],
        [0.00814973082117587, -0.01291712084081603, 0.05],
        [-0.00595022733741124, -0.01400853273650447, 0.05],
    ]
)
STUCK_N = np.array([[0.0, 0, 1], [0, 0, 1], [0, 0, -1], [0, 0, -1]])


@pytest.mark.parametrize("workers", [1, 2])
def test_chunks_and_workers_change_no_number(workers, monkeypatch):
    # the grasps go in chunks of WEIGHT_CHUNK, each solved alone (by the
    # active-set method, the degenerate ones too): the numbers are those of
    # one call on all grasps, for any number of workers
    rng = np.random.default_rng(14)
    P = np.repeat(STUCK_P[None], 23, axis=0)
    N = np.repeat(STUCK_N[None], 23, axis=0)
    P[6:] += rng.normal(0, 0.01, (17, 4, 3))
    N[6:] += rng.normal(0, 0.2, (17, 4, 3))
    N /= np.linalg.norm(N, axis=2, keepdims=True)
    F = np.tile([0, 0, 1, 1], (23, 1))
    exact = _stack_sizes(monkeypatch)
    before = weight._FALLBACKS["clp"]
    whole = weight_capacity(P, N, F, mu=1.0, torque_scale=0.06)
    assert exact and exact[0] == 23 * len(WEIGHT_DIRECTIONS)  # every LP
    monkeypatch.setattr(weight, "WEIGHT_CHUNK", 5)
    chunked = weight_capacity(P, N, F, mu=1.0, torque_scale=0.06, workers=workers)
    assert np.array_equal(chunked, whole)
    if workers == 1:  # (a worker process counts in its own module)
        assert weight._FALLBACKS["clp"] == before


def _highs_capacity(W, groups, u, G=3):
    """α(u) of the primal LP by scipy's HiGHS at tight tolerances."""
    M = len(W)
    c = np.zeros(M + 1)
    c[-1] = -1.0
    A_eq = np.zeros((W.shape[1], M + 1))
    A_eq[:, :M] = W.T
    A_eq[:3, -1] = u
    A_ub = (np.clip(groups, 0, G - 1)[None, :] == np.arange(G)[:, None]).astype(float)
    A_ub = np.hstack([A_ub, np.zeros((G, 1))])
    res = linprog(
        c, A_ub=A_ub, b_ub=np.ones(G), A_eq=A_eq, b_eq=np.zeros(len(A_eq)),
        bounds=[(0, None)] * (M + 1), method="highs",
        options={"primal_feasibility_tolerance": 1e-10,
                 "dual_feasibility_tolerance": 1e-10},
    )  # fmt: skip
    assert res.status == 0
    return res.x[-1]


def _degenerate_grasps(rng, K=12):
    """Pads on opposite flat faces: coplanar contacts, some duplicated."""
    P, N = [], []
    for k in range(K):
        xy = rng.uniform(-0.03, 0.03, (3, 2))
        if k % 3 == 0:
            xy[1] = xy[0]  # a duplicate contact on each pad
        top = np.column_stack([xy, np.full(3, 0.05)])
        bottom = top * [1, 1, -1]
        P.append(np.vstack([bottom, top]))
        N.append(np.repeat([[0.0, 0, 1], [0, 0, -1]], 3, axis=0))
    P = np.array(P)
    P[1::2] += rng.normal(0, 1e-7, P[1::2].shape)  # nearly coplanar too
    return P, np.array(N), np.tile([0, 0, 0, 1, 1, 1], (K, 1))


def test_degenerate_pads_are_solved_in_the_compiled_path():
    # coplanar and duplicated pad contacts: α(u) equals the primal through
    # HiGHS (tight) and Clp, and none of them needs the Clp fallback
    from drakegrasp.batch.build.wrenches import batched_primitive_wrenches

    P, N, F = _degenerate_grasps(np.random.default_rng(21))
    before = weight._FALLBACKS["clp"]
    a = weight_capacity(P, N, F, mu=1.0, torque_scale=0.06)
    assert weight._FALLBACKS["clp"] == before
    clp = weight_capacity(P, N, F, mu=1.0, torque_scale=0.06, solver="drake")
    # Clp stops at its own tolerances (about 1e-6 here); HiGHS is run tighter
    assert a == pytest.approx(clp, rel=5e-6, abs=1e-8)
    K, n, _ = P.shape
    W = batched_primitive_wrenches(
        P, N, np.ones((K, n)), np.zeros((K, n)), np.zeros((K, 3)),
        np.full(K, 0.06), contact_model="hard_finger", num_generators=8,
    )  # fmt: skip
    groups = np.repeat(F, 8, axis=1)
    for k in range(K):
        for d, u in enumerate(WEIGHT_DIRECTIONS):
            assert a[k, d] == pytest.approx(
                _highs_capacity(W[k], groups[k], u), rel=1e-8, abs=1e-9
            )


def test_the_route_without_numba_gives_the_same_capacities(monkeypatch):
    # without numba the interior-point method (numpy) goes first and the
    # active-set method (then a Python loop) takes only what it leaves
    P, N, F = _degenerate_grasps(np.random.default_rng(22), K=6)
    P = np.vstack([P, STUCK_P[None, [0, 1, 1, 2, 3, 3]]])
    N = np.vstack([N, STUCK_N[None, [0, 1, 1, 2, 3, 3]]])
    F = np.vstack([F, [[0, 0, 0, 1, 1, 1]]])
    compiled = weight_capacity(P, N, F, mu=1.0, torque_scale=0.06)
    monkeypatch.setattr(weight.compiled, "AVAILABLE", False)
    routes = _stack_sizes(monkeypatch)
    before = weight._FALLBACKS["clp"]
    numpy_first = weight_capacity(P, N, F, mu=1.0, torque_scale=0.06)
    assert weight._FALLBACKS["clp"] == before
    assert routes and routes[0] < P.shape[0] * len(WEIGHT_DIRECTIONS)  # only some
    np.testing.assert_allclose(numpy_first, compiled, rtol=1e-9, atol=1e-10)
