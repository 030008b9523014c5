"""LP3 beside the squeezes the contacts can carry: a second fact, not a verdict.

Two one-joint fingers, two contacts each (a multi-point pad: the WSG-50's two
tip spheres on a capsule), whose normals are tilted by ``±tilt`` from their
joint axes.  Pressing along the normals, every joint feels the squeeze
(``cos tilt`` of it).  LP3 as the conventions fix it bounds the normals only:
at any tilt above round-off it finds a "squeeze" perpendicular to the joint
axes, ``1 / tan(tilt)`` times harder along the surfaces than into them, and
fails; at 0 it passes.  The verdict keeps that definition.  Beside it the
report now says whether such a squeeze exists within the friction cones: none
until the wedge self-locks, ``tilt >= 90° - atan(mu)``.  Independent routes:
the wedge's self-locking angle, and a squeeze made by hand in N(G) ∩ N(Jᵀ)
far outside the cones, as LP3's own optimum is.
"""

from __future__ import annotations

import numpy as np
import pytest

import drakegrasp as dg


def _tilted_jaw(tilt: float, mu: float = 0.5, **contact):
    """Two one-joint fingers along ±y, two contacts each, normals tilted about x."""
    contacts = []
    for s in (-1.0, 1.0):  # the left finger, at y = +25 mm, pushes along -y
        for z, t in ((0.01, tilt), (-0.01, -tilt)):
            n = [0.0, s * np.cos(t), np.sin(t)]
            contacts.append(dg.Contact([0.0, -s * 0.025, z], n, mu=mu, **contact))
    grasp = dg.Grasp(contacts)
    k = grasp.num_components // 4
    J = np.zeros((grasp.num_components, 2))
    for i, c in enumerate(grasp.contacts):
        axis = np.array([0.0, -1.0 if i < 2 else 1.0, 0.0])
        J[k * i : k * i + 3, i // 2] = np.asarray(c.frame).T @ axis
    return grasp, J


def test_no_tilt_passes_lp3_and_reports_no_second_program():
    grasp, J = _tilted_jaw(0.0)
    lp3 = dg.internal_forces(grasp, J)
    assert lp3.passes
    assert lp3.passes_within_friction is None and lp3.d_star_within_friction is None
    assert "friction cones" not in str(lp3)


@pytest.mark.parametrize("degrees", [1e-5, 0.01, 0.39, 8.0, 60.0])
def test_a_tilt_fails_lp3_but_no_squeeze_within_friction_escapes(degrees):
    grasp, J = _tilted_jaw(np.radians(degrees))
    lp3 = dg.internal_forces(grasp, J)
    assert not lp3.passes  # LP3 as the conventions fix it: unchanged
    assert lp3.passes_within_friction is True
    assert lp3.d_star_within_friction <= lp3.tol
    assert "within the friction cones none exists" in str(lp3)
    for verdict in (dg.force_closure, dg.force_closure_exact):
        result = verdict(grasp, hand_jacobian=J)
        assert not result.is_closure and result.decided_by == "LP3"
        assert result.internal_forces.passes_within_friction is True


@pytest.mark.parametrize("degrees, mu, within", [
    (66.0, 0.5, False), (80.0, 0.5, False),  # beyond 90° - atan(0.5) = 63.43°
    (60.0, 0.5, True), (66.0, 0.4, True),  # at mu 0.4 it locks from 68.2°
])  # fmt: skip
def test_a_wedge_that_self_locks_has_a_squeeze_within_friction(degrees, mu, within):
    grasp, J = _tilted_jaw(np.radians(degrees), mu=mu)
    lp3 = dg.internal_forces(grasp, J)
    assert not lp3.passes
    assert lp3.passes_within_friction is within
    if not within:
        assert lp3.d_star_within_friction > 0.1
        assert "one exists within the friction cones too" in str(lp3)


def test_soft_fingers_bound_the_squeeze_too():
    grasp, J = _tilted_jaw(
        np.radians(0.39), contact_model="soft_finger", torsional_friction=0.3
    )
    lp3 = dg.internal_forces(grasp, J)
    assert not lp3.passes and lp3.passes_within_friction is True


def test_lp3s_squeeze_at_a_tilt_lies_outside_the_cones():
    # each contact's force perpendicular to its joint axis: in N(G) ∩ N(Jᵀ)
    # with positive normals (LP3's kind of witness), 146 times harder along
    # the surface than into it at 0.39°, far outside mu = 0.5
    grasp, J = _tilted_jaw(np.radians(0.39))
    forces = []
    for i in range(4):
        row = J[3 * i : 3 * i + 3, i // 2]
        forces.append(np.array([1.0, 0.0, -row[0] / row[2]]))
    f = np.concatenate(forces)
    assert np.allclose(J.T @ f, 0, atol=1e-9)
    assert np.allclose(dg.grasp_matrix(grasp) @ f, 0, atol=1e-9)
    assert min(abs(x[2]) for x in forces) > 100 * 0.5
    lp3 = dg.internal_forces(grasp, J)
    for x in lp3.contact_forces:  # LP3's own optimum leans as far
        assert np.linalg.norm(x[1:3]) > 0.5 * x[0]


def test_a_solver_failure_on_the_second_program_leaves_the_verdict(monkeypatch):
    # the within-friction program is a fact beside LP3: its solver failing
    # must not turn LP3's answer into an exception (review)
    from drakegrasp.closure import verdicts

    real = verdicts._solve_margin
    calls = []

    def failing_second(prog, variables, *, conic):
        calls.append(conic)
        if len(calls) == 2:
            raise dg.SolverError("Clarabel failed with status kSolverSpecificError")
        return real(prog, variables, conic=conic)

    monkeypatch.setattr(verdicts, "_solve_margin", failing_second)
    grasp, J = _tilted_jaw(np.radians(0.39))
    lp3 = dg.internal_forces(grasp, J)
    assert calls == [False, True]
    assert not lp3.passes and lp3.certificate is not None
    assert lp3.passes_within_friction is None and lp3.d_star_within_friction is None
    assert "friction cones" not in str(lp3)
