"""The shipped models: generated files, package registration, inertias, scenes."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest
from pydrake.common import FindResourceOrThrow
from pydrake.geometry import Box, Convex, Cylinder, Sphere
from pydrake.multibody.parsing import PackageMap, Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import CalcSpatialInertia

from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant import find_contacts, models_dir, register_models
from drakegrasp.plant._shapes import flat_faces
from drakegrasp.plant.contacts import hand_bodies

MODELS = models_dir()


# The generator and its committed output in this checkout (the generator is not
# installed with the package, so an installed copy's models_dir() lacks it).
CHECKOUT_MODELS = Path(__file__).resolve().parents[2] / "models"


def _load_generator():
    spec = importlib.util.spec_from_file_location(
        "make_models", CHECKOUT_MODELS / "generator" / "make_models.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_committed_files_are_the_generators_output():
    generator = _load_generator()
    files = generator.all_files()
    assert "objects/hex_prism.obj" in files
    for rel, text in files.items():
        assert (CHECKOUT_MODELS / rel).read_text() == text, f"{rel} is stale"


def test_package_xml_names_drakegrasp():
    text = (MODELS / "package.xml").read_text()
    assert "<name>drakegrasp</name>" in text


def test_register_models_on_parser_and_package_map():
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    package_map = register_models(parser)
    assert package_map.GetPath("drakegrasp") == str(MODELS)
    register_models(parser)  # twice is harmless
    (box,) = parser.AddModels(url="package://drakegrasp/objects/box.sdf")
    assert plant.GetModelInstanceName(box) == "box"

    pm = PackageMap.MakeEmpty()
    assert register_models(pm) is pm
    assert Path(pm.GetPath("drakegrasp")) == MODELS
    with pytest.raises(InvalidOptionError, match="Parser or PackageMap"):
        register_models("not a parser")


def test_register_models_replaces_a_stale_path(tmp_path):
    pm = PackageMap.MakeEmpty()
    (tmp_path / "package.xml").write_text(
        "<package format='2'><name>drakegrasp</name></package>"
    )
    pm.Add("drakegrasp", str(tmp_path))
    register_models(pm)
    assert Path(pm.GetPath("drakegrasp")) == MODELS


def test_drakes_planar_gripper_ships_in_the_wheel():
    for name in ("planar_gripper.sdf", "planar_brick.sdf"):
        path = FindResourceOrThrow(f"drake/examples/planar_gripper/{name}")
        assert Path(path).is_file()


def _object_plant(name):
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    register_models(parser)
    (instance,) = parser.AddModels(url=f"package://drakegrasp/objects/{name}.sdf")
    plant.Finalize()
    return plant, plant.GetBodyByName(name, instance)


@pytest.mark.parametrize(
    "name, shape, lo, hi",
    [
        ("box", Box(0.05, 0.05, 0.10), 0.1, 0.5),
        ("cylinder", Cylinder(0.03, 0.12), 0.1, 0.5),
        ("sphere", Sphere(0.035), 0.05, 0.3),
        ("hex_prism", None, 0.05, 0.5),
    ],
)
def test_object_inertia_matches_drakes_uniform_density_inertia(name, shape, lo, hi):
    plant, body = _object_plant(name)
    if shape is None:
        shape = Convex(str(MODELS / "objects" / "hex_prism.obj"))
    M = body.default_spatial_inertia()
    mass = M.get_mass()
    assert lo < mass < hi  # a hand-held object's mass, kg
    unit = CalcSpatialInertia(shape, 1.0)  # Drake's own mass properties
    density = mass / unit.get_mass()
    assert 100 < density < 3000  # plausible materials, kg/m^3
    expected = CalcSpatialInertia(shape, density)
    np.testing.assert_allclose(M.get_com(), expected.get_com(), atol=1e-12)
    np.testing.assert_allclose(
        M.CalcRotationalInertia().CopyToFullMatrix3(),
        expected.CalcRotationalInertia().CopyToFullMatrix3(),
        rtol=1e-9,
        atol=1e-15,
    )


def test_hex_prism_inertia_closed_form():
    # Regular hexagon of side s: I_polar / A = 5 s^2 / 12 (and half of it about
    # an in-plane axis through the centre); prism of height h adds h^2 / 12.
    plant, body = _object_plant("hex_prism")
    M = body.default_spatial_inertia()
    m = M.get_mass()
    s = 0.025 / math.cos(math.pi / 6)
    h = 0.08
    volume = 1.5 * math.sqrt(3) * s * s * h
    assert m == pytest.approx(900.0 * volume, rel=1e-12)
    inertia = M.CalcRotationalInertia().CopyToFullMatrix3()
    expected = m * np.diag([5 * s * s / 24 + h * h / 12] * 2 + [5 * s * s / 12])
    np.testing.assert_allclose(inertia, expected, rtol=1e-12)


def test_hex_prism_mesh_is_convex_and_closed():
    shape = Convex(str(MODELS / "objects" / "hex_prism.obj"))
    faces = flat_faces(shape)
    assert len(faces) == 8  # 6 sides + 2 caps, coplanar triangles merged
    vertices = []
    for line in (MODELS / "objects" / "hex_prism.obj").read_text().splitlines():
        if line.startswith("v "):
            vertices.append([float(x) for x in line.split()[1:]])
    vertices = np.array(vertices)
    for n, d, poly in faces:
        assert np.all(vertices @ n <= d + 1e-12)  # every vertex behind every face
        assert len(poly) in (4, 6)
    # Side faces at 30 + 60 k degrees, 25 mm from the axis.
    sides = sorted(
        round(math.degrees(math.atan2(n[1], n[0]))) % 360
        for n, d, _ in faces
        if abs(n[2]) < 1e-12
    )
    assert sides == [30, 90, 150, 210, 270, 330]
    assert all(abs(d - 0.025) < 1e-12 for n, d, _ in faces if abs(n[2]) < 1e-12)


def test_hand_masses_and_sizes_are_realistic(scene_cache):
    plant = scene_cache("parallel_jaw_box").plant
    palm = plant.GetBodyByName("palm")
    assert 0.3 < palm.default_mass() < 2.0
    joint = plant.GetJointByName("left_finger_joint")
    stroke = 2 * (joint.position_upper_limits()[0] - joint.position_lower_limits()[0])
    assert 0.05 <= stroke <= 0.15  # total opening of common two-finger grippers
    plant = scene_cache("three_finger_sphere").plant
    revolute = [
        plant.get_joint(j)
        for j in plant.GetJointIndices(plant.GetModelInstanceByName("hand"))
        if plant.get_joint(j).type_name() == "revolute"
    ]
    assert len(revolute) == 9  # three fingers of three joints


EXPECTED_CONTACTS = {
    "parallel_jaw_box": 2,
    "parallel_jaw_cylinder": 2,
    "parallel_jaw_flat_box": 8,
    "three_finger_sphere": 3,
    "three_finger_hex_prism": 3,
    "planar_gripper_brick": 3,
}


def test_every_shipped_scene_is_listed_here(scene_cache):
    from drakegrasp.plant import list_scenes

    assert sorted(EXPECTED_CONTACTS) == sorted(i.name for i in list_scenes())


@pytest.mark.parametrize("name", sorted(EXPECTED_CONTACTS))
def test_scene_fingers_touch_exactly_and_nothing_else_touches(scene_cache, name):
    scene = scene_cache(name)
    plant, ctx = scene.plant, scene.plant_context
    contacts = find_contacts(plant, ctx, object_body=scene.object_body, hand=scene.hand)
    assert len(contacts) == EXPECTED_CONTACTS[name]
    # The closed-form joint values put the fingertips on the surface to
    # round-off.
    assert max(abs(c.psi) for c in contacts) < 1e-12
    touching = {(c.object_geometry, c.finger_geometry) for c in contacts}
    query = plant.get_geometry_query_input_port().Eval(ctx)
    for finger in hand_bodies(plant, scene.object_body, scene.hand):
        for gf in plant.GetCollisionGeometriesForBody(finger):
            for go in plant.GetCollisionGeometriesForBody(scene.object_body):
                if (go, gf) in touching:
                    continue
                distance = query.ComputeSignedDistancePairClosestPoints(go, gf).distance
                assert distance > 1e-3, (finger.name(), distance)


def test_scene_objects_float_freely(scene_cache):
    plant = scene_cache("parallel_jaw_box").plant
    body = plant.GetBodyByName("box")
    assert body.is_floating_base_body()
    assert plant.num_positions() == 2 + 7 and plant.num_velocities() == 2 + 6


def test_the_installed_models_package_is_data_only():
    """The generator lives beside the data and is not installed with it."""
    import fnmatch

    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10: the test extras install tomli
        import tomli as tomllib
    root = Path(__file__).resolve().parents[2]
    models = root / "models"
    config = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]
    globs = config["package-data"]["drakegrasp.models"]
    files = [p.relative_to(models).as_posix() for p in models.rglob("*") if p.is_file()]
    shipped = [f for f in files if any(fnmatch.fnmatch(f, g) for g in globs)]
    assert "scenes/parallel_jaw_box.yaml" in shipped
    assert "generator/make_models.py" in files
    assert not any(f.startswith("generator/") for f in shipped)
    assert [p.name for p in models.glob("*.py")] == ["__init__.py"]
