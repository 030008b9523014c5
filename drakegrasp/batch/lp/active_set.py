r"""An exact active-set (simplex) solver for the closure LP in a small null space.

On a grasp of full row rank ``w`` with an orthonormal basis ``Z`` (M × n) of
``N(G)``, every balanced force is ``f = Z v`` and the closure LP of
:mod:`drakegrasp.batch.lp.dstar` becomes

.. math::

    t^* = \max_{v \in \mathbb R^n,\, t} t \quad \text{s.t.} \quad
    \tilde c^T v = 1,\; a_j^T v - t \ge 0 \;(j = 1 \dots R),

with ``a_j = (F Z)_j`` (facet row ``j`` of the cones, pulled back to ``v``) and
``c̃ = Zᵀ e`` (the normal-component sum).  Its dual,
``t* = min {s : s c̃ ∈ conv{a_j}}``, is where the line through ``c̃`` first
meets the hull of the ``a_j``.  For three hard contacts ``n = 3`` and
``R = 24`` (eight facets each): a handful of vertex steps settle it, where the
interior-point method needs a dozen linear-algebra-heavy iterations.

The method is the primal active-set method (the simplex method with free
variables, Nocedal & Wright, *Numerical Optimization*, §16.5 specialised to a
linear objective).  ``x = (v, t)`` starts at ``v = c̃ / ‖c̃‖²``,
``t = min_j a_jᵀ v`` with that one facet active.  Each step takes the
projection ``d`` of the objective gradient ``e_t`` onto the null space of the
active constraint gradients (``(c̃, 0)`` and ``(a_j, -1)``, from a Householder QR
of them) and moves along it to the first blocking facet, which joins the
active set; when ``d`` vanishes, the least-squares multipliers of the active
facets either are all non-negative (optimal) or the most negative one leaves.
Blocking facets have gradients outside the active span, so the active set
stays linearly independent; ties go to the lowest facet index, and after
``2R`` steps the leaving facet is chosen by the lowest index too (Bland's rule)
against cycling on degenerate vertices.

The answer is only returned when it is certified: at the end the slacks are
recomputed from scratch (primal feasibility), the multipliers are
non-negative (dual feasibility) and ``‖d‖`` is at rounding level
(stationarity), so ``t`` is ``t*`` to rounding.  Anything else (iteration cap,
no blocking facet, a failed check) returns ``ok = False`` and the caller solves
the LP with the interior-point method instead.
"""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.batch.compiled import FASTMATH, njit
from drakegrasp.batch.lp.householder import _qr, _reflect
from drakegrasp.batch.lp.tolerances import BLOCK_TOL
from drakegrasp.errors import InvalidOptionError

__all__ = ["solve_reduced_lp", "worth_it"]


_D_TOL = 1e-12  # ‖d‖ (d a projection of a unit vector) below this: stationary
_DUAL_TOL = 1e-12  # multipliers above -this count as non-negative
_FEAS_TOL = 1e-12  # slacks above -this (relative to the largest |a_jᵀv|) are feasible


@njit(cache=True)
def worth_it(nz, R):
    """Whether this solver beats the block IPM on ``nz`` unknowns and ``R`` facets.

    Measured on this project's benchmark stacks (one core, µs per LP, active
    set against IPM): ``nz = 3`` 0.7–1.8 against 4.3–6.2 at every ``R``;
    ``(nz, R)`` = (4, 10) 5.3 / 13, (5, 8) 3.8 / 7.2, (6, 12) 9.7 / 20,
    (7, 10) 9.5 / 13, but (6, 30–32) 10–15 / 10–13 and (9, 12) 16 / 15: steps
    grow with ``nz`` and each costs ``O(R nz)``.
    """
    return nz == 2 or nz == 3 or (nz <= 7 and R <= 4 * nz)


@njit(cache=True)
def active_set_work(nz, R):
    """Work arrays of :func:`_active_set` for ``nz`` unknowns and ``R`` facets."""
    n = nz + 1
    BT = np.empty((n, n))
    V = np.empty((n, n))
    beta = np.empty(n)
    y = np.empty((1, n))
    d = np.empty(n)
    mu = np.empty(n)
    v = np.empty(nz)
    slack = np.empty(R)
    gnorm = np.empty(R)
    rates = np.empty(R)
    active = np.empty(n, dtype=np.int64)
    inW = np.empty(R, dtype=np.bool_)
    return BT, V, beta, y, d, mu, v, slack, gnorm, rates, active, inW


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _project(AT, nz, ct, active, k, BT, V, beta, y, d, mu):
    """QR of the ``k`` active gradients, the projected ``e_t`` and the multipliers.

    Column 0 is ``(c̃, 0)``, column ``c >= 1`` is ``(a_j, -1)`` for
    ``j = active[c - 1]``.  Solves ``B mu ≈ e_t`` in least squares and leaves
    ``d = e_t - B mu`` (the component of ``e_t`` outside the active span).
    Returns ``‖d‖``.
    """
    n = nz + 1
    for i in range(nz):
        BT[0, i] = ct[i]
    BT[0, nz] = 0.0
    for c in range(1, k):
        j = active[c - 1]
        for i in range(nz):
            BT[c, i] = AT[i, j]
        BT[c, nz] = -1.0
    _qr(BT, n, k, V, beta)
    for i in range(n):
        y[0, i] = 0.0
    y[0, nz] = 1.0
    for j in range(k):
        _reflect(V, j, beta[j], y, 0, n)  # y = Qᵀ e_t
    for c in range(k - 1, -1, -1):  # R mu = (Qᵀ e_t)[:k]
        acc = y[0, c]
        for m in range(c + 1, k):
            acc -= BT[m, c] * mu[m]
        mu[c] = acc / BT[c, c]
    for i in range(k):
        y[0, i] = 0.0
    for j in range(k - 1, -1, -1):
        _reflect(V, j, beta[j], y, 0, n)  # back to x-space: the residual
    norm = 0.0
    for i in range(n):
        d[i] = y[0, i]
        norm += d[i] * d[i]
    return math.sqrt(norm)


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _active_set(AT, nz, R, ct, cn2, max_iter, work):
    """``(t*, ok, steps)`` of the reduced LP; ``AT`` (nz, R) holds the ``a_j``."""
    BT, V, beta, y, d, mu, v, slack, gnorm, rates, active, inW = work
    for i in range(nz):
        v[i] = ct[i] / cn2
    t = math.inf
    j0 = 0
    for j in range(R):
        acc = 0.0
        g2 = 1.0
        for i in range(nz):
            acc += AT[i, j] * v[i]
            g2 += AT[i, j] * AT[i, j]
        slack[j] = acc
        gnorm[j] = math.sqrt(g2)
        inW[j] = False
        if acc < t:
            t = acc
            j0 = j
    for j in range(R):
        slack[j] -= t
    slack[j0] = 0.0
    active[0] = j0
    inW[j0] = True
    k = 2  # columns of B: (c̃, 0) and the active facets
    optimal = False
    steps = 0
    for steps in range(1, max_iter + 1):
        dn = _project(AT, nz, ct, active, k, BT, V, beta, y, d, mu)
        if dn > _D_TOL:
            best = math.inf
            jb = -1
            for j in range(R):
                if inW[j]:
                    continue
                rate = -d[nz]
                for i in range(nz):
                    rate += AT[i, j] * d[i]
                rates[j] = rate
                if rate < -BLOCK_TOL * dn * gnorm[j]:
                    alpha = max(slack[j], 0.0) / -rate
                    if alpha < best:
                        best = alpha
                        jb = j
            if jb < 0:
                return t, False, steps  # unbounded along d: cannot happen
            for i in range(nz):
                v[i] += best * d[i]
            t += best * d[nz]
            for j in range(R):
                if not inW[j]:
                    slack[j] += best * rates[j]
            slack[jb] = 0.0
            active[k - 1] = jb
            inW[jb] = True
            k += 1
            continue
        # Stationary: λ_j = -mu_c of facet j = active[c - 1].
        leave = -1
        worst = -_DUAL_TOL
        for c in range(1, k):
            lam = -mu[c]
            if steps > 2 * R:  # Bland: the lowest facet index with λ < 0
                lowest = leave < 0 or active[c - 1] < active[leave - 1]
                if lam < -_DUAL_TOL and lowest:
                    leave = c
            elif lam < worst:
                worst = lam
                leave = c
        if leave < 0:
            optimal = True
            break
        inW[active[leave - 1]] = False
        for c in range(leave, k - 1):
            active[c - 1] = active[c]
        k -= 1
    if not optimal:
        return t, False, steps
    # Certify: slacks recomputed from scratch are feasible.
    scale = abs(t)
    lo = math.inf
    for j in range(R):
        acc = 0.0
        for i in range(nz):
            acc += AT[i, j] * v[i]
        scale = max(scale, abs(acc))
        lo = min(lo, acc - t)
    return t, lo >= -_FEAS_TOL * max(1.0, scale), steps


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _cross2(bx, by, i, j):
    """``β_i × β_j`` (the z component of the 2-D cross product)."""
    return bx[i] * by[j] - by[i] * bx[j]


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _plane_lp(AT, R, ct, cn2, al, bx, by, max_iter):
    """:func:`_active_set` for ``nz = 3``, in the plane ``c̃ᵀv = 1``.

    With ``v = c̃/‖c̃‖² + U u`` (``U`` an orthonormal basis of ``c̃⊥``, from a
    Householder reflection of ``c̃``) the LP is ``max t`` s.t. ``t <= α_j +
    β_jᵀ u``, ``u ∈ R²``: one active facet moves along its steepest ascent
    ``(β_a, |β_a|²)``, two along their edge ``(β_a, -1) × (β_b, -1)`` and three
    make a vertex whose multipliers are the barycentric coordinates of 0 in
    the triangle ``β_a β_b β_c``.  The same rules, tolerances and
    certification as :func:`_active_set`; returns ``(t*, ok, steps)``.
    """
    nrm = math.sqrt(cn2)
    w0 = ct[0] + (nrm if ct[0] >= 0.0 else -nrm)
    w1, w2 = ct[1], ct[2]
    h = 2.0 / (w0 * w0 + w1 * w1 + w2 * w2)
    u10, u11, u12 = -h * w0 * w1, 1.0 - h * w1 * w1, -h * w2 * w1
    u20, u21, u22 = -h * w0 * w2, -h * w1 * w2, 1.0 - h * w2 * w2
    t = math.inf
    ia = 0
    for j in range(R):
        a0, a1, a2 = AT[0, j], AT[1, j], AT[2, j]
        al[j] = (a0 * ct[0] + a1 * ct[1] + a2 * ct[2]) / cn2
        bx[j] = a0 * u10 + a1 * u11 + a2 * u12
        by[j] = a0 * u20 + a1 * u21 + a2 * u22
        if al[j] < t:
            t = al[j]
            ia = j
    ux = 0.0
    uy = 0.0
    ib = -1
    ic = -1
    k = 1
    optimal = False
    steps = 0
    d2 = _D_TOL * _D_TOL
    for steps in range(1, max_iter + 1):
        if k == 1:
            dx, dy = bx[ia], by[ia]
            dt = dx * dx + dy * dy
            if dt <= d2 * (1.0 + dt):  # ‖P e_t‖² = |β_a|² / (1 + |β_a|²)
                optimal = True  # λ_a = 1
                break
        elif k == 2:
            dx = by[ib] - by[ia]
            dy = bx[ia] - bx[ib]
            dt = _cross2(bx, by, ia, ib)
            if dt < 0.0:
                dx, dy, dt = -dx, -dy, -dt
            if dt * dt <= d2 * (dx * dx + dy * dy + dt * dt):
                # 0, β_a and β_b collinear: λ_b β_b + λ_a β_a = 0, λ_a + λ_b = 1
                ex, ey = bx[ib] - bx[ia], by[ib] - by[ia]
                lb = -(bx[ia] * ex + by[ia] * ey) / (ex * ex + ey * ey)
                la = 1.0 - lb
                if la >= -_DUAL_TOL and lb >= -_DUAL_TOL:
                    optimal = True
                    break
                if la < lb:
                    ia = ib
                ib = -1
                k = 1
                continue
        else:
            xa = _cross2(bx, by, ib, ic)
            xb = _cross2(bx, by, ic, ia)
            xc = _cross2(bx, by, ia, ib)
            D = xa + xb + xc  # twice the signed area of the triangle
            la, lb, lc = xa / D, xb / D, xc / D
            if la >= -_DUAL_TOL and lb >= -_DUAL_TOL and lc >= -_DUAL_TOL:
                optimal = True
                break
            if steps > 2 * R:  # Bland: the lowest facet index with λ < 0
                drop = R
                for j, lam in ((ia, la), (ib, lb), (ic, lc)):
                    if lam < -_DUAL_TOL and j < drop:
                        drop = j
            else:
                drop = ia if la <= min(lb, lc) else (ib if lb <= lc else ic)
            if drop == ia:
                ia = ic
            elif drop == ib:
                ib = ic
            ic = -1
            k = 2
            continue
        # Move along (dx, dy, dt) to the first blocking facet.
        dd = dx * dx + dy * dy + dt * dt
        best = math.inf
        jb = -1
        for j in range(R):
            if j == ia or j == ib:
                continue
            rate = bx[j] * dx + by[j] * dy - dt
            if rate < 0.0 and rate * rate > (
                BLOCK_TOL * BLOCK_TOL * dd * (1.0 + bx[j] * bx[j] + by[j] * by[j])
            ):
                slack = al[j] + bx[j] * ux + by[j] * uy - t
                alpha = max(slack, 0.0) / -rate
                if alpha < best:
                    best = alpha
                    jb = j
        if jb < 0:
            return t, False, steps  # unbounded along d: cannot happen
        ux += best * dx
        uy += best * dy
        t += best * dt
        if k == 1:
            ib = jb
        else:
            ic = jb
        k += 1
    if not optimal:
        return t, False, steps
    scale = abs(t)
    lo = math.inf
    for j in range(R):
        acc = al[j] + bx[j] * ux + by[j] * uy
        scale = max(scale, abs(acc))
        lo = min(lo, acc - t)
    return t, lo >= -_FEAS_TOL * max(1.0, scale), steps


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def reduced_lp(AT, nz, R, ct, cn2, max_iter, work):
    """``(t*, ok, steps)`` by :func:`_plane_lp` (``nz = 3``) or :func:`_active_set`."""
    if nz == 3:  # the planar form's α, β_x, β_y live in three R-long work rows
        _, _, _, _, _, _, _, slack, gnorm, rates, _, _ = work
        return _plane_lp(AT, R, ct, cn2, slack, gnorm, rates, max_iter)
    return _active_set(AT, nz, R, ct, cn2, max_iter, work)


@njit(
    cache=True,
    entry="f8[:, :, ::1], f8[:, ::1], i8, b1, f8[::1], b1[::1], i8[::1]",
)
def _solve_stack(AT, ct, max_iter, general, out_t, out_ok, out_steps):
    K, nz, R = AT.shape
    work = active_set_work(nz, R)
    for k in range(K):
        cn2 = 0.0
        for i in range(nz):
            cn2 += ct[k, i] * ct[k, i]
        if general:
            t, ok, steps = _active_set(AT[k], nz, R, ct[k], cn2, max_iter, work)
        else:
            t, ok, steps = reduced_lp(AT[k], nz, R, ct[k], cn2, max_iter, work)
        out_t[k], out_ok[k], out_steps[k] = t, ok, steps


def solve_reduced_lp(
    a: np.ndarray,
    c: np.ndarray,
    *,
    max_iter: int | None = None,
    method: str = "auto",
):
    """``t* = max {t : cᵀv = 1, a_jᵀ v >= t}`` for a stack of reduced LPs.

    Parameters
    ----------
    a : (K, R, n) float
        Constraint rows ``a_j`` of each LP.
    c : (K, n) float
        Equality row of each LP, nonzero.
    max_iter : int, optional
        Step cap (default ``10 R + 50``).
    method : {"auto", "general"}, optional
        ``"auto"``: the planar form for ``n = 3`` (as the batch engine);
        ``"general"``: the ``n``-dimensional method for every ``n``.

    Returns
    -------
    t : (K,) float
        ``t*`` where ``ok``.
    ok : (K,) bool
        Solved and certified; False leaves the LP to another solver.
    steps : (K,) int
        Active-set steps taken.
    """
    if method not in ("auto", "general"):
        raise InvalidOptionError(f"method must be 'auto' or 'general', not {method!r}")
    a = np.asarray(a, dtype=float)
    K, R, n = a.shape
    out_t = np.zeros(K)
    out_ok = np.zeros(K, dtype=np.bool_)
    out_steps = np.zeros(K, dtype=np.int64)
    _solve_stack(
        np.ascontiguousarray(np.transpose(a, (0, 2, 1))),
        np.ascontiguousarray(c, dtype=float),
        int(10 * R + 50 if max_iter is None else max_iter), method == "general",
        out_t, out_ok, out_steps,
    )  # fmt: skip
    return out_t, out_ok, out_steps
