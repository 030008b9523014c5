"""Hand, coupling and tolerance specs the fuzz suite found raw or accepted (issue 21).

``hand=99`` and ``couplings=5``, ``[None]``, ``[1.5]`` raised raw TypeErrors; a
joint coupled to itself was accepted (and frozen), bool/str gear ratios were
read as numbers, and ``distance_tolerance="1e-4"`` was read as a float.  Each
is an InvalidOptionError naming the value; valid specs still close the hand.
"""

from __future__ import annotations

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError

LEFT, RIGHT = "gripper::left_finger_joint", "gripper::right_finger_joint"


@pytest.fixture
def scene():
    s = dg.load_scene()
    q = s.plant.GetPositions(s.plant_context)
    q[:2] = 0.03  # open, clear of the box
    s.plant.SetPositions(s.plant_context, q)
    return s


def _close(s, **kwargs):
    return dg.close_hand(
        s.plant, s.context, s.object_body, **{"hand": s.hand, **kwargs}
    )


@pytest.mark.parametrize("hand", [99, 1.5, 1j, b"gripper"])
def test_a_hand_that_is_no_spec_is_refused(scene, hand):
    with pytest.raises(InvalidOptionError, match="hand must be"):
        _close(scene, hand=hand)
    with pytest.raises(InvalidOptionError, match="hand must be"):
        dg.grasp_from_plant(
            scene.plant, scene.context, scene.object_body, hand=hand, mu=0.5
        )


@pytest.mark.parametrize(
    "couplings, match",
    [
        (5, "couplings must be a sequence"),
        ("couplings", "couplings must be a sequence"),
        ([None], "each coupling is"),
        ([1.5], "each coupling is"),
        ([(LEFT, RIGHT, 1.0)], "each coupling is"),
        ([(LEFT, LEFT, 1.0, 0.0)], "to itself"),
        ([(LEFT, RIGHT, True, 0.0)], "gear_ratio"),
        ([(LEFT, RIGHT, "1", 0.0)], "gear_ratio"),
        ([(LEFT, RIGHT, 1j, 0.0)], "gear_ratio"),
        ([(LEFT, RIGHT, 1.0, None)], "gear_ratio"),
    ],
)
def test_bad_couplings_are_refused(scene, couplings, match):
    q0 = scene.plant.GetPositions(scene.plant_context).copy()
    with pytest.raises(InvalidOptionError, match=match):
        _close(scene, couplings=couplings)
    np.testing.assert_array_equal(scene.plant.GetPositions(scene.plant_context), q0)


def test_a_valid_coupling_still_closes_as_one(scene):
    closure = _close(scene, couplings=[(LEFT, RIGHT, 1.0, 0.0)])
    assert closure.q[0] == closure.q[1]
    assert len(closure.touching_fingers) >= 1


@pytest.mark.parametrize("tol", ["1e-4", b"1", True, None, 1j])
def test_distance_tolerance_must_be_a_real_number(scene, tol):
    with pytest.raises(InvalidOptionError, match="distance_tolerance"):
        _close(scene, distance_tolerance=tol)


@pytest.mark.parametrize("q", [[0.05, 0.03], [0.03, 0.043], [0.0576, 0.034]])
def test_a_pre_shape_beyond_the_joint_limits_is_refused(scene, q):
    # It was accepted, and a finger that did not move (max_iterations=1, or a
    # direction that left it) was returned beyond its limit.
    plant, ctx = scene.plant, scene.plant_context
    q_all = plant.GetPositions(ctx)
    q_all[:2] = q
    plant.SetPositions(ctx, q_all)
    with pytest.raises(dg.JointLimitError, match="outside the joint limits"):
        _close(scene, max_iterations=1)
    np.testing.assert_array_equal(plant.GetPositions(ctx), q_all)


@pytest.mark.parametrize("scale", [1e-300, 1e-92, 1e-13, 1.0, 3.5e42, 1e300])
def test_a_positive_multiple_of_a_direction_closes_alike(scale):
    # [1e-13, -1e-13] was read as no direction: the fingers stopped "at limit".
    def closed(direction):
        s = dg.load_scene()
        q = s.plant.GetPositions(s.plant_context)
        q[:2] = [0.0287, 0.0283]
        s.plant.SetPositions(s.plant_context, q)
        return _close(s, direction=direction)

    unit = np.array([-0.9726361996160886, 0.23233343107777749])
    want = closed(unit)
    got = closed(scale * unit)
    np.testing.assert_array_equal(got.q, want.q)
    assert [f.status for f in got.fingers] == [f.status for f in want.fingers]
    assert "touching" in [f.status for f in got.fingers]


def test_a_query_object_of_another_scene_graph_is_refused():
    # analyze_grasp, grasp_from_plant, find_contacts and plant_friction let
    # pydrake's RuntimeError ("Can't report collision filter status ...") or
    # an AttributeError (an int) through; now the check contacts_from_results
    # made, for every entry point that takes a query_object.
    from drakegrasp.plant.friction import plant_friction

    scene, other = (
        dg.load_scene("three_finger_sphere"),
        dg.load_scene("three_finger_sphere"),
    )
    plant, ctx, body = scene.plant, scene.plant_context, scene.object_body
    foreign = other.plant.get_geometry_query_input_port().Eval(other.plant_context)
    contacts = dg.find_contacts(plant, ctx, object_body=body)
    calls = [
        lambda q: dg.analyze_grasp(plant, ctx, body, mu=0.5, query_object=q),
        lambda q: dg.grasp_from_plant(plant, ctx, body, mu=0.5, query_object=q),
        lambda q: dg.find_contacts(plant, ctx, object_body=body, query_object=q),
        lambda q: plant_friction(plant, ctx, contacts, query_object=q),
    ]
    for call in calls:
        with pytest.raises(dg.InvalidOptionError, match="not registered with"):
            call(foreign)
        with pytest.raises(dg.InvalidOptionError, match="QueryObject or None, got int"):
            call(5)
    own = plant.get_geometry_query_input_port().Eval(ctx)
    report = dg.analyze_grasp(plant, ctx, body, mu=0.5, query_object=own)
    assert (
        report.force_closure.is_closure
        == dg.analyze_grasp(plant, ctx, body, mu=0.5).force_closure.is_closure
    )
