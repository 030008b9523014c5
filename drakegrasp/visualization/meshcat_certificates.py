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
from drakegrasp.visualization.primitives import _draw_arrow

__all__ = [
    "CERTIFICATE_COLORS",
    "draw_certificate",
    "draw_result_certificate",
    "lift_planar",
]

CERTIFICATE_COLORS = {
    "force": Rgba(0.9, 0.1, 0.1, 1.0),
    "moment": Rgba(1.0, 0.55, 0.0, 1.0),
    "twist": Rgba(0.1, 0.75, 0.2, 1.0),
    "point": Rgba(0.2, 0.2, 0.2, 1.0),
}
"""Colours of the certificate's parts."""

_SMALL = 1e-6


def lift_planar(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``[a, b, c]`` (planar twist or wrench) as 3-D ``(linear, angular)`` about z."""
    x = np.asarray(x, dtype=float)
    if x.size == 6:
        return x[:3], x[3:]
    return np.array([x[0], x[1], 0.0]), np.array([0.0, 0.0, x[2]])


def _point3(p: np.ndarray) -> np.ndarray:
    p = np.asarray(p, dtype=float)
    return p if p.size == 3 else np.array([p[0], p[1], 0.0])


def _arrow(meshcat, path, tail, vector, radius, rgba, paths):
    if np.linalg.norm(vector) > 0:
        _draw_arrow(meshcat, path, tail, vector, radius=radius, rgba=rgba)
        paths.append(path)


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
    certificate : Certificate
        An unresisted wrench or an escape twist (internal forces draw as forces
        with :func:`~drakegrasp.visualization.draw_grasp` already).
    prefix : str
        The grasp drawing's path (it carries ``X_WG``).
    length : float, optional
        Length of the longest arrow, metres.  Default 0.8 b.
    radius : float, optional
        Arrow radius, metres.  Default 0.015 b.

    Returns
    -------
    tuple of str
        The paths drawn.
    """
    b = grasp.characteristic_length
    L = 0.8 * b if length is None else float(length)
    r = 0.015 * b if radius is None else float(radius)
    base = f"{prefix}/certificate"
    meshcat.Delete(base)
    paths: list[str] = []
    p = _point3(certificate.reference_point)
    if certificate.kind == UNRESISTED_WRENCH:
        f, m = lift_planar(-np.asarray(certificate.direction))  # external wrench
        size = max(np.linalg.norm(f), np.linalg.norm(m) / b)
        f_len, m_len = np.linalg.norm(f) / size, np.linalg.norm(m) / b / size
        point = p
        if f_len > _SMALL:
            point = p + np.cross(f, m) / float(f @ f)  # on the line of action
            fhat = f / np.linalg.norm(f)
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
            m_len = np.linalg.norm(m) / b / size
        if m_len > _SMALL:
            _arrow(
                meshcat,
                f"{base}/moment",
                point,
                L * m_len * m / np.linalg.norm(m),
                1.3 * r,
                CERTIFICATE_COLORS["moment"],
                paths,
            )
    elif certificate.kind == ESCAPE_TWIST:
        v, w = lift_planar(certificate.direction)
        point = p
        if b * np.linalg.norm(w) > _SMALL * np.linalg.norm(v):
            point = p + np.cross(w, v) / float(w @ w)
            what = w / np.linalg.norm(w)
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
            if np.linalg.norm(along) > _SMALL:
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
                L * v / np.linalg.norm(v),
                r,
                CERTIFICATE_COLORS["twist"],
                paths,
            )
    else:
        return ()
    meshcat.SetObject(f"{base}/point", Sphere(2.0 * r), CERTIFICATE_COLORS["point"])
    meshcat.SetTransform(f"{base}/point", RigidTransform(point))
    paths.append(f"{base}/point")
    return tuple(paths)


def draw_result_certificate(
    meshcat: Meshcat, grasp: Grasp, result: Any, prefix: str
) -> tuple[str, ...]:
    """The hook of ``draw_grasp``: draw ``result.certificate`` if it has one."""
    cert = getattr(result, "certificate", None)
    if not isinstance(cert, Certificate) or getattr(result, "is_closure", True):
        return ()
    return draw_certificate(meshcat, grasp, cert, prefix=prefix)
