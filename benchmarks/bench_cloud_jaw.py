"""How often the WSG-50's point-cloud grasps hold YCB objects.

Usage::

    python benchmarks/bench_cloud_jaw.py [--objects NAME ...]
        [--views full side oblique] [--num 600] [--points 3000] [--top 10]
        [--random 10] [--seed 0] [--margin 1.2] [--firm 5] [--noise MM]
        [--camera] [--verbose]

The parallel-jaw cloud route of :func:`drakegrasp.plan_grasps` (Drake's WSG-50,
free base, μ = 1, the models' friction) on clouds sampled from each object's
collision geometry (``--points`` area-uniform points, seed 0, as
``tests/planning/cloud_support.py`` samples them), with ``object_mass=`` the
object's mass:

* **full**: every point, normals given;
* **side**: the points a camera at ``(0.5, 0, 0)`` m sees (a box shows one face
  head-on: its depth is unknown, and nothing is planned, with the reason);
* **oblique**: the points a camera at ``(0.4, 0.25, 0.3)`` m sees (three faces
  of a box).

``--camera`` thins a one-sided cloud to the density a depth camera samples it
with (``cos θ / r²`` points per area: faces seen near or head-on crowd;
``bench_cloud_hold.camera_density``); ``--points`` is then the area-uniform
sample it thins (12,000 leave about 3,000 of a box seen obliquely).

One-sided clouds are planned with ``viewpoint=`` the camera: the unseen side is
completed by point symmetry and O sits at the centre of symmetry.  For each
cloud it prints the candidates (of ``--num`` sampled poses), how many are force
closure, and the hold rates in Drake (:func:`drakegrasp.shake_test` on the true
object at its true pose) of the ``--top`` best and of ``--random`` candidates
drawn uniformly (seeded), at the *predicted* squeeze (``--margin`` times the
largest ``squeeze_needed`` of the best) and at a *firm* one (``--firm`` times
the object's weight), as held / tried.

Measured (seeds 0 / 1; benchmarks/README.md has the table): the ten best held
10 / 10 on every box cloud and 10 / 10, 9 / 10, 10 / 10 on the can's whole,
side and oblique clouds at the predicted squeeze; ten random 1-4.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

from drakegrasp.planning import planning_scene, shake_test

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_cloud_hold import (  # noqa: E402  (the same clouds)
    camera_density,
    noisy,
    plan_cloud,
    sample_cloud,
)
from bench_plan import YCB, drake_models  # noqa: E402  (the same local copy)

CAMERA_NOTE = ", thinned to a depth camera's density"
VIEWS = {"full": None, "side": (0.5, 0.0, 0.0), "oblique": (0.4, 0.25, 0.3)}


def _held(group, full, X_WO, squeeze):
    return [shake_test(full.add_models, c, X_WO=X_WO, squeeze=squeeze) for c in group]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", nargs="+", default=list(YCB), choices=YCB)
    parser.add_argument(
        "--views", nargs="+", default=list(VIEWS), choices=list(VIEWS)
    )  # fmt: skip
    parser.add_argument("--num", type=int, default=600)
    parser.add_argument("--points", type=int, default=3000)
    parser.add_argument("--top", type=int, default=10)
    parser.add_argument("--random", type=int, default=10)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--margin", type=float, default=1.2)
    parser.add_argument("--firm", type=float, default=5.0)
    parser.add_argument(
        "--noise",
        type=float,
        default=0.0,
        help="depth noise, mm (σ along each point's line of sight; normals "
        "then estimated from the points, as read_cloud does)",
    )
    parser.add_argument(
        "--camera",
        action="store_true",
        help="thin one-sided clouds to a depth camera's density (cos θ / r²)",
    )
    parser.add_argument("--verbose", action="store_true")
    args = parser.parse_args(argv)
    models = drake_models()
    if models is None:
        print("drake_models not found (set DRAKEGRASP_DRAKE_MODELS)")
        return 1
    hand = planning_scene(None, models_dir=models)
    print(
        f"load {os.getloadavg()[0]:.2f}; WSG-50 on point clouds, {args.points} "
        f"points{CAMERA_NOTE if args.camera else ''}, "
        f"{args.num} samples, seed {args.seed}"
    )
    print(
        f"{'object':<20} {'view':<8} {'points':>6} {'cands':>6} {'FC':>4}"
        f" {'plan s':>7} {'pred N':>7} {'top':>6} {'random':>7}"
        f" {'firm N':>7} {'top':>6} {'random':>7}"
    )
    for name in args.objects:
        url = f"package://drake_models/ycb/{name}.sdf"
        full = planning_scene(url, models_dir=models)
        ctx = full.plant.GetMyContextFromRoot(full.context)
        X_WO = full.plant.EvalBodyPoseInWorld(ctx, full.object_body)
        mass = full.object_body.get_mass(ctx)
        weight = mass * 9.81
        for view_name in args.views:
            view = VIEWS[view_name]
            p, nrm = sample_cloud(full, args.points, 0, view)
            if args.camera and view is not None:
                p, nrm = camera_density(p, nrm, view)
            if args.noise > 0:
                p, nrm = noisy(p, view, args.noise * 1e-3), None
            result, plan_s = plan_cloud(
                hand, p, nrm, view, num=args.num, seed=args.seed, mass=mass
            )
            fc = sum(c.is_closure for c in result)
            head = f"{name:<20} {view_name:<8} {len(p):>6} {len(result):>6} {fc:>4}"
            if not len(result):
                print(f"{head} {plan_s:>7.1f}  none: {result.reason}", flush=True)
                continue
            top = list(result[: args.top])
            pick = np.random.default_rng(args.seed).choice(
                len(result), size=min(args.random, len(result)), replace=False
            )
            rand = [result[int(i)] for i in pick]
            needed = [c.squeeze_needed for c in top if np.isfinite(c.squeeze_needed)]
            row = f"{head} {plan_s:>7.1f}"
            shaken = {}
            for label, q in (
                ("predicted", args.margin * max(needed, default=0.0)),
                ("firm", args.firm * weight),
            ):
                if q <= 0:
                    row += f" {'-':>7} {'-':>6} {'-':>7}"
                    continue
                shaken[label] = (_held(top, full, X_WO, q), _held(rand, full, X_WO, q))
                held = [sum(s.held for s in g) for g in shaken[label]]
                row += (
                    f" {q:>7.2f} {f'{held[0]}/{len(top)}':>6}"
                    f" {f'{held[1]}/{len(rand)}':>7}"
                )
            print(row, flush=True)
            if args.verbose and "predicted" in shaken:
                for c, s in zip(top, shaken["predicted"][0], strict=True):
                    print(
                        f"      #{c.sample:<4} score {c.score:7.4f} squeeze_needed "
                        f"{c.squeeze_needed:6.2f} N, {len(c.contacts)} contacts: "
                        f"{'held' if s.held else 'fell'} "
                        f"{s.max_displacement * 1e3:6.1f} mm "
                        f"{np.degrees(s.max_rotation):6.1f} deg"
                    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
