"""Pictures of certificates: Meshcat arrows, the escape animation, ghosts, planes."""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.core import examples as ex
from drakegrasp.visualization.certificate_plots import planar_motion
from drakegrasp.visualization.escape import animate_escape, escape_transform

SQUARE = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float)


def test_draw_grasp_draws_the_unresisted_moment_of_two_hard_fingers(meshcat):
    g = ex.spatial_two_fingers(0.5)
    d = dg.draw_grasp(meshcat, g, result=dg.force_closure(g))
    cert = {p.rsplit("/", 1)[-1] for p in d.paths if "/certificate/" in p}
    assert cert == {"moment", "point"}  # a pure moment about the jaw line
    yes = dg.force_closure(ex.equator_fingers(0.5))
    d = dg.draw_grasp(meshcat, ex.equator_fingers(0.5), result=yes)
    assert not any("/certificate/" in p for p in d.paths)


def test_draw_grasp_draws_an_offset_force_and_an_escape_axis(meshcat):
    g = ex.planar_two_finger_square(0.2, offset=0.5)
    frictionless = g.with_friction(0.0, contact_model="frictionless")
    d = dg.draw_grasp(meshcat, frictionless, result=dg.force_closure(frictionless))
    assert any(p.endswith("/certificate/motion") for p in d.paths) or any(
        p.endswith("/certificate/force") for p in d.paths
    )
    disc = dg.Grasp(
        [
            dg.Contact(
                [np.cos(a), np.sin(a)],
                [-np.cos(a), -np.sin(a)],
                contact_model="frictionless",
            )
            for a in (0.1, 2.0, 4.0)
        ]
    )
    d = dg.draw_grasp(meshcat, disc, result=dg.form_closure(disc))
    assert any(p.endswith("/certificate/axis") for p in d.paths)


def test_escape_transform_is_the_flow_of_the_twist():
    rng = np.random.default_rng(4)
    for _ in range(20):
        twist, p = rng.normal(size=6), rng.normal(size=3)
        x = rng.normal(size=3)
        h = 1e-6
        moved = escape_transform(twist, p, h) @ x
        velocity = twist[:3] + np.cross(twist[3:], x - p)  # [v_p; ω] about p
        assert np.allclose((moved - x) / h, velocity, atol=1e-5)
        # a flow: exp(2t) = exp(t) exp(t)
        X1, X2 = escape_transform(twist, p, 0.3), escape_transform(twist, p, 0.6)
        assert np.allclose((X1 @ X1).GetAsMatrix4(), X2.GetAsMatrix4(), atol=1e-12)
    assert np.allclose(
        escape_transform(np.r_[1.0, 2, 3, 0, 0, 0], p, 2.0).translation(), [2, 4, 6]
    )


def test_planar_motion_agrees_with_the_spatial_flow():
    twist, p = np.array([0.3, -0.2, 1.5]), np.array([0.1, 0.4])
    X = np.array([[1.0, 0.0], [0.0, 2.0], [-1.0, 0.5]])
    moved = planar_motion(twist, p, 0.7, X)
    T = escape_transform(np.r_[twist[:2], 0, 0, 0, twist[2]], np.r_[p, 0], 0.7)
    for x, y in zip(X, moved, strict=True):
        assert np.allclose((T @ np.r_[x, 0])[:2], y)


def test_animate_escape_moves_the_box_along_the_jaw_face(meshcat):
    scene = dg.load_scene("parallel_jaw_box")
    report = dg.analyze_grasp(
        scene.plant, scene.plant_context, **scene.analysis_options()
    )
    anim = animate_escape(meshcat, scene, report, frames=10)
    assert len(anim.times) == 20  # both signs escape: there and back
    X0 = scene.plant.EvalBodyPoseInWorld(scene.plant_context, scene.object_body)
    assert np.allclose(anim.transforms[0].GetAsMatrix4(), X0.GetAsMatrix4())
    # the first escape of the jaw grasp is a slide along x of the object frame
    step = X0.inverse() @ anim.transforms[9]
    assert np.allclose(step.rotation().matrix(), np.eye(3))
    assert abs(step.translation()[0]) > 0 and np.allclose(step.translation()[1:], 0)
    with pytest.raises(dg.GraspError, match="escape twist"):
        animate_escape(meshcat, scene, report.force_closure)


def test_animate_escape_of_a_planar_scene_turns_about_the_plane_normal(meshcat):
    scene = dg.load_scene("planar_gripper_brick")
    report = dg.analyze_grasp(
        scene.plant, scene.plant_context, **scene.analysis_options()
    )
    anim = animate_escape(meshcat, scene, report, frames=5)
    assert np.allclose(anim.twist_O[[0, 4, 5]], 0) and anim.twist_O[3] != 0  # ω about x


def test_plot_planar_grasp_draws_the_ghost_where_the_twist_takes_the_outline(plt):
    g = ex.planar_two_finger_square(0.8)
    r = dg.form_closure(g)
    fig = dg.plot_planar_grasp(g, outline=SQUARE, result=r)
    ghost = fig.certificate.ghost.get_xydata()
    t = 0.25 * g.characteristic_length
    expected = planar_motion(r.certificate.direction, g.reference_point, t, SQUARE)
    assert np.allclose(ghost[: len(SQUARE)], expected)
    no_force = dg.force_closure(ex.planar_two_finger_square(0.2))
    fig = dg.plot_planar_grasp(ex.planar_two_finger_square(0.2), result=no_force)
    assert fig.certificate.kind == "unresisted wrench"


def test_plot_wrench_space_plane_separates_every_primitive_wrench(plt):
    g = ex.planar_two_finger_square(0.2)
    r = dg.force_closure(g)
    fig = dg.plot_wrench_space(g, result=r)
    assert fig.separating_plane is not None
    W, _ = dg.visualization.wrench_space_points(g)
    y, b = r.certificate.separating_twist, g.characteristic_length
    normal = np.array([y[0], y[1], b * y[2]])
    assert np.all(normal @ W <= 1e-9)  # every wrench the grasp can apply
    w = r.certificate.direction
    assert normal @ np.array([w[0], w[1], w[2] / b]) > 0  # the unresisted side
