"""drakegrasp: grasp analysis on top of Drake.

Contacts, contact frames and grasp matrices; form closure, force closure and
antipodal grasps decided with Drake's ``MathematicalProgram``; grasps read from a
``MultibodyPlant``.  Conventions: ``shared/CONVENTIONS.md``.
"""

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

__version__ = "0.1.0"

__all__ = [
    "Contact",
    "ContactModel",
    "Grasp",
    "GraspError",
    "InvalidContactError",
    "InvalidGraspError",
    "InvalidOptionError",
    "ModelError",
    "NoContactsError",
    "PenetrationError",
    "SolverError",
    "contact_frame",
    "contact_frames",
    "friction_cone_facets",
    "friction_cone_generators",
    "grasp_matrix",
    "normal_grasp_matrix",
]
