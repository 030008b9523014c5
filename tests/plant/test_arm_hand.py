"""A hand given with the arm that carries it is refused by close_hand, by name.

Drake's ``panda_arm_hand.urdf`` loaded as one model instance and given as
``hand=``: its one "finger" was rooted at the arm's first joint, so closing
moved the arm's joints by up to 3 mrad, left one finger open, and reported
"1 of 1 fingers touch".
"""

from __future__ import annotations

import numpy as np
import pytest
from hand_models import Rig, _urdf_box_link, box_object
from pydrake.math import RigidTransform

from drakegrasp import close_hand
from drakegrasp.errors import ModelError

PANDA = "package://drake_models/franka_description/urdf/panda_arm_hand.urdf"


def _arm_gripper_urdf() -> str:
    """A one-joint arm (about x) carrying a palm with two jaws along y."""
    jaws = "".join(
        f'<joint name="{side}" type="prismatic"><parent link="palm"/>'
        f'<child link="{side}_jaw"/><origin xyz="0 {sign * 0.04} 0.05"/>'
        f'<axis xyz="0 {-sign} 0"/><limit lower="0" upper="0.03" effort="40" '
        'velocity="0.1"/></joint>'
        for side, sign in (("left", -1), ("right", 1))
    )
    return (
        '<?xml version="1.0"?><robot name="arm">'
        + _urdf_box_link("base", (0.05, 0.05, 0.05), mass=1.0)
        + _urdf_box_link("upper", (0.02, 0.02, 0.02), mass=0.5)
        + _urdf_box_link("palm", (0.04, 0.12, 0.02), mass=0.3)
        + _urdf_box_link("left_jaw", (0.02, 0.01, 0.02))
        + _urdf_box_link("right_jaw", (0.02, 0.01, 0.02))
        + '<joint name="shoulder" type="revolute"><parent link="base"/>'
        '<child link="upper"/><origin xyz="0 0 -0.2"/><axis xyz="1 0 0"/>'
        '<limit lower="-1" upper="1" effort="10" velocity="1"/></joint>'
        '<joint name="wrist" type="fixed"><parent link="upper"/><child link="palm"/>'
        '<origin xyz="0 0 0.1"/></joint>' + jaws + "</robot>"
    )


@pytest.fixture
def rig():
    return Rig(
        [(_arm_gripper_urdf(), "urdf"), (box_object(), "sdf")],
        "box",
        RigidTransform([0.0, 0.0, -0.05]),
        weld_hand="base",
    )


def test_a_hand_with_its_arm_is_refused_naming_the_branching_joints(rig):
    q = rig.plant.GetPositions(rig.ctx).copy()
    with pytest.raises(ModelError, match=r"arm::left and arm::right move separate"):
        close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    np.testing.assert_array_equal(rig.plant.GetPositions(rig.ctx), q)


def test_the_hands_own_bodies_close_and_leave_the_arm(rig):
    plant = rig.plant
    jaws = [plant.GetBodyByName(f"{s}_jaw", rig.hand) for s in ("left", "right")]
    shoulder = plant.GetJointByName("shoulder", rig.hand)
    before = shoulder.get_angle(rig.ctx)
    closure = close_hand(plant, rig.ctx, rig.object, hand=jaws)
    assert all(f.status == "touching" for f in closure.fingers)
    assert shoulder.get_angle(rig.ctx) == before


def test_drakes_panda_with_its_arm(drake_models_dir):
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.framework import DiagramBuilder

    from drakegrasp import use_local_drake_models
    from drakegrasp.plant.couplings import add_models

    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, 0.0)
    parser = Parser(plant)
    use_local_drake_models(parser, drake_models_dir)
    (arm,) = add_models(parser, url=PANDA)
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("panda_link0", arm))
    (box,) = parser.AddModelsFromString(box_object(), "sdf")
    plant.Finalize()
    context = builder.Build().CreateDefaultContext()
    ctx = plant.GetMyMutableContextFromRoot(context)
    body = plant.get_body(plant.GetBodyIndices(box)[0])
    plant.SetFreeBodyPose(ctx, body, RigidTransform([0.5, 0.0, 0.3]))
    with pytest.raises(
        ModelError, match="panda_finger_joint1 and .*panda_finger_joint2"
    ):
        close_hand(plant, ctx, body, hand=arm)
