"""Run the generated hostile inputs of issue 21 and print their outcome table.

    python tests/fuzz/report_surfaces.py [--full] [--details]

Families and their independent routes: ``fuzz_surfaces`` (certificates,
second order, numerics, scene YAML), ``fuzz_engine`` (batch engine),
``fuzz_hand`` (close_hand, pose validation), ``fuzz_monitor``
(GraspMonitor), ``fuzz_dask`` (Dask driver) and ``fuzz_command`` (CLI, with
signals).  Every call that may crash or hang runs in a sandboxed worker (time
and memory limits), so a crash or a hang is a row of the table.  The default
sizes total over 1,000 inputs; ``--full`` runs more.  Exit status 1 if any
outcome is bad.
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import sys
import tempfile
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import fuzz_cases  # noqa: E402
import fuzz_command  # noqa: E402
import fuzz_dask  # noqa: E402
import fuzz_engine  # noqa: E402
import fuzz_hand  # noqa: E402
import fuzz_monitor  # noqa: E402
import fuzz_surfaces  # noqa: E402
from sandbox import Sandbox  # noqa: E402

COLUMNS = {
    "clear GraspError": "clear error",
    "plausible verdict": "right answer",
    "raw exception": "raw exception",
    "hang": "hang",
    "silent wrong answer": "silent wrong",
    "lost data": "lost",
    "valid input refused": "valid refused",
}
# Default (CI) sizes: over 1,000 inputs across the surfaces in about a minute;
# DRAKEGRASP_FUZZ_FULL=1 or --full runs the FULL sizes.
SMALL = {
    "certificates": 60,
    "second order": 50,
    "numerics": 40,
    "scene YAML": 40,
    "batch engine": 300,
    "close_hand": 150,
    "pose validation": 100,
    "GraspMonitor": 120,
    "Dask driver": 60,
    "CLI": 120,
    "CLI signals": 1,
}
FULL = {
    "certificates": 300,
    "second order": 250,
    "numerics": 200,
    "scene YAML": 264,
    "batch engine": 1200,
    "close_hand": 600,
    "pose validation": 400,
    "GraspMonitor": 400,
    "Dask driver": 200,
    "CLI": 400,
    "CLI signals": 6,
}
SANDBOXED = {"scene YAML", "batch engine", "close_hand", "pose validation",
             "GraspMonitor", "Dask driver", "CLI"}  # fmt: skip


def has_dask() -> bool:
    """Whether the optional Dask extra (and pyarrow, for its datasets) is here."""
    import importlib.util

    return all(importlib.util.find_spec(m) for m in ("distributed", "pyarrow"))


def cases(root: Path, box: Sandbox, dask_box: Sandbox, *, small: bool):
    """Every family at the small (CI) or the full sizes."""
    size = (SMALL if small else FULL).__getitem__
    yield from fuzz_surfaces.certificate_cases(count=size("certificates"))
    yield from fuzz_surfaces.second_order_cases(count=size("second order"))
    yield from fuzz_surfaces.numeric_cases(count=size("numerics"))
    yield from fuzz_surfaces.scene_cases(root, box, count=size("scene YAML"))
    yield from fuzz_engine.engine_cases(box, count=size("batch engine"))
    yield from fuzz_hand.close_hand_cases(box, count=size("close_hand"))
    yield from fuzz_hand.pose_cases(box, count=size("pose validation"))
    yield from fuzz_monitor.monitor_cases(box, count=size("GraspMonitor"))
    if has_dask():
        yield from fuzz_dask.dask_cases(dask_box, count=size("Dask driver"))
    yield from fuzz_command.command_cases(root, box, count=size("CLI"))
    yield from fuzz_command.signal_cases(root, count=size("CLI signals"))


def run(*, small: bool):
    """(families' counters, bad cases) over every case."""
    families = collections.defaultdict(collections.Counter)
    bad = []
    with contextlib.ExitStack() as stack:
        stack.enter_context(warnings.catch_warnings())
        warnings.simplefilter("ignore")
        box = stack.enter_context(Sandbox(timeout=60.0))
        dask_box = stack.enter_context(Sandbox(timeout=60.0))  # its own threads
        tmp = stack.enter_context(
            tempfile.TemporaryDirectory(prefix="drakegrasp-fuzz21-")
        )
        for case in cases(Path(tmp), box, dask_box, small=small):
            sandboxed = case.family in SANDBOXED or "SIG" in case.name
            limit = 90.0 if sandboxed else fuzz_cases.TIME_LIMIT
            outcome, detail = fuzz_cases.run_case(case, limit=limit)
            families[case.family][outcome] += 1
            if outcome in fuzz_cases.BAD:
                bad.append((case.family, case.name, outcome, detail))
    return families, bad


def table(families) -> str:
    """The issue's table: one row per surface and a total."""
    head = "| surface | inputs | " + " | ".join(COLUMNS.values()) + " |"
    rows = [head, "|---|" + "---:|" * (len(COLUMNS) + 1)]
    total = collections.Counter()
    for family, c in families.items():
        total.update(c)
        cells = " | ".join(str(c[o]) for o in COLUMNS)
        rows.append(f"| {family} | {sum(c.values())} | {cells} |")
    cells = " | ".join(f"**{total[o]}**" for o in COLUMNS)
    rows.append(f"| **all** | **{sum(total.values())}** | {cells} |")
    return "\n".join(rows)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="the full sizes")
    parser.add_argument("--details", action="store_true")
    args = parser.parse_args()
    start = time.perf_counter()
    families, bad = run(small=not args.full)
    print(f"generated inputs run in {time.perf_counter() - start:.0f} s\n")
    print(table(families))
    return fuzz_cases.print_bad(bad, details=args.details)


if __name__ == "__main__":
    sys.exit(main())
