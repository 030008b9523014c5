r"""Jacobians of a grasp read from a plant: ``∂ψ/∂v`` and the hand Jacobian ``J``.

With ``n̂`` the contact normal (into the object), ``Ca`` the object's witness
point and ``Cb`` the finger's, the signed distance changes as

.. math:: \dot\psi_i = \hat n_i^T \big(v_{W\,Ca} - v_{W\,Cb}\big)
          = \frac{\partial \psi_i}{\partial v}\, v,

with ``v`` the plant's generalized velocities (Drake's ``JacobianWrtVariable.kV``;
a floating object has 7 positions and 6 velocities, so ``∂ψ/∂v`` is not
``∂ψ/∂q``).  The hand Jacobian maps the hand's velocities to the velocities of
the finger points ``Cb`` in each contact frame, component by component in the
order of the grasp matrix's columns (a soft finger adds the finger's angular
velocity about ``n̂``):

.. math:: J_i = \begin{bmatrix} R_i^T J_{v,Cb} \\ \hat n_i^T J_{\omega,F}
          \end{bmatrix}_{\text{model components}}, \qquad G^T \nu = J \dot q_h

All vectors are expressed in the object body frame O.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable, JointIndex, RigidBody
from pydrake.systems.framework import Context

from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import Contact, ContactModel
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.validation import check_grasp, describe
from drakegrasp.errors import InvalidGraspError
from drakegrasp.plant.contacts import PlantContact, check_plant_contacts
from drakegrasp.plant.options import PLANES, check_plane
from drakegrasp.plant.validation import (
    _per_plant,
    check_bodies,
    check_plant,
    check_velocity_indices,
    plant_context_of,
    resolve_object_body,
)

__all__ = [
    "PLANES",
    "contact_rows",
    "hand_jacobian",
    "hand_velocity_indices",
    "signed_distance_jacobian",
]


@checked_call
def hand_velocity_indices(
    plant: MultibodyPlant, bodies: Iterable[RigidBody]
) -> np.ndarray:
    """Plant velocity indices of the joints that move the given bodies.

    Parameters
    ----------
    plant : MultibodyPlant
    bodies : iterable of RigidBody
        The hand's bodies (see :func:`~drakegrasp.plant.validation.hand_bodies`).

    Returns
    -------
    (n_h,) int
        Sorted indices into ``v`` of every joint whose child is one of the bodies.

    Raises
    ------
    ModelError
        A body of another plant.
    InvalidOptionError
        ``bodies`` is not an iterable of ``RigidBody``.
    """
    check_plant(plant)
    wanted = frozenset(int(b.index()) for b in check_bodies(plant, bodies))

    def compute():
        out: list[int] = []
        for i in range(plant.num_joints()):
            joint = plant.get_joint(JointIndex(i))
            if int(joint.child_body().index()) in wanted:
                start = joint.velocity_start()
                out += range(start, start + joint.num_velocities())
        return tuple(sorted(out))

    # joints and their velocity ranges are fixed once the plant is finalized
    found = _per_plant(plant, ("hand velocities", wanted), compute)
    return np.array(found, dtype=int)


def _translational(plant, context, body: RigidBody, points_B: np.ndarray, frame_O):
    """(3k, nv) Jacobian of points fixed in ``body``, world velocity, in O."""
    return plant.CalcJacobianTranslationalVelocity(
        context,
        JacobianWrtVariable.kV,
        body.body_frame(),
        np.asarray(points_B, dtype=float).T.reshape(3, -1),
        plant.world_frame(),
        frame_O,
    )


def _finger_jacobians(plant, context, contacts, frame_O):
    """Per contact: (3, nv) translational Jacobian of its finger point, in O."""
    out: list[np.ndarray | None] = [None] * len(contacts)
    groups: dict[int, list[int]] = {}
    for i, c in enumerate(contacts):
        groups.setdefault(int(c.finger_body_index), []).append(i)
    for idx in groups.values():
        body = plant.get_body(contacts[idx[0]].finger_body_index)
        points = np.array([contacts[i].p_FC for i in idx])
        Jv = _translational(plant, context, body, points, frame_O)
        for k, i in enumerate(idx):
            out[i] = Jv[3 * k : 3 * k + 3]
    return out


@checked_call
def signed_distance_jacobian(
    plant: MultibodyPlant,
    plant_context: Context,
    contacts: Sequence[PlantContact],
    object_body,
) -> np.ndarray:
    """``∂ψ/∂v``: one row per contact, one column per plant velocity.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
        The plant's context or the diagram's root context; the configuration
        the contacts were found in.
    contacts : sequence of PlantContact
        From :func:`drakegrasp.find_contacts` (object frame O).
    object_body : RigidBody, BodyIndex or str
        The object (frame O); positional or keyword.

    Returns
    -------
    (N, nv) float
        ``ψ̇ = (∂ψ/∂v) v`` (metres per unit velocity; ``JacobianWrtVariable.kV``);
        ``(0, nv)`` for no contacts.

    Raises
    ------
    InvalidContactError
        ``contacts`` holds what is not a ``PlantContact``.
    ModelError
        A contact of another plant or another object
        (:func:`~drakegrasp.plant.contacts.check_plant_contacts`).
    """
    plant_context = plant_context_of(plant, plant_context)
    object_body = resolve_object_body(plant, object_body)
    contacts = check_plant_contacts(plant, contacts, object_body, reads_geometry=False)
    if not contacts:  # Drake asserts that it is given a point
        return np.zeros((0, plant.num_velocities()))
    frame_O = object_body.body_frame()
    points_O = np.array([c.p_OC for c in contacts])
    J_obj = _translational(plant, plant_context, object_body, points_O, frame_O)
    J_fin = _finger_jacobians(plant, plant_context, contacts, frame_O)
    rows = []
    for i, c in enumerate(contacts):
        rows.append(c.nhat_O @ (J_obj[3 * i : 3 * i + 3] - J_fin[i]))
    return np.array(rows).reshape(len(contacts), plant.num_velocities())


@checked_call
def hand_jacobian(
    plant: MultibodyPlant,
    plant_context: Context,
    contacts: Sequence[PlantContact],
    grasp: Grasp,
    object_body,
    *,
    velocity_indices: np.ndarray,
    plane: str | None = None,
) -> np.ndarray:
    """The hand Jacobian ``J`` in the grasp's contact frames.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
    contacts : sequence of PlantContact
        The plant contacts, in the order of ``grasp.contacts``.
    grasp : Grasp
        The grasp built from them (its contact frames and models set the rows).
    object_body : RigidBody, BodyIndex or str
        Frame O in which everything is expressed; positional or keyword.
    velocity_indices : (n_h,) int
        Plant velocities that are the hand's (the columns of ``J``), each
        once, in ``0..nv-1``.
    plane : {"xy", "yz", "zx"} or None, optional
        For a planar grasp: the object-frame plane the contacts live in
        (given exactly when the grasp is planar).

    Returns
    -------
    J : (M, n_h) float
        ``M`` = the number of columns of ``G``; row blocks follow the contact
        order, each in the contact's components ``[n, t1, t2(, m_n)]`` (planar
        ``[n, t]``; frictionless ``[n]``).  Velocities in m/s (rad/s for the
        soft-finger row) per unit hand velocity.

    Raises
    ------
    InvalidOptionError
        Bad ``velocity_indices`` (negative, not integers, past the plant's
        velocities, repeated) or ``plane``.
    InvalidGraspError
        ``contacts`` are not as many as ``grasp.contacts``, or ``plane`` is
        given for a spatial grasp or missing for a planar one.
    InvalidContactError, ModelError
        As :func:`signed_distance_jacobian`, for ``contacts``.
    """
    plant_context = plant_context_of(plant, plant_context)
    object_body = resolve_object_body(plant, object_body)
    contacts = check_plant_contacts(plant, contacts, object_body, reads_geometry=False)
    grasp = check_grasp(grasp)
    plane = check_plane(plane)
    cols = check_velocity_indices(plant, velocity_indices)
    if len(contacts) != grasp.num_contacts:
        raise InvalidGraspError(
            f"{len(contacts)} contact(s) given for a grasp of "
            f"{grasp.num_contacts} contacts: contacts must be the plant contacts "
            "the grasp was built from, in its order"
        )
    if grasp.planar != (plane is not None):
        raise InvalidGraspError(
            f"plane={describe(plane)} for a spatial grasp: give no plane"
            if plane is not None
            else "a planar grasp needs plane= (the object-frame plane of its "
            f"contacts, one of {sorted(PLANES)})"
        )
    frame_O = object_body.body_frame()
    J_fin = _finger_jacobians(plant, plant_context, contacts, frame_O)
    blocks = []
    for i, (pc, c) in enumerate(zip(contacts, grasp.contacts, strict=True)):
        Jv = J_fin[i][:, cols]
        if plane is not None:
            Jv = Jv[list(PLANES[plane]), :]

        def angular(pc=pc):  # a soft finger's row only
            return plant.CalcJacobianAngularVelocity(
                plant_context,
                JacobianWrtVariable.kV,
                plant.get_body(pc.finger_body_index).body_frame(),
                plant.world_frame(),
                frame_O,
            )[:, cols]

        blocks.append(contact_rows(c, Jv, pc.nhat_O, angular))
    return np.vstack(blocks).reshape(grasp.num_components, cols.size)


def contact_rows(
    contact: Contact,
    Jv: np.ndarray,
    normal: np.ndarray,
    angular: Callable[[], np.ndarray],
) -> np.ndarray:
    """One contact's block of rows of ``J``, in its components.

    Parameters
    ----------
    contact : Contact
        The grasp's contact (its frame ``[n, t1, t2]`` in O, and its model).
    Jv : (3, n_h) or (2, n_h) float
        Translational velocity of the finger's contact point, expressed in O
        (planar: the plane's two components), m/s per unit hand velocity.
    normal : (3,) float
        The contact normal in O, for a soft finger's row.
    angular : callable
        Returns the finger's angular velocity Jacobian (3, n_h), expressed
        in O; called for a soft finger only.

    Returns
    -------
    (k, n_h) float
        ``[n]`` (frictionless), ``R^T Jv`` (hard finger: ``[n, t1, t2]``,
        planar ``[n, t]``), and for a soft finger the normal component of
        the finger's angular velocity below it (rad/s).
    """
    R = contact.frame
    if contact.contact_model is ContactModel.FRICTIONLESS:
        return R[:, :1].T @ Jv
    block = R.T @ Jv
    if contact.num_components == 4:
        block = np.vstack([block, np.asarray(normal) @ angular()])
    return block
