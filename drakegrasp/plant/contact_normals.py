"""The normal of a contact: which surface's normal to trust, and exact fingertips.

Drake guarantees the witness normal at ``ψ = 0`` only for a few shape pairs, so
the normal is derived from the shapes themselves (:func:`choose_normal`): the
object's outward face normal at ``Ca`` (negated) when the object is smooth or on
a face there; else the finger's outward normal at ``Cb`` when the finger is
smooth there (a rounded fingertip on a box edge); else the direction
``Ca − Cb`` when ``ψ`` is clearly non-zero; else Drake's ``nhat_BA_W``.
``PlantContact.normal_source`` says which.

**Spherical fingertips** (:func:`refine_sphere_tip`).  Drake computes some
pairs in closed form (sphere–sphere, sphere–box, sphere–cylinder...) and the
others with GJK/EPA, whose witness points are accurate to about 1e-5 m (convex
meshes, ellipsoids).  For a spherical fingertip drakegrasp recomputes the
finger's contact point as ``centre + r n̂`` and, on a flat face, ``ψ`` exactly
as the centre's distance to the face plane minus ``r``; on an edge or a corner
of flat faces (boxes, convex meshes) the normal runs from the centre to the
closest point of that edge or corner.  Other pairs keep Drake's values.
numpy only.
"""

from __future__ import annotations

import numpy as np

__all__ = ["NORMAL_AGREEMENT", "choose_normal", "clean_unit", "refine_sphere_tip"]

NORMAL_AGREEMENT = np.cos(np.radians(5.0))
"""Object and finger normals within 5 degrees of each other agree."""

_WITNESS_DIRECTION_MIN_DISTANCE = 1e-3
"""|ψ| (m) above which the line between witness points gives the normal.

GJK witnesses are accurate to ~1e-5 m, so nearer than this their direction is
mostly noise; Drake's own normal is then used (exact for the shape pairs that
Drake computes analytically)."""


def clean_unit(n: np.ndarray) -> np.ndarray:
    """Unit vector with round-off components (< 1e-12) set to exactly zero.

    The core picks each contact frame's ``t1`` from the smallest component of
    ``n``; zeroing round-off keeps that choice, hence ``G``, the same wherever
    the object sits in the world.
    """
    n = np.array(n, dtype=float)
    n[np.abs(n) < 1e-12] = 0.0
    return n / np.linalg.norm(n)


def choose_normal(*, obj, obj_flat, fin, fin_flat, witness, psi, drake):
    """Pick the inward normal (frame O) from the candidates of both surfaces.

    ``obj`` and ``fin`` hold the candidate inward normals from the object's and
    the finger's surface pieces at the witness points (several at an edge or a
    corner).  A unique normal of one surface is used when the other agrees
    with it or has no unique normal; when both are unique but disagree, one
    witness point sits numerically next to an edge it should be on (Drake's GJK
    witnesses are accurate to ~1e-5 m), and the curved surface wins over the
    flat face, whose normal jumps there.

    Returns
    -------
    n_O : (3,) float
        The inward normal (not yet cleaned, see :func:`clean_unit`).
    source : str
        ``"object"``, ``"finger"``, ``"witness points"`` or ``"drake"``.
    """
    if len(obj) == 1 and len(fin) == 1:
        if obj[0] @ fin[0] >= NORMAL_AGREEMENT:
            return obj[0], "object"
        if obj_flat and not fin_flat:
            return fin[0], "finger"
        if fin_flat and not obj_flat:
            return obj[0], "object"
    elif len(obj) == 1:
        return obj[0], "object"
    elif len(fin) == 1:
        return fin[0], "finger"
    if abs(psi) > _WITNESS_DIRECTION_MIN_DISTANCE:
        return witness / np.linalg.norm(witness) * np.sign(psi), "witness points"
    return drake, "drake"


def refine_sphere_tip(
    *,
    radius: float,
    centre_O: np.ndarray,
    object_faces_G: list[np.ndarray] | None,
    G_to_O,
    n_O: np.ndarray,
    source: str,
    psi: float,
):
    """Exact contact of a spherical fingertip on a flat face, edge or corner.

    Parameters
    ----------
    radius : float
        The tip's radius, metres.
    centre_O : (3,) float
        The tip's centre, in frame O.
    object_faces_G : list of (k, 3) float, or None
        The object's flat face polygons through its witness point, in the
        object geometry's frame G (one on a face, two on an edge, three at a
        corner); None when a piece there is curved.
    G_to_O : callable
        Maps a point from G to O.
    n_O, source, psi
        The normal chosen so far (:func:`choose_normal`), its source and ψ.

    Returns
    -------
    n_O : (3,) float
    source : str
        ``"edge"`` or ``"corner"`` when the tip sits on one, else unchanged.
    psi : float
    p_OCa, p_OCb : (3,) float
        The object's and the finger's contact points, frame O.
    """
    r = radius
    faces = object_faces_G or []
    feature = _shared_feature(faces) if object_faces_G is not None else None
    if len(faces) == 1 and source == "object":
        psi = float(-n_O @ (centre_O - G_to_O(faces[0][0]))) - r
    elif feature is not None and len(faces) > 1:
        closest_O = _closest_on_segment(centre_O, *(G_to_O(v) for v in feature))
        d = closest_O - centre_O
        if np.linalg.norm(d) > r / 2:  # the centre is outside the object
            n_O, source = clean_unit(d), "edge" if len(feature) == 2 else "corner"
            psi = float(np.linalg.norm(d)) - r
    p_OCb = centre_O + r * n_O
    p_OCa = p_OCb + psi * n_O
    return n_O, source, psi, p_OCa, p_OCb


def _shared_feature(polygons: list[np.ndarray]) -> tuple[np.ndarray, ...] | None:
    """The edge (two vertices) or corner (one) that several faces share."""
    if len(polygons) < 2:
        return None
    shared = [
        v
        for v in polygons[0]
        if all(np.min(np.linalg.norm(P - v, axis=1)) < 1e-9 for P in polygons[1:])
    ]
    return tuple(shared) if len(shared) in (1, 2) else None


def _closest_on_segment(x: np.ndarray, a: np.ndarray, b: np.ndarray | None = None):
    """Closest point to ``x`` on the segment ``ab`` (or the point ``a``)."""
    if b is None:
        return np.asarray(a)
    ab = b - a
    s = float(np.clip((x - a) @ ab / (ab @ ab), 0.0, 1.0))
    return a + s * ab
