"""Construction: frames, grasp matrices, facets, ranks and wrenches of a stack.

Positions, contact frames, grasp matrices, cone facets, ranks and primitive
wrenches of a stack of grasps, in numpy and in numba loops with the same
arithmetic.
"""
