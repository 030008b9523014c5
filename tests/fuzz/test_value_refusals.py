"""Values of the wrong kind that reached a function's work as a bare TypeError.

Each call fits its signature (so ``checked_call`` rightly passes it on); the
value itself is wrong, and must be refused with a GraspError naming it.
"""

from __future__ import annotations

import inspect

import pytest

import drakegrasp as dg
import drakegrasp.core.examples as examples
import drakegrasp.plant as dp
from drakegrasp.planning import scene_from_models

HOSTILE = [None, "1", -1.0, float("nan"), 1e400, [1, 2], 0.0, 1j, True, 10**9]


def _example_calls():
    for name in examples.__all__:
        signature = inspect.signature(getattr(examples, name))
        for parameter in signature.parameters:
            for value in HOSTILE:
                yield name, parameter, value


@pytest.mark.parametrize(("name", "parameter", "value"), list(_example_calls()))
def test_the_example_grasps_refuse_or_answer(name, parameter, value):
    function = getattr(examples, name)
    keywords = {
        p.name: (0.5 if p.name == "mu" else p.default)
        for p in inspect.signature(function).parameters.values()
        if p.default is not p.empty or p.name == "mu"
    }
    keywords[parameter] = value
    try:
        grasp = function(**keywords)
    except dg.GraspError as error:
        assert parameter in str(error) or "mu" in str(error), str(error)
    else:  # accepted: a grasp of the value given
        assert isinstance(grasp, dg.Grasp)


def test_a_thousand_and_one_fingers_are_refused_not_built():
    with pytest.raises(dg.InvalidGraspError, match=r"num_fingers .* \[1, 1000\]"):
        examples.equator_fingers(0.5, num_fingers=10**9)


@pytest.mark.parametrize("plant", [None, [], "plant"])
def test_plant_functions_refuse_what_is_not_a_plant(plant):
    with pytest.raises(dg.ModelError, match="plant must be a pydrake MultibodyPlant"):
        dp.plant_couplings(plant)
    with pytest.raises(dg.ModelError, match="plant must be a pydrake MultibodyPlant"):
        dp.hand_bodies(plant, None)


def test_hand_bodies_refuses_what_is_not_a_body():
    from pydrake.multibody.plant import MultibodyPlant

    plant = MultibodyPlant(0.0)
    plant.Finalize()
    with pytest.raises(dg.InvalidOptionError, match="object_body must be"):
        dp.hand_bodies(plant, [])


@pytest.mark.parametrize(
    ("recipe", "message"),
    [
        (None, "add_models must be a function"),
        (lambda plant, parser: None, "must return .hand model instance"),
        (lambda plant, parser: (None, 3), "scoped name 'model::body'"),
        (lambda plant, parser: (None, "nothing::here"), "no body named"),
    ],
)
def test_a_scene_recipe_that_returns_the_wrong_thing_is_named(recipe, message):
    with pytest.raises(dg.GraspError, match=message):
        scene_from_models(recipe)
