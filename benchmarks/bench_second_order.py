"""Time second-order form closure: the SDP alone and the whole call.

    python benchmarks/bench_second_order.py [--repeats 50]

For five textbook grasps it prints dim W, t*, the median time of solving the
SDP with Clarabel (program prebuilt), of building it (with the support LP),
and of one whole ``second_order_form_closure`` call (LP1, support LP, SDP and,
for a "no", the escape LPs).
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from pydrake.solvers import ClarabelSolver  # noqa: E402

from drakegrasp import (  # noqa: E402
    Contact,
    ContactCurvature,
    Grasp,
    SurfaceCurvature,
    second_order_form_closure,
)
from drakegrasp.closure.second_order import build_second_order_program  # noqa: E402

P2, P3 = SurfaceCurvature.point(planar=True), SurfaceCurvature.point()


def ellipse():
    a, b = 0.08, 0.05
    g = Grasp(
        [
            Contact([a, 0], [-1, 0]),
            Contact([-a, 0], [1, 0]),
            Contact([0, b], [0, -1]),
            Contact([0, -b], [0, 1]),
        ]
    )
    k = [a / b**2, a / b**2, b / a**2, b / a**2]
    return g, [ContactCurvature(SurfaceCurvature((x,)), P2) for x in k]


def ellipsoid():
    axes = np.array([0.06, 0.045, 0.03])
    contacts, curv = [], []
    for i in range(3):
        j, k = [m for m in range(3) if m != i]
        for s in (1.0, -1.0):
            x = np.zeros(3)
            x[i] = s * axes[i]
            contacts.append(Contact(x, -s * np.eye(3)[i]))
            obj = SurfaceCurvature(
                (axes[i] / axes[j] ** 2, axes[i] / axes[k] ** 2), np.eye(3)[j]
            )
            curv.append(ContactCurvature(obj, SurfaceCurvature.convex(0.01)))
    return Grasp(contacts), curv


def concave_pinch():
    g = Grasp([Contact([0, 1.0], [0, -1]), Contact([0, -1.0], [0, 1])])
    obj, tip = SurfaceCurvature((0.25,)), SurfaceCurvature((-0.1,))
    return g, [ContactCurvature(obj, tip)] * 2


def box_between_faces():
    cs = [
        Contact([s * 0.05, y, z], [-s, 0, 0])
        for s in (1, -1)
        for y, z in ((0.01, 0), (-0.01, 0.01), (0, -0.01))
    ]
    return Grasp(cs), [ContactCurvature.point_finger(SurfaceCurvature.flat())] * 6


def sphere():
    rng = np.random.default_rng(0)
    n = rng.normal(size=(5, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    g = Grasp([Contact(-0.05 * v, v) for v in n])
    return g, [ContactCurvature(SurfaceCurvature.convex(0.05), P3)] * 5


def median_ms(fn, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times))


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=50)
    args = parser.parse_args()
    solver = ClarabelSolver()
    print(
        f"{'case':<22}{'dim W':>6}{'t*':>12}{'SDP solve':>12}"
        f"{'build':>10}{'whole call':>12}   (median ms)"
    )
    for name, make in [
        ("ellipse, 4 points", ellipse),
        ("ellipsoid, 6 tips", ellipsoid),
        ("concave pinch", concave_pinch),
        ("box, parallel faces", box_between_faces),
        ("sphere, 5 points", sphere),
    ]:
        grasp, curv = make()
        result = second_order_form_closure(grasp, curv)
        prog, _ = build_second_order_program(grasp, curv)
        solve = median_ms(lambda p=prog: solver.Solve(p), args.repeats)
        build = median_ms(
            lambda g=grasp, c=curv: build_second_order_program(g, c), args.repeats
        )
        whole = median_ms(
            lambda g=grasp, c=curv: second_order_form_closure(g, c), args.repeats
        )
        print(
            f"{name:<22}{result.dim_w:>6}{result.t_star:>12.5g}{solve:>12.2f}"
            f"{build:>10.2f}{whole:>12.2f}"
        )


if __name__ == "__main__":
    main()
