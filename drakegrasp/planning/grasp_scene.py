"""A planned grasp written as a scene file that ``drakegrasp analyze`` loads.

:func:`grasp_scene_text` takes a candidate of
:func:`~drakegrasp.planning.plan_grasps` and the model files the hand and the
object came from, and writes the scene of that grasp (``docs/scene_format.md``):
the hand's model with every joint where the candidate puts it, its base welded
to the world at ``X_WH``, the object free at ``X_WO``, and a ``drakegrasp:``
section with the plan's friction and contact model.  The directives are
written by Drake's own serializer (``yaml_dump_typed`` of
``ModelDirectives``), so Drake reads back exactly what was written.

A file given as a path is referred to relative to the scene's folder, which
the scene loader accepts where it lies inside that folder; elsewhere
``drakegrasp analyze --allow-any-file`` trusts it.  ``package://`` and
``file://`` URLs are kept as they are.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import yaml
from pydrake.common.schema import Transform
from pydrake.common.yaml import yaml_dump_typed
from pydrake.multibody.parsing import (
    AddModel,
    AddWeld,
    ModelDirective,
    ModelDirectives,
)
from pydrake.multibody.tree import JointIndex

from drakegrasp.core.validation import check_length, describe, path_text
from drakegrasp.errors import InvalidOptionError, ModelError
from drakegrasp.planning.candidates import GraspCandidate
from drakegrasp.plant.validation import (
    plant_context_of,
    resolve_body,
    resolve_object_body,
)

__all__ = ["grasp_scene_text"]


def grasp_scene_text(
    plant,
    plant_context,
    candidate: GraspCandidate,
    *,
    object_body,
    hand_file: str | os.PathLike,
    object_file: str | os.PathLike,
    mu: float | str,
    contact_model: str | None = None,
    torsional_friction: float | None = None,
    characteristic_length: float | None = None,
    folder: str | os.PathLike = ".",
    description: str | None = None,
) -> str:
    """The scene file (YAML text) of a planned grasp.

    Parameters
    ----------
    plant : MultibodyPlant
        The plant the candidate was planned in (its hand base free).
    plant_context : Context
        Its context as planned (the plant's or the diagram's): the hand's
        joints that the candidate does not set (a pre-shape's passive
        joints) are written as they stand there.  Not changed.
    candidate : GraspCandidate
    object_body : RigidBody, BodyIndex or str
        The object (a free body of its own model instance).
    hand_file, object_file : str or path
        The model files (or ``package://`` / ``file://`` URLs) the hand's and
        the object's model instances were loaded from.
    mu : float or "plant"
        The friction coefficient the grasp was planned with, or ``"plant"``
        (each pair's from the models, as the scene file's ``mu: plant``).
    contact_model, torsional_friction : optional
        As planned (default: the candidate's ``contact_options``).
    characteristic_length : float, optional
        The length (metres) moments are compared with forces by, and a soft
        finger's torsion limited with (the scene's ``characteristic_length``).
        Default: for soft fingers the candidate's ``torque_scale``, so that
        ``analyze`` of the file finds the planned torsion and ε; for other
        models none (the grasp's own).

        When the candidate was planned for a mass other than the model's
        (``candidate.object_mass``, ``plan --mass``), the scene gets
        ``load: gravity`` and that ``object_mass``: ``analyze`` of the file
        weighs what was planned for.  A massless model has no centre of mass
        to weigh it at: the scene's ``load`` is then the weight as a wrench
        about O's origin, acting at the candidate's ``reference_point``, as
        planned.
    folder : str or path, optional
        The folder the scene file will be written to: paths are written
        relative to it.
    description : str, optional
        One line for ``drakegrasp scenes``.

    Returns
    -------
    str
        The scene file's text.

    Raises
    ------
    ModelError
        The hand's base or the object is not a body of the plant, the hand
        spans several model instances, the hand or the object is a
        ``<model>`` nested in another (Drake's directives cannot set its
        joints or pose), or the object shares its model instance with the
        hand or is not free.
    InvalidOptionError
        A file that is not a string or path.
    """
    must = "a model file's path or URL (a str or an os.PathLike)"
    hand_file = path_text("hand_file", hand_file, must=must)
    object_file = path_text("object_file", object_file, must=must)
    # "" is the current folder (os.path.dirname of a bare file name)
    folder = path_text(
        "folder", folder, must="a folder (a str or an os.PathLike)", empty=True
    )
    planned = plant_context_of(plant, plant_context)  # (checks the plant first)
    if not isinstance(candidate, GraspCandidate):
        raise InvalidOptionError(
            f"candidate must be a GraspCandidate, got {describe(candidate)}"
        )
    ctx = plant.CreateDefaultContext()  # a copy: the caller's stays as it is
    ctx.SetTimeStateAndParametersFrom(planned)
    body = resolve_object_body(plant, object_body)
    base = resolve_body(plant, candidate.hand_base)
    candidate.apply(plant, ctx, object_body=body)
    hand = base.model_instance()
    if body.model_instance() == hand:
        raise ModelError(
            f"the object {body.name()!r} is in the hand's model instance: a scene "
            "file adds them as two models"
        )
    if not body.is_floating_base_body():
        raise ModelError(
            f"the object {body.name()!r} is not a free body: its scene file would "
            "place it with a weld of its own, which this writer does not know"
        )
    for what, instance in (("hand", hand), ("object", body.model_instance())):
        name = plant.GetModelInstanceName(instance)
        if "::" in name:  # Drake's directives set no joint of a nested model
            raise ModelError(
                f"the {what}'s model instance {name!r} is a <model> nested in "
                f"{name.rpartition('::')[0]!r}: a scene file's add_model sets "
                "the joint positions and free-body poses of the model it adds, "
                "not of its nested ones, so no scene file holds this grasp; "
                "load the nested model's own file instead"
            )
    names = {plant.GetModelInstanceName(hand)}
    names |= {n.rpartition("::")[0] for n in candidate.joint_names}
    if len(names) != 1:
        raise ModelError(
            f"the hand spans the model instances {sorted(names)}: a scene file of "
            "the grasp adds one model for the hand"
        )
    hand_name = plant.GetModelInstanceName(hand)
    object_name = plant.GetModelInstanceName(body.model_instance())
    q = plant.GetPositions(ctx)
    positions = {}
    for i in plant.GetJointIndices(hand):
        joint = plant.get_joint(JointIndex(int(i)))
        n = joint.num_positions()
        if n == 0 or joint.child_body().index() == base.index():
            continue  # a weld, or the base's own floating joint
        start = joint.position_start()
        positions[joint.name()] = q[start : start + n].copy()
    X_WO = plant.EvalBodyPoseInWorld(ctx, body)
    directives = ModelDirectives(
        directives=[
            ModelDirective(
                add_model=AddModel(
                    file=_reference(hand_file, folder),
                    name=hand_name,
                    default_joint_positions=positions,
                )
            ),
            ModelDirective(
                add_weld=AddWeld(
                    parent="world",
                    child=f"{hand_name}::{base.name()}",
                    X_PC=Transform(candidate.X_WH),
                )
            ),
            ModelDirective(
                add_model=AddModel(
                    file=_reference(object_file, folder),
                    name=object_name,
                    default_free_body_pose={body.name(): Transform(X_WO)},
                )
            ),
        ]
    )
    options = candidate.contact_options
    if contact_model is None:
        contact_model = options.get("contact_model") or "hard_finger"
    if torsional_friction is None:
        torsional_friction = options.get("torsional_friction")
    section = {
        "description": description
        or f"The grasp of plan sample {candidate.sample} (drakegrasp plan).",
        "object_body": f"{object_name}::{body.name()}",
        "hand": hand_name,
        "mu": mu if mu == "plant" else float(mu),
        "contact_model": str(contact_model),
    }
    if torsional_friction is not None:
        section["torsional_friction"] = float(torsional_friction)
    if characteristic_length is not None:
        section["characteristic_length"] = check_length(
            "characteristic_length", characteristic_length, error=InvalidOptionError
        )
    elif str(contact_model) == "soft_finger" and math.isfinite(candidate.torque_scale):
        section["characteristic_length"] = float(candidate.torque_scale)
    tolerance = options.get("distance_tolerance")
    if tolerance is not None:
        section["distance_tolerance"] = float(tolerance)
    planned, model = float(candidate.object_mass), float(body.get_mass(ctx))
    if math.isfinite(planned) and planned > 0.0 and planned != model:
        if model > 0.0:  # the weight planned for, at the model's centre of mass
            section["load"] = "gravity"
            section["object_mass"] = planned
        else:  # no centre of mass in the model: the weight where the plan put it
            g_W = np.asarray(plant.gravity_field().gravity_vector(), dtype=float)
            f_O = X_WO.rotation().matrix().T @ (planned * g_W)
            m_O = np.cross(np.asarray(candidate.reference_point, dtype=float), f_O)
            section["load"] = [float(v) for v in np.concatenate([f_O, m_O])]
    drakegrasp = yaml.safe_dump(
        {"drakegrasp": section}, sort_keys=False, allow_unicode=True
    )
    return yaml_dump_typed(directives) + drakegrasp


def _reference(file: str, folder: str) -> str:
    """A model file as the scene refers to it: a URL as it is, else a path."""
    if "://" in file:
        return file
    path = Path(file).resolve()
    try:
        return Path(os.path.relpath(path, Path(folder).resolve())).as_posix()
    except ValueError:  # another drive (Windows): no relative path
        return path.as_posix()
