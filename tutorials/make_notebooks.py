"""Write the tutorial notebooks from the cell sources below (outputs cleared).

Run ``python tutorials/make_notebooks.py`` after editing a cell; the notebooks are
generated files, this script is their source (then ``ruff format`` formats their
code cells, when ruff is installed).  Each notebook reads
``DRAKEGRASP_TUTORIAL_TEST=1`` (set by ``tests/tutorials``) to shorten its loops.
"""

# ruff: noqa: E501  (cell sources: Markdown and LaTeX lines are as long as they need)

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import nbformat

HERE = Path(__file__).resolve().parent

KERNELSPEC = {"display_name": "Python 3", "language": "python", "name": "python3"}


def md(text: str) -> nbformat.NotebookNode:
    return nbformat.v4.new_markdown_cell(text.strip("\n"))


def code(text: str) -> nbformat.NotebookNode:
    return nbformat.v4.new_code_cell(text.strip("\n"))


SETUP = """
import os

import matplotlib.pyplot as plt
import numpy as np

import drakegrasp as dg

# tests/tutorials sets this to run the notebook with short loops.
TEST_MODE = os.environ.get("DRAKEGRASP_TUTORIAL_TEST") == "1"
np.set_printoptions(precision=4, suppress=True, linewidth=110)
"""

# Draws the illustration geometry of a loaded scene in Meshcat.  A scene's
# diagram is built without a visualizer, so the shapes are sent one by one.
SCENE_TO_MESHCAT = '''
from pydrake.geometry import Meshcat, Rgba, Role


def draw_scene(meshcat, scene, *, prefix="scene", alpha=None):
    """Send every illustration shape of ``scene`` to Meshcat at its world pose."""
    scene_graph = scene.diagram.GetSubsystemByName("scene_graph")
    query = scene_graph.get_query_output_port().Eval(
        scene_graph.GetMyContextFromRoot(scene.context)
    )
    inspector = query.inspector()
    for gid in inspector.GetAllGeometryIds(Role.kIllustration):
        props = inspector.GetIllustrationProperties(gid)
        rgba = props.GetPropertyOrDefault("phong", "diffuse", Rgba(0.7, 0.7, 0.7))
        if alpha is not None:
            rgba = Rgba(rgba.r(), rgba.g(), rgba.b(), alpha)
        path = f"{prefix}/{gid.get_value()}"
        meshcat.SetObject(path, inspector.GetShape(gid), rgba)
        meshcat.SetTransform(path, query.GetPoseInWorld(gid))
'''


# --------------------------------------------------------------------------- 01


def notebook_01() -> list:
    return [
        md(r"""
# 1. Contacts, contact frames and the grasp matrix

A grasp is a set of contacts on one object.  This notebook builds the **grasp
matrix** $G$ that maps the contact forces to the wrench they exert on the object,
for the three contact models of the chapter (frictionless, hard finger, soft
finger), and then reads a grasp from a Drake `MultibodyPlant`, where the same
matrix appears a second time: as the object part of $\partial\psi/\partial v$, the
derivative of the signed distances.

Conventions (`shared/CONVENTIONS.md`): normals point **into** the object, wrenches
are $w = [f;\, m]$ with moments about a reference point $p$, contact forces are
ordered normal component first.
"""),
        code(SETUP),
        md(r"""
## Contact frames

Each contact $i$ has a point $c_i$ and an inward unit normal $n_i$.  Its contact
frame is the rotation $R_i = [n_i,\ t_{1,i},\ t_{2,i}]$ (columns), right-handed,
with $t_1$ chosen from $n$ alone (so equal normals give equal frames):

$$
\begin{aligned}
R_i &= \begin{bmatrix} n_i & t_{1,i} & t_{2,i} \end{bmatrix}, &
t_{2,i} &= n_i \times t_{1,i}, &
R_i^T R_i &= I, \quad \det R_i = 1 .
\end{aligned}
$$

In the plane $R_i = [n_i,\ t_i]$ with $t_i = (-n_y, n_x)$.
"""),
        code("""
from drakegrasp import examples

grasp = examples.equator_fingers(0.5, num_fingers=3)  # 3 hard fingers, mu = 0.5
for i, c in enumerate(grasp.contacts):
    R = c.frame
    print(f"contact {i}: c = {c.position}, n = {c.normal}")
    print("  R =", R.tolist())
    orthonormal = np.allclose(R.T @ R, np.eye(3))
    print(f"  R^T R = I: {orthonormal}, det R = {np.linalg.det(R):+.3f}")
"""),
        code("""
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
ax.set_title("contact frames R = [n, t1, t2]")
plt.show()
"""),
        md(r"""
## The grasp matrix

A force $f_i$ given in contact frame $i$ is the force $R_i f_i$ in the grasp frame,
applied at $c_i$; its wrench about $p$ is $[R_i f_i;\ (c_i-p)\times R_i f_i]$.
With $S(a)$ the cross-product matrix ($S(a)\,b = a\times b$):

$$
\begin{aligned}
G_i &= \begin{bmatrix} R_i \\ S(c_i - p)\, R_i \end{bmatrix}
\quad\text{(columns of the model only)}, &
w &= G f = \sum_i G_i f_i, \quad G = [G_1 \cdots G_N].
\end{aligned}
$$

The **contact model** picks the columns:

$$
\begin{aligned}
\text{frictionless:}\quad & f_i = [f_n], & G_i &= \begin{bmatrix} n_i \\ (c_i-p)\times n_i \end{bmatrix} \in \mathbb R^{6\times 1},\\
\text{hard finger:}\quad & f_i = [f_n, f_{t1}, f_{t2}], & G_i &\in \mathbb R^{6\times 3},\\
\text{soft finger:}\quad & f_i = [f_n, f_{t1}, f_{t2}, m_n], & G_i &= \begin{bmatrix} R_i & 0 \\ S(c_i-p) R_i & n_i \end{bmatrix} \in \mathbb R^{6\times 4}.
\end{aligned}
$$

$G_n$ keeps only the normal column of every contact.
"""),
        code("""
c = [0.1, 0.0, 0.05]  # metres
n = [-1.0, 0.0, 0.0]  # pushes towards -x, into the object
for model in ("frictionless", "hard_finger", "soft_finger"):
    one = dg.Grasp([dg.Contact(c, n, mu=0.5, model=model, torsional_friction=0.1)])
    print(f"{model}: G_i is {dg.grasp_matrix(one).shape}")
    print(dg.grasp_matrix(one))
"""),
        md(r"""
Check $G$ against the definition, computed independently: apply random contact
forces, turn each into a grasp-frame force $R_i f_i$ at $c_i$ and sum forces and
moments with `np.cross`.
"""),
        code("""
rng = np.random.default_rng(0)
soft = examples.equator_fingers(
    0.5, num_fingers=3, model="soft_finger", torsional_friction=0.2
)
for g in (grasp, soft, grasp.with_friction(model="frictionless")):
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
        f"{g.contacts[0].model.value:>12}: G {G.shape}, "
        f"|G f - w| = {np.abs(G @ f - np.r_[force, moment]).max():.1e}"
    )

G = dg.grasp_matrix(grasp)
Gn = dg.normal_grasp_matrix(grasp)
print("G_n = the normal columns of G:", np.allclose(Gn, G[:, grasp.normal_indices()]))
"""),
        md(r"""
**Reference point.**  Moving $p$ to $p'$ changes only the moment rows:
$G(p') = \begin{bmatrix} I & 0 \\ S(p-p') & I\end{bmatrix} G(p)$.
"""),
        code("""
p2 = np.array([0.2, -0.1, 0.3])
moved = dg.Grasp(grasp.contacts, reference_point=p2)
S = np.array([[0, -p2[2], p2[1]], [p2[2], 0, -p2[0]], [-p2[1], p2[0], 0]])
T = np.block([[np.eye(3), np.zeros((3, 3))], [-S, np.eye(3)]])  # p - p' = -p2
print("G(p') = T G(p):", np.allclose(dg.grasp_matrix(moved), T @ G))
"""),
        md(r"""
**Planar grasps** have 2-D contacts and 3-row wrenches $[f_x, f_y, m_z]$.  The
picture shows a planar two-finger grasp: normals (arrows) and the exact friction
cones (wedges of half-angle $\arctan\mu$).
"""),
        code("""
from drakegrasp.visualization import plot_planar_grasp

planar = examples.planar_two_finger_square(0.6)
print("planar G =\\n", dg.grasp_matrix(planar))
square = [[-1, -1], [1, -1], [1, 1], [-1, 1]]
plot_planar_grasp(planar, outline=square)
plt.title("planar grasp: contacts, normals, friction cones")
plt.show()
"""),
        md(r"""
## From a plant: $\psi$ and $\partial\psi/\partial v$

`load_scene` builds a shipped scene, here the parallel-jaw gripper with rounded
pads holding a box; we turn the box by $15^\circ$ about the vertical axis and close
the jaws onto it (notebook 5 derives the joint value), so that the object frame is
not the world frame.  `grasp_from_plant` reads the contacts with Drake's
signed-distance queries: $\psi_i > 0$ separation, $=0$ contact, $<0$ penetration;
a pair is a contact when $|\psi_i| \le 10^{-4}$ m.  Positions and normals are
expressed in the object body frame $O$, with moments about $O$'s origin.
"""),
        code("""
from pydrake.math import RigidTransform, RotationMatrix

from drakegrasp.plant import grasp_from_plant, load_scene

scene = load_scene("parallel_jaw_box")
plant, context, body = scene.plant, scene.plant_context, scene.object_body
theta = np.radians(15.0)
p_WO = plant.EvalBodyPoseInWorld(context, body).translation()
plant.SetFreeBodyPose(context, body, RigidTransform(RotationMatrix.MakeZRotation(theta), p_WO))
for joint in ("left_finger_joint", "right_finger_joint"):
    plant.GetJointByName(joint).set_translation(context, 0.031 / np.cos(theta) - 0.006)
data = grasp_from_plant(plant, context, object_body=body, hand=scene.hand, mu=0.5)
for pc in data.contacts:
    print(pc)
print("psi [m] =", data.psi)
print("dpsi/dv:", data.dpsi_dv.shape, "(contacts x plant velocities)")
"""),
        md(r"""
With $Ca$ the object's witness point and $Cb$ the finger's,
$\dot\psi_i = n_i^T (v_{Ca} - v_{Cb}) = \frac{\partial\psi_i}{\partial v}\, v$,
with $v$ the plant's generalized velocities.  A floating object has 7 positions
(quaternion + translation) but 6 velocities, so Drake differentiates with respect
to $v$ (`JacobianWrtVariable.kV`), and $\dot\psi = \frac{\partial\psi}{\partial q}
\dot q$ with $\dot q = N(q)\, v$.

**The object columns equal $G_n^T$.**  Let the object move with the spatial
velocity $\xi = [v_p;\ \omega]$ about $p$ (the origin of $O$), expressed in $O$.
The witness point moves with $v_{Ca} = v_p + \omega\times(c_i - p)$, hence

$$
\begin{aligned}
\dot\psi_i &= n_i^T v_p + n_i^T\big(\omega \times (c_i-p)\big)
= \begin{bmatrix} n_i \\ (c_i - p)\times n_i \end{bmatrix}^T
\begin{bmatrix} v_p \\ \omega \end{bmatrix}
\quad\Rightarrow\quad
\frac{\partial \psi}{\partial \xi} = G_n^T .
\end{aligned}
$$

Drake's floating-body velocities are ordered the other way and expressed in the
world: $v_{obj} = [\omega_W;\ v_{O,W}] = T\,\xi$ with
$T = \begin{bmatrix} 0 & R_{WO} \\ R_{WO} & 0 \end{bmatrix}$, so the check is
$\frac{\partial\psi}{\partial v_{obj}}\, T = G_n^T$.  (If $p$ were not the body
origin, $v_O = v_p + \omega\times(O - p)$ would add a shift.)
"""),
        code("""
start = body.floating_velocities_start_in_v()  # the object's 6 columns of v
R_WO = plant.EvalBodyPoseInWorld(context, body).rotation().matrix()
T = np.zeros((6, 6))
T[:3, 3:] = R_WO  # omega_W = R_WO omega_O
T[3:, :3] = R_WO  # v_W = R_WO v_p
dpsi_dxi = data.dpsi_dv[:, start : start + 6] @ T
Gn = dg.normal_grasp_matrix(data.grasp)
print("dpsi/dxi =\\n", dpsi_dxi)
print("max |dpsi/dxi - G_n^T| =", np.abs(dpsi_dxi - Gn.T).max())
"""),
        md(r"""
An independent route: **finite differences**.  Move the object by $\pm\epsilon$
along each basis twist (a translation along an axis of $O$, or a rotation about an
axis of $O$ through $p$), read the contacts again and difference $\psi$.
"""),
        code("""
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
fig, axes = plt.subplots(1, 3, figsize=(10, 2.6))
for ax, M, title in zip(
    axes, (Gn.T * scale, dpsi_dxi * scale, fd * scale), ("$G_n^T$", "Drake $\\\\partial\\\\psi/\\\\partial v\\\\;T$", "finite differences"),
    strict=True,
):
    im = ax.imshow(M, cmap="coolwarm", vmin=-1, vmax=1)
    ax.set_title(title)
    ax.set_xticks(range(6), ["$v_x$", "$v_y$", "$v_z$", "$b\\\\omega_x$", "$b\\\\omega_y$", "$b\\\\omega_z$"])
    ax.set_yticks(range(Gn.shape[1]))
fig.colorbar(im, ax=axes, shrink=0.8)
plt.show()
"""),
        md(r"""
The hand columns of $\partial\psi/\partial v$ carry the same information as the
normal rows of the hand Jacobian $J$ (finger-point velocities in the contact
frames): a finger moving along $n_i$ closes the gap, so
$\partial\psi_i/\partial v_{hand} = -\,n_i^T J_{v,Cb} = -J_{n,i}$.
"""),
        code("""
hand = data.hand_velocity_indices
J_normal_rows = data.hand_jacobian[data.grasp.normal_indices()]
print("J:", data.hand_jacobian.shape, " hand velocities:", hand.tolist())
print("max |dpsi/dv_hand + J_n| =", np.abs(data.dpsi_dv[:, hand] + J_normal_rows).max())
"""),
        md(r"""
**What you learned.**  A contact frame per contact, the grasp matrix
$G = [G_1 \cdots G_N]$ whose columns depend on the contact model, and the identity
$\partial\psi/\partial\xi = G_n^T$: the first-order change of the signed
distances under an object twist is the transpose of the normal grasp matrix.
Notebook 2 uses exactly this to define form closure.
"""),
    ]


# --------------------------------------------------------------------------- 02


def notebook_02() -> list:
    return [
        md(r"""
# 2. Form closure

A grasp is in **form closure** when the contacts alone, without friction,
immobilise the object: every object motion makes some contact penetrate.  With
$\xi$ an object twist, first order says $\dot\psi = G_n^T \xi$, so

$$
\begin{aligned}
\text{first-order form closure}\iff\; & G_n^T\xi \ge 0 \Rightarrow \xi = 0
\iff \operatorname{rank} G_n = 6\ (3 \text{ planar}) \ \text{ and }\ \exists f_n > 0:\ G_n f_n = 0 .
\end{aligned}
$$

The second condition is decided by **LP1**:

$$
\begin{aligned}
d^* = \max_{f_n,\,d}\ d \quad \text{s.t.}\quad G_n f_n &= 0, & f_n - \mathbf 1 d &\ge 0,
& d &\ge 0, & \mathbf 1^T f_n &\le N ,
\end{aligned}
$$

and first-order form closure holds iff $\operatorname{rank} G_n$ is full and
$d^* > \text{tol}$.
"""),
        code(SETUP),
        code("""
from drakegrasp import examples
from drakegrasp.visualization import plot_planar_grasp

SQUARE = [[-1, -1], [1, -1], [1, 1], [-1, 1]]
"""),
        md(r"""
## First order: four contacts on a square

`examples.planar_square_four_contacts` puts two contacts on the left/right faces at
heights $\pm h/2$ and two on the top/bottom faces.  LP1's optimal $f_n$ is a set of
normal forces that balance with every force at least $d^*$.
"""),
        code("""
square4 = examples.planar_square_four_contacts()
result = dg.form_closure(square4)
print(result)
print("optimal f_n:", np.concatenate(result.contact_forces))
print("G_n f_n =", dg.normal_grasp_matrix(square4) @ np.concatenate(result.contact_forces))
plot_planar_grasp(square4, outline=SQUARE, result=result)
plt.title("first-order form closure (arrows: LP1's f_n)")
plt.show()
"""),
        md(r"""
**What $d^*$ says.**  $d^*$ is the smallest normal force of the best balancing set,
with the budget $\sum f_n \le N$.  Slide the top contact to the left, from
$x=+h/2$ towards $-h/2$: the moment it balances shrinks, the left/right pair must
carry less, and at $x_4 = -h/2$ their forces reach zero: $d^* \to 0$ and form
closure is lost (the four normals no longer resist a rotation).
"""),
        code("""
def square_with_top_at(x4):
    c = square4.contacts
    return square4.with_contacts([*c[:3], c[3].with_(position=[x4, 1.0])])


xs = np.linspace(0.5, -0.7, 13 if TEST_MODE else 49)
runs = [dg.form_closure(square_with_top_at(x)) for x in xs]
fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(10, 3.8))
ax0.plot(xs, [r.d_star for r in runs], "o-")
ax0.plot(xs, [r.is_closure for r in runs], "k:", label="verdict (1 = closure)")
ax0.set_xlabel("x of the top contact")
ax0.set_ylabel("$d^*$ of LP1")
ax0.invert_xaxis()
ax0.legend()
plot_planar_grasp(
    square_with_top_at(-0.25), ax=ax1, outline=SQUARE,
    result=dg.form_closure(square_with_top_at(-0.25)),
)  # fmt: skip
ax1.set_title("x4 = -0.25: the left/right pair carries less")
plt.show()
for x, r in zip(xs[::4], runs[::4], strict=True):
    f = np.concatenate(r.contact_forces)
    print(f"x4 = {x:+.2f}: closure {r.is_closure!s:5}, d* = {r.d_star:.3f}, f_n = {f}")
"""),
        md(r"""
## Rank matters as much as $d^*$: first order can be inconclusive

Put four contacts at the ends of the axes of an **ellipse** (semi-axes $a > b$).
All four normals pass through the centre, so no normal force makes a moment:
$\operatorname{rank} G_n = 2 < 3$, and the rotation $\xi = (0, 0, 1)$ satisfies
$G_n^T\xi = 0$.  LP1 still finds balancing normal forces ($d^* > 0$), but the
first-order test fails: to first order the object can rotate.
"""),
        code("""
a, b = 1.5, 1.0
frictionless = dict(model="frictionless")
ellipse4 = dg.Grasp(
    [
        dg.Contact([a, 0], [-1, 0], **frictionless),
        dg.Contact([-a, 0], [1, 0], **frictionless),
        dg.Contact([0, b], [0, -1], **frictionless),
        dg.Contact([0, -b], [0, 1], **frictionless),
    ]
)
r_ellipse = dg.form_closure(ellipse4)
print(r_ellipse)
xi = np.array([0.0, 0.0, 1.0])
print("G_n^T xi for a rotation:", dg.normal_grasp_matrix(ellipse4).T @ xi)
"""),
        md(r"""
**Second order decides.**  Whether the rotation is possible depends on the
curvature of the object relative to the fingers.  Rotate the ellipse by $\phi$
about its centre with the (point) fingers fixed: along the minor axis the ellipse
gets *wider* (its radius towards a fixed finger on the minor axis grows like
$b\,(1 + \frac{a^2-b^2}{2a^2}\phi^2)$), so the top and bottom fingers penetrate,
$\psi \approx -\frac{b\,(a^2-b^2)}{2a^2}\,\phi^2 < 0$, whatever the sign of
$\phi$.  The rotation is
blocked at second order: **second-order form closure**.  A **disc** with the same
four contacts is the counterexample: rotating it changes no distance
($\psi \equiv 0$), so it is in **no form closure** of any order.

The signed distances below are computed from the geometry, independently of
drakegrasp.
"""),
        code("""
from scipy.optimize import minimize_scalar

t = np.linspace(0, 2 * np.pi, 2001)


def psi_point_to_ellipse(point, phi, a, b):
    \"\"\"Signed distance of a fixed point to the ellipse rotated by phi (< 0 inside).\"\"\"
    c, s = np.cos(-phi), np.sin(-phi)
    x, y = c * point[0] - s * point[1], s * point[0] + c * point[1]  # in body frame
    dist = lambda u: np.hypot(a * np.cos(u) - x, b * np.sin(u) - y)  # noqa: E731
    u0 = t[np.argmin(dist(t))]  # coarse search, then refine the parameter
    step = t[1] - t[0]
    best = minimize_scalar(dist, bounds=(u0 - step, u0 + step), method="bounded",
                           options={"xatol": 1e-12}).fun  # fmt: skip
    return -best if (x / a) ** 2 + (y / b) ** 2 < 1 else best


phis = np.linspace(-0.3, 0.3, 31 if TEST_MODE else 61)
fingers = ellipse4.positions
fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
for ax, (name, semi) in zip(axes[:2], (("ellipse", (a, b)), ("disc", (1.0, 1.0))), strict=True):
    pts = fingers if name == "ellipse" else fingers / np.abs(fingers).max(axis=1, keepdims=True)
    for i, finger in enumerate(pts):
        ax.plot(phis, [psi_point_to_ellipse(finger, p, *semi) for p in phis], label=f"contact {i}")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("rotation $\\\\phi$ [rad]")
    ax.set_ylabel("$\\\\psi_i$")
    ax.set_title(f"{name}: rotating about the centre")
    ax.legend(fontsize=8)
phi_demo = 0.25
outline = np.c_[a * np.cos(t[::200]), b * np.sin(t[::200])]
rot = np.array([[np.cos(phi_demo), -np.sin(phi_demo)], [np.sin(phi_demo), np.cos(phi_demo)]])
axes[2].fill(*outline.T, alpha=0.2, label="ellipse")
axes[2].fill(*(outline @ rot.T).T, alpha=0.2, label=f"rotated by {phi_demo} rad")
axes[2].scatter(*fingers.T, color="k", zorder=3, label="fingers")
axes[2].set_aspect("equal")
axes[2].legend(fontsize=8, loc="lower left")
axes[2].set_title("rotated: it runs into fingers 2, 3")
plt.show()
print("predicted -psi/phi^2 = b (a^2 - b^2) / (2 a^2) =", b * (a**2 - b**2) / (2 * a**2))
print("measured -psi/phi^2 at phi = 0.01 (top finger):",
      -psi_point_to_ellipse(fingers[2], 0.01, a, b) / 0.01**2)  # fmt: skip
"""),
        md(r"""
So the three cases of the chapter, side by side:

| grasp | rank $G_n$ | LP1 $d^*$ | verdict |
|---|---|---|---|
| square, 4 contacts | 3 | $> 0$ | first-order form closure |
| ellipse, 4 contacts on the axes | 2 | $> 0$ | first order inconclusive; **second-order** form closure (curvature) |
| disc, 4 contacts | 2 | $> 0$ | **no** form closure (rotation is free) |

drakegrasp decides first order; the second-order analysis above is done by hand.

## Somov's counts: 4 contacts in the plane, 7 in space

A frictionless contact gives one column of $G_n$.  With $k$ contacts and wrench
dimension $m$ (3 or 6), $G_n f_n = 0$ with $f_n>0$ and $\operatorname{rank} G_n = m$
need a null space of dimension $k - m \ge 1$: at least $m+1$ contacts, **4 in the
plane and 7 in space**.  An experiment: random frictionless contacts on a square
(or cube), every count tested many times.
"""),
        code("""
rng = np.random.default_rng(1)
samples = 40 if TEST_MODE else 400


def random_square_contacts(k):
    side = rng.integers(4, size=k)
    s = rng.uniform(-1, 1, size=k)
    normals = np.array([[-1, 0], [1, 0], [0, -1], [0, 1]])[side]
    positions = -normals + s[:, None] * normals[:, ::-1]
    return dg.Grasp([dg.Contact(p, n, **frictionless) for p, n in zip(positions, normals, strict=True)])


def random_cube_contacts(k):
    face = rng.integers(6, size=k)
    axis, sign = face // 2, np.where(face % 2 == 0, 1.0, -1.0)
    positions = rng.uniform(-1, 1, size=(k, 3))
    positions[np.arange(k), axis] = sign
    normals = np.zeros((k, 3))
    normals[np.arange(k), axis] = -sign
    return dg.Grasp([dg.Contact(p, n, **frictionless) for p, n in zip(positions, normals, strict=True)])


rates = {}
for label, make, counts in (
    ("plane (square)", random_square_contacts, range(2, 8)),
    ("space (cube)", random_cube_contacts, range(5, 13)),
):
    rates[label] = {
        k: np.mean([dg.form_closure(make(k)).is_closure for _ in range(samples)])
        for k in counts
    }
    print(label, {k: f"{100 * r:.1f}%" for k, r in rates[label].items()})

fig, axes = plt.subplots(1, 2, figsize=(10, 3.5))
for ax, (label, r), m in zip(axes, rates.items(), (3, 6), strict=True):
    ax.bar(list(r), [100 * x for x in r.values()], color=["C3" if k <= m else "C0" for k in r])
    ax.axvline(m + 0.5, color="k", ls="--", lw=1)
    ax.set_xlabel("number of random frictionless contacts")
    ax.set_ylabel("% in first-order form closure")
    ax.set_title(f"{label}: none with <= {m} contacts")
plt.show()
assert all(rates["plane (square)"][k] == 0 for k in (2, 3))
assert all(rates["space (cube)"][k] == 0 for k in (5, 6))
"""),
        md(r"""
Random sets at the bound pass rarely (seven random contacts on a cube almost never:
they would need one on every face and moment balance besides), but careful
placements reach it exactly: four contacts in the plane, seven in space.  For the cube, $G_n$ is $6\times 7$ with rank 6 and a one-dimensional null
space spanned by a strictly positive vector; drop any contact and closure is lost.
"""),
        code("""
for g in (examples.planar_square_four_contacts(), examples.cube_seven_contacts()):
    r = dg.form_closure(g)
    drop_one = [
        dg.form_closure(g.with_contacts(g.contacts[:i] + g.contacts[i + 1 :])).is_closure
        for i in range(g.num_contacts)
    ]
    null = np.linalg.svd(dg.normal_grasp_matrix(g))[2][-1]
    print(f"{g}: closure {r.is_closure}, rank {r.rank}, d* = {r.d_star:.3f}")
    print("   null space of G_n (sign-normalised):", null * np.sign(null.sum()))
    print("   closure after dropping one contact:", drop_one)
"""),
        md(r"""
**What you learned.**  First-order form closure needs both a full-rank $G_n$ and
LP1's $d^*>0$ (balancing normal forces, all strictly positive); $d^*$ shrinks to 0
as a grasp approaches the boundary and LP1's $f_n$ shows how the load is shared;
when the rank test fails, curvature can still immobilise the object (second
order) or not (the disc); and no fewer than 4 (plane) or 7 (space) frictionless
contacts can give form closure.
"""),
    ]


# --------------------------------------------------------------------------- 03


def notebook_03() -> list:
    return [
        md(r"""
# 3. Friction and force closure

With friction a contact can push in any direction of its **friction cone**, so
fewer contacts can resist every wrench.  A grasp is in **frictional force
closure** when internal forces inside the cones exist that balance, strictly
inside:

$$
\begin{aligned}
\operatorname{rank} G = 6\ (3\text{ planar}) \quad\text{and}\quad
\exists f:\ G f = 0,\ f_i \in \operatorname{int}\mathcal F_i ,
\end{aligned}
$$

with the cones of the three models ($b$: the grasp's characteristic length,
$\nu$: torsional friction):

$$
\begin{aligned}
\text{frictionless:}\ & f_n \ge 0, \qquad
\text{hard finger:}\ \ \|f_t\| \le \mu f_n, \qquad
\text{soft finger:}\ \ \frac{\|f_t\|}{\mu} + \frac{|m_n|}{b\nu} \le f_n .
\end{aligned}
$$
"""),
        code(SETUP),
        code("""
from drakegrasp import examples
from drakegrasp.visualization import plot_planar_grasp, plot_wrench_space

SQUARE = [[-1, -1], [1, -1], [1, 1], [-1, 1]]
"""),
        md(r"""
## Frictionless, hard and soft fingers

Three fingers on a sphere's equator, all pushing to the centre: without friction
the normals meet at the centre and no moment can be resisted (rank 3); with
friction the tangential forces add moments and the rank becomes 6.  Two fingers
squeezing a box never resist a moment about the line between them with hard
fingers (rank 5); soft fingers add exactly that moment.
"""),
        code("""
cases = {
    "3 frictionless (equator)": examples.equator_fingers(0.5, model="frictionless"),
    "3 hard fingers, mu=0.5": examples.equator_fingers(0.5),
    "2 hard fingers, mu=0.5": examples.spatial_two_fingers(0.5),
    "2 soft fingers, mu=0.5, nu=0.2": examples.spatial_two_fingers(
        0.5, model="soft_finger", torsional_friction=0.2
    ),
}
for name, g in cases.items():
    r = dg.force_closure(g)
    verdict = "FORCE CLOSURE" if r.is_closure else "no"
    shape = dg.grasp_matrix(g).shape
    print(f"{name:32s} G {shape}, rank {r.rank}, d* = {r.d_star:.4f} -> {verdict}")
"""),
        md(r"""
## LP2 and the linearised cone

A Coulomb cone is round; an LP needs flat faces.  drakegrasp inscribes a pyramid
with $n_g$ generators $s_k = [1,\ \mu\cos\frac{2\pi k}{n_g},\ \mu\sin\frac{2\pi
k}{n_g}]$ and writes it as facets $F_i f_i \ge 0$ (rows of unit length).  **LP2**:

$$
\begin{aligned}
d^* = \max_{f,\,d}\ d \quad\text{s.t.}\quad G f &= 0, & F f - \mathbf 1 d &\ge 0,
& d &\ge 0, & \textstyle\sum_i f_{n,i} &\le N ,
\end{aligned}
$$

so $d$ is the distance of the contact forces to the nearest facet.  The **exact**
program (`force_closure_exact`) replaces each pyramid by its Lorentz cone
$\|f_t\| \le \mu f_n - \sqrt{1+\mu^2}\,d$ (an SOCP, solved by Clarabel): $d$ is
then the distance to the round cone.  The pyramid is inscribed, so
$d^*_{LP2} \le d^*_{exact}$: a polyhedral "yes" is always a true "yes".

The facet of an inscribed $n_g$-gon lies at $\cos(\pi/n_g)$ of the circle's
radius, so the error of the linearisation falls like $1-\cos(\pi/n_g)\approx
\frac{\pi^2}{2 n_g^2}$.
"""),
        code("""
equator = examples.equator_fingers(0.5)
exact = dg.force_closure_exact(equator)
n_gs = np.arange(3, 17 if TEST_MODE else 65)
lp2 = np.array([dg.force_closure(equator, num_generators=n).d_star for n in n_gs])
print(f"exact d* = {exact.d_star:.5f} ({exact.solver}); LP2 d* for n_g = 4, 8, 16:",
      lp2[np.searchsorted(n_gs, [4, 8, 16])])  # fmt: skip
assert np.all(lp2 <= exact.d_star + 1e-6)

fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11, 3.8))
ax0.plot(n_gs, lp2, "o-", label="LP2 (pyramid, $n_g$ generators)")
ax0.axhline(exact.d_star, color="k", ls="--", label="exact cone (SOCP)")
ax0.set_xlabel("$n_g$")
ax0.set_ylabel("$d^*$")
ax0.legend()
ax1.loglog(n_gs, (exact.d_star - lp2) / exact.d_star, "o", label="relative error of LP2")
ax1.loglog(n_gs, np.pi**2 / (2 * n_gs**2), "k:", label="$\\\\pi^2 / (2 n_g^2)$")
ax1.set_xlabel("$n_g$")
ax1.legend()
ax1.set_title("the error falls like $1/n_g^2$")
plt.show()
"""),
        md(r"""
The error matters for the **verdict** near the boundary.  Two soft fingers squeeze
a box along $x$, offset from each other so that the line between them leaves the
normals at an angle $\alpha$ (rotated by $20^\circ$ about the normal, between the
pyramid's edges).  The exact cone needs $\mu > \tan\alpha$; a pyramid with $n_g$
generators needs a bit more, and the gap closes as $n_g$ grows.  Bisection on
$\mu$ finds the critical friction of each model.
"""),
        code("""
alpha, beta = np.radians(25.0), np.radians(20.0)
offset = np.tan(alpha) * np.array([0.0, np.cos(beta), np.sin(beta)])


def offset_grasp(mu):
    return dg.Grasp(
        [
            dg.Contact(np.r_[-1.0, 0, 0] - offset, [1, 0, 0], mu=mu,
                       model="soft_finger", torsional_friction=0.2),
            dg.Contact(np.r_[1.0, 0, 0] + offset, [-1, 0, 0], mu=mu,
                       model="soft_finger", torsional_friction=0.2),
        ]
    )  # fmt: skip


def critical_mu(decide, lo=0.0, hi=2.0, steps=20 if TEST_MODE else 40):
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if decide(offset_grasp(mid)).is_closure else (mid, hi)
    return hi


mu_exact = critical_mu(dg.force_closure_exact)
n_gs_verdict = [3, 4, 6, 8, 12, 16] if TEST_MODE else [3, 4, 5, 6, 8, 10, 12, 16, 24, 32]
mu_poly = [
    critical_mu(lambda g, n=n: dg.force_closure(g, num_generators=n)) for n in n_gs_verdict
]
print(f"tan(alpha) = {np.tan(alpha):.4f}, exact cone: mu* = {mu_exact:.4f}")
for n, m in zip(n_gs_verdict, mu_poly, strict=True):
    print(f"  n_g = {n:2d}: mu* = {m:.4f}")
plt.figure(figsize=(5, 3.5))
plt.plot(n_gs_verdict, mu_poly, "o-", label="pyramid (LP2)")
plt.axhline(mu_exact, color="k", ls="--", label="exact cone (SOCP)")
plt.xlabel("$n_g$")
plt.ylabel("smallest $\\\\mu$ giving force closure")
plt.legend()
plt.show()
"""),
        md(r"""
## Wrench cones of one, two and four fingers

In the plane, the cones are exact (two edges each).  Each edge $s$ of contact $i$
gives a **primitive wrench** $G_i s$; the grasp can resist every wrench exactly
when the origin lies strictly inside the convex hull of the primitive wrenches
(moments divided by $b$ so the axes are comparable).  `plot_wrench_space` draws
the primitive wrenches (coloured by contact), their hull and the origin (green
inside, red outside).
"""),
        code("""
grasps = {
    "one finger": dg.Grasp([dg.Contact([-1.0, 0.0], [1.0, 0.0], mu=0.5)]),
    "two fingers, mu=0.3": examples.planar_two_finger_square(0.3),
    "two fingers, mu=0.7": examples.planar_two_finger_square(0.7),
    "four fingers, mu=0.2": examples.planar_square_four_contacts().with_friction(
        0.2, model="hard_finger"
    ),
}
fig = plt.figure(figsize=(16, 7.5))
for k, (name, g) in enumerate(grasps.items()):
    plot_planar_grasp(g, ax=fig.add_subplot(2, 4, k + 1), outline=SQUARE)
    plt.title(name)
    ax = fig.add_subplot(2, 4, k + 5, projection="3d")
    picture = plot_wrench_space(g, ax=ax)
    fc = dg.force_closure(g)
    ax.set_title(f"origin inside: {picture.origin_inside}; LP2: {fc.is_closure}")
    assert picture.origin_inside == fc.is_closure
plt.tight_layout()
plt.show()
"""),
        md(r"""
The two-finger grasp needs $\mu > 1/2$ (the line between the fingers makes
$\arctan\frac12$ with the normals): at $\mu=0.3$ the hull misses the origin, at
$\mu=0.7$ it contains it.  One finger can never surround the origin; four fingers
with little friction can.

## LP2 and the exact cone side by side

Both programs return optimal contact forces (contact frames, normal first).  For
the planar grasp they agree: planar cones are exact polyhedra.  For the spatial
soft-finger pair above, both balance with $|f_t|/f_n = \tan\alpha$ (the squeeze
along the line between the contacts), but the round cone leaves that force farther
from its boundary than the pyramid does, so the SOCP's $d^*$ is larger.
"""),
        code("""
two = examples.planar_two_finger_square(0.7)
r_lp2, r_exact = dg.force_closure(two), dg.force_closure_exact(two)
print(r_lp2, "\\n", r_exact, sep="")
print("LP2 forces:  ", [f.round(4) for f in r_lp2.contact_forces])
print("exact forces:", [f.round(4) for f in r_exact.contact_forces])

fig, axes = plt.subplots(1, 2, figsize=(10, 4))
for ax, r, name in zip(axes, (r_lp2, r_exact), ("LP2", "exact cone"), strict=True):
    plot_planar_grasp(two, ax=ax, outline=SQUARE, result=r)
    ax.set_title(f"{name}: d* = {r.d_star:.4f}")
plt.show()

spatial = offset_grasp(0.6)  # the soft-finger pair from above, mu = 0.6
print(f"spatial, soft fingers, mu = 0.6 (tan(alpha) = {np.tan(alpha):.3f}):")
for r in (dg.force_closure(spatial), dg.force_closure_exact(spatial)):
    ft = [np.linalg.norm(f[1:3]) / f[0] for f in r.contact_forces]
    ratios = np.round(ft, 4)
    print(f"{r.formulation:>7}: d* = {r.d_star:.5f}, |f_t| / f_n per contact = {ratios}")
"""),
        md(r"""
**What you learned.**  Friction turns each contact's single column into a cone of
wrenches; hard fingers need rank 6 from friction, soft fingers add the moment about
the normal; LP2 decides force closure on inscribed pyramids, never wrongly saying
"yes", with an error in $d^*$ that falls like $1/n_g^2$ and a critical friction that
converges to the exact cone's; in the plane the verdict is the picture "origin
inside the hull of the primitive wrenches".
"""),
    ]


# --------------------------------------------------------------------------- 04


def notebook_04() -> list:
    return [
        md(r"""
# 4. A hand from SDF: the hand Jacobian and LP3

Force closure of the **grasp** says that contact forces exist to resist any
wrench.  The **hand** must also be able to produce and change them with its
joints.  The hand Jacobian $J$ maps joint velocities $\dot q_h$ to the velocities
of the finger contact points in the contact frames (rows in the order of $G$'s
columns); by duality the joint torques of contact forces $f$ are $\tau = J^T f$.

An internal force ($G f = 0$) with $J^T f = 0$ loads the object and the hand but
needs no torque: the joints can neither create nor change it.  The chapter's
**LP3** looks for one with positive normal forces:

$$
\begin{aligned}
d^* = \max_{f,\,d}\ d \quad\text{s.t.}\quad G f &= 0, & J^T f &= 0, &
E f - \mathbf 1 d &\ge 0, & d &\ge 0, & \textstyle\sum_i f_{n,i} &\le N ,
\end{aligned}
$$

and the hand controls every internal force when $d^* = 0$
($\mathcal N(G)\cap\mathcal N(J^T)$ holds no squeezing force).  Force closure
with a hand needs frictional force closure **and** LP3 to pass.
"""),
        code(SETUP),
        code(SCENE_TO_MESHCAT),
        md(r"""
## The three-finger hand

`three_finger_sphere` loads our three-finger hand (SDF, three flexion joints per
finger: proximal, middle, distal) holding a 35 mm sphere at its equator.
"""),
        code("""
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
"""),
        code("""
meshcat = Meshcat()
print("Meshcat:", meshcat.web_url())
draw_scene(meshcat, scene, alpha=0.6)
from drakegrasp.visualization import draw_grasp

X_WO = plant.EvalBodyPoseInWorld(context, scene.object_body)
drawing = draw_grasp(meshcat, grasp, X_WG=X_WO, result=report.force_closure_exact)
print(len(drawing.paths), "objects drawn under", drawing.prefix)
"""),
        md(r"""
$J$ is block diagonal: each finger's joints move only its own contact.  In each
contact frame the rows are $[n, t_1, t_2]$.  The fingers flex in vertical planes
through the centre, so the fingertips never move sideways: the row of the
horizontal tangent is zero ($t_1$ of contact 0, $t_2$ of contacts 1 and 2, since
$t_1$ is chosen from $n$ alone).
"""),
        code("""
print("J (rows: n, t1, t2 per contact; columns: joints) =\\n", J)
plt.figure(figsize=(6, 4.5))
plt.imshow(J, cmap="coolwarm", vmin=-0.12, vmax=0.12)
plt.yticks(range(9), [f"c{i} {r}" for i in range(3) for r in ("n", "t1", "t2")])
plt.xticks(range(9), [n.replace("_joint", "") for n in joint_names], rotation=60)
plt.colorbar(label="m/s per rad/s")
plt.title("hand Jacobian J")
plt.show()
"""),
        md(r"""
## LP3 with every joint, and with locked joints

Locking joints removes columns of $J$.  With all nine joints LP3 passes; it still
passes with only the distal joints, or with fingers 2 and 3 locked altogether:
every internal force of this grasp needs $f_{n,1} > 0$, and finger 1's proximal
joint pushes along $n_1$, so it feels every squeeze.
"""),
        code("""
choices = {
    "all 9 joints": list(range(9)),
    "distal joints only": [2, 5, 8],
    "finger 1 proximal only": [0],
}
for name, cols in choices.items():
    lp3 = dg.internal_forces(grasp, J[:, cols])
    print(f"{name:24s} {lp3}")
"""),
        md(r"""
## A hand that cannot squeeze

Real hands often drive several joints with one actuator (a tendon, a linkage):
joint velocities $\dot q_h = S u$, so the actuators see the Jacobian $J S$.  Two
couplings with one actuator per finger:

* **curl**: all three joints of a finger together, $s = (1, 1, 1)$: the fingertip
  moves towards the centre and along $n$;
* **slide**: proximal and middle joints in the ratio that cancels the normal
  velocity, $s \perp J_{n,i}$: the fingertip slides along the surface and never
  pushes along $n$.

With the sliding coupling the pure squeeze (equal normal forces, no friction) is
internal and needs no actuator torque: $J^T f = 0$.  LP3 finds it ($d^* = 1$):
the hand cannot squeeze the sphere, so the grasp is not in force closure **with
this hand** even though it is in frictional force closure.
"""),
        code("""
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
print("\\nuncontrollable internal force (per contact [f_n, f_t1, f_t2]):", lp3.contact_forces)
print("G f =", dg.grasp_matrix(grasp) @ f, " (J S)^T f =", (J @ S_slide).T @ f)
"""),
        md(r"""
**Picture.**  Finger 1 seen in its own plane (normal $n$ to the right, up is up):
the velocity of the fingertip per unit rate of each joint and of each coupling.
The sliding coupling moves the tip exactly along the surface; a force along $n$
does no work on it, so its actuator cannot feel or change the squeeze.
"""),
        code("""
c0 = grasp.contacts[0]
# Finger 1's fingertip velocities in the object frame, then along n and up (z).
V = c0.frame @ J[0:3, 0:3]  # columns: proximal, middle, distal
to_plane = np.vstack([c0.normal, [0.0, 0.0, 1.0]])
plt.figure(figsize=(5, 4.5))
for k, name in enumerate(("proximal", "middle", "distal")):
    plt.quiver(0, 0, *(to_plane @ V[:, k]), angles="xy", scale_units="xy", scale=1,
               color=f"C{k}", label=f"{name} joint")  # fmt: skip
for S, name, color in ((S_curl, "curl coupling", "k"), (S_slide, "slide coupling", "m")):
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
"""),
        code("""
# In Meshcat: the uncontrollable squeeze, drawn as forces on the object.
draw_grasp(meshcat, grasp, X_WG=X_WO, result=lp3, prefix="uncontrollable", cone=None)
meshcat.SetProperty(drawing.prefix, "visible", False)  # hide the first drawing
print("Open", meshcat.web_url(), "to see the hand and the squeeze it cannot control.")
"""),
        md(r"""
**What you learned.**  The hand Jacobian $J$ from a plant (rows in contact-frame
components, columns hand joints), the duality $\tau = J^T f$, and LP3: an internal
force in $\mathcal N(G)\cap\mathcal N(J^T)$ with positive normals is a squeeze the
joints cannot produce or change.  Locking joints is harmless here, but coupling the
joints so that the fingertips slide along the surface makes the grasp uncontrollable
although friction alone would hold the object.
"""),
    ]


# --------------------------------------------------------------------------- 05


def notebook_05() -> list:
    return [
        md(r"""
# 5. Antipodal grasps with a parallel-jaw gripper

Two contacts hold an object by squeezing along the line between them.  The pair is
**antipodal** when that line lies inside both friction cones:

$$
\begin{aligned}
\angle\big(c_2 - c_1,\ n_1\big) &\le \arctan\mu, &
\angle\big(c_1 - c_2,\ n_2\big) &\le \arctan\mu,
\end{aligned}
$$

so the smallest friction that makes the pair antipodal is
$\mu_{\min} = \tan\max_i \angle_i$.  For two **soft** fingers (point contacts that
also resist a moment about the normal) an antipodal pair with the line strictly
inside the cones is in force closure; two **hard** fingers never are (nothing
resists a rotation about the line: $\operatorname{rank} G = 5$).
"""),
        code(SETUP),
        code(SCENE_TO_MESHCAT),
        md(r"""
## The gripper and a tilted box

`parallel_jaw_box` holds a $50\times50\times100$ mm box between two jaws with
hemispherical pads (radius $r = 6$ mm) that close along $y$.  We turn the box by
$\theta$ about the vertical axis and close each jaw until its pad touches the
face: the face is $25$ mm from the centre, so the pad's centre must be
$25 + 6$ mm from the face plane, $q = 0.031/\cos\theta - 0.006$ (the joint value is
the distance from the palm's mid-plane to the pad tip).
"""),
        code("""
from pydrake.math import RigidTransform, RotationMatrix

from drakegrasp.plant import grasp_from_plant, load_scene

scene = load_scene("parallel_jaw_box")
plant, context, box = scene.plant, scene.plant_context, scene.object_body
p_box = plant.EvalBodyPoseInWorld(context, box).translation()


def tilt_box(theta):
    \"\"\"Turn the box by theta about z and close both jaws onto it.\"\"\"
    plant.SetFreeBodyPose(context, box, RigidTransform(RotationMatrix.MakeZRotation(theta), p_box))
    q = 0.031 / np.cos(theta) - 0.006
    for name in ("left_finger_joint", "right_finger_joint"):
        plant.GetJointByName(name).set_translation(context, q)


def read_grasp(mu, model="soft_finger"):
    nu = 0.1 if model == "soft_finger" else None
    data = grasp_from_plant(plant, context, object_body=box, hand=scene.hand, mu=mu,
                            contact_model=model, torsional_friction=nu)  # fmt: skip
    return data


theta = np.radians(20.0)
tilt_box(theta)
data = read_grasp(0.5)
for pc in data.contacts:
    print(pc)
print("psi [m]:", data.psi, "(both pads touch)")
"""),
        md(r"""
## The antipodal check and the friction it needs

The pads are round, so each contact point sits $r\sin\theta$ off the jaw axis
along the face: the line between the contacts is steeper than the jaw axis.  In
the box frame the contact is $s = 0.031\tan\theta$ along the face from its centre
and $25$ mm out, so the angle is $\arctan(s / 0.025)$ and
$\mu_{\min} = 1.24\tan\theta$, more than the $\tan\theta$ of the jaw axis alone.
"""),
        code("""
antipodal = dg.is_antipodal(data.grasp)
print(antipodal)
print(f"predicted mu_min = 1.24 tan(theta) = {1.24 * np.tan(theta):.4f}")
print(f"tan(theta) alone would say          {np.tan(theta):.4f}")
"""),
        md(r"""
## A sweep of $\mu$

For each $\mu$: the antipodal margins $\arctan\mu - \angle_i$ (positive inside the
cone), the exact-cone force closure of two soft fingers (its $d^*$), and the same
grasp with hard fingers.  The soft-finger verdict switches on where the margins
cross zero, at $\mu_{\min}$; the hard-finger grasp never closes.
"""),
        code("""
mus = np.linspace(0.2, 0.8, 13 if TEST_MODE else 61)
margins, d_soft, fc_soft, fc_hard = [], [], [], []
for mu in mus:
    soft = read_grasp(mu).grasp
    margins.append(np.degrees(dg.is_antipodal(soft).margins))
    r = dg.force_closure_exact(soft)
    d_soft.append(r.d_star)
    fc_soft.append(r.is_closure)
    fc_hard.append(dg.force_closure_exact(soft.with_friction(model="hard_finger")).is_closure)
margins = np.array(margins)

fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(11, 3.8))
ax0.plot(mus, margins[:, 0], "o-", label="margin of contact 0")
ax0.plot(mus, margins[:, 1], "x--", label="margin of contact 1")
ax0.axhline(0, color="k", lw=0.5)
ax0.axvline(antipodal.min_mu, color="C3", ls=":", label="$\\\\mu_{min}$")
ax0.set_xlabel("$\\\\mu$")
ax0.set_ylabel("antipodal margin [deg]")
ax0.legend()
ax1.plot(mus, d_soft, "o-", label="$d^*$, soft fingers (exact cones)")
ax1.axvline(antipodal.min_mu, color="C3", ls=":")
ax1.set_xlabel("$\\\\mu$")
ax1.set_ylabel("$d^*$")
ax1.legend(fontsize=8, loc="upper left")
verdicts = ax1.twinx()
verdicts.plot(mus, fc_soft, "s", mfc="none", color="C1", label="soft fingers")
verdicts.plot(mus, fc_hard, "kx", label="hard fingers")
verdicts.set_yticks([0, 1], ["no", "force closure"])
verdicts.legend(fontsize=8, loc="center right")
fig.tight_layout()
plt.show()

first = mus[np.argmax(fc_soft)]
print(f"soft fingers: first mu in closure {first:.3f}; mu_min = {antipodal.min_mu:.4f}")
print("hard fingers: any closure?", any(fc_hard))
assert all(f == (m > 0).all() for f, m in zip(fc_soft, margins, strict=True) if abs(m).min() > 0.1)
"""),
        md(r"""
The friction needed grows with the tilt: $\mu_{\min}(\theta) = 1.24\tan\theta$ for
these pads, read back from the plant for each $\theta$.
"""),
        code("""
thetas = np.radians(np.linspace(0, 35, 8 if TEST_MODE else 36))
needed = []
for th in thetas:
    tilt_box(th)
    needed.append(dg.is_antipodal(read_grasp(0.5).grasp).min_mu)
plt.figure(figsize=(5, 3.5))
plt.plot(np.degrees(thetas), needed, "o", label="is_antipodal(...).min_mu")
plt.plot(np.degrees(thetas), 1.24 * np.tan(thetas), "k-", label="$1.24\\\\tan\\\\theta$")
plt.plot(np.degrees(thetas), np.tan(thetas), "k:", label="$\\\\tan\\\\theta$ (jaw axis)")
plt.xlabel("box rotation $\\\\theta$ [deg]")
plt.ylabel("friction needed")
plt.legend()
plt.show()
print("max |min_mu - 1.24 tan(theta)| =", np.abs(np.array(needed) - 1.24 * np.tan(thetas)).max())
"""),
        md(r"""
## In Meshcat

Meshcat serves on localhost; it needs no browser to accept drawings (open the URL
to look).  The scene's shapes are sent to it, then `draw_grasp` adds the contact
points, contact frames ($n$ red, $t_1$ green, $t_2$ blue), the exact friction
cones and the exact program's contact forces, at the object's pose $X_{WO}$.  With
$\mu = 0.5 > \mu_{\min}$ the line between the pads lies inside both cones.
"""),
        code("""
from drakegrasp.visualization import draw_grasp

tilt_box(np.radians(20.0))
meshcat = Meshcat()
print("Meshcat:", meshcat.web_url())
draw_scene(meshcat, scene, alpha=0.5)
soft = read_grasp(0.5).grasp
result = dg.force_closure_exact(soft)
print(result)
drawing = draw_grasp(meshcat, soft, X_WG=plant.EvalBodyPoseInWorld(context, box),
                     result=result, cone="both")  # fmt: skip
print(f"drawn {len(drawing.paths)} objects under {drawing.prefix!r}; "
      f"cone height {1e3 * drawing.cone_height:.1f} mm")  # fmt: skip
"""),
        md(r"""
**What you learned.**  The antipodal test compares the line between two contacts
with their friction cones; `min_mu` is the friction a pair needs, which for round
pads is more than the jaw axis suggests; sweeping $\mu$ shows the antipodal margins
and the soft-finger force-closure verdict switching at the same $\mu_{\min}$, while
two hard fingers never reach force closure.
"""),
    ]


NOTEBOOKS = {
    "01_grasp_matrix.ipynb": notebook_01,
    "02_form_closure.ipynb": notebook_02,
    "03_force_closure.ipynb": notebook_03,
    "04_hand_jacobian_lp3.ipynb": notebook_04,
    "05_antipodal_parallel_jaw.ipynb": notebook_05,
}


def build(name: str) -> nbformat.NotebookNode:
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = KERNELSPEC
    nb.metadata["language_info"] = {"name": "python"}
    nb.cells = NOTEBOOKS[name]()
    for i, cell in enumerate(nb.cells):
        cell["id"] = f"{Path(name).stem[:2]}-{i:02d}"
    nbformat.validate(nb)
    return nb


def main() -> None:
    paths = []
    for name in NOTEBOOKS:
        nbformat.write(build(name), HERE / name)
        paths.append(str(HERE / name))
        print("wrote", HERE / name)
    ruff = shutil.which("ruff", path=str(Path(sys.executable).parent)) or shutil.which(
        "ruff"
    )
    if ruff:
        subprocess.run([ruff, "format", *paths], check=True)


if __name__ == "__main__":
    main()
