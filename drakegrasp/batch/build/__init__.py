"""Construction: frames, grasp matrices, facets, ranks and wrenches of a stack.

Positions, contact frames, grasp matrices, cone facets, ranks and primitive
wrenches of a stack of grasps, in numpy and in numba loops with the same
arithmetic.
"""

from drakegrasp._lazy import lazy_exports

_SUBMODULES = (
    "construction",
    "construction_kernel",
    "kinds",
    "rowspace",
    "wrenches",
)

__getattr__, __dir__ = lazy_exports(__name__, globals(), {}, submodules=_SUBMODULES)
