"""Meshcat primitives the drawings share: triangle meshes and arrows.

Parent-frame coordinates, metres; colours are Drake ``Rgba``.
"""

from __future__ import annotations

import numpy as np
from pydrake.geometry import Cylinder, Meshcat, Rgba
from pydrake.math import RigidTransform, RotationMatrix

from drakegrasp.visualization.geometry import exact_cone_mesh

__all__: list[str] = []


def _set_mesh(meshcat: Meshcat, path: str, vertices, faces, rgba: Rgba, **kw) -> None:
    meshcat.SetTriangleMesh(
        path,
        np.asfortranarray(np.asarray(vertices, dtype=float).T),
        np.asfortranarray(np.asarray(faces, dtype=np.int32).T),
        rgba,
        **kw,
    )


def _draw_arrow(
    meshcat: Meshcat,
    path: str,
    tail: np.ndarray,
    vector: np.ndarray,
    *,
    radius: float,
    rgba: Rgba,
) -> list[str]:
    """Arrow from ``tail`` along ``vector`` (parent-frame coordinates).

    Returns the paths of its parts (shaft, head).
    """
    length = float(np.linalg.norm(vector))
    head = min(0.35 * length, 5.0 * radius)
    shaft = length - head
    R = RotationMatrix.MakeFromOneVector(vector, 2)
    meshcat.SetTransform(path, RigidTransform(R, tail))
    if shaft > 0:
        meshcat.SetObject(f"{path}/shaft", Cylinder(radius, shaft), rgba)
        meshcat.SetTransform(f"{path}/shaft", RigidTransform([0.0, 0.0, shaft / 2]))
    # Head: a cone with its apex at the tip, opening back along -z (the mesh
    # opens along +x; a rotation by π/2 about y takes +x to -z).
    v, f = exact_cone_mesh(2.0 * radius / head, head, num_segments=16)
    _set_mesh(meshcat, f"{path}/head", v, f, rgba)
    meshcat.SetTransform(
        f"{path}/head",
        RigidTransform(RotationMatrix.MakeYRotation(np.pi / 2), [0.0, 0.0, length]),
    )
    return ([f"{path}/shaft"] if shaft > 0 else []) + [f"{path}/head"]
