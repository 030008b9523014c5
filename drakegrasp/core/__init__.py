"""The numpy core: contacts, frames, grasp matrices, friction cones, antipodal pairs.

Everything here is numpy (no solver, no plant): contacts and their frames
(:mod:`~drakegrasp.core.contact`), the grasp matrix **G** and its relatives
(:mod:`~drakegrasp.core.grasp`), friction cones and their support functions
(:mod:`~drakegrasp.core.friction_cone`), the antipodal test, surface curvature,
the textbook example grasps, input validation, the check of every public call's
arguments (:mod:`~drakegrasp.core.calls`), the tolerance table, rank and null
spaces (:mod:`~drakegrasp.core.linalg`), the JSON helper and the test of a
regular file (:mod:`~drakegrasp.core.files`).  Every other layer imports from
here; nothing here imports another layer.
"""

from drakegrasp._lazy import lazy_exports

_SUBMODULES = (
    "antipodal",
    "calls",
    "contact",
    "curvature",
    "deferred",
    "deprecation",
    "examples",
    "files",
    "friction_cone",
    "grasp",
    "linalg",
    "serialize",
    "tolerances",
    "validation",
)

__getattr__, __dir__ = lazy_exports(__name__, globals(), {}, submodules=_SUBMODULES)
