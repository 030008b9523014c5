"""Largest resistible external wrench (an LP with Drake + Clp)."""

import json

import numpy as np
import pytest
from scipy.optimize import linprog

import drakegrasp as dg
from drakegrasp.quality import (
    build_max_resistible_wrench_program,
    max_resistible_wrench,
    primitive_wrenches,
)

GRAVITY_DOWN = np.array([0.0, 0.0, -1.0, 0.0, 0.0, 0.0])


def _box_squeeze(mu, half_width=0.05):
    """Two fingers squeezing a box along x; gravity along -z."""
    return dg.Grasp(
        [
            dg.Contact([half_width, 0, 0], [-1.0, 0, 0], mu=mu),
            dg.Contact([-half_width, 0, 0], [1.0, 0, 0], mu=mu),
        ]
    )


@pytest.mark.parametrize("mu,fmax", [(0.5, 10.0), (0.3, 4.0), (1.2, 0.5)])
def test_box_against_gravity(mu, fmax):
    # Each finger's polyhedral cone has a generator along +z (tangential reach
    # mu f_n exactly), so the weight held is α = 2 mu f_max.
    g = _box_squeeze(mu)
    res = max_resistible_wrench(g, GRAVITY_DOWN, max_normal_force=fmax)
    assert res.alpha == pytest.approx(2 * mu * fmax, rel=1e-7)
    assert res.status == "kSolutionFound" and res.solver == "Clp"
    f = np.concatenate(res.contact_forces)
    assert np.allclose(dg.grasp_matrix(g) @ f, -res.wrench, atol=1e-7)
    for fc, c in zip(res.contact_forces, g.contacts, strict=True):
        assert fc[0] <= fmax + 1e-7
        F = dg.friction_cone_facets(c)
        assert np.all(F @ fc >= -1e-7)


def test_box_with_unequal_limits():
    # The x-forces must balance, so both normal forces are at most min(f_max).
    g = _box_squeeze(0.5)
    res = max_resistible_wrench(g, GRAVITY_DOWN, max_normal_force=[3.0, 5.0])
    assert res.alpha == pytest.approx(2 * 0.5 * 3.0, rel=1e-7)
    assert np.allclose(res.max_normal_force, [3.0, 5.0])


def test_planar_box():
    g = dg.Grasp(
        [
            dg.Contact([0.1, 0.0], [-1.0, 0.0], mu=0.4),
            dg.Contact([-0.1, 0.0], [1.0, 0.0], mu=0.4),
        ]
    )
    res = max_resistible_wrench(g, [0.0, -9.81, 0.0], max_normal_force=20.0)
    # Units: α · direction is a wrench, so α is the mass (kg) held.
    assert res.alpha == pytest.approx(2 * 0.4 * 20.0 / 9.81, rel=1e-7)


def test_unresistible_direction_gives_zero():
    # One finger pushing along +x: resisting α·[1, 0, 0, ...] needs the contact
    # force -α·[1, 0, 0], a pull, so α = 0.
    g = dg.Grasp([dg.Contact([-1.0, 0, 0], [1.0, 0, 0], mu=0.5)])
    res = max_resistible_wrench(g, [1.0, 0, 0, 0, 0, 0], max_normal_force=1.0)
    assert res.alpha == pytest.approx(0.0, abs=1e-9)
    # The opposite direction is resisted up to f_max.
    res = max_resistible_wrench(g, [-1.0, 0, 0, 0, 0, 0], max_normal_force=2.0)
    assert res.alpha == pytest.approx(2.0, rel=1e-7)


def test_scaling_laws(helpers, rng):
    # A force-closure grasp resists every direction: α > 0.
    g = helpers.equator_grasp(0.7)
    d = rng.normal(size=6)
    a = max_resistible_wrench(g, d, max_normal_force=1.0).alpha
    assert a > 1e-3
    assert max_resistible_wrench(g, 2 * d, max_normal_force=1.0).alpha == (
        pytest.approx(a / 2, rel=1e-7)
    )
    assert max_resistible_wrench(g, d, max_normal_force=3.0).alpha == (
        pytest.approx(3 * a, rel=1e-7)
    )


def _alpha_by_linprog(grasp, direction, fmax, n_g):
    """V-form LP with scipy/HiGHS: f_i = S_i λ_i, Σ_k λ_ik = f_n,i <= f_max."""
    wrenches = primitive_wrenches(grasp, num_generators=n_g, torque_scale=1.0)
    W = np.vstack(wrenches).T  # wrench of each generator with f_n = 1
    owner = np.concatenate([np.full(w.shape[0], i) for i, w in enumerate(wrenches)])
    m = W.shape[1]
    c = np.zeros(m + 1)
    c[-1] = -1.0
    A_eq = np.hstack([W, np.asarray(direction)[:, None]])
    A_ub = np.zeros((grasp.num_contacts, m + 1))
    for i in range(grasp.num_contacts):
        A_ub[i, :m] = owner == i
    res = linprog(
        c,
        A_ub=A_ub,
        b_ub=np.full(grasp.num_contacts, fmax),
        A_eq=A_eq,
        b_eq=np.zeros(W.shape[0]),
        bounds=[(0, None)] * (m + 1),
        method="highs",
    )
    assert res.status == 0
    return res.x[-1]


@pytest.mark.parametrize(
    "dim,num,model",
    [
        (3, 3, "hard_finger"),
        (3, 4, "hard_finger"),
        (2, 3, "hard_finger"),
        (3, 3, "soft_finger"),
    ],
)
def test_against_generator_form_with_scipy(helpers, rng, dim, num, model):
    for _ in range(4):
        contacts = helpers.random_grasp(rng, num, dim, mu=0.6, spread=0.4).contacts
        if model == "soft_finger":
            contacts = [
                c.with_(contact_model="soft_finger", torsional_friction=0.3)
                for c in contacts
            ]
        g = dg.Grasp(contacts)
        d = rng.normal(size=g.wrench_dim)
        fmax = rng.uniform(0.5, 5.0)
        a = max_resistible_wrench(g, d, max_normal_force=fmax, num_generators=6)
        ref = _alpha_by_linprog(g, d, fmax, 6)
        assert a.alpha == pytest.approx(ref, rel=1e-6, abs=1e-8)


def test_build_returns_an_inspectable_program():
    g = _box_squeeze(0.5)
    prog, v = build_max_resistible_wrench_program(g, GRAVITY_DOWN, max_normal_force=1.0)
    assert prog.num_vars() == 6 + 1
    assert list(v.columns) == [0, 1, 2, 3, 4, 5]
    assert list(v.normal_positions) == [0, 3]
    # mu = 0 drops the tangential variables (frictionless behaviour).
    prog0, v0 = build_max_resistible_wrench_program(
        g.with_friction(0.0), GRAVITY_DOWN, max_normal_force=1.0
    )
    assert prog0.num_vars() == 2 + 1
    assert list(v0.columns) == [0, 3]
    res = max_resistible_wrench(g.with_friction(0.0), GRAVITY_DOWN, max_normal_force=1)
    assert res.alpha == pytest.approx(0.0, abs=1e-9)
    assert res.contact_forces[0].shape == (3,)


def test_result_to_dict_and_str():
    res = max_resistible_wrench(_box_squeeze(0.5), GRAVITY_DOWN, max_normal_force=2.0)
    d = json.loads(json.dumps(res.to_dict()))
    assert d["alpha"] == pytest.approx(2.0, rel=1e-7)
    assert len(d["contact_forces"]) == 2
    assert "alpha = 2" in str(res)
    with pytest.raises(AttributeError):
        res.alpha = 3.0


def test_bad_inputs():
    g = _box_squeeze(0.5)
    with pytest.raises(dg.InvalidOptionError, match="6-vector"):
        max_resistible_wrench(g, [0, 0, -1], max_normal_force=1.0)
    with pytest.raises(dg.InvalidOptionError, match="non-zero"):
        max_resistible_wrench(g, np.zeros(6), max_normal_force=1.0)
    with pytest.raises(dg.InvalidOptionError, match="6-vector"):
        max_resistible_wrench(g, [0, 0, np.nan, 0, 0, 0], max_normal_force=1.0)
    with pytest.raises(dg.InvalidOptionError, match="max_normal_force"):
        max_resistible_wrench(g, GRAVITY_DOWN, max_normal_force=-1.0)
    with pytest.raises(dg.InvalidOptionError, match="max_normal_force"):
        max_resistible_wrench(g, GRAVITY_DOWN, max_normal_force=[1.0, 2.0, 3.0])
    with pytest.raises(dg.InvalidOptionError, match="max_normal_force"):
        max_resistible_wrench(g, GRAVITY_DOWN, max_normal_force="lots")
    with pytest.raises(dg.InvalidOptionError, match="num_generators"):
        max_resistible_wrench(g, GRAVITY_DOWN, max_normal_force=1.0, num_generators=1)
