"""The shake test pulls on the mass the grasp was planned for.

``plan_grasps(object_mass=...)`` plans for a mass that is not the model's (a
box full of something, a mesh of water).  Before, ``shake_test`` and
``plan --shake --mass`` always shook the model's mass: a 20 kg box planned to
need 217 N per finger "held" at a 20 N squeeze.  Now the mass planned for is
the mass shaken (``object_mass``), and a massless model is refused rather
than shaken with no weight at all.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from drakegrasp.cli import main
from drakegrasp.errors import InvalidOptionError, ModelError
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
    assert "object_mass" not in _plan(scene).settings  # the model's: not given
    assert json.loads(json.dumps(result.to_dict()))["settings"]["object_mass"] == 3.0


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
    assert weak[0].result.object_mass == strong[0].result.object_mass == 3.0
    assert not weak[0].held and strong[0].held, (weak[0], strong[0])
    assert "object 3 kg; squeeze" in str(weak)
    model = shake_test(scene.add_models, best, squeeze=0.5 * needed, **SHAKE)
    assert model.object_mass == pytest.approx(0.3) and model.held_from_seat


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
    with pytest.raises(ModelError, match=r"mass 0 kg in the model.*object_mass="):
        shake_test(scene.add_models, result[0], **SHAKE)
    shaken = shake_candidates(
        scene.add_models, result, top=1, squeeze=2 * result[0].squeeze_needed, **SHAKE
    )
    assert shaken[0].result.object_mass == 0.3 and shaken[0].held, shaken[0]


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
    assert shaken["options"]["object_mass"] == 20.0
    result = shaken["shaken"][0]["result"]
    # the box planned for 20 kg needs about 217 N per finger; 20 N drops it
    assert result["object_mass"] == 20.0 and not shaken["shaken"][0]["held"]
