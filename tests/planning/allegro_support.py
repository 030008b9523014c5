"""The Allegro right hand in the planning tests: its scene and its thumb."""

from __future__ import annotations

from drakegrasp.planning import planning_scene

ALLEGRO = (
    "package://drake_models/allegro_hand_description/sdf/"
    "allegro_hand_description_right.sdf"
)
THUMB = ("link_12", "link_13", "link_14", "link_15")


def allegro_scene(ycb_name: str, models_dir):
    """Drake's Allegro right hand, thumb opposed (``joint_12 = 1.0``), and a YCB
    object (``ycb_name`` such as ``"004_sugar_box"``)."""
    scene = planning_scene(
        f"package://drake_models/ycb/{ycb_name}.sdf",
        hand_url=ALLEGRO,
        models_dir=models_dir,
    )
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    scene.plant.GetJointByName("joint_12").set_angle(ctx, 1.0)
    return scene


def has_thumb(candidate) -> bool:
    """Whether any of the candidate's contacts is on the thumb."""
    return any(
        k.finger_body.split("::")[-1].startswith(THUMB) for k in candidate.contacts
    )
