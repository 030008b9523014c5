"""Generated one-motor parallel jaws, hostile joint limits and passive joints.

Three families, all seeded:

``jaw plan`` / ``jaw cloud``
    Parallel jaws drawn at random: pads of four shapes (box, capsule,
    sphere, cylinder across or along the grasp axis) and sizes, a palm of
    random size, the fingers sliding along the palm's x, y, z or a random
    axis, the right finger's joint axis reversed or not, strokes, and a
    coupling: none (two motors), a direct ``<mimic>`` (either finger
    following, ratio -1, -0.5, -2 or +1, offsets) or a chain through a
    hidden third slide (``drive``, the only motor) that one finger or both
    follow.  Each jaw is planned on a shipped object (at times rigidly moved
    far from the origin) and on a cloud sampled from the object.  Oracles,
    from the jaw's own description: a coupling that moves both pads the
    same way, and a finger without stroke, are refused with a ``ModelError``
    that says so; any other jaw is refused with a one-line ``GraspError`` or
    planned with every candidate on every ``<mimic>`` of the URDF (1e-12 m),
    within its limits, ``ParallelJaw.coupling`` equal to the coupling the
    URDF writes (finger 1 against finger 0), and (on a body)
    ``analyze_grasp`` on the applied candidate giving the same force-closure
    verdict and contact count.
``limits``
    A two-link URDF or SDFormat document whose one joint (revolute,
    prismatic, continuous, fixed, SDFormat universal with ``axis2``) has
    limits drawn from a hostile pool (reversed, equal, NaN, ±inf, missing,
    not a number, a number with a tail, ``1_0``, hex, ±1e17) loaded by
    ``add_models`` (text and file), ``planning_scene(hand_url=...)``, a
    scene YAML through ``load_scene``, and (a handful) ``drakegrasp plan
    --hand``.  The oracle is Drake itself: the same document parsed by a
    bare ``Parser`` in a forked child (it may abort).  Where Drake loads it
    the library must load it; where Drake raises or aborts the library must
    refuse with a one-line ``GraspError`` (``add_models`` may pass Drake's
    parse error on, as ``Parser.AddModels`` does); the library's process
    must never abort (each call runs in a forked child too); the command
    line prints one line ``drakegrasp: error: ...`` and exits non-zero when
    it refuses.
``passive``
    Multi-finger hands (two to four fingers, proximal and distal joints,
    some spreads) whose every joint is drawn: a motor (``<transmission>``),
    a ``<mimic>`` of its finger's proximal joint, fixed, or passive (neither).
    ``passive_joints`` returns exactly the passive ones and ``plan_grasps``
    warns ``PassiveJointWarning`` naming exactly those (nothing when none).

Defects found and not fixed here are :data:`FINDINGS`; :func:`finding`
names the cases that show them.

    python tests/fuzz/fuzz_jaws.py [--details]

prints the outcome table and the findings' cases.
"""

from __future__ import annotations

import collections
import math
import os
import re
import subprocess
import sys
import tempfile
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
# the test hands' helpers, in a sandbox's worker too
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "support"))

from coupled_hands import transmissions  # noqa: E402
from fuzz_cases import Case, report_family, run_family  # noqa: E402
from hostile import pick  # noqa: E402
from sandbox import Sandbox  # noqa: E402

import drakegrasp as dg  # noqa: E402

OBJECTS = ("box", "cylinder", "sphere", "hex_prism")
COUPLING_TOL = 1e-12
LIMIT_TOL = 1e-9
CHECKED: collections.Counter = collections.Counter()
"""What the oracles judged (the test reads it: enough to mean something)."""

# ================================================================ the jaws

_AXES = {  # the palm's rpy that turns the jaw's slide axis (y) onto this one
    "y": (0.0, 0.0, 0.0),
    "x": (0.0, 0.0, math.pi / 2),
    "z": (math.pi / 2, 0.0, 0.0),
}


def _u(rng, lo, hi) -> float:
    return float(rng.uniform(lo, hi))


def draw_jaw(rng) -> dict:
    """A random jaw (see the module docstring); JSON-safe."""
    axis = pick(rng, ("x", "y", "z", "y", "random"))
    rpy = _AXES.get(axis) or tuple(_u(rng, -3.1, 3.1) for _ in range(3))
    stroke = [_u(rng, 0.03, 0.05), _u(rng, 0.03, 0.05)]
    hostile = []
    if rng.random() < 0.06:
        stroke[int(rng.integers(2))] = 0.0
        hostile.append("no stroke")
    kind = pick(rng, ("none", "direct", "direct", "direct", "chain", "chain"))
    flip = bool(rng.random() < 0.3)  # right slide's axis -y, limits [0, s]
    s = -1.0 if flip else 1.0  # the symmetric ratio's sign
    coupling = None
    if kind == "direct":
        ratio = pick(rng, (-1.0, -1.0, -0.5, -2.0, 1.0)) * s
        coupling = {
            "kind": "direct",
            "follower": pick(rng, ("left", "right")),
            "ratio": ratio,
            "offset": pick(rng, (0.0, 0.0, 0.003, -0.004, 0.01)),
        }
    elif kind == "chain":
        m1 = pick(rng, (1.0, 1.0, -1.0, 0.5))
        coupling = {
            "kind": "chain",
            "via": pick(rng, ("drive", "left")),  # what the right slide follows
            "m1": m1,
            "b1": pick(rng, (0.0, 0.002)),
            "m2": pick(rng, (-1.0, -1.0, -0.5, 1.0)) * s,
            "b2": pick(rng, (0.0, -0.003)),
        }
        if coupling["via"] == "drive":
            coupling["m2"] *= m1  # the symmetric jaw again, mostly
    jaw = {
        "pad": pick(rng, ("box", "capsule", "sphere", "cylinder", "disc")),
        "pad_scale": _u(rng, 0.6, 1.5),
        "palm": [_u(rng, 0.03, 0.06), _u(rng, 0.11, 0.2), _u(rng, 0.02, 0.05)],
        "axis": axis,
        "rpy": list(rpy),
        "stroke": stroke,
        "flip": flip,
        "coupling": coupling,
        "hostile": hostile,
    }
    M = jaw_coupling(jaw)
    if M is not None and M[0] * (-1.0 if flip else 1.0) > 0:
        hostile.append(SAME_WAY)
    return jaw


SAME_WAY = "pads one way"


def jaw_coupling(jaw: dict) -> tuple[float, float] | None:
    """``(M, B)`` with ``q_right = M q_left + B`` as the URDF writes it."""
    c = jaw["coupling"]
    if c is None:
        return None
    if c["kind"] == "direct":
        r, o = c["ratio"], c["offset"]
        return (r, o) if c["follower"] == "right" else (1.0 / r, -o / r)
    m1, b1, m2, b2 = c["m1"], c["b1"], c["m2"], c["b2"]
    if c["via"] == "left":
        return m2, b2
    return m2 / m1, b2 - m2 * b1 / m1


def mimics(jaw: dict) -> list[tuple[str, str, float, float]]:
    """(follower, leader, multiplier, offset) of every ``<mimic>`` written."""
    c = jaw["coupling"]
    if c is None:
        return []
    if c["kind"] == "direct":
        f = c["follower"]
        lead = "right" if f == "left" else "left"
        return [(f"{f}_slide", f"{lead}_slide", c["ratio"], c["offset"])]
    return [
        ("left_slide", "drive", c["m1"], c["b1"]),
        ("right_slide", f"{c['via']}_slide" if c["via"] == "left" else "drive",
         c["m2"], c["b2"]),
    ]  # fmt: skip


def limits_of(jaw: dict) -> dict[str, tuple[float, float]]:
    sl, sr = jaw["stroke"]
    out = {
        "left_slide": (0.0, sl),
        "right_slide": (0.0, sr) if jaw["flip"] else (-sr, 0.0),
    }
    if jaw["coupling"] is not None and jaw["coupling"]["kind"] == "chain":
        out["drive"] = (0.0, 0.05)
    return out


def _f(*xs) -> str:
    return " ".join(repr(float(x)) for x in xs)


def _rot(rpy) -> np.ndarray:
    from pydrake.math import RollPitchYaw

    return RollPitchYaw(rpy).ToRotationMatrix().matrix()


def jaw_urdf(jaw: dict) -> str:
    """The URDF text of a jaw drawn by :func:`draw_jaw`."""
    k = jaw["pad_scale"]
    pads = {
        "capsule": ("0 1.5707963 0", f'<capsule radius="{0.007 * k!r}" '
                    f'length="{0.025 * k!r}"/>'),
        "sphere": ("0 0 0", f'<sphere radius="{0.007 * k!r}"/>'),
        "box": ("0 0 0", f'<box size="{_f(0.02 * k, 0.008 * k, 0.02 * k)}"/>'),
        "cylinder": ("0 1.5707963 0", f'<cylinder radius="{0.007 * k!r}" '
                     f'length="{0.025 * k!r}"/>'),
        "disc": ("1.5707963 0 0", f'<cylinder radius="{0.01 * k!r}" '
                 f'length="{0.006 * k!r}"/>'),
    }  # fmt: skip
    pad_rpy, shape = pads[jaw["pad"]]
    R = _rot(jaw["rpy"])
    rpy = _f(*jaw["rpy"])
    px, py, pz = jaw["palm"]
    limits = limits_of(jaw)
    written = {f: (lead, m, o) for f, lead, m, o in mimics(jaw)}

    def inertial(xyz, mass="0.05"):
        return (
            f'<inertial><origin xyz="{xyz}"/><mass value="{mass}"/><inertia '
            'ixx="1.6e-5" iyy="1.7e-5" izz="2.7e-6" ixy="0" ixz="0" iyz="0"/>'
            "</inertial>"
        )

    def finger(name, side):
        return (
            f'<link name="{name}">{inertial(f"0 {0.008 * side} 0.03")}'
            f'<collision><origin xyz="0 {0.012 * side} 0.03"/><geometry><box '
            'size="0.02 0.008 0.06"/></geometry></collision>'
            f'<collision><origin xyz="0 0 0.048" rpy="{pad_rpy}"/><geometry>{shape}'
            "</geometry></collision></link>"
        )

    def slide(name, child, axis="0 1 0"):
        lo, hi = limits[name]
        mimic = ""
        if name in written:
            lead, m, o = written[name]
            mimic = f'<mimic joint="{lead}" multiplier="{m!r}" offset="{o!r}"/>'
        return (
            f'<joint name="{name}" type="prismatic"><parent link="palm"/>'
            f'<child link="{child}"/><origin xyz="0 0 0" rpy="{rpy}"/><axis '
            f'xyz="{axis}"/><limit lower="{lo!r}" upper="{hi!r}" effort="40" '
            f'velocity="0.1"/>{mimic}</joint>'
        )

    c = jaw["coupling"]
    if c is None:
        motors = ["left_slide", "right_slide"]
    elif c["kind"] == "direct":
        motors = ["right_slide" if c["follower"] == "left" else "left_slide"]
    else:
        motors = ["drive"]
    drive = ""
    if "drive" in limits:
        drive = f'<link name="drive_link">{inertial("0 0 0", "0.01")}</link>' + slide(
            "drive", "drive_link"
        )
    transmissions = "".join(
        f'<transmission name="t_{j}"><type>transmission_interface/SimpleTransmission'
        f'</type><joint name="{j}"/><actuator name="m_{j}"><mechanicalReduction>1'
        "</mechanicalReduction></actuator></transmission>"
        for j in motors
    )
    palm_at = R @ np.array([0.0, 0.0, -pz / 2])
    return (
        '<?xml version="1.0"?><robot name="fuzz_jaw">'
        f'<link name="palm">{inertial(_f(*palm_at), "0.6")}<collision><origin '
        f'xyz="{_f(*palm_at)}" rpy="{rpy}"/><geometry><box size="{_f(px, py, pz)}"/>'
        "</geometry></collision></link>"
        f"{finger('left_finger', 1)}{finger('right_finger', -1)}"
        + slide("left_slide", "left_finger")
        + slide("right_slide", "right_finger", "0 -1 0" if jaw["flip"] else "0 1 0")
        + drive
        + transmissions
        + "</robot>"
    )


# ------------------------------------------------------------ worker side

_CACHE: dict = {}


def _jaw_scene(jaw: dict, obj: str | None):
    from fuzz_coupled import cached_scene

    return cached_scene(_CACHE, jaw_urdf(jaw), obj, "jaw.urdf")


def _pose(pose):
    from pydrake.math import RigidTransform, RollPitchYaw

    return RigidTransform(RollPitchYaw(pose["rpy"]), pose["p"])


def _jaw_of(scene) -> dict:
    from drakegrasp.planning.gripper import parallel_jaw

    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    g = parallel_jaw(scene.plant, ctx, scene.object_body, scene.hand)
    return {
        "joints": [j.name() for j in g.joints],
        "coupling": None if g.coupling is None else [float(x) for x in g.coupling],
    }


def _q_of(c) -> dict[str, float]:
    return {
        n.split("::")[-1]: float(v)
        for n, v in zip(c.joint_names, c.q_hand, strict=True)
    }


def jaw_plan_case(spec: dict) -> dict:
    """Worker side: plan the jaw on the object (moved or not); each candidate's data."""
    scene = _jaw_scene(spec["jaw"], spec["object"])
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    if spec.get("object_pose"):
        plant.SetFreeBodyPose(ctx, scene.object_body, _pose(spec["object_pose"]))
    result = dg.plan_grasps(
        plant, scene.context, scene.object_body, hand=scene.hand, **spec["kwargs"]
    )
    out = []
    for c in result:
        data = {
            "q": _q_of(c),
            "closure": bool(c.is_closure),
            "contacts": len(c.contacts),
        }
        try:
            c.apply(plant, scene.context, object_body=scene.object_body)
            report = dg.analyze_grasp(
                plant, scene.context, scene.object_body, hand=scene.hand, mu=result.mu
            )
            data["analysis"] = [
                bool(report.force_closure.is_closure),
                len(report.contacts),
            ]
        except dg.GraspError as e:
            data["analysis"] = f"{type(e).__name__}: {str(e)[:200]}"
        out.append(data)
    return {"jaw": _jaw_of(scene), "candidates": out}


def jaw_cloud_case(spec: dict) -> dict:
    """Worker side: plan the jaw on a cloud sampled from the object's surface."""
    from drakegrasp.planning import object_surface

    obj_scene = _jaw_scene(spec["jaw"], spec["object"])
    ctx = obj_scene.plant.GetMyContextFromRoot(obj_scene.context)
    surface = object_surface(obj_scene.plant, ctx, obj_scene.object_body)
    p, n, _ = surface.sample(spec["points"], np.random.default_rng(spec["cloud_seed"]))
    scene = _jaw_scene(spec["jaw"], None)
    result = dg.plan_grasps(
        scene.plant, scene.context, None, hand=scene.hand, point_cloud=p,
        cloud_normals=n, **spec["kwargs"],
    )  # fmt: skip
    return {
        "jaw": _jaw_of(obj_scene),
        "candidates": [{"q": _q_of(c), "closure": bool(c.is_closure)} for c in result],
    }


# ------------------------------------------------------------ the oracles


def _jaw_faults(jaw: dict, out: dict) -> list[str]:
    faults = []
    want = jaw_coupling(jaw)
    got, names = out["jaw"]["coupling"], out["jaw"]["joints"]
    if want is not None and got is not None and names == ["right_slide", "left_slide"]:
        m, b = got  # q_left = m q_right + b
        got = [1.0 / m, -b / m]
    if (want is None) != (got is None):
        faults.append(f"ParallelJaw.coupling {got}, the URDF's {want}")
    elif want is not None and not np.allclose(got, want, rtol=1e-12, atol=1e-15):
        faults.append(
            f"ParallelJaw.coupling {got} (q_right = m q_left + b), the URDF's {want}"
        )
    limits = limits_of(jaw)
    for k, c in enumerate(out["candidates"]):
        q = dict(c["q"])
        drive = {}  # a hidden drive (no finger joint): where its followers put it
        for f, lead, m, o in mimics(jaw):
            if f in q and lead in q:
                err = abs(q[f] - (m * q[lead] + o))
                if not err <= COUPLING_TOL:
                    faults.append(f"#{k}: {f} off its mimic of {lead} by {err:.3g} m")
            elif f in q and m != 0.0:
                drive.setdefault(lead, []).append((q[f] - o) / m)
            else:
                faults.append(f"#{k}: q_hand lacks {f} or {lead}: {sorted(q)}")
        for lead, values in drive.items():
            if max(values) - min(values) > COUPLING_TOL * 1e3:
                faults.append(f"#{k}: the followers of {lead} disagree: {values}")
            q[lead] = values[0]
        for name, (lo, hi) in limits.items():
            if name in q and not lo - LIMIT_TOL <= q[name] <= hi + LIMIT_TOL:
                faults.append(f"#{k}: {name} = {q[name]!r} outside [{lo}, {hi}]")
        if "analysis" in c:
            CHECKED["analysed"] += 1
            if c["analysis"] != [c["closure"], c["contacts"]]:
                faults.append(
                    f"#{k}: planned closure {c['closure']} with {c['contacts']} "
                    f"contacts, analyze_grasp says {c['analysis']}"
                )
    return faults


def jaw_right(jaw: dict, route: str):
    def check(out: dict) -> bool:
        CHECKED[f"{route} candidates"] += len(out["candidates"])
        if jaw["coupling"] is not None:
            CHECKED[f"coupled {route} candidates"] += len(out["candidates"])
        if SAME_WAY in jaw["hostile"] or "no stroke" in jaw["hostile"]:
            raise AssertionError(
                f"planned ({len(out['candidates'])} candidates), not refused"
            )
        faults = _jaw_faults(jaw, out)
        if faults:
            raise AssertionError("; ".join(faults[:6]))
        return True

    return check


class _RefusedWrongly(Exception):
    pass


def _expect_refusal(jaw: dict, call):
    """A degenerate jaw's refusal must be a ModelError (or the chain's refusal)."""
    from drakegrasp.errors import InvalidOptionError, ModelError

    def run():
        try:
            return call()
        except dg.GraspError as e:
            text = str(e)
            degenerate = SAME_WAY in jaw["hostile"] or "no stroke" in jaw["hostile"]
            chained = isinstance(e, InvalidOptionError) and "lead and follow" in text
            if degenerate and not (isinstance(e, ModelError) or chained):
                raise _wrong(f"{type(e).__name__}: {text}", "ModelError") from None
            raise

    return run


def _wrong(text, want):
    from fuzz_cases import ValidRefused

    return ValidRefused(f"refused without a {want}: {text[:200]}")


def jaw_cases(box: Sandbox, seed: int, count: int) -> Iterator[Case]:
    rng = np.random.default_rng(seed)
    for i in range(count):
        jaw = draw_jaw(rng)
        c = jaw["coupling"]
        what = "uncoupled" if c is None else (
            f"{c['follower']} x{c['ratio']:g} +{c['offset']:g}" if c["kind"] == "direct"
            else f"chain via {c['via']} x{c['m1']:g}/x{c['m2']:g}"
        )  # fmt: skip
        flip = " flip" if jaw["flip"] else ""
        label = f"jaw#{i} {jaw['pad']} axis {jaw['axis']}{flip} {what}"
        if jaw["hostile"]:
            label += " [" + ", ".join(jaw["hostile"]) + "]"
        for route in ("plan", "cloud") if i % 2 == 0 else ("plan",):
            obj = pick(rng, OBJECTS)
            kwargs = {
                "num_candidates": int(pick(rng, (12, 20, 30))),
                "mu": pick(rng, (0.5, 0.8, 1.0)),
                "seed": int(rng.integers(1000)),
                "robustness_samples": 2,
                "certify": 0,
            }
            spec = {"jaw": jaw, "object": obj, "kwargs": kwargs}
            name = f"{label} {route} {obj}"
            if route == "plan" and rng.random() < 0.4:
                spec["object_pose"] = {
                    "p": [_u(rng, -0.6, 0.6) for _ in range(3)],
                    "rpy": [_u(rng, -3.1, 3.1) for _ in range(3)],
                }
                name += " moved"
            if route == "cloud":
                spec["points"], spec["cloud_seed"] = 1500, int(rng.integers(1000))
            fn = f"fuzz_jaws:jaw_{route}_case"
            call = _expect_refusal(jaw, lambda fn=fn, spec=spec: box.call(fn, spec))
            yield Case(f"jaw {route}", name, call, "either", jaw_right(jaw, route))


# ================================================================ limits

LINK_URDF = (
    '<link name="{0}"><inertial><mass value="0.1"/><inertia ixx="1e-5" '
    'iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>'
)
VALUES = (
    None, "0.5", "-0.5", "0.5", "-0.5", "0", "nan", "inf", "-inf", "abc", "",
    "0.5abc", " 0.5 ", "1_0", "0x1p-1", "1e17", "-1e17", "0.5 0.6",
)  # fmt: skip


def limits_doc(spec: dict) -> str:
    """A two-link model whose one joint carries the spec's limits."""
    lo, hi, kind = spec["lower"], spec["upper"], spec["joint"]
    if spec["format"] == "urdf":
        attrs = "".join(
            f' {k}="{v}"' for k, v in (("lower", lo), ("upper", hi)) if v is not None
        )
        return (
            f'<robot name="r">{LINK_URDF.format("a")}{LINK_URDF.format("b")}'
            f'<joint name="j" type="{kind}"><parent link="a"/><child link="b"/>'
            f'<axis xyz="0 1 0"/><limit{attrs} effort="1" velocity="1"/></joint>'
            "</robot>"
        )

    def limit(lo, hi):
        return (
            "<limit>"
            + "".join(
                f"<{k}>{v}</{k}>"
                for k, v in (("lower", lo), ("upper", hi))
                if v is not None
            )
            + "</limit>"
        )

    axis2 = ""
    if kind == "universal":
        axis2 = (
            f"<axis2><xyz>1 0 0</xyz>{limit(spec['lower2'], spec['upper2'])}</axis2>"
        )
    inertial = "<inertial><mass>0.1</mass></inertial>"
    return (
        f'<sdf version="1.9"><model name="m"><link name="a">{inertial}</link>'
        f'<link name="b">{inertial}</link><joint name="j" type="{kind}"><parent>a'
        f"</parent><child>b</child><axis><xyz>0 0 1</xyz>{limit(lo, hi)}</axis>"
        f"{axis2}</joint></model></sdf>"
    )


def _forked(fn) -> dict:
    """``fn()`` in a forked child: its outcome, or how the child died."""
    import json

    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: one answer, then out without cleanup
        os.close(r)
        try:
            out = {"kind": "value", "value": fn()}
        except dg.GraspError as e:
            out = {"kind": "grasp_error", "type": type(e).__name__, "message": str(e)}
        except BaseException as e:  # noqa: BLE001
            out = {"kind": "raw", "type": type(e).__name__, "message": str(e)[:300]}
        os.write(w, json.dumps(out).encode())
        os._exit(0)
    os.close(w)
    chunks = []
    while chunk := os.read(r, 65536):
        chunks.append(chunk)
    os.close(r)
    _, status = os.waitpid(pid, 0)
    if not chunks:
        return {"kind": "crash", "status": status}
    return json.loads(b"".join(chunks))


def _load(route: str, text: str, fmt: str, folder: Path):
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    from drakegrasp.plant.couplings import add_models

    if route == "drake":
        plant = MultibodyPlant(0.001)
        Parser(plant).AddModelsFromString(text, fmt)
        plant.Finalize()
        return True
    path = folder / f"hand.{fmt}"
    path.write_text(text)
    if route in ("text", "file"):
        plant = MultibodyPlant(0.001)
        parser = Parser(plant)
        try:
            if route == "text":
                add_models(parser, text=text, kind=fmt)
            else:
                add_models(parser, path)
        except RuntimeError as e:  # Drake's own parse error, passed on
            if "error" not in str(e):
                raise
            return {"drake_error": str(e)[:200]}
        plant.Finalize()
        return True
    if route == "hand_url":
        from drakegrasp.planning import planning_scene

        planning_scene(None, hand_url=str(path))
        return True
    from drakegrasp.plant.scene import load_scene

    (folder / "ball.sdf").write_text(
        '<sdf version="1.9"><model name="ball"><link name="body"><inertial><mass>'
        '0.1</mass></inertial><collision name="c"><geometry><sphere><radius>0.02'
        "</radius></sphere></geometry></collision></link></model></sdf>"
    )
    root = "a"
    (folder / "scene.yaml").write_text(
        f"directives:\n- add_model:\n    name: hand\n    file: hand.{fmt}\n"
        f"- add_weld:\n    parent: world\n    child: hand::{root}\n"
        "- add_model:\n    name: ball\n    file: ball.sdf\n"
        "drakegrasp:\n  object_body: ball::body\n  hand: hand\n  mu: 0.5\n"
    )
    load_scene(folder / "scene.yaml", allow_any_file=True)
    return True


def limits_case(spec: dict) -> dict:
    """Worker side: Drake's bare parse and the library's route, each in a fork."""
    text = limits_doc(spec)
    with tempfile.TemporaryDirectory(prefix="drakegrasp-fuzz-") as folder:
        drake = _forked(lambda: _load("drake", text, spec["format"], Path(folder)))
        lib = _forked(lambda: _load(spec["route"], text, spec["format"], Path(folder)))
    return {"drake": drake, "lib": lib}


def _raise_outcome(out: dict):
    import drakegrasp.errors as errors

    if out["kind"] == "value":
        return out["value"]
    if out["kind"] == "grasp_error":
        raise getattr(errors, out["type"], errors.GraspError)(out["message"])
    if out["kind"] == "crash":
        raise RuntimeError(f"the process died (wait status {out['status']}): a crash")
    raise RuntimeError(f"{out['type']}: {out['message']}")


def limits_call(box: Sandbox, spec: dict):
    from fuzz_cases import ValidRefused

    def call():
        CHECKED["limit documents"] += 1
        out = box.call("fuzz_jaws:limits_case", spec)
        drake, lib = out["drake"], out["lib"]
        if drake["kind"] == "value" and lib["kind"] == "grasp_error":
            raise ValidRefused(f"Drake loads it; refused: {lib['message'][:160]}")
        value = _raise_outcome(lib)
        if drake["kind"] != "value" and value is True:
            raise AssertionError(
                f"Drake {drake['kind']}: {drake.get('message', '')[:120]}"
            )
        return value

    return call


def _limit_pair(rng) -> tuple:
    r = rng.random()
    if r < 0.25:  # reversed plain numbers
        a, b = sorted(rng.uniform(-1, 1, 2))
        return repr(float(b)), repr(float(a)), "reversed"
    if r < 0.35:
        a = repr(float(rng.uniform(-1, 1)))
        return a, a, "equal"
    if r < 0.45:
        a, b = sorted(rng.uniform(-1, 1, 2))
        return repr(float(a)), repr(float(b)), "valid"
    return pick(rng, VALUES), pick(rng, VALUES), "pool"


def limits_cases(box: Sandbox, seed: int, count: int) -> Iterator[Case]:
    rng = np.random.default_rng(seed)
    for i in range(count):
        fmt = pick(rng, ("urdf", "sdf"))
        kinds = ("revolute", "prismatic", "continuous", "fixed")
        if fmt == "sdf":
            kinds += ("universal",)
        lo, hi, how = _limit_pair(rng)
        spec = {
            "format": fmt,
            "joint": pick(rng, kinds),
            "lower": lo,
            "upper": hi,
            "route": pick(rng, ("text", "file", "hand_url", "yaml")),
        }
        if spec["joint"] == "universal":
            spec["lower2"], spec["upper2"], _ = _limit_pair(rng)
        name = f"{fmt} {spec['joint']} [{lo!r}, {hi!r}] ({how}) via {spec['route']}#{i}"
        if spec["joint"] == "universal":
            name += f" axis2 [{spec['lower2']!r}, {spec['upper2']!r}]"
        yield Case("limits", name, limits_call(box, spec), "either")


CLI_SPECS = (
    ("urdf", "prismatic", "0.04", "0.0"),  # reversed
    ("sdf", "revolute", "nan", "1"),  # NaN
    ("urdf", "revolute", "0.5abc", "0.25"),  # a number with a tail
    ("urdf", "prismatic", "0.02", "0.02"),  # equal: loads, nothing to plan
)


def cli_case(spec: tuple, folder: Path):
    fmt, kind, lo, hi = spec

    def call():
        path = folder / f"hand_{abs(hash(spec))}.{fmt}"
        path.write_text(
            limits_doc({"format": fmt, "joint": kind, "lower": lo, "upper": hi})
        )
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([str(Path(__file__).resolve().parents[2]),
                                            env.get("PYTHONPATH", "")])  # fmt: skip
        run = subprocess.run(
            [sys.executable, "-m", "drakegrasp", "plan", "--hand", str(path),
             "--num", "5"],
            capture_output=True, text=True, timeout=80, env=env,
        )  # fmt: skip
        CHECKED["command lines"] += 1
        lines = [
            x
            for x in run.stderr.strip().splitlines()
            if not x.startswith("drakegrasp: ...")
        ]
        lines = [x for x in lines if "compiling the batch kernels" not in x]
        if run.returncode < 0 or "Failure at" in run.stderr:
            raise RuntimeError(
                f"exit {run.returncode}: "
                f"{' | '.join(run.stderr.strip().splitlines())[:200]}"
            )
        if run.returncode != 0:
            if len(lines) != 1 or not lines[0].startswith("drakegrasp: error: "):
                raise RuntimeError(f"exit {run.returncode}, stderr {lines[:4]!r}")
            raise dg.GraspError(lines[0])
        return run.stdout[-200:]

    return call


# ================================================================ passive joints


def draw_hand(rng) -> dict:
    """A multi-finger hand whose every joint's drive is drawn (see above)."""
    k = int(pick(rng, (2, 3, 3, 4)))
    fingers = []
    for f in range(k):
        yaw = 2 * math.pi * f / k + _u(rng, -0.2, 0.2)
        joints = {}
        names = ["proximal", "distal"] + (["spread"] if rng.random() < 0.3 else [])
        for j in names:
            d = pick(rng, ("motor", "motor", "mimic", "passive", "passive", "fixed"))
            if j == "proximal" and d == "mimic":
                d = "motor"
            joints[j] = d
        fingers.append({"yaw": yaw, "joints": joints,
                        "prismatic": bool(rng.random() < 0.15)})  # fmt: skip
    if rng.random() < 0.1:  # no motor anywhere
        for f in fingers:
            for j, d in f["joints"].items():
                if d == "motor":
                    f["joints"][j] = "passive"
    return {"fingers": fingers, "radius": _u(rng, 0.045, 0.06)}


def _order(f: dict) -> list[str]:
    return [j for j in ("spread", "proximal", "distal") if j in f["joints"]]


def passive_expected(hand: dict) -> set[str]:
    """Joints no motor moves (none in a hand without motors).

    One-dof joints with no transmission and no mimic, and the mimics of such
    a joint (a finger's mimic follows its proximal joint).
    """
    out = set()
    motors = any(d == "motor" for f in hand["fingers"] for d in f["joints"].values())
    if not motors:
        return out
    for i, f in enumerate(hand["fingers"]):
        leader = f["joints"].get("proximal")
        for j, d in f["joints"].items():
            if d == "passive" or (d == "mimic" and leader == "passive"):
                out.add(f"f{i}_{j}")
    return out


def hand_urdf(hand: dict) -> str:
    def link(name, xyz, shape):
        return (
            f'<link name="{name}"><inertial><origin xyz="{xyz}"/><mass value="0.05"/>'
            '<inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/>'
            f'</inertial><collision><origin xyz="{xyz}"/><geometry>{shape}</geometry>'
            "</collision></link>"
        )

    r = hand["radius"]
    parts = [
        link("palm", "0 0 -0.015", f'<cylinder radius="{r + 0.015!r}" length="0.03"/>')
    ]
    motors = []
    for i, f in enumerate(hand["fingers"]):
        c, s = math.cos(f["yaw"]), math.sin(f["yaw"])
        chain = ["palm"]
        for j in _order(f):
            body = f"f{i}_{j}_link"
            if j == "spread":
                parts.append(link(body, "0 0 0.004", '<sphere radius="0.004"/>'))
            else:
                parts.append(
                    link(body, "0 0 0.025", '<capsule radius="0.008" length="0.035"/>')
                )
            parent = chain[-1]
            if parent == "palm":
                xyz, rpy = f"{r * c!r} {r * s!r} 0", f"0 0 {f['yaw'] + math.pi!r}"
            else:
                xyz, rpy = (
                    ("0 0 0.008" if parent.endswith("spread_link") else "0 0 0.05"),
                    "0 0 0",
                )
            d = f["joints"][j]
            name = f"f{i}_{j}"
            if d == "fixed":
                parts.append(
                    f'<joint name="{name}" type="fixed"><parent link="{parent}"/>'
                    f'<child link="{body}"/><origin xyz="{xyz}" rpy="{rpy}"/></joint>'
                )
            else:
                kind = "prismatic" if f["prismatic"] and j == "spread" else "revolute"
                axis = "0 0 1" if j == "spread" else "0 1 0"
                lim = '<limit lower="-0.3" upper="1.5" effort="2" velocity="1"/>'
                if kind == "prismatic":
                    lim = '<limit lower="-0.01" upper="0.01" effort="2" velocity="1"/>'
                mimic = ""
                if d == "mimic":
                    mimic = (
                        f'<mimic joint="f{i}_proximal" multiplier="0.6" offset="0"/>'
                    )
                parts.append(
                    f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
                    f'<child link="{body}"/><origin xyz="{xyz}" rpy="{rpy}"/>'
                    f'<axis xyz="{axis}"/>'
                    f"{lim}{mimic}</joint>"
                )
                if d == "motor":
                    motors.append(name)
            chain.append(body)
    return (
        '<?xml version="1.0"?><robot name="fuzz_hand">'
        + "".join(parts)
        + transmissions(motors)
        + "</robot>"
    )


def passive_case(spec: dict) -> dict:
    """Worker side: ``passive_joints`` and the planner's warning."""
    from drakegrasp.planning import planning_scene
    from drakegrasp.planning.approach import multi_finger_hand
    from drakegrasp.planning.multifinger import PassiveJointWarning
    from drakegrasp.plant.fingers import passive_joints
    from drakegrasp.plant.validation import hand_bodies

    with tempfile.TemporaryDirectory(prefix="drakegrasp-fuzz-") as folder:
        path = Path(folder) / "hand.urdf"
        path.write_text(hand_urdf(spec["hand"]))
        url = f"package://drakegrasp/objects/{spec['object']}.sdf"
        scene = planning_scene(url, hand_url=str(path))
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    out = {}
    try:
        h = multi_finger_hand(plant, ctx, scene.object_body, scene.hand)
    except dg.GraspError as e:
        out["hand"] = f"{type(e).__name__}: {str(e)[:200]}"
    else:
        bodies = hand_bodies(plant, scene.object_body, scene.hand)
        out["passive"] = [j.name() for j in passive_joints(plant, bodies, h.structure)]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            dg.plan_grasps(
                plant, scene.context, scene.object_body, hand=scene.hand,
                num_candidates=3, mu=0.5, seed=spec["seed"], robustness_samples=1,
                certify=0,
            )  # fmt: skip
            out["planned"] = True
        except dg.GraspError as e:
            out["planned"] = f"{type(e).__name__}: {str(e)[:200]}"
    out["warnings"] = [
        str(w.message) for w in caught if issubclass(w.category, PassiveJointWarning)
    ]
    return out


def _warned_names(messages: list[str]) -> set[str]:
    names = set()
    for m in messages:
        found = re.match(r"no motor moves joint\(s\) (.*?) \(no actuator", m)
        if found:
            names |= {n.strip().split("::")[-1] for n in found.group(1).split(",")}
    return names


def passive_right(hand: dict):
    want = passive_expected(hand)

    def check(out: dict) -> bool:
        faults = []
        if "passive" in out:
            CHECKED["passive_joints"] += 1
            if set(out["passive"]) != want:
                faults.append(
                    f"passive_joints {sorted(out['passive'])}, want {sorted(want)}"
                )
        if out["planned"] is True or out["warnings"]:
            CHECKED["plans warned or not"] += 1
            if len(out["warnings"]) > 1:
                faults.append(f"{len(out['warnings'])} warnings")
            got = _warned_names(out["warnings"])
            if got != want:
                faults.append(f"warned of {sorted(got)}, want {sorted(want)}")
        if faults:
            raise AssertionError("; ".join(faults))
        return True

    return check


def passive_cases(box: Sandbox, seed: int, count: int) -> Iterator[Case]:
    rng = np.random.default_rng(seed)
    for i in range(count):
        hand = draw_hand(rng)
        spec = {
            "hand": hand,
            "object": pick(rng, OBJECTS),
            "seed": int(rng.integers(100)),
        }
        drives = ",".join(
            "/".join(f"{j[0]}:{d}" for j, d in f["joints"].items())
            for f in hand["fingers"]
        )
        name = f"hand#{i} {len(hand['fingers'])} fingers [{drives}] on {spec['object']}"
        yield Case(
            "passive", name, lambda s=spec: box.call("fuzz_jaws:passive_case", s),
            "either", passive_right(hand),
        )  # fmt: skip


# ================================================================ findings

FINDINGS: dict[str, str] = {}
"""Defects the families found, not fixed here (see :func:`finding`).

None now: J4 (a parallel jaw whose two slides both follow a hidden third
slide, the only motor, on a link without geometry, was refused as a hand of
3 fingers) is fixed, and ``test_j4_...`` keeps it so.  J1 to J3 were fixed
before it.
"""


def finding(family: str, name: str, outcome: str, detail: str) -> str | None:
    """The known finding (a key of :data:`FINDINGS`) a bad outcome shows, if any."""
    return None


# ================================================================ running

SIZES = {"jaws": 40, "limits": 150, "cli": len(CLI_SPECS), "passive": 30}


def run(sizes: dict | None = None):
    """(families' counters, bad cases, seconds per family) over every case."""
    sizes = SIZES if sizes is None else sizes
    folder = Path(tempfile.mkdtemp(prefix="drakegrasp-fuzz-cli-"))
    return run_family(
        lambda box: [
            *jaw_cases(box, 3001, sizes["jaws"]),
            *limits_cases(box, 3002, sizes["limits"]),
            *(
                Case("command line", f"plan --hand {s}", cli_case(s, folder), "either")
                for s in CLI_SPECS[: sizes["cli"]]
            ),
            *passive_cases(box, 3003, sizes["passive"]),
        ],  # fmt: skip
        lambda case: case.family != "command line",
    )


def main() -> int:
    """Print the outcome table, the known findings' cases and any other bad one."""
    return report_family(run, finding, FINDINGS, CHECKED, __doc__)


if __name__ == "__main__":
    sys.exit(main())
