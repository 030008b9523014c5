"""Cost of GraspMonitor in a simulated pick, and the pick's wall time.

Usage::

    python benchmarks/bench_monitor.py [--period 0.05]

Runs the pick of ``tests/systems/pick_support.py`` (the shipped parallel-jaw gripper
closes on a 0.2 kg box, lifts it 5 cm, lowers it, opens; 3 s simulated, 1 ms
SAP steps) in three set-ups: point contact with distances from geometry (soft
fingers), hydroelastic contact with patches from the contact results (flat
pads, hard fingers), and the same with the monitor's Ferrari–Canny ε (off by
default).  Before them: the cost of one sample on 8 contacts with ε off and on
(and ε alone by Qhull and by the compiled kernel the monitor uses); then the
weak pick's slip-detection times, and those of the WSG-50 + YCB sugar box
picks (``tests/systems/wsg_pick_support.py``).  ``--part`` runs one of these.  For
each it prints the wall time of the whole simulation, of the simulation with a
monitor that never samples (period 1000 s), the median / 90th percentile / max
cost of one evaluation (the first excluded: it loads the solvers) and the
verdict timeline.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "systems"))
from pick_support import DURATION, build_pick  # noqa: E402

from drakegrasp.systems.monitor import GraspMonitor  # noqa: E402

# The two plant set-ups the cases vary: point contact with soft fingers read from
# the geometry, and hydroelastic contact on flat pads read from contact results.
SOFT_POINT = dict(
    plant_contact="point", contact_model="soft_finger", torsional_friction=0.1
)
FLAT_HYDRO = dict(
    plant_contact="hydroelastic_with_fallback", flat=True, contacts="contact_results"
)
CASES = {
    "point contact, geometry, soft fingers": SOFT_POINT,
    "hydroelastic, contact results, flat pads": FLAT_HYDRO,
    "hydroelastic, contact results, with epsilon": {
        **FLAT_HYDRO,
        "compute_epsilon": True,
    },
}
SLIP_CASES = {
    "point, contact results": {**SOFT_POINT, "contacts": "contact_results"},
    "point, geometry": SOFT_POINT,
    "hydroelastic, contact results": FLAT_HYDRO,
}


def slip_times() -> None:
    """Weak pick: when the monitor flagged slip against when the box moved 5 mm."""
    from holding_support import timeline

    print("weak pick (fingers 3 mm past the box), 10 ms samples, lift at 1.0 s:")
    for name, options in SLIP_CASES.items():
        pick = build_pick(
            period=0.01, mu=0.5, distance_tolerance=1e-3, closed=0.022, **options
        )
        pick.run(2.0)
        line = timeline(pick, finger="left_finger", t_ref=1.0)
        flagged, moved, dropped = line.slip_times(after=1.0)
        print(
            f"  {name}: flagged {flagged:.3f} s, moved 5 mm {moved:.3f} s, "
            f"dropped {dropped:.3f} s"
        )


def wsg_slip_times() -> None:
    """WSG-50 + YCB sugar box: firm and weak picks, slip flagged against 5 mm moved."""
    from wsg_pick_support import FIRM, LIFT_START, WEAK, wsg_pick_timeline

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from conftest import local_drake_models

    models = local_drake_models()
    if models is None:
        print(
            "WSG-50 + sugar box: skipped (no drake_models; set DRAKEGRASP_DRAKE_MODELS)"
        )
        return
    print(f"WSG-50 + sugar box (mu='plant'), 10 ms samples, lift at {LIFT_START} s:")
    for contacts in ("contact_results", "geometry"):
        for name, squeeze in (("firm", FIRM), ("weak", WEAK)):
            line = wsg_pick_timeline(models, squeeze=squeeze, contacts=contacts)
            flagged, moved, dropped = line.slip_times(after=LIFT_START)
            print(
                f"  {contacts}, {name}: flagged {flagged:.3f} s, moved 5 mm "
                f"{moved:.3f} s, dropped {dropped:.3f} s, box moved "
                f"{1e3 * line.displacement[line.times >= LIFT_START].max():.1f} mm "
                "in the fingers after the lift began"
            )


def epsilon_cost(repeats: int = 30) -> None:
    """One sample on 8 contacts (flat pads, hydroelastic), ε off and on."""
    from drakegrasp.quality import ferrari_canny
    from drakegrasp.systems.grasp_monitor import epsilon_l1

    print("one sample holding the box in the air (flat pads, 8 contacts):")
    for flag in (False, True):
        pick = build_pick(
            period=0.05,
            mu="plant",
            distance_tolerance=1e-3,
            plant_contact="hydroelastic_with_fallback",
            flat=True,
            contacts="contact_results",
            compute_epsilon=flag,
        )
        pick.simulator.AdvanceTo(1.6)
        monitor = pick.monitor
        context = monitor.GetMyContextFromRoot(pick.simulator.get_context())
        sample = monitor.evaluate(context)  # warm: solvers loaded, kernel compiled
        costs, cpu = [], []
        for _ in range(repeats):
            start = time.process_time()
            costs.append(monitor.evaluate(context).seconds)
            cpu.append(time.process_time() - start)
        c, u = 1e3 * np.array(costs), 1e3 * np.array(cpu)
        print(
            f"  compute_epsilon={flag}: wall median {np.median(c):.2f} ms (min "
            f"{c.min():.2f}, p90 {np.percentile(c, 90):.2f}), CPU median "
            f"{np.median(u):.2f} ms ({sample.report.grasp.num_contacts} contacts, "
            f"eps = {sample.epsilon:.6g})"
        )
    grasp = sample.report.grasp
    routes = (("Qhull (ferrari_canny)", ferrari_canny), ("kernel", epsilon_l1))
    for name, route in routes:
        times, cpu = [], []
        for _ in range(repeats):
            start, start_cpu = time.perf_counter(), time.process_time()
            eps = route(grasp, num_generators=8)
            times.append(time.perf_counter() - start)
            cpu.append(time.process_time() - start_cpu)
        t, u = 1e3 * np.array(times), 1e3 * np.array(cpu)
        print(
            f"  eps alone, {name}: wall median {np.median(t):.2f} ms, CPU median "
            f"{np.median(u):.2f} ms, eps = {eps!r}"
        )


def run(period: float, options: dict) -> tuple[float, list[float], object]:
    pick = build_pick(period=period, mu=0.5, distance_tolerance=1e-3, **options)
    costs: list[float] = []
    evaluate = pick.monitor.evaluate

    def timed(context):
        sample = evaluate(context)
        costs.append(sample.seconds)
        return sample

    pick.monitor.evaluate = timed
    start = time.perf_counter()
    pick.run()
    return time.perf_counter() - start, costs, pick


def timeline(pick) -> str:
    log = pick.verdict_log.FindLog(pick.simulator.get_context())
    parts, previous = [], None
    for t, v in zip(log.sample_times(), log.data().T, strict=True):
        key = (int(v[GraspMonitor.STATUS]), int(v[GraspMonitor.FORCE_CLOSURE]))
        if key != previous:
            label = {0: "no contact", 1: "contact", -1: "invalid"}[key[0]]
            if key[1]:
                label = f"force closure ({int(v[GraspMonitor.NUM_CONTACTS])} contacts)"
            parts.append(f"{t:.2f} s {label}")
            previous = key
    return " -> ".join(parts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--period", type=float, default=0.05)
    parser.add_argument(
        "--part",
        choices=("all", "picks", "epsilon", "slip"),
        default="all",
        help="the pick timings, the per-sample cost with and without eps, "
        "or the slip-detection times (default all)",
    )
    args = parser.parse_args()
    if args.part in ("all", "epsilon"):
        epsilon_cost()
    if args.part in ("all", "slip"):
        slip_times()
        wsg_slip_times()
    if args.part not in ("all", "picks"):
        return
    for name, options in CASES.items():
        idle, _, _ = run(1000.0, options)
        wall, costs, pick = run(args.period, options)
        c = 1e3 * np.array(costs[1:])
        print(f"{name}:")
        print(
            f"  {DURATION:g} s simulated: {wall:.2f} s wall with the monitor every "
            f"{args.period:g} s, {idle:.2f} s with an idle monitor"
        )
        print(
            f"  one evaluation: median {np.median(c):.2f} ms, p90 "
            f"{np.percentile(c, 90):.2f} ms, max {c.max():.2f} ms "
            f"({len(costs)} samples; first {1e3 * costs[0]:.1f} ms)"
        )
        print(f"  verdicts: {timeline(pick)}")


if __name__ == "__main__":
    main()
