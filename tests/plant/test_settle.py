"""Re-seating (issue 20, point 8): close_hand(settle=True) lets the object move.

A box tilted between the four-sphere pads of our own WSG-like gripper (and
the sugar box in the real WSG-50, skipped without drake_models) touches one
or two spheres per pad; settled, it touches all of them.  Every claim is
checked against Drake directly: signed distances of every pair, the pose in
the context, and a Drake simulation without gravity in which the jaws squeeze
the box with constant forces (the physical check of the quasi-static model).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from hand_models import Rig, box_object, sphere_pad_gripper
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.systems.analysis import Simulator

from drakegrasp import InvalidOptionError, UnreachableError, close_hand
from drakegrasp.plant.contacts import DEFAULT_DISTANCE_TOLERANCE as TOL

BOX = 0.03


def tilted(roll_deg, yaw_deg, y=0.0, *, mu=None, time_step=0.0, gravity=True):
    X = RigidTransform(
        RollPitchYaw(np.deg2rad(roll_deg), 0.0, np.deg2rad(yaw_deg)), [0.0, y, 0.05]
    )
    rig = Rig(
        [(sphere_pad_gripper(), "sdf"), (box_object((BOX,) * 3, mu=mu), "sdf")],
        "box",
        X,
        time_step=time_step,
        gravity=gravity,
    )
    return rig, X


def tips(rig):
    """ψ of each of the eight tip spheres (Drake's pair distances)."""
    return {g: d for (g, _), d in rig.pair_distances().items() if "_tip_" in g}


def misalignment(R_WO: RotationMatrix) -> float:
    """Angle (rad) between the jaws' axis (world y) and the nearest box axis."""
    R = R_WO.matrix()
    return float(np.arccos(min(1.0, np.max(np.abs(R[1, :])))))


@pytest.mark.parametrize("roll, yaw", [(0.0, 8.0), (0.0, -5.0), (6.0, 7.0), (-10, 3)])
def test_a_tilted_box_reseats_to_full_pad_contact(roll, yaw):
    rig, X = tilted(roll, yaw)
    close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    before = tips(rig)
    assert sum(d <= TOL for d in before.values()) < 8  # not seated
    rig.plant.SetFreeBodyPose(rig.ctx, rig.object, X)
    rig.plant.SetPositions(rig.ctx, rig.hand, [0.0, 0.0])
    closure = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, settle=True)
    after = tips(rig)
    assert all(0.0 <= d <= TOL for d in after.values()), after  # full pad contact
    assert min(rig.pair_distances().values()) >= 0.0  # nothing penetrates
    settled = closure.settle
    assert settled is not None and settled.converged
    # The context holds the settled pose and the closed jaws.
    X_WO = rig.plant.EvalBodyPoseInWorld(rig.ctx, rig.object)
    assert X_WO.IsExactlyEqualTo(closure.X_WO)
    np.testing.assert_array_equal(rig.plant.GetPositions(rig.ctx, rig.hand), closure.q)
    # Faces parallel to the pads: a box axis along the jaws' axis.
    assert misalignment(X_WO.rotation()) < np.deg2rad(0.05)
    # It turned at least as far as its faces were from the pads' planes.
    assert settled.rotation >= misalignment(X.rotation()) - np.deg2rad(0.05)
    assert all(f.status == "touching" for f in closure.fingers)
    assert all(j.touching for j in closure.jaws) and not closure.warnings
    data = json.loads(json.dumps(closure.to_dict()))
    assert data["settle"]["converged"]
    np.testing.assert_allclose(data["settle"]["X_WO"], X_WO.GetAsMatrix4())
    assert "seated after" in str(closure)


def test_symmetric_jaws_centre_an_off_centre_box():
    rig, _ = tilted(0.0, 0.0, y=0.003)
    closure = close_hand(
        rig.plant, rig.ctx, rig.object, hand=rig.hand, symmetric=True, settle=True
    )
    assert closure.q[0] == closure.q[1]
    assert all(j.touching for j in closure.jaws) and not closure.warnings
    # Pushed by the right jaw onto the left one: centred to within ψ.
    assert closure.X_WO.translation()[1] == pytest.approx(0.0, abs=TOL)
    assert closure.settle.translation == pytest.approx(0.003, abs=TOL)
    assert closure.settle.rotation < 1e-9


@settings(derandomize=True, max_examples=6, deadline=None)
@given(
    roll=st.floats(-10, 10),
    yaw=st.floats(-10, 10),
    y=st.floats(-0.004, 0.004),
    symmetric=st.booleans(),
)
def test_settled_pads_always_seat_without_penetration(roll, yaw, y, symmetric):
    rig, _ = tilted(roll, yaw, y)
    closure = close_hand(
        rig.plant, rig.ctx, rig.object, hand=rig.hand, symmetric=symmetric, settle=True
    )
    assert closure.settle.converged
    assert min(rig.pair_distances().values()) >= 0.0
    assert all(d <= TOL for d in tips(rig).values())
    assert misalignment(closure.X_WO.rotation()) < np.deg2rad(0.05)


def test_settle_refuses_an_object_that_cannot_move():
    welded = box_object((BOX,) * 3).replace(
        "</model>",
        '<joint name="weld" type="fixed"><parent>world</parent><child>box</child>'
        "</joint></model>",
    )
    rig = Rig([(sphere_pad_gripper(), "sdf"), (welded, "sdf")], "box")
    q0 = rig.plant.GetPositions(rig.ctx)
    with pytest.raises(InvalidOptionError, match="'box::box' is not a free body"):
        close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, settle=True)
    np.testing.assert_array_equal(rig.plant.GetPositions(rig.ctx), q0)
    rig, _ = tilted(0, 5)
    with pytest.raises(InvalidOptionError, match="settle must be True or False"):
        close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, settle="yes")


def _squeeze(q, X_WO, mu, duration, force=5.0):
    """Simulate the jaws squeezing the box (no gravity); the box's final pose."""
    sim, _ = tilted(0, 0, mu=mu, time_step=1e-3, gravity=False)
    sim.plant.SetPositions(sim.ctx, sim.hand, q)
    sim.plant.SetFreeBodyPose(sim.ctx, sim.object, X_WO)
    sim.plant.get_actuation_input_port().FixValue(sim.ctx, [force, force])
    Simulator(sim.diagram, sim.root).AdvanceTo(duration)
    return (
        sim.plant.EvalBodyPoseInWorld(sim.ctx, sim.object),
        sim.plant.GetPositions(sim.ctx, sim.hand),
    )


def _angle(X_a, X_b) -> float:
    return X_a.rotation().inverse().multiply(X_b.rotation()).ToAngleAxis().angle()


def test_drake_simulation_seats_the_box_where_settle_does():
    rig, X = tilted(0.0, 8.0, y=0.003)
    closed = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    rig.plant.SetFreeBodyPose(rig.ctx, rig.object, X)
    rig.plant.SetPositions(rig.ctx, rig.hand, [0.0, 0.0])
    settled = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, settle=True)
    # Low friction (the quasi-static model has none): squeezed from the closed,
    # unseated pose, Drake's box turns onto the pads where settle put it.
    X_sim, q_sim = _squeeze(closed.q, X, mu=0.1, duration=0.3)
    assert np.rad2deg(_angle(X_sim, X)) > 7.5  # it did turn
    assert np.rad2deg(_angle(X_sim, settled.X_WO)) < 0.1
    assert np.linalg.norm(X_sim.translation() - settled.X_WO.translation()) < 0.5e-3
    np.testing.assert_allclose(q_sim, settled.q, atol=0.2e-3)  # contact compliance
    # Seated is an equilibrium: squeezed there with friction, the box stays.
    X_hold, _ = _squeeze(settled.q, settled.X_WO, mu=0.5, duration=0.3)
    assert np.rad2deg(_angle(X_hold, settled.X_WO)) < 0.05


def test_wsg_reseats_a_tilted_sugar_box(real_hands):
    R = RotationMatrix.MakeYRotation(np.deg2rad(7)).multiply(
        RotationMatrix(np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0]], dtype=float))
    )
    X = RigidTransform(R, [0.0, 0.09, 0.0])

    def tip_distances(scene):
        query = scene.plant.get_geometry_query_input_port().Eval(scene.ctx)
        inspector = query.inspector()
        out = {}
        for i in scene.plant.GetBodyIndices(scene.hand):
            for g in scene.plant.GetCollisionGeometriesForBody(scene.plant.get_body(i)):
                name = inspector.GetName(g)
                if name.split("::")[-1].split("_")[-1] in (
                    "top",
                    "bottom",
                    "left",
                    "right",
                ):
                    out[name] = min(
                        query.ComputeSignedDistancePairClosestPoints(go, g).distance
                        for go in scene.plant.GetCollisionGeometriesForBody(
                            scene.object
                        )
                    )
        return out

    scene = real_hands.wsg(X_WO=X)
    close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    before = tip_distances(scene)
    assert len(before) == 8
    assert sum(d <= TOL for d in before.values()) == 2  # one tip per finger
    scene = real_hands.wsg(X_WO=X)
    closure = close_hand(
        scene.plant, scene.ctx, scene.object, hand=scene.hand, settle=True
    )
    after = tip_distances(scene)
    assert all(0.0 <= d <= TOL for d in after.values()), after
    assert closure.settle.converged
    assert closure.settle.rotation == pytest.approx(np.deg2rad(7), abs=1e-3)


def test_franka_jaws_centre_an_off_centre_box(real_hands):
    scene = real_hands.franka()  # the box 5 mm off the fingers' midplane
    closure = close_hand(
        scene.plant,
        scene.ctx,
        scene.object,
        hand=scene.hand,
        symmetric=True,
        settle=True,
    )
    assert all(j.touching for j in closure.jaws) and not closure.warnings
    assert closure.X_WO.translation()[1] == pytest.approx(0.0, abs=TOL)
    assert closure.settle.translation == pytest.approx(0.005, abs=TOL)


def test_an_object_squeezed_out_without_friction_is_refused(real_hands):
    # Frictionless, the Allegro's fingers push the ball out of the open hand:
    # nothing touches any more, and the context goes back as it was.
    scene = real_hands.allegro()
    q0 = scene.plant.GetPositions(scene.ctx).copy()
    with pytest.raises(UnreachableError, match="squeeze it out") as info:
        close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand, settle=True)
    np.testing.assert_array_equal(scene.plant.GetPositions(scene.ctx), q0)
    assert info.value.closure.settle.translation > 0.05


def test_a_seated_box_is_a_fixed_point():
    rig, _ = tilted(0.0, 6.0)
    first = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, settle=True)
    again = close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand, settle=True)
    assert again.settle.converged
    assert again.settle.translation < 1e-9 and again.settle.rotation < 1e-9
    np.testing.assert_allclose(again.q, first.q, atol=1e-9)
