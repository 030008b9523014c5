"""An independent force-closure test for the plant tests (scipy, not the library).

Shared by the test modules of this folder (``tests/plant`` is on ``sys.path``,
see its conftest).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linprog


def independent_force_closure(contacts, mu: float, n_g: int = 8) -> bool:
    """Force closure on inscribed pyramids: 0 strictly inside the wrench hull.

    Written here from the definition (not the library's LP2): with primitive
    wrenches ``w_k = [s_k; c × s_k]`` of every generator of every cone, the grasp
    is in force closure iff rank W = 6 and ``W λ = 0`` has a solution with every
    ``λ_k >= t > 0`` (``Σ λ = 1``).
    """
    W = []
    for c in contacts:
        n = c.nhat_O
        a = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
        t1 = np.cross(n, a)
        t1 /= np.linalg.norm(t1)
        t2 = np.cross(n, t1)
        for k in range(n_g):
            th = 2 * np.pi * k / n_g
            s = n + mu * (np.cos(th) * t1 + np.sin(th) * t2)
            W.append(np.concatenate([s, np.cross(c.p_OC, s)]))
    W = np.array(W).T
    if np.linalg.matrix_rank(W, tol=1e-9 * np.abs(W).max()) < 6:
        return False
    m = W.shape[1]
    # variables [λ (m), t]; maximise t
    cost = np.zeros(m + 1)
    cost[-1] = -1.0
    A_eq = np.vstack([np.hstack([W, np.zeros((6, 1))]), np.r_[np.ones(m), 0.0]])
    b_eq = np.r_[np.zeros(6), 1.0]
    A_ub = np.hstack([-np.eye(m), np.ones((m, 1))])  # t - λ_k <= 0
    res = linprog(cost, A_ub=A_ub, b_ub=np.zeros(m), A_eq=A_eq, b_eq=b_eq,
                  bounds=[(0, None)] * (m + 1), method="highs")  # fmt: skip
    if res.status == 2:  # no λ >= 0 with W λ = 0, Σ λ = 1: 0 is outside the hull
        return False
    assert res.status == 0
    return -res.fun > 1e-9
