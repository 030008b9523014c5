"""Second-order form closure on plants, against Drake's own signed distances.

The SDP's verdict is checked by moving the object along ``q + t v + t²/2 a``
(exponential coordinates about the object's origin, fingers fixed) and asking
Drake for every contact pair's signed distance.  Drake's ellipsoid/sphere
distance has a median error of ~7e-7 m but outliers of up to ~1e-4 m while the
pair is separated (always over-estimates) and ~8e-6 m while it penetrates, so:
a "yes" must show some ψ_i below -PENETRATION for every sampled motion; a "no"
must keep every ψ_i above -NOISE along its escape motion.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from free_rig import X_WO, FreeRig
from pydrake.common.eigen_geometry import AngleAxis
from pydrake.geometry import Ellipsoid, Sphere
from pydrake.math import RigidTransform, RotationMatrix

from drakegrasp import (
    Contact,
    ContactCurvature,
    Grasp,
    SurfaceCurvature,
    analyze_grasp,
    second_order_form_closure,
)
from drakegrasp.closure.second_order import build_second_order_program
from drakegrasp.plant import contact_curvatures

R_TIP = 0.01
GAP = 2e-5
NOISE = 1e-5  # Drake's error while a pair penetrates is below ~8e-6 m
PENETRATION = 2e-5
AXES = np.array([0.06, 0.045, 0.03])


class EllipsoidRig(FreeRig):
    """An ellipsoid object and fixed spherical fingertips just off its surface."""

    def __init__(self, axes, tips, *, r=R_TIP):
        super().__init__(Ellipsoid(*axes), [Sphere(r)] * len(tips))
        centres = [
            np.asarray(x, float) - (r + GAP) * np.asarray(n, float) for x, n in tips
        ]
        self.place(X_WO, [RigidTransform(centre) for centre in centres])

    def analyze(self, **kwargs):
        return analyze_grasp(
            self.plant,
            self.ctx,
            object_body=self.object,
            mu=0.0,
            contact_model="frictionless",
            **kwargs,
        )

    def psi_along(self, contacts, v, a, t):
        """Drake's ψ of each contact pair at q + t v + t²/2 a (6-D, about O)."""
        q = t * np.asarray(v) + 0.5 * t * t * np.asarray(a)
        angle = np.linalg.norm(q[3:])
        R = RotationMatrix(AngleAxis(angle, q[3:] / angle)) if angle else None
        X = RigidTransform(R or RotationMatrix(), q[:3])
        self.plant.SetFreeBodyPose(self.ctx, self.object, X_WO.multiply(X))
        query = self.plant.get_geometry_query_input_port().Eval(self.ctx)
        psi = [
            query.ComputeSignedDistancePairClosestPoints(
                c.object_geometry, c.finger_geometry
            ).distance
            for c in contacts
        ]
        self.plant.SetFreeBodyPose(self.ctx, self.object, X_WO)
        return np.array(psi)


def axis_tips(axes, which=(0, 1, 2)):
    tips = []
    for i in which:
        for sign in (1.0, -1.0):
            x = np.zeros(3)
            x[i] = sign * axes[i]
            tips.append((x, -sign * np.eye(3)[i]))
    return tips


def exact_grasp(axes, which=(0, 1, 2), r=R_TIP):
    """The same grasp from the geometry in closed form (no Drake queries)."""
    contacts, curv = [], []
    for x, n in axis_tips(axes, which):
        contacts.append(Contact(x, n, contact_model="frictionless"))
        i = int(np.argmax(np.abs(x)))
        j, k = [m for m in range(3) if m != i]
        # at the end of axis i the principal curvatures are a_i / a_j²
        d = np.eye(3)[j]
        obj = SurfaceCurvature((axes[i] / axes[j] ** 2, axes[i] / axes[k] ** 2), d)
        curv.append(ContactCurvature(obj, SurfaceCurvature.convex(r)))
    return Grasp(contacts), curv


def test_ellipsoid_six_sphere_tips_yes_and_every_sampled_motion_penetrates():
    rig = EllipsoidRig(AXES, axis_tips(AXES))
    report = rig.analyze()
    assert not report.form_closure.is_closure
    so = report.second_order
    assert so is not None and so.is_closure and so.order == 2 and so.dim_w == 3
    # a second route to t*: the exact grasp, curvatures in closed form
    exact = second_order_form_closure(*exact_grasp(AXES))
    assert so.t_star == pytest.approx(exact.t_star, rel=2e-3)
    # sample motions in W with random accelerations
    curv = contact_curvatures(
        rig.plant, rig.ctx, report.contacts, object_body=rig.object
    )
    _, var = build_second_order_program(report.grasp, curv, rank_tol=1e-4)
    rng = np.random.default_rng(7)
    b = report.grasp.characteristic_length
    t = 0.012
    mins = []
    for _ in range(200):
        nu = var.basis @ rng.normal(size=var.basis.shape[1])
        nu /= np.linalg.norm(nu)
        v, a = var.scaling @ nu, var.scaling @ rng.normal(size=6)
        psi = rig.psi_along(report.contacts, v, a, t)
        mins.append(psi.min())
        # Σ λ ψ <= GAP - t²/2 t*/b to second order; the minimum is below that
        bound = GAP - 0.5 * t * t * so.t_star / b
        assert psi.min() < min(-PENETRATION, 0.5 * bound)
    assert max(mins) < -PENETRATION


def test_spheroid_spins_freely_about_its_axis():
    axes = np.array([0.06, 0.035, 0.035])
    rig = EllipsoidRig(axes, axis_tips(axes))
    so = rig.analyze().second_order
    assert not so.is_closure and abs(so.t_star) < 1e-4 and so.escape_verified
    v = so.escape_twist
    assert np.allclose(np.abs(v[3:]) / np.linalg.norm(v[3:]), [1, 0, 0], atol=1e-3)
    report = rig.analyze()
    for t in (0.005, 0.02, 0.05):
        psi = rig.psi_along(report.contacts, v, so.escape_acceleration, t)
        assert psi.min() > -NOISE


def test_two_tips_on_the_minor_axis_escape():
    rig = EllipsoidRig(AXES, axis_tips(AXES, which=(1,)))
    report = rig.analyze()
    so = report.second_order
    assert not so.is_closure and so.t_star < -1e-3 and so.escape_verified
    exact = second_order_form_closure(*exact_grasp(AXES, which=(1,)))
    assert so.t_star == pytest.approx(exact.t_star, rel=2e-3)
    for t in (0.002, 0.01, 0.03):
        psi = rig.psi_along(report.contacts, so.escape_twist, so.escape_acceleration, t)
        assert psi.min() > -NOISE


def test_sphere_scene_never_and_its_escape_keeps_every_finger(scene_cache):
    scene = scene_cache("three_finger_sphere")
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    report = analyze_grasp(scene.plant, ctx, **scene.analysis_options())
    so = report.second_order
    assert not report.form_closure.is_closure
    assert not so.is_closure and so.escape_verified


def test_report_line_and_json(scene_cache):
    scene = scene_cache("parallel_jaw_box")
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    report = analyze_grasp(scene.plant, ctx, **scene.analysis_options())
    assert "second-order form closure" in str(report)
    d = json.loads(json.dumps(report.to_dict()))
    assert d["second_order"]["is_closure"] is False
    assert d["second_order"]["escape_verified"] is True


def test_flat_on_flat_witness_contact_is_reported_undecided(scene_cache):
    """With patches="witness" a pad on a face is one flat-on-flat point, which
    has no second-order model: the report says so instead of failing."""
    scene = scene_cache("parallel_jaw_flat_box")
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    options = {**scene.analysis_options(), "patches": "witness"}
    report = analyze_grasp(scene.plant, ctx, **options)
    so = report.second_order
    assert so.is_closure is None and not so.decided  # not "no": undecided
    assert so.order is None and so.dim_w == -1
    assert "not decided" in so.reason and "not positive" in so.reason
    assert "second-order form closure: not decided" in str(report)
    assert "second-order form closure: no," not in str(report)
    assert report.to_dict()["second_order"]["decided"] is False
