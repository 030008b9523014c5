"""Scene files: Drake model directives plus a small ``drakegrasp:`` section.

A scene is a YAML file that Drake itself can read (its ``directives:`` list is
ordinary :class:`~pydrake.multibody.parsing.ModelDirectives`, with the hand's
joint values in ``default_joint_positions`` and the object's pose in
``default_free_body_pose``), plus a ``drakegrasp:`` mapping::

    drakegrasp:
      description: one line shown by `drakegrasp scenes`
      object_body: box::box          # scoped body name (model::body)
      hand: gripper                  # model instance name, or a list of bodies
      mu: 0.5                        # friction coefficient
      contact_model: hard_finger     # frictionless | hard_finger | soft_finger
      torsional_friction: 0.1        # optional, for soft fingers
      plane: yz                      # optional: analyse in this object-frame plane
      distance_tolerance: 1.0e-4     # optional, metres

``package://drakegrasp/...`` URIs resolve to the models shipped with
drakegrasp.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import yaml
from pydrake.multibody.parsing import (
    LoadModelDirectivesFromString,
    Parser,
    ProcessModelDirectives,
)
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex, RigidBody
from pydrake.systems.framework import Context, Diagram, DiagramBuilder

from drakegrasp.contact import ContactModel
from drakegrasp.errors import GraspError, ModelError
from drakegrasp.plant.jacobians import PLANES
from drakegrasp.plant.models import models_dir, register_models
from drakegrasp.plant.validation import resolve_body

__all__ = [
    "DEFAULT_SCENE",
    "Scene",
    "SceneInfo",
    "list_scenes",
    "load_scene",
    "resolve_body",
    "scene_path",
]

DEFAULT_SCENE = "parallel_jaw_box"
"""Name of the scene that ``drakegrasp analyze`` uses without an argument."""

_KEYS = {
    "description",
    "object_body",
    "hand",
    "mu",
    "contact_model",
    "torsional_friction",
    "plane",
    "distance_tolerance",
}


@dataclass(frozen=True)
class SceneInfo:
    """The ``drakegrasp:`` section of a scene file.

    Attributes
    ----------
    name : str
        File stem.
    path : pathlib.Path
        The scene file.
    description : str
        One-line description.
    object_body : str
        Scoped name of the object's body, ``"model::body"``.
    hand : str or tuple of str or None
        Model-instance name of the hand, scoped body names, or None (every body
        that is not the object, not welded to the world and not part of the
        object's model instance).
    mu : float
        Friction coefficient.
    contact_model : ContactModel
    torsional_friction : float
        Torsional friction coefficient of soft fingers.
    plane : str or None
        ``"xy"``, ``"yz"`` or ``"zx"`` for a planar analysis in that plane of the
        object frame, None for a spatial one.
    distance_tolerance : float
        ``|ψ|`` (metres) below which a pair is in contact.
    """

    name: str
    path: Path
    description: str
    object_body: str
    hand: str | tuple[str, ...] | None
    mu: float
    contact_model: ContactModel
    torsional_friction: float
    plane: str | None
    distance_tolerance: float


@dataclass(frozen=True)
class Scene:
    """A loaded scene: the diagram, its plant and the context the file sets.

    Attributes
    ----------
    info : SceneInfo
        What the file's ``drakegrasp:`` section says.
    diagram : pydrake.systems.framework.Diagram
        Plant and scene graph.
    plant : pydrake.multibody.plant.MultibodyPlant
    context : pydrake.systems.framework.Context
        The diagram's default context (joint values and object pose of the file).
    plant_context : pydrake.systems.framework.Context
        The plant's subcontext of ``context``.
    object_body : pydrake.multibody.tree.RigidBody
    hand : ModelInstanceIndex or tuple of RigidBody or None
        Argument to pass as ``hand=`` to :func:`drakegrasp.find_contacts`.
    """

    info: SceneInfo
    diagram: Diagram
    plant: MultibodyPlant
    context: Context
    plant_context: Context
    object_body: RigidBody
    hand: ModelInstanceIndex | tuple[RigidBody, ...] | None

    @property
    def name(self) -> str:
        """The scene's name (file stem)."""
        return self.info.name

    def analysis_options(self) -> dict:
        """Keyword arguments of :func:`drakegrasp.analyze_grasp` from the file."""
        return {
            "object_body": self.object_body,
            "hand": self.hand,
            "mu": self.info.mu,
            "contact_model": self.info.contact_model,
            "torsional_friction": self.info.torsional_friction,
            "plane": self.info.plane,
            "distance_tolerance": self.info.distance_tolerance,
        }


def scenes_dir() -> Path:
    """Directory of the shipped scene files."""
    return models_dir() / "scenes"


def list_scenes() -> list[SceneInfo]:
    """The shipped scenes, sorted by name (the default scene included)."""
    return [read_scene_info(p) for p in sorted(scenes_dir().glob("*.yaml"))]


def scene_path(path_or_name: str | Path) -> Path:
    """The file of a scene given by path or by the name of a shipped scene.

    Raises
    ------
    ModelError
        If it is neither an existing file nor a shipped scene's name.
    """
    candidate = Path(path_or_name)
    if candidate.is_file():
        return candidate
    name = str(path_or_name)
    shipped = scenes_dir() / f"{name.removesuffix('.yaml')}.yaml"
    if "/" not in name and shipped.is_file():
        return shipped
    names = ", ".join(p.stem for p in sorted(scenes_dir().glob("*.yaml")))
    raise ModelError(
        f"scene {name!r} not found: no such file and no shipped scene of that "
        f"name (shipped scenes: {names})"
    )


class _TolerantLoader(yaml.SafeLoader):
    """Safe YAML loader that accepts Drake's tags (``!Rpy``...) as plain data."""


def _construct_tagged(loader, suffix, node):
    if isinstance(node, yaml.MappingNode):
        return loader.construct_mapping(node, deep=True)
    if isinstance(node, yaml.SequenceNode):
        return loader.construct_sequence(node, deep=True)
    return loader.construct_scalar(node)


_TolerantLoader.add_multi_constructor("!", _construct_tagged)


def _read_yaml(path: Path) -> tuple[str, dict]:
    try:
        text = path.read_text()
    except OSError as e:
        raise ModelError(f"cannot read scene file {str(path)!r}: {e}") from None
    try:
        data = yaml.load(text, Loader=_TolerantLoader)
    except yaml.YAMLError as e:
        first = " ".join(str(e).split())
        raise ModelError(
            f"scene file {str(path)!r} is not valid YAML: {first}"
        ) from None
    if not isinstance(data, dict):
        raise ModelError(
            f"scene file {str(path)!r} must be a YAML mapping with 'directives' "
            f"and 'drakegrasp' keys, got {type(data).__name__}"
        )
    return text, data


def _number(path: Path, key: str, value, *, positive: bool = False) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ModelError(
            f"scene {str(path)!r}: drakegrasp.{key} must be a number, got {value!r}"
        ) from None
    if not (x >= 0.0) or (positive and x == 0.0) or x == float("inf"):
        bound = "> 0" if positive else ">= 0"
        raise ModelError(
            f"scene {str(path)!r}: drakegrasp.{key} must be finite and {bound}, "
            f"got {value!r}"
        )
    return x


def read_scene_info(path: str | Path) -> SceneInfo:
    """Read and check the ``drakegrasp:`` section of a scene file.

    Raises
    ------
    ModelError
        On an unreadable file, invalid YAML, a missing or unknown key, or a bad
        value; the message names the file and the key.
    """
    path = Path(path)
    _, data = _read_yaml(path)
    section = data.get("drakegrasp")
    if not isinstance(section, dict):
        raise ModelError(
            f"scene {str(path)!r} has no 'drakegrasp:' mapping (it needs at least "
            "object_body and mu)"
        )
    unknown = set(section) - _KEYS
    if unknown:
        raise ModelError(
            f"scene {str(path)!r}: unknown key(s) {sorted(unknown)} in 'drakegrasp:'; "
            f"valid keys are {sorted(_KEYS)}"
        )
    for key in ("object_body", "mu"):
        if key not in section:
            raise ModelError(f"scene {str(path)!r}: 'drakegrasp:' needs {key!r}")
    hand = section.get("hand")
    if isinstance(hand, list):
        hand = tuple(str(h) for h in hand)
    elif hand is not None:
        hand = str(hand)
    try:
        model = ContactModel.parse(section.get("contact_model", "hard_finger"))
    except GraspError as e:
        raise ModelError(f"scene {str(path)!r}: {e}") from None
    plane = section.get("plane")
    if plane is not None and plane not in PLANES:
        raise ModelError(
            f"scene {str(path)!r}: drakegrasp.plane must be one of "
            f"{sorted(PLANES)} or absent, got {plane!r}"
        )
    return SceneInfo(
        name=path.stem,
        path=path.resolve(),
        description=str(section.get("description", "")),
        object_body=str(section["object_body"]),
        hand=hand,
        mu=_number(path, "mu", section["mu"]),
        contact_model=model,
        torsional_friction=_number(
            path, "torsional_friction", section.get("torsional_friction", 0.0)
        ),
        plane=plane,
        distance_tolerance=_number(
            path,
            "distance_tolerance",
            section.get("distance_tolerance", 1e-4),
            positive=True,
        ),
    )


def _resolve_hand(plant: MultibodyPlant, hand) -> ModelInstanceIndex | tuple | None:
    if hand is None:
        return None
    if isinstance(hand, str):
        if not plant.HasModelInstanceNamed(hand):
            names = [
                plant.GetModelInstanceName(ModelInstanceIndex(i))
                for i in range(plant.num_model_instances())
            ]
            raise ModelError(f"no model instance named {hand!r}; instances are {names}")
        return plant.GetModelInstanceByName(hand)
    return tuple(resolve_body(plant, h) for h in hand)


def _without_drakegrasp_section(text: str) -> str:
    """The scene text without its top-level ``drakegrasp:`` block.

    Drake's directive loader rejects unknown keys (so typos in the directives
    are caught); the block-style ``drakegrasp:`` mapping is cut out first: from
    its line to the next line that starts in column 0 with a key.
    """
    out, skipping = [], False
    for line in text.splitlines(keepends=True):
        starts_key = bool(line) and not line[0].isspace() and not line.startswith("#")
        if starts_key:
            skipping = line.startswith("drakegrasp:")
        if not skipping:
            out.append(line)
    return "".join(out)


def load_scene(path_or_name: str | Path | None = None) -> Scene:
    """Build the plant of a scene file and set the configuration it describes.

    Parameters
    ----------
    path_or_name : str or pathlib.Path, optional
        A scene file, or the name of a shipped scene (see :func:`list_scenes`).
        Default: :data:`DEFAULT_SCENE`.

    Returns
    -------
    Scene
        The diagram, plant, default context, object body and hand.

    Raises
    ------
    ModelError
        For a missing or malformed file, a model that does not parse, or an
        unknown body or model instance.
    """
    path = scene_path(DEFAULT_SCENE if path_or_name is None else path_or_name)
    info = read_scene_info(path)
    text, _ = _read_yaml(path)
    try:
        directives = LoadModelDirectivesFromString(_without_drakegrasp_section(text))
    except Exception as e:  # Drake raises RuntimeError/ValueError on bad schema
        msg = " ".join(str(e).split())
        raise ModelError(f"scene {str(path)!r}: bad model directives: {msg}") from None
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    parser = Parser(plant)
    register_models(parser)
    try:
        ProcessModelDirectives(directives, plant, parser)
    except Exception as e:  # Drake reports parse errors as RuntimeError
        msg = " ".join(str(e).split())
        raise ModelError(
            f"scene {str(path)!r}: cannot load the models: {msg}"
        ) from None
    plant.Finalize()
    object_body = resolve_body(plant, info.object_body)
    hand = _resolve_hand(plant, info.hand)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant_context = plant.GetMyContextFromRoot(context)
    return Scene(
        info=info,
        diagram=diagram,
        plant=plant,
        context=context,
        plant_context=plant_context,
        object_body=object_body,
        hand=hand,
    )
