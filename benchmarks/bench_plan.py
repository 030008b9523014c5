"""Grasp planning: candidates per second, and how often the chosen grasps hold.

Usage::

    python benchmarks/bench_plan.py [--num 1000] [--top 10] [--random 10]
        [--margin 1.2] [--firm 5] [--mu 1] [--seed 0] [--objects NAME ...]
        [--no-shake] [--allegro 300]

For each object (the YCB boxes and can of ``drake_models``, when present, and
drakegrasp's own box, cylinder, sphere and hexagonal prism), with Drake's
WSG-50 as a free gripper:

* **planning**: ``plan_grasps`` on ``--num`` sampled poses (one warm-up call
  of the same size first, with another seed, so numba's compilation and the
  first imports of its fallbacks, scipy's Qhull among them, are not timed),
  the wall time, samples/s and
  candidates/s (candidates are the samples that survive the collision filter
  and the closing), candidates per CPU second (the machine's load skews wall
  time; numpy's BLAS is held to one thread, whose spinning helpers would
  otherwise count, unless ``OPENBLAS_NUM_THREADS`` is set), the same with
  ``--workers`` (2) batch workers (wall time, after a warm-up call that
  starts the pool, which is kept between calls), and the rejections by
  reason;
* **the user's loop**: ``--loop`` candidates closed and analysed one at a
  time with ``close_hand``, ``analyze_grasp`` and ``ferrari_canny`` from the
  open hand at the candidate's pose (the baseline of issue 18), candidates/s;
* **the course's cost**: a per-candidate re-implementation of the
  manipulation course's ``GraspCandidateCost`` (one signed-distance query per
  cloud point, ``--cloud`` points), candidates/s on the same candidates;
* **hold rates**: :func:`drakegrasp.planning.shake_test` on the ``--top``
  best candidates and on ``--random`` candidates drawn uniformly (seeded)
  from all collision-free closed antipodal candidates of the same run (the
  baseline a planner without ranking would give), as held / tried, at two
  squeezes per finger: the *predicted* one, ``--margin`` (1.2) times the
  largest ``squeeze_needed`` the planner gives its top candidates, and a
  *firm* one, ``--firm`` (5) times the object's weight, at which almost any
  two-sided grasp holds.  The planner uses ``--mu`` 1.0, the friction
  coefficient of the models' proximity properties (what the simulation uses).

With ``--stages``, each object's one-core run also prints the CPU seconds of
each stage (:func:`stage_timer`): sampling, the closing in Drake (with the
reading of the touching pairs), the contacts' batch, verdicts and ε,
robustness, weight capacity, and the rest.

Then the multi-finger route: the Allegro hand on the soup can, ``--allegro``
samples, candidates/s with one and two workers, and the hold rates of the top
and random candidates (:func:`allegro`).
"""

from __future__ import annotations

import os

# one core: numpy's BLAS must not spin threads of its own (their CPU time counts)
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from contextlib import contextmanager, nullcontext  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from drakegrasp.planning import plan_grasps, planning_scene, shake_test  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
YCB = ("003_cracker_box", "004_sugar_box", "005_tomato_soup_can")
OWN = ("box", "cylinder", "sphere", "hex_prism")


def drake_models() -> Path | None:
    for p in (
        os.environ.get("DRAKEGRASP_DRAKE_MODELS"),
        ROOT.parent / "shared" / "drake_models",
    ):
        if p and Path(p).is_dir():
            return Path(p)
    return None


def object_url(name: str) -> str:
    if name in YCB:
        return f"package://drake_models/ycb/{name}.sdf"
    return f"package://drakegrasp/objects/{name}.sdf"


def _hand_of(plant, candidate):
    """The hand's free base body and its finger joints, as a candidate names them."""
    base = plant.GetBodyByName(candidate.hand_base.rpartition("::")[2])
    names = candidate.joint_names
    joints = [plant.GetJointByName(n.rpartition("::")[2]) for n in names]
    return base, joints


def _open_at(plant, pctx, base, joints, candidate) -> None:
    """Put the hand at the candidate's pose, its fingers wide open."""
    plant.SetFreeBodyPose(pctx, base, candidate.X_WH)
    for j, sign in zip(joints, candidate.closing_signs, strict=True):
        lo, hi = j.position_lower_limits()[0], j.position_upper_limits()[0]
        j.set_translation(pctx, lo if sign > 0 else hi)


STAGES = (
    ("drakegrasp.planning.planner", "sample_poses", "sample"),
    ("drakegrasp.planning.planner", "_close_on_body", "close (Drake)"),
    ("drakegrasp.planning.placement", "stage_contacts", "of which pairs read"),
    ("drakegrasp.planning.placement", "BodyCloser.finish", "contacts"),
    ("drakegrasp.planning.ranking", "verdicts", "verdicts + ε"),
    ("drakegrasp.planning.ranking", "reclosed_robustness", "robustness"),
    ("drakegrasp.planning.ranking", "weight_capacity", "weight"),
)
"""(module, function, label) of the stages :func:`stage_timer` times."""


@contextmanager
def stage_timer():
    """CPU seconds per stage of ``plan_grasps`` (parallel jaw), while inside.

    Wraps the stage functions of :data:`STAGES` where the planner looks them
    up and yields a dict ``{label: seconds}`` filled as they run (a nested
    stage, ``of which ...``, is also counted in its parent).
    """
    import importlib

    spent = dict.fromkeys([label for *_, label in STAGES], 0.0)
    undo = []
    for module, name, label in STAGES:
        owner = importlib.import_module(module)
        attr = name
        if "." in name:
            cls, attr = name.split(".")
            owner = getattr(owner, cls)
        original = getattr(owner, attr)

        def timed(*args, _f=original, _label=label, **kwargs):
            t = time.process_time()
            try:
                return _f(*args, **kwargs)
            finally:
                spent[_label] += time.process_time() - t

        setattr(owner, attr, timed)
        undo.append((owner, attr, original))
    try:
        yield spent
    finally:
        for owner, attr, original in undo:
            setattr(owner, attr, original)


def user_loop(scene, candidates, mu: float) -> float:
    """Candidates/s of the one-at-a-time loop a user writes without the planner.

    From each candidate's open pre-grasp: ``close_hand``, ``analyze_grasp`` and
    ``ferrari_canny`` (the issue's baseline), on the same plant.
    """
    from drakegrasp import GraspError, analyze_grasp, close_hand, ferrari_canny

    plant = scene.plant
    ctx = scene.context.Clone()
    pctx = plant.GetMyContextFromRoot(ctx)
    base, joints = _hand_of(plant, candidates[0])
    t = time.perf_counter()
    for c in candidates:
        _open_at(plant, pctx, base, joints, c)
        try:
            close_hand(plant, ctx, scene.object_body, hand=scene.hand)
            report = analyze_grasp(
                plant, ctx, scene.object_body, hand=scene.hand, mu=mu
            )
            ferrari_canny(report.grasp)
        except GraspError:  # timed all the same: the loop pays for it
            pass
    return len(candidates) / (time.perf_counter() - t)


def course_cost_loop(scene, candidates, cloud_points: int, seed: int) -> float:
    """Candidates/s of a per-candidate re-implementation of the course's cost.

    The manipulation course's ``GraspCandidateCost`` on a cloud of the object:
    for each candidate, the open gripper at ``X_WH``, one
    ``ComputeSignedDistanceToPoint`` per cloud point (a point inside any hand
    geometry makes the candidate infeasible), then the antipodal term
    ``-Σ (n̂ᵢ · a)²`` over the points between the jaws and the course's
    orientation term; here on ``cloud_points`` area-uniform surface samples
    with their normals (the course's cloud after downsampling).
    """
    from drakegrasp.planning.gripper import parallel_jaw
    from drakegrasp.planning.planner import object_surface

    plant = scene.plant
    ctx = scene.context.Clone()
    pctx = plant.GetMyContextFromRoot(ctx)
    surface = object_surface(plant, pctx, scene.object_body)
    p_O, n_O, _ = surface.sample(cloud_points, np.random.default_rng(seed))
    X_WO = plant.EvalBodyPoseInWorld(pctx, scene.object_body)
    R_WO = X_WO.rotation().matrix()
    p_W = p_O @ R_WO.T + X_WO.translation()
    n_W = n_O @ R_WO.T
    base, joints = _hand_of(plant, candidates[0])
    port = plant.get_geometry_query_input_port()
    X_HK = parallel_jaw(plant, pctx, scene.object_body, scene.hand).X_HK
    costs = []
    t = time.perf_counter()
    for c in candidates:
        _open_at(plant, pctx, base, joints, c)
        query = port.Eval(pctx)
        hand = {
            g
            for b in plant.GetBodyIndices(base.model_instance())
            for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))
        }
        cost = 0.0
        for p in p_W:
            if any(d.id_G in hand for d in query.ComputeSignedDistanceToPoint(p, 0.0)):
                cost = np.inf
                break
        if np.isfinite(cost):
            X_WK = c.X_WH.multiply(X_HK)  # x: the jaw axis, y: the approach
            R_WK = X_WK.rotation().matrix()
            p_K = (p_W - X_WK.translation()) @ R_WK
            between = (np.abs(p_K[:, 0]) < 0.5 * c.opening) & (
                np.abs(p_K[:, 1:]).max(axis=1) < 0.02
            )
            cost = -np.sum((n_W[between] @ R_WK[:, 0]) ** 2) + 20.0 * R_WK[2, 0]
        costs.append(cost)
    return len(candidates) / (time.perf_counter() - t)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--num", type=int, default=1500)
    ap.add_argument("--top", type=int, default=10)
    ap.add_argument("--random", type=int, default=10)
    ap.add_argument(
        "--firm",
        type=float,
        default=5.0,
        help="the firm squeeze per finger, in multiples of the object's weight",
    )
    ap.add_argument(
        "--margin",
        type=float,
        default=1.2,
        help="the predicted squeeze is this times the largest squeeze_needed "
        "of the top candidates",
    )
    ap.add_argument("--mu", type=float, default=1.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--objects", nargs="*", default=None)
    ap.add_argument("--no-shake", action="store_true")
    ap.add_argument(
        "--stages",
        action="store_true",
        help="print the CPU seconds of each planning stage (one core)",
    )
    ap.add_argument(
        "--allegro",
        type=int,
        default=300,
        help="samples for the Allegro hand on the soup can (multi-finger route; "
        "at 100 the ten best held 8, 6, 4 on seeds 0-2, at 300 10/10); 0 skips it",
    )
    ap.add_argument(
        "--cloud",
        type=int,
        default=1000,
        help="cloud points of the course-cost re-implementation (0 skips it)",
    )
    ap.add_argument(
        "--workers",
        type=int,
        default=2,
        help="also plan with this many workers (0 or 1 skips it)",
    )
    ap.add_argument(
        "--loop",
        type=int,
        default=50,
        help="candidates run through the user's loop (close_hand, analyze_grasp, "
        "ferrari_canny one at a time) for comparison; 0 skips it",
    )
    args = ap.parse_args(argv)
    models = drake_models()
    if models is None:
        print(
            "drake_models not found (set DRAKEGRASP_DRAKE_MODELS): the WSG-50 is needed"
        )
        return 1
    names = [*YCB, *OWN] if args.objects is None else args.objects  # none: Allegro only
    print(f"load {os.getloadavg()[0]:.2f}; WSG-50, mu = {args.mu}")
    print(
        f"{'object':<20} {'samples/s':>10} {'cands/s':>8} {'cands':>6} {'FC':>5}"
        f" {'predicted':>9} {'top':>5} {'random':>6}"
        f" {'firm':>9} {'top':>5} {'random':>6}"
    )
    for name in names:
        scene = planning_scene(object_url(name), models_dir=models)
        kwargs = dict(hand=scene.hand, mu=args.mu, workers=1)
        plan_grasps(
            scene.plant, scene.context, scene.object_body,
            num_candidates=args.num, seed=args.seed + 1, **kwargs,
        )  # fmt: skip
        with stage_timer() if args.stages else nullcontext() as spent:
            t, cpu = time.perf_counter(), time.process_time()
            result = plan_grasps(
                scene.plant, scene.context, scene.object_body,
                num_candidates=args.num, seed=args.seed, **kwargs,
            )  # fmt: skip
            wall = time.perf_counter() - t
            cpu = time.process_time() - cpu
        rng = np.random.default_rng(args.seed)
        pick = rng.choice(
            len(result), size=min(args.random, len(result)), replace=False
        )
        weight = scene.object_body.default_mass() * 9.81
        top = list(result[: args.top])
        rand = [result[int(i)] for i in pick]
        predicted = args.margin * max((c.squeeze_needed for c in top), default=0.0)
        cells = ""
        for q in (predicted, args.firm * weight):
            if args.no_shake or not top or not np.isfinite(q):
                cells += f" {'-':>9} {'-':>5} {'-':>6}"
                continue
            held = [shake_test(scene.add_models, c, squeeze=q).held for c in top]
            held_r = [shake_test(scene.add_models, c, squeeze=q).held for c in rand]
            cells += (
                f" {q:>8.1f}N {f'{sum(held)}/{len(held)}':>5}"
                f" {f'{sum(held_r)}/{len(held_r)}':>6}"
            )
        fc = sum(c.is_closure for c in result)
        print(
            f"{name:<20} {args.num / wall:>10.0f} {len(result) / wall:>8.0f} "
            f"{len(result):>6} {fc:>5}" + cells,
            flush=True,
        )
        print(
            f"    one core: {len(result) / wall:.0f} candidates/s wall, "
            f"{len(result) / cpu:.0f} per CPU second (load "
            f"{os.getloadavg()[0]:.1f})"
        )
        if spent is not None:
            top = sum(v for k, v in spent.items() if not k.startswith("of which"))
            print(
                f"    CPU s by stage ({cpu:.2f} in all): "
                + ", ".join(f"{k} {v:.2f}" for k, v in spent.items())
                + f", rest {cpu - top:.2f}"
            )
        if args.workers > 1:
            # the pool's start-up (it is kept between calls) is not timed
            plan_grasps(
                scene.plant, scene.context, scene.object_body, num_candidates=50,
                seed=1, **{**kwargs, "workers": args.workers},
            )  # fmt: skip
            t = time.perf_counter()
            two = plan_grasps(
                scene.plant, scene.context, scene.object_body,
                num_candidates=args.num, seed=args.seed,
                **{**kwargs, "workers": args.workers},
            )  # fmt: skip
            wall2 = time.perf_counter() - t
            same = [c.sample for c in two] == [c.sample for c in result]
            print(
                f"    {args.workers} workers: {len(two) / wall2:.0f} candidates/s "
                f"wall (same ranking: {same})"
            )
        if args.loop and len(result):
            rate = user_loop(scene, result[: args.loop], args.mu)
            print(
                f"    the user's loop: {rate:.0f} candidates/s ({args.loop} candidates)"
            )
        if args.cloud and len(result):
            rate = course_cost_loop(scene, result[: args.loop or 50], args.cloud, 0)
            print(
                f"    the course's cost, per candidate ({args.cloud} cloud points): "
                f"{rate:.0f} candidates/s"
            )
        reasons = ", ".join(
            f"{k} {v}"
            for k, v in sorted(result.rejections.items(), key=lambda kv: -kv[1])
        )
        print(f"    rejected: {reasons or 'none'}")
    if args.allegro:
        allegro(models, args)
    return 0


ALLEGRO_URL = (
    "package://drake_models/allegro_hand_description/sdf/"
    "allegro_hand_description_right.sdf"
)
ALLEGRO_SHAKE = dict(squeeze=0.5, stiffness=20.0, damping=1.0)
"""Revolute fingers: squeeze in N·m (effort limit 0.7), PD gains per radian."""


def allegro(models: Path, args) -> None:
    """The multi-finger route: the Allegro hand (thumb opposed) on the soup can.

    Candidates/s (approach + pre-shape + ``close_hand`` + scored) with one and
    two batch workers (the closing is one Python loop either way), then the
    hold rates of the ``--top`` best and ``--random`` random candidates.
    """
    scene = planning_scene(
        object_url("005_tomato_soup_can"), hand_url=ALLEGRO_URL, models_dir=models
    )
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    scene.plant.GetJointByName("joint_12").set_angle(ctx, 1.0)

    def run(n, seed, workers):
        return plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=n, mu=args.mu, seed=seed, workers=workers,
        )  # fmt: skip

    run(10, 1, 1)  # warm-up
    print(f"Allegro hand on 005_tomato_soup_can, {args.allegro} samples")
    for workers in (1, 2):
        t = time.perf_counter()
        result = run(args.allegro, args.seed, workers)
        wall = time.perf_counter() - t
        fc = sum(c.is_closure for c in result)
        print(
            f"    workers {workers}: {args.allegro / wall:.1f} samples/s, "
            f"{len(result) / wall:.1f} candidates/s ({len(result)} candidates, "
            f"{fc} force closure, {wall:.1f} s)",
            flush=True,
        )
    reasons = ", ".join(f"{k} {v}" for k, v in result.rejections.items())
    print(f"    rejected: {reasons or 'none'}")
    if args.no_shake or not len(result):
        return
    pick = np.random.default_rng(args.seed).choice(
        len(result), size=min(args.random, len(result)), replace=False
    )
    top = [
        shake_test(scene.add_models, c, **ALLEGRO_SHAKE).held
        for c in result[: args.top]
    ]
    rand = [
        shake_test(scene.add_models, result[int(i)], **ALLEGRO_SHAKE).held for i in pick
    ]
    print(
        f"    hold at {ALLEGRO_SHAKE['squeeze']} N·m per joint: top "
        f"{sum(top)}/{len(top)}, random {sum(rand)}/{len(rand)}"
    )


if __name__ == "__main__":
    sys.exit(main())
