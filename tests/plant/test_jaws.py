"""Two jaws closing as one (issue 20, point 6): close_hand(symmetric=True).

Own model: a WSG-like gripper with two prismatic jaws of four tip spheres
each (``sphere_pad_gripper``); real ones: the WSG-50 and the Franka hand
(skipped without drake_models).  The closing signs are checked against finite
differences of the jaws' gap; which jaw touches, and how far the other one
is, against Drake's signed distances over every pair, computed here.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from hand_models import (
    PAD_SPHERE,
    PAD_Y0,
    Rig,
    box_object,
    one_finger_hand,
    sphere_pad_gripper,
)
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.math import RigidTransform

from drakegrasp import InvalidOptionError, close_hand
from drakegrasp.plant.contacts import DEFAULT_DISTANCE_TOLERANCE as TOL
from drakegrasp.plant.fingers import hand_structure
from drakegrasp.plant.jaws import parallel_jaws
from drakegrasp.plant.validation import hand_bodies

BOX = 0.03  # the box's side, metres


def gripper(y=0.0, *, mimic=False, size=BOX):
    """The sphere-pad gripper, open, around a box centred at (0, y, 0.05)."""
    return Rig(
        [(sphere_pad_gripper(mimic=mimic), "sdf"), (box_object((size,) * 3), "sdf")],
        "box",
        RigidTransform([0.0, y, 0.05]),
    )


def jaw_distances(rig):
    """The smallest ψ of each jaw's spheres, from Drake's pair distances."""
    d = rig.pair_distances()
    return tuple(
        min(v for (g, _), v in d.items() if g.startswith(f"gripper::{side}_tip"))
        for side in ("left", "right")
    )


def _structure(rig):
    query = rig.query()
    bodies = hand_bodies(rig.plant, rig.object, rig.hand)
    hand = hand_structure(rig.plant, rig.object, bodies, inspector=query.inspector())
    return hand, query


def test_closing_signs_agree_with_finite_differences_of_the_gap():
    rig = gripper()
    hand, query = _structure(rig)
    jaws = parallel_jaws(rig.plant, rig.ctx, hand, query)
    assert jaws is not None and jaws.names == (
        "gripper::left_jaw_joint",
        "gripper::right_jaw_joint",
    )

    def gap():
        p = [
            rig.plant.EvalBodyPoseInWorld(
                rig.ctx, rig.plant.GetBodyByName(f"{s}_jaw")
            ).translation()
            for s in ("left", "right")
        ]
        return float(np.linalg.norm(p[1] - p[0]))

    q0 = rig.plant.GetPositions(rig.ctx, rig.hand)
    for k in range(2):
        h = np.zeros(2)
        h[k] = 1e-4
        g0 = gap()
        rig.plant.SetPositions(rig.ctx, rig.hand, q0 + h)
        closes = gap() < g0
        rig.plant.SetPositions(rig.ctx, rig.hand, q0)
        assert jaws.closing_signs[k] == (1.0 if closes else -1.0)
    assert jaws.gear_ratio == 1.0
    np.testing.assert_allclose(jaws.axis_W, [0.0, 1.0, 0.0], atol=1e-12)


def test_off_centre_box_touches_one_jaw_and_the_closure_says_so():
    offset = 0.003
    rig = gripper(offset)
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, symmetric=True)
    assert closure.symmetric and len(closure.fingers) == 1
    assert closure.q[0] == closure.q[1]  # one speed from one pre-shape
    left, right = jaw_distances(rig)
    # The box is 3 mm nearer the right jaw: it touches, the left is 6 mm off.
    assert 0.0 <= right <= TOL
    assert left == pytest.approx(2 * offset + right, abs=1e-9)
    assert [j.touching for j in closure.jaws] == [False, True]
    assert closure.jaws[0].psi == pytest.approx(left, abs=1e-12)
    assert closure.jaws[1].body == "gripper::right_jaw"
    assert closure.one_jaw_only
    (warning,) = closure.warnings
    assert "only one jaw touches" in warning and "gripper::left_jaw" in warning
    assert f"{left * 1e3:.4g} mm" in warning
    text = str(closure)
    assert "WARNING: only one jaw" in text and "jaws closed as one" in text
    data = json.loads(json.dumps(closure.to_dict()))
    assert data["one_jaw_only"] and data["warnings"] == [warning]
    assert data["jaws"][1]["touching"]
    # The right spheres' inner surface, at |y| = PAD_Y0 - q - r, is ψ from
    # the box's face at y = offset + BOX / 2.
    expected = PAD_Y0 - PAD_SPHERE - (offset + BOX / 2) - right
    assert closure.q[1] == pytest.approx(expected, abs=1e-9)


def test_centred_box_touches_both_jaws_without_warning():
    rig = gripper(0.0)
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, symmetric=True)
    assert all(j.touching for j in closure.jaws)
    assert not closure.one_jaw_only and closure.warnings == ()
    assert "WARNING" not in str(closure)
    assert "jaws closed as one; 2 of 2 jaws touch)" in str(closure)


def test_independent_jaws_keep_their_behaviour_and_report_the_jaws():
    rig = gripper(0.003)
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    assert not closure.symmetric and len(closure.fingers) == 2
    # The right jaw meets the box 6 mm sooner than the left.
    assert closure.q[0] - closure.q[1] == pytest.approx(0.006, abs=TOL)
    assert all(j.touching for j in closure.jaws) and not closure.warnings


def test_mimic_coupled_jaws_are_reported_and_symmetric_adds_nothing():
    rig = gripper(0.003, mimic=True)
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    assert len(closure.fingers) == 1 and closure.one_jaw_only
    # one coupled finger touches, yet one of its two jaws does not: the
    # headline once said only "1 of 1 fingers touch"
    assert "1 of 1 fingers touch (tol 0.1 mm; 1 of 2 jaws touch)" in str(closure)
    again = gripper(0.003, mimic=True)
    same = close_hand(
        again.plant, again.ctx, again.object, hand=again.hand, symmetric=True
    )
    np.testing.assert_array_equal(same.q, closure.q)


def test_symmetric_refuses_a_hand_that_is_not_a_parallel_gripper():
    rig = Rig(
        [(one_finger_hand(), "sdf"), (box_object((0.01,) * 3), "sdf")],
        "box",
        RigidTransform([0.0, 0.09, 0.0]),
    )
    with pytest.raises(InvalidOptionError, match="parallel gripper.*revolute"):
        close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, symmetric=True)
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    assert closure.jaws == () and not closure.one_jaw_only
    rig = gripper()
    for bad in ("yes", 1, None):
        with pytest.raises(InvalidOptionError, match="symmetric"):
            close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, symmetric=bad)


def test_wsg_closes_as_one_onto_an_off_centre_box(real_hands):
    X = real_hands.rt([[0, 0, 1], [1, 0, 0], [0, 1, 0]], [0.004, 0.09, 0])
    scene = real_hands.wsg(X_WO=X)
    closure = close_hand(
        scene.plant, scene.ctx, scene.object, hand=scene.hand, symmetric=True
    )
    # WSG: q_left grows to close, q_right shrinks: q_right = -q_left.
    assert closure.q[1] == pytest.approx(-closure.q[0], abs=1e-15)
    assert closure.one_jaw_only
    near, far = sorted(closure.jaws, key=lambda j: j.psi)
    assert near.touching and 0.0 <= near.psi <= TOL
    assert far.psi == pytest.approx(0.008 + near.psi, abs=1e-6)
    assert "only one jaw touches" in str(closure)
    centred = real_hands.wsg()
    closure = close_hand(
        centred.plant, centred.ctx, centred.object, hand=centred.hand, symmetric=True
    )
    assert all(j.touching for j in closure.jaws) and not closure.warnings
    np.testing.assert_allclose(closure.q, [-0.01705, 0.01705], atol=TOL)


def test_franka_closes_as_one_onto_an_off_centre_box(real_hands):
    scene = real_hands.franka()  # the box 5 mm off the fingers' midplane
    closure = close_hand(
        scene.plant, scene.ctx, scene.object, hand=scene.hand, symmetric=True
    )
    assert closure.q[0] == closure.q[1]  # Franka: both close as q shrinks
    assert closure.one_jaw_only
    far = next(j for j in closure.jaws if not j.touching)
    assert far.psi == pytest.approx(0.01, abs=2 * TOL)


@settings(derandomize=True, max_examples=8, deadline=None)
@given(offset=st.floats(-0.004, 0.004).filter(lambda x: abs(x) > 2 * TOL))
def test_the_jaw_report_mirrors_the_offset(offset):
    rig = gripper(offset)
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, symmetric=True)
    assert closure.q[0] == closure.q[1]
    left, right = jaw_distances(rig)
    near = right if offset > 0 else left
    far = left if offset > 0 else right
    assert 0.0 <= near <= TOL
    assert far == pytest.approx(2 * abs(offset) + near, abs=1e-9)
    touching = [j.touching for j in closure.jaws]
    assert touching == ([False, True] if offset > 0 else [True, False])
    assert closure.one_jaw_only
