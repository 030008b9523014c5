"""Per-grasp metrics of a chunk of grasps: the singular values of G, and their scale.

The singular-value metrics of a chunk (``sigma_min``, ``isotropy``,
``ellipsoid_volume``) and the checks that a metric's moments are on the
scale of ``b`` (``MOMENT_ARMS``).  ε L1, the other metric, is the ε stage's:
:mod:`drakegrasp.batch.epsilon.routes`.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import numpy as np

from drakegrasp.batch.inputs import (
    _characteristic_lengths,
    _reference_points,
    check_chunk_positions,
    check_metrics,
    positive_int,
    shape_of,
)
from drakegrasp.core.grasp import scaled_for_metrics
from drakegrasp.core.tolerances import MOMENT_ARMS
from drakegrasp.core.validation import outside_moment_arms, real_array, safe_norm
from drakegrasp.errors import GraspError, InvalidGraspError

__all__ = [
    "asks_for_metrics",
    "check_moment_arms",
    "check_moment_arms_of_batch",
    "metric_moment_arms",
    "moment_arms_in_input_order",
    "singular_value_metrics",
]

SINGULAR_VALUE_METRICS = ("sigma_min", "isotropy", "ellipsoid_volume")


def _out_of_scale(P: np.ndarray, p, b) -> tuple[np.ndarray, np.ndarray]:
    """Grasps whose extent over ``b`` leaves ``MOMENT_ARMS``, and the extents.

    ``P`` (k, N, d) checked contacts (metres); ``p`` None, (d,) or (k, d)
    reference points; ``b`` scalar or (k,) characteristic lengths.  A grasp
    whose contacts all sit within ``LENGTH_MIN`` of its reference point takes
    any ``b``, as :class:`~drakegrasp.Grasp`'s default (1 m) there does.
    """
    k, _, d = P.shape
    p = np.zeros(d) if p is None else np.asarray(p, dtype=float)
    p = np.broadcast_to(p, (k, d))
    b = np.broadcast_to(np.asarray(b, dtype=float), (k,))
    extent = np.max(safe_norm(P - p[:, None, :], axis=-1), axis=-1)
    return outside_moment_arms(extent, b), extent


def _refuse_out_of_scale(index: int, b: float, extent: float) -> None:
    low, high = MOMENT_ARMS
    raise InvalidGraspError(
        f"characteristic length of grasp {index} is {b:g} m, out of scale with "
        f"its contacts, which lie within {extent:g} m of its reference point: "
        f"for the metrics the extent over it must stay within [{low:g}, "
        f"{high:g}], i.e. b in [{extent / high:g}, {extent / low:g}] m; give "
        "characteristic_lengths near the grasps' sizes, or None for their extents"
    )


def check_moment_arms(P, p, b, start: int = 0) -> None:
    """Refuse the first grasp whose extent over its ``b`` leaves ``MOMENT_ARMS``.

    Every metric divides moments by ``b``: beyond
    :data:`~drakegrasp.core.tolerances.MOMENT_ARMS` they are below the LPs'
    resolution or swamp the forces, and ε came out 0 without a word.  The
    single-grasp metrics refuse the same lengths.  The closure verdicts
    take any ``b``.

    Parameters
    ----------
    P : (k, N, d) array-like of float
        Contacts of a chunk of grasps, metres, as given: checked here first
        (the messages of the chunk's own check).
    p : None, (d,) or (k, d) float
        Their reference points (None: the origin), checked.
    b : float or (k,) float
        Their characteristic lengths, metres, checked.
    start : int
        Index of the chunk's first grasp in the batch, for the messages.

    Raises
    ------
    InvalidContactError
        Positions that are not real, finite and within range.
    InvalidGraspError
        Naming the first grasp out of scale, its ``b`` and the range.
    """
    P = real_array("positions", P)
    check_chunk_positions(P, start)
    bad, extent = _out_of_scale(P, p, b)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        b_k = float(np.broadcast_to(np.asarray(b, dtype=float), bad.shape)[k])
        _refuse_out_of_scale(start + k, b_k, float(extent[k]))


def check_moment_arms_of_batch(
    positions, reference_points, characteristic_lengths, *, rows: int = 65_536
) -> None:
    """:func:`check_moment_arms` over a whole stacked batch, ``rows`` at a time.

    For a driver that hands the batch out in parts (a Dask cluster's
    partitions), so that the first grasp out of scale is named by its place
    in the input and before any part is shipped.  A memory-mapped input is
    read ``rows`` grasps at a time.

    Parameters
    ----------
    positions : (K, N, d) array-like of float
        The contacts, metres (not a Dask array: it would be computed here).
    reference_points : None, (d,) or (K, d) float
        As the batch functions take them.
    characteristic_lengths : None, float or (K,) float
        As the batch functions take them; None: nothing to check (the
        default lengths are the extents).
    rows : int, optional
        Grasps read at a time (an integer >= 1).

    Raises
    ------
    InvalidContactError, InvalidGraspError
        As the batch functions raise them, naming the grasp.
    InvalidOptionError
        ``rows`` not an integer >= 1.
    """
    rows = positive_int("rows", rows, 1)
    if characteristic_lengths is None:
        return
    K, _, d = shape_of("positions", positions)
    get_p = _reference_points(reference_points, K, d)
    get_b = _characteristic_lengths(characteristic_lengths, K)
    for start in range(0, K, rows):
        sl = slice(start, min(K, start + rows))
        check_moment_arms(positions[sl], get_p(sl), get_b(sl), start)


def moment_arms_in_input_order(calls, *, always: bool = True) -> None:
    """:func:`check_moment_arms` over a ragged batch's groups, in input order.

    Parameters
    ----------
    calls : list of (RaggedGroup, dict)
        Each group (checked contacts) with the options its call will get, as
        :func:`~drakegrasp.batch.ragged.run_groups` gives its ``check``.
    always : bool, optional
        True (ε): check every group that has ``characteristic_lengths``;
        False (the closure functions): only when the options ask for metrics.

    Raises
    ------
    InvalidGraspError
        Naming the first grasp of the input out of scale.
    """
    worst = None
    for group, options in calls:
        b = options.get("characteristic_lengths")
        if b is None or not (always or asks_for_metrics(options)):
            continue
        bad, extent = _out_of_scale(group.positions, options.get("reference_points"), b)
        b = np.broadcast_to(np.asarray(b, dtype=float), bad.shape)
        for k in np.flatnonzero(bad):
            index = int(group.indices[k])
            if worst is None or index < worst[0]:
                worst = (index, float(b[k]), float(extent[k]))
    if worst is not None:
        _refuse_out_of_scale(*worst)


def asks_for_metrics(options: dict) -> bool:
    """Whether a batch call's keyword options ask for metrics.

    Parameters
    ----------
    options : dict
        The call's keywords, before they are checked: ``metrics`` and
        ``options`` (a :class:`~drakegrasp.BatchOptions`).

    Returns
    -------
    bool
        True when either names a metric as
        :func:`~drakegrasp.batch.inputs.check_metrics` reads it (``{}``,
        ``set()`` and ``()`` name none), and when it is not a valid list of
        names (refused later, by that check).
    """
    given = options.get("options")
    for names in (options.get("metrics"), getattr(given, "metrics", None)):
        if names is None or isinstance(names, Iterator):  # not used up here
            continue
        try:
            if check_metrics(names):
                return True
        except GraspError:  # refused, with its own message, by the call
            return True
    return False


def metric_moment_arms(calls) -> None:
    """The ragged ``check`` of the closure functions: metrics need ``MOMENT_ARMS``.

    :func:`moment_arms_in_input_order` with ``always=False``.
    """
    moment_arms_in_input_order(calls, always=False)


def singular_value_metrics(
    G: np.ndarray,
    b: np.ndarray,
    names: Sequence[str],
    torsion_columns: Sequence[int] = (),
) -> dict[str, np.ndarray]:
    """σ_min, σ_min/σ_max and ∏σ of ``Ĝ = T G S``, as the single-grasp indices.

    ``T`` divides the moment rows by ``b``; ``S`` keeps each soft finger's
    torsion column ``[0; n]`` (its ``m_n`` measured in ``b`` newtons), so the
    metrics do not depend on the unit of length
    (:func:`~drakegrasp.core.grasp.scaled_for_metrics`, which
    :func:`~drakegrasp.grasp_singular_values` reads too).

    Parameters
    ----------
    G : (k, w, M) float
        Grasp matrices about the grasps' reference points.
    b : (k,) float
        Characteristic lengths, metres.
    names : sequence of str
        The metrics wanted (others are ignored).
    torsion_columns : sequence of int, optional
        The columns of ``G`` that are soft fingers' torsional moments (none
        by default).

    Returns
    -------
    dict of str to (k,) float
    """
    wanted = [n for n in names if n in SINGULAR_VALUE_METRICS]
    if not wanted:
        return {}
    w = G.shape[1]
    Gs = scaled_for_metrics(G, b, np.asarray(torsion_columns, dtype=int))
    sv = np.linalg.svd(Gs, compute_uv=False)
    if sv.shape[1] < w:  # fewer columns than wrench rows: the rest are zero
        sv = np.concatenate([sv, np.zeros((sv.shape[0], w - sv.shape[1]))], axis=1)
    out = {}
    if "sigma_min" in wanted:
        out["sigma_min"] = sv[:, -1]
    if "isotropy" in wanted:
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = sv[:, -1] / sv[:, 0]
        out["isotropy"] = np.where(sv[:, 0] > 0.0, ratio, 0.0)
    if "ellipsoid_volume" in wanted:
        out["ellipsoid_volume"] = np.prod(sv, axis=1)
    return out
