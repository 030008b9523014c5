"""One sentence per certificate: which way the object moves, which push wins.

Points are in the grasp frame (metres); a twist is read as a screw (rotation
axis through a point, or a translation), a wrench as a line of action.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.certificates.kinds import (
    BALANCE,
    ESCAPE_TWIST,
    UNCONTROLLABLE,
    UNRESISTED_WRENCH,
    Witness,
)
from drakegrasp.core.validation import safe_norm

__all__ = ["axis_name", "describe_certificate", "screw_point"]

_SMALL = 1e-6
"""Relative size below which a component counts as zero in the wording."""


def axis_name(u: np.ndarray, *, both_signs: bool = False) -> str:
    """``"x"``, ``"−z"``, ``"±y"``... along an axis, else the unit vector."""
    u = np.asarray(u, dtype=float)
    u = u / safe_norm(u)
    names = "xyz"[: len(u)]
    k = int(np.argmax(np.abs(u)))
    if abs(u[k]) > 1.0 - _SMALL:
        sign = "±" if both_signs else ("" if u[k] > 0 else "−")
        return sign + names[k]
    return ("±" if both_signs else "") + _vector(u)


def _vector(x: np.ndarray, scale: float = 1.0) -> str:
    x = np.where(np.abs(x) < _SMALL * scale, 0.0, x)
    return "(" + ", ".join(f"{float(c):.3g}" for c in x + 0.0) + ")"


def screw_point(p: np.ndarray, linear: np.ndarray, angular: np.ndarray) -> np.ndarray:
    """The point of the screw axis nearest ``p`` (twist) or of the line of action.

    Parameters
    ----------
    p : (3,) or (2,) float
        Reference point, metres.
    linear, angular : ndarray
        The twist's ``v_p`` (m/s) and ``ω`` (rad/s; planar: shape (1,)), with
        ``ω ≠ 0``.  The axis point is ``p + ω × v_p / |ω|²`` (planar: the
        centre of rotation ``p + (−v_y, v_x) / ω``).

    Returns
    -------
    ndarray
        A point of the axis, metres.
    """
    if len(p) == 3:
        return p + np.cross(angular, linear) / float(angular @ angular)
    w = float(angular[0])
    return p + np.array([-linear[1], linear[0]]) / w


def _line_point(p: np.ndarray, f: np.ndarray, m: np.ndarray) -> np.ndarray:
    """A point of the line of action of ``[f; m]`` (moment about ``p``)."""
    if len(p) == 3:
        return p + np.cross(f, m) / float(f @ f)
    return p + float(m[0]) * np.array([f[1], -f[0]]) / float(f @ f)


def _more(cert: Witness, what: str) -> str:
    k = cert.null_basis.shape[-1] if cert.two_sided else 1
    return f" (and {k - 1} more independent {what})" if k > 1 else ""


def _contacts_text(cert: Witness) -> str:
    separating = cert.separating()  # the certificate's CONTACT_RATE_TOL
    sep = np.flatnonzero(separating)
    if sep.size == 0:
        return "every contact slides"
    slide = np.flatnonzero(~separating)
    text = f"contact{'s' if sep.size > 1 else ''} {', '.join(map(str, sep))} separate"
    if slide.size:
        text += f"; {', '.join(map(str, slide))} slide{'s' if slide.size == 1 else ''}"
    return text


def _twist_text(cert: Witness) -> str:
    p = np.asarray(cert.reference_point, dtype=float)
    b, d = cert.characteristic_length, len(p)
    v = np.asarray(cert.direction, dtype=float)
    lin, ang = v[:d], v[d:]
    two = cert.two_sided
    if b * np.linalg.norm(ang) <= _SMALL * np.linalg.norm(lin):
        motion = f"translate along {axis_name(lin, both_signs=two)}"
    elif d == 2:
        sense = "counter-clockwise" if ang[0] > 0 else "clockwise"
        sense = "either way" if two else sense
        motion = f"rotate {sense} about {_vector(screw_point(p, lin, ang), b)} m"
    else:
        r = screw_point(p, lin, ang)
        pitch = float(ang @ lin) / float(ang @ ang)
        motion = (
            f"rotate about {axis_name(ang, both_signs=two)} through {_vector(r, b)} m"
        )
        if abs(pitch) > _SMALL * b:
            motion = motion.replace("rotate", "screw") + f" (pitch {pitch:.3g} m/rad)"
    return (
        f"the object can {motion} without penetrating any finger"
        f"{_more(cert, 'motions')}: {_contacts_text(cert)}"
    )


def _wrench_text(cert: Witness) -> str:
    p = np.asarray(cert.reference_point, dtype=float)
    b, d = cert.characteristic_length, len(p)
    e = -np.asarray(cert.direction, dtype=float)  # the external wrench
    f, m = e[:d], e[d:]
    two = cert.two_sided
    if np.linalg.norm(f) * b <= _SMALL * np.linalg.norm(m):
        if d == 2:
            sense = "counter-clockwise" if m[0] > 0 else "clockwise"
            what = "a moment of either sign" if two else f"a {sense} moment"
        else:
            what = f"a moment about {axis_name(m, both_signs=two)}"
    else:
        r = _line_point(p, f, m)
        what = f"a force along {axis_name(f, both_signs=two)} through {_vector(r, b)} m"
        if d == 3:
            pitch = float(f @ m) / float(f @ f)
            if abs(pitch) > _SMALL * b:
                what += f" with a moment about it (pitch {pitch:.3g} m)"
    return f"cannot resist {what}{_more(cert, 'wrenches')}"


def _friction_needed(forces) -> float:
    """The largest ``‖f_t‖ / f_n`` over contacts pressed (0 if none).

    A contact's force is normal first, then its tangential components (one
    planar, two spatial), then a soft finger's moment, which is not counted.
    """
    worst = 0.0
    for f in forces:
        f = np.asarray(f, dtype=float)
        if f.size < 2 or not f[0] > 0:
            continue
        tangential = f[1:3] if f.size >= 3 else f[1:2]
        worst = max(worst, float(np.linalg.norm(tangential)) / float(f[0]))
    return worst


def describe_certificate(cert: Witness) -> str:
    """See :meth:`drakegrasp.certificates.certificate.Certificate.describe`."""
    if cert.kind == ESCAPE_TWIST:
        return _twist_text(cert)
    if cert.kind == UNRESISTED_WRENCH:
        return _wrench_text(cert)
    forces = cert.contact_forces or ()
    f_n = np.array([f[0] for f in forces])
    shown = ", ".join(f"{x:.3g}" for x in f_n)
    if cert.kind == UNCONTROLLABLE:
        text = (
            f"the hand cannot change a squeeze with normal forces ({shown}) N "
            "(per Σ f_n = N): no joint torque acts on it"
        )
        ratio = _friction_needed(forces)
        if ratio > 1.0:  # LP3 leaves the tangential components free
            text += (
                f"; it presses {ratio:.3g} times harder along the surfaces than "
                "into them (LP3 bounds no friction)"
            )
        return text
    assert cert.kind == BALANCE
    k = 0 if cert.internal_basis is None else cert.internal_basis.shape[1]
    return (
        f"normal forces ({shown}) N balance strictly inside every cone, "
        f"found among dim N(G) = {k} internal forces"
    )
