"""Helpers shared by the quality metrics (validation, torque scaling, JSON)."""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.errors import InvalidOptionError
from drakegrasp.grasp import Grasp, grasp_matrix
from drakegrasp.validation import check_grasp, check_length

RANK_TOL = 1e-9
"""Singular values below ``RANK_TOL * σ_max`` count as zero (rank tests here)."""


def _check_grasp(grasp: Grasp) -> Grasp:
    return check_grasp(grasp)


def _torque_scale(grasp: Grasp, torque_scale: float | None) -> float:
    if torque_scale is None:
        return float(grasp.characteristic_length)
    return check_length("torque_scale", torque_scale, error=InvalidOptionError)


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
