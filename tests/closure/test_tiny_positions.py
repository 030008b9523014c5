"""Verdicts do not depend on the unit of length, down to the smallest doubles.

Issue 21: single-grasp ``force_closure`` with positions below about 1e-162 m
flipped 24 of 40 verdicts (the spread of the normalised ``G`` was a sum of
underflowing squares, read as 0, and every moment row was dropped), while the
batch engine kept them.  The independent route is the same grasp at 1 m scale
(the conventions' unit invariance) and the batch engine.
"""

from __future__ import annotations

import numpy as np
import pytest

import drakegrasp as dg

SCALES = [1e-150, 1e-163, 1e-200, 1e-250, 1e-300, 1e-307]


def _random_grasps(count=40, seed=21):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        n = int(rng.integers(2, 6))
        p = rng.normal(size=(n, 3))
        p /= np.linalg.norm(p, axis=1, keepdims=True)
        normals = -p + 0.5 * rng.normal(size=(n, 3))
        out.append((p, normals, float(rng.uniform(0.1, 0.9))))
    return out


def _grasp(p, normals, mu, scale):
    return dg.Grasp(
        [dg.Contact(x * scale, n, mu=mu) for x, n in zip(p, normals, strict=True)]
    )


@pytest.mark.parametrize("scale", SCALES)
def test_tiny_grasps_keep_their_verdicts(scale):
    for p, normals, mu in _random_grasps():
        ref = dg.force_closure(_grasp(p, normals, mu, 1.0))
        got = dg.force_closure(_grasp(p, normals, mu, scale))
        assert got.rank == ref.rank
        assert got.is_closure == ref.is_closure
        assert got.d_star == pytest.approx(ref.d_star, abs=1e-8)
        form = dg.form_closure(_grasp(p, normals, mu, scale))
        assert form.rank == dg.form_closure(_grasp(p, normals, mu, 1.0)).rank


def test_tiny_grasps_agree_with_the_batch_engine():
    cases = [c for c in _random_grasps() if len(c[0]) == 3]
    P = np.array([c[0] for c in cases]) * 1e-200
    Nrm = np.array([c[1] for c in cases])
    mu = np.array([[c[2]] for c in cases])
    batch = dg.batch_force_closure(P, Nrm, mu=mu)
    single = [dg.force_closure(_grasp(p * 1e-200, n, m, 1.0)) for p, n, m in cases]
    np.testing.assert_array_equal(batch.is_closure, [r.is_closure for r in single])
