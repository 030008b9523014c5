"""Generated two-sided pinches: sides, rolled sampling and the shake's mass.

The surfaces of three changes, drawn at random (all seeded):

* :func:`drakegrasp.planning.centring.chain_sides` and
  :func:`~drakegrasp.planning.centring.facing_chains` (chains of one closing
  group that move alike share a side);
* the pinch sampling of :mod:`drakegrasp.planning.approach`
  (``MultiFingerHand.closing_axis``, ``pinch_reach``, ``pinch_width``): a
  hand whose chains move on exactly two sides is rolled so its closing axis
  meets the object's normals;
* ``shake_test(object_mass=)`` and ``shake_candidates`` taking the mass the
  plan was made for (``settings["object_mass"]``); a massless model needs one.

The hands (``pinch_hand``) are two-finger pinches on one motor, as
``tests/support/coupled_hands.py``'s ``one_motor_pinch_urdf`` but drawn:

``revolute``
    two knuckles on hinges about the palm's y axis, each carrying a pad that
    a ``<mimic>`` keeps upright (or tilts, at half the rate); pads of random
    size and offset on each side; knuckles and pads of capsules and boxes,
    or of balls (a ball's distance to a box, cylinder or ball is Drake's
    exact one); the right knuckle's multiplier -1 or not (-0.5, -2,
    -1 - 1e-7, +1: turning with the left, one side); a Robotiq-style
    four-bar's inner knuckles beside the pads (with collision geometry or
    without, turning with their knuckle or at 0.9 of its rate);
``prismatic``
    two slides along the palm's x axis, each carrying a carriage and a pad
    that a ``<mimic>`` of the slide tilts: two joints a chain, so the hand
    is not a parallel jaw and takes the multi-finger route.

The right side may be written otherwise with the same motion: its root's
axis turned with the multiplier's sign, or its frame turned half a turn
about z (on the joint, or on a bracket welded to the palm) with its
geometry and multipliers to match.

A hostile layout on top: the right side without any collision geometry
(``bare``), both sides' pads one behind the other along the approach
(``stacked``: the knuckles at one x, one longer), or a pinch whose open pads
are closer than the object is wide (``narrow``).

Per hand, each call in a sandboxed worker (a hang or crash is an outcome):

``sides``
    ``chain_sides`` at the built pose, at a random pose of the hand's base and
    joints, and over the chains reversed and shuffled; ``multi_finger_hand``'s
    pinch.  Judged against the hand's description: two chains share a side
    exactly when they are joined through root joints each beside the next
    (revolute, their written axis times their rate one vector, their origins
    along the axis at most a tenth of their distance across it); the
    partition is the same
    whatever the pose or order, and numbered from 0 in the chains' order.  A
    pinch is found when there are two sides with geometry and their pads are
    not one behind the other; its closing axis is across the approach, unit,
    and along the two pads' centres (from the description) less their part
    along the approach, ``pinch_width`` the gap between their faces.
``plan``
    ``plan_grasps`` on the shipped box, cylinder, sphere or hex prism (the
    default options, or a tilt of 0 or 90°, a stand-off, an approach
    sideways or leaning; the context's hand open or partly closed, its
    pre-shape); every other hand also in the scene (object and hand) moved
    by a random rigid motion.  Every candidate keeps its couplings and
    limits (1e-9), a finite proper ``X_WH``, no geometry deeper in the
    object than the tolerance (Drake's signed distances), contacts on a
    chain's body or the palm (none on a side without geometry).  Moved, the
    sampled poses and pre-shapes are the same in the object frame to 1e-9;
    for a hand of balls on the box, cylinder or sphere the two plans are
    too: as many candidates, the same rejections, each ``X_OH``, joint
    values and contact (point, normal) to 1e-9.  For the other hands Drake's
    own distances move with the scene (:func:`exact_distances`), and so may
    the closing.
``cloud``
    ``plan_grasps`` on a point cloud of the box (``object_mass`` given),
    judged as ``fuzz_coupled``'s cloud cases.
``shake``
    One plan per hand on a box (the shipped 0.2 kg box, a massless box, a
    URDF box link without ``<inertial>``), planned with or without
    ``object_mass``, then ``shake_test`` with hostile ``object_mass``
    values (0, negative, NaN, inf, 1e308 whose weight overflows, booleans,
    strings, numpy scalars, 1e-300, a milligram whose contacts ask for a step
    under ``MIN_TIME_STEP``, refused at the first candidate shaken, 1e300, 1e4
    kg) or ``shake_candidates``
    on the plan, a slice of it, or a list, with or without ``object_mass``.
    A massless model's shake also gets a candidate whose ``torque_scale``
    or ``reference_point`` (the ball its inertia is taken from) is hostile.
    A refusal must be a GraspError; an answer reports the mass shaken
    (``ShakeResult.object_mass``: the given one; none given, the plan's for
    candidates of a plan made with one, the whole result or a slice or list
    of it, else the model's), finite figures, and an object of 1e4 kg or
    more is not held (a squeeze of 5 N·m per joint, capped at the effort
    limit, presses far less than its weight).

``facing_chains`` gets random and hostile gaps and sides in this process.

Defects found and not fixed are :data:`FINDINGS`; :func:`finding` names
the cases that show them (strict xfails in ``test_fuzz_pinch.py``).

    python tests/fuzz/fuzz_pinch.py [--details]

prints the outcome table and the findings' cases.
"""

from __future__ import annotations

import collections
import dataclasses
import math
import re
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from fuzz_cases import Case, report_family, run_family  # noqa: E402
from fuzz_coupled import (  # noqa: E402
    _f,
    _joint_values,
    _min_distance,
    _transform,
    placed_faults,
)
from hostile import pick  # noqa: E402
from sandbox import Sandbox  # noqa: E402

import drakegrasp as dg  # noqa: E402

BOX = "package://drakegrasp/objects/box.sdf"  # 50 x 50 x 100 mm, 0.2 kg
CYLINDER = "package://drakegrasp/objects/cylinder.sdf"  # r 30 mm, 120 mm, 0.25 kg
INVARIANCE_TOL = 1e-9
HEAVY = 1e4
"""kg: no squeeze of the shake's holds this (see the module docstring)."""

# ================================================================ the hands


def _u(rng, lo, hi) -> float:
    return float(repr(float(rng.uniform(lo, hi))))


def pinch_hand(rng) -> dict:
    """A random two-sided pinch (see the module docstring)."""
    hostile: list[str] = []
    kind = "prismatic" if rng.random() < 0.3 else "revolute"
    layout = pick(rng, ("plain",) * 6 + ("narrow", "narrow", "stacked", "bare"))
    if kind == "prismatic" and layout == "stacked":
        layout = "plain"
    if layout != "plain":
        hostile.append(layout)
    rate = pick(rng, (-1.0,) * 6 + (-0.5, -2.0, -1.0 - 1e-7, 1.0))
    if rate != -1.0:
        hostile.append(f"right x{rate!r}")
    # the right side written otherwise, moving alike: its root's axis turned
    # (and the multiplier's sign), or its frame turned half a turn about z
    # (on the joint, or on a bracket welded to the palm)
    flip = pick(rng, (None, None, None, "axis", "frame", "bracket"))
    if flip:
        hostile.append(f"right {flip} turned")
    pads = {
        side: {
            "size": [_u(rng, 0.005, 0.014), _u(rng, 0.012, 0.03),
                     _u(rng, 0.02, 0.05)],
            "offset": [_u(rng, -0.003, 0.003), _u(rng, -0.003, 0.003),
                       _u(rng, -0.008, 0.008)],
        }
        for side in ("left", "right")
    }  # fmt: skip
    hand = {
        "kind": kind,
        "layout": layout,
        "palm": [_u(rng, 0.12, 0.2), _u(rng, 0.05, 0.08), _u(rng, 0.03, 0.05)],
        "rate": rate,
        "flip": flip,
        "pads": pads,
        "hostile": hostile,
    }
    if kind == "revolute":
        kr = _u(rng, 0.004, 0.008)
        shape = pick(rng, ("capsule", "box", "ball", "ball", "ball"))
        hand["knuckle"] = {"left": _u(rng, 0.035, 0.065), "radius": kr,
                           "shape": shape}  # fmt: skip
        if shape != "capsule":
            hostile.append(f"{shape} geometry")
        hand["knuckle"]["right"] = hand["knuckle"]["left"]
        inner = _u(rng, 0.055, 0.1)  # between the open pads' inner faces
        if layout == "narrow":
            inner = _u(rng, 0.012, 0.04)  # the box is 50 mm, the can 60 mm
        t_l, t_r = pads["left"]["size"][0], pads["right"]["size"][0]
        hand["spacing"] = inner + t_l + t_r + 2 * kr
        hand["lead"] = [0.0, _u(rng, 0.5, 1.0)]
        hand["bars"] = None
        if layout == "stacked":
            hand["spacing"] = 0.0
            for side in pads:  # the pads over the hinges' line, narrow
                pads[side]["size"][1] = min(pads[side]["size"][1], 0.018)
            hand["knuckle"]["right"] = (
                hand["knuckle"]["left"] + pads["left"]["size"][2] + 0.02
            )
        elif rng.random() < 0.4:
            hand["bars"] = {
                "solid": bool(rng.random() < 0.7),
                "off": bool(rng.random() < 0.25),  # at 0.9 of its knuckle's rate
            }
            hostile.append(
                "bars" + ("" if hand["bars"]["solid"] else " bare")
                + (" off-rate" if hand["bars"]["off"] else "")
            )  # fmt: skip
        hand["pad_rate"] = pick(rng, (1.0, 1.0, 1.0, 0.5))
        if hand["pad_rate"] != 1.0:
            hostile.append("pads tilt")
    else:
        travel = _u(rng, 0.02, 0.045)
        inner = _u(rng, 0.06, 0.1)
        if layout == "narrow":
            inner = _u(rng, 0.015, 0.04)
        hand["carriage"] = [0.012, 0.02, _u(rng, 0.03, 0.06)]
        t_l, t_r = pads["left"]["size"][0], pads["right"]["size"][0]
        hand["spacing"] = inner + t_l + t_r + 0.012
        hand["lead"] = [0.0, min(travel, hand["spacing"] / 2 - 0.01)]
        hand["tilt_rate"] = pick(rng, (2.0, -2.0, 5.0))  # rad per metre of slide
    return _described(hand)


def _limits(lo, hi, m, o=0.0) -> list[float]:
    a, b = sorted((m * lo + o, m * hi + o))
    return [a, b]


def _described(hand: dict) -> dict:
    """Its joints: limits, couplings, axes and parents (the oracles' source)."""
    lead = hand["lead"]
    rate = hand["rate"]
    flip = hand["flip"]
    sign = -1.0 if flip else 1.0  # the right side's multipliers
    turned = flip in ("frame", "bracket")  # its frames half a turn about z
    joints, couplings = {}, []
    s = hand["spacing"]
    z0 = hand["palm"][2] + 0.01

    def add(name, kind, parent, child, xyz, axis, m=None):
        right = name.startswith("right")
        if right and flip == "axis" and parent in ("palm", "right_bracket"):
            axis = [-a for a in axis]
        yaw = math.pi if right and turned else 0.0
        if right and turned and parent in ("palm", "right_bracket"):
            xyz = (0.0, 0.0, 0.0) if flip == "bracket" else xyz
        joints[name] = {
            "kind": kind, "parent": parent, "child": child, "xyz": list(xyz),
            "axis": list(axis), "yaw": yaw,
            "rpy": [0.0, 0.0, yaw if right and flip == "frame"
                    and parent == "palm" else 0.0],
            "limits": list(lead) if m is None else _limits(*lead, m),
            "rate": 1.0 if m is None else m,
        }  # fmt: skip
        if m is not None:
            couplings.append((name, first, m, 0.0))

    right_parent = "right_bracket" if flip == "bracket" else "palm"
    if flip == "bracket":
        y = 0.02 if hand["layout"] == "stacked" else 0.0
        hand["bracket"] = [s / 2, y, z0]

    if hand["kind"] == "revolute":
        first = "left_knuckle"
        stacked = hand["layout"] == "stacked"
        y = 0.02 if stacked else 0.0
        add(first, "revolute", "palm", "left_knuckle", (-s / 2, -y, z0), (0, 1, 0))
        add("right_knuckle", "revolute", right_parent, "right_knuckle",
            (s / 2, y, z0), (0, 1, 0), sign * rate)  # fmt: skip
        pr = hand["pad_rate"]
        add("left_pad_joint", "revolute", "left_knuckle", "left_pad",
            (0, 0, hand["knuckle"]["left"]), (0, 1, 0), -pr)  # fmt: skip
        add("right_pad_joint", "revolute", "right_knuckle", "right_pad",
            (0, 0, hand["knuckle"]["right"]), (0, 1, 0),
            -pr if turned else pr)  # fmt: skip
        bars = hand["bars"]
        if bars is not None:
            k = 0.9 if bars["off"] else 1.0
            inset = hand["knuckle"]["radius"] + 0.002
            add("left_bar_joint", "revolute", "palm", "left_bar",
                (-s / 2 + inset, 0, z0), (0, 1, 0), k)  # fmt: skip
            add("right_bar_joint", "revolute", right_parent, "right_bar",
                (s / 2 - inset, 0, z0), (0, 1, 0), sign * k * rate)  # fmt: skip
            if flip == "bracket":
                joints["right_bar_joint"]["xyz"] = [inset, 0.0, 0.0]
    else:
        first = "left_slide"
        add(first, "prismatic", "palm", "left_carriage", (-s / 2, 0, z0), (1, 0, 0))
        add("right_slide", "prismatic", right_parent, "right_carriage",
            (s / 2, 0, z0), (1, 0, 0), sign * rate)  # fmt: skip
        h = hand["carriage"][2]
        k = hand["tilt_rate"]
        add("left_pad_joint", "revolute", "left_carriage", "left_pad", (0, 0, h),
            (0, 1, 0), -k)  # fmt: skip
        add("right_pad_joint", "revolute", "right_carriage", "right_pad", (0, 0, h),
            (0, 1, 0), -k * rate if turned else k * rate)  # fmt: skip
    hand["joints"] = joints
    hand["couplings"] = couplings
    hand["leader"] = first
    return hand


def _link(name, shapes, mass=0.05) -> str:
    """A link; ``shapes`` ((xyz, geometry) ...) its collision geometry."""
    collisions = "".join(
        f'<collision><origin xyz="{_f(*xyz)}"/><geometry>{g}</geometry></collision>'
        for xyz, g in shapes
    )
    return (
        f'<link name="{name}"><inertial><mass value="{mass}"/><inertia ixx="1e-5" '
        f'iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial>{collisions}'
        "</link>"
    )


def urdf(hand: dict) -> str:
    """The URDF text of a hand drawn by :func:`pinch_hand`."""
    px, py, pz = hand["palm"]
    bare = hand["layout"] == "bare"
    parts = [_link("palm", [((0, 0, pz / 2), f'<box size="{_f(px, py, pz)}"/>')], 0.6)]
    stacked = hand["layout"] == "stacked"

    turned = hand["flip"] in ("frame", "bracket")

    def shapes(side, items):
        if side == "right" and turned:  # its frames half a turn about z
            items = [((-x, -y, z), g) for (x, y, z), g in items]
        return [] if bare and side == "right" else items

    for side, toward in (("left", 1.0), ("right", -1.0)):
        pad = hand["pads"][side]
        pt, pw, ph = pad["size"]
        dx, dy, dz = pad["offset"]
        box = f'<box size="{_f(pt, pw, ph)}"/>'
        if hand["kind"] == "revolute":
            kl, kr = hand["knuckle"][side], hand["knuckle"]["radius"]
            shape = hand["knuckle"]["shape"]
            knuckle = {
                "capsule": f'<capsule radius="{kr!r}" length="{kl - 2 * kr!r}"/>',
                "box": f'<box size="{_f(2 * kr, 2 * kr, kl)}"/>',
                "ball": f'<sphere radius="{kr!r}"/>',
            }[shape]
            parts.append(
                _link(f"{side}_knuckle", shapes(side, [((0, 0, kl / 2), knuckle)]))
            )
            if stacked:  # over the hinges' line: the pads one behind the other
                at = (0.0, 0.02 * toward, ph / 2)
            else:
                at = (toward * (pt / 2 + kr) + dx, dy, ph / 2 + dz)
            if shape == "ball":  # a fingertip ball where the pad's centre is
                box = f'<sphere radius="{pt / 2!r}"/>'
            parts.append(_link(f"{side}_pad", shapes(side, [(at, box)]), 0.03))
            if hand["bars"] is not None:
                bar = {
                    "capsule": '<capsule radius="0.004" length='
                    f'"{0.8 * kl - 0.008!r}"/>',
                    "box": f'<box size="{_f(0.008, 0.008, 0.8 * kl)}"/>',
                    "ball": '<sphere radius="0.004"/>',
                }[shape]
                y = pw / 2 + abs(dy) + 0.009
                geoms = [((0, y, 0.4 * kl), bar), ((0, -y, 0.4 * kl), bar)]
                if not hand["bars"]["solid"]:
                    geoms = []
                parts.append(_link(f"{side}_bar", shapes(side, geoms), 0.02))
        else:
            cx, cy, cz = hand["carriage"]
            carriage = f'<box size="{_f(cx, cy, cz)}"/>'
            parts.append(_link(f"{side}_carriage",
                               shapes(side, [((0, 0, cz / 2), carriage)])))  # fmt: skip
            at = (toward * (pt / 2 + cx / 2) + dx, dy, ph / 2 + dz)
            parts.append(_link(f"{side}_pad", shapes(side, [(at, box)]), 0.03))
    for name, j in hand["joints"].items():
        lo, hi = j["limits"]
        mimic = "".join(
            f'<mimic joint="{lead}" multiplier="{m!r}" offset="{o!r}"/>'
            for f, lead, m, o in hand["couplings"]
            if f == name
        )
        effort = 5.0 if j["kind"] == "revolute" else 20.0
        parts.append(
            f'<joint name="{name}" type="{j["kind"]}"><parent link="{j["parent"]}"/>'
            f'<child link="{j["child"]}"/><origin xyz="{_f(*j["xyz"])}" '
            f'rpy="{_f(*j["rpy"])}"/>'
            f'<axis xyz="{_f(*j["axis"])}"/><limit lower="{lo!r}" upper="{hi!r}" '
            f'effort="{effort!r}" velocity="2"/>{mimic}</joint>'
        )
    if hand["flip"] == "bracket":
        parts.append(
            '<link name="right_bracket"><inertial><mass value="0.01"/><inertia '
            'ixx="1e-6" iyy="1e-6" izz="1e-6" ixy="0" ixz="0" iyz="0"/></inertial>'
            '</link><joint name="right_mount" type="fixed"><parent link="palm"/>'
            f'<child link="right_bracket"/><origin xyz="{_f(*hand["bracket"])}" '
            f'rpy="0 0 {math.pi!r}"/></joint>'
        )
    lead = hand["leader"]
    parts.append(
        f'<transmission name="t"><type>transmission_interface/SimpleTransmission'
        f'</type><joint name="{lead}"/><actuator name="motor"><mechanicalReduction>'
        "1</mechanicalReduction></actuator></transmission>"
    )
    return (
        '<?xml version="1.0"?><robot name="fuzz_pinch2">' + "".join(parts) + "</robot>"
    )


def roots(hand: dict) -> list[str]:
    """The joints from the palm: each the root of a chain."""
    return [n for n, j in hand["joints"].items() if j["parent"] in PALM]


PALM = ("palm", "right_bracket")
"""The palm and what is welded to it."""


def motion(hand: dict, root: str) -> tuple:
    """``(kind, rate * axis)`` of a root joint, palm frame (from the description).

    Rounded to 12 digits: the half turn's sine leaves 1e-16 where 0 is meant.
    """
    j = hand["joints"][root]
    c, s = round(math.cos(j["yaw"])), round(math.sin(j["yaw"]))
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]], float)
    return j["kind"], tuple(np.round(j["rate"] * (R @ np.asarray(j["axis"], float)),
                                     12) + 0.0)  # fmt: skip


def origin(hand: dict, root: str) -> np.ndarray:
    """A root joint's origin in the palm frame (from the description)."""
    xyz = np.asarray(hand["joints"][root]["xyz"], float)
    if hand["joints"][root]["parent"] == "right_bracket":  # turned half a turn
        return np.asarray(hand["bracket"], float) + xyz * [-1.0, -1.0, 1.0]
    return xyz


def beside(hand: dict, a: str, b: str) -> bool:
    """Whether two root joints share a side: revolute, turning alike, in one
    plane of motion (along the axis at most a tenth of their distance across
    it: a bar beside its pad)."""
    (kind_a, w_a), (kind_b, w_b) = motion(hand, a), motion(hand, b)
    if kind_a != "revolute" or kind_b != "revolute" or w_a != w_b:
        return False
    axis = np.asarray(w_a) / np.linalg.norm(w_a)
    v = origin(hand, b) - origin(hand, a)
    return abs(float(v @ axis)) <= 0.1 * float(np.linalg.norm(v - (v @ axis) * axis))


def expected_partition(hand: dict, chain_roots: list[str]) -> list[int]:
    """Sides of the chains (by root joint), numbered from 0 in their order.

    Chains joined through chains each :func:`beside` the next share a side
    (found here by growing each side from its first chain).
    """
    out: list[int | None] = [None] * len(chain_roots)
    label = 0
    for c in range(len(chain_roots)):
        if out[c] is not None:
            continue
        out[c], todo = label, [c]
        while todo:
            a = todo.pop()
            for b in range(len(chain_roots)):
                if out[b] is None and beside(hand, chain_roots[a], chain_roots[b]):
                    out[b] = label
                    todo.append(b)
        label += 1
    return out


def _shaped(hand: dict, root: str) -> bool:
    """Whether the chain rooted at ``root`` has collision geometry."""
    if hand["layout"] == "bare" and root.startswith("right"):
        return False
    return not (root.endswith("bar_joint") and not hand["bars"]["solid"])


def expects_pinch(hand: dict) -> tuple[bool | None, bool]:
    """Whether the planner should find a pinch (None: either may be right).

    A pinch: the chains move on exactly two sides, each with a chain that
    has geometry, whose tips are not one behind the other.  Second: whether
    the two sides are the left and the right fingers (the pads' centres then
    give the closing axis).
    """
    names = roots(hand)
    sides = dict(zip(names, expected_partition(hand, names), strict=True))
    if len(set(sides.values())) != 2:
        return False, False
    if len({m for r, m in sides.items() if _shaped(hand, r)}) != 2:
        return False, False  # a side with no geometry: no tip
    standard = len({m for r, m in sides.items() if r.startswith("left")}) == 1
    standard &= len({m for r, m in sides.items() if r.startswith("right")}) == 1
    if hand["layout"] == "stacked":
        return None, standard  # one behind the other: c within 1 mm, or past it
    return True, standard


def pad_centres(hand: dict) -> dict[str, np.ndarray]:
    """Each pad's geometry centre in the palm frame at the joints' zero."""
    out = {}
    z0 = hand["palm"][2] + 0.01
    s = hand["spacing"]
    for side, toward in (("left", 1.0), ("right", -1.0)):
        pt, _, ph = hand["pads"][side]["size"]
        dx, dy, dz = hand["pads"][side]["offset"]
        base = hand["joints"][f"{side}_pad_joint"]["xyz"]
        x0 = -toward * s / 2
        if hand["kind"] == "revolute":
            if hand["layout"] == "stacked":
                at = np.array([0.0, 0.02 * toward, ph / 2])
                x0 = 0.0
                y0 = -0.02 * toward
            else:
                kr = hand["knuckle"]["radius"]
                at = np.array([toward * (pt / 2 + kr) + dx, dy, ph / 2 + dz])
                y0 = 0.0
        else:
            cx = hand["carriage"][0]
            at = np.array([toward * (pt / 2 + cx / 2) + dx, dy, ph / 2 + dz])
            y0 = 0.0
        out[side] = np.array([x0, y0, z0]) + np.asarray(base) + at
    return out


def pad_support(hand: dict, side: str, c: np.ndarray) -> float:
    """How far a pad's geometry reaches from its centre along unit ``c`` (m).

    Upright at the joints' zero (a half turn about z changes no extent): a
    box's half extents along ``c``, a fingertip ball's radius.
    """
    pt, pw, ph = hand["pads"][side]["size"]
    if hand["kind"] == "revolute" and hand["knuckle"]["shape"] == "ball":
        return pt / 2
    return 0.5 * (pt * abs(c[0]) + pw * abs(c[1]) + ph * abs(c[2]))


# ============================================================ worker side

_CACHE: dict = {}


def _add_models(hand_text: str, object_text: str | None, object_kind: str | None,
                object_url: str | None):  # fmt: skip
    """``add_models(plant, parser)`` of the hand (text) and the object."""
    from drakegrasp.plant.couplings import add_models as add_coupled
    from drakegrasp.plant.models import register_models, use_local_drake_models

    def add_models(plant, parser):
        use_local_drake_models(parser, None)
        register_models(parser)
        hand = add_coupled(parser, text=hand_text, kind="urdf")[0]
        if object_url is not None:
            obj = add_coupled(parser, url=object_url)[0]
        elif object_text is not None:
            obj = add_coupled(parser, text=object_text, kind=object_kind)[0]
        else:
            return hand, None
        body = plant.get_body(plant.GetBodyIndices(obj)[0])
        return hand, f"{plant.GetModelInstanceName(obj)}::{body.name()}"

    return add_models


def _scene(hand: dict, obj: str | None):
    """The hand and object (a key of :data:`OBJECT_MODELS` or None), cached."""
    from drakegrasp.planning.scenes import scene_from_models

    text = urdf(hand)
    key = (text, obj)
    if key not in _CACHE:
        if len(_CACHE) > 8:
            _CACHE.clear()
        url, otext, okind = OBJECT_MODELS.get(obj, (None, None, None))
        scene = scene_from_models(_add_models(text, otext, okind, url))
        _CACHE[key] = (scene, scene.context.Clone())
    scene, root0 = _CACHE[key]
    scene.context.SetTimeStateAndParametersFrom(root0)
    return scene


def _massless_sdf(inertial: bool = True) -> str:
    mass = (
        "<inertial><mass>0</mass><inertia><ixx>0</ixx><iyy>0</iyy><izz>0</izz>"
        "<ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>"
    )
    return (
        '<?xml version="1.0"?><sdf version="1.9"><model name="light_box">'
        f"<link name='body'>{mass if inertial else ''}<collision name='c'>"
        "<geometry><box><size>0.05 0.05 0.1</size></box></geometry>"
        "</collision></link></model></sdf>"
    )


_URDF_BOX = (
    '<?xml version="1.0"?><robot name="urdf_box"><link name="body"><collision>'
    '<geometry><box size="0.05 0.05 0.1"/></geometry></collision></link></robot>'
)

OBJECT_MODELS = {
    "box": (BOX, None, None),
    "cylinder": (CYLINDER, None, None),
    "sphere": ("package://drakegrasp/objects/sphere.sdf", None, None),
    "hex_prism": ("package://drakegrasp/objects/hex_prism.sdf", None, None),
    "massless box": (None, _massless_sdf(), "sdf"),
    "urdf box": (None, _URDF_BOX, "urdf"),  # a link without <inertial>
}


def _place(scene, object_pose: dict, hand_pose: dict, q: dict | None = None):
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    if scene.object_body is not None:
        plant.SetFreeBodyPose(ctx, scene.object_body, _transform(object_pose))
    palm = plant.GetBodyByName("palm", scene.hand)
    plant.SetFreeBodyPose(ctx, palm, _transform(hand_pose))
    if q:
        positions = plant.GetPositions(ctx)
        for name, value in q.items():
            j = plant.GetJointByName(name, scene.hand)
            positions[j.position_start()] = value
        plant.SetPositions(ctx, positions)
    return plant, ctx


def sides_case(spec: dict) -> dict:
    """Worker side: ``chain_sides`` in several poses and orders; the pinch."""
    from drakegrasp.planning.approach import multi_finger_hand
    from drakegrasp.planning.centring import chain_sides

    hand = spec["hand"]
    scene = _scene(hand, spec["object"])
    plant, ctx = _place(scene, spec["object_pose"], spec["pose"])
    model = multi_finger_hand(plant, ctx, scene.object_body, scene.hand)
    chains = list(model.chains)
    structure = model.structure

    def root_of(chain) -> str:
        bodies = {int(b.index()) for b in chain.bodies}
        for k in chain.joints:
            j = structure.joints[k]
            if int(j.parent_body().index()) not in bodies:
                return j.name()
        return structure.joints[chain.joints[0]].name()

    names = [root_of(c) for c in chains]
    out = {"roots": names, "sides": {}}
    out["sides"]["built"] = chain_sides(ctx, structure, chains)
    moved = plant.CreateDefaultContext()
    moved.SetTimeStateAndParametersFrom(ctx)
    _place_ctx(plant, moved, scene, spec["pose2"], spec["q2"])
    out["sides"]["moved"] = chain_sides(moved, structure, chains)
    order = spec["order"]
    shuffled = chain_sides(ctx, structure, [chains[k] for k in order])
    out["sides"]["shuffled"] = shuffled
    out["order"] = order
    out["pinch"] = None
    if model.closing_axis is not None:
        R_HK = model.X_HK.rotation().matrix()
        out["pinch"] = {
            "axis_H": (R_HK @ model.closing_axis).tolist(),
            "axis_K": model.closing_axis.tolist(),
            "u_H": R_HK[:, 0].tolist(),
            "origin_H": model.X_HK.translation().tolist(),
            "reach": model.pinch_reach,
            "width": model.pinch_width,
        }
    else:
        out["nan"] = [model.pinch_reach, model.pinch_width]
    return out


def _place_ctx(plant, ctx, scene, pose: dict, q: dict) -> None:
    palm = plant.GetBodyByName("palm", scene.hand)
    plant.SetFreeBodyPose(ctx, palm, _transform(pose))
    positions = plant.GetPositions(ctx)
    for name, value in q.items():
        positions[plant.GetJointByName(name, scene.hand).position_start()] = value
    plant.SetPositions(ctx, positions)


def _candidate_data(c, plant, scene, obj_scene=None) -> dict:
    X_WH = c.X_WH
    X_WO = c.X_WO
    X_OH = X_WO.inverse() @ X_WH
    out = {
        "X_WH": X_WH.GetAsMatrix4().tolist(),
        "X_OH": X_OH.GetAsMatrix4().tolist(),
        "contacts": [x.finger_body.split("::")[-1] for x in c.contacts],
        "contacts_O": [[*np.asarray(x.p_OC).tolist(), *np.asarray(x.nhat_O).tolist()]
                       for x in c.contacts],
        "q_hand": dict(
            zip((n.split("::")[-1] for n in c.joint_names), c.q_hand.tolist(),
                strict=True)
        ),
        "closure": bool(c.is_closure),
        "score": float(c.score),
    }  # fmt: skip
    try:
        c.apply(plant, scene.context)
    except dg.GraspError as e:
        out["apply"] = f"{type(e).__name__}: {e}"
        return out
    out["q"] = _joint_values(plant, plant.GetMyContextFromRoot(scene.context),
                             scene.hand)  # fmt: skip
    if obj_scene is not None:
        c.apply(obj_scene.plant, obj_scene.context)
        out["min_distance"] = _min_distance(obj_scene)
    elif scene.object_body is not None:
        out["min_distance"] = _min_distance(scene)
    return out


def _plan(scene, spec: dict, object_pose: dict, hand_pose: dict) -> dict:
    plant, _ = _place(scene, object_pose, hand_pose, spec.get("q"))
    result = dg.plan_grasps(
        plant, scene.context, scene.object_body, hand=scene.hand, **spec["kwargs"]
    )
    return {
        "candidates": [_candidate_data(c, plant, scene) for c in result],
        "rejections": dict(result.rejections),
        "pinch": "closing_axis_K" in result.settings.get("hand", {}),
    }


def _moved(X: dict, pose: dict) -> dict:
    from pydrake.math import RollPitchYaw

    T = _transform(X) @ _transform(pose)
    return {"p": T.translation().tolist(),
            "rpy": RollPitchYaw(T.rotation()).vector().tolist()}  # fmt: skip


def _sampled(spec: dict, object_pose: dict, hand_pose: dict) -> np.ndarray:
    """The planner's sampled poses and pre-shapes, object frame, one row each."""
    from drakegrasp.planning import object_surface
    from drakegrasp.planning.approach import multi_finger_hand, sample_approaches
    from drakegrasp.planning.multifinger import DEFAULT_TILT

    scene = _scene(spec["hand"], spec["object"])
    plant, ctx = _place(scene, object_pose, hand_pose, spec.get("q"))
    kwargs = spec["kwargs"]
    model = multi_finger_hand(
        plant, ctx, scene.object_body, scene.hand, approach=kwargs.get("approach"),
        standoff=kwargs.get("standoff"),
    )  # fmt: skip
    surface = object_surface(plant, scene.context, scene.object_body)
    X_WO = plant.EvalBodyPoseInWorld(ctx, scene.object_body)
    rng = np.random.default_rng(spec["kwargs"]["seed"])
    n = spec["kwargs"]["num_candidates"]
    poses = sample_approaches(surface, model, X_WO, n, rng,
                              kwargs.get("tilt", DEFAULT_TILT))  # fmt: skip
    R_OW = X_WO.rotation().inverse().matrix()
    R_OH = np.einsum("ij,njk->nik", R_OW, poses["R_WH"]).reshape(n, 9)
    p_OH = (poses["p_WH"] - X_WO.translation()) @ R_OW.T
    return np.hstack([R_OH, p_OH, poses["q"]])


def plan_case(spec: dict) -> dict:
    """Worker side: ``plan_grasps`` on the body, as drawn and rigidly moved.

    Moved, also the sampled poses of both scenes, object frame: the
    sampler's own invariance, apart from Drake's distances.
    """
    scene = _scene(spec["hand"], spec["object"])
    first = _plan(scene, spec, spec["object_pose"], spec["pose"])
    out = {"tol": spec["kwargs"].get("distance_tolerance", 1e-4), "first": first}
    if "motion" in spec:
        X = spec["motion"]
        moved = _moved(X, spec["object_pose"]), _moved(X, spec["pose"])
        scene = _scene(spec["hand"], spec["object"])  # the open hand again
        out["moved"] = _plan(scene, spec, *moved)
        a = _sampled(spec, spec["object_pose"], spec["pose"])
        b = _sampled(spec, *moved)
        out["sampled_diff"] = float(np.max(np.abs(a - b), initial=0.0))
    return out


def cloud_case(spec: dict) -> dict:
    """Worker side: ``plan_grasps`` on a cloud of the object's surface."""
    from scipy.spatial import cKDTree

    from drakegrasp.planning import object_surface

    obj_scene = _scene(spec["hand"], spec["object"])
    plant, _ = _place(obj_scene, spec["object_pose"], spec["pose"])
    surface = object_surface(plant, obj_scene.context, obj_scene.object_body)
    rng = np.random.default_rng(spec["cloud_seed"])
    p_OS, n_O, _ = surface.sample(spec["cloud_points"], rng)
    X_WO = _transform(spec["object_pose"])
    points = (X_WO.rotation().matrix() @ p_OS.T).T + X_WO.translation()
    normals = (X_WO.rotation().matrix() @ n_O.T).T
    scene = _scene(spec["hand"], None)
    hand_plant, _ = _place(scene, spec["object_pose"], spec["pose"])
    result = dg.plan_grasps(
        hand_plant, scene.context, None, hand=scene.hand, point_cloud=points,
        cloud_normals=normals, **spec["kwargs"],
    )  # fmt: skip
    out = [_candidate_data(c, hand_plant, scene, obj_scene) for c in result]
    nearest, _ = cKDTree(points).query(points, k=2)
    return {
        "tol": spec["kwargs"].get("distance_tolerance", 1e-4),
        "spacing": float(np.median(nearest[:, 1])),
        "first": {"candidates": out, "rejections": dict(result.rejections)},
    }


def _planned(spec: dict):
    """The shake's plan (cached per hand, object and planned mass)."""
    scene = _scene(spec["hand"], spec["object"])
    key = ("plan", urdf(spec["hand"]), spec["object"], repr(spec["plan_mass"]))
    if key not in _CACHE:
        plant, _ = _place(scene, spec["object_pose"], spec["pose"])
        kwargs = dict(num_candidates=24, mu=0.8, seed=spec["seed"],
                      robustness_samples=2, certify=0)  # fmt: skip
        if spec["plan_mass"] is not None:
            kwargs["object_mass"] = spec["plan_mass"]
        _CACHE[key] = dg.plan_grasps(
            plant, scene.context, scene.object_body, hand=scene.hand, **kwargs
        )
    return scene, _CACHE[key]


def _result_data(r) -> dict:
    numbers = {
        "max_displacement": r.max_displacement,
        "max_rotation": r.max_rotation,
        "seat_displacement": r.seat_displacement,
        "seat_rotation": r.seat_rotation,
        "seat_speed": r.seat_speed,
        "max_displacement_from_seat": r.max_displacement_from_seat,
        "max_rotation_from_seat": r.max_rotation_from_seat,
        "object_mass": r.object_mass,
    }
    return {
        "held": bool(r.held),
        "held_from_seat": bool(r.held_from_seat),
        "numbers": {k: float(v) for k, v in numbers.items()},
        "efforts": [float(e) for e in r.efforts],
    }


SHAKE = {"squeeze": 5.0, "directions": [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
         "settle": 0.1, "phase": 0.2, "seat": 0.1, "blend": 0.05}  # fmt: skip
"""Short shakes (0.6 s simulated): what is judged is the mass, not the hold."""


def shake_case(spec: dict) -> dict:
    """Worker side: ``shake_test`` or ``shake_candidates`` on the plan's first."""
    from drakegrasp.planning import shake_candidates, shake_test

    scene, result = _planned(spec)
    if not len(result):
        return {"planned": 0}
    body = scene.object_body
    out = {"planned": len(result), "model_mass": float(body.default_mass())}
    options = dict(SHAKE)
    if "object_mass" in spec:
        options["object_mass"] = spec["object_mass"]
    if spec["call"] == "test":
        candidate = result[0]
        if "candidate" in spec:  # a field the massless shake reads, hostile
            candidate = dataclasses.replace(candidate, **{
                k: np.asarray(v, float) if k == "reference_point" else v
                for k, v in spec["candidate"].items()
            })  # fmt: skip
        r = shake_test(scene.add_models, candidate, X_WO=_transform(
            spec["object_pose"]), **options)  # fmt: skip
        out["results"] = [_result_data(r)]
        return out
    given = {"plan": result, "slice": result[:2], "list": list(result)[:2]}
    shaken = shake_candidates(
        scene.add_models, given[spec["call"]], top=1,
        X_WO=_transform(spec["object_pose"]), **options,
    )  # fmt: skip
    out["results"] = [_result_data(s.result) for s in shaken if s.result is not None]
    out["errors"] = [s.error for s in shaken if s.result is None]
    out["summary"] = str(shaken).splitlines()[0]
    return out


# ============================================================ the oracles

CHECKED: collections.Counter = collections.Counter()
"""What the oracles judged (the test reads it: they saw enough to mean something)."""


def sides_right(hand: dict):
    """The judge of a ``sides_case`` answer."""

    def check(out: dict) -> bool:
        CHECKED["sides"] += 1
        faults = []
        names = out["roots"]
        if sorted(set(names)) != sorted(roots(hand)):
            faults.append(f"chains rooted at {names}, not {roots(hand)}")
        else:
            want = expected_partition(hand, names)
            for what, got in out["sides"].items():
                if what == "shuffled":
                    order = out["order"]
                    want_here = expected_partition(hand, [names[k] for k in order])
                else:
                    want_here = want
                if list(got) != want_here:
                    faults.append(f"sides {what} {got}, want {want_here}")
        expect, standard = expects_pinch(hand)
        pinch = out["pinch"]
        if expect is not None and (pinch is not None) != expect:
            faults.append(f"pinch found: {pinch is not None}, expected {expect}")
        if pinch is None:
            if not all(math.isnan(x) for x in out.get("nan", [])):
                faults.append(f"not a pinch, but reach/width {out['nan']}")
        else:
            CHECKED["pinches"] += 1
            a, u = np.asarray(pinch["axis_H"]), np.asarray(pinch["u_H"])
            if abs(np.linalg.norm(a) - 1) > 1e-9 or abs(a @ u) > 1e-9:
                faults.append(f"closing axis {a.tolist()} not unit across {u}")
            if abs(pinch["axis_K"][0]) > 1e-9:
                faults.append(f"closing axis in K {pinch['axis_K']} along x")
            if not (math.isfinite(pinch["width"]) and pinch["width"] >= 1e-3):
                faults.append(f"pinch_width {pinch['width']!r}")
            if not math.isfinite(pinch["reach"]):
                faults.append(f"pinch_reach {pinch['reach']!r}")
            if expect and standard:
                c = pad_centres(hand)
                d = c["right"] - c["left"]
                d = d - (d @ u) * u
                # the gap between the pads' faces along the axis
                width = float(np.linalg.norm(d)) - sum(
                    pad_support(hand, side, d / np.linalg.norm(d))
                    for side in ("left", "right")
                )
                if abs(width - pinch["width"]) > 1e-9:
                    faults.append(f"pinch_width {pinch['width']!r}, pads {width!r}")
                if abs(abs(a @ d) / np.linalg.norm(d) - 1) > 1e-9:
                    faults.append(f"closing axis {a.tolist()}, pads along {d}")
                mid = (c["right"] + c["left"]) / 2
                reach = float((mid - np.asarray(pinch["origin_H"])) @ u)
                if abs(reach - pinch["reach"]) > 1e-9:
                    faults.append(f"pinch_reach {pinch['reach']!r}, pads {reach!r}")
        if faults:
            raise AssertionError("; ".join(faults))
        return True

    return check


def chain_bodies(hand: dict) -> set[str]:
    return {j["child"] for j in hand["joints"].values()}


def candidate_faults(hand: dict, tol: float, data: dict, spacing: float = 0.0):
    faults = placed_faults(hand, tol, data, spacing)
    if "apply" in data:
        return faults
    strays = sorted(set(data["contacts"]) - chain_bodies(hand) - set(PALM))
    if strays:
        faults.append(f"contacts on {strays}, neither a chain's body nor the palm")
    if hand["layout"] == "bare":
        on_bare = sorted(b for b in data["contacts"] if b.startswith("right_"))
        if on_bare:
            faults.append(f"contacts on {on_bare}, which have no geometry")
    CHECKED["contacts"] += len(data["contacts"])
    return faults


def _close(a, b, tol=INVARIANCE_TOL) -> bool:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a.shape == b.shape and bool(np.all(np.abs(a - b) <= tol))


def invariance_faults(first: dict, moved: dict) -> list[str]:
    """The two plans differ in the object frame (count, rejections, poses...)."""
    faults = []
    a, b = first["candidates"], moved["candidates"]
    if len(a) != len(b) or first["rejections"] != moved["rejections"]:
        return [
            f"moved scene: {len(b)} candidates {moved['rejections']}, against "
            f"{len(a)} {first['rejections']}"
        ]
    for k, (x, y) in enumerate(zip(a, b, strict=True)):
        if not _close(x["X_OH"], y["X_OH"]):
            err = np.max(np.abs(np.subtract(x["X_OH"], y["X_OH"])))
            faults.append(f"#{k}: X_OH differs by {err:.3g}")
        qa, qb = x["q_hand"], y["q_hand"]
        if set(qa) != set(qb) or not _close([qa[n] for n in qa], [qb[n] for n in qa]):
            faults.append(f"#{k}: q_hand differs")
        if x["contacts"] != y["contacts"] or not _close(
            x["contacts_O"], y["contacts_O"]
        ):
            faults.append(f"#{k}: contacts differ in O")
    return faults


def exact_distances(hand: dict, obj: str) -> bool:
    """Whether Drake measures every finger/object pair in closed form.

    Drake's signed distance of a sphere to a box or a cylinder is exact;
    those of a box, capsule or cylinder to a box or a cylinder come from an
    iterative solver (FCL's GJK) whose answer moves by 1e-7 to 3e-5 m when
    the scene is rigidly moved (one box pad 10.7 mm from the box: 7.1e-6 m
    apart).  The closing search steps and accepts by them, so a plan is the
    same to 1e-9 in the object frame only for fingers of balls; for the
    others the sampled poses are (the sampler works in the object frame).
    """
    if obj not in ("box", "cylinder", "sphere"):  # the prism is a mesh
        return False
    return hand["kind"] == "revolute" and hand["knuckle"]["shape"] == "ball"


def planned_right(hand: dict, obj: str = "box"):
    """The judge of a ``plan_case`` or ``cloud_case`` answer."""

    def check(out: dict) -> bool:
        faults = []
        for which in ("first", "moved"):
            if which not in out:
                continue
            cands = out[which]["candidates"]
            CHECKED["cloud candidates" if "spacing" in out else "candidates"] += len(
                cands
            )
            for k, data in enumerate(cands):
                found = candidate_faults(hand, out["tol"], data, out.get("spacing", 0))
                faults += [f"{which} #{k}: {f}" for f in found]
        if "moved" in out:
            CHECKED["moved samplers"] += 1
            if not out["sampled_diff"] <= INVARIANCE_TOL:
                faults.append(f"sampled poses differ by {out['sampled_diff']:.3g} "
                              "in the object frame")  # fmt: skip
            if exact_distances(hand, obj):
                CHECKED["moved plans"] += 1
                CHECKED["moved candidates"] += len(out["first"]["candidates"])
                faults += invariance_faults(out["first"], out["moved"])
        if faults:
            raise AssertionError("; ".join(faults[:6]))
        return True

    return check


def _mass_value(x) -> float | None:
    try:
        return float(x)
    except (TypeError, ValueError):
        return None


def shaken_right(spec: dict):
    """The judge of a ``shake_case`` answer: the mass shaken, finite figures."""

    def check(out: dict) -> bool:
        if out["planned"] == 0:
            return True
        CHECKED["shakes"] += 1
        if "object_mass" in spec and spec["object_mass"] is not None:
            want = _mass_value(spec["object_mass"])
        elif spec["plan_mass"] is not None:
            want = float(spec["plan_mass"])  # the mass the candidates were planned for
        else:
            want = out["model_mass"]
        faults = [f"not simulated: {e}" for e in out.get("errors", [])]
        for r in out["results"]:
            got = r["numbers"]["object_mass"]
            if got != want:
                faults.append(f"shook {got!r} kg, not {want!r} kg")
            bad = {k: v for k, v in r["numbers"].items() if not math.isfinite(v)}
            if bad:
                faults.append(f"not finite: {bad}")
            if not all(math.isfinite(e) for e in r["efforts"]):
                faults.append(f"efforts {r['efforts']}")
            if got >= HEAVY and (r["held"] or r["held_from_seat"]):
                faults.append(f"held {got:g} kg (weight {got * 9.81:.3g} N)")
        if faults:
            raise AssertionError("; ".join(faults))
        return True

    return check


# ============================================================ the cases


def _pose(rng, scale: float = 0.02) -> dict:
    return {
        "p": [_u(rng, -scale, scale) for _ in range(3)],
        "rpy": [_u(rng, -3.1, 3.1), _u(rng, -1.4, 1.4), _u(rng, -3.1, 3.1)],
    }


def _far_pose(rng) -> dict:
    """A hand pose away from the object (the planner places it itself)."""
    pose = _pose(rng)
    pose["p"][2] += 0.5
    return pose


def _q(rng, hand: dict, most: float = 1.0) -> dict:
    """Joint values within the limits and couplings: the leader's first ``most``."""
    lo, hi = hand["lead"]
    x = _u(rng, lo, lo + most * (hi - lo))
    q = {hand["leader"]: x}
    for f, _, m, o in hand["couplings"]:
        q[f] = m * x + o
    return q


MASSES = {  # shake_test's object_mass: what a right outcome is
    "refuse": (0.0, -1.0, math.nan, math.inf, -math.inf, 1e308, True, False, "0.3",
               [0.3], 1j, np.float64(-2.0), 1e-12, 1e-300,  # below a milligram
               1e-6),  # a milligram: its contacts ask for a step under 10 µs
    "answer": (0.2, 3.0, 1e-3, 1e300, HEAVY, 1e6, 2,
               np.float32(0.5), np.int64(3), np.float64(0.7)),
}  # fmt: skip


def hand_cases(sandbox: Sandbox, seed: int, count: int) -> Iterator[Case]:
    """``count`` hands: their sides, a plan on a body (and moved), one on a cloud."""
    rng = np.random.default_rng(seed)
    for i in range(count):
        hand = pinch_hand(rng)
        label = f"{hand['kind']}#{i}"
        if hand["hostile"]:
            label += " [" + ", ".join(hand["hostile"]) + "]"
        n = len(roots(hand))
        spec = {
            "hand": hand, "object": "box", "object_pose": _pose(rng),
            "pose": _far_pose(rng), "pose2": _pose(rng, 1.0), "q2": _q(rng, hand),
            "order": [int(k) for k in rng.permutation(n)],
        }  # fmt: skip
        yield _sandboxed(sandbox, "pinch sides", f"{label} sides", "sides_case",
                         spec, sides_right(hand))  # fmt: skip
        obj = pick(rng, ("box", "box", "box", "cylinder", "cylinder", "sphere",
                         "hex_prism"))  # fmt: skip
        spec = {
            "hand": hand, "object": obj, "object_pose": _pose(rng),
            "pose": _far_pose(rng),
            "kwargs": {
                "num_candidates": int(pick(rng, (8, 10, 12))),
                "mu": pick(rng, (0.5, 0.8)), "seed": int(rng.integers(1000)),
                "robustness_samples": 2, "certify": 0,
                "distance_tolerance": pick(rng, (1e-4, 1e-4, 1e-3)),
            },
        }  # fmt: skip
        r = rng.random()
        if r < 0.15:
            spec["kwargs"]["tilt"] = pick(rng, (0.0, math.pi / 2))
        elif r < 0.25:
            spec["kwargs"]["standoff"] = pick(
                rng, ((0.0, 0.0), (0.0, 0.2), (0.05, 0.05))
            )
        elif r < 0.32:  # sideways, along the closing line, or leaning
            spec["kwargs"]["approach"] = pick(rng, ((1.0, 0.0, 0.0), (0.0, 0.4, 1.0)))
        if rng.random() < 0.3:  # the open hand of the context: partly closed
            spec["q"] = _q(rng, hand, 0.5)
        moved = i % 2 == 0
        if moved:
            spec["motion"] = {
                "p": [_u(rng, -1.0, 1.0) for _ in range(3)],
                "rpy": [_u(rng, -3.1, 3.1), _u(rng, -1.4, 1.4), _u(rng, -3.1, 3.1)],
            }
        yield _sandboxed(
            sandbox, "pinch plan", f"{label} plan {obj}" + (" moved" if moved else ""),
            "plan_case", spec, planned_right(hand, obj),
        )  # fmt: skip
        if i % 3 == 0:
            spec = {
                "hand": hand, "object": "box", "object_pose": _pose(rng),
                "pose": _far_pose(rng), "cloud_seed": int(rng.integers(1000)),
                "cloud_points": int(pick(rng, (800, 1200))),
                "kwargs": {
                    "num_candidates": 10, "mu": 0.8,
                    "seed": int(rng.integers(1000)), "robustness_samples": 2,
                    "certify": 0, "distance_tolerance": 1e-3, "object_mass": 0.2,
                },
            }  # fmt: skip
            yield _sandboxed(sandbox, "pinch cloud", f"{label} cloud box",
                             "cloud_case", spec, planned_right(hand))  # fmt: skip


def _sandboxed(sandbox, family, name, fn, spec, check, expect="either") -> Case:
    def call(fn=fn, spec=spec):
        return sandbox.call(f"fuzz_pinch:{fn}", spec)

    return Case(family, name, call, expect, check)


SHAKE_OBJECTS = ("box", "box", "massless box", "urdf box")
SHAKE_CALLS = ("test", "plan", "slice", "list")
MASS_MODES = ("refuse", "answer", "absent")
BALL_FIELDS = (("torque_scale", 1e200), ("reference_point", 1e200),
               ("torque_scale", None), ("reference_point", None))  # fmt: skip
"""The massless shake's ball: a candidate's scale or centre (None: drawn)."""


def shake_cases(sandbox: Sandbox, seed: int, count: int) -> Iterator[Case]:
    """``count`` shakes: hostile masses, massless models, the plan's mass.

    The kinds are crossed (the mass given, hostile or valid, or not; the
    object; ``shake_test`` or ``shake_candidates`` on the plan, a slice or a
    list: 48 cases cover them all), the values drawn.
    """
    rng = np.random.default_rng(seed)
    hands = []
    while len(hands) < 3:  # plain pinches that plan: the shake is under test
        hand = pinch_hand(rng)
        if hand["layout"] == "plain" and hand["kind"] == "revolute":
            hands.append(hand)
    balls = 0
    for i in range(count):
        hand = hands[i % len(hands)]
        mode = MASS_MODES[i % 3]
        obj = SHAKE_OBJECTS[(i // 3) % 4]
        call = SHAKE_CALLS[(i // 12) % 4]
        plan_mass = pick(rng, (None, 0.3, 20.0)) if obj == "box" else 0.3
        if mode == "absent" and obj == "box" and call in ("slice", "list"):
            plan_mass = pick(rng, (0.3, 20.0))  # a plan for a mass to lose
        if obj != "box" and rng.random() < 0.15:
            plan_mass = None  # planned at the model's no weight
        spec = {
            "hand": hand, "object": obj, "object_pose": _pose(rng, 0.0),
            "pose": _far_pose(rng), "seed": i % len(hands), "plan_mass": plan_mass,
            "call": call,
        }  # fmt: skip
        spec["object_pose"]["rpy"] = [0.0, 0.0, 0.0]  # the plans are cached by hand
        name = f"#{i} {obj} planned {plan_mass} {call}"
        if mode == "refuse":
            mass = pick(rng, MASSES["refuse"])
            spec["object_mass"] = mass
            expect = "refuse"
            name += f" object_mass={mass!r}"
        elif mode == "answer":
            mass = pick(rng, MASSES["answer"])
            spec["object_mass"] = mass
            expect = "answer"
            name += f" object_mass={mass!r}"
        else:  # none given: the plan's, else the model's (a massless one: refused)
            massless = obj != "box"
            expect = "either" if massless else "answer"
            name += " object_mass absent"
        if obj != "box" and call == "test" and mode != "refuse":
            # the massless shake's ball: a candidate's scale or centre, hostile
            field, value = BALL_FIELDS[balls % len(BALL_FIELDS)]
            balls += 1
            if value is None:
                value = pick(rng, (math.nan, 0.0, -1.0, math.inf, 1e-300, 2.0))
            spec["candidate"] = {
                field: value if field == "torque_scale" else [value, 0.0, 0.0]
            }
            spec["object_mass"] = 0.3
            expect = "either"
            name = f"#{i} {obj} planned {plan_mass} {call} object_mass=0.3"
            name += f" candidate {field}={value!r}"
        if obj != "box" and plan_mass is None:
            expect = "either"  # the plan itself may refuse a weightless object
        yield _sandboxed(sandbox, "pinch shake", name, "shake_case", spec,
                         shaken_right(spec), expect)  # fmt: skip


# ----------------------------------------------------------- facing_chains


def facing_cases(seed: int = 2903, count: int = 300) -> Iterator[Case]:
    """Random and hostile gaps and sides of ``facing_chains`` (this process)."""
    from drakegrasp.planning.centring import facing_chains

    rng = np.random.default_rng(seed)
    for i in range(count):
        k = int(rng.integers(1, 7))
        psi = rng.uniform(-0.01, 0.03, size=k)
        sides = rng.integers(0, 3, size=k)
        r = rng.random()
        what = "valid"
        if r < 0.3:
            psi[int(rng.integers(k))] = pick(rng, (math.nan, math.inf, -math.inf))
            what = "gap not finite"
        elif r < 0.4:
            psi[:] = psi[0]
            what = "equal gaps"
        if r >= 0.7:
            bad = pick(rng, ("psi 2-d", "sides float", "sides bool", "sides short",
                             "psi str", "psi None", "sides None", "psi complex",
                             "sides huge", "psi lists", "sides object"))  # fmt: skip
            args = {
                "psi 2-d": (psi[:, None], sides),
                "sides float": (psi, sides.astype(float)),
                "sides bool": (psi, sides.astype(bool)),
                "sides short": (psi, sides[:-1]),
                "psi str": (psi.astype(str), sides),
                "psi None": (None, sides),
                "sides None": (psi, None),
                "psi complex": (psi.astype(complex), sides),
                "sides huge": (psi, [2**70] * k),
                "psi lists": (psi.tolist(), sides.tolist()),
                "sides object": (psi, np.array([object()] * k)),
            }[bad]
            valid = bad == "psi lists"
            yield Case(
                "facing_chains", f"{bad}#{i}", lambda a=args: facing_chains(*a),
                "answer" if valid else "either",
                _facing_right(psi, sides) if valid else _facing_shape(k),
            )  # fmt: skip
            continue
        yield Case(
            "facing_chains", f"{what}#{i}",
            lambda a=(psi, sides): facing_chains(*a), "answer",
            _facing_right(psi, sides),
        )  # fmt: skip


def _facing_right(psi, sides):
    """The nearest finite gap per side, the first of equal ones, ascending."""
    want = []
    for s in sorted(set(np.asarray(sides).tolist())):
        mine = [c for c in range(len(psi)) if sides[c] == s and math.isfinite(psi[c])]
        if mine:
            want.append(min(mine, key=lambda c: (psi[c], c)))

    def check(got) -> bool:
        if list(got) != sorted(want):
            raise AssertionError(f"facing {got}, want {sorted(want)}")
        return True

    return check


def _facing_shape(k: int):
    def check(got) -> bool:
        if not (isinstance(got, list) and all(isinstance(c, int) and 0 <= c < k
                                              for c in got)):  # fmt: skip
            raise AssertionError(f"facing {got!r}")
        return True

    return check


# ================================================================ findings

FINDINGS = {
    "P1": "facing_chains refuses sides that are not one integer per gap, and "
    "equalising_move groups that are not (the _integers check both share), with "
    "a GraspError that embeds numpy's repr of the array: over one line for an "
    "object array or more than about a dozen values (the suite's rule: a "
    "refusal is one line; real_array's refusal of psi is)",
    "P2": "shake_candidates on a slice or a list of a plan's candidates "
    "(result[:k], [c for c in result if ...]) shakes the model's mass, not the "
    "object_mass the plan was made for: the slice is a tuple and loses "
    "settings['object_mass'], so a plan for 20 kg is shaken at the box's "
    "0.2 kg and may 'hold' -- the defect the object_mass change fixed, back "
    "through the usual idiom (a massless model is refused instead)",
    "P3": "shake_test accepts a tiny object_mass (1e-12 kg, 1e-300 kg: finite "
    "and > 0, whose weight is a finite float) and then Drake cannot simulate "
    "it: a SolverError that blames the fingers' gains or a ModelError that "
    "blames the model add_models built, after the whole diagram is built; "
    "shake_candidates raises it for the first candidate",
    "P4": "shake_test of a massless model raises Drake's raw RuntimeError "
    "(SpatialInertia::IsPhysicallyValid) when the candidate's torque_scale or "
    "reference_point is finite but so large (1e200) that the ball's inertia "
    "overflows: _object_inertia checks they are finite, not the inertia",
}
"""Defects these families found, all fixed since (P3: masses below
``shake.MIN_SHAKEN_MASS`` are refused): :func:`finding` names any case that
shows one again, and ``test_fuzz_pinch.py`` guards each."""


def finding(family: str, name: str, outcome: str, detail: str) -> str | None:
    """The known finding (a key of :data:`FINDINGS`) a bad outcome shows, if any."""
    if (
        family == "facing_chains"
        and outcome == "raw exception"
        and detail.startswith("unclear GraspError message")
        and "integers, one per gap" in detail
    ):
        return "P1"
    if family != "pinch shake":
        return None
    if outcome == "raw exception" and "IsPhysicallyValid" in detail:
        return "P4"
    if "simulation stopped" in detail and re.search(r"object_mass=1e-(12|300)\b", name):
        return "P3"
    if (
        outcome == "silent wrong answer"
        and re.search(r" (slice|list) ", name)
        and re.fullmatch(r"check failed: AssertionError: shook \S+ kg, not \S+ kg",
                         detail)
    ):  # fmt: skip
        return "P2"
    return None


# ================================================================ running

SIZES = {"hands": 36, "shakes": 48, "facing_chains": 300}
"""Hands (a sides case, a plan, every third a cloud), shakes and
facing_chains inputs: the test's sizes."""


def run(sizes: dict | None = None):
    """(families' counters, bad cases, seconds per family) over every case."""
    sizes = SIZES if sizes is None else sizes
    return run_family(
        lambda box: [
            *hand_cases(box, 2901, sizes["hands"]),
            *shake_cases(box, 2902, sizes["shakes"]),
            *facing_cases(count=sizes["facing_chains"]),
        ],
        lambda case: case.family != "facing_chains",
    )


def main() -> int:
    """Print the outcome table, the known findings' cases and any other bad one."""
    return report_family(run, finding, FINDINGS, CHECKED, __doc__)


if __name__ == "__main__":
    sys.exit(main())
