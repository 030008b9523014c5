r"""The object's size: a length to divide moments by.

Ferrari–Canny's ε compares forces with moments, so it needs a length
``b_s`` that turns a moment into a force (``m / b_s``).  The grasp's own
characteristic length (the farthest contact from O's origin) changes with the
grasp; a number meant to compare grasps of one object should use a length of
the object.  :func:`object_radius` gives one: the radius of a sphere centred
at the origin of the object's body frame O that contains every collision
geometry of the body (each geometry through the sphere that bounds its shape;
a mesh through its convex hull, which is what Drake's queries see).

``drakegrasp analyze`` prints ε with ``torque_scale=object_radius(...)``
(:func:`~drakegrasp.quality.epsilon.ferrari_canny`) and names the length.
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context

from drakegrasp.core.calls import checked_call
from drakegrasp.errors import ModelError
from drakegrasp.plant._shapes import bounding_sphere
from drakegrasp.plant.validation import (
    plant_context_of,
    query_object_of,
    resolve_object_body,
    scoped_name,
)

__all__ = ["SCALE_NAME", "object_radius"]

SCALE_NAME = "the radius about O's origin that bounds the object's collision geometry"
"""What the length of :func:`object_radius` is, in words for a report."""


@checked_call
def object_radius(plant: MultibodyPlant, plant_context: Context, object_body) -> float:
    """Radius of a sphere about the object's origin that holds its geometry.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized, registered with a ``SceneGraph``.
    plant_context : Context
        The plant's context or the diagram's root context.
    object_body : RigidBody, BodyIndex or str

    Returns
    -------
    float
        ``max_g (|p_OGc| + r_g)`` over the body's collision geometries ``g``,
        with ``Gc`` the centre and ``r_g`` the radius of the sphere that bounds
        ``g``'s shape; metres, > 0.  It does not depend on the object's pose.

    Raises
    ------
    ModelError
        The body has no collision geometry, only half spaces, or a shape
        drakegrasp cannot bound.
    InvalidContextError
        A bad context (see :func:`~drakegrasp.plant.validation.plant_context_of`).
    """
    plant_context = plant_context_of(plant, plant_context)
    body = resolve_object_body(plant, object_body)
    query = query_object_of(plant, plant_context)
    inspector = query.inspector()
    radius = 0.0
    for g in plant.GetCollisionGeometriesForBody(body):
        centre_G, r = bounding_sphere(inspector.GetShape(g))
        p_OGc = inspector.GetPoseInFrame(g).multiply(centre_G)
        radius = max(radius, float(np.linalg.norm(p_OGc)) + r)
    if not (0.0 < radius < math.inf):
        raise ModelError(
            f"{scoped_name(plant, body)!r} has no bounded collision geometry "
            f"(radius {radius:g} m): give the object a collision shape, or pass "
            "a length of your own as torque_scale"
        )
    return radius
