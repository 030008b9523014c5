"""Point clouds sampled from an object's collision geometry, for the cloud tests."""

from __future__ import annotations

import numpy as np

from drakegrasp.planning import object_surface


def sample_cloud(full, n: int, seed: int = 0, view=None):
    """``(points, normals)`` on the object of ``full`` (a planning scene), world frame.

    ``view``: keep only what a camera there sees (the object convex).
    """
    surface = object_surface(full.plant, full.context, full.object_body)
    p, nrm, _ = surface.sample(n, np.random.default_rng(seed))
    if view is not None:
        seen = np.sum(nrm * (np.asarray(view) - p), axis=1) > 0
        p, nrm = p[seen], nrm[seen]
    return p, nrm


def box_points(n: int, seed: int, half=(0.025, 0.03, 0.05)) -> np.ndarray:
    """A box's faces sampled at random (m, world frame): points only.

    Each point picks a face axis, then a side; the faces are not weighted by
    their area.
    """
    rng = np.random.default_rng(seed)
    axis = rng.integers(0, 3, n)
    p = rng.uniform(-1.0, 1.0, (n, 3))
    p[np.arange(n), axis] = rng.choice([-1.0, 1.0], size=n)
    return p * np.asarray(half)
