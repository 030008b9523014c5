"""Finding grasps: candidates from object bodies, filters, ranking, shake test.

:func:`plan_grasps` samples antipodal parallel-jaw grasps on an object's
collision geometry (:mod:`~drakegrasp.planning.surface`), places the gripper
whose geometry it learns from the plant (:mod:`~drakegrasp.planning.gripper`;
a multi-finger hand takes approach directions, palm stand-offs and a
pre-shape, :mod:`~drakegrasp.planning.approach`, and closes with
``close_hand``, :mod:`~drakegrasp.planning.multifinger`),
rejects colliding poses and closes the fingers with Drake's distance queries
(:mod:`~drakegrasp.planning.placement`) or on a point cloud
(:mod:`~drakegrasp.planning.cloud`; multi-finger hands,
:mod:`~drakegrasp.planning.cloud_hand`), and ranks the grasps
(:mod:`~drakegrasp.planning.ranking`, :mod:`~drakegrasp.planning.weight`,
:mod:`~drakegrasp.planning.motors`, :mod:`~drakegrasp.planning.opposition`);
the results are :mod:`~drakegrasp.planning.candidates`, and
:mod:`~drakegrasp.planning.shake` checks them in a Drake simulation
(:mod:`~drakegrasp.planning.shake_ranking`: the best ones, those that held
first).  This
folder imports the plant, quality, batch and closure layers; nothing inside
the package imports it except the command line.
"""

from drakegrasp._lazy import lazy_exports

_SOURCES = {
    "drakegrasp.planning.approach": ("MultiFingerHand", "multi_finger_hand"),
    "drakegrasp.planning.candidates": ("GraspCandidate", "GraspCandidates"),
    "drakegrasp.planning.gripper": ("ParallelJaw", "parallel_jaw"),
    "drakegrasp.planning.multifinger": ("hand_is_parallel_jaw",),
    "drakegrasp.planning.planner": ("REASONS", "object_surface", "plan_grasps"),
    "drakegrasp.planning.scenes": (
        "PlanningScene",
        "planning_scene",
        "scene_from_models",
    ),
    "drakegrasp.planning.shake": ("shake_test",),
    "drakegrasp.planning.shake_result": ("ShakeResult",),
    "drakegrasp.planning.shake_ranking": ("ShakenCandidates", "shake_candidates"),
    "drakegrasp.planning.surface": ("ObjectSurface",),
}

_SUBMODULES = (
    "approach",
    "candidates",
    "centring",
    "checks",
    "cloud",
    "cloud_hand",
    "cloud_normals",
    "cloud_spacing",
    "cloud_tips",
    "grasp_scene",
    "gripper",
    "motors",
    "multifinger",
    "needed",
    "opposition",
    "placement",
    "planner",
    "ranking",
    "reclose",
    "scenes",
    "shake",
    "shake_ranking",
    "shake_result",
    "squeeze",
    "surface",
    "turned_gravity",
    "weight",
)

__getattr__, __dir__ = lazy_exports(
    __name__, globals(), _SOURCES, submodules=_SUBMODULES
)

__all__ = [
    "REASONS",
    "GraspCandidate",
    "GraspCandidates",
    "MultiFingerHand",
    "ObjectSurface",
    "ParallelJaw",
    "PlanningScene",
    "ShakeResult",
    "ShakenCandidates",
    "hand_is_parallel_jaw",
    "multi_finger_hand",
    "object_surface",
    "parallel_jaw",
    "plan_grasps",
    "planning_scene",
    "scene_from_models",
    "shake_candidates",
    "shake_test",
]
