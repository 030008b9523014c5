"""Where a spherical fingertip first touches a point cloud.

A fingertip is often smaller than a cloud's spacing: moved along its closing
direction it would pass between the points.  So :func:`sphere_entry` fits
the points of the face around the tip's line with a quadric and finds where
the sphere first meets it.  The fit's constants (:data:`FIT_RADIUS_LINES`,
:data:`FIT_MIN_POINTS`, :data:`FIT_FACE_COS`) are also those of the quadric
at every point that the jaws re-close on
(:class:`.FittedCloud`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["FIT_FACE_COS", "FIT_MIN_POINTS", "FIT_RADIUS_LINES", "sphere_entry"]


FIT_MIN_POINTS = 8
"""Fewest points of one face near a fingertip's line for a quadric fit."""

FIT_RADIUS_LINES = 2.0
"""Quadrics fit the points within this many line radii: of a fingertip's line
(plus its radius, :func:`sphere_entry`) or of a point (:class:`.FittedCloud`);
about 20 points of a random sample."""

FIT_FACE_COS = np.cos(np.radians(45.0))
"""Points whose normals lie within this angle of the first-met point's are
fitted as its face; the others (an edge's other face) are met point by point."""

_DISC = np.array(
    [
        (rho * np.cos(a), rho * np.sin(a), np.sqrt(max(1.0 - rho * rho, 0.0)))
        for rho in (0.0, 0.25, 0.5, 0.7, 0.85, 0.95, 1.0)
        for a in np.linspace(0.0, 2 * np.pi, 1 if rho == 0 else 24, endpoint=False)
    ]
)
"""Unit-disc points ``(x, y, sqrt(1 − x² − y²))`` on which a sphere's first
touch of a fitted surface is sought."""


def sphere_entry(
    r: float,
    q_G: np.ndarray,
    u_G: np.ndarray,
    n_G: np.ndarray,
    line_radius: float,
    min_points: int = FIT_MIN_POINTS,
) -> np.ndarray:
    """Travel at which a sphere first meets the surface that points sample.

    Parameters
    ----------
    r : float
        The sphere's radius, metres; its centre is G's origin.
    q_G : (M, 3) float
        Cloud points, frame G, metres; they move along ``u_G`` (unit).
    n_G : (M, 3) float
        Their outward unit normals, frame G.
    line_radius : float
        Points within ``r + line_radius`` of the centre's line count.
    min_points : int, optional
        Fewest points of the face for the fit: :data:`FIT_MIN_POINTS`, times
        the points a spot holds in scans merged as they were
        (``CloudSurface.seen``), whose twins would let two spots pass for
        eight points.

    Returns
    -------
    (M,) float
        Per point, the travel at which the sphere meets the surface there, NaN
        for a point that does not stand for the first touch.  A sphere (often
        smaller than the spacing) falls between sampled points: each point
        alone would let it sink up to ``r`` where the points are sparse.  The
        points of the face it meets first (their normals within 45° of the
        first-met point's, within ``ρ = r +`` :data:`FIT_RADIUS_LINES` line
        radii of the line and ``ρ`` of the first along it) are fitted by a
        quadric ``s(x, y)`` (travel over the plane across the line); the
        sphere meets it at the smallest ``s(x, y) − sqrt(r² − x² − y²)`` over
        its disc, reported at the fitted point nearest the line.
        The first face is that of the first point met among those not
        already behind the centre by more than ``r``.  Points of another face
        (an edge's, the far side's, one passed) keep their own travel
        ``s − sqrt(max(r² − δ², 0))`` (``δ`` their distance from the line), as
        do faces with fewer than ``min_points`` points.
    """
    s = -(q_G @ u_G)  # travel to the centre's closest approach
    lateral = q_G + s[:, None] * u_G
    delta = np.linalg.norm(lateral, axis=1)
    reach = delta <= r + line_radius
    t = np.where(reach, s - np.sqrt(np.maximum(r * r - delta * delta, 0.0)), np.nan)
    ahead = np.where(s >= -r, t, np.nan)  # not a point the sphere has passed
    if not np.any(np.isfinite(ahead)):
        return t
    first = int(np.nanargmin(ahead))
    fit = r + FIT_RADIUS_LINES * line_radius
    face = (
        (delta <= fit)
        & (n_G @ n_G[first] >= FIT_FACE_COS)
        & (np.abs(s - s[first]) <= fit)  # the same sheet: slopes up to 45°
    )
    if np.count_nonzero(face) < min_points:
        return t
    e1, e2 = _basis_across(u_G[None, :])
    x, y = lateral[face] @ e1[0], lateral[face] @ e2[0]
    xs, ys = x / fit, y / fit  # in units of the neighbourhood: conditioning
    A = np.column_stack([np.ones_like(xs), xs, ys, xs * xs, xs * ys, ys * ys])
    coef, _, rank, _ = np.linalg.lstsq(A, s[face], rcond=None)
    if rank < 6:
        return t
    dx, dy = _DISC[:, 0] * r / fit, _DISC[:, 1] * r / fit
    surface = (
        coef[0] + coef[1] * dx + coef[2] * dy
        + coef[3] * dx * dx + coef[4] * dx * dy + coef[5] * dy * dy
    )  # fmt: skip
    meet = float(np.min(surface - _DISC[:, 2] * r))
    out = np.where(face, np.nan, t)
    nearest = np.flatnonzero(face)[int(np.argmin(delta[face]))]
    out[nearest] = meet
    return out


def _basis_across(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(L, 3) unit ``e1, e2`` with ``(e1, e2, d)`` right-handed, for unit ``d``."""
    helper = np.eye(3)[np.argmin(np.abs(d), axis=1)]
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return e1, np.cross(d, e1)
