"""Fixtures of the plant-layer tests: shipped scenes, loaded once per session."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from drakegrasp.plant.scene import list_scenes, load_scene

SCENE_NAMES = [info.name for info in list_scenes()]
SPATIAL_SCENES = [n for n in SCENE_NAMES if not n.startswith("planar")]


@pytest.fixture(scope="session")
def scene_cache():
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = load_scene(name)
        return cache[name]

    return get


@pytest.fixture(params=SCENE_NAMES)
def any_scene(request, scene_cache):
    return scene_cache(request.param)


def fresh_context(scene):
    """A copy of the scene's root context and the plant context inside it."""
    root = scene.context.Clone()
    return root, scene.plant.GetMyContextFromRoot(root)


def step_q(plant, plant_context, dv: np.ndarray) -> np.ndarray:
    """q + N(q) dv: positions after moving by the generalized velocity dv."""
    q = plant.GetPositions(plant_context)
    qdot = plant.MapVelocityToQDot(plant_context, dv)
    return q + qdot


def make_plant():
    """An empty plant with a scene graph (time step 0)."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    return builder, plant, scene_graph


@pytest.fixture(scope="session")
def tools():
    """Helper functions for the tests (test modules cannot import conftest)."""
    import types

    return types.SimpleNamespace(
        fresh_context=fresh_context, step_q=step_q, make_plant=make_plant
    )
