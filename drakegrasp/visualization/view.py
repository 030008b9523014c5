r"""Where a drawing stands and where Meshcat's camera looks at it.

:func:`grasp_pose` places a grasp's drawing: at ``X_WG`` as given, or at the
object body's pose read from a plant and its context (the frame that
:func:`~drakegrasp.grasp_from_plant` expresses the contacts in).

:func:`frame_points` takes the world points a drawing must show and the
room around them (cones, arrows), and aims Meshcat's default perspective
camera at them:

- the **target** is the centre of the points' axis-aligned bounding box;
- the box, grown by ``pad`` on every side, lies in a sphere of radius ``R``
  (half the grown box's diagonal) about the target;
- the camera looks at the target from the direction :data:`VIEW_DIRECTION`
  (a three-quarter view from above), at the distance
  ``D = MARGIN · R / sin(fov / 2)`` at which a sphere of radius ``R`` fits a
  cone of Meshcat's vertical field of view (:data:`MESHCAT_FOV`, 75°),
  so the whole box is in view for any aspect ratio at least 1.

Drake's ``Meshcat.SetCameraPose(camera_in_world, target_in_world)`` does the
rest; the world's +z stays up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import Meshcat
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context

from drakegrasp.core.calls import checked_call
from drakegrasp.core.validation import describe, real_array, real_scalar
from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant.validation import plant_context_of, resolve_object_body
from drakegrasp.visualization.geometry import DRAW_LENGTH_MAX
from drakegrasp.visualization.primitives import check_meshcat

__all__ = [
    "MARGIN",
    "MESHCAT_FOV",
    "VIEW_BOUND",
    "VIEW_DIRECTION",
    "CameraView",
    "camera_view",
    "frame_points",
    "grasp_pose",
]

MESHCAT_FOV = np.deg2rad(75.0)
"""Vertical field of view (radians) of Meshcat's default perspective camera."""

VIEW_DIRECTION = np.array([1.0, -1.0, 0.8]) / np.linalg.norm([1.0, -1.0, 0.8])
"""Unit direction (world frame) from the target to the camera."""

MARGIN = 1.15
"""Distance factor beyond the tightest fit, so the drawing does not touch the edge."""

VIEW_BOUND = DRAW_LENGTH_MAX
"""Largest absolute coordinate of a framed point, and largest ``pad`` (metres):
1e30, the longest length a drawing takes.  The camera's distance is then below
about 1e31 m and every square computed below 1e63, so the view is finite (points
at ±1e300 once put the camera at ``inf``)."""


@checked_call
@dataclass(frozen=True)
class CameraView:
    """Where :func:`frame_points` put the camera.

    Attributes
    ----------
    position_W : (3,) float
        The camera's position in the world, metres.
    target_W : (3,) float
        The point it looks at, metres.
    radius : float
        ``R``: the framed sphere's radius about the target, metres.
    """

    position_W: np.ndarray
    target_W: np.ndarray
    radius: float

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "position_W": self.position_W.tolist(),
            "target_W": self.target_W.tolist(),
            "radius": self.radius,
        }


def camera_view(points_W, *, pad: float = 0.0) -> CameraView:
    """Where :func:`frame_points` puts the camera, without moving it.

    Parameters and checks are those of :func:`frame_points`.

    Returns
    -------
    CameraView
    """
    p = real_array("points_W", points_W, error=InvalidOptionError)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) == 0 or not np.all(np.isfinite(p)):
        raise InvalidOptionError(
            f"points_W must be (N, 3) finite world points with N >= 1, got shape "
            f"{p.shape}"
        )
    if float(np.max(np.abs(p))) > VIEW_BOUND:
        raise InvalidOptionError(
            f"points_W has a coordinate of {float(np.max(np.abs(p))):.6g} m, beyond "
            f"|x| <= {VIEW_BOUND:g} m "
            "(drakegrasp.visualization.view.VIEW_BOUND): the camera would stand at "
            "an infinite distance"
        )
    x = real_scalar("pad", pad)
    if not (0.0 <= x <= VIEW_BOUND):
        raise InvalidOptionError(
            f"pad must be a finite length >= 0 and <= {VIEW_BOUND:g} metres "
            f"(drakegrasp.visualization.view.VIEW_BOUND), got {describe(pad)}"
        )
    lo, hi = p.min(axis=0) - x, p.max(axis=0) + x
    target = 0.5 * (lo + hi)
    radius = max(0.5 * float(np.linalg.norm(hi - lo)), 1e-3)
    distance = MARGIN * radius / np.sin(0.5 * MESHCAT_FOV)
    position = target + distance * VIEW_DIRECTION
    return CameraView(position_W=position, target_W=target, radius=radius)


@checked_call
def frame_points(meshcat: Meshcat, points_W, *, pad: float = 0.0) -> CameraView:
    """Aim Meshcat's camera so that every point (and ``pad`` around it) is seen.

    Parameters
    ----------
    meshcat : pydrake.geometry.Meshcat
    points_W : (N, 3) float
        Points in the world frame, metres; ``N >= 1``, every coordinate finite
        with ``|x| <=`` :data:`VIEW_BOUND` (1e30 m).
    pad : float, optional
        Room (metres) to keep in view around the points' bounding box: a real
        number in ``[0, VIEW_BOUND]``.

    Returns
    -------
    CameraView
        Finite: with both bounds the camera stands within about 1e31 m.

    Raises
    ------
    InvalidOptionError
        For no points, points that are not real or finite or beyond
        :data:`VIEW_BOUND`, a ``pad`` that is not a real number in
        ``[0, VIEW_BOUND]`` (a string, NaN, a negative one), or a ``meshcat``
        that is not a Meshcat.
    """
    check_meshcat(meshcat)
    view = camera_view(points_W, pad=pad)
    meshcat.SetCameraPose(view.position_W, view.target_W)
    return view


@checked_call
def grasp_pose(
    X_WG: RigidTransform | None = None,
    plant: MultibodyPlant | None = None,
    plant_context: Context | None = None,
    object_body=None,
) -> RigidTransform:
    """Where a drawing of a grasp stands: ``X_WG``, or the object's pose.

    Parameters
    ----------
    X_WG : RigidTransform, optional
        The grasp frame's pose in the world.
    plant, plant_context, object_body : optional
        Together, instead of ``X_WG``: ``X_WG = X_WO``, the object body's
        pose in the plant's context (root context accepted).

    Returns
    -------
    RigidTransform
        ``X_WG``; the identity when nothing is given.

    Raises
    ------
    InvalidOptionError
        For both ``X_WG`` and a plant, a plant without its context and body,
        or an ``X_WG`` that is not a ``RigidTransform``.
    """
    given = [x is not None for x in (plant, plant_context, object_body)]
    if any(given):
        if X_WG is not None:
            raise InvalidOptionError(
                "give X_WG, or plant, plant_context and object_body (whose pose "
                "is X_WG), not both"
            )
        if not all(given):
            missing = [
                name
                for name, g in zip(
                    ("plant", "plant_context", "object_body"), given, strict=True
                )
                if not g
            ]
            raise InvalidOptionError(
                "plant, plant_context and object_body go together (the object's "
                f"pose in the context is X_WG); missing: {', '.join(missing)}"
            )
        context = plant_context_of(plant, plant_context)
        body = resolve_object_body(plant, object_body)
        return plant.EvalBodyPoseInWorld(context, body)
    if X_WG is None:
        return RigidTransform()
    if not isinstance(X_WG, RigidTransform):
        raise InvalidOptionError(
            f"X_WG must be a pydrake RigidTransform, got {type(X_WG).__name__}"
        )
    return X_WG
