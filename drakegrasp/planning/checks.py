"""Input checks shared by the planning stages: arrays, friction, counts, rngs.

Weight capacity, robustness, re-closing and placement take the same kinds of
argument; each check here raises a :class:`~drakegrasp.GraspError` naming the
argument, and is built on :mod:`drakegrasp.core.validation`.
"""

from __future__ import annotations

import reprlib

import numpy as np

from drakegrasp.core.contact import ContactModel
from drakegrasp.core.validation import (
    check_coefficient,
    check_positions,
    integer_or_none,
    real_array,
    real_scalar,
    unit_vectors,
)
from drakegrasp.errors import InvalidContactError, InvalidOptionError

__all__ = [
    "MAX_FINGER_LABEL",
    "checked_contacts",
    "checked_count",
    "checked_directions",
    "checked_fingers",
    "checked_friction",
    "checked_nonnegative",
    "checked_points",
    "checked_rng",
]

MAX_FINGER_LABEL = 63
"""Largest finger label of a contact (``fingers``): a hand of up to 63 fingers
and its palm.  Each label up to the largest is one squeeze-bounded group, with
a variable in every LP of
:func:`~drakegrasp.planning.weight.weight_capacity`, so the LPs grow with it."""


def _describe(value) -> str:
    return reprlib.repr(value)


def checked_points(positions) -> np.ndarray:
    """(K, N, 3) contact points of ``K`` grasps of ``N >= 1`` contacts, checked.

    Real and finite, metres (:func:`~drakegrasp.core.validation.check_positions`);
    :class:`~drakegrasp.InvalidContactError` naming ``positions`` otherwise.
    """
    P = check_positions("positions", positions)
    if P.ndim != 3 or P.shape[2] != 3 or P.shape[1] < 1:
        raise InvalidContactError(
            "positions must have shape (K, N, 3): K grasps of N >= 1 spatial "
            f"contacts, got shape {P.shape}"
        )
    return P


def checked_contacts(positions, normals) -> tuple[np.ndarray, np.ndarray]:
    """``(P, Nrm)`` of ``K`` grasps of ``N`` contacts, checked.

    Parameters
    ----------
    positions : (K, N, 3) array-like
        Real, finite contact points (metres), ``N >= 1``.
    normals : (K, N, 3) array-like
        Finite, non-zero contact normals; normalised here (as
        :func:`~drakegrasp.batch.batch_force_closure` does).

    Returns
    -------
    P : (K, N, 3) float
    Nrm : (K, N, 3) float
        Unit normals.

    Raises
    ------
    InvalidContactError
        Naming ``positions`` or ``normals``.
    """
    P = checked_points(positions)
    Nrm = real_array("normals", normals)
    if Nrm.shape != P.shape:
        raise InvalidContactError(
            f"normals must have the shape of positions {P.shape}, got {Nrm.shape}"
        )
    return P, unit_vectors("normals", Nrm)


def checked_fingers(fingers, shape: tuple) -> np.ndarray:
    """(K, N) int finger labels, each an integer in ``[0, MAX_FINGER_LABEL]``.

    ``shape`` is ``(K, N)`` of the positions.  Integral floats are taken; a
    boolean, negative, fractional or non-finite label is refused
    (:class:`~drakegrasp.InvalidContactError` naming ``fingers``).
    """
    F = real_array("fingers", fingers)  # refuses bool, complex, str, object
    if F.shape != tuple(shape):
        raise InvalidContactError(
            f"fingers must have shape (K, N) = {tuple(shape)}, one label per "
            f"contact, got shape {F.shape}"
        )
    ok = (F >= 0) & (F <= MAX_FINGER_LABEL) & (np.floor(F) == F)  # NaN fails
    if not np.all(ok):
        k, i = (int(j) for j in np.argwhere(~ok)[0])
        raise InvalidContactError(
            f"fingers of grasp {k}, contact {i} is {float(F[k, i])!r}; a finger label "
            f"is an integer in [0, {MAX_FINGER_LABEL}] "
            "(drakegrasp.planning.checks.MAX_FINGER_LABEL)"
        )
    return F.astype(np.int64)


def checked_friction(mu, contact_model, torsional_friction):
    """``(mu, contact_model, torsional_friction)`` checked as the batch engine does.

    ``mu`` and ``torsional_friction`` are 0 or in ``[COEFFICIENT_MIN,
    COEFFICIENT_MAX]`` (:func:`~drakegrasp.core.validation.check_coefficient`:
    booleans, strings, arrays and ``None`` refused); ``contact_model`` a
    :class:`~drakegrasp.ContactModel` or its name, returned as its value;
    ``torsional_friction`` None (not given: refused for a soft finger, as
    :func:`~drakegrasp.batch.batch_force_closure` refuses it) stays None.
    """
    mu = check_coefficient("mu", mu)
    try:
        contact_model = ContactModel.parse(contact_model).value
    except InvalidContactError as err:  # its message names the value, not the argument
        raise InvalidContactError(f"contact_model: {err}") from None
    if torsional_friction is None:
        if contact_model == "soft_finger":
            raise InvalidContactError(
                "contact_model='soft_finger' needs torsional_friction (nu: the "
                "moment about the normal is bounded by b * nu * f_n); pass nu > 0, "
                "or 0 for soft fingers that act as hard fingers"
            )
        return mu, contact_model, None
    nu = check_coefficient("torsional_friction", torsional_friction)
    return mu, contact_model, nu


def checked_directions(name: str, value, *, count=None, error=InvalidOptionError):
    """(D, 3) unit vectors from finite, non-zero 3-vectors ``value`` (normalised).

    ``count`` is the number of rows required (None: any ``D >= 1``).
    """
    a = real_array(name, value, error=error)
    shaped = a.ndim == 2 and a.shape[1] == 3
    if not shaped or not (len(a) >= 1 if count is None else len(a) == count):
        want = "(D, 3) with D >= 1" if count is None else f"({count}, 3)"
        raise error(f"{name} must have shape {want}, got shape {a.shape}")
    bad = ~np.all(np.isfinite(a), axis=1) | ~np.any(a != 0.0, axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise error(
            f"{name}[{i}] is {a[i].tolist()}; each row must be a finite, non-zero "
            "direction (normalised here)"
        )
    return unit_vectors(name, a, error=error)


def checked_count(name: str, value) -> int:
    """``value`` as an int ``>= 0`` (a bool, float or string is refused)."""
    n = integer_or_none(value)
    if n is None or n < 0:
        raise InvalidOptionError(
            f"{name} must be an integer >= 0, got {_describe(value)}"
        )
    return n


def checked_nonnegative(name: str, value, unit: str) -> float:
    """``value`` as a finite float ``>= 0`` (a noise σ, a clearance), in ``unit``."""
    x = real_scalar(name, value)
    if not 0.0 <= x < np.inf:
        raise InvalidOptionError(
            f"{name} must be a finite number >= 0 ({unit}), got {_describe(value)}"
        )
    return x


def checked_rng(rng) -> np.random.Generator:
    """``rng`` if it is a ``numpy.random.Generator``, else InvalidOptionError."""
    if not isinstance(rng, np.random.Generator):
        raise InvalidOptionError(
            "rng must be a numpy.random.Generator (numpy.random.default_rng(seed)), "
            f"got {_describe(rng)} ({type(rng).__name__})"
        )
    return rng
