"""Gravity turned around a grasped object: the shake test's load schedule.

Gravity (``m g``, on the object only, at its centre of mass; ``g`` the
magnitude of the plant's own gravity field, :func:`plant_gravity`) is zero while
the fingers seat, held along the plant's gravity (the world's −z by Drake's
default) while the grasp settles, then turned
through a sequence of directions, each held for a phase; between two
directions it turns along the great circle through them at a constant rate,
so its magnitude stays ``m g`` (``_turned``), opposite directions
included.  ``_TurnedGravity`` is the Drake ``LeafSystem`` that applies it
to the plant as an externally applied spatial force.
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import ExternallyAppliedSpatialForce
from pydrake.systems.framework import LeafSystem

from drakegrasp.errors import ModelError

__all__ = ["DEFAULT_DIRECTIONS", "GRAVITY", "plant_gravity"]

GRAVITY = 9.81
"""Standard gravity, m/s²: the strength of Drake's default gravity field.

No longer the weight's magnitude: the planner (``squeeze_needed``,
``torque_needed``) and the shake test weigh the object with the plant's own
field (:func:`plant_gravity`), as ``analyze_grasp(load="gravity")`` does.  It
bounds the checks made before any plant is built (an ``object_mass`` whose
weight at standard gravity is no float is refused before a shake test
simulates anything) and stays importable for the callers that used it."""


def plant_gravity(plant) -> float:
    """The magnitude ``|g|`` (m/s²) of the plant's gravity field: N per kg of weight.

    ``plant.gravity_field().gravity_vector()`` in the world frame, as
    :func:`~drakegrasp.plant.load.gravity_wrench` reads it; only its length
    is used (the planner holds the weight in every direction, the shake test
    turns it around).  9.81 exactly for Drake's default field; 0 for a plant
    whose gravity was set to zero.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized or not: the field is read as it stands.

    Returns
    -------
    float
        ``|g| >= 0``, finite.

    Raises
    ------
    ModelError
        A field that is not finite (Drake takes ``inf`` and NaN), or whose
        length is no float (components near 1e308), named with its vector.
    """
    return _gravity_field(plant)[0]


def _gravity_field(plant) -> tuple[float, np.ndarray]:
    """The plant's gravity field, read once: ``(|g|, g_W)``.

    ``|g|`` as :func:`plant_gravity` returns it (m/s², finite, >= 0) and
    ``g_W`` the field's vector (3,) in the world frame, m/s², from the same
    read, so that a caller who needs the direction too (the shake settles
    along ``g_W / |g|``) does not ask the plant twice.

    Raises
    ------
    ModelError
        As :func:`plant_gravity`.
    """
    g_W = np.asarray(plant.gravity_field().gravity_vector(), dtype=float)
    g = math.hypot(*g_W)  # |(0, 0, -9.81)| is 9.81 to the bit; no overflow inside
    if not math.isfinite(g):
        raise ModelError(
            f"the plant's gravity field {g_W.tolist()} m/s² has no finite "
            "magnitude: set a finite one (plant.mutable_gravity_field()"
            ".set_gravity_vector) to weigh the object with"
        )
    return g, g_W


DEFAULT_DIRECTIONS = (
    (1.0, 0.0, 0.0),
    (0.0, -1.0, 0.0),
    (0.0, 0.0, 1.0),
    (-1.0, 0.0, 0.0),
    (0.0, 1.0, 0.0),
    (0.0, 0.0, -1.0),
)
"""World directions gravity turns through after settling (each
consecutive pair orthogonal: every blend turns gravity by 90°, the first too
where the plant's gravity is Drake's default −z)."""


class _TurnedGravity(LeafSystem):
    """Outputs ``m g(t)`` on one body at its centre of mass (world frame).

    ``weight``: ``m |g|`` (N), the force's magnitude while gravity acts;
    ``schedule(t)``: its unit direction, or zero (:func:`_schedule`).
    """

    def __init__(self, body_index, weight: float, p_BoBcm_B, schedule):
        super().__init__()
        self._body, self._weight = body_index, float(weight)
        self._com = np.asarray(p_BoBcm_B)
        self._schedule = schedule
        self.DeclareAbstractOutputPort(
            "spatial_forces",
            lambda: AbstractValue.Make([ExternallyAppliedSpatialForce()]),
            self._calc,
        )

    def _calc(self, context, output):
        force = ExternallyAppliedSpatialForce()
        force.body_index = self._body
        force.p_BoBq_B = self._com
        g = self._schedule(context.get_time())
        force.F_Bq_W = SpatialForce(np.zeros(3), self._weight * g)
        output.set_value([force])


def _turned(a: np.ndarray, b: np.ndarray, s: float) -> np.ndarray:
    """Unit vector ``a`` turned towards unit ``b`` by the fraction ``s`` of the angle.

    Along the great circle through both (spherical linear interpolation), at a
    constant rate; for opposite vectors, about an axis perpendicular to ``a``
    (the world axis least aligned with ``a``, made perpendicular).  The result
    is a unit vector for every ``s`` in [0, 1], never the zero vector that a
    linear blend of opposite vectors passes through.
    """
    if s >= 1.0:
        return b
    cos = float(np.clip(a @ b, -1.0, 1.0))
    across = b - cos * a  # b's part perpendicular to a, of length sin(angle)
    sin = float(np.linalg.norm(across))
    if sin > 1e-8:
        u = across / sin
    elif cos > 0.0:
        return b  # the same direction
    else:  # opposite: any perpendicular turns a onto b
        e = np.zeros(3)
        e[int(np.argmin(np.abs(a)))] = 1.0
        u = e - (e @ a) * a
        u /= np.linalg.norm(u)
    angle = s * float(np.arctan2(sin, cos))
    v = np.cos(angle) * a + np.sin(angle) * u
    return v / np.linalg.norm(v)


def _schedule(seat, settle, phase, blend, directions, down=(0.0, 0.0, -1.0)):
    """Gravity's unit direction at time t (zero while the fingers seat).

    ``down`` (a unit vector, world frame) is the settling direction: the
    plant's own gravity's (the world's −z by Drake's default).
    ``directions`` are unit vectors; from each to the next, gravity turns over
    ``blend`` seconds along the great circle (:func:`_turned`), so its
    magnitude stays ``m g`` throughout.
    """
    dirs = [np.asarray(down, dtype=float), *np.asarray(directions, float)]

    def g(t: float) -> np.ndarray:
        if t < seat:
            return np.zeros(3)  # the fingers seat on the object first
        t -= seat
        if t < settle:
            return dirs[0]
        k = min(int((t - settle) // phase), len(dirs) - 2)
        s = min((t - settle - k * phase) / blend, 1.0) if blend > 0 else 1.0
        return _turned(dirs[k], dirs[k + 1], s)

    return g
