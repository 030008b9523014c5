"""The holding state in simulated picks, judged by the object's real motion.

The shipped parallel-jaw gripper picks the shipped 0.2 kg box (no download):
a firm grip (fingers commanded 10 mm past the box faces, ~3 N squeeze each)
holds it through the lift; a weak grip (3 mm past, ~0.9 N: with the plant's
μ = 1 two fingers carry at most ~1.8 N < the box's 1.96 N weight) lets it
slip out.  What the box did is read from the logged plant states, apart from
the monitor: its displacement in the left finger's frame since the lift began
(t = 1.0 s) and its height.
"""

import numpy as np
import pytest
from holding_support import timeline
from pick_support import OPEN, build_pick

from drakegrasp.systems.holding import HOLDING_STATES

# The monitors analyse with mu = 0.5, half what the plant simulates (a
# conservative check), and say so once per monitor: that warning is expected.
pytestmark = pytest.mark.filterwarnings(
    "ignore::drakegrasp.plant.friction.FrictionMismatchWarning"
)

LIFT_START = 1.0
NEAR = 0.0255  # fingers 0.5 mm short of the 50 mm box: within the 1 mm tolerance
POINT = {
    "plant_contact": "point",
    "contact_model": "soft_finger",
    "torsional_friction": 0.1,
}
HYDRO = {"plant_contact": "hydroelastic_with_fallback", "flat": True}
CASES = {
    "point, contact results": dict(POINT, contacts="contact_results"),
    "point, geometry": dict(POINT, contacts="geometry"),
    "hydroelastic, contact results": dict(HYDRO, contacts="contact_results"),
}


def _run(closed, options, until=2.0):
    pick = build_pick(
        mu=0.5, distance_tolerance=1e-3, period=0.01, closed=closed, **options
    )
    pick.run(until)
    return timeline(pick, finger="left_finger", t_ref=LIFT_START)


@pytest.mark.parametrize("case", list(CASES))
def test_firm_pick_is_holding_throughout_the_lift(case):
    line = _run(0.015, CASES[case])
    airborne = line.height > 0.0505  # the box rests at 0.05 on the ground
    assert airborne.sum() > 30
    assert line.displacement[line.times >= LIFT_START].max() < 2e-3  # it held
    held = [s for s, up in zip(line.states, airborne, strict=True) if up]
    assert set(held) == {"holding"}, held


@pytest.mark.parametrize("case", list(CASES))
def test_weak_pick_is_flagged_before_it_moves_5_mm_and_dropped_after(case):
    line = _run(0.022, CASES[case])
    flagged, moved, dropped = line.slip_times(after=LIFT_START)
    print(
        f"{case}: flagged {flagged:.3f} s, moved 5 mm {moved:.3f} s, "
        f"dropped {dropped:.3f} s"
    )
    assert moved < 1.3  # the fingers did slide along the box
    assert flagged < moved < dropped < 1.5  # dropped: the pads left the box
    # No flicker: from the lift until the hand stops, the state only grows
    # more alarming, and it stays dropped while the hand is up.
    codes = line.codes(LIFT_START, 1.8)  # the hand goes down again from 1.8 s
    assert np.all(np.diff(codes) >= 0), line.states
    assert codes[-1] == HOLDING_STATES.index("dropped")


@pytest.mark.parametrize("closed", [OPEN, NEAR], ids=["open", "0.5 mm short"])
@pytest.mark.parametrize("case", list(CASES))
def test_box_at_rest_between_open_fingers_is_never_holding(case, closed):
    line = _run(closed, CASES[case], until=1.6)
    assert line.displacement.max() < 1e-3 or line.height.max() < 0.0505
    assert set(line.states) == {"no contact"}, set(line.states)


@pytest.mark.parametrize("closed", [0.015, -0.05], ids=["3 N", "23 N"])
def test_a_firm_grip_in_contact_results_is_holding_at_the_default_tolerance(closed):
    # The simulator's point contacts penetrate to make their force (0.2 mm at
    # 20 N); at the default 0.1 mm tolerance the pose check called the grip
    # invalid, shown as "touching", until it slipped.  With the contact
    # results penetration is the grip: only a joint off its limits is invalid.
    pick = build_pick(
        mu=0.5, period=0.01, closed=closed, contacts="contact_results", **POINT
    )
    assert pick.monitor.settings.analysis.allow_penetration
    pick.run(2.0)
    line = timeline(pick, finger="left_finger", t_ref=LIFT_START)
    airborne = line.height > 0.0505
    assert airborne.sum() > 30
    assert line.displacement[line.times >= LIFT_START].max() < 2e-3
    held = [s for s, up in zip(line.states, airborne, strict=True) if up]
    assert set(held) == {"holding"}, held


def test_a_restarted_simulation_does_not_inherit_the_last_runs_drop():
    """A simulator run again from time 0 (the plant's state set back, then
    ``Initialize``, as Drake asks after a change of context) continued the
    holding state of the run before: the box dropped in the first run was
    "dropped" through the second run's approach, resting untouched on the
    ground between the open fingers."""
    from pydrake.math import RigidTransform

    pick = build_pick(
        mu=0.5, distance_tolerance=1e-3, period=0.01, closed=0.022,
        **CASES["point, geometry"],
    )  # fmt: skip
    pick.run(1.6)
    root = pick.simulator.get_mutable_context()
    monitor_context = pick.monitor.GetMyContextFromRoot(root)
    report = pick.monitor.get_report_output_port()
    assert report.Eval(monitor_context).holding == "dropped"
    plant, plant_context = pick.plant, pick.plant.GetMyMutableContextFromRoot(root)
    root.SetTime(0.0)
    for name in ("left_finger_joint", "right_finger_joint"):
        plant.GetJointByName(name, pick.gripper).set_translation(plant_context, OPEN)
    plant.GetJointByName("lift", pick.gripper).set_translation(plant_context, 0.0)
    plant.SetVelocities(plant_context, np.zeros(plant.num_velocities()))
    box = plant.GetBodyByName("box", pick.box)
    plant.SetFreeBodyPose(plant_context, box, RigidTransform([0, 0, 0.05]))
    pick.simulator.Initialize()
    seen = []
    for t in np.arange(0.0, 0.3, 0.01):  # the fingers are open until 0.3 s
        pick.simulator.AdvanceTo(t)
        sample = report.Eval(monitor_context)
        # the box is where it was put, away from the fingers
        assert plant.EvalBodyPoseInWorld(plant_context, box).translation()[2] < 0.0505
        seen.append((sample.time, sample.status, sample.holding))
    assert {h for _, _, h in seen} == {"no contact"}, seen


def test_samples_faster_than_the_plant_judge_each_plant_state_once():
    """A period of 0.7 ms on the pick's 1 ms plant: about one sample in three
    finds the plant state of the sample before, and judged that same evidence
    again, counting it twice towards the hysteresis: the state moved ("at
    risk" to "touching") between two samples of one plant state, on a single
    step's evidence.  Two samples of one plant state are now one judgement."""
    pick = build_pick(
        distance_tolerance=1e-3, period=7e-4, contacts="contact_results",
        **POINT,
    )  # fmt: skip
    root = pick.simulator.get_mutable_context()
    monitor_context = pick.monitor.GetMyContextFromRoot(root)
    report = pick.monitor.get_report_output_port()
    samples = []
    for t in np.arange(7e-4, 1.2, 7e-4):
        pick.simulator.AdvanceTo(t)
        sample = report.Eval(monitor_context)
        if not samples or sample.time != samples[-1].time:
            samples.append(sample)
    repeated = [
        (a, b)
        for a, b in zip(samples, samples[1:], strict=False)
        if np.array_equal(a.state, b.state)
    ]
    assert len(repeated) > 100  # the plant steps less often than the samples
    for a, b in repeated:
        assert b.holding == a.holding and b.memory == a.memory, (a.time, b.time)
        assert np.array_equal(a.verdicts, b.verdicts, equal_nan=True)
    # the grip is still seen
    assert "holding" in {s.holding for s in samples}


def test_a_sample_at_each_plant_step_is_judged(monkeypatch):
    """Only a sample that no plant update separates from the one before is a
    repeat: with a period equal to the plant's step every sample is judged,
    once at time 0 (the initialization's sample and the first periodic one
    see one state), so an object at rest, whose state may repeat bit for bit
    from step to step, still counts towards the hysteresis."""
    from drakegrasp.systems.grasp_monitor import GraspMonitor, _plant_steps

    pick = build_pick(
        distance_tolerance=1e-3, period=1e-3, contacts="contact_results", **POINT
    )
    h = pick.plant.time_step()
    assert h == pytest.approx(1e-3)
    # the update at t itself is not yet seen at t
    steps = [_plant_steps(pick.plant, t) for t in (0.0, 7e-4, 1e-3, 1.4e-3, 2e-3)]
    assert steps == [0, 1, 1, 2, 2]
    judged = []
    real = GraspMonitor._analyse

    def counted(self, context, query):
        judged.append(context.get_time())
        return real(self, context, query)

    monkeypatch.setattr(GraspMonitor, "_analyse", counted)
    # The state as the initialization judged it, bit for bit: at its own time
    # a repeat, two plant steps later a new judgement (an object at rest).
    root = pick.simulator.get_mutable_context()
    monitor_context = pick.monitor.GetMyContextFromRoot(root)
    pick.monitor.evaluate(monitor_context)
    assert judged == []
    root.SetTime(2 * h)
    pick.monitor.evaluate(monitor_context)
    assert judged == [pytest.approx(2 * h)]
    judged.clear()
    root.SetTime(0.0)
    pick.simulator.AdvanceTo(0.0105)
    # time 0 was judged once, by the initialization (before the count): the
    # periodic sample at 0 repeated it; then one judgement per plant step
    np.testing.assert_allclose(judged, np.arange(1, 11) * h, atol=1e-12)
