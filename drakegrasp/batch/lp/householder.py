"""Householder QR on small matrices stored transposed, for the compiled kernels.

A matrix ``X`` (rows × cols) is held as ``XT[c, i] = X[i, c]``, so that each
column is one contiguous row of ``XT``.  ``_qr`` leaves reflector ``j``
(``H_j = I - β_j v_j v_jᵀ``, ``v_j`` supported on entries ``j … rows - 1``) in
``V[j]`` and ``beta[j]``, and ``R`` in ``XT`` (``R[i, c] = XT[c, i]``,
``i <= c``), so ``X = H_0 … H_{cols-1} [R; 0]``.
"""

from __future__ import annotations

import math

from drakegrasp.batch.compiled import FASTMATH, njit

__all__: list[str] = []  # helpers of the compiled kernels only


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _qr(XT, rows, cols, V, beta):
    """Householder QR of ``X`` (rows × cols, rows >= cols) stored transposed.

    Returns ``‖X‖_F`` (before the QR).
    """
    fro = 0.0
    for c in range(cols):
        for i in range(rows):
            fro += XT[c, i] * XT[c, i]
    for j in range(cols):
        norm = 0.0
        for i in range(j, rows):
            norm += XT[j, i] * XT[j, i]
            V[j, i] = XT[j, i]
        norm = math.sqrt(norm)
        V[j, j] -= -norm if XT[j, j] >= 0.0 else norm
        vv = 0.0
        for i in range(j, rows):
            vv += V[j, i] * V[j, i]
        b = 2.0 / vv if vv > 0.0 else 0.0
        beta[j] = b
        for c in range(j, cols):
            _reflect(V, j, b, XT, c, rows)
    return math.sqrt(fro)


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _reflect(V, j, b, Y, r, n):
    """Apply reflector ``j`` (``I - b v vᵀ``, ``v = V[j, j:n]``) to ``Y[r, j:n]``."""
    acc = 0.0
    for i in range(j, n):
        acc += V[j, i] * Y[r, i]
    acc *= b
    for i in range(j, n):
        Y[r, i] -= acc * V[j, i]
