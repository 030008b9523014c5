r"""What each finger does to the object in one sample: its :class:`FingerLoad`.

- :func:`finger_loads_from_results` reads, per finger body, the contact force
  that the plant's contact model applied to the object (``ContactResults``:
  point pairs and hydroelastic surfaces), the **friction in use**
  :math:`\|f_t\| / (\mu f_n)` with the plant's own friction coefficient μ of
  the pair (1 means sliding: the force sits on the cone's boundary), and the
  slip speed at the contact.
- :func:`finger_motion_from_contacts` gives what geometry alone can see: which
  fingers press on the object, and the slip and separation speeds of the
  object's contact points against the fingers' material points, computed from
  the plant's velocities; forces, and so friction in use, are unknown there
  (NaN).

Speeds are m/s, forces newtons.  A point pair's slip speed is Drake's own
(``PointPairContactInfo.slip_speed()``); a hydroelastic surface carries no
slip speed in a discrete plant's results, so it is computed from the bodies'
spatial velocities at the surface's centroid, tangent to its mean normal.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from pydrake.geometry import QueryObject
from pydrake.multibody.plant import (
    ContactResults,
    DiscreteContactApproximation,
    MultibodyPlant,
)
from pydrake.systems.framework import Context

from drakegrasp.core.serialize import jsonable
from drakegrasp.errors import ModelError
from drakegrasp.plant.contacts import PlantContact, _scoped_name
from drakegrasp.plant.friction import pair_friction

__all__ = [
    "FORCE_FLOOR",
    "FingerLoad",
    "finger_loads_from_results",
    "finger_motion_from_contacts",
    "point_velocity",
    "split_along",
]

_NO_NORMAL = np.full(3, np.nan)
FORCE_FLOOR = 1e-6
"""Normal force (N) at or below which a reported pair carries no load."""


@dataclass(frozen=True)
class FingerLoad:
    """What one finger body does to the object in one sample.

    Attributes
    ----------
    finger_body : str
        Scoped name ``model::body``.
    touching : bool
        The finger presses on the object: a reported pair with normal force
        above ``FORCE_FLOOR`` (1e-6 N); in geometry mode, a contact that is not
        separating and whose geometries touch or overlap (``ψ <= 0``: the
        plant's contact models push only then, so a finger within the distance
        tolerance but apart from the object is analysed, not pressing).
    normal_force : float
        Total normal force on the object, N (NaN when the source cannot see
        forces).
    tangential_force : float
        Magnitude of the total tangential force on the object, N (NaN likewise).
    mu : float
        The plant's friction coefficient of the pair
        (:func:`~drakegrasp.plant.friction.pair_friction`: Drake's combination of
        the two geometries' coefficients; the largest ratio's pair when
        several), NaN when unknown.
    friction_use : float
        Largest ``‖f_t‖/(μ f_n)`` over this finger's pairs (0 without load, NaN
        when forces are unknown).
    slip_speed : float
        Largest tangential speed of the object against the finger at a
        contact, m/s (0 without contact).
    normal_W : (3,) float
        Mean unit contact normal into the object, in the world frame W (NaN
        without contact).
    """

    finger_body: str
    touching: bool
    normal_force: float
    tangential_force: float
    mu: float
    friction_use: float
    slip_speed: float
    normal_W: np.ndarray = field(default_factory=lambda: _NO_NORMAL.copy())

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return jsonable(self.__dict__)


def point_velocity(plant, plant_context, body, p_WP: np.ndarray) -> np.ndarray:
    """Velocity in W of the material point of ``body`` at ``p_WP`` (in W), m/s."""
    V = plant.EvalBodySpatialVelocityInWorld(plant_context, body)
    p_WBo = plant.EvalBodyPoseInWorld(plant_context, body).translation()
    return np.asarray(V.translational()) + np.cross(V.rotational(), p_WP - p_WBo)


def _unit_or_nan(v: np.ndarray) -> np.ndarray:
    norm = float(np.linalg.norm(v))
    return v / norm if norm > 0 else _NO_NORMAL


def split_along(v: np.ndarray, n: np.ndarray) -> tuple[float, float]:
    """(component along unit n, magnitude of the rest)."""
    along = float(v @ n)
    return along, float(np.linalg.norm(v - along * n))


def finger_loads_from_results(
    plant: MultibodyPlant,
    plant_context: Context,
    contact_results: ContactResults,
    query_object: QueryObject,
    *,
    object_body,
    fingers,
) -> list[FingerLoad]:
    """Per finger body, the force, friction in use and slip that a step reported.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
        Holds the step's positions and velocities (slip of hydroelastic
        surfaces is computed from them).
    contact_results : ContactResults
        The plant's contact results of the step.
    query_object : QueryObject
        Names the geometries and holds their proximity properties.
    object_body : RigidBody
    fingers : sequence of RigidBody
        The hand bodies, in the order of the output.

    Returns
    -------
    list of FingerLoad
        One per finger body, in ``fingers`` order.  Forces are those the hand
        applies to the object; pairs with bodies outside the hand are ignored.
    """
    inspector = query_object.inspector()
    index = {b.index(): k for k, b in enumerate(fingers)}
    # Per finger: force sum, normal-weighted sum, largest ratio (and its mu), slip.
    f_sum = [np.zeros(3) for _ in fingers]
    fn_sum = [0.0] * len(fingers)
    ratio = [0.0] * len(fingers)
    mus = [np.nan] * len(fingers)
    slip = [0.0] * len(fingers)
    pressed = [False] * len(fingers)
    n_sum = [np.zeros(3) for _ in fingers]

    def body_of(gid):
        return plant.GetBodyFromFrameId(inspector.GetFrameId(gid))

    def record(k, f_W, n_W, mu, slip_speed):
        f_n, f_t = split_along(f_W, n_W)
        f_sum[k] += f_W
        fn_sum[k] += f_n
        if f_n > FORCE_FLOOR:
            pressed[k] = True
            n_sum[k] += f_n * n_W
            r = f_t / (mu * f_n) if mu > 0 else np.inf
            if r >= ratio[k]:
                ratio[k], mus[k] = r, mu
            slip[k] = max(slip[k], slip_speed)
        elif np.isnan(mus[k]):
            mus[k] = mu

    obj = object_body.index()
    for i in range(contact_results.num_point_pair_contacts()):
        info = contact_results.point_pair_contact_info(i)
        pp = info.point_pair()
        a, b = info.bodyA_index(), info.bodyB_index()
        if a == obj and b in index:  # force on B is contact_force(); nhat_BA into A
            k, f_W, n_W = index[b], -np.asarray(info.contact_force()), pp.nhat_BA_W
        elif b == obj and a in index:
            k, f_W, n_W = index[a], np.asarray(info.contact_force()), -pp.nhat_BA_W
        else:
            continue
        mu = pair_friction(plant, query_object, pp.id_A, pp.id_B)
        record(k, f_W, np.asarray(n_W), mu, float(info.slip_speed()))
    for i in range(contact_results.num_hydroelastic_contacts()):
        info = contact_results.hydroelastic_contact_info(i)
        surface = info.contact_surface()
        m, n = body_of(surface.id_M()), body_of(surface.id_N())
        F_on_M = np.asarray(info.F_Ac_W().translational())  # on M's body, at c
        if m.index() == obj and n.index() in index:
            k, finger, f_W, sign = index[n.index()], n, F_on_M, 1.0
        elif n.index() == obj and m.index() in index:
            k, finger, f_W, sign = index[m.index()], m, -F_on_M, -1.0
        else:
            continue
        mesh = surface.tri_mesh_W() if surface.is_triangle() else surface.poly_mesh_W()
        normal = sum(
            mesh.area(f) * np.asarray(mesh.face_normal(f))
            for f in range(mesh.num_faces())
        )
        n_W = sign * normal / np.linalg.norm(normal)  # face normals: out of N, into M
        c_W = np.asarray(surface.centroid())
        v_rel = point_velocity(plant, plant_context, object_body, c_W)
        v_rel = v_rel - point_velocity(plant, plant_context, finger, c_W)
        mu = pair_friction(plant, query_object, surface.id_M(), surface.id_N())
        record(k, f_W, n_W, mu, split_along(v_rel, n_W)[1])
    out = []
    for k, body in enumerate(fingers):
        f_n = fn_sum[k]
        out.append(
            FingerLoad(
                finger_body=_scoped_name(plant, body),
                touching=pressed[k],
                normal_force=f_n,
                tangential_force=float(
                    np.sqrt(max(float(f_sum[k] @ f_sum[k]) - f_n * f_n, 0.0))
                ),
                mu=mus[k],
                friction_use=ratio[k],
                slip_speed=slip[k],
                normal_W=_unit_or_nan(n_sum[k]),
            )
        )
    return out


def _opens_sliding_contacts(plant: MultibodyPlant) -> bool:
    """Whether the plant's contact model opens a sliding contact at ``μ ‖v_t‖``.

    Drake's convex approximations (SAP, similar, lagged) of a discrete plant
    do; TAMSI and a continuous plant do not.
    """
    if not plant.time_step() > 0.0:
        return False
    approximation = plant.get_discrete_contact_approximation()
    return approximation != DiscreteContactApproximation.kTamsi


def _dilation(plant, query_object, contact: PlantContact, opens: bool) -> float:
    """``μ`` of the pair when the contact model opens sliding contacts, else 0."""
    if not opens:
        return 0.0
    try:
        return pair_friction(
            plant, query_object, contact.object_geometry, contact.finger_geometry,
            rule="dynamic",
        )  # fmt: skip
    except ModelError:  # no friction property: no allowance
        return 0.0


def finger_motion_from_contacts(
    plant: MultibodyPlant,
    plant_context: Context,
    contacts: list[PlantContact],
    *,
    object_body,
    fingers,
    separation_speed: float,
    query_object: QueryObject | None = None,
) -> tuple[list[PlantContact], list[FingerLoad]]:
    """Keep the contacts that are not separating; per finger, whether it presses.

    A contact found within the distance tolerance counts only if its object
    point does not move away from the finger's material point (``p_FC``) along
    the inward normal faster than ``separation_speed`` plus, on a discrete
    plant with a convex contact approximation (SAP, similar, lagged), ``μ``
    times its slip speed: those models let a sliding contact that still pushes
    open at ``μ ‖v_t‖`` (measured: 0.49 at μ = 0.5, 0.99 at μ = 1; TAMSI: 0),
    which read as separating and lost a sliding grip ("no contact" under a
    4.7 N load).  Of those, a finger presses on the object where its geometry
    touches or overlaps the object's (``ψ <= 0``): a contact model applies
    force only there.

    Parameters
    ----------
    plant, plant_context
        ``plant_context`` holds positions and velocities.
    contacts : list of PlantContact
        From :func:`drakegrasp.find_contacts` (positions and normals in O).
    object_body : RigidBody
    fingers : sequence of RigidBody
    separation_speed : float
        m/s, > 0.
    query_object : QueryObject, optional
        For the pairs' friction (:func:`~drakegrasp.plant.friction.pair_friction`)
        on a plant whose contact approximation opens sliding contacts; without
        it, or for a pair without friction properties, no allowance.

    Returns
    -------
    kept : list of PlantContact
        The contacts that are not separating, in their order.
    loads : list of FingerLoad
        Per finger body; forces, μ and friction in use are NaN (geometry sees
        no force); ``touching``, ``slip_speed`` (the largest tangential speed)
        and ``normal_W`` from its kept contacts with ``ψ <= 0``.
    """
    X_WO = plant.EvalBodyPoseInWorld(plant_context, object_body)
    R_WO = X_WO.rotation().matrix()
    position = {b.index(): k for k, b in enumerate(fingers)}
    slip = [0.0] * len(fingers)
    touching = [False] * len(fingers)
    n_sum = [np.zeros(3) for _ in fingers]
    kept = []
    opens = query_object is not None and _opens_sliding_contacts(plant)
    for c in contacts:
        finger = plant.get_body(c.finger_body_index)
        p_WC = np.asarray(X_WO.multiply(c.p_OC))
        p_WF = np.asarray(
            plant.EvalBodyPoseInWorld(plant_context, finger).multiply(c.p_FC)
        )
        n_W = R_WO @ c.nhat_O  # into the object: from the finger towards it
        v_rel = point_velocity(plant, plant_context, object_body, p_WC)
        v_rel = v_rel - point_velocity(plant, plant_context, finger, p_WF)
        apart, sliding = split_along(v_rel, n_W)
        if apart > separation_speed and apart > (
            separation_speed + _dilation(plant, query_object, c, opens) * sliding
        ):  # the pair's friction is read only for a contact that opens
            continue
        kept.append(c)
        if c.psi > 0.0:  # within the tolerance, but apart: no force there
            continue
        k = position[c.finger_body_index]
        touching[k] = True
        n_sum[k] += n_W
        slip[k] = max(slip[k], sliding)
    loads = [
        FingerLoad(
            finger_body=_scoped_name(plant, b),
            touching=touching[k],
            normal_force=np.nan,
            tangential_force=np.nan,
            mu=np.nan,
            friction_use=np.nan,
            slip_speed=slip[k],
            normal_W=_unit_or_nan(n_sum[k]),
        )
        for k, b in enumerate(fingers)
    ]
    return kept, loads
