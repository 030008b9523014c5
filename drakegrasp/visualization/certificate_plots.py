"""matplotlib pictures of certificates: escape ghosts and separating planes.

* :func:`plot_escape` draws a planar escape twist on a grasp plot: a dashed
  ghost of the outline moved along ``exp(t ξ)``, the velocity of each contact
  point, and the centre of rotation.
* :func:`plot_unresisted_wrench` draws a planar unresisted wrench on a grasp
  plot: the external force along its line of action, or a moment arc.
* :func:`plot_separating_plane` draws, in the wrench space ``(f_x, f_y,
  m_z/b)``, the plane ``yᵀ w = 0`` that separates every wrench the grasp can
  apply from the unresisted direction, and that direction.

:func:`~drakegrasp.visualization.plot_planar_grasp` and
:func:`~drakegrasp.visualization.plot_wrench_space` call these for a "no"
result; they are public for use on any axes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from drakegrasp.certificates.certificate import (
    ESCAPE_TWIST,
    UNRESISTED_WRENCH,
    Certificate,
)
from drakegrasp.certificates.text import screw_point
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.validation import (
    check_grasp,
    check_positions,
    describe,
    real_array,
    real_scalar,
)
from drakegrasp.errors import InvalidOptionError
from drakegrasp.visualization.escape import (
    check_amount,
    check_finite_motion,
    checked_motion,
)
from drakegrasp.visualization.geometry import DRAW_LENGTH_MIN
from drakegrasp.visualization.meshcat_certificates import checked_certificate

__all__ = [
    "MAX_EXTENT",
    "CertificateArtists",
    "planar_motion",
    "plot_escape",
    "plot_separating_plane",
    "plot_unresisted_wrench",
]

MAX_EXTENT = 1e150
"""Largest ``extent`` (newtons) of :func:`plot_separating_plane`: every
coordinate it draws (at most 1.3 extent) and its square stay finite.  Above
what :func:`~drakegrasp.visualization.plot_wrench_space` passes, 1.1 times
the largest wrench entry (at most
:data:`~drakegrasp.visualization.wrench_space.WRENCH_BOUND`, 1e100)."""

_GREEN, _RED, _PLANE = "tab:green", "tab:red", (0.85, 0.2, 0.2, 0.22)

_AXES = {
    "rectilinear": "a 2-D axes (plt.subplots())",
    "3d": "a 3-D axes (fig.add_subplot(projection='3d'))",
}


@dataclass(frozen=True)
class CertificateArtists:
    """Artists drawn for a certificate (any may be None).

    Attributes
    ----------
    kind : str
        The certificate's kind.
    ghost : matplotlib artist or None
        Escape: the displaced outline.
    arrows : matplotlib artist or None
        Escape: contact velocities; wrench: the external force or moment.
    point : matplotlib artist or None
        The centre of rotation or a point of the line of action.
    plane : matplotlib artist or None
        Wrench space: the separating plane.
    """

    kind: str
    ghost: Any = None
    arrows: Any = None
    point: Any = None
    plane: Any = None


def check_axes(ax: Any, projection: str) -> None:
    """Refuse anything but a matplotlib axes of ``projection``.

    Parameters
    ----------
    ax : matplotlib Axes
    projection : {"rectilinear", "3d"}
        A 2-D or a 3-D axes.

    Raises
    ------
    InvalidOptionError
        For an ``ax`` that is not a matplotlib axes (None, a string...) or is
        one of another projection (a polar axes, a 3-D axes for 2-D...).
    """
    from matplotlib.axes import Axes

    if not isinstance(ax, Axes) or ax.name != projection:
        got = (
            f"a {ax.name!r} axes"
            if isinstance(ax, Axes)
            else f"{describe(ax)} ({type(ax).__name__})"
        )
        raise InvalidOptionError(f"ax must be {_AXES[projection]}, got {got}")


def planar_motion(
    twist: np.ndarray, p: np.ndarray, t: float, X: np.ndarray
) -> np.ndarray:
    """Points ``X`` (M, 2) moved by ``exp(t ξ)`` of a planar twist about ``p``.

    Parameters
    ----------
    twist : (3,) array_like
        ``[v_x, v_y, ω]`` (m/s, rad/s), the velocity of ``p`` and the angular
        velocity: real and finite.
    p : (2,) array_like
        The point the twist is about, metres: real, finite, every ``|x| <=``
        :data:`~drakegrasp.core.validation.POSITION_BOUND` (1e20).
    t : float
        The twist parameter: a real, finite number.
    X : (M, 2) array_like
        The points, metres (``M >= 0``), in the range of ``p``.

    Returns
    -------
    (M, 2) float
        The moved points.

    Raises
    ------
    InvalidOptionError
        For a ``twist``, ``p``, ``t`` or ``X`` that is not so (None, a string,
        a bool, complex, NaN, another shape), naming it, or a motion that
        overflows (a ``t`` and ``twist`` that move a point beyond the
        floating-point range).
    """
    twist, p, t = checked_motion(twist, p, t, dim=2)
    X = check_positions("X", X, error=InvalidOptionError)
    if X.ndim != 2 or X.shape[1] != 2:
        raise InvalidOptionError(
            f"X must be an (M, 2) array of points, got shape {X.shape}"
        )
    return _planar_flow(twist, p, t, X)


def _planar_flow(twist: np.ndarray, p: np.ndarray, t: float, X: np.ndarray):
    """:func:`planar_motion` of checked arrays (overflow is still refused)."""
    v, w = twist[:2], float(twist[2])
    with np.errstate(over="ignore", invalid="ignore"):  # checked below
        if abs(w) < 1e-12:
            moved = X + t * v
            check_finite_motion(t * v, moved)
            return moved
        centre = screw_point(p, v, np.array([w]))
        c, s = np.cos(t * w), np.sin(t * w)
        R = np.array([[c, -s], [s, c]])
        moved = (X - centre) @ R.T + centre
    check_finite_motion(centre, t * w, moved)
    return moved


def _checked(
    caller: str, grasp: Any, cert: Any, kind: str
) -> tuple[np.ndarray, np.ndarray, float]:
    """A planar grasp's certificate of ``kind``: (direction, p, b), checked.

    The direction is the certificate's own when it has the certificate's
    scaling (``‖[v; b ω]‖ = 1``, ``‖[f; m / b]‖ = 1``) and that scaling of it
    otherwise, so that every point drawn stays finite; ``p`` is its reference
    point (the grasp's when it has none).

    Raises
    ------
    InvalidGraspError
        For a ``grasp`` that is not a Grasp.
    InvalidOptionError
        For a spatial grasp, a ``cert`` that is not a Certificate of ``kind``
        (a result, None, another kind) or one of another grasp, or a
        direction that is zero or not finite (see
        :func:`~drakegrasp.visualization.meshcat_certificates.checked_certificate`).
    """
    check_grasp(grasp)
    if not grasp.planar:
        raise InvalidOptionError(
            f"{caller} draws the certificates of planar grasps; this grasp is "
            "spatial (draw its certificate in Meshcat: "
            "drakegrasp.visualization.draw_grasp with result=)"
        )
    if not isinstance(cert, Certificate) or cert.kind != kind:
        got = (
            f"a certificate of kind {cert.kind!r}"
            if isinstance(cert, Certificate)
            else f"{describe(cert)} ({type(cert).__name__})"
        )
        raise InvalidOptionError(
            f"cert must be a Certificate of kind {kind!r} (the certificate of a "
            f"{'form' if kind == ESCAPE_TWIST else 'force'}-closure 'no', "
            f"result.certificate), got {got}"
        )
    unit, _ = checked_certificate(grasp, cert)
    own = np.asarray(cert.direction, dtype=float)
    direction = own if float(np.max(np.abs(own - unit))) <= 1e-9 else unit
    point = (
        grasp.reference_point if cert.reference_point is None else cert.reference_point
    )
    return direction, np.asarray(point, dtype=float), grasp.characteristic_length


def _outline_points(outline) -> np.ndarray | None:
    """The vertices of a patch as drawn (data coordinates), checked."""
    if outline is None:
        return None
    from matplotlib.patches import Patch

    if not isinstance(outline, Patch):
        raise InvalidOptionError(
            "outline must be a matplotlib Patch (the object's outline as drawn: "
            "plot_planar_grasp's .outline) or None, got "
            f"{describe(outline)} ({type(outline).__name__})"
        )
    # flatten Bézier curves (a Circle's path) into a polygon in data coordinates
    path = outline.get_patch_transform().transform_path(outline.get_path())
    check_positions("the outline's vertices", path.vertices, error=InvalidOptionError)
    polygons = path.to_polygons(closed_only=False)
    return np.vstack(polygons) if polygons else None


def plot_escape(
    ax, grasp: Grasp, cert: Certificate, *, outline=None, amount: float = 0.25
) -> CertificateArtists:
    """Ghost of the object moved along a planar escape twist.

    Parameters
    ----------
    ax : matplotlib Axes (2-D)
        A rectilinear axes (``plt.subplots()``); not a polar or 3-D one.
    grasp : Grasp
        Planar.
    cert : Certificate
        An escape twist of ``grasp`` (``form_closure(grasp).certificate`` of a
        "no"): its reference point and characteristic length are the grasp's.
    outline : matplotlib Patch, optional
        The object's outline as drawn (its vertices are moved): finite, in the
        range of a position (every ``|x| <=`` 1e20 m,
        :data:`~drakegrasp.core.validation.POSITION_BOUND`).
    amount : float, optional
        Largest twist parameter over ``b``: a real number in
        ``(0, MAX_AMOUNT]`` = (0, 100]
        (:data:`drakegrasp.visualization.escape.MAX_AMOUNT`).

    Returns
    -------
    CertificateArtists

    Raises
    ------
    InvalidOptionError
        For an ``ax`` that is not a 2-D matplotlib axes, a spatial grasp, a
        ``cert`` that is not an escape twist of ``grasp`` (None, a result,
        another kind, another grasp's, a zero or non-finite direction), an
        ``amount`` out of range or an ``outline`` that is not a finite Patch.
        Nothing is drawn then.
    InvalidGraspError
        For a ``grasp`` that is not a Grasp.
    """
    check_axes(ax, "rectilinear")
    v, p, b = _checked("plot_escape", grasp, cert, ESCAPE_TWIST)
    t = check_amount(amount) * b
    pts = _outline_points(outline)
    ghost = None
    if pts is not None:
        moved = _planar_flow(v, p, t, pts)
        (ghost,) = ax.plot(
            moved[:, 0],
            moved[:, 1],
            "--",
            color=_GREEN,
            lw=1.5,
            zorder=2,
            label="escape (ghost)",
        )
    C = grasp.positions
    vel = v[:2] + v[2] * np.column_stack([-(C[:, 1] - p[1]), C[:, 0] - p[0]])
    arrows = ax.quiver(
        C[:, 0],
        C[:, 1],
        t * vel[:, 0],
        t * vel[:, 1],
        angles="xy",
        scale_units="xy",
        scale=1.0,
        color=_GREEN,
        width=0.006,
        zorder=5,
    )
    point = None
    if abs(v[2]) * b > 1e-6 * np.linalg.norm(v[:2]):
        r = screw_point(p, v[:2], v[2:])
        point = ax.scatter([r[0]], [r[1]], marker="+", s=120, color=_GREEN, zorder=6)
    return CertificateArtists(ESCAPE_TWIST, ghost=ghost, arrows=arrows, point=point)


def plot_unresisted_wrench(ax, grasp: Grasp, cert: Certificate) -> CertificateArtists:
    """The external wrench a planar grasp cannot resist, on a grasp plot.

    Parameters
    ----------
    ax : matplotlib Axes (2-D)
        A rectilinear axes (``plt.subplots()``).
    grasp : Grasp
        Planar.
    cert : Certificate
        An unresisted wrench of ``grasp`` (``force_closure(grasp).certificate``
        of a "no").

    Returns
    -------
    CertificateArtists

    Raises
    ------
    InvalidOptionError
        For an ``ax`` that is not a 2-D matplotlib axes, a spatial grasp or a
        ``cert`` that is not an unresisted wrench of ``grasp`` (None, a result,
        another kind, another grasp's, a zero or non-finite direction).
        Nothing is drawn then.
    InvalidGraspError
        For a ``grasp`` that is not a Grasp.
    """
    from matplotlib.patches import FancyArrowPatch

    check_axes(ax, "rectilinear")
    direction, p, b = _checked("plot_unresisted_wrench", grasp, cert, UNRESISTED_WRENCH)
    e = -direction  # the external wrench
    f, m = e[:2], float(e[2])
    if np.linalg.norm(f) * b > 1e-6 * abs(m):
        r = p + m * np.array([f[1], -f[0]]) / float(f @ f)
        u = f / np.linalg.norm(f) * 0.8 * b
        arrow = FancyArrowPatch(
            tuple(r - u),
            tuple(r),
            arrowstyle="-|>",
            mutation_scale=18,
            color=_RED,
            lw=2.5,
            zorder=6,
        )
    else:
        r = p
        sense = "arc3,rad=0.6" if m > 0 else "arc3,rad=-0.6"
        start, end = p + np.array([0.4 * b, 0.0]), p + np.array([0.0, 0.4 * b])
        if m < 0:
            start, end = end, start
        arrow = FancyArrowPatch(
            tuple(start),
            tuple(end),
            connectionstyle=sense,
            arrowstyle="-|>",
            mutation_scale=18,
            color=_RED,
            lw=2.5,
            zorder=6,
        )
    ax.add_patch(arrow)
    point = ax.scatter([r[0]], [r[1]], marker="o", s=20, color=_RED, zorder=6)
    return CertificateArtists(UNRESISTED_WRENCH, arrows=arrow, point=point)


def checked_separating_plane(
    grasp: Any, cert: Any
) -> tuple[np.ndarray, np.ndarray, float]:
    """What :func:`plot_separating_plane` draws of ``cert``, checked on ``grasp``.

    Returns
    -------
    direction : (3,) float
        The unresisted wrench (see :func:`plot_escape` on its scaling).
    normal : (3,) float
        The unit normal of the plane ``yᵀ w = 0`` in ``(f_x, f_y, m_z / b)``.
    b : float
        The grasp's characteristic length.

    Raises
    ------
    InvalidOptionError
        As :func:`plot_unresisted_wrench`, and for a ``separating_twist`` that
        is not a finite (3,) twist whose normal ``(y_x, y_y, b y_ω)`` has a
        finite, non-zero length (None, zero, NaN, 1e300...).
    InvalidGraspError
        For a ``grasp`` that is not a Grasp.
    """
    direction, _, b = _checked("plot_separating_plane", grasp, cert, UNRESISTED_WRENCH)
    message = (
        "the certificate's separating_twist must be a finite, non-zero (3,) twist "
        "y (the plane's normal, scaled as ‖[v; b ω]‖ = 1), got "
        f"{describe(cert.separating_twist)}"
    )
    if cert.separating_twist is None:
        raise InvalidOptionError(message)
    y = real_array(
        "the certificate's separating_twist",
        cert.separating_twist,
        error=InvalidOptionError,
    )
    if y.shape != (3,):
        raise InvalidOptionError(message)
    with np.errstate(over="ignore", invalid="ignore"):  # checked below
        normal = np.array([y[0], y[1], b * y[2]])
        size = np.linalg.norm(normal)
    if not (np.all(np.isfinite(y)) and 0.0 < size < np.inf):
        raise InvalidOptionError(message)
    return direction, normal / size, b


def plot_separating_plane(
    ax, grasp: Grasp, cert: Certificate, extent: float
) -> CertificateArtists:
    """The plane ``yᵀ w = 0`` and the unresisted direction, in ``(f, m/b)``.

    The wrench-space axes are ``(f_x, f_y, m_z / b)``, so the plane's normal
    there is ``(y_x, y_y, b y_ω)``; the arrow is the wrench the fingers cannot
    apply (the grasp cannot resist its opposite).

    Parameters
    ----------
    ax : Axes3D
        A 3-D axes (``fig.add_subplot(projection="3d")``).
    grasp : Grasp
        Planar.
    cert : Certificate
        An unresisted wrench of ``grasp`` with its ``separating_twist``
        (``force_closure(grasp).certificate`` of a "no").
    extent : float
        Half-width of the drawing, newtons (the plane's square is 1.8 extent
        wide): a real number in ``[DRAW_LENGTH_MIN, MAX_EXTENT]`` =
        [2.2e-308, 1e150] (:data:`MAX_EXTENT`).

    Returns
    -------
    CertificateArtists

    Raises
    ------
    InvalidOptionError
        For an ``ax`` that is not a 3-D axes, an ``extent`` out of range (NaN,
        0, negative, a string...), a spatial grasp, or a ``cert`` that is not
        an unresisted wrench of ``grasp`` (see :func:`plot_unresisted_wrench`)
        whose ``separating_twist`` is a finite (3,) twist with a finite,
        non-zero normal ``(y_x, y_y, b y_ω)``.  Nothing is drawn then.
    InvalidGraspError
        For a ``grasp`` that is not a Grasp.
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    check_axes(ax, "3d")
    size = real_scalar("extent", extent)
    if not (DRAW_LENGTH_MIN <= size <= MAX_EXTENT):
        raise InvalidOptionError(
            f"extent must be finite and > 0, a real number in [{DRAW_LENGTH_MIN:.3g}, "
            f"{MAX_EXTENT:g}] newtons (the half-width of the wrench-space axes; "
            "drakegrasp.visualization.certificate_plots.MAX_EXTENT), got "
            f"{describe(extent)}"
        )
    w, normal, b = checked_separating_plane(grasp, cert)
    u = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(u) < 0.3:
        u = np.cross(normal, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    s = 0.9 * size
    square = [s * (a * u + c * v) for a, c in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    plane = Poly3DCollection([square], facecolors=[_PLANE], edgecolors=[_RED])
    ax.add_collection3d(plane)
    w_plot = np.array([w[0], w[1], w[2] / b])
    w_plot *= 0.8 * size / np.linalg.norm(w_plot)
    arrow = ax.quiver(
        0, 0, 0, *w_plot, color=_RED, linewidth=2.5, arrow_length_ratio=0.15
    )
    ax.text(
        *(1.05 * w_plot),
        "fingers cannot apply",
        color=_RED,
        fontsize=8,
        bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.8, "pad": 1.0},
    )
    return CertificateArtists(UNRESISTED_WRENCH, arrows=arrow, plane=plane)
