"""Median wall time of one ``analyze_grasp`` on a scene (default: the default scene).

Usage::

    python benchmarks/bench_analyze.py [SCENE] [--repeats 300] [--profile]

The scene is loaded once (outside the clock); each timed call reads the contacts
from the plant's scene-graph query port, builds the grasp, J, ψ and ∂ψ/∂v, and
solves LP1, LP2 + LP3 and the exact-cone program with LP3.  The breakdown times
the same steps separately so that the bound on the total is visible.  Target:
<= 5 ms on the default scene.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import cProfile  # noqa: E402
import pstats  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from drakegrasp.antipodal import is_antipodal  # noqa: E402
from drakegrasp.closure import (  # noqa: E402
    force_closure,
    force_closure_exact,
    form_closure,
)
from drakegrasp.plant import (  # noqa: E402
    DEFAULT_SCENE,
    analyze_grasp,
    find_contacts,
    grasp_from_plant,
    load_scene,
)


def median_ms(fn, repeats: int) -> tuple[float, float]:
    """Median and 90th percentile of ``fn()`` in milliseconds (after warm-up)."""
    for _ in range(5):
        fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times)), 1e3 * float(np.percentile(times, 90))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=DEFAULT_SCENE)
    parser.add_argument("--repeats", type=int, default=300)
    parser.add_argument("--profile", action="store_true")
    args = parser.parse_args()

    scene = load_scene(args.scene)
    plant, ctx = scene.plant, scene.plant_context
    options = scene.analysis_options()
    data = grasp_from_plant(plant, ctx, **options)
    grasp, J = data.grasp, data.hand_jacobian

    steps = {
        "analyze_grasp (total)": lambda: analyze_grasp(plant, ctx, **options),
        "  find_contacts": lambda: find_contacts(
            plant, ctx, object_body=scene.object_body, hand=scene.hand
        ),
        "  grasp_from_plant (contacts, G, J, dpsi/dv)": lambda: grasp_from_plant(
            plant, ctx, **options
        ),
        "  form_closure (LP1)": lambda: form_closure(grasp),
        "  force_closure (LP2 + LP3)": lambda: force_closure(grasp, hand_jacobian=J),
        "  force_closure_exact (SOCP + LP3)": lambda: force_closure_exact(
            grasp, hand_jacobian=J
        ),
    }
    if grasp.num_contacts == 2:
        steps["  is_antipodal"] = lambda: is_antipodal(grasp)
    print(
        f"scene {scene.name}: {grasp.num_contacts} contacts, "
        f"{'planar' if grasp.planar else 'spatial'}, {grasp.contacts[0].model.value}"
    )
    print(f"{'step':<46} {'median ms':>10} {'p90 ms':>8}")
    for label, fn in steps.items():
        med, p90 = median_ms(fn, args.repeats)
        print(f"{label:<46} {med:10.3f} {p90:8.3f}")
    if args.profile:
        profiler = cProfile.Profile()
        profiler.enable()
        for _ in range(args.repeats):
            analyze_grasp(plant, ctx, **options)
        profiler.disable()
        pstats.Stats(profiler).sort_stats("tottime").print_stats(15)


if __name__ == "__main__":
    main()
