r"""Exact closest points and normal of two convex Drake shapes near contact.

Drake computes sphere pairs in closed form but solves the other pairs with
GJK/EPA, whose witness points on curved shapes can be 0.1–0.4 mm off; a normal
taken from a curved surface at such a point is off by up to a degree.
:func:`closest_pair` starts from Drake's answer and computes the pair exactly
by one of these routes (``ExactPair.method``):

``"core"``
    A sphere is a point and a capsule a segment inflated by a radius ``r``, so
    ``ψ = min_s sd_X(a + s(b − a)) − r`` over the core segment ``ab`` of one
    shape and the exact signed distance ``sd_X`` of the other
    (:meth:`~drakegrasp.plant.shape_queries.PosedShape.project`).  ``sd_X`` is
    convex along a line, so bisection on the sign of its derivative
    ``n_X·(b − a)`` finds the minimum to the last bit.
``"face"``
    A flat face (box, convex hull, cylinder cap, half space) touching the other
    shape inside the face: the normal is the face's, ``ψ`` the other shape's
    support value along it.
``"cylinder side"``, ``"edge"``
    A cylinder touching with its side is, there, its axis inflated by its
    radius; an edge of a box or convex hull (a vertex being an edge's end) is a
    segment inflated by zero: each then goes the ``"core"`` route.
``"newton"``
    Two smooth curved pieces (ellipsoids, spheres, a cylinder's rim): Newton's
    method on the unit normal ``u`` for the maximum of
    ``f(u) = −h_A(−u) − h_B(u)`` (``h`` the support functions), whose value is
    the signed distance; it converges quadratically from Drake's normal.

Every candidate is **certified** before it is used: both witness points lie on
their surfaces, each is a support point of its shape along the normal (so the
normal separates, or for ``ψ < 0`` locally minimises the overlap), and
``p_Ca − p_Cb = ψ n̂``, all to :data:`CERTIFY_TOL`.  Of the certified
candidates the one with the largest ``ψ`` is the signed distance
(``ψ = max_u f(u)``).  When none certifies :func:`closest_pair` returns None
and the caller keeps Drake's witness points.

For a penetrating pair (``ψ < 0``) the certificate is local: the result is
the maximum of ``f`` nearest Drake's normal, and for a capsule the overlap of
its deepest core point, both the penetration depth for the shallow overlaps a
grasp meets.  numpy only, plus the shape classes of ``pydrake.geometry``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import Box, Convex, Cylinder, HalfSpace, Mesh

from drakegrasp.plant._shapes import EXACT_SURFACE_TOL, face_arrays, surface_pieces
from drakegrasp.plant.shape_queries import PosedShape, closest_on_polygon

__all__ = ["CERTIFY_TOL", "ExactPair", "closest_pair"]

CERTIFY_TOL = 1e-10
"""Metres: residual allowed in a certificate (round-off of 0.1 m geometry)."""

_FEATURE_REACH = 2e-3
"""Metres: edges and vertices this near Drake's witness are tried as cores."""

_TOUCHING = EXACT_SURFACE_TOL
"""Metres: a core this near the other shape touches it (its normal is then
taken from the surface, not from round-off)."""

_DRAKE_AGREEMENT = 1e-3
"""Metres: a candidate's ψ must be this near Drake's (GJK/EPA are accurate to
well within it); it rules out the far stationary points of ``f``."""

_FACE_ANGLE = np.radians(10.0)
"""Faces within this angle of Drake's normal are tried as the contact face."""


@dataclass(frozen=True)
class ExactPair:
    """The exact witness points and normal of a pair, in the common frame O.

    Attributes
    ----------
    psi : float
        Signed distance, metres.
    p_OCa, p_OCb : (3,) float
        Witness points on A (the object) and on B (the finger), frame O.
    nhat_O : (3,) float
        Unit normal from B into A; ``p_OCa − p_OCb = psi nhat_O``.
    method : str
        The route that found it (see the module docstring).
    """

    psi: float
    p_OCa: np.ndarray
    p_OCb: np.ndarray
    nhat_O: np.ndarray
    method: str


def closest_pair(
    A: PosedShape,
    B: PosedShape,
    *,
    p_a: np.ndarray,
    p_b: np.ndarray,
    nhat: np.ndarray,
    psi: float,
) -> ExactPair | None:
    """Exact contact of A (object) and B (finger) near Drake's witness.

    Parameters
    ----------
    A, B : PosedShape
        The object's and the finger's geometry, posed in a common frame O.
    p_a, p_b : (3,) float
        Drake's witness points on A and B, frame O.
    nhat : (3,) float
        Drake's unit normal from B into A, frame O.
    psi : float
        Drake's signed distance, metres.

    Returns
    -------
    ExactPair or None
        None when no route certifies (see the module docstring).
    """
    for X, Y, flip in ((B, A, False), (A, B, True)):
        core = X.core()
        if core is not None:  # exact by convexity; no other route can beat it
            near = p_b if not flip else p_a
            cand = _core_route(core, Y, flip=flip, near=near, method="core")
            ok = cand is not None and _certified(A, B, cand, psi)
            return cand if ok else None
    candidates = [
        *_face_routes(A, B, p_a=p_a, p_b=p_b, nhat=nhat),
        *_feature_routes(A, B, p_a=p_a, p_b=p_b),
        _newton_route(A, B, nhat=nhat, p_a=p_a, p_b=p_b),
    ]
    good = [c for c in candidates if c is not None and _certified(A, B, c, psi)]
    if not good:
        return None
    return max(good, key=lambda c: c.psi)


# --- the core route ------------------------------------------------------------


def _core_route(core, Y: PosedShape, *, flip: bool, near, method: str):
    """``X`` = segment ``ab`` inflated by ``r``, against the shape ``Y``.

    ``flip`` False: X is the finger (B), Y the object (A); True: the reverse.
    None when an edge or a vertex (``r = 0``) touches an edge or a vertex of
    ``Y`` at ``ψ = 0``, where the normal is not a projection's.
    """
    a, b, r = core
    s = _minimise_along(Y, a, b, near)
    c = a + s * (b - a)
    sd, q, m = Y.project(c)  # m: Y's outward normal, towards the core
    if r == 0.0 and abs(sd) < _TOUCHING:
        m = _touching_normal(Y, q, b - a)
        if m is None:
            return None
    psi = sd - r
    p_x = c - r * m  # X's surface point facing Y
    if not flip:  # Y is the object: the normal into it is −m
        return ExactPair(psi, q, p_x, -m, method)
    return ExactPair(psi, p_x, q, m, method)


def _touching_normal(Y: PosedShape, q, d):
    """Y's outward normal where a segment (direction ``d``) touches it.

    ``(c − q)/|c − q|`` is round-off when the core touches Y, so the normal
    comes from Y's surface at ``q``: its own where it has one; on an edge (a
    box's or a convex hull's, a cylinder's rim) the direction normal to both
    the edge and the touching segment, in the edge's normal cone.
    """
    pieces = surface_pieces(Y.shape, Y.to_G(q), tol=_TOUCHING)
    normals = [Y.R @ p.normal_G for p in pieces]
    if len(normals) == 1:
        return normals[0]
    if len(normals) != 2 or not np.any(d):
        return None
    m = np.cross(np.cross(normals[0], normals[1]), d)
    if np.linalg.norm(m) < 1e-9 * np.linalg.norm(d):  # the segment runs along
        return None
    m = m / np.linalg.norm(m)
    return m if m @ (normals[0] + normals[1]) > 0 else -m


def _minimise_along(Y: PosedShape, a, b, near) -> float:
    """``argmin_s sd_Y(a + s(b − a))`` on [0, 1], the one nearest ``near``."""
    d = b - a
    if not np.any(d):
        return 0.0

    def slope(s):
        return float(Y.project(a + s * d)[2] @ d)

    if slope(0.0) >= 0.0:
        s = 0.0
    elif slope(1.0) <= 0.0:
        s = 1.0
    else:
        lo, hi = 0.0, 1.0
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if slope(mid) < 0.0:
                lo = mid
            else:
                hi = mid
        s = 0.5 * (lo + hi)
    # A flat minimum (a segment parallel to a face or an axis): keep the point
    # nearest Drake's witness, which is as close.
    s_near = float(np.clip((near - a) @ d / (d @ d), 0.0, 1.0))
    flat = abs(slope(s_near)) <= 1e-12 * float(np.linalg.norm(d))
    if flat and Y.project(a + s_near * d)[0] <= Y.project(a + s * d)[0] + 1e-15:
        return s_near
    return s


# --- the face route --------------------------------------------------------------


def _faces_O(X: PosedShape, out_dir: np.ndarray):
    """X's flat faces whose outward normal is within ``_FACE_ANGLE`` of ``out_dir``.

    Yields ``(outward normal, a point of the face, polygon or None, cap
    radius or None)``, frame O: a polygon for a box's or a hull's face, a cap
    radius for a cylinder's cap, neither for a half space.
    """
    s = X.shape
    cos = np.cos(_FACE_ANGLE)
    if isinstance(s, HalfSpace):
        faces = [(X.R[:, 2], X.t, None, None)]
    elif isinstance(s, Cylinder):
        half, r = 0.5 * s.length(), s.radius()
        faces = [
            (sign * X.R[:, 2], X.t + sign * half * X.R[:, 2], None, r)
            for sign in (1.0, -1.0)
        ]
    elif isinstance(s, (Box, Convex, Mesh)):
        N = face_arrays(X.faces)[0] @ X.R.T  # outward normals in O
        faces = []
        for k in np.flatnonzero(N @ out_dir >= cos):
            poly = X.faces[k][2] @ X.R.T + X.t
            faces.append((N[k], poly[0], poly, None))
    else:
        faces = []
    return [f for f in faces if f[0] @ out_dir >= cos]


def _face_routes(A, B, *, p_a, p_b, nhat):
    out = []
    # X's face, outward normal m; the normal into A is −m on A, +m on B.
    for X, Y, near_y, out_dir, on_a in (
        (A, B, p_b, -nhat, True),
        (B, A, p_a, nhat, False),
    ):
        for m, point, poly, cap in _faces_O(X, out_dir):
            y = Y.support(-m, near_y)
            psi = float(m @ (y - point))
            foot = y - psi * m  # on the face's plane
            if poly is not None:
                if np.linalg.norm(closest_on_polygon(foot, poly, m) - foot) > 1e-12:
                    continue
            elif cap is not None and np.hypot(*X.to_G(foot)[:2]) > cap:
                continue
            if on_a:
                out.append(ExactPair(psi, foot, y, -m, "face"))
            else:
                out.append(ExactPair(psi, y, foot, m, "face"))
    return out


# --- edges, vertices and cylinder sides as cores -----------------------------------


def _feature_cores(X: PosedShape, near: np.ndarray):
    """Cores ``((a, b, r), method)`` of X's features near Drake's witness."""
    s = X.shape
    if isinstance(s, Cylinder):
        half = 0.5 * s.length() * X.R[:, 2]
        return [((X.t - half, X.t + half, float(s.radius())), "cylinder side")]
    if not isinstance(s, (Box, Convex, Mesh)):
        return []
    _, _, EA, EB, _ = face_arrays(X.faces)
    A = EA @ X.R.T + X.t  # every face's edges, in O (each edge twice)
    B = EB @ X.R.T + X.t
    AB = B - A
    t = np.clip(np.einsum("ij,ij->i", near - A, AB) / np.sum(AB**2, axis=1), 0, 1)
    reach = np.linalg.norm(A + t[:, None] * AB - near, axis=1) <= _FEATURE_REACH
    cores, seen = [], set()
    for a, b in zip(A[reach], B[reach], strict=True):
        key = tuple(sorted((tuple(np.round(a, 12)), tuple(np.round(b, 12)))))
        if key not in seen:
            seen.add(key)
            cores.append(((a, b, 0.0), "edge"))
    return cores


def _feature_routes(A, B, *, p_a, p_b):
    out = []
    for X, Y, near, flip in ((B, A, p_b, False), (A, B, p_a, True)):
        for core, method in _feature_cores(X, near):
            out.append(_core_route(core, Y, flip=flip, near=near, method=method))
    return out


# --- Newton on the normal for two smooth pieces --------------------------------------


def _newton_route(A, B, *, nhat, p_a, p_b) -> ExactPair | None:
    u = np.asarray(nhat, dtype=float)
    for _ in range(40):
        Ha, Hb = A.support_hessian(-u), B.support_hessian(u)
        if Ha is None or Hb is None:
            return None
        a, b = A.support(-u, p_a), B.support(u, p_b)
        E = _tangent_basis(u)
        g = E.T @ (a - b)
        M = E.T @ (Ha + Hb) @ E + float(u @ (a - b)) * np.eye(2)
        try:
            step = E @ np.linalg.solve(M, g)
        except np.linalg.LinAlgError:
            return None
        u = u + step
        u = u / np.linalg.norm(u)
        if not np.all(np.isfinite(u)):
            return None
        if np.linalg.norm(step) < 1e-15:
            break
    a, b = A.support(-u, p_a), B.support(u, p_b)
    return ExactPair(float(u @ (a - b)), a, b, u, "newton")


def _tangent_basis(u: np.ndarray) -> np.ndarray:
    e = np.zeros(3)
    e[int(np.argmin(np.abs(u)))] = 1.0
    t1 = np.cross(u, e)
    t1 /= np.linalg.norm(t1)
    return np.column_stack([t1, np.cross(u, t1)])


# --- the certificate ----------------------------------------------------------------


def _certified(A: PosedShape, B: PosedShape, c: ExactPair, psi_drake: float) -> bool:
    n = c.nhat_O
    if not np.all(np.isfinite(n)) or abs(np.linalg.norm(n) - 1.0) > 1e-12:
        return False
    if not abs(c.psi - psi_drake) <= _DRAKE_AGREEMENT:
        return False
    tol = CERTIFY_TOL
    if np.linalg.norm(c.p_OCa - c.p_OCb - c.psi * n) > tol:
        return False
    if abs(A.project(c.p_OCa)[0]) > tol or abs(B.project(c.p_OCb)[0]) > tol:
        return False
    # Support points along the normal: A's lowest, B's highest along n.
    return (
        A.support_value(-n) <= -(n @ c.p_OCa) + tol
        and B.support_value(n) <= n @ c.p_OCb + tol
    )
