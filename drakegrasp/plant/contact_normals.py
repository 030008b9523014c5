"""The normal of a contact: its name, and the choice when no exact one exists.

:func:`drakegrasp.plant.contacts.find_contacts` computes every pair's witness
points and normal exactly where it can (:mod:`drakegrasp.plant.exact_contact`: closed
forms for spheres and capsules, the face's normal for a flat face, edges and
cylinder sides as segments, Newton's method for two smooth pieces), and
:func:`normal_source` names the surface the normal belongs to.  When no exact
route certifies, :func:`choose_normal` derives the normal from the shapes at
Drake's witness points: the object's outward face normal at ``Ca`` (negated)
when the object is smooth or on a face there; else the finger's outward normal
at ``Cb`` when the finger is smooth there; else the direction ``Ca − Cb`` when
``ψ`` is clearly non-zero; else Drake's ``nhat_BA_W``.
``PlantContact.normal_source`` says which.  numpy only.
"""

from __future__ import annotations

import numpy as np

__all__ = ["NORMAL_AGREEMENT", "choose_normal", "clean_unit", "normal_source"]

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


def normal_source(*, obj: list, fin: list) -> str:
    """Name the surface that the exact normal belongs to (``normal_source``).

    Parameters
    ----------
    obj, fin : list of SurfacePiece
        The pieces of the object's and the finger's surface through their
        exact witness points (one on a smooth point or a face, two on an edge,
        three or more at a corner).

    Returns
    -------
    str
        ``"object"`` when the object's surface has one normal there;
        ``"finger"`` when the object touches with an edge or corner and the
        finger with one flat face; else ``"edge"`` or ``"corner"`` (a curved
        finger on an edge or a corner of the object, the normal running from
        the feature to the finger).
    """
    if len(obj) == 1:
        return "object"
    if len(fin) == 1 and fin[0].polygon_G is not None:
        return "finger"
    return "edge" if len(obj) == 2 else "corner"
