"""How many motors a multi-finger candidate's torque is per: ``motors``.

The planner records, for every candidate, the joints that carry a motor
(:func:`drakegrasp.planning.motors.motor_names`); the candidate's line says
how many beside its closing joints.  Checked against a second route: the
``<transmission>`` elements of the hand's URDF, read here as XML.
"""

from __future__ import annotations

import dataclasses
import json
import pickle
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from coupled_hands import one_motor_pinch_urdf, plan_on_box, spread_hand_urdf

from drakegrasp.errors import InvalidGraspError, InvalidOptionError
from drakegrasp.planning.motors import motor_names


def _transmitted(urdf: str) -> set[str]:
    """The joints a ``<transmission>`` of ``urdf`` drives, scoped by its robot."""
    root = ET.fromstring(urdf)
    model = root.get("name")
    return {
        f"{model}::{joint.get('name')}"
        for transmission in root.iter("transmission")
        for joint in transmission.iter("joint")
    }


@pytest.fixture(scope="module")
def spread(tmp_path_factory):
    urdf = spread_hand_urdf()
    scene, result = plan_on_box(tmp_path_factory.mktemp("spread") / "h.urdf", urdf)
    return urdf, scene, result


@pytest.fixture(scope="module")
def pinch(tmp_path_factory):
    urdf = one_motor_pinch_urdf(bars=True)
    scene, result = plan_on_box(tmp_path_factory.mktemp("pinch") / "h.urdf", urdf)
    return urdf, scene, result


@pytest.mark.parametrize("hand", ["spread", "pinch"])
def test_the_motors_are_the_urdfs_transmissions(hand, request):
    urdf, scene, result = request.getfixturevalue(hand)
    assert len(result) > 3
    driven = _transmitted(urdf)
    for c in result:
        assert set(c.motors) == driven & set(c.joint_names)
        # in joint_names' order, each once
        order = [n for n in c.joint_names if n in c.motors]
        assert list(c.motors) == order and c.num_motors == len(order)
    assert 0 < result[0].num_motors < len(result[0].joint_names)  # followers


def test_a_one_motor_pinch_has_one_motor_for_its_six_joints(pinch):
    _, _, result = pinch
    best = next(c for c in result if not np.isnan(c.torque_needed))
    assert best.motors == ("one_motor_pinch::left_knuckle",)
    line = str(best)
    assert len(best.joint_names) == 6  # two knuckles, two pads, two inner bars
    assert "6 closing joints, 1 motor, torque " in line, line
    assert "N·m per motor" in line


def test_the_line_says_motors_in_the_plural(spread):
    _, _, result = spread
    c = result[0]
    assert c.num_motors > 1
    assert f"closing joints, {c.num_motors} motors" in str(c)


def test_the_table_json_and_pickle_carry_the_motors(spread):
    _, _, result = spread
    table = result.table()
    assert table["num_motors"].dtype == np.int64
    assert table["num_motors"].tolist() == [c.num_motors for c in result]
    assert list(table).index("num_motors") == list(table).index("torque_unit") + 1
    record = json.loads(json.dumps(result[0].to_dict()))
    assert record["motors"] == list(result[0].motors)
    back = pickle.loads(pickle.dumps(result[0]))
    assert back.motors == result[0].motors and str(back) == str(result[0])
    # one pickled before motors were recorded: none, and no count in its line
    state = pickle.loads(pickle.dumps(result[0])).__dict__
    state.pop("motors")
    old = object.__new__(type(result[0]))
    old.__dict__.update(state)
    assert old.motors == () and old.num_motors == 0
    assert str(old) == str(result[0]).replace(f", {result[0].num_motors} motors", "")
    empty = dataclasses.replace(result, candidates=())
    assert empty.table()["num_motors"].shape == (0,)


@pytest.mark.parametrize("motors", ["abc", None, (1, 2), ("a", 3.0)])
def test_an_edited_motors_is_refused_by_the_table(spread, motors):
    _, _, result = spread
    edited = dataclasses.replace(
        result,
        candidates=(result[0], dataclasses.replace(result[1], motors=motors)),
    )
    with pytest.raises(InvalidGraspError, match="candidate 1's motors"):
        edited.table()


def test_motor_names_refuses_a_joint_the_plant_lacks(spread):
    _, scene, result = spread
    with pytest.raises(InvalidOptionError):
        motor_names(scene.plant, [*result[0].joint_names, "spread_hand::nothing"])
    assert motor_names(scene.plant, ()) == ()
