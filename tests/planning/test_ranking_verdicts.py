"""Robustness counts verdicts only: the same values as with the full LP2 solve.

Both robustness routes (contacts moved per finger, :func:`robustness`; the
jaws re-closed on the moved object, :func:`reclosed_robustness`) take their
copies' verdicts from :func:`drakegrasp.batch.run.chunk.force_verdicts`, which
stops each LP once its verdict is proved.  With the same seed, the values must
equal those computed from ``batch_force_closure``'s full verdicts.
"""

from __future__ import annotations

import numpy as np
import pytest
from grasp_builders import two_pads
from pydrake.geometry import Box, Cylinder
from pydrake.math import RigidTransform

from drakegrasp.batch import batch_force_closure
from drakegrasp.planning import ranking, reclose
from drakegrasp.planning.ranking import DEFAULT_NOISE, robustness
from drakegrasp.planning.reclose import reclosed_robustness
from drakegrasp.planning.surface import ObjectSurface, piece_of_shape


def _full_verdicts(positions, normals, **options):
    return np.asarray(batch_force_closure(positions, normals, **options).is_closure)


@pytest.mark.parametrize(
    ("model", "nu"), [("hard_finger", None), ("soft_finger", 0.05)]
)
def test_moved_contacts_robustness_equals_the_full_solve(model, nu, monkeypatch):
    rng = np.random.default_rng(8000)
    P, Nrm, F = two_pads(rng, 40, 2)
    noise = {"position": 4e-3, "angle_deg": 8.0, "friction": 0.3}

    def run():
        return robustness(
            P, Nrm, F, mu=0.5, samples=48, rng=np.random.default_rng(1), noise=noise,
            contact_model=model, torsional_friction=nu, workers=1,
        )  # fmt: skip

    fast = run()
    monkeypatch.setattr(ranking, "force_verdicts", _full_verdicts)
    np.testing.assert_array_equal(fast, run())
    assert ((fast > 0) & (fast < 1)).any()  # both verdicts occur among copies


@pytest.mark.parametrize(
    "shape", [Box(0.06, 0.1, 0.2), Cylinder(0.03, 0.1)], ids=["box", "cylinder"]
)
def test_reclosed_robustness_equals_the_full_solve(shape, monkeypatch):
    surface = ObjectSurface.from_pieces([piece_of_shape(shape, RigidTransform(), "o")])
    rng = np.random.default_rng(8100)
    P, _, F = two_pads(rng, 30, 3)
    if isinstance(shape, Cylinder):
        P[..., 1] *= 0.1  # near the line of contact of the two pads
    axes = np.tile([1.0, 0.0, 0.0], (30, 1))

    def run():
        return reclosed_robustness(
            surface, P, F, axes, mu=0.6, samples=64, rng=np.random.default_rng(2),
            **{**DEFAULT_NOISE, "angle_deg": 10.0, "friction": 0.8}, tol=1e-4,
            contact_model="hard_finger",
            torsional_friction=None, workers=1,
        )  # fmt: skip

    fast = run()
    monkeypatch.setattr(reclose, "force_verdicts", _full_verdicts)
    np.testing.assert_array_equal(fast, run())
    assert ((fast > 0) & (fast < 1)).any()  # both verdicts occur among copies
