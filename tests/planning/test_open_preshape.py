"""``preshape="open"``: a multi-finger hand opened before it is placed.

The multi-finger route starts from the context's hand.  An angular gripper
whose model's zero stands its jaws parallel and nearly shut collided with
the object wherever it was placed (0 to 2 candidates of 100, where the
parallel-jaw route opens a jaw's whole stroke).  ``"open"`` turns each joint
the way that parts the fingertips, to its limit, and the plan's best grasp
holds in Drake's simulation.
"""

from __future__ import annotations

import numpy as np
import pytest
from coupled_hands import angular_gripper_urdf, coupled_jaw_urdf, spread_hand_urdf
from quiet_plans import plan_quietly

from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning import planning_scene, shake_test
from drakegrasp.planning.approach import OPEN
from drakegrasp.planning.planner import OPEN_HAND_HINT

CYLINDER = "package://drakegrasp/objects/cylinder.sdf"
LIMITS = (-0.1745, 0.5236)  # the gripper's hinges, rad
PLAN = dict(num_candidates=100, mu=0.5, seed=0, robustness_samples=8, object_mass=0.2)


@pytest.fixture(scope="module")
def gripper(tmp_path_factory):
    path = tmp_path_factory.mktemp("angular") / "angular_gripper.urdf"
    path.write_text(angular_gripper_urdf())
    return path


def _scene(path, left=None):
    scene = planning_scene(CYLINDER, hand_url=str(path))
    if left is not None:  # the context's jaws (the right one follows)
        ctx = scene.plant.GetMyMutableContextFromRoot(scene.context)
        for name in ("left_hinge", "right_hinge"):
            scene.plant.GetJointByName(name).set_angle(ctx, left)
    return scene


def _plan(scene, **options):
    return plan_quietly(scene, **{**PLAN, **options})


@pytest.fixture(scope="module")
def opened(gripper):
    scene = _scene(gripper)
    return scene, _plan(scene, preshape=OPEN)


def _pad_gap(scene, q: float) -> float:
    """Distance (m) between the jaws' tip pads at hinge angle ``q``: by Drake's FK."""
    plant = scene.plant
    ctx = plant.CreateDefaultContext()
    for name in ("left_hinge", "right_hinge"):
        plant.GetJointByName(name).set_angle(ctx, q)
    tip = [0.0, 0.0, 0.09]  # the jaw's end, in its hinge's frame
    a, b = (
        plant.CalcPointsPositions(
            ctx, plant.GetBodyByName(jaw).body_frame(), np.array([tip]).T,
            plant.world_frame(),
        )[:, 0]
        for jaw in ("left_jaw", "right_jaw")
    )  # fmt: skip
    return float(np.linalg.norm(a - b))


def test_the_shut_model_collides_and_is_told_to_open(gripper):
    result = _plan(_scene(gripper))
    assert len(result) == 0
    assert (
        result.rejections["hand collides with the object"]
        >= 0.9 * PLAN["num_candidates"]
    )
    assert result.reason.endswith(OPEN_HAND_HINT)
    assert result.reason.endswith(
        "open it (preshape='open', or joint values) or move the palm back (standoff=)"
    )


def test_open_turns_each_jaw_to_the_limit_that_parts_them(opened, gripper):
    scene, result = opened
    q = np.array(result.settings["hand"]["preshape"])
    np.testing.assert_allclose(q, [LIMITS[1]] * 2, atol=1e-12)
    # a second route: over the hinges' whole range, the pads stand farthest
    # apart where "open" put them
    grid = np.linspace(*LIMITS, 41)
    gaps = [_pad_gap(scene, g) for g in grid]
    assert _pad_gap(scene, q[0]) == pytest.approx(max(gaps), abs=1e-12)
    assert grid[int(np.argmax(gaps))] == pytest.approx(LIMITS[1])


@pytest.mark.parametrize("left", [LIMITS[0], 0.2])
def test_open_does_not_depend_on_where_the_context_left_the_jaws(opened, gripper, left):
    _, result = opened
    again = _plan(_scene(gripper, left=left), preshape=OPEN)
    assert again.settings["hand"]["preshape"] == result.settings["hand"]["preshape"]
    assert [c.sample for c in again] == [c.sample for c in result]


@pytest.mark.filterwarnings("ignore::drakegrasp.plant.friction.FrictionMismatchWarning")
def test_the_opened_plan_finds_grasps_and_its_best_holds_in_drake(opened):
    scene, result = opened
    assert len(result) >= 50
    best = result[0]
    assert best.is_closure and best.score > 0
    shaken = shake_test(
        scene.add_models, best, object_mass=0.2, hydroelastic_modulus=1e6,
        settle=0.2, phase=0.3,
    )  # fmt: skip
    assert shaken.held, shaken
    assert shaken.max_displacement < 5e-3


def test_a_misspelt_open_is_refused(gripper):
    with pytest.raises(InvalidOptionError, match="or 'open', got 'opened'"):
        _plan(_scene(gripper), preshape="opened", num_candidates=2)


def test_a_parallel_jaw_refuses_open(tmp_path):
    path = tmp_path / "jaw.urdf"
    path.write_text(coupled_jaw_urdf())
    with pytest.raises(InvalidOptionError, match="parallel jaw"):
        _plan(_scene(path), preshape=OPEN, num_candidates=2)


def test_the_cli_opens_the_gripper_and_plans(gripper, capsys):
    from drakegrasp.cli import main

    argv = ["plan", "cylinder", "--hand", str(gripper), "--num", "100", "--top", "2"]
    assert main(argv) == 0
    shut = capsys.readouterr().out
    assert "#0" not in shut and "--preshape open" in shut, shut
    assert main([*argv, "--preshape", "open"]) == 0
    opened = capsys.readouterr().out
    assert "#0" in opened and "force closure" in opened, opened


def test_a_barrett_like_hand_opens_from_straight_fingers(tmp_path):
    # the spread hand's fingers stand straight at zero; opened, each flexion
    # bends back to its lower limit (-0.5 rad, the distal joint following at
    # 0.5) and the spread turns f1 and f2 away from f3
    path = tmp_path / "spread.urdf"
    path.write_text(spread_hand_urdf())
    scene = _scene(path)
    shut, opened = _plan(scene), _plan(scene, preshape=OPEN)
    hand = opened.settings["hand"]
    q = dict(zip(hand["joints"], hand["preshape"], strict=True))
    for k in (1, 2, 3):
        assert q[f"spread_hand::f{k}_proximal_joint"] == pytest.approx(-0.5)
        assert q[f"spread_hand::f{k}_distal_joint"] == pytest.approx(-0.25)
    assert q["spread_hand::f1_spread"] > 0.1
    assert len(opened) >= len(shut) > 0


def test_jaws_without_limits_open_as_far_as_that_parts_them(tmp_path):
    # continuous hinges: no limit to stop at; the opening went 0.2 rad (its
    # step budget came from the joints' ranges) and stopped
    urdf = angular_gripper_urdf().replace('type="revolute"', 'type="continuous"')
    urdf = urdf.replace('lower="-0.1745" upper="0.5236" ', "")
    path = tmp_path / "continuous.urdf"
    path.write_text(urdf)
    scene = _scene(path)
    assert np.isinf(scene.plant.GetJointByName("left_hinge").position_upper_limits())
    result = _plan(scene, preshape=OPEN, num_candidates=4)
    q = result.settings["hand"]["preshape"][0]
    # a second route: the jaws' geometry centres, by Drake's FK on a grid, are
    # farthest apart within a sixteenth of the opening's 0.1 rad step of q
    plant = scene.plant
    ctx = plant.CreateDefaultContext()
    inspector = (
        scene.plant.get_geometry_query_input_port()
        .Eval(plant.GetMyContextFromRoot(scene.context))
        .inspector()
    )

    def spread(angle: float) -> float:
        for name in ("left_hinge", "right_hinge"):
            plant.GetJointByName(name).set_angle(ctx, angle)
        centres = []
        for jaw in ("left_jaw", "right_jaw"):
            body = plant.GetBodyByName(jaw)
            X_WB = plant.EvalBodyPoseInWorld(ctx, body)
            centres.append(
                np.mean(
                    [
                        X_WB.multiply(inspector.GetPoseInFrame(g).translation())
                        for g in plant.GetCollisionGeometriesForBody(body)
                    ],
                    axis=0,
                )
            )
        return float(np.linalg.norm(centres[0] - centres[1]))

    grid = np.linspace(0.0, np.pi, 2001)
    best = grid[int(np.argmax([spread(a) for a in grid]))]
    assert q == pytest.approx(best, abs=0.1 / 16)
    assert q > 1.4
