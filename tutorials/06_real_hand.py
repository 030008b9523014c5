# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.6
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # 06 · Real hands: close a WSG-50 and an Allegro hand on YCB objects
#
# The earlier tutorials used drakegrasp's own small hands.  Here the hands are
# Drake's: the Schunk WSG-50 parallel gripper and the 16-joint Allegro hand,
# with objects from the YCB benchmark, all from Drake's `drake_models` package.
# We
#
# 1. load them with an ordinary `Parser` (`dg.use_local_drake_models(parser)`
#    points `package://drake_models` at a local copy when the environment
#    variable `DRAKEGRASP_DRAKE_MODELS` names one, and does nothing otherwise, so
#    Drake downloads the package as usual);
# 2. bring the fingers onto the object with `dg.close_hand`;
# 3. analyse the grasp with `dg.analyze_grasp` and draw it in Meshcat;
# 4. see the pose checks refuse an impossible pose.

# %%
import os

import matplotlib.pyplot as plt
import numpy as np
from pydrake.geometry import Meshcat, MeshcatVisualizer
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

import drakegrasp as dg
from drakegrasp.visualization import draw_grasp

TEST_MODE = os.environ.get("DRAKEGRASP_TUTORIAL_TEST") == "1"
meshcat = Meshcat()
print("Meshcat:", meshcat.web_url())


# %% [markdown]
# ## A scene: a hand welded to the world and a free object
#
# One small function builds both scenes: the hand's base frame welded to the
# world, the object a free body at the pose `X_WO`, and a `MeshcatVisualizer`
# so that Meshcat shows the real meshes.  `package://drakegrasp/...` (our own
# objects) resolves after `dg.register_models(parser)`.


# %%
def build_scene(hand_url, base_frame, object_url, X_WO):
    """Diagram, plant, root context, hand instance and object body."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    parser = Parser(plant)
    dg.use_local_drake_models(parser)
    dg.register_models(parser)
    hand = parser.AddModels(url=hand_url)[0]
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(base_frame, hand))
    obj = parser.AddModels(url=object_url)[0]
    plant.Finalize()
    meshcat.Delete()
    MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat)
    diagram = builder.Build()
    root = diagram.CreateDefaultContext()
    body = plant.get_body(plant.GetBodyIndices(obj)[0])
    plant.SetFreeBodyPose(plant.GetMyContextFromRoot(root), body, X_WO)
    return diagram, plant, root, hand, body


# %% [markdown]
# ## The WSG-50 on the sugar box
#
# The WSG-50's fingers slide along the world $x$ axis.  The sugar box (YCB 004,
# 86.7 × 170.3 × 39.1 mm) stands between them with its thin side along $x$, and
# the fingers start wide open (±50 mm of their ±55 mm travel).  `close_hand`
# takes the plant and *either* context, the plant's or, as here, the root
# context of the diagram; it writes the closed hand into it.

# %%
wsg_url = "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf"
sugar_url = "package://drake_models/ycb/004_sugar_box.sdf"
X_WBox = RigidTransform(RollPitchYaw(np.radians([90, 0, 90])), [0, 0.09, 0])
diagram, plant, root, wsg, box = build_scene(wsg_url, "body", sugar_url, X_WBox)
context = plant.GetMyContextFromRoot(root)
plant.SetPositions(context, wsg, [-0.05, 0.05])  # the pre-shape: open

closure = dg.close_hand(plant, root, box, hand=wsg)
print(closure)

# %% [markdown]
# Each finger is the chain driven by one joint (here one prismatic joint each).
# `close_hand` moves each finger by safeguarded Newton steps on its signed
# distance ψ to the object until $0 \le ψ \le$ the distance tolerance (0.1 mm),
# with the slope $\partial ψ / \partial q$ from Drake's Jacobians.  Now the grasp:

# %%
report = dg.analyze_grasp(plant, root, box, hand=wsg, mu=0.5)
print(report)

# %% [markdown]
# Each pad carries four tip spheres, so each finger makes four point contacts:
# eight hard fingers, in force closure.  In Meshcat, `draw_grasp` draws the
# contact frames, the friction cones and the contact forces at the object's
# pose over Drake's own meshes.

# %%
diagram.ForcedPublish(root)
X_WO = plant.EvalBodyPoseInWorld(context, box)
drawing = draw_grasp(meshcat, report.grasp, X_WG=X_WO, result=report.force_closure)
print(len(drawing.paths), "objects drawn under", drawing.prefix)

# %% [markdown]
# ## Impossible poses are refused
#
# Push the box 20.6 mm into the gripper's palm (welded to the world) and the
# analysis refuses the pose instead of grading it, naming the body and the
# depth.  `check_pose=False` analyses it anyway and the report says it is
# invalid; the same holds for joints outside their limits (`JointLimitError`).

# %%
sunk = RigidTransform(X_WBox.rotation(), [0, 0.03625 + 0.04335 - 0.0206, 0])
plant.SetFreeBodyPose(context, box, sunk)
try:
    dg.analyze_grasp(plant, root, box, mu=0.5)
except dg.InvalidPoseError as e:
    print(type(e).__name__, ":", e)
anyway = dg.analyze_grasp(plant, root, box, mu=0.5, check_pose=False)
print(anyway.pose.summary())

# %% [markdown]
# ## The Allegro hand on the soup can
#
# The Allegro hand has four fingers of four revolute joints each.  Its palm
# faces $+x$ and its fingers point along $+z$; the soup can (YCB 005, a
# cylinder of radius 31.85 mm) stands in front of the palm, and the thumb is
# turned to oppose the fingers (`joint_12` = 1 rad).  By default each finger
# moves along the steepest descent of its fingertip's distance to the object,
# re-aimed at every step within the joint limits (a `direction=` vector over
# the 16 joints gives a fixed closing path, a synergy, instead).

# %%
allegro_url = (
    "package://drake_models/allegro_hand_description/sdf/"
    "allegro_hand_description_right.sdf"
)
can_url = "package://drake_models/ycb/005_tomato_soup_can.sdf"
X_WCan = RigidTransform(RollPitchYaw(np.radians([90, 0, 0])), [0.075, 0, 0.1])
diagram, plant, root, allegro, can = build_scene(
    allegro_url, "hand_root", can_url, X_WCan
)
context = plant.GetMyContextFromRoot(root)
plant.GetJointByName("joint_12", allegro).set_angle(context, 1.0)

closure = dg.close_hand(plant, root, can, hand=allegro)
print(closure)

# %%
report = dg.analyze_grasp(plant, root, can, hand=allegro, mu=0.5)
print(report)
print("J has", report.J.shape[1], "columns, one per hand velocity")

# %%
diagram.ForcedPublish(root)
X_WO = plant.EvalBodyPoseInWorld(context, can)
drawing = draw_grasp(
    meshcat, report.grasp, X_WG=X_WO, result=report.force_closure_exact
)
print(len(drawing.paths), "objects drawn under", drawing.prefix)

# %% [markdown]
# ## How much friction does this grasp need?
#
# The closed pose is fixed; only μ changes.  Below the friction the four
# fingertips need, the polyhedral program's $d^*$ drops to zero and the verdict
# turns to "no".

# %%
mus = np.linspace(0.02, 1.0, 8 if TEST_MODE else 50)
d_star = [
    dg.analyze_grasp(plant, root, can, hand=allegro, mu=mu).force_closure.d_star
    for mu in mus
]
closed = [
    dg.analyze_grasp(plant, root, can, hand=allegro, mu=mu).is_force_closure
    for mu in mus
]
plt.figure(figsize=(6, 3.5))
plt.plot(mus, d_star, "-", color="0.4")
plt.scatter(mus, d_star, c=["tab:green" if c else "tab:red" for c in closed], zorder=3)
plt.xlabel("friction coefficient μ")
plt.ylabel("LP2 d*")
plt.title("Allegro hand on the soup can (green: force closure)")
plt.tight_layout()
plt.show()

# %% [markdown]
# **What you learned.**  Real hands load with an ordinary `Parser`;
# `close_hand` brings every finger that can reach onto the object within its
# joint limits (and names the fingers that cannot); `analyze_grasp` takes the
# same plant and root context, refuses impossible poses, and its `J` has one
# column per hand joint.
