r"""Finding the Farkas dual that proves a load cannot be held (or bounds a payload).

The certificate (:class:`~drakegrasp.certificates.load.LoadCertificate`) is a
twist ``y`` and multipliers ``η`` (joints), ``ρ >= 0`` (per-contact normal
bounds), ``σ >= 0`` (total squeeze) with ``a_i = G_iᵀ y - J_i η - (ρ_i + σ) e_n``
in the negative polar of every cone.  It is found by one program over those
variables, written on the normalised grasp matrix (``y = Tᵀ ȳ``) and the unit
columns of ``J`` (:mod:`~drakegrasp.closure.load_problem`):

* **refute** a load ``w``: ``min ȳᵀ w̄ + B`` s.t. the cone conditions and
  ``‖ȳ‖_∞ <= 1``; a negative optimum is a certificate;
* **bound** a payload along ``d``: ``min B`` s.t. the cone conditions and
  ``ȳᵀ d̄ = -1``; the optimum is the largest multiple of ``d`` the grasp can
  hold (the dual of :func:`~drakegrasp.max_load`'s program).

The cone conditions, per contact over the components its cone allows: on a
polyhedral (or planar, or frictionless) cone ``S_iᵀ a_i <= 0`` (its
generators); on an exact Coulomb cone ``μ ‖a_t‖ <= -a_n`` (a Lorentz cone); a
soft finger adds ``a_n ± b ν a_m <= 0``.

With a ``μ`` far from 1 the program is solved on the friction-scaled twin
(:meth:`~drakegrasp.closure.load_problem.LoadProblem.friction_scaled`): its
balance rows ``B`` make ``ȳ = Bᵀ z_y`` and the multipliers about 1 at
``μ = 1e-12`` and ``1e12`` alike; a payload bound is also solved in newtons
(better scaled when the motors bind a huge ``μ``'s tangential forces) and the
least bound whose certificate re-checks is returned.
"""

from __future__ import annotations

import numpy as np
from pydrake.solvers import MathematicalProgram, SolutionResult

from drakegrasp._solvers import solve
from drakegrasp.certificates.load import LOAD_NOT_HELD, PAYLOAD_BOUND, LoadCertificate
from drakegrasp.closure.constraints import (
    add_linear_constraint,
    add_linear_equality_constraint,
)
from drakegrasp.closure.load_problem import LoadProblem

__all__ = ["find_load_certificate"]

REFUTE_THRESHOLD = 1e-7
"""A refuting dual needs ``ȳᵀ w̄ + B < -REFUTE_THRESHOLD`` (program units, ‖w̄‖_∞ = 1)."""


def _dual_matrix(P: LoadProblem):
    """``a = A z`` over ``z = [ȳ, η⁺, η⁻, ρ, σ]`` and the cost weights of ``z``.

    Only limited joints, bounded contacts and a finite squeeze bound bring a
    multiplier.  Returns ``(A, weights, blocks)`` with ``blocks`` the slices of
    ``z``.
    """
    D = P.Gbar.shape[0]
    m = P.num_forces
    lim = P.limited_joints()
    bounded = P.bounded_contacts()
    squeeze = np.isfinite(P.max_squeeze)
    normals = P.layout.normal_positions
    E = np.zeros((m, len(bounded)))
    E[normals[bounded], np.arange(len(bounded))] = 1.0
    e_all = np.zeros((m, 1 if squeeze else 0))
    if squeeze:
        e_all[normals, 0] = 1.0
    Jl = (P.Jt[lim] / _joint_rows(P)[:, None]).T  # (m, n_lim)
    A = np.hstack([P.balanced()[0].T, -Jl, Jl, -E, -e_all])
    sizes = [D, len(lim), len(lim), len(bounded), int(squeeze)]
    edges = np.cumsum([0, *sizes])
    blocks = [slice(a, b) for a, b in zip(edges[:-1], edges[1:], strict=True)]
    return A, blocks


def _joint_rows(P: LoadProblem) -> np.ndarray:
    """Per limited joint, the scale of its multiplier (1 unless friction-scaled).

    Friction-scaled, a joint that a huge μ's tangential force turns has
    coefficients μ on the scaled variables: its multiplier is taken in units
    of that row's largest coefficient, as the balance rows are (else, at
    ``μ = 1e8``, the polar rows mixed ``μ η`` with the twist's 1 and the
    solvers stopped at a bound 6 times too high).
    """
    lim = P.limited_joints()
    if P.balance_rows is None or not lim.size:
        return np.ones(len(lim))
    r = np.max(np.abs(P.Jt[lim]) * P.layout.scales, axis=1)
    return np.where(r > 0.0, r, 1.0)


def _weights(P: LoadProblem, force_scale: float, blocks) -> np.ndarray:
    """Cost of each multiplier: the limit it prices, in program units."""
    lim = P.limited_joints()
    bounded = P.bounded_contacts()
    w = np.zeros(blocks[-1].stop)
    tau = (
        P.torque_limits[lim] / (P.jscale[lim] * force_scale * _joint_rows(P))
        if lim.size
        else []
    )
    w[blocks[1]] = tau
    w[blocks[2]] = tau
    w[blocks[3]] = P.max_normal_force[bounded] / force_scale
    if blocks[4].stop > blocks[4].start:
        w[blocks[4]] = P.max_squeeze / force_scale
    return w


def _add_polar_conditions(prog, P: LoadProblem, A: np.ndarray, z) -> None:
    """Every contact's ``a_i = A_i z`` in the negative polar of its cone."""
    b = P.grasp.characteristic_length
    # Friction-scaled (balance rows B): ȳ = Bᵀ z_y, so a tiny μ's ‖a_t‖ is
    # 1/μ times a_n and μ ‖a_t‖ about 1; each cone is divided by its largest
    # coefficient (dividing by max(1, μ) left a huge μ's rows at 1/μ).
    balanced = P.balance_rows is not None
    starts = list(P.layout.normal_positions) + [P.num_forces]
    for i, (contact, cone) in enumerate(
        zip(P.grasp.contacts, P.layout.cones, strict=True)
    ):
        Ai = A[starts[i] : starts[i + 1]]
        exact = P.cones == "exact" and cone.components in ((0, 1, 2), (0, 1, 2, 3))
        if not exact:
            S = cone.generators.T @ Ai
            add_linear_constraint(
                prog, S, np.full(len(S), -np.inf), np.zeros(len(S)), z
            )
            continue
        mu = contact.mu
        # μ ‖a_t‖ <= -a_n, divided by max(1, μ) to keep coefficients near 1.
        L = np.vstack([-Ai[0], mu * Ai[1], mu * Ai[2]])
        L = L / (_largest(L) if balanced else max(1.0, mu))
        prog.AddLorentzConeConstraint(L, np.zeros(3), z)
        if len(Ai) == 4:
            tau = b * contact.torsional_friction
            rows = np.vstack([Ai[0] + tau * Ai[3], Ai[0] - tau * Ai[3]])
            rows = rows / (_largest(rows) if balanced else max(1.0, tau))
            add_linear_constraint(prog, rows, [-np.inf] * 2, [0.0, 0.0], z)


def _largest(A: np.ndarray) -> float:
    """The largest ``|A_ij|`` (1 for a zero matrix)."""
    size = float(np.max(np.abs(A)))
    return size if size > 0.0 else 1.0


def build_load_dual_program(
    P: LoadProblem, target: np.ndarray, force_scale: float, *, mode: str
):
    """The dual program in ``z = [ȳ, η⁺, η⁻, ρ, σ]`` (see the module docstring).

    ``target`` is ``T w / F0`` (refute) or ``T d / max|T d|`` (bound), on the
    balance rows ``B`` of :meth:`LoadProblem.balanced` (times ``B``, and the
    twist variables are ``z_y`` with ``ȳ = Bᵀ z_y``).
    """
    A, blocks = _dual_matrix(P)
    with np.errstate(over="ignore"):
        weights = _weights(P, force_scale, blocks)
    # A limit past the largest float in units of a tiny load (1 N over a
    # load of 1e-300 N at μ = 1e12) binds nothing: its multiplier is 0.
    unbinding = ~np.isfinite(weights)
    weights[unbinding] = 0.0
    prog = MathematicalProgram()
    z = prog.NewContinuousVariables(A.shape[1], "z")
    y = z[blocks[0]]
    if blocks[0].stop < len(z):
        prog.AddBoundingBoxConstraint(0.0, np.inf, z[blocks[0].stop :])
    if unbinding.any():
        prog.AddBoundingBoxConstraint(0.0, 0.0, z[unbinding])
    _add_polar_conditions(prog, P, A, z)
    if mode == "refute":
        prog.AddBoundingBoxConstraint(-1.0, 1.0, y)
        prog.AddLinearCost(np.concatenate([target, weights[blocks[0].stop :]]), 0.0, z)
    else:
        add_linear_equality_constraint(prog, target[None, :], [-1.0], y)
        prog.AddLinearCost(weights, 0.0, z)
    return prog, z, blocks, weights


def find_load_certificate(
    P: LoadProblem,
    wrench: np.ndarray,
    *,
    mode: str = "refute",
    force_scale: float,
) -> tuple[LoadCertificate | None, float]:
    """Solve the dual program; the certificate it finds (or None) and its value.

    Parameters
    ----------
    P : LoadProblem
    wrench : (D,) float
        The load (refute) or the payload direction (bound), grasp frame.
    mode : {"refute", "bound"}
    force_scale : float
        ``F0`` of the primal program (refute) or of the limits (bound).

    Returns
    -------
    certificate : LoadCertificate or None
        None when the program finds no refutation (the load may be held, or
        the infeasibility is too weak to have a separating direction).
    value : float
        The optimum in newton-scaled units: ``F0 (ȳᵀ w̄/F0 + B/F0)`` for
        refute, the payload bound for bound (``inf`` when no dual exists).
    """
    # Friction-scaled twin (a μ far from 1): its balance rows B make ȳ = Bᵀ z_y
    # and the multipliers all about 1 (LoadProblem.balanced); in newtons at
    # μ = 1e-12 a twist of size 1/μ had to cancel on G_n to 1 part in 1e12.
    Q = P.friction_scaled()
    if Q is not P:
        force_scale = (
            Q.force_scale(wrench) / Q.tangent_scale
            if mode == "refute"
            else Q.force_scale(None)
        )
    target = Q.normalised(wrench)
    # Refute: the load in units of the primal's F0.  Bound: the direction's
    # size is no part of the question, so the normalisation ȳᵀ T d = -1 is
    # made on a unit direction (on T d itself, ȳ grew or shrank with |d| past
    # the solver's tolerances: a bound below the achieved α at 1e5 x the
    # weight, 0 at 1e200).  The certificate keeps the caller's d, so its bound
    # B / (-yᵀ d) is for d.
    target = target / (force_scale if mode == "refute" else np.max(np.abs(target)))
    B = Q.balanced()[1]
    if mode == "refute" or Q is P:
        return _solve_dual(Q, wrench, B @ target, force_scale, mode)
    # Bound, friction-scaled: the bound in program units is about
    # tangent_scale (μ f_max for every μ tiny; μ τ_max / ‖J‖ when the motors
    # bind a huge μ's normal forces), and a twist whose power is its inverse
    # makes the multipliers about 1 (the bound, B / -yᵀ d, is the same).  When
    # the motors bind a huge μ's tangential forces it is about 1, and the
    # newton program's dual is the better scaled: both are solved, and the
    # least bound whose certificate re-checks is the answer.
    found = [
        _solve_dual(Q, wrench, Q.tangent_scale * (B @ target), force_scale, mode),
        _solve_dual(
            P, wrench, target * min(Q.tangent_scale, 1.0), P.force_scale(None), mode
        ),
    ]
    found = [(c, v) for c, v in found if c is not None]
    checked = [
        (c, v)
        for c, v in found
        if c.check(P.grasp, hand_jacobian=P.hand_jacobian).holds
    ]
    return min(checked or found, key=lambda cv: cv[1], default=(None, np.inf))


def _solve_dual(P, wrench, target, force_scale, mode):
    """Build and solve the dual on ``P``'s balance rows; see find_load_certificate."""
    prog, z, blocks, weights = build_load_dual_program(
        P, target, force_scale, mode=mode
    )
    result = solve(prog, P.kind, retry=True)
    status = result.get_solution_result()
    if status != SolutionResult.kSolutionFound:
        return None, np.inf if mode == "bound" else 0.0
    zv = result.GetSolution(z)
    value = float(result.get_optimal_cost())
    if mode == "refute" and not value < -REFUTE_THRESHOLD:
        return None, value * force_scale
    cert = _certificate(P, wrench, zv, blocks, mode)
    if mode == "bound":
        return cert, cert.bound
    return cert, value * force_scale


def _certificate(P, wrench, zv, blocks, mode) -> LoadCertificate:
    y = P.T.T @ (P.balanced()[1].T @ zv[blocks[0]])
    n_v = P.Jt.shape[0]
    eta = np.zeros(n_v)
    lim = P.limited_joints()
    eta[lim] = (zv[blocks[1]] - zv[blocks[2]]) / (P.jscale[lim] * _joint_rows(P))
    rho = np.zeros(P.grasp.num_contacts)
    rho[P.bounded_contacts()] = np.maximum(zv[blocks[3]], 0.0)
    sigma = (
        float(max(zv[blocks[4]][0], 0.0)) if blocks[4].stop > blocks[4].start else 0.0
    )
    cert = LoadCertificate(
        kind=LOAD_NOT_HELD if mode == "refute" else PAYLOAD_BOUND,
        cones=P.cones,
        num_generators=P.num_generators,
        wrench=np.asarray(wrench, dtype=float).copy(),
        twist=y,
        joint_multipliers=eta,
        normal_multipliers=rho,
        squeeze_multiplier=sigma,
        torque_limits=None if P.torque_limits is None else P.torque_limits.copy(),
        max_normal_force=P.max_normal_force.copy(),
        max_squeeze=P.max_squeeze,
        bound=0.0,
    )
    power = -float(y @ cert.wrench)
    bound = cert.power_budget() / power if power > 0.0 else np.inf
    object.__setattr__(cert, "bound", float(bound))
    return cert
