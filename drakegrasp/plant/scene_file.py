"""Reading a scene file safely: bounded YAML, no aliases, checked types.

A scene file may come from anywhere (a colleague, a download), so reading it
must answer or refuse quickly and within memory proportional to the file:

- files larger than :data:`MAX_SCENE_BYTES` are refused before parsing;
- YAML **anchors and aliases** (``&a`` / ``*a``) are refused: eight nested
  aliases in 1.3 KB expand to gigabytes ("billion laughs"), and no scene needs
  them; so is nesting deeper than :data:`MAX_DEPTH`;
- Drake's tags (``!Rpy``...) are read as plain data;
- the ``drakegrasp:`` section is checked key by key, with the type each value
  must have.

Every refusal is a :class:`~drakegrasp.errors.SceneError` that names the file,
the key and what would be valid.
"""

from __future__ import annotations

import math
from pathlib import Path

import yaml

from drakegrasp.core.contact import ContactModel
from drakegrasp.errors import GraspError, SceneError
from drakegrasp.plant.jacobians import PLANES

__all__ = ["KEYS", "MAX_DEPTH", "MAX_SCENE_BYTES", "check_section", "read_yaml"]

MAX_SCENE_BYTES = 1 << 20
"""Largest scene file read (1 MiB; the shipped scenes are under 2 KB)."""

MAX_DEPTH = 64
"""Deepest nesting of YAML collections accepted."""

KEYS = {
    "description": "a string",
    "object_body": "a 'model::body' name",
    "hand": "a model-instance name or a list of 'model::body' names",
    "mu": "a number >= 0",
    "contact_model": f"one of {[m.value for m in ContactModel]}",
    "torsional_friction": "a number >= 0",
    "plane": f"one of {sorted(PLANES)}",
    "distance_tolerance": "a number > 0 (metres)",
}
"""The keys of the ``drakegrasp:`` section and what each must be."""


class _SceneLoader(yaml.SafeLoader):
    """Safe loader: Drake's tags as plain data; no anchors, no aliases."""

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
        try:
            if self._depth > MAX_DEPTH:
                raise SceneError(
                    f"YAML nested deeper than {MAX_DEPTH} levels at line "
                    f"{event.start_mark.line + 1}"
                )
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


def _construct_tagged(loader, suffix, node):
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
        Unreadable, too large, not valid YAML, anchors or aliases, too deep,
        or not a mapping.
    """
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
    return value


def _number(path: Path, key: str, value, *, positive: bool = False) -> float:
    if not isinstance(value, int | float) or isinstance(value, bool):
        raise SceneError(
            f"scene {str(path)!r}: drakegrasp.{key} must be a number, got "
            f"{value!r} ({type(value).__name__}); valid: {KEYS[key]}"
        )
    x = float(value)
    if not (x >= 0.0) or (positive and x == 0.0) or x == math.inf:
        bound = "> 0" if positive else ">= 0"
        raise SceneError(
            f"scene {str(path)!r}: drakegrasp.{key} must be finite and {bound}, "
            f"got {value!r}"
        )
    return x


def check_section(path: Path, data: dict) -> dict:
    """The checked ``drakegrasp:`` section, with defaults filled in.

    Returns
    -------
    dict
        Keys ``description, object_body, hand, mu, contact_model,
        torsional_friction, plane, distance_tolerance``; ``hand`` is None, a
        string or a tuple of strings, ``contact_model`` a ContactModel.

    Raises
    ------
    SceneError
        Missing section, missing or unknown key, or a value of the wrong type
        or range; the message names the key and what is valid.
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
            f"scene {str(path)!r}: unknown key(s) {[repr(k) for k in unknown]} in "
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
    description = section.get("description", "")
    return {
        "description": ""
        if description == ""
        else _string(path, "description", description),
        "object_body": _string(path, "object_body", section["object_body"]),
        "hand": hand,
        "mu": _number(path, "mu", section["mu"]),
        "contact_model": model,
        "torsional_friction": _number(
            path, "torsional_friction", section.get("torsional_friction", 0.0)
        ),
        "plane": plane,
        "distance_tolerance": _number(
            path,
            "distance_tolerance",
            section.get("distance_tolerance", 1e-4),
            positive=True,
        ),
    }
