"""Write every model and scene file under ``models/`` (run from anywhere).

    python models/generator/make_models.py [OUTPUT_DIR]

The hands, objects, the convex mesh (``objects/hex_prism.obj``) and the scene
YAML files are generated here so that sizes, masses, inertias and the joint
values that put the fingers exactly on the object's surface all come from one
place and from closed-form expressions (no numerical search).  The committed files
are this script's output; ``tests/plant/test_models.py`` checks that they are up
to date.  numpy and PyYAML are needed.  The script is not part of the
installed package: ``drakegrasp.models`` ships only its output.

Conventions: SI units; every inertia is about the body's centre of mass, in the
body frame; collision geometry uses primitives (spheres, boxes, cylinders,
capsules) except the hexagonal prism, a ``<mesh>`` declared convex.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import yaml

HERE = Path(__file__).resolve().parent.parent  # models/

# --------------------------------------------------------------------------------
# Inertia helpers (about the centre of mass, principal axes = body axes).


def box_inertia(m: float, x: float, y: float, z: float) -> tuple[float, float, float]:
    """Principal moments of a solid box with edge lengths x, y, z."""
    return (
        m * (y * y + z * z) / 12.0,
        m * (x * x + z * z) / 12.0,
        m * (x * x + y * y) / 12.0,
    )


def cylinder_inertia(m: float, r: float, length: float) -> tuple[float, float, float]:
    """Principal moments of a solid cylinder whose axis is z."""
    ixx = m * (3.0 * r * r + length * length) / 12.0
    return (ixx, ixx, 0.5 * m * r * r)


def sphere_inertia(m: float, r: float) -> tuple[float, float, float]:
    """Principal moments of a solid sphere."""
    i = 0.4 * m * r * r
    return (i, i, i)


def polyhedron_mass_properties(
    vertices: np.ndarray, triangles: np.ndarray, density: float
) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia (about the COM) of a closed triangle mesh.

    Sums signed tetrahedra (origin, a, b, c) with outward-wound triangles; the
    second moments use the exact covariance of a tetrahedron.
    """
    canonical = np.array([[2.0, 1.0, 1.0], [1.0, 2.0, 1.0], [1.0, 1.0, 2.0]]) / 120.0
    volume, first, cov = 0.0, np.zeros(3), np.zeros((3, 3))
    for tri in triangles:
        a = vertices[tri].T  # columns a, b, c
        det = float(np.linalg.det(a))
        volume += det / 6.0
        first += det / 24.0 * a.sum(axis=1)
        cov += det * a @ canonical @ a.T
    mass = density * volume
    com = first / volume
    cov_com = density * cov - mass * np.outer(com, com)
    inertia = np.trace(cov_com) * np.eye(3) - cov_com
    return mass, com, inertia


# --------------------------------------------------------------------------------
# SDF writing.


def fmt(x: float) -> str:
    """Shortest round-trip representation of a float."""
    return repr(float(x))


def vec(v) -> str:
    """Space-separated floats."""
    return " ".join(fmt(x) for x in v)


def pose(xyz=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0)) -> str:
    """An SDF <pose> element."""
    return f"<pose>{vec(xyz)} {vec(rpy)}</pose>"


def inertial(mass: float, moments, com=(0.0, 0.0, 0.0)) -> str:
    """An SDF <inertial> element (moments about the COM, body axes)."""
    ixx, iyy, izz = moments
    return f"""      <inertial>
        {pose(com)}
        <mass>{fmt(mass)}</mass>
        <inertia>
          <ixx>{fmt(ixx)}</ixx><ixy>0</ixy><ixz>0</ixz>
          <iyy>{fmt(iyy)}</iyy><iyz>0</iyz><izz>{fmt(izz)}</izz>
        </inertia>
      </inertial>"""


def shape(kind: str, **p) -> str:
    """An SDF geometry element of the given kind."""
    if kind == "box":
        return f"<box><size>{vec(p['size'])}</size></box>"
    if kind == "sphere":
        return f"<sphere><radius>{fmt(p['radius'])}</radius></sphere>"
    if kind == "cylinder":
        return (
            f"<cylinder><radius>{fmt(p['radius'])}</radius>"
            f"<length>{fmt(p['length'])}</length></cylinder>"
        )
    if kind == "capsule":
        return (
            f"<capsule><radius>{fmt(p['radius'])}</radius>"
            f"<length>{fmt(p['length'])}</length></capsule>"
        )
    if kind == "mesh":
        return f"<mesh><uri>{p['uri']}</uri><drake:declare_convex/></mesh>"
    raise ValueError(kind)


def geometry(name: str, kind: str, xyz=(0, 0, 0), rpy=(0, 0, 0), rgba=None, **p):
    """A collision element and a matching visual element."""
    g = shape(kind, **p)
    color = rgba or (0.6, 0.6, 0.6, 1.0)
    return f"""      <collision name="{name}">
        {pose(xyz, rpy)}
        <geometry>{g}</geometry>
      </collision>
      <visual name="{name}_visual">
        {pose(xyz, rpy)}
        <geometry>{g}</geometry>
        <material><diffuse>{vec(color)}</diffuse></material>
      </visual>"""


def link(name: str, body: str, xyz=(0, 0, 0), rpy=(0, 0, 0)) -> str:
    """An SDF <link> with its pose in the model frame."""
    return f"""    <link name="{name}">
      {pose(xyz, rpy)}
{body}
    </link>"""


def joint(name, kind, parent, child, axis, lower, upper, effort, velocity) -> str:
    """An SDF <joint> with limits."""
    return f"""    <joint name="{name}" type="{kind}">
      <parent>{parent}</parent>
      <child>{child}</child>
      <axis>
        <xyz>{vec(axis)}</xyz>
        <limit>
          <lower>{fmt(lower)}</lower><upper>{fmt(upper)}</upper>
          <effort>{fmt(effort)}</effort><velocity>{fmt(velocity)}</velocity>
        </limit>
      </axis>
    </joint>"""


def sdf(model: str, body: str, comment: str) -> str:
    """A whole SDF document with one model."""
    return f"""<?xml version="1.0"?>
<!-- Generated by models/generator/make_models.py; edit that script, not this file. -->
<!-- {comment} -->
<sdf version="1.9" xmlns:drake="http://drake.mit.edu">
  <model name="{model}">
{body}
  </model>
</sdf>
"""


# --------------------------------------------------------------------------------
# Parallel-jaw gripper.  Palm frame: approach direction +z (the palm's top face
# is the plane z = 0), fingers close along y.  Each finger's joint value q is the
# distance from the palm's mid-plane y = 0 to that finger's pad tip, so a
# centred object of half-width a is touched at q = a.  Stroke 0..42.5 mm per
# finger (85 mm total opening, like common two-finger industrial grippers).

PJ_STROKE = 0.0425
PJ_PALM = (0.07, 0.13, 0.06)
PJ_PALM_MASS = 0.8
PJ_BAR = (0.02, 0.012, 0.07)  # finger bar, x y z
PJ_BAR_Z0 = 0.005  # bottom of the finger bar above the palm's top face
PJ_FINGER_MASS = 0.06
PJ_PAD_Z = 0.055  # height of the pad centre above the palm's top face
PJ_DOME_RADIUS = 0.006  # rounded pads: a 6 mm hemispherical dome
PJ_FLAT_PAD = (0.02, 0.004, 0.02)  # flat pads: a 20 x 20 mm square, 4 mm thick


def parallel_jaw(flat: bool) -> str:
    """SDF of the parallel-jaw gripper (rounded or flat pads)."""
    palm = link(
        "palm",
        inertial(PJ_PALM_MASS, box_inertia(PJ_PALM_MASS, *PJ_PALM), (0, 0, -0.03))
        + "\n"
        + geometry(
            "palm",
            "box",
            (0, 0, -PJ_PALM[2] / 2),
            size=PJ_PALM,
            rgba=(0.2, 0.2, 0.2, 1),
        ),
    )
    parts = [palm]
    for side, sign in (("left", 1.0), ("right", -1.0)):
        # Distance from the pad tip (y = 0 of the finger at q = 0) to the bar.
        standoff = PJ_FLAT_PAD[1] if flat else PJ_DOME_RADIUS
        bar_y = sign * (standoff + PJ_BAR[1] / 2)
        bar_z = PJ_BAR_Z0 + PJ_BAR[2] / 2
        body = [
            inertial(
                PJ_FINGER_MASS, box_inertia(PJ_FINGER_MASS, *PJ_BAR), (0, bar_y, bar_z)
            ),
            geometry(
                "bar", "box", (0, bar_y, bar_z), size=PJ_BAR, rgba=(0.5, 0.5, 0.55, 1)
            ),
        ]
        if flat:
            body.append(
                geometry(
                    "pad",
                    "box",
                    (0, sign * PJ_FLAT_PAD[1] / 2, PJ_PAD_Z),
                    size=PJ_FLAT_PAD,
                    rgba=(0.1, 0.1, 0.1, 1),
                )
            )
        else:
            body.append(
                geometry(
                    "pad",
                    "sphere",
                    (0, sign * PJ_DOME_RADIUS, PJ_PAD_Z),
                    radius=PJ_DOME_RADIUS,
                    rgba=(0.1, 0.1, 0.1, 1),
                )
            )
        parts.append(link(f"{side}_finger", "\n".join(body)))
        parts.append(
            joint(
                f"{side}_finger_joint",
                "prismatic",
                "palm",
                f"{side}_finger",
                (0, sign, 0),
                0.0,
                PJ_STROKE,
                140.0,
                0.15,
            )
        )
    pads = (
        "flat 20 x 20 mm pads (flat patches)"
        if flat
        else "rounded pads (6 mm hemispherical domes: point contacts)"
    )
    name = "parallel_jaw_flat" if flat else "parallel_jaw"
    return sdf(
        name,
        "\n".join(parts),
        f"Parallel-jaw gripper, 85 mm stroke, {pads}. Joint value = distance "
        "from the palm mid-plane y = 0 to the pad tip.",
    )


# --------------------------------------------------------------------------------
# Three-finger hand.  Palm frame: the palm's top face is z = 0; finger k's knuckle
# sits at radius HAND_BASE_RADIUS, azimuth HAND_AZIMUTHS[k], height HAND_KNUCKLE_Z.
# Each finger has three flexion joints (proximal, middle, distal) whose axis is
# e_rho x z (positive values curl the finger toward the palm's axis) and ends in a
# spherical fingertip.

HAND_PALM_RADIUS = 0.06
HAND_PALM_LENGTH = 0.03
HAND_PALM_MASS = 0.6
HAND_BASE_RADIUS = 0.05
HAND_KNUCKLE_Z = 0.012
HAND_AZIMUTHS = (
    math.pi / 2,
    math.pi / 2 + 2 * math.pi / 3,
    math.pi / 2 + 4 * math.pi / 3,
)
HAND_LINKS = (0.05, 0.035, 0.025)  # joint-to-joint, and distal joint to tip centre
HAND_LINK_MASSES = (0.04, 0.025, 0.02)
HAND_LINK_RADIUS = 0.008
HAND_TIP_RADIUS = 0.01


def three_finger_hand() -> str:
    """SDF of the three-finger hand."""
    palm = link(
        "palm",
        inertial(
            HAND_PALM_MASS,
            cylinder_inertia(HAND_PALM_MASS, HAND_PALM_RADIUS, HAND_PALM_LENGTH),
            (0, 0, -HAND_PALM_LENGTH / 2),
        )
        + "\n"
        + geometry(
            "palm",
            "cylinder",
            (0, 0, -HAND_PALM_LENGTH / 2),
            radius=HAND_PALM_RADIUS,
            length=HAND_PALM_LENGTH,
            rgba=(0.2, 0.2, 0.2, 1),
        ),
    )
    parts = [palm]
    names = ("proximal", "middle", "distal")
    for k, azimuth in enumerate(HAND_AZIMUTHS, start=1):
        e_rho = np.array([math.cos(azimuth), math.sin(azimuth), 0.0])
        base = HAND_BASE_RADIUS * e_rho + np.array([0, 0, HAND_KNUCKLE_Z])
        z = 0.0
        parent = "palm"
        for j, (name, length, mass) in enumerate(
            zip(names, HAND_LINKS, HAND_LINK_MASSES, strict=True)
        ):
            child = f"finger{k}_{name}"
            body = [
                inertial(
                    mass,
                    cylinder_inertia(mass, HAND_LINK_RADIUS, length),
                    (0, 0, length / 2),
                ),
                geometry(
                    "link",
                    "capsule",
                    (0, 0, length / 2),
                    radius=HAND_LINK_RADIUS,
                    length=length,
                    rgba=(0.55, 0.55, 0.6, 1),
                ),
            ]
            if j == 2:
                body.append(
                    geometry(
                        "tip",
                        "sphere",
                        (0, 0, length),
                        radius=HAND_TIP_RADIUS,
                        rgba=(0.1, 0.1, 0.1, 1),
                    )
                )
            parts.append(
                link(child, "\n".join(body), base + [0, 0, z], (0, 0, azimuth))
            )
            parts.append(
                joint(
                    f"finger{k}_{name}_joint",
                    "revolute",
                    parent,
                    child,
                    (0, -1, 0),
                    -0.5,
                    1.6,
                    2.0,
                    3.0,
                )
            )
            parent = child
            z += length
    return sdf(
        "three_finger_hand",
        "\n".join(parts),
        "Three-finger hand: three fingers 120 deg apart, three flexion joints each "
        "(positive = curl toward the palm axis), 10 mm spherical fingertips.",
    )


def finger_tip(q: tuple[float, float, float]) -> tuple[float, float]:
    """(radius, height) of a fingertip centre in the palm frame, closed form."""
    rho, z, phi = HAND_BASE_RADIUS, HAND_KNUCKLE_Z, 0.0
    for qj, length in zip(q, HAND_LINKS, strict=True):
        phi += qj
        rho -= length * math.sin(phi)
        z += length * math.cos(phi)
    return rho, z


def proximal_for_radius(q2: float, q3: float, rho_target: float) -> float:
    """Proximal angle q1 that puts the tip centre at radius ``rho_target``.

    rho = r_b - (A sin q1 + B cos q1) with A = sum L_k cos(beta_k),
    B = sum L_k sin(beta_k), beta = (0, q2, q2 + q3).
    """
    betas = (0.0, q2, q2 + q3)
    a = sum(length * math.cos(b) for length, b in zip(HAND_LINKS, betas, strict=True))
    b = sum(length * math.sin(b) for length, b in zip(HAND_LINKS, betas, strict=True))
    c, gamma = math.hypot(a, b), math.atan2(b, a)
    return math.asin((HAND_BASE_RADIUS - rho_target) / c) - gamma


# --------------------------------------------------------------------------------
# Objects (free bodies; body frame at the centre of mass).

BOX = {"size": (0.05, 0.05, 0.10), "mass": 0.2}
CYLINDER = {"radius": 0.03, "length": 0.12, "mass": 0.25}
SPHERE = {"radius": 0.035, "mass": 0.12}
HEX = {"apothem": 0.025, "height": 0.08, "density": 900.0}


def hex_prism_mesh() -> tuple[np.ndarray, np.ndarray]:
    """Vertices and outward triangles of a regular hexagonal prism (axis z).

    Vertices at azimuths 0, 60, ... deg, so the side faces' outward normals are at
    30 + 60 k deg; faces at 90, 210 and 330 deg face the three-finger hand's
    fingers and the faces at 90 and 270 deg face the parallel jaw.
    """
    rc = HEX["apothem"] / math.cos(math.pi / 6)
    h = HEX["height"] / 2
    ring = [
        (rc * math.cos(k * math.pi / 3), rc * math.sin(k * math.pi / 3))
        for k in range(6)
    ]
    v = [(x, y, -h) for x, y in ring] + [(x, y, h) for x, y in ring]
    tris = []
    for k in range(6):
        j = (k + 1) % 6
        tris += [(k, j, 6 + j), (k, 6 + j, 6 + k)]
    for k in range(1, 5):
        tris.append((0, k + 1, k))  # bottom, normal -z
        tris.append((6, 6 + k, 6 + k + 1))  # top, normal +z
    return np.array(v), np.array(tris)


def obj_text(v: np.ndarray, tris: np.ndarray) -> str:
    """Wavefront OBJ text of a triangle mesh."""
    lines = [
        "# Regular hexagonal prism, 50 mm across flats, 80 mm tall.",
        "# Generated by models/generator/make_models.py.",
    ]
    lines += [f"v {vec(p)}" for p in v]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in tris]
    return "\n".join(lines) + "\n"


def free_object(name: str, kind: str, mass: float, moments, comment: str, **p) -> str:
    """SDF of a free rigid object with one collision geometry."""
    body = (
        inertial(mass, moments)
        + "\n"
        + geometry(name, kind, rgba=(0.85, 0.55, 0.2, 1), **p)
    )
    return sdf(name, link(name, body), comment)


def objects() -> dict[str, str]:
    """Relative path -> text of every object file."""
    out = {}
    m = BOX["mass"]
    out["objects/box.sdf"] = free_object(
        "box",
        "box",
        m,
        box_inertia(m, *BOX["size"]),
        "Box 50 x 50 x 100 mm, 0.2 kg.",
        size=BOX["size"],
    )
    m, r, ln = CYLINDER["mass"], CYLINDER["radius"], CYLINDER["length"]
    out["objects/cylinder.sdf"] = free_object(
        "cylinder",
        "cylinder",
        m,
        cylinder_inertia(m, r, ln),
        "Cylinder of radius 30 mm, 120 mm long (axis z), 0.25 kg.",
        radius=r,
        length=ln,
    )
    m, r = SPHERE["mass"], SPHERE["radius"]
    out["objects/sphere.sdf"] = free_object(
        "sphere",
        "sphere",
        m,
        sphere_inertia(m, r),
        "Sphere of radius 35 mm, 0.12 kg.",
        radius=r,
    )
    v, tris = hex_prism_mesh()
    mass, com, inertia = polyhedron_mass_properties(v, tris, HEX["density"])
    assert np.allclose(com, 0.0, atol=1e-12)
    assert np.allclose(inertia, np.diag(np.diag(inertia)), atol=1e-12)
    out["objects/hex_prism.obj"] = obj_text(v, tris)
    out["objects/hex_prism.sdf"] = free_object(
        "hex_prism",
        "mesh",
        mass,
        np.diag(inertia),
        "Regular hexagonal prism (convex mesh collision), 50 mm across flats, "
        f"80 mm tall, density 900 kg/m^3 ({mass:.4f} kg).",
        uri="package://drakegrasp/objects/hex_prism.obj",
    )
    return out


# --------------------------------------------------------------------------------
# Scenes.  Model directives (Drake's own format) plus a ``drakegrasp:`` section.


TORSIONAL_FRICTION = 0.1
"""Torsional friction coefficient written into the spatial scenes (soft fingers)."""


class Rpy:
    """A rotation written as Drake's ``!Rpy { deg: [r, p, y] }`` (degrees)."""

    def __init__(self, deg) -> None:
        self.deg = [float(x) for x in deg]


class Flow(list):
    """A list written in flow style (``[x, y, z]``): vectors and joint values."""


class Quoted(str):
    """A string written double-quoted (the scenes' free-text descriptions)."""


class SceneDumper(yaml.SafeDumper):
    """``yaml.SafeDumper`` that knows Drake's ``!Rpy`` tag and flow vectors."""


SceneDumper.add_representer(
    Rpy,
    lambda d, r: d.represent_mapping("!Rpy", {"deg": Flow(r.deg)}, flow_style=True),
)
SceneDumper.add_representer(
    Quoted, lambda d, v: d.represent_scalar("tag:yaml.org,2002:str", v, style='"')
)
SceneDumper.add_representer(
    Flow, lambda d, v: d.represent_sequence("tag:yaml.org,2002:seq", v, flow_style=True)
)


def vector(v) -> Flow:
    """A 3-vector of floats (metres or degrees)."""
    return Flow(float(x) for x in v)


def scene(
    description: str,
    directives: list[dict],
    *,
    object_body: str,
    hand: str,
    mu: float,
    contact_model: str = "hard_finger",
    torsional_friction: float | None = TORSIONAL_FRICTION,
    plane: str | None = None,
) -> str:
    """Text of a scene file: Drake's directives plus the drakegrasp section."""
    section = {
        "description": Quoted(description),
        "object_body": object_body,
        "hand": hand,
        "mu": float(mu),
        "contact_model": contact_model,
    }
    if torsional_friction is not None:
        section["torsional_friction"] = float(torsional_friction)
    if plane is not None:
        section["plane"] = plane
    header = (
        "# Generated by models/generator/make_models.py; edit that script, not "
        f"this file.\n# {description}\n"
    )
    body = yaml.dump(
        {"directives": directives, "drakegrasp": section},
        Dumper=SceneDumper,
        sort_keys=False,
        width=1000,
        allow_unicode=True,
    )
    return header + body


def add_model(name: str, file: str, joints: dict | None = None, pose=None) -> list:
    """An add_model directive (joint values, free-body pose)."""
    directive = {"name": name, "file": file}
    if joints:
        directive["default_joint_positions"] = {
            j: Flow([float(q)]) for j, q in joints.items()
        }
    if pose is not None:
        body, xyz, rpy_deg = pose
        directive["default_free_body_pose"] = {
            body: {"translation": vector(xyz), "rotation": Rpy(rpy_deg)}
        }
    return [{"add_model": directive}]


def add_weld(parent: str, child: str, xyz=None, rpy_deg=None) -> list[dict]:
    """An add_weld directive with an optional X_PC."""
    directive = {"parent": parent, "child": child}
    if xyz is not None:
        directive["X_PC"] = {"translation": vector(xyz), "rotation": Rpy(rpy_deg)}
    return [{"add_weld": directive}]


def planar_gripper_joints() -> tuple[dict, list[tuple[float, tuple]]]:
    """Joint values that put Drake's planar-gripper fingertips on the brick.

    Finger base k is welded at X_WB = RotX(alpha_k) * Translation(0, 0, D); at
    zero joint angles the finger points along -z of its base.  With link lengths
    L1 (base joint to mid joint) and L2 (mid joint to tip-sphere centre), the
    tip centre in the base frame is (0, u, -w) with
    u = L1 sin q1 + L2 sin(q1 + q2), w = L1 cos q1 + L2 cos(q1 + q2), so the
    closed-form two-link inverse kinematics gives (q1, q2).
    """
    l1, l2, tip_r = 0.085, 0.045 + 0.0263, 0.015
    half = 0.05  # brick half-extent in y and z
    fingers = [
        # alpha (deg), tip-centre target (y, z) in the world = brick frame, elbow
        (60.0, (-(half + tip_r), 0.02), 1.0),
        (-60.0, ((half + tip_r), 0.02), -1.0),
        (180.0, (0.0, -(half + tip_r)), 1.0),
    ]
    joints, welds = {}, []
    for k, (alpha_deg, (y, z), elbow) in enumerate(fingers, start=1):
        a = math.radians(alpha_deg)
        origin = np.array(
            [
                0.0,
                -PLANAR_BASE_DISTANCE * math.sin(a),
                PLANAR_BASE_DISTANCE * math.cos(a),
            ]
        )
        d = np.array([0.0, y, z]) - origin
        # Rotate into the base frame: R_WB = RotX(a), so p_B = RotX(-a) d.
        u = math.cos(a) * d[1] + math.sin(a) * d[2]
        w = -(-math.sin(a) * d[1] + math.cos(a) * d[2])
        c2 = (u * u + w * w - l1 * l1 - l2 * l2) / (2 * l1 * l2)
        q2 = elbow * math.acos(c2)
        q1 = math.atan2(u, w) - math.atan2(l2 * math.sin(q2), l1 + l2 * math.cos(q2))
        joints[f"finger{k}_BaseJoint"] = q1
        joints[f"finger{k}_MidJoint"] = q2
        welds.append((alpha_deg, tuple(origin)))
    return joints, welds


PLANAR_BASE_DISTANCE = 0.19


def _three_finger_scene(name: str, rho: float, description: str) -> str:
    """The three-finger hand closed on an object, tips at radius ``rho`` (m)."""
    q2, q3 = 0.35, 0.30
    q1 = proximal_for_radius(q2, q3, rho)
    _, z_tip = finger_tip((q1, q2, q3))
    joints = {}
    for k in (1, 2, 3):
        joints.update(
            {
                f"finger{k}_proximal_joint": q1,
                f"finger{k}_middle_joint": q2,
                f"finger{k}_distal_joint": q3,
            }
        )
    return scene(
        description,
        add_model("hand", "package://drakegrasp/hands/three_finger_hand.sdf", joints)
        + add_weld("world", "hand::palm")
        + add_model(
            name,
            f"package://drakegrasp/objects/{name}.sdf",
            pose=(name, (0, 0, z_tip), (0, 0, 0)),
        ),
        object_body=f"{name}::{name}",
        hand="hand",
        mu=0.5,
    )


def scenes() -> dict[str, str]:
    """Relative path -> text of every scene file."""
    out = {}
    pj = "package://drakegrasp/hands/parallel_jaw.sdf"
    pjf = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
    half_box = BOX["size"][1] / 2
    box_z = 0.065
    for name, hand, description in (
        (
            "parallel_jaw_box",
            pj,
            "Parallel-jaw gripper with rounded pads squeezing a 50 x 50 x 100 mm "
            "box (default scene).",
        ),
        (
            "parallel_jaw_flat_box",
            pjf,
            "Parallel-jaw gripper with flat 20 x 20 mm pads on the box: each pad "
            "touches along a square patch.",
        ),
    ):
        out[f"scenes/{name}.yaml"] = scene(
            description,
            add_model(
                "gripper",
                hand,
                {"left_finger_joint": half_box, "right_finger_joint": half_box},
            )
            + add_weld("world", "gripper::palm")
            + add_model(
                "box",
                "package://drakegrasp/objects/box.sdf",
                pose=("box", (0, 0, box_z), (0, 0, 0)),
            ),
            object_body="box::box",
            hand="gripper",
            mu=0.5,
        )
    r = CYLINDER["radius"]
    out["scenes/parallel_jaw_cylinder.yaml"] = scene(
        "Parallel-jaw gripper with rounded pads on an upright cylinder.",
        add_model("gripper", pj, {"left_finger_joint": r, "right_finger_joint": r})
        + add_weld("world", "gripper::palm")
        + add_model(
            "cylinder",
            "package://drakegrasp/objects/cylinder.sdf",
            pose=("cylinder", (0, 0, 0.075), (0, 0, 0)),
        ),
        object_body="cylinder::cylinder",
        hand="gripper",
        mu=0.5,
    )
    # Tip centres on the object's circle of radius rho, at the height z_tip.
    for name, rho, description in (
        (
            "sphere",
            SPHERE["radius"] + HAND_TIP_RADIUS,
            "Three-finger hand holding a 35 mm-radius sphere at its equator.",
        ),
        (
            "hex_prism",
            HEX["apothem"] + HAND_TIP_RADIUS,
            "Three-finger hand on three side faces of the hexagonal prism "
            "(convex mesh).",
        ),
    ):
        out[f"scenes/three_finger_{name}.yaml"] = _three_finger_scene(
            name, rho, description
        )
    joints, welds = planar_gripper_joints()
    directives = add_model(
        "gripper", "package://drake/examples/planar_gripper/planar_gripper.sdf", joints
    )
    for k, (alpha, origin) in enumerate(welds, start=1):
        directives += add_weld(
            "world", f"gripper::finger{k}_base", origin, (alpha, 0, 0)
        )
    directives += add_model(
        "brick", "package://drake/examples/planar_gripper/planar_brick.sdf"
    ) + add_weld("world", "brick::brick_base")
    out["scenes/planar_gripper_brick.yaml"] = scene(
        "Drake's planar gripper (three 2-joint fingers) on Drake's planar brick, "
        "analysed in the y-z plane.",
        directives,
        object_body="brick::brick_link",
        torsional_friction=None,
        hand="gripper",
        mu=0.5,
        plane="yz",
    )
    return out


PACKAGE_XML = """<?xml version="1.0"?>
<!-- Makes package://drakegrasp/... resolve; see drakegrasp.register_models. -->
<package format="2">
  <name>drakegrasp</name>
  <version>0.1.0</version>
  <description>Hand, object and scene models shipped with drakegrasp.</description>
  <maintainer email="drakegrasp@example.com">drakegrasp</maintainer>
  <license>BSD-3-Clause</license>
</package>
"""


def all_files() -> dict[str, str]:
    """Relative path -> text of every generated file."""
    out = {"package.xml": PACKAGE_XML}
    out["hands/parallel_jaw.sdf"] = parallel_jaw(flat=False)
    out["hands/parallel_jaw_flat.sdf"] = parallel_jaw(flat=True)
    out["hands/three_finger_hand.sdf"] = three_finger_hand()
    out.update(objects())
    out.update(scenes())
    return out


def main(argv: list[str]) -> None:
    """Write every file under OUTPUT_DIR (default: this directory)."""
    root = Path(argv[1]) if len(argv) > 1 else HERE
    for rel, text in all_files().items():
        path = root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
        print(f"wrote {path}")


if __name__ == "__main__":
    main(sys.argv)
