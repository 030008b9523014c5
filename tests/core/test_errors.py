"""Bad input raises a GraspError subclass whose message names the bad value."""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.core import examples as ex


@pytest.mark.parametrize(
    ("args", "kwargs", "match"),
    [
        (([0, 0, 1], [0, 0, 0]), {}, r"normal \[0\.0, 0\.0, 0\.0\] has zero length"),
        (([0, 0, 1], [0, np.nan, 1]), {}, r"normal \[0\.0, nan, 1\.0\] is not finite"),
        (([0, 0, 1], [0, 1]), {}, "both must be 2-D or both 3-D"),
        (([0, 0, 1, 2], [0, 0, 1]), {}, r"2 \(planar\) or 3 \(spatial\)"),
        (([0, np.inf, 1], [0, 0, 1]), {}, "not finite"),
        (
            ([0, 0, 1], [0, 0, -1]),
            {"mu": -0.1},
            r"mu must be finite and 0 or in \[1e-12, 1e\+12\].*got -0\.1",
        ),
        (
            ([0, 0, 1], [0, 0, -1]),
            {"mu": "high"},
            "mu must be a real number, got 'high'",
        ),
        (
            ([0, 0, 1], [0, 0, -1]),
            {"contact_model": "sticky"},
            "unknown contact model 'sticky'",
        ),
        (
            ([0, 1], [0, -1]),
            {"contact_model": "soft_finger"},
            "soft-finger contact is spatial",
        ),
        (
            ([0, 0, 1], [0, 0, -1]),
            {"torsional_friction": -1},
            "torsional_friction must be finite and 0 or in",
        ),
    ],
)
def test_invalid_contacts(args, kwargs, match):
    with pytest.raises(dg.InvalidContactError, match=match):
        dg.Contact(*args, **kwargs)


def test_errors_form_one_tree():
    for cls in (
        dg.InvalidContactError,
        dg.InvalidGraspError,
        dg.InvalidOptionError,
        dg.NoContactsError,
        dg.PenetrationError,
        dg.ModelError,
        dg.SolverError,
    ):
        assert issubclass(cls, dg.GraspError)


def test_invalid_grasps():
    with pytest.raises(dg.InvalidContactError, match=r"contacts \[1\] are planar"):
        dg.Grasp([dg.Contact([0, 0, 1], [0, 0, -1]), dg.Contact([0, 1], [0, -1])])
    with pytest.raises(dg.InvalidGraspError, match="at least one contact"):
        dg.Grasp([])
    with pytest.raises(dg.InvalidContactError, match="contact 0 is a tuple"):
        dg.Grasp([((0, 0, 1), (0, 0, -1))])
    with pytest.raises(dg.InvalidGraspError, match=r"reference_point .* got \[1, 2\]"):
        dg.Grasp([dg.Contact([0, 0, 1], [0, 0, -1])], reference_point=[1, 2])
    with pytest.raises(dg.InvalidGraspError, match="characteristic_length .* got -1"):
        dg.Grasp([dg.Contact([0, 0, 1], [0, 0, -1])], characteristic_length=-1)


def test_invalid_options():
    grasp = ex.equator_fingers(0.5)
    with pytest.raises(dg.InvalidOptionError, match="num_generators .* got 2"):
        dg.force_closure(grasp, num_generators=2)
    with pytest.raises(
        dg.InvalidOptionError,
        match=r"tol must be finite and > 0, a real number in \[1e-10, 0.5\]",
    ):
        dg.form_closure(grasp, tol=0)
    with pytest.raises(dg.InvalidOptionError, match="formulation .* 'vertices'"):
        dg.force_closure(grasp, formulation="vertices")
    with pytest.raises(dg.InvalidGraspError, match="non-finite"):
        dg.force_closure(grasp, hand_jacobian=np.full((9, 2), np.nan))
    with pytest.raises(dg.InvalidGraspError, match="exactly two contacts"):
        dg.is_antipodal(grasp)
    with pytest.raises(dg.InvalidOptionError, match="mu must be finite and 0 or in"):
        dg.is_antipodal(grasp.contacts[:2], mu=-1)
    c = dg.Contact([0, 0, 1], [0, 0, -1])
    with pytest.raises(dg.InvalidGraspError, match="coincide"):
        dg.is_antipodal([c, c])
    with pytest.raises(dg.InvalidContactError, match="no field"):
        c.with_(friction=1)


class _FakeResult:
    """A solver result with a chosen status (real solvers rarely fail on cue)."""

    def __init__(self, status):
        self.status = status

    def get_solution_result(self):
        return self.status

    def get_solver_id(self):
        from pydrake.solvers import ClpSolver

        return ClpSolver.id()


def test_a_failing_solver_raises_solver_error_with_program_and_result(monkeypatch):
    from pydrake.solvers import SolutionResult

    import drakegrasp.closure.verdicts as closure

    def failing(prog, kind, *, retry=False):
        return _FakeResult(SolutionResult.kSolverSpecificError)

    monkeypatch.setattr(closure, "solve", failing)
    with pytest.raises(dg.SolverError, match="kSolverSpecificError") as info:
        dg.force_closure(ex.equator_fingers(0.5))
    assert info.value.program is not None
    assert (
        info.value.result.get_solution_result() == SolutionResult.kSolverSpecificError
    )


def test_infeasibility_is_a_verdict_not_an_exception(monkeypatch):
    from pydrake.solvers import SolutionResult

    import drakegrasp.closure.verdicts as closure

    def infeasible(prog, kind, *, retry=False):
        return _FakeResult(SolutionResult.kInfeasibleConstraints)

    monkeypatch.setattr(closure, "solve", infeasible)
    r = dg.form_closure(ex.cube_seven_contacts())
    assert not r.is_closure and np.isnan(r.d_star)
    assert r.status == "kInfeasibleConstraints" and r.to_dict()["d_star"] is None
