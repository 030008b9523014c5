"""A scene may add a mesh (``.obj``) as a model; a vertex that is not finite is
refused, naming the scene and the line (Drake's parser reads it as finite)."""

from __future__ import annotations

import pytest

import drakegrasp as dg
from drakegrasp.plant.scene import load_scene

_TET = (  # a tetrahedron with 50 mm legs, faces wound outwards
    "v {a} 0 0\nv 0.05 0 0\nv 0 0.05 0\nv 0 0 0.05\n"
    "f 1 3 2\nf 1 4 3\nf 1 2 4\nf 2 3 4\n"
)

_SCENE = """\
directives:
- add_model:
    name: gripper
    file: package://drakegrasp/hands/parallel_jaw.sdf
- add_weld:
    parent: world
    child: gripper::palm
- add_model:
    name: mesh
    file: tet.obj
drakegrasp:
  object_body: mesh::mesh
  hand: gripper
  mu: 0.5
"""


@pytest.mark.parametrize("bad", ["nan", "inf", "-inf"])
def test_a_scene_with_a_non_finite_mesh_vertex_is_refused(tmp_path, bad):
    (tmp_path / "tet.obj").write_text(_TET.format(a=bad))
    scene = tmp_path / "scene.yaml"
    scene.write_text(_SCENE)
    with pytest.raises(dg.SceneError, match=r"tet\.obj', line 1: a vertex must"):
        load_scene(scene)


def test_a_scene_with_a_finite_mesh_loads(tmp_path):
    (tmp_path / "tet.obj").write_text(_TET.format(a=0))
    scene = tmp_path / "scene.yaml"
    scene.write_text(_SCENE)
    loaded = load_scene(scene)
    body = loaded.plant.GetBodyByName("mesh")
    assert body.default_mass() == pytest.approx(1000 * 0.05**3 / 6)
