"""Review r22: witnesses on the boundary of force closure.

The planar two-finger square is in force closure exactly when μ > 1/2.  A
"yes" witness of μ = 0.6 (a balancing internal force) checked on the boundary
grasp μ = 0.5 held, beside that grasp's own "no" witness: a force on a cone's
boundary, or outside it by less than the check's tolerance, proves no force
closure ("strictly inside every cone", docs/conventions.md).  And a "no" within
tol of the boundary explained itself as a fact.
"""

from __future__ import annotations

import numpy as np
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
    from drakegrasp.certificates.kinds import INTERIOR_SLACK

    got = yes.check(ex.planar_two_finger_square(mu))
    assert not got.holds and got.slack <= INTERIOR_SLACK
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


@pytest.mark.parametrize("tilt", [0.0, 1e-9, 1e-7, 1e-6])
def test_an_axis_nearly_in_the_null_space_adds_no_column(tilt):
    # four contacts on a cylinder, their normals through its axis but for a
    # tilt (as Drake's distance queries give them): an axis only nearly in
    # the null space was taken as it was, and its small part outside left a
    # third column behind (about the contact normal): the escape twist
    # failed its own check (violation 1) and second order was never decided
    R = 0.03
    contacts = [
        dg.Contact(
            [R * np.cos(a), R * np.sin(a), z],
            [-np.cos(a + tilt), -np.sin(a + tilt), 0.0],
            mu=0.5,
        )
        for a, z in [
            (0.29, 0.019), (0.25, -0.0007), (np.pi + 0.29, -0.0007),
            (np.pi + 0.25, 0.019),
        ]
    ]  # fmt: skip
    grasp = dg.Grasp(contacts)
    result = dg.form_closure(grasp)
    assert not result.is_closure and result.rank == 4
    assert result.certificate.null_basis.shape[1] == 6 - result.rank
    assert result.certificate.check(grasp).holds


@pytest.mark.parametrize("tilt", [1e-8, 1e-6, 1e-5, 4e-5, 1e-4])
def test_an_axis_nearly_in_the_null_space_is_taken_as_the_span_holds_it(tilt):
    # the normals tilted out of the plane instead: the bare axis, taken for
    # the span's direction, tilted the span by up to 4.5e-5 rad, and the
    # escape twist failed its own check (violation about the tilt)
    R = 0.03
    contacts = [
        dg.Contact(
            [R * np.cos(a), R * np.sin(a), z],
            [-np.cos(a), -np.sin(a), tilt * sign],
            mu=0.5,
        )
        for a, z, sign in [
            (0.29, 0.019, 1), (0.25, -0.0007, -1), (np.pi + 0.29, -0.0007, 1),
            (np.pi + 0.25, 0.019, -1),
        ]
    ]  # fmt: skip
    grasp = dg.Grasp(contacts)
    result = dg.form_closure(grasp)
    assert not result.is_closure
    assert result.certificate.null_basis.shape[1] == 6 - result.rank
    assert result.certificate.check(grasp).holds


@pytest.mark.parametrize(
    ("delta", "holds"), [(0.0, False), (1e-15, False), (1e-12, True)]
)
def test_a_force_inside_by_roundoff_is_on_the_boundary(yes, delta, holds):
    # On the boundary the slack is roundoff of either sign: one numpy build
    # computed -1e-17 at mu = 0.5, numpy 2.4 computed +2.8e-17, and the "yes"
    # held beside the grasp's own "no".  A force inside by less than
    # INTERIOR_SLACK (64 eps of sum f_n) proves nothing; inside by 1e-12 holds.
    from drakegrasp.certificates.kinds import INTERIOR_SLACK

    got = yes.check(ex.planar_two_finger_square(0.5 + delta))
    assert got.holds is holds
    assert (got.slack > INTERIOR_SLACK) is holds
    if not holds:
        assert "roundoff of the boundary" in got.detail
