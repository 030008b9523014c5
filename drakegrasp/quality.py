r"""Grasp quality metrics.

Every metric takes a :class:`~drakegrasp.Grasp` (its contacts, reference point
``p`` and characteristic length ``b``, all in one grasp frame) and follows
``shared/CONVENTIONS.md``: wrenches ``[f; m]`` with moments about ``p``, planar
wrenches ``[f_x, f_y, m_z]``, contact forces in contact frames with the normal
component first, inscribed polyhedral cones with ``n_g`` generators.

**Torque scaling.**  Metrics that compare forces with moments divide every
moment by a length ``b_s`` (the option ``torque_scale``; default the grasp's
characteristic length ``b``, an explicit ``1.0`` means no scaling).  A scaled
wrench ``[f; m / b_s]`` has the units of a force in every row, so balls and
singular values in wrench space are measured in newtons (per newton of normal
contact force: the metrics below are dimensionless).  Equivalently the metric
is computed with ``S G`` instead of ``G``, where ``S = diag(I, I / b_s)``.

The metrics:

* :func:`ferrari_canny`: the Ferrari–Canny ε (L1 form with a Qhull hull, L∞
  form through the normal fan of a Minkowski sum);
* :func:`lp2_margin`: the ``d*`` of the force-closure program LP2;
* :func:`grasp_singular_values` and the indices of ``G`` built from them
  (:func:`min_singular_value`, :func:`isotropy`,
  :func:`wrench_ellipsoid_volume`);
* :func:`hand_object_matrix` ``H = (G^+)^T J`` and its indices
  (:func:`distance_to_singularity`, :func:`uniformity_of_transformation`,
  :func:`manipulability_volume`);
* :func:`max_resistible_wrench`: the largest multiple of a given external
  wrench that bounded contact forces can resist (an LP solved with Clp);
* :func:`grasp_quality`: all of them at once, as a :class:`GraspQuality`.

The hull-based ε imports ``scipy.spatial`` (Qhull); the LP imports
``pydrake.solvers``.  Nothing here touches a plant.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, fields

import numpy as np
from pydrake.solvers import (
    ClpSolver,
    MathematicalProgram,
    SolutionResult,
)
from scipy.optimize import nnls
from scipy.spatial import ConvexHull, QhullError

from drakegrasp.errors import InvalidGraspError, InvalidOptionError, SolverError
from drakegrasp.friction_cone import (
    DEFAULT_NUM_GENERATORS,
    effective_cone,
    friction_cone_generators,
)
from drakegrasp.grasp import Grasp, grasp_matrix

__all__ = [
    "GraspQuality",
    "MaxWrenchResult",
    "MaxWrenchVariables",
    "build_max_resistible_wrench_program",
    "distance_to_singularity",
    "ferrari_canny",
    "grasp_quality",
    "grasp_singular_values",
    "hand_object_matrix",
    "hand_object_singular_values",
    "isotropy",
    "lp2_margin",
    "manipulability_volume",
    "max_resistible_wrench",
    "min_singular_value",
    "primitive_wrenches",
    "uniformity_of_transformation",
    "wrench_ellipsoid_volume",
]

RANK_TOL = 1e-9
"""Singular values below ``RANK_TOL * σ_max`` count as zero (rank tests here)."""

HULL_TOL = 1e-9
"""Relative tolerance (times the largest coordinate) of the hull checks."""

LINF_MAX_CANDIDATES = 2_000_000
"""Most candidate facet normals the L∞ ε may test (about 6 s per million)."""

_NORMS = ("L1", "Linf")


# ----------------------------------------------------------------- helpers


def _check_grasp(grasp: Grasp) -> Grasp:
    if not isinstance(grasp, Grasp):
        raise InvalidGraspError(
            f"expected a drakegrasp.Grasp, got a {type(grasp).__name__}"
        )
    return grasp


def _torque_scale(grasp: Grasp, torque_scale: float | None) -> float:
    if torque_scale is None:
        return float(grasp.characteristic_length)
    try:
        b = float(torque_scale)
    except (TypeError, ValueError):
        raise InvalidOptionError(
            f"torque_scale must be a length > 0 (metres) or None, got {torque_scale!r}"
        ) from None
    if not math.isfinite(b) or b <= 0.0:
        raise InvalidOptionError(
            f"torque_scale must be finite and > 0 (metres) or None, got "
            f"{torque_scale!r}"
        )
    return b


def _moment_rows(wrench_dim: int) -> slice:
    return slice(3, 6) if wrench_dim == 6 else slice(2, 3)


def _scaled_grasp_matrix(grasp: Grasp, b: float) -> np.ndarray:
    G = grasp_matrix(grasp)
    G[_moment_rows(G.shape[0]), :] /= b
    return G


def _padded_singular_values(A: np.ndarray) -> np.ndarray:
    """All ``rows`` singular values of ``A``, descending, zero-padded."""
    rows = A.shape[0]
    s = np.zeros(rows)
    if A.size:
        sv = np.linalg.svd(A, compute_uv=False)
        s[: sv.size] = sv[:rows]
    return s


# ------------------------------------------------------- primitive wrenches


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
    b = _torque_scale(grasp, torque_scale)
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

    The generators are those of CONVENTIONS.md (``s_k = [1, μ cos(2πk/n_g),
    μ sin(2πk/n_g)]`` in the contact frame); a test checks that they equal
    :func:`~drakegrasp.friction_cone_generators`.
    """
    n_g = int(num_generators)
    if n_g != num_generators or n_g < 3:
        raise InvalidOptionError(
            f"num_generators must be an integer >= 3, got {num_generators!r}"
        )
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


# ------------------------------------------------------------- convex hulls


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
    tol = HULL_TOL * max(scale, 1e-300)
    try:
        hull = ConvexHull(points, qhull_options="Q0")
        eq = hull.equations
        if np.max(points @ eq[:, :-1].T + eq[:, -1]) <= tol:
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


def _origin_distance_residual(points: np.ndarray, scale: float) -> float:
    r"""Residual of ``min ‖Pᵀλ‖² + ρ²(1ᵀλ - 1)²`` over ``λ >= 0`` (NNLS).

    Zero (to round-off) exactly when some convex combination of the points is
    the origin, i.e. when the origin lies in their hull; positive otherwise.
    Lawson–Hanson NNLS on ``K`` points costs tens of microseconds, so it lets
    :func:`_ball_radius` skip Qhull for grasps that are not in force closure.
    A residual at round-off level is never trusted: Qhull then decides.
    """
    rho = max(scale, 1e-300)
    A = np.vstack([points.T, np.full((1, points.shape[0]), rho)])
    rhs = np.zeros(points.shape[1] + 1)
    rhs[-1] = rho
    try:
        return float(nnls(A, rhs)[1])
    except RuntimeError:  # iteration limit: let Qhull decide
        return 0.0


def _ball_radius(points: np.ndarray) -> float:
    """Radius of the largest origin-centred ball in ``conv(points)``; 0 if none.

    Qhull is called only when needed: a hull that does not contain the origin
    (NNLS residual above round-off) or whose affine hull is lower-dimensional
    than the space (no interior) has radius 0 without it.
    """
    num, dim = points.shape
    scale = float(np.max(np.abs(points))) if points.size else 0.0
    if num <= dim or scale == 0.0:
        return 0.0
    if _origin_distance_residual(points, scale) > HULL_TOL * scale:
        return 0.0  # the origin is outside the hull: no hull needed
    s = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
    if s[-1] <= RANK_TOL * max(s[0], scale):
        return 0.0  # flat hull: no interior
    eq = _qhull(points, scale).equations
    # Unit outward normals n and offsets o: the hull is {x : n·x + o <= 0}, so
    # the distance from the origin to each facet's hyperplane is -o.
    radius = float(np.min(-eq[:, -1]))
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


def _face_tuples(families, dim_test):
    """Yield ``(parts, shape)`` for every choice of one face per contact.

    ``families[i]`` maps a face dimension to bases (see
    :func:`_face_directions`); a contact may also contribute a vertex (no
    direction).  ``dim_test(total)`` selects the total dimensions to keep.
    """
    choices = [[0, *sorted(f)] for f in families]
    for combo in itertools.product(*choices):
        if not dim_test(sum(combo)):
            continue
        parts = [(i, j) for i, j in enumerate(combo) if j > 0]
        shape = [families[i][j].shape[0] for i, j in parts]
        yield parts, shape


def _stacked_bases(families, parts, shape, lo, hi) -> np.ndarray:
    idx = np.unravel_index(np.arange(lo, hi), shape)
    return np.concatenate(
        [families[i][j][k] for (i, j), k in zip(parts, idx, strict=True)], axis=1
    )


def _check_candidate_count(families, dim_test) -> None:
    total = sum(int(np.prod(s)) for _, s in _face_tuples(families, dim_test))
    if total > LINF_MAX_CANDIDATES:
        raise InvalidOptionError(
            f"the L∞ Ferrari–Canny metric of this grasp needs {total} candidate "
            f"facet normals (more than LINF_MAX_CANDIDATES = {LINF_MAX_CANDIDATES});"
            " use norm='L1', fewer contacts or fewer generators"
        )


def _linf_radius(wrenches: Sequence[np.ndarray]) -> float:
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
    sets = [np.vstack([np.zeros((1, D)), W]) for W in wrenches]
    families = [_face_directions(P) for P in sets]
    chunk = 100_000
    exact_dim = (lambda t: t == D - 1), (lambda t: t >= D - 1)
    _check_candidate_count(families, exact_dim[0])
    best, degenerate = math.inf, False
    for parts, shape in _face_tuples(families, exact_dim[0]):
        count = int(np.prod(shape))
        for lo in range(0, count, chunk):
            M = _stacked_bases(families, parts, shape, lo, min(count, lo + chunk))
            u = _cofactor_normals(M)
            norms = np.linalg.norm(u, axis=1)
            if np.any(norms <= RANK_TOL):
                degenerate = True
                break
            best = min(best, _support_min(u / norms[:, None], wrenches))
        if degenerate:
            break
    if not degenerate:
        return best
    _check_candidate_count(families, exact_dim[1])
    best = math.inf
    for parts, shape in _face_tuples(families, exact_dim[1]):
        count = int(np.prod(shape))
        for lo in range(0, count, chunk):
            M = _stacked_bases(families, parts, shape, lo, min(count, lo + chunk))
            _, s, vt = np.linalg.svd(M)
            keep = s[:, D - 2] > RANK_TOL * s[:, 0]
            if M.shape[1] >= D:
                keep &= s[:, D - 1] <= RANK_TOL * s[:, 0]
            if np.any(keep):
                best = min(best, _support_min(vt[keep, D - 1, :], wrenches))
    return best


# ------------------------------------------------------------ Ferrari–Canny


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

    Returns
    -------
    float
        ε ≥ 0, the radius of the largest ball centred at the origin inside the
        wrench set, in newtons of scaled wrench per newton of normal force
        (dimensionless).  0 when the origin is not strictly inside the set (no
        force closure on the polyhedral cones), including wrench sets of lower
        dimension than the wrench space (e.g. two hard fingers in 3-D).

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
    closure is settled before Qhull by an NNLS test.  L∞: the Minkowski sum of
    ``N`` sets of ``n_g + 1`` points has up to ``(n_g + 1)^N`` vertices and tens
    of thousands of facets in 6-D (about a second in Qhull for three hard
    fingers), so ε_∞ is computed through the sum's normal fan instead: every
    facet normal of ``W_∞`` is orthogonal to the directions of one face of each
    summand, so the minimum of the support function over those normals is ε_∞
    (exact; see ``_linf_radius``).  About 20–60 ms for three spatial hard
    fingers with 8 generators (4,710 candidate normals) and about 1 s for four
    (166,188); five need 1.8 million candidates (about 15 s).  Grasps that
    need more than ``LINF_MAX_CANDIDATES`` (six hard fingers do) raise
    :class:`~drakegrasp.InvalidOptionError`.
    """
    if norm not in _NORMS:
        raise InvalidOptionError(f"norm must be one of {_NORMS}, got {norm!r}")
    wrenches = primitive_wrenches(
        grasp, num_generators=num_generators, torque_scale=torque_scale
    )
    if norm == "L1":
        return _ball_radius(np.vstack(wrenches))
    # The origin is strictly inside W_∞ exactly when it is strictly inside W_1
    # (both hold iff the primitive wrenches positively span the wrench space),
    # so the cheap L1 test settles ε_∞ = 0 first.
    if _ball_radius(np.vstack(wrenches)) == 0.0:
        return 0.0
    return _linf_radius(wrenches)


# -------------------------------------------------------------- LP2 margin


def lp2_margin(
    grasp: Grasp,
    *,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    tol: float = 1e-6,
) -> float:
    r"""The optimal ``d*`` of LP2 (frictional force closure) as a quality metric.

    Parameters
    ----------
    grasp : Grasp
    num_generators : int, optional
        Generators ``n_g`` of each spatial Coulomb cone (default 8).
    tol : float, optional
        Passed to :func:`~drakegrasp.closure.force_closure` (it only affects the
        verdict there, not ``d*``).

    Returns
    -------
    float
        ``d*`` of

        .. math:: \max d \;\text{s.t.}\; G f = 0,\; F f - \mathbf 1 d \ge 0,\;
                  d \ge 0,\; \textstyle\sum_i f_{n,i} \le N

        (``F`` with unit facet rows): the largest distance by which a
        self-balanced set of contact forces, with mean normal force at most 1,
        can stay inside every cone facet.  Dimensionless (newtons per newton of
        normal force).  It says nothing about the rank of ``G``: force closure
        needs ``rank(G)`` full as well (see
        :func:`~drakegrasp.closure.force_closure`).
    """
    from drakegrasp.closure import force_closure  # the closure programs' owner

    _check_grasp(grasp)
    result = force_closure(grasp, num_generators=num_generators, tol=tol)
    d = float(result.d_star)
    return d if math.isfinite(d) else 0.0


# ------------------------------------------------- singular values of G


def grasp_singular_values(
    grasp: Grasp, *, torque_scale: float | None = None
) -> np.ndarray:
    r"""Singular values of the torque-scaled grasp matrix ``S G``.

    Parameters
    ----------
    grasp : Grasp
    torque_scale : float, optional
        Length ``b_s`` (metres) dividing the moment rows; default the grasp's
        characteristic length, ``1.0`` for the unscaled ``G``.

    Returns
    -------
    sigma : (6,) or (3,) float
        ``σ_1 >= … >= σ_D`` of ``S G`` (``D`` = wrench dimension), zero-padded
        when ``G`` has fewer than ``D`` columns.  Dimensionless (newtons of
        scaled wrench per newton of contact force).

    Notes
    -----
    ``G`` is :func:`~drakegrasp.grasp_matrix` with every component of each
    contact model (a hard finger with ``mu = 0`` keeps its tangential columns:
    these indices describe the contact geometry, not friction).  The columns of
    ``G`` map orthonormal contact-frame components, so ``σ_i`` are the semi-axes
    of the wrench ellipsoid ``{S G f : ‖f‖ <= 1}``.
    """
    _check_grasp(grasp)
    b = _torque_scale(grasp, torque_scale)
    return _padded_singular_values(_scaled_grasp_matrix(grasp, b))


def min_singular_value(grasp: Grasp, *, torque_scale: float | None = None) -> float:
    """Smallest singular value ``σ_min(S G)``: the worst-direction wrench gain.

    The smallest wrench norm that a unit contact-force vector can produce in
    the least favourable direction; 0 when ``G`` is rank-deficient.  See
    :func:`grasp_singular_values` for ``S``, units and conventions.
    """
    return float(grasp_singular_values(grasp, torque_scale=torque_scale)[-1])


def isotropy(grasp: Grasp, *, torque_scale: float | None = None) -> float:
    """Grasp isotropy index ``σ_min(S G) / σ_max(S G)`` in ``[0, 1]``.

    1 when every wrench direction is produced equally well; 0 when ``G`` is
    rank-deficient.  Depends on the torque scale; see
    :func:`grasp_singular_values`.
    """
    s = grasp_singular_values(grasp, torque_scale=torque_scale)
    return float(s[-1] / s[0]) if s[0] > 0 else 0.0


def wrench_ellipsoid_volume(
    grasp: Grasp, *, torque_scale: float | None = None
) -> float:
    r"""Volume index of the wrench ellipsoid: ``σ_1 σ_2 … σ_D = sqrt(det(S G Gᵀ S))``.

    The ellipsoid ``{S G f : ‖f‖ <= 1}`` has semi-axes ``σ_i``, so its volume is
    ``V_D σ_1 … σ_D`` with ``V_D`` the volume of the unit ball (``π³/6`` in 6-D,
    ``4π/3`` in 3-D).  As in the grasp-quality literature the constant ``V_D``
    is left out: the index is the product of the singular values
    (dimensionless; 0 when ``G`` is rank-deficient).  See
    :func:`grasp_singular_values` for the scaling.
    """
    return float(np.prod(grasp_singular_values(grasp, torque_scale=torque_scale)))


# ------------------------------------------------ hand-object matrix H


def _check_jacobian(grasp: Grasp, hand_jacobian: np.ndarray) -> np.ndarray:
    J = np.asarray(hand_jacobian, dtype=float)
    M = grasp.num_components
    if J.ndim != 2 or J.shape[0] != M or J.shape[1] < 1:
        raise InvalidGraspError(
            f"hand_jacobian must have shape ({M}, n_q): one row per column of G "
            f"(contact-frame components, in contact order) and one column per hand "
            f"velocity; got shape {J.shape}"
        )
    if not np.all(np.isfinite(J)):
        raise InvalidGraspError("hand_jacobian has non-finite entries")
    return J


def hand_object_matrix(
    grasp: Grasp,
    hand_jacobian: np.ndarray,
    *,
    torque_scale: float | None = None,
) -> np.ndarray:
    r"""Hand-object matrix ``H = ((S G)^+)^T J``: hand velocities to object twist.

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_q) float
        Hand Jacobian ``J``: rows in the column order of ``G`` (contact-frame
        components, contact by contact), columns the hand's generalized
        velocities ``q̇``.
    torque_scale : float, optional
        Length ``b_s`` (metres); default the grasp's characteristic length,
        ``1.0`` for no scaling.

    Returns
    -------
    H : (6, n_q) or (3, n_q) float
        Maps ``q̇`` to the object twist ``[v; b_s ω]`` (planar
        ``[v_x, v_y, b_s ω]``) about ``p`` in the grasp frame: every row in
        metres per second per unit of ``q̇``.

    Notes
    -----
    The contact constraint (Prattichizzo & Trinkle, *Grasping*, Springer
    Handbook of Robotics) equates the contact velocities seen by the hand and
    by the object: ``J q̇ = Gᵀ ν``.  Its least-squares solution for the twist
    is ``ν = (Gᵀ)^+ J q̇ = (G^+)ᵀ J q̇``, and ``H = (G^+)ᵀ J`` is the matrix whose
    singular values give the hand-configuration indices of Roa & Suárez,
    *Grasp quality measures: review and performance* (Auton. Robots, 2015).
    With scaling, ``Gᵀ ν = (S G)ᵀ (S^{-1} ν)``, so the twist becomes
    ``S^{-1} ν = [v; b_s ω]``.  The pseudo-inverse drops singular values below
    ``RANK_TOL σ_max``.
    """
    _check_grasp(grasp)
    J = _check_jacobian(grasp, hand_jacobian)
    b = _torque_scale(grasp, torque_scale)
    G = _scaled_grasp_matrix(grasp, b)
    G_pinv = np.linalg.pinv(G, rcond=RANK_TOL)
    return G_pinv.T @ J


def hand_object_singular_values(
    grasp: Grasp, hand_jacobian: np.ndarray, *, torque_scale: float | None = None
) -> np.ndarray:
    """Singular values ``σ_1 >= … >= σ_D`` of ``H`` (zero-padded to ``D`` rows).

    See :func:`hand_object_matrix`.  Units: metres per second of (scaled)
    object twist per unit of hand velocity.
    """
    return _padded_singular_values(
        hand_object_matrix(grasp, hand_jacobian, torque_scale=torque_scale)
    )


def distance_to_singularity(
    grasp: Grasp, hand_jacobian: np.ndarray, *, torque_scale: float | None = None
) -> float:
    """Distance from singular configurations: ``σ_min(H)`` (0 at a singularity).

    ``σ_min`` is the smallest of the ``D`` singular values of ``H``, so it is 0
    whenever the hand cannot move the object in some direction (including
    ``n_q < D``).  See :func:`hand_object_matrix`.
    """
    s = hand_object_singular_values(grasp, hand_jacobian, torque_scale=torque_scale)
    return float(s[-1])


def uniformity_of_transformation(
    grasp: Grasp, hand_jacobian: np.ndarray, *, torque_scale: float | None = None
) -> float:
    """Uniformity of transformation: ``σ_max(H) / σ_min(H) >= 1``; 1 is best.

    The condition number of ``H``; ``inf`` at a singular configuration.  See
    :func:`hand_object_matrix`.
    """
    s = hand_object_singular_values(grasp, hand_jacobian, torque_scale=torque_scale)
    return float(s[0] / s[-1]) if s[-1] > 0 else math.inf


def manipulability_volume(
    grasp: Grasp, hand_jacobian: np.ndarray, *, torque_scale: float | None = None
) -> float:
    r"""Manipulability-ellipsoid volume index ``σ_1 … σ_D = sqrt(det(H Hᵀ))``.

    The ellipsoid ``{H q̇ : ‖q̇‖ <= 1}`` of object twists has volume
    ``V_D σ_1 … σ_D``; the unit-ball constant ``V_D`` is left out (as in
    :func:`wrench_ellipsoid_volume`).  0 at a singular configuration.  See
    :func:`hand_object_matrix`.
    """
    s = hand_object_singular_values(grasp, hand_jacobian, torque_scale=torque_scale)
    return float(np.prod(s))


# ------------------------------------------------- largest resistible wrench


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return [_jsonable(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (float, np.floating)):
        x = float(value)
        return x if math.isfinite(x) else None
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value


@dataclass(frozen=True)
class MaxWrenchVariables:
    """Decision variables of :func:`build_max_resistible_wrench_program`.

    Attributes
    ----------
    alpha : pydrake.symbolic.Variable
        The multiple ``α >= 0`` of the external wrench; the program maximises it.
    forces : (m,) ndarray of Variable
        The contact-force components the cones allow (contact frames).
    columns : (m,) int
        Where each entry of ``forces`` sits in the grasp's stacked force vector
        (columns of :func:`~drakegrasp.grasp_matrix`).
    normal_positions : (N,) int
        Index in ``forces`` of each contact's ``f_n``.
    """

    alpha: object
    forces: np.ndarray
    columns: np.ndarray
    normal_positions: np.ndarray


@dataclass(frozen=True)
class MaxWrenchResult:
    """Largest multiple of an external wrench that a grasp resists.

    Attributes
    ----------
    alpha : float
        The largest ``α >= 0`` such that contact forces in the polyhedral cones,
        each ``f_{n,i} <= max_normal_force_i``, balance the external wrench
        ``α · direction``.  Units: those making ``α · direction`` a wrench
        (``α`` in kg when ``direction`` is the gravity wrench of 1 kg).
    direction : (6,) or (3,) float
        The external wrench direction, ``[f; m]`` about ``p`` in the grasp frame.
    wrench : (6,) or (3,) float
        ``α · direction`` (N, N·m).
    contact_forces : tuple of ndarray
        Optimal force of each contact in its contact frame (normal first, the
        components of its model), N; they satisfy ``G f = -α · direction``.
    max_normal_force : (N,) float
        The per-contact bounds on ``f_n`` used, N.
    num_generators : int
        Generators of each spatial Coulomb cone.
    solver, status : str
        Solver name and its solution status.
    """

    alpha: float
    direction: np.ndarray
    wrench: np.ndarray
    contact_forces: tuple[np.ndarray, ...]
    max_normal_force: np.ndarray
    num_generators: int
    solver: str
    status: str

    def to_dict(self) -> dict:
        """JSON-ready dictionary (non-finite numbers become ``None``)."""
        return {f.name: _jsonable(getattr(self, f.name)) for f in fields(self)}

    def __str__(self) -> str:
        fn = ", ".join(f"{f[0]:.4g}" for f in self.contact_forces)
        return (
            f"max resistible wrench: alpha = {self.alpha:.6g} along "
            f"{np.round(self.direction, 6).tolist()}\n"
            f"  normal forces [{fn}] N (limits "
            f"{np.round(self.max_normal_force, 6).tolist()} N)\n"
            f"  solver {self.solver} ({self.status}), {self.num_generators} "
            "generators"
        )


def _check_direction(grasp: Grasp, direction: np.ndarray) -> np.ndarray:
    d = np.array(direction, dtype=float).reshape(-1)
    D = grasp.wrench_dim
    if d.shape != (D,) or not np.all(np.isfinite(d)):
        raise InvalidOptionError(
            f"direction must be a finite {D}-vector wrench [f; m] (the grasp is "
            f"{'planar' if grasp.planar else 'spatial'}), got "
            f"{np.asarray(direction).tolist()}"
        )
    if not np.any(d):
        raise InvalidOptionError("direction must be a non-zero wrench, got zeros")
    return d


def _check_max_normal_force(grasp: Grasp, max_normal_force) -> np.ndarray:
    N = grasp.num_contacts
    try:
        f = np.array(max_normal_force, dtype=float)
    except (TypeError, ValueError):
        raise InvalidOptionError(
            f"max_normal_force must be a number or {N} numbers (N), got "
            f"{max_normal_force!r}"
        ) from None
    if f.ndim == 0:
        f = np.full(N, float(f))
    if f.shape != (N,) or not np.all(np.isfinite(f)) or np.any(f < 0):
        raise InvalidOptionError(
            f"max_normal_force must be a finite number >= 0 or {N} of them (one per "
            f"contact), got {np.asarray(max_normal_force).tolist()}"
        )
    return f


def build_max_resistible_wrench_program(
    grasp: Grasp,
    direction: np.ndarray,
    *,
    max_normal_force: float | np.ndarray,
    num_generators: int = DEFAULT_NUM_GENERATORS,
) -> tuple[MathematicalProgram, MaxWrenchVariables]:
    r"""Build the LP for the largest resistible multiple of an external wrench.

    Parameters
    ----------
    grasp : Grasp
    direction : (6,) or (3,) float
        External wrench direction ``w_e = [f; m]`` about ``p``, grasp frame
        (e.g. the gravity wrench of 1 kg: ``[m g; (c_m - p) × m g]``).
    max_normal_force : float or (N,) float
        Bound ``f_max >= 0`` on each contact's normal force, N (one for all
        contacts or one per contact).
    num_generators : int, optional
        Generators ``n_g`` of each spatial Coulomb cone (default 8).

    Returns
    -------
    prog : MathematicalProgram
        .. math:: \max_{\alpha, f} \alpha \;\text{s.t.}\;
                  G f + \alpha\, w_e = 0,\; F_i f_i \ge 0,\;
                  0 \le f_{n,i} \le f_{\max,i},\; \alpha \ge 0

        over the force components each cone allows (``F_i`` the unit facet rows
        of the inscribed polyhedral cone; a hard finger with ``mu = 0`` has only
        ``f_n``).  Always feasible (``α = 0``, ``f = 0``) and bounded (the cones
        are pointed and ``f_n`` is bounded).
    variables : MaxWrenchVariables
    """
    _check_grasp(grasp)
    d = _check_direction(grasp, direction)
    fmax = _check_max_normal_force(grasp, max_normal_force)
    b = grasp.characteristic_length
    cones = [
        effective_cone(c, num_generators, characteristic_length=b)
        for c in grasp.contacts
    ]
    columns, normals = [], []
    for sl, cone in zip(grasp.component_slices(), cones, strict=True):
        normals.append(len(columns))
        columns.extend(sl.start + j for j in cone.components)
    columns = np.array(columns, dtype=int)
    normals = np.array(normals, dtype=int)
    G = grasp_matrix(grasp)[:, columns]

    prog = MathematicalProgram()
    f = prog.NewContinuousVariables(len(columns), "f")
    alpha = prog.NewContinuousVariables(1, "alpha")[0]
    prog.AddLinearCost(-1.0 * alpha)
    prog.AddBoundingBoxConstraint(0.0, np.inf, alpha)
    prog.AddLinearEqualityConstraint(
        np.hstack([G, d[:, None]]), np.zeros(G.shape[0]), np.append(f, alpha)
    )
    start = 0
    for cone in cones:
        k = len(cone.components)
        F = cone.facets
        prog.AddLinearConstraint(
            F, np.zeros(F.shape[0]), np.full(F.shape[0], np.inf), f[start : start + k]
        )
        start += k
    prog.AddBoundingBoxConstraint(np.zeros(len(normals)), fmax, f[normals])
    return prog, MaxWrenchVariables(alpha, f, columns, normals)


def max_resistible_wrench(
    grasp: Grasp,
    direction: np.ndarray,
    *,
    max_normal_force: float | np.ndarray,
    num_generators: int = DEFAULT_NUM_GENERATORS,
) -> MaxWrenchResult:
    """Largest ``α`` such that the grasp resists the external wrench ``α · direction``.

    Builds the LP of :func:`build_max_resistible_wrench_program` and solves it
    with Clp.

    Parameters
    ----------
    grasp : Grasp
    direction : (6,) or (3,) float
        External wrench direction ``[f; m]`` about ``p``, in the grasp frame.
    max_normal_force : float or (N,) float
        Bound on each contact's normal force, N.
    num_generators : int, optional
        Generators of each spatial Coulomb cone (default 8).

    Returns
    -------
    MaxWrenchResult

    Raises
    ------
    SolverError
        If Clp is unavailable or fails (the LP is always feasible and bounded).
    """
    prog, v = build_max_resistible_wrench_program(
        grasp,
        direction,
        max_normal_force=max_normal_force,
        num_generators=num_generators,
    )
    solver = ClpSolver()
    if not (solver.available() and solver.enabled()):  # pragma: no cover
        raise SolverError("Clp is not available (it ships with Drake)", program=prog)
    result = solver.Solve(prog)
    status = result.get_solution_result()
    name = result.get_solver_id().name()
    if status != SolutionResult.kSolutionFound:
        raise SolverError(
            f"{name} failed with status {status.name} on the max-resistible-wrench "
            "LP (always feasible and bounded, so this is a numerical failure)",
            program=prog,
            result=result,
        )
    d = _check_direction(grasp, direction)
    alpha = max(float(result.GetSolution(v.alpha)), 0.0)
    full = np.zeros(grasp.num_components)
    full[v.columns] = result.GetSolution(v.forces)
    forces = tuple(full[sl].copy() for sl in grasp.component_slices())
    return MaxWrenchResult(
        alpha=alpha,
        direction=d,
        wrench=alpha * d,
        contact_forces=forces,
        max_normal_force=_check_max_normal_force(grasp, max_normal_force),
        num_generators=int(num_generators),
        solver=name,
        status=status.name,
    )


# ------------------------------------------------------------- the summary


@dataclass(frozen=True)
class GraspQuality:
    """All quality metrics of one grasp (see the functions named in each field).

    Attributes
    ----------
    ferrari_canny_l1 : float
        :func:`ferrari_canny` with ``norm="L1"``.
    ferrari_canny_linf : float or None
        :func:`ferrari_canny` with ``norm="Linf"`` (None when not computed).
    lp2_margin : float
        :func:`lp2_margin`, LP2's ``d*``.
    is_force_closure : bool
        Frictional force closure on the polyhedral cones: ``rank(G)`` full and
        ``d* > tol`` (and, with a hand Jacobian, LP3 passes).
    singular_values : (D,) float
        :func:`grasp_singular_values` of ``S G``.
    min_singular_value, isotropy, wrench_ellipsoid_volume : float
        :func:`min_singular_value`, :func:`isotropy`,
        :func:`wrench_ellipsoid_volume`.
    hand_singular_values : (D,) float or None
        :func:`hand_object_singular_values` (None without a hand Jacobian).
    distance_to_singularity, uniformity_of_transformation, manipulability_volume
        : float or None
        The indices of ``H`` (None without a hand Jacobian).
    num_generators : int
        Generators of each spatial Coulomb cone.
    torque_scale : float
        ``b_s`` (metres) dividing the moments in ε and the singular values.
    tol : float
        Threshold on ``d*`` of the force-closure verdict.
    """

    ferrari_canny_l1: float
    ferrari_canny_linf: float | None
    lp2_margin: float
    is_force_closure: bool
    singular_values: np.ndarray
    min_singular_value: float
    isotropy: float
    wrench_ellipsoid_volume: float
    num_generators: int
    torque_scale: float
    tol: float
    hand_singular_values: np.ndarray | None = field(default=None)
    distance_to_singularity: float | None = field(default=None)
    uniformity_of_transformation: float | None = field(default=None)
    manipulability_volume: float | None = field(default=None)

    def to_dict(self) -> dict:
        """JSON-ready dictionary (non-finite numbers become ``None``)."""
        return {f.name: _jsonable(getattr(self, f.name)) for f in fields(self)}

    def __str__(self) -> str:
        def fmt(x):
            return "n/a" if x is None else f"{x:.6g}"

        lines = [
            f"grasp quality ({self.num_generators} generators, torque scale "
            f"{self.torque_scale:g} m)",
            f"  force closure: {'YES' if self.is_force_closure else 'no'}, "
            f"LP2 d* = {self.lp2_margin:.6g}",
            f"  Ferrari-Canny eps: L1 {fmt(self.ferrari_canny_l1)}, "
            f"Linf {fmt(self.ferrari_canny_linf)}",
            f"  G: sigma_min {self.min_singular_value:.6g}, isotropy "
            f"{self.isotropy:.6g}, ellipsoid volume {self.wrench_ellipsoid_volume:.6g}",
        ]
        if self.hand_singular_values is not None:
            lines.append(
                f"  H: sigma_min {fmt(self.distance_to_singularity)}, uniformity "
                f"{fmt(self.uniformity_of_transformation)}, manipulability volume "
                f"{fmt(self.manipulability_volume)}"
            )
        return "\n".join(lines)


def grasp_quality(
    grasp: Grasp,
    *,
    hand_jacobian: np.ndarray | None = None,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    torque_scale: float | None = None,
    tol: float = 1e-6,
    linf: bool | None = None,
) -> GraspQuality:
    """Compute every quality metric of a grasp.

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_q) float, optional
        Hand Jacobian ``J`` (rows in ``G``'s column order); enables the indices
        of ``H = (G^+)ᵀ J`` and the LP3 part of the force-closure verdict.
    num_generators : int, optional
        Generators of each spatial Coulomb cone (default 8).
    torque_scale : float, optional
        ``b_s`` (metres) dividing moments; default the grasp's characteristic
        length, ``1.0`` for none.
    tol : float, optional
        Threshold on LP2's ``d*`` for the force-closure verdict.
    linf : bool or None, optional
        Whether to compute the L∞ Ferrari–Canny ε.  None (default): when it is
        cheap, i.e. for planar grasps and spatial grasps with at most three
        contacts (20–60 ms for three hard fingers with 8 generators, against
        about 1 s for four).

    Returns
    -------
    GraspQuality
    """
    from drakegrasp.closure import force_closure  # the closure programs' owner

    _check_grasp(grasp)
    b = _torque_scale(grasp, torque_scale)
    J = None if hand_jacobian is None else _check_jacobian(grasp, hand_jacobian)
    closure = force_closure(
        grasp, hand_jacobian=J, num_generators=num_generators, tol=tol
    )
    d_star = float(closure.d_star)
    s = grasp_singular_values(grasp, torque_scale=b)
    hand = {}
    if J is not None:
        sh = hand_object_singular_values(grasp, J, torque_scale=b)
        hand = {
            "hand_singular_values": sh,
            "distance_to_singularity": float(sh[-1]),
            "uniformity_of_transformation": (
                float(sh[0] / sh[-1]) if sh[-1] > 0 else math.inf
            ),
            "manipulability_volume": float(np.prod(sh)),
        }
    return GraspQuality(
        ferrari_canny_l1=ferrari_canny(
            grasp, norm="L1", num_generators=num_generators, torque_scale=b
        ),
        ferrari_canny_linf=(
            ferrari_canny(
                grasp, norm="Linf", num_generators=num_generators, torque_scale=b
            )
            if linf or (linf is None and (grasp.planar or grasp.num_contacts <= 3))
            else None
        ),
        lp2_margin=d_star if math.isfinite(d_star) else 0.0,
        is_force_closure=bool(closure.is_closure),
        singular_values=s,
        min_singular_value=float(s[-1]),
        isotropy=float(s[-1] / s[0]) if s[0] > 0 else 0.0,
        wrench_ellipsoid_volume=float(np.prod(s)),
        num_generators=int(num_generators),
        torque_scale=b,
        tol=float(tol),
        **hand,
    )
