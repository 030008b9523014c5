r"""Exact contacts of spherical finger tips, vectorised over many pairs.

A spherical finger geometry (the WSG-50's four tip spheres, a fingertip ball)
touching a box, a cylinder, a sphere or a convex hull (``Convex``, ``Mesh``)
of the object is the ``"core"`` route
of :mod:`drakegrasp.plant.exact_contact` with a core of one point: the tip's
centre ``c`` projected onto the object's shape gives the signed distance
``sd``, the closest surface point ``q`` and the outward normal ``m`` in closed
form, and then

.. math::

    \psi = sd - r, \qquad p_{Ca} = q, \qquad p_{Cb} = c - r m,
    \qquad \hat n = -m .

:func:`sphere_tip_pairs` computes that, its certificate (the checks of
:func:`~drakegrasp.plant.exact_contact.closest_pair`: both points on their
surfaces, each a support point along the normal, ``p_Ca − p_Cb = ψ n̂``, ``ψ``
near Drake's) and the normal's source
(:func:`~drakegrasp.plant.contact_normals.normal_source`) for ``P`` pairs at
once, in numpy arrays.  It is the formula of the scalar route written over
arrays, element by element (3-vector products are spelled
out, so a pair's result does not depend on which other pairs share the call);
``tests/plant/test_sphere_tips.py`` checks it against the scalar route to
1e-12.  A pair whose certificate fails is left to the scalar route (which then
falls back to Drake's witness points), so nothing is decided differently.

numpy only; shapes are described by ``kind`` and their dimensions
(:func:`shape_key`), not by Drake objects.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.plant._shapes import EXACT_SURFACE_TOL, face_arrays, flat_faces

__all__ = [
    "SOURCES",
    "TIP_KINDS",
    "Hull",
    "clean_rows",
    "shape_key",
    "sphere_tip_pairs",
    "transform_rows",
]

TIP_KINDS = ("Box", "Convex", "Cylinder", "Sphere")
"""Object shapes whose projection is in closed form here."""

SOURCES = ("object", "edge", "corner")
"""``normal_source`` by code: a tip's normal is the object's on a face or a
smooth point, else it runs from the object's edge or corner to the tip."""

_CERTIFY_TOL = 1e-10  # exact_contact.CERTIFY_TOL
_DRAKE_AGREEMENT = 1e-3  # exact_contact._DRAKE_AGREEMENT
_SOURCE_TOL = EXACT_SURFACE_TOL  # what contact_pair gives normal_source's pieces
_FLAT = 1e-12  # shape_queries._FLAT
_CHUNK = 1_000_000  # pairs × hull edges in one array


class Hull:
    """A convex hull's faces and edges as arrays (frame G), hashable by its source.

    ``N`` (F, 3) outward unit normals, ``D`` (F,) offsets, ``EA``/``EB`` (E, 3)
    every face's edges (counter-clockwise, face by face), ``starts`` (F,) each
    face's first edge, ``V`` (M, 3) the vertices.
    """

    def __init__(self, key, faces):
        self.key = key
        self.N, self.D, self.EA, self.EB, EF = face_arrays(faces)
        self.starts = np.flatnonzero(np.r_[True, EF[1:] != EF[:-1]])
        self.EF = EF
        self.V = np.unique(self.EA, axis=0)

    def __hash__(self):
        return hash(self.key)

    def __eq__(self, other):
        return isinstance(other, Hull) and other.key == self.key


_HULLS: dict[tuple, Hull] = {}


def shape_key(shape) -> tuple | None:
    """``(kind, dimensions)`` of a Drake shape this module projects onto, or None.

    A ``Convex`` or ``Mesh`` (its convex hull, as Drake's queries see it) has
    a :class:`Hull` for dimensions.
    """
    kind = type(shape).__name__
    if kind in ("Convex", "Mesh"):
        source = shape.source()
        key = (
            str(source.path()) if source.is_path() else source.description(),
            tuple(np.asarray(shape.scale3()).tolist()),
        )
        if key not in _HULLS:
            if len(_HULLS) >= 256:
                _HULLS.clear()
            _HULLS[key] = Hull(key, flat_faces(shape))
        return "Convex", _HULLS[key]
    if kind == "Box":
        return kind, (shape.width(), shape.depth(), shape.height())
    if kind == "Cylinder":
        return kind, (shape.radius(), shape.length())
    if kind == "Sphere":
        return kind, (shape.radius(),)
    return None


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1] + a[:, 2] * b[:, 2]


def _norm(a: np.ndarray) -> np.ndarray:
    return np.sqrt(_dot(a, a))


def _mv(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``R v`` row by row: (P, 3, 3) times (P, 3)."""
    return (
        R[:, :, 0] * v[:, 0, None]
        + R[:, :, 1] * v[:, 1, None]
        + R[:, :, 2] * v[:, 2, None]
    )


def _mtv(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``Rᵀ v`` row by row."""
    return (
        R[:, 0, :] * v[:, 0, None]
        + R[:, 1, :] * v[:, 1, None]
        + R[:, 2, :] * v[:, 2, None]
    )


def clean_rows(n: np.ndarray) -> np.ndarray:
    """Unit rows with round-off components (< 1e-12) set to exactly zero.

    :func:`~drakegrasp.plant.contact_normals.clean_unit` over rows (P, 3).
    """
    n = np.where(np.abs(n) < 1e-12, 0.0, np.asarray(n, dtype=float))
    return n / _norm(n)[:, None]


def transform_rows(R: np.ndarray, t: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``R p + t`` row by row: points (P, 3) by poses (P, 3, 3), (P, 3).

    Element by element, so a row's result does not depend on the others.
    """
    return _mv(np.asarray(R, float), np.asarray(p, float)) + np.asarray(t, float)


def _project(kind: str, dims: tuple, p: np.ndarray):
    """Signed distance, closest surface point and outward normal, frame G.

    The closed forms of :class:`~drakegrasp.plant.shape_queries.PosedShape`
    over rows of ``p`` (P, 3).
    """
    P = len(p)
    if kind == "Sphere":
        r = dims[0]
        d = _norm(p)
        safe = np.where(d > 0, d, 1.0)[:, None]
        n = np.where(d[:, None] > 0, p / safe, np.array([0.0, 0.0, 1.0]))
        return d - r, r * n, n
    if kind == "Box":
        h = 0.5 * np.array(dims, dtype=float)
        q = np.clip(p, -h, h)
        diff = p - q
        d = _norm(diff)
        off = p != q
        count = off.sum(axis=1)
        # facing one face: that axis' unit vector
        n_face = np.where(off, np.sign(p), 0.0)
        # facing an edge or a corner
        safe = np.where(d > 0, d, 1.0)[:, None]
        n_edge = diff / safe
        # inside: the nearest face
        depth = h - np.abs(p)
        k = np.argmin(depth, axis=1)
        rows = np.arange(P)
        n_in = np.zeros((P, 3))
        n_in[rows, k] = np.where(p[rows, k] >= 0, 1.0, -1.0)
        q_in = p.copy()
        q_in[rows, k] = n_in[rows, k] * h[k]
        one = (count == 1)[:, None]
        outside = (d > 0)[:, None]
        n = np.where(one, n_face, np.where(outside, n_edge, n_in))
        q = np.where(one | outside, q, q_in)
        sd = np.where(count == 1, d, np.where(d > 0, d, -depth[rows, k]))
        return sd, q, n
    if kind == "Cylinder":
        r, half = dims[0], 0.5 * dims[1]
        rho = np.hypot(p[:, 0], p[:, 1])
        safe = np.where(rho > 0, rho, 1.0)
        e = np.column_stack([p[:, 0] / safe, p[:, 1] / safe, np.zeros(P)])
        e = np.where((rho > 0)[:, None], e, np.array([1.0, 0.0, 0.0]))
        z = p[:, 2]
        zero = np.zeros(P)
        ez = np.array([0.0, 0.0, 1.0])
        s = np.where(z >= 0, 1.0, -1.0)
        # 1: facing the side
        side_q = r * e + np.column_stack([zero, zero, z])
        # 2: facing a cap
        cap_q = np.column_stack([p[:, 0], p[:, 1], s * half])
        cap_n = s[:, None] * ez
        # 3: facing the rim
        rim_q = r * e + np.column_stack([zero, zero, np.clip(z, -half, half)])
        rim_v = p - rim_q
        rim_d = _norm(rim_v)
        rim_n = rim_v / np.where(rim_d > 0, rim_d, 1.0)[:, None]
        c1 = (rho > r) & (np.abs(z) <= half)
        c2 = ~c1 & (np.abs(z) > half) & (rho <= r)
        c3 = ~c1 & ~c2 & (rho > r)
        c4 = ~c1 & ~c2 & ~c3 & (r - rho <= half - np.abs(z))  # inside, near the side
        # else inside, nearer a cap (cap_q, cap_n with sd = |z| - half)
        sd = np.select([c1, c2, c3, c4], [rho - r, np.abs(z) - half, rim_d, rho - r])
        sd = np.where(c1 | c2 | c3 | c4, sd, np.abs(z) - half)
        q = np.select(
            [c1[:, None], c2[:, None], c3[:, None], c4[:, None]],
            [side_q, cap_q, rim_q, side_q],
            cap_q,
        )
        n = np.select(
            [c1[:, None], c2[:, None], c3[:, None], c4[:, None]],
            [e, cap_n, rim_n, e],
            cap_n,
        )
        return sd, q, n
    if kind == "Convex":
        return _project_convex(dims, p)
    raise ValueError(f"no closed-form projection onto a {kind}")


def _planes(H: Hull, p: np.ndarray) -> np.ndarray:
    """(P, F) signed gaps of the points to the hull's face planes."""
    N = H.N
    return p[:, 0:1] * N[:, 0] + p[:, 1:2] * N[:, 1] + p[:, 2:3] * N[:, 2] - H.D


def _project_convex(H: Hull, p: np.ndarray):
    """PosedShape's projection onto a hull, over rows.

    Inside, the nearest face plane; outside, the nearest visible face whose
    interior the point projects into, or the nearest point of a visible edge.
    """
    P = len(p)
    rows = np.arange(P)
    N, EA, EB, EF = H.N, H.EA, H.EB, H.EF
    gaps = _planes(H, p)
    k = np.argmax(gaps, axis=1)
    gk = gaps[rows, k]
    q_all = p[:, None, :] - gaps[:, :, None] * N[None]  # on every face plane
    visible = gaps > 0
    side = np.sum(np.cross(EB - EA, q_all[:, EF] - EA) * N[EF], axis=2)
    outside = np.logical_or.reduceat(side < 0, H.starts, axis=1)
    inner = visible & ~outside
    face_gap = np.where(inner, gaps, np.inf)
    f = np.argmin(face_gap, axis=1)
    face_d = face_gap[rows, f]
    AB = EB - EA
    s = np.clip(np.sum((p[:, None, :] - EA) * AB, axis=2) / np.sum(AB**2, axis=1), 0, 1)
    C = EA + s[:, :, None] * AB
    dist = np.where(
        visible[:, EF], np.sqrt(np.sum((p[:, None, :] - C) ** 2, 2)), np.inf
    )
    j = np.argmin(dist, axis=1)
    edge_d = dist[rows, j]
    edge = (edge_d < face_d)[:, None]
    Cj = C[rows, j]
    with np.errstate(invalid="ignore", divide="ignore"):
        n_edge = (p - Cj) / edge_d[:, None]
    d = np.where(edge[:, 0], edge_d, face_d)
    q = np.where(edge, Cj, q_all[rows, f])
    n = np.where(edge, n_edge, N[f])
    inside = (gk <= 0.0)[:, None]
    sd = np.where(inside[:, 0], gk, d)
    q = np.where(inside, p - gk[:, None] * N[k], q)
    n = np.where(inside, N[k], n)
    return sd, q, n


def _pieces_at(kind: str, dims: tuple, p: np.ndarray) -> np.ndarray:
    """How many surface pieces meet at ``p`` (frame G): 1 smooth, 2 edge, 3 corner.

    ``surface_pieces`` with ``tol`` ``EXACT_SURFACE_TOL``,
    counted (never fewer than one).
    """
    if kind == "Sphere":
        return np.ones(len(p), dtype=int)
    tol = _SOURCE_TOL
    if kind == "Convex":
        return np.maximum((np.abs(_planes(dims, p)) < tol).sum(axis=1), 1)
    if kind == "Box":
        h = 0.5 * np.array(dims, dtype=float)
        on = (np.abs(p - h) < tol).sum(axis=1) + (np.abs(-p - h) < tol).sum(axis=1)
        return np.maximum(on, 1)
    r, half = dims[0], 0.5 * dims[1]
    rho = np.hypot(p[:, 0], p[:, 1])
    on = ((np.abs(rho - r) < tol) & (rho > 0)).astype(int)
    on += np.abs(p[:, 2] - half) < tol
    on += np.abs(p[:, 2] + half) < tol
    return np.maximum(on, 1)


def _support_value(kind: str, dims: tuple, R, t, v_O) -> np.ndarray:
    """``max_x v·x`` over the posed shape (rows of ``v_O``, frame O).

    :meth:`~drakegrasp.plant.shape_queries.PosedShape.support_value` with no
    ``near`` point (a face or edge then gives its centre's point).
    """
    v = _mtv(R, v_O)
    if kind == "Convex":  # the top vertex (a face's or an edge's, as high)
        V = dims.V
        top = np.max(v[:, 0:1] * V[:, 0] + v[:, 1:2] * V[:, 1] + v[:, 2:3] * V[:, 2], 1)
        return top + _dot(v_O, t)
    v = v / _norm(v)[:, None]
    if kind == "Sphere":
        x = dims[0] * v
    elif kind == "Box":
        h = 0.5 * np.array(dims, dtype=float)
        x = np.where(np.abs(v) > _FLAT, np.sign(v) * h, 0.0)
    else:
        r, half = dims[0], 0.5 * dims[1]
        P = len(v)
        z = np.where(np.abs(v[:, 2]) > _FLAT, np.sign(v[:, 2]) * half, 0.0)
        rho = np.hypot(v[:, 0], v[:, 1])
        safe = np.where(rho > _FLAT, rho, 1.0)
        xy = np.where((rho > _FLAT)[:, None], r * v[:, :2] / safe[:, None], 0.0)
        x = np.column_stack([xy, z]) if P else np.zeros((0, 3))
    return _dot(v_O, _mv(R, x) + t)


def sphere_tip_pairs(
    kind: str,
    dims: tuple,
    R_OG: np.ndarray,
    p_OG: np.ndarray,
    c_O: np.ndarray,
    radius: np.ndarray,
    psi_drake: np.ndarray,
):
    """Exact contacts of ``P`` spherical tips with one object shape.

    Parameters
    ----------
    kind, dims : str, tuple or Hull
        The object geometry's shape (:func:`shape_key`).
    R_OG : (P, 3, 3) float
        Each pair's object geometry rotation in the common frame O.
    p_OG : (P, 3) float
        Its origin in O, metres.
    c_O : (P, 3) float
        The tips' centres in O, metres.
    radius : (P,) float
        The tips' radii, metres.
    psi_drake : (P,) float
        Drake's signed distances, metres (the certificate asks for agreement).

    Returns
    -------
    certified : (P,) bool
        Pairs whose exact contact is certified; the other rows are not to be
        used.
    psi : (P,) float
        Signed distance, metres.
    p_OCa, p_OCb : (P, 3) float
        The object's and the tip's witness points, frame O.
    nhat_O : (P, 3) float
        The unit normal from the tip into the object, frame O (not yet
        cleaned of round-off components, see
        :func:`~drakegrasp.plant.contact_normals.clean_unit`).
    source : (P,) int
        Index into :data:`SOURCES`.
    """
    R, t, c = (np.asarray(a, dtype=float) for a in (R_OG, p_OG, c_O))
    r = np.asarray(radius, dtype=float)
    psi_drake = np.asarray(psi_drake, dtype=float)
    chunk = max(1, _CHUNK // len(dims.EA)) if kind == "Convex" else len(c)
    if len(c) > chunk:  # a hull of many edges: (pairs × edges) arrays in chunks
        parts = [
            sphere_tip_pairs(
                kind,
                dims,
                R[i : i + chunk],
                t[i : i + chunk],
                c[i : i + chunk],
                r[i : i + chunk],
                psi_drake[i : i + chunk],
            )  # fmt: skip
            for i in range(0, len(c), chunk)
        ]
        return tuple(np.concatenate(x) for x in zip(*parts, strict=True))
    sd, q, m_G = _project(kind, dims, _mtv(R, c - t))
    q_O = _mv(R, q) + t
    m = _mv(R, m_G)
    psi = sd - r
    p_b = c - r[:, None] * m
    n = -m
    tol = _CERTIFY_TOL
    with np.errstate(invalid="ignore", divide="ignore"):
        ok = np.all(np.isfinite(n), axis=1) & (np.abs(_norm(n) - 1.0) <= 1e-12)
        ok &= np.abs(psi - psi_drake) <= _DRAKE_AGREEMENT
        ok &= _norm(q_O - p_b - psi[:, None] * n) <= tol
        on_a = _project(kind, dims, _mtv(R, q_O - t))[0]
        ok &= np.abs(on_a) <= tol
        ok &= np.abs(_norm(p_b - c) - r) <= tol
        ok &= _support_value(kind, dims, R, t, -n) <= -_dot(n, q_O) + tol
        ok &= _dot(n, c) + r * _norm(n) <= _dot(n, p_b) + tol
    pieces = _pieces_at(kind, dims, _mtv(R, q_O - t))
    source = np.minimum(pieces, 3) - 1
    return ok, psi, q_O, p_b, n, source
