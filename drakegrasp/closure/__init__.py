"""Closure: form closure (LP1), force closure (LP2, exact cones), LP3, second order.

:mod:`~drakegrasp.closure.programs` builds each ``MathematicalProgram``
(``build_*``), :mod:`~drakegrasp.closure.verdicts` solves them through the
solver gateway (``drakegrasp._solvers``) and assembles the frozen results
of :mod:`~drakegrasp.closure.results`, and
:mod:`~drakegrasp.closure.second_order` decides Rimon–Burdick second-order
form closure.
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
    "drakegrasp.closure.second_order": (
        "SecondOrderResult",
        "second_order_form_closure",
    ),
}

__getattr__, __dir__ = lazy_exports(__name__, globals(), _SOURCES)

__all__ = [
    "ClosureResult",
    "InternalForceResult",
    "SecondOrderResult",
    "force_closure",
    "force_closure_exact",
    "form_closure",
    "internal_forces",
    "second_order_form_closure",
]
