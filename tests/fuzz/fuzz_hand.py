"""Generated hostile inputs for ``close_hand`` and the pose checks of the plant layer.

Both families use the shipped default scene (a parallel-jaw gripper and a
50 mm box, no download) in the sandbox worker, which keeps the scene and
resets its context before every case.  A case draws a random pre-shape
(fingers anywhere from inside the box to beyond their limits), a random box
pose (offsets, yaw, far away), a context (root, plant, another scene's,
unconnected, not a context) and hostile options (directions: NaN, inf, zero,
wrong length, complex, tiny or huge positive multiples; couplings: self,
``None``, complex, bare numbers, unknown joints; tolerances, counts, bodies,
hands).

Independent routes, computed in the worker from Drake's own queries:

* after ``close_hand``: Drake's signed distance of every (finger geometry,
  object geometry) pair, the joint limits read from the plant's joints and
  the context's positions: a touching finger is at ``0 <= ψ <= tol`` and
  Drake's distance equals its ψ, a finger that is not touching is farther
  than ``tol``, nothing penetrates, every joint is within its limits, and a
  positive multiple of a direction closes as the unit direction does;
* for the pose checks (``grasp_from_plant``): the penetrations Drake's
  distances show (deeper than ``tol``) and the limit violations the joints'
  limits show, pair for pair.

A refusal is judged too: a ``PenetrationError`` needs a penetration that
Drake's distances show, a limit error a joint outside its limits, an
``UnreachableError`` a context left as it was; any other refusal of a valid
input is counted as such.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
from fuzz_cases import Case, ValidRefused
from hostile import opaque, pick
from sandbox import Sandbox

import drakegrasp as dg
import drakegrasp.errors as errors

LEFT, RIGHT = "gripper::left_finger_joint", "gripper::right_finger_joint"
UPPER = 0.0425  # the fingers' upper limit, m; the box's faces are at 0.025
JOINT_TOL = 1e-8

# --------------------------------------------------------------- worker side

_CACHE: dict = {}


def _scene(key: str = "main"):
    if key not in _CACHE:
        s = dg.load_scene()
        _CACHE[key] = (s, s.context.Clone())
    s, root0 = _CACHE[key]
    s.context.SetTimeStateAndParametersFrom(root0)
    return s


def _set_pose(s, pose: dict) -> None:
    from pydrake.math import RigidTransform, RollPitchYaw

    plant, ctx = s.plant, s.plant_context
    q = plant.GetPositions(ctx)
    q[0], q[1] = pose["q"]
    plant.SetPositions(ctx, q)
    X = plant.EvalBodyPoseInWorld(ctx, s.object_body)
    dx, dy, dz, yaw = pose["box"]
    R = RollPitchYaw(0.0, 0.0, yaw).ToRotationMatrix().multiply(X.rotation())
    plant.SetFreeBodyPose(
        ctx, s.object_body, RigidTransform(R, X.translation() + [dx, dy, dz])
    )


def _distances(s) -> dict[str, float]:
    """Drake's smallest signed distance per hand body to the object."""
    from drake_distances import hand_object_distances  # tests/plant, on the path

    plant = s.plant
    query = plant.get_geometry_query_input_port().Eval(s.plant_context)
    out = {}
    for body, _, _, d in hand_object_distances(plant, query, s.hand, s.object_body):
        name = f"{plant.GetModelInstanceName(body.model_instance())}::{body.name()}"
        out[name] = min(out.get(name, math.inf), d)
    return out


def _limits(s) -> dict[str, list[float]]:
    plant = s.plant
    out = {}
    for name in (LEFT, RIGHT):
        j = plant.GetJointByName(name.split("::")[1], s.hand)
        out[name] = [j.position_lower_limits()[0], j.position_upper_limits()[0]]
    return out


def _context(s, which):
    if which == "root":
        return s.context
    if which == "plant":
        return s.plant_context
    if which == "foreign":
        return _CACHE["other"][0].context if "other" in _CACHE else _other().context
    if which == "unconnected":
        return s.plant.CreateDefaultContext()
    return which  # None, a string, a number: not a context


def _other():
    other = dg.load_scene()
    _CACHE["other"] = (other, other.context.Clone())
    return other


def _arg(s, value, default):
    return default if isinstance(value, str) and value == "default" else value


def _refusal(s, e, before) -> dict:
    after = s.plant.GetPositions(s.plant_context)
    return {
        "refused": type(e).__name__,
        "message": str(e),
        "context_changed": not np.array_equal(before, after),
        "distances": _distances(s),
    }


def close_case(spec: dict) -> dict:
    """Worker side: close the hand of the default scene; the oracle's data."""
    if spec["context"] == "foreign" and "other" not in _CACHE:
        _other()
    s = _scene()
    _set_pose(s, spec["pose"])
    plant = s.plant
    before = plant.GetPositions(s.plant_context).copy()
    kwargs = dict(spec["kwargs"])
    try:
        closure = dg.close_hand(
            plant,
            _context(s, spec["context"]),
            _arg(s, spec["object"], s.object_body),
            hand=_arg(s, spec["hand"], s.hand),
            **kwargs,
        )
    except dg.GraspError as e:
        return _refusal(s, e, before)
    dist = _distances(s)
    q_ctx = plant.GetPositions(s.plant_context)[closure.position_indices]
    out = {
        "q": closure.q.tolist(),
        "q_ctx": q_ctx.tolist(),
        "joints": list(closure.joints),
        "limits": _limits(s),
        "tol": closure.distance_tolerance,
        "fingers": [
            {
                "status": f.status,
                "psi": f.psi,
                "drake": min(dist[b] for b in f.bodies),
            }
            for f in closure.fingers
        ],
        "min_pair": min(dist.values()),
    }
    if spec.get("unit") is not None:  # the same start, the unit direction
        s = _scene()
        _set_pose(s, spec["pose"])
        kwargs["direction"] = spec["unit"]
        ref = dg.close_hand(plant, s.context, s.object_body, hand=s.hand, **kwargs)
        out["q_unit"] = ref.q.tolist()
    return out


def pose_case(spec: dict) -> dict:
    """Worker side: the pose check of ``grasp_from_plant``; the oracle's data."""
    if spec["context"] == "foreign" and "other" not in _CACHE:
        _other()
    s = _scene()
    _set_pose(s, spec["pose"])
    before = s.plant.GetPositions(s.plant_context).copy()
    try:
        data = dg.grasp_from_plant(
            s.plant,
            _context(s, spec["context"]),
            _arg(s, spec["object"], s.object_body),
            hand=_arg(s, spec["hand"], s.hand),
            mu=0.5,
            **spec["kwargs"],
        )
    except dg.GraspError as e:
        return _refusal(s, e, before)
    pose = data.pose
    return {
        "penetrations": sorted({p.hand_body for p in pose.penetrations}),
        "violations": sorted(v.joint for v in pose.joint_limit_violations),
        "distances": _distances(s),
        "limits": _limits(s),
        "num_contacts": data.grasp.num_contacts,
    }


# --------------------------------------------------------------- parent side


def _q_violations(q, limits) -> list[str]:
    return sorted(
        name
        for name, value in zip((LEFT, RIGHT), q, strict=True)
        if not limits[name][0] - JOINT_TOL <= value <= limits[name][1] + JOINT_TOL
    )


def _judge(out: dict, spec: dict, hostile: bool):
    """Raise a refusal as its GraspError when it is legitimate (see module doc)."""
    if "refused" not in out:
        return out
    if out["context_changed"]:
        return {"wrong": f"{out['refused']} changed the context: {out['message']}"}
    cls = getattr(errors, out["refused"], dg.GraspError)
    tol = spec["kwargs"].get("distance_tolerance", 1e-4)
    deepest = min(out["distances"].values())
    limits = {LEFT: [0.0, UPPER], RIGHT: [0.0, UPPER]}
    legit = (
        hostile
        or spec["far"]
        or (cls is dg.PenetrationError and deepest < -tol)
        or (
            issubclass(cls, dg.InvalidPoseError)
            and _q_violations(spec["pose"]["q"], limits)
        )
        or cls is dg.UnreachableError
        or (cls is dg.NoContactsError and deepest > tol)
    )
    if not legit:
        raise ValidRefused(f"{out['refused']}: {out['message']}")
    raise cls(out["message"])


def _closed_right(out: dict) -> bool:
    if "wrong" in out:
        return False
    tol, limits = out["tol"], out["limits"]
    if out["q"] != out["q_ctx"] or _q_violations(out["q"], limits):
        return False
    if out["min_pair"] < -tol:
        return False
    for f in out["fingers"]:
        if f["status"] == "touching":
            # |ψ| <= tol: a finger within tol of the surface at the pre-shape
            # (inside by less than the pose check's tol) touches where it is
            if not (-tol <= f["psi"] <= tol and abs(f["drake"] - f["psi"]) <= 1e-9):
                return False
        elif f["drake"] <= tol:
            return False
    if "q_unit" in out:
        return np.allclose(out["q"], out["q_unit"], rtol=0, atol=1e-9)
    return True


def _pose_right(out: dict, tol: float) -> bool:
    if "wrong" in out:
        return False
    pens = sorted(b for b, d in out["distances"].items() if d < -tol)
    return out["penetrations"] == pens and out["violations"] == []


_CONTEXTS = ("root", "plant", "foreign", "unconnected", None, "context", 7)
_OBJECTS = ("nope", 999, None, -1, 1.5, "gripper::palm", opaque())
_HANDS = ("nope", 99, [], [None], "box", 1j)
_COUPLINGS = (
    [(LEFT, LEFT, 1.0, 0.0)],
    [None],
    [1.5],
    [(LEFT, RIGHT, 1j, 0.0)],
    [(LEFT, "gripper::nope", 1.0, 0.0)],
    "couplings",
    [(LEFT, RIGHT, math.nan, 0.0)],
    [(LEFT, RIGHT, 1.0)],
    5,
)
_DIRECTIONS = (
    [math.nan, 1.0],
    [math.inf, -1.0],
    [1.0],
    [1.0, 1.0, 1.0],
    [1j, 1.0],
    "close",
    [None, 1.0],
    [[1.0, 1.0]],
)
_OPTIONS = {
    "distance_tolerance": (
        (1e-4, 1e-3, 5e-5),
        (math.nan, -1.0, 0.0, math.inf, "1e-4", None, 1j),
    ),
    "min_fingers": ((1, 2), (0, -1, 1.5, True, "1", None)),
    "max_iterations": ((1, 5, 100), (0, -1, 2.5, True, "9", None, math.inf)),
}


def _random_pose(rng, *, wild: bool) -> tuple[dict, bool]:
    """A pre-shape and box offset; ``far`` when beyond the resolvable range."""
    if wild:
        q = [float(rng.uniform(-0.01, 0.06)) for _ in range(2)]
    else:
        q = [float(rng.uniform(0.0262, UPPER)) for _ in range(2)]
    box = [float(rng.uniform(-0.004, 0.004)) for _ in range(3)] + [
        float(rng.uniform(-0.15, 0.15))
    ]
    far = False
    if wild and rng.random() < 0.15:
        box[int(rng.integers(3))] = float(pick(rng, (1e3, -1e6, 1e9, 1e12, 1e300)))
        far = max(abs(x) for x in box[:3]) > 4e8
    return {"q": q, "box": box}, far


def _draw_common(rng, spec: dict) -> str | None:
    """Maybe one hostile context, object, hand or option; its description."""
    r = rng.random()
    if r < 0.12:
        spec["context"] = pick(rng, _CONTEXTS[2:])
        return f"context={spec['context']!r}"
    if r < 0.2:
        spec["object"] = pick(rng, _OBJECTS)
        return f"object={spec['object']!r}"
    if r < 0.28:
        spec["hand"] = pick(rng, _HANDS)
        return f"hand={spec['hand']!r}"
    return None


def _spec(rng, pose, far, *, kwargs) -> dict:
    """A case on the default models at ``pose``, through a root or plant context."""
    return {
        "pose": pose,
        "far": far,
        "context": pick(rng, ("root", "plant")),
        "object": "default",
        "hand": "default",
        "kwargs": kwargs,
    }


def close_hand_cases(
    sandbox: Sandbox, seed: int = 215, count: int = 150
) -> Iterator[Case]:
    """Generated ``close_hand`` calls (see the module docstring)."""
    rng = np.random.default_rng(seed)
    for i in range(count):
        pose, far = _random_pose(rng, wild=rng.random() < 0.35)
        spec = _spec(rng, pose, far, kwargs={}) | {"unit": None}
        hostile = _draw_common(rng, spec)
        if hostile is None:
            r = rng.random()
            if r < 0.3:
                d0 = rng.normal(size=2)
                d0 /= np.linalg.norm(d0)
                s = float(10.0 ** rng.uniform(-300, 300))
                spec["kwargs"]["direction"] = (s * d0).tolist()
                spec["unit"] = d0.tolist()
                hostile = None
                name = f"direction {s:.1e} x unit"
            elif r < 0.45:
                spec["kwargs"]["direction"] = pick(rng, _DIRECTIONS)
                hostile = name = f"direction={spec['kwargs']['direction']!r}"
            elif r < 0.6:
                spec["kwargs"]["couplings"] = pick(rng, _COUPLINGS)
                hostile = name = f"couplings={spec['kwargs']['couplings']!r}"
            elif r < 0.68:
                spec["pose"]["q"][1] = spec["pose"]["q"][0]
                spec["kwargs"]["couplings"] = [(LEFT, RIGHT, 1.0, 0.0)]
                name = "coupled jaws"
            else:
                option = pick(rng, tuple(_OPTIONS))
                good, bad = _OPTIONS[option]
                if rng.random() < 0.5:
                    spec["kwargs"][option] = pick(rng, good)
                    name = f"{option}={spec['kwargs'][option]!r}"
                else:
                    spec["kwargs"][option] = pick(rng, bad)
                    hostile = name = f"{option}={spec['kwargs'][option]!r}"
        else:
            name = hostile
        expect = "refuse" if hostile else "either"

        def call(spec=spec, hostile=hostile is not None):
            return _judge(sandbox.call("fuzz_hand:close_case", spec), spec, hostile)

        yield Case(
            "close_hand",
            f"q={np.round(pose['q'], 4).tolist()} {name}#{i}",
            call,
            expect,
            None if hostile else _closed_right,
        )


def pose_cases(sandbox: Sandbox, seed: int = 216, count: int = 100) -> Iterator[Case]:
    """Generated pose checks through ``grasp_from_plant``."""
    rng = np.random.default_rng(seed)
    for i in range(count):
        pose, far = _random_pose(rng, wild=True)
        # the fingers near the box's faces: touching, penetrating or apart
        pose["q"] = [float(0.025 + rng.uniform(-0.004, 0.004)) for _ in range(2)]
        if rng.random() < 0.3:
            pose["q"][int(rng.integers(2))] = float(pick(rng, (-0.003, 0.05, 0.07)))
        spec = _spec(rng, pose, far, kwargs={"allow_penetration": True})
        hostile = _draw_common(rng, spec)
        r = rng.random()
        if hostile is None and r < 0.2:
            spec["kwargs"] = {}  # refuse impossible poses (the default)
        elif hostile is None and r < 0.4:
            spec["kwargs"] = {"check_pose": False}  # report them instead
        elif hostile is None and r < 0.5:
            good, bad = _OPTIONS["distance_tolerance"]
            value = pick(rng, bad if rng.random() < 0.5 else good)
            spec["kwargs"]["distance_tolerance"] = value
            if value in bad:
                hostile = f"distance_tolerance={value!r}"
        elif hostile is None and r < 0.6:
            flag = pick(rng, ("allow_penetration", "check_pose"))
            spec["kwargs"][flag] = pick(rng, (1, "yes", None, 0.0))
            hostile = f"{flag}={spec['kwargs'][flag]!r}"
        tol = spec["kwargs"].get("distance_tolerance", 1e-4)
        limits_broken = bool(
            _q_violations(pose["q"], {LEFT: [0, UPPER], RIGHT: [0, UPPER]})
        )
        expect = "refuse" if hostile or far else "either"

        def call(spec=spec, hostile=hostile is not None):
            return _judge(sandbox.call("fuzz_hand:pose_case", spec), spec, hostile)

        def right(out, tol=tol, broken=limits_broken, q=pose["q"]):
            if "wrong" in out:
                return False
            want = _q_violations(q, out["limits"])
            pens = sorted(b for b, d in out["distances"].items() if d < -tol)
            return out["penetrations"] == pens and out["violations"] == want

        yield Case(
            "pose validation",
            f"q={np.round(pose['q'], 4).tolist()} "
            f"box={np.round(pose['box'], 4).tolist()} {hostile or ''}#{i}",
            call,
            expect,
            None if expect == "refuse" else right,
        )
