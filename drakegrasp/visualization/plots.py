"""matplotlib pictures of planar grasps: outline, contacts, normals, cones, forces.

matplotlib is an optional dependency (the ``viz`` extra): it is imported only
when a function here is called, and its absence raises an ImportError that says
how to install it.  Headless use works with the Agg backend.

By default cones open away from the object and force arrows end at the contact
point (the finger pushes); see :mod:`drakegrasp.visualization.geometry` on
``side``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from drakegrasp.certificates.certificate import (
    ESCAPE_TWIST,
    UNRESISTED_WRENCH,
    Certificate,
)
from drakegrasp.core.calls import checked_call
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.validation import (
    check_flag,
    check_length,
    describe,
    real_array,
    safe_norm,
)
from drakegrasp.errors import InvalidOptionError
from drakegrasp.visualization.certificate_plots import (
    check_axes,
    plot_escape,
    plot_unresisted_wrench,
)
from drakegrasp.visualization.geometry import (
    DRAW_LENGTH_MAX,
    cone_edge_directions,
    contact_forces_in_grasp_frame,
    merge_palette,
    normalize_contact_forces,
    positive_length,
    side_sign,
)
from drakegrasp.visualization.meshcat_certificates import checked_certificate

__all__ = ["PLOT_COLORS", "PlanarGraspPlot", "import_pyplot", "plot_planar_grasp"]

PLOT_COLORS: dict[str, Any] = {
    "outline": (0.85, 0.85, 0.85, 1.0),
    "outline_edge": (0.3, 0.3, 0.3, 1.0),
    "contact": "black",
    "normal": "tab:red",
    "cone": (0.12, 0.47, 0.71, 0.3),
    "cone_edge": (0.12, 0.47, 0.71, 1.0),
    "force": "tab:purple",
}
"""Default colours of :func:`plot_planar_grasp`; override entries with ``colors=``."""


def import_pyplot():
    """Import ``matplotlib.pyplot``, or explain how to install matplotlib.

    Raises
    ------
    ImportError
        When matplotlib is not installed.
    """
    try:
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "drakegrasp's plots need matplotlib, an optional dependency: "
            "pip install 'drakegrasp[viz]' (or pip install matplotlib)"
        ) from exc
    return plt


@checked_call
@dataclass(frozen=True)
class PlanarGraspPlot:
    """Artists of :func:`plot_planar_grasp`, for inspection or restyling.

    Attributes
    ----------
    ax : matplotlib.axes.Axes
    outline : matplotlib.patches.Patch or None
        The object outline.
    contacts : matplotlib.collections.PathCollection
        Contact points (one marker per contact, in contact order).
    normals : matplotlib.quiver.Quiver or None
        One arrow per contact along its inward normal ``n``.
    cones : tuple of (matplotlib.patches.Polygon or None)
        Per contact, the exact friction cone as a wedge ``[apex, edge+, edge-]``
        (None for a contact without friction, whose cone is its normal ray).
    forces : matplotlib.quiver.Quiver or None
        One arrow per contact with the contact force (in the grasp frame).
    labels : tuple of matplotlib.text.Text
        Contact numbers.
    cone_length : float
        Length of each drawn cone edge, metres.
    force_scale : float
        Arrow length per newton (m/N); 0 when no forces were drawn.
    certificate : CertificateArtists or None
        For a "no" result: the escape ghost or the unresisted wrench (see
        :mod:`drakegrasp.visualization.certificate_plots`).
    """

    ax: Any
    outline: Any
    contacts: Any
    normals: Any
    cones: tuple[Any, ...]
    forces: Any
    labels: tuple[Any, ...]
    cone_length: float
    force_scale: float
    certificate: Any = None


def _outline_patch(outline: Any, colors: Mapping[str, Any]):
    from matplotlib.patches import Circle, Patch, Polygon

    style = {"facecolor": colors["outline"], "edgecolor": colors["outline_edge"]}
    if isinstance(outline, Patch):
        return outline
    if isinstance(outline, Mapping):
        if set(outline) != {"center", "radius"}:
            raise InvalidOptionError(
                "a circle outline is a mapping with keys 'center' and 'radius', "
                f"got keys {describe(list(outline))}"
            )
        center = real_array(
            "circle center", outline["center"], error=InvalidOptionError
        ).reshape(-1)
        radius = positive_length("outline radius", outline["radius"])
        if center.shape != (2,) or not np.all(np.isfinite(center)):
            raise InvalidOptionError(
                "circle center must be a finite 2-vector, got "
                f"{describe(outline['center'])}"
            )
        return Circle(tuple(center), radius, **style)
    pts = real_array("outline", outline, error=InvalidOptionError)
    if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 3:
        raise InvalidOptionError(
            "outline must be an (M, 2) polygon with M >= 3, a mapping "
            "{'center': (x, y), 'radius': r}, or a matplotlib Patch; got an "
            f"array of shape {pts.shape}"
        )
    if not np.all(np.isfinite(pts)):
        raise InvalidOptionError("outline vertices must be finite")
    return Polygon(pts, closed=True, **style)


def _arrows(ax, tails, vectors, color, width: float, *, zorder: int):
    """Arrows from ``tails`` along ``vectors`` ((M, 2), data units), none hidden.

    ``minlength=0``: a short arrow is drawn as an arrow, never as a dot.
    """
    return ax.quiver(
        tails[:, 0],
        tails[:, 1],
        vectors[:, 0],
        vectors[:, 1],
        angles="xy",
        scale_units="xy",
        scale=1.0,
        color=color,
        width=width,
        minlength=0.0,
        zorder=zorder,
    )


@checked_call
def plot_planar_grasp(
    grasp: Grasp,
    *,
    ax: Any = None,
    outline: Any = None,
    result: Any = None,
    cone_length: float | None = None,
    force_scale: float | None = None,
    side: str = "outside",
    show_normals: bool = True,
    show_labels: bool = True,
    colors: Mapping[str, Any] | None = None,
) -> PlanarGraspPlot:
    """Draw a planar grasp: outline, contacts, normals, exact cones and forces.

    Parameters
    ----------
    grasp : Grasp
        A planar grasp; coordinates are the grasp frame's, metres.
    ax : matplotlib.axes.Axes, optional
        2-D axes to draw on; a new figure when omitted.  Its aspect is set
        equal and its limits fit the drawing.
    outline : (M, 2) array_like, mapping or Patch, optional
        The object: a polygon's vertices, ``{"center": (x, y), "radius": r}``
        for a disc, or any matplotlib patch (added as given).
    result : ClosureResult or sequence of array_like, optional
        Contact forces to draw: a result with ``contact_forces`` or one array
        per contact in its contact frame, ``[f_n, f_t]`` (newtons).  For a
        "no" result its certificate is drawn too: an escape twist as a dashed
        ghost of the outline moved along it, with each contact's velocity and
        the centre of rotation; an unresisted wrench as the external force
        (or moment) the grasp cannot resist, in red.
    cone_length : float, optional
        Length of the drawn cone edges and normal arrows, metres.  Default
        0.3 b (b: the grasp's characteristic length).
    force_scale : float, optional
        Arrow length per newton (m/N).  Default: the largest force is 0.6 b
        long.
    side : {"outside", "inside"}, optional
        ``"outside"``: cones open away from the object (apex at the contact,
        edges along ``-R[1, ±μ]``) and normal and force arrows end at the
        contact point; ``"inside"``: cones open along ``R[1, ±μ]`` and arrows
        start at the contact point.
    show_normals, show_labels : bool, optional
        Draw the normal arrows / the contact numbers.
    colors : mapping, optional
        Overrides of :data:`PLOT_COLORS`.

    Returns
    -------
    PlanarGraspPlot
        The axes and every artist drawn.

    Raises
    ------
    InvalidOptionError
        For a spatial grasp, a bad outline, size, side, colour key, or forces
        that do not match the contacts.
    ImportError
        When matplotlib is not installed.
    """
    if not isinstance(grasp, Grasp):
        raise InvalidOptionError(
            f"plot_planar_grasp needs a drakegrasp.Grasp, got {type(grasp).__name__}"
        )
    _check_plot_options(colors, outline, force_scale)
    show_normals = check_flag("show_normals", show_normals)
    show_labels = check_flag("show_labels", show_labels)
    if not grasp.planar:
        raise InvalidOptionError(
            "plot_planar_grasp draws planar grasps; this grasp is spatial "
            "(use drakegrasp.visualization.draw_grasp with Meshcat)"
        )
    sign = side_sign(side)
    palette = merge_palette(PLOT_COLORS, colors)
    b = grasp.characteristic_length
    # A given length is checked; the default is a fraction of a valid b.
    L = 0.3 * b if cone_length is None else positive_length("cone_length", cone_length)
    forces = normalize_contact_forces(grasp, result)
    f_G = None if forces is None else contact_forces_in_grasp_frame(grasp, forces)
    scale = 0.0
    if f_G is not None:
        largest = float(np.max(safe_norm(f_G, axis=1)))  # no overflow
        if force_scale is not None:
            scale = positive_length("force_scale", force_scale, unit="m/N")
        elif largest > 0:
            scale = 0.6 * b / largest
        if not scale * largest <= DRAW_LENGTH_MAX:
            raise InvalidOptionError(
                f"force_scale {scale!r} m/N draws the largest force ({largest:.6g} "
                f"N) {scale * largest:.6g} m long, beyond {DRAW_LENGTH_MAX:g} m "
                "(drakegrasp.visualization.geometry.DRAW_LENGTH_MAX); pass a "
                "smaller force_scale"
            )
    plt = import_pyplot()
    from matplotlib.patches import Polygon

    patch = None if outline is None else _outline_patch(outline, palette)

    if ax is not None:
        check_axes(ax, "rectilinear")
    cert = _certificate_to_draw(grasp, result)  # checked before anything is drawn
    if ax is None:
        _, ax = plt.subplots()
    C = grasp.positions
    Nrm = grasp.normals
    extent = [C]
    if patch is not None:
        ax.add_patch(patch)
        patch.set_zorder(0)
        # Vertices in data coordinates (a Circle's path is the unit circle).
        verts = patch.get_patch_transform().transform(patch.get_path().vertices)
        if len(verts):
            extent.append(np.asarray(verts))

    cones = []
    for contact in grasp.contacts:
        if 1 not in contact.effective_components():
            cones.append(None)
            continue
        U = cone_edge_directions(contact)
        c = contact.position
        wedge = np.vstack([c, c + sign * L * U[0], c + sign * L * U[1]])
        poly = Polygon(
            wedge,
            closed=True,
            facecolor=palette["cone"],
            edgecolor=palette["cone_edge"],
            linewidth=1.2,
            zorder=1,
        )
        ax.add_patch(poly)
        cones.append(poly)
        extent.append(wedge)

    normals = None
    if show_normals:
        tails = C if sign > 0 else C - L * Nrm
        normals = _arrows(ax, tails, L * Nrm, palette["normal"], 0.006, zorder=3)
        extent.append(tails)

    force_artist = None
    if f_G is not None and scale > 0:
        vec = scale * f_G
        tails = C if sign > 0 else C - vec
        force_artist = _arrows(ax, tails, vec, palette["force"], 0.009, zorder=4)
        extent += [tails, tails + vec]

    points = ax.scatter(C[:, 0], C[:, 1], color=palette["contact"], s=25, zorder=5)
    labels = []
    if show_labels:
        offset = 0.1 * b
        for i, (c, n) in enumerate(zip(C, Nrm, strict=True)):
            # Put the number beside the contact, off the normal's line.
            t = np.array([-n[1], n[0]])
            x, y = c + offset * t
            labels.append(
                ax.text(x, y, str(i), fontsize=9, ha="center", va="center", zorder=6)
            )

    cert_artists = _draw_certificate(ax, grasp, cert, patch)
    if cert_artists is not None and cert_artists.ghost is not None:
        extent.append(np.asarray(cert_artists.ghost.get_xydata()))
    pts = np.vstack(extent)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = 0.1 * max(float(np.max(hi - lo)), b)
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    return PlanarGraspPlot(
        ax,
        patch,
        points,
        normals,
        tuple(cones),
        force_artist,
        tuple(labels),
        L,
        scale,
        cert_artists,
    )


def _certificate_to_draw(grasp: Grasp, result: Any):
    """A "no" result's certificate that :func:`plot_planar_grasp` draws, or None.

    An escape twist or an unresisted wrench is checked on ``grasp`` here
    (:func:`~drakegrasp.visualization.meshcat_certificates.checked_certificate`),
    so that another grasp's is refused before anything is drawn.
    """
    cert = getattr(result, "certificate", None)
    if not isinstance(cert, Certificate) or getattr(result, "is_closure", True):
        return None
    if cert.kind not in (ESCAPE_TWIST, UNRESISTED_WRENCH):
        return None
    checked_certificate(grasp, cert)
    return cert


def _draw_certificate(ax, grasp: Grasp, cert: Any, patch: Any):
    """Draw a "no" result's certificate (see :func:`plot_planar_grasp`)."""
    if cert is None:
        return None
    if cert.kind == ESCAPE_TWIST:
        return plot_escape(ax, grasp, cert, outline=patch)
    return plot_unresisted_wrench(ax, grasp, cert)


def _colour(is_color_like, value) -> bool:
    """Whether matplotlib can draw ``value``; not if reading it raises.

    matplotlib names a value it cannot read with its ``repr``, so a value whose
    ``repr`` raises made ``is_color_like`` raise instead of answering.
    """
    try:
        return bool(is_color_like(value))
    except Exception:  # noqa: BLE001 - a hostile repr or __array__
        return False


def _check_plot_options(colors, outline, force_scale) -> None:
    """Refuse colours matplotlib cannot draw, a text outline, a bad force scale."""
    if colors is not None:
        if not isinstance(colors, Mapping):
            raise InvalidOptionError(
                f"colors must be a mapping of names to colours, got {describe(colors)}"
            )
        from matplotlib.colors import is_color_like

        bad = {k: v for k, v in colors.items() if not _colour(is_color_like, v)}
        if bad:
            raise InvalidOptionError(
                f"colors {describe(bad)} are not matplotlib colours (names such as "
                "'red', '#1f77b4', or RGB(A) tuples in [0, 1])"
            )
    if isinstance(outline, (str, bytes)):
        raise InvalidOptionError(
            "outline must be polygon vertices (M, 2), {'center': ..., 'radius': "
            f"...}} or a matplotlib patch, got {describe(outline)}"
        )
    if force_scale is not None:
        check_length("force_scale", force_scale, error=InvalidOptionError)
