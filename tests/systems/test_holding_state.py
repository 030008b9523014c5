"""The holding state machine, fed evidence by hand: its rules and its hysteresis.

Each scenario is a list of samples; a sample is the evidence the monitor
gives :func:`next_holding_state`.  The property test replays random evidence
and checks the documented rules from the outside: moves to a less alarming
state only after ``hold_samples + 1`` samples, ``dropped`` only when the
object is out of the hand after a long enough gap, never a grip without
contact beyond the hysteresis window.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from drakegrasp.errors import InvalidOptionError
from drakegrasp.systems.holding import (
    HOLDING_STATES,
    HoldingMemory,
    HoldingThresholds,
    next_holding_state,
)

TH = HoldingThresholds()  # risk 0.8, slip 5 mm/s, hold_samples 1, reach 2 mm
FAR, NEAR = 0.05, 1e-4  # clearances, m
RANK = {name: k for k, name in enumerate(HOLDING_STATES)}


def sample(
    touching=True,
    grasped=True,
    use=0.1,
    slip=0.0,
    sliding=0.0,
    slid=0.0,
    clearance=NEAR,
):
    return dict(
        touching=touching,
        grasped=grasped,
        friction_use=use,
        slip_speed=slip,
        sliding=sliding,
        slid=slid,
        clearance=clearance,
    )


HOLD = sample()
RISK = sample(use=0.95)
SLIP = sample(slip=0.1, use=1.0)
TOUCH = sample(grasped=False)
GONE_AT_REST = sample(touching=False, clearance=FAR)
NEAR_AT_REST = sample(touching=False)
GONE_MOVING = sample(touching=False, sliding=0.1, slid=0.01, clearance=FAR)
NEAR_MOVING = sample(touching=False, sliding=0.1, slid=0.001)
GONE_SLID = sample(touching=False, slid=0.01, clearance=FAR)  # landed, at rest


def run(samples, thresholds=TH, memory=None):
    """States shown, sample by sample; and how often clearance was asked."""
    memory = HoldingMemory() if memory is None else memory
    states, calls = [], []
    for s in samples:
        s = dict(s)
        d = s.pop("clearance")

        def clearance(d=d):
            calls.append(d)
            return d

        memory = next_holding_state(
            memory, clearance=clearance, thresholds=thresholds, **s
        )
        states.append(memory.state)
    return states, memory, len(calls)


def test_evidence_with_contact():
    assert run([HOLD])[0] == ["holding"]
    assert run([RISK])[0] == ["at risk"]
    assert run([SLIP])[0] == ["slipping"]
    assert run([TOUCH])[0] == ["touching"]
    # Geometry sees no force: friction in use NaN is never at risk.
    assert run([sample(use=np.nan)])[0] == ["holding"]


def test_a_touch_survives_one_missing_frame():
    # SAP's point contact may leave a resting contact out of one step's
    # results: a touch no longer reads "no contact" for that one frame
    assert run([TOUCH, GONE_AT_REST, TOUCH])[0] == ["touching"] * 3
    assert run([TOUCH, GONE_AT_REST, GONE_AT_REST])[0] == [
        "touching",
        "touching",
        "no contact",
    ]
    th = HoldingThresholds(hold_samples=0)  # the hysteresis off: at once
    assert run([TOUCH, GONE_AT_REST], thresholds=th)[0] == ["touching", "no contact"]


def test_one_sample_without_contact_is_not_a_drop():
    states, memory, calls = run([HOLD, GONE_AT_REST, HOLD])
    assert states == ["holding"] * 3
    assert calls == 0  # within the window the clearance is not even asked
    states, memory, _ = run([SLIP, GONE_MOVING, SLIP])
    assert states == ["slipping"] * 3
    # The bridged sample is counted (the monitor shows the last analysis).
    _, memory, _ = run([HOLD, NEAR_AT_REST])
    assert memory.lost == 1 and memory.bridged(TH) == 1


def test_release_is_no_contact_and_never_dropped():
    # The hand opens around a box at rest: contact gone, the box does not move.
    states, _, _ = run([HOLD] * 3 + [NEAR_AT_REST] + [GONE_AT_REST] * 5)
    assert states == ["holding"] * 4 + ["no contact"] * 5
    # However the grip was doing: a box set down on the ground loads the
    # fingers' friction fully (at risk, even slipping) just before they open.
    for last in (RISK, SLIP):
        states, _, _ = run([HOLD, last, GONE_AT_REST, GONE_AT_REST, GONE_AT_REST])
        assert "dropped" not in states and states[-1] == "no contact"


def test_a_failing_grip_that_leaves_the_hand_is_dropped_after_the_window():
    states, memory, _ = run([HOLD, SLIP, GONE_MOVING, GONE_MOVING, GONE_AT_REST])
    assert states == ["holding", "slipping", "slipping", "dropped", "dropped"]
    assert memory.last_grip == "slipping"
    # Out of the hand and already at rest (it fell and landed between two
    # samples), but displaced along the fingers since the last contact: a drop.
    states, _, _ = run([RISK, GONE_SLID, GONE_SLID])
    assert states == ["at risk", "at risk", "dropped"]
    # A holding grip whose object moves away along the fingers: a drop.
    states, _, _ = run([HOLD, GONE_MOVING, GONE_MOVING])
    assert states == ["holding", "slipping", "dropped"]


def test_sliding_fingers_in_reach_keep_slipping_without_contact():
    # The WSG-50's pads chatter along the box: contact in one sample of several.
    pattern = [SLIP] + [NEAR_MOVING] * 6
    states, _, _ = run([HOLD] + pattern * 3)
    assert states == ["holding"] + ["slipping"] * 21
    # When the pads leave the box it is a drop, and it stays one.
    states, _, _ = run([HOLD] + pattern + [GONE_MOVING] * 2 + [GONE_AT_REST] * 3)
    assert states[-6:] == ["slipping"] + ["dropped"] * 5
    # Or the fingers stop past it, still within reach, the object at rest
    # 10 mm along them from where they last touched it: dropped too.
    hover = sample(touching=False, slid=0.01)
    states, _, _ = run([HOLD] + pattern + [hover])
    assert states[-2:] == ["slipping", "dropped"]


def test_moves_to_a_milder_state_need_hold_samples_plus_one():
    # at risk <-> holding evidence alternating: no flicker, stays at risk.
    states, _, _ = run([RISK, HOLD, RISK, HOLD, RISK, HOLD])
    assert states == ["at risk"] * 6
    states, _, _ = run([RISK, HOLD, HOLD, HOLD])
    assert states == ["at risk", "at risk", "holding", "holding"]
    # One sticking sample in a slide does not read as holding.
    states, _, _ = run([SLIP, HOLD, SLIP, HOLD, HOLD])
    assert states == ["slipping"] * 4 + ["holding"]
    # Leaving dropped takes hold_samples + 1 samples with contact.
    dropped, memory, _ = run([SLIP, GONE_MOVING, GONE_MOVING])
    assert dropped[-1] == "dropped"
    states, _, _ = run([TOUCH, GONE_AT_REST, TOUCH, TOUCH], memory=memory)
    assert states == ["dropped", "dropped", "dropped", "touching"]
    # A grip lost to touching (no force closure) waits likewise.
    states, _, _ = run([HOLD, TOUCH, HOLD, TOUCH, TOUCH])
    assert states == ["holding"] * 4 + ["touching"]


def test_more_alarming_is_immediate():
    states, _, _ = run([HOLD, RISK, SLIP])
    assert states == ["holding", "at risk", "slipping"]


@pytest.mark.parametrize("n", [0, 2, 4])
def test_window_length_follows_hold_samples(n):
    th = HoldingThresholds(hold_samples=n)
    states, _, _ = run([SLIP] + [GONE_MOVING] * (n + 2), thresholds=th)
    first = states.index("dropped")
    assert first == n + 1  # the (n + 1)-th sample without contact
    states, _, _ = run([HOLD] + [NEAR_AT_REST] * (n + 2), thresholds=th)
    assert states.index("no contact") == n + 1


def test_out_of_reach_is_judged_by_release_distance():
    th = HoldingThresholds(release_distance=0.1)  # FAR = 5 cm is in reach now
    states, _, _ = run([SLIP] + [GONE_MOVING] * 4, thresholds=th)
    assert "dropped" not in states and states[-1] == "slipping"
    # An unmeasurable clearance (NaN) is never out of reach.
    gone_nan = sample(touching=False, sliding=0.1, clearance=np.nan)
    assert "dropped" not in run([SLIP] + [gone_nan] * 4)[0]


def test_unknown_state_is_refused():
    with pytest.raises(InvalidOptionError, match="unknown holding state"):
        run([HOLD], memory=HoldingMemory(state="gripping"))


@pytest.mark.parametrize(
    "kwargs",
    [
        {"release_distance": 0.0},
        {"release_distance": -1e-3},
        {"release_distance": float("nan")},
        {"release_distance": True},
    ],
)
def test_bad_release_distance_is_refused(kwargs):
    with pytest.raises(InvalidOptionError, match="release_distance"):
        HoldingThresholds(**kwargs)


EVIDENCE = [HOLD, RISK, SLIP, TOUCH, GONE_AT_REST, NEAR_AT_REST, GONE_MOVING]
EVIDENCE += [NEAR_MOVING, GONE_SLID]


@settings(max_examples=300, derandomize=True, deadline=None)
@given(
    picks=st.lists(st.integers(0, len(EVIDENCE) - 1), min_size=1, max_size=40),
    n=st.integers(0, 3),
)
def test_rules_hold_on_random_evidence(picks, n):
    th = HoldingThresholds(hold_samples=n)
    samples = [EVIDENCE[k] for k in picks]
    states, _, _ = run(samples, thresholds=th)
    sticky = ("touching", "holding", "at risk", "slipping", "dropped")
    lost = 0
    run_length = 0
    for k, (s, state) in enumerate(zip(samples, states, strict=True)):
        lost = 0 if s["touching"] else lost + 1
        previous = states[k - 1] if k else "no contact"
        run_length = run_length + 1 if state == previous else 1
        if k and RANK[state] < RANK[previous] and previous in sticky:
            # A milder state only after n + 1 samples of the alarming one.
            length = 1
            while k - length - 1 >= 0 and states[k - length - 1] == previous:
                length += 1
            assert length >= n + 1, (states, k)
        if state == "dropped" and previous != "dropped":
            assert not s["touching"] and lost >= n + 1
            if s["sliding"] > th.slip_speed:  # sliding out, clear of the hand
                assert s["clearance"] > th.release_distance
            else:  # at rest, off its place along the fingers
                assert s["slid"] > th.release_distance
        if not s["touching"] and state in ("holding", "at risk"):
            assert lost <= n  # a grip without contact only within the window
        if s["touching"] and s["slip_speed"] > th.slip_speed:
            assert state in ("slipping", "dropped")
        if state == "touching" and not s["touching"]:
            # a touch is kept through at most n samples without contact
            assert previous == "touching" and lost <= n, (states, k)


def test_hand_clearance_against_the_geometry_and_pair_by_pair():
    # The open fingers (pad faces 35 mm from the axis) around the 50 mm box:
    # 10 mm clearance on each side, nearer than the palm (25 mm above the box).
    from pick_support import OPEN, build_pick

    from drakegrasp.systems.sensing import hand_clearance

    pick = build_pick(mu=0.5)
    root = pick.simulator.get_context()
    plant = pick.plant
    query = pick.scene_graph.get_query_output_port().Eval(
        pick.scene_graph.GetMyContextFromRoot(root)
    )
    box = plant.GetBodyByName("box", pick.box)
    hand = [plant.get_body(i) for i in plant.GetBodyIndices(pick.gripper)]
    found = hand_clearance(plant, query, object_body=box, fingers=hand, horizon=0.05)
    assert found == pytest.approx(OPEN - 0.025, abs=1e-9)
    # A second route: every pair of geometries, measured one by one.
    by_pair = min(
        query.ComputeSignedDistancePairClosestPoints(go, gh).distance
        for go in plant.GetCollisionGeometriesForBody(box)
        for b in hand
        for gh in plant.GetCollisionGeometriesForBody(b)
    )
    assert found == pytest.approx(by_pair, abs=1e-12)
    # Beyond the horizon nothing is measured.
    assert hand_clearance(
        plant, query, object_body=box, fingers=hand, horizon=0.005
    ) == float("inf")


def test_motion_along_a_finger_is_measured_in_its_frame():
    # Anchor the box on both fingers, then move it: along the fingers (down,
    # as in a drop) counts as slid; away from them (as the hand opens, or the
    # box pushed along the normal) does not.  Speeds: the box falling at 0.3
    # m/s slides along the fingers at that speed; one moving mostly across
    # them is not moving "along" them.
    from pick_support import build_pick
    from pydrake.math import RigidTransform
    from pydrake.multibody.math import SpatialVelocity

    from drakegrasp.systems.sensing import anchor_fingers, motion_against

    pick = build_pick(mu=0.5)
    plant = pick.plant
    context = plant.CreateDefaultContext()
    plant.SetPositionsAndVelocities(
        context,
        plant.GetPositionsAndVelocities(
            plant.GetMyContextFromRoot(pick.simulator.get_context())
        ),
    )
    box = plant.GetBodyByName("box", pick.box)
    hand = [plant.get_body(i) for i in plant.GetBodyIndices(pick.gripper)]
    fingers = [k for k, b in enumerate(hand) if "finger" in b.name()]
    # Inward normals: each finger pushes towards the box's axis (world x / y).
    p_WO = plant.EvalBodyPoseInWorld(context, box).translation()
    touching = []
    for k in fingers:
        p_WF = plant.EvalBodyPoseInWorld(context, hand[k]).translation()
        d = p_WO - p_WF
        d[2] = 0.0
        touching.append((k, d / np.linalg.norm(d)))
    anchors = anchor_fingers(plant, context, box, hand, touching)
    assert motion_against(plant, context, box, hand, anchors).slid == pytest.approx(
        0.0, abs=1e-12
    )
    n_W = touching[0][1]
    for shift, expected in (([0, 0, -0.004], 0.004), (0.003 * n_W, 0.0)):
        plant.SetFreeBodyPose(context, box, RigidTransform(p_WO + np.array(shift)))
        motion = motion_against(plant, context, box, hand, anchors)
        assert motion.slid == pytest.approx(expected, abs=1e-12)
    plant.SetFreeBodySpatialVelocity(
        context, box, SpatialVelocity(np.zeros(3), [0.0, 0.0, -0.3])
    )
    motion = motion_against(plant, context, box, hand, anchors)
    assert motion.sliding == pytest.approx(0.3, rel=1e-12)
    assert motion.along == motion.sliding  # all of it along the fingers
    assert motion.relative == pytest.approx(0.3, rel=1e-12)
    # Mostly across a finger (as when the hand opens at 70 mm/s), with a
    # little along it: the sliding speed is seen, but it is not "along".
    v = 0.07 * n_W + [0.0, 0.0, -0.0075]
    plant.SetFreeBodySpatialVelocity(context, box, SpatialVelocity(np.zeros(3), v))
    motion = motion_against(plant, context, box, hand, anchors)
    assert motion.sliding == pytest.approx(0.0075, rel=1e-9)
    assert motion.along == 0.0
