r"""Animate a form-closure "no": the object moves along its escape twist.

:func:`animate_escape` draws every body of the plant at its pose in the given
context (the fingers stay where they are) and records a Meshcat animation in
which the object follows the rigid motion ``exp(t ξ)`` of its escape twist ``ξ``
(:class:`~drakegrasp.certificates.certificate.Certificate`, frame O about its
origin), for
``t`` from 0 to ``amount · b`` (and back through ``−`` when both signs escape).

The motion of a constant twist ``ξ = (v_O, ω)`` (``v_O`` the velocity of O's
origin) is the screw (Murray, Li and Sastry's closed form):

.. math:: R(t) = e^{t\hat\omega}, \quad
          p(t) = (I - R)(\hat k \times v') + \hat k \hat k^T v' \theta
          \;(\omega \ne 0), \qquad p(t) = t\, v_O \;(\omega = 0)

with ``θ = t |ω|``, ``k = ω/|ω|`` and ``v' = v_O / |ω|``.  To first order no
finger penetrates; a finite motion may (curvature: second-order analysis).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from pydrake.geometry import Meshcat, MeshcatAnimation, Rgba, Role
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.tree import BodyIndex

from drakegrasp.certificates.certificate import ESCAPE_TWIST, Certificate
from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant.options import PLANES

__all__ = ["EscapeAnimation", "animate_escape", "escape_transform"]

_OBJECT = Rgba(0.95, 0.6, 0.1, 0.9)
_HAND = Rgba(0.55, 0.55, 0.6, 1.0)


@dataclass(frozen=True)
class EscapeAnimation:
    """What :func:`animate_escape` recorded.

    Attributes
    ----------
    prefix : str
        Meshcat path of the drawing.
    object_path : str
        Path that the animation moves.
    animation : MeshcatAnimation
    times : (F,) float
        Twist parameter ``t`` of every frame (seconds of the unit twist).
    transforms : tuple of RigidTransform
        ``X_WO`` of every frame.
    twist_O : (6,) float
        The escape twist ``[v_p; ω]`` in frame O about the grasp's reference
        point (planar twists lifted into 3-D).
    """

    prefix: str
    object_path: str
    animation: Any
    times: np.ndarray
    transforms: tuple[RigidTransform, ...]
    twist_O: np.ndarray


def escape_transform(twist: np.ndarray, p: np.ndarray, t: float) -> RigidTransform:
    """``X_OO'(t) = exp(t ξ)`` for a twist ``[v_p; ω]`` about ``p`` in frame O."""
    v_p, w = np.asarray(twist[:3], float), np.asarray(twist[3:], float)
    v = v_p - np.cross(w, p)  # the velocity of O's origin
    speed = float(np.linalg.norm(w))
    if speed < 1e-12:
        return RigidTransform(t * v)
    k, theta = w / speed, t * speed
    R = RotationMatrix.MakeFromOneVector(k, 2)  # any frame with z = k
    R = R @ RotationMatrix.MakeZRotation(theta) @ R.inverse()
    vp = v / speed
    Rm = R.matrix()
    pos = (np.eye(3) - Rm) @ np.cross(k, vp) + k * (k @ vp) * theta
    return RigidTransform(R, pos)


def _twist_3d(cert: Certificate, plane: str | None) -> tuple[np.ndarray, np.ndarray]:
    x = np.asarray(cert.direction, float)
    p = np.asarray(cert.reference_point, float)
    if x.size == 6:
        return x, p
    if plane not in PLANES:
        raise InvalidOptionError(
            f"a planar escape twist needs its plane, one of {sorted(PLANES)}; "
            f"got {plane!r}"
        )
    i, j = PLANES[plane]
    k = 3 - i - j
    twist, p3 = np.zeros(6), np.zeros(3)
    twist[i], twist[j], twist[3 + k] = x
    p3[i], p3[j] = p
    return twist, p3


def _unpack(scene_or_plant, result, plant_context, object_body, plane):
    """(plant, context, object body, certificate, plane) from the arguments."""
    plant = getattr(scene_or_plant, "plant", scene_or_plant)
    context = plant_context or getattr(scene_or_plant, "plant_context", None)
    body = object_body or getattr(scene_or_plant, "object_body", None)
    data = getattr(result, "data", None)  # a GraspReport
    if data is not None:
        plane = plane or data.plane
        body = body or plant.GetBodyByName(*reversed(data.object_body.split("::")))
        result = result.form_closure
    cert = getattr(result, "certificate", result)
    if context is None or body is None:
        raise InvalidOptionError(
            "animate_escape needs a Scene, or a plant with plant_context= and "
            "object_body="
        )
    if isinstance(body, str):
        body = plant.GetBodyByName(body)
    if not isinstance(cert, Certificate) or cert.kind != ESCAPE_TWIST:
        raise InvalidOptionError(
            "animate_escape needs a form-closure 'no' (a result or report whose "
            f"certificate is an escape twist); got {type(cert).__name__}"
        )
    return plant, context, body, cert, plane


def _draw_body(meshcat, inspector, plant, body, path, rgba) -> None:
    frame_id = plant.GetBodyFrameIdOrThrow(body.index())
    geometries = inspector.GetGeometries(frame_id, Role.kIllustration)
    if not geometries:
        geometries = inspector.GetGeometries(frame_id, Role.kProximity)
    for n, gid in enumerate(geometries):
        meshcat.SetObject(f"{path}/g{n}", inspector.GetShape(gid), rgba)
        meshcat.SetTransform(f"{path}/g{n}", inspector.GetPoseInFrame(gid))


def animate_escape(
    meshcat: Meshcat,
    scene_or_plant: Any,
    result: Any,
    *,
    plant_context: Any = None,
    object_body: Any = None,
    plane: str | None = None,
    amount: float = 0.5,
    duration: float = 2.0,
    frames: int = 60,
    prefix: str = "drakegrasp/escape",
) -> EscapeAnimation:
    """Move the object along its escape twist in Meshcat, the fingers held.

    Parameters
    ----------
    meshcat : Meshcat
    scene_or_plant : Scene or MultibodyPlant
        A :class:`~drakegrasp.Scene` (its plant, context and object body), or
        a plant with ``plant_context`` and ``object_body``.
    result : GraspReport, ClosureResult or Certificate
        A form-closure "no" whose certificate is an escape twist (a report's
        ``form_closure``).
    plant_context, object_body : optional
        For a bare plant (``object_body``: a body or its name).
    plane : str, optional
        Plane of a planar analysis (``"yz"``...); a report gives its own.
    amount : float, optional
        Largest twist parameter over ``b`` (the unit twist moves points by
        about 1 m/s, so ``amount · b`` moves them by about ``amount · b``).
    duration : float, optional
        Seconds of one sweep.
    frames : int, optional
        Frames of one sweep.
    prefix : str, optional
        Meshcat path of the drawing (deleted first).

    Returns
    -------
    EscapeAnimation
    """
    plant, context, body, cert, plane = _unpack(
        scene_or_plant, result, plant_context, object_body, plane
    )
    if not (frames >= 2 and duration > 0 and amount > 0):
        raise InvalidOptionError(
            f"need frames >= 2, duration > 0 and amount > 0; got {frames}, "
            f"{duration}, {amount}"
        )
    twist, p = _twist_3d(cert, plane)
    inspector = plant.get_geometry_query_input_port().Eval(context).inspector()
    meshcat.Delete(prefix)
    for other in range(plant.num_bodies()):
        b_other = plant.get_body(BodyIndex(other))
        if b_other.index() == body.index():
            continue
        path = f"{prefix}/held/{b_other.name()}_{int(b_other.index())}"
        meshcat.SetTransform(path, plant.EvalBodyPoseInWorld(context, b_other))
        _draw_body(meshcat, inspector, plant, b_other, path, _HAND)
    obj = f"{prefix}/object"
    _draw_body(meshcat, inspector, plant, body, obj, _OBJECT)
    X_WO = plant.EvalBodyPoseInWorld(context, body)
    t_max = amount * cert.characteristic_length
    ramp = np.linspace(0.0, 1.0, frames)
    times = t_max * (np.concatenate([ramp, -ramp]) if cert.two_sided else ramp)
    animation = MeshcatAnimation(frames_per_second=frames / duration)
    transforms = []
    for n, t in enumerate(times):
        X = X_WO @ escape_transform(twist, p, float(t))
        animation.SetTransform(n, obj, X)
        transforms.append(X)
    meshcat.SetTransform(obj, X_WO)
    meshcat.SetAnimation(animation)
    return EscapeAnimation(prefix, obj, animation, times, tuple(transforms), twist)
