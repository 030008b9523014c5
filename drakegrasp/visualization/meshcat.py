"""Draw a grasp in Drake's Meshcat: contacts, contact frames, cones and forces.

Everything one call draws lives under one Meshcat path (``prefix``), so a second
call with the same prefix replaces the drawing and :func:`clear_grasp` deletes it.
Meshcat accepts drawings without any browser connected.

Scene tree (``{prefix}`` carries ``X_WG``; each contact path carries ``X_GC_i``,
the contact frame ``R_i`` at the contact point, so everything below it is drawn in
contact-frame coordinates: x = normal, y = t1, z = t2)::

    {prefix}/contact_{i}/point          sphere at the contact point
    {prefix}/contact_{i}/frame/n|t1|t2  triad (red, green, blue)
    {prefix}/contact_{i}/cone/exact     Coulomb cone (translucent triangle mesh)
    {prefix}/contact_{i}/cone/pyramid   linearised cone (wireframe)
    {prefix}/contact_{i}/cone/ray       a frictionless contact's cone (a ray)
    {prefix}/contact_{i}/force          arrow: shaft and head

Planar grasps are drawn in the z = 0 plane of the grasp frame.  By default cones
open away from the object and force arrows end at the contact point (the finger
pushes); see :mod:`drakegrasp.visualization.geometry` on ``side``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydrake.geometry import Cylinder, Meshcat, Rgba, Sphere
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context

from drakegrasp.core.calls import checked_call
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import (
    check_flag,
    check_num_generators,
    describe,
    plain_str,
    safe_norm,
)
from drakegrasp.errors import InvalidOptionError
from drakegrasp.visualization.geometry import (
    DRAW_LENGTH_MAX,
    contact_pose_3d,
    exact_cone_mesh,
    merge_palette,
    normalize_contact_forces,
    positive_length,
    pyramid_generators,
    pyramid_mesh,
    side_sign,
)
from drakegrasp.visualization.meshcat_certificates import (
    draw_certificate,
    result_certificate,
)
from drakegrasp.visualization.primitives import (
    _draw_arrow,
    _set_mesh,
    check_meshcat,
    check_path,
)
from drakegrasp.visualization.robot import set_translucent, translucent_arguments
from drakegrasp.visualization.view import CameraView, camera_view, grasp_pose

__all__ = [
    "DEFAULT_PREFIX",
    "GraspDrawing",
    "MESHCAT_COLORS",
    "clear_grasp",
    "draw_grasp",
]

DEFAULT_PREFIX = "drakegrasp/grasp"

MESHCAT_COLORS: dict[str, tuple[float, float, float, float]] = {
    "point": (0.1, 0.1, 0.1, 1.0),
    "n": (0.85, 0.1, 0.1, 1.0),
    "t1": (0.1, 0.7, 0.1, 1.0),
    "t2": (0.1, 0.2, 0.9, 1.0),
    "cone": (0.1, 0.55, 1.0, 0.35),
    "pyramid": (0.0, 0.25, 0.6, 1.0),
    "ray": (0.0, 0.25, 0.6, 1.0),
    "force": (0.95, 0.05, 0.75, 1.0),
}
"""Default RGBA of each drawn part; override entries with ``colors=``."""

_CONE_CHOICES = ("exact", "pyramid", "both", None)


@checked_call
@dataclass(frozen=True)
class GraspDrawing:
    """What :func:`draw_grasp` put in the scene.

    Attributes
    ----------
    prefix : str
        Meshcat path that holds the whole drawing.
    paths : tuple of str
        Every object path drawn (under ``prefix``).
    cone_height : float
        Extent of each drawn cone along its normal, metres.
    force_scale : float
        Arrow length per newton, metres/N (0 when no forces were drawn).
    forces_G : (N, 3) ndarray or None
        Drawn contact forces in the grasp frame, newtons (planar: ``z = 0``).
    camera : CameraView or None
        Where the camera was aimed (None with ``keep_camera=True``).
    """

    prefix: str
    paths: tuple[str, ...]
    cone_height: float
    force_scale: float
    forces_G: np.ndarray | None
    camera: CameraView | None = None


def _rgba(colors: Mapping[str, Any], key: str) -> Rgba:
    value = colors[key]
    if isinstance(value, Rgba):
        return value
    v = [float(x) for x in value]
    if len(v) == 3:
        v.append(1.0)
    if len(v) != 4:
        raise InvalidOptionError(
            f"colour {describe(key)} must be RGB or RGBA, got {describe(value)}"
        )
    return Rgba(*v)


ON_TOP_RENDER_ORDER = 10.0
"""three.js ``renderOrder`` of an on-top drawing (other objects have 0)."""


def _draw_on_top(meshcat: Meshcat, path: str) -> None:
    """Draw the object at ``path`` over everything else in the scene.

    three.js skips the depth test for the object's material (nothing in front
    of it hides it) and renders it after the scene's geometry.  Drake keeps
    the object that ``SetObject`` sends in the child ``<object>`` of the path.
    """
    meshcat.SetProperty(f"{path}/<object>", "material.depthTest", False)
    meshcat.SetProperty(f"{path}/<object>", "renderOrder", ON_TOP_RENDER_ORDER)


@checked_call
def draw_grasp(
    meshcat: Meshcat,
    grasp: Grasp,
    *,
    X_WG: RigidTransform | None = None,
    result: Any = None,
    prefix: str = DEFAULT_PREFIX,
    cone: str | None = "exact",
    num_generators: int = DEFAULT_NUM_GENERATORS,
    cone_height: float | None = None,
    force_scale: float | None = None,
    point_radius: float | None = None,
    frame_length: float | None = None,
    show_frames: bool = True,
    side: str = "outside",
    colors: Mapping[str, Any] | None = None,
    on_top: bool = False,
    size: float | None = None,
    translucent: str | Sequence[str] = (),
    translucent_opacity: float = 0.3,
    plant: MultibodyPlant | None = None,
    plant_context: Context | None = None,
    object_body: Any = None,
    keep_camera: bool = False,
) -> GraspDrawing:
    """Draw a grasp (and optionally the forces of a closure result) in Meshcat.

    Parameters
    ----------
    meshcat : pydrake.geometry.Meshcat
        The visualizer; no browser needs to be connected.
    grasp : Grasp
        Contacts expressed in the grasp frame G.  Planar grasps are drawn in G's
        z = 0 plane.
    X_WG : RigidTransform, optional
        Pose of G in world (for a grasp from a plant: the object body's pose
        ``X_WO``, which ``plant``, ``plant_context`` and ``object_body`` give
        instead).  Default identity.  It is set on ``prefix``, so
        ``meshcat.SetTransform(prefix, X_WG)`` later moves the whole drawing.
    result : ClosureResult or sequence of array_like, optional
        Contact forces to draw as arrows: a result with ``contact_forces``, or
        one array per contact in that contact's frame, normal first (newtons).
        A "no" result's certificate is drawn too (the unresisted wrench or
        the escape axis, see :mod:`drakegrasp.visualization.meshcat_certificates`).
    prefix : str, optional
        Meshcat path holding the drawing; an existing drawing there is deleted
        first.
    cone : {"exact", "pyramid", "both", None}, optional
        Which friction cones to draw: the exact Coulomb cone (translucent
        surface), the inscribed pyramid with ``num_generators`` edges
        (wireframe, from :func:`~drakegrasp.friction_cone_generators`), both,
        or none.  Planar cones are exact wedges in the plane either way; a
        frictionless contact's cone is the ray along its normal.
    num_generators : int, optional
        Edges of the pyramid (spatial contacts), an integer in [3, 256].
    cone_height : float, optional
        Extent of each cone along its normal, metres.  Default: 0.4 b, with b
        the grasp's characteristic length.  Like every length given here, a
        real number (numpy's too; not a string or a bool) in
        ``[DRAW_LENGTH_MIN, DRAW_LENGTH_MAX]`` = [2.2e-308, 1e30] metres
        (:mod:`drakegrasp.visualization.geometry`), so that everything drawn
        stays finite.
    force_scale : float, optional
        Arrow length per newton (m/N), in the same range.  Default: the
        largest force is drawn 0.6 b long.  The largest force's arrow,
        ``force_scale`` times its magnitude, must not exceed
        ``DRAW_LENGTH_MAX`` either.
    point_radius : float, optional
        Radius of the contact spheres, metres.  Default 0.04 b.
    frame_length : float, optional
        Length of the triad axes, metres.  Default 0.2 b.
    show_frames : bool, optional
        Draw the contact frames ``R_i = [n, t1, t2]`` as red, green and blue
        axes.
    side : {"outside", "inside"}, optional
        ``"outside"``: cones open away from the object and arrows end at the
        contact point; ``"inside"``: cones open along ``n`` and arrows start at
        the contact point.
    colors : mapping, optional
        RGB(A) overrides of :data:`MESHCAT_COLORS` (keys ``point``, ``n``,
        ``t1``, ``t2``, ``cone``, ``pyramid``, ``ray``, ``force``).
    on_top : bool, optional
        Draw over everything else in the scene (no depth test), so that a
        robot drawn by ``MeshcatVisualizer`` never hides the drawing: with
        ``side="outside"`` the cones and arrows lie inside the finger meshes,
        with ``"inside"`` inside the object.  Default False.  ``show_frames``,
        ``on_top`` and ``keep_camera`` are True or False (numpy booleans too).
    size : float, optional
        Length (metres) that the default sizes are fractions of: pass the
        object's size (e.g. the diagonal of its bounding box) to draw to the
        object's scale.  Default: the grasp's characteristic length b (which
        is in range: a grasp's b is at most 1e30 m).
    translucent : str or sequence of str, optional
        Meshcat paths to make translucent with :func:`set_translucent` (e.g.
        ``"visualizer/gripper"``, a hand drawn by ``MeshcatVisualizer``).
    translucent_opacity : float, optional
        Their opacity factor, in (0, 1] (default 0.3).
    plant, plant_context, object_body : optional
        Together, and instead of ``X_WG``: the grasp frame is the object
        body's frame, ``X_WG = plant.EvalBodyPoseInWorld(plant_context,
        object_body)`` (a grasp from
        :func:`~drakegrasp.grasp_from_plant` or
        :func:`~drakegrasp.analyze_grasp` is expressed in it).
        ``plant_context`` may be the diagram's root context; ``object_body`` a
        body, ``BodyIndex`` or name.
    keep_camera : bool, optional
        Leave Meshcat's camera where it is.  Default False: aim it at the
        drawing (:func:`~drakegrasp.visualization.view.frame_points` over
        the contact points, with the cones and arrows in view).

    Returns
    -------
    GraspDrawing
        The prefix, every path drawn, and the sizes used.

    Notes
    -----
    Default sizes, as fractions of ``L`` = ``size`` or b: cones 0.4 L high,
    contact spheres 0.04 L in radius, triads 0.2 L long, the largest force
    0.6 L long.

    Raises
    ------
    InvalidOptionError
        For an unknown ``cone``, ``side`` or colour key, a length that is not
        a real number in ``[DRAW_LENGTH_MIN, DRAW_LENGTH_MAX]`` (NaN, 0, a
        negative one, 1e300, the string ``"1"``...), a force arrow longer
        than ``DRAW_LENGTH_MAX``, forces that are not real or do not match the
        grasp's contacts, a result whose certificate belongs to another grasp,
        a flag that is not a boolean, bad ``translucent`` paths or opacity,
        contact points the camera cannot frame
        (:func:`~drakegrasp.visualization.view.frame_points`), or both
        ``X_WG`` and a plant (or a plant without its context and object body).
        Everything is checked before anything is drawn.
    """
    _check_meshcat(meshcat)
    if not isinstance(grasp, Grasp):
        raise InvalidOptionError(
            f"draw_grasp needs a drakegrasp.Grasp, got {type(grasp).__name__}"
        )
    _check_rgba_colors(colors)
    cone = plain_str(cone)  # compared below: a subclass's own == may raise or lie
    if not (cone is None or type(cone) is str) or cone not in _CONE_CHOICES:
        raise InvalidOptionError(
            f"cone must be 'exact', 'pyramid', 'both' or None, got {describe(cone)}"
        )
    prefix = check_path("prefix", prefix)
    sign = side_sign(side)
    palette = merge_palette(MESHCAT_COLORS, colors)
    # Given lengths are checked; the defaults are fractions of b (or of size),
    # which is itself in range, so they are > 0 and finite too.
    b = _length("size", size, grasp.characteristic_length)
    h = _length("cone_height", cone_height, 0.4 * b)
    r = _length("point_radius", point_radius, 0.04 * b)
    axis_len = _length("frame_length", frame_length, 0.2 * b)
    X_WG = grasp_pose(X_WG, plant, plant_context, object_body)
    translucent, translucent_opacity = translucent_arguments(
        translucent, translucent_opacity
    )
    num_generators = check_num_generators(num_generators)
    show_frames = check_flag("show_frames", show_frames)
    on_top = check_flag("on_top", on_top)
    keep_camera = check_flag("keep_camera", keep_camera)

    forces = normalize_contact_forces(grasp, result)
    forces_G = None
    scale = 0.0
    longest = 0.0
    if forces is not None:
        forces_G = np.zeros((grasp.num_contacts, 3))
        for i, (contact, f) in enumerate(zip(grasp.contacts, forces, strict=True)):
            R3, _ = contact_pose_3d(contact)
            local = np.zeros(3)
            m = min(contact.dim, f.size)
            local[:m] = f[:m]
            forces_G[i] = R3 @ local
        largest = float(np.max(safe_norm(forces_G, axis=1)))  # no overflow
        if force_scale is not None:
            scale = positive_length("force_scale", force_scale, unit="m/N")
        elif largest > 0:
            scale = 0.6 * b / largest
        longest = scale * largest
        if not longest <= DRAW_LENGTH_MAX:
            raise InvalidOptionError(
                f"force_scale {scale!r} m/N draws the largest force ({largest:.6g} "
                f"N) {longest:.6g} m long, beyond the longest arrow drawn, "
                f"{DRAW_LENGTH_MAX:g} m "
                "(drakegrasp.visualization.geometry.DRAW_LENGTH_MAX); pass a "
                "smaller force_scale"
            )
    certificate = result_certificate(grasp, result)  # why "no"; None for a "yes"
    view = None
    if not keep_camera:  # checked before anything is drawn
        reach = max(h if cone is not None else 0.0, axis_len, r, longest)
        points_W = [X_WG.multiply(contact_pose_3d(c)[1]) for c in grasp.contacts]
        view = camera_view(np.array(points_W), pad=reach)

    meshcat.Delete(prefix)
    meshcat.SetTransform(prefix, X_WG)
    paths: list[str] = []
    leaves: list[str] = []  # objects drawn by parts (arrows)
    axis_radius = 0.2 * r
    for i, contact in enumerate(grasp.contacts):
        base = f"{prefix}/contact_{i}"
        R3, p3 = contact_pose_3d(contact)
        meshcat.SetTransform(base, RigidTransform(RotationMatrix(R3), p3))

        meshcat.SetObject(f"{base}/point", Sphere(r), _rgba(palette, "point"))
        paths.append(f"{base}/point")

        if show_frames:
            axes = {
                "n": RotationMatrix.MakeYRotation(np.pi / 2),
                "t1": RotationMatrix.MakeXRotation(-np.pi / 2),
                "t2": RotationMatrix(),
            }
            for k, (name, R_axis) in enumerate(axes.items()):
                path = f"{base}/frame/{name}"
                meshcat.SetObject(
                    path, Cylinder(axis_radius, axis_len), _rgba(palette, name)
                )
                offset = np.zeros(3)
                offset[k] = axis_len / 2
                meshcat.SetTransform(path, RigidTransform(R_axis, offset))
                paths.append(path)

        if cone is not None:
            paths += _draw_cone(
                meshcat,
                f"{base}/cone",
                grasp,
                i,
                cone=cone,
                num_generators=num_generators,
                height=h,
                sign=sign,
                palette=palette,
            )

        if forces_G is not None and scale > 0:
            f_C = R3.T @ forces_G[i]
            if float(safe_norm(f_C)) * scale > 1e-9 * b:
                vec = scale * f_C
                tail = np.zeros(3) if sign > 0 else -vec
                leaves += _draw_arrow(
                    meshcat,
                    f"{base}/force",
                    tail,
                    vec,
                    radius=0.4 * r,
                    rgba=_rgba(palette, "force"),
                )
                paths.append(f"{base}/force")
    if certificate is not None:
        certificate = draw_certificate(meshcat, grasp, certificate, prefix=prefix)
    else:
        certificate = ()
    paths += certificate
    if on_top:
        # Arrows are groups (shaft, head): their parts carry the materials.
        arrows = {p for p in paths if p.endswith("/force")}
        arrows |= {p for p in certificate if not p.endswith("/point")}
        parts = [
            f"{p}/{part}"
            for p in certificate
            if p in arrows
            for part in ("shaft", "head")
        ]
        for path in [p for p in paths if p not in arrows] + leaves + parts:
            _draw_on_top(meshcat, path)
    if translucent:
        set_translucent(meshcat, translucent, translucent_opacity)
    camera = None
    if view is not None:
        meshcat.SetCameraPose(view.position_W, view.target_W)
        camera = view
    return GraspDrawing(prefix, tuple(paths), h, scale, forces_G, camera)


def _length(name: str, value: Any, default: float) -> float:
    """A given length, checked; else the default (a fraction of a valid b)."""
    return default if value is None else positive_length(name, value)


def _draw_cone(
    meshcat: Meshcat,
    path: str,
    grasp: Grasp,
    i: int,
    *,
    cone: str,
    num_generators: int,
    height: float,
    sign: float,
    palette: Mapping[str, Any],
) -> list[str]:
    contact = grasp.contacts[i]
    drawn = []
    if 1 not in contact.effective_components():
        ray = np.array([[0.0, 0.0, 0.0], [sign * height, 0.0, 0.0]]).T
        meshcat.SetLine(f"{path}/ray", ray, 3.0, _rgba(palette, "ray"))
        return [f"{path}/ray"]
    mu = contact.mu
    if contact.planar:
        # The planar cone is exact: the wedge between R[1, ±μ], in the plane.
        v = sign * height * np.array([[0, 0, 0], [1, mu, 0], [1, -mu, 0]], float)
        if cone in ("exact", "both"):
            _set_mesh(meshcat, f"{path}/exact", v, [[0, 1, 2]], _rgba(palette, "cone"))
            drawn.append(f"{path}/exact")
        if cone in ("pyramid", "both"):
            edges = np.array([v[1], v[0], v[2]]).T
            meshcat.SetLine(f"{path}/pyramid", edges, 2.0, _rgba(palette, "pyramid"))
            drawn.append(f"{path}/pyramid")
        return drawn
    if cone in ("exact", "both"):
        v, f = exact_cone_mesh(mu, height, num_segments=48, sign=sign)
        _set_mesh(meshcat, f"{path}/exact", v, f, _rgba(palette, "cone"))
        drawn.append(f"{path}/exact")
    if cone in ("pyramid", "both"):
        S = pyramid_generators(
            contact, num_generators, characteristic_length=grasp.characteristic_length
        )
        v, f = pyramid_mesh(S, height, sign=sign)
        _set_mesh(
            meshcat,
            f"{path}/pyramid",
            v,
            f,
            _rgba(palette, "pyramid"),
            wireframe=True,
            wireframe_line_width=2.0,
        )
        drawn.append(f"{path}/pyramid")
    return drawn


@checked_call
def clear_grasp(meshcat: Meshcat, prefix: str = DEFAULT_PREFIX) -> None:
    """Delete a drawing made by :func:`draw_grasp` (everything under ``prefix``)."""
    _check_meshcat(meshcat)
    prefix = check_path("prefix", prefix)
    meshcat.Delete(prefix)


_check_meshcat = check_meshcat  # the name this module used


def _check_rgba_colors(colors) -> None:
    """Refuse colours that are not Rgba or 3/4 numbers in [0, 1]."""
    if colors is None:
        return
    if not isinstance(colors, Mapping):
        raise InvalidOptionError(
            "colors must be a mapping of names to RGB(A) colours, got "
            f"{describe(colors)}"
        )
    for key, value in colors.items():
        if isinstance(value, Rgba):
            continue
        try:
            v = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            v = None
        if (
            v is None
            or v.shape not in ((3,), (4,))
            or not np.all((v >= 0.0) & (v <= 1.0))
        ):
            raise InvalidOptionError(
                f"colour {describe(key)} must be an Rgba or 3 or 4 numbers in "
                f"[0, 1], got {describe(value)}"
            )
