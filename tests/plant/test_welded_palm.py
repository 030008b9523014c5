"""Every body of the hand touches, a palm welded to the world included (issue 20, 2).

The reproducer: a ball resting 0.05 mm above a welded palm (inside the 0.1 mm
contact tolerance) with two fingers closed on it.  Without the palm the grasp
has 2 contacts, rank 5 and no force closure; with it, 3 contacts, rank 6 and
force closure, which the independent scipy test confirms.
"""

from __future__ import annotations

import numpy as np
import pytest
from closure_oracle import independent_force_closure
from hand_models import Rig, ball, palm_hand
from pydrake.math import RigidTransform

from drakegrasp import ModelError, analyze_grasp, close_hand, find_contacts

GAP = 5e-5


@pytest.fixture
def held_ball():
    rig = Rig(
        [(palm_hand(), "sdf"), (ball(0.035), "sdf")],
        "ball",
        RigidTransform([0.0, 0.0, 0.035 + GAP]),
    )
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    assert closure.touching_fingers == (
        "hand::left_proximal_joint",
        "hand::right_proximal_joint",
    )
    return rig


def _body(rig, name):
    return rig.plant.GetBodyByName(name, rig.hand)


def test_the_welded_palm_is_a_contact_and_makes_force_closure(held_ball):
    rig = held_ball
    report = analyze_grasp(rig.plant, rig.ctx, rig.object, hand=rig.hand, mu=0.5)
    assert [c.finger_body for c in report.contacts] == [
        "hand::palm",
        "hand::left_distal",
        "hand::right_distal",
    ]
    palm = report.contacts[0]
    assert palm.psi == pytest.approx(GAP, abs=1e-12)
    np.testing.assert_allclose(palm.nhat_O, [0, 0, 1], atol=1e-12)
    assert report.force_closure.rank == 6
    assert report.force_closure.is_closure
    assert independent_force_closure(report.contacts, 0.5)
    assert "hand::palm" in report.data.hand_bodies
    # The palm's rows of J are exactly zero; the fingers' are not.
    J = report.J
    assert J.shape == (9, 4)
    assert np.all(J[:3] == 0.0)
    assert np.linalg.norm(J[3:6]) > 0 and np.linalg.norm(J[6:]) > 0


def test_without_the_palm_the_grasp_is_short_of_rank(held_ball):
    rig = held_ball
    fingers = [
        _body(rig, f"{side}_{link}")
        for side in ("left", "right")
        for link in ("proximal", "distal")
    ]
    report = analyze_grasp(rig.plant, rig.ctx, rig.object, hand=fingers, mu=0.5)
    assert report.grasp.num_contacts == 2
    assert report.force_closure.rank == 5
    assert not report.force_closure.is_closure
    assert not independent_force_closure(report.contacts, 0.5)
    # Listing the palm keeps it, whatever the order of the list.
    report = analyze_grasp(
        rig.plant, rig.ctx, rig.object, hand=[*fingers, _body(rig, "palm")], mu=0.5
    )
    assert report.grasp.num_contacts == 3 and report.force_closure.is_closure


def test_a_hand_of_only_the_palm_is_analysed(held_ball):
    rig = held_ball
    palm = _body(rig, "palm")
    (contact,) = find_contacts(rig.plant, rig.ctx, rig.object, hand=[palm])
    assert contact.finger_body == "hand::palm"
    report = analyze_grasp(rig.plant, rig.ctx, rig.object, hand=[palm], mu=0.5)
    assert report.J.shape == (3, 0)  # no hand velocity
    assert not report.force_closure.is_closure
    assert "J: 3 x 0" in str(report)
    # close_hand still needs a joint to close.
    with pytest.raises(ModelError, match="welded to the world"):
        close_hand(rig.plant, rig.ctx, rig.object, hand=[palm])
