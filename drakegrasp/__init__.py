"""drakegrasp: grasp analysis on top of Drake.

Contacts, contact frames and grasp matrices; form closure, force closure and
antipodal grasps decided with Drake's ``MathematicalProgram``; grasps read from a
``MultibodyPlant``; quality metrics; pictures; a batch engine for many grasps.
Conventions: ``docs/conventions.md``.

Layers as folders, inner to outer (an import never points outwards):
``core`` (numpy only: contacts, G, cones, antipodal, curvature, validation),
``certificates`` (witnesses, their check and wording), ``closure`` (the
programs, verdicts and second order), then ``quality`` and ``plant``, then the
outer ring ``batch``, ``systems``, ``planning`` (finding grasps),
``visualization``, ``distributed`` and ``cli``.  ``docs/architecture.md``
draws the map.

Every public name is imported from its module when it is first read
(``drakegrasp._lazy``), so ``import drakegrasp`` and the ``drakegrasp``
command load only the layers they use: ``drakegrasp analyze`` imports no batch
engine, quality metrics, pictures or grasp monitor.
"""

from drakegrasp._lazy import lazy_exports

# Where each public name lives (the imports an eager package would run).
_SOURCES = {
    "drakegrasp.core.antipodal": ("AntipodalResult", "is_antipodal"),
    "drakegrasp.batch": (
        "BatchClosureResult",
        "batch_epsilon_l1",
        "batch_force_closure",
        "batch_form_closure",
        "evaluate_file",
    ),
    "drakegrasp.closure.programs": (
        "ProgramVariables",
        "build_exact_force_closure_program",
        "build_force_closure_program",
        "build_form_closure_program",
        "build_internal_force_program",
    ),
    "drakegrasp.closure.verdicts": (
        "force_closure",
        "force_closure_exact",
        "form_closure",
        "internal_forces",
    ),
    "drakegrasp.core.contact": (
        "Contact",
        "ContactModel",
        "contact_frame",
        "contact_frames",
    ),
    "drakegrasp.core.linalg": ("matrix_rank",),
    "drakegrasp.core.tolerances": ("DEFAULT_TOL",),
    "drakegrasp.core.curvature": (
        "ContactCurvature",
        "SurfaceCurvature",
    ),
    "drakegrasp.errors": (
        "BatchFileError",
        "GraspError",
        "InvalidContactError",
        "InvalidContextError",
        "InvalidGraspError",
        "InvalidOptionError",
        "InvalidPoseError",
        "JointLimitError",
        "ModelError",
        "NoContactsError",
        "PenetrationError",
        "SceneError",
        "SolverError",
        "UnreachableError",
    ),
    "drakegrasp.core.friction_cone": (
        "friction_cone_facets",
        "friction_cone_generators",
    ),
    "drakegrasp.core.grasp": (
        "Grasp",
        "grasp_matrix",
        "normal_grasp_matrix",
        "normalised_grasp_matrix",
    ),
    "drakegrasp.plant": (
        "FingerClosure",
        "GraspFromPlant",
        "GraspReport",
        "HandClosure",
        "PlantContact",
        "Scene",
        "analyze_grasp",
        "close_hand",
        "find_contacts",
        "grasp_from_plant",
        "hand_jacobian",
        "list_scenes",
        "load_scene",
        "register_models",
        "signed_distance_jacobian",
        "use_local_drake_models",
    ),
    "drakegrasp.quality": (
        "GraspQuality",
        "MaxWrenchResult",
        "build_max_resistible_wrench_program",
        "distance_to_singularity",
        "ferrari_canny",
        "grasp_quality",
        "grasp_singular_values",
        "hand_object_matrix",
        "isotropy",
        "lp2_margin",
        "manipulability_volume",
        "max_resistible_wrench",
        "min_singular_value",
        "primitive_wrenches",
        "uniformity_of_transformation",
        "wrench_ellipsoid_volume",
    ),
    "drakegrasp.closure.results": (
        "ClosureResult",
        "InternalForceResult",
    ),
    "drakegrasp.closure.second_order": (
        "SecondOrderResult",
        "second_order_form_closure",
    ),
    "drakegrasp.planning": (
        "GraspCandidate",
        "GraspCandidates",
        "ShakeResult",
        "plan_grasps",
        "planning_scene",
        "shake_test",
    ),
    "drakegrasp.systems.monitor": (
        "GraspMonitor",
        "GraspSample",
        "add_grasp_monitor",
    ),
    "drakegrasp.visualization": (
        "clear_grasp",
        "draw_grasp",
        "plot_planar_grasp",
        "plot_wrench_space",
    ),
}

# Subpackages reachable as attributes after a bare ``import drakegrasp``, and
# ``drakegrasp.examples``, the textbook grasps the README uses.
_SUBMODULES = {
    name: f"drakegrasp.{name}"
    for name in (
        "batch",
        "certificates",
        "closure",
        "core",
        "distributed",
        "errors",
        "planning",
        "plant",
        "quality",
        "systems",
        "visualization",
    )
} | {"examples": "drakegrasp.core.examples"}

__getattr__, __dir__ = lazy_exports(
    __name__, globals(), _SOURCES, submodules=_SUBMODULES
)

__version__ = "0.1.0"

__all__ = [
    "AntipodalResult",
    "BatchClosureResult",
    "BatchFileError",
    "ClosureResult",
    "Contact",
    "ContactCurvature",
    "ContactModel",
    "DEFAULT_TOL",
    "FingerClosure",
    "Grasp",
    "GraspCandidate",
    "GraspCandidates",
    "GraspError",
    "GraspFromPlant",
    "GraspMonitor",
    "GraspQuality",
    "GraspReport",
    "GraspSample",
    "HandClosure",
    "InternalForceResult",
    "InvalidContactError",
    "InvalidContextError",
    "InvalidGraspError",
    "InvalidOptionError",
    "InvalidPoseError",
    "JointLimitError",
    "MaxWrenchResult",
    "ModelError",
    "NoContactsError",
    "PenetrationError",
    "PlantContact",
    "ProgramVariables",
    "Scene",
    "SceneError",
    "SecondOrderResult",
    "ShakeResult",
    "SolverError",
    "SurfaceCurvature",
    "UnreachableError",
    "add_grasp_monitor",
    "analyze_grasp",
    "batch_epsilon_l1",
    "batch_force_closure",
    "batch_form_closure",
    "build_exact_force_closure_program",
    "build_force_closure_program",
    "build_form_closure_program",
    "build_internal_force_program",
    "build_max_resistible_wrench_program",
    "clear_grasp",
    "close_hand",
    "contact_frame",
    "contact_frames",
    "distance_to_singularity",
    "draw_grasp",
    "evaluate_file",
    "examples",
    "ferrari_canny",
    "find_contacts",
    "force_closure",
    "force_closure_exact",
    "form_closure",
    "friction_cone_facets",
    "friction_cone_generators",
    "grasp_from_plant",
    "grasp_matrix",
    "grasp_quality",
    "grasp_singular_values",
    "hand_jacobian",
    "hand_object_matrix",
    "internal_forces",
    "is_antipodal",
    "isotropy",
    "list_scenes",
    "load_scene",
    "lp2_margin",
    "manipulability_volume",
    "matrix_rank",
    "max_resistible_wrench",
    "min_singular_value",
    "normal_grasp_matrix",
    "normalised_grasp_matrix",
    "plan_grasps",
    "planning_scene",
    "plot_planar_grasp",
    "plot_wrench_space",
    "primitive_wrenches",
    "register_models",
    "second_order_form_closure",
    "shake_test",
    "signed_distance_jacobian",
    "uniformity_of_transformation",
    "use_local_drake_models",
    "wrench_ellipsoid_volume",
]
