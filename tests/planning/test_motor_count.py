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
from coupled_hands import (
    coupled_jaw_urdf,
    one_motor_pinch_urdf,
    plan_on_box,
    spread_hand_urdf,
)

from drakegrasp.errors import InvalidGraspError, InvalidOptionError
from drakegrasp.planning.motors import motor_names

BOX = "package://drakegrasp/objects/box.sdf"


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


@pytest.mark.parametrize("motors", ["abc", None, 5, (1, 2), ("a", 3.0), ("a", "a")])
def test_an_edited_motors_is_refused(spread, motors):
    _, _, result = spread
    with pytest.raises(InvalidGraspError, match="the candidate's motors"):
        dataclasses.replace(result[1], motors=motors)
    listed = dataclasses.replace(result[1], motors=list(result[1].motors))
    assert listed.motors == result[1].motors  # a list is taken as its tuple


def test_a_hand_without_actuators_has_no_motor_known_in_any_plant(tmp_path):
    # its joints' torque is taken one per joint; an actuator of another model
    # of the plant (a slider welded beside it) left the hand with no motor in
    # the torque LP too: torque_needed inf, and nothing said
    from drakegrasp.planning import plan_grasps, planning_scene
    from drakegrasp.planning.scenes import scene_from_models
    from drakegrasp.plant.couplings import add_models

    bare = spread_hand_urdf().split("<transmission")[0] + "</robot>"
    slider = (
        '<?xml version="1.0"?><robot name="slider"><link name="base"/>'
        '<link name="cart"><inertial><mass value="0.1"/><inertia ixx="1e-5" '
        'iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        '<joint name="weld" type="fixed"><parent link="world"/><child link="base"/>'
        '<origin xyz="5 5 5"/></joint><joint name="slide" type="prismatic">'
        '<parent link="base"/><child link="cart"/><axis xyz="1 0 0"/>'
        '<limit lower="0" upper="1" effort="1" velocity="1"/></joint>'
        '<transmission name="t"><type>transmission_interface/SimpleTransmission'
        '</type><joint name="slide"/><actuator name="m"/></transmission></robot>'
    )  # fmt: skip
    (tmp_path / "bare.urdf").write_text(bare)
    (tmp_path / "slider.urdf").write_text(slider)
    alone = planning_scene(BOX, hand_url=str(tmp_path / "bare.urdf"))

    def with_slider(plant, parser):
        hand, name = alone.add_models(plant, parser)
        add_models(parser, str(tmp_path / "slider.urdf"))
        return hand, name

    beside = scene_from_models(with_slider)
    assert (alone.plant.num_actuators(), beside.plant.num_actuators()) == (0, 1)
    plans = [
        plan_grasps(
            s.plant,
            s.context,
            s.object_body,
            hand=s.hand,
            num_candidates=40,
            mu=0.5,
            seed=0,
            robustness_samples=4,
            object_mass=0.2,
        )  # fmt: skip
        for s in (alone, beside)
    ]
    a, b = plans
    assert len(a) == len(b) > 3
    for x, y in zip(a, b, strict=True):
        assert x.motors == y.motors == ()
        assert x.sample == y.sample
        assert x.torque_needed == pytest.approx(y.torque_needed, rel=1e-9, nan_ok=True)
    assert any(np.isfinite(x.torque_needed) for x in b)


def test_a_jaws_hidden_drive_is_its_motor(tmp_path):
    # the jaw's slides follow a drive that is not among its closing joints;
    # its twin has the motor on the left slide
    from drakegrasp.planning import plan_grasps, planning_scene

    motors = {}
    for hidden in (False, True):
        path = tmp_path / f"jaw_{hidden}.urdf"
        path.write_text(coupled_jaw_urdf(hidden_drive=hidden))
        s = planning_scene(BOX, hand_url=str(path))
        result = plan_grasps(
            s.plant, s.context, s.object_body, hand=s.hand, num_candidates=20,
            mu=0.5, seed=0, robustness_samples=4,
        )  # fmt: skip
        assert len(result)
        motors[hidden] = {c.motors for c in result}
    assert motors == {
        False: {("coupled_jaw::left_slide",)},
        True: {("coupled_jaw::drive",)},
    }


def test_motor_names_refuses_a_joint_the_plant_lacks(spread):
    _, scene, result = spread
    with pytest.raises(InvalidOptionError):
        motor_names(scene.plant, [*result[0].joint_names, "spread_hand::nothing"])
    assert motor_names(scene.plant, ()) == ()
