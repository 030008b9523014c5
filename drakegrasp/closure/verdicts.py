"""Closure verdicts: the programs of :mod:`drakegrasp.closure.programs`, solved.

Each function solves its program through the solver gateway
(``drakegrasp._solvers``), reads ``d*``, the rank and the forces, and
returns a frozen result with the certificate that backs it.
"""

from __future__ import annotations

import numpy as np
from pydrake.solvers import SolutionResult

from drakegrasp._solvers import solve
from drakegrasp.certificates.witness import (
    balance_certificate,
    escape_twist,
    uncontrollable_force,
    unresisted_wrench,
)
from drakegrasp.closure.programs import (
    ProgramVariables,
    balance_matrix,
    balance_rank,
    build_exact_force_closure_program,
    build_force_closure_program,
    build_form_closure_program,
    build_internal_force_program,
    check_formulation,
    check_program_options,
    cone_layout,
    lp3_is_conic,
    normal_balance_matrix,
    per_grasp,
)
from drakegrasp.closure.results import ClosureResult, InternalForceResult
from drakegrasp.core.calls import checked_call
from drakegrasp.core.deferred import defer, parts, replace, resolve
from drakegrasp.core.grasp import (
    Grasp,
    check_hand_jacobian,
)
from drakegrasp.core.tolerances import (
    DEFAULT_NUM_GENERATORS,
    DEFAULT_RANK_TOL,
    DEFAULT_TOL,
    relative_margin,
)
from drakegrasp.core.validation import (
    check_tol,
)
from drakegrasp.errors import InvalidOptionError, SolverError

__all__ = [
    "force_closure",
    "force_closure_exact",
    "form_closure",
    "internal_forces",
    "with_internal_forces",
]


def _solve_margin(prog, variables: ProgramVariables, *, conic: bool):
    """Solve; return (d*, full-vector forces or None, solver, status)."""
    result = solve(prog, "socp" if conic else "lp", retry=conic)
    status = result.get_solution_result()
    solver = result.get_solver_id().name()
    if status == SolutionResult.kSolutionFound:
        d_star = float(result.GetSolution(variables.d))
        if variables.weights is None:
            forces = result.GetSolution(variables.forces)
        else:
            forces = variables.generators @ result.GetSolution(variables.weights)
        return d_star, np.asarray(forces, dtype=float), solver, status.name
    if status in (SolutionResult.kInfeasibleConstraints,):
        return float("nan"), None, solver, status.name
    raise SolverError(
        f"{solver} failed with status {status.name} (the program is always "
        "feasible, so this is a numerical failure, not a verdict)",
        program=prog,
        result=result,
    )


def _split_forces(
    grasp: Grasp, columns: np.ndarray, values: np.ndarray | None
) -> tuple[np.ndarray, ...]:
    full = np.zeros(grasp.num_components)
    if values is not None:
        full[columns] = values
    return tuple(full[s].copy() for s in grasp.component_slices())


@checked_call
def form_closure(
    grasp: Grasp,
    *,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
) -> ClosureResult:
    """Decide first-order form closure: ``rank(G_n)`` full and LP1 ``d* > tol``.

    Parameters
    ----------
    grasp : Grasp
        Friction and contact models are ignored: form closure is frictionless.
    tol : float, optional
        Threshold on ``d*`` (dimensionless, see
        :data:`~drakegrasp.core.tolerances.DEFAULT_TOL`).
    rank_tol : float, optional
        Relative singular-value threshold of the rank test.

    Returns
    -------
    ClosureResult
        ``contact_forces`` holds ``[f_n]`` per contact.

    Examples
    --------
    Four frictionless contacts on a square's sides hold it in the plane:

    >>> import drakegrasp as dg
    >>> result = dg.form_closure(dg.examples.planar_square_four_contacts())
    >>> result.is_closure, result.rank
    (True, 3)
    """
    rank_tol = check_program_options(grasp, rank_tol)
    tol = check_tol(tol)
    required = grasp.wrench_dim
    rank = balance_rank(normal_balance_matrix(grasp), rank_tol)
    # A short rank decides "no" alone: LP1 then runs when d* is first read.
    args = (grasp, tol, rank_tol)
    solution = (
        _form_closure_solution(*args)
        if rank == required
        else defer(_form_closure_solution, *args)
    )
    d_star, margin, forces, solver, status = parts(solution, 5)
    ok = rank == required and d_star > tol
    if ok:
        certificate = defer(
            balance_certificate, grasp, forces, cones="normals", rank=rank
        )
    else:
        certificate = defer(escape_twist, grasp, rank)
    return ClosureResult(
        kind="form closure",
        is_closure=bool(ok),
        d_star=d_star,
        rank=rank,
        required_rank=required,
        margin=margin,
        contact_forces=forces,
        solver=solver,
        status=status,
        tol=tol,
        formulation="normals",
        frictional_closure=bool(ok),
        decided_by="d*" if rank == required else "rank",
        certificate=certificate,
    )


def _form_closure_solution(grasp: Grasp, tol: float, rank_tol: float) -> tuple:
    """LP1 solved: ``(d*, margin, forces per contact, solver, status)``."""
    prog, variables = build_form_closure_program(grasp, rank_tol=rank_tol)
    d_star, forces, solver, status = _solve_margin(prog, variables, conic=False)
    if forces is None:
        forces = np.zeros(grasp.num_contacts)
    forces = tuple(np.array([x]) for x in forces)
    return d_star, relative_margin(d_star, tol), forces, solver, status


@checked_call
def internal_forces(
    grasp: Grasp,
    hand_jacobian: np.ndarray,
    *,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
) -> InternalForceResult:
    """Solve LP3, which asks whether the hand controls every internal force.

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_v) float
        Rows in the order of the columns of ``G``; columns the hand's velocities.
    tol : float, optional
        LP3 passes when ``d* <= tol``, or when ``d*`` is below the resolution
        of LP3's optimal force (``resolution`` of
        :class:`~drakegrasp.InternalForceResult`).
    rank_tol : float, optional
        Relative singular-value threshold for ``dim(N(G) ∩ N(Jᵀ))``, and the
        relative resolution of the optimal force's normal components.

    Returns
    -------
    InternalForceResult
    """
    rank_tol = check_program_options(grasp, rank_tol)
    tol = check_tol(tol)
    prog, variables = build_internal_force_program(
        grasp, hand_jacobian, rank_tol=rank_tol
    )
    d_star, forces, solver, status = _solve_margin(prog, variables, conic=False)
    (equalities,) = prog.linear_equality_constraints() or (None,)
    rank = 0 if equalities is None else equalities.evaluator().num_constraints()
    null_dim = len(variables.columns) - rank
    # Normals below rank_tol of the force's size are round-off, not a squeeze
    # (InternalForceResult.resolution).
    resolution = rank_tol * _largest(forces)
    threshold = max(tol, resolution)
    passes = not (d_star > threshold)  # NaN (infeasible) passes: no such force
    contact_forces = _split_forces(grasp, variables.columns, forces)
    within = None
    if not passes:  # is there one the contacts can carry, within friction?
        prog, friction_variables = build_internal_force_program(
            grasp, hand_jacobian, rank_tol=rank_tol, within_friction=True
        )
        try:
            d_within, carried, _, _ = _solve_margin(
                prog, friction_variables, conic=lp3_is_conic(grasp)
            )
        except SolverError:  # a fact beside the verdict: unknown, not fatal
            pass
        else:
            within = (
                float(d_within) if np.isfinite(d_within) else 0.0,
                not (d_within > max(tol, rank_tol * _largest(carried))),
            )
    return InternalForceResult(
        passes=bool(passes),
        d_star=d_star,
        margin=(-relative_margin(d_star, threshold) if np.isfinite(d_star) else np.inf),
        null_space_dim=int(null_dim),
        contact_forces=contact_forces,
        solver=solver,
        status=status,
        tol=tol,
        certificate=None if passes else uncontrollable_force(grasp, contact_forces),
        resolution=resolution,
        d_star_within_friction=None if within is None else within[0],
        passes_within_friction=None if within is None else bool(within[1]),
    )


def _largest(forces) -> float:
    """The largest |component| of an optimal force (0 for none)."""
    return 0.0 if forces is None else float(np.max(np.abs(forces), initial=0.0))


def _margin_solution(grasp: Grasp, build, tol: float) -> tuple:
    """``build()``'s program solved: ``(d*, margin, forces, solver, status)``.

    ``build`` returns ``(prog, variables, conic)``.
    """
    prog, variables, conic = build()
    d_star, forces, solver, status = _solve_margin(prog, variables, conic=conic)
    contact_forces = _split_forces(grasp, variables.columns, forces)
    return d_star, relative_margin(d_star, tol), contact_forces, solver, status


def _force_closure_result(
    grasp: Grasp,
    build,
    columns: np.ndarray,
    *,
    kind: str,
    formulation: str,
    hand_jacobian: np.ndarray | None,
    tol: float,
    rank_tol: float,
    num_generators: int = DEFAULT_NUM_GENERATORS,
) -> ClosureResult:
    """The verdict of the program ``build()`` makes over ``columns`` of ``G``.

    A short rank decides "no" alone, so the program is then built and solved
    only when its ``d*`` (or forces, solver, status) is first read; the
    certificate is computed when first read in every case.
    """
    required = grasp.wrench_dim
    rank = per_grasp(
        grasp,
        ("rank", rank_tol, columns.tobytes()),
        lambda: balance_rank(balance_matrix(grasp, columns), rank_tol),
    )
    args = (grasp, build, tol)
    solution = (
        _margin_solution(*args) if rank == required else defer(_margin_solution, *args)
    )
    d_star, margin, contact_forces, solver, status = parts(solution, 5)
    frictional = bool(rank == required and d_star > tol)
    decided_by = "d*" if rank == required else "rank"
    if rank == required and not frictional:
        # d is a distance to the cone boundaries, so it vanishes with μ.  Normal
        # forces alone (f_t = 0) lie inside every cone with μ > 0: if they
        # balance with f_n > tol, the grasp is in force closure for any μ.
        normal = _normal_force_certificate(grasp, columns, tol=tol, rank_tol=rank_tol)
        if normal is not None:
            frictional, decided_by = True, "normal forces"
            margin, contact_forces = normal
    cones = "exact" if formulation == "exact" else "polyhedral"
    if frictional:
        # LP1's forces (f_t = 0) on the normal-force route: inside every cone
        # with μ > 0, and G (not G_n) is the matrix of full rank.
        certificate = defer(
            balance_certificate,
            grasp,
            contact_forces,
            cones=cones,
            rank=rank,
            num_generators=num_generators,
        )
    else:
        certificate = defer(
            unresisted_wrench, grasp, rank, cones=cones, num_generators=num_generators
        )
    result = ClosureResult(
        kind=kind,
        is_closure=frictional,
        d_star=d_star,
        rank=rank,
        required_rank=required,
        margin=margin,
        contact_forces=contact_forces,
        solver=solver,
        status=status,
        tol=tol,
        formulation=formulation,
        frictional_closure=frictional,
        decided_by=decided_by,
        certificate=certificate,
    )
    if hand_jacobian is None:
        return result
    if frictional:
        lp3 = internal_forces(grasp, hand_jacobian, tol=tol, rank_tol=rank_tol)
    else:  # the verdict is "no" whatever LP3 says: solve it when first read
        check_hand_jacobian(grasp, hand_jacobian)
        lp3 = defer(internal_forces, grasp, hand_jacobian, tol=tol, rank_tol=rank_tol)
    return with_internal_forces(result, lp3)


def with_internal_forces(
    result: ClosureResult, lp3: InternalForceResult
) -> ClosureResult:
    """The verdict with a hand: frictional closure and LP3 passing.

    Parameters
    ----------
    result : ClosureResult
        A force-closure result computed without the hand Jacobian.
    lp3 : InternalForceResult
        :func:`internal_forces` of the same grasp and hand Jacobian; one LP3
        can serve the polyhedral and the exact-cone verdicts alike.  It may be
        deferred (``drakegrasp.core.deferred.defer``); it is then computed
        here only when ``result`` holds frictional closure.

    Returns
    -------
    ClosureResult
        ``result`` with ``internal_forces = lp3`` and
        ``is_closure = frictional_closure and lp3.passes``.
    """
    changes = {}
    if result.frictional_closure:
        lp3 = resolve(lp3)  # the verdict needs it
    if result.frictional_closure and not lp3.passes:
        changes = {"decided_by": "LP3", "certificate": lp3.certificate}
    elif result.decided_by == "LP3":  # re-attaching: undo a previous LP3 verdict
        raise InvalidOptionError(
            "with_internal_forces needs a result computed without the hand "
            "Jacobian; this one was already decided by LP3"
        )
    return replace(
        result,
        internal_forces=lp3,
        is_closure=result.frictional_closure and lp3.passes,
        **changes,
    )


def _normal_force_certificate(
    grasp: Grasp, columns: np.ndarray, *, tol: float, rank_tol: float
) -> tuple[float, tuple[np.ndarray, ...]] | None:
    """LP1 on the contacts' normals, when some contact has friction.

    Returns the margin of LP1's ``d*`` and its forces (tangential parts zero) when
    ``d* > tol``, else None.
    """
    normals = grasp.normal_indices()
    if len(columns) == len(normals):  # every contact is frictionless already
        return None
    if balance_rank(normal_balance_matrix(grasp), rank_tol) == len(normals):
        return None  # N(G_n) = {0}: no non-zero normal forces balance
    prog, variables = build_form_closure_program(grasp, rank_tol=rank_tol)
    d_star, f_n, _, _ = _solve_margin(prog, variables, conic=False)
    if not d_star > tol:
        return None
    return relative_margin(d_star, tol), _split_forces(grasp, normals, f_n)


@checked_call
def force_closure(
    grasp: Grasp,
    *,
    hand_jacobian: np.ndarray | None = None,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
    formulation: str = "facets",
) -> ClosureResult:
    """Decide force closure on polyhedral friction cones (LP2, and LP3 with a hand).

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_v) float, optional
        Hand Jacobian ``J`` (rows in ``G``'s column order).  When given, the
        verdict also needs LP3 to pass.
    num_generators : int, optional
        Generators of each spatial Coulomb cone (default 8; the cone is
        inscribed, so a polyhedral closure implies an exact one).
    tol : float, optional
        Closure needs ``d* > tol``.
    rank_tol : float, optional
        Relative singular-value threshold of the rank test.
    formulation : {"facets", "generators"}, optional
        H-form (default, ``d*`` as in the conventions) or V-form.

    Returns
    -------
    ClosureResult

    Examples
    --------
    The equator grasp of three hard fingers is in force closure:

    >>> import drakegrasp as dg
    >>> result = dg.force_closure(dg.examples.equator_fingers(0.5, num_fingers=3))
    >>> result.is_closure, result.rank, round(result.d_star, 4)
    (True, 6, 0.4194)
    """
    rank_tol = check_program_options(grasp, rank_tol)
    tol = check_tol(tol)
    formulation = check_formulation(formulation)  # the plain str it holds

    def build():
        prog, variables = build_force_closure_program(
            grasp,
            num_generators=num_generators,
            formulation=formulation,
            rank_tol=rank_tol,
        )
        return prog, variables, False

    return _force_closure_result(
        grasp,
        build,
        cone_layout(grasp, num_generators).columns,
        kind="force closure",
        formulation=formulation,
        hand_jacobian=hand_jacobian,
        tol=tol,
        rank_tol=rank_tol,
        num_generators=num_generators,
    )


@checked_call
def force_closure_exact(
    grasp: Grasp,
    *,
    hand_jacobian: np.ndarray | None = None,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
) -> ClosureResult:
    """Decide force closure with exact Coulomb cones (an SOCP, Clarabel or SCS).

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_v) float, optional
        When given, the verdict also needs LP3 to pass.
    tol : float, optional
        Closure needs ``d* > tol``; ``d*`` is each contact force's distance to
        its exact cone's boundary.
    rank_tol : float, optional
        Relative singular-value threshold of the rank test.

    Returns
    -------
    ClosureResult
    """
    rank_tol = check_program_options(grasp, rank_tol)
    tol = check_tol(tol)

    def build():
        prog, variables = build_exact_force_closure_program(grasp, rank_tol=rank_tol)
        return prog, variables, bool(prog.lorentz_cone_constraints())

    return _force_closure_result(
        grasp,
        build,
        cone_layout(grasp, DEFAULT_NUM_GENERATORS).columns,
        kind="force closure (exact cones)",
        formulation="exact",
        hand_jacobian=hand_jacobian,
        tol=tol,
        rank_tol=rank_tol,
    )
