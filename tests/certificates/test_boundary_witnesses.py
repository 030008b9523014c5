"""Review r22: witnesses on the boundary of force closure.

The planar two-finger square is in force closure exactly when μ > 1/2.  A
"yes" witness of μ = 0.6 (a balancing internal force) checked on the boundary
grasp μ = 0.5 held, beside that grasp's own "no" witness: a force on a cone's
boundary, or outside it by less than the check's tolerance, proves no force
closure ("strictly inside every cone", docs/conventions.md).  And a "no" within
tol of the boundary explained itself as a fact.
"""

from __future__ import annotations

import pytest

import drakegrasp as dg
from drakegrasp.core import examples as ex


@pytest.fixture(scope="module")
def yes():
    r = dg.force_closure(ex.planar_two_finger_square(0.6))
    assert r.is_closure and r.certificate.kind == "balancing internal force"
    return r.certificate


@pytest.mark.parametrize("mu", [0.5, 0.4999999, 0.4])
def test_a_balancing_force_on_or_past_the_boundary_proves_nothing(yes, mu):
    got = yes.check(ex.planar_two_finger_square(mu))
    assert not got.holds and got.slack <= 0.0
    assert "not strictly inside every cone" in got.detail


@pytest.mark.parametrize("mu", [0.5000001, 0.6, 2.0])
def test_a_balancing_force_strictly_inside_still_holds(yes, mu):
    # Independent route: the internal force along the fingers' line is inside
    # a cone of half-angle atan(mu) exactly when mu > 1/2.
    got = yes.check(ex.planar_two_finger_square(mu))
    assert got.holds and got.slack > 0.0


def test_the_two_witnesses_of_the_boundary_grasp_no_longer_both_hold(yes):
    g = ex.planar_two_finger_square(0.5)
    no = dg.force_closure(g).certificate
    assert no.check(g).holds
    assert not yes.check(g).holds


def test_a_no_within_tol_of_the_boundary_says_so():
    r = dg.force_closure(ex.planar_two_finger_square(0.5000001))
    assert not r.is_closure and r.near_boundary
    assert "within tol of the boundary" in r.why() and "not certain" in r.why()
    far = dg.force_closure(ex.planar_two_finger_square(0.4))
    assert not far.near_boundary and "within tol" not in far.why()
