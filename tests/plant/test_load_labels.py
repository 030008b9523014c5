"""The load section labels each hand velocity by what it is, with its unit.

A free hand base's six entries were printed under the body's name alone
("palm", or "body" for Drake's WSG-50) and no entry had a unit: a prismatic
finger's force read like a revolute joint's torque.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.planning import planning_scene
from drakegrasp.plant.load import _velocity_labels

BASE = tuple(f"free base palm {c}" for c in ("mx", "my", "mz", "fx", "fy", "fz"))
BASE_UNITS = ("N·m",) * 3 + ("N",) * 3


def _load(name, **kw):
    scene = dg.load_scene(name, **kw)
    report = dg.analyze_grasp(
        scene.plant, scene.plant_context, **scene.analysis_options(),
        load="gravity", torque_limits="plant",
    )  # fmt: skip
    return report


def test_a_free_base_is_labelled_by_component_and_fingers_in_newtons():
    report = _load("parallel_jaw_box", free_hand=True)
    load = report.load
    fingers = ("left_finger_joint", "right_finger_joint")
    assert load.joint_names == BASE + fingers
    assert load.torque_units == BASE_UNITS + ("N", "N")
    text = str(report)
    assert "free base palm fz +1.96 N," in text
    assert "left_finger_joint -1.96 N," in text
    assert "right_finger_joint -1.96 N\n" in text
    assert "palm +" not in text  # the bare body name of before
    # numbers unchanged: the torques are still Jᵀ f
    f = load.forces
    np.testing.assert_allclose(f.joint_torques, report.J.T @ f.stacked_forces())
    assert report.to_dict()["load"]["torque_units"] == list(load.torque_units)


def test_a_welded_hand_keeps_its_joint_names_and_revolute_joints_read_n_m():
    jaw = _load("parallel_jaw_box").load
    assert jaw.joint_names == ("left_finger_joint", "right_finger_joint")
    assert jaw.torque_units == ("N", "N")
    three = _load("three_finger_sphere")
    assert set(three.load.torque_units) == {"N·m"}
    tau = next(line for line in str(three).splitlines() if "joint torques" in line)
    assert tau.count(" N·m") == 9 and " N," not in tau


def test_drakes_wsg_base_is_not_labelled_body(drake_models_dir):
    # Drake names a free body's floating joint after the body: the WSG's is
    # "body", which the report printed six times as if it were a joint.
    scene = planning_scene(
        "package://drake_models/ycb/004_sugar_box.sdf", models_dir=drake_models_dir
    )
    plant = scene.plant
    hand = [plant.get_joint(j) for j in plant.GetJointIndices(scene.hand)]
    v = sorted(j.velocity_start() + k for j in hand for k in range(j.num_velocities()))
    labels, units = _velocity_labels(plant, v)
    assert labels[:6] == tuple(
        f"free base body {c}" for c in ("mx", "my", "mz", "fx", "fy", "fz")
    )
    assert labels[6:] == ("left_finger_sliding_joint", "right_finger_sliding_joint")
    assert units == BASE_UNITS + ("N", "N")


@pytest.mark.parametrize("units", [(), ("N", "N")])
def test_a_report_without_units_prints_as_before(units):
    load = _load("parallel_jaw_box").load
    older = dataclasses.replace(load, torque_units=units)
    line = next(s for s in older.report_lines() if "joint torques" in s)
    assert line.endswith("-1.96 N" if units else "-1.96")
