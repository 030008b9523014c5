"""Dense linear constraints for ``MathematicalProgram`` without importing scipy.sparse.

``MathematicalProgram.AddLinearConstraint(A, lb, ub, vars)`` and
``AddLinearEqualityConstraint(Aeq, beq, vars)`` have overloads for sparse and
dense ``A``; resolving them makes pybind11 import ``scipy.sparse`` the first
time (70–90 ms on a quiet machine, most of a first ``analyze_grasp``).
Constructing the ``LinearConstraint`` / ``LinearEqualityConstraint`` from a
dense array and binding it with ``AddConstraint`` adds exactly the same
constraint (same rows, same bounds, same solver attribute) and never touches
the sparse caster.  Core layer: ``pydrake.solvers`` and numpy only.
"""

from __future__ import annotations

import numpy as np
from pydrake.solvers import LinearConstraint, LinearEqualityConstraint

__all__ = ["add_linear_constraint", "add_linear_equality_constraint"]


def add_linear_constraint(prog, A, lb, ub, x):
    """``lb <= A x <= ub`` with dense ``A`` (m, n); returns the binding."""
    A = np.atleast_2d(np.asarray(A, dtype=float))
    lb = np.asarray(lb, dtype=float).reshape(-1)
    ub = np.asarray(ub, dtype=float).reshape(-1)
    return prog.AddConstraint(LinearConstraint(A, lb, ub), np.asarray(x).reshape(-1))


def add_linear_equality_constraint(prog, A, b, x):
    """``A x = b`` with dense ``A`` (m, n); returns the binding."""
    A = np.atleast_2d(np.asarray(A, dtype=float))
    b = np.asarray(b, dtype=float).reshape(-1)
    return prog.AddConstraint(LinearEqualityConstraint(A, b), np.asarray(x).reshape(-1))
