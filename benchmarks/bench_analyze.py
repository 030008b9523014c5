"""Wall time of ``analyze_grasp`` on a scene (default: the default scene).

Usage::

    python benchmarks/bench_analyze.py [SCENE] [--repeats 300] [--fresh 5] [--profile]
    python benchmarks/bench_analyze.py --cli-only [--cli-runs 15] \
        [--against OTHER_VENV/bin/python]

Four tables:

* **the command**: the wall time of ``drakegrasp analyze SCENE`` as a new
  process (interpreter start included), ``--cli-runs`` times, beside Python
  alone and the imports of the pydrake modules the command uses, timed the
  same way; with ``--against``, the same command of another tree (say
  main's ``.venv/bin/python``) and its output compared with this tree's.  The
  runs of all rows alternate (each round in a rotated order) so that load on
  a shared machine falls on every row alike; the table gives the median and
  the minimum, and the load average before and after.  Twice: once with the
  environment as it is, and once with compiled bytecode kept (a private
  ``PYTHONPYCACHEPREFIX``, warmed by one run), as an installed package has
  it: with ``PYTHONDONTWRITEBYTECODE=1`` an editable install compiles its
  modules from source at every start;
* **first call**: in ``--fresh`` new processes, the first ``analyze_grasp``
  after ``load_scene`` (imports and Drake's first-use costs included) and the
  second call;
* **later calls**: median and 90th percentile of one ``analyze_grasp``, with
  the steps it runs in the order it runs them, each timed alone, and the
  rest (the remainder of the total: result assembly, validation, the calls'
  overhead) so that the rows add up to the total;
* **on first read**: what the report leaves for later (the programs whose
  verdict the rank decided, LP3 without frictional closure, certificates,
  the second-order program), timed as reading every part of a fresh report,
  and ``str(report)``.

Targets (issue 11): first call <= 10 ms, later calls <= 2 ms on the default
scene, ``drakegrasp analyze`` <= 0.5 s.
"""

from __future__ import annotations

import os

# The command rows run with the caller's environment, not the pinned one.
_CALLER_ENV = dict(os.environ)
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import cProfile  # noqa: E402
import json  # noqa: E402
import pstats  # noqa: E402
import resource  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from drakegrasp.closure.verdicts import (  # noqa: E402
    force_closure,
    force_closure_exact,
    form_closure,
    internal_forces,
)
from drakegrasp.core.antipodal import is_antipodal  # noqa: E402
from drakegrasp.core.deferred import computed_eagerly  # noqa: E402
from drakegrasp.core.grasp import grasp_matrix, invariant_grasp_matrix  # noqa: E402
from drakegrasp.plant import (  # noqa: E402
    DEFAULT_SCENE,
    analyze_grasp,
    find_contacts,
    grasp_from_plant,
    load_scene,
)
from drakegrasp.plant.curvature import contact_curvatures  # noqa: E402

_FIRST_CALL = """
import json, os, sys, time
for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[v] = "1"
from drakegrasp.plant import analyze_grasp, load_scene
scene = load_scene(sys.argv[1])
options = scene.analysis_options()
times = []
for _ in range(2):
    t0 = time.perf_counter()
    analyze_grasp(scene.plant, scene.plant_context, **options)
    times.append(time.perf_counter() - t0)
print(json.dumps(times))
"""


def timed(fns: dict, repeats: int, rounds: int = 3) -> dict[str, np.ndarray]:
    """Wall times (ms) of each ``fn()``: ``rounds`` blocks of ``repeats`` calls.

    Each function runs in blocks of consecutive calls (as a user's loop would
    call it), the blocks of all functions taking turns; the block with the
    lowest median is kept, so a burst of load on a shared machine does not
    land on one row only.
    """
    best: dict[str, np.ndarray] = {}
    for _ in range(rounds):
        for label, fn in fns.items():
            for _ in range(5):  # warm-up
                fn()
            t = np.empty(repeats)
            for i in range(repeats):
                t0 = time.perf_counter()
                fn()
                t[i] = time.perf_counter() - t0
            if label not in best or np.median(t) < np.median(best[label]):
                best[label] = t
    return {label: 1e3 * t for label, t in best.items()}


def _row(label: str, t: np.ndarray) -> str:
    return f"{label:<56} {np.median(t):10.3f} {np.percentile(t, 90):8.3f}"


# The pydrake modules that `drakegrasp analyze` imports (with what they import).
PYDRAKE_USED = (
    "pydrake.geometry",
    "pydrake.multibody.parsing",
    "pydrake.multibody.plant",
    "pydrake.multibody.tree",
    "pydrake.solvers",
    "pydrake.systems.framework",
)


def _analyze_command(python: str, scene: str) -> list[str]:
    """``drakegrasp analyze SCENE`` of the environment that ``python`` is in."""
    script = Path(python).parent / "drakegrasp"
    if script.exists():  # the console script a user runs
        return [str(script), "analyze", scene]
    return [python, "-m", "drakegrasp", "analyze", scene]


def command_rows(scene: str, against: str | None) -> dict[str, list[str]]:
    """The commands of the command table, by label."""
    rows = {
        "python -c pass": [sys.executable, "-c", "pass"],
        "import pydrake.multibody.plant": [
            sys.executable,
            "-c",
            "import pydrake.multibody.plant",
        ],
        "import the pydrake modules analyze uses": [
            sys.executable,
            "-c",
            f"import {', '.join(PYDRAKE_USED)}",
        ],
        "drakegrasp analyze (this tree)": _analyze_command(sys.executable, scene),
    }
    if against is not None:
        rows["drakegrasp analyze (--against)"] = _analyze_command(against, scene)
    return rows


def _wall(argv: list[str], env: dict[str, str]) -> tuple[float, float, str]:
    """Wall and CPU (user + system) seconds of one run, and its output."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    run = subprocess.run(argv, env=env, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, run.stdout


def command_times(
    rows: dict[str, list[str]], runs: int, env: dict[str, str]
) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """Wall and CPU times (s) of each command, ``runs`` rounds of alternating runs.

    One warm-up run of each first (file cache, bytecode); each round runs
    every command once, the order rotated by one per round.  Returns
    ``(runs, 2)`` arrays (wall, CPU) by label, and each command's output.
    """
    labels = list(rows)
    outputs = {label: _wall(rows[label], env)[2] for label in labels}
    times: dict[str, list[tuple[float, float]]] = {label: [] for label in labels}
    for r in range(runs):
        for label in labels[r % len(labels) :] + labels[: r % len(labels)]:
            times[label].append(_wall(rows[label], env)[:2])
    return {label: np.array(t) for label, t in times.items()}, outputs


def _print_times(times: dict[str, np.ndarray]) -> None:
    """Median, min and max wall time and median and min CPU time per command."""
    print(
        f"{'seconds':<48} {'wall median':>11} {'min':>6} {'max':>6}"
        f" {'CPU median':>10} {'min':>6}"
    )
    for label, t in times.items():
        wall, cpu = t[:, 0], t[:, 1]
        print(
            f"{label:<48} {np.median(wall):11.3f} {wall.min():6.3f} "
            f"{wall.max():6.3f} {np.median(cpu):10.3f} {cpu.min():6.3f}"
        )
    used = np.median(times["import the pydrake modules analyze uses"], axis=0)
    for label in [k for k in times if k.startswith("drakegrasp")]:
        extra = np.median(times[label], axis=0) - used
        print(
            f"  {label}: {extra[0]:.3f} s wall, {extra[1]:.3f} s CPU beyond "
            "pydrake's imports (medians)"
        )


def print_command_table(scene: str, runs: int, against: str | None) -> None:
    """The command table, with the environment as is and with bytecode kept."""
    rows = command_rows(scene, against)
    with tempfile.TemporaryDirectory(prefix="bench_analyze_pyc_") as pyc:
        cached = {
            k: v for k, v in _CALLER_ENV.items() if k != "PYTHONDONTWRITEBYTECODE"
        }
        cached["PYTHONPYCACHEPREFIX"] = pyc
        settings = {
            "environment as is"
            + (
                " (PYTHONDONTWRITEBYTECODE=1: sources compiled at every start)"
                if _CALLER_ENV.get("PYTHONDONTWRITEBYTECODE")
                else ""
            ): dict(_CALLER_ENV),
            "bytecode kept (PYTHONPYCACHEPREFIX, warmed)": cached,
        }
        for setting, env in settings.items():
            before = os.getloadavg()
            times, outputs = command_times(rows, runs, env)
            after = os.getloadavg()
            print(
                f"\ndrakegrasp analyze {scene}, {setting}: {runs} alternating "
                f"runs each; load average {before[0]:.2f} before, "
                f"{after[0]:.2f} after"
            )
            _print_times(times)
            if against is not None:
                same = (
                    outputs["drakegrasp analyze (this tree)"]
                    == outputs["drakegrasp analyze (--against)"]
                )
                print(f"  outputs of the two trees identical: {same}")


def first_calls(scene: str, fresh: int) -> dict[str, np.ndarray]:
    """First and second ``analyze_grasp``, each pair in a new process."""
    first, second = [], []
    for _ in range(fresh):
        out = subprocess.run(
            [sys.executable, "-c", _FIRST_CALL, scene],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
        a, b = json.loads(out.splitlines()[-1])
        first.append(1e3 * a)
        second.append(1e3 * b)
    return {
        "analyze_grasp, first call": np.array(first),
        "analyze_grasp, second call": np.array(second),
    }


def _read_everything(report) -> None:
    report.to_dict()  # every deferred part is computed here


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=DEFAULT_SCENE)
    parser.add_argument("--repeats", type=int, default=300)
    parser.add_argument("--fresh", type=int, default=5, help="new processes")
    parser.add_argument("--profile", action="store_true")
    parser.add_argument(
        "--cli-runs", type=int, default=15, help="runs of each command (0: none)"
    )
    parser.add_argument(
        "--against",
        metavar="PYTHON",
        help="another tree's Python (e.g. main's .venv/bin/python) to compare",
    )
    parser.add_argument(
        "--cli-only", action="store_true", help="only the command table"
    )
    args = parser.parse_args()
    if args.cli_runs > 0:
        print_command_table(args.scene, args.cli_runs, args.against)
    if args.cli_only:
        return

    scene = load_scene(args.scene)
    plant, ctx = scene.plant, scene.plant_context
    options = scene.analysis_options()
    data = grasp_from_plant(plant, ctx, **options)
    grasp, J = data.grasp, data.hand_jacobian
    report = analyze_grasp(plant, ctx, **options)
    print(
        f"scene {scene.name}: {grasp.num_contacts} contacts, "
        f"{'planar' if grasp.planar else 'spatial'}, "
        f"{grasp.contacts[0].contact_model.value}; "
        f"rank G {report.force_closure.rank}/{report.force_closure.required_rank}, "
        f"rank G_n {report.form_closure.rank}; decided by: form "
        f"{report.form_closure.decided_by}, polyhedral "
        f"{report.force_closure.decided_by}, exact "
        f"{report.force_closure_exact.decided_by}"
    )
    header = f"{'':<56} {'median ms':>10} {'p90 ms':>8}"

    if args.fresh > 0:
        print(f"\nfirst call ({args.fresh} new processes)\n{header}")
        for label, t in first_calls(args.scene, args.fresh).items():
            print(_row(label, t))

    frictional = (
        report.force_closure.frictional_closure
        or report.force_closure_exact.frictional_closure
    )
    steps = {
        "analyze_grasp (total)": lambda: analyze_grasp(plant, ctx, **options),
        "  grasp_from_plant (contacts, pose, G, J, dpsi/dv)": lambda: grasp_from_plant(
            plant, ctx, **options
        ),
        "    of which find_contacts": lambda: find_contacts(
            plant, ctx, object_body=scene.object_body, hand=scene.hand
        ),
    }
    # A Grasp keeps G, the normalised G and what its programs share (rank,
    # rows, cone layout): each timed call below gets a grasp of its own whose
    # G and normalised G are already computed (their own row times them).
    size = 3 * (args.repeats + 5)

    def pool(warm: bool):
        grasps = [grasp.with_contacts(grasp.contacts) for _ in range(size)]
        for g in grasps if warm else ():
            grasp_matrix(g)
            invariant_grasp_matrix(g)
            g.normal_indices()
        return iter(grasps)

    def on_fresh(fn, warm=True):
        grasps = pool(warm)
        return lambda: fn(next(grasps))

    if grasp.num_contacts == 2:
        steps["  is_antipodal"] = on_fresh(is_antipodal)

    def verdicts(g):
        form_closure(g)
        b, c = force_closure(g), force_closure_exact(g)
        if b.frictional_closure or c.frictional_closure:
            internal_forces(g, J)

    lp3 = " + LP3" if frictional else ""
    steps[f"  verdicts: LP1, LP2, SOCP unless the rank decides{lp3}"] = on_fresh(
        verdicts
    )
    steps["    of which form_closure"] = on_fresh(form_closure)
    steps["    of which force_closure"] = on_fresh(force_closure)
    steps["    of which force_closure_exact"] = on_fresh(force_closure_exact)
    if frictional:
        steps["    of which internal_forces (LP3)"] = on_fresh(
            lambda g: internal_forces(g, J)
        )
    if not report.form_closure.is_closure:
        steps["  contact_curvatures (read now, for second order)"] = lambda: (
            contact_curvatures(
                plant,
                ctx,
                data.contacts,
                object_body=data.object_body,
                plane=data.plane,
            )
        )

    def first_use(g):
        grasp_matrix(g)
        invariant_grasp_matrix(g)
        g.normal_indices()

    steps["  G, normalised G, slices (first use on a new grasp)"] = on_fresh(
        first_use, warm=False
    )

    print(f"\nlater calls (best of 3 blocks of {args.repeats} calls)\n{header}")
    later = timed(steps, args.repeats)
    total = float(np.median(later["analyze_grasp (total)"]))
    listed = sum(
        float(np.median(t))
        for label, t in later.items()
        if label.startswith("  ") and not label.startswith("    ")
    )
    for label, t in later.items():
        print(_row(label, t))
    label = "  rest (assembly, validation, call overhead)"
    print(f"{label:<56} {total - listed:10.3f}")

    print(f"\non first read (best of 3 blocks of {args.repeats})\n{header}")
    reads = {
        "analyze_grasp + reading every part (to_dict)": lambda: _read_everything(
            analyze_grasp(plant, ctx, **options)
        ),
        "analyze_grasp + str(report)": lambda: str(
            analyze_grasp(plant, ctx, **options)
        ),
    }

    def eager():
        with computed_eagerly():
            return analyze_grasp(plant, ctx, **options)

    reads["analyze_grasp computed eagerly (the old behaviour)"] = eager
    for label, t in timed(reads, args.repeats).items():
        print(_row(label, t))

    if args.profile:
        profiler = cProfile.Profile()
        profiler.enable()
        for _ in range(args.repeats):
            analyze_grasp(plant, ctx, **options)
        profiler.disable()
        pstats.Stats(profiler).sort_stats("cumtime").print_stats(25)


if __name__ == "__main__":
    main()
