"""The shake test's default squeeze on revolute hands: 20 N at the contacts
against 20 N·m on every joint.

Usage::

    python benchmarks/bench_default_squeeze.py [--objects box sugar_box soup_can]
        [--efforts 1000 5] [--top 6] [--num 60]

The hand is the test suite's one-motor pinch (``tests/support/coupled_hands.py``:
two revolute knuckles and their upright pads on one motor, the right knuckle
and both pads ``<mimic>`` followers), with the inner knuckles a Robotiq
2F-85's URDF hangs from the palm, at each ``--efforts`` limit (N·m).  Each is
planned on each object (``plan_grasps``, ``--num`` samples, seed 0, mu 0.5,
the object's mass) and its ``--top`` best are shaken in Drake
(``shake_test``, hydroelastic pads of 1e6 Pa) twice: at the default squeeze
(None: 20 N with which each pad presses, the motor aimed at the torque its
lever arms give, :mod:`drakegrasp.planning.squeeze`) and at ``squeeze=20``
(the old default: 20 N·m per joint, 120 N·m at the motor of six joints,
within its effort limit).  It prints, per run, how many held (from the
seat), the largest displacement, and what the motor pressed with once the
fingers had seated (``ShakeResult.efforts``).  The YCB objects need
Drake's ``drake_models`` (``DRAKEGRASP_DRAKE_MODELS`` or
``../shared/drake_models``; left out without it).

The planning guide's figures for the pinch come from the default run.
Timings are not asserted anywhere.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests" / "support"))
from bench_pinch import OBJECTS  # noqa: E402  (the pinch's objects, by name)
from bench_plan import drake_models  # noqa: E402
from coupled_hands import one_motor_pinch_urdf  # noqa: E402

import drakegrasp as dg  # noqa: E402


def _distance(metres: float) -> str:
    """A displacement in mm, or in m beyond a metre (out of the hand)."""
    return f"{metres:.2f} m" if metres >= 1.0 else f"{metres * 1e3:.2f} mm"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    objects = ["box", "sugar_box", "soup_can"]
    parser.add_argument("--objects", nargs="+", default=objects, choices=OBJECTS)
    parser.add_argument("--efforts", nargs="+", type=float, default=[1000.0, 5.0])
    parser.add_argument("--top", type=int, default=6)
    parser.add_argument("--num", type=int, default=60)
    args = parser.parse_args(argv)
    models = drake_models()
    warnings.simplefilter("ignore")  # the models' friction against the plan's
    with tempfile.TemporaryDirectory() as tmp:
        for effort in args.efforts:
            path = Path(tmp) / f"pinch_{effort:g}.urdf"
            path.write_text(one_motor_pinch_urdf(effort=effort, bars=True))
            print(f"one-motor pinch with inner knuckles, effort limit {effort:g} N·m")
            for name in args.objects:
                url = OBJECTS[name]
                if url.startswith("package://drake_models") and models is None:
                    print(f"  {name:10s} left out: no drake_models")
                    continue
                scene = dg.planning_scene(url, hand_url=str(path), models_dir=models)
                mass = scene.object_body.default_mass()
                result = dg.plan_grasps(
                    scene.plant, scene.context, scene.object_body, hand=scene.hand,
                    num_candidates=args.num, seed=0, mu=0.5, object_mass=mass,
                )  # fmt: skip
                top = result.candidates[: args.top]
                for label, squeeze in (
                    ("20 N at the pads", None),
                    ("20 N·m/joint", 20),
                ):
                    t0 = time.perf_counter()
                    shaken = [
                        dg.shake_test(
                            scene.add_models,
                            c,
                            squeeze=squeeze,
                            hydroelastic_modulus=1e6,
                            object_mass=mass,
                        )  # fmt: skip
                        for c in top
                    ]
                    held = sum(s.held_from_seat for s in shaken)
                    worst = max((s.max_displacement for s in shaken), default=0.0)
                    pressed = [e for s in shaken for e in s.efforts]
                    aim = f"{min(pressed):.3g}-{max(pressed):.3g}" if pressed else "-"
                    print(
                        f"  {name:10s} {label:17s} held {held}/{len(shaken)}, "
                        f"largest displacement {_distance(worst)}, "
                        f"motor pressed with {aim} N·m once seated "
                        f"({time.perf_counter() - t0:.1f} s)",
                        flush=True,
                    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
