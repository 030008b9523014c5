r"""An object's collision surface as convex pieces: samples, normals and chords.

A parallel jaw closes on the first and the last surface that its grasp line
meets, so the planner needs two things from an object's collision geometry:
points on its surface with their outward normals (area-weighted samples), and,
for a line through a sampled point along the inward normal, where the line
enters and leaves the object (its *chord*).  Every Drake shape that can bound
an object is convex (``Sphere``, ``Ellipsoid``, ``Box``, ``Cylinder``,
``Capsule``, ``Convex``; a ``Mesh`` is its convex hull, as Drake's point-contact
queries treat it, read with ``Shape.GetConvexHull()`` from the file Drake
uses), so each geometry is one convex *piece* and an object is their union.

**Chords.**  A line ``x(t) = p + t d`` (``d`` unit) meets a convex piece in
one interval ``[t_in, t_out]``:

- sphere and ellipsoid (semi-axes ``s``): the roots of
  :math:`\lVert (p + t d) / s \rVert^2 = 1`;
- box and hull, faces :math:`n_j^T x \le o_j`:
  :math:`t_{in} = \max_{n_j^T d < 0} (o_j - n_j^T p)/(n_j^T d)`,
  :math:`t_{out} = \min_{n_j^T d > 0} (\cdot)`;
- cylinder: the radial quadratic intersected with the slab
  :math:`|z| \le h`;
- capsule: the union of its cylinder and its two end spheres.

The object's chord runs from the smallest ``t_in`` to the largest ``t_out`` of
its pieces: a jaw closing from outside bridges gaps between pieces.

All arrays are in metres; ``O`` is the object's body frame, ``G`` a
geometry's frame.  numpy only, plus Drake's shape classes.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from pydrake.geometry import (
    Box,
    Capsule,
    Convex,
    Cylinder,
    Ellipsoid,
    Mesh,
    Shape,
    Sphere,
)
from pydrake.math import RigidTransform

from drakegrasp.core.calls import checked_call
from drakegrasp.errors import ModelError
from drakegrasp.plant.mesh_convexity import NON_CONVEX_SHARE as NON_CONVEX_SHARE
from drakegrasp.plant.mesh_convexity import NonConvexMeshWarning as NonConvexMeshWarning
from drakegrasp.plant.mesh_convexity import warn_if_not_convex as warn_if_not_convex

__all__ = [
    "ObjectSurface",
    "Piece",
    "piece_of_shape",
]


_PARALLEL = 1e-12
"""``|n_j^T d|`` (or ``|d_xy|``, ``|d_z|``) below this: the line is parallel."""


def _unit_rows(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _sphere_directions(n: int, rng: np.random.Generator) -> np.ndarray:
    return _unit_rows(rng.standard_normal((n, 3)))


def _quadratic(a, b, c):
    """Roots ``t_in <= t_out`` of ``a t² + 2 b t + c = 0`` (NaN: no real root)."""
    disc = b * b - a * c
    ok = (disc >= 0) & (a > 0)
    root = np.sqrt(np.where(ok, disc, 0.0))
    a_safe = np.where(ok, a, 1.0)
    t_in = np.where(ok, (-b - root) / a_safe, np.nan)
    t_out = np.where(ok, (-b + root) / a_safe, np.nan)
    return t_in, t_out


@dataclass(frozen=True, eq=False)
class Piece:
    """One convex piece of an object's surface, in its geometry frame G.

    Attributes
    ----------
    kind : str
        ``"ellipsoid"`` (spheres too), ``"hull"`` (boxes, convex meshes),
        ``"cylinder"`` or ``"capsule"``.
    X_OG : RigidTransform
        Pose of the geometry frame in the object's body frame.
    name : str
        The geometry's name in the scene graph.
    semi_axes : (3,) float
        Ellipsoid semi-axes; ``(r, r, h)`` (radius, half-length) for a cylinder
        or capsule; unused for a hull.
    normals, offsets : (F, 3), (F,) float
        A hull's faces ``n_j^T x <= o_j`` (outward unit normals).
    triangles : (T, 3, 3) float
        A hull's surface triangles (for sampling).
    """

    kind: str
    X_OG: RigidTransform
    name: str
    semi_axes: np.ndarray
    normals: np.ndarray
    offsets: np.ndarray
    triangles: np.ndarray

    @cached_property
    def bounding_ball(self) -> tuple[np.ndarray, float]:
        """``(centre_G, radius)``: a ball (frame G, metres) holding the piece."""
        if self.kind == "hull":
            v = self.triangles.reshape(-1, 3)
            centre = 0.5 * (v.min(axis=0) + v.max(axis=0))
            return centre, float(np.max(np.linalg.norm(v - centre, axis=1)))
        r, _, h = self.semi_axes
        if self.kind == "ellipsoid":
            return np.zeros(3), float(self.semi_axes.max())
        if self.kind == "cylinder":
            return np.zeros(3), float(np.hypot(r, h))
        return np.zeros(3), float(r + h)

    # -- area and sampling ---------------------------------------------------

    def _side_and_caps(self) -> tuple[float, float]:
        r, _, h = self.semi_axes
        side = 2 * np.pi * r * 2 * h
        ends = (2 if self.kind == "cylinder" else 4) * np.pi * r * r
        return side, ends

    @property
    def area(self) -> float:
        """Surface area, m² (an ellipsoid's by Thomsen's formula, within 1.1 %)."""
        if self.kind == "hull":
            cr = np.cross(
                self.triangles[:, 1] - self.triangles[:, 0],
                self.triangles[:, 2] - self.triangles[:, 0],
            )
            return float(0.5 * np.linalg.norm(cr, axis=1).sum())
        if self.kind == "ellipsoid":
            a, b, c = self.semi_axes
            p = 1.6075
            return float(
                4
                * np.pi
                * (((a * b) ** p + (a * c) ** p + (b * c) ** p) / 3) ** (1 / p)
            )
        return float(sum(self._side_and_caps()))

    def sample(self, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """``n`` area-uniform surface points and outward unit normals, frame G."""
        if self.kind == "ellipsoid":
            s = self.semi_axes
            pts, nrm = np.empty((0, 3)), np.empty((0, 3))
            while len(pts) < n:  # rejection on the area element of the map u -> s u
                u = _sphere_directions(2 * (n - len(pts)) + 8, rng)
                g = np.linalg.norm(u / s, axis=1) * np.prod(s)
                keep = rng.random(len(u)) * np.prod(s) / s.min() <= g
                x = u[keep] * s
                pts = np.vstack([pts, x])
                nrm = np.vstack([nrm, _unit_rows(x / s**2)])
            return pts[:n], nrm[:n]
        if self.kind == "hull":
            tri = self.triangles
            cr = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            area = np.linalg.norm(cr, axis=1)
            k = rng.choice(len(tri), size=n, p=area / area.sum())
            r1, r2 = rng.random(n), rng.random(n)
            flip = r1 + r2 > 1
            r1, r2 = np.where(flip, 1 - r1, r1), np.where(flip, 1 - r2, r2)
            t = tri[k]
            pts = (
                t[:, 0]
                + r1[:, None] * (t[:, 1] - t[:, 0])
                + r2[:, None] * (t[:, 2] - t[:, 0])
            )
            return pts, _unit_rows(cr[k])
        r, _, h = self.semi_axes
        side, ends = self._side_and_caps()
        on_side = rng.random(n) < side / (side + ends)
        phi = rng.uniform(0, 2 * np.pi, n)
        radial = np.column_stack([np.cos(phi), np.sin(phi), np.zeros(n)])
        pts = radial * r + np.outer(rng.uniform(-h, h, n), [0, 0, 1])
        nrm = radial.copy()
        if self.kind == "cylinder":  # caps: uniform on discs
            rho = r * np.sqrt(rng.random(n))
            top = np.where(rng.random(n) < 0.5, 1.0, -1.0)
            cap = radial * rho[:, None]
            cap[:, 2] = top * h
            cap_n = np.zeros((n, 3))
            cap_n[:, 2] = top
        else:  # capsule: hemispheres
            u = _sphere_directions(n, rng)
            cap = u * r
            cap[:, 2] += np.where(u[:, 2] >= 0, h, -h)
            cap_n = u
        pts = np.where(on_side[:, None], pts, cap)
        nrm = np.where(on_side[:, None], nrm, cap_n)
        return pts, nrm

    # -- chords --------------------------------------------------------------

    def chord(self, p: np.ndarray, d: np.ndarray):
        """Where lines ``p + t d`` (frame G, ``d`` unit) enter and leave the piece.

        Returns
        -------
        t_in, t_out : (K,) float
            NaN where the line misses the piece.
        n_out : (K, 3) float
            Outward unit normal at the exit point, frame G.
        """
        if self.kind == "ellipsoid":
            return self._ellipsoid_chord(p, d, np.zeros(3))
        if self.kind == "hull":
            return self._hull_chord(p, d)
        cyl = self._cylinder_chord(p, d)
        if self.kind == "cylinder":
            return cyl
        r, _, h = self.semi_axes
        best_in, best_out, best_n = cyl
        for z in (h, -h):
            t_in, t_out, n = self._ellipsoid_chord(p, d, np.array([0, 0, z]), r)
            best_in = np.fmin(best_in, t_in)
            later = ~(t_out <= best_out)  # NaN-aware: a hit beats a miss
            later &= ~np.isnan(t_out)
            best_out = np.where(later, t_out, best_out)
            best_n = np.where(later[:, None], n, best_n)
        return best_in, best_out, best_n

    def _ellipsoid_chord(self, p, d, centre, radius=None):
        s = self.semi_axes if radius is None else np.full(3, radius)
        u, v = (p - centre) / s, d / s
        t_in, t_out = _quadratic(
            np.sum(v * v, 1), np.sum(u * v, 1), np.sum(u * u, 1) - 1
        )
        x = p + np.nan_to_num(t_out)[:, None] * d - centre
        return t_in, t_out, _unit_rows(x / s**2 + 1e-300)

    def _hull_chord(self, p, d):
        # Face by face over contiguous (K,) columns: numpy's reductions over a
        # short last axis are slow.  t = gap / nd is read only where the line
        # crosses face j (|nd| > _PARALLEL), so no masked division is needed;
        # the exit is the first face of least t (argmin's choice).
        nd = (d @ self.normals.T).T.copy()  # (F, K)
        gap = (self.offsets[None, :] - p @ self.normals.T).T.copy()
        K = len(p)
        t_in = np.full(K, -np.inf)
        t_out = np.full(K, np.inf)
        j = np.zeros(K, dtype=np.intp)
        outside = np.zeros(K, bool)  # parallel to a face and outside it
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            for f in range(len(nd)):
                t = gap[f] / nd[f]
                np.maximum(t_in, np.where(nd[f] < -_PARALLEL, t, -np.inf), out=t_in)
                earlier = (nd[f] > _PARALLEL) & (t < t_out)
                t_out[earlier] = t[earlier]
                j[earlier] = f
                outside |= (np.abs(nd[f]) < _PARALLEL) & (gap[f] < 0)
        miss = (t_in > t_out) | outside
        miss |= ~np.isfinite(t_in) | ~np.isfinite(t_out)
        t_in[miss] = np.nan
        t_out[miss] = np.nan
        return t_in, t_out, self.normals[j]

    def _cylinder_chord(self, p, d):
        r, _, h = self.semi_axes
        a = d[:, 0] ** 2 + d[:, 1] ** 2
        b = p[:, 0] * d[:, 0] + p[:, 1] * d[:, 1]
        c = p[:, 0] ** 2 + p[:, 1] ** 2 - r * r
        axial = a < _PARALLEL
        r_in, r_out = _quadratic(np.where(axial, 1.0, a), b, c)
        r_in = np.where(axial, np.where(c <= 0, -np.inf, np.nan), r_in)
        r_out = np.where(axial, np.where(c <= 0, np.inf, np.nan), r_out)
        dz = d[:, 2]
        flat = np.abs(dz) < _PARALLEL
        dz_safe = np.where(flat, 1.0, dz)
        z1, z2 = (-h - p[:, 2]) / dz_safe, (h - p[:, 2]) / dz_safe
        inside = np.abs(p[:, 2]) <= h
        s_in = np.where(flat, np.where(inside, -np.inf, np.nan), np.minimum(z1, z2))
        s_out = np.where(flat, np.where(inside, np.inf, np.nan), np.maximum(z1, z2))
        t_in, t_out = np.fmax(r_in, s_in), np.fmin(r_out, s_out)
        t_in = np.where(np.isnan(r_in) | np.isnan(s_in), np.nan, t_in)
        t_out = np.where(np.isnan(r_out) | np.isnan(s_out), np.nan, t_out)
        miss = ~(t_in <= t_out)
        t_in, t_out = np.where(miss, np.nan, t_in), np.where(miss, np.nan, t_out)
        radial_exit = r_out <= s_out
        x = p + np.nan_to_num(t_out, posinf=0.0, neginf=0.0)[:, None] * d
        n_rad = _unit_rows(
            np.column_stack([x[:, 0], x[:, 1], np.zeros(len(p))]) + 1e-300
        )
        n_cap = np.zeros_like(p)
        n_cap[:, 2] = np.sign(dz_safe)
        return t_in, t_out, np.where(radial_exit[:, None], n_rad, n_cap)

    def support(self, u_G: np.ndarray) -> float:
        """``max_x u·x`` over the piece (frame G, ``u`` unit), metres."""
        if self.kind == "hull":
            return float(np.max(self.triangles.reshape(-1, 3) @ u_G))
        if self.kind == "ellipsoid":
            return float(np.linalg.norm(self.semi_axes * u_G))
        r, _, h = self.semi_axes
        if self.kind == "cylinder":
            return float(r * np.hypot(u_G[0], u_G[1]) + h * abs(u_G[2]))
        return float(r + h * abs(u_G[2]))

    def radius_about(self, p_O: np.ndarray) -> float:
        """An upper bound of the distance from ``p_O`` to the piece's points, m."""
        if self.kind == "hull":
            v = self.triangles.reshape(-1, 3)
            return float(
                np.max(np.linalg.norm(self.X_OG.multiply(v.T).T - p_O, axis=1))
            )
        centre = np.linalg.norm(self.X_OG.translation() - p_O)
        r, _, h = self.semi_axes
        if self.kind == "ellipsoid":
            return float(centre + self.semi_axes.max())
        if self.kind == "cylinder":
            return float(centre + np.hypot(r, h))
        return float(centre + h + r)


def _near_lines(p: np.ndarray, d: np.ndarray, centre, radius: float, dd=None):
    """Rows whose line ``p + t d`` passes within the ball, or None.

    None when every row does (no subset to take).  The test is loose by a
    relative 1e-9 and 1e-12 m, so a line it drops misses the ball, hence the
    piece, by more than round-off.  ``dd``: the rows' ``d·d`` if known.
    """
    w = centre - p
    along = np.einsum("ij,ij->i", w, d)
    if dd is None:
        dd = np.einsum("ij,ij->i", d, d)
    gap2 = np.einsum("ij,ij->i", w, w) - along * along / dd
    reach = radius * (1.0 + 1e-9) + 1e-12
    near = gap2 <= reach * reach
    return None if near.all() else np.flatnonzero(near)


def _hull_piece(X_OG, name, vertices, polygons) -> Piece:
    tris, normals, offsets = [], [], []
    centroid = vertices.mean(axis=0)
    for poly in polygons:
        pts = vertices[list(poly)]
        fan = [(pts[0], pts[k], pts[k + 1]) for k in range(1, len(pts) - 1)]
        cr = sum(np.cross(b - a, c - a) for a, b, c in fan)
        norm = np.linalg.norm(cr)
        if norm < 1e-18:
            continue
        n = cr / norm
        if n @ (pts[0] - centroid) < 0:  # orient outwards whatever the winding
            n = -n
            fan = [(a, c, b) for a, b, c in fan]
        tris += fan
        normals.append(n)
        offsets.append(n @ pts[0])
    return Piece(
        kind="hull",
        X_OG=X_OG,
        name=name,
        semi_axes=np.zeros(3),
        normals=np.array(normals),
        offsets=np.array(offsets),
        triangles=np.array(tris),
    )


def piece_of_shape(shape: Shape, X_OG: RigidTransform, name: str = "") -> Piece:
    """The convex piece of one Drake shape posed at ``X_OG`` in the object frame.

    Raises
    ------
    ModelError
        For a shape that bounds no object (``HalfSpace``) or that drakegrasp
        does not know.
    """
    empty = np.zeros((0, 3))
    if isinstance(shape, Sphere):
        axes, kind = np.full(3, shape.radius()), "ellipsoid"
    elif isinstance(shape, Ellipsoid):
        axes, kind = np.array([shape.a(), shape.b(), shape.c()]), "ellipsoid"
    elif isinstance(shape, Cylinder | Capsule):
        r, h = shape.radius(), shape.length() / 2
        axes = np.array([r, r, h])
        kind = "cylinder" if isinstance(shape, Cylinder) else "capsule"
    elif isinstance(shape, Box):
        hx, hy, hz = shape.width() / 2, shape.depth() / 2, shape.height() / 2
        corners = np.array(
            [
                [sx * hx, sy * hy, sz * hz]
                for sx in (-1, 1)
                for sy in (-1, 1)
                for sz in (-1, 1)
            ]
        )
        faces = [
            (0, 1, 3, 2),
            (4, 5, 7, 6),
            (0, 1, 5, 4),
            (2, 3, 7, 6),
            (0, 2, 6, 4),
            (1, 3, 7, 5),
        ]
        return _hull_piece(X_OG, name, corners, faces)
    elif isinstance(shape, Convex | Mesh):
        hull = shape.GetConvexHull()
        vertices = np.array([hull.vertex(i) for i in range(hull.num_vertices())])
        polygons = []
        for e in range(hull.num_elements()):
            poly = hull.element(e)
            polygons.append([poly.vertex(k) for k in range(poly.num_vertices())])
        return _hull_piece(X_OG, name, vertices, polygons)
    else:
        raise ModelError(
            f"collision geometry {name!r} is a {type(shape).__name__}, which bounds "
            "no graspable object; an object's collision shapes must be Sphere, "
            "Ellipsoid, Box, Cylinder, Capsule, Convex or Mesh"
        )
    return Piece(kind, X_OG, name, axes, empty, np.zeros(0), np.zeros((0, 3, 3)))


@checked_call
@dataclass(frozen=True, eq=False)
class ObjectSurface:
    """The union of an object's convex collision pieces, in its body frame O.

    Attributes
    ----------
    pieces : tuple of Piece
    areas : (P,) float
        Each piece's area, m².
    """

    pieces: tuple[Piece, ...]
    areas: np.ndarray

    @classmethod
    def from_pieces(cls, pieces) -> ObjectSurface:
        """The surface made of ``pieces`` (at least one with an area)."""
        pieces = tuple(pieces)
        areas = np.array([p.area for p in pieces])
        if not len(pieces) or not np.any(areas > 0):
            raise ModelError("the object has no collision geometry with a surface")
        return cls(pieces, areas)

    def centroid(self) -> np.ndarray:
        """The area centroid of the pieces' surfaces, frame O, metres.

        A hull's is its triangles' centroids weighted by their areas; an
        ellipsoid's, cylinder's or capsule's is its centre (each is centrally
        symmetric).  Overlaps of pieces count twice.
        """
        centres = []
        for piece in self.pieces:
            if piece.kind == "hull" and len(piece.triangles):
                t = piece.triangles
                a = 0.5 * np.linalg.norm(
                    np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1
                )
                c_G = (a @ t.mean(axis=1)) / max(float(a.sum()), 1e-300)
            else:
                c_G = np.zeros(3)
            centres.append(piece.X_OG.multiply(c_G))
        return (self.areas @ np.array(centres)) / float(self.areas.sum())

    def sample(self, n: int, rng: np.random.Generator):
        """``n`` area-uniform points on the pieces' surfaces, frame O.

        Returns
        -------
        p_OS : (n, 3) float
            Surface points, metres.
        nout_O : (n, 3) float
            Outward unit normals.
        piece : (n,) int
            Which piece each point lies on.
        """
        counts = rng.multinomial(n, self.areas / self.areas.sum())
        ps, ns, ks = [], [], []
        for k, (piece, m) in enumerate(zip(self.pieces, counts, strict=True)):
            if m == 0:
                continue
            p_G, n_G = piece.sample(int(m), rng)
            R = piece.X_OG.rotation().matrix()
            ps.append(p_G @ R.T + piece.X_OG.translation())
            ns.append(n_G @ R.T)
            ks.append(np.full(m, k))
        if not ps:
            return np.empty((0, 3)), np.empty((0, 3)), np.empty(0, dtype=int)
        return np.vstack(ps), np.vstack(ns), np.concatenate(ks)

    def chord(self, p_O: np.ndarray, d_O: np.ndarray):
        """Entry and exit of lines ``p + t d`` (frame O, ``d`` unit) through the union.

        Returns
        -------
        t_in, t_out : (K,) float
            Smallest entry and largest exit over the pieces (NaN: a miss).
        nout_O : (K, 3) float
            Outward unit normal at the exit point.
        """
        K = len(p_O)
        t_in = np.full(K, np.nan)
        t_out = np.full(K, np.nan)
        n_out = np.zeros((K, 3))
        dd = np.einsum("ij,ij->i", d_O, d_O)
        for piece, (centre, radius) in zip(self.pieces, self._balls_O, strict=True):
            # a line that misses the piece's ball misses the piece: only the
            # others are cast (a corner sphere of a YCB box meets few lines)
            near = _near_lines(p_O, d_O, centre, radius, dd)
            if near is None:
                rows, p, d = slice(None), p_O, d_O
            elif len(near):
                rows, p, d = near, p_O[near], d_O[near]
            else:
                continue
            R = piece.X_OG.rotation().matrix()
            a, b, n = piece.chord((p - piece.X_OG.translation()) @ R, d @ R)
            t_in[rows] = np.fmin(t_in[rows], a)
            later = ~np.isnan(b) & ~(b <= t_out[rows])
            t_out[rows] = np.where(later, b, t_out[rows])
            n_out[rows] = np.where(later[:, None], n @ R.T, n_out[rows])
        return t_in, t_out, n_out

    @cached_property
    def _balls_O(self) -> tuple[tuple[np.ndarray, float], ...]:
        """Each piece's bounding ball ``(centre_O, radius)`` (frame O, metres)."""
        return tuple(
            (piece.X_OG.multiply(centre), radius)
            for piece in self.pieces
            for centre, radius in [piece.bounding_ball]
        )

    def radius_about(self, p_O: np.ndarray) -> float:
        """Radius of a ball about ``p_O`` that holds the object (an upper bound), m."""
        return max(p.radius_about(np.asarray(p_O, float)) for p in self.pieces)
