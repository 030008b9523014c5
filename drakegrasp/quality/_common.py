"""Helpers shared by the quality metrics (validation, torque scaling, JSON)."""

from __future__ import annotations

import numpy as np

from drakegrasp.core.grasp import Grasp, grasp_matrix
from drakegrasp.core.tolerances import DEFAULT_RANK_TOL
from drakegrasp.core.validation import check_grasp, check_length
from drakegrasp.errors import InvalidOptionError

RANK_TOL = DEFAULT_RANK_TOL
"""Singular values below ``RANK_TOL * σ_max`` count as zero (the default)."""


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
