"""The closure LPs of a stack: ``d*`` in compiled kernels.

``d*`` (:mod:`~drakegrasp.batch.lp.dstar`) from an exact active-set method for
small null spaces and a block interior-point method for the rest, compiled
with numba, with a numpy route of the same iteration where numba is missing.
"""
