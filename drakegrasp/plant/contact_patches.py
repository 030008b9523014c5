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
a single witness point.

A flat face along the side of a cylinder or a capsule (the face parallel to
the axis within :data:`PATCH_ANGLE_TOL`) touches along a line, which Drake
also reports as one point: :func:`line_vertices` clips that line to the face
polygon and to the part within the distance tolerance and returns **its two
ends**.  Their friction cones span every load the line can carry, as a
polygon patch's corners span its area's, so a flat pad on a cylinder resists
turning about the normal, which one point cannot.  numpy only.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.plant._shapes import plane_basis

__all__ = ["PATCH_ANGLE_TOL", "clip_convex", "line_vertices", "patch_vertices"]

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


def line_vertices(
    *,
    face_normal_O: np.ndarray,
    poly_face_O: np.ndarray,
    axis_O: np.ndarray,
    centre_O: np.ndarray,
    radius: float,
    half_length: float,
    tol: float,
) -> list[tuple[np.ndarray, float]]:
    """The ends of the line along which a flat face touches a cylinder's side.

    Parameters
    ----------
    face_normal_O : (3,) float
        The flat face's outward unit normal, towards the round body, frame O.
    poly_face_O : (k, 3) float
        The flat face's polygon, metres, frame O.
    axis_O : (3,) float
        The round body's unit axis, frame O.
    centre_O : (3,) float
        The centre of its straight part, metres, frame O.
    radius, half_length : float
        Its radius and half the length of its straight part, metres.
    tol : float
        Largest gap (metres) kept on the line.

    Returns
    -------
    list of ((3,) float, float)
        Two points of the round body's side, frame O, the ends of the part of
        the line that lies over the face and within ``tol`` of its plane, each
        with its gap ``ψ``: the distance along ``face_normal_O`` from the
        face's plane.  Empty when the face is not parallel to the axis (within
        :data:`PATCH_ANGLE_TOL`), looks away from the round body (a pad's
        back face), or the part is shorter than a micrometre.
    """
    w = np.asarray(face_normal_O, float)
    a = np.asarray(axis_O, float)
    if abs(float(w @ a)) > np.sin(PATCH_ANGLE_TOL):
        return []
    q = poly_face_O[0]
    if float(w @ (centre_O - q)) <= 0.0:  # the face looks away: a pad's back
        return []
    across = -w - float(-w @ a) * a  # the round body's side facing the face
    norm = float(np.linalg.norm(across))
    if norm < 1e-12:
        return []
    start = centre_O + radius * across / norm  # the line: start + t a
    # gap(t) = w · (start + t a - q): affine in t
    g0, g1 = float(w @ (start - q)), float(w @ a)
    lo, hi = -half_length, half_length
    lo, hi = _clip_interval(lo, hi, g1, tol - g0)
    u, v = plane_basis(w)

    def to2(P):
        d = np.asarray(P) - q
        return np.array([d @ u, d @ v])

    poly = _ccw(np.array([to2(P) for P in poly_face_O]))
    s0, s1 = to2(start), np.array([a @ u, a @ v])  # the line in 2-D: s0 + t s1
    # a line along an edge of the face is on it: offsets below this are round-off
    slack = 1e-12 * max(1.0, float(np.max(np.abs(poly))), radius, half_length)
    for i in range(len(poly)):
        p0, p1 = poly[i], poly[(i + 1) % len(poly)]
        edge = p1 - p0
        length = float(np.linalg.norm(edge))
        if length == 0.0:  # a repeated vertex
            continue
        outward = np.array([edge[1], -edge[0]]) / length
        b = float(outward @ (p0 - s0)) + slack
        lo, hi = _clip_interval(lo, hi, float(outward @ s1), b)
    if not hi - lo > 1e-6:
        return []
    return [(start + t * a, g0 + g1 * t) for t in (lo, hi)]


def _clip_interval(lo: float, hi: float, k: float, b: float) -> tuple[float, float]:
    """``[lo, hi]`` cut to the ``t`` with ``k t <= b`` (empty: ``lo > hi``).

    ``k`` is a cosine or a unit slope: below 1e-12 the line runs along the
    boundary, kept when ``b >= 0``.
    """
    if abs(k) < 1e-12:
        return (lo, hi) if b >= 0 else (1.0, 0.0)
    if k > 0:
        return lo, min(hi, b / k)
    return max(lo, b / k), hi
