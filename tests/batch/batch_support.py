"""Shared helpers of the batch-engine tests: random grasps and independent routes."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linprog

from drakegrasp import Contact, Grasp, normal_grasp_matrix
from drakegrasp.core.friction_cone import ConeLayout


def random_grasps(rng, K, N, d, *, spread=0.4, radius=1.0):
    """Contacts on a sphere (circle) with roughly inward normals plus noise.

    ``spread`` mixes closure and no-closure cases: 0 gives exact inward normals.
    """
    P = rng.normal(size=(K, N, d))
    P *= radius / np.linalg.norm(P, axis=-1, keepdims=True)
    Nrm = -P / radius + spread * rng.normal(size=(K, N, d))
    return P, Nrm


def make_grasp(P, Nrm, mu, *, model="hard_finger", nu=0.0, p=None, b=None):
    """One drakegrasp.Grasp from (N, d) arrays and per-contact coefficients."""
    N = P.shape[0]
    mu = np.broadcast_to(np.asarray(mu, dtype=float), (N,))
    nu = np.broadcast_to(np.asarray(nu, dtype=float), (N,))
    contacts = [
        Contact(P[i], Nrm[i], mu=mu[i], contact_model=model, torsional_friction=nu[i])
        for i in range(N)
    ]
    return Grasp(contacts, reference_point=p, characteristic_length=b)


def _lp_margin(G, F, normal_cols, N):
    """max d s.t. G f = 0, F f - d >= 0, d >= 0, sum f_n <= N with HiGHS."""
    w, M = G.shape
    c = np.zeros(M + 1)
    c[-1] = -1.0
    A_ub = np.hstack([-F, np.ones((F.shape[0], 1))])
    budget = np.zeros(M + 1)
    budget[normal_cols] = 1.0
    A_ub = np.vstack([A_ub, budget])
    b_ub = np.zeros(A_ub.shape[0])
    b_ub[-1] = N
    res = linprog(
        c,
        A_ub=A_ub,
        b_ub=b_ub,
        A_eq=np.hstack([G, np.zeros((w, 1))]),
        b_eq=np.zeros(w),
        bounds=[(None, None)] * M + [(0, None)],
        method="highs",
    )
    assert res.status == 0, res.message
    return -res.fun


def _rank(A, rank_tol=1e-9):
    s = np.linalg.svd(A, compute_uv=False)
    return int(np.sum(s > rank_tol * s[0]))


def scipy_force_closure(grasp, num_generators=8):
    """(d*, rank) of LP2 built per grasp from the single-grasp building blocks."""
    layout = ConeLayout.of(grasp, num_generators)
    G, F, normal_cols = layout.G, layout.facet_matrix(), list(layout.normal_positions)
    return _lp_margin(G, F, normal_cols, grasp.num_contacts), _rank(G)


def scipy_form_closure(grasp):
    """(d*, rank) of LP1 on G_n with HiGHS."""
    Gn = normal_grasp_matrix(grasp)
    N = grasp.num_contacts
    return _lp_margin(Gn, np.eye(N), list(range(N)), N), _rank(Gn)


def degenerate_families(rng, K, *, spread=0.4):
    """``[(name, P, Nrm, mu)]``: ``K`` grasps of four spatial contacts per family.

    The degeneracies the batch LPs must survive: a tiny and a huge ``mu``, a
    duplicated contact, metres scaled by 1e±3, coplanar and collinear points,
    all contacts at one point, normals exactly inward.
    """
    P, Nrm = random_grasps(rng, K, 4, 3, spread=spread)
    dup_P, dup_N = P.copy(), Nrm.copy()
    dup_P[:, 3], dup_N[:, 3] = P[:, 0], Nrm[:, 0]
    flat = P.copy()
    flat[:, :, 2] = 0.0
    line = np.zeros_like(P)
    line[:, :, 0] = rng.normal(size=(K, 4))
    one_point = np.repeat(P[:, :1], 4, axis=1)
    exact_P, exact_N = random_grasps(rng, K, 4, 3, spread=0.0)
    return [
        ("tiny mu", P, Nrm, 1e-6),
        ("huge mu", P, Nrm, 50.0),
        ("duplicate contact", dup_P, dup_N, 0.5),
        ("metres x1e3", 1e3 * P, Nrm, 0.5),
        ("metres x1e-3", 1e-3 * P, Nrm, 0.5),
        ("coplanar points", flat, Nrm, 0.5),
        ("collinear points", line, Nrm, 0.5),
        ("all at one point", one_point, Nrm, 0.5),
        ("exactly inward", exact_P, exact_N, 0.2),
    ]
