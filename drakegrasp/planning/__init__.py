"""Finding grasps: candidates from object bodies, filters, ranking, shake test.

:func:`plan_grasps` samples antipodal parallel-jaw grasps on an object's
collision geometry (:mod:`~drakegrasp.planning.surface`), places the gripper
whose geometry it learns from the plant (:mod:`~drakegrasp.planning.gripper`),
rejects colliding poses, closes the fingers with Drake's distance queries and
ranks the grasps in the batch engine (:mod:`~drakegrasp.planning.ranking`);
the results are :mod:`~drakegrasp.planning.candidates`.  This folder imports
the plant, quality, batch and closure layers; nothing inside the package
imports it except the command line.
"""

from drakegrasp._lazy import lazy_exports

_SOURCES = {
    "drakegrasp.planning.candidates": ("GraspCandidate", "GraspCandidates"),
    "drakegrasp.planning.gripper": ("ParallelJaw", "parallel_jaw"),
    "drakegrasp.planning.planner": ("REASONS", "object_surface", "plan_grasps"),
    "drakegrasp.planning.scenes": ("PlanningScene", "planning_scene"),
    "drakegrasp.planning.shake": ("ShakeResult", "shake_test"),
    "drakegrasp.planning.surface": ("ObjectSurface",),
}

_SUBMODULES = (
    "candidates",
    "gripper",
    "planner",
    "ranking",
    "scenes",
    "shake",
    "surface",
)

__getattr__, __dir__ = lazy_exports(
    __name__, globals(), _SOURCES, submodules=_SUBMODULES
)

__all__ = [
    "REASONS",
    "GraspCandidate",
    "GraspCandidates",
    "ObjectSurface",
    "ParallelJaw",
    "PlanningScene",
    "ShakeResult",
    "object_surface",
    "parallel_jaw",
    "plan_grasps",
    "planning_scene",
    "shake_test",
]
