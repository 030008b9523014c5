"""Where a batch force-closure chunk spends its time outside the fused LP kernel.

Usage::

    python benchmarks/bench_chunk_overhead.py [--N 3 12 24] [--repeats 3]
        [--against DIR] [--rounds 3]

For each N the same seeded grasps (hard fingers, μ 0.5, 8 generators, the
sampler of ``bench_epsilon.py``) go through
:func:`drakegrasp.batch.batch_force_closure` with ``workers=1`` (validation,
construction, the compiled kernel, normal certificates, results).  The CPU time
of this process is split by timing every call of the compiled kernel
``drakegrasp.batch.lp.fused_kernel._full_rank_stack``; ``outside`` is the rest,
per grasp.  Rates are grasps per CPU second, best of ``--repeats``, numpy/BLAS
pinned to one thread, numba compiled before the clock starts.

``--against DIR`` measures a second source tree (for example a checkout of
``main``) the same way in separate processes, alternating with this one for
``--rounds`` rounds, and prints both (best over the rounds) with the load
average, so that old and new see the same machine.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from bench_epsilon import random_grasps  # noqa: E402


def measure(N: int, repeats: int) -> dict:
    """Best total and kernel CPU seconds of one ``batch_force_closure`` call."""
    import drakegrasp
    from drakegrasp.batch import batch_force_closure
    from drakegrasp.batch.lp import fused_kernel

    K = 200_000 if N <= 4 else 40_000
    rng = np.random.default_rng(0)
    P, Nrm = random_grasps(rng, K, N, 3)
    inner = fused_kernel._full_rank_stack
    spent = [0.0]

    def timed(*args):
        t0 = time.process_time()
        inner(*args)
        spent[0] += time.process_time() - t0

    fused_kernel._full_rank_stack = timed
    batch_force_closure(P[:200], Nrm[:200], mu=0.5, workers=1)  # compile / load
    best = None
    for _ in range(repeats):
        spent[0] = 0.0
        t0 = time.process_time()
        res = batch_force_closure(P, Nrm, mu=0.5, workers=1)
        total = time.process_time() - t0
        if best is None or total < best["total"]:
            best = {"total": total, "kernel": spent[0]}
    best.update(
        N=N, K=K, closed=float(np.mean(res.is_closure)), source=drakegrasp.__file__
    )
    return best


def _row(label: str, m: dict) -> str:
    K = m["K"]
    return (
        f"{label:>8} N={m['N']:>2}  {K / m['total']:>10,.0f} grasps/s  "
        f"total {m['total'] / K * 1e6:6.2f} us  kernel {m['kernel'] / K * 1e6:6.2f} us"
        f"  outside {(m['total'] - m['kernel']) / K * 1e6:5.2f} us"
    )


def _run(source: str | None, N: int, repeats: int) -> dict:
    env = dict(os.environ)
    if source:
        env["PYTHONPATH"] = source + os.pathsep + env.get("PYTHONPATH", "")
    cmd = [sys.executable, __file__, "--one", str(N), "--repeats", str(repeats)]
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, nargs="+", default=[3, 12, 24])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--against", help="another source tree, measured alternately")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one is not None:
        print(json.dumps(measure(args.one, args.repeats)))
        return
    if args.against is None:
        for N in args.N:
            print(_row("this", measure(N, args.repeats)), flush=True)
        return
    print(f"load average {os.getloadavg()}", flush=True)
    for N in args.N:
        best: dict[str, dict] = {}
        for _ in range(args.rounds):
            for label, source in (("against", args.against), ("this", None)):
                m = _run(source, N, args.repeats)
                if label not in best or m["total"] < best[label]["total"]:
                    best[label] = m
        for label in ("against", "this"):
            print(_row(label, best[label]), flush=True)
    print(f"load average {os.getloadavg()}", flush=True)


if __name__ == "__main__":
    main()
