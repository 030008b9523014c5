"""A parallel jaw's squeeze_needed against Drake: held counts by squeeze.

Usage::

    python benchmarks/bench_jaw_squeeze.py [--hand franka]
        [--objects 004_sugar_box 005_tomato_soup_can 003_cracker_box]
        [--num 300] [--top 6] [--factors 0.5 0.8 1 1.5]

Plans the hand on each object (``plan_grasps``, ``--num`` samples, seed 0)
at the plant's friction (the smallest of ``hand_object_friction``: what
Drake simulates), then
shakes each of the ``--top`` best with :func:`drakegrasp.shake_test` squeezing
at each factor times its own ``squeeze_needed``, capped by the fingers' effort
limit (the shake test applies no more).  It prints, per factor, which
candidates held (counted from the seat) as a row of 1s and 0s, and how many.

``franka`` (Drake's Franka hand, 20 N fingers) and ``wsg`` need Drake's
``drake_models`` (``DRAKEGRASP_DRAKE_MODELS`` or ``../shared/drake_models``);
``rounded`` is drakegrasp's own jaw.  The figures quoted in
``drakegrasp.planning.motors`` and the planning guide come from the default
run (Franka hand, mu = 1, 18 candidates: at 0.5, 0.8, 1 and 1.5 times, 0, 1,
11 and 16 held; the two cracker-box candidates that drop at every squeeze
need 21.7 N and 22.7 N, more than the fingers' 20 N).  Timings
are not asserted anywhere.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_plan import drake_models, object_url  # noqa: E402

import drakegrasp as dg  # noqa: E402
from drakegrasp.planning.motors import motor_limit  # noqa: E402
from drakegrasp.plant.friction import hand_object_friction  # noqa: E402

HANDS = {
    "franka": "package://drake_models/franka_description/urdf/panda_hand.urdf",
    "wsg": "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf",
    "rounded": "package://drakegrasp/hands/parallel_jaw.sdf",
}


def run(args: argparse.Namespace, models: Path | None) -> None:
    if args.hand != "rounded" and models is None:
        print(f"{args.hand}: left out (no drake_models)")
        return
    totals = dict.fromkeys(args.factors, 0)
    shaken = 0
    for obj in args.objects:
        if obj.startswith("0") and models is None:
            print(f"{obj}: left out (no drake_models)")
            continue
        scene = dg.planning_scene(
            object_url(obj), hand_url=HANDS[args.hand], models_dir=models
        )
        mu = float(
            hand_object_friction(
                scene.plant, scene.context, scene.object_body, scene.hand
            ).min()
        )
        result = dg.plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=args.num, mu=mu, seed=0,
        )  # fmt: skip
        top = list(result[: args.top])
        limit = motor_limit(scene.plant, top[0]) if top else float("inf")
        need = [c.squeeze_needed for c in top]
        print(
            f"{args.hand} on {obj}: mu {mu:g}, effort limit {limit:g} N, "
            f"squeeze_needed of the top {len(top)}: "
            + ", ".join(f"{n:.1f}" for n in need)
            + (f"; {result.reason}" if result.reason else "")
        )
        shaken += len(top)
        for factor in args.factors:
            t0 = time.perf_counter()
            held = [
                int(
                    dg.shake_test(
                        scene.add_models, c, squeeze=min(limit, factor * n)
                    ).held_from_seat
                )
                for c, n in zip(top, need, strict=True)
            ]
            totals[factor] += sum(held)
            print(
                f"  {factor:4g} x  held {held}  {sum(held)}/{len(held)}  "
                f"[{time.perf_counter() - t0:.1f} s]"
            )
    for factor, n in totals.items():
        print(f"all objects, {factor:g} x squeeze_needed: {n} of {shaken} held")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hand", default="franka", choices=sorted(HANDS))
    parser.add_argument(
        "--objects",
        nargs="+",
        default=["004_sugar_box", "005_tomato_soup_can", "003_cracker_box"],
    )
    parser.add_argument("--num", type=int, default=300)
    parser.add_argument("--top", type=int, default=6)
    parser.add_argument(
        "--factors", type=float, nargs="+", default=[0.5, 0.8, 1.0, 1.5]
    )
    args = parser.parse_args(argv)
    run(args, drake_models())
    return 0


if __name__ == "__main__":
    sys.exit(main())
