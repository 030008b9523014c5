"""Ferrari–Canny L1 ε of many grasps.

The driver, the compiled expanding-polytope kernel and its polytope updates,
and the two routes of a chunk's ε (kernel, Qhull).
"""

from drakegrasp._lazy import lazy_exports

_SUBMODULES = (
    "driver",
    "kernel",
    "polytope",
    "routes",
)

__getattr__, __dir__ = lazy_exports(__name__, globals(), {}, submodules=_SUBMODULES)
