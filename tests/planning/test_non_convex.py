"""A non-convex collision mesh is planned as its hull, and the planner says so.

Drake's point contact and the planner treat a ``Mesh`` as its convex hull:
all six best WSG-50 grasps of a torus put their contacts across its hole,
reported as force closure, without a word.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from drakegrasp.planning import planning_scene
from drakegrasp.planning.planner import object_surface
from drakegrasp.planning.surface import NonConvexMeshWarning


def _obj(path, vertices, faces):
    path.write_text(
        "".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in vertices)
        + "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in faces)
    )
    return path


def _prism(outline, height=0.04):
    """A closed prism over a counter-clockwise outline (x, y), metres."""
    n = len(outline)
    vertices = [(x, y, z) for z in (0.0, height) for x, y in outline]
    faces = [tuple(range(n - 1, -1, -1)), tuple(range(n, 2 * n))]
    faces += [(i, (i + 1) % n, n + (i + 1) % n, n + i) for i in range(n)]
    return vertices, faces


L_SHAPE = [(0, 0), (0.06, 0), (0.06, 0.02), (0.02, 0.02), (0.02, 0.06), (0, 0.06)]
SQUARE = [(0, 0), (0.06, 0), (0.06, 0.06), (0, 0.06)]


def _surface(path):
    # the shipped jaw: the default hand (the WSG-50) needs drake_models
    hand = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
    scene = planning_scene(str(path), hand_url=hand)
    return object_surface(scene.plant, scene.context, scene.object_body)


def test_an_l_shaped_mesh_is_warned_of_with_its_share(tmp_path):
    path = _obj(tmp_path / "ell.obj", *_prism(L_SHAPE))
    # second route: the L's area is 0.06² - 0.04² = 0.0020 m², its hull's the
    # square less the corner triangle the hull cuts off, 0.0036 - 0.0008
    share = 0.0020 / 0.0028
    with pytest.warns(NonConvexMeshWarning, match=f"{100 * share:.0f}% of its hull"):
        _surface(path)


def test_a_convex_mesh_is_not(tmp_path):
    path = _obj(tmp_path / "block.obj", *_prism(SQUARE))
    with warnings.catch_warnings():
        warnings.simplefilter("error", NonConvexMeshWarning)
        surface = _surface(path)
    assert np.isclose(surface.pieces[0].triangles.shape[0], 12)
