"""Hostile inputs of second-order form closure (issue 21, part 3).

``first_order`` decides the answer outright when it says "yes", so it must be
form closure of *this* grasp (its certificate is re-checked); curvatures that
overflow, zero or non-finite principal directions, complex values and
``ContactCurvature(None, None)`` are refused with an ``InvalidContactError``
naming the value.  The independent routes: the first-order verdicts are those
of scipy's LP1 written here; a tiny principal direction gives the Hessian of
its unit direction; a curvature beyond the bound is refused, and the same
feature given as ``+inf`` (sharp) is answered.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import linprog

import drakegrasp as dg
from drakegrasp import ContactCurvature, SurfaceCurvature
from drakegrasp.core import examples as ex
from drakegrasp.core.curvature import (
    CURVATURE_BOUND,
    RELATIVE_CURVATURE_BOUND,
    contact_hessian,
)


def _lp1(grasp) -> bool:
    """Strictly positive normal forces that balance, with G_n of full rank."""
    G_n = dg.normal_grasp_matrix(grasp)
    m, n = G_n.shape
    if np.linalg.matrix_rank(G_n) < m:
        return False
    c = np.r_[np.zeros(n), -1.0]
    A_eq = np.vstack([np.c_[G_n, np.zeros(m)], np.r_[np.ones(n), 0.0]])
    res = linprog(
        c,
        A_ub=np.c_[-np.eye(n), np.ones(n)],
        b_ub=np.zeros(n),
        A_eq=A_eq,
        b_eq=np.r_[np.zeros(m), n],
        bounds=[(0, None)] * n + [(None, 1)],
        method="highs",
    )
    return res.status == 0 and -res.fun > 1e-6


def _points(grasp):
    return [ContactCurvature.point_finger(SurfaceCurvature.flat())] * len(
        grasp.contacts
    )


def test_a_force_closure_result_is_not_first_order_form_closure():
    g = ex.equator_fingers(0.5)  # force closure with friction, not form closure
    assert dg.force_closure(g).is_closure and not _lp1(g)
    with pytest.raises(dg.InvalidOptionError, match="form closure"):
        dg.second_order_form_closure(g, _points(g), first_order=dg.force_closure(g))


def test_form_closure_of_another_grasp_is_refused():
    cube = ex.cube_seven_contacts()
    assert _lp1(cube)
    # same number of contacts, one finger turned away: not in form closure
    contacts = list(cube.contacts)
    c = contacts[0]
    contacts[0] = dg.Contact(c.position, -np.asarray(c.normal))
    other = dg.Grasp(contacts)
    assert not _lp1(other)
    with pytest.raises(dg.InvalidOptionError, match="another grasp"):
        dg.second_order_form_closure(
            other, _points(other), first_order=dg.form_closure(cube)
        )
    # and the other way round: a "no" of another grasp does not answer for the cube
    with pytest.raises(dg.InvalidOptionError, match="another grasp"):
        dg.second_order_form_closure(
            cube, _points(cube), first_order=dg.form_closure(other)
        )


def test_form_closure_of_a_grasp_with_other_contacts_count_is_refused():
    cube = ex.cube_seven_contacts()
    fewer = dg.Grasp(cube.contacts[:6])
    with pytest.raises(dg.InvalidOptionError, match="contact"):
        dg.second_order_form_closure(
            fewer, _points(fewer), first_order=dg.form_closure(cube)
        )


def test_its_own_first_order_result_is_accepted_and_changes_nothing():
    for g in (ex.cube_seven_contacts(), ex.spatial_two_fingers(0.5)):
        curv = _points(g)
        alone = dg.second_order_form_closure(g, curv)
        given = dg.second_order_form_closure(g, curv, first_order=dg.form_closure(g))
        assert given.is_closure == alone.is_closure
        assert given.order == alone.order
        if _lp1(g):  # a "yes" at first order, decided by LP1
            assert given.is_closure and given.order == 1


@pytest.mark.parametrize(
    "value",
    [None, "1", 3, object(), [SurfaceCurvature.flat()]],
)
def test_contact_curvature_needs_two_surfaces(value):
    with pytest.raises(dg.InvalidContactError, match="SurfaceCurvature"):
        ContactCurvature(value, SurfaceCurvature.flat())
    with pytest.raises(dg.InvalidContactError, match="SurfaceCurvature"):
        ContactCurvature(SurfaceCurvature.flat(), value)


def test_contact_curvature_none_none_is_refused():
    with pytest.raises(dg.InvalidContactError):
        ContactCurvature(None, None)


def test_planar_and_spatial_surfaces_do_not_mix():
    with pytest.raises(dg.InvalidContactError, match="planar"):
        ContactCurvature(SurfaceCurvature.flat(), SurfaceCurvature.point(planar=True))


@pytest.mark.parametrize(
    "k",
    [
        (1e308, 1e308),
        (-1e308, 0.0),
        (2 * CURVATURE_BOUND, 0.0),
        (math.nan, 0.0),
        (-math.inf, 0.0),
        (1 + 1j, 1.0),
        np.array([1.0, 1.0], dtype=complex),
        ("a", "b"),
        (None, 1.0),
        (),
        (1.0, 2.0, 3.0),
        [[1.0], [1.0]],
    ],
)
def test_curvatures_out_of_range_or_not_real_are_refused(k):
    with pytest.raises(dg.InvalidContactError):
        SurfaceCurvature(k, (1.0, 0.0, 0.0))


@pytest.mark.parametrize(
    "d",
    [
        (0.0, 0.0, 0.0),
        (math.nan, 1.0, 0.0),
        (math.inf, 0.0, 0.0),
        (1j, 1.0, 0.0),
        (1.0, 0.0),
        "abc",
        ((1.0, 0.0, 0.0),),
    ],
)
def test_bad_principal_directions_are_refused(d):
    with pytest.raises(dg.InvalidContactError):
        SurfaceCurvature((1.0, 2.0), d)


@pytest.mark.parametrize("scale", [1e-300, 1e-200, 1e-13, 1e13, 1e300])
def test_a_tiny_or_huge_principal_direction_is_its_unit_direction(scale):
    g = dg.Grasp([dg.Contact([0.0, 0.0, 1.0], [0.0, 0.0, -1.0])])
    d = np.array([1.0, 1.0, 0.0])
    ref = ContactCurvature(SurfaceCurvature((1.0, 3.0), d), SurfaceCurvature.point())
    got = ContactCurvature(
        SurfaceCurvature((1.0, 3.0), scale * d), SurfaceCurvature.point()
    )
    np.testing.assert_allclose(
        got.object.direction, d / np.linalg.norm(d), rtol=0, atol=1e-15
    )
    np.testing.assert_allclose(
        contact_hessian(g, 0, got), contact_hessian(g, 0, ref), rtol=1e-13, atol=1e-15
    )


@pytest.mark.parametrize("radius", [0.0, -1.0, math.nan, math.inf, 1e-300, "r", 1j])
def test_radii_out_of_range_are_refused(radius):
    with pytest.raises(dg.InvalidContactError, match="radius"):
        SurfaceCurvature.convex(radius)


def test_a_curvature_sharp_relative_to_the_grasp_is_refused_and_inf_answers():
    g = ex.cube_seven_contacts()  # b of order 1 m
    b = g.characteristic_length
    too_sharp = 10 * RELATIVE_CURVATURE_BOUND / b
    curv = [
        ContactCurvature(SurfaceCurvature.flat(), SurfaceCurvature((too_sharp,) * 2))
    ] * g.num_contacts
    with pytest.raises(dg.InvalidContactError, match=r"\+inf"):
        dg.second_order_form_closure(g, curv)
    sharp = [ContactCurvature.point_finger(SurfaceCurvature.flat())] * g.num_contacts
    assert dg.second_order_form_closure(g, sharp).is_closure == _lp1(g)


def test_second_order_tol_is_a_real_number():
    g = ex.cube_seven_contacts()
    for tol in ("abc", None, 1j, math.nan, -1.0, [1e-6]):
        with pytest.raises(dg.InvalidOptionError, match="tol"):
            dg.second_order_form_closure(g, _points(g), tol=tol)
