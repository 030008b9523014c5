"""A coupled hand of our own: three two-link fingers, each distal joint a
``<drake:mimic>`` follower of its proximal one (a Barrett-like linkage).

Shared by the planning tests of coupled hands (``test_multifinger``,
``test_coupled_hand``).
"""

from __future__ import annotations

import numpy as np

MODEL = "coupled_hand"
RATIO = 1.0  # the followers' multiplier


def coupled_hand_sdf(*, follower_effort: float = 2.0, ratio: float = RATIO) -> str:
    """The hand as SDFormat text.

    Three two-link fingers 120° apart around the palm's z axis, capsule links,
    joints about ``-y`` of each finger (positive closes), limits [-0.6, 1.5]
    rad.  Drake adds an actuator to a joint whose ``<effort>`` is not zero: the
    proximal joints get 2 N·m; ``follower_effort=0`` leaves the distal joints
    without one, as a real linkage's follower has no motor.
    """
    links, joints = [], []
    for k in range(3):
        a = 2 * np.pi * k / 3
        c, s = np.cos(a), np.sin(a)
        x, y = 0.045 * c, 0.045 * s
        for part, z, length in (("prox", 0.0, 0.05), ("dist", 0.05, 0.04)):
            links.append(
                f"<link name='f{k}_{part}'><pose>{x} {y} {z} 0 0 {a}</pose>"
                "<inertial><mass>0.03</mass><inertia><ixx>1e-5</ixx><iyy>1e-5</iyy>"
                "<izz>1e-6</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia>"
                f"</inertial><collision name='c'><pose>0 0 {length / 2} 0 0 0</pose>"
                f"<geometry><capsule><radius>0.007</radius><length>{length}</length>"
                "</capsule></geometry></collision></link>"
            )
        mimic = (
            f"<drake:mimic joint='f{k}_prox_joint' multiplier='{ratio:g}' offset='0'/>"
        )
        for part, parent, extra, effort in (
            ("prox", "palm", "", 2.0),
            ("dist", f"f{k}_prox", mimic, follower_effort),
        ):
            joints.append(
                f"<joint name='f{k}_{part}_joint' type='revolute'>"
                f"<parent>{parent}</parent><child>f{k}_{part}</child>"
                "<axis><xyz>0 -1 0</xyz><limit><lower>-0.6</lower><upper>1.5</upper>"
                f"<effort>{effort:g}</effort></limit></axis>{extra}</joint>"
            )
    return (
        '<?xml version="1.0"?><sdf version="1.9" xmlns:drake="http://drake.mit.edu">'
        f"<model name='{MODEL}'><link name='palm'><inertial><mass>0.5</mass>"
        "<inertia><ixx>1e-3</ixx><iyy>1e-3</iyy><izz>1e-3</izz><ixy>0</ixy>"
        "<ixz>0</ixz><iyz>0</iyz></inertia></inertial><collision name='c'>"
        "<pose>0 0 -0.01 0 0 0</pose><geometry><cylinder><radius>0.055</radius>"
        "<length>0.02</length></cylinder></geometry></collision></link>"
        + "".join(links)
        + "".join(joints)
        + "</model></sdf>"
    )
