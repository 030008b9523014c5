"""The numeric settings of the batch LP kernels, defined once.

Every route to ``d*`` (the fused and unfused numba kernels, the numpy
interior-point method, the active-set and vertex solvers) reads these, so the
routes stop at the same accuracy and agree to it.  They are solver settings,
not user thresholds: those (``tol``, ``rank_tol``) are in
:mod:`drakegrasp.core.tolerances`.
"""

from __future__ import annotations

__all__ = [
    "BLOCK_TOL",
    "HIGHS_MAX_COLUMNS",
    "IPM_MAX_ITER",
    "IPM_MAX_ITER_LARGE",
    "IPM_TOL",
    "PUSH_TOL",
]

IPM_TOL = 1e-10
"""The interior-point iteration stops when its scaled residuals and duality gap
are below this (the gap bounds the error of ``d*`` once the residuals vanish)."""

IPM_MAX_ITER = 60
"""Most interior-point iterations per problem; one that has not converged by
then is reported with ``converged = False``.  (A ``d*`` LP of at most
``HIGHS_MAX_COLUMNS`` force components is then solved again by HiGHS; a
larger one gets ``IPM_MAX_ITER_LARGE`` instead.)"""

PUSH_TOL = 1e-10
"""``‖c‖`` below this: no balanced force has a normal component (``d* = 0``)."""

BLOCK_TOL = 1e-9
"""A facet blocks a step when its rate along the step, relative to the norms
involved, is below ``-BLOCK_TOL`` (active set) or above it (vertex walk)."""

HIGHS_MAX_COLUMNS = 2048
"""Most force components ``M`` of an LP that HiGHS solves again after the
interior-point method reached its cap.  HiGHS's time grows about as ``M³``
on these LPs (one grasp of frictionless contacts on an ellipsoid: 0.07 s at
``M = 1000``, 0.38 s at 2000, 3.2 s at 4000, more than 10 minutes at 20,000);
a larger LP gets ``IPM_MAX_ITER_LARGE`` iterations instead and then keeps
the interior-point method's last iterate, reported with ``converged = False``,
rather than hang.  The LPs of hands (``M <= 4 * 32``)
are far below it."""

IPM_MAX_ITER_LARGE = 300
"""The iteration cap of an LP past ``HIGHS_MAX_COLUMNS`` force components,
which has no HiGHS to fall back on.  The interior-point method needs more
iterations as the LP grows (LP1 of frictionless contacts on an ellipsoid
converged in 158 iterations at 8,000 contacts, within 100 at 20,000 and
within 150 at 100,000; each iteration costs time linear in ``M``, about 3 ms
at 8,000 contacts); at ``IPM_MAX_ITER`` they ended unconverged with ``d*``
off by up to 6e-4.  Smaller LPs keep ``IPM_MAX_ITER`` and HiGHS, so their
answers are unchanged."""
