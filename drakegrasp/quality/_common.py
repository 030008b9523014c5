"""Helpers shared by the quality metrics (validation, torque scaling, JSON)."""

from __future__ import annotations

import numpy as np

from drakegrasp.core.contact import ContactModel
from drakegrasp.core.grasp import Grasp, grasp_matrix, scaled_for_metrics
from drakegrasp.core.tolerances import DEFAULT_RANK_TOL, MOMENT_ARMS
from drakegrasp.core.validation import (
    check_grasp,
    check_length,
    outside_moment_arms,
    safe_norm,
)
from drakegrasp.errors import InvalidOptionError

RANK_TOL = DEFAULT_RANK_TOL
"""Singular values below ``RANK_TOL * σ_max`` count as zero (the default)."""


def _check_grasp(grasp: Grasp) -> Grasp:
    return check_grasp(grasp)


def grasp_extent(grasp: Grasp) -> float:
    """The largest distance from the grasp's reference point to a contact, m.

    Computed without overflow (:func:`~drakegrasp.core.validation.safe_norm`);
    0 when every contact is at the reference point.
    """
    offsets = grasp.positions - grasp.reference_point
    return float(np.max(safe_norm(offsets, axis=-1)))


def _torque_scale(grasp: Grasp, torque_scale: float | None) -> float:
    """``b_s``: the grasp's characteristic length, or a checked ``torque_scale``.

    Either length is a length (``[2.2e-308, 1e30]`` m) with the grasp's extent
    over it in :data:`~drakegrasp.core.tolerances.MOMENT_ARMS` (any length when
    every contact is within ``LENGTH_MIN`` of the reference point, where the
    Grasp's own default is 1 m).  The closure verdicts take any
    characteristic length; the metrics, which divide moments by it, do not.

    Raises
    ------
    InvalidOptionError
        When the length is out of scale with the grasp; the message names
        ``torque_scale`` or ``characteristic_length``, whichever was used.
    """
    if torque_scale is None:
        b, name = float(grasp.characteristic_length), "characteristic_length"
        remedy = (
            "build the Grasp with a characteristic_length near its size (or None "
            "for its extent), or give a torque_scale"
        )
    else:
        b = check_length("torque_scale", torque_scale, error=InvalidOptionError)
        name = "torque_scale"
        remedy = (
            "give a torque_scale near the grasp's size, or None for its "
            "characteristic length"
        )
    extent = grasp_extent(grasp)
    if outside_moment_arms(extent, b):
        low, high = MOMENT_ARMS
        raise InvalidOptionError(
            f"{name} = {b:g} m is out of scale with the grasp, whose contacts "
            f"lie within {extent:g} m of its reference point: the extent over "
            f"{name} must stay within [{low:g}, {high:g}], i.e. {name} "
            f"in [{extent / high:g}, {extent / low:g}] m here (beyond, the scaled "
            f"moments are below the metrics' resolution or swamp the forces); "
            f"{remedy}"
        )
    return b


def _moment_rows(wrench_dim: int) -> slice:
    return slice(3, 6) if wrench_dim == 6 else slice(2, 3)


def _scaled_grasp_matrix(grasp: Grasp, b: float) -> np.ndarray:
    """``T G``: moment rows over ``b``, for wrenches of generators (ε).

    A generator's torsion component is already ``b ν`` N·m per newton of
    ``f_n``, so ε's wrenches are dimensionless without ``S`` (contrast
    :func:`_metric_grasp_matrix`).
    """
    G = grasp_matrix(grasp)
    G[_moment_rows(G.shape[0]), :] /= b
    return G


def _torsion_columns(grasp: Grasp) -> np.ndarray:
    """The columns of ``G`` that are a soft finger's torsional moment ``m_n``."""
    return np.array(
        [
            sl.start + 3
            for c, sl in zip(grasp.contacts, grasp.component_slices(), strict=True)
            if c.contact_model is ContactModel.SOFT_FINGER
        ],
        dtype=int,
    )


def _metric_grasp_matrix(grasp: Grasp, b: float) -> np.ndarray:
    """``T G S`` of :func:`~drakegrasp.core.grasp.scaled_for_metrics`.

    The singular-value indices' matrix: moment rows over ``b``, each soft
    finger's torsion column kept ``[0; n]`` (``m_n`` measured in ``b`` N).
    """
    return scaled_for_metrics(grasp_matrix(grasp), b, _torsion_columns(grasp))


def _padded_singular_values(A: np.ndarray) -> np.ndarray:
    """All ``rows`` singular values of ``A``, descending, zero-padded."""
    rows = A.shape[0]
    s = np.zeros(rows)
    if A.size:
        sv = np.linalg.svd(A, compute_uv=False)
        s[: sv.size] = sv[:rows]
    return s
