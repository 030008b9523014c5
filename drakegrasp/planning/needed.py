"""What a hand must apply to hold a weight: a load over a capacity, and its words.

A candidate's ``squeeze_needed`` is the object's weight over its weight
capacity (N of weight per N of squeeze), and ``torque_needed`` the weight
over its torque capacity (N of weight per N·m at every motor: an actuated
closing joint, whose ``<mimic>`` followers it drives;
:mod:`~drakegrasp.planning.motors`).  Both
come from :func:`needed_for`, and are said by :func:`needed_text`:

- NaN where the capacity or the weight is unknown (not computed);
- ``inf`` where the capacity is 0: no effort holds the weight;
- 0 where the capacity is infinite: nothing is needed;
- otherwise the quotient, which is ``inf`` too where it exceeds the largest
  float (:data:`FLOAT_MAX`, about 1.8e308: an ``object_mass`` near 1e307
  kg).  Such a figure exists but no float holds it; :func:`beyond_float_range`
  tells it from "none holds" by its capacity, and :func:`needed_text` says
  "more than 1.8e+308 N, beyond float range" rather than ``inf``.

The quotient is taken in Python floats, without numpy's overflow warning:
``inf`` is its honest value, not an accident to warn about.
"""

from __future__ import annotations

import math
import sys

import numpy as np

from drakegrasp.core.deprecation import warn_deprecated
from drakegrasp.core.validation import describe
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "FLOAT_MAX",
    "LONG_FIGURE",
    "beyond_float_range",
    "needed_for",
    "needed_text",
    "per_joint",
    "per_motor",
]

FLOAT_MAX = sys.float_info.max
"""The largest float, about 1.8e308: a needed effort above it reads ``inf``."""

LONG_FIGURE = 1e6
"""From this size on, a figure printed with fixed decimals (``.1f``) is printed
with three significant digits instead: no 300-digit squeeze."""


def needed_for(load: float, capacity: float) -> float:
    """``load / capacity``: the effort that holds ``load`` at ``capacity`` per unit.

    Parameters
    ----------
    load : float
        The object's weight (N), >= 0; NaN when unknown.
    capacity : float
        Weight held per unit of effort (N per N of squeeze, or per N·m of
        torque), >= 0 or ``inf``; NaN when not computed.

    Returns
    -------
    float
        0 for no load; NaN for a capacity not computed; ``inf`` for a capacity
        of 0 (none holds, whatever the weight: also when it is unknown); NaN
        for an unknown weight; 0 for an infinite capacity; else the quotient,
        ``inf`` where it exceeds :data:`FLOAT_MAX` (:func:`beyond_float_range`).

    Raises
    ------
    InvalidOptionError
        A load or capacity that is not a real number, or a negative load (a
        negative capacity, an LP's rounding, holds none).
    """
    load = _figure("load", load)
    capacity = _figure("capacity", capacity, negative_is_none=True)
    if load == 0.0:
        return 0.0
    if math.isnan(capacity):
        return math.nan
    if capacity <= 0.0:  # an LP's -1e-17 is none too
        return math.inf
    if math.isnan(load):
        return math.nan
    if math.isinf(capacity):
        return 0.0
    return load / capacity  # Python floats: inf beyond FLOAT_MAX, no warning


def _figure(name: str, value, *, negative_is_none: bool = False) -> float:
    """A load or capacity: a real number >= 0, inf or NaN (unknown).

    ``negative_is_none``: a capacity below 0 (an LP's rounding) reads as 0.
    """
    if isinstance(value, bool) or not isinstance(
        value, int | float | np.integer | np.floating
    ):
        raise InvalidOptionError(f"{name} must be a real number, got {describe(value)}")
    value = float(value)
    if value < 0.0 and not negative_is_none:
        raise InvalidOptionError(f"{name} must be >= 0, got {value:g}")
    return value


def beyond_float_range(needed: float, capacity: float) -> bool:
    """Whether an ``inf`` of :func:`needed_for` is a figure above :data:`FLOAT_MAX`.

    True for an infinite ``needed`` at a finite capacity > 0 (some effort
    holds the weight, more than a float can say); False for one at a capacity
    of 0 (none holds) and for any finite or NaN ``needed``.
    """
    return math.isinf(needed) and needed > 0 and 0.0 < capacity < math.inf


def needed_text(needed: float, capacity: float, unit: str, spec: str = ".3g") -> str:
    """``needed`` in words with its ``unit``: "12.3 N per finger", honest at inf.

    Parameters
    ----------
    needed : float
        From :func:`needed_for`.
    capacity : float
        The capacity it came from, which tells "beyond float range" from "none
        holds".
    unit : str
        Appended after the figure ("N per finger", "N·m per motor").
    spec : str, optional
        The figure's format (default ``".3g"``); a fixed-point one (``".1f"``)
        gives way to ``".3g"`` from :data:`LONG_FIGURE` on.

    Returns
    -------
    str
        "12.3 N per finger"; "more than 1.8e+308 N per finger, beyond float
        range" (:func:`beyond_float_range`); "inf N per finger" where none
        holds; "nan N per finger" where not computed.
    """
    capacity = _figure("capacity", capacity, negative_is_none=True)
    if isinstance(needed, bool) or not isinstance(
        needed, int | float | np.integer | np.floating
    ):
        raise InvalidOptionError(
            f"needed must be a real number, got {describe(needed)}"
        )
    needed = float(needed)
    if beyond_float_range(needed, capacity):
        return f"more than {FLOAT_MAX:.2g} {unit}, beyond float range"
    if spec.endswith("f") and math.isfinite(needed) and needed >= LONG_FIGURE:
        spec = ".3g"
    try:
        return f"{needed:{spec}} {unit}"
    except (TypeError, ValueError):
        raise InvalidOptionError(
            f"spec must be a float format such as '.3g', got {describe(spec)}"
        ) from None


def per_motor(unit: str) -> str:
    """A motor effort's ``unit`` as ``torque_needed``'s words: "N·m per motor".

    ``unit`` is the unit of the efforts of a hand's closing joints: ``"N·m"``
    (every joint turns), ``"N"`` (every one slides) or ``"N·m, N at prismatic
    joints"`` (both; ``GraspCandidate.torque_unit``), which reads "N·m per
    motor, N at prismatic joints".  ``torque_needed`` is what every motor
    applies: a hand's motors are its actuated closing joints, a ``<mimic>``
    follower turning with its leader's (the 2F-85's one motor closes six
    joints), and a model without actuators has one at each joint
    (:mod:`~drakegrasp.planning.motors`).
    """
    return _per(unit, "motor")


def per_joint(unit: str) -> str:
    """Deprecated name of :func:`per_motor`.

    Its words ("N·m per joint") misnamed ``torque_needed`` for a hand whose
    motors drive several joints.
    """
    warn_deprecated("per_joint is deprecated; use per_motor (torque is per motor)")
    return _per(unit, "joint")


def _per(unit: str, each: str) -> str:
    """``unit`` per ``each``: "N·m per motor" (mixed: "..., N at prismatic joints")."""
    one, _, other = unit.partition(", ")
    return f"{one} per {each}, {other}" if other else f"{one} per {each}"
