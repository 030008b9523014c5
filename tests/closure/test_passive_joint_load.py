"""A joint without a motor carries no torque, and the load analysis says so.

``torque_limits="plant"`` gives a joint without an actuator a limit of 0.
On a fuzzer's three-finger hand whose distal joints are passive, holding a
ball as ``plan --scene-out`` wrote it, the forces the solver found pressed
1e-12 of the load at one finger and left 2e-14 N·m at its passive joint.
The re-check measured that against the finger's own terms (of the same
size) and called it a violation "by 3 %" (0.91 with the limits set to 0
by hand): a ``SolverError`` and no report, where a limit of 1e-12 gave
"holds: yes".  A joint's torque is now also measured against its torque at
the problem's force size.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import drakegrasp as dg

SCENE = Path(__file__).with_name("passive_hand") / "held_ball.yaml"


@pytest.mark.parametrize(
    "limits", ["plant", [2.0, 0.0, 2.0, 0.0, 2.0, 0.0], [2.0, 1e-300] * 3]
)
def test_passive_joints_hold_the_ball_with_no_torque(limits):
    scene = dg.load_scene(SCENE)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        report = dg.analyze_grasp(
            scene.plant, scene.context,
            **{**scene.analysis_options(), "load": "gravity", "torque_limits": limits},
        )  # fmt: skip
    load = report.load
    assert load.holds
    torques = load.forces.joint_torques
    assert max(abs(torques[j]) for j in (1, 3, 5)) < 1e-9  # the passive joints
    assert max(abs(torques[j]) for j in (0, 2, 4)) <= 2.0 * (1 + 1e-6)


@pytest.mark.parametrize(
    "limit, torque",
    [(0.0, 2e-6), (1e-7, 2e-6), (1e-7, 9e-6), (1e-6, 9e-6), (5e-6, 9e-6)],
)
def test_a_torque_over_a_small_real_limit_is_still_a_violation(limit, torque):
    # measured against the hand's torques, a small limit accepted 90 times
    # its torque, and a smaller limit a larger one: the floor is now the
    # tolerance times the hand's torques (1e-12 of them), continuous in it
    from drakegrasp.closure.load_problem import load_problem

    grasp = dg.Grasp(
        [
            dg.Contact([-0.05, 0, 0], [1, 0, 0], mu=0.5),
            dg.Contact([0.05, 0, 0], [-1, 0, 0], mu=0.5),
            dg.Contact([0, -0.05, 0], [0, 1, 0], mu=0.5),
            dg.Contact([0, 0.05, 0], [0, -1, 0], mu=0.5),
        ]
    )
    J = np.zeros((grasp.num_components, 4))
    for j, s in enumerate(grasp.component_slices()):
        J[s.start, j] = 1.0  # each finger presses along its normal
    w = np.array([0.0, 0.0, -9.81, 0.0, 0.0, 0.0])
    P = load_problem(grasp, hand_jacobian=J, torque_limits=[100, 100, 100, limit])
    f = np.array([9.81, 0, 4.905, 9.81, 0, -4.905, torque, 0, 0, torque, 0, 0])
    violation, where = P.violation(f, w)
    assert violation > 1e-2 and where == "joint 3"
