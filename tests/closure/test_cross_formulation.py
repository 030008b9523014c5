"""LP2 in H-form vs V-form vs the exact SOCP on hundreds of seeded random grasps.

The polyhedral cone with n_g generators is inscribed in the Coulomb cone of μ and
circumscribes the Coulomb cone of μ cos(π/n_g).  Hence, for every grasp,

    LP2(μ cos(π/n_g))-free  ⊆  exact(μ cos(π/n_g)) ⇒ LP2(μ) ⇒ exact(μ),

and wherever LP2 at μ and LP2 at μ / cos(π/n_g) agree (the grasp is not within
the linearisation margin of a boundary), the exact verdict must equal them.
"""

import numpy as np
import pytest

import drakegrasp as dg

NG = 8


def _random_grasps(rng, make_contacts, count):
    for i in range(count):
        num = 3 if i % 2 else 4
        model = "soft_finger" if i % 7 == 0 else "hard_finger"
        mu = rng.uniform(0.05, 0.8)
        yield dg.Grasp(make_contacts(rng, num, mu=mu, model=model, nu=0.3, tilt=0.54))


def _certain(result):
    return not result.near_boundary


def test_facets_generators_and_exact_agree_away_from_boundaries(rng, make_contacts):
    compared = closures = 0
    for grasp in _random_grasps(rng, make_contacts, 300):
        h = dg.force_closure(grasp, num_generators=NG)
        v = dg.force_closure(grasp, num_generators=NG, formulation="generators")
        e = dg.force_closure_exact(grasp)
        # Inscribed: polyhedral closure implies exact closure, and d* orders.
        assert h.d_star <= e.d_star + 1e-6
        if h.is_closure and _certain(h):
            assert e.is_closure
        # Same cone, two descriptions: the verdicts agree.
        if _certain(h) and _certain(v):
            assert h.is_closure == v.is_closure
        mu = grasp.contacts[0].mu
        outer = dg.force_closure(
            grasp.with_friction(mu / np.cos(np.pi / NG)), num_generators=NG
        )
        if _certain(h) and _certain(outer) and h.is_closure == outer.is_closure:
            if _certain(e):
                assert e.is_closure == h.is_closure
                compared += 1
                closures += h.is_closure
    # The sample must exercise both verdicts, or the test proves nothing.
    assert compared > 200 and 30 < closures < compared - 30


def test_planar_exact_program_is_the_lp(rng, make_contacts):
    for _ in range(40):
        grasp = dg.Grasp(make_contacts(rng, 3, dim=2, mu=rng.uniform(0, 1)))
        h, e = dg.force_closure(grasp), dg.force_closure_exact(grasp)
        assert h.is_closure == e.is_closure
        assert h.d_star == pytest.approx(e.d_star, abs=1e-9)


def test_more_generators_converge_to_the_exact_margin():
    from drakegrasp.core import examples as ex

    grasp = ex.equator_fingers(0.5)
    exact = dg.force_closure_exact(grasp).d_star
    gaps = [
        exact - dg.force_closure(grasp, num_generators=n).d_star for n in (4, 8, 32)
    ]
    assert gaps[0] > gaps[1] > gaps[2] >= -1e-7
    assert gaps[2] < 0.01 * exact
