"""Input checks shared by the planning stages: arrays, friction, counts, noise, rngs.

Weight capacity, robustness, re-closing and placement take the same kinds of
argument; each check here raises a :class:`~drakegrasp.GraspError` naming the
argument, and is built on :mod:`drakegrasp.core.validation`.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.core.contact import ContactModel, missing_torsional_friction
from drakegrasp.core.tolerances import MOMENT_ARMS
from drakegrasp.core.validation import (
    check_coefficient,
    check_length,
    check_positions,
    describe,
    integer_or_none,
    outside_moment_arms,
    real_array,
    real_scalar,
    unit_vectors,
)
from drakegrasp.errors import InvalidContactError, InvalidOptionError

__all__ = [
    "MAX_COPY_BYTES",
    "MAX_FINGER_LABEL",
    "MOMENT_ARMS",
    "NOISE_MAX",
    "checked_contacts",
    "checked_count",
    "checked_directions",
    "checked_fingers",
    "checked_friction",
    "checked_noise",
    "checked_palm",
    "checked_nonnegative",
    "checked_points",
    "checked_rng",
    "checked_samples",
    "checked_torque_scale",
]

MAX_FINGER_LABEL = 63
"""Largest finger label of a contact (``fingers``): a hand of up to 63 fingers
and its palm.  Each label up to the largest is one squeeze-bounded group, with
a variable in every LP of
:func:`~drakegrasp.planning.weight.weight_capacity`, so the LPs grow with it."""

MAX_COPY_BYTES = 2**29
"""Bytes the perturbed copies' contact points may take, ``K * samples * N * 3``
float64 (:func:`checked_samples`): 512 MiB.  A stage holds several arrays of
that size at its peak (the copies' points and normals, rotations, the
re-closing's chord query: measured 8 times it in
:func:`~drakegrasp.planning.ranking.perturbed_copies`, 11 in
:func:`~drakegrasp.planning.ranking.robustness`, 16 in
:func:`~drakegrasp.planning.reclose.reclosed_robustness`), so about 8 GiB,
a third of the project's 24 GiB machine.  Unbounded, ``samples=10**12`` ended
in a MemoryError, and a count just small enough to be allocated could swap
or be killed.  The planner's largest runs (1,500 poses, the default 32 copies,
20 contacts: 23 MB) stay 23 times below it."""


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
    return P, _unit_rows("normals", Nrm, error=InvalidContactError)


def _unit_rows(name: str, a: np.ndarray, *, error: type) -> np.ndarray:
    """``unit_vectors`` of ``a``, keeping the rows that are unit to 4 ulp as given.

    Normalising a unit vector again moves its last bits, and with them every
    capacity and ranking computed from it: a caller's unit normals are used
    as they are, as they were before they were checked here.
    """
    u = unit_vectors(name, a, error=error)
    norm2 = np.einsum("...i,...i->...", a, a)
    unit = np.abs(norm2 - 1.0) <= 4.0 * np.finfo(float).eps
    return np.where(unit[..., None], a, u)


def checked_torque_scale(torque_scale, positions: np.ndarray) -> float:
    """``torque_scale`` (metres), checked against the extent of each grasp.

    Parameters
    ----------
    torque_scale : float
        A length (:func:`~drakegrasp.core.validation.check_length`).
    positions : (K, N, 3) float
        Checked contact points (metres).

    Raises
    ------
    InvalidOptionError
        ``torque_scale`` not a length, or out of
        :data:`~drakegrasp.core.tolerances.MOMENT_ARMS` with some grasp whose
        contacts are not all at O (naming the first such grasp).
    """
    torque_scale = check_length("torque_scale", torque_scale, error=InvalidOptionError)
    if positions.size == 0:
        return torque_scale
    reach = np.max(np.abs(positions), axis=(1, 2))  # (K,) each grasp's extent
    off = outside_moment_arms(reach, torque_scale)
    if off.any():
        k = int(np.flatnonzero(off)[0])
        low, high = MOMENT_ARMS
        raise InvalidOptionError(
            f"torque_scale = {torque_scale:g} m is out of scale with grasp {k}, "
            f"whose contacts lie within {reach[k]:g} m of O: the moments divided "
            f"by torque_scale must stay within [{low:g}, {high:g}] (beyond, they "
            "are below the LPs' resolution or overflow their arithmetic); give a "
            "torque_scale near the grasps' size"
        )
    return torque_scale


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
    contact_model = ContactModel.parse(contact_model).value  # names contact_model=
    if torsional_friction is None:
        if contact_model == "soft_finger":
            raise missing_torsional_friction()
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
    return _unit_rows(name, a, error=error)


def checked_count(name: str, value, minimum: int = 0) -> int:
    """``value`` as an int ``>= minimum`` (a bool, float or string is refused)."""
    n = integer_or_none(value)
    if n is None or n < minimum:
        raise InvalidOptionError(
            f"{name} must be an integer >= {minimum}, got {describe(value)}"
        )
    return n


def checked_palm(value) -> int | None:
    """The passive palm's label of a weight capacity: None or a finger label.

    An integer in ``[0, MAX_FINGER_LABEL]``; integral floats are taken, as in
    ``fingers`` (a bool, fractional float or string is refused:
    :class:`~drakegrasp.InvalidOptionError` naming ``palm``).
    """
    if value is None:
        return None
    n = integer_or_none(value, integral_floats=True)  # as fingers takes them
    if n is None or not 0 <= n <= MAX_FINGER_LABEL:
        raise InvalidOptionError(
            f"palm must be None or a finger label, an integer in [0, "
            f"{MAX_FINGER_LABEL}], got {describe(value)}"
        )
    return n


def checked_samples(value, grasps: int, contacts: int, name: str = "samples") -> int:
    """Copies per grasp: an int ``>= 0`` whose copies fit :data:`MAX_COPY_BYTES`.

    Parameters
    ----------
    value : int
        Copies of each grasp (perturbed, or drawn along a fan).
    grasps, contacts : int
        ``K`` grasps of ``N`` contacts each, copied ``value`` times: the
        copies' points are ``K * value * N * 3`` float64.
    name : str, optional
        The argument's name in a message.

    Raises
    ------
    InvalidOptionError
        Naming ``name``: not an integer ``>= 0``, or copies over
        :data:`MAX_COPY_BYTES`.
    """
    n = checked_count(name, value)
    size = n * int(grasps) * int(contacts) * 3 * 8  # Python ints: no overflow
    if size > MAX_COPY_BYTES:
        raise InvalidOptionError(
            f"{name} = {n} copies of {grasps} grasp(s) of {contacts} contacts "
            f"would take {size / 2**30:.3g} GiB for their points alone, above "
            f"{MAX_COPY_BYTES / 2**20:g} MiB "
            f"(drakegrasp.planning.checks.MAX_COPY_BYTES); give fewer {name}"
            + (", or fewer grasps a call" if grasps > 1 else "")
        )
    return n


def checked_nonnegative(name: str, value, unit: str) -> float:
    """``value`` as a finite float ``>= 0`` (a clearance, a noise σ), in ``unit``.

    Unbounded above; a noise σ is checked by :func:`checked_noise`, which
    also bounds it by :data:`NOISE_MAX`.
    """
    x = real_scalar(name, value)
    if not 0.0 <= x < np.inf:
        raise InvalidOptionError(
            f"{name} must be a finite number >= 0 ({unit}), got {describe(value)}"
        )
    return x


NOISE_MAX = {"position": 1e6, "angle_deg": 1e6, "friction": 1e6}
"""Largest noise σ of the robustness (:func:`checked_noise`): σ_p (metres),
σ_θ (degrees), σ_μ (relative), each taken in ``[0, NOISE_MAX[key]]``.

Far above any use (the defaults are 2 mm, 3° and 0.1; the bounds are 5e8,
3.3e5 and 1e7 times them), the bounds keep the copies' arithmetic finite:
without them a σ of 1e300 scattered the copies' contacts to 1e300 m or
overflowed (numpy's ``RuntimeWarning``) in the re-closing's chord query.

* ``position``, 1e6 m (a thousand kilometres): a pose error beyond any
  grasped object's size already leaves every copy without its grasp; the
  copies' contacts stay far inside the positions' bound
  (:data:`~drakegrasp.core.validation.POSITION_BOUND`, 1e20 m) and their
  squares far from overflow.
* ``angle_deg``, 1e6 degrees (about 2,800 turns): beyond a few turns the
  drawn rotation angle is already spread evenly over the circle; the angles
  (radians, a few times 1.7e4 at most) keep their sines and cosines accurate.
* ``friction``, 1e6: beyond a few units half the copies' μ are already 0
  (``max(0, 1 + σ_μ ξ)``); ``μ (1 + σ_μ ξ)`` stays below 1e19 for ``μ <= 1e12``
  before it is clipped to the batch engine's range.
"""

_NOISE_UNITS = {"position": "metres", "angle_deg": "degrees", "friction": "relative"}


def checked_noise(sigmas, name: str = "{}") -> dict[str, float]:
    """The noise σ of ``sigmas``, each a number in ``[0, NOISE_MAX[key]]``.

    The one check of the robustness noise, for
    :func:`~drakegrasp.planning.ranking.robustness`,
    :func:`~drakegrasp.planning.ranking.perturbed_copies`,
    :func:`~drakegrasp.planning.reclose.reclosed_robustness` and the planner's
    ``noise=``.

    Parameters
    ----------
    sigmas : mapping of str to float
        Some of the keys of :data:`NOISE_MAX`: ``"position"`` (σ_p, metres),
        ``"angle_deg"`` (σ_θ, degrees), ``"friction"`` (σ_μ, relative).
    name : str, optional
        Spells an argument's name in a message from its key (``"{}"``:
        ``position``; ``"noise[{!r}]"``: ``noise['position']``).

    Returns
    -------
    dict of str to float
        The σ as floats, in the order of ``sigmas``.

    Raises
    ------
    InvalidOptionError
        Naming the σ: not a real number, negative, not finite, or above its
        bound in :data:`NOISE_MAX` (the message gives the range).
    """
    out = {}
    for key, value in sigmas.items():
        label = name.format(key)
        x = checked_nonnegative(label, value, _NOISE_UNITS[key])
        if x > NOISE_MAX[key]:
            raise InvalidOptionError(
                f"{label} = {x:g} {_NOISE_UNITS[key]} is beyond the bound of a "
                f"noise σ: it must be in [0, {NOISE_MAX[key]:g}] "
                f"{_NOISE_UNITS[key]} (drakegrasp.planning.checks.NOISE_MAX; "
                "far above any pose or friction error a grasp meets)"
            )
        out[key] = x
    return out


def checked_rng(rng) -> np.random.Generator:
    """``rng`` if it is a ``numpy.random.Generator``, else InvalidOptionError."""
    if not isinstance(rng, np.random.Generator):
        raise InvalidOptionError(
            "rng must be a numpy.random.Generator (numpy.random.default_rng(seed)), "
            f"got {describe(rng)} ({type(rng).__name__})"
        )
    return rng
