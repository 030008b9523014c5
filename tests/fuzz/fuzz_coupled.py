"""Generated coupled hands: closing, planning and centring with ``<mimic>``.

Hands whose fingers a ``<mimic>`` closes as one group, of the two kinds of
``tests/support/coupled_hands.py`` but drawn at random (all seeded):

``pinch``
    A Robotiq-style pinch: two knuckles on a palm, each carrying a pad; the
    right knuckle and both pads follow the left knuckle (one motor).
``spread``
    A Barrett-style hand: two fingers on spread joints (the second spread
    follows the first), each finger's distal joint following its proximal
    one, and a third finger fixed on the palm.

A hand draws its link sizes, knuckle spacing and joint limits; 60 % of the
hands also draw hostile parts: zero-width ranges, a follower's own range
whatever its coupling maps to (so that no motor value, or one, keeps every
joint in range), mimic multipliers of 0, ±1e-9, ±1e6 or the wrong sign,
large offsets, effort limits of 0, 1e-12 or 1e9, transmissions on every
joint, on none or on a follower only.  With it, per call: an
object (``package://drakegrasp/objects/{box,cylinder,sphere,hex_prism}.sdf``),
the hand's pose over it (mostly where its fingers reach the object; at times
far away or sunk into it) and a pre-shape (within the limits and couplings,
or breaking one of them).  Each hand is

* closed twice directly by :func:`drakegrasp.close_hand` (the palm placed in a
  :func:`~drakegrasp.planning.planning_scene`, as ``tests/plant/
  test_free_part.py`` does);
* planned on the object body by :func:`drakegrasp.plan_grasps`;
* planned on a point cloud of the object's surface, in a scene of the hand
  only.

Every call runs in a sandboxed worker (time and memory limits: a crash or a
hang is an outcome).  The oracles, all from the hand's own description (the
joint limits and couplings written in its URDF) and Drake's signed
distances, computed in the worker and judged here:

(a) only :class:`drakegrasp.GraspError` is raised (a refusal is counted, not
    judged);
(b) in every closed configuration (the context after ``close_hand``, each
    candidate applied with ``GraspCandidate.apply``) every coupling holds,
    ``q_f = m q_l + o`` to 1e-9 (relative to the size of ``m q_l``), and
    every joint is within its limits (1e-9);
(c) every candidate's ``X_WH`` is finite and a proper rigid transform, no
    hand geometry penetrates the object deeper than the distance tolerance
    (Drake's signed distance of every hand/object pair with the candidate
    applied), and every contact's finger body is a body of one of the
    hand's chains (a link moved by a closing joint) or the palm's (the
    planner reports a palm's contact, labelled as the palm's); on a cloud,
    no cloud point lies deeper than the tolerance inside a hand geometry
    (Drake's signed distance to each point), and the true object (where the
    cloud was sampled) is not penetrated deeper than the tolerance plus the
    cloud's spacing (its points' median distance to their nearest): the
    cloud route closes fingers on the points' tangent discs, which a finger
    may pass between by about that much (``cloud_hand.GAP_SPACINGS``).
    ``close_hand`` leaves nothing penetrating deeper than the tolerance
    either.

``equalising_move`` (the centring's step, :mod:`drakegrasp.planning.
centring`) gets random gaps and lines (two to six chains, unit lines or
not, one group or several) and hostile arrays (NaN, inf, wrong shapes,
empty, wrong dtypes, ragged, a bad tolerance).  A move it returns is a
finite (3,) vector after which no group's gaps spread more (max - min) than
before (inputs that no move equalises are labelled ``overdetermined``); a
hostile array is refused with a GraspError or gets None.

Defects found and not fixed here are :data:`FINDINGS`; :func:`finding`
names the cases that show them.

    python tests/fuzz/fuzz_coupled.py [--details]

prints the outcome table and the findings' cases.
"""

from __future__ import annotations

import collections
import json
import math
import re
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from fuzz_cases import Case, report_family, run_family  # noqa: E402
from hostile import array, pick  # noqa: E402
from sandbox import Sandbox  # noqa: E402

import drakegrasp as dg  # noqa: E402

OBJECTS = {  # name: (half width across, top above the centre), metres
    "box": (0.025, 0.05),
    "cylinder": (0.03, 0.06),
    "sphere": (0.035, 0.035),
    "hex_prism": (0.027, 0.04),
}
COUPLING_TOL = 1e-9
LIMIT_TOL = 1e-9
KINDS = ("pinch", "spread")
EMPTY_RANGE, POINT_RANGE = "empty coupled range", "one-point coupled range"
"""Labels of a hand whose limits and couplings leave a leader no value, or one."""

# ================================================================ the hands


def _u(rng, lo, hi) -> float:
    return float(rng.uniform(lo, hi))


def _rnd(x: float) -> float:
    """``x`` as the URDF writes it (``repr``: every digit), for the oracles."""
    return float(repr(float(x)))


_BAD_MULTIPLIERS = (0.0, 1e-9, -1e-9, 1e6, -1e6)
_BAD_OFFSETS = (0.3, -0.3, 2.0, 1e3)
_EFFORTS = (5.0, 5.0, 5.0, 0.0, 1e-12, 1e9)
_TRANSMISSIONS = ("leader", "leader", "leader", "all", "none", "follower")


def _limits_of(lo, hi, m, o) -> list[float]:
    """The follower's range that the leader's ``[lo, hi]`` maps onto."""
    a, b = sorted((m * lo + o, m * hi + o))
    return [_rnd(a), _rnd(b)]


def _follower(rng, hostile: list, name: str, lead, nominal: float) -> tuple:
    """A follower's multiplier, offset and limits (its leader's ``[lo, hi]``).

    ``hostile`` is None for a valid hand, else the list of what is hostile.
    """
    m, o = nominal * _u(rng, 0.5, 1.5), _u(rng, -0.05, 0.05)
    r = rng.random() if hostile is not None else 1.0
    if r < 0.12:
        m = pick(rng, _BAD_MULTIPLIERS)
        hostile.append(f"{name} x{m:g}")
    elif r < 0.18:
        m = -m  # the wrong sign: the follower opens as the leader closes
        hostile.append(f"{name} sign")
    elif r < 0.24:
        o = pick(rng, _BAD_OFFSETS)
        hostile.append(f"{name} +{o:g}")
    m, o = _rnd(m), _rnd(o)
    limits = _limits_of(*lead, m, o)
    r = rng.random() if hostile is not None else 1.0
    if r < 0.1:  # the follower's own range, whatever the coupling maps to
        limits = sorted([_rnd(nominal * _u(rng, 0, 1)), 0.0])
        hostile.append(f"{name} own range")
    elif r < 0.16:
        limits = [limits[0], limits[0]]
        hostile.append(f"{name} zero range")
    return m, o, limits


def _leader(rng, hostile: list, name: str, lo: float, hi: float) -> list[float]:
    lo, hi = _rnd(lo), _rnd(hi)
    r = rng.random() if hostile is not None else 1.0
    if r < 0.06:
        hostile.append(f"{name} zero range")
        return [lo, lo]
    if r < 0.09:
        hostile.append(f"{name} [0, 0]")
        return [0.0, 0.0]
    return [lo, hi]


def _efforts(rng, hostile: list, joints: list[str]) -> dict:
    e = pick(rng, _EFFORTS) if hostile is not None else 5.0
    if e != 5.0:
        hostile.append(f"effort {e:g}")
    return dict.fromkeys(joints, e)


def _transmitted(rng, hostile: list, leaders: list, followers: list) -> list[str]:
    t = pick(rng, _TRANSMISSIONS) if hostile is not None else "leader"
    if t != "leader":
        hostile.append(f"transmissions: {t}")
    return {
        "leader": leaders,
        "all": leaders + followers,
        "none": [],
        "follower": followers[:1],
    }[t]


def coupled_ranges(hand: dict) -> dict[str, tuple[float, float]]:
    """Each motor's values that keep it and its followers within their limits.

    ``lo > hi`` where there is none.
    """
    out = {}
    followers = {c[0] for c in hand["couplings"]}
    for lead, j in hand["joints"].items():
        if lead in followers:
            continue
        lo, hi = j["limits"]
        for f, leader, m, o in hand["couplings"]:
            if leader != lead:
                continue
            flo, fhi = hand["joints"][f]["limits"]
            if m == 0:
                lo, hi = (lo, hi) if flo <= o <= fhi else (1.0, 0.0)
            else:
                a, b = sorted(((flo - o) / m, (fhi - o) / m))
                lo, hi = max(lo, a), min(hi, b)
        out[lead] = (lo, hi)
    return out


def _finish(hand: dict) -> dict:
    ranges = coupled_ranges(hand)
    for label, which in ((EMPTY_RANGE, lambda lo, hi: lo > hi),
                         (POINT_RANGE, lambda lo, hi: lo == hi)):  # fmt: skip
        found = [lead for lead, r in ranges.items() if which(*r)]
        if found:  # the limits and couplings leave a motor no position, or one
            hand["hostile"].append(f"{label} of {'/'.join(found)}")
    return hand


def pinch_hand(rng) -> dict:
    """A random Robotiq-style pinch (see the module docstring); 60 % hostile."""
    hostile: list[str] | None = [] if rng.random() < 0.6 else None
    palm = [_u(rng, 0.12, 0.2), _u(rng, 0.04, 0.08), _u(rng, 0.03, 0.06)]
    spacing = _u(rng, 0.11, 0.17)
    if hostile is not None and rng.random() < 0.1:
        spacing = pick(rng, (0.0, 0.012, 0.4))
        hostile.append(f"spacing {spacing:g}")
    knuckle = [_u(rng, 0.03, 0.07), _u(rng, 0.004, 0.008)]  # length, radius
    pad = [_u(rng, 0.006, 0.012), _u(rng, 0.015, 0.035), _u(rng, 0.025, 0.05)]
    lead = _leader(rng, hostile, "left_knuckle", 0.0, _u(rng, 0.5, 1.1))
    joints = {"left_knuckle": {"limits": lead}}
    couplings = []
    for name, nominal in (
        ("right_knuckle", -1.0),
        ("left_pad_joint", -1.0),
        ("right_pad_joint", 1.0),
    ):
        m, o, limits = _follower(rng, hostile, name, lead, nominal)
        joints[name] = {"limits": limits}
        couplings.append((name, "left_knuckle", m, o))
    followers = [c[0] for c in couplings]
    return _finish(
        {
            "kind": "pinch",
            "palm": palm,
            "spacing": spacing,
            "knuckle": knuckle,
            "pad": pad,
            "joints": joints,
            "couplings": couplings,
            "efforts": _efforts(rng, hostile, list(joints)),
            "transmissions": _transmitted(rng, hostile, ["left_knuckle"], followers),
            "hostile": hostile or [],
        }
    )


def spread_hand(rng) -> dict:
    """A random Barrett-style hand, its spread coupled (see above); 60 % hostile."""
    hostile: list[str] | None = [] if rng.random() < 0.6 else None
    a, b = _u(rng, 0.045, 0.07), _u(rng, 0.012, 0.035)
    if hostile is not None and rng.random() < 0.08:
        b = 0.0  # f1 and f2 on one spot
        hostile.append("f1 on f2")
    fingers = {
        "f3": {"xyz": [a, 0.0, 0.0], "yaw": math.pi, "axis": None},
        "f1": {"xyz": [-a, b, 0.0], "yaw": 0.0, "axis": [0, 0, -1]},
        "f2": {"xyz": [-a, -b, 0.0], "yaw": 0.0, "axis": [0, 0, 1]},
    }
    links = [_u(rng, 0.035, 0.07), _u(rng, 0.03, 0.045), _u(rng, 0.006, 0.011)]
    spread = _leader(rng, hostile, "f1_spread", _u(rng, -0.5, 0), _u(rng, 0.3, 1.6))
    joints = {"f1_spread": {"limits": spread}}
    couplings = []
    m, o, limits = _follower(rng, hostile, "f2_spread", spread, 1.0)
    joints["f2_spread"] = {"limits": limits}
    couplings.append(("f2_spread", "f1_spread", m, o))
    leaders = ["f1_spread"]
    for k in ("f3", "f1", "f2"):
        prox = f"{k}_proximal_joint"
        lims = _leader(rng, hostile, prox, _u(rng, -0.5, 0), _u(rng, 1.0, 2.2))
        joints[prox] = {"limits": lims}
        dist = f"{k}_distal_joint"
        m, o, limits = _follower(rng, hostile, dist, lims, 0.5)
        joints[dist] = {"limits": limits}
        couplings.append((dist, prox, m, o))
        leaders.append(prox)
    followers = [c[0] for c in couplings]
    return _finish(
        {
            "kind": "spread",
            "palm_radius": max(a, b) + 0.02,
            "fingers": fingers,
            "links": links,
            "joints": joints,
            "couplings": couplings,
            "efforts": _efforts(rng, hostile, list(joints)),
            "transmissions": _transmitted(rng, hostile, leaders, followers),
            "hostile": hostile or [],
        }
    )


def _f(*xs) -> str:
    return " ".join(repr(float(x)) for x in xs)


def _link(name: str, xyz, shape: str, mass: float = 0.05) -> str:
    return (
        f'<link name="{name}"><inertial><origin xyz="{_f(*xyz)}"/><mass value='
        f'"{mass}"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" '
        f'iyz="0"/></inertial><collision><origin xyz="{_f(*xyz)}"/><geometry>'
        f"{shape}</geometry></collision></link>"
    )


def _joint(hand: dict, name: str, parent, child, xyz, axis, rpy=(0, 0, 0)) -> str:
    """A revolute joint of ``hand`` with its limits, effort and mimic."""
    lo, hi = hand["joints"][name]["limits"]
    mimic = "".join(
        f'<mimic joint="{lead}" multiplier="{m!r}" offset="{o!r}"/>'
        for f, lead, m, o in hand["couplings"]
        if f == name
    )
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/>'
        f'<child link="{child}"/><origin xyz="{_f(*xyz)}" rpy="{_f(*rpy)}"/>'
        f'<axis xyz="{_f(*axis)}"/><limit lower="{lo!r}" upper="{hi!r}" '
        f'effort="{hand["efforts"][name]!r}" velocity="2"/>{mimic}</joint>'
    )


def _transmissions(hand: dict) -> str:
    return "".join(
        f'<transmission name="t_{j}"><type>transmission_interface/'
        f'SimpleTransmission</type><joint name="{j}"/><actuator name="m_{j}">'
        "<mechanicalReduction>1</mechanicalReduction></actuator></transmission>"
        for j in hand["transmissions"]
    )


def urdf(hand: dict) -> str:
    """The URDF text of a hand drawn by :func:`pinch_hand` or :func:`spread_hand`."""
    if hand["kind"] == "pinch":
        px, py, pz = hand["palm"]
        s, (kl, kr), (pt, pw, ph) = hand["spacing"], hand["knuckle"], hand["pad"]
        capsule = f'<capsule radius="{kr!r}" length="{kl - 2 * kr!r}"/>'
        box = f'<box size="{_f(pt, pw, ph)}"/>'
        off = pt / 2 + kr
        parts = [
            _link("palm", (0, 0, pz / 2), f'<box size="{_f(px, py, pz)}"/>', 0.6),
            _link("left_knuckle", (0, 0, kl / 2), capsule),
            _link("right_knuckle", (0, 0, kl / 2), capsule),
            _link("left_pad", (off, 0, ph / 2), box, 0.03),
            _link("right_pad", (-off, 0, ph / 2), box, 0.03),
            _joint(hand, "left_knuckle", "palm", "left_knuckle",
                   (-s / 2, 0, pz + 0.01), (0, 1, 0)),
            _joint(hand, "right_knuckle", "palm", "right_knuckle",
                   (s / 2, 0, pz + 0.01), (0, 1, 0)),
            _joint(hand, "left_pad_joint", "left_knuckle", "left_pad",
                   (0, 0, kl), (0, 1, 0)),
            _joint(hand, "right_pad_joint", "right_knuckle", "right_pad",
                   (0, 0, kl), (0, 1, 0)),
        ]  # fmt: skip
        name = "fuzz_pinch"
    else:
        lp, ld, r = hand["links"]
        parts = [
            _link(
                "palm",
                (0, 0, -0.015),
                f'<cylinder radius="{hand["palm_radius"]!r}" length="0.03"/>',
            )
        ]
        for k, f in hand["fingers"].items():
            parts += [
                _link(f"{k}_knuckle", (0, 0, 0.005), '<sphere radius="0.004"/>'),
                _link(f"{k}_proximal", (0, 0, 0.005 + lp / 2),
                      f'<capsule radius="{r!r}" length="{lp - 2 * r!r}"/>'),
                _link(f"{k}_distal", (0, 0, ld / 2),
                      f'<capsule radius="{0.9 * r!r}" length="{ld - 1.8 * r!r}"/>'),
            ]  # fmt: skip
            if f["axis"] is None:
                parts.append(
                    f'<joint name="{k}_spread" type="fixed"><parent link="palm"/>'
                    f'<child link="{k}_knuckle"/><origin xyz="{_f(*f["xyz"])}" '
                    f'rpy="0 0 {f["yaw"]!r}"/></joint>'
                )
            else:
                parts.append(
                    _joint(hand, f"{k}_spread", "palm", f"{k}_knuckle", f["xyz"],
                           f["axis"])
                )  # fmt: skip
            parts += [
                _joint(hand, f"{k}_proximal_joint", f"{k}_knuckle",
                       f"{k}_proximal", (0, 0, 0.01), (0, 1, 0)),
                _joint(hand, f"{k}_distal_joint", f"{k}_proximal",
                       f"{k}_distal", (0, 0, 0.01 + lp), (0, 1, 0)),
            ]  # fmt: skip
        name = "fuzz_spread"
    return (
        f'<?xml version="1.0"?><robot name="{name}">'
        + "".join(parts)
        + _transmissions(hand)
        + "</robot>"
    )


def reach(hand: dict) -> float:
    """How far the open fingers' ends stand above the palm's frame, metres."""
    if hand["kind"] == "pinch":
        return hand["palm"][2] + 0.01 + hand["knuckle"][0] + hand["pad"][2]
    return 0.01 + hand["links"][0] + hand["links"][1]


def chain_bodies(hand: dict) -> set[str]:
    """The links a joint of the hand moves: the bodies of its chains."""
    if hand["kind"] == "pinch":
        return {"left_knuckle", "right_knuckle", "left_pad", "right_pad"}
    out = set()
    for k, f in hand["fingers"].items():
        out |= {f"{k}_proximal", f"{k}_distal"}
        if f["axis"] is not None:
            out.add(f"{k}_knuckle")
    return out


def palm_bodies(hand: dict) -> set[str]:
    """The palm and what is welded to it: a contact there is the palm's."""
    if hand["kind"] == "pinch":
        return {"palm"}
    return {"palm"} | {
        f"{k}_knuckle" for k, f in hand["fingers"].items() if f["axis"] is None
    }


def preshape(rng, hand: dict, hostile: list) -> dict[str, float]:
    """Joint values: leaders low in their range, followers by their coupling."""
    joints, couplings = hand["joints"], hand["couplings"]
    followers = {c[0]: c for c in couplings}
    q = {}
    for name, j in joints.items():
        if name not in followers:
            lo, hi = j["limits"]
            q[name] = lo + (hi - lo) * _u(rng, 0.0, 0.12)
    for f, lead, m, o in couplings:
        q[f] = m * q[lead] + o
    r = rng.random()
    if r < 0.06:
        name = pick(rng, sorted(followers))
        q[name] += 0.05
        hostile.append(f"{name} breaks its coupling")
    elif r < 0.1:
        name = pick(rng, sorted(set(joints) - set(followers)))
        q[name] = joints[name]["limits"][1] + 0.2
        hostile.append(f"{name} beyond its limit")
    return q


def hand_pose(rng, hand: dict, obj: str, hostile: list) -> dict:
    """The palm's pose over the object: +z down, the fingers' ends at its side."""
    _, top = OBJECTS[obj]
    depth = _u(rng, 0.012, 0.035)
    p = [_u(rng, -0.012, 0.012), _u(rng, -0.012, 0.012), top + reach(hand) - depth]
    rpy = [math.pi + _u(rng, -0.15, 0.15), _u(rng, -0.15, 0.15), _u(rng, -3.2, 3.2)]
    r = rng.random()
    if r < 0.07:
        p[2] = pick(rng, (1.0, 30.0, 1e6))
        hostile.append(f"palm at z={p[2]:g}")
    elif r < 0.12:
        p[2] = _u(rng, 0.0, top)
        hostile.append("palm in the object")
    return {"p": p, "rpy": rpy}


def object_pose(rng) -> dict:
    """The object's pose: near the origin, turned about z (and a little tilted)."""
    return {
        "p": [_u(rng, -0.01, 0.01), _u(rng, -0.01, 0.01), _u(rng, -0.01, 0.01)],
        "rpy": [_u(rng, -0.1, 0.1), _u(rng, -0.1, 0.1), _u(rng, -3.2, 3.2)],
    }


# ============================================================ worker side

_CACHE: dict = {}


def _transform(pose: dict):
    from pydrake.math import RigidTransform, RollPitchYaw

    return RigidTransform(RollPitchYaw(pose["rpy"]), pose["p"])


def _scene(hand: dict, obj: str | None):
    """The hand (and object) in a planning scene, its context as it was built."""
    return cached_scene(_CACHE, urdf(hand), obj, f"{hand['kind']}.urdf")


def cached_scene(cache: dict, text: str, obj: str | None, filename: str):
    """A planning scene of a hand's URDF ``text`` (and a shipped object), cached.

    Its context is reset to how it was built on every call; ``cache`` holds
    at most nine scenes, to keep a worker's memory flat.
    """
    from drakegrasp.planning import planning_scene

    key = (text, obj)
    if key not in cache:
        url = None if obj is None else f"package://drakegrasp/objects/{obj}.sdf"
        if len(cache) > 8:
            cache.clear()
        # the file only while Drake parses it: a killed worker leaves nothing
        with tempfile.TemporaryDirectory(prefix="drakegrasp-fuzz-") as folder:
            path = Path(folder) / filename
            path.write_text(text)
            scene = planning_scene(url, hand_url=str(path))
        cache[key] = (scene, scene.context.Clone())
    scene, root0 = cache[key]
    scene.context.SetTimeStateAndParametersFrom(root0)
    return scene


def _set_joints(plant, ctx, instance, q: dict) -> None:
    for name, value in q.items():
        plant.GetJointByName(name, instance).set_angle(ctx, value)


def _joint_values(plant, ctx, instance) -> dict[str, float]:
    q = plant.GetPositions(ctx)
    out = {}
    for i in plant.GetJointIndices(instance):
        j = plant.get_joint(i)
        if j.num_positions() == 1:
            out[j.name()] = float(q[j.position_start()])
    return out


def _min_distance(scene) -> float:
    """Drake's smallest signed distance of a hand/object geometry pair."""
    from drake_distances import hand_object_distances  # tests/plant

    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    query = plant.get_geometry_query_input_port().Eval(ctx)
    found = hand_object_distances(plant, query, scene.hand, scene.object_body)
    return min((d for *_, d in found), default=math.inf)


def _place(scene, spec: dict):
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    if scene.object_body is not None:
        plant.SetFreeBodyPose(ctx, scene.object_body, _transform(spec["object_pose"]))
    palm = plant.GetBodyByName("palm", scene.hand)
    plant.SetFreeBodyPose(ctx, palm, _transform(spec["pose"]))
    _set_joints(plant, ctx, scene.hand, spec["q"])
    return plant, ctx


def close_case(spec: dict) -> dict:
    """Worker side: ``close_hand`` on the placed hand; the oracles' data."""
    scene = _scene(spec["hand"], spec["object"])
    plant, ctx = _place(scene, spec)
    closure = dg.close_hand(
        plant, ctx, scene.object_body, hand=scene.hand, **spec["kwargs"]
    )
    return {
        "q": _joint_values(plant, ctx, scene.hand),
        "tol": closure.distance_tolerance,
        "min_distance": _min_distance(scene),
        "fingers": [[f.name, f.status, f.psi] for f in closure.fingers],
        "touching": sum(f.status == "touching" for f in closure.fingers),
    }


def _candidate_data(c, plant, scene, obj_scene=None) -> dict:
    """A candidate's pose, closed joints and contacts, applied to ``scene``."""
    X = c.X_WH.GetAsMatrix4()
    out = {
        "X_WH": X.tolist(),
        "contacts": [x.finger_body.split("::")[-1] for x in c.contacts],
        "q_hand": dict(
            zip((n.split("::")[-1] for n in c.joint_names), c.q_hand.tolist(),
                strict=True)
        ),
        "closure": bool(c.is_closure),
    }  # fmt: skip
    try:
        c.apply(plant, scene.context)
    except dg.GraspError as e:  # a candidate its own apply refuses
        out["apply"] = f"{type(e).__name__}: {e}"
        return out
    out["q"] = _joint_values(plant, plant.GetMyContextFromRoot(scene.context),
                             scene.hand)  # fmt: skip
    if obj_scene is not None:  # the true object, where the cloud was sampled
        c.apply(obj_scene.plant, obj_scene.context)
        out["min_distance"] = _min_distance(obj_scene)
    elif scene.object_body is not None:
        out["min_distance"] = _min_distance(scene)
    return out


def plan_case(spec: dict) -> dict:
    """Worker side: ``plan_grasps`` on the object body; every candidate's data."""
    scene = _scene(spec["hand"], spec["object"])
    plant, _ = _place(scene, spec)
    result = dg.plan_grasps(
        plant, scene.context, scene.object_body, hand=scene.hand, **spec["kwargs"]
    )
    return {
        "tol": spec["kwargs"].get("distance_tolerance", 1e-4),
        "candidates": [_candidate_data(c, plant, scene) for c in result],
        "rejections": dict(result.rejections),
    }


def _cloud_depth(scene, points: np.ndarray) -> float:
    """The deepest a cloud point lies inside a hand geometry (Drake's distances)."""
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    query = plant.get_geometry_query_input_port().Eval(ctx)
    deepest = math.inf
    for p in points:
        for d in query.ComputeSignedDistanceToPoint(p, 0.0):
            deepest = min(deepest, d.distance)
    return deepest


def cloud_case(spec: dict) -> dict:
    """Worker side: ``plan_grasps`` on a cloud of the object's surface."""
    from drakegrasp.planning import object_surface

    obj_scene = _scene(spec["hand"], spec["object"])
    plant, ctx = _place(obj_scene, spec)
    surface = object_surface(plant, obj_scene.context, obj_scene.object_body)
    rng = np.random.default_rng(spec["cloud_seed"])
    p_OS, n_O, _ = surface.sample(spec["cloud_points"], rng)  # frame O
    X_WO = _transform(spec["object_pose"])
    points = (X_WO.rotation().matrix() @ p_OS.T).T + X_WO.translation()
    normals = (X_WO.rotation().matrix() @ n_O.T).T
    # the object out of the way while the cloud's candidates are measured on
    # the hand-only scene; back where it was for the true object's distances
    scene = _scene(spec["hand"], None)
    hand_plant, _ = _place(scene, spec)
    result = dg.plan_grasps(
        hand_plant, scene.context, None, hand=scene.hand, point_cloud=points,
        cloud_normals=normals, **spec["kwargs"],
    )  # fmt: skip
    out = []
    for c in result:
        data = _candidate_data(c, hand_plant, scene, obj_scene)
        if "apply" not in data:
            data["cloud_depth"] = _cloud_depth(scene, points)
        out.append(data)
    from scipy.spatial import cKDTree

    nearest, _ = cKDTree(points).query(points, k=2)
    return {
        "tol": spec["kwargs"].get("distance_tolerance", 1e-4),
        "spacing": float(np.median(nearest[:, 1])),
        "candidates": out,
        "rejections": dict(result.rejections),
    }


# ============================================================ the oracles


def configuration_faults(hand: dict, q: dict[str, float]) -> list[str]:
    """(b): couplings and limits of the hand's URDF broken by ``q``."""
    faults = []
    for f, lead, m, o in hand["couplings"]:
        want = m * q[lead] + o
        scale = max(1.0, abs(m * q[lead]), abs(o))
        if not abs(q[f] - want) <= COUPLING_TOL * scale:
            faults.append(
                f"{f} = {q[f]!r}, its coupling {m:g} * {lead} ({q[lead]!r}) + "
                f"{o:g} = {want!r}"
            )
    for name, j in hand["joints"].items():
        lo, hi = j["limits"]
        if not lo - LIMIT_TOL <= q[name] <= hi + LIMIT_TOL:
            faults.append(f"{name} = {q[name]!r} outside [{lo!r}, {hi!r}]")
    return faults


def transform_faults(X) -> list[str]:
    """(c): ``X`` is not a finite proper rigid transform."""
    X = np.asarray(X, dtype=float)
    if X.shape != (4, 4) or not np.all(np.isfinite(X)):
        return [f"X_WH not finite: {X.tolist()}"]
    R = X[:3, :3]
    faults = []
    if not np.allclose(R.T @ R, np.eye(3), rtol=0, atol=1e-9):
        faults.append(f"R_WH not orthonormal: {R.tolist()}")
    if not abs(np.linalg.det(R) - 1.0) <= 1e-9:
        faults.append(f"det R_WH = {np.linalg.det(R)!r}")
    if not np.array_equal(X[3], [0, 0, 0, 1]):
        faults.append(f"last row {X[3].tolist()}")
    return faults


def candidate_faults(
    hand: dict, tol: float, data: dict, spacing: float = 0.0
) -> list[str]:
    """(b) and (c) for one candidate's data from the worker.

    ``spacing``: a cloud's (median distance of a point to its nearest), by
    which a finger closed on the cloud may lie inside the true object.
    """
    faults = placed_faults(hand, tol, data, spacing)
    if "apply" in data:
        return faults
    if data.get("cloud_depth", math.inf) < -tol:
        faults.append(f"a cloud point {-data['cloud_depth']:.3g} m inside the hand")
    chains = chain_bodies(hand)
    strays = sorted(set(data["contacts"]) - chains - palm_bodies(hand))
    if strays:
        faults.append(f"contacts on {strays}, neither a chain's body nor the palm")
    CHECKED["contacts on a chain"] += sum(b in chains for b in data["contacts"])
    CHECKED["contacts on the palm"] += sum(b not in chains for b in data["contacts"])
    return faults


def placed_faults(hand: dict, tol: float, data: dict, spacing: float = 0.0):
    """A candidate's pose, joints and depth in the object, as the worker applied it.

    Its ``X_WH`` a rigid pose, ``apply`` not refused, its joints within
    their limits and couplings and as the candidate says, and the hand no
    deeper in the object than ``tol`` (plus a cloud's ``spacing``).
    """
    faults = transform_faults(data["X_WH"])
    if "apply" in data:
        return [*faults, f"apply refused its candidate: {data['apply']}"]
    faults += configuration_faults(hand, data["q"])
    for name, value in data["q_hand"].items():
        if data["q"].get(name) != value:
            faults.append(f"apply set {name} = {data['q'].get(name)!r}, not {value!r}")
    if data.get("min_distance", math.inf) < -(tol + spacing):
        faults.append(f"penetrates the object by {-data['min_distance']:.3g} m")
    return faults


CHECKED: collections.Counter = collections.Counter()
"""What the oracles judged: closed hands, candidates, contacts (the test reads
it: the oracles saw enough to mean something)."""


def closed_right(hand: dict):
    """The judge of a ``close_case`` answer."""

    def check(out: dict) -> bool:
        CHECKED["closed hands"] += 1
        faults = configuration_faults(hand, out["q"])
        if out["min_distance"] < -out["tol"]:
            faults.append(f"penetrates by {-out['min_distance']:.3g} m")
        if faults:
            raise AssertionError("; ".join(faults))
        return True

    return check


def planned_right(hand: dict):
    """The judge of a ``plan_case`` or ``cloud_case`` answer."""

    def check(out: dict) -> bool:
        faults = []
        CHECKED["cloud candidates" if "spacing" in out else "candidates"] += len(
            out["candidates"]
        )
        for k, data in enumerate(out["candidates"]):
            found = candidate_faults(hand, out["tol"], data, out.get("spacing", 0.0))
            faults += [f"#{k}: {f}" for f in found]
        if faults:
            raise AssertionError("; ".join(faults[:6]))
        return True

    return check


# ============================================================ the cases


def _json_safe(spec: dict) -> dict:
    return json.loads(json.dumps(spec))


def coupled_cases(sandbox: Sandbox, kind: str, seed: int, count: int) -> Iterator[Case]:
    """``count`` hands of ``kind``: each closed twice, planned, and on a cloud."""
    draw = pinch_hand if kind == "pinch" else spread_hand
    rng = np.random.default_rng(seed)
    for i in range(count):
        hand = draw(rng)
        label = f"{kind}#{i}"
        if hand["hostile"]:
            label += " [" + ", ".join(hand["hostile"]) + "]"
        for route in ("close", "close", "plan", "cloud"):
            obj = pick(rng, sorted(OBJECTS))
            hostile: list[str] = []
            spec = {
                "hand": hand,
                "object": obj,
                "object_pose": object_pose(rng),
                # the planner samples its own poses: a hostile palm only closes
                "pose": hand_pose(rng, hand, obj, hostile if route == "close" else []),
                "q": preshape(rng, hand, hostile),
            }
            if route == "close":
                spec["kwargs"] = {
                    "distance_tolerance": pick(rng, (1e-4, 1e-4, 1e-3, 5e-5)),
                    "min_fingers": int(pick(rng, (1, 1, 1, 2))),
                }
                fn, check = "fuzz_coupled:close_case", closed_right(hand)
            else:
                spec["kwargs"] = {
                    "num_candidates": int(pick(rng, (10, 14, 20))),
                    "mu": pick(rng, (0.3, 0.5, 0.8)),
                    "seed": int(rng.integers(1000)),
                    "robustness_samples": 2,
                    "certify": 0,
                    "distance_tolerance": pick(rng, (1e-4, 1e-4, 1e-3)),
                }
                fn, check = f"fuzz_coupled:{route}_case", planned_right(hand)
                if route == "cloud":
                    spec["cloud_seed"] = int(rng.integers(1000))
                    spec["cloud_points"] = int(pick(rng, (600, 1000, 1500)))
                    spec["kwargs"]["object_mass"] = 0.2
            spec = _json_safe(spec)
            name = f"{label} {route} {obj}"
            if hostile:
                name += " [" + ", ".join(hostile) + "]"

            def call(fn=fn, spec=spec):
                return sandbox.call(fn, spec)

            yield Case(f"coupled {kind}", name, call, "either", check)


# -------------------------------------------------------- equalising_move


def _unit_rows(rng, k: int) -> np.ndarray:
    n = rng.normal(size=(k, 3))
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def _gaps_and_lines(rng) -> tuple[np.ndarray, np.ndarray, object, str]:
    """Valid random gaps, lines and groups; a description."""
    k = int(pick(rng, (2, 2, 3, 3, 4, 5, 6, 6)))
    psi = rng.uniform(0.0, 0.03, size=k)
    what = pick(rng, ("pinch", "unit", "unit", "tilted", "any length"))
    if what == "pinch":  # chains facing each other across the object, tilted
        k = 2
        psi = psi[:2]
        n = _unit_rows(rng, 1)[0]
        lines = np.array([n, -n]) + 0.2 * rng.normal(size=(2, 3))
        lines /= np.linalg.norm(lines, axis=1, keepdims=True)
    elif what == "tilted":  # all the lines within a cone: little to move by
        lines = _unit_rows(rng, 1) + 0.1 * rng.normal(size=(k, 3))
        lines /= np.linalg.norm(lines, axis=1, keepdims=True)
    elif what == "any length":
        lines = _unit_rows(rng, k) * rng.uniform(0.0, 3.0, size=(k, 1))
    else:
        lines = _unit_rows(rng, k)
    groups = None
    if rng.random() < 0.4:
        groups = rng.integers(0, 2 if k < 4 else 3, size=k).tolist()
        what += f" groups {groups}"
    if not determined(psi, lines, groups):
        what += f" {OVERDETERMINED}"
    return psi, lines, groups, f"k={k} {what}"


OVERDETERMINED = "overdetermined"
"""The label of gaps that no move makes equal (see :func:`determined`)."""


def determined(psi, lines, groups) -> bool:
    """Whether some move makes every group's gaps equal.

    The move ``t`` solves ``(n̂_c − n̄)·t = ψ_c − ψ̄`` when the centred lines
    (their singular values above ``equalising_move``'s cut of 1e-6) span
    every vector that sums to 0 over each group: rank ``k − groups``.
    Otherwise (five chains or more in a group, two groups of three...) the
    least-squares move only lessens the gaps' spread in the mean square.
    """
    lines = np.asarray(lines, float)
    g = np.zeros(len(psi), int) if groups is None else np.asarray(groups)
    A = lines.copy()
    for x in np.unique(g):
        A[g == x] -= lines[g == x].mean(axis=0)
    rank = int(np.sum(np.linalg.svd(A, compute_uv=False) > 1e-6))
    return rank == len(psi) - len(np.unique(g))


def spread_after(psi, lines, groups, t) -> tuple[float, float]:
    """(largest spread of a group's gaps before, after moving by ``t``)."""
    psi, lines = np.asarray(psi, float), np.asarray(lines, float)
    after = psi - lines @ np.asarray(t, float)
    g = np.zeros(len(psi), int) if groups is None else np.asarray(groups)
    before = max(float(np.ptp(psi[g == x])) for x in np.unique(g))
    worse = max(
        float(np.ptp(after[g == x])) - float(np.ptp(psi[g == x])) for x in np.unique(g)
    )
    return before, worse


def _move_right(psi, lines, groups):
    def check(t) -> bool:
        if t is None:
            return True
        t = np.asarray(t)
        if t.shape != (3,) or t.dtype.kind != "f" or not np.all(np.isfinite(t)):
            raise AssertionError(f"a move of shape {t.shape}, dtype {t.dtype}: {t}")
        before, worse = spread_after(psi, lines, groups, t)
        if worse > 1e-12 * max(1.0, before):
            raise AssertionError(
                f"a group's gaps spread {worse:.3g} m more after the move {t.tolist()}"
            )
        return True

    return check


def _hostile_arrays(rng, psi, lines, groups) -> tuple[list, str, bool]:
    """Arguments with one hostile array; whether only its shape or dtype is bad."""
    k = len(psi)
    r = int(rng.integers(14))
    if r == 0:
        a = psi.copy()
        a[int(rng.integers(k))] = pick(rng, (math.nan, math.inf, -math.inf))
        return [a, lines, 1e-4, groups], "psi not finite", False
    if r == 1:
        a = lines.copy()
        a[int(rng.integers(k)), int(rng.integers(3))] = pick(rng, (math.nan, math.inf))
        return [psi, a, 1e-4, groups], "lines not finite", False
    if r == 2:
        a = pick(rng, (1e300, -1e300, 1e-300, 1e308))
        return [psi * 0 + a * rng.random(k), lines, 1e-4, groups], f"gaps ~{a:g}", False
    if r == 3:
        return [psi, lines * 1e300, 1e-4, groups], "lines x1e300", False
    if r == 4:
        shape = pick(rng, ((k, 2), (k, 4), (k,), (k, 3, 1), (3, k), (1, 3)))
        if shape == (3, k) and k == 3:
            shape = (k, 4)
        return [psi, rng.normal(size=shape), 1e-4, groups], f"lines {shape}", True
    if r == 5:
        shape = pick(rng, ((k, 1), (1, k), (k + 1,), (k - 1,), ()))
        return [rng.random(shape), lines, 1e-4, groups], f"psi {shape}", True
    if r == 6:
        which = pick(rng, ("psi", "lines", "both"))
        p = np.zeros(0) if which != "lines" else psi
        a = np.zeros((0, 3)) if which != "psi" else lines
        return [p, a, 1e-4, groups], f"empty {which}", True
    if r == 7:
        dtype = pick(rng, ("<U4", "O", "<c16", "?", "<M8[s]"))
        if dtype == "O":
            values = [None] * k
        elif dtype == "<U4":
            values = ["a"] * k
        elif dtype == "<M8[s]":
            values = ["2020-01-01"] * k
        else:
            values = psi.tolist()
        return [array(values, dtype=dtype), lines, 1e-4, groups], f"psi {dtype}", True
    if r == 8:
        dtype = pick(rng, ("<U4", "O", "<c16", "?"))
        values = lines.tolist() if dtype in ("<c16", "?") else [["x"] * 3] * k
        return [psi, array(values, dtype=dtype), 1e-4, groups], f"lines {dtype}", True
    if r == 9:
        ragged = [[1.0, 0.0, 0.0], [0.0, 1.0]] + [[0.0, 0.0, 1.0]] * (k - 2)
        return [psi, ragged, 1e-4, groups], "ragged lines", True
    if r == 10:
        g = pick(rng, ([0] * (k + 1), [0], [0.5] * k, ["a"] * k, [[0]] * k))
        return [psi, lines, 1e-4, g], f"groups {g!r}", True
    if r == 11:
        tol = pick(rng, (math.nan, -1.0, math.inf, "1e-4", None, 1j))
        return [psi, lines, tol, groups], f"tol {tol!r}", True
    if r == 12:
        return [None, lines, 1e-4, groups], "psi None", True
    return [psi.tolist(), lines.tolist(), 1e-4, groups], "lists (valid)", False


def equalising_cases(seed: int = 2801, count: int = 300) -> Iterator[Case]:
    """Random and hostile inputs of ``equalising_move`` (in this process)."""
    from hostile import decode, encode

    from drakegrasp.planning.centring import equalising_move

    rng = np.random.default_rng(seed)
    for i in range(count):
        psi, lines, groups, what = _gaps_and_lines(rng)
        if rng.random() < 0.5:
            args = [psi, lines, pick(rng, (1e-4, 1e-3, 1e-6)), groups]
            yield Case(
                "equalising_move", f"{what}#{i}",
                lambda a=args: equalising_move(*a), "answer",
                _move_right(psi, lines, groups),
            )  # fmt: skip
            continue
        args, bad, shape_only = _hostile_arrays(rng, psi, lines, groups)
        args = [decode(encode(a)) for a in args]  # the hostile arrays built
        family = "equalising_move shapes" if shape_only else "equalising_move"

        def check(t, a=args):
            if t is None:
                return True
            t = np.asarray(t)
            if t.shape != (3,) or not np.all(np.isfinite(t)):
                raise AssertionError(f"a move of shape {t.shape}: {t}")
            return _move_right(a[0], a[1], a[3])(t)

        yield Case(
            family, f"{what} {bad}#{i}", lambda a=args: equalising_move(*a),
            "either", check,
        )  # fmt: skip


# ================================================================ findings

FINDINGS = {
    "F1": "equalising_move raises numpy's own errors (TypeError, ValueError, "
    "IndexError, LinAlgError), not a GraspError, for psi or lines of a wrong "
    "shape, dtype or length, None, ragged lists, wrong groups or a tol that is "
    "not a number; and returns a move as wide as the lines ((2,) or (4,)) for "
    "lines of 2 or 4 columns, or a wrong one for psi of shape (k, 1)",
    "F2": "plan_grasps on a body raises a raw ValueError (operands could not be "
    "broadcast together with shapes (4,) (0,)) from the closing search for a "
    "hand whose joint limits and couplings leave its motor no value or one: "
    "the default pre-shape clipped to the limits breaks a coupling, the search "
    "re-couples it inside the object, and the first step's regula falsi steps "
    "along the still empty direction (FingerState.d)",
    "F3": "equalising_move's least-squares move can spread a group's gaps "
    "(max - min) more than before when no move makes them equal (five chains "
    "or more in one group): it lessens their mean square, not their spread",
    "F4": "plan_grasps on a point cloud keeps candidates with a finger link "
    "wholly inside the object (over 2 cm into the hex prism): no cloud point "
    "lies inside the link, so the collision stage passes it",
}
"""Defects these families found in their first run, all fixed since:
:func:`finding` names the cases that would show one again."""


def finding(family: str, name: str, outcome: str, detail: str) -> str | None:
    """The known finding (a key of :data:`FINDINGS`) a bad outcome shows, if any."""
    if family == "equalising_move shapes" and (
        outcome == "raw exception" or "a move of shape" in detail
    ):
        return "F1"
    if family.startswith("equalising_move") and OVERDETERMINED in name:
        if outcome == "silent wrong answer" and "gaps spread" in detail:
            return "F3"
    if not family.startswith("coupled"):
        return None
    if (
        " plan " in name
        and outcome == "raw exception"
        and "could not be broadcast together" in detail
        and (EMPTY_RANGE in name or POINT_RANGE in name)
    ):
        return "F2"
    if " cloud " in name and outcome == "silent wrong answer":
        faults = detail.removeprefix("check failed: AssertionError: ").split("; ")
        if all(
            re.fullmatch(r"#\d+: penetrates the object by \S+ m", f) for f in faults
        ):
            return "F4"
    return None


# ================================================================ running

SIZES = {"pinch": 32, "spread": 32, "equalising_move": 600}
"""Hands per kind (four cases each: two closings, a plan on the body, one on
a cloud) and equalising_move inputs: the test's sizes, about 30 s."""


def run(sizes: dict | None = None):
    """(families' counters, bad cases, seconds per family) over every case."""
    sizes = SIZES if sizes is None else sizes
    return run_family(
        lambda box: [
            *coupled_cases(box, "pinch", 2811, sizes["pinch"]),
            *coupled_cases(box, "spread", 2812, sizes["spread"]),
            *equalising_cases(count=sizes["equalising_move"]),
        ],
        lambda case: case.family.startswith("coupled"),
    )


def main() -> int:
    """Print the outcome table, the known findings' cases and any other bad one."""
    return report_family(run, finding, FINDINGS, CHECKED, __doc__)


if __name__ == "__main__":
    sys.exit(main())
