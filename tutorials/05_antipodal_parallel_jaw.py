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
# # 5. Antipodal grasps with a parallel-jaw gripper
#
# Two contacts hold an object by squeezing along the line between them.  The pair is
# **antipodal** when that line lies inside both friction cones:
#
# $$
# \begin{aligned}
# \angle\big(c_2 - c_1,\ n_1\big) &\le \arctan\mu, &
# \angle\big(c_1 - c_2,\ n_2\big) &\le \arctan\mu,
# \end{aligned}
# $$
#
# so the smallest friction that makes the pair antipodal is
# $\mu_{\min} = \tan\max_i \angle_i$.  For two **soft** fingers (point contacts that
# also resist a moment about the normal) an antipodal pair with the line strictly
# inside the cones is in force closure; two **hard** fingers never are (nothing
# resists a rotation about the line: $\operatorname{rank} G = 5$).

# %%
import os

import matplotlib.pyplot as plt
import numpy as np

import drakegrasp as dg

# tests/tutorials sets this to run the notebook with short loops.
TEST_MODE = os.environ.get("DRAKEGRASP_TUTORIAL_TEST") == "1"
np.set_printoptions(precision=4, suppress=True, linewidth=110)

# %% [markdown]
# ## The gripper and a tilted box
#
# `parallel_jaw_box` holds a $50\times50\times100$ mm box between two jaws with
# hemispherical pads (radius $r = 6$ mm) that close along $y$.  We turn the box by
# $\theta$ about the vertical axis and close each jaw until its pad touches the
# face: the face is $25$ mm from the centre, so the pad's centre must be
# $25 + 6$ mm from the face plane, $q = 0.031/\cos\theta - 0.006$ (the joint value is
# the distance from the palm's mid-plane to the pad tip).

# %%
from pydrake.math import RigidTransform, RotationMatrix

from drakegrasp.plant import grasp_from_plant, load_scene

scene = load_scene("parallel_jaw_box")
plant, context, box = scene.plant, scene.plant_context, scene.object_body
p_box = plant.EvalBodyPoseInWorld(context, box).translation()


def tilt_box(theta):
    """Turn the box by theta about z and close both jaws onto it."""
    plant.SetFreeBodyPose(
        context, box, RigidTransform(RotationMatrix.MakeZRotation(theta), p_box)
    )
    q = 0.031 / np.cos(theta) - 0.006
    for name in ("left_finger_joint", "right_finger_joint"):
        plant.GetJointByName(name).set_translation(context, q)


def read_grasp(mu, contact_model="soft_finger"):
    nu = 0.1 if contact_model == "soft_finger" else None
    data = grasp_from_plant(plant, context, object_body=box, hand=scene.hand, mu=mu,
                            contact_model=contact_model, torsional_friction=nu)  # fmt: skip
    return data


theta = np.radians(20.0)
tilt_box(theta)
data = read_grasp(0.5)
for pc in data.contacts:
    print(pc)
print("psi [m]:", data.psi, "(both pads touch)")

# %% [markdown]
# ## The antipodal check and the friction it needs
#
# The pads are round, so each contact point sits $r\sin\theta$ off the jaw axis
# along the face: the line between the contacts is steeper than the jaw axis.  In
# the box frame the contact is $s = 0.031\tan\theta$ along the face from its centre
# and $25$ mm out, so the angle is $\arctan(s / 0.025)$ and
# $\mu_{\min} = 1.24\tan\theta$, more than the $\tan\theta$ of the jaw axis alone.

# %%
antipodal = dg.is_antipodal(data.grasp)
print(antipodal)
print(f"predicted mu_min = 1.24 tan(theta) = {1.24 * np.tan(theta):.4f}")
print(f"tan(theta) alone would say          {np.tan(theta):.4f}")

# %% [markdown]
# ## A sweep of $\mu$
#
# For each $\mu$: the antipodal margins $\arctan\mu - \angle_i$ (positive inside the
# cone), the exact-cone force closure of two soft fingers (its $d^*$), and the same
# grasp with hard fingers.  The soft-finger verdict switches on where the margins
# cross zero, at $\mu_{\min}$; the hard-finger grasp never closes.

# %%
mus = np.linspace(0.2, 0.8, 13 if TEST_MODE else 61)
margins, d_soft, fc_soft, fc_hard = [], [], [], []
for mu in mus:
    soft = read_grasp(mu).grasp
    margins.append(np.degrees(dg.is_antipodal(soft).margins))
    r = dg.force_closure_exact(soft)
    d_soft.append(r.d_star)
    fc_soft.append(r.is_closure)
    fc_hard.append(
        dg.force_closure_exact(
            soft.with_friction(contact_model="hard_finger")
        ).is_closure
    )
margins = np.array(margins)

fig = plt.figure(figsize=(11, 4.2))
grid = fig.add_gridspec(2, 2, height_ratios=[3, 1], hspace=0.08, wspace=0.3)
ax0 = fig.add_subplot(grid[:, 0])
ax1 = fig.add_subplot(grid[0, 1])
strip = fig.add_subplot(grid[1, 1], sharex=ax1)
ax0.plot(mus, margins[:, 0], "o-", label="margin of contact 0")
ax0.plot(mus, margins[:, 1], "x--", label="margin of contact 1")
ax0.axhline(0, color="k", lw=0.5)
ax0.axvline(antipodal.min_mu, color="C3", ls=":", label="$\\mu_{min}$")
ax0.set_xlabel("$\\mu$")
ax0.set_ylabel("antipodal margin [deg]")
ax0.legend()
ax1.plot(mus, d_soft, "o-", label="$d^*$, soft fingers (exact cones)")
ax1.axvline(antipodal.min_mu, color="C3", ls=":", label="$\\mu_{min}$")
ax1.set_ylabel("$d^*$")
ax1.legend(fontsize=8, loc="upper left")
ax1.tick_params(labelbottom=False)
# The verdicts in a strip of their own: one row per contact model.
for row, verdict in enumerate((fc_hard, fc_soft)):
    verdict = np.array(verdict)
    strip.plot(mus[verdict], np.full(verdict.sum(), row), "s", color="C2",
               label="force closure" if row else None)  # fmt: skip
    strip.plot(mus[~verdict], np.full((~verdict).sum(), row), "x", color="C3",
               label="no" if row else None)  # fmt: skip
strip.axvline(antipodal.min_mu, color="C3", ls=":")
strip.set_yticks([0, 1], ["hard", "soft"])
strip.set_ylim(-0.6, 1.6)
strip.set_xlabel("$\\mu$")
strip.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5))
plt.show()

first = mus[np.argmax(fc_soft)]
print(f"soft fingers: first mu in closure {first:.3f}; mu_min = {antipodal.min_mu:.4f}")
print("hard fingers: any closure?", any(fc_hard))
assert all(
    f == (m > 0).all()
    for f, m in zip(fc_soft, margins, strict=True)
    if abs(m).min() > 0.1
)

# %% [markdown]
# The friction needed grows with the tilt: $\mu_{\min}(\theta) = 1.24\tan\theta$ for
# these pads, read back from the plant for each $\theta$.

# %%
thetas = np.radians(np.linspace(0, 35, 8 if TEST_MODE else 36))
needed = []
for th in thetas:
    tilt_box(th)
    needed.append(dg.is_antipodal(read_grasp(0.5).grasp).min_mu)
plt.figure(figsize=(5, 3.5))
plt.plot(np.degrees(thetas), needed, "o", label="is_antipodal(...).min_mu")
plt.plot(np.degrees(thetas), 1.24 * np.tan(thetas), "k-", label="$1.24\\tan\\theta$")
plt.plot(np.degrees(thetas), np.tan(thetas), "k:", label="$\\tan\\theta$ (jaw axis)")
plt.xlabel("box rotation $\\theta$ [deg]")
plt.ylabel("friction needed")
plt.legend()
plt.show()
print(
    "max |min_mu - 1.24 tan(theta)| =",
    np.abs(np.array(needed) - 1.24 * np.tan(thetas)).max(),
)

# %% [markdown]
# ## In Meshcat
#
# Meshcat serves on localhost; it needs no browser to accept drawings (open the URL
# to look).  The scene's shapes are sent to it, then `draw_grasp` adds the contact
# points, contact frames ($n$ red, $t_1$ green, $t_2$ blue), the exact friction
# cones and the exact program's contact forces, at the object's pose $X_{WO}$.  With
# $\mu = 0.5 > \mu_{\min}$ the line between the pads lies inside both cones.

# %%
from drakegrasp.visualization import draw_grasp

tilt_box(np.radians(20.0))
from pydrake.geometry import Meshcat

meshcat = Meshcat()
print("Meshcat:", meshcat.web_url())
scene_graph = scene.diagram.GetSubsystemByName("scene_graph")
dg.draw_scene_geometry(meshcat, scene_graph, scene.context, opacity=0.5)
soft = read_grasp(0.5).grasp
result = dg.force_closure_exact(soft)
print(result)
drawing = draw_grasp(meshcat, soft, X_WG=plant.EvalBodyPoseInWorld(context, box),
                     result=result, cone="both")  # fmt: skip
print(f"drawn {len(drawing.paths)} objects under {drawing.prefix!r}; "
      f"cone height {1e3 * drawing.cone_height:.1f} mm")  # fmt: skip

# %% [markdown]
# **What you learned.**  The antipodal test compares the line between two contacts
# with their friction cones; `min_mu` is the friction a pair needs, which for round
# pads is more than the jaw axis suggests; sweeping $\mu$ shows the antipodal margins
# and the soft-finger force-closure verdict switching at the same $\mu_{\min}$, while
# two hard fingers never reach force closure.
