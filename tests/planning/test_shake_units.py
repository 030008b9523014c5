"""The shake test's summary names the squeeze's unit: N for the prismatic
fingers of a parallel jaw, N·m for the revolute joints of a multi-finger hand."""

from __future__ import annotations

import warnings

import pytest
from allegro_support import allegro_scene, has_thumb

from drakegrasp.planning import plan_grasps, planning_scene, shake_test
from drakegrasp.planning.shake import ShakeResult, SoftFingerShakeWarning
from drakegrasp.planning.shake_ranking import shake_candidates

THREE = "package://drakegrasp/hands/three_finger_hand.sdf"
JAW = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
THREE_OPEN = [-0.4, 0.0, 0.0] * 3
SHORT = dict(settle=0.05, phase=0.05, blend=0.02, seat=0.05, directions=[(1, 0, 0)])


def _best(hand_url, **kw):
    scene = planning_scene(
        "package://drakegrasp/objects/cylinder.sdf", hand_url=hand_url
    )
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=20, mu=1.0, seed=3, robustness_samples=4, **kw,
    )  # fmt: skip
    assert len(result) > 0
    return scene, result[0]


def test_a_revolute_hand_squeezes_in_newton_metres():
    scene, best = _best(THREE, preshape=THREE_OPEN)
    result = shake_test(
        scene.add_models, best, squeeze=1.0, stiffness=20.0, damping=1.0, **SHORT
    )
    assert result.effort_units == ("N·m",) * len(best.joint_names)
    assert "squeeze 1 N·m," in str(result)
    assert result.to_dict()["effort_units"] == ["N·m"] * len(best.joint_names)


def test_a_parallel_jaw_squeezes_in_newtons():
    scene, best = _best(JAW)
    result = shake_test(scene.add_models, best, squeeze=5.0, **SHORT)
    assert set(result.effort_units) == {"N"}
    assert "squeeze 5 N," in str(result)


@pytest.mark.parametrize(
    ("units", "text"),
    [
        ((), "squeeze 2 N,"),
        (("N", "N·m"), "squeeze 2 (N·m, N at prismatic joints),"),  # the plan's
    ],
)
def test_the_summary_unit_of_an_older_or_mixed_result(units, text):
    result = ShakeResult(
        held=True, max_displacement=0.0, max_rotation=0.0, phases=(), squeeze=2.0,
        efforts=(2.0,) * len(units), time_step=1e-3, duration=1.0, wall_time=0.1,
        bounds=(0.01, 0.1), **({"effort_units": units} if units else {}),
    )  # fmt: skip
    assert text in str(result)


def test_a_simulation_drake_cannot_advance_is_a_solver_error_not_a_raw_one():
    """Gains far too stiff for light revolute fingers: Drake's SAP solver stops
    ("failed to converge", a raw ``RuntimeError`` with a page of advice) at the
    first step.  The shake test says so on one line, with the time and what
    to lower, as a ``SolverError``."""
    from drakegrasp.errors import SolverError

    scene, best = _best(THREE, preshape=THREE_OPEN)
    with pytest.raises(SolverError, match=r"stopped at t = .* s \(.*converge") as info:
        shake_test(scene.add_models, best, stiffness=1e7, damping=1e4, **SHORT)
    assert "\n" not in str(info.value)
    assert "stiffness = 1e+07" in str(info.value)
    assert isinstance(info.value.__cause__, RuntimeError)


def test_the_seat_phase_is_reported_apart_from_the_shake():
    """``seat_displacement``/``seat_rotation``/``seat_speed``: where seating
    left the object and how fast it still moved, before any gravity.  A jaw
    squeezing a cylinder seats it within a millimetre and holds it still; the
    figures are part of the whole run's maxima, and of its JSON and summary."""
    import json
    import math

    scene, best = _best(JAW)
    result = shake_test(scene.add_models, best, squeeze=5.0, **SHORT)
    assert 0.0 <= result.seat_displacement <= result.max_displacement
    assert 0.0 <= result.seat_rotation <= result.max_rotation
    assert result.seat_displacement < 1e-3
    assert 0.0 <= result.seat_speed < 5e-3
    # From the seated pose: within the triangle inequality of the two others.
    assert 0.0 <= result.max_displacement_from_seat
    assert (
        result.max_displacement - result.seat_displacement - 1e-12
        <= result.max_displacement_from_seat
        <= result.max_displacement + result.seat_displacement + 1e-12
    )
    assert (
        0.0
        <= result.max_rotation_from_seat
        <= result.max_rotation + result.seat_rotation + 1e-12
    )
    data = json.loads(json.dumps(result.to_dict()))
    assert math.isclose(data["seat_speed"], result.seat_speed)
    assert "seated " in str(result) and "mm/s" in str(result)
    unseated = shake_test(scene.add_models, best, squeeze=5.0, **{**SHORT, "seat": 0.0})
    assert math.isnan(unseated.seat_displacement) and math.isnan(unseated.seat_speed)
    assert math.isnan(unseated.max_displacement_from_seat)
    assert "seated" not in str(unseated)


def test_a_model_drake_refuses_to_advance_is_a_model_error_not_advice_on_gains():
    """Only a contact solver that did not converge is about the gains: a model
    Drake cannot simulate (hydroelastic contact between geometries without a
    hydroelastic representation) is a ``ModelError`` with Drake's sentence."""
    from pydrake.multibody.plant import ContactModel

    from drakegrasp.errors import ModelError

    scene, best = _best(JAW)

    def hydroelastic(plant, parser):
        models = scene.add_models(plant, parser)
        plant.set_contact_model(ContactModel.kHydroelastic)
        return models

    with pytest.raises(ModelError, match="hydroelastic") as info:
        shake_test(hydroelastic, best, squeeze=5.0, **SHORT)
    assert "stiffness" not in str(info.value)
    assert "\n" not in str(info.value)


def test_seat_speed_tells_a_squeeze_that_pushes_out_from_one_that_holds(
    drake_models_dir,
):
    """The Allegro hand on the YCB sugar box (``mu=1``, seed 0): the squeeze
    alone pushes its best thumbless candidate out of the hand (an independent
    seat-only simulation measured 0.15-0.28 m/s), and seats its best candidate
    with the thumb.  ``seat_speed`` of the object (not of the welded hand,
    which never moves) tells them apart by far."""
    scene = allegro_scene("004_sugar_box", drake_models_dir)
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=150, mu=1.0, seed=0,
    )  # fmt: skip
    closures = [c for c in result if c.is_closure]
    with_thumb = next(c for c in closures if has_thumb(c))
    thumbless = next(c for c in closures if not has_thumb(c))
    gains = dict(squeeze=0.7, stiffness=10.0, damping=0.1, **{**SHORT, "seat": 0.1})
    held = shake_test(scene.add_models, with_thumb, **gains)
    pushed = shake_test(scene.add_models, thumbless, **gains)
    assert pushed.seat_speed > 0.1  # m/s, still on its way out
    assert pushed.seat_speed > 5.0 * held.seat_speed


def test_a_squeeze_past_the_effort_limit_says_it_was_capped():
    # the shipped jaw's fingers have <effort>140</effort>: asked for 300 N,
    # each presses with 140 N (Drake's own actuation output agrees), and the
    # summary once said "squeeze 300 N" with no word of it
    scene, best = _best(JAW)
    asked = shake_test(scene.add_models, best, squeeze=300.0, **SHORT)
    assert asked.squeeze_caps == (140.0, 140.0) and asked.squeeze_capped
    assert max(asked.efforts) == pytest.approx(140.0, rel=1e-3)
    assert "squeeze 300 N (capped at the effort limit: 140 N)," in str(asked)
    within = shake_test(scene.add_models, best, squeeze=5.0, **SHORT)
    assert within.squeeze_caps == (5.0, 5.0) and not within.squeeze_capped
    assert "capped" not in str(within)
    assert within.to_dict()["squeeze_caps"] == [5.0, 5.0]


def test_shaken_candidates_name_a_capped_squeeze():
    scene = planning_scene("package://drakegrasp/objects/cylinder.sdf", hand_url=JAW)
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=20, mu=1.0, seed=3, robustness_samples=4,
    )  # fmt: skip
    ranked = shake_candidates(scene.add_models, result, top=1, squeeze=300.0, **SHORT)
    assert "squeeze 300 N capped at the effort limit: 140 N;" in str(ranked)
    ranked = shake_candidates(scene.add_models, result, top=1, squeeze=5.0, **SHORT)
    assert "capped" not in str(ranked)


def test_soft_fingers_in_point_contact_are_warned_of():
    # the plan's soft fingers resist a torque about each normal; Drake's point
    # contact resists none, so the shake may drop what the plan holds
    scene, best = _best(JAW, contact_model="soft_finger", torsional_friction=0.05)
    with pytest.warns(SoftFingerShakeWarning, match="hydroelastic_modulus="):
        shake_test(scene.add_models, best, squeeze=5.0, **SHORT)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SoftFingerShakeWarning)
        shake_test(
            scene.add_models, best, squeeze=5.0, hydroelastic_modulus=1e6, **SHORT
        )
        hard_scene, hard = _best(JAW)
        shake_test(hard_scene.add_models, hard, squeeze=5.0, **SHORT)


def test_caps_that_differ_are_named_as_a_range():
    # a Barrett-style hand: its spread motor drives two joints (0.5 N·m each of
    # 1), each flexion motor a proximal and a distal joint (1.125 of 1.5); the
    # summary named only the smallest, as if every joint pressed with 0.5
    from drakegrasp.planning.shake_result import _limits

    assert _limits((0.5, 0.5, 1.125, 1.125, 20.0), 20.0) == (
        "the effort limits: 0.5-1.125"
    )
    assert _limits((140.0, 140.0), 300.0) == "the effort limit: 140"
    assert _limits((140.0, 300.0), 300.0) == "the effort limit: 140"
