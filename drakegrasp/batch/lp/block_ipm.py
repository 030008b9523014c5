r"""A batched interior-point method that keeps the closure LPs' block structure.

Every problem ``k`` of a stack is the closure LP in its unreduced form

.. math::

    t^* = \max_{f, t} t \quad \text{s.t.} \quad A f = b,\quad
    C f - \mathbf 1 t \ge 0 ,

with ``A = [Qᵀ; eᵀ]`` (``Q`` an orthonormal basis of the row space of ``G``, so
``G f = 0`` stays ``w <= 6`` rows; ``e`` sums the normal components;
``b = [0; 1]``) and ``C = BlockDiag(C_1 … C_N)`` the facet rows of each contact's
cone.  Nothing is eliminated up front, so the cost per iteration is linear in
the number of contacts ``N``: with ``D = λ/s``, the Newton system

.. math::

    \begin{bmatrix} H & \tilde A^T \\ \tilde A & 0 \end{bmatrix},\qquad
    H = [C, -\mathbf 1]^T D\, [C, -\mathbf 1] ,

has ``H`` block-diagonal per contact (``C_iᵀ D_i C_i``, ``k_i × k_i``) apart
from the single variable ``t``.  Eliminating the contact blocks leaves a
``(w + 1) × (w + 1)`` Schur complement ``S = Σ_i A_i H_i^{-1} A_iᵀ`` (7 × 7
spatial, 4 × 4 planar) and one scalar for ``t``.  ``H`` itself is singular
(moving every ``f_i`` along its cone axis and ``t`` together leaves ``C f - t``
unchanged), which is why ``t`` is eliminated last, through ``S``.

Arrays are "structure of arrays": a contact group's vectors are (rows, n_c, K)
with the batch axis last and contiguous; contacts of the same kind form one
group so each operation runs over all of them at once.

Dual: :math:`\min b^T y` s.t. :math:`C^T λ = A^T y,\ \mathbf 1^T λ = 1,\ λ \ge 0`.
An early exit proves ``t* < stop_below`` without solving to the end: for
``λ̂ = λ / 1ᵀλ``, ``ŷ = y / 1ᵀλ`` and ``g = Cᵀλ̂ - Aᵀŷ``, every feasible ``f``
with ``t >= 0`` (so every ``f_i`` in its cone, ``‖f_i‖ <= κ_i f_{n,i}``) has
``t <= λ̂ᵀ C f = ŷ_{last} + gᵀ f <= ŷ_{last} + max_i κ_i ‖g_i‖``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drakegrasp.batch.lp.tolerances import IPM_MAX_ITER, IPM_TOL

__all__ = ["BlockSolution", "ContactGroup", "solve_block_lp"]

_STEP = 0.9995  # fraction of the distance to the boundary taken per step
_FLOOR = 0.1  # smallest centring target, as a fraction of tol / (rows)


@dataclass
class ContactGroup:
    """The contacts of one kind in a stack of closure LPs.

    Attributes
    ----------
    facets : (r, c) or (r, c, n, K) or (r, c, n, 1) float
        Facet rows ``C_i`` of the ``n`` contacts (``c`` components, ``r`` rows);
        2-D when every contact of every problem shares them.
    rows : (e, c, n, K) float
        Columns of ``A`` that belong to these contacts' components.
    kappa : (n, K) float
        ``κ_i >= ‖f_i‖ / f_{n,i}`` on the cone (for the ``stop_below`` proof).
    start : (c, n, K) float
        A starting ``f`` that satisfies ``A f = b`` (together with the other
        groups).
    """

    facets: np.ndarray
    rows: np.ndarray
    kappa: np.ndarray
    start: np.ndarray


@dataclass(frozen=True)
class BlockSolution:
    """Optimal values of a stack of block LPs.

    Attributes
    ----------
    value : (K,) float
        ``t*`` (or, where ``below`` is set, a certified upper bound of it).
    converged : (K,) bool
        Residuals and gap below the tolerance, or ``below``.
    below : (K,) bool
        Stopped early: ``t* <= value < stop_below`` is proved.
    iterations : (K,) int
    """

    value: np.ndarray
    converged: np.ndarray
    below: np.ndarray
    iterations: np.ndarray


# --------------------------------------------------------------------------
# Per-group products; the batch axes are (n, K) for contacts, (K,) for globals.


def _mul(F: np.ndarray, f: np.ndarray) -> np.ndarray:
    """``C_i f_i`` for every contact: (c, n, K) -> (r, n, K)."""
    if F.ndim == 2:
        return np.tensordot(F, f, axes=(1, 0))
    return np.einsum("rc...,c...->r...", F, f)


def _tmul(F: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``C_iᵀ v_i`` for every contact: (r, n, K) -> (c, n, K)."""
    if F.ndim == 2:
        return np.tensordot(F, v, axes=(0, 0))
    return np.einsum("rc...,r...->c...", F, v)


def _gram(F: np.ndarray, D: np.ndarray) -> np.ndarray:
    """``C_iᵀ diag(D_i) C_i``: (r, n, K) -> (c, c, n, K)."""
    r, c = F.shape[:2]
    if F.ndim == 2:
        FF = (F[:, :, None] * F[:, None, :]).reshape(r, c * c).T
        return (FF @ D.reshape(r, -1)).reshape((c, c) + D.shape[1:])
    return np.einsum("ra...,rb...,r...->ab...", F, F, D)


def _cholesky(M: np.ndarray) -> np.ndarray:
    """Lower Cholesky factors of SPD stacks (n, n, ...); the diagonal holds 1/L_jj."""
    n = M.shape[0]
    L = np.zeros_like(M)
    floor = 1e-300 + 1e-14 * np.abs(M[np.arange(n), np.arange(n)]).max(axis=0)
    for j in range(n):
        s = M[j, j].copy()
        for k in range(j):
            s -= L[j, k] * L[j, k]
        inv = 1.0 / np.sqrt(np.maximum(s, floor))
        L[j, j] = inv
        for i in range(j + 1, n):
            s = M[i, j].copy()
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s * inv
    return L


def _cho_solve(L: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve ``L Lᵀ z = b``, factors from :func:`_cholesky`.

    ``L`` is (n, n, *batch) and ``b`` (n, *batch) or (n, m, *batch) (``m``
    right-hand sides; the batch axes broadcast).
    """
    n = L.shape[0]
    y = np.empty_like(b)
    for i in range(n):
        acc = b[i].copy()
        for j in range(i):
            acc -= L[i, j] * y[j]
        y[i] = acc * L[i, i]
    for i in reversed(range(n)):
        acc = y[i]
        for j in range(i + 1, n):
            acc = acc - L[j, i] * y[j]
        y[i] = acc * L[i, i]
    return y


def _max_step(v: np.ndarray, dv: np.ndarray) -> np.ndarray:
    """Largest α in (0, ∞] with ``v + α dv >= 0`` per problem, as 1/α: (K,)."""
    q = -(dv / v)
    return q.reshape(-1, q.shape[-1]).max(axis=0)


def _step(qs: list[np.ndarray], fraction: float) -> np.ndarray:
    q = np.max(np.stack(qs), axis=0)
    with np.errstate(divide="ignore"):
        return np.where(q > 0.0, np.minimum(1.0, fraction / q), 1.0)


def _axis_scale(F: np.ndarray) -> np.ndarray:
    """``γ_i`` with ``C_i e_0 = γ_i 1`` (every cone here is symmetric about e_0)."""
    gamma = F[:1, 0]
    if not np.allclose(F[:, 0], gamma, rtol=1e-12, atol=0.0):
        raise ValueError("facet rows must share their normal coefficient")
    return gamma[0]


def _starting_point(F, groups: list[ContactGroup]):
    """``t`` below every ``C f``, ``g = f - t â``, centred ``s``, ``λ``, and ``y``."""
    Cf = [_mul(Fg, g.start) for Fg, g in zip(F, groups, strict=True)]
    lo = np.min(np.stack([c.reshape(-1, c.shape[-1]).min(axis=0) for c in Cf]), 0)
    hi = np.max(np.stack([c.reshape(-1, c.shape[-1]).max(axis=0) for c in Cf]), 0)
    R = sum(c.shape[0] * c.shape[1] for c in Cf)
    t = lo - 0.5 * (hi - lo) - 1e-3
    s = [c - t for c in Cf]
    lam = [np.full_like(c, 1.0 / R) for c in Cf]
    # Mehrotra's shift towards the central path, then 1ᵀλ = 1.
    sl = sum((si * li).sum(axis=(0, 1)) for si, li in zip(s, lam, strict=True))
    ssum = sum(si.sum(axis=(0, 1)) for si in s)
    lam = [li + 0.5 * sl / ssum for li in lam]
    lsum = sum(li.sum(axis=(0, 1)) for li in lam)
    lam = [li / lsum for li in lam]
    # y: least-squares fit of Aᵀ y = Cᵀ λ.
    AAt = sum(np.einsum("ecnk,fcnk->efk", g.rows, g.rows) for g in groups)
    rhs = sum(
        np.einsum("ecnk,cnk->ek", g.rows, _tmul(Fg, li))
        for Fg, g, li in zip(F, groups, lam, strict=True)
    )
    y = _cho_solve(_cholesky(AAt), rhs)
    return t, s, lam, y


def _cut(arrs: list[np.ndarray], keep: np.ndarray) -> list[np.ndarray]:
    return [x[..., keep] for x in arrs]


def _amax(arrs: list[np.ndarray]) -> np.ndarray:
    return np.max(
        np.stack([np.abs(a).reshape(-1, a.shape[-1]).max(axis=0) for a in arrs]),
        axis=0,
    )


def _sum(arrs) -> np.ndarray:
    return sum(a.sum(axis=(0, 1)) for a in arrs)


class _Newton:
    """One iteration's factorised Newton system (block Cholesky and Schur)."""

    def __init__(self, F, A, s, D, r1, r2, r3, r4, Lh, W, LS, a, u, denom):
        self.F, self.A, self.s, self.D = F, A, s, D
        self.r1, self.r2, self.r3, self.r4 = r1, r2, r3, r4
        self.Lh, self.W, self.LS, self.a, self.u, self.denom = Lh, W, LS, a, u, denom

    def direction(self, r5):
        """Newton direction for the complementarity right-hand side ``r5``."""
        F, A, s, D, r1, r2, r3, r4 = (
            self.F,
            self.A,
            self.s,
            self.D,
            self.r1,
            self.r2,
            self.r3,
            self.r4,
        )
        Lh, W, LS, a, u, denom = self.Lh, self.W, self.LS, self.a, self.u, self.denom
        q = [r5g / sg + Dg * r4g for r5g, sg, Dg, r4g in zip(r5, s, D, r4, strict=True)]
        z = [
            _cho_solve(Lg, _tmul(Fg, qg) + r1g)
            for Lg, Fg, qg, r1g in zip(Lh, F, q, r1, strict=True)
        ]
        rho = r3 - sum(
            np.einsum("ecnk,cnk->ek", Ag, zg) for Ag, zg in zip(A, z, strict=True)
        )
        w = _cho_solve(LS, rho)
        dt = (r2 + np.einsum("ek,ek->k", a, w)) / denom
        dy = u * dt - w
        dg = [
            zg - np.einsum("cenk,ek->cnk", Wg, dy) for zg, Wg in zip(z, W, strict=True)
        ]
        ds = [_mul(Fg, dgg) - r4g for Fg, dgg, r4g in zip(F, dg, r4, strict=True)]
        dl = [
            r5g / sg - Dg * dsg for r5g, sg, Dg, dsg in zip(r5, s, D, ds, strict=True)
        ]
        return dg, dt, dy, ds, dl


def solve_block_lp(
    groups: list[ContactGroup],
    *,
    tol: float = IPM_TOL,
    max_iter: int = IPM_MAX_ITER,
    stop_below: float | None = None,
) -> BlockSolution:
    r"""Solve a stack of closure LPs in block form (module docstring).

    Parameters
    ----------
    groups : list of ContactGroup
        The contacts of the LPs, grouped by kind; together their ``rows`` form
        ``A`` (e, M) with ``e = w + 1`` rows, the last one ``eᵀ``.
    tol : float, optional
        Tolerance on the residuals and on the gap ``sᵀλ / (1 + |t|)``.
    max_iter : int, optional
        Iteration cap; problems still open then are accepted at ``1e3 tol``
        or reported with ``converged = False``.
    stop_below : float, optional
        Stop a problem once ``t* < stop_below`` is proved (its ``value`` is
        then the proved bound).

    Returns
    -------
    BlockSolution

    Notes
    -----
    Every cone is symmetric about its axis, ``C_i e_0 = γ_i 1``, so with
    ``â_i = e_0 / γ_i`` the substitution ``f = g + t â`` turns the rows into
    ``C g >= 0`` and the equalities into ``A g + t a = b``, ``a = A â``.  The
    Newton matrix in ``g`` is then the block-diagonal ``Cᵀ D C`` (positive
    definite), and ``t`` enters only through ``a``:
    ``Δt = (r_2 + aᵀ S⁻¹ ρ) / (aᵀ S⁻¹ a)``, with no cancellation.
    """
    K = groups[0].rows.shape[-1]
    out_t = np.zeros(K)
    out_conv = np.zeros(K, dtype=bool)
    out_below = np.zeros(K, dtype=bool)
    out_it = np.zeros(K, dtype=int)
    if K == 0:
        return BlockSolution(out_t, out_conv, out_below, out_it)
    F = [g.facets for g in groups]
    A = [g.rows for g in groups]
    kappa = [g.kappa for g in groups]
    gamma = [_axis_scale(Fg) for Fg in F]
    a = sum(
        np.einsum("enk,nk->ek", Ag[:, 0], np.broadcast_to(1.0 / gm, Ag.shape[2:]))
        if np.ndim(gm) else Ag[:, 0].sum(axis=1) / gm
        for Ag, gm in zip(A, gamma, strict=True)
    )  # fmt: skip
    t, s, lam, y = _starting_point(F, groups)
    g = [grp.start.copy() for grp in groups]
    for gg, gm in zip(g, gamma, strict=True):
        gg[0] -= t / gm
    R = sum(si.shape[0] * si.shape[1] for si in s)
    idx = np.arange(K)
    for it in range(1, max_iter + 1):
        r1 = [
            _tmul(Fg, lg) - np.einsum("ecnk,ek->cnk", Ag, y)
            for Fg, lg, Ag in zip(F, lam, A, strict=True)
        ]
        lsum = _sum(lam)
        r2 = 1.0 - np.einsum("ek,ek->k", a, y)
        r3 = -sum(
            np.einsum("ecnk,cnk->ek", Ag, gg) for Ag, gg in zip(A, g, strict=True)
        )
        r3 -= a * t
        r3[-1] += 1.0
        r4 = [sg - _mul(Fg, gg) for sg, Fg, gg in zip(s, F, g, strict=True)]
        gap = sum((sg * lg).sum(axis=(0, 1)) for sg, lg in zip(s, lam, strict=True))
        err_d = np.maximum(_amax(r1), np.abs(r2))
        err_p = np.maximum(np.abs(r3).max(axis=0), _amax(r4))
        err_g = gap / (1.0 + np.abs(t))
        done = (err_p <= tol) & (err_d <= tol) & (err_g <= tol)
        below = np.zeros_like(done)
        value = t
        if stop_below is not None:
            worst = np.max(
                np.stack(
                    [
                        (np.sqrt((rg * rg).sum(axis=0)) * kg).max(axis=0)
                        for rg, kg in zip(r1, kappa, strict=True)
                    ]
                ),
                axis=0,
            )
            with np.errstate(divide="ignore", invalid="ignore"):
                bound = (y[-1] + worst) / lsum
            below = (bound < stop_below) & ~done & (lsum > 0.0)
            done = done | below
            value = np.where(below, bound, t)
        last = it == max_iter
        if last or done.any():
            if last:
                loose = 1e3 * tol
                ok = (err_p <= loose) & (err_d <= loose) & (err_g <= loose) | below
                done[:] = True
            else:
                ok = done
            k = idx[done]
            out_t[k] = value[done]
            out_conv[k] = ok[done]
            out_below[k] = below[done]
            out_it[k] = it
            keep = ~done
            if not keep.any():
                break
            idx, t, y, a = idx[keep], t[keep], y[:, keep], a[:, keep]
            r2, r3, gap = r2[keep], r3[:, keep], gap[keep]

            g, s, lam, r1, r4 = (_cut(x, keep) for x in (g, s, lam, r1, r4))
            A, kappa = _cut(A, keep), _cut(kappa, keep)
            F = [Fg if Fg.ndim == 2 or Fg.shape[-1] == 1 else Fg[..., keep] for Fg in F]
        mu = gap / R

        D = [lg / sg for lg, sg in zip(lam, s, strict=True)]
        Lh = [_cholesky(_gram(Fg, Dg)) for Fg, Dg in zip(F, D, strict=True)]
        W = [
            _cho_solve(Lg, np.swapaxes(Ag, 0, 1)) for Lg, Ag in zip(Lh, A, strict=True)
        ]  # (c, e, n, K)
        S = sum(
            np.einsum("ecnk,cfnk->efk", Ag, Wg) for Ag, Wg in zip(A, W, strict=True)
        )
        LS = _cholesky(S)
        u = _cho_solve(LS, a)
        denom = np.einsum("ek,ek->k", a, u)

        newton = _Newton(F, A, s, D, r1, r2, r3, r4, Lh, W, LS, a, u, denom)
        direction = newton.direction

        # Predictor (affine scaling).
        dg, dt, dy, ds, dl = direction(
            [-(sg * lg) for sg, lg in zip(s, lam, strict=True)]
        )
        a_p = _step([_max_step(sg, dsg) for sg, dsg in zip(s, ds, strict=True)], 1.0)
        a_d = _step([_max_step(lg, dlg) for lg, dlg in zip(lam, dl, strict=True)], 1.0)
        mu_aff = (
            sum(
                ((sg + a_p * dsg) * (lg + a_d * dlg)).sum(axis=(0, 1))
                for sg, dsg, lg, dlg in zip(s, ds, lam, dl, strict=True)
            )
            / R
        )
        sigma = (mu_aff / np.maximum(mu, 1e-300)) ** 3
        # Corrector; its centring target stays above a tenth of the gap
        # tolerance so that the complementarity cannot collapse (and D = λ/s
        # explode) while the residuals still have to converge.
        target = np.maximum(sigma * mu, _FLOOR * tol / R)
        r5 = [
            target - sg * lg - dsg * dlg
            for sg, lg, dsg, dlg in zip(s, lam, ds, dl, strict=True)
        ]
        dg, dt, dy, ds, dl = direction(r5)
        a_p = _step([_max_step(sg, dsg) for sg, dsg in zip(s, ds, strict=True)], _STEP)
        a_d = _step(
            [_max_step(lg, dlg) for lg, dlg in zip(lam, dl, strict=True)], _STEP
        )
        g = [gg + a_p * dgg for gg, dgg in zip(g, dg, strict=True)]
        s = [sg + a_p * dsg for sg, dsg in zip(s, ds, strict=True)]
        t = t + a_p * dt
        lam = [lg + a_d * dlg for lg, dlg in zip(lam, dl, strict=True)]
        y = y + a_d * dy
    return BlockSolution(out_t, out_conv, out_below, out_it)
