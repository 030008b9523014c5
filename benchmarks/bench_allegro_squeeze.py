"""Where the Allegro hand's squeeze pushes its planned grasps of YCB objects.

Usage::

    python benchmarks/bench_allegro_squeeze.py [--objects 004_sugar_box ...]
        [--num 150] [--top 10] [--mu 1.0] [--seed 0] [--squeeze 0.7]
        [--stiffness 10] [--damping 0.1]

For each object (Drake's ``drake_models`` YCB models; the folder is found as
the tests find it, ``DRAKEGRASP_DRAKE_MODELS`` or ``../shared/drake_models``),
plans Drake's Allegro right hand (thumb opposed, ``joint_12 = 1.0``) with
:func:`drakegrasp.plan_grasps` at ``--mu`` and shakes the ``--top`` best
candidates with :func:`drakegrasp.shake_test` at light-finger gains (each
closing joint pressing with ``--squeeze`` N·m within the hand's 0.7 N·m
effort limit, ``--stiffness`` N·m/rad, ``--damping`` N·m·s/rad).  It prints,
per candidate, the fingers its contacts are on (I, M, R: index, middle and
ring; T: thumb; P: the palm), whether it is force closure, its
``torque_needed``, where seating left the object (``seat_displacement``) and
how fast it still moved (``seat_speed``) before any gravity, how far it moved
from there under the turned gravity (``max_displacement_from_seat``,
``max_rotation_from_seat``), and whether the shake held it within 10 mm and
10° of the planned pose (``held``); then
the seat speeds of the candidates with and without the thumb.

The planning guide's paragraph on the shake test quotes this run
(objects 004_sugar_box, seed 0, ``--mu 1``, squeeze 0.7): seat speeds of 12
and 45 mm/s for the two best candidates, with the thumb; 170-530 mm/s for
the seven thumbless ones among the top 10 (the squeeze alone pushes them out
of the hand); 250 mm/s for a third with the thumb.  On the soup can
(``--objects 005_tomato_soup_can``) ``held`` is true for 2 of the top 10,
while 9 stay within 7.3 mm and 12.1° of where seating left them.  Timings are not
asserted anywhere: they depend on the machine.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_plan import drake_models  # noqa: E402  (the same local copy)

import drakegrasp as dg  # noqa: E402

ALLEGRO = (
    "package://drake_models/allegro_hand_description/sdf/"
    "allegro_hand_description_right.sdf"
)
FINGERS = {  # the Allegro right hand's links, by finger
    "I": ("link_0", "link_1", "link_2", "link_3"),
    "M": ("link_4", "link_5", "link_6", "link_7"),
    "R": ("link_8", "link_9", "link_10", "link_11"),
    "T": ("link_12", "link_13", "link_14", "link_15"),
}


def _finger_of(body: str) -> str:
    link = body.split("::")[-1]
    for finger, links in FINGERS.items():
        if any(link == name or link.startswith(name + "_") for name in links):
            return finger
    return "P"


def run(args: argparse.Namespace, models: Path) -> None:
    for obj in args.objects:
        scene = dg.planning_scene(
            f"package://drake_models/ycb/{obj}.sdf", hand_url=ALLEGRO, models_dir=models
        )
        ctx = scene.plant.GetMyContextFromRoot(scene.context)
        scene.plant.GetJointByName("joint_12").set_angle(ctx, 1.0)  # thumb opposed
        t0 = time.perf_counter()
        result = dg.plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=args.num, mu=args.mu, seed=args.seed,
        )  # fmt: skip
        print(
            f"{obj}: {len(result)} candidates of {args.num} samples at mu = "
            f"{args.mu:g} ({time.perf_counter() - t0:.1f} s)"
        )
        speeds: dict[bool, list[float]] = {True: [], False: []}
        for rank, c in enumerate(list(result)[: args.top]):
            fingers = "".join(sorted({_finger_of(k.finger_body) for k in c.contacts}))
            try:
                shake = dg.shake_test(
                    scene.add_models, c, squeeze=args.squeeze,
                    stiffness=args.stiffness, damping=args.damping,
                )  # fmt: skip
            except dg.GraspError as e:
                print(f"  #{rank:<3d} {fingers:5s} shake refused: {e}")
                continue
            speeds["T" in fingers].append(shake.seat_speed)
            tn = c.torque_needed
            print(
                f"  #{rank:<3d} sample {c.sample:<4d} {fingers:5s} "
                f"{'closure' if c.is_closure else 'no closure':10s} "
                f"torque needed {tn if tn is not None else float('nan'):6.2f} N·m  "
                f"seated {shake.seat_displacement * 1e3:5.1f} mm "
                f"{np.degrees(shake.seat_rotation):5.1f} deg "
                f"{shake.seat_speed * 1e3:6.1f} mm/s, then within "
                f"{shake.max_displacement_from_seat * 1e3:7.1f} mm "
                f"{np.degrees(shake.max_rotation_from_seat):6.1f} deg  "
                f"{'held' if shake.held else 'dropped'} (from the plan)"
            )
        for thumb, values in speeds.items():
            if values:
                print(
                    f"  seat speed {'with' if thumb else 'without'} the thumb: "
                    f"{len(values)} candidates, {1e3 * np.min(values):.0f}-"
                    f"{1e3 * np.max(values):.0f} mm/s"
                )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", nargs="+", default=["004_sugar_box"])
    parser.add_argument("--num", type=int, default=150)
    parser.add_argument("--top", type=int, default=10)
    parser.add_argument("--mu", type=float, default=1.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--squeeze", type=float, default=0.7)
    parser.add_argument("--stiffness", type=float, default=10.0)
    parser.add_argument("--damping", type=float, default=0.1)
    args = parser.parse_args(argv)
    models = drake_models()
    if models is None:
        print(
            "drake_models not found: set DRAKEGRASP_DRAKE_MODELS or put a copy at "
            "../shared/drake_models",
            file=sys.stderr,
        )
        return 1
    run(args, models)
    return 0


if __name__ == "__main__":
    sys.exit(main())
