"""The characteristic length ``b``: every valid value gives checkable witnesses.

A witness is scaled so that ``[v; b ω]`` (twist) or ``[f; m / b]`` (wrench) is a
unit vector.  With ``b`` below about 1e-150 the squares in a plain norm
underflowed or overflowed: the escape direction came out NaN and its wording
read "a moment about ±(nan, nan, nan)".  Subnormal lengths (below the smallest
normal double) are refused: a moment of 1 N·m over them overflows.
"""

import warnings

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.core.validation import LENGTH_BOUND, LENGTH_MIN


@pytest.mark.parametrize("b", [LENGTH_MIN, 1e-300, 1e-200, 1e-100, 1.0, LENGTH_BOUND])
def test_witnesses_hold_and_read_well_at_every_valid_length(b):
    jaws = dg.examples.spatial_two_fingers(0.5)
    g = dg.Grasp(jaws.contacts, characteristic_length=b)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow or division by zero
        for result in (dg.force_closure(g), dg.form_closure(g)):
            assert not result.is_closure
            assert result.certificate.check(g).holds
            assert np.all(np.isfinite(result.certificate.direction))
            assert "nan" not in result.why()
        # The unit invariance of the wording: the same axis as at b = 1.
        assert dg.force_closure(g).why() == dg.force_closure(jaws).why()


@pytest.mark.parametrize("b", [1e-320, 5e-324, 0.0, -1.0, np.inf, 1e31])
def test_lengths_outside_the_range_are_refused(b):
    jaws = dg.examples.spatial_two_fingers(0.5)
    with pytest.raises(dg.InvalidGraspError, match="characteristic_length"):
        dg.Grasp(jaws.contacts, characteristic_length=b)
    with pytest.raises(dg.GraspError, match="characteristic"):
        dg.batch_force_closure(
            np.array([c.position for c in jaws.contacts])[None],
            np.array([c.normal for c in jaws.contacts])[None],
            mu=0.5,
            characteristic_lengths=b,
        )
