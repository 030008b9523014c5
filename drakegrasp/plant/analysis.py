"""From a plant's configuration to a grasp and its full analysis.

:func:`grasp_from_plant` turns the contacts that :func:`find_contacts` reads into
the core's :class:`~drakegrasp.Grasp` (object frame O, reference point = the
object body's origin) with the hand Jacobian ``J``, ``ψ`` and ``∂ψ/∂v``.
:func:`analyze_grasp` adds the verdicts of the core: form closure (LP1), force
closure on polyhedral cones with the hand check LP3, force closure on exact
cones, and the antipodal test for two contacts.  The verdicts are the core's;
nothing here re-decides them.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from pydrake.geometry import QueryObject
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context

from drakegrasp.certificates.kinds import CertificateCheck
from drakegrasp.closure.results import ClosureResult
from drakegrasp.closure.second_order import SecondOrderResult, second_order_form_closure
from drakegrasp.closure.verdicts import (
    force_closure,
    force_closure_exact,
    form_closure,
    internal_forces,
    with_internal_forces,
)
from drakegrasp.core.antipodal import AntipodalResult, is_antipodal
from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import Contact, ContactModel
from drakegrasp.core.deferred import defer, deferrable
from drakegrasp.core.grasp import Grasp, check_hand_jacobian, grasp_matrix
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS, DEFAULT_TOL
from drakegrasp.core.validation import check_distance_tolerance
from drakegrasp.errors import GraspError, InvalidOptionError, NoContactsError
from drakegrasp.plant.contacts import (
    DEFAULT_DISTANCE_TOLERANCE,
    HandSpec,
    PlantContact,
    _scoped_name,
    check_plant_contacts,
    find_contacts,
    resolve_object_body,
)
from drakegrasp.plant.couplings import (
    COUPLING_TOL,
    coupling_map,
    coupling_violations,
    plant_couplings,
    recorded_couplings,
)
from drakegrasp.plant.curvature import SECOND_ORDER_RANK_TOL, contact_curvatures
from drakegrasp.plant.finger_antipodal import FingerAntipodal, finger_antipodal
from drakegrasp.plant.jacobians import (
    PLANES,
    hand_jacobian,
    hand_velocity_indices,
    signed_distance_jacobian,
)
from drakegrasp.plant.load import LoadReport, load_section
from drakegrasp.plant.options import AnalysisOptions, resolve_options
from drakegrasp.plant.pose import PoseCheck
from drakegrasp.plant.pose import check_pose as _check_pose
from drakegrasp.plant.validation import (
    checked_context,
    checked_query_object,
    hand_contact_bodies,
    hand_model_instances,
)

__all__ = ["GraspFromPlant", "GraspReport", "analyze_grasp", "grasp_from_plant"]

CLOSE_HINT = (
    "if the hand is open, close it onto the object first: "
    "`drakegrasp analyze SCENE --close`, 'close: true' in the scene file's "
    "drakegrasp: section, load_scene(..., close=True) or "
    "drakegrasp.close_hand(plant, context, object_body, hand=...)"
)
"""What a :class:`~drakegrasp.NoContactsError` of a hand that stops short adds."""

PLANE_NORMAL_TOL = 1e-6
"""A planar analysis needs every normal's out-of-plane component below this."""


@checked_call
@dataclass(frozen=True, eq=False)
class GraspFromPlant:
    """A grasp read from a plant, with its Jacobians.

    Attributes
    ----------
    grasp : Grasp
        Contacts in the object body frame O; reference point = O's origin
        (planar: the two in-plane coordinates).
    contacts : tuple of PlantContact
        The plant contacts, in the order of ``grasp.contacts``.
    hand_jacobian : (M, n_h) float
        ``J``: rows in the contact-frame components of ``G``'s columns, columns
        the hand's independent velocities ``hand_velocity_indices``; for a
        coupled hand ``J C`` (:func:`~drakegrasp.plant.couplings.coupling_map`),
        one column per independent motion.
    hand_velocity_indices : (n_h,) int
        Which plant velocities are the hand's independent ones (a coupling's
        follower is not).
    psi : (N,) float
        Signed distance of each contact, metres.
    dpsi_dv : (N, nv) float
        ``∂ψ/∂v`` over all plant velocities (``JacobianWrtVariable.kV``).
    object_body : str
        Scoped name of the object body (the frame O).
    hand_bodies : tuple of str
        Scoped names of the hand's bodies, welded ones (a palm) included.
    plane : str or None
        Object-frame plane of a planar analysis (``"yz"``...), or None.
    pose : PoseCheck or None
        Penetrations and joint-limit violations of the hand's model instances
        (``pose.valid`` is False only when the caller opted out of the refusal
        with ``check_pose=False`` or ``allow_penetration=True``).
    couplings : tuple of (joint_0, joint_1, gear_ratio, offset)
        The couplings of the hand's joints that shaped ``J``.
    coupling_matrix : (n_a, n_h) float or None
        ``C`` of :func:`~drakegrasp.plant.couplings.coupling_map`: the hand's
        velocities (every one, followers included:
        ``all_hand_velocity_indices``) are ``C u`` of the independent ones.
        None: the identity (no coupling known).
    all_hand_velocity_indices : (n_a,) int or None
        Plant indices of every hand velocity, the followers of couplings
        included (each carries its own actuator); None: the same as
        ``hand_velocity_indices``.
    """

    grasp: Grasp
    contacts: tuple[PlantContact, ...]
    hand_jacobian: np.ndarray
    hand_velocity_indices: np.ndarray
    psi: np.ndarray
    dpsi_dv: np.ndarray
    object_body: str
    hand_bodies: tuple[str, ...]
    plane: str | None
    pose: PoseCheck | None = None
    couplings: tuple = ()
    coupling_matrix: np.ndarray | None = None
    all_hand_velocity_indices: np.ndarray | None = None

    @property
    def G(self) -> np.ndarray:
        """Grasp matrix of ``self.grasp``, (6, M) or (3, M)."""
        return grasp_matrix(self.grasp)

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "object_body": self.object_body,
            "hand_bodies": list(self.hand_bodies),
            "plane": self.plane,
            "grasp": self.grasp.to_dict(),
            "contacts": [c.to_dict() for c in self.contacts],
            "psi": jsonable(self.psi),
            "hand_velocity_indices": self.hand_velocity_indices.tolist(),
            "hand_jacobian": jsonable(self.hand_jacobian),
            "dpsi_dv": jsonable(self.dpsi_dv),
            "pose": None if self.pose is None else self.pose.to_dict(),
            "couplings": [jsonable(list(c)) for c in self.couplings],
            "coupling_matrix": jsonable(self.coupling_matrix),
            "all_hand_velocity_indices": None
            if self.all_hand_velocity_indices is None
            else self.all_hand_velocity_indices.tolist(),
        }


def lp3_jacobian(J: np.ndarray) -> np.ndarray:
    """``J`` as the programs take it: one zero column for a hand without joints.

    A hand made only of welded bodies (``hand=[palm]``) has no velocities, so
    ``J`` has no column and ``Jᵀ f = 0`` constrains nothing; a single zero
    column states exactly that to the programs, which want at least one.
    """
    return J if J.shape[1] else np.zeros((J.shape[0], 1))


def _core_contact(
    pc: PlantContact,
    *,
    plane: str | None,
    mu: float,
    contact_model: ContactModel,
    torsional_friction: float,
) -> Contact:
    position, normal = pc.p_OC, pc.nhat_O
    if plane is not None:
        axes = list(PLANES[plane])
        off = ({0, 1, 2} - set(axes)).pop()
        if abs(normal[off]) > PLANE_NORMAL_TOL:
            raise InvalidOptionError(
                f"contact of {pc.finger_body} at {np.round(position, 6).tolist()} has "
                f"normal {np.round(normal, 6).tolist()}, which leaves the {plane} "
                f"plane (component {normal[off]:.3g} along the plane's normal); the "
                "grasp is not planar in that plane"
            )
        position, normal = position[axes], normal[axes]
    return Contact(
        position,
        normal,
        mu=mu,
        contact_model=contact_model,
        torsional_friction=torsional_friction,
    )


@checked_call
def grasp_from_plant(
    plant: MultibodyPlant,
    plant_context: Context,
    object_body,
    *,
    hand: HandSpec = None,
    options: AnalysisOptions | None = None,
    mu: float | str | None = None,
    contact_model: ContactModel | str = ContactModel.HARD_FINGER,
    torsional_friction: float | None = None,
    distance_tolerance: float = DEFAULT_DISTANCE_TOLERANCE,
    plane: str | None = None,
    characteristic_length: float | None = None,
    allow_penetration: bool = False,
    patches: str = "vertices",
    check_pose: bool = True,
    query_object: QueryObject | None = None,
    contacts: list[PlantContact] | None = None,
    couplings: Sequence[tuple] | None = None,
) -> GraspFromPlant:
    """The grasp that the plant's configuration makes, with ``J``, ``ψ``, ``∂ψ/∂v``.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized, registered with a ``SceneGraph``.
    plant_context : Context
        The plant's context, or the root context of the diagram holding it.
    object_body : RigidBody, BodyIndex or str
        The grasped object; its body frame O is the grasp frame and its origin
        the reference point.  Positional or keyword.
    hand : ModelInstanceIndex, str, iterable of RigidBody, or None, optional
        See :func:`~drakegrasp.plant.validation.hand_contact_bodies`: every
        body of the hand touches, a palm welded to the world included (its
        contacts are in ``G``, its rows of ``J`` are zero).
    options : AnalysisOptions, optional
        Every option below at once, validated when it was made; give it or
        the keywords, not both.
    mu : float or "plant"
        Friction coefficient of every contact, or ``"plant"``: each contact's
        coefficient from its two geometries' proximity properties
        (:func:`~drakegrasp.plant.friction.plant_friction`).  Required (here or in
        ``options``).
    contact_model : ContactModel or str, optional
        ``"frictionless"``, ``"hard_finger"`` (default) or ``"soft_finger"``.
    torsional_friction : float, optional
        ``ν`` of soft fingers; required (>= 0) with ``"soft_finger"``, where
        0 makes a soft finger act as a hard one.
    distance_tolerance : float, optional
        Contact when ``|ψ| <=`` this (metres, default 1e-4, at most
        :data:`~drakegrasp.core.tolerances.MAX_DISTANCE_TOLERANCE`, 0.01).
    plane : {"xy", "yz", "zx"}, optional
        Analyse a planar grasp in this plane of frame O (wrenches
        ``[f_a, f_b, m]``); every contact normal must lie in the plane.
    characteristic_length : float, optional
        ``b`` of the grasp (default: farthest contact from O's origin).
    allow_penetration, patches, query_object
        Passed to :func:`drakegrasp.find_contacts` (``query_object``: read the
        geometry from this scene-graph query object instead of the plant's
        query input port in ``plant_context``).  ``allow_penetration=True``
        also stops the pose check from refusing penetration (it is still
        recorded in ``pose``).
    check_pose : bool, optional
        True (default): refuse an impossible pose, i.e. any body of the hand's
        model instances (the welded palm too) penetrating the object, or a
        joint of the hand outside its limits.  False: analyse it anyway; the
        result's ``pose.valid`` is then False and the report says so.
    contacts : list of PlantContact, optional
        Analyse these contacts (frame O of ``object_body``) instead of finding
        them from signed distances: e.g. the patches of hydroelastic contact
        surfaces read by :func:`drakegrasp.plant.contacts_from_results`.
        They must be contacts of this plant and object: contacts found in
        another plant (even one built from the same files) are refused
        (:func:`~drakegrasp.plant.contacts.check_plant_contacts`).
    couplings : sequence of (joint_0, joint_1, gear_ratio, offset), optional
        Joint couplings ``q_0 = gear_ratio * q_1 + offset``; ``J`` becomes
        ``J C`` with one column per independent motion.  Default: those
        recorded on the plant
        (:func:`~drakegrasp.plant.couplings.plant_couplings`); an explicit
        list overrides them (``()``: none).

    Returns
    -------
    GraspFromPlant

    Raises
    ------
    PenetrationError, JointLimitError
        Both :class:`~drakegrasp.InvalidPoseError`: the pose is impossible
        (names the bodies and the depth, or the joint, its value and limits).
    NoContactsError, ModelError, InvalidOptionError, InvalidContextError
    InvalidContactError
        For ``contacts`` that are not PlantContacts.
    """
    opts = resolve_options(
        options,
        mu=mu,
        contact_model=contact_model,
        torsional_friction=torsional_friction,
        distance_tolerance=distance_tolerance,
        plane=plane,
        characteristic_length=characteristic_length,
        allow_penetration=allow_penetration,
        patches=patches,
        check_pose=check_pose,
    ).require_friction()
    with checked_context(plant, plant_context) as plant_context:
        plane = opts.plane
        distance_tolerance, allow_penetration = (
            opts.distance_tolerance,
            opts.allow_penetration,
        )
        check_pose = opts.check_pose
        torsional_friction = opts.torsional_friction or 0.0
        body = resolve_object_body(plant, object_body)
        bodies = hand_contact_bodies(plant, body, hand)
        if query_object is not None:  # before the pose check reads it
            checked_query_object(plant, query_object, plant_context, [body, *bodies])
        if contacts is not None:  # only mu="plant" reads their geometries
            contacts = check_plant_contacts(
                plant, contacts, body, reads_geometry=opts.mu == "plant"
            )
        couplings = plant_couplings(plant, couplings)
        pose = _pose_of(
            plant,
            plant_context,
            body,
            bodies,
            distance_tolerance=distance_tolerance,
            refuse=check_pose,
            allow_penetration=allow_penetration,
            query_object=query_object,
            couplings=couplings,
            coupling_tolerance=opts.coupling_tolerance,
        )
        if contacts is None:
            try:
                contacts = find_contacts(
                    plant,
                    plant_context,
                    object_body=body,
                    hand=bodies,
                    distance_tolerance=distance_tolerance,
                    allow_penetration=allow_penetration or not check_pose,
                    patches=opts.patches,
                    query_object=query_object,
                )
            except NoContactsError as e:
                if "does not touch" not in str(e):  # no geometry: closing won't help
                    raise
                raise NoContactsError(f"{e}; {CLOSE_HINT}") from None
        elif not contacts:
            raise NoContactsError(
                f"no contacts given for {_scoped_name(plant, body)!r}"
            )
        if opts.mu == "plant":
            from drakegrasp.plant.friction import plant_friction

            mus = plant_friction(
                plant, plant_context, contacts, query_object=query_object
            )
        else:
            mus = [opts.mu] * len(contacts)
        core = [
            _core_contact(
                c,
                plane=plane,
                mu=m,
                contact_model=opts.contact_model,
                torsional_friction=torsional_friction,
            )
            for c, m in zip(contacts, mus, strict=True)
        ]
        dim = 2 if plane is not None else 3
        grasp = Grasp(
            core,
            reference_point=np.zeros(dim),
            characteristic_length=opts.characteristic_length,
        )
        indices = hand_velocity_indices(plant, bodies)
        J = hand_jacobian(
            plant,
            plant_context,
            contacts,
            grasp,
            object_body=body,
            velocity_indices=indices,
            plane=plane,
        )
        all_indices = indices
        C, indices = coupling_map(plant, indices, couplings)
        J = J @ C
        dpsi = signed_distance_jacobian(
            plant, plant_context, contacts, object_body=body
        )
        return GraspFromPlant(
            grasp=grasp,
            contacts=tuple(contacts),
            hand_jacobian=J,
            hand_velocity_indices=indices,
            psi=np.array([c.psi for c in contacts]),
            dpsi_dv=dpsi,
            object_body=_scoped_name(plant, body),
            hand_bodies=tuple(_scoped_name(plant, b) for b in bodies),
            plane=plane,
            pose=pose,
            couplings=couplings,
            coupling_matrix=C,
            all_hand_velocity_indices=np.asarray(all_indices, dtype=int),
        )


def _pose_of(
    plant,
    plant_context,
    body,
    bodies,
    *,
    distance_tolerance,
    refuse,
    allow_penetration,
    query_object=None,
    couplings=(),
    coupling_tolerance=COUPLING_TOL,
) -> PoseCheck:
    """Check the pose; raise unless the caller opted out.

    Besides penetration and joint limits, the hand's joints must keep the
    couplings used (``couplings``) and those recorded on the plant (its coupler
    constraints, which Drake enforces whatever ``couplings=`` says).
    """
    tol = check_distance_tolerance(distance_tolerance)
    hand_bodies = hand_model_instances(plant, bodies, body)
    found = _check_pose(
        plant,
        plant_context,
        body,
        hand_bodies,
        distance_tolerance=tol,
        query_object=query_object,
    )
    broken = coupling_violations(
        plant,
        plant_context,
        (*couplings, *recorded_couplings(plant)),
        model_instances={b.model_instance() for b in hand_bodies},
        tol=coupling_tolerance,
    )
    found = PoseCheck(found.penetrations, found.joint_limit_violations, refuse, broken)
    if refuse:
        if allow_penetration:
            PoseCheck((), found.joint_limit_violations, True, broken).raise_if_invalid()
        else:
            found.raise_if_invalid()
    return found


@checked_call
@dataclass(frozen=True, eq=False)
class GraspReport:
    """Everything drakegrasp says about the grasp in a plant's configuration.

    Attributes
    ----------
    data : GraspFromPlant
        Grasp, contacts, ``J``, ``ψ`` and ``∂ψ/∂v``.
    G : (6, M) or (3, M) float
        Grasp matrix (object frame, moments about O's origin).
    form_closure : ClosureResult
        First-order form closure (LP1, frictionless).
    force_closure : ClosureResult
        Force closure on polyhedral cones (LP2) with the hand check LP3 on ``J``
        (``force_closure.internal_forces``).
    force_closure_exact : ClosureResult
        Force closure on exact (second-order / planar) cones, with LP3.
    antipodal : AntipodalResult, FingerAntipodal or None
        The antipodal test: of the two contacts when there are exactly two,
        else per finger for a two-finger hand (one patch per finger,
        :mod:`drakegrasp.plant.finger_antipodal`), else None.
    pose : PoseCheck or None
        Whether the pose is possible (``pose.valid``); an invalid pose is only
        analysed with ``check_pose=False`` (or ``allow_penetration=True``).
    second_order : SecondOrderResult or None
        Second-order form closure (curvatures read off the shapes) when
        first-order form closure fails; None when it holds.
    load : LoadReport or None
        With ``analyze_grasp(..., load=...)``: whether the hand holds the load,
        with which joint torques and squeeze, the payload factor and the
        joint that saturates first (:mod:`drakegrasp.plant.load`).
    options : AnalysisOptions or None
        The options the analysis used (validated).

    Notes
    -----
    The parts that no verdict needs (the second-order program, certificates,
    the ``d*`` of a verdict the rank decided, LP3 when no frictional closure
    holds) are computed on first access from inputs captured at the call
    (never from the plant context), so reading them later gives exactly what
    an eager computation would have stored; ``to_dict()``, ``str()`` and
    pickling compute them.
    """

    data: GraspFromPlant
    G: np.ndarray
    form_closure: ClosureResult
    force_closure: ClosureResult
    force_closure_exact: ClosureResult
    antipodal: AntipodalResult | FingerAntipodal | None
    pose: PoseCheck | None = None
    second_order: SecondOrderResult | None = deferrable(None)
    load: LoadReport | None = None
    options: AnalysisOptions | None = None

    @property
    def grasp(self) -> Grasp:
        """The core grasp (object frame)."""
        return self.data.grasp

    @property
    def contacts(self) -> tuple[PlantContact, ...]:
        """The plant contacts, in grasp order."""
        return self.data.contacts

    @property
    def J(self) -> np.ndarray:
        """The hand Jacobian, (M, n_h)."""
        return self.data.hand_jacobian

    @property
    def is_force_closure(self) -> bool:
        """Polyhedral force closure with LP3 passing."""
        return self.force_closure.is_closure

    @functools.cached_property
    def certificate_checks(self) -> dict[str, CertificateCheck | None]:
        """Each verdict's certificate re-checked on this grasp, once per report.

        Keys ``form_closure``, ``force_closure``, ``force_closure_exact``; None
        where a verdict has no certificate.  The checks run on first access
        and are kept (the report is immutable), so printing a report twice
        does not check twice.
        """
        out = {}
        for name in ("form_closure", "force_closure", "force_closure_exact"):
            cert = getattr(self, name).certificate
            out[name] = (
                None if cert is None else cert.check(self.grasp, hand_jacobian=self.J)
            )
        return out

    def to_dict(self) -> dict:
        """JSON-ready dictionary of the whole report."""
        return {
            **self.data.to_dict(),
            "G": jsonable(self.G),
            "form_closure": self.form_closure.to_dict(),
            "force_closure": self.force_closure.to_dict(),
            "force_closure_exact": self.force_closure_exact.to_dict(),
            "antipodal": None if self.antipodal is None else self.antipodal.to_dict(),
            "pose": None if self.pose is None else self.pose.to_dict(),
            "second_order": jsonable(self.second_order),
            "load": None if self.load is None else self.load.to_dict(),
            "options": None if self.options is None else self.options.to_dict(),
        }

    def __str__(self) -> str:
        g = self.grasp
        c0 = g.contacts[0]
        kind = f"planar ({self.data.plane} plane of O)" if g.planar else "spatial"
        friction = f"mu = {c0.mu:g}"
        if c0.contact_model is ContactModel.SOFT_FINGER:
            friction += f", nu = {c0.torsional_friction:g}"
        lines = [
            f"Grasp of {self.data.object_body} — {g.num_contacts} contacts, {kind}, "
            f"{c0.contact_model.value}, {friction}",
            "  frame O = the object body frame; moments about its origin; "
            f"b = {g.characteristic_length * 1e3:.4g} mm",
            *([] if self.pose is None else ["  " + self.pose.summary()]),
            f"  {'#':>2}  {'finger':<28} {'p_OC [mm]':<27} {'nhat_O':<25} psi [mm]",
        ]
        for i, pc in enumerate(self.contacts):
            # round first so that -0.0001 does not print as "-0.000"
            p = ", ".join(f"{x:7.2f}" for x in np.round(pc.p_OC * 1e3, 2) + 0.0)
            n = ", ".join(f"{x:6.3f}" for x in np.round(pc.nhat_O, 3) + 0.0)
            patch = (
                "" if pc.patch_vertex is None else f"  (patch vertex {pc.patch_vertex})"
            )
            psi = f"{pc.psi * 1e3:+.1e}"
            lines.append(f"  {i:>2}  {pc.finger_body:<28} ({p})  ({n})  {psi}{patch}")
        rows, cols = self.G.shape
        lines.append(
            f"  G: {rows} x {cols}, rank {self.force_closure.rank}; "
            f"J: {self.J.shape[0]} x {self.J.shape[1]} (hand velocities "
            f"{self.data.hand_velocity_indices.tolist()})"
        )
        if g.planar and self.data.plane is not None:
            axes = ", ".join("xyz"[i] for i in PLANES[self.data.plane])
            lines.append(f"  (points below are ({axes}) of frame O, metres)")
        else:
            lines.append("  (points below are in frame O, metres)")
        checks = self.certificate_checks
        for name in ("form_closure", "force_closure", "force_closure_exact"):
            result = getattr(self, name)
            lines += ["  " + x for x in result.report_lines(internal_forces=False)]
            if checks[name] is not None:
                kind = result.certificate.kind
                lines.append(f"    {kind} re-checked: {checks[name]}")
        lp3 = self.force_closure.internal_forces
        if lp3 is not None:  # one LP3 serves both force-closure verdicts
            lines += ["  " + x for x in lp3.report_lines()]
        if self.antipodal is not None:
            lines += ["  " + x for x in str(self.antipodal).splitlines()]
        if self.second_order is not None:
            lines += ["  " + line for line in str(self.second_order).splitlines()]
        if self.load is not None:
            lines += ["  " + line for line in self.load.report_lines()]
        return "\n".join(lines)


@checked_call
def analyze_grasp(
    plant: MultibodyPlant,
    plant_context: Context,
    object_body,
    *,
    hand: HandSpec = None,
    options: AnalysisOptions | None = None,
    mu: float | str | None = None,
    contact_model: ContactModel | str = ContactModel.HARD_FINGER,
    torsional_friction: float | None = None,
    distance_tolerance: float = DEFAULT_DISTANCE_TOLERANCE,
    plane: str | None = None,
    characteristic_length: float | None = None,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    tol: float = DEFAULT_TOL,
    allow_penetration: bool = False,
    patches: str = "vertices",
    check_pose: bool = True,
    query_object: QueryObject | None = None,
    contacts: list[PlantContact] | None = None,
    load=None,
    object_mass: float | None = None,
    torque_limits=None,
    couplings: Sequence[tuple] | None = None,
) -> GraspReport:
    """Read the grasp from the plant and decide every closure property.

    Parameters
    ----------
    plant, plant_context, object_body, hand
        As in :func:`grasp_from_plant` (``plant_context`` may be the diagram's
        root context; ``object_body`` may be positional).
    options : AnalysisOptions, optional
        Every option below at once (validated when it was made); give it or
        the keywords, not both.  The report keeps the options it used
        (``report.options``).
    mu : float or "plant"
        Friction of every contact, or ``"plant"``: each contact's coefficient
        combined from its two geometries' proximity properties
        (:func:`~drakegrasp.plant.friction.plant_friction`).  Required (here or in
        ``options``).
    contact_model, torsional_friction, distance_tolerance, plane
        As in :func:`grasp_from_plant`.
    characteristic_length, allow_penetration, patches
        As in :func:`grasp_from_plant`.
    check_pose, query_object, contacts, couplings
        As in :func:`grasp_from_plant`.
    num_generators : int, optional
        Generators of each polyhedral Coulomb cone (default 8).
    tol : float, optional
        Threshold on ``d*`` of every program (see :mod:`drakegrasp.closure.verdicts`).
    load : None, "gravity" or (6,) / (3,) float, optional
        An external wrench on the object (frame O about its origin), or its
        weight: the report then has a ``load`` section
        (:class:`~drakegrasp.plant.load.LoadReport`), with a warning where a
        given ``mu`` disagrees with the plant's friction.
    object_mass : float, optional
        The mass (kg, finite and > 0) that ``load="gravity"`` weighs, at the
        object's centre of mass, instead of the model's (a plan's
        ``object_mass``); needs ``load="gravity"``.
    torque_limits : None, "plant" or (n_h,) float, optional
        Motor limits for the load section: the actuators' effort limits, or
        one per hand velocity.

    Returns
    -------
    GraspReport
    """
    opts = resolve_options(
        options,
        mu=mu,
        contact_model=contact_model,
        torsional_friction=torsional_friction,
        distance_tolerance=distance_tolerance,
        plane=plane,
        characteristic_length=characteristic_length,
        num_generators=num_generators,
        tol=tol,
        allow_penetration=allow_penetration,
        patches=patches,
        check_pose=check_pose,
        load=load,
        object_mass=object_mass,
        torque_limits=torque_limits,
    ).require_friction()
    with checked_context(plant, plant_context) as plant_context:
        if contacts is not None:  # the friction and curvatures read geometries
            contacts = check_plant_contacts(
                plant, contacts, resolve_object_body(plant, object_body)
            )
        data = grasp_from_plant(
            plant,
            plant_context,
            object_body=object_body,
            hand=hand,
            options=opts.replace(mu=1.0) if opts.mu == "plant" else opts,
            query_object=query_object,
            contacts=contacts,
            couplings=couplings,
        )
        data, load_report = load_section(
            plant,
            plant_context,
            data,
            mu=opts.mu,
            load=None if opts.load is None else _as_load(opts.load),
            torque_limits=None
            if opts.torque_limits is None
            else _as_load(opts.torque_limits),
            query_object=query_object,
            object_mass=opts.object_mass,
            distance_tolerance=opts.distance_tolerance,
        )
        tol, num_generators = opts.tol, opts.num_generators
        grasp, J = data.grasp, lp3_jacobian(data.hand_jacobian)
        if grasp.num_contacts == 2:
            antipodal = is_antipodal(grasp)
        else:
            antipodal = finger_antipodal(
                plant,
                data.contacts,
                grasp,
                hand_contact_bodies(
                    plant, resolve_object_body(plant, object_body), hand
                ),
            )
        first_order = form_closure(grasp, tol=tol)
        polyhedral = force_closure(grasp, num_generators=num_generators, tol=tol)
        exact = force_closure_exact(grasp, tol=tol)
        # One LP3 serves both verdicts: it depends on G and J, not on the cones.
        # Without frictional closure neither verdict needs it: solved when read.
        if polyhedral.frictional_closure or exact.frictional_closure:
            lp3 = internal_forces(grasp, J, tol=tol)
        else:
            check_hand_jacobian(grasp, J)
            lp3 = defer(internal_forces, grasp, J, tol=tol)
        return GraspReport(
            data=data,
            G=grasp_matrix(grasp),
            form_closure=first_order,
            force_closure=with_internal_forces(polyhedral, lp3),
            force_closure_exact=with_internal_forces(exact, lp3),
            antipodal=antipodal,
            pose=data.pose,
            second_order=None
            if first_order.is_closure
            else _second_order(plant, plant_context, data, first_order, query_object),
            load=load_report,
            options=opts,
        )


def _as_load(value):
    """A load option as the load section takes it: a word, or an array."""
    return value if isinstance(value, str) else np.array(value)


def _second_order(plant, plant_context, data, first_order, query_object):
    """Second-order form closure with the shapes' curvatures (or why not).

    The curvatures are read from the plant now (the context may change
    later); the program runs when the result is first read.
    """
    try:
        curvatures = contact_curvatures(
            plant,
            plant_context,
            data.contacts,
            object_body=data.object_body,
            plane=data.plane,
            query_object=query_object,
        )
    except GraspError as e:  # a contact without a second-order model
        return SecondOrderResult.undecided(data.grasp.num_contacts, str(e))
    return defer(_second_order_of, data.grasp, curvatures, first_order)


def _second_order_of(grasp, curvatures, first_order) -> SecondOrderResult:
    try:
        return second_order_form_closure(
            grasp, curvatures, first_order=first_order, rank_tol=SECOND_ORDER_RANK_TOL
        )
    except GraspError as e:  # e.g. a curvature the program cannot use
        return SecondOrderResult.undecided(grasp.num_contacts, str(e))
