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
from coupled_hands import pivot_jaw_urdf

from drakegrasp.planning import plan_grasps, planning_scene, shake_test


def test_a_one_motor_jaw_held_at_its_torque_needed_per_driven_joint(tmp_path):
    path = tmp_path / "pivot_jaw.urdf"
    path.write_text(pivot_jaw_urdf())
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
