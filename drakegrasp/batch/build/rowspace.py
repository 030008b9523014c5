r"""Ranks and row spaces of stacks of grasp matrices, invariant to units and to ``p``.

Ranks, row spaces and null spaces are decided on a *normalised* grasp matrix
(:doc:`/conventions`, Invariance): moments about the contacts' centroid
``c̄`` divided by their spread ``L = max_i ‖c_i - c̄‖`` (``L = 1`` when all
contacts coincide).  Moving the reference point or changing units multiplies
``G`` on the left by an invertible matrix ``T``, which changes neither
``N(G)`` nor ``G``'s row space, so the normalised matrix gives the same LPs
while its singular values no longer depend on where ``p`` is or on the unit of
length.  A soft finger's torsion column ``[0; n]`` is a moment, so its variable
is measured in units of ``L`` too (:func:`normalised_positions` documents the
scaling).

The row space is found in ``O(N)`` per grasp: a Householder QR of ``G̃ᵀ``
(``M × w``), vectorised over the stack, certifies full row rank with
``1/‖R⁻¹‖_F <= σ_min`` and ``σ_max <= ‖G̃‖_F`` and then gives an orthonormal
basis ``Q`` (``M × w``); the uncertain rest takes an SVD, which applies the
threshold ``σ <= rank_tol σ_max`` exactly.
"""

from __future__ import annotations

import numpy as np

__all__ = ["normalised_positions", "row_spaces"]


def normalised_positions(positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Contact points about their centroid in units of their spread.

    Parameters
    ----------
    positions : (K, N, d) float
        Contact points, metres.

    Returns
    -------
    scaled : (K, N, d) float
        ``(c_i - c̄) / L``, dimensionless; a grasp matrix built from these with
        ``p = 0`` is ``T G`` for the grasp's ``G`` about any ``p`` (``T``
        invertible), with a soft finger's torsion variable ``m_n`` replaced by
        ``m_n / L``.
    spread : (K,) float
        ``L = max_i ‖c_i - c̄‖`` metres (1 where every contact sits at ``c̄``).
    """
    centre = positions.mean(axis=1, keepdims=True)
    r = positions - centre
    # max |r| first, so that squaring cannot overflow for huge coordinates.
    big = np.abs(r).max(axis=(1, 2))
    big = np.where(big > 0.0, big, 1.0)
    u = r / big[:, None, None]
    spread = big * np.sqrt((u * u).sum(axis=-1).max(axis=1))
    ok = spread > 0.0
    spread = np.where(ok, spread, 1.0)
    return np.where(ok[:, None, None], r / spread[:, None, None], 0.0), spread


def _householder(GT: np.ndarray, *, complement: bool = False):
    """Householder QR of stacks (M, w, K), M >= w: ``R`` (w, w, K) and ``Q``.

    ``Q`` is the thin factor (M, w, K), or with ``complement=True`` the last
    ``M - w`` columns of the complete one (M, M - w, K): an orthonormal basis of
    the complement of the columns.
    """
    M, w, K = GT.shape
    A = GT.copy()
    vs, betas = [], []
    for j in range(w):
        x = A[j:, j]
        norm = np.sqrt(np.einsum("ik,ik->k", x, x))
        alpha = np.where(x[0] >= 0.0, -norm, norm)
        v = x.copy()
        v[0] -= alpha
        vv = np.einsum("ik,ik->k", v, v)
        with np.errstate(divide="ignore", invalid="ignore"):
            beta = np.where(vv > 0.0, 2.0 / vv, 0.0)
        sub = A[j:, j:]
        sub -= v[:, None, :] * (beta * np.einsum("ik,ijk->jk", v, sub))[None]
        vs.append(v)
        betas.append(beta)
    if complement:
        Q = np.zeros((M, M - w, K))
        Q[w:] = np.eye(M - w)[:, :, None]
    else:
        Q = np.zeros((M, w, K))
        Q[np.arange(w), np.arange(w)] = 1.0
    for j in reversed(range(w)):
        v, sub = vs[j], Q[j:]
        sub -= v[:, None, :] * (betas[j] * np.einsum("ik,ijk->jk", v, sub))[None]
    return A[:w], Q


def _inverse_frobenius(R: np.ndarray) -> np.ndarray:
    """``‖R⁻¹‖_F`` of upper-triangular (w, w, K) stacks (inf when singular)."""
    w = R.shape[0]
    X = np.zeros_like(R)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for j in range(w):
            X[j, j] = 1.0 / R[j, j]
            for i in reversed(range(j)):
                X[i, j] = -np.einsum(
                    "ik,ik->k", R[i, i + 1 : j + 1], X[i + 1 : j + 1, j]
                )
                X[i, j] /= R[i, i]
        out = np.sqrt(np.einsum("ijk,ijk->k", X, X))
    return np.where(np.isfinite(out), out, np.inf)


def row_spaces(G: np.ndarray, *, rank_tol: float):
    """Numerical ranks and orthonormal row-space bases of a stack of matrices.

    Parameters
    ----------
    G : (K, w, M) float
        Normalised grasp matrices (module docstring).
    rank_tol : float
        Singular values ``<= rank_tol * σ_max`` count as zero.

    Returns
    -------
    rank : (K,) int
    groups : list of (rows, Q)
        For each rank ``r`` present: grasp indices (k,) and bases ``Q``
        (M, r, k) whose orthonormal columns span ``G``'s row space (``r = 0``:
        an empty basis).  ``G f = 0`` ⇔ ``Qᵀ f = 0`` on the numerical row space.
    """
    K, w, M = G.shape
    rank = np.zeros(K, dtype=int)
    groups = []
    svd_rows = np.arange(K)
    if M >= w and K > 0:
        GT = np.ascontiguousarray(np.transpose(G, (2, 1, 0)))
        R, Q = _householder(GT)
        gnorm = np.sqrt(np.einsum("kij,kij->k", G, G))
        certain = _inverse_frobenius(R) * rank_tol * gnorm < 1.0
        rows = np.flatnonzero(certain)
        if rows.size:
            rank[rows] = w
            groups.append((rows, Q[:, :, rows] if rows.size < K else Q))
        svd_rows = np.flatnonzero(~certain)
    if svd_rows.size:
        _, sv, Vh = np.linalg.svd(G[svd_rows], full_matrices=False)
        r = np.sum(sv > rank_tol * sv[:, :1], axis=1)
        rank[svd_rows] = r
        for value in np.unique(r):
            sel = np.flatnonzero(r == value)
            Q = np.transpose(Vh[sel, : int(value), :], (2, 1, 0))
            groups.append((svd_rows[sel], np.ascontiguousarray(Q)))
    return rank, groups
