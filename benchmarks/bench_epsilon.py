"""Batch Ferrari–Canny ε (L1) against the per-grasp Qhull route, one core.

Usage::

    python benchmarks/bench_epsilon.py [--quick] [--N 3 8] [--cases hard ...]

For each case (spatial hard fingers, planar hard fingers, soft fingers,
frictionless contacts; μ 0.5, 8 generators) and number of contacts N, the same
seeded grasps (contacts on the unit sphere, normals inward plus noise
``--spread``: by default 6 % of three hard fingers and 93 % of eight are in
force closure; ``--spread 0.2`` closes most three-finger grasps) go through

* ``batch ε``: :func:`drakegrasp.batch.batch_epsilon_l1` with ``workers=1``
  (validation, primitive wrenches, the compiled expanding polytope and the
  Qhull fallback all included);
* ``kernel``: the compiled kernel alone on prebuilt wrenches;
* ``qhull loop``: what ``metrics=["epsilon_l1"]`` did before, one
  :func:`drakegrasp.quality.ferrari_canny` per grasp with its ``Grasp`` built
  inside the loop (:func:`drakegrasp.batch.epsilon.routes.epsilon_l1_per_grasp`);
* ``ferrari_canny``: the same calls on ``Grasp`` objects built outside the
  clock.

Rates are grasps per CPU second of this process (numpy/BLAS pinned to one
thread), best of ``--repeats``; numba compiles before the clock starts.  The
batch values are compared with the Qhull loop's on its grasps (max relative
|Δε|, zeros that differ), and the kernel's fallback count (grasps handed to
Qhull) is printed over all ``K``.

Columns: ``ratio`` is batch ε over the Qhull loop; ``max rel Δ`` the largest
|Δε|/ε where ε > 1e-3 (there 1e-9 relative is the binding bound),
``abs Δ`` the largest |Δε| where ε <= 1e-3 (bound 1e-12), ``out`` the grasps
outside ``max(1e-9 ε, 1e-12)``, ``≠0`` the grasps where exactly one route
says 0, ``fallb`` the grasps of all ``K`` that the kernel handed to Qhull,
``closed`` the fraction with ε > 0, ``facets`` the mean facets the kernel made
on them.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from drakegrasp import Contact, Grasp  # noqa: E402
from drakegrasp.batch import batch_epsilon_l1  # noqa: E402
from drakegrasp.batch.build.construction import batched_characteristic_lengths  # noqa: E402
from drakegrasp.batch.build.wrenches import batched_primitive_wrenches  # noqa: E402
from drakegrasp.batch.epsilon import kernel as epsilon_kernel  # noqa: E402
from drakegrasp.batch.epsilon.routes import epsilon_l1_per_grasp, epsilon_l1_routes  # noqa: E402
from drakegrasp.quality import ferrari_canny  # noqa: E402

CASES = {
    # name: (dimension, model, torsional friction)
    "hard": (3, "hard_finger", 0.0),
    "planar": (2, "hard_finger", 0.0),
    "soft": (3, "soft_finger", 0.2),
    "frictionless": (3, "frictionless", 0.0),
}
MU = 0.5
N_GEN = 8


def random_grasps(rng, K, N, d, spread=None):
    P = rng.normal(size=(K, N, d))
    P /= np.linalg.norm(P, axis=-1, keepdims=True)
    if spread is None:  # as bench_scale.py
        spread = 0.7 if N <= 4 else 0.4
    Nrm = -P + spread * rng.normal(size=(K, N, d))
    return P, Nrm / np.linalg.norm(Nrm, axis=-1, keepdims=True)


def best_cpu(fn, repeats):
    best, out = np.inf, None
    for _ in range(repeats):
        t0 = time.process_time()
        out = fn()
        best = min(best, time.process_time() - t0)
    return best, out


def epsilon_rates(case, N, *, quick=False, seed=0, repeats=3, spread=None):
    """One row: rates of every route, agreement and fallbacks for (case, N)."""
    d, model, nu = CASES[case]
    rng = np.random.default_rng(seed)
    K = int(np.clip((8_000 if quick else 40_000) / N, 500, 20_000))
    P, Nrm = random_grasps(rng, K, N, d, spread)
    mu_c, nu_c = np.full((K, N), MU), np.full((K, N), nu)
    p = np.zeros((K, d))
    b = batched_characteristic_lengths(P, p)
    opts = {"contact_model": model, "torsional_friction": nu}
    batch_epsilon_l1(P[:50], Nrm[:50], mu=MU, workers=1, **opts)  # compile / load
    t_batch, eps = best_cpu(
        lambda: batch_epsilon_l1(P, Nrm, mu=MU, workers=1, **opts), repeats
    )
    W = batched_primitive_wrenches(
        P, Nrm, mu_c, nu_c, p, b, contact_model=model, num_generators=N_GEN
    )
    t_kernel, (_, status, info) = best_cpu(
        lambda: epsilon_kernel.epsilon_l1_stack(W, return_info=True), repeats
    )
    _, qhull = epsilon_l1_routes(
        P, Nrm, mu_c, nu_c, p, b, contact_model=model, num_generators=N_GEN
    )
    budget = 1.0 if quick else 4.0  # CPU seconds aimed at per Qhull route
    probe = min(K, 20)
    t_probe, _ = best_cpu(
        lambda: epsilon_l1_per_grasp(
            P[:probe], Nrm[:probe], mu_c[:probe], nu_c[:probe], p[:probe],
            b[:probe], contact_model=model, num_generators=N_GEN,
        ),
        1,
    )  # fmt: skip
    Kq = int(np.clip(budget * probe / max(t_probe, 1e-9), 20, K))
    t_loop, ref = best_cpu(
        lambda: epsilon_l1_per_grasp(
            P[:Kq], Nrm[:Kq], mu_c[:Kq], nu_c[:Kq], p[:Kq], b[:Kq],
            contact_model=model, num_generators=N_GEN,
        ),
        1,
    )  # fmt: skip
    grasps = [
        Grasp([Contact(P[k, i], Nrm[k, i], mu=MU, contact_model=model,
                       torsional_friction=nu) for i in range(N)],
              characteristic_length=b[k])
        for k in range(Kq)
    ]  # fmt: skip
    t_fc, _ = best_cpu(lambda: [ferrari_canny(g) for g in grasps], 1)
    err = np.abs(eps[:Kq] - ref)
    # Relative where 1e-9 relative is the binding bound (ε > 1e-3), else the
    # 1e-12 absolute floor.
    big = ref > 1e-3
    ok = err <= np.maximum(1e-9 * ref, 1e-12)
    closed = eps > 0
    return {
        "case": case,
        "N": N,
        "K": K,
        "K_qhull": Kq,
        "batch ε": K / t_batch,
        "kernel": K / t_kernel,
        "qhull loop": Kq / t_loop,
        "ferrari_canny": Kq / t_fc,
        "max_rel_diff": float((err[big] / ref[big]).max()) if big.any() else 0.0,
        "max_abs_diff_small": float(err[~big].max()) if (~big).any() else 0.0,
        "outside_1e-9": int((~ok).sum()),
        "zero_mismatch": int(((ref == 0) != (eps[:Kq] == 0)).sum()),
        "fallbacks": int(qhull.sum()),
        "fallback_status": np.bincount(status, minlength=5).tolist(),
        "closed": float(closed.mean()),
        "insertions_closed": float(info[closed, 0].mean()) if closed.any() else 0.0,
        "facets_closed": float(info[closed, 1].mean()) if closed.any() else 0.0,
        "load": round(os.getloadavg()[0], 2),
    }


def print_row(r):
    print(
        f"{r['case']:12s} {r['N']:3d} {r['K']:6d} {r['load']:5.1f} "
        f"{r['batch ε']:9.0f} {r['kernel']:9.0f} {r['qhull loop']:9.0f} "
        f"{r['ferrari_canny']:9.0f} {r['batch ε'] / r['qhull loop']:7.1f} "
        f"{r['max_rel_diff']:9.1e} {r['max_abs_diff_small']:8.1e} "
        f"{r['outside_1e-9']:3d} {r['zero_mismatch']:3d} "
        f"{r['fallbacks']:5d} {r['closed']:6.2f} {r['facets_closed']:7.0f}",
        flush=True,
    )


HEADER = (
    f"{'case':12s} {'N':>3s} {'K':>6s} {'load':>5s} {'batch ε':>9s} {'kernel':>9s} "
    f"{'qhull':>9s} {'fc only':>9s} {'ratio':>7s} {'max rel Δ':>9s} {'abs Δ':>8s} "
    f"{'out':>3s} {'≠0':>3s} "
    f"{'fallb':>5s} {'closed':>6s} {'facets':>7s}"
)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer grasps")
    parser.add_argument("--N", nargs="*", type=int, default=[3, 8])
    parser.add_argument("--cases", nargs="*", default=["hard"], choices=CASES)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument(
        "--spread", type=float, default=None,
        help="normal noise (default 0.7 for N <= 4, else 0.4; smaller: more closed)",
    )  # fmt: skip
    parser.add_argument("--out", default=None, help="write the rows to this JSON")
    args = parser.parse_args(argv)
    if not epsilon_kernel.AVAILABLE:
        print("numba is not installed: batch ε takes the per-grasp Qhull route")
    print("batch ε L1 vs per-grasp Qhull: grasps per CPU second, one core; "
          f"μ {MU}, {N_GEN} generators\n")  # fmt: skip
    print(HEADER)
    print("-" * len(HEADER))
    rows = []
    for ci, case in enumerate(args.cases):
        for N in args.N:
            r = epsilon_rates(
                case, N, quick=args.quick, seed=100 * ci + N, repeats=args.repeats,
                spread=args.spread,
            )  # fmt: skip
            rows.append(r)
            print_row(r)
    if args.out:
        Path(args.out).write_text(json.dumps(rows, indent=1))
        print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
