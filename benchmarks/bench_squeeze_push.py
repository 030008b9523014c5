"""Does the ranking put first the grasps that hold?  Multi-finger hands in Drake.

Usage::

    python benchmarks/bench_squeeze_push.py [--cases allegro:005_tomato_soup_can ...]
        [--top 10] [--num 150] [--seed 0] [--mu 1.0] [--mass KG] [--json OUT]

Each case is ``HAND:OBJECT``: ``allegro`` (Drake's Allegro right hand, thumb
opposed at ``joint_12 = 1.0``, as the tests plan it), ``wsg`` (Drake's WSG-50,
the parallel-jaw control), ``three`` (drakegrasp's three-finger hand, its
proximal joints splayed to -0.4 rad), ``spread`` (the tests' Barrett-like
hand, ``tests/support/coupled_hands.py``, 0.2 kg) and ``pinch`` (the tests'
one-motor pinch, pads swinging on arcs, hydroelastic pads of 1e6 Pa in the
shake); ``OBJECT`` a YCB model of ``drake_models`` (``004_sugar_box``...) or a
shipped one (``box``, ``cylinder``, ``sphere``).  Each is planned with
:func:`drakegrasp.plan_grasps` (``--num`` samples, ``--seed``, ``--mu``; the
coupled hands at ``mu`` 0.5 and seed 0, the three-finger hand at seed 3, as
their tests do; ``--mass`` plans and shakes that mass instead of the
model's, and the spread hand's and the pinch's shipped objects weigh 0.2 kg
without it) twice: as the library ranks now, and as it ranked before the
squeeze push (``drakegrasp.planning.motors.SQUEEZE_PUSH_MAX`` set to
infinity: the order of the torque figures and the score alone).  The first
``--top`` candidates of either order are shaken with
:func:`drakegrasp.shake_test` at its defaults (20 N at the contacts, each
motor within its effort limit; the pinch's pads hydroelastic), each once.

Per candidate it prints its place in either order, the fingers its contacts
are on (the Allegro's I, M, R, T; P the palm), whether it is force closure,
``torque_needed`` against ``torque_limit`` (N·m per motor), ``squeeze_push``,
whether it held (from the seat), the object's speed at the end of the
gravity-free seating (a push-out reads above 0.1 m/s), how far it moved from
there, and the simulation's wall time; then, per order, how many of its
first ``--top`` held, and the hold counts by ``squeeze_push`` above and below
``SQUEEZE_PUSH_MAX``.  ``--json`` writes the rows.  Timings are not asserted
anywhere: they depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests" / "support"))
from bench_plan import drake_models  # noqa: E402
from coupled_hands import one_motor_pinch_urdf, spread_hand_urdf  # noqa: E402

import drakegrasp as dg  # noqa: E402
import drakegrasp.planning.motors as motors  # noqa: E402

ALLEGRO = (
    "package://drake_models/allegro_hand_description/sdf/"
    "allegro_hand_description_right.sdf"
)
WSG = "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf"
THREE = "package://drakegrasp/hands/three_finger_hand.sdf"
FINGERS = {  # the Allegro right hand's links, by finger
    "I": ("link_0", "link_1", "link_2", "link_3"),
    "M": ("link_4", "link_5", "link_6", "link_7"),
    "R": ("link_8", "link_9", "link_10", "link_11"),
    "T": ("link_12", "link_13", "link_14", "link_15"),
}
DEFAULT_CASES = [
    "allegro:004_sugar_box",
    "allegro:005_tomato_soup_can",
    "allegro:003_cracker_box",
    "wsg:004_sugar_box",
]


def _finger_of(body: str) -> str:
    link = body.split("::")[-1]
    for finger, links in FINGERS.items():
        if link in links:
            return finger
    return "P" if link.startswith(("link", "base", "hand", "palm")) else "-"


def _object_url(name: str) -> str:
    if name[:3].isdigit():
        return f"package://drake_models/ycb/{name}.sdf"
    return f"package://drakegrasp/objects/{name}.sdf"


def _setup(hand: str, obj: str, args, folder: Path, models):
    """``(scene, plan options, shake options)`` of a case."""
    plan = dict(num_candidates=args.num, mu=args.mu, seed=args.seed)
    if args.mass is not None:
        plan["object_mass"] = args.mass
    shake: dict = {}
    if hand in ("spread", "pinch"):
        path = folder / f"{hand}.urdf"
        path.write_text(
            spread_hand_urdf() if hand == "spread" else one_motor_pinch_urdf()
        )
        url = str(path)
        plan.update(mu=0.5, seed=0)
        if not obj[:3].isdigit() and args.mass is None:
            plan["object_mass"] = 0.2
        if hand == "pinch":
            shake["hydroelastic_modulus"] = 1e6
    else:
        url = {"allegro": ALLEGRO, "wsg": WSG, "three": THREE}[hand]
        if hand == "three":
            plan.update(seed=3, preshape=[-0.4, 0.0, 0.0] * 3)
    scene = dg.planning_scene(_object_url(obj), hand_url=url, models_dir=models)
    if hand == "allegro":
        ctx = scene.plant.GetMyContextFromRoot(scene.context)
        scene.plant.GetJointByName("joint_12").set_angle(ctx, 1.0)  # thumb opposed
    return scene, plan, shake


def _plan(scene, plan: dict, before: bool):
    saved = motors.SQUEEZE_PUSH_MAX
    if before:
        motors.SQUEEZE_PUSH_MAX = math.inf  # no candidate pushes past it
    try:
        t0 = time.perf_counter()
        result = dg.plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand, **plan
        )
        return result, time.perf_counter() - t0
    finally:
        motors.SQUEEZE_PUSH_MAX = saved


def run_case(case: str, args, folder: Path, models) -> list[dict]:
    hand, _, obj = case.partition(":")
    scene, plan, shake = _setup(hand, obj, args, folder, models)
    now, t_now = _plan(scene, plan, before=False)
    old, t_old = _plan(scene, plan, before=True)
    print(
        f"== {case}: {len(now)} candidates of {plan['num_candidates']} samples, "
        f"plan {t_now:.2f} s (before the squeeze push: {t_old:.2f} s)"
    )
    for line in str(now).splitlines()[1:4]:
        if not line.lstrip().startswith(("#", "rejected")):
            print(f"   {line.strip()}")
    new_rank = {c.sample: k for k, c in enumerate(now)}
    old_rank = {c.sample: k for k, c in enumerate(old)}
    chosen = {c.sample: c for c in [*now[: args.top], *old[: args.top]]}
    rows = []
    for sample, c in sorted(chosen.items(), key=lambda kv: new_rank[kv[0]]):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the shake's advice, not a result
            try:
                r = dg.shake_test(scene.add_models, c, **shake)
            except dg.GraspError as e:
                r, error = None, str(e).splitlines()[0][:90]
        c = now[new_rank[sample]]  # with its figures as ranked now
        row = dict(
            case=case, sample=sample, new=new_rank[sample], old=old_rank[sample],
            fingers="".join(sorted({_finger_of(k.finger_body) for k in c.contacts})),
            closure=bool(c.is_closure), score=c.score, torque_needed=c.torque_needed,
            torque_limit=c.torque_limit, squeeze_push=c.squeeze_push,
            concerns=list(c.concerns), held=bool(r is not None and r.held_from_seat),
            seat_speed=math.nan if r is None else r.seat_speed,
            from_seat=math.nan if r is None else r.max_displacement_from_seat,
            wall=math.nan if r is None else r.wall_time,
            error="" if r is not None else error,
        )  # fmt: skip
        rows.append(row)
        moved = row["from_seat"]
        print(
            f"  now #{row['new']:<3d} before #{row['old']:<3d} s{sample:<4d} "
            f"{row['fingers']:6s} {'FC' if c.is_closure else '--'} "
            f"torque {c.torque_needed:6.3f}/{c.torque_limit:.2g}  push "
            f"{c.squeeze_push:4.2f}  {'HELD' if row['held'] else 'drop'}  seat "
            f"{row['seat_speed'] * 1e3:4.0f} mm/s, then "
            + (f"{moved * 1e3:6.1f} mm" if moved < 1 else f"{moved:5.1f} m ")
            + f"  {row['wall']:.1f} s"
            + (f"  not simulated: {row['error']}" if row["error"] else "")
        )
    held = {r["sample"]: r["held"] for r in rows}
    for name, order in (("now", now), ("before", old)):
        top = [c.sample for c in order[: args.top]]
        print(f"   {name:6s}: {sum(held[s] for s in top)} of the first {len(top)} held")
    above = [r for r in rows if r["squeeze_push"] > motors.SQUEEZE_PUSH_MAX]
    below = [r for r in rows if r["squeeze_push"] <= motors.SQUEEZE_PUSH_MAX]
    bound = motors.SQUEEZE_PUSH_MAX
    print(
        f"   squeeze_push > {bound:g}: {sum(r['held'] for r in above)} of "
        f"{len(above)} held; <=: {sum(r['held'] for r in below)} of {len(below)}"
    )
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", nargs="+", default=DEFAULT_CASES)
    parser.add_argument("--top", type=int, default=10)
    parser.add_argument("--num", type=int, default=150)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--mu", type=float, default=1.0)
    parser.add_argument("--mass", type=float, default=None)
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)
    models = drake_models()
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for case in args.cases:
            if models is None and ("allegro" in case or "wsg" in case or ":0" in case):
                print(f"{case}: drake_models not found (DRAKEGRASP_DRAKE_MODELS)")
                continue
            rows += run_case(case, args, Path(folder), models)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
