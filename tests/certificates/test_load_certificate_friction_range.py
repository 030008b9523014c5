"""LoadCertificate.check at friction coefficients from 1e-12 to 1e12.

Two antipodal hard fingers on the x axis (normals ±x, second tangents ±z),
the load along -z.  The twist ``y = [0, 0, 1/μ, 0, 0, 0]`` gives each contact
``a = (-ρ_i - σ - η_i, 0, ∓1/μ)``: support ``1 - ρ_i - σ - η_i``, so
multipliers summing to 1 per contact make it exactly 0, and the bound
``B / (-yᵀ w)`` is ``2 μ f_max`` (per-finger bound), ``μ s`` (squeeze) or
``2 μ τ / |w|`` (joint ``j`` with ``τ_j = f_n,j``): the closed forms of
``test_huge_friction`` and ``test_tiny_friction``, written by hand, in floats
that are exact.  A bound 1e-5 low must fail at every μ: at μ = 1e-9 the check
measured a contact's support against ``‖G‖ ‖y‖`` (1e9 times the inequality's
own terms) and passed bounds 10 % low.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.certificates.load import PAYLOAD_BOUND, LoadCertificate

A, FMAX, SQUEEZE, TAU = 0.05, 3.0, 4.0, 2.0
MUS = [1e-12, 1e-11, 1e-10, 1e-9, 1e-6, 1e-3, 0.5, 1.0, 1e3, 1e6, 1e9, 1e12]
LOW = 1.0 - 1e-5


def _pinch(mu):
    return dg.Grasp(
        [
            dg.Contact([-A, 0, 0], [1, 0, 0], mu=mu),
            dg.Contact([A, 0, 0], [-1, 0, 0], mu=mu),
        ]
    )


def _hand():
    J = np.zeros((6, 2))
    J[0, 0], J[3, 1] = 1.0, 1.0
    return J


def _certificate(mu, limit, cones, w):
    """The exact payload certificate of the module docstring."""
    N = 2
    rho, sigma, eta = np.zeros(N), 0.0, np.zeros(0)
    fmax, squeeze, tau = np.full(N, np.inf), np.inf, None
    if limit == "f_max":
        rho, fmax = np.ones(N), np.full(N, FMAX)
    elif limit == "squeeze":
        sigma, squeeze = 1.0, SQUEEZE
    else:
        eta, tau = np.ones(N), np.full(N, TAU)
    y = np.array([0.0, 0.0, 1.0 / mu, 0.0, 0.0, 0.0])
    cert = LoadCertificate(
        kind=PAYLOAD_BOUND,
        cones=cones,
        num_generators=4,
        wrench=w,
        twist=y,
        joint_multipliers=eta,
        normal_multipliers=rho,
        squeeze_multiplier=sigma,
        torque_limits=tau,
        max_normal_force=fmax,
        max_squeeze=squeeze,
        bound=0.0,
    )
    return dataclasses.replace(cert, bound=cert.power_budget() / -(y @ w))


def _closed_form(mu, limit, w):
    size = np.linalg.norm(w)
    return {"f_max": 2 * mu * FMAX, "squeeze": mu * SQUEEZE, "motors": 2 * mu * TAU}[
        limit
    ] / size


@pytest.mark.parametrize("cones", ["exact", "polyhedral"])
@pytest.mark.parametrize("limit", ["f_max", "squeeze", "motors"])
@pytest.mark.parametrize("mu", MUS)
def test_a_true_payload_bound_passes_and_one_1e_5_low_fails(mu, limit, cones):
    g = _pinch(mu)
    J = _hand() if limit == "motors" else None
    w = np.array([0.0, 0.0, -9.81, 0.0, 0.0, 0.0])
    cert = _certificate(mu, limit, cones, w)
    assert cert.bound == pytest.approx(_closed_form(mu, limit, w), rel=1e-12, abs=0.0)
    check = cert.check(g, hand_jacobian=J)
    assert check.holds, check
    low = [
        # Smaller multipliers, with the bound they prove.
        dataclasses.replace(
            cert,
            joint_multipliers=LOW * cert.joint_multipliers,
            normal_multipliers=LOW * cert.normal_multipliers,
            squeeze_multiplier=LOW * cert.squeeze_multiplier,
            bound=LOW * cert.bound,
        ),
        # A longer twist: the load's power grows, the bound shrinks.
        dataclasses.replace(cert, twist=cert.twist / LOW, bound=LOW * cert.bound),
        # Only a smaller claim.
        dataclasses.replace(cert, bound=LOW * cert.bound),
    ]
    for forged in low:
        check = forged.check(g, hand_jacobian=J)
        assert not check.holds, (forged, check)
