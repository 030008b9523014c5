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
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex

from drakegrasp.certificates.certificate import ESCAPE_TWIST, Certificate
from drakegrasp.core.validation import (
    check_length,
    check_positions,
    describe,
    integer_or_none,
    plain_str,
    real_array,
    real_scalar,
)
from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.plant.options import PLANES, check_plane
from drakegrasp.plant.validation import (
    check_plant,
    plant_context_of,
    resolve_body,
    resolve_object_body,
    scoped_name,
)
from drakegrasp.visualization.primitives import check_meshcat, check_path

__all__ = [
    "MAX_AMOUNT",
    "MAX_DURATION",
    "MAX_FRAMES",
    "MIN_DURATION",
    "EscapeAnimation",
    "animate_escape",
    "escape_transform",
]

MAX_FRAMES = 3600
"""Most frames of one sweep: a minute at 60 frames per second.  Recording is
linear in the frames (10**5 frames took 6 to 10 s)."""

MIN_DURATION = 0.01
"""Shortest sweep, seconds (a shorter one is not seen)."""

MAX_DURATION = 3600.0
"""Longest sweep, seconds (an hour; ``inf`` made a frame rate of 0)."""

MAX_AMOUNT = 100.0
"""Largest ``amount``: the object moves by at most about 100 times the grasp's
characteristic length ``b`` (the poses stay finite)."""

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


def check_amount(amount) -> float:
    """``amount`` of an escape picture: a real number in ``(0, MAX_AMOUNT]``.

    The largest twist parameter over ``b`` that :func:`animate_escape` and
    :func:`~drakegrasp.visualization.certificate_plots.plot_escape` move the
    object by (a negative one would move it into the fingers).

    Raises
    ------
    InvalidOptionError
        For anything else (NaN, 0, a negative number, a string, a bool...).
    """
    x = real_scalar("amount", amount)
    if not (0.0 < x <= MAX_AMOUNT):
        raise InvalidOptionError(
            f"amount must be a real number > 0 and <= {MAX_AMOUNT:g} "
            f"(drakegrasp.visualization.escape.MAX_AMOUNT), got {describe(amount)}"
        )
    return x


def checked_motion(twist, p, t, *, dim: int) -> tuple[np.ndarray, np.ndarray, float]:
    """``(twist, p, t)`` of a rigid motion ``exp(t ξ)`` in ``dim`` (2 or 3) D, checked.

    Parameters
    ----------
    twist : ((3,) or (6,)) array_like
        ``[v_p; ω]``: real and finite.
    p : (dim,) array_like
        The point the twist is about: a position (real, finite, every
        ``|x| <=`` :data:`~drakegrasp.core.validation.POSITION_BOUND`).
    t : float
        A real, finite number.

    Returns
    -------
    twist : (3,) or (6,) float
    p : (dim,) float
    t : float

    Raises
    ------
    InvalidOptionError
        Naming the first of ``twist``, ``p`` and ``t`` that is not so.
    """
    n = 3 if dim == 2 else 6
    x = real_array("twist", twist, error=InvalidOptionError)
    if x.shape != (n,) or not np.all(np.isfinite(x)):
        raise InvalidOptionError(
            f"twist must be a finite ({n},) vector [v_p; ω], got {describe(twist)}"
        )
    q = check_positions("p", p, error=InvalidOptionError)
    if q.shape != (dim,):
        raise InvalidOptionError(
            f"p must be a ({dim},) point (what the twist is about), got {describe(p)}"
        )
    s = real_scalar("t", t)
    if not np.isfinite(s):
        raise InvalidOptionError(f"t must be a finite real number, got {describe(t)}")
    return x, q, s


def check_finite_motion(*arrays) -> None:
    """Refuse a rigid motion ``exp(t ξ)`` some of whose ``arrays`` overflowed.

    Raises
    ------
    InvalidOptionError
        When an entry of ``arrays`` is NaN or infinite.
    """
    if not all(np.all(np.isfinite(a)) for a in arrays):
        raise InvalidOptionError(
            "the motion exp(t ξ) of this twist, point p and parameter t overflows "
            "(a speed, an angle or a position beyond the floating-point range): "
            "give a smaller t or twist"
        )


def escape_transform(twist: np.ndarray, p: np.ndarray, t: float) -> RigidTransform:
    """``X_OO'(t) = exp(t ξ)`` for a twist ``[v_p; ω]`` about ``p`` in frame O.

    Parameters
    ----------
    twist : (6,) array_like
        ``[v_p; ω]`` (m/s, rad/s): real and finite.
    p : (3,) array_like
        The point the twist is about, metres: real, finite, every ``|x| <=``
        :data:`~drakegrasp.core.validation.POSITION_BOUND` (1e20).
    t : float
        The twist parameter (seconds of the twist): a real, finite number.

    Returns
    -------
    RigidTransform
        With a finite translation and rotation.

    Raises
    ------
    InvalidOptionError
        For a ``twist``, ``p`` or ``t`` that is not so (None, a string, a
        bool, complex, NaN, another shape), naming it, or for a motion that
        overflows (``|ω|``, ``t |ω|`` or a position beyond the floating-point
        range, which Drake refused or, for the angle, ended the program on).
    """
    return _flow(*checked_motion(twist, p, t, dim=3))


def _flow(twist: np.ndarray, p: np.ndarray, t: float) -> RigidTransform:
    """:func:`escape_transform` of checked arrays (overflow is still refused)."""
    v_p, w = twist[:3], twist[3:]
    with np.errstate(over="ignore", invalid="ignore"):  # checked below
        v = v_p - np.cross(w, p)  # the velocity of O's origin
        speed = float(np.linalg.norm(w))
        if speed < 1e-12:
            check_finite_motion(v, t * v)
            return RigidTransform(t * v)
        k, theta = w / speed, t * speed
        check_finite_motion(v, speed, theta)  # Drake demands a finite angle
        R = RotationMatrix.MakeFromOneVector(k, 2)  # any frame with z = k
        R = R @ RotationMatrix.MakeZRotation(theta) @ R.inverse()
        vp = v / speed
        Rm = R.matrix()
        pos = (np.eye(3) - Rm) @ np.cross(k, vp) + k * (k @ vp) * theta
    check_finite_motion(pos)
    return RigidTransform(R, pos)


def _twist_3d(
    x: np.ndarray, p: np.ndarray, plane: str | None
) -> tuple[np.ndarray, np.ndarray]:
    if x.size == 6:
        return x, p
    plane = plain_str(plane)
    if type(plane) is not str or plane not in PLANES:
        raise InvalidOptionError(
            f"a planar escape twist needs its plane, one of {sorted(PLANES)}; "
            f"got {describe(plane)}"
        )
    i, j = PLANES[plane]
    k = 3 - i - j
    twist, p3 = np.zeros(6), np.zeros(3)
    twist[i], twist[j], twist[3 + k] = x
    p3[i], p3[j] = p
    return twist, p3


def _escape_twist(cert: Any) -> tuple[np.ndarray, np.ndarray, float, bool]:
    """(direction, reference point, b, two_sided) of an escape twist, checked.

    The direction keeps the certificate's scaling ``‖[v; b ω]‖ = 1`` (rescaled
    to it only when it is off by more than round-off), so the poses stay finite.
    """
    if not isinstance(cert, Certificate) or cert.kind != ESCAPE_TWIST:
        raise InvalidOptionError(
            "animate_escape needs a form-closure 'no' (a result or report whose "
            f"certificate is an escape twist); got {type(cert).__name__}"
            + (f" of kind {cert.kind!r}" if isinstance(cert, Certificate) else "")
        )
    x = real_array(
        "the certificate's direction", cert.direction, error=InvalidOptionError
    )
    if x.shape not in ((3,), (6,)) or not np.all(np.isfinite(x)) or not x.any():
        raise InvalidOptionError(
            "the escape twist must be a finite, non-zero (3,) or (6,) vector, got "
            f"{describe(x.tolist())}"
        )
    d = 3 if x.size == 6 else 2  # the point's (and the linear part's) dimension
    if cert.reference_point is None:
        raise InvalidOptionError(
            "the escape twist needs its reference_point (the point it is about)"
        )
    p = real_array(
        "the certificate's reference_point",
        cert.reference_point,
        error=InvalidOptionError,
    )
    if p.shape != (d,) or not np.all(np.isfinite(p)):
        raise InvalidOptionError(
            f"the certificate's reference_point must be a finite ({d},) "
            f"point for a ({x.size},) twist, got {describe(p.tolist())}"
        )
    b = check_length(
        "the certificate's characteristic_length",
        cert.characteristic_length,
        error=InvalidOptionError,
    )
    top = float(np.max(np.abs(x)))
    unit = x / top  # its norms cannot overflow
    size = float(np.linalg.norm(np.concatenate([unit[:d], b * unit[d:]])))
    if not abs(top * size - 1.0) <= 1e-9:  # the motion is proportional to x
        x = unit / size
    null_basis = real_array(
        "the certificate's null_basis", cert.null_basis, error=InvalidOptionError
    )
    two_sided = null_basis.ndim > 0 and null_basis.shape[-1] > 0
    return x, p, b, two_sided


def _unpack(scene_or_plant, result, plant_context, object_body, plane):
    """(plant, context, object body, certificate arrays, plane), all checked."""
    plant = getattr(scene_or_plant, "plant", scene_or_plant)
    if not isinstance(plant, MultibodyPlant):
        raise InvalidOptionError(
            "scene_or_plant must be a drakegrasp Scene (load_scene's) or a "
            f"finalized MultibodyPlant, got {describe(scene_or_plant)} "
            f"({type(scene_or_plant).__name__})"
        )
    check_plant(plant)
    context = plant_context
    if context is None:
        context = getattr(scene_or_plant, "plant_context", None)
    body = object_body
    if body is None:
        body = getattr(scene_or_plant, "object_body", None)
    plane = check_plane(plane)
    data = getattr(result, "data", None)  # a GraspReport
    if data is not None and hasattr(result, "form_closure"):
        analysed = getattr(data, "object_body", None)
        if not isinstance(analysed, str):
            raise InvalidOptionError(
                "result looks like a GraspReport but names no object body; pass "
                "analyze_grasp's report, its form_closure or a Certificate"
            )
        try:
            report_body = resolve_body(plant, analysed)
        except ModelError as e:
            raise InvalidOptionError(
                f"the report is of object body {analysed!r}, which this plant does "
                f"not have ({e}); animate the report with the scene or plant it "
                "was analysed in"
            ) from None
        if body is None:
            body = report_body
        else:
            body = resolve_object_body(plant, body)
            if body.index() != report_body.index():
                raise InvalidOptionError(
                    f"the report is of object body {analysed!r}, but the object "
                    f"body to move is {scoped_name(plant, body)!r}; animate the "
                    "report with the scene it was analysed in"
                )
        report_plane = getattr(data, "plane", None)
        if plane is not None and report_plane is not None and plane != report_plane:
            raise InvalidOptionError(
                f"plane={describe(plane)}, but the report was analysed in the "
                f"{report_plane!r} plane"
            )
        plane = plane or report_plane
        result = result.form_closure
    if context is None or body is None:
        raise InvalidOptionError(
            "animate_escape needs a Scene, or a plant with plant_context= and "
            "object_body="
        )
    context = plant_context_of(plant, context)
    body = resolve_object_body(plant, body)
    if not isinstance(result, Certificate):
        result = getattr(result, "certificate", result)
    return plant, context, body, _escape_twist(result), plane


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
        a finalized plant with ``plant_context`` and ``object_body``.
    result : GraspReport, ClosureResult or Certificate
        A form-closure "no" whose certificate is an escape twist (a report's
        ``form_closure``).  A report must be of this plant's object body: its
        ``data.object_body`` must name a body of the plant, the one moved.
    plant_context, object_body : optional
        For a bare plant (``object_body``: a body, ``BodyIndex`` or name);
        ``plant_context`` may be the diagram's root context.
    plane : str, optional
        Plane of a planar analysis (``"xy"``, ``"yz"`` or ``"zx"``); a report
        gives its own (a different one is refused).
    amount : float, optional
        Largest twist parameter over ``b`` (the unit twist moves points by
        about 1 m/s, so ``amount · b`` moves them by about ``amount · b``): a
        real number in ``(0, MAX_AMOUNT]`` = (0, 100].
    duration : float, optional
        Seconds of one sweep: a real number in ``[MIN_DURATION, MAX_DURATION]``
        = [0.01, 3600].
    frames : int, optional
        Frames of one sweep: an integer in ``[2, MAX_FRAMES]`` = [2, 3600]
        (not a float: ``2.5`` frames is refused).
    prefix : str, optional
        Meshcat path of the drawing (deleted first), non-empty.

    Returns
    -------
    EscapeAnimation

    Raises
    ------
    InvalidOptionError
        For ``frames``, ``duration`` or ``amount`` out of range (or not
        numbers), a ``scene_or_plant`` that is neither a Scene nor a plant
        (None too), a report whose object body is not in the plant or is not
        the body to move, a result without an escape twist (or a twist that
        is not finite and non-zero, or whose motion overflows: see
        :func:`escape_transform`), a planar twist without its plane, an empty
        ``prefix`` or a ``meshcat`` that is not a Meshcat.
    ModelError
        For a plant that is not finalized, or an ``object_body`` that is not
        one of its bodies.
    InvalidContextError
        For a ``plant_context`` of another system.
    """
    check_meshcat(meshcat)
    prefix = check_path("prefix", prefix)
    frames_n = integer_or_none(frames)
    if frames_n is None or not (2 <= frames_n <= MAX_FRAMES):
        raise InvalidOptionError(
            f"frames must be an integer >= 2 and <= {MAX_FRAMES} "
            "(drakegrasp.visualization.escape.MAX_FRAMES), got "
            f"{describe(frames)}"
        )
    duration = real_scalar("duration", duration)
    if not (MIN_DURATION <= duration <= MAX_DURATION):
        raise InvalidOptionError(
            f"duration must be a real number of seconds in [{MIN_DURATION:g}, "
            f"{MAX_DURATION:g}], got {describe(duration)}"
        )
    amount = check_amount(amount)
    plant, context, body, (x, p_cert, b, two_sided), plane = _unpack(
        scene_or_plant, result, plant_context, object_body, plane
    )
    twist, p = _twist_3d(x, p_cert, plane)
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
    t_max = amount * b
    ramp = np.linspace(0.0, 1.0, frames_n)
    times = t_max * (np.concatenate([ramp, -ramp]) if two_sided else ramp)
    animation = MeshcatAnimation(frames_per_second=frames_n / duration)
    transforms = []
    for n, t in enumerate(times):
        X = X_WO @ _flow(twist, p, float(t))
        animation.SetTransform(n, obj, X)
        transforms.append(X)
    meshcat.SetTransform(obj, X_WO)
    meshcat.SetAnimation(animation)
    return EscapeAnimation(prefix, obj, animation, times, tuple(transforms), twist)
