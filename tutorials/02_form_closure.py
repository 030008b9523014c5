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
# # 2. Form closure
#
# A grasp is in **form closure** when the contacts alone, without friction,
# immobilise the object: every object motion makes some contact penetrate.  With
# $\xi$ an object twist, first order says $\dot\psi = G_n^T \xi$, so
#
# $$
# \begin{aligned}
# \text{first-order form closure}\iff\; & G_n^T\xi \ge 0 \Rightarrow \xi = 0
# \iff \operatorname{rank} G_n = 6\ (3 \text{ planar}) \ \text{ and }\ \exists f_n > 0:\ G_n f_n = 0 .
# \end{aligned}
# $$
#
# The second condition is decided by **LP1**:
#
# $$
# \begin{aligned}
# d^* = \max_{f_n,\,d}\ d \quad \text{s.t.}\quad G_n f_n &= 0, & f_n - \mathbf 1 d &\ge 0,
# & d &\ge 0, & \mathbf 1^T f_n &\le N ,
# \end{aligned}
# $$
#
# and first-order form closure holds iff $\operatorname{rank} G_n$ is full and
# $d^* > \text{tol}$.

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
from drakegrasp.visualization import plot_planar_grasp

SQUARE = [[-1, -1], [1, -1], [1, 1], [-1, 1]]

# %% [markdown]
# ## First order: four contacts on a square
#
# `examples.planar_square_four_contacts` puts two contacts on the left/right faces at
# heights $\pm h/2$ and two on the top/bottom faces.  LP1's optimal $f_n$ is a set of
# normal forces that balance with every force at least $d^*$.

# %%
square4 = examples.planar_square_four_contacts()
result = dg.form_closure(square4)
print(result)
print("optimal f_n:", np.concatenate(result.contact_forces))
print(
    "G_n f_n =", dg.normal_grasp_matrix(square4) @ np.concatenate(result.contact_forces)
)
plot_planar_grasp(square4, outline=SQUARE, result=result)
plt.title("first-order form closure (arrows: LP1's f_n)")
plt.show()


# %% [markdown]
# **What $d^*$ says.**  $d^*$ is the smallest normal force of the best balancing set,
# with the budget $\sum f_n \le N$.  Slide the top contact to the left, from
# $x=+h/2$ towards $-h/2$: the moment it balances shrinks, the left/right pair must
# carry less, and with the top contact (contact 3) at $x = -h/2$ their forces reach zero: $d^* \to 0$ and form
# closure is lost (the four normals no longer resist a rotation).


# %%
def square_with_top_at(x):
    """The square grasp with its top contact (contact 3) moved to ``(x, 1)``."""
    c = square4.contacts
    return square4.with_contacts([*c[:3], c[3].with_(position=[x, 1.0])])


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
ax1.set_title("contact 3 at x = -0.25: the left/right pair carries less")
plt.show()
for x, r in zip(xs[::4], runs[::4], strict=True):
    f = np.concatenate(r.contact_forces)
    print(
        f"contact 3 at x = {x:+.2f}: closure {r.is_closure!s:5}, d* = {r.d_star:.3f}, f_n = {f}"
    )

# %% [markdown]
# ## Rank matters as much as $d^*$: first order can be inconclusive
#
# Put four contacts at the ends of the axes of an **ellipse** (semi-axes $a > b$).
# All four normals pass through the centre, so no normal force makes a moment:
# $\operatorname{rank} G_n = 2 < 3$, and the rotation $\xi = (0, 0, 1)$ satisfies
# $G_n^T\xi = 0$.  LP1 still finds balancing normal forces ($d^* > 0$), but the
# first-order test fails: to first order the object can rotate.

# %%
a, b = 1.5, 1.0
frictionless = dict(contact_model="frictionless")
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

# %% [markdown]
# **Second order decides.**  Whether the rotation is possible depends on the
# curvature of the object relative to the fingers.  Rotate the ellipse by $\phi$
# about its centre with the (point) fingers fixed: along the minor axis the ellipse
# gets *wider* (its radius towards a fixed finger on the minor axis grows like
# $b\,(1 + \frac{a^2-b^2}{2a^2}\phi^2)$), so the top and bottom fingers penetrate,
# $\psi \approx -\frac{b\,(a^2-b^2)}{2a^2}\,\phi^2 < 0$, whatever the sign of
# $\phi$.  The rotation is
# blocked at second order: **second-order form closure**.  A **disc** with the same
# four contacts is the counterexample: rotating it changes no distance
# ($\psi \equiv 0$), so it is in **no form closure** of any order.
#
# The signed distances below are computed from the geometry, independently of
# drakegrasp.

# %%
from scipy.optimize import minimize_scalar

t = np.linspace(0, 2 * np.pi, 2001)


def psi_point_to_ellipse(point, phi, a, b):
    """Signed distance of a fixed point to the ellipse rotated by phi (< 0 inside)."""
    c, s = np.cos(-phi), np.sin(-phi)
    x, y = c * point[0] - s * point[1], s * point[0] + c * point[1]  # in body frame
    if a == b:  # a disc: closed form, exact (a minimiser would add 1e-8 noise)
        return np.hypot(x, y) - a
    dist = lambda u: np.hypot(a * np.cos(u) - x, b * np.sin(u) - y)  # noqa: E731
    u0 = t[np.argmin(dist(t))]  # coarse search, then refine the parameter
    step = t[1] - t[0]
    best = minimize_scalar(dist, bounds=(u0 - step, u0 + step), method="bounded",
                           options={"xatol": 1e-12}).fun  # fmt: skip
    return -best if (x / a) ** 2 + (y / b) ** 2 < 1 else best


phis = np.linspace(-0.3, 0.3, 31 if TEST_MODE else 61)
fingers = ellipse4.positions
fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
axes[1].sharey(axes[0])  # same ψ scale: the disc's ψ ≡ 0 shows as flat
for ax, (name, semi) in zip(
    axes[:2], (("ellipse", (a, b)), ("disc", (1.0, 1.0))), strict=True
):
    pts = (
        fingers
        if name == "ellipse"
        else fingers / np.abs(fingers).max(axis=1, keepdims=True)
    )
    for i, finger in enumerate(pts):
        ax.plot(
            phis,
            [psi_point_to_ellipse(finger, p, *semi) for p in phis],
            ls="--" if i % 2 else "-",  # 1 and 3 retrace 0 and 2 (symmetry)
            label=f"contact {i}",
        )
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("rotation $\\phi$ [rad]")
    ax.set_ylabel("$\\psi_i$ [m]" if name == "ellipse" else "")
    ax.set_title(f"{name}: rotating about the centre")
    ax.legend(fontsize=8)
phi_demo = 0.25
outline = np.c_[a * np.cos(t), b * np.sin(t)]
rot = np.array(
    [[np.cos(phi_demo), -np.sin(phi_demo)], [np.sin(phi_demo), np.cos(phi_demo)]]
)
axes[2].fill(*outline.T, alpha=0.2, label="ellipse")
axes[2].fill(*(outline @ rot.T).T, alpha=0.2, label=f"rotated by {phi_demo} rad")
axes[2].scatter(*fingers.T, color="k", zorder=3, label="fingers")
for i, finger in enumerate(fingers):
    axes[2].annotate(str(i), finger, xytext=(6, 4), textcoords="offset points")
axes[2].set_aspect("equal")
axes[2].set_xlim(-1.9, 1.9)
axes[2].set_ylim(-1.4, 1.4)
axes[2].legend(fontsize=8, loc="center left", bbox_to_anchor=(1.02, 0.5))
axes[2].set_title("rotated: it runs into fingers 2, 3")
plt.show()
print(
    "predicted -psi/phi^2 = b (a^2 - b^2) / (2 a^2) =", b * (a**2 - b**2) / (2 * a**2)
)
print("measured -psi/phi^2 at phi = 0.01 (top finger):",
      -psi_point_to_ellipse(fingers[2], 0.01, a, b) / 0.01**2)  # fmt: skip

# %% [markdown]
# So the three cases of the chapter, side by side:
#
# | grasp | rank $G_n$ | LP1 $d^*$ | verdict |
# |---|---|---|---|
# | square, 4 contacts | 3 | $> 0$ | first-order form closure |
# | ellipse, 4 contacts on the axes | 2 | $> 0$ | first order inconclusive; **second-order** form closure (curvature) |
# | disc, 4 contacts | 2 | $> 0$ | **no** form closure (rotation is free) |
#
# drakegrasp decides first order; the second-order analysis above is done by hand.
#
# ## Somov's counts: 4 contacts in the plane, 7 in space
#
# A frictionless contact gives one column of $G_n$.  With $k$ contacts and wrench
# dimension $m$ (3 or 6), $G_n f_n = 0$ with $f_n>0$ and $\operatorname{rank} G_n = m$
# need a null space of dimension $k - m \ge 1$: at least $m+1$ contacts, **4 in the
# plane and 7 in space**.  An experiment: random frictionless contacts on a square
# (or cube), every count tested many times.

# %%
rng = np.random.default_rng(1)
samples = 40 if TEST_MODE else 400


def random_square_contacts(k):
    side = rng.integers(4, size=k)
    s = rng.uniform(-1, 1, size=k)
    normals = np.array([[-1, 0], [1, 0], [0, -1], [0, 1]])[side]
    positions = -normals + s[:, None] * normals[:, ::-1]
    return dg.Grasp(
        [
            dg.Contact(p, n, **frictionless)
            for p, n in zip(positions, normals, strict=True)
        ]
    )


def random_cube_contacts(k):
    face = rng.integers(6, size=k)
    axis, sign = face // 2, np.where(face % 2 == 0, 1.0, -1.0)
    positions = rng.uniform(-1, 1, size=(k, 3))
    positions[np.arange(k), axis] = sign
    normals = np.zeros((k, 3))
    normals[np.arange(k), axis] = -sign
    return dg.Grasp(
        [
            dg.Contact(p, n, **frictionless)
            for p, n in zip(positions, normals, strict=True)
        ]
    )


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
    ax.bar(
        list(r),
        [100 * x for x in r.values()],
        color=["C3" if k <= m else "C0" for k in r],
    )
    ax.axvline(m + 0.5, color="k", ls="--", lw=1)
    ax.set_xlabel("number of random frictionless contacts")
    ax.set_ylabel("% in first-order form closure")
    ax.set_title(f"{label}: none with <= {m} contacts")
plt.show()
assert all(rates["plane (square)"][k] == 0 for k in (2, 3))
assert all(rates["space (cube)"][k] == 0 for k in (5, 6))

# %% [markdown]
# Random sets at the bound pass rarely (seven random contacts on a cube almost never:
# they would need one on every face and moment balance besides), but careful
# placements reach it exactly: four contacts in the plane, seven in space.  For the cube, $G_n$ is $6\times 7$ with rank 6 and a one-dimensional null
# space spanned by a strictly positive vector; drop any contact and closure is lost.

# %%
for g in (examples.planar_square_four_contacts(), examples.cube_seven_contacts()):
    r = dg.form_closure(g)
    drop_one = [
        dg.form_closure(
            g.with_contacts(g.contacts[:i] + g.contacts[i + 1 :])
        ).is_closure
        for i in range(g.num_contacts)
    ]
    null = np.linalg.svd(dg.normal_grasp_matrix(g))[2][-1]
    print(f"{g}: closure {r.is_closure}, rank {r.rank}, d* = {r.d_star:.3f}")
    print("   null space of G_n (sign-normalised):", null * np.sign(null.sum()))
    print("   closure after dropping one contact:", drop_one)

# %% [markdown]
# **What you learned.**  First-order form closure needs both a full-rank $G_n$ and
# LP1's $d^*>0$ (balancing normal forces, all strictly positive); $d^*$ shrinks to 0
# as a grasp approaches the boundary and LP1's $f_n$ shows how the load is shared;
# when the rank test fails, curvature can still immobilise the object (second
# order) or not (the disc); and no fewer than 4 (plane) or 7 (space) frictionless
# contacts can give form closure.
