r"""Scene files: Drake model directives plus a small ``drakegrasp:`` section.

A scene is a YAML file that Drake itself can read, plus one mapping that tells
drakegrasp what to analyse.  ``drakegrasp analyze FILE`` and
:func:`load_scene` take it; ``drakegrasp scenes`` lists the shipped ones.

The format
----------
::

    directives:                      # Drake's ModelDirectives, unchanged
    - add_model:
        name: gripper                # model instance name
        file: package://drakegrasp/hands/parallel_jaw.sdf
        default_joint_positions:     # the hand's configuration
          left_finger_joint: [0.025]
          right_finger_joint: [0.025]
    - add_weld:
        parent: world
        child: gripper::palm
    - add_model:
        name: box
        file: package://drakegrasp/objects/box.sdf
        default_free_body_pose:      # the object's pose
          box:
            translation: [0.0, 0.0, 0.065]
            rotation: !Rpy { deg: [0.0, 0.0, 0.0] }
    drakegrasp:
      description: one line shown by `drakegrasp scenes`
      object_body: box::box          # required: scoped body name (model::body)
      hand: gripper                  # model instance name, or a list of bodies
      mu: 0.5                        # required: friction coefficient, >= 0, or plant
      contact_model: hard_finger     # frictionless | hard_finger | soft_finger
      torsional_friction: 0.1        # soft fingers: nu >= 0
      plane: yz                      # optional: planar analysis (xy | yz | zx)
      distance_tolerance: 1.0e-4     # optional, metres, > 0, <= 0.01
      close: true                    # optional: close the hand when loading
      load: gravity                  # optional: analyse under the weight
      torque_limits: plant           # optional: the actuators' effort limits

``directives`` is any list that Drake's ``LoadModelDirectives`` accepts
(``add_model``, ``add_weld``, ``add_frame``, ``add_directives``,
``add_collision_filter_group``...): Drake checks its schema and reports
unknown keys.  ``drakegrasp:`` keys (see :data:`drakegrasp.plant.scene_file.KEYS`):

- ``object_body`` (required): the grasped body, ``"model::body"`` (an
  unscoped name is refused, listing the scoped names it could mean);
- ``mu`` (required): friction coefficient of every contact;
- ``hand``: a model-instance name (all its bodies not welded to the world) or
  a list of ``"model::body"`` names; absent: every body that is not the
  object, not welded to the world and not in the object's model instance;
- ``contact_model`` (default ``hard_finger``), ``torsional_friction``
  (``ν >= 0``; absent is not 0, and a ``soft_finger`` file without it is
  refused when read), ``plane`` (absent: spatial),
  ``distance_tolerance`` (default 1e-4 m, at most 0.01 m), ``description``
  (default empty);
- ``close`` (default false): ``true`` closes the hand onto the object when
  the scene is loaded (:func:`~drakegrasp.plant.closing.close_hand` from the
  joint values of the directives, the pre-shape, with the scene's distance
  tolerance), so the directives need only an open hand; ``close:
  {direction: [...]}`` closes along that direction over the closing joints
  (order of ``HandClosure.joints``) instead of each fingertip's steepest
  descent.  ``load_scene(..., close=...)`` and ``drakegrasp analyze
  --close`` / ``--no-close`` override the file;
- ``load`` (absent: none): ``gravity`` or a wrench ``[f; m]`` (6 numbers, 3
  with ``plane``; N and N·m, frame O about its origin) the grasp is analysed
  under, and ``torque_limits`` (needs ``load``): ``plant`` or one limit per
  hand velocity; ``drakegrasp analyze --load`` / ``--torque-limits``
  override them;
- ``characteristic_length`` (absent: the grasp's own): the length ``b``
  (metres) that makes moments comparable with forces and bounds a soft
  finger's torsion by ``b ν f_n`` (``plan --scene-out`` of soft fingers
  writes the plan's); ``drakegrasp analyze --characteristic-length``
  overrides it;
- ``object_mass`` (absent: the model's; needs ``load: gravity``): the mass
  (kg) the weight is taken of (``plan --mass`` with ``--scene-out`` writes
  it); ``drakegrasp analyze --object-mass`` overrides it.

Packages and files
------------------
``package://drakegrasp/...`` resolves to the models shipped with drakegrasp,
``package://drake/...`` to Drake's own resources and
``package://drake_models/...`` to Drake's model collection (downloaded on
demand, or the local copy named by ``DRAKEGRASP_DRAKE_MODELS``).  Your own
packages: ``load_scene(path, package_map={"mypkg": "/path/to/mypkg"})`` (or a
list of directories holding a ``package.xml``, or a Drake ``PackageMap``),
``drakegrasp analyze scene.yaml --package mypkg=/path/to/mypkg`` (repeatable),
or ``ROS_PACKAGE_PATH``, crawled as Drake does.  Details:
:mod:`drakegrasp.plant.scene_refs`.

A ``file:`` without a URL scheme is a path relative to the scene file
(``file: models/my_object.sdf``).  A scene may reference only files inside its
packages and its own directory:
``package://drakegrasp/../../outside/evil.sdf``, ``file:///etc/...`` or a
path that climbs out of the scene's directory is a :class:`SceneError`
unless ``allow_any_file=True`` says the scene is trusted.

Safety
------
A scene file is read with a safe YAML loader, at most 1 MiB, without YAML
anchors or aliases (which can expand without bound) and at most 64 levels
deep, with no key given twice and numbers read as YAML 1.2 (as Drake reads
them); every key and value of ``drakegrasp:`` is type-checked, and the
directives' poses are refused by line and key where Drake would drop them (an
``!AngleAxis`` axis of zero) or stop on them unnamed (a NaN or infinite angle
or translation: :func:`~drakegrasp.plant.scene_file.check_poses`).  References are
checked on Drake's own reading of the directives, include loops are refused
before Drake would follow them, and the include limit counts loads.  Every problem is
a :class:`~drakegrasp.errors.SceneError` (a :class:`~drakegrasp.ModelError`)
naming the file, the key and what is valid (:mod:`drakegrasp.plant.scene_file`).

Example: Drake's WSG-50 from ``drake_models``
---------------------------------------------
Its tip spheres touch the box's faces at finger values of ±22.5 mm, with the
box's centre between the tips::

    directives:
    - add_model:
        name: wsg
        file: package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf
        default_joint_positions:
          left_finger_sliding_joint: [-0.0225]
          right_finger_sliding_joint: [0.0225]
    - add_weld:
        parent: world
        child: wsg::body
    - add_model:
        name: box
        file: package://drakegrasp/objects/box.sdf
        default_free_body_pose:
          box:
            translation: [0.0, 0.108, 0.0]
    drakegrasp:
      description: Drake's WSG-50 squeezing a 50 x 50 x 100 mm box
      object_body: box::box
      hand: wsg
      mu: 0.5

(``docs/scene_format.md`` walks through it with the joint values that make the
tips touch.)
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from pydrake.multibody.parsing import (
    FlattenModelDirectives,
    LoadModelDirectivesFromString,
    ProcessModelDirectives,
)
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.multibody.tree import BodyIndex, ModelInstanceIndex, RigidBody
from pydrake.systems.framework import Context, Diagram, DiagramBuilder

from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import ContactModel
from drakegrasp.core.files import MISSING, not_a_file
from drakegrasp.core.validation import (
    check_coefficient,
    check_flag,
    describe,
    path_text,
)
from drakegrasp.errors import InvalidOptionError, ModelError, SceneError
from drakegrasp.plant.couplings import (
    check_joint_limits,
    model_resolver,
    record_model_couplings,
)
from drakegrasp.plant.models import (
    drake_reading,
    explain_drake_models,
    load_models,
    models_dir,
    new_parser,
)
from drakegrasp.plant.options import AnalysisOptions
from drakegrasp.plant.scene_file import (
    check_directives,
    check_poses,
    check_section,
    directives_text,
    read_yaml,
)
from drakegrasp.plant.scene_refs import PackagesSpec, add_packages, check_references
from drakegrasp.plant.validation import (
    hand_bodies,
    hand_contact_bodies,
    model_instance,
    resolve_body,
    scoped_name,
)

if TYPE_CHECKING:  # closing is imported only when a scene closes its hand
    from drakegrasp.plant.closing import HandClosure

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


@checked_call
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
    torsional_friction : float or None
        Torsional friction coefficient ``ν >= 0`` of soft fingers; None when the
        file does not give it (a soft finger then needs it).
    plane : str or None
        ``"xy"``, ``"yz"`` or ``"zx"`` for a planar analysis in that plane of the
        object frame, None for a spatial one.
    distance_tolerance : float
        ``|ψ|`` (metres) below which a pair is in contact.
    close : bool
        Close the hand onto the object when the scene is loaded.
    close_direction : tuple of float or None
        The closing direction over the closing joints; None: each fingertip's
        steepest descent.
    load : None, "gravity" or tuple of float
        The load the file analyses the grasp under (``AnalysisOptions.load``);
        None: no load section.
    torque_limits : None, "plant" or tuple of float
        The motor limits of that load analysis
        (``AnalysisOptions.torque_limits``).
    characteristic_length : float or None
        The length ``b`` (metres) that makes moments comparable with forces
        and sets a soft finger's torsion limit ``b ν f_n``
        (``AnalysisOptions.characteristic_length``); None: the grasp's own.
    object_mass : float or None
        The mass (kg) that ``load: gravity`` weighs
        (``AnalysisOptions.object_mass``); None: the model's.
    """

    name: str
    path: Path
    description: str
    object_body: str
    hand: str | tuple[str, ...] | None
    mu: float | str
    contact_model: ContactModel
    torsional_friction: float | None
    plane: str | None
    distance_tolerance: float
    close: bool = False
    close_direction: tuple[float, ...] | None = None
    load: str | tuple[float, ...] | None = None
    torque_limits: str | tuple[float, ...] | None = None
    characteristic_length: float | None = None
    object_mass: float | None = None


@checked_call
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
        Loaded with ``free_hand``, the hand's whole model instance (see
        :func:`load_scene`).
    closure : HandClosure or None
        How the hand was closed when the scene was loaded with closing (the
        file's ``close:`` or ``load_scene(..., close=True)``); the context
        holds the closed hand.  None when it was not closed.
    """

    info: SceneInfo
    diagram: Diagram
    plant: MultibodyPlant
    context: Context
    plant_context: Context
    object_body: RigidBody
    hand: ModelInstanceIndex | tuple[RigidBody, ...] | None
    closure: HandClosure | None = None

    @property
    def name(self) -> str:
        """The scene's name (file stem)."""
        return self.info.name

    @property
    def options(self) -> AnalysisOptions:
        """The scene file's analysis options (friction, model, plane, load...)."""
        info = self.info
        return AnalysisOptions(
            mu=info.mu,
            contact_model=info.contact_model,
            torsional_friction=info.torsional_friction,
            plane=info.plane,
            distance_tolerance=info.distance_tolerance,
            load=info.load,
            torque_limits=info.torque_limits,
            characteristic_length=info.characteristic_length,
            object_mass=info.object_mass,
        )

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
            # only when the file gives them: a caller may add its own
            **{
                key: value
                for key, value in (
                    ("load", self.info.load),
                    ("torque_limits", self.info.torque_limits),
                    ("characteristic_length", self.info.characteristic_length),
                    ("object_mass", self.info.object_mass),
                )
                if value is not None
            },
        }


def scenes_dir() -> Path:
    """Directory of the shipped scene files."""
    return models_dir() / "scenes"


@checked_call
def list_scenes() -> list[SceneInfo]:
    """The shipped scenes, sorted by name (the default scene included)."""
    return [read_scene_info(p) for p in sorted(scenes_dir().glob("*.yaml"))]


_SCENE_MUST = "a scene file's path or a shipped scene's name (a str or a pathlib.Path)"


def _path_argument(name: str, path, *, empty: bool = False) -> str:
    """``path`` (a ``str`` or an ``os.PathLike`` of one) as a plain str."""
    return path_text(name, path, must=_SCENE_MUST, empty=empty)


def scene_path(path_or_name: str | Path) -> Path:
    """The file of a scene given by path or by the name of a shipped scene.

    Raises
    ------
    InvalidOptionError
        If it is not a ``str`` or an ``os.PathLike`` of one.
    ModelError
        If it is neither an existing file nor a shipped scene's name (a
        directory, a named pipe or a device is named as one, by ``stat``: a
        pipe is never opened).
    """
    name = _path_argument("path_or_name", path_or_name, empty=True)
    candidate = Path(name)
    why = not_a_file(candidate, "a scene file") if name else MISSING
    if not why:
        return candidate
    names = ", ".join(p.stem for p in sorted(scenes_dir().glob("*.yaml")))
    if not name.strip():
        raise ModelError(f"the scene's name is empty (shipped scenes: {names})")
    shipped = scenes_dir() / f"{name.removesuffix('.yaml')}.yaml"
    if "/" not in name and not not_a_file(shipped):  # (a name too long: no file)
        return shipped
    shown = describe(name)  # a name of thousands of characters, cut
    if why != MISSING:
        raise ModelError(f"scene {shown} {why} (shipped scenes: {names})")
    raise ModelError(
        f"scene {shown} not found: no such file and no shipped scene of that "
        f"name (shipped scenes: {names})"
    )


def read_scene_info(
    path: str | Path, *, torsional_friction: float | None = None
) -> SceneInfo:
    """Read and check the ``drakegrasp:`` section of a scene file.

    ``torsional_friction``, when given, replaces the file's, as
    :func:`load_scene`'s does (a soft-finger file may then leave it out).

    Raises
    ------
    SceneError
        On an unreadable, oversized or invalid YAML file, a missing or unknown
        key, or a bad value; the message names the file and the key.
    InvalidOptionError
        If ``path`` is not a ``str`` or an ``os.PathLike`` of one.
    """
    path = Path(_path_argument("path", path))
    _, data = read_yaml(path)
    section = check_section(path, data, torsional_friction=torsional_friction)
    return SceneInfo(name=path.stem, path=path.resolve(), **section)


def _new_plant(path: Path, package_map: PackagesSpec, ros_package_path: bool):
    """(builder, plant, parser, packages) of an empty scene, packages registered."""
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    parser = new_parser(plant, f"scene {str(path)!r}")
    packages = add_packages(parser, package_map, ros_package_path=ros_package_path)
    return builder, plant, parser, packages


def _load_models(path: Path, directives, plant: MultibodyPlant, parser) -> None:
    """Process the (checked) directives into ``plant`` and finalize it."""
    _check_joint_limits(path, directives, parser)
    try:
        added = load_models(
            f"scene {str(path)!r}", ProcessModelDirectives, directives, plant, parser
        )
    except ModelError as e:
        if _DRAKE_NESTED_WELD in str(e):
            _refuse_nested_weld(path, directives, plant)
        raise
    record_model_couplings(plant, added, parser.package_map())
    plant.Finalize()


_DRAKE_NESTED_WELD = "AddWeld(): condition 'found' failed"
"""Drake's words when an ``add_weld`` child lies in a model nested in the one
an ``add_model`` added (its directives record welds by added model only)."""


def _refuse_nested_weld(path: Path, directives, plant: MultibodyPlant) -> None:
    """Name the ``add_weld`` whose child is in a nested model, and the way out.

    A model instance is nested when a proper prefix of its scoped name
    (``rig`` of ``rig::gripper::jaw``) is a model instance of the plant too;
    an ``add_directives`` namespace (``left::gripper``) is no model instance,
    so its models are not taken for nested ones.  Returns when no weld fits
    (the caller re-raises Drake's words).
    """
    added = {d.add_model.name for d in directives.directives if d.add_model}
    for d in directives.directives:
        weld = d.add_weld
        if weld is None:
            continue
        instance = _instance_of(weld.child)
        if instance in added:  # an add_model's own (its name may hold "::")
            continue
        parts = instance.split("::")
        outer = [
            "::".join(parts[:n])
            for n in range(1, len(parts))
            if plant.HasModelInstanceNamed("::".join(parts[:n]))
        ]
        if outer and plant.HasModelInstanceNamed(instance):
            # the add_model it sits in: the longest such prefix (rig::extra
            # beside rig holds rig::extra::gripper::jaw, not rig)
            by_added = [o for o in outer if o in added]
            outer = by_added[-1:] or outer
            raise SceneError(
                f"scene {str(path)!r}: add_weld child {weld.child!r} is a frame of "
                f"the model {instance!r}, nested in {outer[0]!r}, and Drake's model "
                "directives weld only frames of the models an add_model adds: weld "
                f"a link of {outer[0]!r} itself (fixed to the nested model by a joint "
                "in the model file), or add the nested model with an add_model of "
                "its own"
            )


_UNKNOWN_KEY = re.compile(
    r"^\S*?:(?P<line>\d+):(?P<column>\d+): .*?key '(?P<key>[^']*)' did not "
    r"match any visited value entry.*?while visiting (?P<type>[\w:]+)"
)

_ROTATION_KEYS = {
    "Rpy": "!Rpy {deg: [roll, pitch, yaw]}",
    "AngleAxis": "!AngleAxis {angle_deg: a, axis: [x, y, z]}",
}
"""Drake's rotation schemas, written as a scene file gives them (in degrees)."""


def _schema_words(message: str) -> str:
    """Drake's 'key did not match any visited value entry' as one short clause.

    Drake names the key, then every enclosing schema; the first is the one
    that lacks the key.  A rotation's key (``rad``, ``angle``) gets the
    spelling Drake reads: rotations are in degrees.
    """
    found = _UNKNOWN_KEY.match(message)
    if found is None:
        return message
    kind = found["type"].rpartition("::")[2]
    where = f"line {found['line']}, column {found['column']}"
    if kind in _ROTATION_KEYS:
        return (
            f"{where}: unknown key {found['key']!r} in an !{kind} rotation; "
            f"Drake's rotations are in degrees: {_ROTATION_KEYS[kind]}"
        )
    return f"{where}: unknown key {found['key']!r} in {found['type']}"


def _check_joint_limits(path: Path, directives, parser) -> None:
    """Refuse a model of the scene whose joint limits are reversed (Drake aborts).

    Each ``add_model``'s file is read first
    (:func:`~drakegrasp.plant.couplings.check_joint_limits`); one that
    cannot be resolved or read is left to Drake, which reports it.
    """
    for d in _flattened(path, directives, parser).directives:
        if d.add_model is None:
            continue
        try:
            model = Path(parser.package_map().ResolveUrl(d.add_model.file))
        except (RuntimeError, OSError, ValueError):
            continue
        why = not_a_file(model, "a model file")
        if why and why != MISSING:  # a pipe would block the read and Drake
            raise SceneError(f"scene {str(path)!r}: model file {str(model)!r} {why}")
        try:
            kind = {".urdf": "urdf", ".sdf": "sdf"}.get(model.suffix.lower())
            text = model.read_text() if kind else None
        except (RuntimeError, OSError, ValueError):
            continue
        if text is not None:
            try:
                check_joint_limits(
                    text, kind, model.name,
                    resolve=model_resolver(parser.package_map(), model.parent),
                )  # fmt: skip
            except ModelError as e:
                raise ModelError(f"scene {str(path)!r}: {e}") from None


def _scene_body(path: Path, plant: MultibodyPlant, name: str) -> RigidBody:
    """The file's ``object_body``; an unknown name is refused naming the file."""
    _require_scoped(path, plant, "object_body", name)
    try:
        return resolve_body(plant, name)
    except ModelError as e:
        raise ModelError(f"scene {str(path)!r}: object_body: {e}") from None


def _require_scoped(path: Path, plant: MultibodyPlant, key: str, name: str) -> None:
    """Refuse a body name of the file without its model scope (``model::body``).

    The Python API takes an unscoped name used by one body; a file does not:
    it is shared and grows (a second object, an included directive file), and
    a name unique today would then become ambiguous, far from the edit that
    made it so.  Drake's own directives
    (``add_weld``) take scoped names too.  ``world`` is let through, to be
    refused as no object by the checks that follow.

    Raises
    ------
    SceneError
        Naming the file, the key and the scoped names of the bodies called
        ``name`` (all the plant's bodies when none is).
    """
    if "::" in name or name == "world":
        return
    bodies = [plant.get_body(BodyIndex(i)) for i in range(1, plant.num_bodies())]
    same = [scoped_name(plant, b) for b in bodies if b.name() == name]
    shown = same or [scoped_name(plant, b) for b in bodies]
    which = (
        f"the bodies named {name!r}: {same}"
        if same
        else f"no body is named {name!r}; the bodies are {shown}"
    )
    raise SceneError(
        f"scene {str(path)!r}: {key} {name!r} has no model scope; a scene file "
        f"names a body 'model::body' ({which})"
    )


def _scene_hand(path: Path, plant: MultibodyPlant, hand):
    """The file's ``hand:`` in the plant; an unknown name is refused naming the file."""
    if isinstance(hand, tuple):
        for name in hand:
            _require_scoped(path, plant, "hand", name)
    try:
        return _resolve_hand(plant, hand)
    except ModelError as e:
        raise ModelError(f"scene {str(path)!r}: hand: {e}") from None


def _resolve_hand(plant: MultibodyPlant, hand) -> ModelInstanceIndex | tuple | None:
    if hand is None:
        return None
    if isinstance(hand, str):
        return model_instance(plant, hand)
    return tuple(resolve_body(plant, h) for h in hand)


def _hand_instances(hand) -> set[str]:
    """Names of the model instances the file's ``hand:`` names.

    ``hand: NAME`` is a model instance's name, which may itself be scoped
    (``left::gripper`` of an ``add_directives`` with ``model_namespace:
    left``); a list names bodies, ``INSTANCE::BODY``.
    """
    if isinstance(hand, str):
        return {hand}
    return {_instance_of(name) for name in hand}


def _instance_of(frame: str) -> str:
    """The model instance of a scoped frame or body name ('' for ``world``)."""
    return frame.rpartition("::")[0]


def _flattened(path: Path, directives, parser):
    """``directives`` with each ``add_directives`` replaced by what it includes.

    Drake's ``FlattenModelDirectives`` (the same scene, its names scoped by
    each include's ``model_namespace``): a weld that places the hand may sit
    in an included directive file.
    """
    if all(d.add_directives is None for d in directives.directives):
        return directives
    try:
        return drake_reading(FlattenModelDirectives, directives, parser.package_map())
    except Exception as e:  # Drake raises RuntimeError on a file it cannot read
        msg = " ".join(explain_drake_models(str(e)).split())
        raise SceneError(
            f"scene {str(path)!r}: cannot follow its add_directives: {msg}"
        ) from None


def _drop_hand_welds(directives, instances: set[str]) -> bool:
    """Remove ``directives``' welds that attach the hand to anything else.

    A weld whose child is a body of the hand's model ``instances`` and whose
    parent is not (the world, a table, an arm's flange, a frame) places the
    hand; welds inside the hand (one of its instances to another) stay.
    ``directives`` are flattened (:func:`_flattened`).  Returns whether a
    weld was removed.
    """
    kept = [
        d
        for d in directives.directives
        if d.add_weld is None
        or _instance_of(d.add_weld.child) not in instances
        or _instance_of(d.add_weld.parent) in instances
    ]
    dropped = len(kept) != len(directives.directives)
    directives.directives = kept
    return dropped


def _whole_hand(plant: MultibodyPlant, hand, object_body: RigidBody):
    """``Scene.hand`` for ``free_hand``: the hand's whole model instances.

    A ``hand:`` of bodies (the fingers of a palm welded to the world, as
    ``analyze`` reads them) becomes their model instance, or every body of
    their instances when they are several (the object left out): the planner
    places the hand by its base, which must be part of it.
    """
    if not isinstance(hand, tuple):
        return hand
    hand_contact_bodies(plant, object_body, hand)  # refuses the object listed
    instances = sorted({b.model_instance() for b in hand}, key=int)
    if len(instances) == 1:
        return instances[0]
    return tuple(
        plant.get_body(i)
        for m in instances
        for i in plant.GetBodyIndices(m)
        if i != object_body.index()
    )


def _infer_hand(path: Path, plant: MultibodyPlant, object_body: RigidBody) -> str:
    """The one model instance that moves besides the object, for ``free_hand``.

    The instance of the bodies that ``hand=None`` takes for the hand
    (:func:`~drakegrasp.plant.validation.hand_bodies`).

    Raises
    ------
    SceneError
        If no body but the object can move, or bodies of several model
        instances can (a hand and another free object): the file must say
        which is the hand.
    """
    try:
        bodies = hand_bodies(plant, object_body, None)
    except ModelError:
        bodies = []
    found = sorted({b.model_instance() for b in bodies}, key=int)
    names = [plant.GetModelInstanceName(m) for m in found]
    if len(names) == 1:
        return names[0]
    where = (
        f"the bodies that can move besides the object belong to {len(names)} "
        f"model instances {names}: say which is the hand, e.g. 'hand: {names[0]}'"
        if names
        else "no body besides the object can move (a hand needs joints): add the "
        "hand and name it with 'hand: NAME'"
    )
    raise SceneError(
        f"scene {str(path)!r} names no hand (no 'hand:' in its drakegrasp: "
        f"section) and {where}"
    )


@checked_call
def load_scene(
    path_or_name: str | Path | None = None,
    *,
    package_map: PackagesSpec = None,
    ros_package_path: bool = True,
    allow_any_file: bool = False,
    close: bool | None = None,
    free_hand: bool = False,
    torsional_friction: float | None = None,
) -> Scene:
    """Build the plant of a scene file and set the configuration it describes.

    Parameters
    ----------
    path_or_name : str or pathlib.Path, optional
        A scene file, or the name of a shipped scene (see :func:`list_scenes`).
        Default: :data:`DEFAULT_SCENE`.
    package_map : PackageMap, mapping or iterable, optional
        The user's packages: a Drake ``PackageMap``, ``{name: directory}``, or
        directories that hold a ``package.xml`` (see
        :func:`drakegrasp.plant.scene_refs.add_packages`).
    ros_package_path : bool, optional
        Also register the packages under ``$ROS_PACKAGE_PATH`` (default True).
    allow_any_file : bool, optional
        Trust the scene: let it reference files outside its packages and its
        own directory (default False: refused).
    close : bool, optional
        Close the hand onto the object (:func:`~drakegrasp.close_hand`, from
        the file's joint values, along the file's ``close: {direction: ...}``
        if it gives one).  Default: what the file's ``close:`` says.
    free_hand : bool, optional
        Leave out the file's welds that attach a body of the hand's model
        instances to anything outside them (the world, a table, an arm's
        flange), so that the hand floats free: what a grasp planner places
        itself (``drakegrasp plan`` on a scene).  The hand is then its whole
        model instances: ``Scene.hand`` is the instance of a ``hand:`` of
        bodies (a palm welded to the world and its fingers, as ``analyze``
        reads them), and a file without ``hand:`` frees the one model instance
        whose bodies can move besides the object (the hand ``analyze`` would
        take).  Welds of included directive files (``add_directives``) count
        as the file's own; welds inside the hand, and those written in model
        files (an SDFormat ``<joint type="fixed">`` to the world), stay.
        Default False.
    torsional_friction : float, optional
        The soft fingers' ``ν`` (0 or in [1e-12, 1e12]), in place of the
        file's ``torsional_friction:``, which a file of soft fingers may then
        leave out (``drakegrasp analyze --torsional-friction``).  Default:
        the file's.

    Returns
    -------
    Scene
        The diagram, plant, default context, object body and hand.

    Raises
    ------
    SceneError
        For a malformed file or a reference the policy refuses; with
        ``free_hand``, a file without ``hand:`` whose movable bodies (the
        object's left out) are of several model instances, or of none.
    ModelError
        For a model that does not parse, or an unknown body or model instance
        (the message names the file and the key).
    UnreachableError, PenetrationError
        Closing asked for, and no finger reaches the object, or the file's
        pre-shape already penetrates it.
    """
    if close is not None:
        close = check_flag("close", close)
    path = scene_path(DEFAULT_SCENE if path_or_name is None else path_or_name)
    text, data = read_yaml(path)
    if torsional_friction is not None:
        torsional_friction = check_coefficient(
            "torsional_friction", torsional_friction, error=InvalidOptionError
        )
    section = check_section(path, data, torsional_friction=torsional_friction)
    info = SceneInfo(name=path.stem, path=path.resolve(), **section)
    check_directives(path, data)
    free_hand = check_flag("free_hand", free_hand)
    ros_package_path = check_flag("ros_package_path", ros_package_path)
    builder, plant, parser, packages = _new_plant(path, package_map, ros_package_path)
    try:
        directives = drake_reading(
            LoadModelDirectivesFromString, directives_text(path, text)
        )
    except SceneError:
        raise
    except Exception as e:  # Drake raises RuntimeError/ValueError on bad schema
        msg = _schema_words(" ".join(str(e).split()))
        raise SceneError(f"scene {str(path)!r}: bad model directives: {msg}") from None
    check_poses(path, text)  # what Drake read without a word, by line and key
    # What Drake will load, from Drake's reading (and includes followed first:
    # a loop would crash Drake), with the reference policy unless trusted.
    check_references(
        path,
        data,
        directives,
        packages,
        read_yaml=read_yaml,
        allow_any_file=check_flag("allow_any_file", allow_any_file),
    )
    if free_hand:
        directives = _flattened(path, directives, parser)
    if free_hand and info.hand is not None:
        _drop_hand_welds(directives, _hand_instances(info.hand))
    _load_models(path, directives, plant, parser)
    object_body = _scene_body(path, plant, info.object_body)
    if free_hand and info.hand is None:
        # the hand analyze would take, by its model instance; freed, the
        # plant is built again without the welds that placed it
        inferred = _infer_hand(path, plant, object_body)
        if _drop_hand_welds(directives, {inferred}):
            builder, plant, parser, _ = _new_plant(path, package_map, ros_package_path)
            _load_models(path, directives, plant, parser)
            object_body = _scene_body(path, plant, info.object_body)
        hand = plant.GetModelInstanceByName(inferred)
    else:
        hand = _scene_hand(path, plant, info.hand)
        if free_hand:
            hand = _whole_hand(plant, hand, object_body)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant_context = plant.GetMyContextFromRoot(context)
    closure = None
    if info.close if close is None else close:
        from drakegrasp.plant.closing import close_hand

        closure = close_hand(
            plant,
            plant_context,
            object_body,
            hand=hand,
            direction=info.close_direction,
            distance_tolerance=info.distance_tolerance,
        )
    return Scene(
        info=info,
        diagram=diagram,
        plant=plant,
        context=context,
        plant_context=plant_context,
        object_body=object_body,
        hand=hand,
        closure=closure,
    )
