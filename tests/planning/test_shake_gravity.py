"""The shake test turns the weight the plant's own gravity gives, not Earth's.

``shake_test`` zeroed the plant's gravity field and applied ``m · 9.81`` as an
external force, whatever gravity ``add_models`` gave the plant: a grasp
planned on the moon (1.62 m/s²) was shaken with six times its weight.  Now the
turned gravity's magnitude is ``|g|`` of the plant ``add_models`` builds
(``ShakeResult.gravity``), and a plant without gravity is refused: an object
that weighs nothing is held by every grasp.

Checked in Drake: a 3 kg box that a squeeze of half the Earth's
``squeeze_needed`` drops on Earth is held on the moon, where that squeeze is
three times the moon's ``squeeze_needed``; the force the simulation applies
is recorded as it runs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from drakegrasp.errors import ModelError
from drakegrasp.planning import plan_grasps, planning_scene, shake_test
from drakegrasp.planning import shake as shake_module
from drakegrasp.planning.scenes import scene_from_models
from drakegrasp.planning.shake_ranking import shake_candidates
from drakegrasp.planning.turned_gravity import _TurnedGravity

FLAT = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
SHAKE = {"hydroelastic_modulus": 1e6, "directions": [[1.0, 0.0, 0.0]]}
MOON = (0.0, 0.0, -1.62)
# the box's μ 0.5 against the jaw's 1.0 simulates at 0.667: the plan at 0.5
# is the conservative one (as in test_shake_mass)
pytestmark = pytest.mark.filterwarnings(
    "ignore::drakegrasp.plant.friction.FrictionMismatchWarning"
)
MASS = 3.0  # kg: ten times the box's model, a squeeze of tens of newtons
BOX = (  # test_shake_mass's box: 5 x 4 x 12 cm, 0.3 kg, μ = 0.5 in Drake too
    '<?xml version="1.0"?><sdf version="1.9"><model name="tall_box">'
    "<link name='body'><inertial><mass>0.3</mass><inertia><ixx>4e-4</ixx>"
    "<iyy>4e-4</iyy><izz>1e-4</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz>"
    "</inertia></inertial><collision name='c'><geometry><box><size>0.05 0.04 "
    "0.12</size></box></geometry><drake:proximity_properties><drake:mu_dynamic>"
    "0.5</drake:mu_dynamic><drake:mu_static>0.5</drake:mu_static>"
    "</drake:proximity_properties></collision></link></model></sdf>"
)


def _with_gravity(add_models, gravity):
    """``add_models`` whose plant has ``gravity`` (m/s², world frame)."""

    def add(plant, parser):
        plant.mutable_gravity_field().set_gravity_vector(gravity)
        return add_models(plant, parser)

    return add


def _plan(scene):
    return plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, seed=0, mu=0.5, object_mass=MASS,
    )  # fmt: skip


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    """(Earth scene, its plan, moon scene, its plan): the box and the flat jaw."""
    path = tmp_path_factory.mktemp("gravity") / "box.sdf"
    path.write_text(BOX)
    earth = planning_scene(str(path), hand_url=FLAT)
    moon = scene_from_models(_with_gravity(earth.add_models, MOON))
    return earth, _plan(earth), moon, _plan(moon)


@pytest.fixture
def applied(monkeypatch):
    """The magnitudes (N) of every force the shake's turned gravity output."""
    seen: list[float] = []

    class Recording(_TurnedGravity):
        def _calc(self, context, output):
            super()._calc(context, output)
            force = output.get_value()[0].F_Bq_W.translational()
            seen.append(float(np.linalg.norm(force)))

    monkeypatch.setattr(shake_module, "_TurnedGravity", Recording)
    return seen


def test_the_moon_plan_needs_the_moons_squeeze(scenes):
    _, earth, _, moon = scenes
    assert earth[0].sample == moon[0].sample
    ratio = moon[0].squeeze_needed / earth[0].squeeze_needed
    assert ratio == pytest.approx(1.62 / 9.81, rel=1e-14)


def test_a_squeeze_that_drops_on_earth_holds_on_the_moon(scenes, applied):
    earth_scene, earth, moon_scene, moon = scenes
    best = earth[0]
    squeeze = 0.5 * best.squeeze_needed  # about 16 N: 3 moon squeezes needed
    assert squeeze > 2.5 * moon[0].squeeze_needed
    on_earth = shake_test(earth_scene.add_models, best, squeeze=squeeze, **SHAKE)
    earth_forces = list(applied)
    applied.clear()
    on_moon = shake_test(moon_scene.add_models, best, squeeze=squeeze, **SHAKE)
    moon_forces = list(applied)
    print(
        f"squeeze {squeeze:.3g} N: earth {on_earth}\nmoon {on_moon}\n"
        f"largest applied force: earth {max(earth_forces)!r} N, "
        f"moon {max(moon_forces)!r} N"
    )
    assert not on_earth.held_from_seat and on_moon.held_from_seat
    assert max(earth_forces) == pytest.approx(MASS * 9.81, rel=1e-12)
    assert max(moon_forces) == pytest.approx(MASS * 1.62, rel=1e-12)
    assert min(f for f in moon_forces if f > 0) == pytest.approx(MASS * 1.62)
    assert (on_earth.gravity, on_moon.gravity) == (9.81, 1.62)
    assert on_earth.object_mass == on_moon.object_mass == MASS
    assert on_moon.to_dict()["gravity"] == 1.62


def test_the_moon_plan_is_held_above_its_squeeze_and_dropped_below(scenes):
    # the plan and the shake on the same moon plant agree, as on Earth
    # (test_shake_mass): 0.5 and 1.6 times the moon's squeeze_needed
    _, _, moon_scene, moon = scenes
    weak, strong = (
        shake_test(
            moon_scene.add_models, moon[0], squeeze=f * moon[0].squeeze_needed, **SHAKE
        )
        for f in (0.5, 1.6)
    )
    print(f"moon squeeze_needed {moon[0].squeeze_needed:.3g} N: {weak}\n{strong}")
    assert not weak.held_from_seat and strong.held_from_seat


def test_a_plant_without_gravity_is_refused_by_name(scenes, applied):
    earth_scene, earth, _, _ = scenes
    weightless = _with_gravity(earth_scene.add_models, (0.0, 0.0, 0.0))
    says = r"gravity \[0\.0, 0\.0, 0\.0\] m/s².*weighs nothing.*set_gravity_vector"
    with pytest.raises(ModelError, match=says):
        shake_test(weightless, earth[0], **SHAKE)
    with pytest.raises(ModelError, match=says):  # at the first candidate
        shake_candidates(weightless, earth, top=3, **SHAKE)
    assert applied == []  # nothing simulated


@pytest.mark.parametrize(
    ("gravity", "says"),
    [
        ((0.0, 0.0, math.inf), r"gravity field \[0\.0, 0\.0, inf\] m/s²"),
        ((0.0, 0.0, -1e308), r"3 kg in the plant's gravity, 1e\+308 m/s², weighs inf"),
    ],
)
def test_a_gravity_whose_weight_is_no_float_is_refused(scenes, gravity, says):
    earth_scene, earth, _, _ = scenes
    with pytest.raises(ModelError, match=says):
        shake_test(_with_gravity(earth_scene.add_models, gravity), earth[0], **SHAKE)


def test_a_weight_that_rounds_to_zero_is_refused(scenes):
    # a milligram in the least subnormal gravity weighs 0.0 N
    earth_scene, earth, _, _ = scenes
    tiny = _with_gravity(earth_scene.add_models, (0.0, 0.0, -5e-324))
    with pytest.raises(ModelError, match="weighs 0 N: the shake test needs"):
        shake_test(tiny, earth[0], object_mass=1e-6, **SHAKE)


def test_a_plan_shaken_in_another_gravity_is_warned_of(scenes):
    # The review: settings["gravity"] was recorded for the shake to match,
    # and nothing read it.  The moon plan shaken with Earth's add_models
    # weighs six times what was planned; with the moon's, nothing is said.
    import warnings

    from drakegrasp.planning.shake_ranking import GravityMismatchWarning

    earth, _, moon, moon_plan = scenes
    assert moon_plan.settings["gravity"] == pytest.approx(1.62, rel=1e-15)
    short = {**SHAKE, "settle": 0.05, "phase": 0.05, "seat": 0.05, "blend": 0.02}
    with pytest.warns(GravityMismatchWarning, match="1.62 m/s²") as seen:
        shake_candidates(earth.add_models, moon_plan, top=2, **short)
    assert len([w for w in seen if w.category is GravityMismatchWarning]) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error", GravityMismatchWarning)
        shaken = shake_candidates(moon.add_models, moon_plan, top=1, **short)
    assert shaken.shaken[0].result.gravity == pytest.approx(1.62, rel=1e-15)


def test_the_grasp_settles_under_the_plants_own_gravity_direction(scenes, monkeypatch):
    # The review: the shake settled along the world's -z whatever the plant's
    # gravity; a scene whose gravity points along -y (a model turned on its
    # side) settled under a weight across the planned one.  The first forces
    # after the seat now point along the plant's gravity, at its magnitude.
    earth, earth_plan, _, _ = scenes
    forces: list[tuple[float, np.ndarray]] = []

    class Recording(_TurnedGravity):
        def _calc(self, context, output):
            super()._calc(context, output)
            f = np.array(output.get_value()[0].F_Bq_W.translational())
            forces.append((context.get_time(), f))

    monkeypatch.setattr(shake_module, "_TurnedGravity", Recording)
    sideways = _with_gravity(earth.add_models, (0.0, -9.81, 0.0))
    result = shake_test(
        sideways, earth_plan[0], squeeze=60.0, seat=0.05, settle=0.05,
        phase=0.05, blend=0.02, directions=[[1.0, 0.0, 0.0]], **{
            k: v for k, v in SHAKE.items() if k != "directions"
        },
    )  # fmt: skip
    assert result.gravity == 9.81
    settling = [f for t, f in forces if 0.05 < t < 0.1]
    assert settling
    for f in settling:
        np.testing.assert_allclose(f, [0.0, -MASS * 9.81, 0.0], rtol=1e-12)


def test_the_gravity_mismatch_warning_points_at_the_callers_line(scenes):
    # shake_candidates is wrapped by checked_call: a fixed stacklevel=3 named
    # drakegrasp/core/calls.py, not the line that called it.
    from drakegrasp.planning.shake_ranking import GravityMismatchWarning

    earth, _, _, moon_plan = scenes
    short = {**SHAKE, "settle": 0.05, "phase": 0.05, "seat": 0.05, "blend": 0.02}
    with pytest.warns(GravityMismatchWarning) as seen:
        shake_candidates(earth.add_models, moon_plan, top=1, **short)
    assert [w.filename for w in seen if w.category is GravityMismatchWarning] == [
        __file__
    ]


@pytest.mark.parametrize(
    "planned",
    [1.62, np.float64(1.62), np.float32(1.62), 2, np.int64(2), np.array(1.62)],
)
def test_a_recorded_gravity_of_any_real_type_is_compared(planned):
    # The review: a plan's settings["gravity"] read back from JSON (an int) or
    # computed in numpy (float64) was skipped, since only a float was compared
    import types
    import warnings

    from drakegrasp.planning.shake_ranking import GravityMismatchWarning, _check_gravity
    from drakegrasp.planning.shake_result import ShakeResult

    def shaken(g: float) -> ShakeResult:
        return ShakeResult(
            held=True, max_displacement=0.0, max_rotation=0.0, phases=(),
            squeeze=1.0, efforts=(), time_step=1e-3, duration=1.0, wall_time=0.1,
            bounds=(0.01, 0.1), gravity=g,
        )  # fmt: skip

    plan = types.SimpleNamespace(settings={"gravity": planned})
    with pytest.warns(GravityMismatchWarning, match=f"{float(planned):g} m/s²"):
        _check_gravity(plan, shaken(9.81))
    with warnings.catch_warnings():
        warnings.simplefilter("error", GravityMismatchWarning)
        _check_gravity(plan, shaken(float(planned)))  # the same: nothing said


@pytest.mark.parametrize("recorded", [None, "1.62", True, float("nan"), [1.62]])
def test_no_recorded_gravity_is_compared_with_nothing_said(recorded):
    import types
    import warnings

    from drakegrasp.planning.shake_ranking import GravityMismatchWarning, _check_gravity
    from drakegrasp.planning.shake_result import ShakeResult

    result = ShakeResult(
        held=True, max_displacement=0.0, max_rotation=0.0, phases=(), squeeze=1.0,
        efforts=(), time_step=1e-3, duration=1.0, wall_time=0.1, bounds=(0.01, 0.1),
        gravity=9.81,
    )  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("error", GravityMismatchWarning)
        _check_gravity(types.SimpleNamespace(settings={"gravity": recorded}), result)
        _check_gravity([], result)  # a list of candidates records none
