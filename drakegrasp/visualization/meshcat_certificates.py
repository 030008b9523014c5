"""Draw a verdict's certificate in Meshcat: the unresisted wrench, the escape axis.

Paths (under the grasp drawing's ``prefix``, so in the grasp frame G)::

    {prefix}/certificate/force     the external force the grasp cannot resist,
                                   along its line of action (red arrow)
    {prefix}/certificate/moment    its moment part, along the moment axis
                                   (orange arrow)
    {prefix}/certificate/axis      escape twist: the rotation (screw) axis
                                   through its nearest point to p (green arrow)
    {prefix}/certificate/motion    escape twist: the translation of p (green)
    {prefix}/certificate/point     the line's / axis's point (sphere)

Planar certificates are drawn in G's z = 0 plane (a planar moment or rotation is
about z).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydrake.geometry import Meshcat, Rgba, Sphere
from pydrake.math import RigidTransform

from drakegrasp.certificates.certificate import (
    ESCAPE_TWIST,
    UNRESISTED_WRENCH,
    Certificate,
)
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.validation import describe, real_array, real_scalar, safe_norm
from drakegrasp.errors import InvalidOptionError
from drakegrasp.visualization.geometry import positive_length
from drakegrasp.visualization.primitives import _draw_arrow, check_meshcat, check_path

__all__ = [
    "CERTIFICATE_COLORS",
    "MATCH_TOL",
    "checked_certificate",
    "draw_certificate",
    "draw_result_certificate",
    "lift_planar",
    "result_certificate",
]

CERTIFICATE_COLORS = {
    "force": Rgba(0.9, 0.1, 0.1, 1.0),
    "moment": Rgba(1.0, 0.55, 0.0, 1.0),
    "twist": Rgba(0.1, 0.75, 0.2, 1.0),
    "point": Rgba(0.2, 0.2, 0.2, 1.0),
}
"""Colours of the certificate's parts."""

_SMALL = 1e-6

MATCH_TOL = 1e-6
"""Relative difference up to which a certificate's reference point (over
``b + |p|``) and characteristic length (over ``b``) are the grasp's own."""


def lift_planar(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``[a, b, c]`` (planar twist or wrench) as 3-D ``(linear, angular)`` about z."""
    x = np.asarray(x, dtype=float)
    if x.size == 6:
        return x[:3], x[3:]
    return np.array([x[0], x[1], 0.0]), np.array([0.0, 0.0, x[2]])


def _point3(p: np.ndarray) -> np.ndarray:
    p = np.asarray(p, dtype=float)
    return p if p.size == 3 else np.array([p[0], p[1], 0.0])


def _norm(x: np.ndarray) -> float:
    return float(safe_norm(x))


def _arrow(meshcat, path, tail, vector, radius, rgba, paths):
    if _norm(vector) > 0:
        _draw_arrow(meshcat, path, tail, vector, radius=radius, rgba=rgba)
        paths.append(path)


def checked_certificate(
    grasp: Grasp, certificate: Any
) -> tuple[np.ndarray, np.ndarray]:
    """A drawable certificate's direction and reference point, checked on ``grasp``.

    Parameters
    ----------
    grasp : Grasp
    certificate : Certificate
        Of any kind; only an escape twist and an unresisted wrench have a
        direction to draw.

    Returns
    -------
    direction : (3,) or (6,) float
        Scaled as the certificate's convention has it (``‖[v; b ω]‖ = 1``,
        ``‖[f; m / b]‖ = 1``), computed without overflow; empty for the kinds
        that are not drawn.
    reference_point : (3,) float
        The grasp's ``p`` (planar: ``z = 0``).

    Raises
    ------
    InvalidOptionError
        For a ``certificate`` that is not a Certificate, or one of another
        grasp: arrays of another shape (other number of contacts or
        dimension), another reference point or characteristic length, or a
        direction that is zero or not finite.
    """
    if not isinstance(grasp, Grasp):
        raise InvalidOptionError(
            f"grasp must be a drakegrasp.Grasp, got {describe(grasp)} "
            f"({type(grasp).__name__})"
        )
    if not isinstance(certificate, Certificate):
        raise InvalidOptionError(
            "certificate must be a drakegrasp Certificate (a verdict's "
            f"result.certificate), got {describe(certificate)} "
            f"({type(certificate).__name__})"
        )
    p = _point3(grasp.reference_point)
    if certificate.kind not in (UNRESISTED_WRENCH, ESCAPE_TWIST):
        return np.zeros(0), p
    certificate.check(grasp)  # refuses arrays of another grasp's shapes
    b = grasp.characteristic_length
    if certificate.reference_point is not None:
        q = real_array(
            "the certificate's reference_point",
            certificate.reference_point,
            error=InvalidOptionError,
        )
        g = np.asarray(grasp.reference_point, dtype=float)
        far = (
            q.shape != g.shape
            or not np.all(np.isfinite(q))
            or float(safe_norm(q - g)) > MATCH_TOL * (b + float(safe_norm(g)))
        )
        if far:
            raise InvalidOptionError(
                "this certificate belongs to another grasp: its reference point "
                f"is {describe(q.tolist())}, the grasp's {describe(g.tolist())} "
                "(draw a verdict's certificate with the grasp it was computed for)"
            )
    b_cert = real_scalar(
        "the certificate's characteristic_length", certificate.characteristic_length
    )
    if not abs(b_cert - b) <= MATCH_TOL * b:
        raise InvalidOptionError(
            "this certificate belongs to another grasp: it was computed with the "
            f"characteristic length b = {b_cert!r} m, the grasp has b = {b!r} m"
        )
    x = real_array(
        "the certificate's direction", certificate.direction, error=InvalidOptionError
    )
    m = float(np.max(np.abs(x))) if np.all(np.isfinite(x)) else float("nan")
    if not 0.0 < m < np.inf:
        raise InvalidOptionError(
            f"the certificate's direction {describe(x.tolist())} must be finite and "
            "non-zero to be drawn"
        )
    x = x / m  # a norm of it cannot overflow; then the certificate's own scaling
    d = grasp.dim
    lin, ang = x[:d], x[d:]
    if certificate.kind == ESCAPE_TWIST:
        x = x / _norm(np.concatenate([lin, b * ang]))
    else:
        x = x / _norm(np.concatenate([lin, ang / b]))
    return x, p


def draw_certificate(
    meshcat: Meshcat,
    grasp: Grasp,
    certificate: Certificate,
    *,
    prefix: str,
    length: float | None = None,
    radius: float | None = None,
) -> tuple[str, ...]:
    """Draw one certificate under ``{prefix}/certificate`` (grasp frame).

    Parameters
    ----------
    meshcat : Meshcat
    grasp : Grasp
        The grasp the certificate was computed for.
    certificate : Certificate
        An unresisted wrench or an escape twist of ``grasp`` (internal forces
        draw as forces with :func:`~drakegrasp.visualization.draw_grasp`
        already; their kinds draw nothing here).
    prefix : str
        The grasp drawing's path (it carries ``X_WG``): a non-empty string.
    length : float, optional
        Length of the longest arrow, metres.  Default 0.8 b.  A real number in
        ``[DRAW_LENGTH_MIN, DRAW_LENGTH_MAX]`` = [2.2e-308, 1e30]
        (:mod:`drakegrasp.visualization.geometry`): every arrow, point and
        radius drawn is then finite.
    radius : float, optional
        Arrow radius, metres.  Default 0.015 b.  Same range as ``length``.

    Returns
    -------
    tuple of str
        The paths drawn (empty for the kinds that are not drawn).

    Raises
    ------
    InvalidOptionError
        For a ``length`` or ``radius`` that is not a real number in that range
        (NaN, 0, negative, a string...), a ``certificate`` that is not a
        Certificate or belongs to another grasp (see
        :func:`checked_certificate`), a ``grasp`` that is not a Grasp, an
        empty ``prefix`` or a ``meshcat`` that is not a Meshcat.  Nothing is
        drawn then.
    """
    check_meshcat(meshcat)
    prefix = check_path("prefix", prefix)
    direction, p = checked_certificate(grasp, certificate)
    b = grasp.characteristic_length
    L = 0.8 * b if length is None else positive_length("length", length)
    r = 0.015 * b if radius is None else positive_length("radius", radius)
    base = f"{prefix}/certificate"
    meshcat.Delete(base)
    if direction.size == 0:
        return ()
    paths: list[str] = []
    if certificate.kind == UNRESISTED_WRENCH:
        f, m = lift_planar(-direction)  # external wrench
        size = max(_norm(f), _norm(m) / b)
        f_len, m_len = _norm(f) / size, _norm(m) / b / size
        point = p
        if f_len > _SMALL:
            fhat = f / _norm(f)
            point = p + np.cross(fhat, m) / _norm(f)  # on the line of action
            _arrow(
                meshcat,
                f"{base}/force",
                point - L * f_len * fhat,
                L * f_len * fhat,
                r,
                CERTIFICATE_COLORS["force"],
                paths,
            )
            # about a point of the line only the moment along it (pitch) remains
            m = (m @ fhat) * fhat
            m_len = _norm(m) / b / size
        if m_len > _SMALL:
            _arrow(
                meshcat,
                f"{base}/moment",
                point,
                L * m_len * m / _norm(m),
                1.3 * r,
                CERTIFICATE_COLORS["moment"],
                paths,
            )
    else:
        v, w = lift_planar(direction)
        point = p
        if b * _norm(w) > _SMALL * _norm(v):
            what = w / _norm(w)
            point = p + np.cross(what, v) / _norm(w)
            _arrow(
                meshcat,
                f"{base}/axis",
                point - 0.5 * L * what,
                L * what,
                r,
                CERTIFICATE_COLORS["twist"],
                paths,
            )
            along = (v @ what) * what  # pitch translation along the axis
            if _norm(along) > _SMALL:
                _arrow(
                    meshcat,
                    f"{base}/motion",
                    point,
                    L * along,
                    0.7 * r,
                    CERTIFICATE_COLORS["twist"],
                    paths,
                )
        else:
            _arrow(
                meshcat,
                f"{base}/motion",
                p,
                L * v / _norm(v),
                r,
                CERTIFICATE_COLORS["twist"],
                paths,
            )
    meshcat.SetObject(f"{base}/point", Sphere(2.0 * r), CERTIFICATE_COLORS["point"])
    meshcat.SetTransform(f"{base}/point", RigidTransform(point))
    paths.append(f"{base}/point")
    return tuple(paths)


def result_certificate(grasp: Grasp, result: Any) -> Certificate | None:
    """``result.certificate`` when ``draw_grasp`` draws it, checked on ``grasp``.

    None for a "yes", a result without a certificate, or forces given as
    arrays.

    Raises
    ------
    InvalidOptionError
        For a certificate of another grasp (:func:`checked_certificate`).
    """
    cert = getattr(result, "certificate", None)
    if not isinstance(cert, Certificate) or getattr(result, "is_closure", True):
        return None
    checked_certificate(grasp, cert)
    return cert


def draw_result_certificate(
    meshcat: Meshcat, grasp: Grasp, result: Any, prefix: str
) -> tuple[str, ...]:
    """Draw the certificate a result carries, if it carries one.

    What ``draw_grasp(..., result=)`` draws beside the grasp, for a caller
    that draws the grasp itself: :func:`result_certificate` then
    :func:`draw_certificate`.

    Parameters
    ----------
    meshcat : pydrake.geometry.Meshcat
    grasp : Grasp
        The grasp the result judged (object frame O, metres).
    result : object
        A result of a closure decision (its ``certificate`` is read), as
        :func:`result_certificate` takes it.
    prefix : str
        Meshcat path under which the certificate is drawn.

    Returns
    -------
    tuple of str
        The Meshcat paths drawn (empty when the result carries none).
    """
    cert = result_certificate(grasp, result)
    if cert is None:
        return ()
    return draw_certificate(meshcat, grasp, cert, prefix=prefix)
