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
# # 3. Friction and force closure
#
# With friction a contact can push in any direction of its **friction cone**, so
# fewer contacts can resist every wrench.  A grasp is in **frictional force
# closure** when internal forces inside the cones exist that balance, strictly
# inside:
#
# $$
# \begin{aligned}
# \operatorname{rank} G = 6\ (3\text{ planar}) \quad\text{and}\quad
# \exists f:\ G f = 0,\ f_i \in \operatorname{int}\mathcal F_i ,
# \end{aligned}
# $$
#
# with the cones of the three models ($b$: the grasp's characteristic length,
# $\nu$: torsional friction):
#
# $$
# \begin{aligned}
# \text{frictionless:}\ & f_n \ge 0, \qquad
# \text{hard finger:}\ \ \|f_t\| \le \mu f_n, \qquad
# \text{soft finger:}\ \ \frac{\|f_t\|}{\mu} + \frac{|m_n|}{b\nu} \le f_n .
# \end{aligned}
# $$

# %%
import os

import matplotlib.pyplot as plt
import numpy as np

import drakegrasp as dg

# tests/tutorials sets this to run the notebook with short loops.
TEST_MODE = os.environ.get("DRAKEGRASP_TUTORIAL_TEST") == "1"
np.set_printoptions(precision=4, suppress=True, linewidth=110)

# %%
from drakegrasp import examples
from drakegrasp.visualization import plot_planar_grasp, plot_wrench_space

SQUARE = [[-1, -1], [1, -1], [1, 1], [-1, 1]]

# %% [markdown]
# ## Frictionless, hard and soft fingers
#
# Three fingers on a sphere's equator, all pushing to the centre: without friction
# the normals meet at the centre and no moment can be resisted (rank 3); with
# friction the tangential forces add moments and the rank becomes 6.  Two fingers
# squeezing a box never resist a moment about the line between them with hard
# fingers (rank 5); soft fingers add exactly that moment.

# %%
cases = {
    "3 frictionless (equator)": examples.equator_fingers(
        0.5, contact_model="frictionless"
    ),
    "3 hard fingers, mu=0.5": examples.equator_fingers(0.5),
    "2 hard fingers, mu=0.5": examples.spatial_two_fingers(0.5),
    "2 soft fingers, mu=0.5, nu=0.2": examples.spatial_two_fingers(
        0.5, contact_model="soft_finger", torsional_friction=0.2
    ),
}
for name, g in cases.items():
    r = dg.force_closure(g)
    verdict = "FORCE CLOSURE" if r.is_closure else "no"
    shape = dg.grasp_matrix(g).shape
    print(f"{name:32s} G {shape}, rank {r.rank}, d* = {r.d_star:.4f} -> {verdict}")

# %% [markdown]
# ## LP2 and the linearised cone
#
# A Coulomb cone is round; an LP needs flat faces.  drakegrasp inscribes a pyramid
# with $n_g$ generators $s_k = [1,\ \mu\cos\frac{2\pi k}{n_g},\ \mu\sin\frac{2\pi
# k}{n_g}]$ and writes it as facets $F_i f_i \ge 0$ (rows of unit length).  **LP2**:
#
# $$
# \begin{aligned}
# d^* = \max_{f,\,d}\ d \quad\text{s.t.}\quad G f &= 0, & F f - \mathbf 1 d &\ge 0,
# & d &\ge 0, & \textstyle\sum_i f_{n,i} &\le N ,
# \end{aligned}
# $$
#
# so $d$ is the distance of the contact forces to the nearest facet.  The **exact**
# program (`force_closure_exact`) replaces each pyramid by its Lorentz cone
# $\|f_t\| \le \mu f_n - \sqrt{1+\mu^2}\,d$ (an SOCP, solved by Clarabel): $d$ is
# then the distance to the round cone.  The pyramid is inscribed, so
# $d^*_{LP2} \le d^*_{exact}$: a polyhedral "yes" is always a true "yes".
#
# The facet of an inscribed $n_g$-gon lies at $\cos(\pi/n_g)$ of the circle's
# radius, so the error of the linearisation falls like $1-\cos(\pi/n_g)\approx
# \frac{\pi^2}{2 n_g^2}$.

# %%
from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter

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
ax1.loglog(
    n_gs, (exact.d_star - lp2) / exact.d_star, "o", label="relative error of LP2"
)
ax1.loglog(n_gs, np.pi**2 / (2 * n_gs**2), "k:", label="$\\pi^2 / (2 n_g^2)$")
ax1.set_xlabel("$n_g$")
# Plain numbers at a few ticks; no labels on the minor ticks (they ran together).
ax1.set_xticks([n for n in (3, 4, 8, 16, 32, 64) if n <= n_gs[-1]])
ax1.yaxis.set_major_locator(LogLocator(subs=(1, 2, 5)))
for axis in (ax1.xaxis, ax1.yaxis):
    axis.set_major_formatter(FormatStrFormatter("%g"))
    axis.set_minor_formatter(NullFormatter())
ax1.legend()
ax1.set_title("the error falls like $1/n_g^2$")
plt.show()

# %% [markdown]
# The error matters for the **verdict** near the boundary.  Two soft fingers squeeze
# a box along $x$, offset from each other so that the line between them leaves the
# normals at an angle $\alpha$ (rotated by $20^\circ$ about the normal, between the
# pyramid's edges).  The exact cone needs $\mu > \tan\alpha$; a pyramid with $n_g$
# generators needs a bit more, and the gap closes as $n_g$ grows.  Bisection on
# $\mu$ finds the critical friction of each model.

# %%
alpha, beta = np.radians(25.0), np.radians(20.0)
offset = np.tan(alpha) * np.array([0.0, np.cos(beta), np.sin(beta)])


def offset_grasp(mu):
    return dg.Grasp(
        [
            dg.Contact(np.r_[-1.0, 0, 0] - offset, [1, 0, 0], mu=mu,
                       contact_model="soft_finger", torsional_friction=0.2),
            dg.Contact(np.r_[1.0, 0, 0] + offset, [-1, 0, 0], mu=mu,
                       contact_model="soft_finger", torsional_friction=0.2),
        ]
    )  # fmt: skip


def critical_mu(decide, lo=0.0, hi=2.0, steps=20 if TEST_MODE else 40):
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if decide(offset_grasp(mid)).is_closure else (mid, hi)
    return hi


mu_exact = critical_mu(dg.force_closure_exact)
n_gs_verdict = (
    [3, 4, 6, 8, 12, 16] if TEST_MODE else [3, 4, 5, 6, 8, 10, 12, 16, 24, 32]
)
mu_poly = [
    critical_mu(lambda g, n=n: dg.force_closure(g, num_generators=n))
    for n in n_gs_verdict
]
print(f"tan(alpha) = {np.tan(alpha):.4f}, exact cone: mu* = {mu_exact:.4f}")
for n, m in zip(n_gs_verdict, mu_poly, strict=True):
    print(f"  n_g = {n:2d}: mu* = {m:.4f}")
plt.figure(figsize=(5, 3.5))
plt.plot(n_gs_verdict, mu_poly, "o-", label="pyramid (LP2)")
plt.axhline(mu_exact, color="k", ls="--", label="exact cone (SOCP)")
plt.xlabel("$n_g$")
plt.ylabel("smallest $\\mu$ giving force closure")
plt.legend()
plt.show()

# %% [markdown]
# ## Wrench cones of one, two and four fingers
#
# In the plane, the cones are exact (two edges each).  Each edge $s$ of contact $i$
# gives a **primitive wrench** $G_i s$; the grasp can resist every wrench exactly
# when the origin lies strictly inside the convex hull of the primitive wrenches
# (moments divided by $b$ so the axes are comparable).  `plot_wrench_space` draws
# the primitive wrenches (coloured by contact), their hull and the origin (green
# inside, red outside).

# %%
grasps = {
    "one finger": dg.Grasp([dg.Contact([-1.0, 0.0], [1.0, 0.0], mu=0.5)]),
    "two fingers, mu=0.3": examples.planar_two_finger_square(0.3),
    "two fingers, mu=0.7": examples.planar_two_finger_square(0.7),
    "four fingers, mu=0.2": examples.planar_square_four_contacts().with_friction(
        0.2, contact_model="hard_finger"
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
    for set_ticks in (ax.set_xticks, ax.set_yticks, ax.set_zticks):
        set_ticks([-1, 0, 1])  # three ticks per axis: five ran together
    assert picture.origin_inside == fc.is_closure
plt.tight_layout()
plt.show()

# %% [markdown]
# The two-finger grasp needs $\mu > 1/2$ (the line between the fingers makes
# $\arctan\frac12$ with the normals): at $\mu=0.3$ the hull misses the origin, at
# $\mu=0.7$ it contains it.  One finger can never surround the origin; four fingers
# with little friction can.
#
# ## LP2 and the exact cone side by side
#
# Both programs return optimal contact forces (contact frames, normal first).  For
# the planar grasp they agree: planar cones are exact polyhedra.  For the spatial
# soft-finger pair above, both balance with $|f_t|/f_n = \tan\alpha$ (the squeeze
# along the line between the contacts), but the round cone leaves that force farther
# from its boundary than the pyramid does, so the SOCP's $d^*$ is larger.

# %%
two = examples.planar_two_finger_square(0.7)
r_lp2, r_exact = dg.force_closure(two), dg.force_closure_exact(two)
print(r_lp2, "\n", r_exact, sep="")
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
    print(
        f"{r.formulation:>7}: d* = {r.d_star:.5f}, |f_t| / f_n per contact = {ratios}"
    )

# %% [markdown]
# **What you learned.**  Friction turns each contact's single column into a cone of
# wrenches; hard fingers need rank 6 from friction, soft fingers add the moment about
# the normal; LP2 decides force closure on inscribed pyramids, never wrongly saying
# "yes", with an error in $d^*$ that falls like $1/n_g^2$ and a critical friction that
# converges to the exact cone's; in the plane the verdict is the picture "origin
# inside the hull of the primitive wrenches".
