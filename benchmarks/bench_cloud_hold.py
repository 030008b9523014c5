"""How often the Allegro hand's point-cloud grasps hold the YCB soup can.

Usage::

    python benchmarks/bench_cloud_hold.py [--num 600] [--points 3000] [--top 10]
        [--random 10] [--seed 0] [--clouds full one-sided] [--no-mass]
        [--effort-limit] [--noise MM] [--verbose]

The multi-finger cloud route of :func:`drakegrasp.plan_grasps` (Drake's
Allegro hand, thumb opposed, free base) on two clouds sampled from the soup
can's collision geometry (``--points`` area-uniform points, seed 0, as
``tests/planning/cloud_support.py`` samples them):

* **full**: every point, normals given;
* **one-sided**: the points a camera at ``(0.5, 0, 0)`` m sees (normals
  facing it), planned with ``viewpoint=`` the camera.

Both are planned with ``object_mass=`` the can's mass (from its model), as a
user who knows it would, and ``torque_limit=`` the shake's 0.5 N·m per joint
(per motor: each of the Allegro's joints is one), the torque the hand will
apply: the candidates then carry ``torque_needed`` and those held at that
torque are ranked first
(:func:`~drakegrasp.planning.motors.with_torques_needed`).
``--effort-limit`` ranks by the Allegro's effort limit (0.7 N·m) instead, as
before ``torque_limit`` existed; ``--no-mass`` plans without the mass (no
torque_needed, the score's order alone).  ``--noise MM`` moves the points
along their lines of sight by N(0, σ²), as ``bench_cloud_jaw.py --noise``
does, and estimates the normals from them.

For each cloud it prints the candidates (of ``--num`` sampled poses), how many
are force closure, and the hold rates in Drake
(:func:`drakegrasp.shake_test` on the true can, ``X_WO`` its real pose, the
Allegro's revolute fingers at 0.5 N·m, PD gains 20 N·m/rad and 1 N·m·s/rad)
of the ``--top`` best candidates and of ``--random`` candidates drawn
uniformly (seeded) from all of them, as held / tried.  ``--verbose`` prints
each shaken candidate's torque needed (N·m), largest displacement and
rotation, its contacts per finger and how many carry an edge's normal fan
(the planning guide's "Edges: the normal fan").

Measured (the ten best held out of ten, seeds 0, 1, 2, the seated shake
test; benchmarks/README.md has the rest): 600 samples, full 10, 8, 8 and
one-sided 9, 10, 8 (random 1, 1, 1 and 2, 1, 0).  At 300 samples, full 8, 4,
7 and one-sided 8, 6, 10.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

from drakegrasp.planning import object_surface, plan_grasps, planning_scene, shake_test

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_plan import drake_models  # noqa: E402  (the same local copy)

ALLEGRO = (
    "package://drake_models/allegro_hand_description/sdf/"
    "allegro_hand_description_right.sdf"
)
CAN = "package://drake_models/ycb/005_tomato_soup_can.sdf"
VIEW = np.array([0.5, 0.0, 0.0])
SHAKE = dict(squeeze=0.5, stiffness=20.0, damping=1.0)


def allegro_scene(models, object_url=None):
    """A planning scene with the Allegro hand (thumb opposed), the can optional."""
    scene = planning_scene(object_url, hand_url=ALLEGRO, models_dir=models)
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    scene.plant.GetJointByName("joint_12").set_angle(ctx, 1.0)
    return scene


def sample_cloud(full, n, seed=0, view=None):
    """``(points, normals)`` on the can, world frame; ``view``: the seen ones."""
    surface = object_surface(full.plant, full.context, full.object_body)
    p, nrm, _ = surface.sample(n, np.random.default_rng(seed))
    if view is not None:
        seen = np.sum(nrm * (np.asarray(view) - p), axis=1) > 0
        p, nrm = p[seen], nrm[seen]
    return p, nrm


def plan_cloud(hand, points, normals, view, *, num, seed, mass, **options):
    """``plan_grasps`` for ``hand`` (a planning scene) on a cloud, μ = 1.

    Returns the result and the seconds it took.
    """
    t = time.perf_counter()
    result = plan_grasps(
        hand.plant, hand.context, None, hand=hand.hand, num_candidates=num,
        mu=1.0, seed=seed, point_cloud=points, cloud_normals=normals,
        viewpoint=view, object_mass=mass, **options,
    )  # fmt: skip
    return result, time.perf_counter() - t


def noisy(points, view, sigma):
    """Points moved by N(0, σ²) along the line of sight (seed 0): a depth camera.

    A whole cloud (no view) is seen from afar along each point's own direction
    from the cloud's centre.
    """
    rng = np.random.default_rng(0)
    centre = points.mean(axis=0)
    eye = points - (centre if view is None else np.asarray(view, float))
    ray = eye / np.linalg.norm(eye, axis=1, keepdims=True)
    return points + rng.normal(0.0, sigma, len(points))[:, None] * ray


def camera_density(points, normals, view, seed=0):
    """The points a depth camera at ``view`` would keep: as many per area as it sees.

    A camera's pixels sample a face seen near or head-on more densely than
    one seen far or obliquely: ``cos θ / r²`` points per area (θ between the
    normal and the line of sight, ``r`` the distance).  Each point is kept
    with that density over the largest (seeded), from an area-uniform sample.
    """
    eye = np.asarray(view, float) - points
    r = np.linalg.norm(eye, axis=1)
    density = np.maximum(np.sum(normals * eye, axis=1), 0.0) / r**3
    keep = np.random.default_rng(seed).random(len(points)) < density / density.max()
    return points[keep], normals[keep]


def _describe(c, s) -> str:
    fingers = Counter(k.finger_body.split("::")[-1] for k in c.contacts)
    fans = sum(getattr(k, "fan", None) is not None for k in c.contacts)
    return (
        f"      #{c.sample:<4} score {c.score:8.4f} rho {c.robustness:4.2f} "
        f"torque {c.torque_needed:6.3f} "
        f"{'held' if s.held else 'fell'}: {s.max_displacement * 1e3:6.1f} mm "
        f"{np.degrees(s.max_rotation):6.1f} deg  contacts {dict(fingers)}"
        f" ({fans} with an edge fan)"
    )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--num", type=int, default=600)  # 300 leaves too few holders
    parser.add_argument("--points", type=int, default=3000)
    parser.add_argument("--top", type=int, default=10)
    parser.add_argument("--random", type=int, default=10)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--clouds", nargs="+", default=["full", "one-sided"],
        choices=["full", "one-sided"],
    )  # fmt: skip
    parser.add_argument(
        "--no-mass",
        action="store_true",
        help="plan without object_mass (no torque_needed, no motors-first ranking)",
    )
    parser.add_argument(
        "--effort-limit",
        action="store_true",
        help="rank by the actuators' effort limit, not the shake's squeeze",
    )
    parser.add_argument(
        "--noise",
        type=float,
        default=0.0,
        help="depth noise, mm (σ along each point's line of sight; normals "
        "then estimated from the points)",
    )
    parser.add_argument("--verbose", action="store_true")
    args = parser.parse_args(argv)
    models = drake_models()
    if models is None:
        print("drake_models not found (set DRAKEGRASP_DRAKE_MODELS)")
        return 1
    full = allegro_scene(models, CAN)
    hand = allegro_scene(models)
    full_ctx = full.plant.GetMyContextFromRoot(full.context)
    X_WO = full.plant.EvalBodyPoseInWorld(full_ctx, full.object_body)
    mass = None if args.no_mass else full.object_body.get_mass(full_ctx)
    # without the mass there is no torque_needed to rank by
    limit = None if args.effort_limit or mass is None else SHAKE["squeeze"]
    print(
        f"load {os.getloadavg()[0]:.2f}; Allegro on the YCB soup can, "
        f"{args.points} points, {args.num} samples, seed {args.seed}, "
        f"object_mass {mass}, torque_limit {limit}"
    )
    print(
        f"{'cloud':<10} {'points':>6} {'cands':>6} {'FC':>4} {'plan s':>7}"
        f" {'top':>6} {'random':>7} {'shake s':>8}"
    )
    for name in args.clouds:
        view = VIEW if name == "one-sided" else None
        p, nrm = sample_cloud(full, args.points, 0, view)
        if args.noise > 0:
            p, nrm = noisy(p, view, args.noise * 1e-3), None
        result, plan_s = plan_cloud(
            hand, p, nrm, view, num=args.num, seed=args.seed, mass=mass,
            torque_limit=limit,
        )  # fmt: skip
        pick = np.random.default_rng(args.seed).choice(
            len(result), size=min(args.random, len(result)), replace=False
        )
        top = list(result[: args.top])
        rand = [result[int(i)] for i in pick]
        t = time.perf_counter()
        shaken = []
        for group in (top, rand):
            shaken.append(
                [shake_test(full.add_models, c, X_WO=X_WO, **SHAKE) for c in group]
            )
        shake_s = time.perf_counter() - t
        held = [sum(s.held for s in g) for g in shaken]
        fc = sum(c.is_closure for c in result)
        print(
            f"{name:<10} {len(p):>6} {len(result):>6} {fc:>4} {plan_s:>7.1f}"
            f" {f'{held[0]}/{len(top)}':>6} {f'{held[1]}/{len(rand)}':>7}"
            f" {shake_s:>8.1f}",
            flush=True,
        )
        print(f"    rejections: {dict(result.rejections)}")
        if args.verbose:
            for label, group, shakes in (
                ("top", top, shaken[0]),
                ("random", rand, shaken[1]),
            ):
                print(f"    {label}:")
                for c, s in zip(group, shakes, strict=True):
                    print(_describe(c, s))
    return 0


if __name__ == "__main__":
    sys.exit(main())
