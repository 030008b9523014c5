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
# # 09 · Find grasps: sample, filter, close, rank, and check in simulation
#
# The earlier tutorials judged a grasp they were handed.  Here drakegrasp finds
# them: Drake's WSG-50 as a free-floating gripper and YCB objects from Drake's
# `drake_models`.  We
#
# 1. build a planning scene (the gripper's base a free body, placed by its
#    pose `X_WH`);
# 2. plan: `dg.plan_grasps` samples antipodal grasps on the object's collision
#    geometry, rejects poses that collide, closes the fingers with Drake's
#    distance queries and ranks the grasps;
# 3. look at the ranking: what the score is and why it is not ε;
# 4. check it against physics: `dg.shake_test` squeezes a grasp in a Drake
#    simulation and turns gravity around it.

# %%
import os

import matplotlib.pyplot as plt
import numpy as np
from pydrake.geometry import Meshcat, MeshcatVisualizer
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

import drakegrasp as dg

TEST_MODE = os.environ.get("DRAKEGRASP_TUTORIAL_TEST") == "1"
NUM = 300 if TEST_MODE else 1500
meshcat = Meshcat()
print("Meshcat:", meshcat.web_url())

# %% [markdown]
# ## A planning scene
#
# `dg.planning_scene` adds the gripper (its base left free) and the object to a
# new plant and keeps the recipe, `scene.add_models`, for the simulation later.
# With a scene of your own (a table, clutter), build the plant yourself: the
# planner needs only the plant, a context, the object body and the hand.

# %%
scene = dg.planning_scene("package://drake_models/ycb/004_sugar_box.sdf")
print(scene.plant.GetModelInstanceName(scene.hand), "and", scene.object_body.name())

# %% [markdown]
# ## Plan
#
# Every sampled pose becomes a candidate or is counted under one rejection
# reason.  The gripper's geometry (grasp axis, stroke, the four 1 mm tip spheres
# of each WSG finger as its pads, the approach direction) is read from the
# plant, not typed in.

# %%
result = dg.plan_grasps(
    scene.plant,
    scene.context,
    scene.object_body,
    hand=scene.hand,
    num_candidates=NUM,
    mu=0.5,
    seed=0,
)
print(result)
print(result.settings["gripper"])

# %% [markdown]
# Each candidate carries the hand pose `X_WH`, the closing joints' values
# `q_hand`, the contacts (the WSG's tip spheres: up to four per finger), the
# force-closure verdict with its certificate for the best ones, ε with **one**
# torque scale for the object, robustness and the score.

# %%
best = result[0]
print(best)
print(best.closure)

# %% [markdown]
# ## Why the score is not ε
#
# ε is the radius of the largest ball in the grasp's wrench set; for two pads
# its weakest direction is the torsion about the grasp axis, which is the same
# wherever the pads sit, so ε hardly changes from grasp to grasp.  What drops an
# object is its weight, acting at its centre of mass, in whatever direction the
# hand is turned.  The **weight capacity** is the weight a grasp holds per
# newton of squeeze on each finger in the worst of 14 directions; it falls as
# the pads move away from the centre of mass.  The score is the weight capacity
# times the robustness.

# %%
scored = [c for c in result if np.isfinite(c.weight_capacity)]
offset = [1e3 * np.linalg.norm(c.grasp.positions.mean(axis=0)) for c in scored]
fig, ax = plt.subplots(1, 2, figsize=(10, 3.5))
ax[0].scatter(offset, [c.epsilon for c in scored], s=8)
ax[0].set(xlabel="pads' centre from the centre of mass [mm]", ylabel="ε")
ax[1].scatter(offset, [c.weight_capacity for c in scored], s=8)
ax[1].set(xlabel="pads' centre from the centre of mass [mm]", ylabel="weight capacity")
plt.tight_layout()
plt.show()

# %% [markdown]
# ## See the best grasp
#
# `candidate.apply(plant, context)` puts the hand where the candidate says.

# %%
builder = DiagramBuilder()
plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
hand, name = scene.add_models(plant, Parser(plant))
plant.Finalize()
meshcat.Delete()
MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat)
diagram = builder.Build()
root = diagram.CreateDefaultContext()
best.apply(plant, root, object_body=plant.GetBodyByName(name.rpartition("::")[2]))
diagram.ForcedPublish(root)

# %% [markdown]
# ## Check against physics
#
# `dg.shake_test` welds the hand at `X_WH`, holds the fingers with Drake's
# PD-controlled actuators pressing with a set squeeze, lets the object free and
# turns gravity through six directions.  A light squeeze, 1.5 times the box's
# weight per finger, separates well-placed grasps from the others.

# %%
weight = scene.object_body.default_mass() * 9.81
squeeze = 1.5 * weight
kw = dict(settle=0.2, phase=0.3) if TEST_MODE else {}
print("best:", dg.shake_test(scene.add_models, best, squeeze=squeeze, **kw))
worst = scored[-1]
print("worst scored:", worst)
print("   ", dg.shake_test(scene.add_models, worst, squeeze=squeeze, **kw))

# %% [markdown]
# `benchmarks/bench_plan.py` runs this check on ten top and ten random
# candidates of several objects, at a light and a firm squeeze.
