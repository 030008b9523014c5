"""Hostile inputs for the public API and the command line, and their outcomes.

A :class:`Case` is one call with what a right outcome is: a refusal
(``GraspError``), an answer (checked against an independent route where one
exists), or either.  :func:`run_case` classifies what happened into the
outcome table of issue 9:

* ``clear GraspError`` — refused with a one-line GraspError message;
* ``plausible verdict`` — answered, and the independent check (if any) agrees;
* ``raw exception`` — any exception that is not a GraspError;
* ``hang`` — took longer than the time limit (a SIGALRM interrupts Python code;
  a hard watchdog ends the process if C code never returns);
* ``silent wrong answer`` — answered where a refusal was due, or the answer
  disagrees with the independent route;
* ``valid input refused`` — a GraspError for an input inside the documented
  ranges (not in the issue's table; must also be 0);
* ``lost data`` — a file that existed before (input or earlier output) changed
  or vanished.

:func:`all_cases` builds every family; each family is deterministic (fixed
seeds), so the counts are reproducible.
"""

from __future__ import annotations

import collections
import contextlib
import hashlib
import itertools
import math
import os
import signal
import tempfile
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import fuzz_oracles as oracle
import numpy as np
from pydrake.math import RigidTransform
from sandbox import SandboxTimeout

import drakegrasp as dg
from drakegrasp.core import examples as ex
from drakegrasp.core import validation as V
from drakegrasp.planning.motors import torque_needed

OUTCOMES = (
    "clear GraspError",
    "plausible verdict",
    "raw exception",
    "hang",
    "silent wrong answer",
    "lost data",
    "valid input refused",
)
BAD = OUTCOMES[2:]
TIME_LIMIT = 10.0


@dataclass
class Case:
    """One hostile call; ``expect`` is "refuse", "answer" or "either"."""

    family: str
    name: str
    call: Callable[[], Any]
    expect: str = "either"
    check: Callable[[Any], bool] | None = None
    files: tuple[Path, ...] = ()


class _Timeout(Exception):
    pass


class ValidRefused(Exception):
    """Raised by a case whose worker judged a refusal illegitimate (a valid input)."""


def _alarm(signum, frame):
    raise _Timeout


def _digest(path: Path) -> str | None:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return None


def print_bad(bad, *, details: bool = False) -> int:
    """List the bad outcomes (all of them when ``details``); the exit status.

    ``bad`` holds ``(family, name, outcome, detail)`` rows; the status is 1
    when there is any, else 0.
    """
    if details or bad:
        print()
        for family, name, outcome, detail in bad:
            print(f"{outcome}: [{family}] {name}: {detail}")
    return 1 if bad else 0


def run_family(make_cases, sandboxed) -> tuple[dict, list, dict]:
    """Run a generated family: ``(families' counters, bad cases, seconds per family)``.

    ``make_cases(box)`` gives the cases, those that may crash or hang run in
    the :class:`~sandbox.Sandbox` ``box`` (60 s a call); ``sandboxed(case)``
    says which are (their limit 90 s, the others' 10 s).  Warnings are
    silenced: they are not outcomes.
    """
    from sandbox import Sandbox

    families = collections.defaultdict(collections.Counter)
    bad, seconds = [], collections.Counter()
    with contextlib.ExitStack() as stack:
        stack.enter_context(warnings.catch_warnings())
        warnings.simplefilter("ignore")
        box = stack.enter_context(Sandbox(timeout=60.0))
        for case in make_cases(box):
            start = time.perf_counter()
            limit = 90.0 if sandboxed(case) else 10.0
            outcome, detail = run_case(case, limit=limit)
            seconds[case.family] += time.perf_counter() - start
            families[case.family][outcome] += 1
            if outcome in BAD:
                bad.append((case.family, case.name, outcome, detail))
    return families, bad, seconds


def report_family(run, finding, findings: dict, checked: dict, doc: str) -> int:
    """The command line of a generated family: its outcome table and findings.

    ``run() -> (families, bad, seconds)`` runs the family; ``finding(*row)``
    names the known finding a bad row shows (or None), ``findings`` describes
    them, ``checked`` counts what the oracles checked, ``doc`` is the
    module's docstring.  Prints the table, each finding's first cases (all
    with ``--details``) and any other bad case; returns the exit status.
    """
    import argparse

    from report_surfaces import table

    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--details", action="store_true", help="every bad case")
    args = parser.parse_args()
    start = time.perf_counter()
    families, bad, seconds = run()
    print(f"generated inputs run in {time.perf_counter() - start:.0f} s")
    print(", ".join(f"{f}: {s:.1f} s" for f, s in seconds.items()))
    print(", ".join(f"{what}: {n}" for what, n in checked.items()), "\n")
    print(table(families))
    known = collections.defaultdict(list)
    for row in bad:
        key = finding(*row)
        if key is not None:
            known[key].append(row)
    for key, rows in sorted(known.items()):
        print(f"\n{key} ({len(rows)} cases): {findings[key]}")
        for family, name, outcome, detail in rows if args.details else rows[:3]:
            print(f"  {outcome}: [{family}] {name}: {detail[:160]}")
    others = [row for row in bad if finding(*row) is None]
    return print_bad(others, details=args.details)


def run_case(case: Case, limit: float = TIME_LIMIT) -> tuple[str, str]:
    """Run one case; return (outcome, detail)."""
    before = {p: _digest(p) for p in case.files}
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, limit)
    start = time.perf_counter()
    outcome, detail = "plausible verdict", ""
    try:
        result = case.call()
    except (_Timeout, SandboxTimeout):
        outcome, detail = "hang", f"over {limit:g} s"
    except ValidRefused as e:
        outcome, detail = "valid input refused", str(e)[:200]
    except dg.GraspError as e:
        text = str(e)
        if case.expect == "answer":
            outcome, detail = "valid input refused", text[:200]
        elif not text.strip() or "\n" in text.strip():
            outcome, detail = "raw exception", f"unclear GraspError message {text!r}"
        else:
            outcome, detail = "clear GraspError", text[:200]
    except (Exception, SystemExit) as e:  # noqa: BLE001 - what the fuzz counts
        # SystemExit: a failed Drake assertion, which ends a user's program
        outcome, detail = "raw exception", f"{type(e).__name__}: {str(e)[:200]}"
    else:
        if case.expect == "refuse":
            outcome, detail = "silent wrong answer", f"accepted: {_short(result)}"
        elif case.check is not None:
            try:
                ok = case.check(result)
            except Exception as e:  # noqa: BLE001
                ok, detail = False, f"check failed: {type(e).__name__}: {e}"
            if not ok:
                outcome = "silent wrong answer"
                detail = detail or f"disagrees: {_short(result)}"
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    if time.perf_counter() - start > limit and outcome != "hang":
        outcome, detail = "hang", f"{time.perf_counter() - start:.1f} s"
    for p, digest in before.items():
        if digest is not None and _digest(p) != digest:
            outcome, detail = "lost data", f"{p.name} changed or vanished"
    return outcome, detail


def _short(x) -> str:
    text = " ".join(repr(x).split())  # one line (a numpy or pydrake repr)
    return text if len(text) < 160 else text[:157] + "..."


# ----------------------------------------------------------------- value pools

NAN, INF = math.nan, math.inf
BAD_SCALARS = [
    NAN,
    INF,
    -INF,
    -1.0,
    "abc",
    None,
    True,
    1j,
    [1.0, 2.0],
    np.array([0.5, 0.5]),
    object(),
    {"a": 1},
]
BAD_VECTORS = [
    [NAN, 0, 1],
    [INF, 0, 0],
    [0, 0, 0],
    [1, 2],
    [1, 2, 3, 4],
    "abc",
    None,
    [1 + 1j, 0, 0],
    np.array([1, 0, 0], dtype=complex),
    [[1, 0], [0]],
    [1e308, -1e308, 1e308],
    [1.5e308, -1.5e308, 0],
    ["a", "b", "c"],
    [None, 0, 1],
    np.zeros((2, 2)),
]
HUGE_NORMALS = [
    [-1e155, 0, 0],
    [0, 1e200, 0],
    [1e-300, 0, 0],
    [3e307, 4e307, 0],
    [-1e-200, 1e-200, 0],
]


def _valid_grasp(mu=0.5):
    return ex.equator_fingers(mu)


# ------------------------------------------------------------------- families


def contact_cases() -> Iterator[Case]:
    """Contact(...) with hostile positions, normals, mu, nu and models."""
    for i, v in enumerate(BAD_VECTORS):
        if i != 2:  # [0, 0, 0] is a valid position
            yield Case(
                "Contact",
                f"position#{i}",
                lambda v=v: dg.Contact(v, [0, 0, 1]),
                "refuse",
            )
        if i in (10, 11):  # huge finite normals are valid (normalised safely)
            continue
        yield Case(
            "Contact", f"normal#{i}", lambda v=v: dg.Contact([0, 0, 1], v), "refuse"
        )
    for i, n in enumerate(HUGE_NORMALS):
        want = oracle.unit(n)

        def check(c, want=want):
            return np.allclose(c.normal, want, atol=1e-15)

        yield Case(
            "Contact",
            f"huge-normal#{i}",
            lambda n=n: dg.Contact([0, 0, 0], n),
            "answer",
            check,
        )
    coefficient_pool = BAD_SCALARS + [1e-300, 1e-13, 1e13, 1e78, 1e155, -0.0]
    for name in ("mu", "torsional_friction"):
        for i, x in enumerate(coefficient_pool):
            kw = {name: x, "contact_model": "soft_finger"}
            if name == "mu":
                kw["torsional_friction"] = 0.1
            expect = "either" if (isinstance(x, float) and x == 0.0) else "refuse"
            yield Case(
                "Contact",
                f"{name}#{i}",
                lambda kw=kw: dg.Contact([0, 0, 1], [0, 0, -1], **kw),
                expect,
            )
        for x in (0.0, 1e-12, 1e-6, 0.3, 1e6, 1e12):
            kw = {name: x, "contact_model": "soft_finger"}
            if name == "mu":
                kw["torsional_friction"] = 0.1
            yield Case(
                "Contact",
                f"{name}={x:g}",
                lambda kw=kw: dg.Contact([0, 0, 1], [0, 0, -1], **kw),
                "answer",
                lambda c, kw=kw, name=name: getattr(c, name) == kw[name],
            )
    for i, m in enumerate(["sticky", None, 3, "", "SOFT-FINGER", "Hard_Finger"]):
        expect = "answer" if i >= 4 else "refuse"
        kw = {"torsional_friction": 0.1} if i == 4 else {}
        yield Case(
            "Contact",
            f"model#{i}",
            lambda m=m, kw=kw: dg.Contact([0, 0, 1], [0, 0, -1], contact_model=m, **kw),
            expect,
        )
    # A perpendicular normal of length 1e200 is not antipodal (its squared norm
    # overflowed, the normal became 0 and the pair passed).
    a = dg.Contact([0, 0, 0], [1, 0, 0], mu=0.1)
    for i, n in enumerate(([0, 1e200, 0], [0, 1e-300, 0], [1e300, 1e300, 0])):
        b = dg.Contact([1, 0, 0], n, mu=0.1)
        yield Case(
            "Contact",
            f"antipodal-huge#{i}",
            lambda b=b: dg.is_antipodal([a, b]),
            "answer",
            lambda r: not r.is_antipodal,
        )
    yield Case(
        "Contact",
        "antipodal-huge-opposed",
        lambda: dg.is_antipodal([a, dg.Contact([1, 0, 0], [-1e300, 0, 0], mu=0.1)]),
        "answer",
        lambda r: r.is_antipodal,
    )
    yield Case(
        "Contact",
        "soft-without-nu",
        lambda: dg.Contact([0, 0, 1], [0, 0, -1], contact_model="soft_finger"),
        "refuse",
    )
    yield Case(
        "Contact",
        "planar-soft",
        lambda: dg.Contact(
            [0, 1], [0, -1], contact_model="soft_finger", torsional_friction=1
        ),
        "refuse",
    )


def grasp_cases() -> Iterator[Case]:
    """Grasp(...) with hostile contacts, reference points and lengths."""
    c3 = dg.Contact([0, 0, 1], [0, 0, -1], mu=0.5)
    c2 = dg.Contact([0, 1], [0, -1], mu=0.5)
    for i, cs in enumerate(
        [None, [], 5, "abc", [1, 2], [c3, c2], [c3, None], [(0, 0, 1)], {1: c3}]
    ):
        yield Case("Grasp", f"contacts#{i}", lambda cs=cs: dg.Grasp(cs), "refuse")
    for i, p in enumerate(BAD_VECTORS + [[1e21, 0, 0]]):
        # [0, 0, 0] is valid and None is the default; 1e308 is beyond the bound.
        expect = "answer" if i in (2, 6) else "refuse"
        yield Case(
            "Grasp",
            f"reference#{i}",
            lambda p=p: dg.Grasp([c3], reference_point=p),
            expect,
        )
    for i, b in enumerate(BAD_SCALARS + [0.0, 1e31, -5.0]):
        expect = "answer" if b is None else "refuse"  # None: the default
        yield Case(
            "Grasp",
            f"length#{i}",
            lambda b=b: dg.Grasp([c3], characteristic_length=b),
            expect,
        )
    far = [[1e20, 0, 0], [0, 1e19, 0]]
    for i, p in enumerate(far):
        yield Case(
            "Grasp",
            f"far-reference#{i}",
            lambda p=p: dg.Grasp([c3], reference_point=p),
            "answer",
            lambda g: math.isfinite(g.characteristic_length),
        )
    # characteristic length of huge positions is finite (was inf for 1e200).
    yield Case(
        "Grasp",
        "length-of-1e20",
        lambda: dg.Grasp(
            [
                dg.Contact([1e20, 1e20, 0], [1, 0, 0]),
                dg.Contact([-1e20, 0, 0], [1, 0, 0]),
            ]
        ),
        "answer",
        lambda g: g.characteristic_length == oracle_length(g),
    )
    for i, pos in enumerate([[1e200, 0, 0], [1.5e308, -1.5e308, 0], [1e21, 0, 0]]):
        yield Case(
            "Grasp",
            f"position-beyond-bound#{i}",
            lambda pos=pos: dg.Contact(pos, [1, 0, 0]),
            "refuse",
        )


def oracle_length(g) -> float:
    P = np.asarray(g.positions, dtype=np.longdouble) - np.asarray(
        g.reference_point, dtype=np.longdouble
    )
    return float(np.max(np.sqrt(np.sum(P * P, axis=1))))


def _functions_of_a_grasp():
    """Public functions whose first argument is a Grasp, with a valid call."""
    J = np.eye(9)
    d = np.array([1.0, 0, 0, 0, 0, 0])
    return {
        "form_closure": lambda g, **k: dg.form_closure(g, **k),
        "force_closure": lambda g, **k: dg.force_closure(g, **k),
        "force_closure_exact": lambda g, **k: dg.force_closure_exact(g, **k),
        "internal_forces": lambda g, **k: dg.internal_forces(g, J, **k),
        "ferrari_canny": lambda g, **k: dg.ferrari_canny(g, **k),
        "ferrari_canny_linf": lambda g, **k: dg.ferrari_canny(g, norm="Linf", **k),
        "lp2_d_star": lambda g, **k: dg.lp2_d_star(g, **k),
        "grasp_quality": lambda g, **k: dg.grasp_quality(g, **k),
        "grasp_singular_values": lambda g, **k: dg.grasp_singular_values(g, **k),
        "min_singular_value": lambda g, **k: dg.min_singular_value(g, **k),
        "isotropy": lambda g, **k: dg.isotropy(g, **k),
        "wrench_ellipsoid_volume": lambda g, **k: dg.wrench_ellipsoid_volume(g, **k),
        "hand_object_matrix": lambda g, **k: dg.hand_object_matrix(g, J, **k),
        "distance_to_singularity": lambda g, **k: dg.distance_to_singularity(g, J, **k),
        "uniformity_of_transformation": lambda g, **k: dg.uniformity_of_transformation(
            g, J, **k
        ),
        "manipulability_volume": lambda g, **k: dg.manipulability_volume(g, J, **k),
        "max_resistible_wrench": lambda g, **k: dg.max_resistible_wrench(
            g, d, max_normal_force=1.0, **k
        ),
        "build_max_resistible_wrench_program": lambda g, **k: (
            dg.build_max_resistible_wrench_program(g, d, max_normal_force=1.0, **k)
        ),
        "primitive_wrenches": lambda g, **k: dg.primitive_wrenches(g, **k),
        "grasp_matrix": lambda g, **k: dg.grasp_matrix(g, **k),
        "normal_grasp_matrix": lambda g, **k: dg.normal_grasp_matrix(g, **k),
        "build_form_closure_program": lambda g, **k: dg.build_form_closure_program(
            g, **k
        ),
        "build_force_closure_program": lambda g, **k: dg.build_force_closure_program(
            g, **k
        ),
        "build_exact_force_closure_program": lambda g, **k: (
            dg.build_exact_force_closure_program(g, **k)
        ),
        "build_internal_force_program": lambda g, **k: dg.build_internal_force_program(
            g, J, **k
        ),
        "is_antipodal": lambda g, **k: dg.is_antipodal(g, **k),
        "plot_wrench_space": lambda g, **k: dg.plot_wrench_space(g, **k),
    }


SCALED_METRICS = (
    "ferrari_canny", "ferrari_canny_linf", "grasp_quality", "grasp_singular_values",
    "min_singular_value", "isotropy", "wrench_ellipsoid_volume", "hand_object_matrix",
    "distance_to_singularity", "uniformity_of_transformation",
    "manipulability_volume", "primitive_wrenches",
)  # fmt: skip
"""The functions that divide moments by the grasp's characteristic length."""


def length_scale_cases() -> Iterator[Case]:
    """Every function of a grasp on a grasp whose length is far from its size.

    The metrics gave ε = 0 and σ_min = 0 at such lengths without a word; they
    refuse now.  The verdicts and matrices answer at any valid length.
    """
    g0 = ex.equator_fingers(mu=0.5)
    for b in (1e-300, 1e-15, 1e14, 1e30):
        g = dg.Grasp(
            g0.contacts, reference_point=g0.reference_point, characteristic_length=b
        )
        for name, fn in _functions_of_a_grasp().items():
            yield Case(
                name,
                f"characteristic-length-{b:g}",
                lambda fn=fn, g=g: fn(g),
                "refuse" if name in SCALED_METRICS else "either",
            )
    P = np.stack([g0.positions] * 3)
    N = np.stack([g0.normals] * 3)
    for b in (1e-15, 1e14, [1.0, 1e-15, 1.0]):
        yield Case(
            "batch_epsilon_l1",
            f"characteristic-lengths-{b}",
            lambda b=b: dg.batch_epsilon_l1(P, N, mu=0.5, characteristic_lengths=b),
            "refuse",
        )
        yield Case(
            "batch_force_closure",
            f"metrics-at-lengths-{b}",
            lambda b=b: dg.batch_force_closure(
                P, N, mu=0.5, characteristic_lengths=b, metrics=("isotropy",)
            ),
            "refuse",
        )
        yield Case(
            "batch_force_closure",
            f"verdicts-at-lengths-{b}",
            lambda b=b: dg.batch_force_closure(P, N, mu=0.5, characteristic_lengths=b),
            "answer",
            lambda r: bool(np.all(r.is_closure)),
        )


WRONG_GRASPS = [
    None,
    1,
    "grasp",
    [],
    np.zeros(3),
    {"contacts": []},
    dg.Contact([0, 0, 1], [0, 0, -1]),
]


def wrong_type_cases() -> Iterator[Case]:
    """Every grasp function with a first argument that is not a Grasp."""
    for name, fn in _functions_of_a_grasp().items():
        for i, g in enumerate(WRONG_GRASPS):
            if name == "is_antipodal" and i == 3:
                continue  # [] is a (bad) sequence of contacts: still a refusal
            yield Case(
                "wrong type", f"{name}(#{i})", lambda fn=fn, g=g: fn(g), "refuse"
            )
    others = {
        "friction_cone_facets": dg.friction_cone_facets,
        "friction_cone_generators": dg.friction_cone_generators,
        "contact_frame": dg.contact_frame,
        "contact_frames": dg.contact_frames,
        "matrix_rank": dg.matrix_rank,
        "plot_planar_grasp": dg.plot_planar_grasp,
    }
    for name, fn in others.items():
        for i, g in enumerate([None, "abc", 1j, np.array([np.nan, 1.0, 0]), object()]):
            yield Case(
                "wrong type", f"{name}(#{i})", lambda fn=fn, g=g: fn(g), "refuse"
            )
    for name in ("draw_grasp", "clear_grasp"):
        fn = getattr(dg, name)
        for i, g in enumerate([None, 1, "meshcat"]):
            yield Case(
                "wrong type",
                f"{name}(#{i})",
                lambda fn=fn, g=g: fn(g, _valid_grasp()),
                "refuse",
            )
    # batch entry points
    P, N = _valid_batch()
    for i, x in enumerate(
        [None, "abc", 1, np.zeros((2, 3)), np.zeros((1, 3, 4)), P.astype(complex)]
    ):
        yield Case(
            "wrong type",
            f"batch_force_closure(P#{i})",
            lambda x=x: dg.batch_force_closure(x, N, mu=0.5),
            "refuse",
        )
        yield Case(
            "wrong type",
            f"batch_form_closure(N#{i})",
            lambda x=x: dg.batch_form_closure(P, x),
            "refuse",
        )
    for i, x in enumerate([None, 1, [], object()]):
        yield Case(
            "wrong type",
            f"evaluate_file(#{i})",
            lambda x=x: dg.evaluate_file(x, x),
            "refuse",
        )


OPTION_POOLS = {
    "tol": [NAN, INF, 0.0, -1.0, 2.0, "abc", None, 1e-300, True, 1j],
    "rank_tol": [NAN, INF, 2.0, 0.0, -1.0, "abc", None, 1e-300, 1j],
    "num_generators": [None, 2, 2.5, 10**9, 10**7, "8", -3, True, INF],
    "torque_scale": [NAN, INF, 0.0, -1.0, "abc", 1e40, 1j],
    "angle_tol": [INF, NAN, -1.0, 1.0, "abc", None],
    "mu": [NAN, INF, -1.0, 1e78, 1e-200, "abc", 1j],
    "formulation": ["vertices", None, 3],
    "norm": ["L2", None, 1],
    "hand_jacobian": [
        np.full((9, 2), np.nan),
        np.eye(3),
        "abc",
        np.eye(9) * 1e200,
        np.eye(9, dtype=complex),
    ],
}


def _ragged_batch_cases(P, N) -> Iterator[Case]:
    """Ragged batches (a list of per-grasp arrays) with hostile pieces."""
    Pr = [P[0], P[1, :2], P[2, :1]]
    Nr = [N[0], N[1, :2], N[2, :1]]
    alone = [
        dg.batch_force_closure(p[None], n[None], mu=0.5).d_star[0]
        for p, n in zip(Pr, Nr, strict=True)
    ]
    yield Case(
        "batch",
        "ragged-agrees",
        lambda: dg.batch_force_closure(Pr, Nr, mu=0.5),
        "answer",
        lambda r: bool(np.array_equal(r.d_star, alone)),
    )
    hostile = {
        "ragged-nan": ([Pr[0], np.full((2, 3), NAN), Pr[2]], Nr, 0.5),
        "ragged-zero-normal": (Pr, [Nr[0], np.zeros((2, 3)), Nr[2]], 0.5),
        "ragged-empty-grasp": ([Pr[0], np.zeros((0, 3)), Pr[2]], Nr, 0.5),
        "ragged-mixed-dim": ([Pr[0], Pr[1][:, :2], Pr[2]], Nr, 0.5),
        "ragged-short-normals": (Pr, Nr[:2], 0.5),
        "ragged-normals-array": (Pr, N, 0.5),
        "ragged-mu-rows": (Pr, Nr, [np.ones(3), np.ones(3), np.ones(3)]),
        "ragged-mu-nan": (Pr, Nr, [0.5, NAN, 0.5]),
        "ragged-mu-strings": (Pr, Nr, ["a", "b", "c"]),
        "ragged-strings": ([Pr[0], "abc", Pr[2]], Nr, 0.5),
        "ragged-nested": ([Pr[0], [[0.0, 1.0], [2.0]], Pr[2]], Nr, 0.5),
    }
    for name, (p, n, mu) in hostile.items():
        yield Case(
            "batch",
            name,
            lambda p=p, n=n, mu=mu: dg.batch_force_closure(p, n, mu=mu),
            "refuse",
        )
        yield Case(
            "batch",
            f"{name}-epsilon",
            lambda p=p, n=n, mu=mu: dg.batch_epsilon_l1(p, n, mu=mu),
            "refuse",
        )
    yield Case(
        "batch",
        "uneven-stream",
        lambda: next(dg.batch.stream_form_closure([[[0.0, 0, 1]], [[1.0, 2]]], N)),
        "refuse",
    )


def _accepts(fn, option: str) -> bool:
    import inspect

    target = {
        "ferrari_canny_linf": dg.ferrari_canny,
    }.get(fn, getattr(dg, fn, None))
    if target is None:
        return False
    return option in inspect.signature(target).parameters


def option_cases() -> Iterator[Case]:
    """Every option of every grasp function, with hostile values."""
    g = _valid_grasp()
    for name, fn in _functions_of_a_grasp().items():
        for option, pool in OPTION_POOLS.items():
            if not _accepts(name, option) or (
                name == "ferrari_canny_linf" and option == "norm"
            ):
                continue
            if option == "mu" and name != "is_antipodal":
                continue
            if option == "hand_jacobian" and name not in (
                "force_closure",
                "force_closure_exact",
                "grasp_quality",
            ):
                continue
            for i, value in enumerate(pool):
                yield Case(
                    "options",
                    f"{name}({option}#{i})",
                    lambda fn=fn, o=option, v=value: fn(g, **{o: v}),
                    "refuse",
                )
    hostile = ["abc", None, [1j, 0, 0, 0, 0, 0], [NAN] * 6, np.zeros(6), [1, 0, 0], {}]
    for i, d in enumerate(hostile):
        yield Case(
            "options",
            f"max_resistible_wrench(direction#{i})",
            lambda d=d: dg.max_resistible_wrench(g, d, max_normal_force=1.0),
            "refuse",
        )
    for i, f in enumerate(["abc", None, 1j, -1.0, NAN, [1.0, 2.0], INF]):
        yield Case(
            "options",
            f"max_resistible_wrench(max_normal_force#{i})",
            lambda f=f: dg.max_resistible_wrench(g, np.eye(6)[0], max_normal_force=f),
            "refuse",
        )
    for i, flag in enumerate(["yes", 1, [True]]):
        yield Case(
            "options",
            f"grasp_quality(linf#{i})",
            lambda f=flag: dg.grasp_quality(g, linf=f),
            "refuse",
        )
    # Unbounded work is refused up front: L∞ with 40 contacts (4^40 face
    # choices), any ε of 300 contacts (a 2,400-point hull in 6-D).
    rng = np.random.default_rng(2)
    for num in (40, 300):
        P = rng.normal(size=(num, 3))
        P /= np.linalg.norm(P, axis=1, keepdims=True)
        big = dg.Grasp(
            [dg.Contact(p, -p + 0.2 * rng.normal(size=3), mu=0.5) for p in P]
        )
        yield Case(
            "options",
            f"ferrari_canny_linf(N={num})",
            lambda g=big: dg.ferrari_canny(g, norm="Linf"),
            "refuse",
        )
        if num == 300:
            yield Case(
                "options",
                f"ferrari_canny(N={num})",
                lambda g=big: dg.ferrari_canny(g),
                "refuse",
            )
    # Valid extremes are answered (and agree with the default where they should).
    ref = dg.force_closure(g)

    def force_closure_with(option, value, expect, check=None):
        return Case(
            "options",
            f"force_closure({option}={value:g})",
            lambda: dg.force_closure(g, **{option: value}),
            expect,
            check,
        )

    # Equator fingers: LP2's d* = 0.4194 and LP1's d* = 1 (three unit normal
    # forces balance), so closure holds for every tol in the valid range.
    for tol in (V.TOL_MIN, 1e-3, V.TOL_MAX):
        yield force_closure_with("tol", tol, "answer", lambda r: r.is_closure)
    for tol in (1.0, 2.0):
        yield force_closure_with("tol", tol, "refuse")
    J = np.eye(9)
    for name, fn in (
        ("internal_forces", dg.internal_forces),
        ("hand_object_matrix", dg.hand_object_matrix),
        ("build_internal_force_program", dg.build_internal_force_program),
        ("distance_to_singularity", dg.distance_to_singularity),
    ):
        for i, bad_J in enumerate(OPTION_POOLS["hand_jacobian"] + [None, J[:, :0]]):
            yield Case(
                "options",
                f"{name}(J#{i})",
                lambda fn=fn, bad_J=bad_J: fn(g, bad_J),
                "refuse",
            )
    for rt in (V.RANK_TOL_MIN, 1e-6, V.RANK_TOL_MAX):
        yield force_closure_with(
            "rank_tol",
            rt,
            "answer",
            lambda r: r.is_closure and abs(r.d_star - ref.d_star) < 1e-7,
        )
    yield force_closure_with(
        "num_generators",
        V.MAX_NUM_GENERATORS,
        "answer",
        lambda r: r.is_closure and r.d_star >= ref.d_star - 1e-7,
    )


def _valid_batch(K=4):
    g = _valid_grasp()
    return np.repeat(g.positions[None], K, 0), np.repeat(g.normals[None], K, 0)


def batch_cases() -> Iterator[Case]:
    """Batch entry points: hostile coefficient arrays, positions and options."""
    P, N = _valid_batch()
    single = dg.force_closure(_valid_grasp())
    for i, mu in enumerate(
        [
            NAN,
            INF,
            -1.0,
            1e78,
            1e155,
            1e-200,
            "abc",
            None,
            1j,
            np.full((4, 3), np.nan),
            np.full((4, 3), 1e78),
            np.full((4, 3), 1e-200),
            np.full((4, 3), 0.5 + 0j),
            np.full((4, 3), "x"),
            np.ones((5, 3)),
            np.ones((4, 2)),
        ]
    ):
        yield Case(
            "batch",
            f"mu#{i}",
            lambda mu=mu: dg.batch_force_closure(P, N, mu=mu),
            "refuse",
        )
    for i, nu in enumerate([NAN, -1.0, 1e13, "abc", 1j, None]):
        yield Case(
            "batch",
            f"nu#{i}",
            lambda nu=nu: dg.batch_force_closure(
                P, N, mu=0.5, contact_model="soft_finger", torsional_friction=nu
            ),
            "refuse",
        )
    for option, pool in OPTION_POOLS.items():
        if option in ("tol", "rank_tol", "num_generators"):
            for i, v in enumerate(pool):
                yield Case(
                    "batch",
                    f"{option}#{i}",
                    lambda o=option, v=v: dg.batch_force_closure(
                        P, N, mu=0.5, **{o: v}
                    ),
                    "refuse",
                )
                if option != "num_generators":
                    yield Case(
                        "batch",
                        f"form-{option}#{i}",
                        lambda o=option, v=v: dg.batch_form_closure(P, N, **{o: v}),
                        "refuse",
                    )
    # chunk_size=None is the default (as many grasps as fit in CHUNK_BYTES).
    for i, v in enumerate([0, -1, 2.5, "abc", True]):
        yield Case(
            "batch",
            f"chunk_size#{i}",
            lambda v=v: dg.batch_force_closure(P, N, mu=0.5, chunk_size=v),
            "refuse",
        )
    for i, v in enumerate(["yes", None, 1]):
        yield Case(
            "batch",
            f"progress#{i}",
            lambda v=v: dg.batch_force_closure(P, N, mu=0.5, progress=v),
            "refuse",
        )
    for i, v in enumerate(["sigma", None, ["epsilon_l1", "bogus"]]):
        yield Case(
            "batch",
            f"metrics#{i}",
            lambda v=v: dg.batch_force_closure(P, N, mu=0.5, metrics=v),
            "refuse",
        )
    yield from _ragged_batch_cases(P, N)
    bad_positions = P.copy()
    bad_positions[2, 1] = [1.5e308, -1.5e308, 0]
    yield Case(
        "batch",
        "overflowing-moments",
        lambda: dg.batch_force_closure(bad_positions, N, mu=0.5),
        "refuse",
    )
    huge = N.copy()
    huge[1, 0] *= 1e155
    huge[3, 2] *= 1e-300
    yield Case(
        "batch",
        "huge-normals",
        lambda: dg.batch_force_closure(P, huge, mu=0.5),
        "answer",
        lambda r: (
            bool(np.all(r.is_closure == single.is_closure))
            and np.allclose(r.d_star, single.d_star, atol=1e-6)
        ),
    )
    for mu in (1e-12, 1e-6, 1e3, 1e12):
        want = dg.force_closure(_valid_grasp(mu))
        yield Case(
            "batch",
            f"mu={mu:g}-agrees",
            lambda mu=mu: dg.batch_force_closure(P, N, mu=mu),
            "answer",
            lambda r, want=want: (
                bool(np.all(r.is_closure == want.is_closure))
                and bool(np.all(r.converged))
            ),
        )


def geometry_cases(seed: int = 0, count: int = 120) -> Iterator[Case]:
    """Random grasps at extreme units, far references and huge/tiny normals.

    Each verdict is compared with :func:`fuzz_oracles.closure_verdict` on the
    same grasp (which the oracle rescales itself); near-boundary grasps, where
    no independent verdict is clear, only need to answer.
    """
    rng = np.random.default_rng(seed)
    for k in range(count):
        num = int(rng.integers(2, 6))
        planar = k % 5 == 4
        dim = 2 if planar else 3
        unit = 10.0 ** rng.uniform(-9, 9)
        mu = float(rng.choice([0.0, 1e-12, 1e-6, 0.05, 0.5, 2.0, 1e6, 1e12]))
        p = rng.normal(size=(num, dim))
        p /= np.linalg.norm(p, axis=1, keepdims=True)
        n = -p + 0.4 * rng.normal(size=(num, dim))
        n *= 10.0 ** rng.uniform(-150, 150, size=(num, 1))
        ref = rng.normal(size=dim) * 10.0 ** rng.uniform(0, 6)
        P = p * unit
        contacts = [dg.Contact(P[i], n[i], mu=mu) for i in range(num)]
        grasp = dg.Grasp(contacts, reference_point=ref * unit)
        want = oracle.closure_verdict(P, n, [mu] * num)
        # The programs run on this grasp, each with the oracle's verdict for it.
        programs = [(f"force#{k} unit={unit:.1e} mu={mu:g}", dg.force_closure, want)]
        if k % 3 == 0:
            programs.append((f"exact#{k}", dg.force_closure_exact, want))
        if k % 3 == 1:
            wf = oracle.form_closure_verdict(P, n)
            programs.append((f"form#{k}", dg.form_closure, wf))
        for name, program, verdict in programs:
            yield Case(
                "geometry",
                name,
                lambda g=grasp, program=program: program(g),
                "answer",
                None
                if verdict is None
                else (lambda r, v=verdict: r.is_closure == v[0]),
            )
        if k % 4 == 0:
            Pb, Nb = P[None], n[None]
            yield Case(
                "geometry batch",
                f"batch#{k}",
                lambda Pb=Pb, Nb=Nb, r=ref * unit, mu=mu: dg.batch_force_closure(
                    Pb, Nb, mu=mu, reference_points=r
                ),
                "answer",
                None
                if want is None
                else (lambda r, want=want: bool(r.is_closure[0] == want[0])),
            )


def monotonicity_cases(seed: int = 1, count: int = 80) -> Iterator[Case]:
    """soft >= hard >= frictionless and larger mu/nu >= smaller, every metric."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        # 3 to 6 contacts with normals near the inward radial: most grasps are
        # in closure for some models and not others, so the chain is tested.
        num = int(rng.integers(3, 7))
        p = rng.normal(size=(num, 3))
        p /= np.linalg.norm(p, axis=1, keepdims=True)
        n = -p + 0.2 * rng.normal(size=(num, 3))
        mu = float(10.0 ** rng.uniform(-12, 1))
        nu = float(10.0 ** rng.uniform(-12, 12))
        hard = dg.Grasp([dg.Contact(p[i], n[i], mu=mu) for i in range(num)])
        soft = hard.with_friction(contact_model="soft_finger", torsional_friction=nu)
        fl = hard.with_friction(contact_model="frictionless")

        def both(hard=hard, soft=soft, fl=fl):
            return [
                (f(fl), f(hard), f(soft))
                for f in (
                    lambda g: dg.force_closure(g),
                    lambda g: dg.force_closure_exact(g),
                    lambda g: dg.ferrari_canny(g),
                )
            ]

        def check(out):
            (lf, lh, ls), (xf, xh, xs), (ef, eh, es) = out
            verdicts = (lf.is_closure <= lh.is_closure <= ls.is_closure) and (
                xf.is_closure <= xh.is_closure <= xs.is_closure
            )
            d_ok = ls.d_star >= lh.d_star - 1e-7 and xs.d_star >= xh.d_star - 1e-6
            eps_ok = ef <= eh + 1e-9 and eh <= es + 1e-9 * max(1.0, eh)
            return bool(verdicts and d_ok and eps_ok)

        yield Case(
            "monotone",
            f"soft>=hard>=frictionless#{k} mu={mu:.1e} nu={nu:.1e}",
            both,
            "answer",
            check,
        )


# ----------------------------------------------------------------- files, CLI


def _save(path: Path, **arrays) -> Path:
    with open(path, "wb") as f:
        np.savez(f, **arrays)
    return path


def file_cases(root: Path) -> Iterator[Case]:
    """evaluate_file and the CLI (in process) on damaged files and unsafe paths."""
    from drakegrasp import cli

    P, N = _valid_batch(6)

    def refused(name, source, out, *, cli_name=None, files=None):
        """Cases: ``evaluate_file(source, out)`` refused (``cli_name``: the CLI too).

        ``files`` (default: the input) must be left as they were.
        """
        files = (source,) if files is None else files
        yield Case(
            "files",
            name,
            lambda: dg.evaluate_file(source, out),
            "refuse",
            files=files,
        )
        if cli_name is not None:
            yield Case(
                "files",
                cli_name,
                lambda: _cli(cli, "batch", str(source), str(out)),
                "refuse",
                files=files,
            )

    good = _save(root / "good.npz", positions=P, normals=N, mu=np.full((6, 3), 0.5))
    payload = good.read_bytes()
    damaged = {
        "truncated": payload[: len(payload) // 2],
        "empty": b"",
        "text": b"positions,normals\n1,2,3\n",
        "random": bytes(
            np.random.default_rng(0).integers(0, 256, 4096, dtype=np.uint8)
        ),
        "zip-header-only": payload[:30],
        "bit-flipped": payload[:200] + bytes([payload[200] ^ 0xFF]) + payload[201:],
    }
    for name, data in damaged.items():
        path = root / f"{name}.npz"
        path.write_bytes(data)
        out = root / f"out-{name}.npz"
        yield from refused(f"evaluate_file({name})", path, out, cli_name=f"cli({name})")
    npy = root / "lone.npz"
    np.save(open(npy, "wb"), P)
    yield from refused("lone-npy", npy, root / "o1.npz")
    pickled = root / "pickled.npz"
    np.savez(open(pickled, "wb"), positions=np.array([object()] * 3), normals=N)
    yield from refused("pickled", pickled, root / "o2.npz")
    for i, arrays in enumerate(
        [
            {"positions": P},
            {"positions": P, "normals": N, "bogus": P},
            {"positions": P.astype(complex), "normals": N, "mu": 0.5},
            {"positions": np.array(["a"] * 3), "normals": N, "mu": 0.5},
            {"positions": P, "normals": N, "mu": np.full((6, 3), np.nan)},
            {"positions": P, "normals": N},
            {"positions": P, "normals": N, "mu": 1e80},
        ]
    ):
        path = _save(root / f"bad{i}.npz", **arrays)
        yield from refused(f"bad-arrays#{i}", path, root / f"o-bad{i}.npz")
    # The output is the input: directly, through a symlink, through a hard link.
    link = root / "link.npz"
    link.symlink_to(good)
    hard = root / "hard.npz"
    os.link(good, hard)
    for name, out in (
        ("same", good),
        ("symlink", link),
        ("hardlink", hard),
        ("upper", root / "GOOD.npz"),
    ):
        if name == "upper" and not (root / "GOOD.npz").exists():
            continue  # case-sensitive file system: a different file
        yield from refused(
            f"output-is-input({name})",
            good,
            out,
            cli_name=f"cli-output-is-input({name})",
        )
    # An existing output is kept unless --overwrite; then it is replaced whole.
    existing = _save(root / "existing.npz", kept=np.arange(3))
    yield from refused(
        "existing-output",
        good,
        existing,
        cli_name="cli-existing-output",
        files=(good, existing),
    )
    upper = root / "OUT.NPZ"

    def wrote_upper(result):
        return (
            upper.exists() and not (root / "OUT.NPZ.npz").exists() and _readable(upper)
        )

    yield Case(
        "files",
        "upper-suffix",
        lambda: dg.evaluate_file(good, upper),
        "answer",
        wrote_upper,
        files=(good,),
    )
    replaced = _save(root / "replace.npz", kept=np.arange(3))

    def overwrite_and_check():
        r = dg.evaluate_file(good, replaced, overwrite=True)
        return r

    yield Case(
        "files",
        "overwrite",
        overwrite_and_check,
        "answer",
        lambda r: _readable(replaced) and len(r) == 6,
        files=(good,),
    )
    yield from refused("output-dir", good, root)
    yield from refused("output-missing-dir", good, root / "nope" / "o.npz")
    yield from refused("output-suffix", good, root / "o.txt")
    yield from refused("input-missing", root / "missing.npz", root / "o3.npz", files=())
    # A failure while writing leaves the earlier output intact (atomic write).
    earlier = _save(root / "earlier.npz", kept=np.arange(3))

    def failing_write():
        from drakegrasp.batch.files.writer import placed

        try:
            with placed(earlier, overwrite=True) as tmp:
                with open(tmp, "wb") as f:
                    f.write(b"partial")
                raise OSError("disk full (simulated)")
        except OSError:
            return sorted(p.name for p in root.glob(".earlier.npz.*"))
        return ["no error"]

    # The error propagates, no temporary file is left, the earlier file stays.
    yield Case(
        "files",
        "failed-write-keeps-earlier",
        failing_write,
        "answer",
        lambda left: left == [],
        files=(earlier,),
    )
    # CLI option errors: one line, non-zero exit.
    for i, argv in enumerate(
        [
            ["batch", str(good), str(root / "c1.npz"), "--num-generators", "100000000"],
            ["batch", str(good), str(root / "c2.npz"), "--tol", "2"],
            [
                "batch",
                str(good),
                str(root / "c3.npz"),
                "--contact-model",
                "soft_finger",
            ],
            ["batch", str(good), str(root / "c4.npz"), "--chunk-size", "0"],
            ["batch", str(root / "bad5.npz"), str(root / "c5.npz")],
        ]
    ):
        yield Case(
            "files",
            f"cli-options#{i}",
            lambda a=argv: _cli(cli, *a),
            "refuse",
            files=(good,),
        )
    # plan --out follows batch: an existing file is kept unless --overwrite.
    planned = root / "earlier-plan.parquet"
    planned.write_bytes(b"earlier plan")
    yield Case(
        "files",
        "cli-plan-out-existing",
        lambda: _cli(cli, "plan", "--num", "2", "--out", str(planned)),
        "refuse",
        files=(planned,),
    )


def _readable(path: Path) -> bool:
    with np.load(path) as data:
        return "is_closure" in data.files


def _cli(cli, *argv):
    """Run the CLI in process; raise a GraspError-like failure on non-zero exit."""
    import contextlib
    import io

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = cli.main(list(argv))
    text = err.getvalue()
    if code == 0:
        return text
    lines = [line for line in text.splitlines() if line.strip()]
    if (
        "Traceback" in text
        or len(lines) != 1
        or not lines[0].startswith("drakegrasp: error:")
    ):
        raise RuntimeError(f"CLI exit {code} with stderr {text!r}")
    raise dg.InvalidOptionError(lines[0])


WALK_VALUES = (object(), 1j, None, "x", np.full(3, np.nan))


def api_walk_cases(names=None) -> Iterator[Case]:
    """Every callable of ``drakegrasp.__all__`` with wrong-typed required arguments.

    Each required parameter (positional or keyword-only) gets the same wrong
    value; functions without required parameters (``list_scenes``) are left
    out, as are exceptions and result dataclasses (plain records).
    """
    import dataclasses
    import inspect

    for name in sorted(dg.__all__ if names is None else names):
        obj = getattr(dg, name)
        if inspect.ismodule(obj) or not callable(obj) or name == "ContactModel":
            continue
        if isinstance(obj, type) and (
            issubclass(obj, BaseException)
            or (dataclasses.is_dataclass(obj) and name not in ("Contact", "Grasp"))
        ):
            continue
        params = inspect.signature(obj).parameters.values()
        required = [
            p
            for p in params
            if p.default is p.empty and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
        ]
        if not required:
            continue
        for i, wrong in enumerate(WALK_VALUES):
            args = [wrong for p in required if p.kind != p.KEYWORD_ONLY]
            kwargs = {p.name: wrong for p in required if p.kind == p.KEYWORD_ONLY}
            yield Case(
                "api walk",
                f"{name}#{i}",
                lambda obj=obj, a=args, k=kwargs: obj(*a, **k),
                "refuse",
            )


def picture_cases() -> Iterator[Case]:
    """Pictures with bad colours, sizes and outlines (matplotlib and Meshcat)."""
    import matplotlib

    matplotlib.use("Agg")

    from drakegrasp.core import examples

    g = examples.planar_square_four_contacts()
    bad = [
        {"colors": {"contact": "notacolor"}},
        {"colors": {"contact": (2.0, 0, 0)}},
        {"colors": {"bogus": "red"}},
        {"colors": "red"},
        {"force_scale": NAN},
        {"force_scale": -1.0},
        {"cone_length": INF},
        {"outline": "abc"},
        {"side": None},
        {"result": "abc"},
    ]
    for i, kw in enumerate(bad):
        yield Case(
            "pictures",
            f"plot_planar_grasp#{i}",
            lambda kw=kw: dg.plot_planar_grasp(g, **kw),
            "refuse",
        )
    for i, kw in enumerate(
        [{"tol": NAN}, {"tol": "abc"}, {"num_generators": 10**9}, {"tol": 2.0}]
    ):
        yield Case(
            "pictures",
            f"plot_wrench_space#{i}",
            lambda kw=kw: dg.plot_wrench_space(g, **kw),
            "refuse",
        )
    from pydrake.geometry import Meshcat

    meshcat = _meshcat(Meshcat)
    if meshcat is None:
        return
    g3 = _valid_grasp()
    for i, kw in enumerate(
        [
            {"colors": {"point": "notacolor"}},
            {"colors": {"point": (2.0, 0, 0)}},
            {"colors": {"point": (1, 0)}},
            {"colors": "red"},
            {"cone": "wide"},
            {"cone_height": NAN},
            {"prefix": ""},
            {"side": 3},
        ]
    ):
        yield Case(
            "pictures",
            f"draw_grasp#{i}",
            lambda kw=kw: dg.draw_grasp(meshcat, g3, **kw),
            "refuse",
        )


_MESHCAT = []


def _meshcat(cls):
    """One Meshcat for all cases (each opens a server); None if none can open."""
    if not _MESHCAT:
        try:
            _MESHCAT.append(cls())
        except RuntimeError:
            _MESHCAT.append(None)
    return _MESHCAT[0]


# ----------------------------------------------------------------- planning

OWN_GRIPPER = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
PLAN_POOLS = {
    "mu": [v for v in BAD_SCALARS if v is not True],
    "num_candidates": [-1, 1.5, NAN, "10", None, True, 10**12, [3]],
    "seed": [-1, 1.5, "abc", NAN, [1, -2], object()],
    "clearance": [-1e-3, NAN, INF, "abc", None, 1j],
    "distance_tolerance": [0.0, -1e-4, NAN, INF, "abc", None],
    "robustness_samples": [-1, 2.5, "8", NAN, True],
    "certify": [-1, 2.5, "all", NAN],
    "weight_check": [-1, 2.5, True, "3"],
    "workers": [0, -2, 1.5, "two", True],
    "progress": ["yes", 1, None],
    "noise": [{"wobble": 1}, {"position_mm": -1.0}, {"position_mm": NAN}, "loud", 3],
    "contact_model": ["sticky", 3, None],
    "torsional_friction": [-0.1, NAN, "abc"],
    "complete_unseen": ["no", 1, None],
    "object_mass": [-1.0, 0.0, NAN, INF, "abc"],
    "tilt": [NAN, -1.0, "abc"],
    "min_fingers": [0, -1, 2.5, "2"],
    "squeeze_limit": [-1.0, 0.0, NAN, INF, "abc", True, [5.0], 10**400],
}
"""Hostile values of :func:`drakegrasp.plan_grasps`'s options, one at a time."""


SHAKE_POOLS = {
    "squeeze": [-1.0, 0.0, NAN, INF, "abc", True],  # None: the default
    "stiffness": [-1.0, NAN, INF, "x"],
    "damping": [-1.0, NAN, "x"],
    "directions": [[], [[0, 0, 0]], [[NAN, 0, 1]], "down", [[1, 2]], None],
    "settle": [-1.0, NAN, INF],
    "phase": [0.0, -1.0, NAN, INF],
    "blend": [-1.0, NAN],
    "time_step": [0.0, -1e-3, NAN, 10.0],
    "max_displacement": [-1.0, NAN],
    "max_rotation": [-1.0, NAN],
    "object_mass": [0.0, -1.0, NAN, INF, "1", True, 10**400, 1e308],
    "X_WO": [
        "x",
        np.eye(4),
        RigidTransform([NAN, 0.0, 0.0]),
        RigidTransform(np.diag([2.0, 2.0, 2.0, 1.0])),
    ],
}
"""Hostile values of :func:`drakegrasp.shake_test`'s options, one at a time."""

CANDIDATE_POOLS = {
    "q_hand": [np.array([NAN, NAN]), np.array([0.01]), np.array([0.01, INF]), "ab"],
    "closing_signs": [(1.0,), (NAN, 1.0)],
    "X_WH": [RigidTransform([NAN, 0.0, 0.0]), np.eye(4)],
    "X_WO": [RigidTransform(np.diag([2.0, 2.0, 2.0, 1.0]))],
    "object_mass": [-1.0, 0.0, INF, 1e308, "x", None],
}
"""Hostile fields of a planned candidate (flat jaw: two closing joints)."""


SHAKEN_POOLS = {
    "top": [0, -1, True, 1.5, "3", None, 10**4 + 1, NAN],
    "held_from": ["x", None, 0, "SEAT"],
    "stiffnes": [1.0],  # a misspelt shake_test option
}
"""Hostile values of :func:`drakegrasp.shake_candidates`' own options."""


def _shake_candidates_cases(scene, best) -> Iterator[Case]:
    """``shake_candidates``: refused before any simulation, or a bounded answer."""
    for option, values in {**SHAKE_POOLS, **SHAKEN_POOLS}.items():
        for i, value in enumerate(values):
            yield Case(
                "planning",
                f"shake_candidates {option}={_short(value)}#{i}",
                lambda o=option, v=value: dg.shake_candidates(
                    scene.add_models, [best], **{o: v}
                ),
                "refuse",
            )
    for i, candidates in enumerate(["abc", None, 3.5, best, [best, "x"], [{}]]):
        yield Case(
            "planning",
            f"shake_candidates candidates={_short(candidates)}#{i}",
            lambda c=candidates: dg.shake_candidates(scene.add_models, c),
            "refuse",
        )
    # Bad options are refused even when there is nothing to shake.
    yield Case(
        "planning",
        "shake_candidates squeeze=-1 on no candidates",
        lambda: dg.shake_candidates(scene.add_models, [], squeeze=-1.0),
        "refuse",
    )
    # An endless iterator is read top deep, not forever.
    yield Case(
        "planning",
        "shake_candidates endless iterator top=1",
        lambda: dg.shake_candidates(
            scene.add_models,
            itertools.repeat(best),
            top=1,
            settle=0.05,
            phase=0.05,
            blend=0.02,
            seat=0.05,
            directions=[(1, 0, 0)],
        ),  # fmt: skip
        "answer",
        lambda r: len(r) == 1 and r[0].result is not None,
    )


def _shake_cases(scene) -> Iterator[Case]:
    """``shake_test`` refusals (before any simulation) on the scene's best grasp."""
    best = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=8, mu=0.5, seed=0, robustness_samples=4,
    )[0]  # fmt: skip
    for option, values in SHAKE_POOLS.items():
        for i, value in enumerate(values):
            yield Case(
                "planning",
                f"shake {option}={_short(value)}#{i}",
                lambda o=option, v=value: dg.shake_test(
                    scene.add_models, best, **{o: v}
                ),
                "refuse",
            )
    for name, models, candidate in (
        ("shake no candidate", scene.add_models, "x"),
        ("shake no models", None, best),
    ):
        yield Case(
            "planning",
            name,
            lambda m=models, c=candidate: dg.shake_test(m, c),
            "refuse",
        )
    yield from _shake_candidates_cases(scene, best)
    # Valid directions that once made NaN gravity (a raw RuntimeError from
    # Drake): a norm that overflows, and a blend from the settling -z to +z.
    for name, kw in {
        "shake directions=[[1e308, 1e308, 0]]": {"directions": [[1e308, 1e308, 0]]},
        "shake directions=[[0, 0, 1]] (opposite -z)": {
            "directions": [[0.0, 0.0, 1.0]], "seat": 0.0, "settle": 0.0, "blend": 0.2
        },
    }.items():  # fmt: skip
        yield Case(
            "planning",
            name,
            lambda kw=kw: dg.shake_test(scene.add_models, best, phase=0.3, **kw),
            "answer",
            lambda r: np.isfinite(r.max_displacement),
        )
    # An edited or deserialised candidate: refused before Drake sees it.
    for field, values in CANDIDATE_POOLS.items():
        for i, value in enumerate(values):
            edited = replace(best, **{field: value})
            if field != "object_mass":  # apply puts no mass anywhere
                yield Case(
                    "planning",
                    f"apply {field}={_short(value)}#{i}",
                    lambda c=edited: c.apply(scene.plant, scene.context.Clone()),
                    "refuse",
                )
            yield Case(
                "planning",
                f"shake {field}={_short(value)}#{i}",
                lambda c=edited: dg.shake_test(scene.add_models, c),
                "refuse",
            )
    for i, body in enumerate(["box::nope", 3.5, None]):
        yield Case(
            "planning",
            f"apply object_body={_short(body)}#{i}",
            lambda b=body: best.apply(
                scene.plant, scene.context.Clone(), object_body=b
            ),
            "either" if body is None else "refuse",
        )
    # the object body by its scoped name, as every other function takes it
    yield Case(
        "planning",
        "apply object_body='box::box'",
        lambda: best.apply(scene.plant, scene.context.Clone(), object_body="box::box"),
        "answer",
    )


def planning_cases() -> Iterator[Case]:
    """``plan_grasps`` on drakegrasp's own gripper and box: hostile options,
    hostile clouds, and two valid calls whose ranking is checked."""
    scene = dg.planning_scene(
        "package://drakegrasp/objects/box.sdf", hand_url=OWN_GRIPPER
    )
    hand_only = dg.planning_scene(None, hand_url=OWN_GRIPPER)
    base = dict(hand=scene.hand, num_candidates=8, mu=0.5, seed=0,
                robustness_samples=4)  # fmt: skip

    def plan(**kw):
        return dg.plan_grasps(
            scene.plant, scene.context, scene.object_body, **{**base, **kw}
        )

    def ranked(r) -> bool:
        scores = [c.score for c in r]
        return len(r) <= 8 and scores == sorted(scores, reverse=True)

    yield Case("planning", "valid", plan, "answer", ranked)
    yield Case(
        "planning", "zero-candidates", lambda: plan(num_candidates=0), "either",
        lambda r: len(r) == 0 and r.table()["p_WH"].shape == (0, 3),
    )  # fmt: skip
    for option, values in PLAN_POOLS.items():
        for i, value in enumerate(values):
            yield Case(
                "planning",
                f"{option}={_short(value)}#{i}",
                lambda o=option, v=value: plan(**{o: v}),
                "refuse",
            )
    yield Case(
        "planning", "squeeze_limit-below-every-need",
        lambda: plan(squeeze_limit=1e-3), "answer",
        lambda r: len(r) == 0 or "squeeze_limit 0.001 N holds none" in r.reason,
    )  # fmt: skip
    # torque_needed of the best candidate: hostile weights and candidates.
    best = plan()[0]

    def torque(candidate=best, weight=1.0):
        return torque_needed(
            scene.plant, scene.context, candidate, scene.object_body, weight=weight
        )

    for i, w in enumerate(["abc", None, -1.0, INF, [1.0], True]):
        yield Case("planning", f"torque_needed(weight#{i})",
                   lambda w=w: torque(weight=w), "refuse")  # fmt: skip
    yield Case("planning", "torque_needed(candidate)",
               lambda: torque(candidate="x"), "refuse")  # fmt: skip
    yield Case(
        "planning", "torque_needed(weight=nan)", lambda: torque(weight=NAN),
        "answer", lambda t: np.isnan(t),
    )  # fmt: skip
    # hand=None: every body but the object's (valid here: the gripper).
    yield Case("planning", "hand=None", lambda: plan(hand=None), "either", ranked)
    for name, kw in {
        "hand-is-object": {"hand": [scene.object_body]},
        "soft-finger-without-nu": {"contact_model": "soft_finger"},
        "object-and-cloud": {"point_cloud": np.zeros((10, 3))},
    }.items():
        yield Case("planning", name, lambda kw=kw: plan(**kw), "refuse")
    yield from _odd_plant_cases(scene)
    # Clouds: the plant holds the hand alone.
    rng = np.random.default_rng(5)
    cloud = rng.normal(size=(200, 3))
    cloud = 0.04 * cloud / np.linalg.norm(cloud, axis=1, keepdims=True)
    holes = cloud.copy()
    holes[::7] = NAN

    def on_cloud(points, **kw):
        return dg.plan_grasps(
            hand_only.plant, hand_only.context, None,
            **{**base, "hand": hand_only.hand, "point_cloud": points, **kw},
        )  # fmt: skip

    hostile_clouds = {
        "cloud-empty": (np.zeros((0, 3)), {}),
        "cloud-all-nan": (np.full((50, 3), NAN), {}),
        "cloud-2d": (cloud[:, :2], {}),
        "cloud-strings": ([["a", "b", "c"]] * 20, {}),
        "cloud-huge": (cloud * 1e300, {}),
        "cloud-one-point": (cloud[:1], {}),
        "cloud-normals-short": (cloud, {"cloud_normals": -cloud[:10]}),
        "cloud-normals-zero": (cloud, {"cloud_normals": np.zeros_like(cloud)}),
        "cloud-viewpoint-nan": (cloud, {"viewpoint": [NAN, 0, 0]}),
        "cloud-viewpoint-short": (cloud, {"viewpoint": [1.0, 0.0]}),
        "cloud-complete-unseen-str": (cloud, {"viewpoint": [0.5, 0, 0],
                                              "complete_unseen": "no"}),
    }  # fmt: skip
    for name, (points, kw) in hostile_clouds.items():
        yield Case(
            "planning", name, lambda p=points, kw=kw: on_cloud(p, **kw), "refuse"
        )
    yield from _shake_cases(scene)
    flat = np.c_[rng.uniform(-0.03, 0.03, (300, 2)), np.zeros(300)]
    line = np.c_[np.linspace(-0.03, 0.03, 100), np.zeros((100, 2))]
    for name, kw in {
        "cloud-valid": {"cloud_normals": -cloud},
        # NaN marks a depth camera's missing points: they are dropped.
        "cloud-nan-holes": {"point_cloud": holes},
        # degenerate but finite: the fitted surface (a quadric per point, a
        # fingertip's first touch) must not break on them
        "cloud-every-point-five-times": {"point_cloud": np.repeat(cloud, 5, axis=0)},
        "cloud-nine-points": {"point_cloud": cloud[:9]},
        "cloud-flat-plate": {
            "point_cloud": flat,
            "cloud_normals": np.tile([0.0, 0.0, 1.0], (300, 1)),
        },
        "cloud-one-line": {"point_cloud": line},
        # 10,000 points within 10 µm of one spot: bounded memory (the fits
        # once padded every point to the densest one's neighbours: 2.9 GiB)
        "cloud-dense-spot": {
            "point_cloud": np.vstack(
                [cloud, cloud[0] + rng.normal(0.0, 1e-5, (10000, 3))]
            ),
            "cloud_normals": np.vstack([-cloud, np.tile(-cloud[0], (10000, 1))]),
        },
        "cloud-seen-from-one-side": {"viewpoint": [0.5, 0.0, 0.0]},
    }.items():
        points = kw.pop("point_cloud", cloud)
        yield Case(
            "planning",
            name,
            lambda p=points, kw=kw: on_cloud(p, **kw),
            "either",
            ranked,
        )
    # Fused frames repeat points; estimated normals once saw every
    # neighbourhood as a line and refused the cloud.
    yield Case(
        "planning",
        "cloud-estimated-normals-every-point-ten-times",
        lambda: on_cloud(np.repeat(cloud, 10, axis=0)),
        "answer",
        lambda r: len(r) > 0 and ranked(r),
    )
    yield from _estimated_normal_cases()
    # Only a normal's direction counts: any finite length plans as unit normals
    # (1e200 once overflowed the norm into zero normals, all poses rejected).
    for scale in (1e200, 1e-310):
        yield Case(
            "planning",
            f"cloud-normals-times-{scale:g}",
            lambda s=scale: on_cloud(cloud, cloud_normals=-cloud * s),
            "answer",
            lambda r: len(r) > 0 and ranked(r),
        )


def _estimated_normal_cases() -> Iterator[Case]:
    """``read_cloud``'s estimated normals on hostile clouds of easy shapes: a
    flat grid's normals must stay vertical."""
    from drakegrasp.planning.cloud import read_cloud

    def vertical(name, points, tol_deg):
        def check(r) -> bool:
            _, n, dropped = r
            cos = np.cos(np.radians(tol_deg))
            return dropped == 0 and bool(np.all(np.abs(n[:, 2]) >= cos))

        call = lambda: read_cloud(points)  # noqa: E731
        return Case("planning", f"read_cloud-{name}", call, "answer", check)

    g = np.stack(np.meshgrid(np.arange(10), np.arange(10)), -1).reshape(-1, 2)
    grid = np.c_[0.005 * g, np.zeros(100)]
    rng = np.random.default_rng(11)
    clouds = {
        # fused frames: each point 25 times, round-off apart (its copies once
        # filled its neighbourhood, normals up to 90 deg off)
        "jittered-copies-1e-12": np.repeat(grid, 25, axis=0)
        + rng.normal(0.0, 1e-12, (2500, 3)),
        "jittered-copies-1e-9": np.repeat(grid, 25, axis=0)
        + rng.normal(0.0, 1e-9, (2500, 3)),
        # 10^5 copies of one spot: merged without listing 10^10 pairs
        "one-spot-100k-times": np.vstack(
            [grid, grid[0] + rng.normal(0.0, 1e-12, (100_000, 3))]
        ),
        "far-1e6-m-spacing-5e-6": 1e-3 * grid + [999_999.0, 0.0, 0.0],
        "float32": grid.astype(np.float32),
        "integer-mm": np.round(1000 * grid).astype(int),
    }
    for name, points in clouds.items():
        yield vertical(f"grid-{name}", points, 1.0)
    # eight points on a plane with 0.1 mm noise: a quadric fitted to the
    # noise once passed the 20-point F threshold (12 deg off here)
    rng = np.random.default_rng(125)
    eight = np.c_[rng.uniform(0, 0.01 * np.sqrt(8), (8, 2)), rng.normal(0, 1e-4, 8)]
    yield vertical("eight-noisy-plane-points", eight, 5.0)


def load_cases() -> Iterator[Case]:
    """Grasp forces at extreme μ mixes and loads of 1e-300 / 1e300 N.

    A RuntimeWarning counts as a raw exception here.  Forces said to hold a
    load must balance it (to 1e-3 of it), and none may be inf or NaN.
    """

    def pinch(*mus):
        spots = ([-1.0, 0, 0], [1.0, 0, 0], [0, -1.0, 0])
        return dg.Grasp(
            [
                dg.Contact(p, -np.array(p), mu=mu)
                for p, mu in zip(spots[: len(mus)], mus, strict=True)
            ]
        )

    def strict(call):
        def run():
            with warnings.catch_warnings():
                warnings.simplefilter("error", RuntimeWarning)
                return call()

        return run

    def balanced(g, w):
        def check(r) -> bool:
            if not r.feasible:
                return True
            f = np.concatenate(r.contact_forces)
            if not np.all(np.isfinite(f)):
                return False
            res = dg.grasp_matrix(g) @ f + w
            return bool(np.max(np.abs(res)) <= 1e-3 * np.max(np.abs(w)))

        return check

    up = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    cases = {
        # forces of 3e8 N that balanced two thirds of the load were "held"
        "mu-0.5-1e-12-1e-12": (pinch(0.5, 1e-12, 1e-12), 0.2 * up, {}),
        "mu-1e12-load-1e300": (pinch(1e12, 1e12), 1e300 * up, {}),
        "mu-1e-12-load-1e300": (pinch(1e-12, 1e-12), 1e300 * up, {}),
        "mu-1e-12-1e12-load-1e-300": (
            pinch(1e-12, 1e12),
            1e-300 * up,
            {"max_normal_force": 1.0},
        ),
        "mu-1e-12-load-1e-300": (pinch(1e-12, 1e-12), 1e-300 * up, {}),
    }
    for name, (g, w, kw) in cases.items():
        call = strict(lambda g=g, w=w, kw=kw: dg.grasp_forces(g, w, **kw))
        yield Case("load", f"grasp_forces {name}", call, "either", balanced(g, w))


def _odd_rig(edit):
    """A free flat-pad jaw and a free box, edited before ``Finalize``.

    ``edit(plant, parser, hand, obj)`` welds or joins bodies; it may return
    keyword arguments of ``plan_grasps`` (another ``hand``).
    """
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.framework import DiagramBuilder

    from drakegrasp.plant.models import register_models

    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    parser = Parser(plant)
    register_models(parser)
    parser.SetAutoRenaming(True)
    hand = parser.AddModels(url=OWN_GRIPPER)[0]
    obj = parser.AddModels(url="package://drakegrasp/objects/box.sdf")[0]
    kw = edit(plant, parser, hand, obj) or {}
    plant.Finalize()
    context = builder.Build().CreateDefaultContext()
    body = plant.GetBodyByName("box", obj)
    return lambda: dg.plan_grasps(
        plant, context, body, **{"hand": hand, "num_candidates": 4, "mu": 0.5, **kw}
    )


def _odd_plant_cases(scene) -> Iterator[Case]:
    """Objects no hand can pick up and hands the planner cannot place.

    Each was planned on, or refused naming another cause: a welded object (held
    "nan N/N"), a hinged one, one welded to the palm; a palm welded to the
    world or a table ("add the hand without welding it", where the weld is the
    table's); fingers without their free palm; ``hand=None`` taking a second
    free box for the hand's base; the world or a finger as the object.
    """
    from pydrake.multibody.tree import RevoluteJoint

    from drakegrasp.plant.friction import hand_object_friction

    def palm(p, h):
        return p.GetBodyByName("palm", h).body_frame()

    def box(p, o):
        return p.GetBodyByName("box", o).body_frame()

    def other_box(p, parser):
        return p.GetBodyByName(
            "box", parser.AddModels(url="package://drakegrasp/objects/box.sdf")[0]
        )

    def object_welded(p, parser, h, o):
        p.WeldFrames(p.world_frame(), box(p, o))

    def object_hinged(p, parser, h, o):
        p.AddJoint(RevoluteJoint("hinge", p.world_frame(), box(p, o), [0, 0, 1]))

    def object_on_palm(p, parser, h, o):
        p.WeldFrames(palm(p, h), box(p, o), RigidTransform([0, 0.1, 0]))

    def hand_welded(p, parser, h, o):
        p.WeldFrames(p.world_frame(), palm(p, h))

    def hand_on_table(p, parser, h, o):
        t = other_box(p, parser).body_frame()
        p.WeldFrames(p.world_frame(), t, RigidTransform([0.3, 0, 0]))
        p.WeldFrames(t, palm(p, h), RigidTransform([-0.3, 0, 0.2]))

    def fingers_only(p, parser, h, o):
        return {
            "hand": [p.GetBodyByName(f, h) for f in ("left_finger", "right_finger")]
        }

    def second_box(p, parser, h, o):
        p.SetDefaultFloatingBaseBodyPose(
            other_box(p, parser), RigidTransform([0.5, 0, 0])
        )
        return {"hand": None}

    def welded_and_second_box(p, parser, h, o):
        hand_welded(p, parser, h, o)
        return second_box(p, parser, h, o)

    edits = {
        "object-welded-to-world": object_welded,
        "object-on-a-hinge": object_hinged,
        "object-welded-to-palm": object_on_palm,
        "hand-welded-to-world": hand_welded,
        "hand-welded-to-table": hand_on_table,
        "hand-fingers-palm-free": fingers_only,
        "hand-none-second-free-box": second_box,
        "hand-none-welded-palm-second-box": welded_and_second_box,
    }
    for name, edit in edits.items():
        yield Case("planning", name, lambda e=edit: _odd_rig(e)(), "refuse")
    finger = f"{scene.plant.GetModelInstanceName(scene.hand)}::left_finger"

    def plan_on(obj):
        return dg.plan_grasps(
            scene.plant, scene.context, obj, hand=scene.hand, num_candidates=4, mu=0.5
        )

    for name, obj in {"object-world": "world", "object-is-finger": finger}.items():
        yield Case("planning", name, lambda o=obj: plan_on(o), "refuse")
    for name, obj in {
        "friction-of-world": "world",
        "friction-of-world-index": scene.plant.world_body().index(),
        "friction-of-finger": finger,
    }.items():
        yield Case(
            "planning",
            name,
            lambda o=obj: hand_object_friction(
                scene.plant, scene.context, o, scene.hand
            ),
            "refuse",
        )


MODEL_SPELLINGS = [
    "SOFT_FINGER",
    "Soft-Finger",
    " soft_finger ",
    dg.ContactModel.SOFT_FINGER,
]
BAD_MODELS = ["sticky", "", None, 3, 1j, ["soft_finger"], b"soft_finger"]


def _replaced_model(options):
    """``dataclasses.replace(options, model="frictionless")``, its warning caught."""
    import dataclasses
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        return dataclasses.replace(options, model="frictionless")


def value_cases() -> Iterator[Case]:
    """Option objects, core linear algebra and the batch builders, value by value.

    Each field of ``AnalysisOptions`` and ``BatchOptions`` gets the hostile
    values of its kind (refused when the object is made), unknown and doubled
    arguments are refused; ``equilibrated`` gets what is not a finite real
    matrix; the batch builders get every spelling of a contact model
    (answered alike) and names that are none.
    """
    from drakegrasp.batch.build.construction import contact_kinds
    from drakegrasp.batch.build.wrenches import (
        batched_primitive_wrenches,
        wrenches_per_contact,
    )
    from drakegrasp.core.linalg import equilibrated

    bad_flags = ["yes", 1, None, [True], NAN]
    analysis = {
        "mu": [NAN, INF, -1.0, True, "0.5", [0.5], 1j, "plants"],
        "contact_model": BAD_MODELS,
        "torsional_friction": [NAN, INF, -0.1, True, "0.1", [0.1]],
        "distance_tolerance": [NAN, INF, 0.0, -1e-4, "1e-4", True, None],
        "plane": ["xz", "XY", 0, ["xy"], ""],
        "characteristic_length": [NAN, INF, 0.0, -1.0, 1e-310, 1e31, "1", True],
        "num_generators": OPTION_POOLS["num_generators"],
        "tol": OPTION_POOLS["tol"],
        "allow_penetration": bad_flags,
        "patches": ["all", None, 1, ["vertices"]],
        "check_pose": bad_flags,
        "load": ["weight", [1, 2], np.zeros(7), [NAN] * 6, [INF] * 6, ["1"] * 6, 1j],
        "torque_limits": ["motors", [-1.0], [NAN], [-INF], [[1.0]], [True], 1j, []],
        # 1.0: a valid mass, but no load 'gravity' to weigh it
        "object_mass": [NAN, INF, 0.0, -1.0, 1e-330, "1", True, [1.0], 1j, 1.0],
    }
    batch = {
        "contact_model": BAD_MODELS,
        "num_generators": OPTION_POOLS["num_generators"],
        "tol": OPTION_POOLS["tol"],
        "rank_tol": OPTION_POOLS["rank_tol"],
        "metrics": ["sigma", ["volume"], [None], 3, [["sigma_min"]]],
        "kernel": ["fortran", None, 1],
        "chunk_size": [0, -1, 2.5, "8", True, INF],
        "workers": [0, -2, 2.5, "2", True],
        "progress": bad_flags,
    }
    for cls, pools in ((dg.AnalysisOptions, analysis), (dg.BatchOptions, batch)):
        for field, pool in pools.items():
            for i, value in enumerate(pool):
                yield Case(
                    "values",
                    f"{cls.__name__}({field}#{i})",
                    lambda cls=cls, f=field, v=value: cls(**{f: v}),
                    "refuse",
                )
        yield Case(
            "values", f"{cls.__name__}(bogus)", lambda c=cls: c(bogus=1), "refuse"
        )
        yield Case(
            "values", f"{cls.__name__}(*too many)",
            lambda c=cls: c(*([None] * 20)), "refuse",
        )  # fmt: skip
        yield Case(
            "values", f"{cls.__name__}(model+contact_model)",
            lambda c=cls: c(model="frictionless", contact_model="hard_finger"),
            "refuse",
        )  # fmt: skip
        yield Case(
            "values", f"{cls.__name__}(self=)", lambda c=cls: c(self=1), "refuse"
        )
        yield Case(
            "values", f"{cls.__name__}()", cls, "answer",
            lambda o: o.contact_model is dg.ContactModel.HARD_FINGER,
        )  # fmt: skip
        yield Case(
            "values", f"dataclasses.replace({cls.__name__}, model=)",
            lambda c=cls: _replaced_model(c()), "answer",
            lambda o: o.contact_model is dg.ContactModel.FRICTIONLESS,
        )  # fmt: skip
    # A str subclass is kept as the plain str it spells.
    yield Case(
        "values", "AnalysisOptions(numpy str_)",
        lambda: dg.AnalysisOptions(plane=np.str_("xy"), mu=np.str_("plant")),
        "answer", lambda o: type(o.plane) is str and type(o.mu) is str,
    )  # fmt: skip
    # equilibrated: what is not a finite real matrix, and extreme columns
    for i, A in enumerate(
        [[1.0, 2.0], 1.0, [[NAN, 1.0], [0, 1]], [[INF, 0], [0, 1]],
         [[1j, 0], [0, 1]], "A", None, [[1, 2], [3]], np.array([["a"]])]
    ):  # fmt: skip
        yield Case("values", f"equilibrated#{i}", lambda A=A: equilibrated(A), "refuse")
    for v in [1e-320, 1e-310, 1e-200, 1e154, 1e300, 1.7e308]:
        A = np.array([[v, 0.0], [-v, 3.0], [v, 4.0]])

        def unit(r):
            A_s, scale = r
            return np.allclose(np.linalg.norm(A_s, axis=0), 1.0, rtol=1e-14) and (
                np.all(np.isfinite(A_s)) and scale[1] == 0.2
            )

        yield Case("values", f"equilibrated(col {v:g})", lambda A=A: equilibrated(A),
                   "answer", unit)  # fmt: skip
    # The batch builders read a model as ContactModel.parse does, or refuse it.
    g = _valid_grasp()
    P, N = np.repeat(g.positions[None], 2, 0), np.repeat(g.normals[None], 2, 0)
    mu, nu = np.full((2, 3), 0.5), np.full((2, 3), 0.1)
    args = (P, N, mu, nu, np.zeros((2, 3)), np.ones(2))
    soft = batched_primitive_wrenches(*args, contact_model="soft_finger",
                                      num_generators=8)  # fmt: skip
    kinds = contact_kinds(mu, nu, contact_model="soft_finger", dim=3)
    for i, m in enumerate(MODEL_SPELLINGS):
        yield Case(
            "values", f"batched_primitive_wrenches(model#{i})",
            lambda m=m: batched_primitive_wrenches(*args, contact_model=m,
                                                   num_generators=8),
            "answer", lambda W: np.array_equal(W, soft),
        )  # fmt: skip
        yield Case(
            "values", f"contact_kinds(model#{i})",
            lambda m=m: contact_kinds(mu, nu, contact_model=m, dim=3),
            "answer", lambda k: np.array_equal(k, kinds),
        )  # fmt: skip
        yield Case("values", f"wrenches_per_contact(model#{i})",
                   lambda m=m: wrenches_per_contact(m, 3, 8), "answer",
                   lambda n: n == 10)  # fmt: skip
    for i, m in enumerate(BAD_MODELS):
        for name, call in (
            ("batched_primitive_wrenches", lambda m=m: batched_primitive_wrenches(
                *args, contact_model=m, num_generators=8)),
            ("contact_kinds", lambda m=m: contact_kinds(
                mu, nu, contact_model=m, dim=3)),
            ("wrenches_per_contact", lambda m=m: wrenches_per_contact(m, 3, 8)),
            ("batch_force_closure", lambda m=m: dg.batch_force_closure(
                P, N, mu=0.5, contact_model=m, torsional_friction=0.1)),
        ):  # fmt: skip
            yield Case("values", f"{name}(bad model#{i})", call, "refuse")
    yield Case(
        "values", "wrenches_per_contact(position and model=)",
        lambda: wrenches_per_contact("hard_finger", 3, 8, model="soft_finger"),
        "refuse",
    )  # fmt: skip


def all_cases(root: Path | None = None) -> Iterator[Case]:
    """Every family, in a fixed order."""
    yield from api_walk_cases()
    yield from contact_cases()
    yield from grasp_cases()
    yield from length_scale_cases()
    yield from wrong_type_cases()
    yield from option_cases()
    yield from value_cases()
    yield from batch_cases()
    yield from geometry_cases()
    yield from monotonicity_cases()
    yield from picture_cases()
    yield from planning_cases()
    if root is None:
        root = Path(tempfile.mkdtemp(prefix="drakegrasp-fuzz-"))
    yield from file_cases(root)
