"""A Robotiq-style pinch: its roll laid along the object's normals, or drawn.

Usage::

    python benchmarks/bench_pinch.py [--objects sugar_box soup_can cracker_box box]
        [--num 200] [--mu 0.5] [--top 8] [--squeeze 5] [--bars both|yes|no]
        [--no-shake]

The hand is the test suite's one-motor pinch (``tests/support/coupled_hands.py``:
two revolute knuckles 110 mm apart and their upright 8 x 22 x 40 mm pads on
one 5 N·m motor, written with ``<mimic>``), with and without the inner
knuckles a Robotiq 2F-85's URDF hangs from the palm (``--bars``).  Each hand
is planned on each object (``plan_grasps``, ``--num`` samples, seed 0,
``--mu``) twice: as the planner rolls a pinch now (its closing axis laid
along the object's normals, :mod:`drakegrasp.planning.approach`) and with
the roll drawn at random, as before (this script turns the pinch's closing
axis off).  It prints the candidates, how many are force closure and their
contact counts; then shakes the ``--top`` best of each with
:func:`drakegrasp.shake_candidates` at ``--squeeze`` N·m (capped by the
motor's share), with Drake's point contact and with hydroelastic pads
(1e6 Pa).  The YCB objects need Drake's ``drake_models``
(``DRAKEGRASP_DRAKE_MODELS`` or ``../shared/drake_models``; left out
without it).

The planning guide's and the Changes page's figures for the pinch come from
the default run.  Timings are not asserted anywhere.
"""

from __future__ import annotations

import argparse
import collections
import sys
import tempfile
import time
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests" / "support"))
from bench_plan import drake_models  # noqa: E402
from coupled_hands import one_motor_pinch_urdf  # noqa: E402

import drakegrasp as dg  # noqa: E402
from drakegrasp.planning import approach  # noqa: E402

OBJECTS = {
    "sugar_box": "package://drake_models/ycb/004_sugar_box.sdf",
    "soup_can": "package://drake_models/ycb/005_tomato_soup_can.sdf",
    "cracker_box": "package://drake_models/ycb/003_cracker_box.sdf",
    "box": "package://drakegrasp/objects/box.sdf",
}


def plan(hand_file: str, url: str, args, aligned: bool):
    """The plan of one hand on one object; the roll aligned or drawn."""
    scene = dg.planning_scene(url, hand_url=hand_file, models_dir=args.models)
    pinch = approach._pinch
    if not aligned:  # as before: no closing axis, the roll drawn at random
        approach._pinch = lambda *_, **__: None
    try:
        t0 = time.perf_counter()
        result = dg.plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=args.num, seed=0, mu=args.mu,
        )  # fmt: skip
        elapsed = time.perf_counter() - t0
    finally:
        approach._pinch = pinch
    return scene, result, elapsed


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--objects", nargs="+", default=list(OBJECTS))
    parser.add_argument("--num", type=int, default=200)
    parser.add_argument("--mu", type=float, default=0.5)
    parser.add_argument("--top", type=int, default=8)
    parser.add_argument("--squeeze", type=float, default=5.0)
    parser.add_argument("--bars", choices=("both", "yes", "no"), default="both")
    parser.add_argument("--no-shake", action="store_true")
    args = parser.parse_args(argv)
    args.models = drake_models()
    warnings.simplefilter("ignore")  # SqueezeLostWarning and friends: counted below
    bars = {"both": (False, True), "yes": (True,), "no": (False,)}[args.bars]
    with tempfile.TemporaryDirectory() as tmp:
        for with_bars in bars:
            path = Path(tmp) / f"pinch_{with_bars}.urdf"
            path.write_text(one_motor_pinch_urdf(bars=with_bars))
            print(f"pinch {'with' if with_bars else 'without'} inner knuckles")
            for name in args.objects:
                url = OBJECTS[name]
                if url.startswith("package://drake_models") and args.models is None:
                    print(f"  {name:12s} left out: no drake_models")
                    continue
                for aligned in (True, False):
                    scene, result, elapsed = plan(str(path), url, args, aligned)
                    counts = collections.Counter(len(c.contacts) for c in result)
                    closure = sum(c.is_closure for c in result)
                    line = (
                        f"  {name:12s} {'aligned' if aligned else 'drawn  '} "
                        f"{len(result):4d} candidates, {closure:4d} force closure "
                        f"({elapsed:.1f} s); contacts {dict(sorted(counts.items()))}"
                    )
                    if not args.no_shake and len(result):
                        held = []
                        for modulus in (None, 1e6):
                            shaken = dg.shake_candidates(
                                scene.add_models, result, top=args.top,
                                squeeze=args.squeeze, hydroelastic_modulus=modulus,
                            )  # fmt: skip
                            held.append(f"{sum(s.held for s in shaken)}/{len(shaken)}")
                        line += f"; held {held[0]} point, {held[1]} hydroelastic"
                    print(line, flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
