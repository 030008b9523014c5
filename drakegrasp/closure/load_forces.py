r"""Grasp-force optimisation: contact forces and joint torques that hold a load.

:func:`grasp_forces` looks for contact forces ``f`` (contact frames, normal
first) in the friction cones that balance an external wrench ``w`` on the
object, ``G f = -w`` (``w = [f; m]`` about the grasp's reference point ``p``,
grasp frame: the contacts supply ``-w``), and, with a hand Jacobian ``J``,
joint torques ``τ = Jᵀ f`` within ``|τ_j| <= τ_max,j``.  Among them it picks

* ``"min_squeeze"``: the least total normal force ``Σ f_n`` (how hard the hand
  must squeeze);
* ``"min_torque"``: the least largest ``|τ_j| / τ_max,j`` (``|τ_j|`` in N·m
  without limits), then the least squeeze among those;
* ``"max_margin"``: the largest ``d`` with every force at least ``d`` (N)
  inside its cone, for a bounded squeeze (``max_squeeze``, or per-contact
  ``max_normal_force``) — the most robust forces the hand may use.

Exact cones (default) make the program an SOCP (Lorentz cones; planar cones
are exact polyhedra); ``cones="polyhedral"`` uses the inscribed cones with
``num_generators`` edges (an LP; conservative).  When no admissible forces
exist, the result carries a
:class:`~drakegrasp.certificates.load.LoadCertificate` that anyone can
re-check without a solver.  :func:`build_grasp_forces_program` returns the
program unsolved.

This is a statement about forces; it is unrelated to LP2's ``d*``, which
measures how far the best *internal* force (no load) sits from the cone
boundaries and says nothing of the load a grasp can carry.
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
    check_wrench,
    effort_unit_of,
    load_problem,
    saturating_joints,
)
from drakegrasp.core.calls import checked_call
from drakegrasp.core.grasp import Grasp, grasp_matrix
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import describe, plain_str, safe_norm
from drakegrasp.errors import InvalidOptionError, SolverError

__all__ = [
    "OBJECTIVES",
    "GraspForceResult",
    "GraspForceVariables",
    "build_grasp_forces_program",
    "grasp_forces",
]

OBJECTIVES = ("min_squeeze", "min_torque", "max_margin")
"""The objectives of :func:`grasp_forces`."""


_TIE = 1e-7
"""``min_torque`` re-solves for the least squeeze at a ratio ``<= t* (1 + _TIE)``,
plus ``_TIE`` of the ratio's natural size (that of one unit of the program's
force variables on the most sensitive joint), so the slack never depends on the
size of the load or of the limits."""


@checked_call
@dataclass(frozen=True)
class GraspForceVariables:
    """Decision variables of :func:`build_grasp_forces_program`.

    Attributes
    ----------
    x : ndarray of Variable, (m,)
        The program's force variables; the force components are
        ``forces = force_scale * scales * x`` (N).
    forces : ndarray of Expression, (m,)
        The contact-force components the cones allow, N, contact frames.
    columns : (m,) int
        Where each entry of ``forces`` sits in the stacked force vector
        (columns of :func:`~drakegrasp.grasp_matrix`).
    normal_positions : (N,) int
        Index in ``forces`` of each contact's ``f_n``.
    force_scale : float
        ``F0``, N: the load's size (``max |T w|``), the program's unit of force.
    ratio : Variable or None
        ``min_torque``: the largest ``|τ_j| / τ_max,j`` (minimised) over
        ``force_scale``, so that the program's entries do not grow or shrink
        with the load: ``force_scale * ratio`` is the ratio (1 without limits,
        where ``τ_max,j`` is 1 N·m).
    margin : Variable or None
        ``max_margin``: ``d / F0``, each force's distance inside its cone.
    """

    x: np.ndarray
    forces: np.ndarray
    columns: np.ndarray
    normal_positions: np.ndarray
    force_scale: float
    ratio: object = None
    margin: object = None


@checked_call
@dataclass(frozen=True, eq=False)
class GraspForceResult:
    r"""Contact forces and joint torques that hold a load, or why none exist.

    Attributes
    ----------
    feasible : bool
        True when forces within the cones and limits balance the load.
    objective : str
        ``"min_squeeze"``, ``"min_torque"`` or ``"max_margin"``.
    cones : str
        ``"exact"`` or ``"polyhedral"``.
    wrench : (6,) or (3,) float
        The external wrench on the object, ``[f; m]`` about ``p`` (N, N·m).
    contact_forces : tuple of ndarray or None
        Per contact, in its contact frame, normal first (N; soft finger's
        ``m_n`` in N·m); they satisfy ``G f = -wrench``.  None when infeasible.
    joint_torques : (n_v,) float or None
        ``τ = Jᵀ f`` (N·m, or N for prismatic joints); None without ``J`` or
        when infeasible.
    squeeze : float
        ``Σ f_n`` (N); NaN when infeasible.
    torque_usage : float
        ``max_j |τ_j| / τ_max,j`` over joints with a finite positive limit
        (1 = a motor at its limit); NaN without such limits.
    saturating_joints : tuple of int
        Joints (columns of ``J``) at their limit, most loaded first:
        ``|τ_j| >= (1 - SATURATION_TOL) τ_max,j``
        (:data:`~drakegrasp.closure.load_problem.SATURATION_TOL`).
    margin : float
        ``max_margin``: the smallest distance of a contact force inside its
        cone, N; NaN for the other objectives.
    torque_limits : (n_v,) float or None
        The limits used (``inf`` = none).
    balance_residual : float
        ``‖G f + w‖ / max(‖w‖, ‖G‖ ‖f‖)`` of the returned forces.
    num_generators : int
    solver, status : str
        The primal program's solver and status.
    certificate : LoadCertificate or None
        Infeasible: the dual direction that proves it (re-check with
        ``certificate.check(grasp, hand_jacobian=J)``); None when feasible, or
        when the infeasibility is too weak for a separating direction.
    """

    feasible: bool
    objective: str
    cones: str
    wrench: np.ndarray
    contact_forces: tuple[np.ndarray, ...] | None
    joint_torques: np.ndarray | None
    squeeze: float
    torque_usage: float
    saturating_joints: tuple[int, ...]
    margin: float
    torque_limits: np.ndarray | None
    balance_residual: float
    num_generators: int
    solver: str
    status: str
    certificate: LoadCertificate | None = None

    def stacked_forces(self) -> np.ndarray:
        """The contact forces as one (M,) vector in ``G``'s column order."""
        if self.contact_forces is None:
            return np.zeros(0)
        return np.concatenate(self.contact_forces)

    def to_dict(self) -> dict:
        """JSON-ready dictionary (non-finite numbers become ``None``)."""
        return {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}

    def __str__(self) -> str:
        w = np.round(self.wrench, 6).tolist()
        head = f"grasp forces ({self.objective}, {self.cones} cones) for load {w}"
        if not self.feasible:
            lines = [f"{head}: NOT HELD ({self.solver}: {self.status})"]
            if self.certificate is not None:
                lines.append(f"  proof: {self.certificate}")
            return "\n".join(lines)
        fn = ", ".join(f"{f[0]:.4g}" for f in self.contact_forces)
        lines = [
            f"{head}: held",
            f"  squeeze {self.squeeze:.6g} N; normal forces [{fn}] N",
        ]
        if self.joint_torques is not None:
            tau = ", ".join(f"{t:.4g}" for t in self.joint_torques)
            unit = effort_unit_of(("N·m", "N"))  # a joint turns or slides
            lines.append(f"  joint torques [{tau}] ({unit})")
        if not math.isnan(self.torque_usage):
            sat = list(self.saturating_joints) or "none"
            lines.append(
                f"  torque usage {self.torque_usage:.4g} of the limits; "
                f"saturating joints: {sat}"
            )
        if not math.isnan(self.margin):
            lines.append(f"  margin {self.margin:.6g} N inside every cone")
        lines.append(f"  solver {self.solver} ({self.status})")
        return "\n".join(lines)


def _check_objective(objective) -> str:
    objective = plain_str(objective)
    if type(objective) is not str or objective not in OBJECTIVES:
        raise InvalidOptionError(
            f"objective must be one of {OBJECTIVES}, got {describe(objective)}"
        )
    return objective


def _torque_weights(P: LoadProblem) -> tuple[np.ndarray, np.ndarray]:
    """Joints that enter ``min_torque``'s ratio and their weights (N·m)."""
    n_v = P.Jt.shape[0]
    if P.torque_limits is None:
        return np.arange(n_v), np.ones(n_v)
    lim = P.torque_limits
    use = np.flatnonzero(np.isfinite(lim) & (lim > 0.0))
    return use, lim[use]


@checked_call
def build_grasp_forces_program(
    grasp: Grasp,
    wrench: np.ndarray,
    *,
    hand_jacobian: np.ndarray | None = None,
    torque_limits: np.ndarray | float | None = None,
    objective: str = "min_squeeze",
    cones: str = "exact",
    num_generators: int = DEFAULT_NUM_GENERATORS,
    max_normal_force: np.ndarray | float | None = None,
    max_squeeze: float | None = None,
    _ratio_cap: float | None = None,
) -> tuple[MathematicalProgram, GraspForceVariables]:
    r"""Build the grasp-force program (unsolved); see :func:`grasp_forces`.

    Parameters
    ----------
    grasp : Grasp
    wrench : (6,) or (3,) float
        External wrench on the object ``w = [f; m]`` (N, N·m) about ``p``,
        grasp frame (e.g. gravity ``[m g; (c_m - p) × m g]``).
    hand_jacobian : (M, n_v) float, optional
        ``J``: rows in ``G``'s column order; joint torques ``τ = Jᵀ f``.
    torque_limits : float or (n_v,) float, optional
        ``τ_max >= 0`` per joint (``inf`` = none; ``0`` = a passive joint that
        must carry no torque).  Needs ``hand_jacobian``.
    objective : {"min_squeeze", "min_torque", "max_margin"}, optional
    cones : {"exact", "polyhedral"}, optional
    num_generators : int, optional
        Generators of each polyhedral cone (default 8).
    max_normal_force : float or (N,) float, optional
        Bound on each contact's ``f_n``, N.
    max_squeeze : float, optional
        Bound on ``Σ f_n``, N; ``max_margin`` needs it (or finite
        ``max_normal_force`` at every contact).

    Returns
    -------
    prog : MathematicalProgram
        .. math:: \min\ \text{objective} \;\text{s.t.}\; \bar G f = -T w,\;
                  f_i \in K_i,\; |J^T f| \le \tau_{\max},\;
                  0 \le f_{n,i} \le f_{\max,i},\; \textstyle\sum f_n \le s_{\max}

        in units of ``F0`` (see :mod:`~drakegrasp.closure.load_problem`).
    variables : GraspForceVariables
    """
    objective = _check_objective(objective)
    w = check_wrench(grasp, wrench)
    P = load_problem(
        grasp,
        hand_jacobian=hand_jacobian,
        torque_limits=torque_limits,
        max_normal_force=max_normal_force,
        max_squeeze=max_squeeze,
        cones=cones,
        num_generators=num_generators,
    )
    return _build(P, w, objective, ratio_cap=_ratio_cap)


def _build(P: LoadProblem, w: np.ndarray, objective: str, *, ratio_cap=None):
    # Friction-scaled (μ >> 1): tangential forces of the load's size are
    # μ F0 x_t, so F0 is the load over μ (tangent_scale is 1 otherwise).
    F0 = P.force_scale(w) / P.tangent_scale
    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(P.num_forces, "f")
    normals = P.layout.normal_positions
    margin = ratio = None
    if objective == "max_margin":
        if not (
            math.isfinite(P.max_squeeze) or np.all(np.isfinite(P.max_normal_force))
        ):
            raise InvalidOptionError(
                "objective='max_margin' needs a bounded squeeze: pass max_squeeze "
                "(N, the bound on the total normal force) or a finite "
                "max_normal_force for every contact"
            )
        margin = prog.NewContinuousVariables(1, "d")[0]
        prog.AddBoundingBoxConstraint(0.0, np.inf, margin)
        prog.AddLinearCost(-1.0 * margin)
    A_tau = add_force_constraints(prog, P, x, F0, d=margin)
    add_balance(prog, P, x, -P.normalised(w) / F0)
    if objective in ("min_squeeze",) or ratio_cap is not None:
        prog.AddLinearCost(np.ones(len(normals)), 0.0, x[normals])
    if objective == "min_torque":
        if P.hand_jacobian is None:
            raise InvalidOptionError(
                "objective='min_torque' needs the hand_jacobian (τ = Jᵀ f)"
            )
        use, weight = _torque_weights(P)
        ratio = prog.NewContinuousVariables(1, "t")[0]
        prog.AddBoundingBoxConstraint(
            0.0, np.inf if ratio_cap is None else ratio_cap, ratio
        )
        if ratio_cap is None:
            prog.AddLinearCost(1.0 * ratio)
        if use.size:
            # |τ_j| <= t w_j with τ_j = c_j F0 (A_τ x)_j and t = F0 r (r is
            # the variable): F0 cancels, so a load of any size gives the
            # same rows (a subnormal F0 made k infinite, a large one tiny).
            k = (weight / P.jscale[use])[:, None]
            rows = np.vstack(
                [np.hstack([A_tau[use], -k]), np.hstack([-A_tau[use], -k])]
            )
            add_linear_constraint_rows(prog, rows, np.append(x, ratio))
    with np.errstate(invalid="ignore"):
        forces = (F0 * P.layout.scales) * x
    variables = GraspForceVariables(
        x=x,
        forces=forces,
        columns=P.layout.columns,
        normal_positions=normals,
        force_scale=F0,
        ratio=ratio,
        margin=margin,
    )
    return prog, variables


def add_linear_constraint_rows(prog, rows: np.ndarray, z) -> None:
    """``rows z <= 0``."""
    add_linear_constraint(
        prog, rows, np.full(len(rows), -np.inf), np.zeros(len(rows)), z
    )


def _load_text(w: np.ndarray) -> str:
    """A load for a message, to 9 significant digits.

    ``np.round(w, 9)`` overflowed, with a RuntimeWarning, past 1e299 N.
    """
    return "[" + ", ".join(f"{x:.9g}" for x in w) + "]"


def _solved(P, w, objective, result, v, F0) -> GraspForceResult:
    xv = result.GetSolution(v.x)
    with np.errstate(over="ignore", invalid="ignore"):
        full = P.stacked(xv, F0)
    if not np.all(np.isfinite(full)):
        # 1e300 N at μ = 1e-12 needs normal forces of 1e312 N: "held" with
        # forces inf and nan was no answer
        raise SolverError(
            f"the forces that hold the load {_load_text(w)} pass the "
            "largest float (1.8e308 N): the load is too large for this grasp's "
            "friction to compute"
        )
    margin = (
        float(F0 * result.GetSolution(v.margin)) if v.margin is not None else math.nan
    )
    return _held_by(
        P, w, objective, full, margin=margin,
        solver=result.get_solver_id().name(),
        status=result.get_solution_result().name,
    )  # fmt: skip


def _held_by(P: LoadProblem, w, objective, full, *, margin, solver, status):
    """The feasible result of stacked forces ``full`` for the load ``w``."""
    tau = P.joint_torques(full)
    sat, usage = saturating_joints(tau, P.torque_limits)
    G = grasp_matrix(P.grasp)
    # safe norms: a load of 1e300 N has a norm, not an overflow warning
    scale = max(
        float(safe_norm(w)),
        float(np.linalg.norm(G, 2)) * float(safe_norm(full)),
        1e-300,
    )
    normals = P.grasp.normal_indices()
    return GraspForceResult(
        feasible=True,
        objective=objective,
        cones=P.cones,
        wrench=w.copy(),
        contact_forces=P.per_contact(full),
        joint_torques=tau,
        squeeze=float(np.sum(full[normals])),
        torque_usage=usage,
        saturating_joints=sat,
        margin=margin,
        torque_limits=_limits_copy(P),
        balance_residual=float(safe_norm(G @ full + w)) / scale,
        num_generators=P.num_generators,
        solver=solver,
        status=status,
    )


def _zero_forces(P: LoadProblem, w: np.ndarray, objective: str) -> GraspForceResult:
    """The exact answer to a zero load: every force zero (in every cone)."""
    full = np.zeros(P.grasp.num_components)
    return _held_by(
        P, w, objective, full, margin=math.nan, solver="none (a zero load)",
        status="kSolutionFound",
    )  # fmt: skip


def _refutation_reaches(P, w, cert, prog, result) -> None:
    """Refuse a "not held" whose proof stops short of the forces friction needs.

    A refutation proves the load cannot be held by forces whose total normal
    force stays below its reach (:meth:`LoadCertificate.force_reach`; round-off
    in the twist's cone supports).  With a tiny ``μ`` a load may need
    ``|w| / μ`` of normal force: at ``μ = (0.5, 1e-12)`` a planar pinch holds
    1 N with 1e12 N, and a refutation reaching 5e11 N said "not held".
    """
    mus = [c.mu for c in P.grasp.contacts if c.mu > 0.0]
    if not mus:
        return
    D = len(w)
    f, m = (w[:2], w[2:]) if D == 3 else (w[:3], w[3:])
    size = max(float(safe_norm(f)), float(safe_norm(m)) / P.grasp.characteristic_length)
    need = size / min(mus)
    reach = cert.force_reach(P.grasp, hand_jacobian=P.hand_jacobian)
    if not reach > 0.0:
        raise SolverError(
            f"{result.get_solver_id().name()} found no forces that hold the load, "
            "and the dual's refutation proves nothing (the load's power along "
            "its twist does not exceed the limits' budget): undecided",
            program=prog,
            result=result,
        )
    if reach < need:
        raise SolverError(
            f"{result.get_solver_id().name()} found no forces that hold the load, "
            f"but the refutation is proven only for total normal force below "
            f"{reach:.3g} N, and at mu = {min(mus):g} the load may need "
            f"{need:.3g} N (|w| / mu): undecided; a mu this far from 1 is past "
            "what the solvers resolve",
            program=prog,
            result=result,
        )


def _infeasible(P, w, objective, prog, result, F0) -> GraspForceResult:
    cert, _ = find_load_certificate(P, w, mode="refute", force_scale=F0)
    status = result.get_solution_result()
    proven = status in (
        SolutionResult.kInfeasibleConstraints,
        SolutionResult.kInfeasibleOrUnbounded,
    )
    if cert is None and not proven:
        raise SolverError(
            f"{result.get_solver_id().name()} failed with status {status.name} on "
            "the grasp-force program, and no dual direction proves it infeasible",
            program=prog,
            result=result,
        )
    if cert is not None:
        _refutation_reaches(P, w, cert, prog, result)
    return GraspForceResult(
        feasible=False,
        objective=objective,
        cones=P.cones,
        wrench=w.copy(),
        contact_forces=None,
        joint_torques=None,
        squeeze=math.nan,
        torque_usage=math.nan,
        saturating_joints=(),
        margin=math.nan,
        torque_limits=None if P.torque_limits is None else P.torque_limits.copy(),
        balance_residual=math.nan,
        num_generators=P.num_generators,
        solver=result.get_solver_id().name(),
        status=status.name,
        certificate=cert,
    )


@checked_call
def grasp_forces(
    grasp: Grasp,
    wrench: np.ndarray,
    *,
    hand_jacobian: np.ndarray | None = None,
    torque_limits: np.ndarray | float | None = None,
    objective: str = "min_squeeze",
    cones: str = "exact",
    num_generators: int = DEFAULT_NUM_GENERATORS,
    max_normal_force: np.ndarray | float | None = None,
    max_squeeze: float | None = None,
) -> GraspForceResult:
    """Contact forces (and joint torques) that hold the external wrench ``wrench``.

    Parameters
    ----------
    grasp : Grasp
    wrench : (6,) or (3,) float
        External wrench on the object ``[f; m]`` about ``p``, grasp frame (N,
        N·m); the contacts must supply ``-wrench``.
    hand_jacobian, torque_limits, objective, cones, num_generators
        See :func:`build_grasp_forces_program`.
    max_normal_force, max_squeeze
        Optional bounds on each ``f_n`` and on ``Σ f_n`` (N).

    Returns
    -------
    GraspForceResult
        ``feasible`` with the forces and torques, or not, with a certificate.

    Raises
    ------
    InvalidOptionError
        Bad options (an unknown objective, torque limits without ``J``,
        ``min_torque`` without ``J``, ``max_margin`` without a squeeze bound).
    SolverError
        The solver failed and no dual direction proves infeasibility.

    Examples
    --------
    Two hard fingers squeeze a 1 kg box along x; gravity pulls along -z.  The
    least squeeze is ``m g / μ``:

    >>> import numpy as np
    >>> import drakegrasp as dg
    >>> grasp = dg.Grasp([dg.Contact([-0.05, 0, 0], [1, 0, 0], mu=0.5),
    ...                   dg.Contact([0.05, 0, 0], [-1, 0, 0], mu=0.5)])
    >>> r = dg.grasp_forces(grasp, [0, 0, -9.81, 0, 0, 0])
    >>> round(r.squeeze, 3)
    19.62
    """
    objective = _check_objective(objective)
    w = check_wrench(grasp, wrench)
    P = load_problem(
        grasp,
        hand_jacobian=hand_jacobian,
        torque_limits=torque_limits,
        max_normal_force=max_normal_force,
        max_squeeze=max_squeeze,
        cones=cones,
        num_generators=num_generators,
    )
    return solve_load(P, w, objective)


LIMIT_GAP = 1e8
"""Limits at least this many times the load's size are first left out.

The program's unit of force is the load's size, so such limits are entries of
1e8 and more beside the balance's entries of 1: a load of 1e-14 N with 10 N
bounds was "not held" (the solvers' status on a bound of 1e15).  Leaving the
limits out is a relaxation: forces of the relaxed problem that re-check within
the limits are the least squeeze of the limited one too, and a refutation of
the relaxed problem (which prices no limit) refutes the limited one.  Anything
else is decided with the limits, as before.
"""


def solve_load(P: LoadProblem, w: np.ndarray, objective: str) -> GraspForceResult:
    """Build, solve and read the program of a validated problem.

    The returned forces are re-checked against the cones, the limits and the
    balance (:meth:`~drakegrasp.closure.load_problem.LoadProblem.violation`).
    When they fail, the problem is solved again friction-scaled (the cure at
    ``μ >> 1``); a second failure is a :class:`~drakegrasp.SolverError`, never
    forces that break a limit reported as feasible.  Limits far above the
    load (:data:`LIMIT_GAP`) are first left out, for the least squeeze.
    A zero load is held by zero forces, the least squeeze and torque there
    is, without a solver (whose forces of 1e-11 N were judged against
    themselves and "violated" a cone by all of their size).
    """
    if objective != "max_margin" and not np.any(w):
        if objective == "min_torque" and P.hand_jacobian is None:
            _build(P, w, objective)  # refuses it, as for any other load
        return _zero_forces(P, w, objective)
    free = _without_far_limits(P, w, objective)
    if free is not None:
        relaxed = _solve_checked(free, w, objective)
        if not relaxed.feasible:
            cert = relaxed.certificate
            if cert is not None:
                cert = replace(
                    cert,
                    torque_limits=P.torque_limits,
                    max_normal_force=P.max_normal_force,
                    max_squeeze=P.max_squeeze,
                )
            return replace(relaxed, certificate=cert, torque_limits=_limits_copy(P))
        if P.violation(relaxed.stacked_forces(), w)[0] <= FEASIBILITY_TOL:
            sat, usage = saturating_joints(relaxed.joint_torques, P.torque_limits)
            return replace(
                relaxed,
                torque_limits=_limits_copy(P),
                saturating_joints=sat,
                torque_usage=usage,
            )
    return _solve_checked(P, w, objective)


def _limits_copy(P: LoadProblem) -> np.ndarray | None:
    return None if P.torque_limits is None else P.torque_limits.copy()


def _without_far_limits(P: LoadProblem, w: np.ndarray, objective: str):
    """``P`` without its limits when all are :data:`LIMIT_GAP` times the load."""
    if objective != "min_squeeze":  # the other objectives are shaped by limits
        return None
    size = P.load_size(w)
    sizes = P.limit_sizes()
    if not (size > 0.0 and sizes.size and np.min(sizes) >= LIMIT_GAP * size):
        return None
    return replace(
        P,
        torque_limits=None,
        max_normal_force=np.full(P.max_normal_force.shape, math.inf),
        max_squeeze=math.inf,
    )


def _solve_checked(P: LoadProblem, w: np.ndarray, objective: str) -> GraspForceResult:
    """:func:`solve_load` with the limits as they are."""
    first = _solve_load(P, w, objective)
    Ps = P.friction_scaled()
    scaled = Ps is not P
    if _holds(P, w, first, scaled) and (first.feasible or not scaled):
        return first
    # A μ far from 1: forces that fail, or a refusal, in newtons are not the
    # answer (at μ = 1e-12 a held load was "refuted" by a certificate that
    # re-checked): the friction-scaled program decides.
    second = None if Ps is P else _solve_load(Ps, w, objective)
    if second is not None and not second.feasible and not first.feasible:
        return first if first.certificate is not None else second
    if second is not None and (not second.feasible or _holds(P, w, second, scaled)):
        # The friction-scaled program's proof of infeasibility is trusted.
        return second
    bad = second or first
    if not bad.feasible:
        found = f"status {bad.status} without a certificate"
    else:
        excess, what = P.violation(bad.stacked_forces(), w)
        found = f"forces violating the constraints by {excess:.2g} (at {what})"
    raise SolverError(
        f"{bad.solver} returned {found} for the load {_load_text(w)}, "
        "even friction-scaled: the answer is not known to the solvers' accuracy"
    )


def _holds(P: LoadProblem, w: np.ndarray, r: GraspForceResult, scaled: bool) -> bool:
    """A result to trust: an infeasibility proof, or forces that re-check.

    ``scaled``: ``P`` has a friction-scaled twin (a μ far from 1).
    """
    if not r.feasible:
        # A certificate is re-checkable; a bare status at μ >> 1 is not.
        return r.certificate is not None or not scaled
    return P.violation(r.stacked_forces(), w)[0] <= FEASIBILITY_TOL


def _solve_load(P: LoadProblem, w: np.ndarray, objective: str) -> GraspForceResult:
    prog, v = _build(P, w, objective)
    result = solve(prog, P.kind, retry=True)
    if result.get_solution_result() != SolutionResult.kSolutionFound:
        return _infeasible(P, w, objective, prog, result, v.force_scale)
    if objective == "min_torque":
        t = float(result.GetSolution(v.ratio))
        use, weight = _torque_weights(P)
        unit = 1.0 / float(np.max(weight / P.jscale[use])) if use.size else 1.0
        cap = t * (1.0 + _TIE) + _TIE * unit
        prog2, v2 = _build(P, w, objective, ratio_cap=cap)
        result2 = solve(prog2, P.kind, retry=True)
        if result2.get_solution_result() == SolutionResult.kSolutionFound:
            return _solved(P, w, objective, result2, v2, v2.force_scale)
    return _solved(P, w, objective, result, v, v.force_scale)
