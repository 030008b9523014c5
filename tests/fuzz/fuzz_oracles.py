"""Independent answers for the fuzz suite: closed forms and scipy LPs.

Nothing here calls drakegrasp's programs: the grasp matrix is written from its
formula with ``np.cross``, the cones from their generators, and the LPs are
solved by ``scipy.optimize.linprog`` (HiGHS) on a well-scaled copy of the grasp
(contacts about their centroid, lengths divided by their spread), so the answer
for nanometre, gigametre or far-referenced grasps is the answer for the same
grasp in well-scaled units.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linprog

RANK_TOL = 1e-9


def frame(n: np.ndarray) -> np.ndarray:
    """[n, t1, t2] with t1 from the coordinate axis least aligned with n."""
    n = np.asarray(n, dtype=np.longdouble)
    n = n / np.max(np.abs(n))
    n = np.asarray(n / np.sqrt(np.sum(n * n)), dtype=float)
    if n.size == 2:
        return np.column_stack([n, [-n[1], n[0]]])
    e = np.zeros(3)
    e[np.argmin(np.abs(n))] = 1.0
    t1 = e - (e @ n) * n
    t1 /= np.linalg.norm(t1)
    return np.column_stack([n, t1, np.cross(n, t1)])


def unit(v) -> np.ndarray:
    """Unit vector computed in extended precision (no overflow below 1e4932)."""
    v = np.asarray(v, dtype=np.longdouble)
    return np.asarray(v / np.sqrt(np.sum(v * v)), dtype=float)


def well_scaled(positions: np.ndarray) -> np.ndarray:
    """Positions about their centroid over their spread (extended precision)."""
    P = np.asarray(positions, dtype=np.longdouble)
    c = P - P.mean(axis=0)
    spread = np.sqrt(np.max(np.sum(c * c, axis=1)))
    return np.asarray(c / (spread if spread > 0 else 1), dtype=float)


def _wrench(r, u):
    if r.size == 2:
        return np.concatenate([u, [r[0] * u[1] - r[1] * u[0]]])
    return np.concatenate([u, np.cross(r, u)])


def cones(normals, mus, n_g=8):
    """Per contact: (generators in the grasp frame as columns, cone kind)."""
    out = []
    for n, mu in zip(normals, mus, strict=True):
        R = frame(n)
        if mu == 0:
            out.append(R[:, :1])
        elif R.shape[0] == 2:
            out.append(
                np.column_stack([R[:, 0] + mu * R[:, 1], R[:, 0] - mu * R[:, 1]])
            )
        else:
            k = 2 * np.pi * np.arange(1, n_g + 1) / n_g
            dirs = [
                R[:, 0] + mu * (np.cos(a) * R[:, 1] + np.sin(a) * R[:, 2]) for a in k
            ]
            out.append(np.column_stack(dirs))
    return out


def closure_verdict(positions, normals, mus, *, n_g=8, tol=1e-6):
    """Force closure (hard fingers / frictionless when mu = 0) by a scipy LP.

    Generator (V-) form on the well-scaled copy: force closure iff ``rank(G)``
    (over the allowed components) is full and ``max d`` s.t. ``W λ = 0``, ``λ >= d``,
    ``Σ λ <= K`` has ``d* > 0``.  Returns (verdict, d*, rank), or None near the
    boundary (``1e-9 < d* < 1e-4``), where no independent verdict is clear.
    """
    P = well_scaled(positions)
    gens = cones(normals, mus, n_g)
    cols = []
    for r, S in zip(P, gens, strict=True):
        cols += [_wrench(r, S[:, j]) for j in range(S.shape[1])]
    W = np.array(cols).T
    W = W / np.linalg.norm(W, axis=0)  # the cone, not the generators' lengths
    dim = W.shape[0]
    # Rank of G over the components the cones allow (f_n, and f_t when mu > 0).
    gcols = []
    for r, n, mu in zip(P, normals, mus, strict=True):
        R = frame(n)
        gcols += [_wrench(r, R[:, j]) for j in range(R.shape[1] if mu > 0 else 1)]
    G = np.array(gcols).T
    s = np.linalg.svd(G / np.linalg.norm(G, axis=0), compute_uv=False)
    rank = int(np.sum(s > RANK_TOL * s[0])) if s[0] > 0 else 0
    K = W.shape[1]
    c = np.zeros(K + 1)
    c[-1] = -1.0
    A_eq = np.hstack([W, np.zeros((dim, 1))])
    A_ub = np.vstack(
        [np.hstack([-np.eye(K), np.ones((K, 1))]), np.append(np.ones(K), 0)[None]]
    )
    b_ub = np.append(np.zeros(K), K)
    res = linprog(
        c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=np.zeros(dim), method="highs"
    )
    d = float(res.x[-1]) if res.status == 0 else 0.0
    if 1e-9 < d < 1e-4 or (rank < min(dim, s.size) and s[rank] > 1e-6 * s[0]):
        return None
    return bool(rank == dim and d > 1e-9), d, rank


def form_closure_verdict(positions, normals):
    """Form closure: the frictionless verdict (mu = 0 everywhere)."""
    return closure_verdict(positions, normals, [0.0] * len(normals))
