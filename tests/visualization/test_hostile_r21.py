"""Review r21 of the pictures: hostile arguments are refused with a GraspError.

Every value below once escaped as a raw ``TypeError``/``ValueError``/
``AttributeError``/``RuntimeError``, as a ``SystemExit`` from a Drake
``DRAKE_DEMAND`` (``Cylinder(radius=nan)``), or was drawn silently wrong.  Each
is now an :class:`~drakegrasp.InvalidOptionError` (or another GraspError)
naming the argument and what is valid, raised before anything is drawn.

* ``draw_certificate``: ``radius``/``length`` and the certificate itself.
* ``draw_grasp`` / ``positive_length``: lengths are real numbers (no strings,
  no bools) in ``[DRAW_LENGTH_MIN, DRAW_LENGTH_MAX]``; a force arrow stays
  within the bound too.
* ``animate_escape``: ``frames``, ``duration``, ``amount``, the scene and a
  report of another object body.
* ``wrench_hull``, ``score_colors``, ``exact_cone_mesh``, ``pyramid_mesh``.
* ``set_translucent``, ``visualizer_paths``, ``frame_points``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from pydrake.multibody.tree import ModelInstanceIndex

import drakegrasp as dg
from drakegrasp import GraspError, InvalidOptionError
from drakegrasp.core import examples as ex
from drakegrasp.visualization import (
    exact_cone_mesh,
    frame_points,
    pyramid_mesh,
    score_colors,
    set_translucent,
    visualizer_paths,
    wrench_hull,
    wrench_space_points,
)
from drakegrasp.visualization.escape import MAX_FRAMES, animate_escape
from drakegrasp.visualization.geometry import (
    DRAW_LENGTH_MAX,
    MAX_CONE_SEGMENTS,
    positive_length,
)
from drakegrasp.visualization.meshcat_certificates import draw_certificate
from drakegrasp.visualization.view import VIEW_BOUND

NAN, INF = float("nan"), float("inf")

BAD_LENGTHS = [NAN, INF, -INF, 0.0, -1.0, 1e300, 1e31, "1", "0.01", True, [0.1]]


@pytest.fixture(scope="module")
def box():
    scene = dg.load_scene("parallel_jaw_box")
    report = dg.analyze_grasp(
        scene.plant, scene.plant_context, **scene.analysis_options()
    )
    return scene, report


@pytest.fixture(scope="module")
def two_fingers():
    g = ex.spatial_two_fingers(0.5)
    return g, dg.force_closure(g)  # a "no": an unresisted moment


# ------------------------------------------------------- 1. draw_certificate


@pytest.mark.parametrize("name", ["radius", "length"])
@pytest.mark.parametrize("bad", BAD_LENGTHS, ids=repr)
def test_draw_certificate_refuses_bad_sizes(meshcat, box, name, bad):
    _, report = box
    cert = report.form_closure.certificate
    with pytest.raises(InvalidOptionError, match=name):
        draw_certificate(meshcat, report.grasp, cert, prefix="r21/c", **{name: bad})
    assert not meshcat.HasPath("r21/c/certificate")


def test_draw_certificate_draws_with_valid_sizes(meshcat, box):
    _, report = box
    cert = report.form_closure.certificate
    paths = draw_certificate(
        meshcat, report.grasp, cert, prefix="r21/ok", length=np.float32(0.05)
    )
    assert paths and all(meshcat.HasPath(p) for p in paths)
    assert draw_certificate(
        meshcat, report.grasp, cert, prefix="r21/ok", radius=DRAW_LENGTH_MAX
    )


@pytest.mark.parametrize(
    "bad", [None, "escape twist", 3, {"kind": "escape twist"}], ids=repr
)
def test_draw_certificate_refuses_what_is_no_certificate(meshcat, box, bad):
    _, report = box
    with pytest.raises(InvalidOptionError, match="certificate must be"):
        draw_certificate(meshcat, report.grasp, bad, prefix="r21/none")


def test_draw_certificate_refuses_a_result_for_its_certificate(meshcat, box):
    _, report = box
    with pytest.raises(InvalidOptionError, match="Certificate"):
        draw_certificate(meshcat, report.grasp, report.form_closure, prefix="r21/x")


def test_draw_certificate_refuses_a_certificate_of_another_grasp(
    meshcat, box, two_fingers
):
    _, report = box
    g, result = two_fingers
    # other contacts: another shape of contact rates / null basis
    planar = ex.planar_two_finger_square(0.2)
    planar_cert = dg.force_closure(planar).certificate
    with pytest.raises(InvalidOptionError, match="another grasp"):
        draw_certificate(meshcat, g, planar_cert, prefix="r21/other")
    # same shapes, another reference point
    moved = dg.Grasp(g.contacts, reference_point=[0.3, 0.0, 0.0])
    with pytest.raises(InvalidOptionError, match="reference point"):
        draw_certificate(meshcat, moved, result.certificate, prefix="r21/other")
    # same shapes, another characteristic length
    scaled = dg.Grasp(g.contacts, characteristic_length=7.0)
    with pytest.raises(InvalidOptionError, match="characteristic length"):
        draw_certificate(meshcat, scaled, result.certificate, prefix="r21/other")
    assert not meshcat.HasPath("r21/other/certificate")


@pytest.mark.parametrize("direction", [[NAN] * 6, [0.0] * 6, [INF, 0, 0, 0, 0, 0]])
def test_draw_certificate_refuses_a_forged_direction(meshcat, two_fingers, direction):
    g, result = two_fingers
    forged = dataclasses.replace(result.certificate, direction=np.array(direction))
    with pytest.raises(InvalidOptionError, match="direction"):
        draw_certificate(meshcat, g, forged, prefix="r21/forged")


def test_draw_grasp_refuses_the_certificate_of_another_grasp_before_drawing(
    meshcat, two_fingers
):
    g, result = two_fingers
    moved = dg.Grasp(g.contacts, reference_point=[0.3, 0.0, 0.0])
    with pytest.raises(InvalidOptionError, match="another grasp"):
        dg.draw_grasp(meshcat, moved, result=result, prefix="r21/moved")
    assert not meshcat.HasPath("r21/moved")


# --------------------------------------------------- 2. draw_grasp's lengths


@pytest.mark.parametrize(
    "name", ["size", "cone_height", "point_radius", "frame_length", "force_scale"]
)
@pytest.mark.parametrize("bad", BAD_LENGTHS, ids=repr)
def test_draw_grasp_refuses_bad_lengths(meshcat, box, name, bad):
    _, report = box
    with pytest.raises(InvalidOptionError, match=name):
        dg.draw_grasp(
            meshcat,
            report.grasp,
            result=report.force_closure,
            prefix="r21/lengths",
            **{name: bad},
        )
    assert not meshcat.HasPath("r21/lengths")


@pytest.mark.parametrize("bad", ["1", True, None, NAN, 1e300, -1.0, 0.0], ids=repr)
def test_positive_length_takes_real_lengths_in_range_only(bad):
    with pytest.raises(InvalidOptionError, match="thing"):
        positive_length("thing", bad)


@pytest.mark.parametrize(
    "good", [1, 0.5, np.float32(0.25), np.int64(2), np.array(0.5), DRAW_LENGTH_MAX]
)
def test_positive_length_takes_numpy_reals(good):
    assert positive_length("thing", good) == float(good)


def test_a_force_arrow_beyond_the_bound_is_refused(meshcat):
    g = ex.spatial_two_fingers(0.5)
    huge = [[1e200, 0.0, 0.0], [1e200, 0.0, 0.0]]
    with pytest.raises(InvalidOptionError, match="force_scale"):
        dg.draw_grasp(meshcat, g, result=huge, force_scale=1e29, prefix="r21/huge")
    assert not meshcat.HasPath("r21/huge")
    # the default scale draws huge forces 0.6 b long (no overflow to inf)
    d = dg.draw_grasp(meshcat, g, result=huge, prefix="r21/huge")
    assert any(p.endswith("/force") for p in d.paths)
    assert np.isclose(d.force_scale * 1e200, 0.6 * g.characteristic_length)


@pytest.mark.parametrize("size", [1e-30, 1e-100, 1e-300])
def test_tiny_sizes_draw(meshcat, box, size):
    # Drake refuses to normalise an arrow shorter than 1e-10 itself.
    _, report = box
    d = dg.draw_grasp(
        meshcat, report.grasp, result=report.force_closure, size=size, prefix="r21/t"
    )
    assert d.cone_height == pytest.approx(0.4 * size)
    assert np.all(np.isfinite(d.camera.position_W))


@pytest.mark.parametrize("name", ["show_frames", "on_top", "keep_camera"])
@pytest.mark.parametrize("bad", ["no", None, 1, 0.0])
def test_draw_grasp_flags_are_booleans(meshcat, name, bad):
    with pytest.raises(InvalidOptionError, match=name):
        dg.draw_grasp(meshcat, ex.equator_fingers(0.5), prefix="r21/f", **{name: bad})


@pytest.mark.parametrize(
    "kw",
    [
        {"translucent": "visualizer/hand", "translucent_opacity": "0.3"},
        {"translucent": None, "translucent_opacity": 0.3},
        {"translucent": "visualizer/hand", "translucent_opacity": True},
        {"num_generators": 10**9},
    ],
    ids=repr,
)
def test_draw_grasp_checks_its_options_before_drawing(meshcat, kw):
    with pytest.raises(InvalidOptionError):
        dg.draw_grasp(meshcat, ex.equator_fingers(0.5), prefix="r21/opts", **kw)
    assert not meshcat.HasPath("r21/opts")


def test_draw_grasp_refuses_forces_that_are_not_numbers(meshcat):
    g = ex.spatial_two_fingers(0.5)
    for bad in (["a", "b"], [[1.0, 0, 0], [1j, 0, 0]], 5):
        with pytest.raises(InvalidOptionError):
            dg.draw_grasp(meshcat, g, result=bad, prefix="r21/forces")


# ------------------------------------------------------ 3. animate_escape


@pytest.mark.parametrize(
    "bad", [2.5, "10", True, 1, 0, -1, MAX_FRAMES + 1, 10**5, None, NAN], ids=repr
)
def test_animate_escape_refuses_bad_frames(meshcat, box, bad):
    scene, report = box
    with pytest.raises(InvalidOptionError, match="frames"):
        animate_escape(meshcat, scene, report, frames=bad)


@pytest.mark.parametrize("bad", [INF, NAN, 0.0, -1.0, 1e-9, 1e6, "2"], ids=repr)
def test_animate_escape_refuses_bad_durations(meshcat, box, bad):
    scene, report = box
    with pytest.raises(InvalidOptionError, match="duration"):
        animate_escape(meshcat, scene, report, duration=bad)


@pytest.mark.parametrize("bad", [INF, NAN, 0.0, -1.0, 1e300, "0.5", True], ids=repr)
def test_animate_escape_refuses_bad_amounts(meshcat, box, bad):
    scene, report = box
    with pytest.raises(InvalidOptionError, match="amount"):
        animate_escape(meshcat, scene, report, amount=bad)


@pytest.mark.parametrize(
    "bad", [None, "parallel_jaw_box", 3, object()], ids=["None", "name", "3", "object"]
)
def test_animate_escape_refuses_what_is_no_scene(meshcat, box, bad):
    _, report = box
    with pytest.raises(InvalidOptionError, match="scene_or_plant"):
        animate_escape(meshcat, bad, report)


def test_animate_escape_refuses_the_report_of_another_scene(meshcat, box):
    _, report = box
    sphere = dg.load_scene("three_finger_sphere")
    with pytest.raises(InvalidOptionError, match="box::box"):
        animate_escape(meshcat, sphere, report, prefix="r21/escape")
    assert not meshcat.HasPath("r21/escape")


def test_animate_escape_refuses_another_body_to_move(meshcat, box):
    scene, report = box
    with pytest.raises(InvalidOptionError, match="gripper::left_finger"):
        animate_escape(
            meshcat,
            scene.plant,
            report,
            plant_context=scene.plant_context,
            object_body="gripper::left_finger",
        )


@pytest.mark.parametrize("bad", [["yz"], 3, "ab", ""], ids=repr)
def test_animate_escape_refuses_bad_planes(meshcat, box, bad):
    scene, report = box
    with pytest.raises(InvalidOptionError, match="plane"):
        animate_escape(meshcat, scene, report, plane=bad)


def test_animate_escape_refuses_a_forged_twist(meshcat, box):
    scene, report = box
    cert = report.form_closure.certificate
    for forged in (
        dataclasses.replace(cert, direction=np.full(6, NAN)),
        dataclasses.replace(cert, direction=np.zeros(6)),
        dataclasses.replace(cert, characteristic_length=INF),
        dataclasses.replace(cert, reference_point=None),
    ):
        with pytest.raises(InvalidOptionError):
            animate_escape(meshcat, scene, forged)


def test_animate_escape_takes_numpy_integers_and_the_bounds(meshcat, box):
    scene, report = box
    anim = animate_escape(meshcat, scene, report, frames=np.int64(3), duration=0.01)
    assert len(anim.times) == 6
    anim = animate_escape(meshcat, scene, report, frames=2, amount=100.0)
    assert all(np.all(np.isfinite(X.GetAsMatrix4())) for X in anim.transforms)


# ------------------------------------- 4. hulls, colours and cone meshes


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((0, 3)),
        np.full((3, 10), NAN),
        np.ones(3),
        np.ones((1, 5)),
        np.ones((7, 10)),
        np.full((3, 10), INF),
        np.full((3, 4), 1e200),
        np.ones((3, 4)) * 1j,
        "abc",
        None,
    ],
    ids=lambda a: f"{np.shape(a)}",
)
def test_wrench_hull_refuses_bad_wrenches(bad):
    with pytest.raises(InvalidOptionError, match="W"):
        wrench_hull(bad)


@pytest.mark.parametrize("bad", [NAN, -1e-9, INF, "1e-9", None])
def test_wrench_hull_refuses_bad_tolerances(bad):
    W, _ = wrench_space_points(ex.planar_two_finger_square(0.8))
    with pytest.raises(InvalidOptionError, match="tol"):
        wrench_hull(W, tol=bad)


def test_wrench_hull_keeps_its_answers():
    W, _ = wrench_space_points(ex.planar_two_finger_square(0.8))
    info = wrench_hull(W)
    assert info.rank == 3
    assert wrench_hull(W.tolist()).margin == info.margin
    assert wrench_hull(np.zeros((3, 0))).hull is None


@pytest.mark.parametrize(
    "bad", ["abc", None, [1.0, "a"], [1j, 2.0], [[1.0], [2.0, 3.0]]], ids=repr
)
def test_score_colors_refuses_scores_that_are_not_real(bad):
    with pytest.raises(InvalidOptionError, match="scores"):
        score_colors(bad)


@pytest.mark.parametrize("bad", ["0.5", True, NAN, -0.1, None], ids=repr)
def test_score_colors_refuses_bad_alphas(bad):
    with pytest.raises(InvalidOptionError, match="alpha"):
        score_colors([1.0, 2.0], alpha=bad)


def test_score_colors_of_huge_scores_go_from_red_to_green():
    colours = score_colors([-1.5e308, 0.0, 1.5e308])
    np.testing.assert_allclose(colours[0, :3], [0.85, 0.2, 0.15])  # red
    np.testing.assert_allclose(colours[1, :3], [0.95, 0.8, 0.2])  # yellow
    np.testing.assert_allclose(colours[2, :3], [0.2, 0.7, 0.3])  # green


@pytest.mark.parametrize("bad", [-1.0, NAN, INF, 1e13, "0.5", None], ids=repr)
def test_exact_cone_mesh_refuses_bad_mu(bad):
    with pytest.raises(InvalidOptionError, match="mu"):
        exact_cone_mesh(bad, 1.0)


@pytest.mark.parametrize("bad", [NAN, -1.0, 0.0, 1e300, "1"], ids=repr)
def test_exact_cone_mesh_refuses_bad_heights(bad):
    with pytest.raises(InvalidOptionError, match="height"):
        exact_cone_mesh(0.5, bad)


@pytest.mark.parametrize(
    "bad", [10**9, MAX_CONE_SEGMENTS + 1, 2, 2.5, "32", True, None], ids=repr
)
def test_exact_cone_mesh_refuses_bad_segment_counts(bad):
    with pytest.raises(InvalidOptionError, match="num_segments"):
        exact_cone_mesh(0.5, 1.0, num_segments=bad)


@pytest.mark.parametrize("bad", [0.0, 2.0, NAN, "1"], ids=repr)
def test_cone_meshes_refuse_bad_signs(bad):
    with pytest.raises(InvalidOptionError, match="sign"):
        exact_cone_mesh(0.5, 1.0, sign=bad)
    S = np.array([[1.0, 1, 1], [0.5, -0.25, -0.25], [0.0, 0.4, -0.4]])
    with pytest.raises(InvalidOptionError, match="sign"):
        pyramid_mesh(S, 1.0, sign=bad)


def test_exact_cone_mesh_keeps_valid_cones():
    v, f = exact_cone_mesh(np.float32(0.5), 2, num_segments=np.int64(8), sign=-1)
    assert v.shape == (9, 3) and f.shape == (8, 3)
    np.testing.assert_allclose(np.linalg.norm(v[1:, 1:], axis=1), 1.0)
    v, _ = exact_cone_mesh(0.0, 1.0, num_segments=MAX_CONE_SEGMENTS)
    np.testing.assert_array_equal(v[1:, 1:], 0.0)  # μ = 0: a ray


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((3, 0)),
        np.ones((2, 4)),
        np.array([[0.0, 1, 1], [1, 0, 0], [0, 1, 0]]),
        np.array([[1e-300, 1, 1], [1e300, 0, 0], [0, 1, 0]]),
        np.full((3, 4), NAN),
    ],
    ids=lambda a: f"{a.shape}",
)
def test_pyramid_mesh_refuses_bad_generators(bad):
    with pytest.raises(InvalidOptionError, match="generators"):
        pyramid_mesh(bad, 1.0)


# ------------------------------- 5. translucency, model paths and the camera


@pytest.mark.parametrize(
    "good", [np.float32(0.5), np.float64(0.25), np.int64(1), 1, 0.3], ids=repr
)
def test_set_translucent_takes_numpy_reals(meshcat, recorded, good):
    set_translucent(meshcat, "scene", good)
    assert recorded[("scene", "modulated_opacity")] == pytest.approx(float(good))


@pytest.mark.parametrize(
    "bad", [True, False, np.bool_(True), "0.5", None, NAN, 0.0, 1.5], ids=repr
)
def test_set_translucent_refuses_what_is_no_opacity(meshcat, bad):
    with pytest.raises(InvalidOptionError, match="opacity"):
        set_translucent(meshcat, "scene", bad)


@pytest.mark.parametrize("bad", [None, 3, b"scene", [None], [""], ["a", 3]], ids=repr)
def test_set_translucent_refuses_what_is_no_path(meshcat, bad):
    with pytest.raises(InvalidOptionError, match="paths"):
        set_translucent(meshcat, bad, 0.5)


def test_set_translucent_refuses_what_is_no_meshcat():
    with pytest.raises(InvalidOptionError, match="meshcat"):
        set_translucent(None, "scene", 0.5)


@pytest.mark.parametrize(
    "bad",
    [99, None, 1.5, [99], [None], ModelInstanceIndex(99), ["gripper", 2]],
    ids=repr,
)
def test_visualizer_paths_refuses_what_is_no_model_instance(box, bad):
    scene, _ = box
    scene_graph = scene.diagram.GetSubsystemByName("scene_graph")
    with pytest.raises(InvalidOptionError, match="model instance|ModelInstanceIndex"):
        visualizer_paths(scene.plant, scene_graph, bad)


def test_visualizer_paths_checks_the_scene_graph_and_prefix(box):
    scene, _ = box
    scene_graph = scene.diagram.GetSubsystemByName("scene_graph")
    with pytest.raises(InvalidOptionError, match="scene_graph"):
        visualizer_paths(scene.plant, None, "gripper")
    with pytest.raises(InvalidOptionError, match="prefix"):
        visualizer_paths(scene.plant, scene_graph, "gripper", prefix="")
    with pytest.raises(GraspError, match="plant"):
        visualizer_paths(None, scene_graph, "gripper")
    by_index = visualizer_paths(scene.plant, scene_graph, [scene.hand])
    assert by_index == visualizer_paths(scene.plant, scene_graph, ("gripper",))


@pytest.mark.parametrize(
    "bad", ["1", True, None, NAN, INF, -1.0, 2 * VIEW_BOUND, [1.0]], ids=repr
)
def test_frame_points_refuses_bad_pads(meshcat, bad):
    with pytest.raises(InvalidOptionError, match="pad"):
        frame_points(meshcat, [[0, 0, 0]], pad=bad)


@pytest.mark.parametrize(
    "bad",
    [
        [[1e300, 0, 0], [-1e300, 0, 0]],
        [[2 * VIEW_BOUND, 0, 0]],
        [[NAN, 0, 0]],
        [[1j, 0, 0]],
        "abc",
        None,
        [[0, 0]],
    ],
    ids=repr,
)
def test_frame_points_refuses_points_the_camera_cannot_frame(meshcat, bad):
    with pytest.raises(InvalidOptionError, match="points_W"):
        frame_points(meshcat, bad)


def test_frame_points_at_the_bounds_is_finite(meshcat):
    view = frame_points(
        meshcat, [[VIEW_BOUND, -VIEW_BOUND, 0]], pad=np.float32(0.5 * VIEW_BOUND)
    )
    assert np.all(np.isfinite(view.position_W)) and np.isfinite(view.radius)
    view = frame_points(meshcat, [[0, 0, 0]], pad=np.float64(0.1))
    assert view.radius == pytest.approx(0.5 * np.sqrt(3) * 0.2)


@pytest.fixture
def recorded(monkeypatch):
    """The properties set through Meshcat.SetProperty, by (path, property)."""
    from pydrake.geometry import Meshcat

    seen = {}
    original = Meshcat.SetProperty

    def record(self, path, prop, value, *args, **kwargs):
        seen[(path, prop)] = value
        return original(self, path, prop, value, *args, **kwargs)

    monkeypatch.setattr(Meshcat, "SetProperty", record)
    return seen
