"""Contacts on a mesh's convex hull near its rim (issue 20, point 4).

A plate-like mesh (a flat foot and a wider rounded rim of 24 rings of 256
vertices, written as an OBJ in a temporary folder) is queried by Drake as its
convex hull.  Spherical tips touch it near the rim, where the hull's narrow
facets meet at small angles: the planes of several facets then pass within
GJK's 1e-5 m of Drake's witness point, which misled the witness-based normals
by up to 0.4 mm and 2°.
The reference is an independent hull computation: scipy's ``ConvexHull`` of
the OBJ's vertices, and the closest point of the tip's centre on its
triangles.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from free_rig import FreeRig
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.geometry import Convex, Mesh, Sphere
from pydrake.math import RigidTransform, RollPitchYaw

from drakegrasp import find_contacts

spatial = pytest.importorskip("scipy.spatial", reason="the reference hull is scipy's")

N_SIDES, N_RIM = 256, 24  # finely meshed, as kitchen meshes are
R_FOOT, R_RIM, RIM_R, RIM_Z = 0.07, 0.11, 0.01, 0.012
R_TIP = 0.01
X_WO = RigidTransform(RollPitchYaw(0.2, 0.4, -0.3), [0.05, -0.1, 0.4])
DRAKE_WITNESS = 5e-4
"""Metres: how near Drake's GJK witness points come to the exact ones on a
hull (measured: 1.6e-4 m at worst at the rim); the contact must be as near."""


def plate_rings() -> list[tuple[float, float]]:
    """(radius, height) of each ring: the foot, then the rounded rim."""
    phi = np.linspace(-np.pi / 2, np.pi / 2, N_RIM)
    rim = zip(
        R_RIM + RIM_R * np.cos(phi), RIM_Z + 0.8 * RIM_R * np.sin(phi), strict=True
    )
    return [(R_FOOT, 0.0), *rim]


def plate_vertices() -> np.ndarray:
    a = 2 * np.pi * np.arange(N_SIDES) / N_SIDES
    rings = [
        np.column_stack([R * np.cos(a), R * np.sin(a), 0 * a + z])
        for R, z in plate_rings()
    ]
    return np.vstack(rings)


@pytest.fixture(scope="module")
def plate_obj(tmp_path_factory):
    V = plate_vertices()
    n, rings = N_SIDES, len(plate_rings())
    faces = []
    for r in range(rings - 1):  # quads between rings, as two triangles
        for k in range(n):
            a, b = r * n + k, r * n + (k + 1) % n
            faces += [(a, b, b + n), (a, b + n, a + n)]
    top = (rings - 1) * n
    faces += [(0, k + 1, k) for k in range(1, n - 1)]  # the foot
    faces += [(top, top + k, top + k + 1) for k in range(1, n - 1)]  # the well
    path = tmp_path_factory.mktemp("plate") / "plate.obj"
    lines = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in V]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


class ReferenceHull:
    """The plate's hull by scipy: distance of a point outside, closest point."""

    def __init__(self):
        self.V = plate_vertices()
        self.hull = spatial.ConvexHull(self.V)

    def closest(self, p):
        """Closest point of the hull's triangles (interiors, then edges)."""
        T = self.V[self.hull.simplices]  # (t, 3, 3)
        a, b, c = T[:, 0], T[:, 1], T[:, 2]
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n, axis=1)[:, None]
        h = np.einsum("ij,ij->i", p - a, n)
        q = p - h[:, None] * n
        inside = np.ones(len(T), dtype=bool)
        for x, y in ((a, b), (b, c), (c, a)):
            inside &= np.einsum("ij,ij->i", np.cross(y - x, q - x), n) >= 0
        X = np.vstack([a, b, c])
        Y = np.vstack([b, c, a])
        t = np.clip(
            np.einsum("ij,ij->i", p - X, Y - X) / np.sum((Y - X) ** 2, axis=1), 0, 1
        )
        points = np.vstack([q[inside], X + t[:, None] * (Y - X)])
        return points[np.argmin(np.linalg.norm(points - p, axis=1))]

    def distance(self, p):
        return float(np.linalg.norm(p - self.closest(p)))


REF = ReferenceHull()


def tip_centre(azimuth, direction, gap):
    """A tip centre near the rim at ``azimuth``, moved along ``direction`` until
    its sphere is ``gap`` from the reference hull (Newton on the distance)."""
    R, z = R_RIM + RIM_R, RIM_Z  # the rim's outermost ring
    rim = np.array([R * math.cos(azimuth), R * math.sin(azimuth), z])
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    t = R_TIP
    for _ in range(30):
        c = rim + t * d
        q = REF.closest(c)
        dist = float(np.linalg.norm(c - q))
        step = (R_TIP + gap - dist) / (((c - q) / dist) @ d)
        t += step
        if abs(step) < 1e-15:
            break
    return rim + t * d


_RIGS: dict = {}


def rig(shape, centres_O):
    """The plate and free tips at the given centres (plants cached per shape)."""
    key = (type(shape).__name__, len(centres_O))
    if key not in _RIGS:
        _RIGS[key] = _build(shape, len(centres_O))
    plant, ctx, obj, tips, _ = _RIGS[key]
    for body, c in zip(tips, centres_O, strict=True):
        plant.SetFreeBodyPose(ctx, body, X_WO.multiply(RigidTransform(c)))
    return plant, ctx, obj, tips


def _build(shape, num_tips):
    rig = FreeRig(
        shape, [Sphere(R_TIP)] * num_tips, object_name="plate", finger_name="tip"
    )
    rig.plant.SetFreeBodyPose(rig.ctx, rig.object, X_WO)
    return rig.plant, rig.ctx, rig.object, rig.fingers, rig.diagram


def drake_witness(plant, ctx, obj, tip):
    query = plant.get_geometry_query_input_port().Eval(ctx)
    go = plant.GetCollisionGeometriesForBody(obj)[0]
    gt = plant.GetCollisionGeometriesForBody(tip)[0]
    r = query.ComputeSignedDistancePairClosestPoints(go, gt)
    assert r.id_A == go
    p_W = query.GetPoseInWorld(go).multiply(r.p_ACa)
    return r.distance, np.asarray(X_WO.inverse().multiply(p_W))


def angle(u, v):
    return float(np.arctan2(np.linalg.norm(np.cross(u, v)), np.dot(u, v)))


@settings(derandomize=True, max_examples=20, deadline=None)
@given(
    azimuth=st.floats(0.0, 2 * math.pi),
    out=st.floats(0.2, 1.0),
    up=st.floats(-0.6, 1.0),
    gap=st.floats(0.0, 9e-5),
    mesh=st.booleans(),
)
def test_tip_near_the_rim_matches_the_exact_hull_and_drake(
    plate_obj, azimuth, out, up, gap, mesh
):
    direction = [out * math.cos(azimuth), out * math.sin(azimuth), up]
    c = tip_centre(azimuth + 0.01, direction, gap)
    shape = Mesh(plate_obj) if mesh else Convex(plate_obj)
    plant, ctx, obj, (tip,) = rig(shape, [c])
    (contact,) = find_contacts(plant, ctx, obj, distance_tolerance=2e-4)
    q = REF.closest(c)
    n = (q - c) / np.linalg.norm(q - c)  # into the plate: the gradient of ψ
    np.testing.assert_allclose(contact.p_OC, q, atol=1e-9)
    assert angle(contact.nhat_O, n) < 1e-9
    assert contact.psi == pytest.approx(gap, abs=1e-9)
    np.testing.assert_allclose(contact.p_FC, [0, 0, 0] + R_TIP * n, atol=1e-9)
    psi_drake, p_drake = drake_witness(plant, ctx, obj, tip)
    assert np.linalg.norm(contact.p_OC - p_drake) < DRAKE_WITNESS
    assert contact.psi == pytest.approx(psi_drake, abs=DRAKE_WITNESS)


def test_normal_is_the_gradient_of_the_hull_distance(plate_obj):
    """Independent route: ψ̇ = nᵀ v, so moving the tip by h along each axis
    of O changes the reference hull distance by −h n (central differences)."""
    for azimuth, up in ((0.3, 0.5), (2.0, -0.3), (4.0, 1.0)):
        c = tip_centre(azimuth, [math.cos(azimuth), math.sin(azimuth), up], 5e-5)
        plant, ctx, obj, _ = rig(Convex(plate_obj), [c])
        (contact,) = find_contacts(plant, ctx, obj)
        h = 1e-7
        grad = [
            (REF.distance(c + h * e) - REF.distance(c - h * e)) / (2 * h)
            for e in np.eye(3)
        ]
        np.testing.assert_allclose(contact.nhat_O, -np.array(grad), atol=1e-7)


def test_two_tips_across_the_plate_are_antipodal_exactly(plate_obj):
    """Two tips on opposite rim edges, images under the half-turn about the
    plate's axis: so are the normals, and the two antipodal angles agree."""
    up = 0.4
    cs = [
        tip_centre(a, [math.cos(a), math.sin(a), up], 3e-5) for a in (0.1, 0.1 + np.pi)
    ]
    plant, ctx, obj, _ = rig(Convex(plate_obj), cs)
    c1, c2 = find_contacts(plant, ctx, obj)
    line = c2.p_OC - c1.p_OC
    assert angle(line, c1.nhat_O) == pytest.approx(angle(-line, c2.nhat_O), abs=1e-9)
