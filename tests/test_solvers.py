"""The solver gateway: which solver runs a program, the fallback, and its errors."""

import numpy as np
import pytest
from pydrake.solvers import (
    ClarabelSolver,
    ClpSolver,
    MathematicalProgram,
    ScsSolver,
    SolutionResult,
    SolverId,
)

import drakegrasp as dg
from drakegrasp import _solvers

FOUND = SolutionResult.kSolutionFound
INFEASIBLE = SolutionResult.kInfeasibleConstraints
NOT_VERDICTS = [
    SolutionResult.kSolverSpecificError,
    SolutionResult.kIterationLimit,
    SolutionResult.kUnbounded,
    SolutionResult.kDualInfeasible,
    SolutionResult.kInfeasibleOrUnbounded,
    SolutionResult.kInvalidInput,
]


class _FakeResult:
    """A solver result with a chosen status (real solvers rarely fail on cue)."""

    def __init__(self, status, name):
        self.status = status
        self.name = name

    def get_solution_result(self):
        return self.status

    def get_solver_id(self):
        return SolverId(self.name)


def _fake_solver(calls, name, status=FOUND, *, available=True, enabled=True):
    """A solver class that records ``name`` in ``calls`` when it solves."""

    class Fake:
        def available(self):
            return available

        def enabled(self):
            return enabled

        def solver_id(self):
            return SolverId(name)

        def Solve(self, prog):
            calls.append(name)
            return _FakeResult(status, name)

    return Fake


@pytest.fixture
def calls():
    return []


@pytest.fixture
def install(monkeypatch, calls):
    """Replace the solvers of one kind with fakes: ``install(kind, spec, ...)``
    where each spec is ``(name, status)`` or ``(name, status, options)``."""

    def _install(kind, *specs):
        classes = tuple(
            _fake_solver(calls, name, status, **(rest[0] if rest else {}))
            for name, status, *rest in specs
        )
        monkeypatch.setitem(_solvers._ORDER, kind, classes)

    return _install


def _unavailable(calls, name="Gone"):
    return _fake_solver(calls, name, available=False)


# --- the documented order --------------------------------------------------------


def test_order_is_the_documented_one():
    assert _solvers.KINDS == ("lp", "socp", "sdp")
    assert _solvers._ORDER == {
        "lp": (ClpSolver, ClarabelSolver),
        "socp": (ClarabelSolver, ScsSolver),
        "sdp": (ClarabelSolver, ScsSolver),
    }
    assert set(_solvers.VERDICT_STATUSES) == {FOUND, INFEASIBLE}


# --- real programs, known optima -------------------------------------------------


def _simplex_lp(c):
    """min c.x over the probability simplex: the optimum is min(c), at a vertex."""
    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(len(c), "x")
    prog.AddBoundingBoxConstraint(0, np.inf, x)
    prog.AddLinearEqualityConstraint(np.ones((1, len(c))), [1.0], x)
    prog.AddLinearCost(np.asarray(c, float), 0.0, x)
    return prog, x


def _plane_distance_socp(a, b, p):
    """min ||x - p|| s.t. a.x = b: the optimum is |a.p - b| / ||a||."""
    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(len(p), "x")
    t = prog.NewContinuousVariables(1, "t")[0]
    prog.AddLorentzConeConstraint(np.eye(len(p) + 1), np.r_[0.0, -p], np.r_[t, x])
    prog.AddLinearEqualityConstraint(np.atleast_2d(a), [b], x)
    prog.AddLinearCost(t)
    return prog, x


def _min_eigenvalue_sdp(C):
    """min tr(C X) s.t. tr(X) = 1, X PSD: the optimum is the least eigenvalue of C."""
    prog = MathematicalProgram()
    X = prog.NewSymmetricContinuousVariables(len(C), "X")
    prog.AddPositiveSemidefiniteConstraint(X)
    n = len(C)
    prog.AddLinearEqualityConstraint(sum(X[i, i] for i in range(n)) == 1)
    prog.AddLinearCost(sum(C[i, j] * X[i, j] for i in range(n) for j in range(n)))
    return prog


def test_lp_is_solved_by_clp_at_a_vertex():
    c = [3.0, -1.5, 2.0, 0.5]
    prog, x = _simplex_lp(c)
    result = _solvers.solve(prog, "lp")
    assert result.get_solution_result() == FOUND
    assert result.get_solver_id() == ClpSolver.id()
    assert result.get_optimal_cost() == pytest.approx(min(c), abs=1e-9)
    np.testing.assert_allclose(result.GetSolution(x), [0, 1, 0, 0], atol=1e-9)


def test_socp_is_solved_by_clarabel():
    a, b, p = np.array([1.0, 2.0, -2.0]), 4.0, np.array([0.5, -1.0, 2.0])
    prog, x = _plane_distance_socp(a, b, p)
    result = _solvers.solve(prog, "socp")
    assert result.get_solution_result() == FOUND
    assert result.get_solver_id() == ClarabelSolver.id()
    expected = abs(a @ p - b) / np.linalg.norm(a)
    assert result.get_optimal_cost() == pytest.approx(expected, rel=1e-6)
    foot = p - (a @ p - b) / (a @ a) * a
    np.testing.assert_allclose(result.GetSolution(x), foot, atol=1e-6)


def test_sdp_is_solved_by_clarabel():
    C = np.array([[2.0, 1.0, 0.0], [1.0, 3.0, -1.0], [0.0, -1.0, 1.5]])
    result = _solvers.solve(_min_eigenvalue_sdp(C), "sdp")
    assert result.get_solution_result() == FOUND
    assert result.get_solver_id() == ClarabelSolver.id()
    assert result.get_optimal_cost() == pytest.approx(
        np.linalg.eigvalsh(C)[0], abs=1e-6
    )


def test_an_unavailable_first_solver_falls_back_to_the_real_next(monkeypatch, calls):
    monkeypatch.setitem(_solvers._ORDER, "socp", (_unavailable(calls), ScsSolver))
    a, b, p = np.array([0.0, 0.0, 1.0]), 1.0, np.array([3.0, -2.0, 4.0])
    prog, _ = _plane_distance_socp(a, b, p)
    result = _solvers.solve(prog, "socp")
    assert calls == []
    assert result.get_solver_id() == ScsSolver.id()
    assert result.get_solution_result() == FOUND
    assert result.get_optimal_cost() == pytest.approx(3.0, rel=1e-3)


def test_infeasibility_is_a_verdict_and_not_retried():
    """Clp's proof of infeasibility is the answer: neither raised nor re-solved."""
    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(2, "x")
    prog.AddBoundingBoxConstraint(0, 1, x)
    prog.AddLinearConstraint(x[0] + x[1] >= 3)
    prog.AddLinearCost(x[0])
    result = _solvers.solve(prog, "lp", retry=True)
    assert result.get_solution_result() == INFEASIBLE
    assert result.get_solver_id() == ClpSolver.id()


def test_retry_hands_an_unbounded_lp_to_clarabel_and_returns_its_result():
    """Unboundedness is no verdict: with retry every solver runs, and the last
    one's result comes back whatever its status, without an exception."""
    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(1, "x")
    prog.AddLinearConstraint(x[0] <= 0)
    prog.AddLinearCost(x[0])
    alone = _solvers.solve(prog, "lp")
    assert alone.get_solver_id() == ClpSolver.id()
    assert alone.get_solution_result() not in _solvers.VERDICT_STATUSES
    retried = _solvers.solve(prog, "lp", retry=True)
    assert retried.get_solver_id() == ClarabelSolver.id()
    assert retried.get_solution_result() not in _solvers.VERDICT_STATUSES


# --- choice and fallback, with fake solvers --------------------------------------


@pytest.mark.parametrize(
    "skipped", [{"available": False}, {"enabled": False}], ids=["unavailable", "off"]
)
def test_the_first_usable_solver_runs(install, calls, skipped):
    install("lp", ("A", FOUND, skipped), ("B", FOUND), ("C", FOUND))
    result = _solvers.solve(MathematicalProgram(), "lp")
    assert calls == ["B"]
    assert result.get_solver_id().name() == "B"


@pytest.mark.parametrize("status", NOT_VERDICTS, ids=lambda s: s.name)
def test_without_retry_a_failure_is_returned_as_is(install, calls, status):
    install("socp", ("A", status), ("B", FOUND))
    result = _solvers.solve(MathematicalProgram(), "socp")
    assert calls == ["A"]
    assert result.get_solution_result() == status


@pytest.mark.parametrize("status", NOT_VERDICTS, ids=lambda s: s.name)
def test_retry_hands_a_failure_to_the_next_solver(install, calls, status):
    install("sdp", ("A", status), ("B", FOUND), ("C", FOUND))
    result = _solvers.solve(MathematicalProgram(), "sdp", retry=True)
    assert calls == ["A", "B"]
    assert result.get_solver_id().name() == "B"
    assert result.get_solution_result() == FOUND


@pytest.mark.parametrize("status", [FOUND, INFEASIBLE], ids=lambda s: s.name)
def test_retry_stops_at_a_verdict(install, calls, status):
    install("lp", ("A", status), ("B", FOUND))
    result = _solvers.solve(MathematicalProgram(), "lp", retry=True)
    assert calls == ["A"]
    assert result.get_solution_result() == status


def test_retry_runs_the_usable_solvers_in_order_and_returns_the_last(install, calls):
    fail = SolutionResult.kIterationLimit
    install(
        "socp",
        ("A", fail),
        ("B", FOUND, {"available": False}),
        ("C", SolutionResult.kSolverSpecificError),
        ("D", fail),
    )
    result = _solvers.solve(MathematicalProgram(), "socp", retry=True)
    assert calls == ["A", "C", "D"]
    assert result.get_solver_id().name() == "D"
    assert result.get_solution_result() == fail


# --- errors ----------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["lp", "socp", "sdp"])
def test_no_usable_solver_is_a_solver_error(install, calls, kind):
    install(
        kind,
        ("Alpha", FOUND, {"available": False}),
        ("Beta", FOUND, {"enabled": False}),
    )
    prog = MathematicalProgram()
    with pytest.raises(
        dg.SolverError,
        match=rf"no solver available for this {kind.upper()}: need Alpha or Beta",
    ) as info:
        _solvers.solve(prog, kind, retry=True)
    assert info.value.program is prog
    assert calls == []


@pytest.mark.parametrize("kind", ["LP", "qp", "", None, "lp ", ["lp"]])
def test_an_unknown_kind_is_an_invalid_option(kind):
    with pytest.raises(dg.InvalidOptionError, match="solver kind must be one of") as e:
        _solvers.solve(MathematicalProgram(), kind)
    assert repr(kind) in str(e.value)
    assert "'lp', 'socp', 'sdp'" in str(e.value)
    assert not isinstance(e.value, KeyError)
    assert e.value.__cause__ is None and e.value.__suppress_context__


def test_require_solution_passes_a_solution_through():
    prog, _ = _simplex_lp([1.0, 2.0])
    result = _solvers.solve(prog, "lp")
    assert _solvers.require_solution(prog, result, "the test LP") is result


@pytest.mark.parametrize("status", [INFEASIBLE, *NOT_VERDICTS], ids=lambda s: s.name)
def test_require_solution_raises_naming_solver_status_and_program(status):
    prog = MathematicalProgram()
    result = _FakeResult(status, "Clarabel")
    with pytest.raises(
        dg.SolverError,
        match=rf"Clarabel failed with status {status.name} on the LP2 program "
        r"\(always feasible and bounded, so this is a numerical failure",
    ) as info:
        _solvers.require_solution(prog, result, "the LP2 program")
    assert info.value.program is prog
    assert info.value.result is result


def test_require_solution_on_a_real_infeasible_lp():
    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(1, "x")
    prog.AddLinearConstraint(x[0] >= 1)
    prog.AddLinearConstraint(x[0] <= 0)
    result = _solvers.solve(prog, "lp")
    with pytest.raises(
        dg.SolverError, match="Clp failed with status kInfeasibleConstraints on LP3"
    ) as info:
        _solvers.require_solution(prog, result, "LP3")
    assert info.value.result is result


@pytest.mark.parametrize("raised", [ValueError("vector::reserve"), MemoryError()])
def test_a_solver_that_raises_is_a_solver_error_naming_it_and_the_size(
    monkeypatch, raised
):
    class Raising(_fake_solver([], "Huge")):
        def Solve(self, prog):
            raise raised

    monkeypatch.setitem(_solvers._ORDER, "lp", (Raising,))
    prog = MathematicalProgram()
    prog.NewContinuousVariables(7)
    with pytest.raises(dg.SolverError, match=r"Huge failed on this LP of 7 var") as e:
        _solvers.solve(prog, "lp")
    assert e.value.program is prog and e.value.__cause__ is raised
