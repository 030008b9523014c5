r"""Ferrari–Canny ε: primitive wrenches, convex hulls and the L∞ normal fan.

See :func:`ferrari_canny`.  The L1 form is one Qhull hull; the L∞ form uses
the normal fan of a Minkowski sum (see ``_linf_radius``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.friction_cone import friction_cone_generators
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS, L1_MAX_POINTS
from drakegrasp.core.validation import check_num_generators, describe, plain_str
from drakegrasp.errors import InvalidOptionError, SolverError
from drakegrasp.quality._common import (
    RANK_TOL,
    _check_grasp,
    _scaled_grasp_matrix,
    _torque_scale,
    grasp_extent,
)

if TYPE_CHECKING:
    from scipy.spatial import ConvexHull

__all__ = [
    "HULL_TOL",
    "L1_MAX_POINTS",
    "LINF_MAX_CANDIDATES",
    "ferrari_canny",
    "hull_point_nearest_origin",
    "primitive_wrenches",
]

HULL_TOL = 1e-9
"""Relative tolerance (times the largest coordinate) of the hull checks."""

LINF_MAX_CANDIDATES = 2_000_000
"""Most candidate facet normals the L∞ ε may test (about 6 s per million)."""

_NORMS = ("L1", "Linf")


@checked_call
def primitive_wrenches(
    grasp: Grasp,
    *,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    torque_scale: float | None = None,
) -> tuple[np.ndarray, ...]:
    r"""Wrenches of the friction-cone generators of each contact.

    Parameters
    ----------
    grasp : Grasp
    num_generators : int, optional
        Generators ``n_g`` of each spatial Coulomb cone (default 8).
    torque_scale : float, optional
        Length ``b_s`` (metres) by which moments are divided; default the
        grasp's characteristic length, ``1.0`` for unscaled moments.
        An explicit length must be in ``[2.2e-308, 1e30]`` m with the grasp's
        extent (the largest distance from ``p`` to a contact) over it in
        ``[1e-4, 1e12]`` (any length when every contact is at ``p``), else
        :class:`~drakegrasp.InvalidOptionError`.

    Returns
    -------
    wrenches : tuple of (m_i, 6) or (m_i, 3) float
        For contact ``i``, row ``k`` is the scaled wrench ``S G_i s_k`` of its
        ``k``-th generator ``s_k`` (contact frame), in the grasp frame about
        ``p``.  Every generator has unit normal component, so these are the
        wrenches of contact forces with ``f_n = 1``.  A frictionless contact
        (or a hard finger with ``mu = 0``) has one row, a planar hard finger
        two, a spatial hard finger ``n_g``, a soft finger ``n_g + 2``.

    Notes
    -----
    .. math:: w_{i,k} = S\, G_i\, s_k, \qquad S = \operatorname{diag}(I, I / b_s)
    """
    _check_grasp(grasp)
    num_generators = check_num_generators(num_generators)
    return _wrenches(grasp, num_generators, _torque_scale(grasp, torque_scale))


def _wrenches(grasp: Grasp, num_generators: int, b: float) -> tuple[np.ndarray, ...]:
    """:func:`primitive_wrenches` of checked arguments, moments over ``b``."""
    if not grasp.planar and all(
        c.effective_components() == (0, 1, 2) for c in grasp.contacts
    ):
        return _hard_finger_wrenches(grasp, num_generators, b)
    G = _scaled_grasp_matrix(grasp, b)
    out = []
    for contact, sl in zip(grasp.contacts, grasp.component_slices(), strict=True):
        S = friction_cone_generators(
            contact, num_generators, characteristic_length=grasp.characteristic_length
        )
        out.append((G[:, sl] @ S).T.copy())
    return tuple(out)


@functools.lru_cache(maxsize=16)
def _unit_circle(n_g: int) -> tuple[np.ndarray, np.ndarray]:
    angles = 2.0 * np.pi * np.arange(1, n_g + 1) / n_g
    return np.cos(angles), np.sin(angles)


def _hard_finger_wrenches(
    grasp: Grasp, num_generators: int, b: float
) -> tuple[np.ndarray, ...]:
    """Vectorised :func:`primitive_wrenches` for spatial hard fingers (mu > 0).

    The generators are those of ``docs/conventions.md`` (``s_k = [1, μ cos(2πk/n_g),
    μ sin(2πk/n_g)]`` in the contact frame); a test checks that they equal
    :func:`~drakegrasp.friction_cone_generators`.
    """
    n_g = check_num_generators(num_generators)
    R = np.array([c.frame for c in grasp.contacts])  # (N, 3, 3) columns n, t1, t2
    mu = np.array([c.mu for c in grasp.contacts])
    r = np.array([c.position for c in grasp.contacts]) - grasp.reference_point
    cos, sin = _unit_circle(n_g)
    # Force directions R_i s_k, (N, n_g, 3).
    forces = R[:, None, :, 0] + mu[:, None, None] * (
        cos[None, :, None] * R[:, None, :, 1] + sin[None, :, None] * R[:, None, :, 2]
    )
    W = np.empty(forces.shape[:2] + (6,))
    W[:, :, :3] = forces
    rx, ry, rz = (r[:, i, None] / b for i in range(3))
    fx, fy, fz = forces[:, :, 0], forces[:, :, 1], forces[:, :, 2]
    W[:, :, 3] = ry * fz - rz * fy
    W[:, :, 4] = rz * fx - rx * fz
    W[:, :, 5] = rx * fy - ry * fx
    return tuple(W)


def _qhull(points: np.ndarray, scale: float) -> ConvexHull:
    """Convex hull of full-dimensional points, fast when the input allows it.

    First Qhull runs with ``Q0`` (no facet merging), about three times faster
    than the default merging options in 5-D and 6-D; its answer is accepted
    only if every point lies below every facet hyperplane (within
    ``HULL_TOL * scale``).  Qhull keeps the facets a closed surface, so facets
    that all support the point set are the hull's boundary.  Otherwise (or if
    Qhull reports a precision error) it runs again with its default merging
    for 5-D and up, ``Qx``, plus ``Qs`` (search every point for the initial
    simplex, which symmetric wrench sets need), and as a last resort with
    joggled input ``QJ`` (which perturbs the points by about 1e-11 relative,
    far below any quality we report).
    """
    # scipy.spatial is imported on first use: it costs 0.4 s of `import drakegrasp`.
    from scipy.spatial import ConvexHull, QhullError

    tol = HULL_TOL * max(scale, 1e-300)
    try:
        hull = ConvexHull(points, qhull_options="Q0")
        if _below_every_facet(points, hull.equations, tol):
            return hull
    except QhullError:
        pass
    try:
        return ConvexHull(points, qhull_options="Qx Qs")
    except QhullError:
        pass
    try:
        return ConvexHull(points, qhull_options="QJ")
    except QhullError as err:  # pragma: no cover - Qhull's last resort failed
        raise SolverError(
            f"Qhull could not build the convex hull of {points.shape[0]} points in "
            f"{points.shape[1]}-D: {err}"
        ) from err


def _below_every_facet(points: np.ndarray, eq: np.ndarray, tol: float) -> bool:
    """Whether every point is below every facet hyperplane, in bounded memory.

    A thousand contacts make a hull of about 10^6 facets: the full
    points-by-facets product would take 57 GiB, so facets go in blocks of
    about 8 million products.
    """
    block = max(1, 8_000_000 // max(1, points.shape[0]))
    for lo in range(0, eq.shape[0], block):
        part = eq[lo : lo + block]
        if np.max(points @ part[:, :-1].T + part[:, -1]) > tol:
            return False
    return True


def hull_point_nearest_origin(
    points: np.ndarray, rho: float = 1.0
) -> np.ndarray | None:
    r"""The point of ``conv(points)`` nearest the origin, as NNLS proposes it.

    Lawson–Hanson NNLS on ``min ‖Pᵀλ‖² + ρ²(1ᵀλ - 1)²``, ``λ >= 0`` (tens of
    microseconds for a few hundred points) gives ``y = Pᵀλ / 1ᵀλ``.  Not
    certified: scipy 1.15's ``nnls`` stops short of the optimum on some
    inputs, so a caller trusts ``y`` only through a check of its own (a
    separating plane, a bound that errs on the safe side).

    Parameters
    ----------
    points : (K, n) float
        The points, one a row (trusted: finite, ``K >= 1``).
    rho : float, optional
        Weight of the constraint ``1ᵀλ = 1`` (the points' scale).

    Returns
    -------
    (n,) float or None
        ``y``; None where NNLS reached its iteration limit or gave ``λ = 0``.
    """
    A = np.vstack([points.T, np.full((1, points.shape[0]), rho)])
    rhs = np.zeros(points.shape[1] + 1)
    rhs[-1] = rho
    try:
        # Imported here: scipy.optimize alone doubles `import drakegrasp`'s time.
        from scipy.optimize import nnls

        lam = nnls(A, rhs)[0]
    except RuntimeError:  # the iteration limit
        return None
    total = float(np.sum(lam))
    if not total > 0.0:
        return None
    return points.T @ lam / total


def _separated_from_origin(points: np.ndarray, scale: float) -> bool:
    r"""Whether a checked hyperplane separates the origin from ``conv(points)``.

    Lawson–Hanson NNLS on ``min ‖Pᵀλ‖² + ρ²(1ᵀλ - 1)²``, ``λ >= 0`` (tens of
    microseconds for ``K`` points) proposes ``y = Pᵀλ / 1ᵀλ``, the hull's point
    nearest the origin; the answer is trusted only through its certificate:
    every point ``x`` with ``x·y > HULL_TOL · scale · ‖y‖`` puts the whole hull
    strictly beyond the plane ``x·y = 0``, so the origin is outside and ε = 0
    without Qhull.  Otherwise (the origin inside or on the hull, a wrong NNLS
    answer — scipy 1.15's ``nnls`` stops short of the optimum on some inputs,
    the last release for Python 3.10 —, or its iteration limit) Qhull decides.
    """
    rho = max(scale, 1e-300)
    y = hull_point_nearest_origin(points, rho)
    if y is None:  # iteration limit: let Qhull decide
        return False
    norm = float(np.linalg.norm(y))
    return bool(norm > 0.0 and np.min(points @ y) > HULL_TOL * rho * norm)


FLAT_TOL = 1e-14
"""Relative singular value below which a wrench set counts as flat (no interior).

Wrench sets of thin cones (``μ = 1e-12``) are full-dimensional with singular
values ratios near 1e-12; round-off leaves ratios near 1e-16.
"""


def _whitening(points: np.ndarray) -> np.ndarray | None:
    """``A`` (D, D) with ``points @ A.T`` well conditioned; None if flat.

    ``A = diag(1/s) Vᵀ`` from the SVD ``points = U S Vᵀ``, so the mapped points
    are ``U`` (orthonormal columns).  A linear map keeps the origin, convex
    hulls and Minkowski sums, and maps a facet ``n'·x' + o' <= 0`` of the mapped
    set to the facet ``(Aᵀ n')·x + o' <= 0`` of the original one, so ε can be
    computed in the mapped coordinates and measured in the original ones.
    This keeps ε accurate for thin cones (``μ`` down to 1e-12: the wrench set is
    then ``μ`` thin in four directions) and for very long soft-finger torsion
    generators (``ν`` up to 1e12), where Qhull on the raw points returned 0.
    """
    _, s, vt = np.linalg.svd(points, full_matrices=False)
    if s.size < points.shape[1] or not s[-1] > FLAT_TOL * s[0]:
        return None
    return vt / s[:, None]


def _hull_input(points: np.ndarray, A: np.ndarray | None = None):
    """``(X, scale, A)`` for Qhull, or None when the ball's radius is 0 without it.

    The cheap tests of :func:`_ball_radius` (no Qhull): too few points, all
    zero, a wrench set of lower dimension than the space, a hull that does
    not contain the origin (a separating plane proposed by NNLS and checked,
    see :func:`_separated_from_origin`) or whose affine hull is
    lower-dimensional than the space.  ``X = points @ A.T`` are the whitened
    points (see :func:`_whitening`) and ``scale`` their largest coordinate.
    """
    num, dim = points.shape
    if num <= dim or not np.any(points):
        return None
    if A is None:
        A = _whitening(points)
        if A is None:
            return None  # the points span less than the wrench space
    X = points @ A.T
    scale = float(np.max(np.abs(X)))
    if _separated_from_origin(X, scale):
        return None  # the origin is outside the hull: no hull needed
    s = np.linalg.svd(X - X.mean(axis=0), compute_uv=False)
    if s[-1] <= RANK_TOL * max(s[0], scale):
        return None  # flat hull: no interior
    return X, scale, A


def _ball_radius(points: np.ndarray, A: np.ndarray | None = None) -> float:
    """Radius of the largest origin-centred ball in ``conv(points)``; 0 if none.

    Qhull is called only when needed (see :func:`_hull_input` for the cases
    settled without it).  Everything runs on the whitened points (see
    :func:`_whitening`); the facets are measured in the original coordinates.
    """
    found = _hull_input(points, A)
    if found is None:
        return 0.0
    X, scale, A = found
    eq = _qhull(X, scale).equations
    # Unit outward normals n' and offsets o' in whitened coordinates: the hull
    # is {x : (Aᵀ n')·x + o' <= 0}; the origin's distance to each facet's
    # hyperplane is -o' / |Aᵀ n'|.
    normals = eq[:, :-1] @ A
    radius = float(np.min(-eq[:, -1] / np.linalg.norm(normals, axis=1)))
    return radius if radius > 0.0 else 0.0


def _face_directions(points: np.ndarray) -> dict[int, np.ndarray]:
    """Direction spaces of the faces of ``conv(points)``, grouped by dimension.

    ``points`` must contain the origin (a per-contact set ``{0} ∪ {w_ik}``), so
    the polytope's affine span is the linear span of its points.

    Returns
    -------
    dict
        ``j -> (n_j, j, D)``: an orthonormal basis (rows) of the direction space
        of each ``j``-dimensional face, ``1 <= j <= m`` (``m`` the polytope's
        dimension; the one ``m``-face is the polytope itself).  Vertices
        (``j = 0``) have no direction and are left out.

    Notes
    -----
    Facets come from Qhull (default merging options, so coplanar triangles of a
    facet share one hyperplane) in ``m``-D coordinates; every face of a polytope
    is an intersection of facets, so the faces are the closure of the facets'
    vertex sets under intersection.
    """
    # scipy.spatial is imported on first use: it costs 0.4 s of `import drakegrasp`.
    from scipy.spatial import ConvexHull, QhullError

    scale = float(np.max(np.abs(points)))
    _, s, vt = np.linalg.svd(points, full_matrices=False)
    m = int(np.sum(s > RANK_TOL * max(s[0], scale)))
    out = {m: vt[None, :m]}
    if m < 2:
        return out
    coords = points @ vt[:m].T
    try:
        hull = ConvexHull(coords)
    except QhullError:  # symmetric sets may need a search for the first simplex
        hull = ConvexHull(coords, qhull_options="Qx Qs")
    verts = hull.vertices
    tol = HULL_TOL * float(np.max(np.abs(coords)))
    facets = set()
    for eq in hull.equations:
        on = verts[np.abs(coords[verts] @ eq[:-1] + eq[-1]) <= tol]
        facets.add(frozenset(on.tolist()))
    faces, frontier = set(facets), set(facets)
    while frontier:
        frontier = {a & f for a in frontier for f in facets if a & f} - faces
        faces |= frontier
    by_dim: dict[int, list[np.ndarray]] = {}
    for face in faces:
        idx = sorted(face)
        if len(idx) < 2:
            continue
        _, sf, vtf = np.linalg.svd(points[idx[1:]] - points[idx[0]])
        j = int(np.sum(sf > RANK_TOL * max(sf[0], scale)))
        if 0 < j < m:
            by_dim.setdefault(j, []).append(vtf[:j])
    out.update({j: np.array(bases) for j, bases in by_dim.items()})
    return out


def _cofactor_normals(M: np.ndarray) -> np.ndarray:
    """Normals of the hyperplanes spanned by the rows of ``M`` (n, D-1, D).

    ``u_j = (-1)^j det(M without column j)`` is orthogonal to every row, and
    ``‖u‖ = sqrt(det(M Mᵀ))`` (0 when the rows are dependent).
    """
    D = M.shape[2]
    u = np.empty((M.shape[0], D))
    for j in range(D):
        cols = [k for k in range(D) if k != j]
        u[:, j] = (-1.0) ** j * np.linalg.det(M[:, :, cols])
    return u


def _support_min(U: np.ndarray, wrenches: Sequence[np.ndarray]) -> float:
    """``min over rows u of U (unit) and ±u`` of ``h(u) = Σ_i max(0, max_k u·w_ik)``."""
    hp = np.zeros(U.shape[0])
    hm = np.zeros(U.shape[0])
    for W in wrenches:
        V = U @ W.T
        hp += np.maximum(V.max(axis=1), 0.0)
        hm += np.maximum(-V.min(axis=1), 0.0)
    return float(min(hp.min(), hm.min()))


def _face_tuples(families, target: int, exact: bool):
    """Yield ``(parts, shape)`` for every choice of one face per contact.

    ``families[i]`` maps a face dimension to bases (see
    :func:`_face_directions`); a contact may also contribute a vertex (no
    direction).  The total dimension is ``target`` (``exact``) or at least
    ``target``.  Choices are built contact by contact and a partial choice whose
    total already exceeds an exact target is dropped, so the work is
    proportional to the choices kept, never to the ``∏ (faces + 1)`` of all
    combinations (``4^40`` for 40 contacts).
    """
    choices = [[0, *sorted(f)] for f in families]
    n = len(choices)
    # Largest total the remaining contacts can still add.
    room = [0] * (n + 1)
    for i in range(n - 1, -1, -1):
        room[i] = room[i + 1] + max(choices[i])

    def walk(i, total, combo):
        if exact and total > target:
            return
        if total + room[i] < target:
            return
        if i == n:
            parts = [(k, j) for k, j in enumerate(combo) if j > 0]
            yield parts, [families[k][j].shape[0] for k, j in parts]
            return
        for j in choices[i]:
            combo.append(j)
            yield from walk(i + 1, total + j, combo)
            combo.pop()

    yield from walk(0, 0, [])


def _face_counts(families) -> list[dict[int, int]]:
    """Faces of each dimension of each summand (from :func:`_face_directions`)."""
    return [{j: int(bases.shape[0]) for j, bases in f.items()} for f in families]


def _candidate_count(counts, target: int, exact: bool) -> int:
    """Number of candidate normals, by polynomial products (no enumeration).

    ``counts[i]`` maps a face dimension ``j`` to the number ``c_ij`` of faces
    of summand ``i`` (:func:`_face_counts`, :func:`_model_face_counts`).
    Contact ``i`` contributes ``1 + Σ_j c_ij x^j``; the coefficient of ``x^t``
    in the product counts the face choices of total dimension ``t`` weighted
    by their number of bases.
    """
    top = max(target, 1) + 1
    poly = [1] + [0] * top  # coefficient top collects every degree >= top
    for family in counts:
        term = [1] + [0] * top
        for j, count in family.items():
            term[min(j, top)] += count
        new = [0] * (top + 1)
        for a, pa in enumerate(poly):
            if pa:
                for b, tb in enumerate(term):
                    if tb:
                        new[min(a + b, top)] += pa * tb
        poly = new
    return poly[target] if exact else sum(poly[target:])


def _stacked_bases(families, parts, shape, lo, hi) -> np.ndarray:
    idx = np.unravel_index(np.arange(lo, hi), shape)
    return np.concatenate(
        [families[i][j][k] for (i, j), k in zip(parts, idx, strict=True)], axis=1
    )


def _too_many_candidates(total: int) -> InvalidOptionError:
    return InvalidOptionError(
        f"the L∞ Ferrari–Canny metric of this grasp needs {total} candidate "
        f"facet normals (more than LINF_MAX_CANDIDATES = {LINF_MAX_CANDIDATES});"
        " use norm='L1', fewer contacts or fewer generators"
    )


def _too_many_contacts(num: int, lower: int) -> InvalidOptionError:
    return InvalidOptionError(
        f"the L∞ Ferrari–Canny metric of {num} contacts needs at least "
        f"{lower} candidate facet normals (more than LINF_MAX_CANDIDATES = "
        f"{LINF_MAX_CANDIDATES}); use norm='L1' or fewer contacts"
    )


def _check_candidate_count(families, target: int, exact: bool) -> None:
    total = _candidate_count(_face_counts(families), target, exact)
    if total > LINF_MAX_CANDIDATES:
        raise _too_many_candidates(total)


MODEL_FRICTION = (1e-4, 1e2)
"""Friction coefficients (and soft fingers' ``b ν`` over the grasp's extent:
:data:`MODEL_TORSION`) for which :func:`_model_face_counts` trusts its counts.

Outside, thin or flat cones may lose faces to the rank tests of
:func:`_face_directions` (seen at ``μ = 1e-9``, at ``μ = 1e3`` with
``ν = 1e-6``), so the counts of the models could exceed the ones the metric
finds."""

MODEL_TORSION = (1e-4, 1e4)
"""Range of a soft finger's ``b ν`` over the grasp's extent (see
:data:`MODEL_FRICTION`)."""


def _model_face_counts(contact, num_generators: int, b: float, extent: float):
    """Faces per dimension of ``conv({0} ∪ {w_k})`` from the contact's model.

    ``G_i`` maps the contact's force components one to one into the wrench
    space, so the set is the cone's generators with the apex, up to a linear
    map: a segment (frictionless, or ``μ = 0`` without torsion), a triangle
    (a planar hard finger; a soft finger with ``μ = 0``), a pyramid over the
    ``n``-gon of generators (a spatial hard finger) or a pyramid over the
    bipyramid of the ``n``-gon and the two torsion generators (a soft
    finger).  None when the counts are not to be trusted (see
    :data:`MODEL_FRICTION`): the metric's own count decides then.
    """
    components = contact.effective_components()
    if components == (0,):
        return {1: 1}
    if 1 in components and not (MODEL_FRICTION[0] <= contact.mu <= MODEL_FRICTION[1]):
        return None
    if 3 in components:
        torsion = b * contact.torsional_friction / extent if extent > 0.0 else 0.0
        if not (MODEL_TORSION[0] <= torsion <= MODEL_TORSION[1]):
            return None
    n = num_generators
    if components in ((0, 1), (0, 3)):
        return {1: 3, 2: 1}
    if components == (0, 1, 2):
        return {1: 2 * n, 2: n + 1, 3: 1}
    if components == (0, 1, 2, 3):
        return {1: 4 * n + 2, 2: 5 * n, 3: 2 * n + 1, 4: 1}
    return None  # pragma: no cover - every contact model is listed above


def _linf_refusal(grasp: Grasp, num_generators: int) -> InvalidOptionError | None:
    """The refusal of an L∞ ε too costly to compute, from the models alone.

    Nothing is built: the lower bound ``C(N, D - 1)`` of :func:`_linf_radius`
    and the count of its first pass, from the faces of each contact's model
    (:func:`_model_face_counts`), are checked against
    :data:`LINF_MAX_CANDIDATES` with the messages :func:`_linf_radius` gives.
    None when neither exceeds it, or when some contact's counts are not to be
    trusted: :func:`_linf_radius` checks its own counts then.
    """
    D = grasp.wrench_dim
    lower = math.comb(grasp.num_contacts, D - 1)
    if lower > LINF_MAX_CANDIDATES:
        return _too_many_contacts(grasp.num_contacts, lower)
    extent = grasp_extent(grasp)
    counts = []
    for contact in grasp.contacts:
        count = _model_face_counts(
            contact, num_generators, grasp.characteristic_length, extent
        )
        if count is None:
            return None
        counts.append(count)
    total = _candidate_count(counts, D - 1, exact=True)
    return _too_many_candidates(total) if total > LINF_MAX_CANDIDATES else None


def _linf_radius(wrenches: Sequence[np.ndarray], A: np.ndarray | None = None) -> float:
    r"""ε of the Minkowski sum ``⊕_i conv({0} ∪ {w_ik})`` through its normal fan.

    Call only when the origin is strictly inside (ε_1 > 0).  Every facet of a
    Minkowski sum is a sum of faces ``F_i`` of the summands, and its normal is
    orthogonal to every ``dir(F_i)``.  Any unit ``u`` bounds
    ``ε = min_{‖u‖=1} h(u)`` from above, so the minimum of ``h`` over a set of
    directions that contains every facet normal is ε exactly:

    1. every choice of one face per summand (a vertex counts as dimension 0)
       with ``Σ dim F_i = D - 1`` and independent directions gives one normal
       (by cofactors).  If no such choice has dependent directions, every facet
       normal is among them: shrinking a facet's faces to sub-faces whose
       dimensions add up to ``D - 1`` gives a choice whose directions lie in the
       facet's hyperplane, so they either span it (its normal is found) or are
       dependent (which this step detects).
    2. otherwise (symmetric grasps) every choice with ``Σ dim F_i >= D - 1``
       whose directions span exactly ``D - 1`` dimensions gives one normal (by
       SVD); each facet is such a choice, with its own faces.
    """
    D = wrenches[0].shape[1]
    if A is None:
        A = np.eye(D)
    # Every summand has at least one edge, so there are at least C(N, D - 1)
    # candidates: refuse before building N face lattices (40 ms each).
    lower = math.comb(len(wrenches), D - 1)
    if lower > LINF_MAX_CANDIDATES:
        raise _too_many_contacts(len(wrenches), lower)
    mapped = [W @ A.T for W in wrenches]
    sets = [np.vstack([np.zeros((1, D)), W]) for W in mapped]
    families = [_face_directions(P) for P in sets]
    chunk = 100_000

    def support_min(U):
        # Candidate normals in whitened coordinates map to U @ A originally.
        V = U @ A
        return _support_min(V / np.linalg.norm(V, axis=1)[:, None], wrenches)

    _check_candidate_count(families, D - 1, exact=True)
    best, degenerate = math.inf, False
    for parts, shape in _face_tuples(families, D - 1, exact=True):
        count = int(np.prod(shape))
        for lo in range(0, count, chunk):
            M = _stacked_bases(families, parts, shape, lo, min(count, lo + chunk))
            u = _cofactor_normals(M)
            norms = np.linalg.norm(u, axis=1)
            if np.any(norms <= RANK_TOL):
                degenerate = True
                break
            best = min(best, support_min(u / norms[:, None]))
        if degenerate:
            break
    if not degenerate:
        return best
    _check_candidate_count(families, D - 1, exact=False)
    best = math.inf
    for parts, shape in _face_tuples(families, D - 1, exact=False):
        count = int(np.prod(shape))
        for lo in range(0, count, chunk):
            M = _stacked_bases(families, parts, shape, lo, min(count, lo + chunk))
            _, s, vt = np.linalg.svd(M)
            keep = s[:, D - 2] > RANK_TOL * s[:, 0]
            if M.shape[1] >= D:
                keep &= s[:, D - 1] <= RANK_TOL * s[:, 0]
            if np.any(keep):
                best = min(best, support_min(vt[keep, D - 1, :]))
    return best


@checked_call
def ferrari_canny(
    grasp: Grasp,
    *,
    norm: str = "L1",
    num_generators: int = DEFAULT_NUM_GENERATORS,
    torque_scale: float | None = None,
) -> float:
    r"""Ferrari–Canny ε: the largest origin-centred ball in the grasp wrench set.

    Parameters
    ----------
    grasp : Grasp
    norm : {"L1", "Linf"}, optional
        ``"L1"`` (default): the contact forces are bounded by ``Σ_i f_{n,i} <= 1``
        and the wrench set is the convex hull of all primitive wrenches.
        ``"Linf"``: each ``f_{n,i} <= 1`` and the wrench set is the Minkowski sum
        of the per-contact sets ``conv({0} ∪ {w_{i,k}})``.
    num_generators : int, optional
        Generators ``n_g`` of each spatial Coulomb cone (default 8).
    torque_scale : float, optional
        Length ``b_s`` (metres) dividing the moments; default the grasp's
        characteristic length ``b``; ``1.0`` means no scaling.
        An explicit length must be in ``[2.2e-308, 1e30]`` m with the grasp's
        extent (the largest distance from ``p`` to a contact) over it in
        ``[1e-4, 1e12]`` (any length when every contact is at ``p``), else
        :class:`~drakegrasp.InvalidOptionError`.

    Returns
    -------
    float
        ε ≥ 0, the radius of the largest ball centred at the origin inside the
        wrench set, in newtons of scaled wrench per newton of normal force
        (dimensionless).  0 when the origin is not strictly inside the set (no
        force closure on the polyhedral cones), including wrench sets of lower
        dimension than the wrench space (e.g. two hard fingers in 3-D).
        Its error is absolute, up to about 1e-15 times the largest primitive
        wrench (whose size grows with ``μ`` and ``ν``): with ``μ = 1e12`` an ε
        near 1e-3 is not resolved, and a grasp in force closure may get 0
        (see the Conventions page, Monotonicity).

    Notes
    -----
    With the primitive wrenches ``w_{i,k} = S G_i s_k`` (see
    :func:`primitive_wrenches`; every generator has ``f_n = 1``):

    .. math::

        W_1 = \operatorname{conv}\bigcup_i \{w_{i,k}\}_k, \qquad
        W_\infty = \bigoplus_i \operatorname{conv}(\{0\} \cup \{w_{i,k}\}_k),

        \varepsilon = \min_{\|u\| = 1} \max_{w \in W} u^T w
                    = \min_{\text{facets } (n_j, o_j)} (-o_j)

    where Qhull gives each facet as ``n_j·x + o_j <= 0`` with unit ``n_j``.
    Since every ``w_{i,k}`` lies in ``W_∞``, ``ε_1 <= ε_∞``, and
    ``ε_∞ <= N ε_1``; the origin is strictly inside one exactly when it is
    strictly inside the other.  The cones are inscribed in the Coulomb cones, so
    ε underestimates the exact-cone value.  (Ferrari & Canny, *Planning optimal
    grasps*, ICRA 1992; the L1/L∞ names follow the bound on the normal forces.)

    Cost.  L1: one Qhull hull of ``Σ_i m_i`` points (24 for three hard fingers
    with 8 generators: about a millisecond in 6-D); a grasp that is not in force
    closure is settled before Qhull (NNLS, checked).  L∞: the Minkowski sum of
    ``N`` sets of ``n_g + 1`` points has up to ``(n_g + 1)^N`` vertices and tens
    of thousands of facets in 6-D (about a second in Qhull for three hard
    fingers), so ε_∞ is computed through the sum's normal fan instead: every
    facet normal of ``W_∞`` is orthogonal to the directions of one face of each
    summand, so the minimum of the support function over those normals is ε_∞
    (exact; see ``_linf_radius``).  About 20–60 ms for three spatial hard
    fingers with 8 generators (4,710 candidate normals) and about 1 s for four
    (166,188); five need 1.8 million candidates (about 15 s).  Grasps that
    need more than ``LINF_MAX_CANDIDATES`` (six hard fingers do) raise
    :class:`~drakegrasp.InvalidOptionError`, and so do grasps with more than
    :data:`~drakegrasp.core.tolerances.L1_MAX_POINTS` primitive wrenches
    (either norm).  The candidates are counted from ``num_generators`` and
    the contact models before anything is built (three hard fingers with 128
    generators need 12,977,670: refused in milliseconds, where the L1 hull
    alone takes 30 s), unless the grasp is shown out of force closure
    without Qhull (NNLS, flatness: ε_∞ = 0 then, as always; a grasp whose
    origin lies on the hull's boundary, which only Qhull shows, is refused
    too); for friction coefficients outside ``[1e-4, 1e2]`` (soft fingers'
    ``b ν`` outside ``[1e-4, 1e4]`` times the grasp's extent) the faces are
    counted once built, before any enumeration.  Symmetric grasps need a
    second pass over all face choices of total dimension at least ``D - 1``;
    its count is checked after the first pass.

    Raises
    ------
    InvalidOptionError
        Bad ``norm``, ``num_generators`` or ``torque_scale`` (see
        :func:`primitive_wrenches`), or a grasp past the limits above.
    """
    norm = plain_str(norm)
    if type(norm) is not str or norm not in _NORMS:
        raise InvalidOptionError(f"norm must be one of {_NORMS}, got {describe(norm)}")
    eps_1, eps_inf = _epsilons(
        grasp,
        num_generators=num_generators,
        torque_scale=torque_scale,
        linf=norm == "Linf",
    )
    return eps_1 if norm == "L1" else eps_inf


def _epsilons(
    grasp: Grasp,
    *,
    num_generators: int,
    torque_scale: float | None,
    linf: bool | None,
) -> tuple[float, float | None]:
    """``(ε_1, ε_∞)`` of :func:`ferrari_canny`, sharing their work.

    ``linf``: True, ``ε_∞`` or the refusal of one too costly (refused before
    the L1 hull when the contact models show it, see
    :func:`_linf_refusal`); None, ``ε_∞`` or None when it is too costly;
    False, None.  ``ε_∞ = 0`` whenever ``ε_1 = 0``, whatever its cost.
    """
    _check_grasp(grasp)
    num_generators = check_num_generators(num_generators)
    b = _torque_scale(grasp, torque_scale)
    # From the models alone, before anything is built.
    refusal = None if linf is False else _linf_refusal(grasp, num_generators)
    wrenches = _wrenches(grasp, num_generators, b)
    points = np.vstack(wrenches)
    if points.shape[0] > L1_MAX_POINTS:
        raise InvalidOptionError(
            f"the Ferrari–Canny metric of this grasp needs the hull of "
            f"{points.shape[0]} primitive wrenches (more than L1_MAX_POINTS = "
            f"{L1_MAX_POINTS}); use fewer contacts or fewer generators"
        )
    A = _whitening(points)
    if A is None:
        # The wrench set is flat: no interior for either norm.
        return 0.0, None if linf is False else 0.0
    if linf and refusal is not None and _hull_input(points, A) is not None:
        # ε_∞ was asked for and is too costly, and the grasp is not shown
        # out of force closure without Qhull: refused before the L1 hull.
        raise refusal
    eps_1 = _ball_radius(points, A)
    if linf is False:
        return eps_1, None
    # The origin is strictly inside W_∞ exactly when it is strictly inside W_1
    # (both hold iff the primitive wrenches positively span the wrench space),
    # so the L1 test settles ε_∞ = 0 first.
    if eps_1 == 0.0:
        return 0.0, 0.0
    if refusal is not None:
        return eps_1, None  # linf is None here: an explicit request was refused
    try:
        return eps_1, _linf_radius(wrenches, A)
    except InvalidOptionError:
        # Past LINF_MAX_CANDIDATES after all (the second pass of a symmetric
        # grasp, or counts the models could not give): skipped unless asked.
        if linf:
            raise
        return eps_1, None
