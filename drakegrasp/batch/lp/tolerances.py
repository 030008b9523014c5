"""The numeric settings of the batch LP kernels, defined once.

Every route to ``d*`` (the fused and unfused numba kernels, the numpy
interior-point method, the active-set and vertex solvers) reads these, so the
routes stop at the same accuracy and agree to it.  They are solver settings,
not user thresholds: those (``tol``, ``rank_tol``) are in
:mod:`drakegrasp.core.tolerances`.
"""

from __future__ import annotations

__all__ = ["BLOCK_TOL", "IPM_MAX_ITER", "IPM_TOL", "PUSH_TOL"]

IPM_TOL = 1e-10
"""The interior-point iteration stops when its scaled residuals and duality gap
are below this (the gap bounds the error of ``d*`` once the residuals vanish)."""

IPM_MAX_ITER = 60
"""Most interior-point iterations per problem; one that has not converged by
then is reported with ``converged = False``."""

PUSH_TOL = 1e-10
"""``‖c‖`` below this: no balanced force has a normal component (``d* = 0``)."""

BLOCK_TOL = 1e-9
"""A facet blocks a step when its rate along the step, relative to the norms
involved, is below ``-BLOCK_TOL`` (active set) or above it (vertex walk)."""
