"""The one solver gateway: which Drake solver runs a program, and its fallback.

Every program drakegrasp solves (the closure LPs, the exact-cone SOCP, the
witness programs, the second-order SDP, the quality LPs) goes through
:func:`solve`.  A program is of one of three kinds; each kind has an ordered
list of the solvers that ship with Drake's wheel:

========  ======================  ================================================
kind      solvers, in order       why
========  ======================  ================================================
``lp``    Clp, Clarabel           Clp is a simplex method: vertex solutions, and
                                  ``d*`` to about 1e-10 with the objective scaled
``socp``  Clarabel, SCS           Clarabel is an interior-point conic solver; SCS,
                                  a first-order method, finishes the degenerate
                                  cones on which Clarabel can stall
``sdp``   Clarabel, SCS           as for ``socp``
========  ======================  ================================================

The first available solver runs.  With ``retry=True``, a result whose status is
neither a solution nor proven infeasibility is handed to the next available
solver.  When no solver of the kind is available, or the last one fails where
the caller needs a solution, the error is one :class:`~drakegrasp.SolverError`
carrying the program and result.
"""

from __future__ import annotations

from pydrake.solvers import (
    ClarabelSolver,
    ClpSolver,
    MathematicalProgram,
    MathematicalProgramResult,
    ScsSolver,
    SolutionResult,
)

from drakegrasp.errors import InvalidOptionError, SolverError

__all__ = ["KINDS", "VERDICT_STATUSES", "require_solution", "solve"]

_ORDER = {
    "lp": (ClpSolver, ClarabelSolver),
    "socp": (ClarabelSolver, ScsSolver),
    "sdp": (ClarabelSolver, ScsSolver),
}
KINDS = tuple(_ORDER)
"""The kinds of program :func:`solve` knows."""

VERDICT_STATUSES = (
    SolutionResult.kSolutionFound,
    SolutionResult.kInfeasibleConstraints,
)
"""Statuses that answer the question asked (a solution, or proof there is none)."""


def _available(kind: str) -> list:
    try:
        order = _ORDER[kind]
    except (KeyError, TypeError):  # TypeError: an unhashable kind, e.g. a list
        raise InvalidOptionError(
            f"solver kind must be one of {KINDS}, got {kind!r}"
        ) from None
    solvers = [cls() for cls in order]
    return [s for s in solvers if s.available() and s.enabled()]


def solve(
    prog: MathematicalProgram, kind: str, *, retry: bool = False
) -> MathematicalProgramResult:
    """Solve ``prog`` with the first available solver of ``kind``.

    Parameters
    ----------
    prog : MathematicalProgram
    kind : {"lp", "socp", "sdp"}
        What the program is; it picks the solvers and their order.
    retry : bool, optional
        Hand a result that is neither solved nor proven infeasible to the next
        available solver of the kind (default False).

    Returns
    -------
    MathematicalProgramResult
        The last solver's result, whatever its status.

    Raises
    ------
    SolverError
        No solver of this kind is available, or the solver raised (out of
        memory on a huge program, say).
    """
    solvers = _available(kind)
    if not solvers:
        names = " or ".join(cls().solver_id().name() for cls in _ORDER[kind])
        raise SolverError(
            f"no solver available for this {kind.upper()}: need {names} "
            "(they ship with Drake's wheel)",
            program=prog,
        )
    result = _run(solvers[0], prog, kind)
    if retry:
        for solver in solvers[1:]:
            if result.get_solution_result() in VERDICT_STATUSES:
                break
            result = _run(solver, prog, kind)
    return result


def _run(solver, prog: MathematicalProgram, kind: str) -> MathematicalProgramResult:
    """``solver.Solve(prog)``, a solver's own exception turned into a SolverError.

    A solver that cannot hold the program (Clp's ``vector::reserve`` on an LP
    of tens of thousands of variables, an out-of-memory) raises from C++; the
    caller gets a :class:`SolverError` naming the solver and the program's size.
    """
    try:
        return solver.Solve(prog)
    except (RuntimeError, ValueError, MemoryError) as err:
        raise SolverError(
            f"{solver.solver_id().name()} failed on this {kind.upper()} of "
            f"{prog.num_vars()} variables and {len(prog.GetAllConstraints())} "
            f"constraints: {type(err).__name__}: {err}",
            program=prog,
        ) from err


def require_solution(
    prog: MathematicalProgram, result: MathematicalProgramResult, what: str
) -> MathematicalProgramResult:
    """``result`` when it holds a solution; otherwise a :class:`SolverError`.

    ``what`` names the program in the message ("the LP2 program").  Use it for
    programs that are always feasible and bounded, where any other status is a
    numerical failure rather than an answer.
    """
    status = result.get_solution_result()
    if status == SolutionResult.kSolutionFound:
        return result
    solver = result.get_solver_id().name()
    raise SolverError(
        f"{solver} failed with status {status.name} on {what} (always feasible "
        "and bounded, so this is a numerical failure, not a verdict)",
        program=prog,
        result=result,
    )
