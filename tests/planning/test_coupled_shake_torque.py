"""``torque_needed`` is per motor; ``shake_test``'s squeeze is per driven joint.

``GraspCandidate.torque_needed`` said "use it as shake_test's squeeze", but
the shake presses every joint a motor drives with the squeeze: a one-motor
jaw's motor applied twice the torque the candidate said it needed (efforts
0.8-2.6 times it for squeezes of 0.4-1.3 times it, on a pivoting jaw of a
user's own).  Checked in Drake: the motor's effort is the squeeze times the
joints it closes, and the recipe the docstring now gives holds the box.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.planning import plan_grasps, planning_scene, shake_test

INERTIA = '<inertia ixx="2e-5" iyy="2e-5" izz="2e-6" ixy="0" ixz="0" iyz="0"/>'


def _jaw(name: str, side: float) -> str:
    shapes = "".join(
        f'<collision><origin xyz="{x:g} {-0.002 * side:g} 0.075"/>'
        '<geometry><sphere radius="0.006"/></geometry></collision>'
        for x in (-0.008, 0.008)
    )
    return (
        f'<link name="{name}"><inertial><origin xyz="0 0 0.04"/>'
        f'<mass value="0.05"/>{INERTIA}</inertial><collision><origin '
        f'xyz="0 {0.004 * side:g} 0.045"/><geometry><box size="0.015 0.008 0.07"/>'
        f"</geometry></collision>{shapes}</link>"
    )


def _pivot(name: str, child: str, side: float, extra: str = "") -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="palm"/>'
        f'<child link="{child}"/><origin xyz="0 {0.05 * side:g} 0"/>'
        f'<axis xyz="{side:g} 0 0"/><limit lower="-0.2" upper="0.9" effort="3" '
        f'velocity="2"/>{extra}</joint>'
    )


PIVOT_JAW = (
    '<?xml version="1.0"?><robot name="pivot_jaw"><link name="palm"><inertial>'
    '<origin xyz="0 0 -0.02"/><mass value="0.5"/><inertia ixx="1e-3" iyy="1e-3" '
    'izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial><collision><origin '
    'xyz="0 0 -0.02"/><geometry><box size="0.04 0.12 0.04"/></geometry>'
    "</collision></link>"
    + _jaw("left", 1.0)
    + _jaw("right", -1.0)
    + _pivot("left_pivot", "left", 1.0)
    + _pivot(
        "right_pivot",
        "right",
        -1.0,
        '<mimic joint="left_pivot" multiplier="1" offset="0"/>',
    )
    + '<transmission name="t"><type>transmission_interface/SimpleTransmission'
    '</type><joint name="left_pivot"><hardwareInterface>EffortJointInterface'
    '</hardwareInterface></joint><actuator name="m"><mechanicalReduction>1'
    "</mechanicalReduction></actuator></transmission></robot>"
)
"""Two jaws pivoting about x at y = ±50 mm, two 6 mm tip spheres each, the
right jaw a ``<mimic>`` of the left: one 3 N·m motor closes both."""


def test_a_one_motor_jaw_held_at_its_torque_needed_per_driven_joint(tmp_path):
    path = tmp_path / "pivot_jaw.urdf"
    path.write_text(PIVOT_JAW)
    scene = planning_scene("package://drakegrasp/objects/box.sdf", hand_url=path)
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, mu=1.0, seed=0, robustness_samples=8,
    )  # fmt: skip
    best = result[0]
    assert best.is_closure and len(best.joint_names) == 2
    needed = float(np.max(best.torque_needed))  # the one motor's
    assert 0.0 < needed < 3.0
    # the recipe: the motor's torque needed over the two joints it closes,
    # with a margin for the seated contacts (a lower bound, see motors)
    squeeze = 1.5 * needed / 2
    shaken = shake_test(scene.add_models, best, squeeze=squeeze)
    assert shaken.held
    (effort,) = shaken.efforts  # the motor presses both jaws with the squeeze
    assert abs(effort - 2 * squeeze) < 0.05 * squeeze
