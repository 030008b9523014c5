r"""Grasps with different numbers of contacts in one batch call (ragged input).

The compiled kernels take ``K`` grasps of ``N`` contacts each, stacked.  Real
batches are ragged: a parallel-jaw finger seats one to four tip spheres, a
multi-finger hand touches with two to five fingers, a dataset mixes them.  The
batch functions therefore also accept ``positions`` and ``normals`` as
sequences of ``K`` per-grasp arrays of shape ``(N_k, d)``; this module groups
the grasps by ``N_k``, stacks each group, and says where each group's grasps
sit in the input, so that the results come back in input order.

Per-contact options (``mu``, ``torsional_friction``) are then a scalar, one
value per grasp (shape ``(K,)``), or a sequence of ``K`` per-grasp arrays of
shape ``(N_k,)``; per-grasp options (``reference_points``,
``characteristic_lengths``) keep their stacked shapes ``(d,)``/``(K, d)`` and
scalar/``(K,)``.

A grasp's verdict, ``d*`` and metrics do not depend on the grasps beside it in
a chunk (each grasp's LP is solved on its own), so a ragged call gives, grasp
by grasp, bitwise what the stacked call of its group gives
(``tests/batch/test_ragged.py``).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from drakegrasp.batch.inputs import (
    _characteristic_lengths,
    _reference_points,
    check_chunk_coefficients,
    check_chunk_positions,
    check_metrics,
    chunk_unit_normals,
)
from drakegrasp.core.validation import items_of, real_array, refuse_structured
from drakegrasp.errors import InvalidContactError

__all__ = [
    "PER_CONTACT",
    "PER_GRASP",
    "RaggedGroup",
    "accepts_ragged",
    "is_ragged",
    "ragged_groups",
    "run_groups",
]


@dataclass(frozen=True)
class RaggedGroup:
    """The grasps of a ragged batch that have ``N`` contacts each.

    Attributes
    ----------
    indices : (k,) int
        Their positions in the input sequence, increasing.
    positions, normals : (k, N, d) float
        Their contacts, stacked (metres; normals as given).
    """

    indices: np.ndarray
    positions: np.ndarray
    normals: np.ndarray

    @property
    def num_contacts(self) -> int:
        """``N``, the contacts of each grasp of the group."""
        return int(self.positions.shape[1])


def _shape(value) -> tuple[int, ...] | None:
    """``np.shape`` of a homogeneous array-like; None for a ragged one."""
    try:
        return np.shape(value)
    except Exception:  # noqa: BLE001 - ragged, or a hostile __len__ or __iter__
        return None


def is_ragged(positions) -> bool:
    """True for a list or tuple of per-grasp arrays whose lengths differ.

    A sequence of equally long grasps is stacked as before (it is a ``(K, N,
    d)`` array-like); an ``ndarray`` is never ragged.
    """
    if not isinstance(positions, (list, tuple)):
        return False
    try:
        if not positions:
            return False
    except Exception:  # noqa: BLE001 - a list whose __len__ raises: real_array names it
        return False
    return _shape(positions) is None


def _grasp_array(name: str, value, k: int) -> np.ndarray:
    refuse_structured(f"{name}[{k}]", value)
    shape = _shape(value)
    if shape is None or len(shape) != 2 or shape[1] not in (2, 3) or shape[0] < 1:
        raise InvalidContactError(
            f"{name}[{k}] must have shape (N, 2) or (N, 3) with N >= 1 (one row "
            f"per contact of grasp {k}), got "
            f"{'a ragged sequence' if shape is None else shape}"
        )
    return real_array(f"{name}[{k}]", value)


def ragged_groups(positions, normals) -> tuple[int, int, list[RaggedGroup]]:
    """Group a ragged batch by contact count.

    Parameters
    ----------
    positions, normals : sequence of (N_k, d) float
        One array per grasp; ``normals[k]`` has the shape of ``positions[k]``
        and every grasp the same ``d`` (2 or 3).

    Returns
    -------
    K : int
        Number of grasps.
    d : int
        2 (planar) or 3 (spatial).
    groups : list of RaggedGroup
        By increasing ``N``.

    Raises
    ------
    InvalidContactError
        Naming the grasp whose positions or normals are ill-shaped, or whose
        dimension differs from the first grasp's.
    """
    must = "a list of per-grasp (N_k, d) arrays"
    positions = items_of("positions", positions, must, error=InvalidContactError)
    if isinstance(normals, (list, tuple)):
        normals = items_of("normals", normals, must, error=InvalidContactError)
    if not isinstance(normals, (list, tuple)) or len(normals) != len(positions):
        raise InvalidContactError(
            f"with ragged positions ({len(positions)} per-grasp arrays), normals "
            "must be a list of as many per-grasp arrays, got "
            + (
                f"{len(normals)}"
                if isinstance(normals, (list, tuple))
                else type(normals).__name__
            )
        )
    K = len(positions)
    by_count: dict[int, list[int]] = {}
    P, Nrm = [], []
    d = None
    for k in range(K):
        p = _grasp_array("positions", positions[k], k)
        n = _grasp_array("normals", normals[k], k)
        if n.shape != p.shape:
            raise InvalidContactError(
                f"normals[{k}] must have the shape of positions[{k}] {p.shape}, "
                f"got {n.shape}"
            )
        if d is None:
            d = p.shape[1]
        elif p.shape[1] != d:
            raise InvalidContactError(
                f"positions[{k}] has {p.shape[1]} columns and positions[0] {d}: "
                "a batch is all planar or all spatial"
            )
        check_chunk_positions(p[None], k)
        chunk_unit_normals(n[None], k)
        P.append(p)
        Nrm.append(n)
        by_count.setdefault(p.shape[0], []).append(k)
    groups = [
        RaggedGroup(
            np.array(idx, dtype=int),
            np.stack([P[k] for k in idx]),
            np.stack([Nrm[k] for k in idx]),
        )
        for _, idx in sorted(by_count.items())
    ]
    return K, int(d), groups


def _per_contact(name: str, value, K: int, counts: list[int]):
    """A per-contact coefficient as one checked row per grasp, or a shared scalar.

    Returns None or the scalar itself (checked by the stacked call), else a
    list of ``K`` float rows of shapes ``(N_k,)``.
    """
    if value is None:
        return None
    shape = _shape(value)
    if shape == ():
        return value
    if shape == (K,):  # one value per grasp
        values = real_array(name, value)
        rows = [np.full(n, values[k]) for k, n in enumerate(counts)]
    elif isinstance(value, (list, tuple)) and len(value) == K:
        rows = []
        for k, n in enumerate(counts):
            row = _shape(value[k])
            if row not in ((), (n,)):
                raise InvalidContactError(
                    f"{name}[{k}] must be a scalar or have shape ({n},), one "
                    f"value per contact of grasp {k}; got "
                    f"{'a ragged sequence' if row is None else row}"
                )
            rows.append(np.broadcast_to(real_array(f"{name}[{k}]", value[k]), (n,)))
    else:
        raise InvalidContactError(
            f"with ragged positions, {name} must be a scalar, one value per grasp "
            f"(shape ({K},)) or a list of {K} per-grasp arrays of shape (N_k,); "
            f"got {'a ragged sequence' if shape is None else shape}"
        )
    for k, row in enumerate(rows):
        check_chunk_coefficients(name, np.asarray(row, dtype=float)[None], k)
    return rows


def _per_grasp(name: str, value, K: int, d: int):
    """A per-grasp option checked in input order; returns it for slicing."""
    if name == "reference_points":
        _reference_points(value, K, d)(slice(0, K))
        row_shape: tuple = (d,)
    else:
        get = _characteristic_lengths(value, K)
        if get is not None:
            get(slice(0, K))
        row_shape = ()
    if value is None or np.shape(value) == row_shape:
        return value, False
    return np.asarray(value), True


PER_CONTACT = ("mu", "torsional_friction")
"""Options with one value per contact: sliced and stacked per group."""

PER_GRASP = ("reference_points", "characteristic_lengths")
"""Options with one value (or row) per grasp: sliced per group."""


def accepts_ragged(
    merge: Callable[[int, int, list], Any],
    check: Callable[[list[tuple[RaggedGroup, dict]]], None] | None = None,
):
    """Let a stacked batch function take ragged lists of per-grasp arrays too.

    ``fn(positions, normals, **options)`` runs unchanged on stacked input; on
    a ragged one (:func:`is_ragged`) it runs once per contact-count group
    (:func:`run_groups`) and ``merge(K, d, parts)`` makes the one result.
    ``check``, when given, sees every group with its options before any runs,
    so that it can name a bad grasp by its place in the input.
    """

    def decorate(fn):
        @functools.wraps(fn)
        def batch(*args, **options):
            # positions and normals by position or by name; a call that does
            # not fit goes to ``fn`` as it is, whose check (checked_call)
            # names what is wrong, as for any other call
            if len(args) > 2:
                return fn(*args, **options)
            given = dict(zip(("positions", "normals")[: len(args)], args, strict=True))
            named = {k: options[k] for k in ("positions", "normals") if k in options}
            if given.keys() & named.keys():
                return fn(*args, **options)
            arrays = given | named
            if len(arrays) < 2 or not is_ragged(arrays["positions"]):
                return fn(*args, **options)
            rest = {k: v for k, v in options.items() if k not in named}
            return merge(
                *run_groups(fn, arrays["positions"], arrays["normals"], check, **rest)
            )

        return batch

    return decorate


def run_groups(
    call: Callable[..., Any],
    positions,
    normals,
    check: Callable[[list[tuple[RaggedGroup, dict]]], None] | None = None,
    /,
    **options,
) -> tuple[int, int, list[tuple[np.ndarray, Any]]]:
    """Run a stacked batch function once per contact-count group.

    Parameters
    ----------
    call : callable
        ``call(positions, normals, **options)`` on a stacked group.
    positions, normals : sequence of (N_k, d) float
        The ragged batch.
    check : callable, optional
        ``check([(group, options), ...])``: called once with every group and
        the options its call will get, before any call (positional only, so
        that no keyword of ``call`` is taken for it).
    **options
        Passed to every call; those of :data:`PER_CONTACT` and
        :data:`PER_GRASP` restricted to the group's grasps.

    Returns
    -------
    K, d : int
        Number of grasps and dimension.
    parts : list of (indices, result)
        Each group's input positions and ``call``'s result, by increasing
        ``N``.
    """
    K, d, groups = ragged_groups(positions, normals)
    # Every group's call reads the options: a one-shot iterator of metrics would
    # be used up by the first and leave the others without (other options are
    # arrays, and their checks refuse iterators).
    if isinstance(options.get("metrics"), Iterator):
        options = {**options, "metrics": check_metrics(options["metrics"])}
    counts = [0] * K
    for group in groups:
        for k in group.indices:
            counts[k] = group.num_contacts
    contact_rows = {
        name: _per_contact(name, options.pop(name), K, counts)
        for name in PER_CONTACT
        if name in options
    }
    grasp_values = {
        name: _per_grasp(name, options.pop(name), K, d)
        for name in PER_GRASP
        if name in options
    }
    calls = []
    for group in groups:
        kwargs = dict(options)
        for name, rows in contact_rows.items():
            kwargs[name] = (
                rows
                if rows is None or not isinstance(rows, list)
                else np.stack([rows[k] for k in group.indices]).astype(float)
            )
        for name, (value, per_row) in grasp_values.items():
            kwargs[name] = value[group.indices] if per_row else value
        calls.append((group, kwargs))
    if check is not None:
        check(calls)
    parts = [
        (group.indices, call(group.positions, group.normals, **kwargs))
        for group, kwargs in calls
    ]
    return K, d, parts
