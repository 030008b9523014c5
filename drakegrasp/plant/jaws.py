r"""Parallel grippers: two prismatic jaws that face each other, closed as one.

**Detection.**  A hand is a *parallel gripper* when its closing joints
(:mod:`drakegrasp.plant.fingers`) are exactly two prismatic joints whose
translation axes are parallel in the world (to within
:data:`PARALLEL_AXIS_TOL`) and whose jaws face each other along that axis.
Jaw ``k`` is the set of hand bodies its joint moves; its centre ``c_k`` is the
mean of the world positions of its collision geometries that can touch the
object.  With ``a_k`` the world direction in which jaw ``k`` moves when its
joint value grows, the joint *closes* its jaw when ``q_k`` grows if
``s_k = sign(a_k · (c_other − c_k)) = +1`` and when it shrinks if ``s_k = −1``.
The WSG-50 (``s = (+1, −1)``) and the Franka hand (``s = (−1, −1)``) are
parallel grippers; an Allegro hand is not.

**Symmetric closing.**  The real grippers move both jaws with one motor,
through a belt or a rack: each jaw closes as fast as the other.  As a coupling
(``q_0 = ρ q_1 + Δq``, :mod:`drakegrasp.plant.couplings`) the second jaw
follows the first with

.. math:: \rho = s_0 s_1, \qquad \Delta q = q_1^0 - \rho\, q_0^0,

(jaw 1 the follower) so that ``s_1 q̇_1 = s_0 q̇_0``: equal closing speeds,
and the pre-shape ``q^0`` satisfies the coupling (the midpoint of the jaws
stays where the pre-shape put it).

**One jaw.**  A coupled pair stops when the first jaw touches; an object off
the jaws' midpoint then touches only one of them, which a real gripper would
push until both touch.  :func:`jaw_contacts` measures each jaw's distance to
the object so that :class:`~drakegrasp.plant.closing.HandClosure` can say so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import PrismaticJoint
from pydrake.systems.framework import Context

from drakegrasp.core.calls import checked_call
from drakegrasp.plant.couplings import JointCoupling
from drakegrasp.plant.fingers import HandStructure, check_hand_structure
from drakegrasp.plant.validation import (
    checked_query_object,
    plant_context_of,
    scoped_name,
)

__all__ = [
    "PARALLEL_AXIS_TOL",
    "JawContact",
    "ParallelJaws",
    "jaw_contacts",
    "parallel_jaws",
]

PARALLEL_AXIS_TOL = np.deg2rad(1.0)
"""Largest angle (radians) between two jaws' axes of a parallel gripper."""


@checked_call
@dataclass(frozen=True, eq=False)
class ParallelJaws:
    """The two jaws of a parallel gripper (see the module docstring).

    Attributes
    ----------
    joints : (int, int)
        Positions of the jaws' joints in ``HandStructure.joints``.
    names : (str, str)
        Their scoped names ``model::joint``.
    closing_signs : (float, float)
        ``s_k``: +1 when jaw ``k`` closes as its joint value grows, −1 when
        it closes as the value shrinks.
    pairs : (tuple, tuple)
        Per jaw, the (object geometry, jaw geometry, jaw body) pairs that the
        scene graph does not filter.
    axis_W : (3,) float
        Unit direction in which jaw 0 closes, in the world frame.
    """

    joints: tuple[int, int]
    names: tuple[str, str]
    closing_signs: tuple[float, float]
    pairs: tuple[tuple, tuple]
    axis_W: np.ndarray

    @property
    def gear_ratio(self) -> float:
        """``ρ = s_0 s_1``: jaw 1's rate per unit rate of jaw 0 at equal speed."""
        return float(self.closing_signs[0] * self.closing_signs[1])

    def symmetric_coupling(self, q: np.ndarray) -> JointCoupling:
        """The coupling that closes both jaws at one speed from ``q``.

        Parameters
        ----------
        q : (n_h,) float
            Closing-joint positions (order of ``HandStructure.joints``), metres;
            the pre-shape the coupling keeps.

        Returns
        -------
        JointCoupling
            Jaw 1 follows jaw 0: ``q_1 = ρ q_0 + (q_1 − ρ q_0)``.
        """
        rho = self.gear_ratio
        j0, j1 = self.joints
        return JointCoupling(
            self.names[1], self.names[0], rho, float(q[j1] - rho * q[j0])
        )


def _jaw_pairs(plant, hand: HandStructure, position: int) -> tuple:
    joint = hand.joints[position]
    moved = {int(b) for b in plant.GetBodiesKinematicallyAffectedBy([joint.index()])}
    return tuple(
        pair
        for finger in hand.fingers
        for pair in finger.pairs
        if int(pair[2].index()) in moved
    )


@checked_call
def parallel_jaws(
    plant: MultibodyPlant, plant_context: Context, hand: HandStructure, query
) -> ParallelJaws | None:
    """The hand's two jaws if it is a parallel gripper, else None.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
        The plant's context (the jaws' present poses).
    hand : HandStructure
        From :func:`~drakegrasp.plant.fingers.hand_structure`.
    query : pydrake.geometry.QueryObject
        The scene graph's query object in ``plant_context``.

    Returns
    -------
    ParallelJaws or None
        None unless the closing joints are two prismatic joints with parallel
        axes whose jaws (each with a geometry that can touch the object)
        face each other.

    Raises
    ------
    ModelError, InvalidContextError
        For what is not a finalized plant, or a context of another system.
    InvalidOptionError
        For a ``hand`` that is not a ``HandStructure``, or a ``query`` that is
        not a ``QueryObject`` of the plant's scene graph.
    """
    plant_context = plant_context_of(plant, plant_context)
    check_hand_structure(hand)
    checked_query_object(plant, query)
    if len(hand.joints) != 2 or not all(
        isinstance(j, PrismaticJoint) for j in hand.joints
    ):
        return None
    axes, centres, pairs = [], [], []
    for k, joint in enumerate(hand.joints):
        R_WF = joint.frame_on_parent().CalcPoseInWorld(plant_context).rotation()
        axes.append(R_WF.multiply(np.asarray(joint.translation_axis())))
        mine = _jaw_pairs(plant, hand, k)
        if not mine:
            return None
        pairs.append(mine)
        geometries = {gf for _, gf, _ in mine}
        centres.append(
            np.mean(
                [np.asarray(query.GetPoseInWorld(g).translation()) for g in geometries],
                axis=0,
            )
        )
    a0, a1 = (a / np.linalg.norm(a) for a in axes)
    if abs(float(a0 @ a1)) < np.cos(PARALLEL_AXIS_TOL):
        return None
    gap = centres[1] - centres[0]
    along = float(a0 @ gap)
    if abs(along) <= 1e-9:  # the jaws do not face each other along the axis
        return None
    s0 = 1.0 if along > 0 else -1.0
    s1 = 1.0 if float(a1 @ -gap) > 0 else -1.0
    return ParallelJaws(
        joints=(0, 1),
        names=(hand.names[0], hand.names[1]),
        closing_signs=(s0, s1),
        pairs=(pairs[0], pairs[1]),
        axis_W=s0 * a0,
    )


@checked_call
@dataclass(frozen=True)
class JawContact:
    """How far one jaw of a parallel gripper is from the object.

    Attributes
    ----------
    joint : str
        The jaw's joint, ``model::joint``.
    psi : float
        Smallest signed distance from the jaw's geometries to the object,
        metres.
    touching : bool
        ``−tol <= psi <= tol`` (``tol`` the contact tolerance; a jaw may
        touch slightly inside the object where its pre-shape did, as
        :func:`~drakegrasp.plant.closing.close_hand` allows).
    body : str
        The jaw body (``model::body``) of the closest geometry.
    """

    joint: str
    psi: float
    touching: bool
    body: str

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return dict(vars(self))


def jaw_contacts(
    plant: MultibodyPlant, jaws: ParallelJaws, query, tol: float
) -> tuple[JawContact, JawContact]:
    """Each jaw's distance to the object in the query's configuration.

    Parameters
    ----------
    plant : MultibodyPlant
    jaws : ParallelJaws
    query : pydrake.geometry.QueryObject
        In the configuration to measure.
    tol : float
        Contact tolerance, metres.

    Returns
    -------
    (JawContact, JawContact)
    """
    out = []
    for name, pairs in zip(jaws.names, jaws.pairs, strict=True):
        best, body = np.inf, pairs[0][2]
        for go, gf, b in pairs:
            psi = query.ComputeSignedDistancePairClosestPoints(go, gf).distance
            if psi < best:
                best, body = float(psi), b
        out.append(
            JawContact(
                joint=name,
                psi=best,
                touching=bool(-tol <= best <= tol),
                body=scoped_name(plant, body),
            )
        )
    return out[0], out[1]
