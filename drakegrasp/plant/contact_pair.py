"""The contact points of one touching geometry pair, in the object frame.

:func:`pair_points` turns Drake's answer for a pair (its witness points,
normal and ψ) into the pair's contact points: the corners of the patch when a
flat pad lies on a flat face or the ends of the line along which a flat face
touches a cylinder's or capsule's side
(:mod:`~drakegrasp.plant.contact_patches`), else
the exact contact (:mod:`~drakegrasp.plant.exact_contact`), else Drake's
witness points with the normal that
:func:`~drakegrasp.plant.contact_normals.choose_normal` picks.
:func:`drakegrasp.plant.contacts.find_contacts` runs the query loop and turns
each :class:`PairPoint` into a :class:`~drakegrasp.PlantContact`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import Capsule, Cylinder, Sphere
from pydrake.math import RigidTransform

from drakegrasp.errors import NoContactsError, PenetrationError
from drakegrasp.plant._shapes import EXACT_SURFACE_TOL, ON_SURFACE_TOL, surface_pieces
from drakegrasp.plant.contact_normals import (
    choose_normal,
    clean_unit,
    normal_source,
)
from drakegrasp.plant.contact_patches import (
    PATCH_ANGLE_TOL,
    line_vertices,
    patch_vertices,
)
from drakegrasp.plant.exact_contact import closest_pair
from drakegrasp.plant.shape_queries import PosedShape
from drakegrasp.plant.sphere_tips import (
    SOURCES,
    clean_rows,
    shape_key,
    sphere_tip_pairs,
    transform_rows,
)

__all__ = [
    "PairPoint",
    "PendingPair",
    "StagedContacts",
    "dedupe_contacts",
    "pair_points",
    "pending_pair",
    "resolve_pairs",
]


@dataclass(frozen=True)
class PairPoint:
    """One contact point of a geometry pair, frame O (the object body's).

    Attributes
    ----------
    p_OC : (3,) float
        The point on the object's surface, metres.
    nhat_O : (3,) float
        Unit normal into the object.
    psi : float
        Signed distance, metres.
    p_OF : (3,) float
        The finger's touching point, metres, frame O.
    normal_source : str
        As in :class:`~drakegrasp.PlantContact` (``normal_source``).
    patch_vertex : int or None
        Index among the patch's corners, or None for a point contact.
    exact : bool
        Computed exactly (a patch corner or a certified exact contact).
    """

    p_OC: np.ndarray
    nhat_O: np.ndarray
    psi: float
    p_OF: np.ndarray
    normal_source: str
    patch_vertex: int | None
    exact: bool


def _rotation(X) -> np.ndarray:
    return X.rotation().matrix()


def pair_points(
    *,
    query,
    inspector,
    go,
    gf,
    p_GaCa: np.ndarray,
    p_GbCb: np.ndarray,
    nhat_W: np.ndarray,
    psi: float,
    to_O,
    R_OW: np.ndarray,
    tol: float,
    patches: str,
) -> list[PairPoint]:
    """The contact points of the pair (object geometry ``go``, finger ``gf``).

    Parameters
    ----------
    query, inspector
        The scene graph's query object and its inspector.
    go, gf : GeometryId
        The object's and the finger's geometry.
    p_GaCa, p_GbCb : (3,) float
        Drake's witness points, each in its geometry's frame.
    nhat_W : (3,) float
        Drake's normal from the finger into the object, world frame.
    psi : float
        Drake's signed distance, metres.
    to_O : callable
        Maps a world point to frame O.
    R_OW : (3, 3) float
        Rotation of the world in O.
    tol : float
        The distance tolerance, metres (a patch keeps the part within it).
    patches : {"vertices", "witness"}
        Whether a flat pad on a flat face gives its patch's corners.

    Returns
    -------
    list of PairPoint
    """
    X_WGa = query.GetPoseInWorld(go)
    X_WGb = query.GetPoseInWorld(gf)
    R_OGa = R_OW @ _rotation(X_WGa)
    R_OGb = R_OW @ _rotation(X_WGb)
    p_OCa = to_O(X_WGa.multiply(p_GaCa))
    p_OCb = to_O(X_WGb.multiply(p_GbCb))
    obj_pieces = _pieces_in(inspector, go, p_GaCa)
    fin_pieces = _pieces_in(inspector, gf, p_GbCb)
    if patches == "vertices":
        for po in obj_pieces:
            if po.polygon_G is None:
                continue
            m_O = R_OGa @ po.normal_G  # object's outward face normal
            for pf in fin_pieces:
                if pf.polygon_G is None:
                    continue
                f_O = R_OGb @ pf.normal_G  # finger's outward face normal
                if m_O @ f_O > -np.cos(PATCH_ANGLE_TOL):
                    continue
                poly_obj = _to_O_points(po.polygon_G, X_WGa, to_O)
                poly_fin = _to_O_points(pf.polygon_G, X_WGb, to_O)
                n_O = clean_unit(-m_O)
                verts = patch_vertices(
                    n_O=n_O,
                    poly_obj_O=poly_obj,
                    poly_fin_O=poly_fin,
                    plane_point_obj_O=poly_obj[0],
                    finger_normal_O=f_O,
                    plane_point_fin_O=poly_fin[0],
                    tol=tol,
                )
                if len(verts) >= 2:
                    return [
                        PairPoint(p, n_O, gap, p - gap * n_O, "patch", k, True)
                        for k, (p, gap) in enumerate(verts)
                    ]
        line = _line_points(
            inspector,
            (go, obj_pieces, X_WGa, R_OGa),
            (gf, fin_pieces, X_WGb, R_OGb),
            to_O,
            tol,
            psi,
        )
        if line:
            return line
    exact = closest_pair(
        PosedShape(inspector.GetShape(go), R_OGa, to_O(X_WGa.translation())),
        PosedShape(inspector.GetShape(gf), R_OGb, to_O(X_WGb.translation())),
        p_a=p_OCa,
        p_b=p_OCb,
        nhat=R_OW @ nhat_W,
        psi=psi,
    )
    if exact is not None:
        n_O = clean_unit(exact.nhat_O)
        psi, p_OCa, p_OCb = exact.psi, exact.p_OCa, exact.p_OCb
        source = normal_source(
            obj=surface_pieces(
                inspector.GetShape(go),
                _to_G(X_WGa, to_O, p_OCa, R_OGa),
                tol=EXACT_SURFACE_TOL,
            ),
            fin=surface_pieces(
                inspector.GetShape(gf),
                _to_G(X_WGb, to_O, p_OCb, R_OGb),
                tol=EXACT_SURFACE_TOL,
            ),
        )
    else:  # no certified exact contact: Drake's witness points
        n_O, source = choose_normal(
            obj=[-(R_OGa @ p.normal_G) for p in obj_pieces],
            obj_flat=all(p.polygon_G is not None for p in obj_pieces),
            fin=[R_OGb @ p.normal_G for p in fin_pieces],
            fin_flat=all(p.polygon_G is not None for p in fin_pieces),
            witness=p_OCa - p_OCb,
            psi=psi,
            drake=R_OW @ nhat_W,
        )
        n_O = clean_unit(n_O)
    return [PairPoint(p_OCa, n_O, psi, p_OCb, source, None, exact is not None)]


def _round_side(shape, pieces) -> tuple[float, float] | None:
    """(radius, half length) of a cylinder's or capsule's straight side.

    None unless ``shape`` is one and a surface piece at the witness point is
    its side or, for a witness that a slight tilt moved off the side, a
    piece within :data:`~drakegrasp.plant.contact_patches.PATCH_ANGLE_TOL` of
    it (a cylinder's rim, a capsule's hemisphere near its equator); a
    cylinder's flat cap alone is not.
    """
    if not isinstance(shape, Cylinder | Capsule) or not pieces:
        return None
    if not any(
        p.polygon_G is None and abs(p.normal_G[2]) <= np.sin(PATCH_ANGLE_TOL)
        for p in pieces
    ):
        return None
    return float(shape.radius()), 0.5 * float(shape.length())


LINE_PSI_TOL = 1e-4
"""Largest difference (m) between a line's nearest end and Drake's ψ for the
pair, past which the line is not the pair's contact (Drake's own ψ is within
0.05 mm on a box on a cylinder or capsule: the Contacts guide)."""


def _line_points(inspector, obj, fin, to_O, tol: float, psi: float) -> list[PairPoint]:
    """A flat face along a cylinder's (capsule's) side: the ends of the line.

    ``obj`` and ``fin`` are each ``(geometry, pieces at the witness, X_WG,
    R_OG)``.  Either may be the round one (an object cylinder between flat
    pads, or a finger's cylindrical link on a box's face).  Each end's normal
    is the object's (the round side's across its axis, or the flat face's)
    and its ``ψ`` the distance along it to the other surface.  Empty when the
    pair is not such a line contact
    (:func:`~drakegrasp.plant.contact_patches.line_vertices`), or the line's
    nearest end is not where Drake's ``psi`` says the pair is closest.
    """
    for round_, flat, round_is_object in ((obj, fin, True), (fin, obj, False)):
        g_round, pieces_round, X_round, R_round = round_
        side = _round_side(inspector.GetShape(g_round), pieces_round)
        if side is None:
            continue
        _, pieces_flat, X_flat, R_flat = flat
        axis = R_round[:, 2]
        for piece in pieces_flat:
            if piece.polygon_G is None:
                continue
            w = clean_unit(R_flat @ piece.normal_G)  # towards the round body
            ends = line_vertices(
                face_normal_O=w,
                poly_face_O=_to_O_points(piece.polygon_G, X_flat, to_O),
                axis_O=axis,
                centre_O=to_O(X_round.translation()),
                radius=side[0],
                half_length=side[1],
                tol=tol,
            )
            if len(ends) != 2 or abs(min(g for _, g in ends) - psi) > LINE_PSI_TOL:
                continue
            if round_is_object:
                # the side's inward normal: w across the axis; psi along it
                n_O = clean_unit(w - (w @ axis) * axis)
                cos = float(w @ n_O)
                return [
                    PairPoint(p, n_O, g / cos, p - (g / cos) * n_O, "line", k, True)
                    for k, (p, g) in enumerate(ends)
                ]
            # the object's face below the finger's line, its normal -w
            return [
                PairPoint(p - g * w, -w, g, p, "line", k, True)
                for k, (p, g) in enumerate(ends)
            ]
    return []


def _pieces_in(inspector, gid, p_GC: np.ndarray):
    return surface_pieces(inspector.GetShape(gid), p_GC)


def _to_G(X_WG, to_O, p_O: np.ndarray, R_OG: np.ndarray) -> np.ndarray:
    """A point from the object frame O to the geometry frame G."""
    return R_OG.T @ (p_O - to_O(X_WG.translation()))


def _to_O_points(poly_G: np.ndarray, X_WG, to_O) -> np.ndarray:
    """Polygon vertices from a geometry frame to the object frame."""
    return np.array([to_O(X_WG.multiply(p)) for p in poly_G])


# --- pairs read now, their points computed later in one batch ------------------------


class _PosesAt:
    """The two geometry poses a pair's query gave, for the scalar route later."""

    def __init__(self, poses: dict):
        self._poses = poses

    def GetPoseInWorld(self, gid):  # noqa: N802 (QueryObject's name)
        return self._poses[gid]


class PendingPair:
    """A touching pair read from Drake, its points still to come.

    Made by :func:`pending_pair` while the query object describes the pair's
    configuration; :func:`resolve_pairs` fills ``points`` (a spherical tip
    on a box, cylinder, sphere or hull in one vectorised batch with every
    other such pair, anything else at once by :func:`pair_points`).
    """

    __slots__ = ("_read", "points", "tip")

    def __init__(self, read: tuple, tip: tuple | None):
        self._read = read
        self.tip = tip
        self.points: list[PairPoint] | None = None

    @property
    def args(self) -> dict:
        """The keyword arguments of :func:`pair_points` for this pair."""
        inspector, go, gf, r, swapped, psi, X_OW, R_OW, poses, tol, patches = self._read
        if swapped:  # Drake's pair (finger, object): its normal into the finger
            p_GaCa, p_GbCb, nhat_W = r.p_BCb, r.p_ACa, -r.nhat_BA_W
        else:
            p_GaCa, p_GbCb, nhat_W = r.p_ACa, r.p_BCb, r.nhat_BA_W

        def to_O(p_W):
            return np.asarray(X_OW.multiply(p_W))

        return dict(
            query=_PosesAt(poses),
            inspector=inspector,
            go=go,
            gf=gf,
            p_GaCa=np.asarray(p_GaCa),
            p_GbCb=np.asarray(p_GbCb),
            nhat_W=np.asarray(nhat_W),
            psi=psi,
            to_O=to_O,
            R_OW=R_OW,
            tol=tol,
            patches=patches,
        )


def pending_pair(
    *,
    query,
    inspector,
    go,
    gf,
    pair,
    swapped: bool,
    X_OW,
    tol: float,
    patches: str,
    cache: dict | None = None,
    frame: dict | None = None,
) -> PendingPair:
    """Read the pair (object geometry ``go``, finger ``gf``) from the query now.

    ``pair`` is Drake's ``SignedDistancePair``, ``swapped`` True when its
    ``A`` is the finger's geometry; ``X_OW`` maps the world to the object
    frame; ``tol`` and ``patches`` are those of :func:`pair_points`.  The
    points are those :func:`pair_points` returns (to round-off, 1e-12 m, for
    a spherical tip, whose closed form runs over arrays in
    :mod:`~drakegrasp.plant.sphere_tips`), once :func:`resolve_pairs` ran.
    ``cache`` (kept by the caller across calls on one scene graph) holds the
    geometries' shapes; ``frame`` (kept for one configuration, with ``X_OW``
    and its rotation ``R_OW``) the object geometries' poses.
    """
    cache = {} if cache is None else cache
    frame = {"X_OW": X_OW, "R_OW": _rotation(X_OW)} if frame is None else frame
    R_OW = frame["R_OW"]
    # copies: the query's poses are views of its state, which the next
    # configuration overwrites
    if ("X_WG", go) not in frame:
        X_WGa = RigidTransform(query.GetPoseInWorld(go))
        frame["X_WG", go] = X_WGa
        frame["pose", go] = (
            R_OW @ _rotation(X_WGa),
            np.asarray(X_OW.multiply(X_WGa.translation())),
        )
    X_WGb = RigidTransform(query.GetPoseInWorld(gf))
    read = (
        inspector, go, gf, pair, swapped, float(pair.distance), X_OW, R_OW,
        {go: frame["X_WG", go], gf: X_WGb}, tol, patches,
    )  # fmt: skip
    tip = cache.get(("tip", go, gf), False)
    if tip is False:
        fin = inspector.GetShape(gf)
        key = shape_key(inspector.GetShape(go)) if isinstance(fin, Sphere) else None
        tip = cache["tip", go, gf] = None if key is None else (key, fin.radius())
    if tip is None:
        pending = PendingPair(read, None)
        pending.points = pair_points(**pending.args)
        return pending
    R_OGa, p_OGa = frame["pose", go]
    if "p_OW" not in frame:
        frame["p_OW"] = np.array(X_OW.translation())
    tip_W = np.array(X_WGb.translation())  # the tip's centre, to O in the batch
    return PendingPair(read, (tip[0], R_OGa, p_OGa, tip_W, tip[1], R_OW, frame["p_OW"]))


def resolve_pairs(pending) -> None:
    """Compute the points of every unresolved :class:`PendingPair`, in batches."""
    groups: dict[tuple, list[PendingPair]] = {}
    for p in pending:
        if p.points is None:
            kind, dims = p.tip[0]
            groups.setdefault((kind, dims), []).append(p)
    for (kind, dims), rows in groups.items():
        ok, psi, p_a, p_b, n, source = sphere_tip_pairs(
            kind,
            dims,
            np.array([p.tip[1] for p in rows]),
            np.array([p.tip[2] for p in rows]),
            transform_rows(
                np.array([p.tip[5] for p in rows]),
                np.array([p.tip[6] for p in rows]),
                np.array([p.tip[3] for p in rows]),
            ),
            np.array([p.tip[4] for p in rows]),
            np.array([p._read[5] for p in rows]),
        )
        n = clean_rows(n)
        psi = psi.tolist()
        for k, p in enumerate(rows):
            if not ok[k]:  # the scalar route decides (Drake's witness then)
                p.points = pair_points(**p.args)
                continue
            p.points = [
                PairPoint(p_a[k], n[k], psi[k], p_b[k], SOURCES[source[k]], None, True)
            ]


class StagedContacts:
    """One configuration's touching pairs, read from Drake, points pending.

    :func:`~drakegrasp.plant.contacts.stage_contacts` reads everything the
    contacts need from the query object and the plant while they describe the
    configuration;
    :func:`~drakegrasp.plant.contacts.resolve_staged` computes the points of
    many staged configurations in one batch (a planner stages each closed
    candidate and resolves them all at once);
    :func:`~drakegrasp.plant.contacts.staged_contacts` then gives what
    :func:`~drakegrasp.plant.contacts.contacts_of_distances` returns, or
    raises what it raises.
    """

    def __init__(self, object_name, tol, allow_penetration, closest, items, inspector):
        self.object_name = object_name
        self.tol = tol
        self.allow_penetration = allow_penetration
        self.closest = closest  # (ψ, finger body's name, GeometryId) or None
        self.items = items  # ("penetration", message) or ("pair", ...)
        self.inspector = inspector

    def pending(self):
        """The staged pairs (:class:`~drakegrasp.plant.contact_pair.PendingPair`)."""
        return [it[1] for it in self.items if it[0] == "pair"]

    def rows(self) -> list[tuple]:
        """``(PairPoint, X_FO, fields)`` of every contact point, once resolved.

        In :func:`~drakegrasp.find_contacts`' order, before duplicates are
        dropped; ``fields`` are the pair's :class:`~drakegrasp.PlantContact`
        fields other than the point's.

        Raises
        ------
        NoContactsError, PenetrationError
            As :func:`~drakegrasp.find_contacts`.
        """
        tol = self.tol
        rows: list[tuple] = []
        penetrations: list[str] = []
        for item in self.items:
            if item[0] == "penetration":
                penetrations.append(item[1])
                continue
            _, pending, X_FO, common, where = item
            deepest = min(pp.psi for pp in pending.points)
            if deepest < -tol and not self.allow_penetration:  # a tilted patch
                go, finger, gf = where
                penetrations.append(
                    f"{self.object_name} ({self.inspector.GetName(go)}) and "
                    f"{self._finger_geom(finger, gf)} penetrate by "
                    f"{-deepest * 1e3:.4g} mm at a patch corner"
                )
                continue
            rows += [(pp, X_FO, common) for pp in pending.points]
        if penetrations:
            raise PenetrationError(
                f"penetration deeper than distance_tolerance = {tol:g} m: "
                + "; ".join(penetrations)
            )
        if not rows:
            if self.closest is None:
                raise NoContactsError(
                    "the hand has no collision geometry that can touch "
                    f"{self.object_name!r}"
                )
            psi, finger, gf = self.closest
            raise NoContactsError(
                f"the hand does not touch {self.object_name!r}: the closest finger "
                f"geometry is {self._finger_geom(finger, gf)} at {psi * 1e3:.4g} mm "
                f"(distance_tolerance {tol * 1e3:g} mm)"
            )
        return rows

    def _finger_geom(self, finger_name, gf) -> str:
        return f"{finger_name} ({self.inspector.GetName(gf)})"


def dedupe_contacts(contacts: list) -> list:
    """Drop a contact (``PlantContact``) that repeats a kept one of its finger body.

    Repeats: within ``ON_SURFACE_TOL`` (1e-5 m) and with normals within 1e-9 of
    each other (two geometries of one body touching at one point).
    """
    if len(contacts) < 2:
        return list(contacts)
    P = np.array([c.p_OC for c in contacts])
    N = np.array([c.nhat_O for c in contacts])
    body = np.array([int(c.finger_body_index) for c in contacts])
    gap = P[:, None, :] - P[None, :, :]
    same = (
        (body[:, None] == body[None, :])
        & (np.sqrt(np.sum(gap * gap, axis=2)) < ON_SURFACE_TOL)
        & (N @ N.T > 1 - 1e-9)
    )
    np.fill_diagonal(same, False)
    if not same.any():
        return list(contacts)
    kept: list[int] = []
    for i in range(len(contacts)):
        if not same[i, kept].any():
            kept.append(i)
    return [contacts[i] for i in kept]
