"""Normals of a point cloud, estimated from the flattest patch near each point.

A cloud from a depth camera comes without normals, or with normals tilted
where a point's neighbourhood straddles two faces or curves away.
:func:`estimate_normals` fits each point's neighbourhood with a plane and,
where the face curves beyond chance, with a quadric, and takes the flattest
patch that passes through the point: faces keep sharp normals up to their
edges.  The normals are unoriented; :func:`.read_cloud`
turns them outwards.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

__all__ = [
    "NORMAL_ANGLE_TARGET",
    "NORMAL_CURVED_F",
    "NORMAL_MAX_NEIGHBOURS",
    "NORMAL_NEIGHBOURS",
    "NORMAL_OWN_FACTOR",
    "estimate_normals",
]


NORMAL_NEIGHBOURS = 20
"""Points of each neighbourhood whose plane gives an estimated normal (more on
a noisy cloud: :data:`NORMAL_ANGLE_TARGET`)."""

NORMAL_ANGLE_TARGET = np.radians(0.1)
"""Standard error (radians) of an estimated normal that a noisy cloud's
neighbourhoods grow to reach, up to :data:`NORMAL_MAX_NEIGHBOURS` points.

The error of a plane fitted to ``k`` points with in-plane variances ``λ₁, λ₂``
and noise ``σ`` across it is ``σ √((1/λ₁ + 1/λ₂)/k)``, about ``1/k`` as the
patch grows with ``k``.  A parallel jaw closes along a point's normal, and a
pad a fraction of a degree off a face touches it along an edge: on the YCB
cracker box's cloud (3,000 points, depth noise σ = 0.25 mm) the normals of
20 points were 0.3° off and 4 of the ten best grasps fell even at five times
the box's weight, with closing axes 0.3-0.6° off the faces; with 60 points
(0.1°) the axes were within 0.14° and all ten held.  A noise-free cloud
(residuals of its quadric fits near zero) keeps :data:`NORMAL_NEIGHBOURS`."""

NORMAL_MAX_NEIGHBOURS = 100
"""Most points of a neighbourhood grown for noise (:data:`NORMAL_ANGLE_TARGET`):
a patch must still fit on one face to be flat (100 points of a 3,000-point
cloud of the YCB cracker box span about 70 mm; its narrowest face is 66 mm
wide)."""

NORMAL_OWN_FACTOR = 1.5
"""A point keeps its own neighbourhood's plane unless that plane's surface
variation is more than this times the flattest plane that passes through it."""

NORMAL_CURVED_F = 5.6
"""A neighbourhood is fitted with a quadric, and a point takes the quadric's
normal at itself, where the quadric explains the points better than the plane
beyond chance: the F statistic of the three added terms exceeds this (the 1 %
point of F(3, 14), 20 points less six coefficients).  A cloud of fewer than
:data:`NORMAL_NEIGHBOURS` points has fewer residual degrees of freedom, and
its test the 1 % point of F(3, k - 6) instead, when that is higher."""

_NORMAL_CHUNK = 50_000
"""Points whose neighbourhoods are fitted at once (memory: chunk × 20 × 3)."""


def estimate_normals(points: np.ndarray) -> np.ndarray:
    """Unit normals of a cloud's points, unoriented, from the flattest nearby patch.

    Each point's :data:`NORMAL_NEIGHBOURS` nearest points are fitted with a
    plane (principal components; the surface variation ``λ₀ / Σλ`` measures
    how badly).  Near an edge, a point's own neighbourhood straddles two
    faces and its plane is tilted between them (Drake's
    ``PointCloud.EstimateNormals`` tilted normals up to 66° at the soup can's
    rim, and planning on one-sided clouds with them held 0 of the ten best
    grasps of the can and of the cracker box at the predicted squeeze).  So a
    point takes, among the planes of its neighbours' neighbourhoods that pass
    within a quarter spacing of it (plus their own scatter), the flattest
    (of equally flat ones, the nearest), and keeps its own unless that is
    more than :data:`NORMAL_OWN_FACTOR` times as curved.  The neighbourhoods
    shift off the edge, so faces keep sharp normals: on a sampled box, 2-3 %
    of the points end more than 10° off (those within about a spacing of an
    edge, which may take the other face's normal) against Drake's 28 %.

    On a curved face the patch taken is off-centre (always so at a one-sided
    cloud's silhouette), and its plane's normal is that of the patch's
    centre, not the point's: 4-5° off on average on the soup can, up to 14°
    at the silhouette of its side view.  So the patch is also fitted with a
    quadric ``w = a u² + b uv + c v² + d u + e v + f`` in its principal
    frame, and where the quadric is the better model beyond chance (F test of
    its three added terms, :data:`NORMAL_CURVED_F`) the point takes the
    quadric's normal at itself: 0.02° on average on the can's side view
    (0.3° at most), while a box's flat faces keep their planes.

    On a noisy cloud the patches grow (to at most
    :data:`NORMAL_MAX_NEIGHBOURS` points) until the normals' expected error,
    from the quadrics' residuals, falls to :data:`NORMAL_ANGLE_TARGET`.

    Parameters
    ----------
    points : (M, 3) float
        Finite points, metres.

    Returns
    -------
    normals : (M, 3) float
        Unit normals (either sign); NaN where a neighbourhood spans no plane
        (fewer than 3 distinct points, or all on a line).  A point given
        twice counts once, and both copies get its normal; so do points
        closer than single precision resolves at the cloud's extent.
    """
    return _estimate_normals(points)[0]


def _estimate_normals(points: np.ndarray) -> tuple[np.ndarray, dict]:
    """:func:`estimate_normals`, and the fit :func:`.read_cloud_fit` reports."""
    same = _same_point(points)
    if same is not None:  # repeated points (fused frames) count once
        first, inverse = np.unique(same, return_index=True, return_inverse=True)[1:]
        normals, fit = _estimate_normals(points[first])
        return normals[inverse.reshape(-1)], fit
    M = len(points)
    k = min(NORMAL_NEIGHBOURS, M)
    normals, error, noise = _patch_normals(points, k)
    # error ~ 1/k: the patch's in-plane variances grow with its size
    wanted = np.nan_to_num(k * error / NORMAL_ANGLE_TARGET, nan=0.0, posinf=M)
    grown = min(M, NORMAL_MAX_NEIGHBOURS, int(np.ceil(wanted)))
    if grown > k:
        k = grown
        normals, error, noise = _patch_normals(points, k)
    fit = {"neighbours": k, "noise": noise, "error_deg": float(np.degrees(error))}
    return normals, fit


def _patch_normals(points: np.ndarray, k: int) -> tuple[np.ndarray, float, float]:
    """:func:`estimate_normals` with ``k`` points a patch, and its typical error.

    Returns
    -------
    normals : (M, 3) float
        As :func:`estimate_normals` returns them.
    error : float
        Median over the points of the standard error (radians) of their
        chosen plane's normal, with the noise taken as the median residual
        of the patches' quadric fits (0 when ``k <= 6``).
    noise : float
        That residual, metres (RMS about the quadric; 0 when ``k <= 6``).
    """
    M = len(points)
    tree = cKDTree(points)
    dist, idx = tree.query(points, k=k)
    dist, idx = dist.reshape(M, k), idx.reshape(M, k)
    centre = np.empty((M, 3))
    frame = np.empty((M, 3, 3))  # columns: the plane's normal, then its axes
    eig = np.empty((M, 3))
    chunk = max(1, _NORMAL_CHUNK * NORMAL_NEIGHBOURS // k)
    for start in range(0, M, chunk):
        rows = slice(start, start + chunk)
        Q = points[idx[rows]]
        centre[rows] = Q.mean(axis=1)
        X = Q - centre[rows][:, None, :]
        w, frame[rows] = np.linalg.eigh(np.einsum("lki,lkj->lij", X, X) / k)
        eig[rows] = np.maximum(w, 0.0)
    plane = frame[:, :, 0]
    total = eig.sum(axis=1)
    flat = eig[:, 1] > 1e-12 * eig[:, 2]  # spans a plane, not a line or a point
    variation = np.where(flat, eig[:, 0] / np.where(total > 0, total, 1.0), np.inf)
    spacing = float(np.median(dist[:, 1])) if k > 1 else 0.0
    best = np.empty(M, dtype=int)
    for start in range(0, M, chunk):
        rows = slice(start, start + chunk)
        near_idx = idx[rows]
        off = np.abs(
            np.einsum(
                "lki,lki->lk",
                points[rows, None, :] - centre[near_idx],
                plane[near_idx],
            )
        )
        # within a quarter spacing, plus three times the plane's own scatter
        near = off <= 0.25 * spacing + 3.0 * np.sqrt(eig[near_idx, 0])
        # flattest first; among equally flat planes (two faces at an edge)
        # the one the point lies on
        closeness = (off / spacing) ** 2 if spacing > 0 else np.zeros_like(off)
        score = np.where(near, variation[near_idx] + 1e-3 * closeness, np.inf)
        j = np.argmin(score, axis=1)
        best[rows] = near_idx[np.arange(len(j)), j]
    own = variation <= NORMAL_OWN_FACTOR * variation[best] + 1e-4
    chosen = np.where(own, np.arange(M), best)
    normals = plane[chosen]
    noise = np.full(M, np.nan)  # residual variance of each chosen quadric, m²
    if k > 6:
        for start in range(0, M, chunk):
            rows = slice(start, start + chunk)
            c = chosen[rows]
            normals[rows], noise[rows] = _quadric_normals(
                points[rows], points[idx[c]], centre[c], frame[c], eig[c, 0], spacing
            )
    bad = ~np.isfinite(variation[chosen])
    normals[bad] = np.nan
    error = spread = 0.0
    fitted = ~bad & np.isfinite(noise)
    if fitted.any():
        lam = eig[chosen[fitted]][:, 1:]  # in-plane variances (> 0: flat), m²
        spread = float(np.median(noise[fitted]))
        ratio = spread / lam  # dimensionless: no overflow
        error = float(np.median(np.sqrt(np.sum(ratio, axis=1) / k)))
    return normals, error, float(np.sqrt(spread))


def _same_point(points: np.ndarray):
    """Which points are one point given more than once, or None if none are.

    Points closer than a single-precision float resolves at the cloud's
    extent (or than a few units of round-off of its coordinates) are one
    point: fused frames repeat points with such jitter, and twenty copies of
    a point 1e-12 m apart once filled its neighbourhood with the jitter, whose
    "plane" is any direction (normals 55-60 deg off on a flat grid).

    Returns
    -------
    labels : (M,) int or None
        Equal for points that are one; None when every point is apart.
    """
    extent = float(np.max(np.ptp(points, axis=0)))
    size = float(np.max(np.abs(points)))
    tol = max(np.finfo(np.float32).eps * extent, 8 * np.finfo(float).eps * size)
    if tol == 0.0:  # one point, or none
        return np.zeros(len(points), int) if len(points) > 1 else None
    # cells of side tol first (a cluster of 10^5 copies is one cell, not 10^10
    # pairs), then cells whose points are within tol across a cell boundary
    cell = np.floor((points - points.min(axis=0)) / tol)
    _, first, label = np.unique(cell, axis=0, return_index=True, return_inverse=True)
    label = label.reshape(-1)
    pairs = cKDTree(points[first]).query_pairs(tol, output_type="ndarray")
    if len(pairs):
        n = len(first)
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), (n, n))
        label = connected_components(graph, directed=False)[1][label]
    return label if len(np.unique(label)) < len(points) else None


def _curved_threshold(k: int) -> float:
    """The F statistic a patch of ``k`` points must exceed to take its quadric.

    :data:`NORMAL_CURVED_F` is the 1 % point for 20 points; a smaller patch
    (a cloud of 7-19 points) leaves the quadric fewer residual degrees of
    freedom, ``k - 6``, and chance alone gives far larger F: the 1 % point of
    F(3, 1) is 5403.  With 5.6 there, seven points on a noisy plane took a
    quadric fitted to the noise, normals up to 18° off.
    """
    if k >= NORMAL_NEIGHBOURS:  # the constant's own case (scipy.stats is slow to load)
        return NORMAL_CURVED_F
    from scipy.stats import f as f_distribution

    return max(NORMAL_CURVED_F, float(f_distribution.ppf(0.99, 3, k - 6)))


def _quadric_normals(p, Q, centre, frame, plane_var, spacing):
    """Normals at ``p`` of quadrics fitted to patches, or the patches' planes.

    Parameters
    ----------
    p : (L, 3) float
        The points, metres.
    Q : (L, k, 3) float
        Each point's patch, metres.
    centre : (L, 3) float
        The patches' centroids.
    frame : (L, 3, 3) float
        Their principal axes as columns, the plane's normal first.
    plane_var : (L,) float
        Mean squared distance of a patch's points to its plane, m².
    spacing : float
        The cloud's median point spacing, metres (sets a floor on the residual
        an exactly sampled surface leaves).

    Returns
    -------
    normals : (L, 3) float
        Unit normals: the quadric's at ``p`` where the F statistic exceeds
        :func:`_curved_threshold` of the patch size (:data:`NORMAL_CURVED_F`
        for 20 points), the plane's elsewhere and where the patch's points
        leave the quadric undetermined (all on one conic of the plane).
    noise : (L,) float
        Residual variance of each quadric fit, ``RSS / (k − 6)``, m² (NaN
        where it is undetermined): the cloud's noise across its surface.
    """
    L, k, _ = Q.shape
    local = np.einsum("lki,lij->lkj", Q - centre[:, None, :], frame)
    w, u, v = local[..., 0], local[..., 1], local[..., 2]
    scale = np.sqrt(np.mean(u * u + v * v, axis=1))  # patch radius: conditioning
    scale = np.where(scale > 0, scale, 1.0)[:, None]
    u, v = u / scale, v / scale
    A = np.stack([u * u, u * v, v * v, u, v, np.ones_like(u)], axis=-1)
    AtA = np.einsum("lki,lkj->lij", A, A)
    spread = np.linalg.eigvalsh(AtA)
    # patches whose points lie on a conic (two scan lines, a ring) leave the
    # quadric undetermined: those keep their planes
    posed = spread[:, 0] > 1e-8 * spread[:, -1]
    AtA[~posed] += np.eye(6)
    coef = np.linalg.solve(AtA, np.einsum("lki,lk->li", A, w)[..., None])[..., 0]
    quadric_rss = np.sum((np.einsum("lki,li->lk", A, coef) - w) ** 2, axis=1)
    plane_rss = k * plane_var
    floor = (1e-6 * spacing) ** 2  # round-off on an exact plane
    F = ((plane_rss - quadric_rss) / 3.0) / np.maximum(quadric_rss / (k - 6), floor)
    at = np.einsum("li,lij->lj", p - centre, frame)
    u0, v0 = at[:, 1] / scale[:, 0], at[:, 2] / scale[:, 0]
    a, b, c, d, e = coef[:, :5].T
    du = (2 * a * u0 + b * v0 + d) / scale[:, 0]
    dv = (b * u0 + 2 * c * v0 + e) / scale[:, 0]
    local_n = np.stack([np.ones(L), -du, -dv], axis=1)
    local_n /= np.linalg.norm(local_n, axis=1, keepdims=True)
    curved = np.einsum("lij,lj->li", frame, local_n)
    better = posed & (F > _curved_threshold(k))
    noise = np.where(posed, quadric_rss / (k - 6), np.nan)
    return np.where(better[:, None], curved, frame[:, :, 0]), noise
