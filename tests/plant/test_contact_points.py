"""``p_FC`` is what its docstring says (issue 20, point 11)."""

from __future__ import annotations

import numpy as np
from hand_models import (
    PALM_LINKS,
    PALM_TIP_RADIUS,
    Rig,
    ball,
    box_object,
    mimic_gripper_urdf,
    palm_hand,
)
from pydrake.math import RigidTransform

from drakegrasp import close_hand, find_contacts


def _in_O(rig, contact):
    plant, ctx = rig.plant, rig.ctx
    body = plant.get_body(contact.finger_body_index)
    X_WO = plant.EvalBodyPoseInWorld(ctx, rig.object)
    X_OF = X_WO.inverse().multiply(plant.EvalBodyPoseInWorld(ctx, body))
    return X_OF, np.asarray(X_OF.multiply(contact.p_FC))


def test_a_spherical_tip_touches_at_centre_plus_r_n():
    rig = Rig(
        [(palm_hand(), "sdf"), (ball(0.035), "sdf")],
        "ball",
        RigidTransform([0.0, 0.0, 0.035 + 5e-5]),
    )
    close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    tips = [
        c
        for c in find_contacts(rig.plant, rig.ctx, rig.object)
        if "distal" in c.finger_body
    ]
    assert len(tips) == 2
    for c in tips:
        X_OF, p_OF = _in_O(rig, c)
        centre_O = np.asarray(X_OF.multiply([0.0, 0.0, PALM_LINKS[1]]))
        np.testing.assert_allclose(
            p_OF, centre_O + PALM_TIP_RADIUS * c.nhat_O, atol=1e-15
        )


def test_a_patch_vertex_has_p_oc_minus_psi_n():
    rig = Rig(
        [(mimic_gripper_urdf(), "urdf"), (box_object(), "sdf")],
        "box",
        RigidTransform([0.0, 0.0, 0.05]),
        weld_hand="palm",
    )
    close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    contacts = find_contacts(rig.plant, rig.ctx, rig.object)
    assert all(c.normal_source == "patch" for c in contacts)
    for c in contacts:
        _, p_OF = _in_O(rig, c)
        np.testing.assert_allclose(p_OF, c.p_OC - c.psi * c.nhat_O, atol=1e-15)
