"""Meshcat primitives the drawings share: triangle meshes and arrows.

Parent-frame coordinates, metres; colours are Drake ``Rgba``.
"""

from __future__ import annotations

import numpy as np
from pydrake.geometry import Cylinder, Meshcat, Rgba
from pydrake.math import RigidTransform, RotationMatrix

from drakegrasp.core.validation import describe, plain_str, safe_norm
from drakegrasp.errors import InvalidOptionError
from drakegrasp.visualization.geometry import exact_cone_mesh

__all__: list[str] = []

_UNIT_CONE = exact_cone_mesh(1.0, 1.0, num_segments=16)
"""An arrow head's cone, 1 high and 1 in radius, opening along +x."""


def check_meshcat(meshcat) -> None:
    """Refuse anything that is not a Meshcat (or quacks like one)."""
    # Duck-typed, so wrappers of a Meshcat (recorders in tests) still work.
    if not isinstance(meshcat, Meshcat) and not all(
        callable(getattr(meshcat, name, None))
        for name in ("SetObject", "SetTransform", "Delete")
    ):
        raise InvalidOptionError(
            f"meshcat must be a pydrake.geometry.Meshcat, got {type(meshcat).__name__}"
        )


def check_path(name: str, value) -> str:
    """A Meshcat path: a string with something besides slashes, as a plain str.

    A ``str`` subclass is read once as the plain ``str`` it holds (its own
    ``strip``, ``encode`` or ``__format__`` may raise or lie), and an object
    whose ``__class__`` merely claims ``str`` is refused; a character that
    UTF-8 cannot encode (a lone surrogate) is refused here, not by pydrake's
    bare ``UnicodeEncodeError`` when Meshcat is called.
    """
    # type(), not isinstance(): an object whose __class__ claims str passes
    # isinstance, and str's own methods then raise a bare TypeError on it.
    text = plain_str(value)
    if type(text) is not str or not text.strip("/"):
        raise InvalidOptionError(
            f"{name} must be a non-empty path, got {describe(value)}"
        )
    try:
        text.encode("utf-8")
    except UnicodeError:
        raise InvalidOptionError(
            f"{name} {describe(text)} holds a character UTF-8 cannot encode "
            "(a lone surrogate?)"
        ) from None
    return text


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
    vector = np.asarray(vector, dtype=float)
    length = float(safe_norm(vector))
    if not (0.0 < length < np.inf):  # the callers draw finite, non-zero arrows
        return []
    head = min(0.35 * length, 5.0 * radius)
    shaft = length - head
    # The unit vector: Drake refuses to normalise one shorter than 1e-10 itself.
    R = RotationMatrix.MakeFromOneVector(vector / length, 2)
    meshcat.SetTransform(path, RigidTransform(R, tail))
    if shaft > 0:
        meshcat.SetObject(f"{path}/shaft", Cylinder(radius, shaft), rgba)
        meshcat.SetTransform(f"{path}/shaft", RigidTransform([0.0, 0.0, shaft / 2]))
    # Head: a cone with its apex at the tip, opening back along -z (the mesh
    # opens along +x; a rotation by π/2 about y takes +x to -z).
    v, f = _UNIT_CONE  # scaled, not built with μ = 2r / head (which overflows)
    v = v * np.array([head, 2.0 * radius, 2.0 * radius])
    _set_mesh(meshcat, f"{path}/head", v, f, rgba)
    meshcat.SetTransform(
        f"{path}/head",
        RigidTransform(RotationMatrix.MakeYRotation(np.pi / 2), [0.0, 0.0, length]),
    )
    return ([f"{path}/shaft"] if shaft > 0 else []) + [f"{path}/head"]
