"""The shake test pulls on the mass the grasp was planned for.

``plan_grasps(object_mass=...)`` plans for a mass that is not the model's (a
box full of something, a mesh of water).  Before, ``shake_test`` and
``plan --shake --mass`` always shook the model's mass: a 20 kg box planned to
need 217 N per finger "held" at a 20 N squeeze.  Now the mass planned for is
the mass shaken: each candidate records it (``GraspCandidate.object_mass``),
``shake_test`` takes it by default, and a massless model whose candidate
records none is refused rather than shaken with no weight at all.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from drakegrasp.cli import main
from drakegrasp.errors import InvalidGraspError, InvalidOptionError, ModelError
from drakegrasp.planning import plan_grasps, planning_scene, shake_test
from drakegrasp.planning.shake_ranking import check_settings, shake_candidates

FLAT = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
SHAKE = {"hydroelastic_modulus": 1e6, "directions": [[1.0, 0.0, 0.0]]}


def _box(path, mass: float) -> str:
    """A 5 x 4 x 12 cm box of ``mass`` kg (no inertia when massless)."""
    inertia = ("4e-4", "4e-4", "1e-4") if mass > 0 else ("0", "0", "0")
    path.write_text(
        '<?xml version="1.0"?><sdf version="1.9"><model name="tall_box">'
        f"<link name='body'><inertial><mass>{mass}</mass><inertia>"
        f"<ixx>{inertia[0]}</ixx><iyy>{inertia[1]}</iyy><izz>{inertia[2]}</izz>"
        "<ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>"
        "<collision name='c'><geometry><box><size>0.05 0.04 0.12</size></box>"
        "</geometry><drake:proximity_properties><drake:mu_dynamic>0.5"
        "</drake:mu_dynamic><drake:mu_static>0.5</drake:mu_static>"
        "</drake:proximity_properties></collision></link></model></sdf>"
    )
    return str(path)


def _plan(scene, **kw):
    return plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, seed=0, mu=0.5, **kw,
    )  # fmt: skip


@pytest.fixture(scope="module")
def light_box(tmp_path_factory):
    """A 0.3 kg box and its plan for 3 kg: ten times the model's weight."""
    path = _box(tmp_path_factory.mktemp("mass") / "box.sdf", 0.3)
    scene = planning_scene(path, hand_url=FLAT)
    return scene, _plan(scene, object_mass=3.0)


def test_the_plan_records_the_mass_it_was_planned_for(light_box):
    scene, result = light_box
    assert result.settings["object_mass"] == 3.0
    assert all(c.object_mass == 3.0 for c in result)
    model = _plan(scene)  # the body's own
    assert "object_mass" not in model.settings
    assert all(c.object_mass == 0.3 for c in model)
    data = json.loads(json.dumps(result.to_dict()))
    assert data["settings"]["object_mass"] == 3.0
    assert data["candidates"][0]["object_mass"] == 3.0


def test_the_shake_agrees_with_squeeze_needed_at_the_planned_mass(light_box):
    """Below the squeeze the plan says 3 kg needs, the box falls; above, it
    holds.  Shaken with the model's 0.3 kg, both squeezes held (the old
    behaviour: ten times the squeeze needed at 0.3 kg)."""
    scene, result = light_box
    best = result[0]
    needed = best.squeeze_needed
    assert 20.0 < needed < 60.0  # 3 kg's weight, m g / capacity: about 33 N
    weak, strong = (
        shake_candidates(scene.add_models, result, top=1, squeeze=f * needed, **SHAKE)
        for f in (0.5, 1.6)
    )
    assert weak[0].result.object_mass == 3.0
    assert strong[0].result.object_mass == 3.0
    assert not weak[0].held and strong[0].held, (weak[0], strong[0])
    assert "object 3 kg; squeeze" in str(weak)
    one = shake_test(scene.add_models, best, squeeze=0.5 * needed, **SHAKE)
    assert one.object_mass == 3.0 and not one.held_from_seat
    model = shake_test(
        scene.add_models, best, squeeze=0.5 * needed, object_mass=0.3, **SHAKE
    )
    assert model.object_mass == 0.3 and model.held_from_seat


def test_candidates_sliced_or_filtered_keep_their_mass(light_box):
    # each candidate records the mass it was planned for: a slice or a list
    # of them is shaken at 3 kg, as the whole result is
    scene, result = light_box
    squeeze = 0.5 * result[0].squeeze_needed
    for chosen in (result[:1], [c for c in result if c.is_closure][:1]):
        shaken = shake_candidates(
            scene.add_models, chosen, top=1, squeeze=squeeze, **SHAKE
        )
        assert shaken[0].result.object_mass == 3.0
        assert not shaken[0].held


def test_an_explicit_mass_overrides_the_planned_one(light_box):
    scene, result = light_box
    shaken = shake_candidates(
        scene.add_models, result, top=1, object_mass=0.3,
        squeeze=0.5 * result[0].squeeze_needed, **SHAKE,
    )  # fmt: skip
    assert shaken[0].result.object_mass == 0.3 and shaken[0].held
    assert shaken.options["object_mass"] == 0.3


def test_a_massless_model_is_shaken_only_with_a_mass(tmp_path):
    scene = planning_scene(_box(tmp_path / "massless.sdf", 0.0), hand_url=FLAT)
    result = _plan(scene, object_mass=0.3)
    unknown = dataclasses.replace(result[0], object_mass=math.nan)  # none recorded
    with pytest.raises(ModelError, match=r"mass 0 kg in the model.*object_mass="):
        shake_test(scene.add_models, unknown, **SHAKE)
    squeeze = 2 * result[0].squeeze_needed
    for shaken in (
        shake_test(
            scene.add_models, unknown, squeeze=squeeze, object_mass=0.3, **SHAKE
        ),
        shake_candidates(scene.add_models, result[:1], top=1, squeeze=squeeze, **SHAKE)[
            0
        ].result,
    ):
        assert shaken.object_mass == 0.3 and shaken.held


@pytest.mark.parametrize(
    "mass", [0.0, -1.0, math.inf, 1e308, 1e-12, "3", True, None, 10**400]
)
def test_a_candidate_with_a_bad_mass_is_refused(light_box, mass):
    scene, result = light_box
    bad = dataclasses.replace(result[0], object_mass=mass)
    with pytest.raises(InvalidGraspError, match="object_mass"):
        shake_test(scene.add_models, bad, **SHAKE)


@pytest.mark.parametrize(
    "mass", [0.0, -1.0, math.nan, math.inf, True, "1", 10**400, 1e308, np.float64(-2)]
)
def test_a_bad_mass_is_refused_before_any_simulation(mass):
    with pytest.raises(InvalidOptionError, match="object_mass"):
        check_settings(1, "seat", {"object_mass": mass})


def test_plan_shake_shakes_the_mass_given_with_mass(capsys):
    argv = ["plan", "--num", "40", "--top", "1", "--shake", "1", "--json"]
    assert main([*argv, "--mass", "20"]) == 0
    shaken = json.loads(capsys.readouterr().out)["shaken"]
    result = shaken["shaken"][0]["result"]
    # the box planned for 20 kg needs about 217 N per finger; 20 N drops it
    assert result["object_mass"] == 20.0
    assert not shaken["shaken"][0]["held"]


def test_a_massless_models_ball_sits_at_the_planners_centre_of_mass(tmp_path):
    # The ball's centre of mass is the candidate's reference point (frame O),
    # not O's origin; its inertia about that point is 2/5 m r², r the
    # candidate's torque scale.
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    from drakegrasp.planning.shake import _object_inertia

    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(_box(tmp_path / "massless.sdf", 0.0))
    plant.Finalize()
    body = plant.GetBodyByName("body")
    scene = planning_scene(str(tmp_path / "massless.sdf"), hand_url=FLAT)
    candidate = _plan(scene, object_mass=0.3)[0]
    moved = dataclasses.replace(
        candidate, reference_point=np.array([0.02, -0.01, 0.03])
    )
    mass, com, M = _object_inertia(body, 0.3, moved)
    np.testing.assert_allclose(com, moved.reference_point)
    np.testing.assert_allclose(M.get_com(), moved.reference_point)
    r = moved.torque_scale
    central = M.Shift(moved.reference_point).CopyToFullMatrix6()[:3, :3]
    np.testing.assert_allclose(central, 0.4 * 0.3 * r**2 * np.eye(3), rtol=1e-12)
    assert mass == M.get_mass() == 0.3


def test_a_massless_body_planned_without_a_mass_needs_no_squeeze_figure(tmp_path):
    # Before: squeeze_needed 0 N (no weight), so any motor "held" every
    # candidate; now not computed, as on a point cloud without object_mass.
    scene = planning_scene(_box(tmp_path / "massless.sdf", 0.0), hand_url=FLAT)
    result = _plan(scene)
    assert len(result) and all(np.isnan(c.squeeze_needed) for c in result)
    assert all(np.isnan(c.object_mass) for c in result)
    assert result.settings.get("held_first", {}).get("held", 0) == 0  # none known
    with pytest.raises(ModelError, match="give object_mass="):
        shake_test(scene.add_models, result[0], **SHAKE)


def test_the_recorded_mass_is_the_one_given(capsys):
    # 0.11 * 9.81 / 9.81 is 0.11000000000000001: the mass is recorded as given,
    # not recovered from the weight
    assert main(["plan", "--num", "20", "--top", "1", "--mass", "0.11", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["candidates"][0]["object_mass"] == 0.11


def test_plan_refuses_a_mass_too_light_to_shake_before_planning(capsys):
    argv = ["plan", "--num", "40", "--top", "1", "--mass", "1e-9", "--shake", "1"]
    assert main(argv) == 1
    captured = capsys.readouterr()
    assert captured.out == ""  # nothing planned
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and "--mass = 1e-09 kg is lighter" in err[0], err


def test_plan_shake_of_a_massless_file_asks_for_mass(tmp_path, capsys):
    path = _box(tmp_path / "massless.sdf", 0.0)
    assert main(["plan", path, "--num", "40", "--top", "1", "--shake", "1"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "give --mass KG" in err[0], err
