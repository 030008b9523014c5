"""The closure LPs of a stack: ``d*`` in compiled kernels.

``d*`` (:mod:`~drakegrasp.batch.lp.dstar`) from an exact active-set method for
small null spaces and a block interior-point method for the rest, compiled
with numba, with a numpy route of the same iteration where numba is missing.
"""

from drakegrasp._lazy import lazy_exports

_SUBMODULES = (
    "active_set",
    "block_ipm",
    "block_kernel",
    "block_ops",
    "dstar",
    "fused_kernel",
    "householder",
    "ipm",
    "ipm_kernel",
    "tolerances",
    "vertex_kernel",
)

__getattr__, __dir__ = lazy_exports(__name__, globals(), {}, submodules=_SUBMODULES)
