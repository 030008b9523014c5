"""How a parallel jaw's cloud plan scales with the cloud's size.

Usage::

    python benchmarks/bench_cloud_size.py [--points 3000 30000 100000]
        [--num 100] [--repeat 1]

A box's surface (50 x 50 x 100 mm), sampled area-uniform at each
``--points`` without normals (they are estimated), planned with the shipped
rounded-pad jaw (``--num`` sampled poses, seed 0).  Each size is planned twice
in this run: as the library does it, and with its two screens of
:mod:`drakegrasp.planning.cloud` turned off, the route they replaced: every
point of the ball that holds a finger piece's closing sweep measured by a
chord (``CloudFingers._in_sweep`` keeps those near the sweep's line), and
every point of a hand piece's bounding ball by three chords in the collision
test (``_maybe_inside`` keeps those inside a hull's box and faces).
It prints the best of ``--repeat`` wall times of each, their ratio, and
whether the two plans agree bit for bit.  Timings are not asserted anywhere.
"""

from __future__ import annotations

import argparse
import hashlib
import time

import numpy as np

from drakegrasp.planning import cloud, plan_grasps, planning_scene

JAW = "package://drakegrasp/hands/parallel_jaw.sdf"


def box_cloud(n: int, seed: int = 0) -> np.ndarray:
    """``(n, 3)`` points on a 50 x 50 x 100 mm box, area-uniform, metres."""
    half = np.array([0.025, 0.025, 0.05])
    rng = np.random.default_rng(seed)
    areas = np.array([half[1] * half[2], half[0] * half[2], half[0] * half[1]])
    axis = rng.choice(3, size=n, p=areas / areas.sum())
    p = rng.uniform(-1.0, 1.0, (n, 3))
    p[np.arange(n), axis] = rng.choice([-1.0, 1.0], size=n)
    return p * half


def digest(result) -> str:
    h = hashlib.sha256()
    for c in result.candidates:
        for x in (c.X_WH.GetAsMatrix4(), c.q_hand, c.d_star, c.epsilon, c.score):
            h.update(np.asarray(x, float).tobytes())
        for k in c.contacts:
            h.update(np.asarray(k.p_OC, float).tobytes())
    return h.hexdigest()[:16]


def plan(scene, points, num):
    started = time.perf_counter()
    result = plan_grasps(
        scene.plant, scene.context, None, hand=scene.hand, num_candidates=num,
        mu=0.5, seed=0, point_cloud=points,
    )  # fmt: skip
    return time.perf_counter() - started, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, nargs="+", default=[3000, 30000, 100000])
    parser.add_argument("--num", type=int, default=100)
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    scene = planning_scene(None, hand_url=JAW)
    plan(scene, box_cloud(1000), 5)  # compile and load once, untimed
    kept = cloud.CloudFingers._in_sweep, cloud._maybe_inside
    print("points  filtered_s  unfiltered_s  ratio  candidates  same")
    for n in args.points:
        points = box_cloud(n)
        times = {}
        for label in ("filtered", "unfiltered"):
            if label == "unfiltered":
                cloud.CloudFingers._in_sweep = lambda _self, idx, *_: idx
                cloud._maybe_inside = lambda _piece, q_G: q_G
            try:
                best, result = min(
                    (plan(scene, points, args.num) for _ in range(args.repeat)),
                    key=lambda tr: tr[0],
                )
            finally:
                cloud.CloudFingers._in_sweep, cloud._maybe_inside = kept
            times[label] = (best, result)
        (a, ra), (b, rb) = times["filtered"], times["unfiltered"]
        same = digest(ra) == digest(rb)
        print(f"{n:6d}  {a:10.2f}  {b:12.2f}  {b / a:5.2f}  {len(ra):10d}  {same}")


if __name__ == "__main__":
    main()
