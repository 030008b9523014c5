"""find_contacts: normals for every shape pair, flat patches, tolerances, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from free_rig import X_WO, FreeRig
from pydrake.geometry import (
    Box,
    Capsule,
    Convex,
    Cylinder,
    Ellipsoid,
    ProximityProperties,
    Sphere,
)
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.multibody.tree import BodyIndex, SpatialInertia
from pydrake.systems.framework import DiagramBuilder

from drakegrasp import ModelError, NoContactsError, PenetrationError
from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant import find_contacts, models_dir
from drakegrasp.plant.contacts import contacts_of_distances

R_TIP = 0.01
GAP = 5e-5  # inside the default tolerance, so both sides of an FD stay separated
HEX = str(models_dir() / "objects" / "hex_prism.obj")


class Rig(FreeRig):
    """An object and free-floating fingers of given shapes, at given poses."""

    def __init__(self, object_shape, fingers, X_WO=X_WO):
        super().__init__(object_shape, [shape for shape, _ in fingers])
        self.X_WO = X_WO
        self.place(X_WO, [X_OF for _, X_OF in fingers])

    def contacts(self, **kwargs):
        return find_contacts(self.plant, self.ctx, object_body=self.object, **kwargs)

    def psi(self, k=0):
        query = self.plant.get_geometry_query_input_port().Eval(self.ctx)
        go = self.plant.GetCollisionGeometriesForBody(self.object)[0]
        gf = self.plant.GetCollisionGeometriesForBody(self.fingers[k])[0]
        return query.ComputeSignedDistancePairClosestPoints(go, gf).distance

    def translate_object(self, d_O):
        X = RigidTransform(self.X_WO.rotation(), self.X_WO.multiply(d_O))
        self.plant.SetFreeBodyPose(self.ctx, self.object, X)


def at(p, R=None):
    return RigidTransform(R or RotationMatrix(), np.asarray(p, dtype=float))


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def tip_touching(point_O, inward_n):
    """Pose (in O) of a sphere tip whose surface is GAP from point_O along -n."""
    return at(np.asarray(point_O) - (R_TIP + GAP) * unit(inward_n))


U = unit([0.3, -0.5, 0.8])
c60 = (math.cos(math.pi / 3), math.sin(math.pi / 3), 0.0)
RC = 0.025 / math.cos(math.pi / 6)

# (id, object shape, contact point on the object (frame O), inward normal,
#  expected normal source, check the normal by finite differences of Drake's ψ)
SPHERE_TIP_CASES = [
    ("box-face", Box(0.1, 0.06, 0.04), [0.05, 0.01, -0.005], [-1, 0, 0], "object"),
    ("box-edge", Box(0.1, 0.06, 0.04), [0.05, 0.03, 0.0], [-1, -1, 0], "edge"),
    ("box-corner", Box(0.1, 0.06, 0.04), [0.05, 0.03, 0.02], [-1, -1, -1], "corner"),
    (
        "cylinder-side",
        Cylinder(0.03, 0.1),
        [0.03 * math.cos(0.7), 0.03 * math.sin(0.7), 0.01],
        [-math.cos(0.7), -math.sin(0.7), 0],
        "object",
    ),
    ("cylinder-cap", Cylinder(0.03, 0.1), [0.01, 0.005, 0.05], [0, 0, -1], "object"),
    ("cylinder-rim", Cylinder(0.03, 0.1), [0.03, 0.0, 0.05], [-1, 0, -1], "edge"),
    ("sphere", Sphere(0.04), 0.04 * U, -U, "object"),
    (
        "ellipsoid",
        Ellipsoid(0.05, 0.03, 0.02),
        [0.05 * 0.6, 0.03 * 0.0, 0.02 * 0.8],
        -unit([0.6 / 0.05, 0.0, 0.8 / 0.02]),
        "object",
    ),
    ("capsule-side", Capsule(0.02, 0.06), [0.0, 0.02, 0.01], [0, -1, 0], "object"),
    ("convex-face", "hex", [0.0, 0.025, 0.01], [0, -1, 0], "object"),
    (
        "convex-edge",
        "hex",
        [RC * c60[0], RC * c60[1], 0.0],
        [-c60[0], -c60[1], 0],
        "edge",
    ),
]


def _shape(shape):
    return Convex(HEX) if shape == "hex" else shape


@pytest.mark.parametrize("case", SPHERE_TIP_CASES, ids=[c[0] for c in SPHERE_TIP_CASES])
def test_sphere_fingertip_normal_on_every_object_shape(case):
    name, shape, point, inward, source = case
    rig = Rig(_shape(shape), [(Sphere(R_TIP), tip_touching(point, inward))])
    (c,) = rig.contacts()
    n = unit(inward)
    # Drake's GJK witnesses (meshes, ellipsoids) are accurate to ~1e-5 m;
    # drakegrasp makes a spherical tip exact on flat faces, edges and corners.
    gjk = isinstance(shape, Ellipsoid)
    np.testing.assert_allclose(c.nhat_O, n, atol=1e-3 if gjk else 1e-9)
    assert c.normal_source == source
    assert c.psi == pytest.approx(GAP, abs=2e-5 if gjk else 1e-9)
    np.testing.assert_allclose(c.p_OC, point, atol=2e-5)
    if not gjk and shape != "hex":  # GJK distances are too noisy to difference
        # Independent route: ψ̇ = nᵀ v_object, so the gradient of Drake's ψ with
        # respect to the object's translation (frame O) is n.
        h = 1e-6
        grad = []
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            rig.translate_object(e)
            plus = rig.psi()
            rig.translate_object(-e)
            minus = rig.psi()
            grad.append((plus - minus) / (2 * h))
        rig.translate_object(np.zeros(3))
        np.testing.assert_allclose(grad, n, atol=1e-5)


@pytest.mark.parametrize(
    "finger_shape, X_OF, point, inward",
    [
        # A box fingertip's face on a sphere object: the object is smooth.
        (
            Box(0.02, 0.02, 0.02),
            at([0.04 + 0.01 + GAP, 0, 0]),
            [0.04, 0, 0],
            [-1, 0, 0],
        ),
        # A capsule finger lying across a box face.
        (
            Capsule(0.005, 0.04),
            at([0, 0, 0.02 + 0.005 + GAP], RotationMatrix.MakeXRotation(math.pi / 2)),
            [0, 0, 0.02],
            [0, 0, -1],
        ),
        # A box finger's edge on a box face (object face unique).
        (
            Box(0.02, 0.02, 0.02),
            at(
                [0.05 + 0.01 * math.sqrt(2) + GAP, 0.0, 0.0],
                RotationMatrix.MakeZRotation(math.pi / 4),
            ),
            [0.05, 0.0, 0.0],
            [-1, 0, 0],
        ),
    ],
    ids=["box-on-sphere", "capsule-on-box", "box-edge-on-box-face"],
)
def test_other_finger_shapes(finger_shape, X_OF, point, inward):
    obj = (
        Sphere(0.04)
        if np.isclose(np.linalg.norm(point), 0.04)
        else Box(0.1, 0.06, 0.04)
    )
    rig = Rig(obj, [(finger_shape, X_OF)])
    contacts = rig.contacts(patches="witness")
    assert len(contacts) == 1
    np.testing.assert_allclose(contacts[0].nhat_O, unit(inward), atol=1e-6)
    assert contacts[0].psi == pytest.approx(GAP, abs=1e-8)


PAD = Box(0.02, 0.004, 0.02)  # a 20 x 20 mm flat pad, thin along y


def test_flat_pad_on_box_face_gives_the_patch_corners():
    # Pad face y = -0.002 (pad frame) touches the box face y = 0.03 from outside.
    rig = Rig(Box(0.1, 0.06, 0.08), [(PAD, at([0.01, 0.03 + 0.002, -0.005]))])
    contacts = rig.contacts()
    assert len(contacts) == 4
    assert {c.patch_vertex for c in contacts} == {0, 1, 2, 3}
    corners = sorted(tuple(np.round(c.p_OC, 9)) for c in contacts)
    expected = sorted(
        (0.01 + a, 0.03, -0.005 + b) for a in (-0.01, 0.01) for b in (-0.01, 0.01)
    )
    np.testing.assert_allclose(corners, expected, atol=1e-9)
    for c in contacts:
        np.testing.assert_allclose(c.nhat_O, [0, -1, 0], atol=1e-12)
        assert abs(c.psi) < 1e-9
        # The finger point is the pad's corner, in the pad's frame.
        np.testing.assert_allclose(np.abs(c.p_FC), [0.01, 0.002, 0.01], atol=1e-9)
    (single,) = rig.contacts(patches="witness")
    assert single.patch_vertex is None


def test_pad_overhanging_the_face_is_clipped_to_the_face():
    # The pad's centre sits on the box's top edge: half the pad overhangs.
    rig = Rig(Box(0.1, 0.06, 0.08), [(PAD, at([0.0, 0.032, 0.04]))])
    contacts = rig.contacts()
    z = sorted({round(float(c.p_OC[2]), 9) for c in contacts})
    assert z == [0.03, 0.04]
    assert len(contacts) == 4


@pytest.mark.parametrize("tilt", [0.002, 0.02])
def test_tilted_pad_keeps_the_part_within_the_tolerance(tilt):
    # Pad rotated about the box face's x axis so that its edge z = -0.01 (pad
    # frame) touches the face at z = 0 (frame O) and the gap grows along +z.
    R = RotationMatrix.MakeXRotation(-tilt)
    centre = np.array([0.0, 0.03, 0.0]) - R.matrix() @ np.array([0.0, -0.002, -0.01])
    rig = Rig(Box(0.1, 0.06, 0.08), [(PAD, at(centre, R))])
    contacts = rig.contacts()
    tol = 1e-4
    reach = min(0.02, tol / math.tan(tilt))  # extent (along z) where gap <= tol
    z = sorted({round(float(c.p_OC[2]), 7) for c in contacts})
    assert z == pytest.approx([0.0, reach * math.cos(tilt)], abs=2e-6)
    assert len(contacts) == 4
    for c in contacts:
        assert -1e-9 <= c.psi <= tol + 1e-9
        expected_gap = math.tan(tilt) * c.p_OC[2]
        assert c.psi == pytest.approx(expected_gap, abs=1e-8)


def test_flat_pad_on_convex_mesh_face():
    rig = Rig(Convex(HEX), [(PAD, at([0.0, 0.025 + 0.002, 0.0]))])
    contacts = rig.contacts()
    assert len(contacts) == 4
    for c in contacts:
        np.testing.assert_allclose(c.nhat_O, [0, -1, 0], atol=1e-9)
    np.testing.assert_allclose(
        sorted(np.abs(c.p_OC[0]) for c in contacts), [0.01] * 4, atol=1e-9
    )


def test_tolerance_boundary():
    box = Box(0.1, 0.06, 0.04)
    for gap, touching in ((0.5e-4, True), (2e-4, False)):
        X = at([0.05 + R_TIP + gap, 0, 0])
        rig = Rig(box, [(Sphere(R_TIP), X)])
        if touching:
            (c,) = rig.contacts()
            assert c.psi == pytest.approx(gap, abs=1e-12)
        else:
            with pytest.raises(NoContactsError):
                rig.contacts()
    rig = Rig(box, [(Sphere(R_TIP), at([0.05 + R_TIP + 2e-4, 0, 0]))])
    assert len(rig.contacts(distance_tolerance=3e-4)) == 1


def test_no_contact_names_the_object_and_the_closest_finger():
    rig = Rig(
        Box(0.1, 0.06, 0.04),
        [
            (Sphere(R_TIP), at([0.05 + R_TIP + 0.004, 0, 0])),
            (Sphere(R_TIP), at([0, 0.03 + R_TIP + 0.002, 0])),
        ],
    )
    with pytest.raises(NoContactsError) as info:
        rig.contacts()
    message = str(info.value)
    assert "object::object" in message
    assert "hand::finger1" in message and "tip1" in message
    assert "2 mm" in message


def test_penetration_is_an_error_naming_the_pair_and_depth():
    rig = Rig(
        Box(0.1, 0.06, 0.04), [(Sphere(R_TIP), at([0.05 + R_TIP - 0.0015, 0, 0]))]
    )
    with pytest.raises(PenetrationError) as info:
        rig.contacts()
    message = str(info.value)
    assert "object::object" in message and "hand::finger0" in message
    assert "1.5 mm" in message
    # A pad tilted into the face: its far edge is 0.02 * sin(0.02) = 0.4 mm deep.
    R = RotationMatrix.MakeXRotation(0.02)
    centre = np.array([0.0, 0.03, 0.0]) - R.matrix() @ np.array([0.0, -0.002, -0.01])
    tilted = Rig(Box(0.1, 0.06, 0.08), [(PAD, at(centre, R))])
    with pytest.raises(PenetrationError, match="penetrate by 0.4 mm"):
        tilted.contacts()
    (c,) = rig.contacts(allow_penetration=True)
    assert c.psi == pytest.approx(-0.0015, abs=1e-12)
    np.testing.assert_allclose(c.nhat_O, [-1, 0, 0], atol=1e-9)


def test_bad_options_and_bodies():
    rig = Rig(Box(0.1, 0.06, 0.04), [(Sphere(R_TIP), at([0.05 + R_TIP, 0, 0]))])
    with pytest.raises(InvalidOptionError, match="distance_tolerance"):
        rig.contacts(distance_tolerance=-1.0)
    with pytest.raises(InvalidOptionError, match="patches"):
        rig.contacts(patches="centroid")
    with pytest.raises(InvalidOptionError, match="object_body"):
        find_contacts(rig.plant, rig.ctx, object_body=3.5)
    with pytest.raises(ModelError, match="no body named 'nope'"):
        find_contacts(rig.plant, rig.ctx, object_body="nope")
    assert find_contacts(rig.plant, rig.ctx, object_body="object::object")
    # the object as the hand: once "the hand has no bodies", now the cause
    with pytest.raises(InvalidOptionError, match="also listed as a body of the hand"):
        rig.contacts(hand=[rig.object])
    with pytest.raises(ModelError, match="hand has no bodies"):
        rig.contacts(hand=[])
    # A wrong item of a hand given as bodies is named as the hand's item, not
    # as the object_body (which was right); a generator is read once, so the
    # message shows the bodies it gave, not the spent generator's nothing.
    for hand in ([rig.fingers[0], 3], (b for b in [rig.fingers[0], None])):
        with pytest.raises(InvalidOptionError) as e:
            rig.contacts(hand=hand)
        assert str(e.value).startswith("hand[1] must be a RigidBody")
    with pytest.raises(InvalidOptionError) as e:
        rig.contacts(hand=(b for b in [rig.fingers[0], rig.object]))
    assert "(hand=['hand::finger0', 'object::object'])" in str(e.value)
    # An unknown name or index among them is named by its place too.
    for item in ("hand::nope", BodyIndex(99)):
        with pytest.raises(ModelError) as e:
            rig.contacts(hand=[rig.fingers[0], item])
        assert str(e.value).startswith("hand[1]: ")
    # The diagram's root context resolves to the plant's; object_body positional.
    from_root = find_contacts(rig.plant, rig.root, rig.object)
    assert [c.psi for c in from_root] == [c.psi for c in rig.contacts()]


def test_hand_selection():
    rig = Rig(
        Box(0.1, 0.06, 0.04),
        [
            (Sphere(R_TIP), at([0.05 + R_TIP, 0, 0])),
            (Sphere(R_TIP), at([-0.05 - R_TIP, 0, 0])),
        ],
    )
    assert len(rig.contacts()) == 2
    only = rig.contacts(hand=[rig.fingers[1]])
    assert [c.finger_body for c in only] == ["hand::finger1"]
    instance = rig.plant.GetModelInstanceByName("hand")
    assert len(rig.contacts(hand=instance)) == 2
    assert len(rig.contacts(hand="hand")) == 2
    assert len(rig.contacts(hand=["hand::finger0"])) == 1
    with pytest.raises(ModelError, match="no model instance named 'claw'"):
        rig.contacts(hand="claw")


def test_object_without_collision_geometry():
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    inertia = SpatialInertia.SolidSphereWithMass(0.1, 0.01)
    obj = plant.AddRigidBody("bare", plant.AddModelInstance("o"), inertia)
    finger = plant.AddRigidBody("f", plant.AddModelInstance("h"), inertia)
    plant.RegisterCollisionGeometry(
        finger, RigidTransform(), Sphere(0.01), "tip", ProximityProperties()
    )
    plant.Finalize()
    diagram = builder.Build()
    ctx = plant.GetMyContextFromRoot(diagram.CreateDefaultContext())
    with pytest.raises(ModelError, match="no collision geometry"):
        find_contacts(plant, ctx, object_body=obj)


def test_contacts_of_distances_from_the_pairwise_query_equal_find_contacts():
    # a flat pad patch, a sphere tip on an edge-free face and a far finger: the
    # pairwise query's pairs (within any reach >= the tolerance) give find_contacts'
    # contacts, in its order, bitwise
    rig = Rig(
        Box(0.1, 0.06, 0.04),
        [
            (Box(0.01, 0.02, 0.02), at([0.055 + GAP, 0.0, 0.0])),
            (Sphere(R_TIP), at([-0.05 - R_TIP, 0.01, 0.0])),
            (Sphere(R_TIP), at([0.0, 0.03 + R_TIP + 0.004, 0.0])),
        ],
    )
    expected = rig.contacts()
    query = rig.plant.get_geometry_query_input_port().Eval(rig.ctx)
    slot = {rig.plant.GetCollisionGeometriesForBody(b)[0]: b for b in rig.fingers}
    for reach in (1e-4, 0.01):
        results = []
        for pair in query.ComputeSignedDistancePairwiseClosestPoints(reach):
            body = slot.get(pair.id_A) or slot.get(pair.id_B)
            results.append((body, 0, 0, pair))
        results.sort(key=lambda r: int(r[0].index()))
        got = contacts_of_distances(
            rig.plant, rig.ctx, rig.object, query, results, distance_tolerance=1e-4
        )
        assert len(got) == len(expected) == 5  # four patch corners and one tip
        for a, b in zip(got, expected, strict=True):
            assert a.finger_geometry_label == b.finger_geometry_label
            assert np.array_equal(a.p_OC, b.p_OC)
            assert np.array_equal(a.nhat_O, b.nhat_O)
            assert a.psi == b.psi and a.normal_source == b.normal_source
    with pytest.raises(NoContactsError, match="closest finger geometry"):
        contacts_of_distances(
            rig.plant, rig.ctx, rig.object, query, results[2:], distance_tolerance=1e-4
        )


def test_staged_contacts_are_those_of_their_configuration():
    # stage_contacts reads a configuration; the context then moves on (a
    # planner's next candidate) before resolve_staged computes the points:
    # they must be the staged configuration's, for the batched tip route, the
    # scalar patch route and the scalar fallback of an uncertified tip alike
    from drakegrasp.plant import contact_pair
    from drakegrasp.plant.contacts import (
        resolve_staged,
        stage_contacts,
        staged_contacts,
    )

    rig = Rig(
        Box(0.1, 0.06, 0.04),
        [
            (Box(0.01, 0.02, 0.02), at([0.055 + GAP, 0.0, 0.0])),
            (Sphere(R_TIP), at([-0.05 - R_TIP, 0.01, 0.0])),
        ],
    )
    expected = rig.contacts()
    query = rig.plant.get_geometry_query_input_port().Eval(rig.ctx)
    slot = {rig.plant.GetCollisionGeometriesForBody(b)[0]: b for b in rig.fingers}
    results = sorted(
        (
            (slot.get(p.id_A) or slot.get(p.id_B), 0, 0, p)
            for p in query.ComputeSignedDistancePairwiseClosestPoints(1e-4)
        ),
        key=lambda r: int(r[0].index()),
    )
    staged = stage_contacts(
        rig.plant, rig.ctx, rig.object, query, results, distance_tolerance=1e-4
    )
    staged_scalar = stage_contacts(
        rig.plant, rig.ctx, rig.object, query, results, distance_tolerance=1e-4
    )
    for pending in staged_scalar.pending():  # as if the certificate failed
        pending.tip = None
    rig.translate_object([0.013, -0.02, 0.007])  # the next configuration
    rig.plant.SetFreeBodyPose(rig.ctx, rig.fingers[1], RigidTransform([0.3, -0.1, 0.2]))
    query = rig.plant.get_geometry_query_input_port().Eval(rig.ctx)
    query.ComputeSignedDistancePairwiseClosestPoints(0.0)  # the new poses
    resolve_staged([staged])
    for p in staged_scalar.pending():
        if p.points is None:
            p.points = contact_pair.pair_points(**p.args)
    for got in (staged_contacts(staged), staged_contacts(staged_scalar)):
        assert len(got) == len(expected) == 5
        for a, b in zip(got, expected, strict=True):
            assert a.finger_geometry_label == b.finger_geometry_label
            np.testing.assert_allclose(a.p_OC, b.p_OC, rtol=0, atol=1e-12)
            np.testing.assert_allclose(a.nhat_O, b.nhat_O, rtol=0, atol=1e-12)
            np.testing.assert_allclose(a.p_FC, b.p_FC, rtol=0, atol=1e-12)
            assert a.normal_source == b.normal_source
