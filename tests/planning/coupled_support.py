"""A coupled hand of our own: three two-link fingers, each distal joint a
``<drake:mimic>`` follower of its proximal one (a Barrett-like linkage).

Shared by the planning tests of coupled hands (``test_multifinger``,
``test_coupled_hand``).
"""

from __future__ import annotations

import numpy as np

MODEL = "coupled_hand"
RATIO = 1.0  # the followers' multiplier


def coupled_hand_sdf(
    *,
    follower_effort: float = 2.0,
    ratio: float = RATIO,
    tip_ratio: float | None = None,
) -> str:
    """The hand as SDFormat text.

    Three two-link fingers 120° apart around the palm's z axis, capsule links,
    joints about ``-y`` of each finger (positive closes), limits [-0.6, 1.5]
    rad.  Drake adds an actuator to a joint whose ``<effort>`` is not zero: the
    proximal joints get 2 N·m; ``follower_effort=0`` leaves the distal joints
    without one, as a real linkage's follower has no motor.  ``tip_ratio``
    adds a third link to each finger, its joint a follower of the distal one
    at that multiplier (a chain of couplings: tip → distal → proximal), the
    distal and proximal links then 0.04 and 0.035 m long.
    """
    links, joints = [], []
    parts = (("prox", 0.0, 0.05), ("dist", 0.05, 0.04))
    if tip_ratio is not None:
        parts = (("prox", 0.0, 0.04), ("dist", 0.04, 0.035), ("tip", 0.075, 0.03))
    for k in range(3):
        a = 2 * np.pi * k / 3
        c, s = np.cos(a), np.sin(a)
        x, y = 0.045 * c, 0.045 * s
        for part, z, length in parts:
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
        chain = [
            ("prox", "palm", "", 2.0),
            ("dist", f"f{k}_prox", mimic, follower_effort),
        ]
        if tip_ratio is not None:
            tip = (
                f"<drake:mimic joint='f{k}_dist_joint' multiplier='{tip_ratio:g}' "
                "offset='0'/>"
            )
            chain.append(("tip", f"f{k}_dist", tip, follower_effort))
        for part, parent, extra, effort in chain:
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


def one_motor_jaw_urdf(*, effort: float = 40.0) -> str:
    """A parallel jaw whose right finger follows the left (``<mimic>``, -1).

    Two prismatic fingers 120 mm apart on a 200 mm palm, each closing 55 mm
    towards the middle; one ``<transmission>``, on the left slide: one motor
    closes both fingers, as many real two-finger grippers do.
    """

    def link(name, xyz, size, mass):
        return (
            f'<link name="{name}"><inertial><origin xyz="{xyz}"/><mass value='
            f'"{mass}"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0"'
            f' iyz="0"/></inertial><collision><origin xyz="{xyz}"/><geometry>'
            f'<box size="{size}"/></geometry></collision></link>'
        )

    def slide(name, child, x, lower, upper, extra=""):
        return (
            f'<joint name="{name}" type="prismatic"><parent link="palm"/>'
            f'<child link="{child}"/><origin xyz="{x} 0 0"/><axis xyz="1 0 0"/>'
            f'<limit lower="{lower}" upper="{upper}" effort="{effort:g}" '
            f'velocity="0.1"/>{extra}</joint>'
        )

    return (
        '<?xml version="1.0"?><robot name="one_motor_jaw">'
        + link("palm", "0 0 0.02", "0.2 0.05 0.04", 0.8)
        + link("left", "0 0 0.07", "0.01 0.025 0.06", 0.05)
        + link("right", "0 0 0.07", "0.01 0.025 0.06", 0.05)
        + slide("left_slide", "left", -0.06, 0, 0.055)
        + slide(
            "right_slide",
            "right",
            0.06,
            -0.055,
            0,
            '<mimic joint="left_slide" multiplier="-1" offset="0"/>',
        )
        + '<transmission name="t"><type>transmission_interface/SimpleTransmission'
        '</type><joint name="left_slide"/><actuator name="motor">'
        "<mechanicalReduction>1</mechanicalReduction></actuator></transmission>"
        "</robot>"
    )
