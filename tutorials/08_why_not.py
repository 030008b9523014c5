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
# # 8. Why not? Certificates of every verdict
#
# A closure test answers "yes" or "no".  This notebook asks **why**: which way
# the object will move, which push the grasp cannot resist, which squeeze the
# hand cannot control.  Every program of drakegrasp already holds the answer in
# its alternative (Stiemke's theorem, a sharp form of Gordan's):
#
# | verdict | witness (`result.certificate`) | definition |
# | --- | --- | --- |
# | form closure "no" | escape twist $v = [v_p;\ \omega]$ | $G_n^T v \ge 0$, $v \ne 0$: no contact penetrates to first order |
# | force closure "no" | unresisted wrench $w = [f;\ m]$ and the plane's normal $y$ | $y^T G f \le 0$ on every cone, $y^T w > 0$: the grasp cannot resist $-w$ |
# | LP3 fails | uncontrollable internal force $f$ | $f \in N(G) \cap N(J^T)$, every $f_n > 0$ |
# | "yes" | balancing internal force | $G f = 0$ strictly inside the cones, $G$ of full rank |
#
# Everything is in the grasp frame about the reference point, wrenches
# $[f; m]$ and twists $[v; \omega]$ as in the conventions.
# `result.certificate.check(grasp)` re-verifies a witness **without a solver**
# and says by how much it holds; `result.decided_by` says whether the rank,
# $d^*$, the normal forces or LP3 decided.

# %%
import os

import matplotlib.pyplot as plt
import numpy as np

import drakegrasp as dg
from drakegrasp import examples as ex

# tests/tutorials sets this to run the notebook with short loops.
TEST_MODE = os.environ.get("DRAKEGRASP_TUTORIAL_TEST") == "1"
np.set_printoptions(precision=4, suppress=True, linewidth=110)

# %% [markdown]
# ## 1. A parallel-jaw grasp that fails, and why
#
# The default scene: a parallel-jaw gripper with rounded pads squeezes a box.
# Two hard fingers are never in force closure in space.  The report says what
# decided each verdict and, for each "no", one line that says why (points in
# the object frame O, metres).

# %%
scene = dg.load_scene("parallel_jaw_box")
report = dg.analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
for result in (report.form_closure, report.force_closure):
    print("\n".join(result.report_lines(internal_forces=False)))

# %% [markdown]
# Form closure fails by rank: $\operatorname{rank} G_n = 1$, so five independent
# motions escape; the first (axis directions come first) is a slide along x,
# in the jaws' face plane.  Force closure fails by rank too: nothing resists a
# moment about the line between the pads.  The witnesses hold by direct
# evaluation:

# %%
grasp = report.grasp
for result in (report.form_closure, report.force_closure):
    cert = result.certificate
    print(f"{cert.kind:>18}: {cert.check(grasp)}")
print("escape twist v =", report.form_closure.certificate.direction)
print("unresisted wrench w =", report.force_closure.certificate.direction)

# %% [markdown]
# In Meshcat, `draw_grasp` draws the unresisted wrench (its moment part, in
# orange, about the jaw line) and `animate_escape` moves the box along its
# escape twist while the fingers stay put.  Open the printed URL and press play.

# %%
from pydrake.geometry import Meshcat

from drakegrasp.visualization.escape import animate_escape

meshcat = Meshcat()
X_WO = scene.plant.EvalBodyPoseInWorld(scene.plant_context, scene.object_body)
dg.draw_grasp(meshcat, grasp, X_WG=X_WO, result=report.force_closure)
animation = animate_escape(meshcat, scene, report, frames=10 if TEST_MODE else 60)
print(meshcat.web_url(), "-", len(animation.times), "animation frames")

# %% [markdown]
# ## 2. The same question in the plane, in pictures
#
# Two hard fingers on opposite faces of a square, offset vertically: the line
# between them makes $\arctan(1/2) \approx 26.6°$ with the normals, so they
# need $\mu > 1/2$.  With $\mu = 0.2$ the squeeze turns the square
# counter-clockwise and nothing turns it back.  `plot_planar_grasp` draws the
# certificate of a "no": the external moment the grasp cannot resist (red) or
# the ghost of the object moved along its escape twist (green, dashed).

# %%
square = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float)
weak = ex.planar_two_finger_square(0.2)
strong = ex.planar_two_finger_square(0.8)
fig, axes = plt.subplots(1, 3, figsize=(13, 4.4))
panels = [
    (weak, dg.force_closure(weak), "mu = 0.2: force closure no"),
    (weak, dg.form_closure(weak), "form closure no: escape ghost"),
    (strong, dg.force_closure(strong), "mu = 0.8: force closure YES"),
]
for ax, (g, r, title) in zip(axes, panels, strict=True):
    dg.plot_planar_grasp(g, ax=ax, outline=square, result=r)
    ax.set_title(title)
    print(f"{title:<32} decided by {r.decided_by:<5} why: {r.why()}")
fig.tight_layout()

# %% [markdown]
# In wrench space $(f_x, f_y, m_z/b)$ the certificate is a plane through the
# origin with every wrench the fingers can apply on one side.  The red arrow is
# the unresisted side: the fingers cannot apply it, so they cannot resist its
# opposite.

# %%
fig = plt.figure(figsize=(6, 5))
ax = fig.add_subplot(projection="3d")
dg.plot_wrench_space(weak, ax=ax, result=dg.force_closure(weak))
for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
    axis.set_major_locator(plt.MaxNLocator(3))
ax.set_title("mu = 0.2: the separating plane")
fig.tight_layout()

# %% [markdown]
# ## 3. The fixes: more friction, a third finger, soft fingers
#
# Each fix attacks what the certificate names.  In the plane, more friction
# widens the cones until the squeeze line fits inside them (above).  In space
# the unresisted wrench is a moment about the jaw line: friction at two points
# on that line can never produce it, whatever $\mu$.  A third finger off the
# line, or soft fingers (a torsional moment about each normal), can.

# %%
two = ex.spatial_two_fingers(0.5)
fixes = {
    "two hard fingers, mu = 0.5": two,
    "two hard fingers, mu = 1.5": ex.spatial_two_fingers(1.5),
    "a third finger below": dg.Grasp(
        [*two.contacts, dg.Contact([0, 0, -0.05], [0, 0, 1], mu=0.5)]
    ),
    "two soft fingers, nu = 0.3": ex.spatial_two_fingers(
        0.5, contact_model="soft_finger", torsional_friction=0.3
    ),
}
for name, g in fixes.items():
    r = dg.force_closure(g)
    verdict = "YES" if r.is_closure else "no "
    print(f"{name:<28} {verdict} decided by {r.decided_by:<3}  {r.why() or ''}")
    assert r.certificate.check(g).holds

# %% [markdown]
# ## 4. A squeeze the hand cannot control (LP3)
#
# With a hand, force closure also needs the hand to control every internal
# force.  **LP3 (uncontrollable squeezing)** looks for an internal force with
# every normal component positive that no joint torque can change; the
# **null-space condition** $\dim N(G) \cap N(J^T) = 0$ is stricter and is
# reported beside it.  Three equator fingers whose joints only slide the tips
# sideways cannot squeeze; a hand that drives only finger 0 along its normal
# has $\dim N(G) \cap N(J^T) = 2$ and still passes LP3 (the joint feels
# finger 0's normal force, which every squeeze needs).

# %%
equator = ex.equator_fingers(0.5)
sliding = np.zeros((equator.num_components, equator.num_contacts))
for i, s in enumerate(equator.component_slices()):
    sliding[s, i] = [0.0, 1.0, 0.0]
one_finger = np.zeros((equator.num_components, 1))
one_finger[0, 0] = 1.0
for name, J in (("tangential joints", sliding), ("one driven finger", one_finger)):
    r = dg.force_closure(equator, hand_jacobian=J)
    print(f"{name}: force closure {'YES' if r.is_closure else 'no'}")
    print("\n".join("  " + line for line in r.internal_forces.report_lines()))
    if not r.is_closure:
        print("  why:", r.why())
        print("  ", r.certificate.check(equator, hand_jacobian=J))

# %% [markdown]
# ## 5. The ellipse that only second-order analysis calls immobilised
#
# Four frictionless point fingers at the ends of an ellipse's axes: the four
# normals pass through the centre, $\operatorname{rank} G_n = 2$, and the escape
# twist is a rotation about the centre.  To first order nothing stops it.  But
# the ghost shows that a finite rotation pushes the ellipse through fingers 2
# and 3 (its long axis swings towards them): curvature immobilises it, and the second-order test
# (`second_order_form_closure`, Rimon–Burdick) says so.  A disc under the same
# fingers really can turn: second order says no.

# %%
from drakegrasp import ContactCurvature, SurfaceCurvature


def axis_fingers(a, b):
    """Four point fingers on the axes of the ellipse x²/a² + y²/b² = 1."""
    contacts = [
        dg.Contact([a, 0], [-1, 0], contact_model="frictionless"),
        dg.Contact([-a, 0], [1, 0], contact_model="frictionless"),
        dg.Contact([0, b], [0, -1], contact_model="frictionless"),
        dg.Contact([0, -b], [0, 1], contact_model="frictionless"),
    ]
    kappa = [a / b**2, a / b**2, b / a**2, b / a**2]  # the ellipse at each finger
    point = SurfaceCurvature.point(planar=True)
    curvatures = [ContactCurvature(SurfaceCurvature((k,)), point) for k in kappa]
    return dg.Grasp(contacts), curvatures


theta = np.linspace(0, 2 * np.pi, 240, endpoint=False)
fig, axes = plt.subplots(1, 2, figsize=(10, 4.6))
for ax, (a, b) in zip(axes, [(0.06, 0.035), (0.05, 0.05)], strict=True):
    g, curvatures = axis_fingers(a, b)
    first = dg.form_closure(g)
    second = dg.second_order_form_closure(g, curvatures, first_order=first)
    outline = np.column_stack([a * np.cos(theta), b * np.sin(theta)])
    dg.plot_planar_grasp(g, ax=ax, outline=outline, result=first)
    shape = "ellipse" if a != b else "disc"
    ax.set_title(
        f"{shape}: first order {'YES' if first else 'no'}, "
        f"second order {'YES' if second.is_closure else 'no'}"
    )
    ax.xaxis.set_major_locator(plt.MaxNLocator(5))
    print(f"{shape}: why not first order: {first.why()}")
    print(f"{shape}: {str(second).splitlines()[0]}")
fig.tight_layout()

# %% [markdown]
# ## 6. Trust, but verify
#
# Every witness is checked by direct evaluation.  On random grasps of every
# contact model (and in the batch engine, with `batch_certificates`) the largest
# violation stays at round-off.

# %%
from drakegrasp.batch.witnesses import batch_certificates, grasp_at

rng = np.random.default_rng(8)
count = 60 if TEST_MODE else 600
worst, checked = 0.0, 0
for k in range(count):
    model = ("frictionless", "hard_finger", "soft_finger")[k % 3]
    P = rng.normal(size=(3, 3))
    P /= np.linalg.norm(P, axis=1, keepdims=True)
    n = -P + 0.9 * rng.normal(size=P.shape)
    g = dg.Grasp(
        [
            dg.Contact(P[i], n[i], mu=0.3, contact_model=model, torsional_friction=0.1)
            for i in range(3)
        ]
    )
    for r in (dg.form_closure(g), dg.force_closure(g), dg.force_closure_exact(g)):
        if r.certificate is not None:
            worst = max(worst, r.certificate.check(g).violation)
            checked += 1
print(f"{checked} single-path witnesses checked, largest violation {worst:.1e}")

K = 200 if TEST_MODE else 2000
P = rng.normal(size=(K, 3, 2))
P /= np.linalg.norm(P, axis=2, keepdims=True)
n = -P + 0.9 * rng.normal(size=P.shape)
batch = dg.batch_force_closure(P, n, mu=0.2)
certs = batch_certificates(P, n, batch, mu=0.2)
violations = [
    certs.certificates[k].check(grasp_at(P, n, k, mu=0.2)).violation
    for k in np.flatnonzero(certs.has_witness)
]
print(
    f"batch: {int((~batch.is_closure).sum())} of {K} planar grasps fail, "
    f"{len(violations)} witnesses, largest violation {max(violations):.1e}"
)
