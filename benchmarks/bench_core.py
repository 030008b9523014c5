"""Time the single-grasp programs (MathematicalProgram path) on seeded grasps.

Prints the median and 90th-percentile wall time of one call of each program, for
3-contact spatial hard-finger grasps with 8 generators, and the share of that time
spent building the program versus solving it.  The certificate rows time the
witness program alone on the full-rank "no" grasps (each verdict above already
includes it), so that a certificate's cost can be read against a verdict's.

Run: ``python benchmarks/bench_core.py [--grasps 200]``
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from pydrake.solvers import ClpSolver  # noqa: E402

import drakegrasp as dg  # noqa: E402
from drakegrasp.batch.witnesses import batch_certificates  # noqa: E402
from drakegrasp.certificates.witness import escape_twist, unresisted_wrench  # noqa: E402
from drakegrasp.closure import verdicts as closure  # noqa: E402


def random_grasps(count: int, num_contacts: int, seed: int = 7) -> list[dg.Grasp]:
    rng = np.random.default_rng(seed)
    grasps = []
    for _ in range(count):
        p = rng.normal(size=(num_contacts, 3))
        p /= np.linalg.norm(p, axis=1, keepdims=True)
        n = -p + 0.5 * rng.normal(size=p.shape)
        grasps.append(dg.Grasp([dg.Contact(p[i], n[i], mu=0.5) for i in range(len(p))]))
    return grasps


def batch_slice(result):
    """The first five grasps of a batch result (for a warm-up call)."""
    import dataclasses

    return dataclasses.replace(
        result,
        is_closure=result.is_closure[:5],
        rank=result.rank[:5],
        d_star=result.d_star[:5],
        margin=result.margin[:5],
        converged=result.converged[:5],
        metrics={},
        normal_certificate=None,
    )


def timed(fn, items) -> np.ndarray:
    times = np.empty(len(items))
    for i, item in enumerate(items):
        t0 = time.perf_counter()
        fn(item)
        times[i] = time.perf_counter() - t0
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grasps", type=int, default=200)
    args = parser.parse_args()
    grasps = random_grasps(args.grasps, 3)
    closures = sum(dg.force_closure(g).is_closure for g in grasps[:50])
    print(
        f"{args.grasps} seeded 3-contact spatial hard-finger grasps, mu = 0.5, "
        f"n_g = 8 ({closures}/50 of the first 50 in force closure)"
    )
    print(f"{'call':<44}{'median':>10}{'p90':>10}")
    rows = [
        ("force_closure (LP2, facets)", dg.force_closure),
        (
            "force_closure (LP2, generators)",
            lambda g: dg.force_closure(g, formulation="generators"),
        ),
        ("force_closure_exact (SOCP)", dg.force_closure_exact),
        ("form_closure (LP1)", dg.form_closure),
        ("build_force_closure_program only", dg.build_force_closure_program),
        ("certificate of a force-closure 'no' (LP)", "cert_poly"),
        ("certificate of an exact-cone 'no' (SOCP)", "cert_exact"),
        ("certificate of a form-closure 'no' (LP)", "cert_form"),
        ("certificate.check (no solver)", "check"),
        ("Clp solve of a prebuilt LP2 only", None),
    ]
    prebuilt = [dg.build_force_closure_program(g)[0] for g in grasps]
    solver = ClpSolver()
    fails = [g for g in grasps if not dg.force_closure(g).is_closure]
    certs = [dg.force_closure(g).certificate for g in fails]
    extra = {
        "cert_poly": lambda g: unresisted_wrench(g, 6, cones="polyhedral"),
        "cert_exact": lambda g: unresisted_wrench(g, 6, cones="exact"),
        "cert_form": lambda g: escape_twist(g, 6),
    }
    rows += [
        ("batch_certificates, per failing grasp", "batch"),
        ("force_closure without its certificate", "bare_poly"),
        ("force_closure_exact without its certificate", "bare_exact"),
    ]
    P = np.array([g.positions for g in grasps])
    n = np.array([g.normals for g in grasps])
    for name, fn in rows:
        if fn == "batch":
            batch = dg.batch_force_closure(P, n, mu=0.5)
            batch_certificates(P[:5], n[:5], batch_slice(batch), mu=0.5)  # warm up
            t0 = time.perf_counter()
            batch_certificates(P, n, batch, mu=0.5)
            per = (time.perf_counter() - t0) / max(1, int((~batch.is_closure).sum()))
            t = np.array([per])
            print(f"{name:<44}{per * 1e3:>8.3f}ms")
            # two jaws: rank 5, the vectorised null-space path
            rng = np.random.default_rng(3)
            P2 = rng.normal(size=(2000, 2, 3))
            n2 = -P2 + 0.3 * rng.normal(size=P2.shape)
            jaws = dg.batch_force_closure(P2, n2, mu=0.5)
            t0 = time.perf_counter()
            batch_certificates(P2, n2, jaws, mu=0.5)
            per = (time.perf_counter() - t0) / max(1, int((~jaws.is_closure).sum()))
            name = "batch_certificates, rank-deficient (2 jaws)"
            t = np.array([per])
            t0 = time.perf_counter()
            dg.batch_force_closure(P, n, mu=0.5)
            verdict = (time.perf_counter() - t0) / len(grasps)
            print(f"{'batch_force_closure, per grasp':<44}{verdict * 1e3:>8.3f}ms")
        elif fn in ("bare_poly", "bare_exact"):
            real = closure.unresisted_wrench
            closure.unresisted_wrench = lambda *_args, **_kwargs: None
            try:
                call = dg.force_closure if fn == "bare_poly" else dg.force_closure_exact
                t = timed(call, grasps)
            finally:
                closure.unresisted_wrench = real
        elif fn is None:
            t = timed(solver.Solve, prebuilt)
        elif fn == "check":
            t = timed(
                lambda gc: gc[1].check(gc[0]), list(zip(fails, certs, strict=True))
            )
        elif isinstance(fn, str):
            full = [g for g in fails if dg.force_closure(g).rank == 6]
            t = timed(extra[fn], full)
        else:
            t = timed(fn, grasps)
        median, p90 = np.median(t) * 1e3, np.percentile(t, 90) * 1e3
        print(f"{name:<44}{median:>8.3f}ms{p90:>8.3f}ms")


if __name__ == "__main__":
    main()
