import numpy as np
import pytest

import drakegrasp as dg


def test_angles_margins_and_needed_friction():
    c1 = dg.Contact([0, 0, 0], [1, 0, 0], mu=0.3)
    c2 = dg.Contact([2, 0.4, 0], [-1, 0, 0], mu=0.3)
    r = dg.is_antipodal([c1, c2])
    angle = np.arctan(0.2)
    assert np.allclose(r.angles, [angle, angle])
    assert np.allclose(r.margins, np.arctan(0.3) - angle)
    assert r.is_antipodal and r.min_mu == pytest.approx(0.2)
    assert not dg.is_antipodal([c1, c2], mu=0.19).is_antipodal
    assert dg.is_antipodal(dg.Grasp([c1, c2]), mu=0.21).is_antipodal


def test_frictionless_pair_is_antipodal_only_when_collinear():
    a = dg.Contact([0, 0], [1, 0], contact_model="frictionless", mu=0.9)
    b = dg.Contact([1, 0], [-1, 0], contact_model="frictionless")
    assert dg.is_antipodal([a, b]).is_antipodal
    b2 = dg.Contact([1, 1e-3], [-1, 0], contact_model="frictionless")
    assert not dg.is_antipodal([a, b2]).is_antipodal


def test_pointing_away_is_never_antipodal():
    a = dg.Contact([0, 0, 0], [-1, 0, 0], mu=5.0)
    b = dg.Contact([1, 0, 0], [-1, 0, 0], mu=5.0)
    r = dg.is_antipodal([a, b])
    assert not r.is_antipodal and r.min_mu == np.inf


def test_planar_antipodal_equals_two_finger_force_closure(rng):
    # Nguyen: two planar hard fingers are in force closure iff antipodal
    # (strictly inside the cones).  An independent route through LP2.
    agree = positives = 0
    for _ in range(150):
        p = rng.normal(size=(2, 2))
        n = (p[::-1] - p) + 0.8 * rng.normal(size=(2, 2))
        mu = rng.uniform(0.05, 1.0)
        grasp = dg.Grasp([dg.Contact(p[i], n[i], mu=mu) for i in range(2)])
        anti = dg.is_antipodal(grasp)
        closure = dg.force_closure(grasp)
        if np.min(np.abs(anti.margins)) < 1e-4 or closure.near_boundary:
            continue
        assert anti.is_antipodal == closure.is_closure
        agree += 1
        positives += anti.is_antipodal
    assert agree > 100 and 10 < positives < agree - 10


def test_symmetric_in_contact_order():
    a = dg.Contact([0, 0, 0], [1, 0.1, 0], mu=0.3)
    b = dg.Contact([1, 0.2, 0.1], [-1, 0, 0.05], mu=0.5)
    r1, r2 = dg.is_antipodal([a, b]), dg.is_antipodal([b, a])
    assert (
        np.allclose(r1.angles, r2.angles[::-1]) and r1.is_antipodal == r2.is_antipodal
    )
    assert "antipodal" in str(r1) and r1.to_dict()["mu"] == [0.3, 0.5]


@pytest.mark.parametrize(
    ("normals", "said"),
    [
        (([-1, 0, 0], [1, 0, 0]), "both normals point away from the other contact"),
        (([-1, 0.1, 0], [-1, 0, 0]), "the normal of contact 1 points away"),
        (([1, 0, 0], [0.2, 1, 0]), "the normal of contact 2 points away"),
    ],
)
def test_outward_normals_are_named_not_reported_as_mu_inf(normals, said):
    # "antipodal for mu >= inf" hid a sign convention mistake: drakegrasp's
    # normals point into the object (docs/conventions.md).
    pair = [dg.Contact([-1, 0, 0], normals[0]), dg.Contact([1, 0, 0], normals[1])]
    r = dg.is_antipodal(pair, mu=0.5)
    text = str(r)
    assert not r.is_antipodal and r.min_mu == np.inf  # the numbers are unchanged
    assert said in text and "point into the object" in text
    assert "conventions.md" in text and "mu >= inf" not in text
    # the same pair with the normals flipped into the object is antipodal
    if "both" in said:
        flipped = [dg.Contact(c.position, -c.normal) for c in pair]
        assert dg.is_antipodal(flipped, mu=0.5).is_antipodal


def test_a_normal_square_to_the_line_needs_infinite_friction():
    pair = [dg.Contact([-1, 0, 0], [0, 1, 0]), dg.Contact([1, 0, 0], [-1, 0, 0])]
    text = str(dg.is_antipodal(pair, mu=0.5))
    assert "the normal of contact 1 is perpendicular to the line" in text
    assert "mu >= inf" not in text and "points away" not in text


def test_the_caveat_names_the_contact_model_it_is_about():
    # a soft-finger report once read "two hard fingers never resist a moment"
    pair = [dg.Contact([-1, 0, 0], [1, 0, 0]), dg.Contact([1, 0, 0], [-1, 0, 0])]
    text = str(dg.is_antipodal(pair, mu=0.5))
    assert "two point contacts without torsional friction (hard fingers)" in text
