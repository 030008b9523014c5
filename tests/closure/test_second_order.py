"""Second-order form closure: closed forms, analytic ψ, and a second formulation.

Independent routes used here:
* ψ̈ of each contact by finite differences of closed-form signed distances
  (sphere/sphere, sphere in a spherical cup, plane/sphere, point/ellipsoid by a
  1-D root solve) along ``q + t v + t²/2 a``, against ``G_iᵀ a + vᵀ H_i v``;
* the ellipse and two-finger verdicts in closed form;
* the six-finger ellipsoid SDP against an LP solved by scipy (HiGHS), valid
  because every ``H_i`` is diagonal there;
* sampled motions in W evaluated with exact distances (ellipse, triangle).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

import drakegrasp as dg
from drakegrasp import (
    Contact,
    ContactCurvature,
    Grasp,
    InvalidContactError,
    InvalidGraspError,
    SurfaceCurvature,
    second_order_form_closure,
)
from drakegrasp.closure.second_order import (
    build_second_order_program,
    equilibrium_support,
)
from drakegrasp.core.curvature import contact_hessian, contact_hessians
from drakegrasp.core.grasp import normal_grasp_matrix

POINT2 = SurfaceCurvature.point(planar=True)
POINT3 = SurfaceCurvature.point()
FAST = settings(max_examples=25, deadline=None, derandomize=True)


# ------------------------------------------------------------ motion helpers


def _rot(theta: np.ndarray) -> np.ndarray:
    """exp(S(θ)) (Rodrigues); planar θ is a scalar."""
    theta = np.atleast_1d(np.asarray(theta, dtype=float))
    if theta.size == 1:
        c, s = math.cos(theta[0]), math.sin(theta[0])
        return np.array([[c, -s], [s, c]])
    angle = np.linalg.norm(theta)
    if angle < 1e-300:
        return np.eye(3)
    k = theta / angle
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def _motion(v, a, p, t):
    """(R, x ↦ R (x - p) + p + d) of q + t v + t²/2 a about p."""
    v, a = np.asarray(v, float), np.asarray(a, float)
    d = len(p)
    q = t * v + 0.5 * t * t * a
    R = _rot(q[d:])
    return R, (lambda x: R @ (np.asarray(x) - p) + p + q[:d])


def _second_derivative(psi, h=2e-3):
    """Central second difference with one Richardson step (error O(h⁴))."""

    def d2(s):
        return (psi(s) - 2 * psi(0.0) + psi(-s)) / (s * s)

    return (4 * d2(h / 2) - d2(h)) / 3


def _point_ellipsoid_distance(y, axes):
    """Signed distance from y to the ellipsoid (ellipse) with these semi-axes.

    The closest point is ``x_i = a_i² y_i / (a_i² + μ)`` with μ the root of
    ``Σ (a_i y_i / (a_i² + μ))² = 1`` nearest 0 (Newton from μ = 0), which is the
    right root for points near the surface; μ > 0 outside.
    """
    y, a2 = np.asarray(y, float), np.asarray(axes, float) ** 2
    mu = 0.0
    for _ in range(100):
        q = a2 * y * y / (a2 + mu) ** 2
        f = q.sum() - 1.0
        step = f / (2 * np.sum(q / (a2 + mu)))
        mu += step
        if abs(step) < 1e-17 * (1 + abs(mu)):
            break
    x = a2 * y / (a2 + mu)
    return math.copysign(float(np.linalg.norm(y - x)), mu)


def _ellipsoid_curvature(axes, x):
    """Curvature of the ellipsoid Σ x_i²/a_i² = 1 at x, and its inward normal."""
    ax = np.asarray(axes, float)
    grad = 2 * x / ax**2
    m = grad / np.linalg.norm(grad)
    form = np.diag(2 / ax**2) / np.linalg.norm(grad)
    if len(ax) == 2:
        t = np.array([-m[1], m[0]])
        return SurfaceCurvature((float(t @ form @ t),)), -m
    return SurfaceCurvature.from_shape_form(form, m), -m


def _ellipse_grasp(a, b):
    contacts = [
        Contact([a, 0], [-1, 0]),
        Contact([-a, 0], [1, 0]),
        Contact([0, b], [0, -1]),
        Contact([0, -b], [0, 1]),
    ]
    kappa = [a / b**2, a / b**2, b / a**2, b / a**2]
    curv = [ContactCurvature(SurfaceCurvature((k,)), POINT2) for k in kappa]
    return Grasp(contacts), curv


def _ellipsoid_grasp(axes):
    contacts, curv = [], []
    for i in range(3):
        for sign in (1.0, -1.0):
            x = np.zeros(3)
            x[i] = sign * axes[i]
            k, n = _ellipsoid_curvature(axes, x)
            contacts.append(Contact(x, n))
            curv.append(ContactCurvature(k, POINT3))
    return Grasp(contacts), curv


# ------------------------------------------- H_i against finite differences

angles = st.floats(0, 2 * math.pi)
unit = st.floats(-1, 1)


def _random_motion(rng, d):
    n = 3 if d == 2 else 6
    return rng.normal(size=n), rng.normal(size=n), rng.normal(size=d) * 0.5


@FAST
@given(seed=st.integers(0, 10**6), kind=st.sampled_from(["convex", "cup", "point"]))
def test_hessian_sphere_fingers_match_finite_differences(seed, kind):
    rng = np.random.default_rng(seed)
    R = 0.3 + rng.random()
    C = rng.normal(size=3) * 0.2
    m = rng.normal(size=3)
    m /= np.linalg.norm(m)  # outward normal of the object sphere
    c = C + R * m
    r = {"convex": 0.1 + rng.random(), "cup": R + 0.2 + rng.random(), "point": 0.0}
    r = r[kind]
    if kind == "point":
        finger = POINT3
    elif kind == "cup":
        finger = SurfaceCurvature.concave(r)
    else:
        finger = SurfaceCurvature.convex(r)
    F = c + r * m if kind != "cup" else c - r * m  # the finger sphere's centre
    v, a, p = _random_motion(rng, 3)
    grasp = Grasp([Contact(c, -m)], reference_point=p)

    def psi(t):
        _, move = _motion(v, a, p, t)
        dist = np.linalg.norm(move(C) - F)
        return r - R - dist if kind == "cup" else dist - R - r

    H = contact_hessian(grasp, 0, ContactCurvature(SurfaceCurvature.convex(R), finger))
    Gn = normal_grasp_matrix(grasp)[:, 0]
    assert abs(psi(0.0)) < 1e-12
    expected = Gn @ a + v @ H @ v
    assert _second_derivative(psi) == pytest.approx(expected, rel=1e-4, abs=1e-6)


@FAST
@given(seed=st.integers(0, 10**6), r=st.sampled_from([0.0, 0.05, 0.4]))
def test_hessian_plane_face_matches_finite_differences(seed, r):
    rng = np.random.default_rng(seed)
    m = rng.normal(size=3)
    m /= np.linalg.norm(m)
    c = rng.normal(size=3) * 0.3
    F = c + r * m
    v, a, p = _random_motion(rng, 3)
    finger = SurfaceCurvature.convex(r) if r else POINT3
    grasp = Grasp([Contact(c, -m)], reference_point=p)

    def psi(t):
        R, move = _motion(v, a, p, t)
        return (R @ m) @ (F - move(c)) - r

    H = contact_hessian(grasp, 0, ContactCurvature(SurfaceCurvature.flat(), finger))
    expected = normal_grasp_matrix(grasp)[:, 0] @ a + v @ H @ v
    assert _second_derivative(psi) == pytest.approx(expected, rel=1e-4, abs=1e-6)


@FAST
@given(seed=st.integers(0, 10**6), r=st.sampled_from([0.0, 0.02, 0.3]))
def test_hessian_ellipsoid_matches_finite_differences(seed, r):
    """Non-umbilic curvature with principal directions; exact point distance."""
    rng = np.random.default_rng(seed)
    axes = np.array([0.6, 0.4, 0.25]) * (0.5 + rng.random(3))
    x = rng.normal(size=3)
    x /= np.linalg.norm(x / axes)
    k, n = _ellipsoid_curvature(axes, x)
    F = x - r * n
    v, a, p = _random_motion(rng, 3)
    finger = SurfaceCurvature.convex(r) if r else POINT3
    grasp = Grasp([Contact(x, n)], reference_point=p)

    def psi(t):
        R, move = _motion(v, a, p, t)
        y = R.T @ (F - move(np.zeros(3)))  # finger centre in the object's frame
        return _point_ellipsoid_distance(y, axes) - r

    H = contact_hessian(grasp, 0, ContactCurvature(k, finger))
    expected = normal_grasp_matrix(grasp)[:, 0] @ a + v @ H @ v
    assert abs(psi(0.0)) < 1e-10
    assert _second_derivative(psi) == pytest.approx(expected, rel=1e-4, abs=1e-6)


@FAST
@given(seed=st.integers(0, 10**6))
def test_hessian_planar_ellipse_matches_finite_differences(seed):
    rng = np.random.default_rng(seed)
    axes = np.array([0.5, 0.3]) * (0.5 + rng.random(2))
    phi = rng.random() * 2 * math.pi
    x = axes * np.array([math.cos(phi), math.sin(phi)])
    k, n = _ellipsoid_curvature(axes, x)
    v, a, p = _random_motion(rng, 2)
    grasp = Grasp([Contact(x, n)], reference_point=p)

    def psi(t):
        R, move = _motion(v, a, p, t)
        return _point_ellipsoid_distance(R.T @ (x - move(np.zeros(2))), axes)

    H = contact_hessian(grasp, 0, ContactCurvature(k, POINT2))
    expected = normal_grasp_matrix(grasp)[:, 0] @ a + v @ H @ v
    assert _second_derivative(psi) == pytest.approx(expected, rel=1e-4, abs=1e-6)


def test_hessian_limits_of_sharp_features():
    """A finite curvature of 1e9 approaches the sharp (inf) model."""
    grasp = Grasp([Contact([0.1, 0.2, 0.3], [0, 0, 1])], reference_point=[0.3, 0, 0])
    obj = SurfaceCurvature((2.0, 5.0), [1, 0, 0])
    sharp = contact_hessian(grasp, 0, ContactCurvature(obj, POINT3))
    blunt = contact_hessian(
        grasp, 0, ContactCurvature(obj, SurfaceCurvature((1e9, 1e9)))
    )
    assert np.allclose(sharp, blunt, atol=1e-7)
    edge = SurfaceCurvature.edge([1, 0, 0])
    crossing = SurfaceCurvature.edge([1, 1, 0] / np.sqrt(2))
    sharp = contact_hessian(grasp, 0, ContactCurvature(edge, crossing))
    blunt = contact_hessian(
        grasp,
        0,
        ContactCurvature(
            SurfaceCurvature((0.0, 1e9), [1, 0, 0]),
            SurfaceCurvature((0.0, 1e9), [1, 1, 0] / np.sqrt(2)),
        ),
    )
    assert np.allclose(sharp, blunt, atol=1e-6)


# ---------------------------------------------------------------- verdicts


@FAST
@given(a=st.floats(1.05, 4.0), b=st.floats(0.2, 1.0))
def test_ellipse_four_point_fingers_closed_form(a, b):
    """First order no; second order yes with t* = b (a² - b²) / a³."""
    grasp, curv = _ellipse_grasp(a, b)
    r = second_order_form_closure(grasp, curv)
    assert r.is_closure and r.order == 2 and r.dim_w == 1
    # normalised twists: ω scaled by b_char = a; H = b (b² - a²)/a² on λ=1/2 each
    assert r.t_star == pytest.approx(b * (a * a - b * b) / a**3, rel=1e-6)
    assert r.multipliers[:2] == pytest.approx([0, 0], abs=1e-6)


def test_ellipsoid_six_point_fingers_matches_an_lp():
    axes = np.array([0.06, 0.045, 0.03])
    grasp, curv = _ellipsoid_grasp(axes)
    r = second_order_form_closure(grasp, curv)
    assert r.is_closure and r.order == 2 and r.dim_w == 3
    # Second formulation: every A_i is diagonal on the rotations, so the SDP
    # is the LP max t s.t. -Σ λ_i diag(A_i) >= t, Σ λ = 1, λ >= 0, G_n λ = 0.
    _, var = build_second_order_program(grasp, curv)
    A = var.matrices
    assert np.allclose(A, np.array([np.diag(np.diag(x)) for x in A]), atol=1e-12)
    D = np.array([np.diag(x) for x in A])  # (6, 3)
    Gn = normal_grasp_matrix(grasp)
    cost = np.zeros(7)
    cost[-1] = -1
    lp = linprog(
        cost,
        A_ub=np.hstack([D.T, np.ones((3, 1))]),
        b_ub=np.zeros(3),
        A_eq=np.vstack([np.hstack([Gn, np.zeros((6, 1))]), [1] * 6 + [0]]),
        b_eq=np.append(np.zeros(6), 1),
        bounds=[(0, None)] * 6 + [(None, None)],
        method="highs",
    )
    assert lp.status == 0
    assert r.t_star == pytest.approx(-lp.fun, rel=1e-6)


@FAST
@given(
    angles=st.lists(angles, min_size=2, max_size=6),
    radius=st.floats(0.01, 1.0),
    finger=st.sampled_from(["point", "flat", "convex", "cup"]),
)
def test_disc_is_never_immobilised(angles, radius, finger):
    contacts = [
        Contact(
            -radius * np.array([math.cos(t), math.sin(t)]), [math.cos(t), math.sin(t)]
        )
        for t in angles
    ]
    f = {
        "point": POINT2,
        "flat": SurfaceCurvature.flat(planar=True),
        "convex": SurfaceCurvature.convex(0.3 * radius, planar=True),
        "cup": SurfaceCurvature.concave(2 * radius, planar=True),
    }[finger]
    curv = [ContactCurvature(SurfaceCurvature.convex(radius, planar=True), f)] * len(
        contacts
    )
    r = second_order_form_closure(Grasp(contacts), curv)
    assert not r.is_closure
    assert r.t_star <= 1e-6 or math.isnan(r.t_star)
    assert r.escape_verified


def test_sphere_is_never_immobilised():
    rng = np.random.default_rng(3)
    for _ in range(10):
        n = rng.normal(size=(7, 3))
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        grasp = Grasp([Contact(-0.05 * ni, ni) for ni in n])
        curv = [ContactCurvature(SurfaceCurvature.convex(0.05), POINT3)] * 7
        r = second_order_form_closure(grasp, curv)
        assert not r.is_closure and r.escape_verified
        assert r.t_star <= 1e-6 or math.isnan(r.t_star)


def test_flat_faces_point_fingers_translations_stay_free():
    """Box between parallel faces: W holds the sliding translations; H = 0 on
    them, so the second order says no like the first (t* = 0)."""
    contacts = [
        Contact([0.05, 0.01, 0.0], [-1, 0, 0]),
        Contact([0.05, -0.01, 0.01], [-1, 0, 0]),
        Contact([0.05, 0.0, -0.01], [-1, 0, 0]),
        Contact([-0.05, 0.01, 0.0], [1, 0, 0]),
        Contact([-0.05, -0.01, 0.01], [1, 0, 0]),
        Contact([-0.05, 0.0, -0.01], [1, 0, 0]),
    ]
    grasp = Grasp(contacts)
    curv = [ContactCurvature.point_finger(SurfaceCurvature.flat())] * 6
    H = contact_hessians(grasp, curv)
    assert np.allclose(H[:, :3, :3], 0.0)
    r = second_order_form_closure(grasp, curv)
    assert not r.is_closure and abs(r.t_star) < 1e-6 and r.escape_verified
    # Every motion in W (slides in y, z and the spin about x) keeps every
    # point finger on its plane exactly: check the escape with point-plane ψ.
    v, acc = r.escape_twist, r.escape_acceleration
    for t in (0.05, 0.2):
        R, move = _motion(v, acc, np.zeros(3), t)
        psi = [(move(c.position) - c.position) @ (R @ c.normal) for c in contacts]
        assert min(psi) > -1e-12


def test_first_order_closure_is_kept():
    contacts = [
        Contact([1, 0.5], [-1, 0]),
        Contact([1, -0.5], [-1, 0]),
        Contact([-1, 0.5], [1, 0]),
        Contact([-1, -0.5], [1, 0]),
        Contact([0, -1], [0, 1]),
        Contact([0, 1], [0, -1]),
    ]
    curv = [ContactCurvature.point_finger(SurfaceCurvature.flat(planar=True))] * 6
    r = second_order_form_closure(Grasp(contacts), curv)
    assert r.is_closure and r.order == 1 and r.dim_w == 0


def _triangle():
    """Triangle with three point fingers whose normals meet at x0 inside."""
    verts = np.array([[0.0, 0.0], [1.0, 0.0], [0.3, 0.8]])
    x0 = np.array([0.4, 0.25])
    contacts, dists, lines = [], [], []
    for i in range(3):
        p, q = verts[i], verts[(i + 1) % 3]
        e = (q - p) / np.linalg.norm(q - p)
        n = np.array([-e[1], e[0]])  # inward for a counter-clockwise triangle
        c = p + ((x0 - p) @ e) * e  # foot of the perpendicular from x0
        contacts.append(Contact(c, n))
        dists.append(float(n @ (x0 - c)))
        lines.append((c, n))
    return Grasp(contacts, reference_point=x0), dists, lines


def test_triangle_with_concurrent_normals_is_immobilised_to_second_order():
    """Flat faces and point fingers: first order fails (3 fingers), yet the
    rotation about the normals' common point x0 penetrates every finger by
    d_i (1 - cos φ): H_i = -d_i there (the three-finger immobilisation of
    polygons).  Checked in closed form and with exact point-line distances."""
    grasp, dists, lines = _triangle()
    curv = [ContactCurvature.point_finger(SurfaceCurvature.flat(planar=True))] * 3
    H = contact_hessians(grasp, curv)
    assert [h[2, 2] for h in H] == pytest.approx([-d for d in dists])
    r = second_order_form_closure(grasp, curv)
    assert r.is_closure and r.order == 2 and r.dim_w == 1
    for sign in (1.0, -1.0):
        _, move = _motion([0, 0, sign], [0, 0, 0], grasp.reference_point, 0.1)
        R = _rot(sign * 0.1)
        psi = [(move(c) - c) @ (R @ n) for c, n in lines]
        assert psi == pytest.approx([-d * (1 - math.cos(0.1)) for d in dists])


@pytest.mark.parametrize(
    ("kappa_f", "closed"),
    [(-0.2, True), (-0.1, True), (0.0, False), (0.5, False), (math.inf, False)],
)
def test_concave_fingertips_immobilise_what_convex_ones_cannot(kappa_f, closed):
    """Ellipse (a=2, b=1) pinched at its minor axis by two fingers.  Closed
    form: Q = κ_oκ_f/(κ_o+κ_f) v_x² + (bκ_o-1)(bκ_f+1)/(κ_o+κ_f) ω² per unit λ."""
    a, b = 2.0, 1.0
    ko = b / a**2
    contacts = [Contact([0, b], [0, -1]), Contact([0, -b], [0, 1])]
    finger = POINT2 if math.isinf(kappa_f) else SurfaceCurvature((kappa_f,))
    curv = [ContactCurvature(SurfaceCurvature((ko,)), finger)] * 2
    r = second_order_form_closure(Grasp(contacts), curv)
    assert r.is_closure is closed
    if math.isinf(kappa_f):
        qx, qw = ko, b * ko - 1 - b + b  # point finger: K_f -> inf
        qw = (b * ko - 1) * b
    else:
        qx = ko * kappa_f / (ko + kappa_f)
        qw = (b * ko - 1) * (b * kappa_f + 1) / (ko + kappa_f)
    # normalised twists: b_char = b, so A = diag(b qx, qw / b)
    assert r.t_star == pytest.approx(-max(b * qx, qw / b), abs=1e-7)
    if not closed:
        assert r.escape_verified


def test_invariances():
    grasp, curv = _ellipsoid_grasp(np.array([0.06, 0.045, 0.03]))
    base = second_order_form_closure(grasp, curv)
    rng = np.random.default_rng(0)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    Q *= np.sign(np.linalg.det(Q))
    shift = rng.normal(size=3)
    moved = Grasp(
        [Contact(Q @ c.position + shift, Q @ c.normal) for c in grasp.contacts],
        reference_point=shift + Q @ np.array([0.01, -0.02, 0.03]),
        characteristic_length=grasp.characteristic_length,
    )
    mcurv = [
        ContactCurvature(
            SurfaceCurvature(cc.object.curvatures, Q @ np.array(cc.object.direction)),
            cc.finger,
        )
        for cc in curv
    ]
    r = second_order_form_closure(moved, mcurv)
    assert r.t_star == pytest.approx(base.t_star, rel=1e-6)
    s = 7.0  # scale lengths by s, curvatures by 1/s
    scaled = Grasp([Contact(s * c.position, c.normal) for c in grasp.contacts])
    scurv = [
        ContactCurvature(
            SurfaceCurvature(
                tuple(k / s for k in cc.object.curvatures), cc.object.direction
            ),
            cc.finger,
        )
        for cc in curv
    ]
    assert second_order_form_closure(scaled, scurv).t_star == pytest.approx(
        base.t_star, rel=1e-6
    )
    perm = rng.permutation(6)
    pg = Grasp([grasp.contacts[i] for i in perm])
    pr = second_order_form_closure(pg, [curv[i] for i in perm])
    assert pr.t_star == pytest.approx(base.t_star, rel=1e-6)


def test_ellipse_sampled_motions_penetrate_with_exact_distances():
    """Sampled motions q + t v + t²/2 a with v in W (rotation) and random a:
    some finger penetrates, by at least t²/2 · (weighted bound)."""
    a_, b_ = 0.08, 0.05
    grasp, curv = _ellipse_grasp(a_, b_)
    r = second_order_form_closure(grasp, curv)
    rng = np.random.default_rng(1)
    t = 0.02
    worst = -np.inf
    for _ in range(200):
        v = np.array([0, 0, rng.choice([-1.0, 1.0])])
        acc = rng.normal(size=3) * np.array([0.1, 0.1, 1.0])
        R, move = _motion(v, acc, np.zeros(2), t)
        psi = [
            _point_ellipsoid_distance(R.T @ (c.position - move(np.zeros(2))), [a_, b_])
            for c in grasp.contacts
        ]
        weighted = float(r.multipliers @ psi)
        worst = max(worst, min(psi))
        assert min(psi) <= weighted + 1e-12
        # Σ λ_i ψ_i ≈ t²/2 vᵀ(Σ λ_i H_i)v = -t²/2 t* b for a unit ω (b = a_)
        assert weighted < -0.5 * t * t * 0.8 * r.t_star * a_
    assert worst < 0


def test_bad_inputs():
    grasp, curv = _ellipse_grasp(2, 1)
    with pytest.raises(InvalidContactError, match="4 contacts"):
        second_order_form_closure(grasp, curv[:3])
    with pytest.raises(InvalidContactError, match="not positive"):
        flat = SurfaceCurvature.flat(planar=True)
        second_order_form_closure(grasp, [ContactCurvature(flat, flat)] * 4)
    with pytest.raises(InvalidContactError, match="tangent plane"):
        g3 = Grasp([Contact([0, 0, 0], [0, 0, 1])])
        contact_hessian(
            g3, 0, ContactCurvature(SurfaceCurvature((1, 2), [0, 0, 1]), POINT3)
        )
    with pytest.raises(InvalidContactError, match="sharp in the same"):
        g3 = Grasp([Contact([0, 0, 0], [0, 0, 1])])
        contact_hessian(
            g3, 0, ContactCurvature(SurfaceCurvature.edge([1, 0, 0]), POINT3)
        )
    with pytest.raises(InvalidContactError, match="not valid"):
        SurfaceCurvature((-math.inf,))
    with pytest.raises(InvalidContactError, match="direction"):
        SurfaceCurvature((1.0, 2.0))
    with pytest.raises(InvalidContactError, match="planar"):
        second_order_form_closure(
            grasp, [ContactCurvature.point_finger(SurfaceCurvature.flat())] * 4
        )
    with pytest.raises(InvalidGraspError, match="no equilibrium"):
        g = Grasp([Contact([1, 0], [-1, 0])])
        build_second_order_program(
            g, [ContactCurvature.point_finger(SurfaceCurvature.flat(planar=True))]
        )


def test_no_equilibrium_gives_a_first_order_escape():
    g = Grasp([Contact([1, 0], [-1, 0]), Contact([0, 1], [0, -1])])
    curv = [ContactCurvature.point_finger(SurfaceCurvature.flat(planar=True))] * 2
    assert equilibrium_support(g) == ()
    r = second_order_form_closure(g, curv)
    assert not r.is_closure and r.escape_verified and math.isnan(r.t_star)
    assert np.all(normal_grasp_matrix(g).T @ r.escape_twist > 0)
    assert "no equilibrium" in str(r)
    assert "t* not solved" in str(r) and "nan" not in str(r)  # not "t* = nan"
    assert r.to_dict()["support"] == []


def test_partial_support_uses_the_larger_w():
    """An ellipse pinched at its major axis plus a finger that no equilibrium
    can load: the object escapes by sliding away from that finger, so W is
    taken over the loaded contacts only (W = N(G_nᵀ) over all would say yes)."""
    a, b = 2.0, 1.0
    contacts = [
        Contact([a, 0], [-1, 0]),
        Contact([-a, 0], [1, 0]),
        Contact([0, b], [0, -1]),
    ]
    kappa = [a / b**2, a / b**2, b / a**2]
    curv = [ContactCurvature(SurfaceCurvature((k,)), POINT2) for k in kappa]
    r = second_order_form_closure(Grasp(contacts), curv)
    assert r.support == (0, 1) and r.dim_w == 2
    assert not r.is_closure and r.escape_verified
    assert r.escape_twist[1] < 0  # away from the unloaded finger at +y


# --------------------------------------------- a large tol claims no escape


def test_a_tol_above_t_star_reports_no_escape_that_penetrates():
    """Review r22: with tol >= t* the escape search took a shortfall of up to
    tol as an escape, and reported "the motion v = [0, 0, 0.95] penetrates no
    finger" for the ellipse, which that rotation does penetrate (t* > 0)."""
    grasp, curv = _ellipse_grasp(1.05, 1.0)
    t_star = 1.0 * (1.05**2 - 1.0) / 1.05**3
    assert second_order_form_closure(grasp, curv).is_closure
    for tol in (0.1, 0.5):
        r = second_order_form_closure(grasp, curv, tol=tol)
        assert r.t_star == pytest.approx(t_star, rel=1e-6) and 0 < r.t_star < tol
        assert not r.is_closure and r.order is None  # the verdict is tol's
        assert r.escape_twist is None and not r.escape_verified
        assert "not called immobilised at this tolerance" in r.reason
        assert "penetrates no finger" not in r.reason
    # Independent route: the rotation the old result offered, applied to the
    # ellipse, sinks a finger into it to second order (Σ λ ψ < 0).
    phi = 1e-3
    R = np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
    sunk = [
        _point_ellipsoid_distance(R.T @ c.position, [1.05, 1.0]) for c in grasp.contacts
    ]
    assert min(sunk) < 0


def test_a_true_escape_still_holds_at_a_large_tol():
    # A disc: t* = 0 and the spin escapes with margin 0 at any tol.
    grasp, curv = _ellipse_grasp(1.0, 1.0)
    for tol in (1e-6, 0.1, 0.5):
        r = second_order_form_closure(grasp, curv, tol=tol)
        assert not r.is_closure and r.escape_verified and r.escape_margin >= -1e-6
        assert "penetrates no finger to second order" in r.reason


@pytest.mark.parametrize("tol", [0.6, 1e300, 1e-11, math.inf])
def test_second_order_tol_is_bounded_as_the_first_orders(tol):
    grasp, curv = _ellipse_grasp(2.0, 1.0)
    with pytest.raises(dg.InvalidOptionError, match=r"tol must be .* \[1e-10, 0.5\]"):
        second_order_form_closure(grasp, curv, tol=tol)


def test_a_curvature_flat_only_on_a_tiny_length_says_so():
    """Positive curvatures judged flat on a user's tiny ``b`` are not "not positive".

    At ``b = 1e-12`` m the jaw's 6 mm pads (166.7 1/m) times ``b`` fall under
    ``ISOLATION_TOL``: the message said "not positive: [166.67, 166.67]".
    """
    from drakegrasp.core.curvature import (
        ContactCurvature,
        SurfaceCurvature,
        contact_hessian,
    )

    contacts = [
        dg.Contact([0.0, 0.0, 0.025], [0.0, 0.0, -1.0], mu=0.5),
        dg.Contact([0.0, 0.0, -0.025], [0.0, 0.0, 1.0], mu=0.5),
    ]
    pad = ContactCurvature(SurfaceCurvature.flat(), SurfaceCurvature.convex(0.006))
    for b, words in ((1e-12, "times the grasp's length b = 1e-12 m"), (0.05, None)):
        grasp = dg.Grasp(contacts, characteristic_length=b)
        if words is None:
            contact_hessian(grasp, 0, pad)
            continue
        with pytest.raises(dg.InvalidContactError) as info:
            contact_hessian(grasp, 0, pad)
        assert words in str(info.value)
        assert "not positive" not in str(info.value)
