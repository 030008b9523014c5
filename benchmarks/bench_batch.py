"""Grasps per second of the batch engine vs. per-grasp solvers, on one core.

Usage::

    python benchmarks/bench_batch.py [--quick] [--profile]

For each case the same seeded random grasps go through

* ``mathprog``: ``drakegrasp.force_closure`` / ``form_closure`` (one Drake
  ``MathematicalProgram`` per grasp; ``Grasp`` objects built outside the clock);
* ``scipy``: ``scipy.optimize.linprog(method="highs")`` per grasp on the same LP
  (LP2 with unit facet rows, or LP1), matrices built outside the clock — the
  most favourable timing for the baseline;
* ``batch``: ``drakegrasp.batch_force_closure`` / ``batch_form_closure`` from the
  raw arrays (validation and construction included), best of 3 runs.

The slow paths run on a prefix of the grasps and report per-grasp rates; the batch
engine's verdicts and d* are compared with both on that prefix.
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
from scipy.optimize import linprog  # noqa: E402

from drakegrasp import Contact, Grasp, normal_grasp_matrix  # noqa: E402
from drakegrasp.batch import batch_force_closure, batch_form_closure  # noqa: E402
from drakegrasp.core.friction_cone import ConeLayout  # noqa: E402

try:  # the single-grasp MathematicalProgram path
    from drakegrasp.closure.verdicts import force_closure, form_closure  # noqa: E402
except ImportError:  # pragma: no cover
    force_closure = form_closure = None

CASES = [
    # name, contacts, dimension, kind, mu
    ("3 spatial hard fingers, n_g=8", 3, 3, "force", 0.5),
    ("4 spatial hard fingers, n_g=8", 4, 3, "force", 0.5),
    ("4 planar hard fingers", 4, 2, "force", 0.5),
    ("7 frictionless spatial (form)", 7, 3, "form", 0.0),
]


def random_grasps(rng, K, N, d, spread):
    P = rng.normal(size=(K, N, d))
    P /= np.linalg.norm(P, axis=-1, keepdims=True)
    return P, -P + spread * rng.normal(size=(K, N, d))


def make_grasp(P, Nrm, mu, kind):
    model = "frictionless" if kind == "form" else "hard_finger"
    return Grasp(
        [Contact(p, n, mu=mu, contact_model=model) for p, n in zip(P, Nrm, strict=True)]
    )


def lp_matrices(grasp, kind):
    """(c, A_ub, b_ub, A_eq, b_eq, bounds) of LP1/LP2 for linprog."""
    N = grasp.num_contacts
    if kind == "form":
        G, F, normal_cols = normal_grasp_matrix(grasp), np.eye(N), list(range(N))
    else:
        layout = ConeLayout.of(grasp, 8)
        G, F = layout.G, layout.facet_matrix()
        normal_cols = list(layout.normal_positions)
    w, M = G.shape
    cost = np.zeros(M + 1)
    cost[-1] = -1.0
    budget = np.zeros(M + 1)
    budget[normal_cols] = 1.0
    A_ub = np.vstack([np.hstack([-F, np.ones((F.shape[0], 1))]), budget])
    b_ub = np.zeros(A_ub.shape[0])
    b_ub[-1] = N
    A_eq = np.hstack([G, np.zeros((w, 1))])
    bounds = [(None, None)] * M + [(0, None)]
    return cost, A_ub, b_ub, A_eq, np.zeros(w), bounds


def run_batch(P, Nrm, mu, kind, chunk_size):
    if kind == "form":
        return batch_form_closure(P, Nrm, chunk_size=chunk_size)
    return batch_force_closure(P, Nrm, mu=mu, chunk_size=chunk_size)


def rate(n, seconds):
    return n / seconds if seconds > 0 else float("inf")


def bench_case(name, N, d, kind, mu, *, n_batch, n_scipy, n_mp, chunk_size, seed):
    rng = np.random.default_rng(seed)
    P, Nrm = random_grasps(rng, n_batch, N, d, spread=0.4 if kind == "force" else 0.3)

    run_batch(P[:1000], Nrm[:1000], mu, kind, chunk_size)  # warm-up (imports, caches)
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        res = run_batch(P, Nrm, mu, kind, chunk_size)
        best = min(best, time.perf_counter() - t0)
    batch_rate = rate(n_batch, best)

    n_slow = max(n_scipy, n_mp)
    grasps = [make_grasp(P[k], Nrm[k], mu, kind) for k in range(n_slow)]
    lps = [lp_matrices(g, kind) for g in grasps[:n_scipy]]
    d_scipy = np.empty(n_scipy)
    c, A_ub, b_ub, A_eq, b_eq, bounds = lps[0]
    linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq, bounds=bounds)  # warm-up
    t0 = time.perf_counter()
    for k, (c, A_ub, b_ub, A_eq, b_eq, bounds) in enumerate(lps):
        out = linprog(
            c,
            A_ub=A_ub,
            b_ub=b_ub,
            A_eq=A_eq,
            b_eq=b_eq,
            bounds=bounds,
            method="highs",
        )
        d_scipy[k] = -out.fun
    scipy_rate = rate(n_scipy, time.perf_counter() - t0)

    mp_rate = float("nan")
    d_mp = v_mp = None
    if force_closure is not None and n_mp > 0:
        single = form_closure if kind == "form" else force_closure
        d_mp, v_mp = np.empty(n_mp), np.empty(n_mp, dtype=bool)
        single(grasps[0])  # warm-up
        t0 = time.perf_counter()
        for k in range(n_mp):
            r = single(grasps[k])
            d_mp[k], v_mp[k] = r.d_star, r.is_closure
        mp_rate = rate(n_mp, time.perf_counter() - t0)

    err_scipy = float(np.abs(res.d_star[:n_scipy] - d_scipy).max())
    line = {
        "case": name,
        "closure": float(res.is_closure.mean()),
        "batch": batch_rate,
        "scipy": scipy_rate,
        "mathprog": mp_rate,
        "n_batch": n_batch,
        "n_scipy": n_scipy,
        "n_mp": n_mp,
        "err_scipy": err_scipy,
        "err_mp": float(np.abs(res.d_star[:n_mp] - d_mp).max()) if n_mp else np.nan,
        "verdict_mismatch": int((res.is_closure[:n_mp] != v_mp).sum()) if n_mp else 0,
        "converged": bool(res.converged.all()),
    }
    return line


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer grasps")
    parser.add_argument("--profile", action="store_true", help="profile the batch")
    parser.add_argument("--chunk-size", type=int, default=None)
    args = parser.parse_args(argv)
    from drakegrasp.batch import DEFAULT_CHUNK_SIZE

    chunk = args.chunk_size or DEFAULT_CHUNK_SIZE
    scale = 0.1 if args.quick else 1.0
    n_batch, n_scipy, n_mp = int(100_000 * scale), int(1000 * scale), int(300 * scale)
    print(
        f"drakegrasp batch benchmark, one thread, chunk_size={chunk}; batch on "
        f"{n_batch} grasps (best of 3), scipy on {n_scipy}, MathematicalProgram on "
        f"{n_mp} (same seeded grasps, per-grasp rates)\n"
    )
    header = (
        f"{'case':32s} {'closed':>6s} {'batch/s':>10s} {'scipy/s':>9s} "
        f"{'mathprog/s':>10s} {'batch/scipy':>11s} {'batch/mp':>9s} "
        f"{'scipy/mp':>8s}  {'max|Δd*| scipy, mp':>20s} {'verdict≠mp':>10s}"
    )
    print(header)
    print("-" * len(header))
    for i, (name, N, d, kind, mu) in enumerate(CASES):
        r = bench_case(
            name,
            N,
            d,
            kind,
            mu,
            n_batch=n_batch,
            n_scipy=n_scipy,
            n_mp=n_mp,
            chunk_size=chunk,
            seed=100 + i,
        )
        print(
            f"{r['case']:32s} {r['closure']:6.1%} {r['batch']:10.0f} "
            f"{r['scipy']:9.0f} {r['mathprog']:10.0f} "
            f"{r['batch'] / r['scipy']:10.1f}x {r['batch'] / r['mathprog']:8.1f}x "
            f"{r['scipy'] / r['mathprog']:7.2f}x  "
            f"{r['err_scipy']:9.1e}, {r['err_mp']:8.1e} {r['verdict_mismatch']:10d}"
            + ("" if r["converged"] else "  (some LPs did not converge)")
        )
    if args.profile:
        rng = np.random.default_rng(100)
        P, Nrm = random_grasps(rng, n_batch, 3, 3, 0.4)
        print("\nprofile: batch_force_closure, 3 spatial hard fingers")
        prof = cProfile.Profile()
        prof.enable()
        batch_force_closure(P, Nrm, mu=0.5, chunk_size=chunk)
        prof.disable()
        pstats.Stats(prof).sort_stats("tottime").print_stats(12)


if __name__ == "__main__":
    main()
