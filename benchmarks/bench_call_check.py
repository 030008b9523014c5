"""Time what the check of every public call's arguments costs a call that fits.

Every public function and constructor is wrapped by
:func:`drakegrasp.core.calls.checked_call`: one more Python frame and a ``try``
per call, the signature read only when Python has refused the call.  This
prints, for an empty function and for four public calls, the median time per
call with and without the wrapper (``inspect.unwrap``), and their ratio, in
one run (the machines are shared: read the ratios, not the absolute figures).

Run: ``python benchmarks/bench_call_check.py [--repeat 2000]``
"""

from __future__ import annotations

import argparse
import inspect
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import drakegrasp as dg  # noqa: E402
from drakegrasp.core.calls import checked_call  # noqa: E402


def per_call(call, repeat: int, rounds: int = 7) -> float:
    """Median over ``rounds`` of the mean seconds per call of ``repeat`` calls."""
    call()  # warm
    means = []
    for _ in range(rounds):
        t0 = time.perf_counter()
        for _ in range(repeat):
            call()
        means.append((time.perf_counter() - t0) / repeat)
    return float(np.median(means))


def nothing(a, b=1, *, c=2):
    return a, b, c


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=2000)
    repeat = parser.parse_args().repeat

    grasp = dg.examples.cube_seven_contacts()
    p, n = np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, -1.0])
    checked_nothing = checked_call(nothing)
    contact_init = dg.Contact.__init__
    plain_init = contact_init.__wrapped__.__wrapped__  # below renamed and checked

    def plain_contact():
        contact = object.__new__(dg.Contact)
        plain_init(contact, p, n, mu=0.5)

    def checked_contact():  # the renamed-keyword wrapper left out, as above
        contact = object.__new__(dg.Contact)
        contact_init.__wrapped__(contact, p, n, mu=0.5)

    plain_matrix = inspect.unwrap(dg.grasp_matrix)
    plain_rank = inspect.unwrap(dg.matrix_rank)
    plain_form = inspect.unwrap(dg.form_closure)
    G = dg.grasp_matrix(grasp)
    cases = [
        ("empty function", lambda: nothing(1, c=3), lambda: checked_nothing(1, c=3)),
        (
            "Contact(p, n, mu=0.5)",
            plain_contact,
            checked_contact,
        ),
        (
            "grasp_matrix(grasp), 7 contacts",
            lambda: plain_matrix(grasp),
            lambda: dg.grasp_matrix(grasp),
        ),
        (
            "matrix_rank(G)",
            lambda: plain_rank(G),
            lambda: dg.matrix_rank(G),
        ),
        (
            "form_closure(grasp), 7 contacts",
            lambda: plain_form(grasp),
            lambda: dg.form_closure(grasp),
        ),
    ]
    print(f"{'call':34s} {'plain':>10s} {'checked':>10s} {'extra':>9s} {'ratio':>7s}")
    for name, plain, checked in cases:
        count = repeat if "closure" not in name else max(repeat // 20, 20)
        a, b = per_call(plain, count), per_call(checked, count)
        print(
            f"{name:34s} {a * 1e6:8.2f} µs {b * 1e6:8.2f} µs "
            f"{(b - a) * 1e9:6.0f} ns {b / a:7.3f}"
        )


if __name__ == "__main__":
    main()
