r"""The wrench space of a planar grasp: primitive wrenches and their convex hull.

Each contact's friction cone is spanned by its generators ``s_k`` (planar: the
exact edge rays ``[1, ±μ]``; frictionless: ``[1]``), all with unit normal
component.  Their wrenches ``w = G_i s_k`` are the *primitive wrenches*; the grasp
is force closure exactly when they positively span the wrench space, i.e. when
the origin lies strictly inside their convex hull.  Moments are divided by the
characteristic length ``b`` so the three axes share units (newtons).

.. math:: w_{ik} = \begin{bmatrix} R_i s_k \\ (c_i - p) \times R_i s_k / b
          \end{bmatrix}

matplotlib and scipy are imported only when a function here needs them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.friction_cone import friction_cone_generators
from drakegrasp.core.grasp import Grasp, wrench_columns
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import (
    check_flag,
    check_grasp,
    describe,
    real_array,
    real_scalar,
)
from drakegrasp.errors import InvalidOptionError
from drakegrasp.visualization.plots import import_pyplot

__all__ = [
    "MAX_HULL_DIM",
    "MAX_HULL_FACETS",
    "ORIGIN_CLEARANCE_TOL",
    "WRENCH_BOUND",
    "WrenchHull",
    "WrenchSpacePlot",
    "plot_wrench_space",
    "wrench_space_points",
    "wrench_hull",
]

MAX_HULL_DIM = 6
"""Most rows of the wrenches :func:`wrench_hull` takes (a spatial wrench's)."""

WRENCH_BOUND = 1e100
"""Largest absolute entry of a wrench :func:`wrench_hull` takes, so that the
rank's SVD and Qhull square nothing beyond ``1e200`` (an array of NaN made the
SVD fail to converge)."""

MAX_HULL_FACETS = 10**6
"""Most facets the hull of :func:`wrench_hull` may have.

Qhull's time and memory grow with the hull's facets, and in 6-D ``K`` points
can have about ``K**3 / 6`` of them: the wrenches of three contacts with 256
generators each (768 points) ran for minutes, a cyclic polytope of 400 points
took 88 s and 4 GB.  :func:`wrench_hull` therefore refuses more columns than
can have at most this many facets (McMullen's upper bound theorem: the
cyclic polytope's count): 1,000,000 columns in 2-D,
500,002 in 3-D, 1,415 in 4-D, 1,003 in 5-D and 184 in 6-D.  A hull of 10**6
facets took about 5 s and 0.5 GB."""

ORIGIN_CLEARANCE_TOL = 1e-9
"""Default distance (in the wrench space's units) by which every facet of the
primitive wrenches' hull must clear the origin for it to count as inside."""


@checked_call
def wrench_space_points(
    grasp: Grasp,
    *,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    scale_moments: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """Wrenches of the friction-cone generators of every contact, as columns.

    (:func:`drakegrasp.quality.primitive_wrenches` returns the same wrenches
    grouped per contact, as rows; this flat form is what a plot needs.)

    Parameters
    ----------
    grasp : Grasp
        Planar or spatial.
    num_generators : int, optional
        Generators of a spatial Coulomb cone (planar cones are exact with 2).
    scale_moments : bool, optional
        Divide the moment rows by the characteristic length ``b`` (default).

    Returns
    -------
    W : (3, K) or (6, K) float
        Primitive wrenches ``[f; m]`` (or ``[f; m / b]``) as columns, about the
        grasp's reference point, in the grasp frame; forces have unit normal
        component (newtons per newton of normal force).
    contact_index : (K,) int
        Contact that each column comes from.

    Notes
    -----
    Only force generators enter: a soft finger's moment generators
    ``[1, 0, 0, ±bν]`` add the wrench ``[n; (c - p) × n ± bν n]``.
    """
    check_grasp(grasp)
    scale_moments = check_flag("scale_moments", scale_moments)
    b = grasp.characteristic_length
    p = grasp.reference_point
    cols, owner = [], []
    for i, contact in enumerate(grasp.contacts):
        S = friction_cone_generators(contact, num_generators, characteristic_length=b)
        d = contact.dim
        forces = np.zeros((d, S.shape[1]))
        k = min(d, S.shape[0])
        forces[:k] = S[:k]
        W = wrench_columns(contact.position, contact.frame @ forces, p)
        if S.shape[0] == 4:  # soft finger: the moment about the normal
            W[3:] += np.outer(contact.normal, S[3])
        cols.append(W)
        owner += [i] * S.shape[1]
    W = np.hstack(cols)
    if scale_moments:
        W[grasp.dim :] /= b  # moment rows: 2: (planar) or 3: (spatial)
    return W, np.array(owner, dtype=int)


def _most_hull_facets(m: int, K: int) -> int:
    """Most facets the convex hull of ``K`` points in ``m`` dimensions can have.

    McMullen's upper bound theorem: the cyclic polytope's count,
    ``K / (K - k) · C(K - k, k)`` for ``m = 2k`` and ``2 C(K - k - 1, k)`` for
    ``m = 2k + 1`` (0 when ``K <= m``: no interior).  A triangulated hull
    (Qhull's simplices) has at most as many.
    """
    if K <= m:
        return 0
    k = m // 2
    if m % 2 == 0:
        return K * math.comb(K - k, k) // (K - k)
    return 2 * math.comb(K - k - 1, k)


def _most_hull_columns(m: int) -> int:
    """Most columns ``K`` with ``_most_hull_facets(m, K) <= MAX_HULL_FACETS``."""
    low, high = m, 2 * MAX_HULL_FACETS + m  # facets >= K - m + 1 > the bound there
    while low < high:  # the count grows with K
        mid = (low + high + 1) // 2
        if _most_hull_facets(m, mid) <= MAX_HULL_FACETS:
            low = mid
        else:
            high = mid - 1
    return low


@checked_call
@dataclass(frozen=True)
class WrenchHull:
    """Convex hull of a set of wrenches and where the origin lies.

    Attributes
    ----------
    hull : scipy.spatial.ConvexHull or None
        None when the wrenches do not span the space (no interior).
    origin_inside : bool
        True when the origin is strictly inside, by more than ``tol``.
    margin : float
        Smallest signed distance from the origin to a facet plane, positive
        inside: when positive, the radius of the largest ball about the origin
        inside the hull (units of the wrenches).  0.0 when ``hull`` is None.
    rank : int
        Rank of the wrench matrix.
    """

    hull: Any
    origin_inside: bool
    margin: float
    rank: int


@checked_call
def wrench_hull(W: np.ndarray, *, tol: float = ORIGIN_CLEARANCE_TOL) -> WrenchHull:
    """Convex hull of the columns of ``W`` and whether it contains the origin.

    Parameters
    ----------
    W : (m, K) float
        Wrenches as columns, ``2 <= m <= MAX_HULL_DIM`` (6, a spatial wrench)
        and ``K >= 0`` columns, at most as many as can have
        :data:`MAX_HULL_FACETS` facets in ``m`` dimensions (1,000,000 in 2-D,
        500,002 in 3-D, 1,415 in 4-D, 1,003 in 5-D, 184 in 6-D); every entry
        real, finite and at most :data:`WRENCH_BOUND` (1e100) in absolute
        value.
    tol : float, optional
        The origin counts as inside only when every facet is farther than
        ``tol``: a real number, finite and >= 0 (units of ``W``).

    Returns
    -------
    WrenchHull

    Raises
    ------
    InvalidOptionError
        For a ``W`` that is not a 2-D real array with 2 to 6 rows (a 1-D or
        an empty-shaped one), has more columns than that (whatever their
        values: Qhull could run for minutes), a NaN or infinite entry or one
        beyond :data:`WRENCH_BOUND`, or a ``tol`` that is not a finite real
        >= 0.
    """
    from scipy.spatial import ConvexHull, QhullError

    W = real_array("W", W, error=InvalidOptionError)
    if W.ndim != 2 or not (2 <= W.shape[0] <= MAX_HULL_DIM):
        raise InvalidOptionError(
            f"W must be an (m, K) array of wrenches as columns with 2 <= m <= "
            f"{MAX_HULL_DIM} (3 planar, 6 spatial), got shape {W.shape}"
        )
    m, K = W.shape
    if _most_hull_facets(m, K) > MAX_HULL_FACETS:
        raise InvalidOptionError(
            f"W has {K} columns in {m} dimensions, whose hull may have "
            f"{_most_hull_facets(m, K):.3g} facets, more than MAX_HULL_FACETS = "
            f"{MAX_HULL_FACETS:g} (drakegrasp.visualization.wrench_space; Qhull "
            f"could run for minutes): pass at most {_most_hull_columns(m)} "
            f"columns of {m} rows"
        )
    if W.size and not float(np.max(np.abs(W))) <= WRENCH_BOUND:  # NaN fails too
        raise InvalidOptionError(
            f"W must be finite with every |w| <= {WRENCH_BOUND:g} "
            "(drakegrasp.visualization.wrench_space.WRENCH_BOUND), got "
            + ("a NaN or infinite entry" if not np.all(np.isfinite(W)) else
               f"an entry of {float(np.max(np.abs(W))):.6g}")
        )  # fmt: skip
    tol = real_scalar("tol", tol)
    if not (0.0 <= tol < np.inf):
        raise InvalidOptionError(
            f"tol must be a finite real number >= 0, got {describe(tol)}"
        )
    rank = int(np.linalg.matrix_rank(W)) if K else 0
    # The hull has an interior only if the points' affine hull is m-dimensional.
    affine_rank = int(np.linalg.matrix_rank(W[:, 1:] - W[:, :1])) if K > 1 else 0
    if K < m + 1 or affine_rank < m:
        return WrenchHull(None, False, 0.0, rank)
    try:
        hull = ConvexHull(W.T)
    except QhullError:
        return WrenchHull(None, False, 0.0, rank)
    # equations: [normal, offset] with unit outward normals; inside: n·x + o <= 0.
    margin = float(-np.max(hull.equations[:, -1]))
    return WrenchHull(hull, margin > tol, margin, rank)


@checked_call
@dataclass(frozen=True)
class WrenchSpacePlot:
    """Artists and data of :func:`plot_wrench_space`.

    Attributes
    ----------
    ax : mpl_toolkits.mplot3d.axes3d.Axes3D
    wrenches : (3, K) ndarray
        Primitive wrenches ``[fx, fy, mz / b]`` that were drawn.
    contact_index : (K,) ndarray of int
        Contact of each wrench.
    points : matplotlib collection
        The wrenches as points.
    rays : Line3DCollection or None
        Segments from the origin to each wrench.
    hull : WrenchHull
        Hull data, including ``origin_inside`` and ``margin``.
    hull_artist : Poly3DCollection or None
        Hull facets (None when ``hull=False`` or the hull is degenerate).
    origin : matplotlib collection
        The origin marker (green when inside, red when not).
    separating_plane : CertificateArtists or None
        The certificate's separating plane and unresisted direction, when a
        "no" result was given.
    """

    ax: Any
    wrenches: np.ndarray
    contact_index: np.ndarray
    points: Any
    rays: Any
    hull: WrenchHull
    hull_artist: Any
    origin: Any
    separating_plane: Any = None

    @property
    def origin_inside(self) -> bool:
        """True when the origin is strictly inside the hull (force closure)."""
        return self.hull.origin_inside


@checked_call
def plot_wrench_space(
    grasp: Grasp,
    *,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    ax: Any = None,
    hull: bool = True,
    rays: bool = True,
    tol: float = ORIGIN_CLEARANCE_TOL,
    result: Any = None,
) -> WrenchSpacePlot:
    """Plot the primitive wrenches of a planar grasp and their convex hull.

    Parameters
    ----------
    grasp : Grasp
        A planar grasp (its wrench space ``(fx, fy, mz / b)`` is 3-D).
    num_generators : int, optional
        Passed to :func:`wrench_space_points` (planar cones are exact, so it
        only matters for the validation of the value).
    ax : Axes3D, optional
        A 3-D axes (``fig.add_subplot(projection="3d")``); a new figure when
        omitted.
    hull : bool, optional
        Draw the convex hull's facets (translucent): True or False.
    rays : bool, optional
        Draw a segment from the origin to each primitive wrench: True or
        False.
    tol : float, optional
        Margin the origin needs to count as inside (see :func:`wrench_hull`).
    result : ClosureResult, optional
        A verdict of this grasp (a result with a boolean ``is_closure``); for
        a force-closure "no" its certificate's separating plane ``yᵀ w = 0``
        (every primitive wrench lies on one side) and the unresisted direction
        are drawn in red (see
        :func:`~drakegrasp.visualization.certificate_plots.plot_separating_plane`).

    Returns
    -------
    WrenchSpacePlot

    Raises
    ------
    InvalidOptionError
        For a spatial grasp (6-D wrench space), an ``ax`` that is not a 3-D
        axes, a ``hull`` or ``rays`` that is not a boolean, a ``result`` that
        is not a verdict, or a "no" whose certificate is of another grasp or
        has no finite, non-zero separating twist.  Nothing is drawn then.
    ImportError
        When matplotlib (or scipy) is not installed.
    """
    if not isinstance(grasp, Grasp):
        raise InvalidOptionError(
            f"plot_wrench_space needs a drakegrasp.Grasp, got {type(grasp).__name__}"
        )
    tol = real_scalar("tol", tol)
    if not (0.0 < tol < 1.0):
        raise InvalidOptionError(
            f"tol must be a real number in (0, 1), got {describe(tol)}"
        )
    if not grasp.planar:
        raise InvalidOptionError(
            "plot_wrench_space draws planar grasps, whose wrench space is 3-D; "
            "this grasp is spatial (6-D wrenches)"
        )
    hull, rays = check_flag("hull", hull), check_flag("rays", rays)
    plt = import_pyplot()
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    from drakegrasp.visualization.certificate_plots import (
        check_axes,
        checked_separating_plane,
        plot_separating_plane,
    )

    cert = None
    if result is not None:
        is_closure = getattr(result, "is_closure", None)
        if not isinstance(is_closure, bool | np.bool_):
            raise InvalidOptionError(
                "result must be a verdict of this grasp (a ClosureResult such as "
                f"force_closure(grasp)), got {describe(result)} "
                f"({type(result).__name__})"
            )
        cert = getattr(result, "certificate", None)
        if getattr(cert, "separating_twist", None) is None or is_closure:
            cert = None
        else:
            checked_separating_plane(grasp, cert)
    if ax is None:
        fig = plt.figure()
        ax = fig.add_subplot(projection="3d")
    else:
        check_axes(ax, "3d")
    W, owner = wrench_space_points(grasp, num_generators=num_generators)
    info = wrench_hull(W, tol=tol)
    cmap = plt.get_cmap("tab10")
    colors = [cmap(i % 10) for i in owner]
    points = ax.scatter(W[0], W[1], W[2], c=colors, s=30, depthshade=False)
    ray_artist = None
    if rays:
        segments = [[(0.0, 0.0, 0.0), tuple(w)] for w in W.T]
        ray_artist = Line3DCollection(segments, colors=colors, linewidths=1.0)
        ax.add_collection3d(ray_artist)
    hull_artist = None
    if hull and info.hull is not None:
        faces = [W.T[s] for s in info.hull.simplices]
        hull_artist = Poly3DCollection(
            faces, facecolors=(0.3, 0.5, 0.9, 0.18), edgecolors=(0.2, 0.3, 0.6, 0.6)
        )
        ax.add_collection3d(hull_artist)
    origin_color = "tab:green" if info.origin_inside else "tab:red"
    origin = ax.scatter(
        [0.0], [0.0], [0.0], c=origin_color, marker="X", s=80, depthshade=False
    )
    extent = float(np.max(np.abs(W))) * 1.1 if W.size else 1.0
    for setter in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        setter(-extent, extent)
    ax.set_xlabel("$f_x$ [N]")
    ax.set_ylabel("$f_y$ [N]")
    ax.set_zlabel("$m_z / b$ [N]")
    where = "inside" if info.origin_inside else "NOT inside"
    ax.set_title(f"origin {where} the hull (margin {info.margin:.3g})")
    plane = None
    if cert is not None:
        plane = plot_separating_plane(ax, grasp, cert, extent)
    return WrenchSpacePlot(
        ax, W, owner, points, ray_artist, info, hull_artist, origin, plane
    )
