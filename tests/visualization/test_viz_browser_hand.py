"""A grasp drawing stays visible on a real hand drawn by MeshcatVisualizer.

The hand's meshes hide what ``draw_grasp`` draws at the contacts: with
``side="outside"`` the cones and force arrows lie inside the fingers.  Headless
Chromium screenshots (see ``browser_support.py``) show that ``on_top=True``
draws them over the fingers, where the camera model puts the arrows, and that
:func:`set_translucent` on the hand's visualizer paths lets them be seen
through the fingers.  The shipped parallel-jaw gripper is always available;
Drake's WSG-50 (meshes) runs when ``drake_models`` is present.
"""

import numpy as np
from browser_support import (
    SKIP_WITHOUT_CHROMIUM,
    colour_mask,
    distance_to_segment,
    project,
    screenshot,
)
from pydrake.geometry import MeshcatVisualizer
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

import drakegrasp as dg
from drakegrasp.visualization import MESHCAT_COLORS, set_translucent, visualizer_paths

pytestmark = SKIP_WITHOUT_CHROMIUM

FORCE = MESHCAT_COLORS["force"]


def _scene(meshcat, url, *, drake_models=None, **joints):
    """Diagram with a MeshcatVisualizer; returns plant, scene graph, report."""
    meshcat.Delete()
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    parser = Parser(plant)
    dg.register_models(parser)
    if drake_models is not None:
        dg.use_local_drake_models(parser, drake_models)
    (hand,) = parser.AddModels(url=url)
    (box,) = parser.AddModels(url="package://drakegrasp/objects/box.sdf")
    palm = plant.get_body(plant.GetBodyIndices(hand)[0])
    plant.WeldFrames(plant.world_frame(), palm.body_frame())
    plant.Finalize()
    MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant_context = plant.GetMyMutableContextFromRoot(context)
    position = joints.pop("box_at")
    for name, q in joints.items():
        plant.GetJointByName(name, hand).set_translation(plant_context, q)
    body = plant.GetBodyByName("box", box)
    plant.SetFreeBodyPose(plant_context, body, RigidTransform(position))
    diagram.ForcedPublish(context)
    report = dg.analyze_grasp(
        plant,
        plant_context,
        object_body=body,
        hand=hand,
        mu=0.5,
        contact_model="soft_finger",
        torsional_friction=0.1,
    )
    assert report.is_force_closure
    X_WO = plant.EvalBodyPoseInWorld(plant_context, body)
    return plant, scene_graph, hand, report, X_WO


def _look(meshcat, report, X_WO, camera, target):
    """Point the camera at ``target``; the draw_grasp options that keep it there."""
    meshcat.SetCameraPose(camera, target)
    return {
        "X_WG": X_WO,
        "result": report.force_closure,
        "cone": "exact",
        "keep_camera": True,
    }


def _force_pixels(meshcat, tmp_path, name, *, expected=False):
    """The screenshot and its force-coloured pixels; ``expected``: the arrows
    are to be seen (a shot without any is taken again, as one taken before
    the arrows reached the page)."""
    img = screenshot(
        meshcat.web_url(),
        tmp_path / f"{name}.png",
        tmp_path / "prof",
        drawn=(lambda img: colour_mask(img, FORCE).any()) if expected else None,
    )
    return img, colour_mask(img, FORCE)


def _arrow_segments(drawing, report, X_WO, camera, target):
    segments = []
    for c, f in zip(report.grasp.positions, drawing.forces_G, strict=True):
        ends_O = np.array([c - drawing.force_scale * f, c])
        ends_W = np.array([X_WO.multiply(p) for p in ends_O])
        segments.append(project(ends_W, camera, target))
    return segments


def _hidden_then_on_top(
    meshcat, tmp_path, name, report, X_WO, camera, target, options, *, each=True
):
    """Draw plainly, then on top; the arrows on top are where the camera puts them.

    ``each``: also require pixels on every arrow (not where arrows overlap in
    the picture, as the WSG-50's four tips per finger do seen from the front).
    Returns the force-coloured pixels of the plain drawing.
    """
    dg.draw_grasp(meshcat, report.grasp, **options)
    _, plain = _force_pixels(meshcat, tmp_path, f"{name}_plain")
    drawing = dg.draw_grasp(meshcat, report.grasp, on_top=True, **options)
    _, on_top = _force_pixels(meshcat, tmp_path, f"{name}_on_top", expected=True)
    print(f"{name} force pixels: hidden {plain.sum()}, on top {on_top.sum()}")
    assert on_top.sum() > 2 * plain.sum() + 50
    segments = _arrow_segments(drawing, report, X_WO, camera, target)
    ys, xs = np.nonzero(on_top)
    pixels = np.column_stack([xs, ys]).astype(float)
    near = np.array([distance_to_segment(pixels, a, b) < 8.0 for a, b in segments])
    assert near.any(axis=0).mean() > 0.9
    assert not each or all(row.sum() >= 3 for row in near), "an arrow is hidden"
    return plain


def test_shipped_hand_on_top_and_translucent(meshcat, tmp_path):
    plant, scene_graph, hand, report, X_WO = _scene(
        meshcat,
        "package://drakegrasp/hands/parallel_jaw.sdf",
        left_finger_joint=0.025,
        right_finger_joint=0.025,
        box_at=[0.0, 0.0, 0.065],
    )
    camera, target = np.array([0.07, 0.0, 0.075]), np.array([0.0, 0.0, 0.055])
    options = _look(meshcat, report, X_WO, camera, target)

    hand_only, _ = _force_pixels(meshcat, tmp_path, "hand")
    assert colour_mask(hand_only, FORCE).sum() == 0
    plain = _hidden_then_on_top(
        meshcat, tmp_path, "parallel_jaw", report, X_WO, camera, target, options
    )

    # A translucent hand shows the (not on-top) drawing through the fingers.
    paths = visualizer_paths(plant, scene_graph, hand)
    assert paths and all(meshcat.HasPath(p) for p in paths)
    dg.draw_grasp(meshcat, report.grasp, **options)
    set_translucent(meshcat, paths, 0.25)
    _, seen_through = _force_pixels(meshcat, tmp_path, "translucent", expected=True)
    print(f"force pixels through a translucent hand: {seen_through.sum()}")
    assert seen_through.sum() > plain.sum() + 50
    set_translucent(meshcat, paths, 1.0)
    _, restored = _force_pixels(meshcat, tmp_path, "restored")
    assert abs(int(restored.sum()) - int(plain.sum())) <= 0.2 * plain.sum() + 20


def test_wsg50_meshes_do_not_hide_an_on_top_drawing(
    meshcat, tmp_path, drake_models_dir
):
    _, _, _, report, X_WO = _scene(
        meshcat,
        "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf",
        drake_models=drake_models_dir,
        left_finger_sliding_joint=-0.0225,
        right_finger_sliding_joint=0.0225,
        box_at=[0.0, 0.108, 0.0],
    )
    camera, target = np.array([0.0, 0.05, 0.07]), np.array([0.0, 0.108, 0.0])
    options = _look(meshcat, report, X_WO, camera, target)
    _hidden_then_on_top(
        meshcat, tmp_path, "wsg50", report, X_WO, camera, target, options, each=False
    )
