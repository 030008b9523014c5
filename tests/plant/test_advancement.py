"""close_hand never carries a finger through a thin obstacle (issue 20, point 1).

The reproducer: the closest feature of the object (a bead on the finger's joint
axis) keeps its distance along the whole path, so a step aimed at it alone was
unbounded (capped at 0.2 rad), and the fingertip jumped over a 0.3 mm wire.
Every check here samples the finger's path densely with Drake's signed
distances, independently of the closing's own bound.
"""

from __future__ import annotations

import numpy as np
import pytest
from hand_models import (
    BEAD_HEIGHT,
    FINGER_RADIUS,
    TIP_RADIUS,
    Rig,
    bead_and_wire_object,
    one_finger_hand,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pydrake.math import RigidTransform

from drakegrasp import close_hand
from drakegrasp.plant.contacts import DEFAULT_DISTANCE_TOLERANCE as TOL


def bead_wire_rig(wire_angle, **wire):
    return Rig(
        [(one_finger_hand(), "sdf"), (bead_and_wire_object(wire_angle, **wire), "sdf")],
        "bead_wire",
        RigidTransform([0.0, 0.0, BEAD_HEIGHT]),
    )


def path_minimum(rig, q_start, q_end, *, tip_travel=2e-4):
    """Smallest ψ over every pair at samples of the path, tip moving <= tip_travel."""
    plant, ctx = rig.plant, rig.ctx
    joint = plant.GetJointByName("finger_joint", rig.hand)
    arc = (FINGER_RADIUS + TIP_RADIUS) * abs(q_end - q_start)
    lowest = np.inf
    for q in np.linspace(q_start, q_end, int(np.ceil(arc / tip_travel)) + 2):
        joint.set_angle(ctx, q)
        lowest = min(lowest, min(rig.pair_distances().values()))
    joint.set_angle(ctx, q_end)
    return lowest


def test_the_bead_and_wire_reproducer_stops_at_the_wire():
    rig = bead_wire_rig(0.12)  # tip 6.3 mm from the wire, 10.8 mm of arc past it
    start = rig.pair_distances()
    assert min(start, key=start.get) == ("hand::phalanx", "bead_wire::bead")
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, direction=[1.0])
    (finger,) = closure.fingers
    assert finger.status == "touching"
    end = rig.pair_distances()
    assert 0.0 <= end[("hand::tip", "bead_wire::wire")] <= TOL
    # The bead kept its distance: it could never have bounded a step.
    assert end[("hand::phalanx", "bead_wire::bead")] == pytest.approx(
        start[("hand::phalanx", "bead_wire::bead")], abs=1e-12
    )
    assert path_minimum(rig, 0.0, float(closure.q[0])) >= 0.0
    # The tip stopped on the near side: its centre is short of the wire's angle.
    assert closure.q[0] < 0.12


@settings(
    derandomize=True,
    max_examples=30,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    angle=st.floats(0.06, 1.5),
    thickness=st.floats(1e-4, 1e-3),
    kind=st.sampled_from(["cylinder", "plate"]),
    tilt=st.floats(-0.7, 0.7),
)
def test_closing_never_crosses_a_thin_obstacle_on_its_path(
    angle, thickness, kind, tilt
):
    rig = bead_wire_rig(angle, wire_radius=thickness / 2, kind=kind, wire_tilt=tilt)
    if min(rig.pair_distances().values()) <= TOL:
        return  # the obstacle already touches the open finger
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, direction=[1.0])
    (finger,) = closure.fingers
    assert finger.status == "touching"
    assert 0.0 <= min(rig.pair_distances().values()) <= TOL
    assert path_minimum(rig, 0.0, float(closure.q[0])) >= 0.0


def test_reach_of_a_one_joint_finger_is_its_closed_form():
    from drakegrasp.plant.advancement import reach
    from drakegrasp.plant.fingers import hand_structure
    from drakegrasp.plant.validation import hand_bodies

    rig = bead_wire_rig(0.5)
    inspector = rig.query().inspector()
    bodies = hand_bodies(rig.plant, rig.object, rig.hand)
    hand = hand_structure(rig.plant, rig.object, bodies, inspector=inspector)
    (finger,) = hand.fingers
    rows = reach(rig.plant, rig.ctx, hand, finger, inspector)
    x0, x1 = 0.002, 0.075
    half_diagonal = 0.5 * np.linalg.norm([x1 - x0, 0.008, 0.01])
    expected = {
        "hand::tip": FINGER_RADIUS + TIP_RADIUS,
        "hand::phalanx": 0.5 * (x0 + x1) + half_diagonal,
    }
    for (_, gf, _), row in zip(finger.pairs, rows, strict=True):
        assert row[0] == pytest.approx(expected[inspector.GetName(gf)], rel=1e-12)


@settings(
    derandomize=True,
    max_examples=10,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(seed=st.integers(0, 2**16))
def test_speed_bound_holds_on_the_allegro_hand(seed, real_hands):
    """Every corner of every finger geometry's bounding box moves slower than V."""
    from pydrake.geometry import Box, Capsule, Cylinder, Sphere

    from drakegrasp.plant._shapes import bounding_sphere
    from drakegrasp.plant.advancement import finger_speed_bound, reach
    from drakegrasp.plant.fingers import hand_structure
    from drakegrasp.plant.validation import hand_bodies

    rng = np.random.default_rng(seed)
    scene = real_hands.allegro()
    plant, ctx = scene.plant, scene.ctx
    query = plant.get_geometry_query_input_port().Eval(ctx)
    inspector = query.inspector()
    bodies = hand_bodies(plant, scene.object, scene.hand)
    hand = hand_structure(plant, scene.object, bodies, inspector=inspector)
    q = plant.GetPositions(ctx)
    q[hand.position_indices] = rng.uniform(hand.lower, hand.upper)
    plant.SetPositions(ctx, q)
    d = rng.uniform(-1, 1, len(hand.joints))
    h = 1e-7

    def corners(gf):
        shape = inspector.GetShape(gf)
        c, r = bounding_sphere(shape)
        signs = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
        assert isinstance(shape, Box | Sphere | Capsule | Cylinder)
        return c + signs * r / np.sqrt(3.0)  # on the bounding sphere

    for finger in hand.fingers:
        rows = reach(plant, ctx, hand, finger, inspector)
        speed = finger_speed_bound(rows, hand.coupling.tangent(d))
        for (_, gf, body), V in zip(finger.pairs, speed, strict=True):
            X_BG = inspector.GetPoseInFrame(gf)
            p_B = np.array([X_BG.multiply(c) for c in corners(gf)]).T
            plant.SetPositions(ctx, q)
            before = plant.CalcPointsPositions(
                ctx, body.body_frame(), p_B, plant.world_frame()
            )
            q2 = q.copy()
            q2[hand.position_indices] += h * d
            plant.SetPositions(ctx, q2)
            after = plant.CalcPointsPositions(
                ctx, body.body_frame(), p_B, plant.world_frame()
            )
            fastest = np.max(np.linalg.norm(after - before, axis=0)) / h
            assert fastest <= V * (1 + 1e-6)
            assert fastest >= 0.05 * V  # a bound, not a blanket
        plant.SetPositions(ctx, q)
