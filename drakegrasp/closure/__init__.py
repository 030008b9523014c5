"""Closure: form closure (LP1), force closure (LP2, exact cones), LP3, second order.

:mod:`~drakegrasp.closure.programs` builds each ``MathematicalProgram``
(``build_*``), :mod:`~drakegrasp.closure.verdicts` solves them through the
solver gateway (``drakegrasp._solvers``) and assembles the frozen results
of :mod:`~drakegrasp.closure.results`, and
:mod:`~drakegrasp.closure.second_order` decides Rimon–Burdick second-order
form closure.  Under load: :mod:`~drakegrasp.closure.load_forces` (forces and
joint torques that hold a wrench within cones and motor limits, or a
certificate that none do), :mod:`~drakegrasp.closure.payload` (the largest
multiple of a load), with :mod:`~drakegrasp.closure.load_problem` (what they
share) and :mod:`~drakegrasp.closure.force_dual` (the certificates' program).
"""

from drakegrasp._lazy import lazy_exports

_SOURCES = {
    "drakegrasp.closure.verdicts": (
        "force_closure",
        "force_closure_exact",
        "form_closure",
        "internal_forces",
    ),
    "drakegrasp.closure.results": ("ClosureResult", "InternalForceResult"),
    "drakegrasp.closure.load_forces": (
        "GraspForceResult",
        "build_grasp_forces_program",
        "grasp_forces",
    ),
    "drakegrasp.closure.payload": (
        "MaxLoadResult",
        "build_max_load_program",
        "max_load",
    ),
    "drakegrasp.closure.second_order": (
        "SecondOrderResult",
        "second_order_form_closure",
    ),
}

_SUBMODULES = (
    "constraints",
    "force_dual",
    "load_forces",
    "load_problem",
    "payload",
    "programs",
    "results",
    "second_order",
    "verdicts",
)

__getattr__, __dir__ = lazy_exports(
    __name__, globals(), _SOURCES, submodules=_SUBMODULES
)

__all__ = [
    "ClosureResult",
    "GraspForceResult",
    "InternalForceResult",
    "MaxLoadResult",
    "SecondOrderResult",
    "force_closure",
    "force_closure_exact",
    "build_grasp_forces_program",
    "build_max_load_program",
    "form_closure",
    "grasp_forces",
    "internal_forces",
    "max_load",
    "second_order_form_closure",
]
