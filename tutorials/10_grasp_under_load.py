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
# # 10 · A grasp under load: squeeze, motors and payload
#
# Force closure says that *some* contact forces resist *every* wrench; it does
# not say how hard the hand must squeeze to hold *this* object, whether its
# motors can squeeze that hard, or how much heavier the object could be.  LP2's
# $d^*$ does not say it either: $d^*$ is the geometric distance of the best
# **internal** force (no load at all) to the boundaries of the friction cones.
# It is the same for a feather and an anvil.
#
# The load questions have their own programs.  With $w$ the external wrench on
# the object (its weight, about the grasp's reference point, in the grasp
# frame), $G$ the grasp matrix, $K_i$ the friction cones and $J$ the hand
# Jacobian, the hand holds the load when contact forces $f$ exist with
#
# $$
# G f = -w,\qquad f_i \in K_i,\qquad |J^T f| \le \tau_{\max}
# $$
#
# (quasi-statically: $\tau = J^T f$ are the joint torques that press the fingers
# on with $f$).  In this notebook
#
# 1. `dg.grasp_forces` finds the least squeeze on two fingers, where the answer
#    is known in closed form, then with motors (`dg.max_load`: the payload) and
#    with motors too weak, where it returns a **certificate** that no forces
#    exist, which we re-check by hand;
# 2. the same on a real hand: Drake's WSG-50 holding the YCB sugar box, with
#    the weight, the motors' effort limits and the friction read from the plant
#    (`analyze_grasp(..., load="gravity", torque_limits="plant", mu="plant")`);
# 3. a Drake simulation squeezes the box with a constant finger force, below,
#    at and above the least squeeze, and shows which grips hold.
#
# Conventions (signs, frames, the Farkas certificate):
# `docs/conventions.md`, section *Grasps under load*.

# %%
import dataclasses
import os

import matplotlib.pyplot as plt
import numpy as np
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, ContactModel
from pydrake.solvers import MathematicalProgram, Solve
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

import drakegrasp as dg

TEST_MODE = os.environ.get("DRAKEGRASP_TUTORIAL_TEST") == "1"
m, g = 0.514, 9.81  # the YCB sugar box's mass (kg) and gravity (m/s²)

# %% [markdown]
# ## Two fingers and a weight: the closed form
#
# Two hard fingers squeeze a box along $x$, 40 mm apart; gravity pulls along
# $-z$, in the plane tangent to both contacts.  The normal forces cancel each
# other, so friction alone carries the weight: each finger's tangential force
# is at most $\mu f_n$, and the least total squeeze is
#
# $$
# \textstyle\sum_i f_{n,i} = \dfrac{m g}{\mu}, \qquad f_{n,i} = \dfrac{m g}{2\mu}.
# $$
#
# The load is the wrench of the weight on the object, $w = [0, 0, -m g, 0, 0,
# 0]$ (N, N·m) about the box's centre.

# %%
w = np.array([0.0, 0.0, -m * g, 0.0, 0.0, 0.0])


def two_fingers(mu):
    """Two hard fingers on the faces x = ±20 mm of a box centred at the origin."""
    return dg.Grasp(
        [
            dg.Contact([-0.02, 0, 0], [1, 0, 0], mu=mu),
            dg.Contact([0.02, 0, 0], [-1, 0, 0], mu=mu),
        ]
    )


result = dg.grasp_forces(two_fingers(0.5), w)
print(result)
print(f"closed form m g / μ = {m * g / 0.5:.6g} N")

# %% [markdown]
# The optimiser (an SOCP on the exact cones, solved by Clarabel) finds the
# closed form.  Across μ:

# %%
mus = np.linspace(0.1, 1.2, 6 if TEST_MODE else 23)
squeeze = np.array([dg.grasp_forces(two_fingers(mu), w).squeeze for mu in mus])
print("largest relative difference from m g / μ:",
      f"{np.max(np.abs(squeeze * mus / (m * g) - 1)):.1e}")  # fmt: skip

# %% [markdown]
# ## Motors: torque limits and the payload factor
#
# Now each finger is driven by one prismatic joint that slides it along its
# normal; the hand Jacobian maps the two joint velocities to the contact-frame
# velocities (rows in the order of $G$'s columns: each contact's normal, then
# its two tangents).  The joint forces are then $\tau = J^T f$: each motor
# pushes with exactly its finger's normal force.  With a limit $\tau_{\max}$
# per motor, friction carries at most $2 \mu \tau_{\max}$, so the largest
# multiple of the weight the hand holds, the **payload factor**, is
#
# $$
# \alpha^* = \frac{2 \mu \tau_{\max}}{m g}.
# $$

# %%
J = np.zeros((6, 2))
J[0, 0] = 1.0  # finger 1's joint moves contact 1 along its normal
J[3, 1] = 1.0  # finger 2's joint moves contact 2 along its normal
grasp = two_fingers(0.5)

held = dg.grasp_forces(grasp, w, hand_jacobian=J, torque_limits=[20.0, 20.0])
print(held)
payload = dg.max_load(grasp, w, hand_jacobian=J, torque_limits=[20.0, 20.0])
print(payload)
print(f"closed form 2 μ τ_max / (m g) = {2 * 0.5 * 20.0 / (m * g):.6g}")

# %% [markdown]
# `max_load` comes with its own certificate (kind `"payload bound"`) that no
# larger multiple can be held; its bound agrees with α*.  The figure puts the
# two closed forms beside the programs' answers.


# %%
def payload_factors(grasp, wrench, J, limits):
    """``max_load``'s α* with the same limit on both motors, for each limit."""
    return np.array(
        [
            dg.max_load(grasp, wrench, hand_jacobian=J, torque_limits=[t, t]).alpha
            for t in limits
        ]
    )


def plot_payload(ax, limits, alpha, closed_form, closed_label, *, xlabel, weight):
    """α* against the motor limit, beside a closed form; α* = 1 holds ``weight``."""
    ax.plot(limits, closed_form, color="0.6", label=closed_label)
    ax.plot(limits, alpha, "o", color="tab:orange", label="max_load")
    ax.axhline(1.0, color="tab:red", lw=0.8, ls="--", label=weight)
    ax.set(xlabel=xlabel, ylabel="payload factor α*")


tau_max = np.linspace(0.0, 40.0, 5 if TEST_MODE else 21)
alpha = payload_factors(grasp, w, J, tau_max)
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.6))
fine = np.linspace(mus[0], mus[-1], 200)
ax1.plot(fine, m * g / fine, color="0.6", label="m g / μ (closed form)")
ax1.plot(mus, squeeze, "o", color="tab:blue", label="grasp_forces")
ax1.set(xlabel="friction coefficient μ", ylabel="least squeeze Σ f_n (N)")
ax1.set_title("two fingers, weight 5.04 N")
ax1.legend()
plot_payload(
    ax2, tau_max, alpha, 2 * 0.5 * tau_max / (m * g), "2 μ τ_max / m g",
    xlabel="motor limit τ_max per finger (N)", weight="the weight itself",
)  # fmt: skip
ax2.set_title("two fingers, μ = 0.5")
ax2.legend()
plt.tight_layout()
plt.show()

# %% [markdown]
# ## Motors too weak: a proof that the grip cannot hold
#
# With $\tau_{\max} = 4$ N per finger, friction carries at most
# $2 \cdot 0.5 \cdot 4 = 4$ N of a 5.04 N weight.  `grasp_forces` says
# "not held", and does not ask to be believed: its `certificate` is a Farkas
# dual, a twist $y$ of the object and one multiplier $\eta_j$ per joint with,
# at every contact,
#
# $$
# a_i = G_i^T y - J_i \eta \in -K_i^*
# \quad\text{(for a hard finger: } a_{n} + \mu \lVert a_{t} \rVert \le 0),
# $$
#
# and a power deficit $-y^T w > B = \sum_j |\eta_j|\, \tau_{\max,j}$.  Along
# $y$ the load delivers more power than the contacts and the motors within
# their limits can absorb, so no admissible $f$ balances $w$.

# %%
weak = dg.grasp_forces(grasp, w, hand_jacobian=J, torque_limits=[4.0, 4.0])
print(weak)
cert = weak.certificate
print(cert.check(grasp, hand_jacobian=J))

# %% [markdown]
# `check` multiplies matrices; no solver is involved.  The same test, written
# out here from the definition (the cones' support function for hard fingers):


# %%
def recheck(cert, grasp, J):
    """Re-verify a load certificate of hard-finger contacts with numpy alone."""
    G = dg.grasp_matrix(grasp)
    y, eta = cert.twist, cert.joint_multipliers
    a = G.T @ y - J @ eta
    worst = max(
        a[3 * i] + c.mu * np.linalg.norm(a[3 * i + 1 : 3 * i + 3])
        for i, c in enumerate(grasp.contacts)
    )
    power = -y @ cert.wrench
    budget = np.sum(np.abs(eta) * cert.torque_limits)
    return worst, power, budget


worst, power, budget = recheck(cert, grasp, J)
print(f"largest a_n + μ‖a_t‖ = {worst:.2e} (≤ 0: every cone condition holds)")
print(f"power of the load -yᵀw = {power:.4f}  >  budget B = {budget:.4f}")
print(f"so at most {budget / power:.4f} x the weight can be held "
      f"(closed form 2 μ τ_max / m g = {2 * 0.5 * 4.0 / (m * g):.4f})")  # fmt: skip

# %% [markdown]
# Here $y$ is the vertical direction, $\eta_j = \mu$ (up to a common scale),
# and the budget
# $2 \mu \tau_{\max} = 4$ is the friction the motors can buy against the
# weight $m g = 5.04$: the closed form, rediscovered by the solver.  The proof
# is tied to the limits it names; against 20 N motors the same numbers prove
# nothing, and the check says so:

# %%
stronger = dataclasses.replace(cert, torque_limits=np.array([20.0, 20.0]))
print(stronger.check(grasp, hand_jacobian=J))

# %% [markdown]
# ## A real hand: the WSG-50 holding the sugar box
#
# The scene of tutorial 06, with two changes for what follows: the plant is
# *discrete* (1 ms steps), as for a simulation, and uses *point* contact, so
# that the simulator sees the same eight point contacts (four tip spheres per
# pad) that the analysis models as hard fingers.  `dg.use_local_drake_models`
# points `package://drake_models` at a local copy when
# `DRAKEGRASP_DRAKE_MODELS` names one (Drake downloads it otherwise).

# %%
wsg_url = "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf"
sugar_url = "package://drake_models/ycb/004_sugar_box.sdf"
X_WBox = RigidTransform(RollPitchYaw(np.radians([90, 0, 90])), [0, 0.09, 0])

builder = DiagramBuilder()
plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=1e-3)
parser = Parser(plant)
dg.use_local_drake_models(parser)
wsg = parser.AddModels(url=wsg_url)[0]
plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("body", wsg))
box = plant.get_body(plant.GetBodyIndices(parser.AddModels(url=sugar_url)[0])[0])
plant.set_contact_model(ContactModel.kPoint)
plant.Finalize()
diagram = builder.Build()
root = diagram.CreateDefaultContext()
context = plant.GetMyContextFromRoot(root)
plant.SetFreeBodyPose(context, box, X_WBox)
plant.SetPositions(context, wsg, [-0.05, 0.05])  # open
print(dg.close_hand(plant, root, box, hand=wsg))

# %% [markdown]
# `load="gravity"` reads the box's mass and centre of mass from the context and
# the plant's gravity field; `torque_limits="plant"` reads each finger
# actuator's effort limit from the SDF (80 N: the fingers slide, so their
# "torques" are forces); `mu="plant"` reads each contact pair's friction from
# the geometries' proximity properties, combined as Drake combines them (the
# dynamic coefficient for a discrete plant: that is the one its solver uses).

# %%
report = dg.analyze_grasp(
    plant, root, box, hand=wsg, mu="plant", load="gravity", torque_limits="plant"
)
load = report.load
print(load)

# %% [markdown]
# The report's load section answers the hand's own question: it holds, with
# these motor forces, and could hold 17.5 times the box.  Had we typed a μ that
# the plant does not simulate, the section would say so:

# %%
typed = dg.analyze_grasp(plant, root, box, hand=wsg, mu=0.5, load="gravity")
print(typed.load.warnings[0])

# %% [markdown]
# ### Least squeeze against μ: why more than m g / μ?
#
# The weight lies in the pads' plane here too, yet the least squeeze is
# 9.14 N, not $m g / \mu = 5.04$ N.  The pads grip the box 18 mm from its
# centre of mass (the box's origin), so the weight also **twists** the box
# about the squeeze axis, and that moment, too, must come from friction at the
# four spheres of each pad.  Move the weight's line of action to the pads'
# centre (the same force, its moment taken about that point) and the closed
# form returns.

# %%
G_contacts = report.grasp.contacts
mg = np.linalg.norm(load.wrench[:3])
p_pads = np.mean([c.position for c in G_contacts], axis=0)  # pads' centre, frame O
print("pads' centre in O (mm):", np.round(1e3 * p_pads, 2))
w_centred = np.concatenate([load.wrench[:3], np.cross(p_pads, load.wrench[:3])])

mus = np.linspace(0.2, 1.2, 6 if TEST_MODE else 21)
grasps = [
    report.grasp.with_contacts([c.with_(mu=mu) for c in G_contacts]) for mu in mus
]
real = np.array([dg.grasp_forces(gr, load.wrench).squeeze for gr in grasps])
centred = np.array([dg.grasp_forces(gr, w_centred).squeeze for gr in grasps])
print("centred weight vs m g / μ, largest relative difference:",
      f"{np.max(np.abs(centred * mus / mg - 1)):.1e}")  # fmt: skip

# %% [markdown]
# Both curves fall as $1/\mu$; the twist costs the real grasp a factor
# 9.14 / 5.04 = 1.81 at every μ (the programs are homogeneous in the friction
# forces, so the ratio cannot depend on μ).

# %%
fig, ax = plt.subplots(figsize=(6, 3.6))
fine = np.linspace(mus[0], mus[-1], 200)
ax.plot(fine, mg / fine, color="0.6", label="m g / μ")
ax.plot(mus, centred, "s", color="tab:green",
        label="weight through the pads' centre")  # fmt: skip
ax.plot(mus, real, "o", color="tab:blue", label="the real box (grasp_forces)")
ax.set(xlabel="friction coefficient μ", ylabel="least squeeze Σ f_n (N)")
ax.set_title("WSG-50 holding the sugar box")
ax.legend()
plt.tight_layout()
plt.show()
print("squeeze ratio real / centred:", np.round(real / centred, 4))

# %% [markdown]
# ### Payload against motor strength
#
# Every constraint is homogeneous in $(f, \alpha)$ except the motor limits, so
# the payload grows linearly with them: $\alpha^* = \tau_{\max} / \tau_1$,
# where $\tau_1$ is the least largest joint force that holds the weight once.
# `objective="min_torque"` gives $\tau_1$ directly, an independent route to the
# slope of `max_load`'s line.

# %%
tau_1 = np.max(
    np.abs(
        dg.grasp_forces(
            report.grasp, load.wrench, hand_jacobian=report.J, objective="min_torque"
        ).joint_torques
    )
)
limits = np.linspace(0.0, 80.0, 5 if TEST_MODE else 17)
alpha = payload_factors(report.grasp, load.wrench, report.J, limits)
print(f"τ_1 = {tau_1:.4f} N; at the SDF's 80 N: α* = {alpha[-1]:.4f}, "
      f"80 / τ_1 = {80 / tau_1:.4f}")  # fmt: skip
fig, ax = plt.subplots(figsize=(6, 3.6))
plot_payload(
    ax, limits, alpha, limits / tau_1, "τ_max / τ_1 (min_torque)",
    xlabel="finger force limit τ_max (N)", weight="the box itself",
)  # fmt: skip
ax.axvline(80.0, color="0.3", lw=0.8, ls=":", label="the SDF's effort limit")
ax.set_title("WSG-50 and the sugar box, μ from the plant")
ax.legend()
plt.tight_layout()
plt.show()

# %% [markdown]
# ### A grip too weak, proved and re-checked
#
# Limit both fingers to 2 N (below $\tau_1$ = 4.57 N).  The load section says
# the hand does not hold, with the proof; we re-check it with the library's
# `check` and with the numpy test written above.

# %%
weak = dg.analyze_grasp(
    plant, root, box, hand=wsg, mu="plant", load="gravity", torque_limits=[2.0, 2.0]
)
print(weak.load)
cert = weak.load.forces.certificate
print(cert.check(weak.grasp, hand_jacobian=weak.J))
worst, power, budget = recheck(cert, weak.grasp, weak.J)
print(f"largest a_n + μ‖a_t‖ = {worst:.2e}; -yᵀw = {power:.4f} > B = {budget:.4f}")
print(f"proven: at most {budget / power:.4f} x the box can be held")
bound = weak.load.payload.certificate
print(f"payload factor {weak.load.payload.alpha:.4f} (2 / τ_1 = {2 / tau_1:.4f}), "
      f"its certificate re-checked: {bool(bound.check(weak.grasp, hand_jacobian=weak.J))}")  # fmt: skip

# %% [markdown]
# A refutation only has to prove a bound below 1, and this one proves 0.63;
# the payload program's own certificate proves the tight bound, 2 N / τ_1.

# %% [markdown]
# ## What the simulator says
#
# The analysis is quasi-static; Drake's simulator is the judge of "holds".
# Squeeze the box with a constant force on each finger, a multiple $k$ of the
# least-squeeze finger forces found above, let gravity act for a while, and
# measure how far the box slides down between the fingers.


# %%
def slide(k, duration):
    """The box's drop (mm) after `duration` s with k x the least-squeeze forces."""
    simulator = Simulator(diagram)
    sim_context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    plant.SetPositions(sim_context, plant.GetPositions(context))  # the closed grasp
    plant.get_actuation_input_port(wsg).FixValue(
        sim_context, k * load.forces.joint_torques
    )
    z0 = plant.EvalBodyPoseInWorld(sim_context, box).translation()[2]
    simulator.AdvanceTo(duration)
    return 1e3 * (z0 - plant.EvalBodyPoseInWorld(sim_context, box).translation()[2])


duration = 0.5 if TEST_MODE else 1.0
ks = [0.5, 0.9, 1.5, 2.0] if TEST_MODE else [0.3, 0.5, 0.7, 0.9, 1.0, 1.1, 1.2,
                                             1.35, 1.5, 2.0, 3.0]  # fmt: skip
drops = np.array([slide(k, duration) for k in ks])
for k, d in zip(ks, drops, strict=True):
    print(f"k = {k:4.2f}: the box slid {d:8.3f} mm in {duration} s")

# %% [markdown]
# Below the least squeeze ($k < 1$) the box cannot stay where it is, as the
# certificate's argument proves: it swings about the squeeze axis (by about
# 16°) and slides down until it leans on the gripper's palm, a ninth contact
# that the analysis of the pads alone does not have, or it falls out.  From
# $k = 1.35$ on, the box stays within a fraction of a millimetre (the slow
# creep of the simulator's regularised friction).  Between the two, the least
# squeeze is not enough in simulation, and the reason can be computed: the
# optimum puts most of each pad's force on the sphere nearest the centre of
# mass, to resist the twist, but a rigid pad pressed flat on the box shares its
# force equally among its four spheres (the simulator's contact forces show
# it).  The least squeeze *with that split* is one more small program, a
# second formulation written here with Drake directly:

# %%
print("optimal normal forces (N):",
      np.round([f[0] for f in load.forces.contact_forces], 3))  # fmt: skip
G = dg.grasp_matrix(report.grasp)
prog = MathematicalProgram()
F = prog.NewContinuousVariables(1, "F")[0]  # each pad's force, N
f_t = prog.NewContinuousVariables(8, 2, "f_t")
f = np.array([[F / 4, f_t[i, 0], f_t[i, 1]] for i in range(8)]).reshape(-1)
for row, w_row in zip(G, load.wrench, strict=True):
    prog.AddLinearEqualityConstraint(row @ f == -w_row)
for i, c in enumerate(report.grasp.contacts):
    prog.AddLorentzConeConstraint(np.array([c.mu * F / 4, f_t[i, 0], f_t[i, 1]]))
prog.AddLinearCost(F)
equal_split = Solve(prog)
k_equal = equal_split.GetSolution(F) / load.forces.joint_torques[0]
print(f"equal split needs k = {k_equal:.3f} x the least squeeze")

# %%
fig, ax = plt.subplots(figsize=(6, 3.6))
ax.semilogy(ks, np.maximum(drops, 1e-3), "o-", color="tab:purple")
ax.axvline(1.0, color="tab:red", lw=0.8, ls="--", label="least squeeze (necessary)")
ax.axvline(k_equal, color="tab:green", lw=0.8, ls="--",
           label="least squeeze, equal split per pad")  # fmt: skip
ax.set(xlabel="finger force / least-squeeze finger force  k",
       ylabel=f"box slid in {duration} s (mm)")  # fmt: skip
ax.set_title("WSG-50 and the sugar box in Drake's simulator")
ax.legend()
plt.tight_layout()
plt.show()

# %% [markdown]
# **What you learned.**  $d^*$ is geometry; load has its own answers.
# `grasp_forces` gives the least squeeze and the joint torques that hold a
# wrench within the cones and the motors' limits (the closed form $m g / \mu$
# for two fingers), `max_load` the payload factor (linear in the motor limits:
# $\tau_{\max} / \tau_1$), and a grip that cannot hold comes with a Farkas
# certificate that anyone can re-check with a few matrix products.
# `analyze_grasp(..., load="gravity", torque_limits="plant", mu="plant")` reads
# the weight, the motors and the friction from the plant.  The least squeeze is
# *necessary*: the simulator drops every grip below it; what a real pad needs
# on top depends on how it shares its force, which a second small program
# predicts.
