r"""Payload: the largest multiple of a load that a hand holds within its limits.

:func:`max_load` solves

.. math::

    \max_{\alpha, f} \alpha \;\text{s.t.}\; G f = -\alpha\, w_d,\;
    f_i \in K_i,\; |J^T f| \le \tau_{\max},\; 0 \le f_{n,i} \le f_{\max,i},\;
    \textstyle\sum_i f_{n,i} \le s_{\max}

for a load direction ``w_d`` (e.g. the gravity wrench of the object: ``α`` is
then the payload factor, ``α >= 1`` holds the object).  It refines
:func:`~drakegrasp.max_resistible_wrench`, which bounds normal forces but knows
no motors: with ``max_normal_force`` only and polyhedral cones the two agree.
The answer comes with a dual certificate
(:class:`~drakegrasp.certificates.load.LoadCertificate`, kind ``"payload
bound"``) that no ``α`` above ``upper_bound`` can be held, and with the
forces, torques and the joints that limit it at ``α*``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np
from pydrake.solvers import MathematicalProgram, SolutionResult

from drakegrasp._solvers import solve
from drakegrasp.certificates.load import LoadCertificate
from drakegrasp.closure.constraints import add_linear_constraint
from drakegrasp.closure.force_dual import find_load_certificate
from drakegrasp.closure.load_problem import (
    FEASIBILITY_TOL,
    LoadProblem,
    add_balance,
    add_force_constraints,
    check_direction,
    load_problem,
    saturating_joints,
)
from drakegrasp.core.calls import checked_call
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import check_flag
from drakegrasp.errors import SolverError

__all__ = ["ALPHA_CAP", "MaxLoadResult", "build_max_load_program", "max_load"]

ALPHA_CAP = 1e8
"""In the program's units, ``α`` is capped here; the dual decides an answer at it."""

_AGREE = 1e-6
"""Relative gap allowed between the rescaled ``α*`` and its dual bound."""


@checked_call
@dataclass(frozen=True, eq=False)
class MaxLoadResult:
    """The largest multiple of a load direction that the grasp holds.

    Attributes
    ----------
    alpha : float
        ``α*``: the payload factor (``inf`` when no limit binds along the
        direction, 0 when not even a small load along it can be held).
    direction : (6,) or (3,) float
        The load direction ``w_d = [f; m]`` about ``p``, grasp frame.
    wrench : (6,) or (3,) float
        ``α* w_d`` (zeros when ``α*`` is infinite).
    upper_bound : float
        The bound proven by ``certificate`` (equal to ``alpha`` up to the
        solvers' accuracy, never below it); ``inf`` without a certificate.
    contact_forces : tuple of ndarray
        The forces at ``α*`` per contact, contact frame, normal first (N);
        zeros when ``α*`` is infinite (as ``wrench``).
    joint_torques : (n_v,) float or None
        ``τ = Jᵀ f`` at ``α*``.
    squeeze : float
        ``Σ f_n`` at ``α*`` (N); 0 when ``α*`` is infinite.
    saturating_joints : tuple of int
        Joints at their torque limit at ``α*`` (the ones that limit the
        payload, with the cones and the force bounds), most loaded first.
    saturating_contacts : tuple of int
        Contacts whose ``f_n`` is at its bound at ``α*``.
    cones : str
    num_generators : int
    solver, status : str
    certificate : LoadCertificate or None
        Kind ``"payload bound"``: re-check with
        ``certificate.check(grasp, hand_jacobian=J)``.
    """

    alpha: float
    direction: np.ndarray
    wrench: np.ndarray
    upper_bound: float
    contact_forces: tuple[np.ndarray, ...]
    joint_torques: np.ndarray | None
    squeeze: float
    saturating_joints: tuple[int, ...]
    saturating_contacts: tuple[int, ...]
    cones: str
    num_generators: int
    solver: str
    status: str
    certificate: LoadCertificate | None = None

    def to_dict(self) -> dict:
        """JSON-ready dictionary (non-finite numbers become ``None``)."""
        return {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}

    def __str__(self) -> str:
        d = np.round(self.direction, 6).tolist()
        lines = [f"max load: alpha = {self.alpha:.6g} x {d} ({self.cones} cones)"]
        if math.isfinite(self.alpha):
            lines.append(
                f"  proven bound {self.upper_bound:.6g}; squeeze {self.squeeze:.6g} N"
            )
            joints = list(self.saturating_joints) or "none"
            contacts = list(self.saturating_contacts) or "none"
            lines.append(
                f"  limited by joints {joints}, contacts at their f_n bound {contacts}"
            )
        lines.append(f"  solver {self.solver} ({self.status})")
        return "\n".join(lines)


@checked_call
def build_max_load_program(
    grasp: Grasp,
    direction: np.ndarray,
    *,
    hand_jacobian: np.ndarray | None = None,
    torque_limits: np.ndarray | float | None = None,
    max_normal_force: np.ndarray | float | None = None,
    max_squeeze: float | None = None,
    cones: str = "exact",
    num_generators: int = DEFAULT_NUM_GENERATORS,
):
    """Build the payload program (unsolved); see :func:`max_load`.

    Returns
    -------
    prog : MathematicalProgram
        ``max α`` in program units (forces over ``F0``, ``α`` over
        ``F0 / max|T w_d|``).
    x : ndarray of Variable
        Force variables (components ``F0 * scales * x``).
    alpha : Variable
        ``α`` in program units.
    problem : LoadProblem
    scales : (float, float)
        ``(F0, α unit)``: ``α* = alpha_unit * alpha``.
    """
    d = check_direction(grasp, direction)
    P = load_problem(
        grasp,
        hand_jacobian=hand_jacobian,
        torque_limits=torque_limits,
        max_normal_force=max_normal_force,
        max_squeeze=max_squeeze,
        cones=cones,
        num_generators=num_generators,
    )
    return _build(P, d)


def _build(P: LoadProblem, d: np.ndarray, alpha_unit: float | None = None):
    """The program; ``α`` in units of ``alpha_unit`` (default ``F0 / size``)."""
    target = P.normalised(d)
    size = float(np.max(np.abs(target)))
    if alpha_unit is None:
        F0 = P.force_scale(None)
        column, unit = target / size, F0 / size
    else:
        # Forces in units of the load α_unit d over the largest μ (the forces
        # of a friction-scaled problem, see LoadProblem.friction_scaled).
        unit = alpha_unit
        F0 = unit * size / P.tangent_scale
        column = (target / size) * P.tangent_scale  # a subnormal size: no inf
    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(P.num_forces, "f")
    alpha = prog.NewContinuousVariables(1, "alpha")[0]
    prog.AddBoundingBoxConstraint(0.0, ALPHA_CAP, alpha)
    prog.AddLinearCost(-1.0 * alpha)
    add_force_constraints(prog, P, x, F0)
    # Ḡ f + α T d = 0 with f = F0 x and α = unit α̃.
    add_balance(prog, P, x, column, alpha=alpha)
    return prog, x, alpha, P, (F0, unit)


def _solved(prog, result, what: str):
    status = result.get_solution_result()
    if status != SolutionResult.kSolutionFound:
        raise SolverError(
            f"{result.get_solver_id().name()} failed with status {status.name} on "
            f"the payload program{what} (always feasible with α = 0, f = 0): a "
            "numerical failure, not a verdict",
            program=prog,
            result=result,
        )
    return result


def _rescaled(P: LoadProblem, d: np.ndarray, alpha_unit: float, bound: float):
    """Re-solve with ``α`` in units of ``alpha_unit``, friction-scaled.

    For ``μ`` far above 1 the newton-unit program is ill-conditioned (the
    tangential forces are ``μ`` times the normal ones) and ``α`` may pass
    :data:`ALPHA_CAP`; here the cones read ``‖x_t‖ <= x_n`` and ``α̃`` is
    about 1 when ``alpha_unit`` is the dual ``bound``.  The forces are
    re-checked against every constraint and ``α`` against a finite ``bound``.
    Returns ``(result, α, forces, capped)``; ``capped``: ``α̃`` at the cap.
    """
    Ps = P.friction_scaled()
    prog, x, alpha, _, (F0, unit) = _build(Ps, d, alpha_unit=alpha_unit)
    result = _solved(prog, solve(prog, Ps.kind, retry=True), " (rescaled)")
    a_tilde = max(float(result.GetSolution(alpha)), 0.0)
    capped = a_tilde >= ALPHA_CAP * (1.0 - 1e-6)
    a = a_tilde * unit
    full = Ps.stacked(result.GetSolution(x), F0)
    excess, what = P.violation(full, a * d)
    gap = abs(a - bound) if math.isfinite(bound) else 0.0
    if not capped and excess <= FEASIBILITY_TOL and gap > _AGREE * bound:
        # Forces that hold α short of the bound: at a huge μ whose motors
        # bind the tangential forces the normal forces are nearly free, an
        # interior point squeezed 80 units of them (1e-6 of a motor's row)
        # and α came out that much short.  The least squeeze at that α, then
        # the most α at that squeeze, take the slack back.
        polished = _polished(Ps, d, alpha_unit, a_tilde)
        if polished is not None:
            result, a2, full2 = polished
            excess2, what2 = P.violation(full2, a2 * d)
            if excess2 <= FEASIBILITY_TOL and a2 > a:
                a, full, excess, what = a2, full2, excess2, what2
                gap = abs(a - bound)
    if not capped and (excess > FEASIBILITY_TOL or gap > _AGREE * bound):
        raise SolverError(
            f"{result.get_solver_id().name()} found α = {a:.9g} on the rescaled "
            f"payload program, its dual bound is {bound:.9g}, and the forces "
            f"violate the constraints by {excess:.2g} (relative, at {what}): the "
            "payload is not known to the solvers' accuracy",
            program=prog,
            result=result,
        )
    return result, a, full, capped


def _polished(Ps: LoadProblem, d, alpha_unit: float, a_tilde: float):
    """``(result, α, forces)`` of :func:`_rescaled`'s two-stage polish, or None.

    The least squeeze that holds ``α̃ >= a_tilde``, then the largest ``α̃``
    within that squeeze and 1e-3 of it (a larger ``α`` needs a little more).
    """
    normals = Ps.layout.normal_positions
    prog, x1, alpha, _, (F0, unit) = _build(Ps, d, alpha_unit=alpha_unit)
    prog.AddBoundingBoxConstraint(a_tilde, ALPHA_CAP, alpha)
    prog.AddLinearCost(np.ones(len(normals)), 0.0, x1[normals])
    first = solve(prog, Ps.kind, retry=True)
    if first.get_solution_result() != SolutionResult.kSolutionFound:
        return None
    squeeze = float(np.sum(first.GetSolution(x1)[normals]))
    prog, x2, alpha, _, (F0, unit) = _build(Ps, d, alpha_unit=alpha_unit)
    add_linear_constraint(
        prog,
        np.ones((1, len(normals))),
        [-np.inf],
        [squeeze * (1.0 + 1e-3)],
        x2[normals],
    )
    second = solve(prog, Ps.kind, retry=True)
    if second.get_solution_result() != SolutionResult.kSolutionFound:
        return None
    a = max(float(second.GetSolution(alpha)), 0.0) * unit
    return second, a, Ps.stacked(second.GetSolution(x2), F0)


def _homogeneous(P: LoadProblem) -> bool:
    """Whether every finite limit of the problem is 0 (its α is 0 or inf).

    A torque limit counts as the force it allows, ``τ_max / ‖J_j‖``: 5e-324
    N·m on a column of norm 2 is 0 N.
    """
    limits = [P.max_normal_force, [P.max_squeeze]]
    if P.torque_limits is not None:
        limits.append(P.torque_limits / P.jscale)
    values = np.concatenate([np.asarray(x, dtype=float) for x in limits])
    return not np.any(np.isfinite(values) & (values > 0.0))


def _verified(P: LoadProblem, cert: LoadCertificate) -> bool:
    """Whether a payload certificate of the dual holds on the problem's grasp."""
    return cert.check(P.grasp, hand_jacobian=P.hand_jacobian).holds


def _held_without_limits(P: LoadProblem, d: np.ndarray) -> bool:
    """Whether the grasp provably holds ``d`` with every finite limit at zero.

    These are the limits' recession cone: ``α d`` is held for every ``α``
    exactly when ``d`` is.  The program is homogeneous, so its ``α̃`` is 0 or
    :data:`ALPHA_CAP`; it is solved in newtons and friction-scaled (each
    scaling fails somewhere past ``μ = 1e10``), and "held" needs forces that
    re-check (:meth:`LoadProblem.violation`): a feasible point is its proof.
    """
    finite = np.isfinite
    zero = replace(
        P,
        torque_limits=None
        if P.torque_limits is None
        else np.where(finite(P.torque_limits), 0.0, np.inf),
        max_normal_force=np.where(finite(P.max_normal_force), 0.0, np.inf),
        max_squeeze=0.0 if math.isfinite(P.max_squeeze) else math.inf,
    )
    scaled = zero.friction_scaled()
    for Q in (zero,) if scaled is zero else (zero, scaled):
        prog, x, alpha, _, (F0, unit) = _build(Q, d, alpha_unit=1.0)
        result = solve(prog, Q.kind, retry=True)
        if result.get_solution_result() != SolutionResult.kSolutionFound:
            continue
        a = float(result.GetSolution(alpha))
        # α at the cap times a huge load's force scale (1e300 N) may overflow
        # to inf: such forces re-check as no proof, and say so by their value.
        with np.errstate(over="ignore", invalid="ignore"):
            full = Q.stacked(result.GetSolution(x), F0)
            excess = Q.violation(full, a * unit * d)[0]
        if a >= 0.5 * ALPHA_CAP and excess <= FEASIBILITY_TOL:
            return True
    return False


@checked_call
def max_load(
    grasp: Grasp,
    direction: np.ndarray,
    *,
    hand_jacobian: np.ndarray | None = None,
    torque_limits: np.ndarray | float | None = None,
    max_normal_force: np.ndarray | float | None = None,
    max_squeeze: float | None = None,
    cones: str = "exact",
    num_generators: int = DEFAULT_NUM_GENERATORS,
    certify: bool = True,
) -> MaxLoadResult:
    """The largest ``α`` such that the grasp holds the load ``α · direction``.

    The program is solved with ``α`` capped at :data:`ALPHA_CAP` in its
    units; an answer at the cap, or any answer with a ``μ`` above
    :data:`~drakegrasp.closure.load_problem.FRICTION_SCALING`, is settled by
    the dual: none (no limit binds) is ``α = inf``; a finite bound is
    re-solved in units of that bound, friction-scaled, and re-checked.

    Parameters
    ----------
    grasp : Grasp
    direction : (6,) or (3,) float
        Load direction ``[f; m]`` about ``p``, grasp frame (the object's
        gravity wrench gives the payload factor).
    hand_jacobian : (M, n_v) float, optional
        ``J``; with ``torque_limits`` the motors bound the load.
    torque_limits : float or (n_v,) float, optional
        ``τ_max`` per joint (``inf`` = none, ``0`` = passive).
    max_normal_force : float or (N,) float, optional
        Bound on each contact's ``f_n`` (N).
    max_squeeze : float, optional
        Bound on ``Σ f_n`` (N).
    cones : {"exact", "polyhedral"}, optional
    num_generators : int, optional
    certify : bool, optional
        Also solve the dual for a re-checkable bound (default True).  Without
        it ``alpha`` is the primal solver's, accurate to its tolerance: where
        the true payload is 0 it can come out up to about 1e-5 (measured, exact
        cones), and two such runs need not be monotone in the limits at that
        level.  With it ``alpha`` never exceeds the re-checked bound.

    Returns
    -------
    MaxLoadResult
        ``alpha = inf`` when nothing bounds the forces along the direction.

    Raises
    ------
    SolverError
        The program (always feasible: ``α = 0``, ``f = 0``) was not solved.
    """
    d = check_direction(grasp, direction)
    certify = check_flag("certify", certify)
    prog, x, alpha, P, (F0, unit) = build_max_load_program(
        grasp,
        d,
        hand_jacobian=hand_jacobian,
        torque_limits=torque_limits,
        max_normal_force=max_normal_force,
        max_squeeze=max_squeeze,
        cones=cones,
        num_generators=num_generators,
    )
    result = _solved(prog, solve(prog, P.kind, retry=True), "")
    a = max(float(result.GetSolution(alpha)), 0.0)
    full = P.stacked(result.GetSolution(x), F0)
    capped = a >= ALPHA_CAP * (1.0 - 1e-6)
    value = a * unit
    big_mu = P.friction_scaled() is not P
    cert, bound = None, math.inf
    if certify or capped or big_mu:
        # Reaching the cap is no proof of unboundedness (at μ = 1e8 the
        # payload passes it), nor is a solution at μ >> 1 right: the dual
        # decides.  No dual direction: no limit binds, α is unbounded.
        cert, bound = find_load_certificate(P, d, mode="bound", force_scale=F0)
        if bound == 0.0 and not _verified(P, cert):
            # At μ = 1e12 the dual returned "α <= 0" for a load a finger
            # pushes without limit: a zero bound decides only if it re-checks.
            cert, bound = None, math.inf
    unbounded = False
    if bound == 0.0 and (capped or big_mu):
        # A re-checked proof that no multiple is held has no program in units
        # of the bound (0) to solve, so α = 0 with no forces, unless the
        # friction-scaled program holds some (at μ = 1e-12 the check passed a
        # dual that missed a bound of 2 μ f_max): then nothing is known.
        if value > 0.0:
            result, again, _, _ = _rescaled(P, d, value, math.inf)
            if again > _AGREE * value:
                raise SolverError(
                    f"the payload's dual bound is 0 but the friction-scaled "
                    f"program holds α = {again:.9g}: the payload is not known to "
                    "the solvers' accuracy",
                    program=prog,
                    result=result,
                )
        value, full = 0.0, np.zeros_like(full)
    elif math.isfinite(bound) and (capped or big_mu):
        if (
            capped
            or P.violation(full, value * d)[0] > FEASIBILITY_TOL
            or (abs(value - bound) > _AGREE * bound)
        ):
            result, value, full, _ = _rescaled(P, d, bound, bound)
    elif capped or big_mu:
        # No dual bound: none exists, or the conic solver missed it at a huge
        # μ.  Unbounded needs its proof (:func:`_held_without_limits`); a
        # finite answer needs the dual's, so without one it is refused.
        unbounded = _held_without_limits(P, d)
        if not unbounded:
            raise SolverError(
                f"the payload program reached α = {value:.9g}, no dual bound was "
                "found and the load is not held with the limits at zero: the "
                "payload is not known to the solvers' accuracy (a friction "
                f"coefficient of {P.friction_scaled().tangent_scale:.3g} is past "
                "what the conic solvers resolve)",
                program=prog,
                result=result,
            )
    if not unbounded and value > bound and _verified(P, cert):
        # α above a bound whose certificate re-checks is the solvers' noise
        # (exact cones whose α* is 0 returned α = 3.5e-6 over a bound of
        # 2.1e-6): α is the bound, and the forces shrink with it, which keeps
        # every cone and every limit (they are cones and upper bounds).
        full = full * (bound / value)
        value = bound
    if not unbounded and value > 0.0 and _homogeneous(P):
        # Every finite limit 0 (passive joints, max_squeeze = 0): α is 0 or
        # inf, never the 1e-10 of the solvers' tolerance it was reported as.
        unbounded = _held_without_limits(P, d)
        if not unbounded:
            value, full = 0.0, np.zeros_like(full)
    if unbounded:
        # The forces of the capped program hold ALPHA_CAP in its units, not α*
        # (5.7e9 N were reported beside α = inf): none, as the wrench is.
        value, full = math.inf, np.zeros_like(full)
    if not certify:
        cert, bound = None, math.inf
    tau = P.joint_torques(full)
    sat, _ = saturating_joints(tau, P.torque_limits)
    normals = P.grasp.normal_indices()
    fn = full[normals]
    fmax = P.max_normal_force
    at = np.flatnonzero(np.isfinite(fmax) & (fn >= fmax * (1 - 1e-6)) & (fmax > 0))
    return MaxLoadResult(
        alpha=value,
        direction=d.copy(),
        wrench=np.zeros_like(d) if unbounded else value * d,
        upper_bound=float(bound),
        contact_forces=P.per_contact(full),
        joint_torques=tau,
        squeeze=float(np.sum(fn)),
        saturating_joints=sat,
        saturating_contacts=tuple(int(i) for i in at),
        cones=P.cones,
        num_generators=P.num_generators,
        solver=result.get_solver_id().name(),
        status="unbounded (no limit binds along the direction)"
        if unbounded
        else result.get_solution_result().name,
        certificate=cert,
    )
