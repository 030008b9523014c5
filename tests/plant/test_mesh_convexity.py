"""A non-convex collision mesh is analysed as its hull, and the analysis says so.

Drake's signed distances treat a ``Mesh`` as its convex hull, so
``analyze_grasp`` can report contacts where the object has no surface: the
flat jaw's best grasp of an L-shaped prism puts pad corners over the L's
missing square, and the analysis used to say nothing.  The second routes:
volumes from the prisms' areas, and the contact points tested against the L.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from pydrake.geometry import Box, Mesh

import drakegrasp as dg
from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.planning.grasp_scene import grasp_scene_text
from drakegrasp.plant.mesh_convexity import (
    NON_CONVEX_SHARE,
    NonConvexMeshWarning,
    hull_share,
    hull_volume,
)
from drakegrasp.plant.scene import load_scene

FLAT = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
HEIGHT = 0.04
L_SHAPE = [(0, 0), (0.06, 0), (0.06, 0.02), (0.02, 0.02), (0.02, 0.06), (0, 0.06)]
SQUARE = [(0, 0), (0.06, 0), (0.06, 0.06), (0, 0.06)]
L_SHARE = 0.0020 / 0.0028  # the L's area over its hull's (the square less a corner)


def _prism_obj(path, outline, height=HEIGHT):
    """A closed prism over a counter-clockwise outline (x, y), metres, as OBJ."""
    n = len(outline)
    vertices = [(x, y, z) for z in (0.0, height) for x, y in outline]
    faces = [tuple(range(n - 1, -1, -1)), tuple(range(n, 2 * n))]
    faces += [(i, (i + 1) % n, n + (i + 1) % n, n + i) for i in range(n)]
    path.write_text(
        "".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in vertices)
        + "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in faces)
    )
    return path


@pytest.mark.parametrize("scale", [1.0, 2.5])
def test_shares_are_the_prisms_areas(tmp_path, scale):
    ell = Mesh(str(_prism_obj(tmp_path / "ell.obj", L_SHAPE)), scale)
    block = Mesh(str(_prism_obj(tmp_path / "block.obj", SQUARE)), scale)
    assert hull_share(ell) == pytest.approx(L_SHARE, rel=1e-12)
    assert hull_share(block) == pytest.approx(1.0, rel=1e-12)
    want = 0.0028 * HEIGHT * scale**3  # the L's hull: a prism over 0.0028 m²
    assert hull_volume(ell.GetConvexHull()) == pytest.approx(want, rel=1e-12)


def _shifted(outline, dx, dy):
    return [(x + dx, y + dy) for x, y in outline]


@pytest.mark.parametrize("shift", [(0.0, 0.0), (-0.03, -0.03), (0.5, 0.2)])
def test_other_shapes_and_open_meshes_have_no_share(tmp_path, shift):
    # Drake's CalcVolume measures an open mesh too: a box missing a side
    # read 0.83 of its hull about its centre (a false warning), 3.78 away
    assert hull_share(Box(1, 2, 3)) is None
    block = _prism_obj(tmp_path / "block.obj", _shifted(SQUARE, *shift))
    open_box = tmp_path / "open.obj"
    open_box.write_text("\n".join(block.read_text().splitlines()[:-1]) + "\n")
    assert hull_share(Mesh(str(open_box))) is None
    assert hull_share(Mesh(str(block))) == pytest.approx(1.0, rel=1e-12)


def test_a_rewritten_file_is_measured_again(tmp_path):
    path = tmp_path / "shape.obj"
    _prism_obj(path, SQUARE)
    assert hull_share(Mesh(str(path))) == pytest.approx(1.0, rel=1e-12)
    _prism_obj(path, L_SHAPE)  # another size and content, the same path
    assert hull_share(Mesh(str(path))) == pytest.approx(L_SHARE, rel=1e-12)


def _written_scene(tmp_path, outline):
    """The flat jaw's best grasp of a prism, written and loaded as a scene."""
    obj = _prism_obj(tmp_path / "prism.obj", outline)
    scene = planning_scene(str(obj), hand_url=FLAT)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NonConvexMeshWarning)  # the planner's
        result = plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=60, mu=0.5, seed=0, robustness_samples=4,
        )  # fmt: skip
    path = tmp_path / "grasp.yaml"
    analysed = tmp_path / "analysed.obj"  # the planner warned of its own file
    analysed.write_text(obj.read_text())
    path.write_text(
        grasp_scene_text(
            scene.plant,
            scene.context,
            result[0],
            object_body=scene.object_body,
            hand_file=FLAT,
            object_file=analysed,
            mu=0.5,
            folder=tmp_path,
        )  # fmt: skip
    )
    return load_scene(path)


def _in_ell(p_O) -> bool:
    x, y = p_O[0], p_O[1]
    return (x <= 0.02 + 1e-9 or y <= 0.02 + 1e-9) and -1e-9 <= min(x, y)


def test_analysing_an_l_warns_where_a_contact_is_off_the_object(tmp_path):
    scene = _written_scene(tmp_path, L_SHAPE)
    with pytest.warns(NonConvexMeshWarning, match=r"71% of its hull's\): this") as w:
        report = dg.analyze_grasp(
            scene.plant, scene.plant_context, scene.object_body,
            hand=scene.hand, mu=0.5,
        )  # fmt: skip
    assert sum(issubclass(r.category, NonConvexMeshWarning) for r in w) == 1
    with warnings.catch_warnings(record=True) as again:  # once per mesh file
        warnings.simplefilter("always")
        dg.analyze_grasp(
            scene.plant, scene.plant_context, scene.object_body,
            hand=scene.hand, mu=0.5,
        )  # fmt: skip
    assert not [r for r in again if issubclass(r.category, NonConvexMeshWarning)]
    # the warning is not idle: this grasp touches where the L has no surface
    off = [c.p_OC for c in report.contacts if not _in_ell(c.p_OC)]
    assert off, "expected a contact over the L's missing square"


def test_analysing_a_convex_prism_does_not(tmp_path):
    scene = _written_scene(tmp_path, SQUARE)
    with warnings.catch_warnings():
        warnings.simplefilter("error", NonConvexMeshWarning)
        report = dg.analyze_grasp(
            scene.plant, scene.plant_context, scene.object_body,
            hand=scene.hand, mu=0.5,
        )  # fmt: skip
    assert report.contacts


def test_a_plan_warns_once(tmp_path):
    obj = _prism_obj(tmp_path / "ell.obj", L_SHAPE)
    scene = planning_scene(str(obj), hand_url=FLAT)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=30, mu=0.5, seed=0, robustness_samples=4,
        )  # fmt: skip
    said = [str(r.message) for r in w if issubclass(r.category, NonConvexMeshWarning)]
    assert len(said) == 1 and "the planner" in said[0]


def test_the_planning_module_keeps_its_names():
    from drakegrasp.planning import surface

    assert surface.NonConvexMeshWarning is NonConvexMeshWarning
    assert surface.NON_CONVEX_SHARE == NON_CONVEX_SHARE
    assert np.isclose(NON_CONVEX_SHARE, 0.95)
