"""Time per grasp of the quality metrics on seeded random grasps.

Run: ``python benchmarks/bench_quality.py [--grasps 300] [--seed 0]``.

The headline row is the Ferrari–Canny ε (L1, 8 generators, 3 spatial hard
fingers; target <= 1 ms per grasp).  It is reported over all grasps and over the
force-closure ones alone: ε of a grasp that is not in force closure is settled by
a cheap NNLS test, without a hull, so the mix of the sample matters.  The
breakdown rows time the stages of one ε on the force-closure grasps.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np
from scipy.spatial import ConvexHull

import drakegrasp as dg
from drakegrasp import quality as q
from drakegrasp.quality import epsilon


def random_grasps(rng, count, num_contacts=3, *, mu=0.5, spread=0.3):
    """Contacts on the unit sphere, normals tilted from the inward radial."""
    grasps = []
    for _ in range(count):
        p = rng.normal(size=(num_contacts, 3))
        p /= np.linalg.norm(p, axis=1, keepdims=True)
        n = -p + spread * rng.normal(size=p.shape)
        grasps.append(
            dg.Grasp([dg.Contact(a, b, mu=mu) for a, b in zip(p, n, strict=True)])
        )
    return grasps


def per_grasp(fn, items, repeat=3):
    """Best-of-``repeat`` mean (wall, CPU) seconds per item of ``fn(item)``.

    CPU time (``time.process_time``) is what one core spends; on a machine
    shared with other jobs the wall time also counts waiting for the core.
    """
    best_wall = best_cpu = np.inf
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        for x in items:
            fn(x)
        best_wall = min(best_wall, (time.perf_counter() - w0) / len(items))
        best_cpu = min(best_cpu, (time.process_time() - c0) / len(items))
    return best_wall, best_cpu


def row(name, seconds, note=""):
    wall, cpu = seconds
    print(f"  {name:<48s} {wall * 1e3:9.3f} {cpu * 1e3:9.3f}  {note}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grasps", type=int, default=300)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--linf", type=int, default=5, help="grasps for the L∞ row")
    args = parser.parse_args()

    rng = np.random.default_rng(args.seed)
    grasps = random_grasps(rng, args.grasps)
    eps = np.array([q.ferrari_canny(g) for g in grasps])
    fc = [g for g, e in zip(grasps, eps, strict=True) if e > 0]
    print(
        f"drakegrasp quality benchmark: {len(grasps)} random grasps (seed "
        f"{args.seed}), 3 spatial hard fingers, mu = 0.5, 8 generators; "
        f"{len(fc)} in force closure"
    )
    print(f"  python {platform.python_version()}, {platform.machine()}")
    print(f"  {'':<48s} {'wall ms':>9s} {'CPU ms':>9s}  (per grasp)")

    t_all = per_grasp(q.ferrari_canny, grasps)
    t_fc = per_grasp(q.ferrari_canny, fc)
    row("ferrari_canny L1, all grasps", t_all, "(target <= 1 ms)")
    row("ferrari_canny L1, force-closure grasps only", t_fc, "(target <= 1 ms)")

    print("  breakdown on the force-closure grasps:")
    Ws = [np.vstack(q.primitive_wrenches(g)) for g in fc]
    row("  primitive wrenches (24 x 6)", per_grasp(q.primitive_wrenches, fc))
    row(
        "  NNLS origin-in-hull test",
        per_grasp(lambda W: epsilon._origin_distance_residual(W, np.abs(W).max()), Ws),
    )
    row(
        "  rank test (SVD of centred points)",
        per_grasp(lambda W: np.linalg.svd(W - W.mean(0), compute_uv=False), Ws),
    )
    row(
        "  Qhull, 'Q0' (what ferrari_canny runs)",
        per_grasp(lambda W: ConvexHull(W, qhull_options="Q0"), Ws),
    )
    row("  Qhull, scipy defaults (merging, for comparison)", per_grasp(ConvexHull, Ws))
    facets = np.mean([len(ConvexHull(W, qhull_options="Q0").equations) for W in Ws])
    print(f"    (mean {facets:.0f} simplicial facets per hull in 6-D)")

    print("  other metrics (all grasps):")
    row("grasp_singular_values", per_grasp(q.grasp_singular_values, grasps))
    row("lp2_d_star (Drake + Clp)", per_grasp(q.lp2_d_star, grasps[:100], repeat=1))
    down = np.array([0.0, 0.0, -1.0, 0.0, 0.0, 0.0])
    row(
        "max_resistible_wrench (Drake + Clp)",
        per_grasp(
            lambda g: q.max_resistible_wrench(g, down, max_normal_force=10.0),
            grasps[:100],
            repeat=1,
        ),
    )
    row(
        "grasp_quality(linf=False)",
        per_grasp(lambda g: q.grasp_quality(g, linf=False), grasps[:100], repeat=1),
    )
    row(
        "grasp_quality (default: with L∞ for <= 3 contacts)",
        per_grasp(q.grasp_quality, grasps[:100], repeat=1),
    )
    if args.linf > 0:
        print("  L∞ Ferrari–Canny (normal-fan route) vs its Qhull hull:")
        sub = fc[: args.linf]
        row(
            f"ferrari_canny Linf, {len(sub)} force-closure grasps",
            per_grasp(lambda g: q.ferrari_canny(g, norm="Linf"), sub, 1),
        )

        def hull_of_sum(g):
            sets = [np.vstack([np.zeros((1, 6)), W]) for W in q.primitive_wrenches(g)]
            pts = sets[0]
            for P in sets[1:]:
                pts = (pts[:, None, :] + P[None, :, :]).reshape(-1, 6)
            return ConvexHull(pts, qhull_options="Qx Qs")

        row(
            "  Qhull hull of all 9^3 sums (for comparison)",
            per_grasp(hull_of_sum, sub[:2], 1),
        )
        four = [
            g
            for g in random_grasps(np.random.default_rng(args.seed + 1), 20, 4)
            if q.ferrari_canny(g) > 0
        ][:2]
        row(
            f"ferrari_canny Linf, 4 contacts ({len(four)} grasps)",
            per_grasp(lambda g: q.ferrari_canny(g, norm="Linf"), four, 1),
        )


if __name__ == "__main__":
    main()
