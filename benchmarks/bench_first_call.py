"""The first batch call on a fresh install, and the load with a warm compile cache.

Usage::

    python benchmarks/bench_first_call.py [--grasps 1000] [--N 3] [--runs 1]
        [--python PYTHON] [--routes auto,jit]

Each figure comes from a new Python process with ``NUMBA_CACHE_DIR`` pointed at a
fresh temporary folder, so numba's on-disk cache starts empty (a fresh install)
and is then warm for the following processes (the same install, a new session):

* ``cold``: ``batch_force_closure`` of ``--grasps`` seeded ``--N``-contact spatial
  hard-finger grasps (μ 0.5, 8 generators), then ``batch_epsilon_l1`` of the same
  grasps, each timed from its call to its return, compiles included;
* ``warm``: the same two calls in a second and a third process that reuse the
  cache (loading the compiled code included);
* ``again``: the same two calls once more in the same process (the steady
  cost), so ``closure - again`` is what loading the kernels cost;
* ``import``: ``import drakegrasp.batch`` and reading its two functions (the
  package's lazy table imports their modules then; numpy included) in each
  process, apart.

Routes (``--routes``): ``auto`` takes the install's ahead-of-time kernels when
they were built (:mod:`drakegrasp.batch.aot`), ``jit`` forces numba's JIT and
its cache (``DRAKEGRASP_KERNELS=jit``).  ``--python`` runs the children with
another interpreter, e.g. that of a fresh venv where ``pip install .`` put a
non-editable copy (the children then import that copy, not this checkout).

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
b.batch_force_closure, b.batch_epsilon_l1  # the package's table loads them on read
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
b.batch_force_closure(p, n, 0.5, workers=1)
t5 = time.perf_counter()
b.batch_epsilon_l1(p, n, 0.5, workers=1)
t6 = time.perf_counter()
from drakegrasp.batch import aot, compiled
print(json.dumps({"import": t1 - t0, "closure": t3 - t2, "epsilon": t4 - t3,
                  "again": t6 - t4, "closed": int(r.is_closure.sum()),
                  "numba": "numba" in sys.modules, "route": aot.status(),
                  "compiled": compiled.compile_count(), "file": b.__file__}))
"""


def _run(python: str, cache: str, route: str, grasps: int, N: int) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, OMP_NUM_THREADS="1",
               OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1",
               DRAKEGRASP_KERNELS=route)  # fmt: skip
    out = subprocess.run(
        [python, "-c", CHILD, str(grasps), str(N)],
        env=env, capture_output=True, text=True, check=True, cwd=tempfile.gettempdir(),
    )  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grasps", type=int, default=1000)
    parser.add_argument("--N", type=int, default=3)
    parser.add_argument("--runs", type=int, default=1, help="fresh caches to try")
    parser.add_argument("--python", default=sys.executable, help="child interpreter")
    parser.add_argument("--routes", default="auto,jit", help="auto, jit or both")
    args = parser.parse_args()
    print(f"{args.grasps} grasps, N = {args.N}; load {os.getloadavg()[0]:.1f}")
    for route in args.routes.split(","):
        print(f"\nroute {route}")
        print(
            f"{'process':>8} {'import s':>9} {'closure s':>10} {'epsilon s':>10} "
            f"{'again s':>8} {'compiled':>8} {'numba':>6}"
        )
        for _ in range(args.runs):
            with tempfile.TemporaryDirectory(prefix="numba-cache-") as cache:
                for label in ("cold", "warm", "warm"):
                    t = time.perf_counter()
                    r = _run(args.python, cache, route, args.grasps, args.N)
                    wall = time.perf_counter() - t
                    print(
                        f"{label:>8} {r['import']:9.2f} {r['closure']:10.2f} "
                        f"{r['epsilon']:10.2f} {r['again']:8.2f} {r['compiled']:8d} "
                        f"{'yes' if r['numba'] else 'no':>6}   (process {wall:.1f} s, "
                        f"load {os.getloadavg()[0]:.1f})"
                    )
        print(f"  kernels: {r['route']}\n  package: {r['file']}")


if __name__ == "__main__":
    main()
