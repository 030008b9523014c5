"""Run every hostile input of the fuzz suite and print issue 9's outcome table.

    python tests/fuzz/report.py [--details]

Counts each case's outcome (see ``fuzz_cases.run_case``); with ``--details`` it
also lists every case whose outcome is bad (raw exception, hang, silent wrong
answer, lost data, valid input refused).  Exit status 1 if any is bad.
"""

from __future__ import annotations

import argparse
import collections
import faulthandler
import sys
import tempfile
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import fuzz_cases  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--details", action="store_true")
    args = parser.parse_args()
    warnings.simplefilter("ignore")  # the outcomes are what we count
    # A hard watchdog: C code that never returns (no SIGALRM delivery) ends the
    # run with a traceback of where it hung, instead of hanging the report.
    faulthandler.dump_traceback_later(300, repeat=True, exit=True)
    counts = collections.Counter()
    families = collections.defaultdict(collections.Counter)
    bad = []
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="drakegrasp-fuzz-") as tmp:
        for case in fuzz_cases.all_cases(Path(tmp)):
            faulthandler.cancel_dump_traceback_later()
            faulthandler.dump_traceback_later(300, exit=True)
            outcome, detail = fuzz_cases.run_case(case)
            counts[outcome] += 1
            families[case.family][outcome] += 1
            if outcome in fuzz_cases.BAD:
                bad.append((case.family, case.name, outcome, detail))
    faulthandler.cancel_dump_traceback_later()
    total = sum(counts.values())
    print(f"{total} hostile inputs in {time.perf_counter() - start:.0f} s\n")
    print("| outcome | count |")
    print("| --- | --- |")
    for outcome in fuzz_cases.OUTCOMES:
        print(f"| {outcome} | {counts[outcome]} |")
    print("\n| family | cases | " + " | ".join(fuzz_cases.OUTCOMES) + " |")
    print("| --- " * (len(fuzz_cases.OUTCOMES) + 2) + "|")
    for family, c in families.items():
        cells = " | ".join(str(c[o]) for o in fuzz_cases.OUTCOMES)
        print(f"| {family} | {sum(c.values())} | {cells} |")
    return fuzz_cases.print_bad(bad, details=args.details)


if __name__ == "__main__":
    sys.exit(main())
