"""A flat face along a cylinder's side touches along a line: its two ends.

``line_vertices`` is checked against the closed form (a square face over a
cylinder lying along x), for invariance under rigid motion (hypothesis), and
through ``find_contacts`` on drakegrasp's flat jaw closed on its cylinder.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.geometry import Box, Capsule, Cylinder
from scipy.spatial.transform import Rotation
from test_exact_normals import PairRig, finger_pose

import drakegrasp as dg
from drakegrasp.plant import contact_curvatures
from drakegrasp.plant.contact_patches import line_vertices

R, H = 0.02, 0.05  # radius and half length of the cylinder (axis x)


def _face(x0, x1, y0, y1, z):
    """A rectangle in the plane ``z``, its outward normal -z (down, at the cylinder)."""
    return np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]])


def _moved_ends(poly, Q, t):
    """``_ends(poly)`` with the face and the cylinder rotated by Q, moved by t."""
    return line_vertices(
        face_normal_O=Q @ np.array([0.0, 0.0, -1.0]),
        poly_face_O=poly @ Q.T + t,
        axis_O=Q @ np.array([1.0, 0.0, 0.0]),
        centre_O=t,
        radius=R,
        half_length=H,
        tol=1e-3,
    )


def _ends(poly, *, normal=(0.0, 0.0, -1.0), tol=1e-3, axis=(1.0, 0.0, 0.0)):
    return line_vertices(
        face_normal_O=np.array(normal),
        poly_face_O=poly,
        axis_O=np.array(axis),
        centre_O=np.zeros(3),
        radius=R,
        half_length=H,
        tol=tol,
    )


def test_a_face_over_the_side_gives_the_ends_under_it():
    gap = 2e-4
    ends = _ends(_face(-0.01, 0.03, -0.01, 0.01, R + gap))
    points = np.array([p for p, _ in ends])
    np.testing.assert_allclose(points, [[-0.01, 0, R], [0.03, 0, R]], atol=1e-15)
    np.testing.assert_allclose([g for _, g in ends], [gap, gap], atol=1e-15)


def test_the_line_stops_where_the_cylinder_does():
    ends = _ends(_face(-0.2, 0.3, -0.01, 0.01, R))
    np.testing.assert_allclose([p[0] for p, _ in ends], [-H, H], atol=1e-15)


def test_a_face_pressed_in_has_negative_gaps():
    ends = _ends(_face(-0.01, 0.01, -0.01, 0.01, R - 1e-4))
    np.testing.assert_allclose([g for _, g in ends], [-1e-4, -1e-4], atol=1e-15)


def test_a_tilted_face_keeps_the_part_within_the_tolerance():
    """Tilted by 1° about y: the gap grows along x; the line ends where it
    reaches ``tol`` (closed form: the plane's height over the line)."""
    theta, tol = np.radians(1.0), 1e-4
    n = np.array([np.sin(theta), 0.0, -np.cos(theta)])  # outward, tilted
    # the face's plane passes through (0, 0, R): gap(x) = -n . (x, 0, R) + n . q
    u = np.array([np.cos(theta), 0.0, np.sin(theta)])  # in the plane, along x
    v = np.array([0.0, 1.0, 0.0])
    q = np.array([0.0, 0.0, R])
    corners = [(-0.04, -0.01), (0.04, -0.01), (0.04, 0.01), (-0.04, 0.01)]
    poly = np.array([q + a * u + b * v for a, b in corners])
    ends = _ends(poly, normal=n, tol=tol)
    # gap at x along the line (x, 0, R): n . ((x, 0, R) - q) = x sin(theta);
    # the face's edge a = -0.04 seen from the line (normal to the face): where
    # (x, 0, R) - q has the component -0.04 along u, x cos(theta) = -0.04
    x_end = tol / np.sin(theta)
    np.testing.assert_allclose(
        [p[0] for p, _ in ends], [-0.04 / np.cos(theta), x_end], atol=1e-11
    )
    np.testing.assert_allclose(ends[1][1], tol, rtol=1e-12)


@pytest.mark.parametrize(
    ("poly", "normal"),
    [
        (_face(0.06, 0.08, -0.01, 0.01, R), (0, 0, -1)),  # beyond the cylinder's end
        (_face(-0.01, 0.01, 0.03, 0.05, R), (0, 0, -1)),  # beside the line
        (_face(-0.01, 0.01, -0.01, 0.01, R + 0.01), (0, 0, -1)),  # too far
        (_face(-0.01, 0.01, -0.01, 0.01, R), (np.sin(0.1), 0, -np.cos(0.1))),  # 5.7°
    ],
)
def test_no_line_where_the_face_is_not_along_the_side(poly, normal):
    assert _ends(poly, normal=np.array(normal, float)) == []


def test_a_pads_back_face_gives_no_line():
    """The face looking away from the cylinder (a pad's back) is not a line
    contact: it once gave two ends at ψ = -45 mm (the review's case)."""
    assert _ends(_face(-0.01, 0.01, -0.01, 0.01, R + 1e-4), normal=(0, 0, 1)) == []


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3),
    st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3),
)
def test_a_face_whose_edge_runs_along_the_line_keeps_it(angles, shift):
    """The face's edge y = 0 lies exactly over the line: round-off once gave
    the whole line or nothing at random (1,008 against 992 of 2,000 poses)."""
    Q, t = Rotation.from_euler("xyz", angles).as_matrix(), np.array(shift)
    ends = _moved_ends(_face(-0.03, 0.03, 0.0, 0.02, R), Q, t)
    assert len(ends) == 2
    np.testing.assert_allclose(
        sorted(float((p - t) @ (Q @ [1.0, 0.0, 0.0])) for p, _ in ends),
        [-0.03, 0.03],
        atol=1e-9,
    )


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3),
    st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3),
)
def test_rigid_motion_moves_the_ends_with_it(angles, shift):
    Q, t = Rotation.from_euler("xyz", angles).as_matrix(), np.array(shift)
    poly = _face(-0.01, 0.03, -0.01, 0.01, R + 2e-4)
    here = _ends(poly)
    there = _moved_ends(poly, Q, t)
    assert len(there) == 2
    for (p, g), (p2, g2) in zip(here, there, strict=True):
        np.testing.assert_allclose(p2, Q @ p + t, atol=1e-12)
        assert abs(g2 - g) < 1e-12


def test_the_flat_jaw_touches_the_cylinder_along_two_lines():
    """The planner's best grasp of drakegrasp's cylinder (radius 30 mm) with
    its flat jaw (20 mm square pads): each pad's contacts are the two ends of
    a line on the cylinder's side, parallel to the axis, one normal each, at
    most a pad's diagonal long; hard fingers are force closure (one point per
    pad never is)."""
    scene = dg.planning_scene(
        "package://drakegrasp/objects/cylinder.sdf",
        hand_url="package://drakegrasp/hands/parallel_jaw_flat.sdf",
    )
    result = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, mu=0.5, seed=0, robustness_samples=4,
    )  # fmt: skip
    best = result[0]
    assert best.is_closure
    by_pad: dict[str, list] = {}
    for c in best.contacts:
        if c.normal_source == "line":
            by_pad.setdefault(c.finger_body, []).append(c)
    assert len(by_pad) == 2
    for pad in by_pad.values():
        assert len(pad) == 2
        p0, p1 = (np.asarray(c.p_OC) for c in pad)
        along = p1 - p0
        assert abs(abs(along[2]) - np.linalg.norm(along)) < 1e-9  # along z (axis)
        assert 0.02 - 1e-9 <= np.linalg.norm(along) <= 0.02 * np.sqrt(2) + 1e-9
        for c in pad:
            p = np.asarray(c.p_OC)
            assert abs(np.hypot(p[0], p[1]) - 0.03) < 1e-9  # on the side
            assert abs(c.nhat_O[2]) < 1e-12
            np.testing.assert_allclose(c.nhat_O, pad[0].nhat_O, atol=1e-15)


def _round_object_rig(round_shape, *, gap, tilt_deg=0.0, pad=(0.004, 0.03, 0.2)):
    """A pad (outward face +x of a thin box, frame F) lying along the round
    object's side (axis z) at the side point (r, 0, 0), tilted about y."""
    r = round_shape.radius()
    t = np.radians(tilt_deg)
    m = np.array([np.cos(t), 0.0, np.sin(t)])  # the pad's face normal, reversed
    return PairRig(
        round_shape,
        [(Box(*pad), finger_pose([r, 0.0, 0.0], m, [-pad[0] / 2, 0, 0], [-1, 0, 0],
                                 gap=gap, spin=0.0))],
    )  # fmt: skip


@pytest.mark.parametrize("shape", [Cylinder(0.02, 0.1), Capsule(0.02, 0.1)])
@pytest.mark.parametrize("gap", [0.0, 5e-5, -3e-5])
def test_find_contacts_gives_the_two_ends_with_the_objects_normal(shape, gap):
    rig = _round_object_rig(shape, gap=gap, pad=(0.004, 0.03, 0.04))
    contacts = rig.contacts(allow_penetration=True)
    assert [c.normal_source for c in contacts] == ["line", "line"]
    ends = sorted(np.asarray(c.p_OC)[2] for c in contacts)
    np.testing.assert_allclose(ends, [-0.02, 0.02], atol=1e-12)  # the pad's edges
    for c in contacts:
        p = np.asarray(c.p_OC)
        assert abs(np.hypot(p[0], p[1]) - 0.02) < 1e-12  # on the side
        np.testing.assert_allclose(c.nhat_O, [-1.0, 0.0, 0.0], atol=1e-12)
        assert c.psi == pytest.approx(gap, abs=1e-9)
        np.testing.assert_allclose(
            np.asarray(c.p_OC) - c.psi * np.asarray(c.nhat_O),
            _p_OF(rig, c),
            atol=1e-12,
        )
    (one,) = rig.contacts(patches="witness", allow_penetration=True)
    assert one.normal_source != "line"


def _p_OF(rig, c):
    """The finger's touching point in O, from p_FC and the finger's pose."""
    plant, ctx = rig.plant, rig.ctx
    X_WO = plant.EvalBodyPoseInWorld(ctx, rig.object)
    X_WF = plant.EvalBodyPoseInWorld(ctx, plant.get_body(c.finger_body_index))
    return np.asarray(X_WO.inverse().multiply(X_WF).multiply(c.p_FC))


@pytest.mark.parametrize("shape", [Cylinder(0.02, 0.1), Capsule(0.02, 0.1)])
def test_a_slightly_tilted_overhanging_pad_still_gives_a_line(shape):
    """A 200 mm pad on a 100 mm straight side, tilted by 0.001°: Drake's
    witness moves to the rim (a capsule's hemisphere); the line is still there
    (the review found one point here)."""
    rig = _round_object_rig(shape, gap=1e-5, tilt_deg=0.001)
    contacts = rig.contacts()
    assert [c.normal_source for c in contacts] == ["line", "line"]
    ends = sorted(np.asarray(c.p_OC)[2] for c in contacts)
    np.testing.assert_allclose(ends, [-0.05, 0.05], atol=1e-9)


def test_a_round_finger_on_a_box_face_gives_the_two_ends_on_the_face():
    """The other role: a cylindrical link (radius 8 mm, 50 mm) lying on a box's
    top face, 40 µm above it: the ends are on the face, the normal the face's
    (into the box), ψ the gap."""
    gap = 4e-5
    X_OF = finger_pose([0.01, 0.0, 0.02], [0, 0, 1], [0.008, 0.0, 0.0], [1, 0, 0],
                       gap=gap, spin=0.0)  # fmt: skip
    rig = PairRig(Box(0.1, 0.06, 0.04), [(Cylinder(0.008, 0.05), X_OF)])
    contacts = rig.contacts()
    assert [c.normal_source for c in contacts] == ["line", "line"]
    for c in contacts:
        assert np.asarray(c.p_OC)[2] == pytest.approx(0.02, abs=1e-12)
        np.testing.assert_allclose(c.nhat_O, [0.0, 0.0, -1.0], atol=1e-12)
        assert c.psi == pytest.approx(gap, abs=1e-12)
    along = np.asarray(contacts[1].p_OC) - np.asarray(contacts[0].p_OC)
    assert np.linalg.norm(along) == pytest.approx(0.05, abs=1e-9)


def test_line_ends_have_curvatures_for_second_order_analysis():
    """``contact_curvatures`` took every non-point contact for flat on flat and
    raised for a line ("a patch contact whose faces cannot be found"): a line
    end has the cylinder's curvature 1/r across the axis and 0 along it."""
    rig = _round_object_rig(Cylinder(0.02, 0.1), gap=0.0, pad=(0.004, 0.03, 0.04))
    contacts = rig.contacts()
    curv = contact_curvatures(rig.plant, rig.ctx, contacts, object_body=rig.object)
    for cc in curv:
        assert sorted(cc.object.curvatures) == pytest.approx([0.0, 50.0])
