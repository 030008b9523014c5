"""Review r22 of the pictures: hostile arguments are refused with a GraspError.

The helpers the r21 review did not cover.  Every value below once escaped as a
raw ``TypeError``/``ValueError``/``AttributeError``/``IndexError``/
``RuntimeError``, as a ``SystemExit`` from a Drake ``DRAKE_DEMAND``, hung, or
was drawn silently wrong.  Each is now an
:class:`~drakegrasp.InvalidOptionError` (or another GraspError) naming the
argument and what is valid, raised before anything is drawn.

* ``certificate_plots``: ``planar_motion``, ``plot_escape``,
  ``plot_unresisted_wrench``, ``plot_separating_plane`` (axes, grasp,
  certificate, ``amount``, ``outline``, ``extent``).
* ``snapshot.draw_scene_geometry``: numpy opacities, roles, a scene graph
  the context does not hold.
* ``candidates.draw_candidates``: ``prefix``, ``alpha``, candidates Drake
  cannot pose, checked before the old drawing is deleted;
  ``plot_score_distribution``: its axes, ``bins`` (at most ``MAX_BINS``) and
  scores numpy cannot bin.
* ``wrench_space.wrench_hull``: at most ``MAX_HULL_FACETS`` facets' worth of
  columns; ``plot_wrench_space``: its ``result`` and flags.
* ``escape.escape_transform``: ``twist``, ``p`` and ``t``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from pydrake.geometry import SceneGraph
from pydrake.math import RigidTransform

import drakegrasp as dg
from drakegrasp import GraspError, InvalidOptionError
from drakegrasp.core import examples as ex
from drakegrasp.planning.candidates import GraspCandidate
from drakegrasp.visualization.candidates import (
    MAX_BINS,
    draw_candidates,
    plot_score_distribution,
)
from drakegrasp.visualization.certificate_plots import (
    MAX_EXTENT,
    planar_motion,
    plot_escape,
    plot_separating_plane,
    plot_unresisted_wrench,
)
from drakegrasp.visualization.escape import MAX_AMOUNT, escape_transform
from drakegrasp.visualization.wrench_space import (
    MAX_HULL_FACETS,
    WRENCH_BOUND,
    plot_wrench_space,
    wrench_hull,
)

NAN, INF = float("nan"), float("inf")
SQUARE = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float)


@pytest.fixture(scope="module")
def escape():
    """A planar grasp and its form-closure "no" (an escape twist)."""
    g = ex.planar_two_finger_square(0.8)
    return g, dg.form_closure(g)


@pytest.fixture(scope="module")
def unresisted():
    """A planar grasp and its force-closure "no" (an unresisted wrench)."""
    g = ex.planar_two_finger_square(0.2)
    return g, dg.force_closure(g)


@pytest.fixture(scope="module")
def spatial():
    g = ex.spatial_two_fingers(0.5)
    return g, dg.force_closure(g), dg.form_closure(g)


@pytest.fixture
def ax(plt):
    return plt.subplots()[1]


@pytest.fixture
def ax3(plt):
    return plt.figure().add_subplot(projection="3d")


def _count(ax) -> int:
    return len(ax.get_children())


def _moved(grasp):
    """The same contacts about another reference point (another grasp)."""
    return dg.Grasp(grasp.contacts, reference_point=[0.5, 0.25])


# ----------------------------------------------------------- planar_motion

TWIST, P, X = np.array([0.3, -0.2, 1.5]), np.array([0.1, 0.4]), SQUARE


@pytest.mark.parametrize(
    "bad",
    [None, "abc", [NAN, 0, 1], [INF, 0, 1], np.ones(2), np.ones(6), [1j, 0, 1],
     np.ones((3, 1)), [True, False, True]],
    ids=repr,
)  # fmt: skip
def test_planar_motion_refuses_bad_twists(bad):
    with pytest.raises(InvalidOptionError, match="twist"):
        planar_motion(bad, P, 0.5, X)


@pytest.mark.parametrize(
    "bad", [None, "ab", np.ones(3), [NAN, 0.0], [1e21, 0.0], 1.0], ids=repr
)
def test_planar_motion_refuses_bad_points(bad):
    with pytest.raises(InvalidOptionError, match="p "):
        planar_motion(TWIST, bad, 0.5, X)


@pytest.mark.parametrize("bad", ["1", None, NAN, INF, True, [0.5], 1j], ids=repr)
def test_planar_motion_refuses_bad_parameters(bad):
    with pytest.raises(InvalidOptionError, match="^t must"):
        planar_motion(TWIST, P, bad, X)


@pytest.mark.parametrize(
    "bad",
    [None, "abc", np.ones(2), np.ones((3, 3)), np.ones((2, 2, 2)),
     np.full((2, 2), NAN), [[1e21, 0.0]]],
    ids=lambda a: f"{np.shape(a)}",
)  # fmt: skip
def test_planar_motion_refuses_bad_point_sets(bad):
    with pytest.raises(InvalidOptionError, match="X "):
        planar_motion(TWIST, P, 0.5, bad)


def test_planar_motion_refuses_a_motion_that_overflows():
    with pytest.raises(InvalidOptionError, match="overflow"):
        planar_motion([1e300, 1e300, 1e-11], P, 1e300, X)


def test_planar_motion_keeps_its_answers():
    moved = planar_motion(TWIST, P, 0.7, X)
    assert np.array_equal(planar_motion(TWIST.tolist(), P.tolist(), 0.7, X), moved)
    assert np.array_equal(planar_motion(TWIST, P, np.float64(0.7), X.tolist()), moved)
    assert planar_motion(TWIST, P, 0.7, np.zeros((0, 2))).shape == (0, 2)
    assert np.array_equal(planar_motion([1, 2, 0], [0, 0], 2, [[1, 1]]), [[3, 5]])


# ------------------------------------------------------------- plot_escape


@pytest.mark.parametrize("bad", [None, "ax", 3, "3d", "polar"])
def test_plot_escape_refuses_what_is_no_2d_axes(plt, escape, bad):
    g, r = escape
    if bad == "3d":
        bad = plt.figure().add_subplot(projection="3d")
    elif bad == "polar":
        bad = plt.figure().add_subplot(projection="polar")
    before = _count(bad) if hasattr(bad, "get_children") else 0
    with pytest.raises(InvalidOptionError, match="ax must be a 2-D"):
        plot_escape(bad, g, r.certificate)
    if hasattr(bad, "get_children"):
        assert _count(bad) == before


def test_plot_escape_refuses_what_is_no_planar_grasp(ax, escape, spatial):
    _, r = escape
    before = _count(ax)
    with pytest.raises(GraspError, match="grasp must be"):
        plot_escape(ax, None, r.certificate)
    with pytest.raises(GraspError, match="grasp must be"):
        plot_escape(ax, r.certificate, r.certificate)
    g3, _, form = spatial
    with pytest.raises(InvalidOptionError, match="planar"):
        plot_escape(ax, g3, form.certificate)
    assert _count(ax) == before


@pytest.mark.parametrize("bad", [None, "escape twist", "grasp", "result", "wrench"])
def test_plot_escape_refuses_what_is_no_escape_twist(ax, escape, unresisted, bad):
    g, r = escape
    bad = {
        "grasp": g,
        "result": r,
        "wrench": dg.force_closure(
            g.with_friction(0.0, contact_model="frictionless")
        ).certificate,
    }.get(bad, bad)
    before = _count(ax)
    with pytest.raises(InvalidOptionError, match="cert must be"):
        plot_escape(ax, g, bad)
    assert _count(ax) == before


def test_plot_escape_refuses_the_certificate_of_another_grasp(ax, escape):
    g, r = escape
    before = _count(ax)
    with pytest.raises(InvalidOptionError, match="another grasp"):
        plot_escape(ax, _moved(g), r.certificate, outline=None)
    assert _count(ax) == before


@pytest.mark.parametrize("direction", [[NAN] * 3, [0.0] * 3, [INF, 0.0, 0.0]])
def test_plot_escape_refuses_a_forged_twist(ax, escape, direction):
    g, r = escape
    forged = dataclasses.replace(r.certificate, direction=np.array(direction))
    with pytest.raises(InvalidOptionError, match="direction"):
        plot_escape(ax, g, forged)


def test_plot_escape_draws_an_off_scale_twist_as_the_twist(plt, escape):
    from matplotlib.patches import Polygon

    g, r = escape
    scaled = dataclasses.replace(
        r.certificate, direction=1e300 * r.certificate.direction
    )
    a = plot_escape(plt.subplots()[1], g, r.certificate, outline=Polygon(SQUARE))
    b = plot_escape(plt.subplots()[1], g, scaled, outline=Polygon(SQUARE))
    np.testing.assert_allclose(b.ghost.get_xydata(), a.ghost.get_xydata(), atol=1e-12)
    assert np.all(np.isfinite(b.arrows.U)) and np.all(np.isfinite(b.arrows.V))


@pytest.mark.parametrize(
    "bad", [NAN, INF, -1.0, 0.0, "0.25", None, True, 1e300, MAX_AMOUNT * 1.01, [0.2]],
    ids=repr,
)  # fmt: skip
def test_plot_escape_refuses_bad_amounts(ax, escape, bad):
    g, r = escape
    with pytest.raises(InvalidOptionError, match="amount"):
        plot_escape(ax, g, r.certificate, amount=bad)
    assert not ax.lines and not ax.collections


@pytest.mark.parametrize("bad", ["abc", 3, "array", "nan polygon", "huge polygon"])
def test_plot_escape_refuses_bad_outlines(ax, escape, bad):
    from matplotlib.patches import Polygon

    g, r = escape
    bad = {
        "array": SQUARE,
        "nan polygon": Polygon(np.full((3, 2), NAN)),
        "huge polygon": Polygon(SQUARE * 1e25),
    }.get(bad, bad)
    with pytest.raises(InvalidOptionError, match="outline"):
        plot_escape(ax, g, r.certificate, outline=bad)
    assert not ax.lines and not ax.collections


def test_plot_escape_takes_numpy_amounts_and_the_bound(ax, escape):
    g, r = escape
    a = plot_escape(ax, g, r.certificate, amount=np.float32(0.25))
    b = plot_escape(ax, g, r.certificate, amount=0.25)
    assert np.array_equal(a.arrows.U, b.arrows.U)
    assert np.all(
        np.isfinite(plot_escape(ax, g, r.certificate, amount=MAX_AMOUNT).arrows.U)
    )


# -------------------------------------------------- plot_unresisted_wrench


@pytest.mark.parametrize("bad", [None, "ax", "3d"])
def test_plot_unresisted_wrench_refuses_what_is_no_2d_axes(plt, unresisted, bad):
    g, r = unresisted
    if bad == "3d":
        bad = plt.figure().add_subplot(projection="3d")
    with pytest.raises(InvalidOptionError, match="ax must be a 2-D"):
        plot_unresisted_wrench(bad, g, r.certificate)


def test_plot_unresisted_wrench_refuses_bad_grasps(ax, unresisted, spatial):
    g, r = unresisted
    with pytest.raises(GraspError, match="grasp must be"):
        plot_unresisted_wrench(ax, None, r.certificate)
    g3, force, _ = spatial
    with pytest.raises(InvalidOptionError, match="planar"):
        plot_unresisted_wrench(ax, g3, force.certificate)
    with pytest.raises(InvalidOptionError, match="another grasp"):
        plot_unresisted_wrench(ax, _moved(g), r.certificate)
    assert not ax.patches and not ax.collections


@pytest.mark.parametrize("bad", [None, "result", "escape", "zero", "nan"])
def test_plot_unresisted_wrench_refuses_bad_certificates(ax, unresisted, escape, bad):
    g, r = unresisted
    bad = {
        "result": r,
        "escape": escape[1].certificate,
        "zero": dataclasses.replace(r.certificate, direction=np.zeros(3)),
        "nan": dataclasses.replace(r.certificate, direction=np.full(3, NAN)),
    }.get(bad, bad)
    with pytest.raises(InvalidOptionError, match="cert must be|direction"):
        plot_unresisted_wrench(ax, g, bad)
    assert not ax.patches and not ax.collections


def test_plot_unresisted_wrench_keeps_its_picture(plt, unresisted):
    g, r = unresisted
    a = plot_unresisted_wrench(plt.subplots()[1], g, r.certificate)
    scaled = dataclasses.replace(
        r.certificate, direction=1e300 * r.certificate.direction
    )
    b = plot_unresisted_wrench(plt.subplots()[1], g, scaled)
    np.testing.assert_allclose(b.point.get_offsets(), a.point.get_offsets())


# --------------------------------------------------- plot_separating_plane


@pytest.mark.parametrize(
    "bad",
    [NAN, INF, -1.0, 0.0, "1", None, True, 1e300, 1.01 * MAX_EXTENT, [1.0]],
    ids=repr,
)
def test_plot_separating_plane_refuses_bad_extents(ax3, unresisted, bad):
    g, r = unresisted
    with pytest.raises(InvalidOptionError, match="extent"):
        plot_separating_plane(ax3, g, r.certificate, bad)
    assert not ax3.collections


@pytest.mark.parametrize("bad", [None, "ax", "2d"])
def test_plot_separating_plane_refuses_what_is_no_3d_axes(ax, unresisted, bad):
    g, r = unresisted
    bad = ax if bad == "2d" else bad
    with pytest.raises(InvalidOptionError, match="ax must be a 3-D"):
        plot_separating_plane(bad, g, r.certificate, 1.0)
    assert not ax.collections


@pytest.mark.parametrize(
    "bad", [None, "escape", "no twist", "zero twist", "nan twist", "wide twist",
            "huge twist"],
)  # fmt: skip
def test_plot_separating_plane_refuses_bad_certificates(ax3, unresisted, escape, bad):
    g, r = unresisted
    c = r.certificate
    bad = {
        "escape": escape[1].certificate,
        "no twist": dataclasses.replace(c, separating_twist=None),
        "zero twist": dataclasses.replace(c, separating_twist=np.zeros(3)),
        "nan twist": dataclasses.replace(c, separating_twist=np.full(3, NAN)),
        "wide twist": dataclasses.replace(c, separating_twist=np.ones(6)),
        "huge twist": dataclasses.replace(c, separating_twist=np.full(3, 1e300)),
    }.get(bad, bad)
    with pytest.raises(InvalidOptionError, match="cert must be|separating_twist"):
        plot_separating_plane(ax3, g, bad, 1.0)
    assert not ax3.collections


def test_plot_separating_plane_refuses_other_grasps(ax3, unresisted, spatial):
    g, r = unresisted
    with pytest.raises(InvalidOptionError, match="another grasp"):
        plot_separating_plane(
            ax3, dg.Grasp(g.contacts, characteristic_length=7.0), r.certificate, 1.0
        )
    g3, force, _ = spatial
    with pytest.raises(InvalidOptionError, match="planar"):
        plot_separating_plane(ax3, g3, force.certificate, 1.0)
    with pytest.raises(GraspError, match="grasp must be"):
        plot_separating_plane(ax3, "grasp", r.certificate, 1.0)
    assert not ax3.collections


def test_plot_separating_plane_takes_numpy_extents(plt, unresisted):
    g, r = unresisted
    drawn = []
    for extent in (np.float32(2.0), 2.0, np.int64(2)):
        ax = plt.figure().add_subplot(projection="3d")
        out = plot_separating_plane(ax, g, r.certificate, extent)
        ax.figure.canvas.draw()  # a 3-D collection has its paths once projected
        drawn.append(out.plane.get_paths()[0].vertices)
    np.testing.assert_allclose(drawn[0], drawn[1], rtol=1e-12)
    np.testing.assert_array_equal(drawn[2], drawn[1])


def test_plot_separating_plane_takes_what_plot_wrench_space_passes(ax3, unresisted):
    g, r = unresisted
    assert MAX_EXTENT >= 1.1 * WRENCH_BOUND  # plot_wrench_space's largest extent
    out = plot_separating_plane(ax3, g, r.certificate, MAX_EXTENT)
    ax3.set_xlim(-MAX_EXTENT, MAX_EXTENT)
    ax3.set_ylim(-MAX_EXTENT, MAX_EXTENT)
    ax3.set_zlim(-MAX_EXTENT, MAX_EXTENT)
    ax3.figure.canvas.draw()
    assert np.all(np.isfinite(out.plane.get_paths()[0].vertices))


# ------------------------------------------------------- plot_wrench_space


def test_plot_wrench_space_refuses_a_result_of_another_grasp_before_drawing(
    ax3, unresisted
):
    g, r = unresisted
    with pytest.raises(InvalidOptionError, match="another grasp"):
        plot_wrench_space(_moved(g), ax=ax3, result=r)
    assert not ax3.collections


@pytest.mark.parametrize("bad", ["no", 3, "certificate"])
def test_plot_wrench_space_refuses_what_is_no_result(ax3, unresisted, bad):
    g, r = unresisted
    bad = r.certificate if bad == "certificate" else bad
    with pytest.raises(InvalidOptionError, match="result"):
        plot_wrench_space(g, ax=ax3, result=bad)
    assert not ax3.collections


def test_plot_wrench_space_refuses_a_forged_separating_twist(ax3, unresisted):
    g, r = unresisted
    forged = dataclasses.replace(
        r, certificate=dataclasses.replace(r.certificate, separating_twist=np.zeros(3))
    )
    with pytest.raises(InvalidOptionError, match="separating_twist"):
        plot_wrench_space(g, ax=ax3, result=forged)
    assert not ax3.collections


@pytest.mark.parametrize("name", ["hull", "rays"])
@pytest.mark.parametrize("bad", ["no", None, 1, 0.0])
def test_plot_wrench_space_flags_are_booleans(ax3, unresisted, name, bad):
    g, _ = unresisted
    with pytest.raises(InvalidOptionError, match=name):
        plot_wrench_space(g, ax=ax3, **{name: bad})
    assert not ax3.collections


def test_plot_wrench_space_still_draws_the_plane_of_its_own_no(ax3, unresisted):
    g, r = unresisted
    out = plot_wrench_space(g, ax=ax3, result=r, hull=np.bool_(True))
    assert out.separating_plane is not None
    yes = ex.planar_two_finger_square(0.8)
    assert plot_wrench_space(yes, result=dg.force_closure(yes)).separating_plane is None


# ------------------------------------------------------------- wrench_hull


@pytest.mark.parametrize(("m", "most"), [(2, 10**6), (3, 500_002), (6, 184)])
def test_wrench_hull_refuses_more_columns_than_its_facet_bound(m, most):
    with pytest.raises(InvalidOptionError, match="MAX_HULL_FACETS"):
        wrench_hull(np.zeros((m, most + 1)))
    assert MAX_HULL_FACETS == 10**6


def test_wrench_hull_refuses_a_realistic_spatial_hull_that_took_minutes():
    # 3 contacts x 256 generators: Qhull ran > 2 minutes (4 x 128: 41 s, 1 GB)
    W = np.zeros((6, 3 * 256))
    with pytest.raises(InvalidOptionError, match=r"at most 184 columns"):
        wrench_hull(W)


def test_wrench_hull_takes_the_most_columns_of_its_bound():
    W = np.random.default_rng(3).normal(size=(6, 184))
    info = wrench_hull(W)
    assert info.hull is not None and info.rank == 6


# -------------------------------------------------------- escape_transform

TW6, P3 = np.array([1.0, 2, 3, 0.1, 0.2, 0.3]), np.zeros(3)


@pytest.mark.parametrize(
    "bad",
    [None, "abcdef", np.ones(3), np.ones(7), np.ones((2, 3)), [NAN] * 6,
     [INF, 0, 0, 0, 0, 0], np.ones(6) * 1j, 3.0],
    ids=repr,
)  # fmt: skip
def test_escape_transform_refuses_bad_twists(bad):
    with pytest.raises(InvalidOptionError, match="twist"):
        escape_transform(bad, P3, 1.0)


@pytest.mark.parametrize(
    "bad", [None, "abc", np.ones(2), [NAN, 0, 0], [1e21, 0, 0], np.ones((1, 3))],
    ids=repr,
)  # fmt: skip
def test_escape_transform_refuses_bad_points(bad):
    with pytest.raises(InvalidOptionError, match="p "):
        escape_transform(TW6, bad, 1.0)


@pytest.mark.parametrize("bad", ["1", None, True, INF, NAN, [1.0]], ids=repr)
def test_escape_transform_refuses_bad_parameters(bad):
    # t = inf ended the program: Drake's MakeZRotation DRAKE_DEMANDs a finite angle
    with pytest.raises(InvalidOptionError, match="^t must"):
        escape_transform(TW6, P3, bad)


@pytest.mark.parametrize(
    ("twist", "t"),
    [([0, 0, 0, 1e200, 0, 0], 1.0), ([1e300, 0, 0, 0, 0, 0], 1e10),
     ([1e300, 0, 0, 1e-11, 0, 0], 1.0), ([0, 0, 0, 2.0, 0, 0], 1e308)],
)  # fmt: skip
def test_escape_transform_refuses_a_motion_that_overflows(twist, t):
    with pytest.raises(InvalidOptionError, match="overflow"):
        escape_transform(twist, P3, t)


def test_escape_transform_keeps_its_answers():
    X = escape_transform(TW6, P3, 0.3).GetAsMatrix4()
    np.testing.assert_array_equal(
        escape_transform(TW6.tolist(), [0, 0, 0], np.float64(0.3)).GetAsMatrix4(), X
    )
    np.testing.assert_array_equal(
        escape_transform([1, 2, 3, 0, 0, 0], P3, 2).translation(), [2, 4, 6]
    )
    assert np.all(np.isfinite(escape_transform(TW6, P3, 1e300).GetAsMatrix4()))


# ---------------------------------------------------- draw_scene_geometry


@pytest.fixture(scope="module")
def box():
    return dg.load_scene("parallel_jaw_box")


@pytest.mark.parametrize(
    "good", [np.float32(0.5), np.array(0.5), np.int64(1)], ids=repr
)
def test_draw_scene_geometry_takes_numpy_opacities(meshcat, box, good):
    scene_graph = box.diagram.GetSubsystemByName("scene_graph")
    paths = dg.draw_scene_geometry(
        meshcat, scene_graph, box.context, prefix="r22/snap", opacity=good
    )
    assert paths and all(meshcat.HasPath(p) for p in paths)


@pytest.mark.parametrize(
    "bad", [np.float32(0.0), np.array([0.5]), 0.5j, "0.5", np.bool_(True), 1e300],
    ids=repr,
)  # fmt: skip
def test_draw_scene_geometry_refuses_bad_opacities(meshcat, box, bad):
    scene_graph = box.diagram.GetSubsystemByName("scene_graph")
    with pytest.raises(InvalidOptionError, match="opacity"):
        dg.draw_scene_geometry(meshcat, scene_graph, box.context, opacity=bad)


@pytest.mark.parametrize("bad", [["illustration"], {"proximity": 1}, 3, b"proximity"])
def test_draw_scene_geometry_refuses_roles_that_are_no_role(meshcat, box, bad):
    scene_graph = box.diagram.GetSubsystemByName("scene_graph")
    with pytest.raises(InvalidOptionError, match="role"):
        dg.draw_scene_geometry(meshcat, scene_graph, box.context, role=bad)


def test_draw_scene_geometry_refuses_a_scene_graph_the_context_does_not_hold(
    meshcat, box
):
    meshcat.Delete("r22/alone")
    with pytest.raises(InvalidOptionError, match="context"):
        dg.draw_scene_geometry(meshcat, SceneGraph(), box.context, prefix="r22/alone")
    assert not meshcat.HasPath("r22/alone")


def test_draw_scene_geometry_refuses_what_is_no_meshcat(box):
    scene_graph = box.diagram.GetSubsystemByName("scene_graph")
    for bad in (None, "meshcat", object()):
        with pytest.raises(InvalidOptionError, match="meshcat"):
            dg.draw_scene_geometry(bad, scene_graph, box.context)


# -------------------------------------------------------- draw_candidates

JOINTS = ("gripper::left_finger_joint", "gripper::right_finger_joint")


def _candidate(**changes) -> GraspCandidate:
    """A candidate of the jaw of ``parallel_jaw_box`` (its palm is welded)."""
    fields = dict(
        sample=0, hand_base="gripper::palm", X_WH=RigidTransform(),
        X_WO=RigidTransform(), q_hand=np.array([0.025, 0.025]), joint_names=JOINTS,
        closing_signs=(1.0, 1.0), opening=0.1, contacts=(),
        reference_point=np.zeros(3), contact_options={}, is_closure=True,
        d_star=0.5, rank=6, epsilon=0.1, robustness=1.0, score=1.0,
    )  # fmt: skip
    fields.update(changes)
    return GraspCandidate(**fields)


class _Posed:
    """A duck-typed candidate: poses the jaw, but names its joints as given."""

    def __init__(self, joint_names):
        self._c = _candidate()
        self.joint_names = joint_names
        self.hand_base, self.score, self.is_closure = "gripper::palm", 1.0, True

    def apply(self, plant, context):
        self._c.apply(plant, context)


GOOD = [_candidate(score=2.0), _candidate(q_hand=np.array([0.01, 0.01]))]


def _drawn(meshcat, box, prefix="r22/cands"):
    """Draw the two good candidates under ``prefix``; their paths."""
    d = draw_candidates(meshcat, box.plant, box.context, GOOD, prefix=prefix)
    assert all(meshcat.HasPath(p) for p in d.paths)
    return d.paths


@pytest.mark.parametrize("bad", [None, "", "/", 3, b"cands"], ids=repr)
def test_draw_candidates_refuses_bad_prefixes(meshcat, box, bad):
    paths = _drawn(meshcat, box, prefix="r22/keep")
    with pytest.raises(InvalidOptionError, match="prefix"):
        draw_candidates(meshcat, box.plant, box.context, GOOD, prefix=bad)
    assert all(meshcat.HasPath(p) for p in paths)  # "" once deleted everything


@pytest.mark.parametrize("bad", ["x", NAN, 2.0, None], ids=repr)
def test_draw_candidates_checks_alpha_without_candidates(meshcat, box, bad):
    with pytest.raises(InvalidOptionError, match="alpha"):
        draw_candidates(meshcat, box.plant, box.context, [], alpha=bad)


@pytest.mark.parametrize(
    "bad",
    ["base", "joint", "nan q", "nan pose", "base None", "no apply", "posed joint",
     "posed joint int", "posed names None"],
)  # fmt: skip
def test_draw_candidates_checks_every_candidate_before_deleting(meshcat, box, bad):
    class NoApply:
        score, is_closure, hand_base, joint_names = 1.0, True, "gripper::palm", JOINTS

    bad = {
        "base": _candidate(hand_base="wsg::body"),
        "joint": _candidate(joint_names=("gripper::nope", JOINTS[1])),
        "nan q": _candidate(q_hand=np.array([NAN, 0.0])),
        "nan pose": _candidate(X_WH=RigidTransform([NAN, 0.0, 0.0])),
        "base None": _candidate(hand_base=None),
        "no apply": NoApply(),
        "posed joint": _Posed(("gripper::nope",)),
        "posed joint int": _Posed((3,)),
        "posed names None": _Posed(None),
    }[bad]
    paths = _drawn(meshcat, box)
    with pytest.raises(GraspError):
        draw_candidates(
            meshcat, box.plant, box.context, [GOOD[0], bad], prefix="r22/cands"
        )
    assert all(meshcat.HasPath(p) for p in paths)  # the old drawing is kept


def test_draw_candidates_draws_as_before(meshcat, box):
    d = draw_candidates(meshcat, box.plant, box.context, GOOD, prefix="r22/same")
    assert d.paths == ("r22/same/0", "r22/same/1")
    np.testing.assert_array_equal(d.scores, [2.0, 1.0])
    assert meshcat.HasPath("r22/same/1/left_finger/g0")
    empty = draw_candidates(meshcat, box.plant, box.context, [], prefix="r22/same")
    assert empty.paths == () and empty.colors.shape == (0, 4)
    assert not meshcat.HasPath("r22/same/0")


# ------------------------------------------------- plot_score_distribution


class _Scored:
    """What plot_score_distribution reads of a candidate."""

    def __init__(self, score, is_closure=True):
        self.score, self.is_closure = score, is_closure


ROWS = [_Scored(float(i), i % 2 == 0) for i in range(6)]


@pytest.mark.parametrize("bad", ["ax", 3, "3d", "polar"])
def test_plot_score_distribution_refuses_what_is_no_2d_axes(plt, bad):
    if bad in ("3d", "polar"):
        bad = plt.figure().add_subplot(projection=bad)
    with pytest.raises(InvalidOptionError, match="ax must be a 2-D"):
        plot_score_distribution(ROWS, ax=bad)
    if hasattr(bad, "patches"):
        assert not bad.patches


@pytest.mark.parametrize("bad", [MAX_BINS + 1, 10**9, 0, 2.0, True, "30"], ids=repr)
def test_plot_score_distribution_refuses_bad_bin_counts(plt, bad):
    # 10**5 bins took 90 s and 2 GB; more hung
    with pytest.raises(InvalidOptionError, match="bins"):
        plot_score_distribution(ROWS, bins=bad)


@pytest.mark.parametrize(
    "scores", [[NAN, 1.0], [INF, 1.0], [-1.5e308, 1.5e308]], ids=repr
)
def test_plot_score_distribution_refuses_scores_it_cannot_bin(plt, scores):
    with pytest.raises(InvalidOptionError, match="score"):
        plot_score_distribution([_Scored(s) for s in scores])


def test_plot_score_distribution_bins_scores_a_few_ulps_apart(plt):
    # numpy cannot make 30 bins of [0.3, 0.1 + 0.2]: a ValueError escaped
    ax = plot_score_distribution([_Scored(0.3), _Scored(0.1 + 0.2, False)])
    assert sum(p.get_height() for p in ax.patches) == 2
    ax = plot_score_distribution([_Scored(1e300), _Scored(np.nextafter(1e300, 2e300))])
    assert sum(p.get_height() for p in ax.patches) == 2
    ax = plot_score_distribution(ROWS, bins=np.int64(MAX_BINS))
    assert sum(p.get_height() for p in ax.patches) == len(ROWS)


def test_plot_planar_grasp_refuses_another_grasps_certificate_before_drawing():
    # The outline, cones and contacts were drawn, then plot_escape raised.
    import matplotlib.pyplot as plt

    from drakegrasp.visualization import plot_planar_grasp

    no = dg.form_closure(ex.planar_two_finger_square(0.5))
    assert not no.is_closure and no.certificate.kind == "escape twist"
    other = ex.planar_square_four_contacts()
    fig, ax = plt.subplots()
    try:
        with pytest.raises(InvalidOptionError):
            plot_planar_grasp(
                other, ax=ax, result=no, outline=[[-1, -1], [1, -1], [1, 1], [-1, 1]]
            )
        assert not ax.patches and not ax.collections and not ax.texts
        with pytest.raises(InvalidOptionError, match="ax must be"):
            plot_planar_grasp(other, ax="axes")
    finally:
        plt.close(fig)


def test_an_endless_iterator_of_candidates_is_refused():
    # list(candidates) never returned.
    import itertools

    import matplotlib.pyplot as plt

    from drakegrasp.visualization.candidates import (
        MAX_CANDIDATES,
        plot_score_distribution,
    )

    class Row:
        score, is_closure = 0.5, True

    endless = itertools.repeat(Row())
    fig, ax = plt.subplots()
    try:
        with pytest.raises(InvalidOptionError, match="MAX_CANDIDATES"):
            plot_score_distribution(endless, ax=ax)
        assert MAX_CANDIDATES == 10**6
    finally:
        plt.close(fig)
