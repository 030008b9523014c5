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

__all__ = [
    "CertificateArtists",
    "planar_motion",
    "plot_escape",
    "plot_separating_plane",
    "plot_unresisted_wrench",
]

_GREEN, _RED, _PLANE = "tab:green", "tab:red", (0.85, 0.2, 0.2, 0.22)


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


def planar_motion(
    twist: np.ndarray, p: np.ndarray, t: float, X: np.ndarray
) -> np.ndarray:
    """Points ``X`` (M, 2) moved by ``exp(t ξ)`` of a planar twist about ``p``."""
    v, w = np.asarray(twist[:2], float), float(twist[2])
    X = np.asarray(X, float)
    if abs(w) < 1e-12:
        return X + t * v
    centre = screw_point(np.asarray(p, float), v, np.array([w]))
    c, s = np.cos(t * w), np.sin(t * w)
    R = np.array([[c, -s], [s, c]])
    return (X - centre) @ R.T + centre


def _outline_points(outline) -> np.ndarray | None:
    if outline is None:
        return None
    # flatten Bézier curves (a Circle's path) into a polygon in data coordinates
    path = outline.get_patch_transform().transform_path(outline.get_path())
    polygons = path.to_polygons(closed_only=False)
    return np.vstack(polygons) if polygons else None


def plot_escape(
    ax, grasp: Grasp, cert: Certificate, *, outline=None, amount: float = 0.25
) -> CertificateArtists:
    """Ghost of the object moved along a planar escape twist.

    Parameters
    ----------
    ax : matplotlib Axes (2-D)
    grasp : Grasp
        Planar.
    cert : Certificate
        An escape twist.
    outline : matplotlib Patch, optional
        The object's outline as drawn (its vertices are moved).
    amount : float, optional
        Largest twist parameter over ``b``.

    Returns
    -------
    CertificateArtists
    """
    b = grasp.characteristic_length
    t = amount * b
    v = np.asarray(cert.direction, float)
    p = np.asarray(cert.reference_point, float)
    ghost = None
    pts = _outline_points(outline)
    if pts is not None:
        moved = planar_motion(v, p, t, pts)
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
    """The external wrench a planar grasp cannot resist, on a grasp plot."""
    from matplotlib.patches import FancyArrowPatch

    b = grasp.characteristic_length
    e = -np.asarray(cert.direction, float)  # the external wrench
    p = np.asarray(cert.reference_point, float)
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


def plot_separating_plane(
    ax, grasp: Grasp, cert: Certificate, extent: float
) -> CertificateArtists:
    """The plane ``yᵀ w = 0`` and the unresisted direction, in ``(f, m/b)``.

    The wrench-space axes are ``(f_x, f_y, m_z / b)``, so the plane's normal
    there is ``(y_x, y_y, b y_ω)``; the arrow is the wrench the fingers cannot
    apply (the grasp cannot resist its opposite).
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    b = grasp.characteristic_length
    y = np.asarray(cert.separating_twist, float)
    normal = np.array([y[0], y[1], b * y[2]])
    normal /= np.linalg.norm(normal)
    u = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(u) < 0.3:
        u = np.cross(normal, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    s = 0.9 * extent
    square = [s * (a * u + c * v) for a, c in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    plane = Poly3DCollection([square], facecolors=[_PLANE], edgecolors=[_RED])
    ax.add_collection3d(plane)
    w = np.asarray(cert.direction, float)
    w_plot = np.array([w[0], w[1], w[2] / b])
    w_plot *= 0.8 * extent / np.linalg.norm(w_plot)
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
