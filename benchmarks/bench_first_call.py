"""The first batch call on a fresh install, and the load with a warm compile cache.

Usage::

    python benchmarks/bench_first_call.py [--grasps 1000] [--N 3] [--runs 1]

Each figure comes from a new Python process with ``NUMBA_CACHE_DIR`` pointed at a
fresh temporary folder, so numba's on-disk cache starts empty (a fresh install)
and is then warm for the following processes (the same install, a new session):

* ``cold``: ``batch_force_closure`` of ``--grasps`` seeded ``--N``-contact spatial
  hard-finger grasps (μ 0.5, 8 generators), then ``batch_epsilon_l1`` of the same
  grasps, each timed from its call to its return, compiles included;
* ``warm``: the same two calls in a second and a third process that reuse the
  cache (loading the compiled code included);
* ``import``: ``import drakegrasp.batch`` in each process, apart.

It also prints the load the machine is under (``os.getloadavg``), since the
compile is CPU-bound and a shared machine stretches it.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

CHILD = r"""
import json, os, sys, time
t0 = time.perf_counter()
import numpy as np
import drakegrasp.batch as b
t1 = time.perf_counter()
K, N = int(sys.argv[1]), int(sys.argv[2])
rng = np.random.default_rng(0)
p = rng.normal(size=(K, N, 3))
p /= np.linalg.norm(p, axis=-1, keepdims=True)
n = -p + 0.3 * rng.normal(size=(K, N, 3))
t2 = time.perf_counter()
r = b.batch_force_closure(p, n, 0.5, workers=1)
t3 = time.perf_counter()
e = b.batch_epsilon_l1(p, n, 0.5, workers=1)
t4 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "closure": t3 - t2, "epsilon": t4 - t3,
                  "closed": int(r.is_closure.sum())}))
"""


def _run(cache: str, grasps: int, N: int) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, OMP_NUM_THREADS="1",
               OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")  # fmt: skip
    out = subprocess.run(
        [sys.executable, "-c", CHILD, str(grasps), str(N)],
        env=env, capture_output=True, text=True, check=True,
    )  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grasps", type=int, default=1000)
    parser.add_argument("--N", type=int, default=3)
    parser.add_argument("--runs", type=int, default=1, help="fresh caches to try")
    args = parser.parse_args()
    print(f"{args.grasps} grasps, N = {args.N}; load {os.getloadavg()[0]:.1f}")
    print(f"{'process':>8} {'import s':>9} {'closure s':>10} {'epsilon s':>10}")
    for _ in range(args.runs):
        with tempfile.TemporaryDirectory(prefix="numba-cache-") as cache:
            for label in ("cold", "warm", "warm"):
                t = time.perf_counter()
                r = _run(cache, args.grasps, args.N)
                wall = time.perf_counter() - t
                print(
                    f"{label:>8} {r['import']:9.2f} {r['closure']:10.2f} "
                    f"{r['epsilon']:10.2f}   (process {wall:.1f} s, "
                    f"load {os.getloadavg()[0]:.1f})"
                )


if __name__ == "__main__":
    main()
