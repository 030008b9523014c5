"""Flat pads in Drake's point contact and as hydroelastic patches.

Usage::

    python benchmarks/bench_pad_contact.py [--hands flat rounded wsg]
        [--objects box cylinder] [--num 300] [--top 6] [--mu 0.5]
        [--squeeze 20 0.5] [--modulus 1e6]

Plans each hand on each object (``plan_grasps``, ``--num`` samples, seed 0,
``--mu``) and shakes the ``--top`` best with
:func:`drakegrasp.shake_candidates` twice per squeeze: with the models' own
contact (Drake's point contact: one point per pair of geometries) and with
hydroelastic fingers (``hydroelastic_modulus=--modulus``).  It prints how
many held, the largest displacement and rotation among them, the range of
rotations of those that dropped, the planner's ``squeeze_needed`` for the top
candidates and the wall time of each run.  ``wsg`` needs Drake's
``drake_models`` (``DRAKEGRASP_DRAKE_MODELS`` or ``../shared/drake_models``;
left out without it).

The figures quoted in ``drakegrasp.plant.hydroelastic``, the planning guide and
the command line's defaults come from the default run (flat jaw on the box,
top 6, 20 N: 1 held with point contact, 6 with hydroelastic pads; at 0.5 N
none).  Timings are not asserted anywhere: they depend on the machine.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_plan import drake_models, object_url  # noqa: E402

import drakegrasp as dg  # noqa: E402

HANDS = {
    "flat": "package://drakegrasp/hands/parallel_jaw_flat.sdf",
    "rounded": "package://drakegrasp/hands/parallel_jaw.sdf",
    "wsg": "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf",
}


def _summary(ranked) -> str:
    held = [s.result for s in ranked if s.held]
    dropped = [s.result for s in ranked if s.result is not None and not s.held]
    text = f"held {len(held)}/{len(ranked)}"
    if held:
        text += (
            f" (within {1e3 * max(r.max_displacement for r in held):.1f} mm, "
            f"{np.degrees(max(r.max_rotation for r in held)):.1f} deg)"
        )
    if dropped:
        turns = [np.degrees(r.max_rotation) for r in dropped]
        text += f"; dropped turned {min(turns):.0f}-{max(turns):.0f} deg"
    return text


def run(args: argparse.Namespace, models: Path | None) -> None:
    for hand in args.hands:
        if hand == "wsg" and models is None:
            print("wsg: left out (no drake_models)")
            continue
        for obj in args.objects:
            scene = dg.planning_scene(
                object_url(obj), hand_url=HANDS[hand], models_dir=models
            )
            result = dg.plan_grasps(
                scene.plant, scene.context, scene.object_body, hand=scene.hand,
                num_candidates=args.num, mu=args.mu, seed=0,
            )  # fmt: skip
            need = np.array([c.squeeze_needed for c in result[: args.top]])
            known = need[np.isfinite(need)]
            print(
                f"{hand} on {obj}: {len(result)} candidates; squeeze_needed of the "
                f"top {len(need)}: "
                + (
                    f"{known.min():.2f}-{known.max():.2f} N"
                    if known.size
                    else "not computed"
                )
            )
            for squeeze in args.squeeze:
                for label, modulus in (("point", None), ("hydroelastic", args.modulus)):
                    t0 = time.perf_counter()
                    ranked = dg.shake_candidates(
                        scene.add_models, result, top=args.top, squeeze=squeeze,
                        hydroelastic_modulus=modulus,
                    )  # fmt: skip
                    print(
                        f"  {squeeze:5g} N  {label:12s} {_summary(ranked)}  "
                        f"[{time.perf_counter() - t0:.1f} s]"
                    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hands", nargs="+", default=["flat"], choices=sorted(HANDS))
    parser.add_argument("--objects", nargs="+", default=["box"])
    parser.add_argument("--num", type=int, default=300)
    parser.add_argument("--top", type=int, default=6)
    parser.add_argument("--mu", type=float, default=0.5)
    parser.add_argument("--squeeze", type=float, nargs="+", default=[20.0, 0.5])
    parser.add_argument("--modulus", type=float, default=1e6)
    args = parser.parse_args(argv)
    run(args, drake_models())
    return 0


if __name__ == "__main__":
    sys.exit(main())
