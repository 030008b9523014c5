"""Time one grasp of many contacts through the MathematicalProgram path.

For N contacts spread over a unit sphere (hard fingers, and soft fingers with
ν = 0.1; μ = 0.3, 8 generators) it prints the time to build LP2 in each
formulation and the time of the whole ``force_closure`` call, so that the
build's share of a large program can be read off.  Building once took time
quadratic in N (the generator form's symbolic ``S λ``: 8.6 s of 9.9 s at
N = 400); it is now linear, and the solve (Clp) is the rest.

Run: ``python benchmarks/bench_many_contacts.py [--sizes 100 300 1000]``
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import drakegrasp as dg  # noqa: E402


def sphere_grasp(n: int, **contact) -> dg.Grasp:
    p = np.random.default_rng(n).normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    return dg.Grasp([dg.Contact(x, -x, mu=0.3, **contact) for x in p])


def timed(fn, *args, **kwargs):
    """``(seconds, fn(*args, **kwargs))``."""
    start = time.perf_counter()
    out = fn(*args, **kwargs)
    return time.perf_counter() - start, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 300, 1000])
    args = parser.parse_args()
    cases = {
        "hard": {},
        "soft": {"contact_model": "soft_finger", "torsional_friction": 0.1},
    }
    print(f"{'case':<5} {'N':>5} {'form':<10} {'build s':>8} {'call s':>8}  d*")
    for name, contact in cases.items():
        for n in args.sizes:
            for form in ("facets", "generators"):
                # a fresh grasp per timing: nothing cached from before
                build, _ = timed(
                    dg.build_force_closure_program,
                    sphere_grasp(n, **contact),
                    formulation=form,
                )
                call, r = timed(
                    dg.force_closure, sphere_grasp(n, **contact), formulation=form
                )
                print(
                    f"{name:<5} {n:>5} {form:<10} {build:>8.3f} {call:>8.3f}  "
                    f"{r.d_star:.4g} ({'yes' if r.is_closure else 'no'})",
                    flush=True,
                )


if __name__ == "__main__":
    main()
