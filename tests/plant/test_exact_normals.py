"""Exact contact normals for every shape pair (issue 20, point 3).

Each case is built from its answer: a point ``x`` of the object's surface with
its outward normal ``m``, and a point ``y`` of the finger's surface with its
outward normal ``m_F``.  The finger is turned so that ``m_F = −m`` (and spun
about ``m`` by any angle), then placed so that ``y = x + gap m``.  Both shapes
being convex, the plane through ``x`` normal to ``m`` separates them, so the
exact contact is ``p_OC = x``, ``nhat_O = −m``, ``ψ = gap``, whatever Drake's
GJK/EPA witnesses say.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from free_rig import X_WO, FreeRig
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.geometry import (
    Box,
    Capsule,
    Convex,
    Cylinder,
    Ellipsoid,
    Sphere,
)
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix

from drakegrasp import Contact, find_contacts, is_antipodal
from drakegrasp.plant import models_dir

HEX = str(models_dir() / "objects" / "hex_prism.obj")
MAX_ANGLE = math.radians(1e-4)  # the issue's bound: 1e-4 degrees
EXACT = 1e-9  # what the exact routes reach (metres; radians for angles)


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def angle(u, v):
    return float(np.arctan2(np.linalg.norm(np.cross(u, v)), np.dot(u, v)))


def rotation_taking(a, b):
    """A rotation matrix R with R a = b (unit vectors)."""
    a, b = unit(a), unit(b)
    v, c = np.cross(a, b), float(a @ b)
    if np.linalg.norm(v) < 1e-12:
        if c > 0:
            return np.eye(3)
        p = unit(np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0, 1.0, 0]))
        return 2 * np.outer(p, p) - np.eye(3)
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + K + K @ K / (1 + c)


def _axis_angle(k, t):
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(t) * K + (1 - math.cos(t)) * K @ K


def finger_pose(x, m, y_F, m_F, *, gap, spin):
    """X_OF placing the finger's point y_F at x + gap m, its normal m_F = −m."""
    R = _axis_angle(unit(m), spin) @ rotation_taking(m_F, -np.asarray(m, float))
    p = np.asarray(x, float) + gap * unit(m) - R @ np.asarray(y_F, float)
    return RigidTransform(RotationMatrix(R), p)


class PairRig(FreeRig):
    """An object and free fingers of given shapes at given poses (frame O)."""

    def __init__(self, object_shape, fingers, X_WO=X_WO):
        super().__init__(object_shape, [shape for shape, _ in fingers])
        self.place(X_WO, [X_OF for _, X_OF in fingers])

    def contacts(self, **kwargs):
        return find_contacts(self.plant, self.ctx, self.object, **kwargs)

    def drake(self, k=0):
        """Drake's (ψ, p_OCa, nhat_O) for finger k."""
        query = self.plant.get_geometry_query_input_port().Eval(self.ctx)
        go = self.plant.GetCollisionGeometriesForBody(self.object)[0]
        gf = self.plant.GetCollisionGeometriesForBody(self.fingers[k])[0]
        r = query.ComputeSignedDistancePairClosestPoints(go, gf)
        X_OW = self.plant.EvalBodyPoseInWorld(self.ctx, self.object).inverse()
        assert r.id_A == go
        p = X_OW.multiply(query.GetPoseInWorld(go).multiply(r.p_ACa))
        return r.distance, np.asarray(p), X_OW.rotation().multiply(r.nhat_BA_W)


def _ell_point(abc, d):
    """Surface point of an ellipsoid along the direction d, and its normal."""
    abc = np.asarray(abc, float)
    d = unit(d)
    x = d / np.sqrt(np.sum((d / abc) ** 2))
    return x, unit(x / abc**2)


C7, S7 = math.cos(0.7), math.sin(0.7)
ELL = (0.05, 0.03, 0.02)
ELL_X, ELL_M = _ell_point(ELL, [0.4, -0.5, 0.7])
FELL = (0.01, 0.015, 0.02)
FELL_Y, FELL_M = _ell_point(FELL, [-0.3, 0.2, 0.9])
PAD = Box(0.02, 0.004, 0.03)  # a PR2-like pad: its face y = +0.002 touches
PAD_Y, PAD_M = [0.003, 0.002, -0.004], [0, 1, 0]
LINK = Box(0.02, 0.03, 0.04)  # a LEAP-like box link
LINK_EDGE_Y, LINK_EDGE_M = [0.01, 0.015, 0.006], unit([0.8, 0.6, 0])
CYL25 = Cylinder(0.025, 0.1)
CYL25_X, CYL25_M = [0.025 * C7, 0.025 * S7, 0.02], [C7, S7, 0]  # on its side
rim_m = unit([C7 * math.cos(0.6), S7 * math.cos(0.6), math.sin(0.6)])

# (id, object shape, x (O), m (O), finger shape, y (F), m_F (F), line contact)
CASES = [
    (
        "PR2 pad on cylinder r15 side",
        Cylinder(0.015, 0.08),
        [0.015 * C7, 0.015 * S7, 0.01],
        [C7, S7, 0],
        PAD,
        PAD_Y,
        PAD_M,
        True,
    ),
    (
        "PR2 pad on cylinder r15 rim",
        Cylinder(0.015, 0.08),
        [0.015 * C7, 0.015 * S7, 0.04],
        rim_m,
        PAD,
        PAD_Y,
        PAD_M,
        False,
    ),
    (
        "pad on capsule r10 side",
        Capsule(0.01, 0.06),
        [0.01 * C7, 0.01 * S7, -0.01],
        [C7, S7, 0],
        PAD,
        PAD_Y,
        PAD_M,
        True,
    ),
    (
        "pad on capsule r10 cap",
        Capsule(0.01, 0.06),
        np.array([0, 0, 0.03]) + 0.01 * rim_m,
        rim_m,
        PAD,
        PAD_Y,
        PAD_M,
        False,
    ),
    (
        "box link face on cylinder r25",
        CYL25,
        CYL25_X,
        CYL25_M,
        LINK,
        [0.004, 0.015, 0.01],
        [0, 1, 0],
        True,
    ),
    (
        "box link edge on cylinder r25",
        CYL25,
        CYL25_X,
        CYL25_M,
        LINK,
        LINK_EDGE_Y,
        LINK_EDGE_M,
        False,
    ),
    (
        "box link edge on cylinder r25 rim",
        CYL25,
        [0.025 * C7, 0.025 * S7, 0.05],
        rim_m,
        LINK,
        LINK_EDGE_Y,
        LINK_EDGE_M,
        False,
    ),
    (
        "box corner on ellipsoid",
        Ellipsoid(*ELL),
        ELL_X,
        ELL_M,
        LINK,
        [0.01, -0.015, 0.02],
        unit([0.5, -0.4, 0.6]),
        False,
    ),
    (
        "ellipsoid on ellipsoid",
        Ellipsoid(*ELL),
        ELL_X,
        ELL_M,
        Ellipsoid(*FELL),
        FELL_Y,
        FELL_M,
        False,
    ),
    (
        "cylinder rim on ellipsoid",
        Ellipsoid(*ELL),
        ELL_X,
        ELL_M,
        Cylinder(0.01, 0.03),
        [0.01 * C7, 0.01 * S7, 0.015],
        rim_m,
        False,
    ),
    (
        "cylinder side across cylinder side",
        CYL25,
        CYL25_X,
        CYL25_M,
        Cylinder(0.008, 0.05),
        [0.008, 0.0, 0.004],
        [1, 0, 0],
        False,
    ),
    (
        "ellipsoid on box face",
        Box(0.1, 0.06, 0.04),
        [0.01, 0.03, -0.005],
        [0, 1, 0],
        Ellipsoid(*FELL),
        FELL_Y,
        FELL_M,
        False,
    ),
    (
        "ellipsoid on box edge",
        Box(0.1, 0.06, 0.04),
        [0.05, 0.03, 0.004],
        unit([1, 2, 0]),
        Ellipsoid(*FELL),
        FELL_Y,
        FELL_M,
        False,
    ),
    (
        "ellipsoid on cylinder cap",
        Cylinder(0.03, 0.1),
        [0.01, -0.005, 0.05],
        [0, 0, 1],
        Ellipsoid(*FELL),
        FELL_Y,
        FELL_M,
        False,
    ),
    (
        "capsule on cylinder rim",
        Cylinder(0.03, 0.1),
        [0.03 * C7, 0.03 * S7, 0.05],
        rim_m,
        Capsule(0.006, 0.03),
        [0.006, 0.0, 0.01],
        [1, 0, 0],
        False,
    ),
    (
        "sphere on ellipsoid",
        Ellipsoid(*ELL),
        ELL_X,
        ELL_M,
        Sphere(0.01),
        [0, 0, 0.01],
        [0, 0, 1],
        False,
    ),
    (
        "box link corner on hex mesh face",
        Convex(HEX),
        [0.0, 0.025, 0.01],
        [0, 1, 0],
        LINK,
        [0.01, 0.015, 0.02],
        unit([0.5, 0.6, 0.4]),
        False,
    ),
]


def _check(rig, x, m, y_F, gap, line):
    (c,) = rig.contacts(patches="witness")
    n = -unit(m)
    assert angle(c.nhat_O, n) < EXACT
    assert c.psi == pytest.approx(gap, abs=EXACT)
    if line:  # a face on a side (axis z): any point of the contact line
        assert np.linalg.norm(np.cross(c.p_OC - x, [0.0, 0.0, 1.0])) < EXACT
    else:
        np.testing.assert_allclose(c.p_OC, x, atol=EXACT)
        np.testing.assert_allclose(c.p_FC, y_F, atol=EXACT)
    return c


@pytest.mark.parametrize("gap", [0.0, 5e-5])
@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_normal_is_exact_for_every_shape_pair(case, gap):
    _, obj, x, m, finger, y_F, m_F, line = case
    rig = PairRig(obj, [(finger, finger_pose(x, m, y_F, m_F, gap=gap, spin=0.4))])
    _check(rig, np.asarray(x, float), m, np.asarray(y_F, float), gap, line)


@settings(derandomize=True, max_examples=25, deadline=None)
@given(
    case=st.sampled_from(CASES),
    spin=st.floats(0.2, math.pi - 0.2),  # 0 and π lay an edge along an axis
    gap=st.floats(0.0, 9e-5),
    rpy=st.tuples(*[st.floats(-math.pi, math.pi)] * 3),
)
def test_exactness_survives_spin_gap_and_object_pose(case, spin, gap, rpy):
    """Invariance: any spin about the normal, gap and pose of the object."""
    _, obj, x, m, finger, y_F, m_F, line = case
    if line:  # a face on a side touches along a line only without spin
        spin = 0.0
    X = RigidTransform(RollPitchYaw(*rpy), [0.3, -0.1, 0.2])
    rig = PairRig(obj, [(finger, finger_pose(x, m, y_F, m_F, gap=gap, spin=spin))], X)
    _check(rig, np.asarray(x, float), m, np.asarray(y_F, float), gap, line)


def test_issue_cases_beat_drake_and_meet_the_bound():
    """The issue's three pairs: Drake's normals are off, drakegrasp's are not."""
    worst_drake = 0.0
    for name in (
        "PR2 pad on cylinder r15 side",
        "pad on capsule r10 side",
        "box link face on cylinder r25",
    ):
        _, obj, x, m, finger, y_F, m_F, _ = next(c for c in CASES if c[0] == name)
        for spin in (0.0, 0.3):
            X_OF = finger_pose(x, m, y_F, m_F, gap=2e-5, spin=spin)
            rig = PairRig(obj, [(finger, X_OF)])
            (c,) = rig.contacts(patches="witness")
            assert angle(c.nhat_O, -unit(m)) < MAX_ANGLE
            worst_drake = max(worst_drake, angle(rig.drake()[2], -unit(m)))
    # Not a requirement on Drake: a record that the cases exercise its error.
    assert worst_drake > 1e3 * EXACT


def test_mirror_symmetric_capsule_grasp_has_equal_antipodal_angles():
    """Two pads touch a capsule's end cap, mirror images across x = 0.

    The inward normals are (±cos β, 0, −sin β); the contacts sit on the cap's
    sphere at ``e − r n``, so the line between them is along x and each
    antipodal angle is exactly β.
    """
    beta = math.radians(28.0)
    r, length = 0.01, 0.06
    e = np.array([0.0, 0.0, length / 2])
    fingers = []
    for sx in (1.0, -1.0):
        n = np.array([sx * math.cos(beta), 0.0, -math.sin(beta)])
        x = e - r * n  # the cap point with outward normal −n
        fingers.append((PAD, finger_pose(x, -n, PAD_Y, PAD_M, gap=3e-5, spin=0.0)))
    rig = PairRig(Capsule(r, length), fingers)
    c1, c2 = rig.contacts(patches="witness")
    result = is_antipodal([Contact(c.p_OC, c.nhat_O, mu=0.6) for c in (c1, c2)])
    assert abs(result.angles[0] - result.angles[1]) < 1e-6
    assert result.angles == pytest.approx([beta, beta], abs=1e-9)
