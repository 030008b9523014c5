"""Run the generated hostile inputs of issue 21 and print their outcome table.

    python tests/fuzz/report_surfaces.py [--small] [--details]

Families and their independent routes: ``fuzz_surfaces``.  Scene files load in
a sandboxed worker (time and memory limits), so a crash or a hang is a row of
the table.  Exit status 1 if any outcome is bad.
"""

from __future__ import annotations

import argparse
import collections
import sys
import tempfile
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import fuzz_cases  # noqa: E402
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
SMALL = {"certificates": 60, "second order": 50, "numerics": 40, "scene YAML": 40}


def cases(root: Path, sandbox: Sandbox, *, small: bool):
    """The families at full size, or the small CI sizes."""
    size = (lambda name, full: SMALL[name]) if small else (lambda name, full: full)
    yield from fuzz_surfaces.certificate_cases(count=size("certificates", 300))
    yield from fuzz_surfaces.second_order_cases(count=size("second order", 250))
    yield from fuzz_surfaces.numeric_cases(count=size("numerics", 200))
    yield from fuzz_surfaces.scene_cases(root, sandbox, count=size("scene YAML", 264))


def run(*, small: bool):
    """(families' counters, bad cases) over every case."""
    families = collections.defaultdict(collections.Counter)
    bad = []
    with warnings.catch_warnings(), Sandbox(timeout=60.0) as box:
        warnings.simplefilter("ignore")
        with tempfile.TemporaryDirectory(prefix="drakegrasp-fuzz21-") as tmp:
            for case in cases(Path(tmp), box, small=small):
                limit = 90.0 if case.family == "scene YAML" else fuzz_cases.TIME_LIMIT
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
    parser.add_argument("--small", action="store_true", help="the CI sizes")
    parser.add_argument("--details", action="store_true")
    args = parser.parse_args()
    start = time.perf_counter()
    families, bad = run(small=args.small)
    print(f"generated inputs run in {time.perf_counter() - start:.0f} s\n")
    print(table(families))
    if args.details or bad:
        print()
        for family, name, outcome, detail in bad:
            print(f"{outcome}: [{family}] {name}: {detail}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
