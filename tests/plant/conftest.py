"""Fixtures of the plant-layer tests: shipped scenes, loaded once per session."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from drakegrasp.plant.scene import list_scenes, load_scene

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:  # the test models (hand_models) are importable
    sys.path.insert(0, _HERE)

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


def stepped_context(scene, k: int, step: float):
    """:func:`fresh_context`, moved by ``step`` along generalized velocity ``k``."""
    plant = scene.plant
    root, ctx = fresh_context(scene)
    dv = np.zeros(plant.num_velocities())
    dv[k] = step
    plant.SetPositions(ctx, step_q(plant, ctx, dv))
    return root, ctx


def analyze_scene(scene, options=None):
    """``analyze_grasp`` of a loaded scene with its file's options (or ``options``)."""
    from drakegrasp import analyze_grasp

    return analyze_grasp(
        scene.plant,
        scene.plant_context,
        scene.object_body,
        hand=scene.hand,
        options=scene.options if options is None else options,
    )


def alias_bomb(tail: str) -> str:
    """YAML whose nested anchors expand to 12**8 strings of 100 bytes, then ``tail``."""
    lines = ['a0: &a0 ["' + "x" * 100 + '"]']
    for i in range(1, 9):
        prev = f"*a{i - 1}"
        lines.append(f"a{i}: &a{i} [{', '.join([prev] * 12)}]")
    return "\n".join(lines) + "\n" + tail


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
        fresh_context=fresh_context,
        step_q=step_q,
        stepped_context=stepped_context,
        make_plant=make_plant,
        analyze_scene=analyze_scene,
        alias_bomb=alias_bomb,
    )


# --- Real hands from drake_models (tests skip with a reason where it is absent) ---

WSG_URL = "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf"
ALLEGRO_URL = (
    "package://drake_models/allegro_hand_description/sdf/"
    "allegro_hand_description_right.sdf"
)
FRANKA_URL = "package://drake_models/franka_description/urdf/hand.urdf"


class RealScene:
    """A welded hand and a free object in a diagram; contexts ready to use."""

    def __init__(
        self, models_dir, hand_url, hand_frame, object_url, X_WO, *, edit=None
    ):
        from pydrake.multibody.parsing import Parser

        from drakegrasp.plant.models import register_models, use_local_drake_models

        builder, plant, self.scene_graph = make_plant()
        parser = Parser(plant)
        use_local_drake_models(parser, models_dir)
        register_models(parser)
        if edit is not None:  # a model file written by the test
            self.hand = parser.AddModels(str(edit))[0]
        else:
            self.hand = parser.AddModels(url=hand_url)[0]
        plant.WeldFrames(
            plant.world_frame(), plant.GetFrameByName(hand_frame, self.hand)
        )
        self.object_instance = parser.AddModels(url=object_url)[0]
        plant.Finalize()
        self.plant = plant
        self.diagram = builder.Build()
        self.root = self.diagram.CreateDefaultContext()
        self.ctx = plant.GetMyContextFromRoot(self.root)
        self.object = plant.get_body(plant.GetBodyIndices(self.object_instance)[0])
        plant.SetFreeBodyPose(self.ctx, self.object, X_WO)

    def set_hand(self, q):
        self.plant.SetPositions(self.ctx, self.hand, np.asarray(q, dtype=float))


def structure_of(scene):
    """The scene's hand structure computed anew, as a planner passes it."""
    from drakegrasp.plant.couplings import plant_couplings
    from drakegrasp.plant.fingers import hand_structure
    from drakegrasp.plant.validation import hand_bodies, query_object_of

    inspector = query_object_of(scene.plant, scene.ctx).inspector()
    return hand_structure(
        scene.plant, scene.object,
        hand_bodies(scene.plant, scene.object, scene.hand),
        plant_couplings(scene.plant), inspector=inspector,
    )  # fmt: skip


def _rt(R, p):
    from pydrake.math import RigidTransform, RotationMatrix

    return RigidTransform(RotationMatrix(np.array(R, dtype=float)), p)


@pytest.fixture
def real_hands(drake_models_dir):
    """Builders of real-hand scenes: the WSG-50, the Allegro hand, the Franka hand."""
    import types

    def wsg(
        object_url="package://drake_models/ycb/004_sugar_box.sdf", X_WO=None, q=0.05
    ):
        # Sugar box 39.1 mm thick between the pads (its z along the world x,
        # the fingers' motion), clear of the palm (which ends at y = 36 mm).
        X_WO = X_WO or _rt([[0, 0, 1], [1, 0, 0], [0, 1, 0]], [0, 0.09, 0])
        s = RealScene(drake_models_dir, WSG_URL, "body", object_url, X_WO)
        s.set_hand([-q, q])
        return s

    def allegro(p_ball=(0.08, 0.0, 0.1)):
        from pydrake.math import RigidTransform

        s = RealScene(
            drake_models_dir,
            ALLEGRO_URL,
            "hand_root",
            "package://drakegrasp/objects/sphere.sdf",
            RigidTransform(list(p_ball)),
        )
        s.plant.GetJointByName("joint_12").set_angle(s.ctx, 1.0)  # thumb opposed
        return s

    def franka(edit=None, y=0.005):
        from pydrake.math import RigidTransform

        s = RealScene(
            drake_models_dir,
            FRANKA_URL,
            "panda_hand",
            "package://drakegrasp/objects/box.sdf",
            RigidTransform([0.0, y, 0.135]),
            edit=edit,
        )
        s.set_hand([0.04, 0.04])
        return s

    return types.SimpleNamespace(wsg=wsg, allegro=allegro, franka=franka, rt=_rt)
