"""Hands of our own whose fingers a ``<mimic>`` closes as one group.

- :func:`spread_hand_urdf`: a Barrett-style hand, two fingers on a coupled
  spread, each with its own flexion motor, and a fixed third;
- :func:`one_motor_pinch_urdf`: a Robotiq-style pinch, two knuckles and their
  pads on one motor;
- :func:`coupled_jaw_urdf`: a parallel jaw whose prismatic fingers one motor
  drives;
- :func:`angular_gripper_urdf`: two jaws that turn apart on one motor, shut
  (parallel) at the model's zero.

Shared by the plant and planning tests.
"""

from __future__ import annotations

MODEL = "spread_hand"


def _link(name: str, xyz: str, shape: str, rpy: str = "0 0 0") -> str:
    return (
        f'<link name="{name}"><inertial><origin xyz="{xyz}"/><mass value="0.05"/>'
        '<inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/>'
        f'</inertial><collision><origin xyz="{xyz}" rpy="{rpy}"/><geometry>{shape}'
        "</geometry></collision></link>"
    )


def _joint(name, kind, parent, child, xyz, rpy="0 0 0", axis="0 1 0", extra=""):
    limit = (
        ""
        if kind == "fixed"
        else f'<axis xyz="{axis}"/><limit lower="-0.5" upper="2.0" effort="1.5" '
        'velocity="1"/>'
    )
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
        f'<child link="{child}"/><origin xyz="{xyz}" rpy="{rpy}"/>{limit}{extra}'
        "</joint>"
    )


def transmissions(joints) -> str:
    """URDF ``<transmission>`` s giving each of ``joints`` its own motor."""
    return "".join(
        f'<transmission name="t_{j}"><type>transmission_interface/SimpleTransmission'
        f'</type><joint name="{j}"/><actuator name="m_{j}"><mechanicalReduction>1'
        "</mechanicalReduction></actuator></transmission>"
        for j in joints
    )


def spread_hand_urdf() -> str:
    """The hand as URDF text.

    A palm (a 40 mm cylinder whose top is z = 0) with three fingers pointing
    along +z: ``f3`` fixed at x = +50 mm, ``f1`` and ``f2`` at x = -50 mm,
    y = ±20 mm on spread joints about z, ``f2``'s spread a ``<mimic>`` of
    ``f1``'s (one motor turns both, as a Barrett hand's).  Each finger has a
    proximal joint about its y axis (positive curls it towards the palm's
    centre line; its own motor) and a distal joint following it at 0.5.
    Open (0 rad) the fingers stand straight, 100 mm apart across x.
    """
    capsule = '<capsule radius="0.01" length="0.05"/>'
    tip = '<capsule radius="0.009" length="0.035"/>'
    parts = [_link("palm", "0 0 -0.015", '<cylinder radius="0.07" length="0.03"/>')]
    joints = []
    motors = []
    for name, xyz, yaw, spread in (
        ("f3", "0.05 0 0", "3.14159265", None),
        ("f1", "-0.05 0.02 0", "0", "0 0 -1"),
        ("f2", "-0.05 -0.02 0", "0", "0 0 1"),
    ):
        parts += [
            _link(f"{name}_knuckle", "0 0 0.005", '<sphere radius="0.004"/>'),
            _link(f"{name}_proximal", "0 0 0.035", capsule),
            _link(f"{name}_distal", "0 0 0.0275", tip),
        ]
        if spread is None:
            joints.append(
                _joint(
                    f"{name}_spread",
                    "fixed",
                    "palm",
                    f"{name}_knuckle",
                    xyz,
                    f"0 0 {yaw}",
                )  # fmt: skip
            )
        else:
            mimic = (
                '<mimic joint="f1_spread" multiplier="1" offset="0"/>'
                if name == "f2"
                else ""
            )
            joints.append(
                _joint(
                    f"{name}_spread",
                    "revolute",
                    "palm",
                    f"{name}_knuckle",
                    xyz,
                    axis=spread,
                    extra=mimic,
                )  # fmt: skip
            )
            if name == "f1":
                motors.append("f1_spread")
        joints += [
            _joint(
                f"{name}_proximal_joint",
                "revolute",
                f"{name}_knuckle",
                f"{name}_proximal",
                "0 0 0.01",
            ),  # fmt: skip
            _joint(
                f"{name}_distal_joint",
                "revolute",
                f"{name}_proximal",
                f"{name}_distal",
                "0 0 0.06",
                extra=f'<mimic joint="{name}_proximal_joint" multiplier="0.5" '
                'offset="0"/>',
            ),  # fmt: skip
        ]
        motors.append(f"{name}_proximal_joint")
    return (
        f'<?xml version="1.0"?><robot name="{MODEL}">'
        + "".join(parts)
        + "".join(joints)
        + transmissions(motors)
        + "</robot>"
    )


def one_motor_pinch_urdf(
    *,
    effort: float = 5.0,
    bars: bool = False,
    hidden_drive: bool = False,
    drive_ratio: float = 1.0,
) -> str:
    """A Robotiq-style pinch: two revolute knuckles on one motor, pads kept upright.

    Knuckles 110 mm apart on the palm, about ``y``, 50 mm long; each carries a
    pad (a 8 × 22 × 40 mm box) on a joint that undoes the knuckle's turn, so
    the pads stay parallel as they close (a four-bar's effect, written as
    ``<mimic>``).  The right knuckle and both pads follow the left knuckle,
    whose slide is the only one with a ``<transmission>``: one motor.  Open
    (0 rad) the pads are 71 mm apart.

    ``bars``: the four-bar's other links too, as a Robotiq 2F-85's URDF has
    them: beside each knuckle an inner knuckle (two 4 mm capsules, 18 mm
    either side of the pad, 5 mm behind its face) on its own hinge from the
    palm, turning with the knuckle (``<mimic>`` 1 on the left, -1 on the
    right) and joined to nothing: a chain of the closing group that never
    reaches the object before its pad.

    ``hidden_drive``: the motor on a fifth hinge, ``drive``, whose link has no
    geometry, and the knuckles and pads follow it (``<mimic>`` of the drive,
    with the ratios they have to the left knuckle above): the same pinch, its
    motor moved off the fingers, as a linkage's input crank.  ``drive_ratio``
    scales every ratio to the drive, and the drive's range by its inverse:
    the fingers reach what they reach at 1.
    """
    lead = "drive" if hidden_drive else "left_knuckle"
    scale = drive_ratio if hidden_drive else 1.0

    def link(name, xyz, shape, mass, *more):
        collisions = "".join(
            f'<collision><origin xyz="{at}"/><geometry>{shape}</geometry></collision>'
            for at in (xyz, *more)
        )
        return (
            f'<link name="{name}"><inertial><origin xyz="{xyz}"/><mass value='
            f'"{mass}"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0"'
            f' iyz="0"/></inertial>{collisions}</link>'
        )

    def hinge(name, parent, child, xyz, lower, upper, mimic=None):
        extra = (
            ""
            if mimic is None
            else f'<mimic joint="{lead}" multiplier="{mimic * scale:g}" offset="0"/>'
        )
        return (
            f'<joint name="{name}" type="revolute"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}"/><axis xyz="0 1 0"/>'
            f'<limit lower="{lower}" upper="{upper}" effort="{effort:g}" '
            f'velocity="2"/>{extra}</joint>'
        )

    knuckle = '<capsule radius="0.006" length="0.038"/>'
    pad = '<box size="0.008 0.022 0.04"/>'
    bar = '<capsule radius="0.004" length="0.042"/>'
    four_bar = (
        link("left_bar", "0 0.018 0.025", bar, 0.02, "0 -0.018 0.025")
        + link("right_bar", "0 0.018 0.025", bar, 0.02, "0 -0.018 0.025")
        + hinge("left_bar_joint", "palm", "left_bar", "-0.05 0 0.06", 0, 0.8, 1)
        + hinge("right_bar_joint", "palm", "right_bar", "0.05 0 0.06", -0.8, 0, -1)
        if bars
        else ""
    )
    drive = (
        '<link name="drive"><inertial><mass value="0.01"/><inertia ixx="1e-6" '
        'iyy="1e-6" izz="1e-6" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        + hinge("drive", "palm", "drive", "0 0 0.03", 0, 0.8 / drive_ratio)
        if hidden_drive
        else ""
    )
    knuckle_mimic = 1 if hidden_drive else None
    return (
        '<?xml version="1.0"?><robot name="one_motor_pinch">'
        + link("palm", "0 0 0.025", '<box size="0.14 0.06 0.05"/>', 0.6)
        + link("left_knuckle", "0 0 0.025", knuckle, 0.05)
        + link("right_knuckle", "0 0 0.025", knuckle, 0.05)
        + link("left_pad", "0.0085 0 0.02", pad, 0.03)
        + link("right_pad", "-0.0085 0 0.02", pad, 0.03)
        + drive
        + hinge(
            "left_knuckle",
            "palm",
            "left_knuckle",
            "-0.055 0 0.06",
            0,
            0.8,
            knuckle_mimic,
        )
        + hinge("right_knuckle", "palm", "right_knuckle", "0.055 0 0.06", -0.8, 0, -1)
        + hinge("left_pad_joint", "left_knuckle", "left_pad", "0 0 0.05", -0.8, 0, -1)
        + hinge("right_pad_joint", "right_knuckle", "right_pad", "0 0 0.05", 0, 0.8, 1)
        + four_bar
        + '<transmission name="t"><type>transmission_interface/SimpleTransmission'
        f'</type><joint name="{lead}"/><actuator name="motor">'
        "<mechanicalReduction>1</mechanicalReduction></actuator></transmission>"
        "</robot>"
    )


def coupled_jaw_urdf(
    *,
    pad: str = "capsule",
    ratio: float = -1.0,
    offset: float = 0.0,
    follower: str = "right",
    stroke: float = 0.045,
    hidden_drive: bool = False,
) -> str:
    """A parallel jaw whose two prismatic fingers one motor drives (``<mimic>``).

    The palm (a 40 × 140 × 40 mm box) carries two fingers sliding along ``y``,
    both at the middle when closed; the left one opens towards +y over
    ``[0, stroke]``, the right one towards -y over ``[-stroke, 0]``.
    The ``follower`` finger's joint mimics the other's with ``ratio`` and
    ``offset`` (the right one with ``ratio = -1`` is the symmetric jaw); only
    the leader has a ``<transmission>``.  Each finger ends in a ``pad`` 48 mm
    past the palm: a ``"capsule"`` (7 mm radius, 25 mm long, across the axis),
    a ``"sphere"`` (7 mm) or a ``"box"`` (a 20 × 8 × 20 mm plate).

    With ``hidden_drive`` the motor is on a third slide, ``drive``, whose link
    has no geometry (10 g), and both fingers follow it: the leader finger
    with ratio 1, the follower with ``ratio`` and ``offset``.  The jaw moves
    as the one without it, whose leader finger is where the drive is.
    """
    shapes = {
        "capsule": ('rpy="0 1.5707963 0"', '<capsule radius="0.007" length="0.025"/>'),
        "sphere": ('rpy="0 0 0"', '<sphere radius="0.007"/>'),
        "box": ('rpy="0 0 0"', '<box size="0.02 0.008 0.02"/>'),
    }
    rpy, shape = shapes[pad]

    def finger(name, side):
        y = 0.012 * side
        return (
            f'<link name="{name}"><inertial><origin xyz="0 {0.008 * side} 0.03"/>'
            '<mass value="0.05"/><inertia ixx="1.6e-5" iyy="1.7e-5" izz="2.7e-6" '
            'ixy="0" ixz="0" iyz="0"/></inertial>'
            f'<collision><origin xyz="0 {y} 0.03"/><geometry><box size="0.02 0.008 '
            '0.06"/></geometry></collision>'
            f'<collision><origin xyz="0 0 0.048" {rpy}/><geometry>{shape}</geometry>'
            "</collision></link>"
        )

    def slide(name, child, lower, upper, mimic=""):
        return (
            f'<joint name="{name}" type="prismatic"><parent link="palm"/>'
            f'<child link="{child}"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/>'
            f'<limit lower="{lower}" upper="{upper}" effort="40" velocity="0.1"/>'
            f"{mimic}</joint>"
        )

    lead, follow = ("left", "right") if follower == "right" else ("right", "left")
    leader = "drive" if hidden_drive else f"{lead}_slide"
    mimic = f'<mimic joint="{leader}" multiplier="{ratio}" offset="{offset}"/>'
    mimics = {follow: mimic}
    if hidden_drive:
        mimics[lead] = '<mimic joint="drive" multiplier="1" offset="0"/>'
    limits = {"left": (0.0, stroke), "right": (-stroke, 0.0)}
    joints = "".join(
        slide(f"{s}_slide", f"{s}_finger", *limits[s], mimics.get(s, ""))
        for s in ("left", "right")
    )
    if hidden_drive:
        joints += (
            '<link name="drive_link"><inertial><mass value="0.01"/><inertia '
            'ixx="1e-6" iyy="1e-6" izz="1e-6" ixy="0" ixz="0" iyz="0"/>'
            "</inertial></link>" + slide("drive", "drive_link", *limits[lead])
        )
    return (
        '<?xml version="1.0"?><robot name="coupled_jaw">'
        '<link name="palm"><inertial><origin xyz="0 0 -0.02"/><mass value="0.6"/>'
        '<inertia ixx="1e-3" iyy="1.6e-4" izz="1e-3" ixy="0" ixz="0" iyz="0"/>'
        '</inertial><collision><origin xyz="0 0 -0.02"/><geometry><box size="0.04 '
        '0.14 0.04"/></geometry></collision></link>'
        f"{finger('left_finger', 1)}{finger('right_finger', -1)}{joints}"
        f'<transmission name="t"><type>transmission_interface/SimpleTransmission'
        f'</type><joint name="{leader}"><hardwareInterface>EffortJointInterface'
        f'</hardwareInterface></joint><actuator name="m"><mechanicalReduction>1'
        "</mechanicalReduction></actuator></transmission></robot>"
    )


def angular_gripper_urdf() -> str:
    """An angular gripper: two jaws on hinges, one motor, parallel at zero.

    A palm (30 x 60 x 70 mm, its top at z = 70 mm) with two 90 mm jaws
    (16 x 10 mm section, a 30 mm pad on each inner face near the tip) hinged
    about x at y = -/+24 mm, z = 75 mm.  At 0 rad the jaws stand parallel, the
    pads 32 mm apart: too narrow for drakegrasp's cylinder, sphere or box.
    Positive turns them apart, up to 30 degrees (the pads then some 120 mm
    apart at the tips); the right jaw's hinge is a ``<mimic>`` of the left's,
    which alone has a ``<transmission>`` (0.8 N·m).
    """
    inertia = '<inertia ixx="4e-5" iyy="4e-5" izz="4e-5" ixy="0" ixz="0" iyz="0"/>'

    def jaw(name: str, side: float) -> str:
        boxes = (
            ("0 {y:g} 0.045", "0.016 0.01 0.09"),
            ("0 {p:g} 0.075", "0.016 0.008 0.03"),
        )
        shapes = "".join(
            f'<collision><origin xyz="{xyz.format(y=-0.004 * side, p=0.005 * side)}"/>'
            f'<geometry><box size="{size}"/></geometry></collision>'
            for xyz, size in boxes
        )
        return (
            f'<link name="{name}"><inertial><mass value="0.04"/>{inertia}'
            f"</inertial>{shapes}</link>"
        )

    def hinge(name: str, child: str, y: float, axis: str, extra: str = "") -> str:
        return (
            f'<joint name="{name}" type="revolute"><parent link="palm"/>'
            f'<child link="{child}"/><origin xyz="0 {y:g} 0.075"/>'
            f'<axis xyz="{axis}"/><limit lower="-0.1745" upper="0.5236" '
            f'effort="0.8" velocity="2"/>{extra}</joint>'
        )

    return (
        '<?xml version="1.0"?><robot name="angular_gripper">'
        '<link name="palm"><inertial><mass value="0.3"/>'
        '<inertia ixx="3e-4" iyy="3e-4" izz="3e-4" ixy="0" ixz="0" iyz="0"/>'
        '</inertial><collision><origin xyz="0 0 0.035"/><geometry>'
        '<box size="0.03 0.06 0.07"/></geometry></collision></link>'
        + jaw("left_jaw", 1.0)
        + jaw("right_jaw", -1.0)
        + hinge("left_hinge", "left_jaw", -0.024, "1 0 0")
        + hinge(
            "right_hinge",
            "right_jaw",
            0.024,
            "-1 0 0",
            '<mimic joint="left_hinge" multiplier="1" offset="0"/>',
        )  # fmt: skip
        + transmissions(["left_hinge"])
        + "</robot>"
    )


def plan_on_box(path, urdf: str, **plan):
    """``(scene, result)``: ``urdf`` written to ``path`` and planned on the box.

    The coupled hands' tests' plan: 60 samples, ``mu`` 0.5, seed 0, 8
    robustness samples, an object of 0.2 kg; ``plan`` overrides any of them.
    """
    from drakegrasp.planning import plan_grasps, planning_scene

    path.write_text(urdf)
    scene = planning_scene("package://drakegrasp/objects/box.sdf", hand_url=str(path))
    options = dict(
        num_candidates=60, mu=0.5, seed=0, robustness_samples=8, object_mass=0.2
    )
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        **{**options, **plan},
    )  # fmt: skip
    return scene, result


_PIVOT_INERTIA = '<inertia ixx="2e-5" iyy="2e-5" izz="2e-6" ixy="0" ixz="0" iyz="0"/>'


def _pivot_jaw(name: str, side: float) -> str:
    shapes = "".join(
        f'<collision><origin xyz="{x:g} {-0.002 * side:g} 0.075"/>'
        '<geometry><sphere radius="0.006"/></geometry></collision>'
        for x in (-0.008, 0.008)
    )
    return (
        f'<link name="{name}"><inertial><origin xyz="0 0 0.04"/>'
        f'<mass value="0.05"/>{_PIVOT_INERTIA}</inertial><collision><origin '
        f'xyz="0 {0.004 * side:g} 0.045"/><geometry><box size="0.015 0.008 0.07"/>'
        f"</geometry></collision>{shapes}</link>"
    )


def _pivot_hinge(name: str, child: str, side: float, extra: str = "") -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="palm"/>'
        f'<child link="{child}"/><origin xyz="0 {0.05 * side:g} 0"/>'
        f'<axis xyz="{side:g} 0 0"/><limit lower="-0.2" upper="0.9" effort="3" '
        f'velocity="2"/>{extra}</joint>'
    )


def pivot_jaw_urdf(*, mount: tuple[str, str] | None = None) -> str:
    """A pivoting jaw on one motor: two jaws hinged about x at y = ±50 mm.

    Each jaw carries two 6 mm tip spheres 16 mm apart, 75 mm above its
    hinge; the right hinge is a ``<mimic>`` of the left, which alone has a
    ``<transmission>`` (3 N·m).  ``mount``: ``(xyz, rpy)`` of the palm under
    a root link ``mount`` (no geometry, a fixed joint), so that the hand's
    base frame lies there and is turned so.
    """
    mounted = ""
    if mount is not None:
        mounted = (
            '<link name="mount"><inertial><mass value="0.1"/><inertia ixx="1e-4" '
            'iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>'
            '<joint name="mount_weld" type="fixed"><parent link="mount"/>'
            f'<child link="palm"/><origin xyz="{mount[0]}" rpy="{mount[1]}"/>'
            "</joint>"
        )
    return (
        '<?xml version="1.0"?><robot name="pivot_jaw">'
        + mounted
        + '<link name="palm"><inertial><origin xyz="0 0 -0.02"/><mass value="0.5"/>'
        '<inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/>'
        '</inertial><collision><origin xyz="0 0 -0.02"/><geometry>'
        '<box size="0.04 0.12 0.04"/></geometry></collision></link>'
        + _pivot_jaw("left", 1.0)
        + _pivot_jaw("right", -1.0)
        + _pivot_hinge("left_pivot", "left", 1.0)
        + _pivot_hinge(
            "right_pivot",
            "right",
            -1.0,
            '<mimic joint="left_pivot" multiplier="1" offset="0"/>',
        )
        + '<transmission name="t"><type>transmission_interface/SimpleTransmission'
        '</type><joint name="left_pivot"><hardwareInterface>EffortJointInterface'
        '</hardwareInterface></joint><actuator name="m"><mechanicalReduction>1'
        "</mechanicalReduction></actuator></transmission></robot>"
    )
