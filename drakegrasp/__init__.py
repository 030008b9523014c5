"""drakegrasp: grasp analysis on top of Drake.

Contacts, contact frames and grasp matrices; form closure, force closure and
antipodal grasps decided with Drake's ``MathematicalProgram``; grasps read from a
``MultibodyPlant``.  Conventions: ``shared/CONVENTIONS.md``.
"""

from drakegrasp.antipodal import is_antipodal
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
from drakegrasp.errors import (
    GraspError,
    InvalidContactError,
    InvalidGraspError,
    InvalidOptionError,
    ModelError,
    NoContactsError,
    PenetrationError,
    SolverError,
)
from drakegrasp.friction_cone import (
    friction_cone_facets,
    friction_cone_generators,
)
from drakegrasp.grasp import Grasp, grasp_matrix, normal_grasp_matrix
from drakegrasp.results import AntipodalResult, ClosureResult, InternalForceResult

__version__ = "0.1.0"

__all__ = [
    "DEFAULT_TOL",
    "AntipodalResult",
    "ClosureResult",
    "Contact",
    "ContactModel",
    "Grasp",
    "GraspError",
    "InternalForceResult",
    "InvalidContactError",
    "InvalidGraspError",
    "InvalidOptionError",
    "ModelError",
    "NoContactsError",
    "PenetrationError",
    "ProgramVariables",
    "SolverError",
    "build_exact_force_closure_program",
    "build_force_closure_program",
    "build_form_closure_program",
    "build_internal_force_program",
    "contact_frame",
    "contact_frames",
    "force_closure",
    "force_closure_exact",
    "form_closure",
    "friction_cone_facets",
    "friction_cone_generators",
    "grasp_matrix",
    "internal_forces",
    "is_antipodal",
    "matrix_rank",
    "normal_grasp_matrix",
]
