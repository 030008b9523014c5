"""Test models of the plant tests: hands and objects written for one reproducer each.

Each function returns model text (SDFormat or URDF); :class:`Rig` parses the
texts into one plant with a scene graph, welds what the text welds, and keeps
the diagram, its root context and the plant context.

- :func:`bead_and_wire_object` — a 1.5 mm bead and a 0.3 mm wire on one free
  body (issue 20, point 1);
- :func:`one_finger_hand` — a palm welded to the world and one revolute finger
  (a phalanx box and a spherical tip) turning about the world z axis;
- :func:`palm_hand` — a palm welded to the world and two opposed revolute
  fingers with spherical tips, to hold a ball against the palm (point 2);
- :func:`mimic_gripper_urdf`, :func:`mimic_gripper_sdf` — a parallel gripper
  whose jaws are coupled by URDF ``<mimic>`` / SDFormat ``<drake:mimic>``.
"""

from __future__ import annotations

import numpy as np
from drake_distances import hand_object_distances
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from drakegrasp.plant import add_models


def _v(*xs) -> str:
    return " ".join(repr(float(x)) for x in xs)


def _inertial(mass=0.05, i=1e-5) -> str:
    return (
        f"<inertial><mass>{mass}</mass><inertia><ixx>{i}</ixx><iyy>{i}</iyy>"
        f"<izz>{i}</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>"
    )


def _collision(name, geometry, xyz=(0, 0, 0), rpy=(0, 0, 0)) -> str:
    return (
        f'<collision name="{name}"><pose>{_v(*xyz, *rpy)}</pose>'
        f"<geometry>{geometry}</geometry></collision>"
    )


def _sdf(model: str, body: str) -> str:
    return (
        '<?xml version="1.0"?><sdf version="1.9" xmlns:drake="http://drake.mit.edu">'
        f'<model name="{model}">{body}</model></sdf>'
    )


def _box(x, y, z) -> str:
    return f"<box><size>{_v(x, y, z)}</size></box>"


def _sphere(r) -> str:
    return f"<sphere><radius>{r}</radius></sphere>"


def _cylinder(r, length) -> str:
    return f"<cylinder><radius>{r}</radius><length>{length}</length></cylinder>"


def _revolute(name, parent, child, axis, lower, upper, xyz=(0, 0, 0)) -> str:
    return (
        f'<joint name="{name}" type="revolute"><pose relative_to="{child}">'
        f"{_v(*xyz, 0, 0, 0)}</pose><parent>{parent}</parent><child>{child}</child>"
        f"<axis><xyz>{_v(*axis)}</xyz><limit><lower>{lower}</lower>"
        f"<upper>{upper}</upper></limit></axis></joint>"
    )


def _palm(size, z) -> str:
    """The 0.5 kg link ``palm``: a box of ``size`` (m) centred at height ``z``."""
    return (
        '<link name="palm">'
        + _inertial(0.5, 1e-3)
        + _collision("palm_box", _box(*size), xyz=(0, 0, z))
        + "</link>"
    )


def _weld_to_world(child) -> str:
    return (
        f'<joint name="{child}_weld" type="fixed"><parent>world</parent>'
        f"<child>{child}</child></joint>"
    )


FINGER_RADIUS = 0.09
"""Distance (m) of the one-finger hand's tip centre from its joint axis."""
TIP_RADIUS = 0.004
PHALANX = (0.002, 0.075)  # x range of the phalanx box in the finger frame


def one_finger_hand() -> str:
    """A welded palm (below z = -0.02) and one finger turning about world z.

    The finger frame's x axis points from the axis to the tip; at ``q = 0`` it
    is the world x axis.  The phalanx is a 8 x 10 mm box over
    ``x ∈ [2, 75] mm``; the tip a sphere of radius 4 mm at ``x = 90 mm``.
    """
    x0, x1 = PHALANX
    palm = _palm((0.05, 0.05, 0.01), z=-0.03)
    finger = (
        '<link name="finger">'
        + _inertial()
        + _collision("phalanx", _box(x1 - x0, 0.008, 0.01), xyz=(0.5 * (x0 + x1), 0, 0))
        + _collision("tip", _sphere(TIP_RADIUS), xyz=(FINGER_RADIUS, 0, 0))
        + "</link>"
    )
    return _sdf(
        "hand",
        palm
        + finger
        + _weld_to_world("palm")
        + _revolute("finger_joint", "palm", "finger", (0, 0, 1), -1.0, 2.5),
    )


BEAD_RADIUS = 0.0015
BEAD_HEIGHT = 0.0085
"""Height (m) of the bead's centre above the finger's plane, on the joint axis:
the phalanx stays ``hypot(2, 3.5) mm − 1.5 mm = 2.53 mm`` from it at every angle."""


def bead_and_wire_object(
    wire_angle: float,
    *,
    wire_radius: float = 0.00015,
    wire_length: float = 0.03,
    kind: str = "cylinder",
    wire_tilt: float = 0.0,
) -> str:
    """A bead on the finger's joint axis and a thin wire across the tip's circle.

    The body frame is the bead's centre, placed at ``(0, 0, BEAD_HEIGHT)`` in
    the world by :class:`Rig`.  The wire crosses the tip's circle (radius
    :data:`FINGER_RADIUS` in the plane z = 0) at polar angle ``wire_angle``:
    a cylinder of radius ``wire_radius`` along z (``kind="cylinder"``) or a
    plate ``2 wire_radius`` thick (``kind="plate"``) whose thin axis is the
    circle's tangent, tilted by ``wire_tilt`` about the radial direction.
    """
    c, s = np.cos(wire_angle), np.sin(wire_angle)
    centre = (FINGER_RADIUS * c, FINGER_RADIUS * s, -BEAD_HEIGHT)
    if kind == "cylinder":
        wire = _cylinder(wire_radius, wire_length)
    else:
        wire = _box(2 * wire_radius, wire_length, wire_length)
    # the plate's thin x axis along the tangent (yaw by the angle + 90°), tilted
    # about the radial direction (the plate's own y axis after the yaw)
    if kind == "plate":
        rpy = (0.0, wire_tilt, wire_angle + 0.5 * np.pi)
    else:
        rpy = (wire_tilt, 0.0, 0.0)
    body = (
        '<link name="bead_wire">'
        + _inertial(0.01, 1e-6)
        + _collision("bead", _sphere(BEAD_RADIUS))
        + _collision("wire", wire, xyz=centre, rpy=rpy)
        + "</link>"
    )
    return _sdf("bead_wire", body)


class Rig:
    """Models parsed from text into one plant; contexts ready to use.

    Parameters
    ----------
    texts : list of (str, str)
        ``(text, "sdf" | "urdf")``; the first model is the hand.
    object_model : str
        Name of the object's model instance; its first body is ``self.object``
        and is placed at ``X_WO``.
    X_WO : RigidTransform, optional
    weld_hand : str, optional
        A frame of the hand to weld to the world (URDF has no world joint).
    time_step : float
    gravity : bool
        False: no gravity (``plant.mutable_gravity_field()`` set to zero).
    record_couplings : bool
        Parse with :func:`drakegrasp.plant.add_models` (default), which records
        the models' mimic couplings, or with a bare ``Parser``.
    """

    def __init__(
        self,
        texts,
        object_model,
        X_WO=None,
        *,
        weld_hand=None,
        time_step=0.0,
        record_couplings=True,
        gravity=True,
    ):
        from pydrake.math import RigidTransform

        builder = DiagramBuilder()
        plant, self.scene_graph = AddMultibodyPlantSceneGraph(builder, time_step)
        parser = Parser(plant)
        instances = []
        for text, kind in texts:
            if record_couplings:
                instances += add_models(parser, text=text, kind=kind)
            else:
                instances += parser.AddModelsFromString(text, kind)
        self.hand = instances[0]
        if not gravity:
            plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
        if weld_hand is not None:
            plant.WeldFrames(
                plant.world_frame(), plant.GetFrameByName(weld_hand, self.hand)
            )
        plant.Finalize()
        self.plant = plant
        self.diagram = builder.Build()
        self.root = self.diagram.CreateDefaultContext()
        self.ctx = plant.GetMyContextFromRoot(self.root)
        instance = plant.GetModelInstanceByName(object_model)
        self.object = plant.get_body(plant.GetBodyIndices(instance)[0])
        if self.object.is_floating_base_body():
            plant.SetFreeBodyPose(self.ctx, self.object, X_WO or RigidTransform())

    def query(self):
        """The scene graph's query object in the present configuration."""
        return self.plant.get_geometry_query_input_port().Eval(self.ctx)

    def pair_distances(self) -> dict[tuple[str, str], float]:
        """ψ of every unfiltered (hand geometry, object geometry) pair."""
        query = self.query()
        name = query.inspector().GetName
        return {
            (name(gh), name(go)): d
            for _, gh, go, d in hand_object_distances(
                self.plant, query, self.hand, self.object
            )
        }


PALM_FINGER_X = 0.05
"""|x| (m) of the two finger joints of :func:`palm_hand` on the palm's top face."""
PALM_LINKS = (0.035, 0.025)  # proximal and distal lengths to the next joint / tip
PALM_TIP_RADIUS = 0.008


def palm_hand() -> str:
    """A palm (top face z = 0) welded to the world and two opposed two-link fingers.

    Each finger's joints turn about axes parallel to y, the proximal one
    through ``(±x, 0, 0)``; at ``q = 0`` the finger points up (+z): a 6 x 6 mm
    proximal bar 35 mm long, then a distal bar and a spherical tip (radius
    8 mm) 25 mm above the distal joint.  The ``left_*`` joints (at −x) close
    with q > 0, the ``right_*`` joints with q < 0.
    """
    x, r = PALM_FINGER_X, PALM_TIP_RADIUS
    l1, l2 = PALM_LINKS
    palm = _palm((0.16, 0.08, 0.02), z=-0.01)
    links, joints = "", ""
    for side, sx, sign in (("left", -x, 1.0), ("right", x, -1.0)):
        lo, hi = sorted((-0.3 * sign, 1.4 * sign))
        links += (
            f'<link name="{side}_proximal"><pose>{_v(sx, 0, 0, 0, 0, 0)}</pose>'
            + _inertial()
            + _collision(
                f"{side}_proximal_bar",
                _box(0.006, 0.006, l1 - 0.004),
                xyz=(0, 0, 0.5 * l1),
            )
            + "</link>"
            + f'<link name="{side}_distal"><pose>{_v(sx, 0, l1, 0, 0, 0)}</pose>'
            + _inertial()
            + _collision(
                f"{side}_distal_bar",
                _box(0.006, 0.006, l2 - r),
                xyz=(0, 0, 0.5 * (l2 - r)),
            )
            + _collision(f"{side}_tip", _sphere(r), xyz=(0, 0, l2))
            + "</link>"
        )
        joints += _revolute(
            f"{side}_proximal_joint", "palm", f"{side}_proximal", (0, 1, 0), lo, hi
        )
        joints += _revolute(
            f"{side}_distal_joint",
            f"{side}_proximal",
            f"{side}_distal",
            (0, 1, 0),
            lo,
            hi,
        )
    return _sdf("hand", palm + links + _weld_to_world("palm") + joints)


def ball(radius: float = 0.035) -> str:
    """A free ball (SDFormat model ``ball``)."""
    return _sdf(
        "ball",
        '<link name="ball">'
        + _inertial(0.1, 5e-5)
        + _collision("ball", _sphere(radius))
        + "</link>",
    )


JAW_Y0 = 0.05
"""|y| (m) of each jaw's pad centre at q = 0; a jaw at q has its pad centre
at ``|y| = JAW_Y0 − q``."""
JAW_PAD = (0.02, 0.004, 0.02)
JAW_STROKE = 0.045


def _urdf_box_link(name, size=None, xyz=(0, 0, 0), mass=0.05) -> str:
    geometry = (
        ""
        if size is None
        else (
            f'<collision name="{name}_pad"><origin xyz="{_v(*xyz)}"/>'
            f'<geometry><box size="{_v(*size)}"/></geometry></collision>'
        )
    )
    return (
        f'<link name="{name}"><inertial><mass value="{mass}"/>'
        '<inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/>'
        f"</inertial>{geometry}</link>"
    )


def _follows_left(tag: str, multiplier: float, offset: float) -> str:
    """The ``<mimic>`` (URDF) or ``<drake:mimic>`` (SDF) that follows the left jaw."""
    return (
        f'<{tag} joint="left_jaw_joint" multiplier="{multiplier}" offset="{offset}"/>'
    )


def mimic_gripper_urdf(multiplier: float = 1.0, offset: float = 0.0) -> str:
    """A parallel gripper whose right jaw follows the left by URDF ``<mimic>``.

    Palm frame: the jaws close along y, their pads centred at z = 0.05 m.
    ``left_jaw_joint`` moves the left pad from ``y = −JAW_Y0`` towards +y,
    ``right_jaw_joint`` (the follower) the right pad from ``+JAW_Y0`` towards
    −y; both prismatic, ``[0, JAW_STROKE]``, flat 20 x 20 mm pads.  Weld the
    frame ``palm`` to the world.
    """
    joints = ""
    for side, sign in (("left", -1.0), ("right", 1.0)):
        mimic = _follows_left("mimic", multiplier, offset) if side == "right" else ""
        joints += (
            f'<joint name="{side}_jaw_joint" type="prismatic"><parent link="palm"/>'
            f'<child link="{side}_jaw"/><origin xyz="{_v(0, sign * JAW_Y0, 0.05)}"/>'
            f'<axis xyz="{_v(0, -sign, 0)}"/>'
            f'<limit lower="0" upper="{JAW_STROKE}" effort="40" velocity="0.1"/>'
            f"{mimic}</joint>"
        )
    links = (
        _urdf_box_link("palm", (0.04, 0.12, 0.02), xyz=(0, 0, 0.0), mass=0.5)
        + _urdf_box_link("left_jaw", JAW_PAD)
        + _urdf_box_link("right_jaw", JAW_PAD)
    )
    return f'<?xml version="1.0"?><robot name="mimic_gripper">{links}{joints}</robot>'


def mimic_gripper_sdf(multiplier: float = 1.0, offset: float = 0.0) -> str:
    """The gripper of :func:`mimic_gripper_urdf`, coupled by ``<drake:mimic>``."""
    body = _palm((0.04, 0.12, 0.02), z=0)
    for side, sign in (("left", -1.0), ("right", 1.0)):
        mimic = (
            _follows_left("drake:mimic", multiplier, offset) if side == "right" else ""
        )
        body += (
            f'<link name="{side}_jaw">'
            f"<pose>{_v(0, sign * JAW_Y0, 0.05, 0, 0, 0)}</pose>"
            + _inertial()
            + _collision(f"{side}_jaw_pad", _box(*JAW_PAD))
            + "</link>"
            + f'<joint name="{side}_jaw_joint" type="prismatic"><parent>palm</parent>'
            f"<child>{side}_jaw</child><axis><xyz>{_v(0, -sign, 0)}</xyz>"
            f"<limit><lower>0</lower><upper>{JAW_STROKE}</upper></limit></axis>"
            f"{mimic}</joint>"
        )
    body += _weld_to_world("palm")
    return _sdf("mimic_gripper", body)


def box_object(size=(0.03, 0.03, 0.03), name="box", mu=None) -> str:
    """A free box (SDFormat model ``name``), with friction ``mu`` if given."""
    collision = _collision(name, _box(*size))
    if mu is not None:
        friction = (
            f"<drake:proximity_properties><drake:mu_dynamic>{mu}</drake:mu_dynamic>"
            f"<drake:mu_static>{mu}</drake:mu_static></drake:proximity_properties>"
        )
        collision = collision.replace("</collision>", friction + "</collision>")
    return _sdf(
        name, f'<link name="{name}">' + _inertial(0.1, 5e-5) + collision + "</link>"
    )


PAD_SPHERE = 0.002
"""Radius (m) of the four spheres of each pad of :func:`sphere_pad_gripper`."""
PAD_HALF = 0.008
"""Half the side (m) of the square the pad spheres' centres make."""
PAD_Y0 = 0.05
"""|y| (m) of each pad's sphere centres at q = 0; a jaw at q has them at
``|y| = PAD_Y0 − q``."""


def sphere_pad_gripper(mimic: bool = False) -> str:
    """A WSG-like parallel gripper: two prismatic jaws with four-sphere pads.

    A palm box below z = 0 is welded to the world.  ``left_jaw_joint`` moves
    the left jaw from ``y = −PAD_Y0`` towards +y, ``right_jaw_joint`` the right
    one from ``+PAD_Y0`` towards −y (both ``[0, 0.045]`` m, actuated).  Each pad
    is four spheres (radius :data:`PAD_SPHERE`) centred at ``x, z − 0.05 ∈
    {±PAD_HALF}`` in the plane ``|y| = PAD_Y0 − q``, as the WSG-50's tips.
    With ``mimic`` the right jaw follows the left by ``<drake:mimic>``.
    """
    palm = (
        '<link name="palm">'
        + _inertial(0.5, 1e-3)
        + _collision("palm_box", _box(0.04, 0.14, 0.01), xyz=(0, 0, -0.005))
        + "</link>"
    )
    body = palm
    for side, sign in (("left", -1.0), ("right", 1.0)):
        spheres = "".join(
            _collision(f"{side}_tip_{i}{j}", _sphere(PAD_SPHERE), xyz=(x, 0, z))
            for i, x in enumerate((-PAD_HALF, PAD_HALF))
            for j, z in enumerate((-PAD_HALF, PAD_HALF))
        )
        mimic_text = (
            '<drake:mimic joint="left_jaw_joint" multiplier="1" offset="0"/>'
            if mimic and side == "right"
            else ""
        )
        body += (
            f'<link name="{side}_jaw">'
            f"<pose>{_v(0, sign * PAD_Y0, 0.05, 0, 0, 0)}</pose>"
            + _inertial()
            + spheres
            + "</link>"
            + f'<joint name="{side}_jaw_joint" type="prismatic"><parent>palm</parent>'
            f"<child>{side}_jaw</child><axis><xyz>{_v(0, -sign, 0)}</xyz>"
            f"<limit><lower>0</lower><upper>0.045</upper><effort>20</effort>"
            f"</limit></axis>{mimic_text}</joint>"
        )
    body += _weld_to_world("palm")
    return _sdf("gripper", body)
