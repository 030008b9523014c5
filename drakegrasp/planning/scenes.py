"""A planning scene: a free-floating gripper and an object, built from model URLs.

:func:`planning_scene` builds the plant :func:`~drakegrasp.planning.planner.plan_grasps`
needs (the hand's base a free body) and keeps the recipe, ``add_models``,
that :func:`~drakegrasp.planning.shake.shake_test` replays in its own
discrete-time plant.  A user with a scene of their own (a table, clutter)
writes the same kind of function and builds the plant themselves.
"""

from __future__ import annotations

import inspect
import os
from dataclasses import dataclass
from typing import Any

from pydrake.math import RigidTransform
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from drakegrasp.core.calls import checked_call
from drakegrasp.core.validation import describe, path_text
from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.plant.couplings import add_models as add_coupled_models
from drakegrasp.plant.models import (
    check_obj_vertices,
    new_parser,
    register_models,
    use_local_drake_models,
)
from drakegrasp.plant.scene_refs import (
    add_named_package,
    package_folder,
    package_name,
)
from drakegrasp.plant.validation import check_rigid_transform, resolve_body

__all__ = ["WSG_URL", "PlanningScene", "planning_scene", "scene_from_models"]

WSG_URL = "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf"
"""Drake's Schunk WSG-50 with its four tip spheres per finger."""


@checked_call
@dataclass(frozen=True, eq=False)
class PlanningScene:
    """A built planning scene.

    Attributes
    ----------
    diagram : Diagram
    plant : MultibodyPlant
    context : Context
        The diagram's root context (object at ``X_WO``).
    hand : ModelInstanceIndex
    object_body : RigidBody or None
    add_models : callable
        ``add_models(plant, parser) -> (hand, object body name)``, the recipe.
    """

    diagram: Any
    plant: Any
    context: Any
    hand: Any
    object_body: Any
    add_models: Any


@checked_call
def planning_scene(
    object_url: str | None = None,
    *,
    hand_url: str = WSG_URL,
    X_WO: RigidTransform | None = None,
    models_dir=None,
    package_map: dict | None = None,
) -> PlanningScene:
    """A free gripper and a free object in a new plant (time step 0).

    Parameters
    ----------
    object_url : str, path or None, optional
        ``package://`` URL or file path of the object's model (one body with
        collision geometry is the object: the model's first such body, that
        of a nested ``<model>`` after those of the model holding it); None
        (default) for a scene with the hand only (planning on a point cloud).
    hand_url : str or path, optional
        The gripper's model (default Drake's WSG-50 with tip spheres); its
        base is left free.  Of nested ``<model>`` elements, the hand is the first
        model instance that holds a body.
    X_WO : RigidTransform, optional
        The object's pose (default the identity): a finite translation and a
        proper rotation.
    models_dir : path, optional
        Local ``drake_models`` folder
        (:func:`~drakegrasp.plant.models.use_local_drake_models`).
    package_map : dict of str to path, optional
        More packages for ``package://NAME/...`` URLs of the object and the
        hand: ``{NAME: folder}`` (``drakegrasp plan --package NAME=DIR``).  A
        folder given for ``drake_models`` replaces Drake's download of it;
        ``drake`` and ``drakegrasp`` are built in and refused.

    Raises
    ------
    ModelError
        A model that does not load, or a path (not a URL) that is not a file.
    InvalidOptionError
        A URL that is not a string or path, or an ``X_WO`` that is not a
        finite rigid pose.
    """
    must = "a package:// URL or a file path (a str or an os.PathLike)"
    if object_url is not None:
        object_url = path_text("object_url", object_url, must=must)
    hand_url = path_text("hand_url", hand_url, must=must)
    if models_dir is not None:
        models_dir = path_text(
            "models_dir", models_dir, must="a folder name (a str or an os.PathLike)"
        )
    for name, url in (("object_url", object_url), ("hand_url", hand_url)):
        if url is not None and "://" not in url and not os.path.isfile(url):
            # Checked before the hand loads: a wrong object name was reported
            # as the hand's failure to download drake_models, offline.
            what = "a directory" if os.path.isdir(url) else "not a file"
            raise ModelError(
                f"{name} {url!r} is {what}: give a model file (.sdf, .urdf, "
                ".obj, ...) or a package:// URL"
            )
    X_WO = RigidTransform() if X_WO is None else check_rigid_transform("X_WO", X_WO)
    packages = _checked_packages(package_map)

    def add_models(plant, parser):
        use_local_drake_models(parser, models_dir)
        register_models(parser)
        for name, folder in packages:  # drake_models too: the user's folder wins
            add_named_package(parser.package_map(), name, folder)
        try:
            hands = _add(parser, hand_url)
            objs = None if object_url is None else _add(parser, object_url)
        except RuntimeError as exc:  # Drake's parser errors
            raise ModelError(f"could not load a model: {exc}") from exc
        hand = _hand_instance(plant, hands, hand_url)
        if objs is None:
            return hand, None
        body = _object_body(plant, objs, object_url)
        plant.SetDefaultFloatingBaseBodyPose(body, X_WO)
        model = plant.GetModelInstanceName(body.model_instance())
        return hand, f"{model}::{body.name()}"

    return scene_from_models(add_models)


def _checked_packages(package_map) -> list[tuple[str, str]]:
    """``package_map``'s ``(name, folder)`` pairs, each folder an existing one."""
    if package_map is None:
        return []
    if not isinstance(package_map, dict):
        raise InvalidOptionError(
            f"package_map must be a dict of package name to folder, got "
            f"{type(package_map).__name__}"
        )
    pairs = []
    for name, folder in package_map.items():
        name = package_name(name, error=InvalidOptionError)
        if name in ("drake", "drakegrasp"):  # (refused again where it is added)
            raise InvalidOptionError(
                f"package {describe(name)} is built in and cannot be replaced"
            )
        where = f"package {describe(name)}"
        # as a scene file's packages are read: "" the current folder, ~ expanded
        folder = package_folder(where, folder, error=InvalidOptionError)
        if not os.path.isdir(folder):
            raise InvalidOptionError(
                f"{where}: {describe(str(folder))} is not a folder"
            )
        pairs.append((name, str(folder.resolve())))
    return pairs


@checked_call
def scene_from_models(add_models) -> PlanningScene:
    """A planning scene built by a recipe of one's own (time step 0).

    Parameters
    ----------
    add_models : callable
        ``add_models(plant, parser) -> (hand, object body)``: adds the hand
        (its base left free) and the object to a fresh plant, and returns
        the hand's model instance and the object body's scoped name
        ``model::body`` (None: a hand alone, for a point cloud).  The shake
        test builds its plants with it too.

    Returns
    -------
    PlanningScene
        The finalized plant in its diagram, a default context and the recipe.
    """
    # A class is callable but no recipe: float(plant, parser) raised a bare
    # TypeError from the call below.
    if not callable(add_models) or inspect.isclass(add_models):
        raise InvalidOptionError(
            "add_models must be a function add_models(plant, parser) -> (hand, "
            f"object body name), got {describe(add_models)}"
        )
    try:
        inspect.signature(add_models).bind(None, None)
    except TypeError:
        raise InvalidOptionError(
            "add_models must take two arguments, add_models(plant, parser); "
            f"{describe(add_models)} takes {inspect.signature(add_models)}"
        ) from None
    except ValueError:  # a builtin without a signature to read
        pass
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    returned = add_models(plant, new_parser(plant, "the planning scene"))
    if not (isinstance(returned, tuple | list) and len(returned) == 2):
        raise InvalidOptionError(
            "add_models must return (hand model instance, object body name "
            f"'model::body' or None), got {describe(returned)}"
        )
    hand, name = returned
    if name is not None and not isinstance(name, str):
        raise InvalidOptionError(
            "add_models must return the object body's scoped name 'model::body' "
            f"(or None), got {describe(name)}"
        )
    plant.Finalize()
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    object_body = None if name is None else resolve_body(plant, name)
    return PlanningScene(diagram, plant, context, hand, object_body, add_models)


def _add(parser, url: str) -> list:
    """Every model instance that the file at ``url`` adds, in the parser's order.

    A file of nested SDFormat models adds one instance per ``<model>``, the
    outer ones first and possibly without a body of their own.
    """
    # Through drakegrasp's loader, which records a <mimic>'s coupling on the
    # plant: a bare Parser leaves a coupled hand's constraints unreadable, and
    # the planner refuses such a plant.
    if "://" in url:  # (a plain str: read by planning_scene's path_text)
        return list(add_coupled_models(parser, url=url))
    if url.lower().endswith(".obj"):
        check_obj_vertices(url)
    return list(add_coupled_models(parser, url))


def _hand_instance(plant, instances: list, url) -> Any:
    """The hand's model instance: the first of ``instances`` that holds a body.

    An SDFormat file whose hand is a nested ``<model>`` (``robot`` holding
    ``robot::hand``) adds the empty outer instance first; planning on it
    found no bodies, and the command line has no way to name the inner one.
    """
    for instance in instances:
        if plant.GetBodyIndices(instance):
            return instance
    raise ModelError(f"the hand's model {str(url)!r} has no bodies")


def _object_body(plant, instances: list, url) -> Any:
    """The object: the first body with collision geometry of ``instances``.

    In the order the file adds its models (a nested ``<model>`` after the one
    holding it) and their bodies; the first body at all where none has
    collision geometry (which the planner then refuses, naming it).
    """
    bodies = [
        plant.get_body(index)
        for instance in instances
        for index in plant.GetBodyIndices(instance)
    ]
    if not bodies:
        raise ModelError(f"the object's model {str(url)!r} has no bodies")
    for body in bodies:
        if plant.GetCollisionGeometriesForBody(body):
            return body
    return bodies[0]
