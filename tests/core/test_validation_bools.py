"""A flag is not a number: numpy reads ``[0, True]`` as ``[0, 1]``.

``real_array`` refused a bool array but took a list that mixed a ``True``
with numbers, so ``AnalysisOptions(load=[0, 0, True, 0, 0, 0])`` or a contact
at ``[0, True, 0]`` was analysed as a load of 1 N or a point 1 m away.
"""

from __future__ import annotations

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.core.validation import real_array
from drakegrasp.errors import InvalidOptionError


@pytest.mark.parametrize(
    "value", [[0, True], (1.5, False), [[0.0, 1.0], [np.bool_(True), 2.0]]]
)
def test_a_bool_among_numbers_is_refused(value):
    with pytest.raises(InvalidOptionError, match="True/False"):
        real_array("x", value, error=InvalidOptionError)


@pytest.mark.parametrize("value", [[0, 1], (0.5, 2), np.array([True, False]) * 1.0])
def test_numbers_pass(value):
    np.testing.assert_array_equal(
        real_array("x", value, error=InvalidOptionError), np.asarray(value, float)
    )


def test_the_public_surfaces_refuse_it():
    with pytest.raises(dg.GraspError, match="load must be"):
        dg.AnalysisOptions(load=[0, 0, True, 0, 0, 0])
    with pytest.raises(dg.GraspError, match="True/False"):
        dg.Contact([0, True, 0], [1, 0, 0])
