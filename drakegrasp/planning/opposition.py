r"""Where a hand's squeeze pushes the object: whether its closing motions oppose.

The ranking judges a candidate's planned contacts held still
(:mod:`~drakegrasp.planning.ranking`, :mod:`~drakegrasp.planning.motors`).  It
does not see which way the hand's squeeze pushes: a parallel jaw's fingers
close towards each other, but three fingers of a hand that curl the same way
(the Allegro hand's index, middle and ring on a box, without the thumb) all
push the object one way, and the squeeze carries it out of the hand before
any load is applied, force closure or not.  This module measures that.

Each contact ``i`` pushes along a direction ``d_i`` (frame O): the velocity of
the finger's contact point when every closing joint closes at unit rate, the
way the plan closed it (``d_i = J_i s``, ``J_i`` the contact's rows of the
hand Jacobian, ``s`` the candidate's ``closing_signs``); a contact that
closing does not move (the palm, a finger none of whose joints closed) pushes
back along its inward normal ``n_i``, as a support does.  The **squeeze
push**

.. math::

    r = \max\Big(0,\; \max_{\lVert u\rVert = 1}\ \min_i\ \hat d_i^T u\Big)
      = \operatorname{dist}\big(0,\ \operatorname{conv}\{\hat d_i\}\big)

is 0 when the unit directions oppose one another (the origin lies in their
convex hull: two jaws, a thumb against fingers, fingers against the palm) and
approaches 1 as they all lean one way ``u`` (every direction within
``arccos r`` of it).

Measured in Drake (``shake_test`` at its default squeeze and gains, the
object's speed at the end of the gravity-free seating telling a push-out;
``benchmarks/bench_squeeze_push.py``, 150 samples, ``mu=1``): of the
Allegro hand's force-closure candidates among the first 10 or 20 of the YCB
sugar box (also planned as if 0.25 kg), cracker box and soup can (seeds
0-2), the 24 above :data:`SQUEEZE_PUSH_MAX` (0.81-0.92, every one without the
thumb) were pushed out while seating 23 times and held once; the 69 below it
(0-0.66, every one with the thumb) held 35 times (16 pushed out).  The
three-finger hand on the shipped cylinder, box and sphere (0.04-0.29), a
Barrett-like spread hand (0.23-0.35) and a one-motor pinch whose pads swing
on arcs (0.35-0.46: a revolute pinch pushes both pads a little towards its
palm) held 55 of their first 56 candidates, none above the bound.

The figure is kinematic: it reads directions, not forces, and does not ask
whether the fingers can follow the object (a pinch's one-joint fingers
cannot, and holds at 0.46).  It is a warning sign for the squeeze, not a
verdict; confirm a choice with :func:`~drakegrasp.planning.shake.shake_test`.
"""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.core.validation import (
    describe,
    integer_or_none,
    real_array,
    real_scalar,
    safe_norm,
)
from drakegrasp.errors import InvalidOptionError
from drakegrasp.quality.epsilon import hull_point_nearest_origin

__all__ = [
    "FRAME_TOL",
    "PASSIVE_SPEED",
    "SQUEEZE_PUSH_MAX",
    "closing_directions",
    "push_text",
    "squeeze_push_of",
]

SQUEEZE_PUSH_MAX = 0.7
"""Above this squeeze push, the ranking puts a candidate after the other
force-closure candidates (:func:`~drakegrasp.planning.motors.with_squeeze_push`):
every contact's closing motion lies within about 45° of one direction (cos 45°
= 0.707).  The measurements of the module docstring put the Allegro hand's
grasps without the thumb at 0.81-0.92, and every grasp with the thumb, and
every grasp of the other hands measured, at 0.66 or below."""

PASSIVE_SPEED = 1e-9
"""A contact point moving slower than this (m per rad, or m per m, of the
closing joints) when the hand closes is passive: it pushes back along its
inward normal (the palm; a finger that closing left still)."""

FRAME_TOL = 1e-6
"""How far (largest entry of ``RᵀR - I``) a contact frame given to
:func:`closing_directions` may be from orthonormal."""


def closing_directions(
    J: np.ndarray, frames: np.ndarray, components, signs
) -> np.ndarray:
    """Each contact's unit push direction, frame O (module docstring).

    Parameters
    ----------
    J : (M, n_j) float
        The hand Jacobian over the closing joints, rows in the contacts'
        frames and components as a grasp stacks them (``[n, t1, t2]`` for a
        hard finger, a soft finger's torsion row after them, ``[n]`` for a
        frictionless contact); m/s per unit joint velocity.
    frames : (N, 3, 3) float
        Each contact's frame ``[n, t1, t2]`` (columns, frame O; ``n`` into the
        object): orthonormal, within :data:`FRAME_TOL`.
    components : sequence of int
        Each contact's number of rows in ``J`` (1, 3 or 4), summing to ``M``.
    signs : (n_j,) float
        The sign with which each joint closed (``closing_signs``; 0: closing
        left it still); finite.

    Returns
    -------
    (N, 3) float
        Unit vectors: the direction in which closing moves each contact's
        finger point (for a frictionless contact, the normal, signed by the
        normal motion), or the contact's inward normal where it moves slower
        than :data:`PASSIVE_SPEED`.

    Raises
    ------
    InvalidOptionError
        Shapes that do not match, values that are not finite, frames that are
        not orthonormal, component counts that are not integers, or a motion
        too large for a float.
    """
    J = real_array("J", J, error=InvalidOptionError)
    frames = real_array("frames", frames, error=InvalidOptionError)
    signs = real_array("signs", signs, error=InvalidOptionError)
    components = _counts(components)
    if (
        J.ndim != 2
        or frames.ndim != 3
        or frames.shape[1:] != (3, 3)
        or len(components) != len(frames)
        or any(k not in (1, 3, 4) for k in components)
        or sum(components) != J.shape[0]
        or signs.shape != (J.shape[1],)
    ):
        raise InvalidOptionError(
            f"closing_directions needs J (M, n_j), frames (N, 3, 3), N "
            f"component counts of 1, 3 or 4 summing to M and n_j signs; got J "
            f"{J.shape}, frames {frames.shape}, {len(components)} counts "
            f"summing to {sum(components)}, signs {signs.shape}"
        )
    if not (
        np.all(np.isfinite(J))
        and np.all(np.isfinite(frames))
        and np.all(np.isfinite(signs))
    ):
        raise InvalidOptionError("closing_directions needs finite J, frames and signs")
    # a NaN sign left every contact "passive"; a zero frame gave a zero "unit"
    # direction, read as opposing every other one
    off = np.abs(frames.transpose(0, 2, 1) @ frames - np.eye(3)).max(axis=(1, 2))
    if np.any(off > FRAME_TOL):
        i = int(np.argmax(off))
        raise InvalidOptionError(
            f"closing_directions needs orthonormal contact frames; frames[{i}] "
            f"is {off[i]:.3g} from it (|RᵀR - I|)"
        )
    out = np.empty((len(frames), 3))
    rows = np.cumsum([0, *components])
    for i, (R, k) in enumerate(zip(frames, components, strict=True)):
        m = min(k, 3)  # a soft finger's torsion row is no translation
        with np.errstate(over="ignore", invalid="ignore"):
            v = R[:, :m] @ (J[rows[i] : rows[i] + m] @ signs)
        if not np.all(np.isfinite(v)):
            raise InvalidOptionError(
                f"closing_directions: contact {i}'s closing motion overflows a "
                "float (J and signs too large)"
            )
        speed = float(safe_norm(v))
        out[i] = v / speed if speed > PASSIVE_SPEED else R[:, 0]
    return out


def _counts(components) -> list[int]:
    """``components`` as a list of ints, or InvalidOptionError naming them."""
    try:
        values = list(components)
    except Exception:  # noqa: BLE001 - not iterable, or a hostile __iter__
        raise InvalidOptionError(
            f"components must be a sequence of integers (1, 3 or 4), got "
            f"{describe(components)}"
        ) from None
    counts = [integer_or_none(k, integral_floats=True) for k in values]
    if any(k is None for k in counts):
        bad = next(v for v, k in zip(values, counts, strict=True) if k is None)
        raise InvalidOptionError(
            f"components must be integers (1, 3 or 4), got {describe(bad)}"
        )
    return counts


def squeeze_push_of(directions) -> float:
    """The squeeze push ``r`` of push directions (module docstring).

    The hull's point nearest the origin comes from Lawson-Hanson NNLS; ``r``
    is then ``min_i d_i·y/‖y‖`` for that point ``y``, a value that some unit
    ``u`` attains, so an inexact NNLS answer can only under-state the push
    (it is exact at the optimum, where the two meet).

    Parameters
    ----------
    directions : (N, 3) float
        Push directions, ``N >= 1`` (:func:`closing_directions`); each row is
        read as its unit vector, so their lengths do not matter, but a zero
        row has no direction and is refused.

    Returns
    -------
    float
        In ``[0, 1]``: 0 when the directions oppose one another (the origin
        in their convex hull), 1 when they are all one.

    Raises
    ------
    InvalidOptionError
        Not an ``(N, 3)`` array of finite numbers with ``N >= 1``, or a row
        of zeros.
    """
    D = real_array("directions", directions, error=InvalidOptionError)
    if D.ndim != 2 or D.shape[1] != 3 or len(D) == 0:
        raise InvalidOptionError(
            f"directions must be (N, 3) finite vectors, N >= 1; got shape {D.shape}"
        )
    if not np.all(np.isfinite(D)):
        raise InvalidOptionError("directions must be finite; got NaN or inf")
    # a row of length 10 was read as reaching 10 times as far (push 1 for two
    # orthogonal rows, whose push is 0.71), a zero row as opposing every other
    big = np.max(np.abs(D), axis=1)
    if not np.all(big > 0.0):
        i = int(np.argmin(big))
        raise InvalidOptionError(
            f"directions[{i}] is zero: a push direction needs a length"
        )
    D = D / big[:, None]
    D = D / np.linalg.norm(D, axis=1)[:, None]
    y = hull_point_nearest_origin(D)  # a point of the hull
    if y is None:  # the iteration limit: no point, no push claimed
        return 0.0
    norm = float(np.linalg.norm(y))
    if not norm > 1e-12:
        return 0.0
    return float(min(1.0, max(0.0, np.min(D @ y) / norm)))


def push_text(push) -> str:
    """``push`` in words, for a candidate's concerns: "" at or below the bound.

    Parameters
    ----------
    push : float
        A squeeze push, in ``[0, 1]``; NaN (not computed) says nothing.

    Returns
    -------
    str
        A sentence when ``push`` exceeds :data:`SQUEEZE_PUSH_MAX`, else "".

    Raises
    ------
    InvalidOptionError
        ``push`` is not a real number, or outside ``[0, 1]``.
    """
    push = real_scalar("squeeze_push", push)
    if math.isnan(push):
        return ""
    if not 0.0 <= push <= 1.0:
        raise InvalidOptionError(f"squeeze_push must be in [0, 1] or NaN, got {push!r}")
    if push <= SQUEEZE_PUSH_MAX:
        return ""
    return (
        f"its closing motions all push the object one way (squeeze_push "
        f"{push:.2f} > {SQUEEZE_PUSH_MAX:g}): the squeeze may push it out of "
        "the hand"
    )
