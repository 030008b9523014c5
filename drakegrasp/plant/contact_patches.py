"""Flat pads as the corners of their contact patch.

A flat pad on a flat face touches along an area, for which Drake reports a
single witness point somewhere in the patch.  When both surfaces are flat faces
of boxes or convex meshes with opposite normals (within :data:`PATCH_ANGLE_TOL`),
:func:`patch_vertices` intersects the two face polygons in the contact plane,
keeps the part where the gap between the faces is within the distance
tolerance, and returns **each vertex** of that patch polygon with its gap ``ψ``.
:func:`drakegrasp.plant.contacts.find_contacts` reports one contact per vertex
(same normal), so the pad's resistance to torsion and tilt appears in the
analysis.  Patches on a cylinder's flat cap (a disc) are not polygons and stay
a single witness point.  numpy only.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.plant._shapes import plane_basis

__all__ = ["PATCH_ANGLE_TOL", "clip_convex", "patch_vertices"]

PATCH_ANGLE_TOL = np.radians(2.0)
"""Two flat faces whose normals are opposite within this angle (rad) form a patch."""


def _clip(poly: np.ndarray, a: np.ndarray, b: float) -> np.ndarray:
    """Clip a 2-D polygon (k, 2) to the half-plane ``a·x <= b``."""
    if len(poly) == 0:
        return poly
    out = []
    for i in range(len(poly)):
        p, q = poly[i], poly[(i + 1) % len(poly)]
        fp, fq = a @ p - b, a @ q - b
        if fp <= 0:
            out.append(p)
        if fp < 0 < fq or fq < 0 < fp:  # fp * fq < 0, which can overflow
            t = fp / (fp - fq)
            out.append(p + t * (q - p))
    return np.array(out).reshape(-1, 2)


def _ccw(poly: np.ndarray) -> np.ndarray:
    area = 0.5 * np.sum(
        poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1]
    )
    return poly if area >= 0 else poly[::-1]


def clip_convex(subject: np.ndarray, clipper: np.ndarray) -> np.ndarray:
    """Intersection of two convex 2-D polygons (Sutherland–Hodgman).

    Parameters
    ----------
    subject, clipper : (k, 2) float
        Convex polygons, either orientation.

    Returns
    -------
    (m, 2) float
        The intersection, counter-clockwise; empty when they do not overlap.
    """
    clipper = _ccw(clipper)
    out = _ccw(subject)
    for i in range(len(clipper)):
        p, q = clipper[i], clipper[(i + 1) % len(clipper)]
        edge = q - p
        outward = np.array([edge[1], -edge[0]])  # right of a CCW edge is outside
        out = _clip(out, outward, outward @ p)
    return out


def _dedupe(points: np.ndarray, tol: float) -> np.ndarray:
    keep: list[np.ndarray] = []
    for p in points:
        if all(np.linalg.norm(p - k) > tol for k in keep):
            keep.append(p)
    return np.array(keep).reshape(-1, points.shape[1])


def patch_vertices(
    *,
    n_O: np.ndarray,
    poly_obj_O: np.ndarray,
    poly_fin_O: np.ndarray,
    plane_point_obj_O: np.ndarray,
    finger_normal_O: np.ndarray,
    plane_point_fin_O: np.ndarray,
    tol: float,
) -> list[tuple[np.ndarray, float]]:
    """Vertices (on the object face, frame O) of a flat patch and their gaps ψ.

    Parameters
    ----------
    n_O : (3,) float
        The inward contact normal (minus the object face's outward normal).
    poly_obj_O, poly_fin_O : (k, 3) float
        The object's and the finger's face polygons, metres, in frame O.
    plane_point_obj_O, plane_point_fin_O : (3,) float
        A point of each face's plane, in O.
    finger_normal_O : (3,) float
        The finger face's outward normal, in O.
    tol : float
        Largest gap (metres) kept in the patch.

    Returns
    -------
    list of ((3,) float, float)
        Each vertex of the patch on the object's face (frame O) and the gap
        ``ψ`` there: the distance along ``-n_O`` to the finger face's plane.
    """
    u, w = plane_basis(n_O)
    origin = plane_point_obj_O

    def to2(P):
        d = P - origin
        return np.column_stack([d @ u, d @ w])

    inter = clip_convex(to2(poly_fin_O), to2(poly_obj_O))
    # The finger point above x is x - gap n, on the finger's plane
    # m · (y - p_fin) = 0 (m: the finger face's outward normal, m ≈ n), so
    # gap(x) = m · (x - p_fin) / (m · n), affine in the 2-D coordinates.
    denom = float(n_O @ finger_normal_O)
    g0 = float((origin - plane_point_fin_O) @ finger_normal_O) / denom
    g = np.array([u @ finger_normal_O, w @ finger_normal_O]) / denom
    inter = _clip(inter, g, tol - g0)
    inter = _dedupe(inter, 1e-9)
    return [(origin + x[0] * u + x[1] * w, g0 + float(g @ x)) for x in inter]
