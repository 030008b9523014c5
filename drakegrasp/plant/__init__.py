"""The Drake plant layer: models, scenes, contacts, Jacobians and grasp analysis.

Everything here takes ``(plant, plant_context, ...)`` as Drake users expect and
builds on the numpy core (:mod:`drakegrasp.contact`, :mod:`drakegrasp.grasp`,
:mod:`drakegrasp.closure`); the core never imports this package.  The context
may be the plant's or the root context of the diagram that holds the plant, and
``object_body`` may be positional (``find_contacts(plant, context, body)``); the
options after it are keyword-only (:mod:`drakegrasp.plant.validation`).
"""

from drakegrasp.plant.analysis import (
    GraspFromPlant,
    GraspReport,
    analyze_grasp,
    grasp_from_plant,
)
from drakegrasp.plant.closing import FingerClosure, HandClosure, close_hand
from drakegrasp.plant.contact_results import contacts_from_results
from drakegrasp.plant.contacts import (
    DEFAULT_DISTANCE_TOLERANCE,
    PlantContact,
    find_contacts,
    hand_bodies,
)
from drakegrasp.plant.curvature import contact_curvatures
from drakegrasp.plant.jacobians import (
    hand_jacobian,
    hand_velocity_indices,
    signed_distance_jacobian,
)
from drakegrasp.plant.models import models_dir, register_models, use_local_drake_models
from drakegrasp.plant.pose import PoseCheck
from drakegrasp.plant.scene import (
    DEFAULT_SCENE,
    Scene,
    SceneInfo,
    list_scenes,
    load_scene,
)

__all__ = [
    "DEFAULT_DISTANCE_TOLERANCE",
    "DEFAULT_SCENE",
    "FingerClosure",
    "GraspFromPlant",
    "GraspReport",
    "HandClosure",
    "PlantContact",
    "PoseCheck",
    "Scene",
    "SceneInfo",
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
    "register_models",
    "use_local_drake_models",
    "signed_distance_jacobian",
]
