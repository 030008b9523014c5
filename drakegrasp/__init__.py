"""drakegrasp: grasp analysis on top of Drake.

Contacts, contact frames and grasp matrices; form closure, force closure and
antipodal grasps decided with Drake's ``MathematicalProgram``; grasps read from a
``MultibodyPlant``; quality metrics; pictures; a batch engine for many grasps.
Conventions: ``docs/conventions.md``.

Layers, inner to outer (an import never points outwards): the numpy core
(``contact``, ``grasp``, ``friction_cone``, ``antipodal``, ``examples``), the
programs on ``pydrake.solvers`` (``closure``, ``quality``), the plant adapters
(``plant``), and the outside ring (``visualization``, ``batch``, ``systems``,
``cli``).
"""

from drakegrasp import examples
from drakegrasp.antipodal import is_antipodal
from drakegrasp.batch import (
    BatchClosureResult,
    batch_epsilon_l1,
    batch_force_closure,
    batch_form_closure,
    evaluate_file,
)
from drakegrasp.closure import (
    DEFAULT_TOL,
    ProgramVariables,
    build_exact_force_closure_program,
    build_force_closure_program,
    build_form_closure_program,
    build_internal_force_program,
    force_closure,
    force_closure_exact,
    form_closure,
    internal_forces,
    matrix_rank,
)
from drakegrasp.contact import Contact, ContactModel, contact_frame, contact_frames
from drakegrasp.curvature import ContactCurvature, SurfaceCurvature
from drakegrasp.errors import (
    BatchFileError,
    GraspError,
    InvalidContactError,
    InvalidContextError,
    InvalidGraspError,
    InvalidOptionError,
    InvalidPoseError,
    JointLimitError,
    ModelError,
    NoContactsError,
    PenetrationError,
    SceneError,
    SolverError,
    UnreachableError,
)
from drakegrasp.friction_cone import (
    friction_cone_facets,
    friction_cone_generators,
)
from drakegrasp.grasp import (
    Grasp,
    grasp_matrix,
    normal_grasp_matrix,
    normalised_grasp_matrix,
)
from drakegrasp.plant import (
    FingerClosure,
    GraspFromPlant,
    GraspReport,
    HandClosure,
    PlantContact,
    Scene,
    analyze_grasp,
    close_hand,
    find_contacts,
    grasp_from_plant,
    hand_jacobian,
    list_scenes,
    load_scene,
    register_models,
    signed_distance_jacobian,
    use_local_drake_models,
)
from drakegrasp.quality import (
    GraspQuality,
    MaxWrenchResult,
    build_max_resistible_wrench_program,
    distance_to_singularity,
    ferrari_canny,
    grasp_quality,
    grasp_singular_values,
    hand_object_matrix,
    isotropy,
    lp2_margin,
    manipulability_volume,
    max_resistible_wrench,
    min_singular_value,
    primitive_wrenches,
    uniformity_of_transformation,
    wrench_ellipsoid_volume,
)
from drakegrasp.results import AntipodalResult, ClosureResult, InternalForceResult
from drakegrasp.second_order import SecondOrderResult, second_order_form_closure
from drakegrasp.systems import GraspMonitor, GraspSample, add_grasp_monitor
from drakegrasp.visualization import (
    clear_grasp,
    draw_grasp,
    plot_planar_grasp,
    plot_wrench_space,
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
    "plot_planar_grasp",
    "plot_wrench_space",
    "primitive_wrenches",
    "register_models",
    "second_order_form_closure",
    "signed_distance_jacobian",
    "uniformity_of_transformation",
    "use_local_drake_models",
    "wrench_ellipsoid_volume",
]
