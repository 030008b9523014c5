r"""Exact point queries on a posed Drake shape: projection, support, curvature.

:class:`PosedShape` is a convex Drake shape placed in a common frame ``O`` by
its pose ``X_OG``.  It answers, to round-off,

- :meth:`~PosedShape.project`: the signed distance of a point to the shape,
  the closest surface point and the outward normal (the gradient of the signed
  distance) — closed forms for the sphere, box, cylinder, capsule and half
  space, a bracketed root of the one-dimensional secular equation for the
  ellipsoid, and the faces of the convex hull for ``Convex`` and ``Mesh``
  (which Drake's distance queries see as their hull);
- :meth:`~PosedShape.support`: a point of the shape farthest along a direction
  ``v`` (``h(v) = max_x v·x``), the one nearest a given point when the
  farthest points form a face or an edge;
- :meth:`~PosedShape.support_hessian`: ``∇²h(v)``, the radii of curvature of a
  smooth, curved support point (ellipsoid, cylinder rim), used by the Newton
  iteration of :mod:`drakegrasp.plant.exact_contact`.

A sphere is a point inflated by its radius and a capsule a segment inflated by
its radius (:meth:`~PosedShape.core`): every distance to them reduces to a
distance to their core.  numpy only, plus the shape classes of
``pydrake.geometry``.
"""

from __future__ import annotations

import numpy as np
from pydrake.geometry import (
    Box,
    Capsule,
    Cylinder,
    Ellipsoid,
    HalfSpace,
    Mesh,
    Shape,
    Sphere,
)

from drakegrasp.plant._shapes import face_arrays, flat_faces

__all__ = ["PosedShape", "closest_on_polygon", "closest_on_segment"]

_FLAT = 1e-12
"""Relative size below which a direction's component counts as zero."""


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def closest_on_segment(x: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Closest point to ``x`` on the segment ``ab`` (3-vectors, any frame)."""
    ab = b - a
    L2 = float(ab @ ab)
    if L2 == 0.0:
        return np.array(a, dtype=float)
    s = float(np.clip((x - a) @ ab / L2, 0.0, 1.0))
    return a + s * ab


def closest_on_polygon(x: np.ndarray, poly: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Closest point to ``x`` on a convex planar polygon.

    ``poly`` (k, 3) holds the vertices counter-clockwise about the unit normal
    ``n``.
    """
    q = x - ((x - poly[0]) @ n) * n
    k = len(poly)
    inside = all(
        np.cross(poly[(i + 1) % k] - poly[i], q - poly[i]) @ n >= 0 for i in range(k)
    )
    if inside:
        return q
    best = None
    for i in range(k):
        c = closest_on_segment(x, poly[i], poly[(i + 1) % k])
        if best is None or np.sum((x - c) ** 2) < np.sum((x - best) ** 2):
            best = c
    return best


class PosedShape:
    """A convex Drake shape with its pose ``X_OG`` in a common frame ``O``.

    Parameters
    ----------
    shape : pydrake.geometry.Shape
        Sphere, Box, Cylinder, Capsule, Ellipsoid, HalfSpace, Convex or Mesh.
    R_OG : (3, 3) float
        Rotation of the geometry frame ``G`` in ``O``.
    p_OG : (3,) float
        Origin of ``G`` in ``O``, metres.
    """

    def __init__(self, shape: Shape, R_OG: np.ndarray, p_OG: np.ndarray):
        self.shape = shape
        self.R = np.asarray(R_OG, dtype=float)
        self.t = np.asarray(p_OG, dtype=float)
        self.kind = type(shape).__name__
        if isinstance(shape, Mesh):
            self.kind = "Convex"  # Drake queries a mesh as its convex hull
        self._faces = None
        self._vertices = None

    # --- frames ---------------------------------------------------------------
    def to_G(self, p_O: np.ndarray) -> np.ndarray:
        """A point from ``O`` to ``G``."""
        return self.R.T @ (np.asarray(p_O, dtype=float) - self.t)

    def to_O(self, p_G: np.ndarray) -> np.ndarray:
        """A point from ``G`` to ``O``."""
        return self.R @ p_G + self.t

    @property
    def faces(self) -> list:
        """Hull faces ``(normal_G, offset, polygon_G)`` of a box or convex shape."""
        if self._faces is None:
            self._faces = flat_faces(self.shape)
        return self._faces

    @property
    def vertices_G(self) -> np.ndarray:
        """Vertices of a box or convex hull, in ``G``."""
        if self._vertices is None:
            self._vertices = np.unique(
                np.vstack([poly for _, _, poly in self.faces]), axis=0
            )
        return self._vertices

    # --- cores ----------------------------------------------------------------
    def core(self) -> tuple[np.ndarray, np.ndarray, float] | None:
        """``(a_O, b_O, r)``: the shape is the segment ``ab`` inflated by ``r``.

        A sphere's segment has ``a = b``; None for the other shapes.
        """
        s = self.shape
        if isinstance(s, Sphere):
            return self.t.copy(), self.t.copy(), float(s.radius())
        if isinstance(s, Capsule):
            half = 0.5 * s.length() * self.R[:, 2]
            return self.t - half, self.t + half, float(s.radius())
        return None

    # --- projection -------------------------------------------------------------
    def project(self, p_O: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
        """Signed distance, closest surface point and outward normal at ``p``.

        Returns
        -------
        sd : float
            Signed distance of ``p`` to the shape, metres (< 0 inside).
        q_O : (3,) float
            The closest point of the shape's surface, frame ``O``.
        n_O : (3,) float
            Outward unit normal, ``(p − q)/sd`` where ``sd != 0``: the gradient
            of the signed distance at ``p``.
        """
        p = self.to_G(p_O)
        sd, q, n = getattr(self, "_project_" + self.kind)(p)
        return float(sd), self.to_O(q), self.R @ n

    def _project_Sphere(self, p):
        r = self.shape.radius()
        d = float(np.linalg.norm(p))
        n = p / d if d > 0 else np.array([0.0, 0.0, 1.0])
        return d - r, r * n, n

    def _project_HalfSpace(self, p):
        return p[2], np.array([p[0], p[1], 0.0]), np.array([0.0, 0.0, 1.0])

    def _project_Capsule(self, p):
        half = 0.5 * self.shape.length()
        c = np.array([0.0, 0.0, np.clip(p[2], -half, half)])
        d = float(np.linalg.norm(p - c))
        n = (p - c) / d if d > 0 else np.array([1.0, 0.0, 0.0])
        r = self.shape.radius()
        return d - r, c + r * n, n

    def _project_Box(self, p):
        h = 0.5 * np.array(
            [self.shape.width(), self.shape.depth(), self.shape.height()]
        )
        q = np.clip(p, -h, h)
        d = float(np.linalg.norm(p - q))
        out = np.flatnonzero(p != q)
        if len(out) == 1:  # facing one face: its normal, exact even as d → 0
            n = np.zeros(3)
            n[out[0]] = np.sign(p[out[0]])
            return d, q, n
        if d > 0:  # facing an edge or a corner
            return d, q, (p - q) / d
        depth = h - np.abs(p)
        k = int(np.argmin(depth))
        n = np.zeros(3)
        n[k] = 1.0 if p[k] >= 0 else -1.0
        q = p.copy()
        q[k] = n[k] * h[k]
        return -float(depth[k]), q, n

    def _project_Cylinder(self, p):
        r, half = self.shape.radius(), 0.5 * self.shape.length()
        rho = float(np.hypot(p[0], p[1]))
        e = np.array([p[0] / rho, p[1] / rho, 0.0]) if rho > 0 else np.eye(3)[0]
        z = p[2]
        if rho > r and abs(z) <= half:  # facing the side
            return rho - r, r * e + np.array([0.0, 0.0, z]), e
        if abs(z) > half and rho <= r:  # facing a cap
            s = 1.0 if z >= 0 else -1.0
            q = np.array([p[0], p[1], s * half])
            return abs(z) - half, q, np.array([0.0, 0.0, s])
        if rho > r:  # facing the rim
            q = r * e + np.array([0.0, 0.0, np.clip(z, -half, half)])
            d = float(np.linalg.norm(p - q))
            return d, q, (p - q) / d
        if r - rho <= half - abs(z):  # inside, nearer the side
            return rho - r, r * e + np.array([0.0, 0.0, z]), e
        s = 1.0 if z >= 0 else -1.0
        return abs(z) - half, np.array([p[0], p[1], s * half]), np.array([0, 0, s])

    def _project_Ellipsoid(self, p):
        abc = np.array([self.shape.a(), self.shape.b(), self.shape.c()])
        return _project_ellipsoid(abc, p)

    def _project_Convex(self, p):
        N, D, EA, EB, EF = face_arrays(self.faces)
        gaps = N @ p - D
        k = int(np.argmax(gaps))
        if gaps[k] <= 0.0:  # inside: the nearest face plane
            return float(gaps[k]), p - gaps[k] * N[k], N[k].copy()
        # Outside, the closest point lies on a face that p sees: in its
        # interior (where p projects inside every edge), or on one of its edges.
        visible = gaps > 0
        q = p - gaps[:, None] * N  # projections on every face plane
        e_vis = visible[EF]
        side = np.einsum("ij,ij->i", np.cross(EB - EA, q[EF] - EA), N[EF])
        outside = np.zeros(len(N), dtype=bool)
        np.logical_or.at(outside, EF, side < 0)
        inner = np.flatnonzero(visible & ~outside)
        best_d, best_q, best_face = np.inf, None, False
        if inner.size:
            f = inner[np.argmin(gaps[inner])]
            best_d, best_q, best_face = float(gaps[f]), q[f], True
            n_face = N[f]
        A, B = EA[e_vis], EB[e_vis]
        if len(A):
            AB = B - A
            t = np.clip(np.einsum("ij,ij->i", p - A, AB) / np.sum(AB**2, axis=1), 0, 1)
            C = A + t[:, None] * AB
            dist = np.linalg.norm(p - C, axis=1)
            j = int(np.argmin(dist))
            if dist[j] < best_d:
                best_d, best_q, best_face = float(dist[j]), C[j], False
        if best_face:
            return best_d, best_q, n_face.copy()
        return best_d, best_q, (p - best_q) / best_d

    # --- support ----------------------------------------------------------------
    def support(self, v_O: np.ndarray, near_O: np.ndarray | None = None) -> np.ndarray:
        """A point of the shape farthest along ``v`` (frame ``O``).

        Where the farthest points form a face or an edge, the one closest to
        ``near_O`` (default: the face's centre).  A half space has a finite
        support point only along its outward normal.
        """
        v = self.R.T @ np.asarray(v_O, dtype=float)
        v = v / np.linalg.norm(v)
        near = np.zeros(3) if near_O is None else self.to_G(near_O)
        s = self.shape
        if isinstance(s, Sphere):
            x = s.radius() * v
        elif isinstance(s, Ellipsoid):
            a2 = np.array([s.a(), s.b(), s.c()]) ** 2
            x = a2 * v / np.sqrt(v @ (a2 * v))
        elif isinstance(s, Capsule):
            x = s.radius() * v + _axial(v[2], near[2], 0.5 * s.length())
        elif isinstance(s, Cylinder):
            x = _axial(v[2], near[2], 0.5 * s.length())
            rho = float(np.hypot(v[0], v[1]))
            if rho > _FLAT:
                x[:2] = s.radius() * v[:2] / rho
            else:  # the cap: the nearest point of the disc
                m = float(np.hypot(near[0], near[1]))
                x[:2] = near[:2] * min(1.0, s.radius() / m) if m > 0 else 0.0
        elif isinstance(s, Box):
            h = 0.5 * np.array([s.width(), s.depth(), s.height()])
            x = np.where(np.abs(v) > _FLAT, np.sign(v) * h, np.clip(near, -h, h))
        elif isinstance(s, HalfSpace):
            x = np.array([near[0], near[1], 0.0])
        else:
            x = self._support_convex(v, near)
        return self.to_O(x)

    def _support_convex(self, v: np.ndarray, near: np.ndarray) -> np.ndarray:
        N = face_arrays(self.faces)[0]
        k = int(np.argmax(N @ v))
        if N[k] @ v > 1 - _FLAT:  # a face facing v: its point nearest ``near``
            return closest_on_polygon(near, self.faces[k][2], N[k])
        V = self.vertices_G
        h = V @ v
        top = np.flatnonzero(h >= h.max() - _FLAT * np.max(np.abs(V)))
        if len(top) == 2:  # an edge
            return closest_on_segment(near, V[top[0]], V[top[1]])
        return V[top[0]]

    def support_value(self, v_O: np.ndarray) -> float:
        """``h(v) = max_x v·x`` over the shape.

        ``inf`` for a half space, except along its outward normal.
        """
        v = np.asarray(v_O, dtype=float)
        if isinstance(self.shape, HalfSpace):
            m = self.R[:, 2]
            if np.linalg.norm(v / np.linalg.norm(v) - m) > 1e-12:
                return float("inf")
        return float(v @ self.support(v))

    def support_hessian(self, v_O: np.ndarray) -> np.ndarray | None:
        """``∇²h`` at the unit direction ``v`` (frame ``O``), or None at a kink.

        Defined where the support point is unique and the support function is
        twice differentiable: everywhere on an ellipsoid or a sphere, on a
        cylinder's rim; None on faces, edges and vertices, on a cylinder's side
        or cap and on a capsule.
        """
        v = self.R.T @ np.asarray(v_O, dtype=float)
        s = self.shape
        if isinstance(s, Sphere):
            H = s.radius() * (np.eye(3) - np.outer(v, v))
        elif isinstance(s, Ellipsoid):
            a2 = np.array([s.a(), s.b(), s.c()]) ** 2
            w = a2 * v
            m = float(np.sqrt(v @ w))
            H = np.diag(a2) / m - np.outer(w, w) / m**3
        elif isinstance(s, Cylinder):
            rho = float(np.hypot(v[0], v[1]))
            if rho <= 1e-9 or abs(v[2]) <= 1e-9:
                return None
            e = np.array([v[0], v[1], 0.0]) / rho
            H = s.radius() / rho * (np.diag([1.0, 1.0, 0.0]) - np.outer(e, e))
        else:
            return None
        return self.R @ H @ self.R.T


def _axial(vz: float, near_z: float, half: float) -> np.ndarray:
    z = np.sign(vz) * half if abs(vz) > _FLAT else float(np.clip(near_z, -half, half))
    return np.array([0.0, 0.0, z])


def _project_ellipsoid(abc: np.ndarray, p: np.ndarray):
    """Closest point of the ellipsoid ``Σ (x_i/a_i)² = 1`` to ``p`` (frame G).

    The closest point is ``x_i = a_i² p_i / (t + a_i²)`` where ``t`` is the root
    of ``F(t) = Σ (a_i p_i/(t + a_i²))² − 1`` on ``t > −min a_i²`` (F decreases
    there), by bisection to the last bit.  ``t`` is the
    signed distance times the normal's scale, so ``t > 0`` outside.
    """
    a2 = abc**2
    k = int(np.argmin(abc))
    if abs(p[k]) < 1e-14 * abc[k]:  # on the smallest axis' plane
        p = p.copy()
        p[k] = 1e-14 * abc[k]  # the medial sheet: either side is as close

    def F(t):
        w = t + a2
        if np.any(w <= 0.0):
            return np.inf
        return float(np.sum((abc * p / w) ** 2)) - 1.0

    lo = -a2[k]  # F(lo⁺) = +inf
    hi = float(abc.max() * np.linalg.norm(p))  # F(hi) <= 0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if F(mid) > 0:
            lo = mid
        else:
            hi = mid
    t = 0.5 * (lo + hi)
    x = a2 * p / (t + a2)
    x = x / np.sqrt(np.sum((x / abc) ** 2))  # exactly on the surface
    n = _unit(x / a2)
    inside = float(np.sum((p / abc) ** 2)) < 1.0
    d = float(np.linalg.norm(p - x))
    return (-d if inside else d), x, n
