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
# # 4. A hand from SDF: the hand Jacobian and LP3
#
# Force closure of the **grasp** says that contact forces exist to resist any
# wrench.  The **hand** must also be able to produce and change them with its
# joints.  The hand Jacobian $J$ maps joint velocities $\dot q_h$ to the velocities
# of the finger contact points in the contact frames (rows in the order of $G$'s
# columns); by duality the joint torques of contact forces $f$ are $\tau = J^T f$.
#
# An internal force ($G f = 0$) with $J^T f = 0$ loads the object and the hand but
# needs no torque: the joints can neither create nor change it.  The chapter's
# **LP3** looks for one with positive normal forces:
#
# $$
# \begin{aligned}
# d^* = \max_{f,\,d}\ d \quad\text{s.t.}\quad G f &= 0, & J^T f &= 0, &
# E f - \mathbf 1 d &\ge 0, & d &\ge 0, & \textstyle\sum_i f_{n,i} &\le N ,
# \end{aligned}
# $$
#
# and the hand controls every internal force when $d^* = 0$
# ($\mathcal N(G)\cap\mathcal N(J^T)$ holds no squeezing force).  Force closure
# with a hand needs frictional force closure **and** LP3 to pass.

# %%
import os

import matplotlib.pyplot as plt
import numpy as np

import drakegrasp as dg

# tests/tutorials sets this to run the notebook with short loops.
TEST_MODE = os.environ.get("DRAKEGRASP_TUTORIAL_TEST") == "1"
np.set_printoptions(precision=4, suppress=True, linewidth=110)

# %% [markdown]
# ## The three-finger hand
#
# `three_finger_sphere` loads our three-finger hand (SDF, three flexion joints per
# finger: proximal, middle, distal) holding a 35 mm sphere at its equator.

# %%
from drakegrasp.plant import analyze_grasp, load_scene

scene = load_scene("three_finger_sphere")
plant, context = scene.plant, scene.plant_context
report = analyze_grasp(plant, context, **scene.analysis_options())
print(report)
grasp, J = report.grasp, report.J
joints = {plant.get_joint(j).velocity_start(): plant.get_joint(j).name()
          for j in plant.GetJointIndices(scene.hand)
          if plant.get_joint(j).num_velocities() == 1}  # fmt: skip
joint_names = [joints[i] for i in report.data.hand_velocity_indices]
print("columns of J:", joint_names)

# %%
from pydrake.geometry import Meshcat

meshcat = Meshcat()
print("Meshcat:", meshcat.web_url())
scene_graph = scene.diagram.GetSubsystemByName("scene_graph")
dg.draw_scene_geometry(meshcat, scene_graph, scene.context, opacity=0.6)
from drakegrasp.visualization import draw_grasp

X_WO = plant.EvalBodyPoseInWorld(context, scene.object_body)
drawing = draw_grasp(meshcat, grasp, X_WG=X_WO, result=report.force_closure_exact)
print(len(drawing.paths), "objects drawn under", drawing.prefix)

# %% [markdown]
# $J$ is block diagonal: each finger's joints move only its own contact.  In each
# contact frame the rows are $[n, t_1, t_2]$.  The fingers flex in vertical planes
# through the centre, so the fingertips never move sideways: the row of the
# horizontal tangent is zero ($t_1$ of contact 0, $t_2$ of contacts 1 and 2, since
# $t_1$ is chosen from $n$ alone).

# %%
print("J (rows: n, t1, t2 per contact; columns: joints) =\n", J)
plt.figure(figsize=(6, 4.5))
plt.imshow(J, cmap="coolwarm", vmin=-0.12, vmax=0.12)
plt.yticks(range(9), [f"c{i} {r}" for i in range(3) for r in ("n", "t1", "t2")])
plt.xticks(range(9), [n.replace("_joint", "") for n in joint_names], rotation=60)
plt.colorbar(label="m/s per rad/s")
plt.title("hand Jacobian J")
plt.show()

# %% [markdown]
# ## LP3 with every joint, and with locked joints
#
# Locking joints removes columns of $J$.  With all nine joints LP3 passes; it still
# passes with only the distal joints, or with fingers 2 and 3 locked altogether:
# every internal force of this grasp needs $f_{n,1} > 0$, and finger 1's proximal
# joint pushes along $n_1$, so it feels every squeeze.

# %%
choices = {
    "all 9 joints": list(range(9)),
    "distal joints only": [2, 5, 8],
    "finger 1 proximal only": [0],
}
for name, cols in choices.items():
    lp3 = dg.internal_forces(grasp, J[:, cols])
    print(f"{name:24s} {lp3}")

# %% [markdown]
# ## A hand that cannot squeeze
#
# Real hands often drive several joints with one actuator (a tendon, a linkage):
# joint velocities $\dot q_h = S u$, so the actuators see the Jacobian $J S$.  Two
# couplings with one actuator per finger:
#
# * **curl**: all three joints of a finger together, $s = (1, 1, 1)$: the fingertip
#   moves towards the centre and along $n$;
# * **slide**: proximal and middle joints in the ratio that cancels the normal
#   velocity, $s \perp J_{n,i}$: the fingertip slides along the surface and never
#   pushes along $n$.
#
# With the sliding coupling the pure squeeze (equal normal forces, no friction) is
# internal and needs no actuator torque: $J^T f = 0$.  LP3 finds it ($d^* = 1$):
# the hand cannot squeeze the sphere, so the grasp is not in force closure **with
# this hand** even though it is in frictional force closure.

# %%
normal_rows = grasp.normal_indices()
S_curl = np.zeros((9, 3))
S_slide = np.zeros((9, 3))
for i in range(3):
    S_curl[3 * i : 3 * i + 3, i] = 1.0
    jn = J[normal_rows[i], 3 * i : 3 * i + 3]  # finger i's normal row
    s = np.array([jn[1], -jn[0], 0.0])  # proximal + middle, n-velocity = 0
    S_slide[3 * i : 3 * i + 3, i] = s / np.linalg.norm(s)

for name, S in (("curl", S_curl), ("slide", S_slide)):
    r = dg.force_closure(grasp, hand_jacobian=J @ S)
    print(f"--- {name} coupling: normal velocity of each fingertip per actuator =",
          np.round([(J @ S)[normal_rows[i], i] for i in range(3)], 4))  # fmt: skip
    print(r)

lp3 = dg.internal_forces(grasp, J @ S_slide)
f = np.concatenate(lp3.contact_forces)
print(
    "\nuncontrollable internal force (per contact [f_n, f_t1, f_t2]):",
    lp3.contact_forces,
)
print("G f =", dg.grasp_matrix(grasp) @ f, " (J S)^T f =", (J @ S_slide).T @ f)

# %% [markdown]
# **Picture.**  Finger 1 seen in its own plane (normal $n$ to the right, up is up):
# the velocity of the fingertip per unit rate of each joint and of each coupling.
# The sliding coupling moves the tip exactly along the surface; a force along $n$
# does no work on it, so its actuator cannot feel or change the squeeze.

# %%
c0 = grasp.contacts[0]
# Finger 1's fingertip velocities in the object frame, then along n and up (z).
V = c0.frame @ J[0:3, 0:3]  # columns: proximal, middle, distal
to_plane = np.vstack([c0.normal, [0.0, 0.0, 1.0]])
plt.figure(figsize=(5, 4.5))
for k, name in enumerate(("proximal", "middle", "distal")):
    plt.quiver(0, 0, *(to_plane @ V[:, k]), angles="xy", scale_units="xy", scale=1,
               color=f"C{k}", label=f"{name} joint")  # fmt: skip
for S, name, color in (
    (S_curl, "curl coupling", "k"),
    (S_slide, "slide coupling", "m"),
):
    v = to_plane @ V @ S[0:3, 0]
    plt.quiver(0, 0, *(4 * v), angles="xy", scale_units="xy", scale=1, color=color,
               width=0.012, label=f"{name} (x4)")  # fmt: skip
plt.axvline(0, color="0.5", lw=3, label="object surface")
plt.xlabel("velocity along n [m/s]")
plt.ylabel("velocity upwards (z) [m/s]")
plt.xlim(-0.05, 0.2)
plt.ylim(-0.08, 0.08)
plt.gca().set_aspect("equal")
plt.legend(fontsize=8)
plt.title("finger 1: fingertip velocity per unit joint/actuator rate")
plt.show()

# %%
# In Meshcat: the uncontrollable squeeze, drawn as forces on the object.
draw_grasp(meshcat, grasp, X_WG=X_WO, result=lp3, prefix="uncontrollable", cone=None)
meshcat.SetProperty(drawing.prefix, "visible", False)  # hide the first drawing
print("Open", meshcat.web_url(), "to see the hand and the squeeze it cannot control.")

# %% [markdown]
# **What you learned.**  The hand Jacobian $J$ from a plant (rows in contact-frame
# components, columns hand joints), the duality $\tau = J^T f$, and LP3: an internal
# force in $\mathcal N(G)\cap\mathcal N(J^T)$ with positive normals is a squeeze the
# joints cannot produce or change.  Locking joints is harmless here, but coupling the
# joints so that the fingertips slide along the surface makes the grasp uncontrollable
# although friction alone would hold the object.
