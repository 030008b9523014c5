"""Grasps of many contacts: memory that grows linearly in N, within the chunk budget.

One grasp of ``N`` contacts needs ``O(N)`` numbers on every route to ``d*``;
a grasp too large for any chunk is refused before anything is allocated.
"""

from __future__ import annotations

import numpy as np
import pytest

from drakegrasp.batch import batch_force_closure
from drakegrasp.batch.lp import block_kernel


def _ellipsoid(N, K=1, seed=3):
    """``K`` grasps of ``N`` contacts on a triaxial ellipsoid, normals inward.

    Frictionless contacts all over it hold it in form closure.
    """
    axes = np.array([1.0, 0.7, 0.5])
    rng = np.random.default_rng(seed)
    u = rng.normal(size=(K, N, 3))
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    return u * axes, -u / axes


needs_numba = pytest.mark.skipif(
    not block_kernel.AVAILABLE, reason="numba (extra 'fast') is not installed"
)


@needs_numba
def test_one_grasp_of_twenty_thousand_contacts_is_solved():
    # The fused pass allocated the active set's null-space arrays for every
    # null space: 8 (27 + 3 n_g) N² bytes, 163 GB here (a MemoryError),
    # where only null spaces of at most 7 dimensions use them.
    P, Nrm = _ellipsoid(20_000)
    res = batch_force_closure(P, Nrm, mu=0.5, kernel="numba")
    assert res.is_closure.all() and res.converged.all()
