"""Helpers shared by the quality metrics (validation, torque scaling, JSON)."""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.errors import InvalidGraspError, InvalidOptionError
from drakegrasp.grasp import Grasp, grasp_matrix

RANK_TOL = 1e-9
"""Singular values below ``RANK_TOL * σ_max`` count as zero (rank tests here)."""


def _check_grasp(grasp: Grasp) -> Grasp:
    if not isinstance(grasp, Grasp):
        raise InvalidGraspError(
            f"expected a drakegrasp.Grasp, got a {type(grasp).__name__}"
        )
    return grasp


def _torque_scale(grasp: Grasp, torque_scale: float | None) -> float:
    if torque_scale is None:
        return float(grasp.characteristic_length)
    try:
        b = float(torque_scale)
    except (TypeError, ValueError):
        raise InvalidOptionError(
            f"torque_scale must be a length > 0 (metres) or None, got {torque_scale!r}"
        ) from None
    if not math.isfinite(b) or b <= 0.0:
        raise InvalidOptionError(
            f"torque_scale must be finite and > 0 (metres) or None, got "
            f"{torque_scale!r}"
        )
    return b


def _moment_rows(wrench_dim: int) -> slice:
    return slice(3, 6) if wrench_dim == 6 else slice(2, 3)


def _scaled_grasp_matrix(grasp: Grasp, b: float) -> np.ndarray:
    G = grasp_matrix(grasp)
    G[_moment_rows(G.shape[0]), :] /= b
    return G


def _padded_singular_values(A: np.ndarray) -> np.ndarray:
    """All ``rows`` singular values of ``A``, descending, zero-padded."""
    rows = A.shape[0]
    s = np.zeros(rows)
    if A.size:
        sv = np.linalg.svd(A, compute_uv=False)
        s[: sv.size] = sv[:rows]
    return s


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return [_jsonable(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (float, np.floating)):
        x = float(value)
        return x if math.isfinite(x) else None
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value
