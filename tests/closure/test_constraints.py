"""The contact-cone constraints every closure and load program shares.

:func:`~drakegrasp.closure.constraints.add_contact_cones` is checked against
the cones written out by hand (independent of its rows): Coulomb's
``‖f_t‖ <= μ f_n``, the soft finger's ``‖f_t‖ <= μ (f_n - |m_n| / (b ν))``
(both signs of the Lorentz rows), and, with ``exact=False``, the inscribed
pyramid, which lies inside the Coulomb cone.
"""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.solvers import MathematicalProgram

import drakegrasp as dg
from drakegrasp.closure.constraints import add_contact_cones
from drakegrasp.core.friction_cone import ConeLayout

TOL = 1e-9


def _one_contact(model: str, mu: float, nu: float = 0.3):
    extra = {"torsional_friction": nu} if model == "soft_finger" else {}
    contact = dg.Contact(
        [0.0, 0.0, 0.1], [0.0, 0.0, -1.0], mu=mu, contact_model=model, **extra
    )
    grasp = dg.Grasp(
        [contact, dg.Contact([0.0, 0.0, -0.1], [0.0, 0.0, 1.0], mu=mu)],
        characteristic_length=0.1,
    )
    return grasp, ConeLayout.of(grasp, 8)


def _satisfied(grasp, layout, x_value, *, exact=True, d_value=None) -> bool:
    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(len(layout.columns), "x")
    d = None if d_value is None else prog.NewContinuousVariables(1, "d")[0]
    add_contact_cones(
        prog,
        grasp.contacts,
        layout,
        x,
        grasp.characteristic_length,
        d=d,
        exact=exact,
    )
    values = {v.get_id(): val for v, val in zip(x, x_value, strict=True)}
    if d is not None:
        values[d.get_id()] = d_value
    for binding in prog.GetAllConstraints():
        z = np.array([values[v.get_id()] for v in binding.variables()])
        if not binding.evaluator().CheckSatisfied(z, TOL):
            return False
    return True


@pytest.mark.parametrize("model", ["hard_finger", "soft_finger"])
def test_exact_cones_are_the_coulomb_and_soft_finger_cones(model):
    rng = np.random.default_rng(11)
    mu, nu = 0.6, 0.3
    grasp, layout = _one_contact(model, mu, nu)
    b = grasp.characteristic_length
    k = len(layout.cones[0].components)
    seen = {True: 0, False: 0}
    for _ in range(300):
        x = np.zeros(len(layout.columns))
        x[:k] = rng.normal(size=k) + np.eye(k)[0]
        x[k:] = [1.0, 0.0, 0.0]  # the second contact: its normal force alone
        f = layout.scales * x
        torsion = abs(f[3]) / (b * nu) if model == "soft_finger" else 0.0
        slack = mu * (f[0] - torsion) - np.hypot(f[1], f[2])
        if abs(slack) < 1e-6:
            continue
        inside = slack > 0
        assert _satisfied(grasp, layout, x) == inside
        seen[inside] += 1
    assert min(seen.values()) > 30  # both sides of the boundary were sampled


@pytest.mark.parametrize("model", ["hard_finger", "soft_finger"])
def test_the_pyramid_lies_inside_the_exact_cone(model):
    rng = np.random.default_rng(12)
    grasp, layout = _one_contact(model, 0.8)
    inside_pyramid = 0
    for _ in range(300):
        x = np.zeros(len(layout.columns))
        k = len(layout.cones[0].components)
        x[:k] = rng.normal(size=k) + np.eye(k)[0]
        x[k:] = [1.0, 0.0, 0.0]
        if _satisfied(grasp, layout, x, exact=False):
            inside_pyramid += 1
            assert _satisfied(grasp, layout, x)
    assert inside_pyramid > 30


@pytest.mark.parametrize("exact", [True, False])
def test_a_margin_shrinks_the_cone(exact):
    """``d > 0`` asks for more than the closed cone; ``d < 0`` for less."""
    rng = np.random.default_rng(13)
    grasp, layout = _one_contact("soft_finger", 0.5)
    bitten = widened = 0  # the margin must change the answer somewhere
    for _ in range(200):
        x = np.zeros(len(layout.columns))
        x[:4] = rng.normal(size=4) + [1.0, 0.0, 0.0, 0.0]
        x[4:] = [1.0, 0.0, 0.0]
        closed = _satisfied(grasp, layout, x, exact=exact)
        inside = _satisfied(grasp, layout, x, exact=exact, d_value=0.05)
        outside = _satisfied(grasp, layout, x, exact=exact, d_value=-0.05)
        if inside:
            assert closed
        if closed:
            assert outside
        bitten += closed and not inside
        widened += outside and not closed
    assert bitten > 0 and widened > 0  # (a d left out would pass the above)
