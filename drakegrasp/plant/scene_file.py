"""Reading a scene file safely: bounded YAML, no aliases, checked types.

A scene file may come from anywhere (a colleague, a download), so reading it
must answer or refuse quickly and within memory proportional to the file:

- files larger than :data:`MAX_SCENE_BYTES` are refused before parsing;
- YAML **anchors and aliases** (``&a`` / ``*a``) are refused: eight nested
  aliases in 1.3 KB expand to gigabytes ("billion laughs"), and no scene needs
  them; so is nesting deeper than :data:`MAX_DEPTH`, and a file of more than
  :data:`MAX_NODES` values (a list of 200,000 numbers fits in 1 MiB and took
  a minute to read, three times over);
- a key given twice in one mapping is refused (PyYAML keeps the last, other
  readers the first: the two readings of the file would differ);
- plain scalars are read with the YAML 1.2 core schema, as Drake reads them:
  ``5e-1`` and ``1e-3`` are numbers, ``yes``/``on`` and ``2001-12-14`` strings,
  ``017`` is seventeen, and ``<<`` merges nothing;
- Drake's tags (``!Rpy``...) are read as plain data;
- the ``drakegrasp:`` section is checked key by key, with the type each value
  must have; its strings are printable text (no terminal escapes or other
  control characters).

Every refusal is a :class:`~drakegrasp.errors.SceneError` that names the file,
the key and what would be valid.
"""

from __future__ import annotations

import math
import re
import unicodedata
from pathlib import Path

import yaml

from drakegrasp.core.contact import ContactModel
from drakegrasp.core.files import not_a_file
from drakegrasp.core.tolerances import (
    DEFAULT_DISTANCE_TOLERANCE,
    MAX_DISTANCE_TOLERANCE,
)
from drakegrasp.core.validation import (
    COEFFICIENT_MAX,
    COEFFICIENT_MIN,
    check_coefficient,
    check_distance_tolerance,
)
from drakegrasp.errors import GraspError, SceneError
from drakegrasp.plant.options import PLANES, AnalysisOptions

__all__ = [
    "KEYS",
    "LOADER_NU_REMEDY",
    "MAX_ANGLE_DEG",
    "MAX_DEPTH",
    "MAX_NODES",
    "MAX_SCENE_BYTES",
    "TOP_LEVEL_KEYS",
    "check_directives",
    "check_poses",
    "check_section",
    "directives_text",
    "read_yaml",
]

MAX_SCENE_BYTES = 1 << 20
"""Largest scene file read (1 MiB; the shipped scenes are under 2 KB)."""

MAX_DEPTH = 64
"""Deepest nesting of YAML collections accepted."""

MAX_NODES = 10_000
"""Most YAML values (scalars, lists, mappings) of one file: the shipped and
tested scenes hold at most about 120, and PyYAML composes some 10,000 a
second on each of the three readings of a scene."""

MAX_ANGLE_DEG = 1e8
"""Largest magnitude of a pose's angle, degrees.

Drake turns degrees into radians by one multiplication, whose rounding is
about ``|angle| · 1e-18`` rad: 2e-10 rad here, and a whole turn at 1e19
degrees, where the rotation is no longer the one written.  No pose means more
than a few turns; a larger angle is refused with the advice to take it
modulo 360.
"""

KEYS = {
    "description": "a string",
    "object_body": "a 'model::body' name",
    "hand": "a model-instance name or a list of 'model::body' names",
    "mu": f"0 or a number in [{COEFFICIENT_MIN:g}, {COEFFICIENT_MAX:g}], or plant",
    "contact_model": f"one of {[m.value for m in ContactModel]}",
    "torsional_friction": f"0 or a number in [{COEFFICIENT_MIN:g}, "
    f"{COEFFICIENT_MAX:g}]",
    "plane": f"one of {sorted(PLANES)}",
    "distance_tolerance": f"a number > 0 and at most {MAX_DISTANCE_TOLERANCE:g} "
    "(metres)",
    "close": "true, false, or a mapping {direction: [one number per closing "
    "joint]}: close the hand onto the object when the scene is loaded",
    "load": "'gravity' (the object's weight) or a list of 6 numbers (3 with "
    "plane:), the wrench [f; m] on the object in N and N·m, frame O about its "
    "origin: analyse the grasp under that load",
    "torque_limits": "'plant' (the actuators' effort limits) or a list of "
    "numbers >= 0 (.inf: no limit), one per hand velocity (a coupled hand: per "
    "actuated joint or per independent coordinate), or one number >= 0 for all: "
    "the motors of the load analysis",
    "characteristic_length": "a number > 0 (metres): the length b that makes "
    "moments comparable with forces and sets a soft finger's torsion limit "
    "b nu f_n (as planned: plan --scene-out writes the plan's); absent: the "
    "grasp's own",
    "object_mass": "a number > 0 (kg): the mass that load: gravity weighs, at the "
    "model's centre of mass (plan --mass with --scene-out writes it); needs "
    "load: gravity; absent: the model's",
}
"""The keys of the ``drakegrasp:`` section and what each must be."""

TOP_LEVEL_KEYS = ("directives", "drakegrasp")
"""The keys of a scene file: Drake's model directives and drakegrasp's section."""


class _SceneLoader(yaml.SafeLoader):
    """Safe loader for scene files (see the module docstring).

    Drake's tags as plain data; no anchors, no aliases, no key given twice;
    plain scalars resolved by the YAML 1.2 core schema.
    """

    def compose_node(self, parent, index):
        event = self.peek_event()
        anchor = getattr(event, "anchor", None)
        if anchor is not None:
            kind = "alias" if isinstance(event, yaml.AliasEvent) else "anchor"
            mark = event.start_mark
            raise SceneError(
                f"YAML {kind} {anchor!r} at line {mark.line + 1}, column "
                f"{mark.column + 1}: scene files may not use anchors or aliases "
                "(they can expand without bound); write the values out"
            )
        self._depth = getattr(self, "_depth", 0) + 1
        self._nodes = getattr(self, "_nodes", 0) + 1
        if self._nodes > MAX_NODES:
            self._depth -= 1
            raise SceneError(
                f"YAML holds more than {MAX_NODES} values (lists, mappings and "
                f"scalars; drakegrasp.plant.scene_file.MAX_NODES) by line "
                f"{event.start_mark.line + 1}; a scene needs a few hundred"
            )
        try:
            if self._depth > MAX_DEPTH:
                raise SceneError(
                    f"YAML nested deeper than {MAX_DEPTH} levels at line "
                    f"{event.start_mark.line + 1}"
                )
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen = {}
            for key_node, _ in node.value:
                key = key_node.value
                if isinstance(key_node, yaml.ScalarNode) and key in seen:
                    raise SceneError(
                        f"key {key_node.value!r} given twice in one mapping (lines "
                        f"{seen[key] + 1} and {key_node.start_mark.line + 1}); "
                        "each key may appear once"
                    )
                seen[key] = key_node.start_mark.line
        return super().construct_mapping(node, deep=deep)

    def construct_yaml_int(self, node):
        text = self.construct_scalar(node)
        sign, digits = (-1, text[1:]) if text[:1] == "-" else (1, text.lstrip("+"))
        try:
            if digits[:2] in ("0o", "0x"):
                return sign * int(digits[2:], 8 if digits[1] == "o" else 16)
            return sign * int(digits, 10)
        except ValueError:  # more digits than Python converts (4300)
            mark = node.start_mark
            raise SceneError(
                f"integer of {len(digits)} digits at line {mark.line + 1}, column "
                f"{mark.column + 1}: more digits than any value of a scene needs"
            ) from None


# YAML 1.2 core schema (https://yaml.org/spec/1.2.2/#1032-tag-resolution), the
# schema of Drake's reader: PyYAML's 1.1 table reads 5e-1 as a string, yes/on as
# booleans, 017 as octal, 1_000 and 1:30 as numbers, dates as timestamps and <<
# as a merge.
_SceneLoader.yaml_implicit_resolvers = {}
for _tag, _pattern, _first in (
    ("null", r"^(?:~|null|Null|NULL|)$", "~nN"),
    ("bool", r"^(?:true|True|TRUE|false|False|FALSE)$", "tTfF"),
    ("int", r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$", "-+0123456789"),
    (
        "float",
        r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
        r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$",
        "-+0123456789.",
    ),
):
    _SceneLoader.add_implicit_resolver(
        f"tag:yaml.org,2002:{_tag}", re.compile(_pattern), list(_first)
    )
_SceneLoader.yaml_implicit_resolvers.setdefault("", []).insert(
    0, ("tag:yaml.org,2002:null", re.compile(r"^$"))
)
_SceneLoader.add_constructor("tag:yaml.org,2002:int", _SceneLoader.construct_yaml_int)


def _construct_tagged(loader, _suffix, node):
    if isinstance(node, yaml.MappingNode):
        return loader.construct_mapping(node, deep=True)
    if isinstance(node, yaml.SequenceNode):
        return loader.construct_sequence(node, deep=True)
    return loader.construct_scalar(node)


_SceneLoader.add_multi_constructor("!", _construct_tagged)


def read_yaml(path: Path) -> tuple[str, dict]:
    """The text of a scene file and its YAML data (a mapping).

    Raises
    ------
    SceneError
        Not a regular file (a pipe is never opened), unreadable, too large,
        not valid YAML, anchors or aliases, too deep, or not a mapping.
    """
    why = not_a_file(path, "a scene file")
    if why:
        raise SceneError(f"cannot read scene file {str(path)!r}: it {why}")
    try:
        size = path.stat().st_size
        if size > MAX_SCENE_BYTES:
            raise SceneError(
                f"scene file {str(path)!r} is {size} bytes; the limit is "
                f"{MAX_SCENE_BYTES} bytes"
            )
        raw = path.read_bytes()
    except OSError as e:
        raise SceneError(f"cannot read scene file {str(path)!r}: {e}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise SceneError(f"scene file {str(path)!r} is not UTF-8 text: {e}") from None
    try:
        data = yaml.load(text, Loader=_SceneLoader)
    except SceneError as e:
        raise SceneError(f"scene file {str(path)!r}: {e}") from None
    except yaml.YAMLError as e:
        first = " ".join(str(e).split())
        raise SceneError(
            f"scene file {str(path)!r} is not valid YAML: {first}"
        ) from None
    except (RecursionError, ValueError, TypeError) as e:  # e.g. unhashable keys
        raise SceneError(
            f"scene file {str(path)!r} is not valid YAML: {type(e).__name__}: {e}"
        ) from None
    if not isinstance(data, dict):
        raise SceneError(
            f"scene file {str(path)!r} must be a YAML mapping with 'directives' "
            f"and 'drakegrasp' keys, got {type(data).__name__}"
        )
    return text, data


def _string(path: Path, key: str, value) -> str:
    if not isinstance(value, str) or not value:
        raise SceneError(
            f"scene {str(path)!r}: drakegrasp.{key} must be {KEYS[key]}, got "
            f"{value!r} ({type(value).__name__})"
        )
    bad = next((c for c in value if unicodedata.category(c) in ("Cc", "Cf")), None)
    if bad is not None:
        raise SceneError(
            f"scene {str(path)!r}: drakegrasp.{key} holds the control character "
            f"U+{ord(bad):04X} in {value!r}; it must be one line of printable "
            "text (terminal escapes and bidirectional controls are refused)"
        )
    return value


def _coefficient(path: Path, key: str, value) -> float:
    """``mu`` or ``torsional_friction``: in the range every analysis takes."""
    x = _number(path, key, value)
    try:
        return check_coefficient(key, x, error=SceneError)
    except SceneError as e:
        raise SceneError(f"scene {str(path)!r}: drakegrasp.{e}") from None


def _distance_tolerance(path: Path, value) -> float:
    """``distance_tolerance``: in the range every analysis takes (at most 10 mm)."""
    x = _number(path, "distance_tolerance", value, positive=True)
    try:
        return check_distance_tolerance(x)
    except GraspError as e:
        raise SceneError(f"scene {str(path)!r}: drakegrasp.{e}") from None


def _number(
    path: Path, key: str, value, *, positive: bool = False, signed: bool = False
) -> float:
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise SceneError(
            f"scene {str(path)!r}: drakegrasp.{key} must be a number, got "
            f"{value!r} ({type(value).__name__}); valid: {KEYS[key]}"
        )
    try:
        x = float(value)
    except OverflowError:
        x = math.inf
    if signed:
        if not math.isfinite(x):
            raise SceneError(
                f"scene {str(path)!r}: drakegrasp.{key} holds {value!r}; valid: "
                f"{KEYS[key]}, every number finite"
            )
        return x
    if not (x >= 0.0) or (positive and x == 0.0) or x == math.inf:
        bound = "> 0" if positive else ">= 0"
        raise SceneError(
            f"scene {str(path)!r}: drakegrasp.{key} must be finite and {bound}, "
            f"got {value!r}"
        )
    return x


def _close(path: Path, value) -> tuple[bool, tuple[float, ...] | None]:
    """``close:`` as (close the hand?, its direction or None)."""
    if isinstance(value, bool):
        return value, None
    if isinstance(value, dict):
        unknown = [k for k in value if k != "direction"]
        direction = value.get("direction")
        if not unknown and isinstance(direction, list) and direction:
            return True, tuple(
                _number(path, "close", x, signed=True) for x in direction
            )
    raise SceneError(
        f"scene {str(path)!r}: drakegrasp.close must be {KEYS['close']}, got {value!r}"
    )


def check_directives(path: Path, data: dict) -> None:
    """Refuse a file without a ``directives:`` list, or with another top-level key.

    Drake's own message for these ("the top level element should be a
    Mapping", "key 'directive' did not match any visited value entry") names
    neither the file nor what is missing.

    Raises
    ------
    SceneError
        Naming the file, the key and what is valid.
    """
    unknown = [k for k in data if k not in TOP_LEVEL_KEYS]
    if unknown:
        raise SceneError(
            f"scene {str(path)!r}: unknown top-level key(s) "
            f"{', '.join(repr(k) for k in unknown)}; a scene file has exactly "
            "'directives:' (Drake's model directives) and 'drakegrasp:'"
        )
    if "directives" not in data:
        raise SceneError(
            f"scene {str(path)!r} has no 'directives:' key: it needs a list of "
            "Drake model directives (add_model, add_weld, ...) that adds the hand "
            "and the object (docs/scene_format.md)"
        )
    if not isinstance(data["directives"], list):
        raise SceneError(
            f"scene {str(path)!r}: 'directives:' must be a list of Drake model "
            "directives (- add_model: ..., - add_weld: ...), got "
            f"{type(data['directives']).__name__}"
        )


_TRANSFORMS = {
    "add_model": "default_free_body_pose",
    "add_frame": "X_PF",
    "add_weld": "X_PC",
}
"""Where a directive holds poses (Drake's ``schema::Transform``): a mapping of
body names to poses for ``add_model``, one pose for the others."""


def check_poses(path: Path, text: str) -> None:
    """Refuse a pose of the directives that Drake would drop or fail on unnamed.

    Drake reads ``!AngleAxis {angle_deg: a, axis: [0, 0, 0]}`` without a
    word and normalises nothing: the rotation is lost (the object stood
    unrotated).  A NaN or infinite angle stops it later with "NaN is
    detected during Symbolic computation.", and a non-finite translation is
    refused later still, as a body's position: neither names the key.  Each
    pose of ``add_model``'s ``default_free_body_pose``, ``add_frame``'s
    ``X_PF`` and ``add_weld``'s ``X_PC`` is checked here, on the text Drake
    has just read without complaint (its schema holds), so the message can
    give the line and the key.  Poses given by a random distribution
    (``!Uniform``...) are left to Drake.

    Raises
    ------
    SceneError
        Naming the file, the line and column, the key and what is valid: an
        ``!AngleAxis`` axis whose length cannot be normalised (zero, or too
        short or too long in double precision), a non-finite angle or
        translation, or an angle beyond :data:`MAX_ANGLE_DEG`.
    """
    loader = _SceneLoader(text)  # text that read_yaml has read: it parses
    try:
        directives = _entries(loader.get_single_node()).get("directives")
        if not isinstance(directives, yaml.SequenceNode):
            return
        for index, directive in enumerate(directives.value):
            for name, pose in _poses(directive):
                _check_pose(path, loader, f"directives[{index}].{name}", pose)
    finally:
        loader.dispose()


def _entries(node) -> dict:
    """A mapping node's entries by their (scalar) key; {} for another node."""
    if not isinstance(node, yaml.MappingNode):
        return {}
    return {k.value: v for k, v in node.value if isinstance(k, yaml.ScalarNode)}


def _poses(directive):
    """``(key path, pose node)`` of each pose a directive node holds."""
    for kind, holder in _entries(directive).items():
        key = _TRANSFORMS.get(kind)
        pose = _entries(holder).get(key) if key else None
        if pose is None:
            continue
        if kind == "add_model":
            for body, body_pose in _entries(pose).items():
                yield f"{kind}.{key}.{body}", body_pose
        else:
            yield f"{kind}.{key}", pose


def _numbers(loader, node) -> list[float] | None:
    """The numbers of a scalar or a sequence of scalars; None for anything else."""
    nodes = node.value if isinstance(node, yaml.SequenceNode) else [node]
    if not all(isinstance(n, yaml.ScalarNode) for n in nodes):
        return None
    values = [loader.construct_object(n) for n in nodes]
    if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
        return None
    try:
        return [float(v) for v in values]
    except OverflowError:  # an integer beyond a double: Drake's schema refuses it
        return None


_TOO_LARGE = (
    f"is beyond ±{MAX_ANGLE_DEG:.0e} degrees, where double precision no longer "
    "holds the angle's part of a turn; give it modulo 360"
)


def _check_pose(path: Path, loader, where: str, pose) -> None:
    """Refuse one pose node's non-finite numbers and degenerate rotation axis."""
    fields = _entries(pose)

    def refuse(node, key: str, what: str) -> None:
        mark = node.start_mark
        raise SceneError(
            f"scene {str(path)!r}: line {mark.line + 1}, column {mark.column + 1}: "
            f"{where}.{key} {what}"
        )

    translation = fields.get("translation")
    shown = _numbers(loader, translation) if translation is not None else None
    if shown is not None and not all(math.isfinite(x) for x in shown):
        refuse(translation, "translation", f"{shown} must be finite (metres)")
    rotation = fields.get("rotation")
    if rotation is None:
        return
    tag = rotation.tag
    parts = _entries(rotation)
    if tag == "!Rpy" and "deg" in parts:
        deg = _numbers(loader, parts["deg"])
        if deg is not None and not all(math.isfinite(x) for x in deg):
            refuse(
                parts["deg"], "rotation",
                f"!Rpy deg {deg} must be finite (degrees): "
                "!Rpy {deg: [roll, pitch, yaw]}",
            )  # fmt: skip
        if deg is not None and any(abs(x) > MAX_ANGLE_DEG for x in deg):
            refuse(parts["deg"], "rotation", f"!Rpy deg {deg} {_TOO_LARGE}")
    if tag == "!AngleAxis":
        angle = parts.get("angle_deg")
        value = _numbers(loader, angle) if angle is not None else None
        if value is not None and not math.isfinite(value[0]):
            refuse(
                angle, "rotation",
                f"!AngleAxis angle_deg {value[0]} must be finite (degrees)",
            )  # fmt: skip
        if value is not None and abs(value[0]) > MAX_ANGLE_DEG:
            refuse(angle, "rotation", f"!AngleAxis angle_deg {value[0]} {_TOO_LARGE}")
        axis = parts.get("axis")
        value = _numbers(loader, axis) if axis is not None else None
        if value is None:
            return
        if not all(math.isfinite(x) for x in value):
            refuse(axis, "rotation", f"!AngleAxis axis {value} must be finite")
        squared = sum(x * x for x in value)  # as Eigen's normalized() does
        if not 0.0 < squared < math.inf:
            why = (
                "is zero"
                if not any(value)
                else "is too short to normalise in double precision"
                if squared == 0.0
                else "is too long to normalise in double precision"
            )
            refuse(
                axis, "rotation",
                f"!AngleAxis axis {value} {why}: the axis must be a non-zero "
                "direction, such as [0, 0, 1] (Drake normalises it, and drops "
                "this one without a word)",
            )  # fmt: skip


LOADER_NU_REMEDY = "give it to the loader (load_scene(..., torsional_friction=NU))"
"""The refusal's remedy of a soft finger without ``ν`` naming the loader's keyword
(the command line names ``--torsional-friction`` instead)."""


def check_section(
    path: Path, data: dict, *, torsional_friction: float | None = None
) -> dict:
    """The checked ``drakegrasp:`` section, with defaults filled in.

    ``torsional_friction``, when given, replaces the file's (checked as the
    file's is): a file of soft fingers may then leave it out.

    Returns
    -------
    dict
        Keys ``description, object_body, hand, mu, contact_model,
        torsional_friction, plane, distance_tolerance, close,
        close_direction, load, torque_limits, characteristic_length,
        object_mass``; the last two are None or a float; ``hand`` is None, a string or
        a tuple of strings, ``contact_model`` a ContactModel, ``close`` a bool,
        ``close_direction`` None or a tuple of floats, ``load`` None,
        ``"gravity"`` or a tuple of floats, ``torque_limits`` None,
        ``"plant"`` or a tuple of floats.

    Raises
    ------
    SceneError
        Missing section, missing or unknown key (a soft finger's
        ``torsional_friction`` included), or a value of the wrong type or
        range; the message names the key and what is valid.
    """
    section = data.get("drakegrasp")
    if not isinstance(section, dict):
        raise SceneError(
            f"scene {str(path)!r} has no 'drakegrasp:' mapping (it needs at least "
            "object_body and mu)"
        )
    unknown = [k for k in section if not isinstance(k, str) or k not in KEYS]
    if unknown:
        raise SceneError(
            f"scene {str(path)!r}: unknown key(s) {', '.join(map(repr, unknown))} in "
            f"'drakegrasp:'; valid keys are {sorted(KEYS)}"
        )
    for key in ("object_body", "mu"):
        if key not in section:
            raise SceneError(f"scene {str(path)!r}: 'drakegrasp:' needs {key!r}")
    hand = section.get("hand")
    if isinstance(hand, list):
        hand = tuple(_string(path, "hand", h) for h in hand)
        if not hand:
            raise SceneError(f"scene {str(path)!r}: drakegrasp.hand is an empty list")
    elif hand is not None:
        hand = _string(path, "hand", hand)
    model = section.get("contact_model", "hard_finger")
    try:
        model = ContactModel.parse(_string(path, "contact_model", model))
    except SceneError:
        raise
    except GraspError as e:
        raise SceneError(
            f"scene {str(path)!r}: drakegrasp.contact_model: {e}"
        ) from None
    plane = section.get("plane")
    if plane is not None and (not isinstance(plane, str) or plane not in PLANES):
        raise SceneError(
            f"scene {str(path)!r}: drakegrasp.plane must be {KEYS['plane']} or "
            f"absent, got {plane!r}"
        )
    if torsional_friction is not None:
        section = {**section, "torsional_friction": torsional_friction}
    if model is ContactModel.SOFT_FINGER and "torsional_friction" not in section:
        # Refused here, as a missing mu is: the file is incomplete on its own
        # (absent is not 0, see below), and here its name and key are known.
        raise SceneError(
            f"scene {str(path)!r}: drakegrasp.contact_model is soft_finger but "
            "drakegrasp.torsional_friction is absent; add 'torsional_friction: "
            "NU' (nu >= 0: the moment about each contact normal is bounded by "
            f"b * nu * f_n; 0 makes a soft finger act as a hard one), "
            f"{LOADER_NU_REMEDY}, or use 'contact_model: hard_finger'"
        )
    description = section.get("description", "")
    close, close_direction = _close(path, section.get("close", False))
    checked = _checked_options(path, section, plane)
    load, limits = checked["load"], checked["torque_limits"]
    if limits is not None and load is None:
        raise SceneError(
            f"scene {str(path)!r}: drakegrasp.torque_limits without "
            "drakegrasp.load: the limits are the motors of the load analysis; "
            "add 'load: gravity' (or a wrench)"
        )
    return {
        "description": ""
        if description == ""
        else _string(path, "description", description),
        "object_body": _string(path, "object_body", section["object_body"]),
        "hand": hand,
        "mu": (
            "plant"
            if section["mu"] == "plant"
            else _coefficient(path, "mu", section["mu"])
        ),
        "contact_model": model,
        # Absent is not 0: a soft finger without a given nu is refused above
        # (and by the analysis, when --contact-model soft_finger asks for one),
        # one given nu = 0 acts as a hard finger.
        "torsional_friction": None
        if "torsional_friction" not in section
        else _coefficient(path, "torsional_friction", section["torsional_friction"]),
        "plane": plane,
        "distance_tolerance": _distance_tolerance(
            path, section.get("distance_tolerance", DEFAULT_DISTANCE_TOLERANCE)
        ),
        "close": close,
        "close_direction": close_direction,
        **checked,
    }


_CHECKED_OPTIONS = ("load", "torque_limits", "characteristic_length", "object_mass")
"""The section's keys that :class:`~drakegrasp.AnalysisOptions` checks."""


def _checked_options(path: Path, section: dict, plane) -> dict:
    """:data:`_CHECKED_OPTIONS` of ``section``, checked with the key named.

    :class:`~drakegrasp.AnalysisOptions` checks them: one rule for the file,
    the command line and Python.
    """
    given = {key: section.get(key) for key in _CHECKED_OPTIONS}
    try:
        options = AnalysisOptions(plane=plane, **given)
    except GraspError as e:
        raise SceneError(f"scene {str(path)!r}: drakegrasp.{e}") from None
    return {key: getattr(options, key) for key in _CHECKED_OPTIONS}


def directives_text(path: Path, text: str) -> str:
    """The scene text without its top-level ``drakegrasp:`` entry, for Drake.

    Drake's directive loader rejects unknown keys (so typos in the directives are
    caught), so the ``drakegrasp:`` entry is cut out first: the characters from
    its key to the end of its value, as this module's reading of the file places
    them.  Cutting where the YAML parser says (rather than by lines) leaves no
    way to hide text from one reader: a quoted multi-line value that looks like a
    ``directives:`` key is cut with its entry.

    Raises
    ------
    SceneError
        When the file does not parse (:func:`read_yaml` says why).
    """
    loader = _SceneLoader(text)
    try:
        root = loader.get_single_node()
    except (yaml.YAMLError, SceneError) as e:
        raise SceneError(f"scene file {str(path)!r}: {e}") from None
    finally:
        loader.dispose()
    if not isinstance(root, yaml.MappingNode):
        return text
    cuts = [
        (key.start_mark.index, value.end_mark.index)
        for key, value in root.value
        if isinstance(key, yaml.ScalarNode) and key.value == "drakegrasp"
    ]
    out, start = [], 0
    for begin, end in sorted(cuts):
        out.append(text[start:begin])
        start = end
    out.append(text[start:])
    return "".join(out)
