"""Generated hostile inputs for ``GraspMonitor``: options, contexts and states.

The sandbox worker builds the simulated pick of ``tests/systems/pick_support``
once (the shipped parallel-jaw gripper over a box, a monitor wired in) and
then, per case, either

* constructs another monitor on that plant with one option drawn from a pool
  of valid and hostile values (periods, offsets, characteristic lengths,
  flags, friction, tolerances, thresholds, bodies, hands); a valid option
  must be taken as given (the monitor's ``period``/``offset`` read back);
* evaluates the pick's monitor on a random state (fingers from inside the box
  to wide open, the box shifted and turned, random velocities) fed to its
  input ports, possibly with NaN or ±inf at a random index, or with a foreign
  or wrong context.

Independent routes for an evaluated sample: Drake's signed distances of every
(hand geometry, box geometry) pair at that state: no pair within the
tolerance means "no contact", a pair deeper than it means "invalid" (an
impossible pose); and for "ok" the force-closure verdict of the sample's
contacts by ``fuzz_oracles.closure_verdict`` (an LP written with scipy).  A
non-finite state must be an "invalid" sample naming the index.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import fuzz_oracles as oracle
import numpy as np
from fuzz_cases import Case
from hostile import opaque, pick
from sandbox import Sandbox

from drakegrasp import HoldingThresholds

BOX = "box::box"
TOL = 1e-3  # the pick's monitor's distance tolerance, m
_PICK = []


def _pick():
    if not _PICK:
        from pick_support import build_pick  # tests/systems, on the path

        p = build_pick(mu=0.5, distance_tolerance=TOL)
        _PICK.append((p, p.simulator.get_context().Clone()))
    return _PICK[0]


def construct(options: dict) -> dict:
    """Worker side: a second monitor on the pick's plant with ``options``."""
    from drakegrasp.systems.monitor import GraspMonitor

    p, _ = _pick()
    kwargs = {"object_body": BOX, "mu": 0.5, **options}
    if kwargs.get("object_body") == "box object":
        kwargs["object_body"] = p.plant.GetBodyByName("box", p.box)
    m = GraspMonitor(p.plant, **kwargs)
    return {"period": m.period}


def evaluate(state: dict) -> dict:
    """Worker side: the pick's monitor on one state; the oracle's data."""
    from drake_distances import hand_object_distances  # tests/plant, on the path
    from pydrake.math import RigidTransform, RollPitchYaw

    p, root0 = _pick()
    plant, sg = p.plant, p.scene_graph
    root = root0.Clone()
    ctx = plant.GetMyMutableContextFromRoot(root)
    for name, q in zip(
        ("left_finger_joint", "right_finger_joint"), state["q"], strict=True
    ):
        plant.GetJointByName(name, p.gripper).set_translation(ctx, q)
    box = plant.GetBodyByName("box", p.box)
    dx, dy, dz, yaw = state["box"]
    plant.SetFreeBodyPose(
        ctx, box, RigidTransform(RollPitchYaw(0, 0, yaw), [dx, dy, 0.05 + dz])
    )
    v = np.asarray(state["v"], dtype=float)
    plant.SetVelocities(ctx, v[: plant.num_velocities()])
    query = sg.get_query_output_port().Eval(sg.GetMyContextFromRoot(root))
    x = plant.GetPositionsAndVelocities(ctx)
    if state["bad"] is not None:
        x[state["bad"][0] % len(x)] = state["bad"][1]
    own = p.monitor.CreateDefaultContext()
    p.monitor.get_plant_state_input_port().FixValue(own, x)
    p.monitor.get_query_object_input_port().FixValue(own, query)
    which = state["context"]
    context = {
        "own": own,
        "root": root,
        "plant": ctx,
        "string": "context",
        "none": None,
    }.get(which, own)
    sample = p.monitor.evaluate(context)
    deepest = min(
        (d for *_, d in hand_object_distances(plant, query, p.gripper, box)),
        default=math.inf,
    )
    out = {
        "status": sample.status,
        "message": sample.message,
        "deepest": deepest,
        "closure": None,
        "n": len(x),
    }
    if sample.report is not None:
        g = sample.report.data.grasp
        out["closure"] = bool(sample.report.is_force_closure)
        out["positions"] = np.asarray(g.positions).tolist()
        out["normals"] = np.asarray(g.normals).tolist()
        out["mus"] = [float(c.mu) for c in g.contacts]
    return out


def _sample_right(out: dict, bad) -> bool:
    if bad is not None:
        i = bad[0] % out["n"]
        return out["status"] == "invalid" and f"[{i}]" in out["message"]
    deepest, status = out["deepest"], out["status"]
    if deepest > TOL:
        return status == "no contact"
    if -deepest > HoldingThresholds().max_penetration:  # no grip to judge
        return status == "invalid" and "penetrate" in out["message"]
    if status != "ok":
        # a graze; or, as a monitor allows penetration by default (a
        # simulation's contacts penetrate to make their force), contacts
        # that separate faster than the separation speed
        separating = "separating faster" in out["message"]
        return status == "no contact" and (deepest > -TOL or separating)
    truth = oracle.closure_verdict(out["positions"], out["normals"], out["mus"])
    return truth is None or truth[0] == out["closure"]


_OPTIONS = {
    "period": (
        (0.05, 1, 1e-3, 2.5),
        (None, "0.05", 0.05j, [0.05], True, math.nan, -1, 1e-300, 0.0),
    ),
    "offset": ((0.0, 0.01, 3), (None, "0", 1j, math.inf, -1.0, math.nan)),
    "characteristic_length": (
        (None, 0.05, 1.0),
        (-1, 0, math.nan, "1", True, math.inf),
    ),
    "compute_epsilon": ((True, False), (1, 0, "yes", None, [True])),
    "check_pose": ((True, False), (1, "no", None)),
    "allow_penetration": ((True, False), (1.0, "yes")),
    "mu": ((0.5, 0.1, "plant"), (math.nan, -0.5, "steel", 1j, [0.5])),
    "distance_tolerance": ((1e-3, 1e-4), (0.0, -1e-3, math.nan, "1e-3", None)),
    "object_body": ((BOX, "box object"), ("nope", 17, None, opaque(), 1.5)),
    "hand": (("parallel_jaw",), ("nope", 99, "box", [None])),
    "holding": ((None,), ({"risk": 0.5}, "strict", 3)),
}


def monitor_cases(
    sandbox: Sandbox, seed: int = 218, count: int = 120
) -> Iterator[Case]:
    """Generated GraspMonitor cases (see the module docstring)."""
    rng = np.random.default_rng(seed)
    for i in range(count):
        if i % 2 == 0:
            option = pick(rng, tuple(_OPTIONS))
            good, bad = _OPTIONS[option]
            valid = rng.random() < 0.4
            value = pick(rng, good if valid else bad)

            def same(out, option=option, value=value):
                if option == "period":
                    return out[option] == float(value)
                return True

            yield Case(
                "GraspMonitor",
                f"GraspMonitor({option}={value!r})#{i}",
                lambda o={option: value}: sandbox.call("fuzz_monitor:construct", o),
                "answer" if valid else "refuse",
                same if valid else None,
            )
            continue
        state = {
            "q": [float(rng.uniform(0.018, 0.04)) for _ in range(2)],
            "box": [float(rng.uniform(-0.004, 0.004)) for _ in range(3)]
            + [float(rng.uniform(-0.2, 0.2))],
            "v": rng.normal(scale=0.05, size=9).tolist(),
            "bad": None,
            "context": "own",
        }
        r = rng.random()
        if r < 0.25:
            state["bad"] = [
                int(rng.integers(-19, 19)),
                pick(rng, (math.nan, math.inf, -math.inf)),
            ]
        elif r < 0.4:
            state["context"] = pick(rng, ("root", "plant", "string", "none"))
        expect = "refuse" if state["context"] != "own" else "answer"
        yield Case(
            "GraspMonitor",
            f"evaluate q={np.round(state['q'], 4).tolist()} bad={state['bad']} "
            f"context={state['context']}#{i}",
            lambda s=state: sandbox.call("fuzz_monitor:evaluate", s),
            expect,
            (lambda out, b=state["bad"]: _sample_right(out, b))
            if expect == "answer"
            else None,
        )
