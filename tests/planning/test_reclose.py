"""Robustness by re-closing the jaws on the moved object: closed forms on a
cylinder and a box, invariance to motions along the axis, and agreement with
the planner's own contacts when nothing moves."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.geometry import Box, Cylinder
from pydrake.math import RigidTransform

from drakegrasp.planning import plan_grasps
from drakegrasp.planning.planner import object_surface
from drakegrasp.planning.reclose import reclosed_copies, reclosed_robustness
from drakegrasp.planning.surface import ObjectSurface, piece_of_shape

TOL = 1e-4
R = 0.03


def _surface(shape):
    return ObjectSurface.from_pieces([piece_of_shape(shape, RigidTransform(), "o")])


def _one(surface, P, F, a, t, theta=0.0):
    touch, p, n, ok = reclosed_copies(
        surface, P[None], np.asarray(F)[None], np.asarray(a, float)[None],
        np.asarray(t, float)[None], np.array([theta]), tol=TOL,
    )  # fmt: skip
    return touch[0], p[0], n[0], bool(ok[0])


def test_a_cylinder_moved_across_the_axis_meets_the_jaws_where_the_circle_says():
    # jaws along x squeeze a cylinder (axis z) at (∓R, 0, 0); the object moves
    # by t_y: in its frame the jaws' line is y = -t_y, meeting the circle at
    # x = ∓sqrt(R² - t_y²), with the circle's inward normals there
    cyl = _surface(Cylinder(R, 0.1))
    P = np.array([[-R, 0.0, 0.01], [-R, 0.0, -0.01], [R, 0.0, 0.01], [R, 0.0, -0.01]])
    F = [0, 0, 1, 1]
    for ty in (0.0, 0.004, -0.011):
        touch, p, n, ok = _one(cyl, P, F, [1, 0, 0], [0.0, ty, 0.0])
        x = np.sqrt(R**2 - ty**2)
        assert ok and touch.all()
        want = np.array(
            [[-x, -ty, 0.01], [-x, -ty, -0.01], [x, -ty, 0.01], [x, -ty, -0.01]]
        )
        np.testing.assert_allclose(p, want, atol=1e-12)
        inward = -want * [1, 1, 0] / R
        np.testing.assert_allclose(n, inward, atol=1e-12)


def test_motion_along_the_axis_and_about_it_on_a_box_changes_nothing_but_the_spot():
    box = _surface(Box(0.06, 0.1, 0.2))  # faces at x = ±0.03
    P = np.array([[-0.03, 0.01, 0.01], [-0.03, -0.01, -0.01], [0.03, 0.01, 0.0]])
    F = [0, 0, 1]
    # along the axis: the jaws close again on the same spots
    touch, p, n, ok = _one(box, P, F, [1, 0, 0], [0.007, 0.0, 0.0])
    assert ok and touch.all()
    np.testing.assert_allclose(p, P, atol=1e-12)
    np.testing.assert_allclose(n, [[1, 0, 0], [1, 0, 0], [-1, 0, 0]], atol=1e-12)
    # a turn about the axis by θ: the spots turn by -θ about the centre
    theta = 0.2
    touch, p, _, ok = _one(box, P, F, [1, 0, 0], [0.0, 0.0, 0.0], theta)
    c = np.array([0.0, 0.005, 0.0])  # midway between the fingers' centroids
    Rx = np.array(
        [
            [1, 0, 0],
            [0, np.cos(theta), -np.sin(theta)],
            [0, np.sin(theta), np.cos(theta)],
        ]
    )
    np.testing.assert_allclose(p, (P - c) @ Rx + c, atol=1e-12)  # Rᵀ(p - c) + c
    assert ok and touch.all()


def test_a_pad_pushed_past_the_edge_loses_its_contacts():
    box = _surface(Box(0.06, 0.1, 0.2))  # y in [-0.05, 0.05]
    P = np.array([[-0.03, 0.045, 0.0], [-0.03, 0.035, 0.0], [0.03, 0.04, 0.0]])
    F = [0, 0, 1]
    touch, _, _, ok = _one(box, P, F, [1, 0, 0], [0.0, -0.012, 0.0])
    # the object moved -12 mm in y: probes at y' = 0.057, 0.047, 0.052
    assert touch.tolist() == [False, True, False] and not ok


def test_a_tilted_face_touches_at_its_nearest_probe_only():
    # the pad's probes at different depths: only those within TOL of the first
    box = _surface(Box(0.06, 0.1, 0.2))
    P = np.array([[-0.03, 0.0, 0.0], [-0.03008, 0.02, 0.0], [-0.0305, -0.02, 0.0],
                  [0.03, 0.0, 0.0]])  # fmt: skip
    touch, _, _, ok = _one(box, P, [0, 0, 0, 1], [1, 0, 0], [0.0, 0.0, 0.0])
    assert ok and touch.tolist() == [True, True, False, True]


def test_unmoved_copies_are_the_planned_grasp_and_hold(wsg_scene):
    scene = wsg_scene()
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=0.5, seed=3, robustness_samples=4,
    )  # fmt: skip
    surface = object_surface(scene.plant, scene.context, scene.object_body)
    for c in [c for c in result if c.is_closure][:5]:
        P = np.array([k.p_OC for k in c.contacts])
        Nrm = np.array([k.nhat_O for k in c.contacts])
        names = c.contacts[0].finger_body
        F = np.array([0 if k.finger_body == names else 1 for k in c.contacts])
        a = P[F == 1].mean(0) - P[F == 0].mean(0)
        a /= np.linalg.norm(a)
        touch, p, n, ok = _one(surface, P, F, a, np.zeros(3))
        assert ok and touch.all()
        np.testing.assert_allclose(p, P, atol=2 * TOL)
        np.testing.assert_allclose(n, Nrm, atol=1e-6)
        rho = reclosed_robustness(
            surface, P[None], F[None], a[None], mu=0.5, samples=3,
            rng=np.random.default_rng(0), position=0.0, angle_deg=0.0,
            friction=0.0, tol=TOL, contact_model="hard_finger", torsional_friction=None,
            workers=1,
        )  # fmt: skip
        assert rho[0] == 1.0


@pytest.mark.parametrize("samples", [0, 5])
def test_robustness_is_seeded_and_in_range(samples):
    cyl = _surface(Cylinder(R, 0.1))
    P = np.array([[[-R, 0.0, 0.01], [-R, 0.0, -0.01], [R, 0.0, 0.01], [R, 0.0, -0.01]]])
    F = np.array([[0, 0, 1, 1]])
    a = np.array([[1.0, 0, 0]])

    def run(seed):
        return reclosed_robustness(
            cyl, P, F, a, mu=0.5, samples=samples, rng=np.random.default_rng(seed),
            position=3e-3, angle_deg=5.0, friction=0.1, tol=TOL,
            contact_model="hard_finger", torsional_friction=None, workers=1,
        )  # fmt: skip

    assert run(1) == run(1) and 0.0 <= run(1)[0] <= 1.0
    if samples == 0:
        assert run(1)[0] == 0.0


@pytest.mark.parametrize("model", ["hard_finger", "frictionless", "soft_finger"])
def test_copies_too_few_to_hold_skip_the_lp_and_nothing_else(model, monkeypatch):
    # a cylinder between two pads of two probes each: many copies keep one
    # contact per pad; skipping their LPs changes no robustness
    from drakegrasp.planning import reclose

    cyl = _surface(Cylinder(R, 0.1))
    z = 0.004
    P = np.array(
        [
            [[-R, 0.0, z], [-R, 0.0, -z], [R, 0.0, z], [R, 0.0, -z]],
            [[-R, 0.0, 0.02], [-R, 0.0, -0.02], [R, 0.0, 0.02], [R, 0.0, -0.02]],
        ]
    )
    F = np.array([[0, 0, 1, 1], [0, 0, 1, 1]])
    a = np.array([[1.0, 0, 0], [1.0, 0, 0]])

    def run():
        return reclosed_robustness(
            cyl, P, F, a, mu=0.8, samples=64, rng=np.random.default_rng(4),
            position=3e-3, angle_deg=8.0, friction=0.1, tol=TOL, contact_model=model,
            torsional_friction=0.05 if model == "soft_finger" else None, workers=1,
        )  # fmt: skip

    lps = []
    solve = reclose.force_verdicts

    def counted(positions, *args, **kwargs):
        lps.append(len(positions))
        return solve(positions, *args, **kwargs)

    monkeypatch.setattr(reclose, "force_verdicts", counted)
    fast = run()
    skipped = sum(lps)
    touch, _, _, ok = reclosed_copies(
        cyl, np.repeat(P, 64, 0), np.repeat(F, 64, 0), np.repeat(a, 64, 0),
        np.zeros((128, 3)), np.zeros(128), tol=TOL,
    )  # fmt: skip
    monkeypatch.setattr(reclose, "NEVER_CLOSURE", {})
    lps.clear()
    assert np.array_equal(run(), fast)
    assert (skipped < sum(lps)) == (model != "soft_finger")  # soft: no skip
    if model == "hard_finger":  # the unperturbed copies hold with four contacts
        assert touch.sum(axis=1).max() == 4 and fast.max() > 0
