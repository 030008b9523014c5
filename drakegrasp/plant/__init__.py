"""The Drake plant layer: models, scenes, contacts, Jacobians and grasp analysis.

Everything here takes ``(plant, plant_context, ...)`` as Drake users expect and
builds on the numpy core (:mod:`drakegrasp.core.contact`, :mod:`drakegrasp.core.grasp`,
:mod:`drakegrasp.closure.verdicts`); the core never imports this package.  The context
may be the plant's or the root context of the diagram that holds the plant, and
``object_body`` may be positional (``find_contacts(plant, context, body)``); the
options after it are keyword-only (:mod:`drakegrasp.plant.validation`).

Names are imported from their modules on first access
(``drakegrasp._lazy``): loading a scene and analysing it does not import
:mod:`~drakegrasp.plant.closing` or :mod:`~drakegrasp.plant.contact_results`.
"""

from drakegrasp._lazy import lazy_exports

_SOURCES = {
    "drakegrasp.plant.analysis": (
        "GraspFromPlant",
        "GraspReport",
        "analyze_grasp",
        "grasp_from_plant",
    ),
    "drakegrasp.plant.closing": (
        "FingerClosure",
        "HandClosure",
        "close_hand",
    ),
    "drakegrasp.plant.contact_results": ("contacts_from_results",),
    "drakegrasp.plant.contacts": (
        "DEFAULT_DISTANCE_TOLERANCE",
        "PlantContact",
        "find_contacts",
        "hand_bodies",
    ),
    "drakegrasp.plant.couplings": (
        "JointCoupling",
        "add_coupler_constraint",
        "add_models",
        "plant_couplings",
    ),
    "drakegrasp.plant.curvature": ("contact_curvatures",),
    "drakegrasp.plant.finger_antipodal": ("FingerAntipodal",),
    "drakegrasp.plant.jaws": (
        "JawContact",
        "ParallelJaws",
        "parallel_jaws",
    ),
    "drakegrasp.plant.jacobians": (
        "hand_jacobian",
        "hand_velocity_indices",
        "signed_distance_jacobian",
    ),
    "drakegrasp.plant.models": (
        "models_dir",
        "register_models",
        "use_local_drake_models",
    ),
    "drakegrasp.plant.options": ("AnalysisOptions",),
    "drakegrasp.plant.pose": ("PoseCheck",),
    "drakegrasp.plant.scale": ("object_radius",),
    "drakegrasp.plant.settle": (
        "SettleResult",
        "settle_object",
    ),
    "drakegrasp.plant.scene": (
        "DEFAULT_SCENE",
        "Scene",
        "SceneInfo",
        "list_scenes",
        "load_scene",
    ),
}

# Every module of the folder, an attribute after ``import drakegrasp.plant``.
_SUBMODULES = (
    "_closing_steps",
    "_shapes",
    "advancement",
    "analysis",
    "attachment",
    "closing",
    "contact_normals",
    "contact_pair",
    "contact_patches",
    "contact_results",
    "contacts",
    "couplings",
    "curvature",
    "exact_contact",
    "finger_antipodal",
    "fingers",
    "friction",
    "handles",
    "hydroelastic",
    "jacobians",
    "jaws",
    "load",
    "mesh_convexity",
    "models",
    "options",
    "pose",
    "scale",
    "scene",
    "scene_file",
    "scene_refs",
    "settle",
    "shape_queries",
    "sphere_tips",
    "validation",
)

__getattr__, __dir__ = lazy_exports(
    __name__, globals(), _SOURCES, submodules=_SUBMODULES
)

__all__ = [
    "AnalysisOptions",
    "DEFAULT_DISTANCE_TOLERANCE",
    "DEFAULT_SCENE",
    "FingerAntipodal",
    "FingerClosure",
    "GraspFromPlant",
    "GraspReport",
    "HandClosure",
    "JawContact",
    "JointCoupling",
    "ParallelJaws",
    "PlantContact",
    "PoseCheck",
    "Scene",
    "SceneInfo",
    "SettleResult",
    "add_coupler_constraint",
    "add_models",
    "analyze_grasp",
    "close_hand",
    "contacts_from_results",
    "contact_curvatures",
    "find_contacts",
    "grasp_from_plant",
    "hand_bodies",
    "hand_jacobian",
    "hand_velocity_indices",
    "list_scenes",
    "load_scene",
    "models_dir",
    "object_radius",
    "parallel_jaws",
    "plant_couplings",
    "register_models",
    "use_local_drake_models",
    "settle_object",
    "signed_distance_jacobian",
]
