"""Small scene files of odd shapes, modelled on the shipped parallel-jaw box.

Shared by the plant, planning and fuzz tests of odd scenes (a hand without
``hand:``, a hand of finger bodies, a hand welded to a table, an object welded
to the world...).  :func:`jaw_scene` writes one into a folder and returns its
path; :func:`edited_shipped` edits a shipped scene's text with the snippets
here (``HAND_LINE``, ``PALM_ON_WORLD``, ``SHIPPED_BOX_POSE``...).
"""

from __future__ import annotations

from pathlib import Path

GRIPPER = """\
- add_model:
    name: gripper
    file: package://drakegrasp/hands/parallel_jaw.sdf
    default_joint_positions:
      left_finger_joint: [0.025]
      right_finger_joint: [0.025]
"""

PALM_ON_WORLD = """\
- add_weld:
    parent: world
    child: gripper::palm
"""

BOX = """\
- add_model:
    name: box
    file: package://drakegrasp/objects/box.sdf
    default_free_body_pose:
      box:
        translation: [0.0, 0.0, 0.065]
"""

BOX_WELD = """\
- add_weld:
    parent: world
    child: box::box
    X_PC:
      translation: [0.0, 0.0, 0.065]
"""

BOX_ON_WORLD = (
    """\
- add_model:
    name: box
    file: package://drakegrasp/objects/box.sdf
"""
    + BOX_WELD
)

HAND_LINE = "  hand: gripper\n"
"""The shipped parallel_jaw_box's ``hand:`` line."""

SHIPPED_BOX_POSE = """\
    default_free_body_pose:
      box:
        translation: [0.0, 0.0, 0.065]
        rotation: !Rpy {deg: [0.0, 0.0, 0.0]}
"""
"""The shipped parallel_jaw_box's free pose of its box."""

SECOND_BOX = """\
- add_model:
    name: box2
    file: package://drakegrasp/objects/box.sdf
    default_free_body_pose:
      box:
        translation: [0.3, 0.0, 0.065]
"""

# the palm welded to a table (a box welded to the world), where the shipped
# scene welds it to the world: the palm ends where it is in the shipped scene
TABLE_AND_PALM = """\
- add_model:
    name: table
    file: package://drakegrasp/objects/box.sdf
- add_weld:
    parent: world
    child: table::box
    X_PC:
      translation: [0.3, 0.0, 0.0]
- add_weld:
    parent: table::box
    child: gripper::palm
    X_PC:
      translation: [-0.3, 0.0, 0.0]
"""


def jaw_scene(
    folder: Path,
    name: str,
    *,
    hand: str | None = "gripper",
    object_body: str = "box::box",
    directives: str = GRIPPER + PALM_ON_WORLD + BOX,
) -> Path:
    """Write ``folder/name.yaml``: ``directives`` and a ``drakegrasp:`` section.

    ``hand`` is the YAML value of ``hand:`` (None: no ``hand:`` line).
    """
    section = f"drakegrasp:\n  object_body: {object_body}\n"
    if hand is not None:
        section += f"  hand: {hand}\n"
    section += "  mu: 0.5\n"
    path = Path(folder) / f"{name}.yaml"
    path.write_text("directives:\n" + directives + section)
    return path


def edited_shipped(name: str, *pairs: tuple[str, str]) -> str:
    """A shipped scene's text with each ``(old, new)`` replaced (``old`` must occur)."""
    from drakegrasp.plant.scene import scene_path

    text = scene_path(name).read_text()
    for old, new in pairs:
        assert old in text, old
        text = text.replace(old, new)
    return text
