"""Bad input to the plant layer's public functions is a GraspError.

A fuzzer of the plant-side API found Drake's and Python's own errors escaping
(and one ``SystemExit`` from a Drake assertion), and answers computed
silently from contacts or bodies of another plant.
"""

from __future__ import annotations

import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

import drakegrasp as dg
from drakegrasp.plant.load import gravity_wrench


@pytest.fixture(scope="module")
def jaw():
    return dg.load_scene("parallel_jaw_box")


# -- add_models ------------------------------------------------------------


@pytest.fixture
def parser():
    # pydrake's Parser does not keep its plant alive: a Parser of a temporary
    # MultibodyPlant reads freed memory (a crash, or Drake asserting)
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    dg.register_models(parser)
    yield parser
    del parser, plant


@pytest.mark.parametrize(
    ("given", "words"),
    [
        ({"file_name": "/nonexistent/hand.urdf"}, "/nonexistent/hand.urdf"),
        ({"url": "package://nopkg/hand.sdf"}, "nopkg"),
        ({"text": "garbage", "kind": "urdf"}, "the model text"),
    ],
)
def test_add_models_refusals_are_model_errors(parser, given, words):
    with pytest.raises(dg.ModelError, match="cannot load") as e:
        dg.plant.add_models(parser, **given)
    assert words in str(e.value)


# -- the plane of a planar analysis ------------------------------------------


def test_gravity_wrench_refuses_a_bad_plane(jaw):
    with pytest.raises(dg.InvalidOptionError, match="plane must be one of"):
        gravity_wrench(jaw.plant, jaw.plant_context, jaw.object_body, plane="ab")
