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
# # 1. Contacts, contact frames and the grasp matrix
#
# A grasp is a set of contacts on one object.  This notebook builds the **grasp
# matrix** $G$ that maps the contact forces to the wrench they exert on the object,
# for the three contact models of the chapter (frictionless, hard finger, soft
# finger), and then reads a grasp from a Drake `MultibodyPlant`, where the same
# matrix appears a second time: as the object part of $\partial\psi/\partial v$, the
# derivative of the signed distances.
#
# Conventions (the documentation's *Conventions* page, `docs/conventions.md`):
# normals point **into** the object, wrenches are $w = [f;\, m]$ with moments about a
# reference point $p$, contact forces are ordered normal component first.

# %%
import os

import matplotlib.pyplot as plt
import numpy as np

import drakegrasp as dg

# tests/tutorials sets this to run the notebook with short loops.
TEST_MODE = os.environ.get("DRAKEGRASP_TUTORIAL_TEST") == "1"
np.set_printoptions(precision=4, suppress=True, linewidth=110)

# %% [markdown]
# ## Contact frames
#
# Each contact $i$ has a point $c_i$ and an inward unit normal $n_i$.  Its contact
# frame is the rotation $R_i = [n_i,\ t_{1,i},\ t_{2,i}]$ (columns), right-handed,
# with $t_1$ chosen from $n$ alone (so equal normals give equal frames):
#
# $$
# \begin{aligned}
# R_i &= \begin{bmatrix} n_i & t_{1,i} & t_{2,i} \end{bmatrix}, &
# t_{2,i} &= n_i \times t_{1,i}, &
# R_i^T R_i &= I, \quad \det R_i = 1 .
# \end{aligned}
# $$
#
# In the plane $R_i = [n_i,\ t_i]$ with $t_i = (-n_y, n_x)$.

# %%
from drakegrasp import examples

grasp = examples.equator_fingers(0.5, num_fingers=3)  # 3 hard fingers, mu = 0.5
for i, c in enumerate(grasp.contacts):
    R = c.frame
    print(f"contact {i}: c = {c.position}, n = {c.normal}")
    print("  R =", R.tolist())
    orthonormal = np.allclose(R.T @ R, np.eye(3))
    print(f"  R^T R = I: {orthonormal}, det R = {np.linalg.det(R):+.3f}")

# %%
# Picture: the sphere, the contact points and their frames (n red, t1 green, t2 blue).
fig = plt.figure(figsize=(5, 5))
ax = fig.add_subplot(projection="3d")
u, v = np.mgrid[0 : 2 * np.pi : 30j, 0 : np.pi : 15j]
ax.plot_wireframe(
    np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v), color="0.8", lw=0.5
)
for c in grasp.contacts:
    for axis, color in zip(c.frame.T, "rgb", strict=True):
        ax.quiver(*c.position, *(0.6 * axis), color=color)
    ax.scatter(*c.position, color="k", s=30)
ax.set_box_aspect((1, 1, 1))
for set_ticks in (ax.set_xticks, ax.set_yticks, ax.set_zticks):
    set_ticks([-1, 0, 1])
ax.set(xlabel="x", ylabel="y", zlabel="z")
ax.set_title("contact frames $R = [n, t_1, t_2]$")
plt.show()

# %% [markdown]
# ## The grasp matrix
#
# A force $f_i$ given in contact frame $i$ is the force $R_i f_i$ in the grasp frame,
# applied at $c_i$; its wrench about $p$ is $[R_i f_i;\ (c_i-p)\times R_i f_i]$.
# With $S(a)$ the cross-product matrix ($S(a)\,b = a\times b$):
#
# $$
# \begin{aligned}
# G_i &= \begin{bmatrix} R_i \\ S(c_i - p)\, R_i \end{bmatrix}
# \quad\text{(columns of the model only)}, &
# w &= G f = \sum_i G_i f_i, \quad G = [G_1 \cdots G_N].
# \end{aligned}
# $$
#
# The **contact model** picks the columns:
#
# $$
# \begin{aligned}
# \text{frictionless:}\quad & f_i = [f_n], & G_i &= \begin{bmatrix} n_i \\ (c_i-p)\times n_i \end{bmatrix} \in \mathbb R^{6\times 1},\\
# \text{hard finger:}\quad & f_i = [f_n, f_{t1}, f_{t2}], & G_i &\in \mathbb R^{6\times 3},\\
# \text{soft finger:}\quad & f_i = [f_n, f_{t1}, f_{t2}, m_n], & G_i &= \begin{bmatrix} R_i & 0 \\ S(c_i-p) R_i & n_i \end{bmatrix} \in \mathbb R^{6\times 4}.
# \end{aligned}
# $$
#
# $G_n$ keeps only the normal column of every contact.

# %%
c = [0.1, 0.0, 0.05]  # metres
n = [-1.0, 0.0, 0.0]  # pushes towards -x, into the object
for model in ("frictionless", "hard_finger", "soft_finger"):
    one = dg.Grasp(
        [dg.Contact(c, n, mu=0.5, contact_model=model, torsional_friction=0.1)]
    )
    print(f"{model}: G_i is {dg.grasp_matrix(one).shape}")
    print(dg.grasp_matrix(one))

# %% [markdown]
# Check $G$ against the definition, computed independently: apply random contact
# forces, turn each into a grasp-frame force $R_i f_i$ at $c_i$ and sum forces and
# moments with `np.cross`.

# %%
rng = np.random.default_rng(0)
soft = examples.equator_fingers(
    0.5, num_fingers=3, contact_model="soft_finger", torsional_friction=0.2
)
for g in (grasp, soft, grasp.with_friction(contact_model="frictionless")):
    G = dg.grasp_matrix(g)
    f = rng.normal(size=G.shape[1])
    force, moment = np.zeros(3), np.zeros(3)
    for ci, sl in zip(g.contacts, g.component_slices(), strict=True):
        fi = f[sl]
        f_G = ci.frame[:, : min(len(fi), 3)] @ fi[:3]  # R_i f_i in the grasp frame
        force += f_G
        moment += np.cross(ci.position - g.reference_point, f_G)
        if len(fi) == 4:  # soft finger: pure moment about n
            moment += fi[3] * ci.normal
    print(
        f"{g.contacts[0].contact_model.value:>12}: G {G.shape}, "
        f"|G f - w| = {np.abs(G @ f - np.r_[force, moment]).max():.1e}"
    )

G = dg.grasp_matrix(grasp)
Gn = dg.normal_grasp_matrix(grasp)
print("G_n = the normal columns of G:", np.allclose(Gn, G[:, grasp.normal_indices()]))

# %% [markdown]
# **Reference point.**  Moving $p$ to $p'$ changes only the moment rows:
# $G(p') = \begin{bmatrix} I & 0 \\ S(p-p') & I\end{bmatrix} G(p)$.

# %%
p2 = np.array([0.2, -0.1, 0.3])
moved = dg.Grasp(grasp.contacts, reference_point=p2)
S = np.array([[0, -p2[2], p2[1]], [p2[2], 0, -p2[0]], [-p2[1], p2[0], 0]])
T = np.block([[np.eye(3), np.zeros((3, 3))], [-S, np.eye(3)]])  # p - p' = -p2
print("G(p') = T G(p):", np.allclose(dg.grasp_matrix(moved), T @ G))

# %% [markdown]
# **Planar grasps** have 2-D contacts and 3-row wrenches $[f_x, f_y, m_z]$.  The
# picture shows a planar two-finger grasp: normals (arrows) and the exact friction
# cones (wedges of half-angle $\arctan\mu$).

# %%
from drakegrasp.visualization import plot_planar_grasp

planar = examples.planar_two_finger_square(0.6)
print("planar G =\n", dg.grasp_matrix(planar))
square = [[-1, -1], [1, -1], [1, 1], [-1, 1]]
plot_planar_grasp(planar, outline=square)
plt.title("planar grasp: contacts, normals, friction cones")
plt.show()

# %% [markdown]
# ## From a plant: $\psi$ and $\partial\psi/\partial v$
#
# `load_scene` builds a shipped scene, here the parallel-jaw gripper with rounded
# pads holding a box; we turn the box by $15^\circ$ about the vertical axis and close
# the jaws onto it (notebook 5 derives the joint value), so that the object frame is
# not the world frame.  `grasp_from_plant` reads the contacts with Drake's
# signed-distance queries: $\psi_i > 0$ separation, $=0$ contact, $<0$ penetration;
# a pair is a contact when $|\psi_i| \le 10^{-4}$ m.  Positions and normals are
# expressed in the object body frame $O$, with moments about $O$'s origin.

# %%
from pydrake.math import RigidTransform, RotationMatrix

from drakegrasp.plant import grasp_from_plant, load_scene

scene = load_scene("parallel_jaw_box")
plant, context, body = scene.plant, scene.plant_context, scene.object_body
theta = np.radians(15.0)
p_WO = plant.EvalBodyPoseInWorld(context, body).translation()
plant.SetFreeBodyPose(
    context, body, RigidTransform(RotationMatrix.MakeZRotation(theta), p_WO)
)
for joint in ("left_finger_joint", "right_finger_joint"):
    plant.GetJointByName(joint).set_translation(context, 0.031 / np.cos(theta) - 0.006)
data = grasp_from_plant(plant, context, object_body=body, hand=scene.hand, mu=0.5)
for pc in data.contacts:
    print(pc)
print("psi [m] =", data.psi)
print("dpsi/dv:", data.dpsi_dv.shape, "(contacts x plant velocities)")

# %% [markdown]
# With $Ca$ the object's witness point and $Cb$ the finger's,
# $\dot\psi_i = n_i^T (v_{Ca} - v_{Cb}) = \frac{\partial\psi_i}{\partial v}\, v$,
# with $v$ the plant's generalized velocities.  A floating object has 7 positions
# (quaternion + translation) but 6 velocities, so Drake differentiates with respect
# to $v$ (`JacobianWrtVariable.kV`), and $\dot\psi = \frac{\partial\psi}{\partial q}
# \dot q$ with $\dot q = N(q)\, v$.
#
# **The object columns equal $G_n^T$.**  Let the object move with the spatial
# velocity $\xi = [v_p;\ \omega]$ about $p$ (the origin of $O$), expressed in $O$.
# The witness point moves with $v_{Ca} = v_p + \omega\times(c_i - p)$, hence
#
# $$
# \begin{aligned}
# \dot\psi_i &= n_i^T v_p + n_i^T\big(\omega \times (c_i-p)\big)
# = \begin{bmatrix} n_i \\ (c_i - p)\times n_i \end{bmatrix}^T
# \begin{bmatrix} v_p \\ \omega \end{bmatrix}
# \quad\Rightarrow\quad
# \frac{\partial \psi}{\partial \xi} = G_n^T .
# \end{aligned}
# $$
#
# Drake's floating-body velocities are ordered the other way and expressed in the
# world: $v_{obj} = [\omega_W;\ v_{O,W}] = T\,\xi$ with
# $T = \begin{bmatrix} 0 & R_{WO} \\ R_{WO} & 0 \end{bmatrix}$, so the check is
# $\frac{\partial\psi}{\partial v_{obj}}\, T = G_n^T$.  (If $p$ were not the body
# origin, $v_O = v_p + \omega\times(O - p)$ would add a shift.)

# %%
start = body.floating_velocities_start_in_v()  # the object's 6 columns of v
R_WO = plant.EvalBodyPoseInWorld(context, body).rotation().matrix()
T = np.zeros((6, 6))
T[:3, 3:] = R_WO  # omega_W = R_WO omega_O
T[3:, :3] = R_WO  # v_W = R_WO v_p
dpsi_dxi = data.dpsi_dv[:, start : start + 6] @ T
Gn = dg.normal_grasp_matrix(data.grasp)
print("dpsi/dxi =\n", dpsi_dxi)
print("max |dpsi/dxi - G_n^T| =", np.abs(dpsi_dxi - Gn.T).max())

# %% [markdown]
# An independent route: **finite differences**.  Move the object by $\pm\epsilon$
# along each basis twist (a translation along an axis of $O$, or a rotation about an
# axis of $O$ through $p$), read the contacts again and difference $\psi$.

# %%
X_WO = plant.EvalBodyPoseInWorld(context, body)
eps = 1e-6
rotations = (RotationMatrix.MakeXRotation, RotationMatrix.MakeYRotation,
             RotationMatrix.MakeZRotation)  # fmt: skip


def psi_after(k, step):
    if k < 3:
        X_OOp = RigidTransform(np.eye(3)[k] * step)
    else:
        X_OOp = RigidTransform(rotations[k - 3](step), np.zeros(3))
    plant.SetFreeBodyPose(context, body, X_WO @ X_OOp)
    moved = grasp_from_plant(plant, context, object_body=body, hand=scene.hand, mu=0.5)
    return moved.psi


fd = np.column_stack(
    [(psi_after(k, eps) - psi_after(k, -eps)) / (2 * eps) for k in range(6)]
)
plant.SetFreeBodyPose(context, body, X_WO)  # restore
print("max |finite differences - G_n^T| =", np.abs(fd - Gn.T).max())

# Rotation columns are in metres per radian: divide them by b to compare shapes.
b = data.grasp.characteristic_length
scale = np.r_[1, 1, 1, 1 / b, 1 / b, 1 / b]
fig, axes = plt.subplots(1, 3, figsize=(11, 2.6))
for ax, M, title in zip(
    axes,
    (Gn.T * scale, dpsi_dxi * scale, fd * scale),
    (
        "$G_n^T$",
        "Drake: $\\partial\\psi/\\partial v_{obj}$ times $T$",
        "finite differences",
    ),
    strict=True,
):
    im = ax.imshow(M, cmap="coolwarm", vmin=-1, vmax=1)
    ax.set_title(title)
    ax.set_xticks(
        range(6),
        ["$v_x$", "$v_y$", "$v_z$", "$b\\omega_x$", "$b\\omega_y$", "$b\\omega_z$"],
    )
    ax.set_yticks(range(Gn.shape[1]))
axes[0].set_ylabel("contact")
fig.colorbar(im, ax=axes, shrink=0.8)
plt.show()

# %% [markdown]
# The hand columns of $\partial\psi/\partial v$ carry the same information as the
# normal rows of the hand Jacobian $J$ (finger-point velocities in the contact
# frames): a finger moving along $n_i$ closes the gap, so
# $\partial\psi_i/\partial v_{hand} = -\,n_i^T J_{v,Cb} = -J_{n,i}$.

# %%
hand = data.hand_velocity_indices
J_normal_rows = data.hand_jacobian[data.grasp.normal_indices()]
print("J:", data.hand_jacobian.shape, " hand velocities:", hand.tolist())
print("max |dpsi/dv_hand + J_n| =", np.abs(data.dpsi_dv[:, hand] + J_normal_rows).max())

# %% [markdown]
# **What you learned.**  A contact frame per contact, the grasp matrix
# $G = [G_1 \cdots G_N]$ whose columns depend on the contact model, and the identity
# $\partial\psi/\partial\xi = G_n^T$: the first-order change of the signed
# distances under an object twist is the transpose of the normal grasp matrix.
# Notebook 2 uses exactly this to define form closure.
