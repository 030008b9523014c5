"""An exact (rational) simplex method, and the polyhedral payload solved with it.

A reference route that shares no code, no units and no tolerance with the
solvers: every float of the grasp matrix, the generators, the load and the
limits is read as the exact rational it is (``Fraction(float)``), and the
simplex method (two phases, Bland's rule) pivots in rational arithmetic.  At
``μ = 1e-12`` the tangential forces are 1e-12 of the normal ones; here that
is no reason for any digit to be lost.  Small problems only (a few contacts).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

import drakegrasp as dg
from drakegrasp.core.friction_cone import ConeLayout


def _rat(x) -> Fraction:
    return Fraction(float(x))


def lp_max(c, A_eq, b_eq, A_ub=(), b_ub=()):
    """``max cᵀx`` s.t. ``A_eq x = b_eq``, ``A_ub x <= b_ub``, ``x >= 0``, exactly.

    Entries may be floats or Fractions.  Returns ``(value, x)`` with Fractions,
    ``(inf, None)`` when unbounded; raises ``ValueError`` when infeasible.
    """
    n = len(c)
    rows = [[_rat(a) for a in r] + [Fraction(0)] * len(A_ub) for r in A_eq]
    rhs = [_rat(b) for b in b_eq]
    for k, (r, b) in enumerate(zip(A_ub, b_ub, strict=True)):
        slack = [Fraction(0)] * len(A_ub)
        slack[k] = Fraction(1)
        rows.append([_rat(a) for a in r] + slack)
        rhs.append(_rat(b))
    for i, b in enumerate(rhs):
        if b < 0:
            rows[i] = [-a for a in rows[i]]
            rhs[i] = -b
    m, width = len(rows), n + len(A_ub)
    # Phase 1: artificials width .. width + m - 1, minimise their sum.
    T = [
        rows[i] + [Fraction(int(i == k)) for k in range(m)] + [rhs[i]] for i in range(m)
    ]
    basis = [width + i for i in range(m)]
    phase1 = [Fraction(0)] * width + [Fraction(-1)] * m
    _simplex(T, basis, phase1)
    if sum(T[i][-1] for i in range(m) if basis[i] >= width) != 0:
        raise ValueError("infeasible")
    # Drive artificials out of the basis (or drop their redundant rows).
    for i in range(m - 1, -1, -1):
        if basis[i] >= width:
            j = next((j for j in range(width) if T[i][j] != 0), None)
            if j is None:
                del T[i], basis[i]
            else:
                _pivot(T, basis, i, j)
    T = [r[:width] + [r[-1]] for r in T]
    cost = [_rat(a) for a in c] + [Fraction(0)] * len(A_ub)
    if not _simplex(T, basis, cost):
        return math.inf, None
    x = [Fraction(0)] * width
    for i, j in enumerate(basis):
        x[j] = T[i][-1]
    return sum(cj * xj for cj, xj in zip(cost, x, strict=True)), x[:n]


def _pivot(T, basis, r, j):
    p = T[r][j]
    T[r] = [a / p for a in T[r]]
    for i in range(len(T)):
        if i != r and T[i][j] != 0:
            f = T[i][j]
            T[i] = [a - f * b for a, b in zip(T[i], T[r], strict=True)]
    basis[r] = j


def _simplex(T, basis, cost) -> bool:
    """Maximise ``cost`` over the tableau (Bland's rule); False when unbounded."""
    width = len(T[0]) - 1
    while True:
        cb = [cost[j] for j in basis]
        entering = None
        for j in range(width):
            if j in basis:
                continue
            reduced = cost[j] - sum(cb[i] * T[i][j] for i in range(len(T)))
            if reduced > 0:
                entering = j
                break
        if entering is None:
            return True
        best = None
        for i in range(len(T)):
            a = T[i][entering]
            if a > 0:
                ratio = T[i][-1] / a
                if (
                    best is None
                    or ratio < best[0]
                    or (ratio == best[0] and basis[i] < basis[best[1]])
                ):
                    best = (ratio, i)
        if best is None:
            return False
        _pivot(T, basis, best[1], entering)


def polyhedral_max_load(
    grasp,
    direction,
    *,
    num_generators=4,
    max_normal_force=None,
    max_squeeze=None,
    hand_jacobian=None,
    torque_limits=None,
):
    """``α*`` of :func:`drakegrasp.max_load` with ``cones="polyhedral"``, exactly.

    The cones in generator form (``f_i = S_i λ_i``, ``λ_i >= 0``, the same
    floats as :class:`~drakegrasp.core.friction_cone.ConeLayout`), the balance
    ``G f + α d = 0`` on the grasp matrix in newtons, every limit a row.
    Returns a float (``inf`` when unbounded).
    """
    G = dg.grasp_matrix(grasp)
    layout = ConeLayout.of(grasp, num_generators)
    d = np.asarray(direction, dtype=float)
    N = grasp.num_contacts
    blocks, normal_rows = [], []
    for s, cone in zip(grasp.component_slices(), layout.cones, strict=True):
        cols = np.arange(s.start, s.stop)[list(cone.components)]
        blocks.append((cols, cone.generators))
    n_lam = sum(S.shape[1] for _, S in blocks)
    # Variables: λ (every generator of every contact), then α.
    gen = np.zeros((G.shape[1], n_lam), dtype=object)
    gen[:] = Fraction(0)
    k = 0
    for i, (cols, S) in enumerate(blocks):
        for col in range(S.shape[1]):
            for r, c in enumerate(cols):
                gen[c, k] = _rat(S[r, col])
            normal_rows.append((i, k))
            k += 1
    Gr = [[_rat(v) for v in row] for row in G]
    # Forces per generator: f = gen @ λ (exact); balance rows G f + α d = 0.
    A_eq = []
    for r in range(G.shape[0]):
        row = [
            sum(Gr[r][c] * gen[c, j] for c in range(G.shape[1])) for j in range(n_lam)
        ]
        A_eq.append(row + [_rat(d[r])])
    b_eq = [0] * G.shape[0]
    A_ub, b_ub = [], []

    def normal_row(contacts):
        row = [Fraction(0)] * (n_lam + 1)
        for i, j in normal_rows:
            if i in contacts:
                row[j] = gen[blocks[i][0][0], j]
        return row

    if max_normal_force is not None:
        fmax = np.broadcast_to(np.asarray(max_normal_force, dtype=float), (N,))
        for i in range(N):
            if np.isfinite(fmax[i]):
                A_ub.append(normal_row({i}))
                b_ub.append(fmax[i])
    if max_squeeze is not None and np.isfinite(max_squeeze):
        A_ub.append(normal_row(set(range(N))))
        b_ub.append(max_squeeze)
    if torque_limits is not None:
        J = np.asarray(hand_jacobian, dtype=float)
        tau = np.broadcast_to(np.asarray(torque_limits, dtype=float), (J.shape[1],))
        for j in range(J.shape[1]):
            if not np.isfinite(tau[j]):
                continue
            Jr = [_rat(v) for v in J[:, j]]
            row = [
                sum(Jr[c] * gen[c, q] for c in range(G.shape[1])) for q in range(n_lam)
            ]
            A_ub.append(row + [Fraction(0)])
            b_ub.append(tau[j])
            A_ub.append([-v for v in row] + [Fraction(0)])
            b_ub.append(tau[j])
    c = [0] * n_lam + [1]
    value, _ = lp_max(c, A_eq, b_eq, A_ub, b_ub)
    return float(value)
