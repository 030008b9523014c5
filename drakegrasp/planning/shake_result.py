"""What the shake test saw: :class:`ShakeResult`.

The figures of one :func:`~drakegrasp.planning.shake.shake_test` run: how far
the object moved from its planned pose and from where the fingers seated it,
what the actuators pressed with, and the contact model the simulation used.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from pydrake.math import RigidTransform

from drakegrasp.closure.load_problem import effort_unit_of
from drakegrasp.core.calls import checked_call
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import describe, real_scalar
from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning.turned_gravity import GRAVITY

__all__ = ["ShakeResult", "motion_text", "squeeze_unit_of"]


@checked_call
@dataclass(frozen=True, eq=False)
class ShakeResult:
    """What the shake test saw.

    Attributes
    ----------
    held : bool
        Whether the object stayed within both bounds for the whole run.
    max_displacement : float
        Largest distance (m) of the object's origin from its planned place in
        the hand frame.
    max_rotation : float
        Largest rotation angle (rad) of the object from its planned
        orientation in the hand frame.
    phases : tuple of dict
        Per gravity direction: ``direction`` (world), ``displacement`` and
        ``rotation`` at the end of the phase.
    squeeze : float
        What each closing joint's actuator presses with: a force in newtons
        for a prismatic joint (a parallel jaw), a torque in N·m for a revolute
        one (a multi-finger hand); see ``effort_units``.  With
        ``squeeze_at_contacts``, newtons with which each finger body that
        touches presses at its contacts, every joint's kind alike.
    efforts : tuple of float
        The magnitude of what each closing joint's actuator applied once the
        fingers had seated (newtons, or N·m for a revolute joint), in
        actuator order,
        read at the end of seating (with ``seat=0``, of settling).  A
        parallel jaw's fingers press with ``squeeze`` (within their effort
        limits); a motor that drives ``<mimic>`` followers without actuators
        applies theirs too (a one-motor jaw's: twice the squeeze).  A
        multi-finger hand's joints share each finger's contact
        force through its chain (``τ = Jᵀ f``), so theirs differ: a joint
        the contact pushes back presses harder, up to its effort limit, and
        one whose link moves freely presses with none.
    time_step, duration : float
        Seconds (simulated).
    wall_time : float
        Seconds.
    bounds : tuple of float
        ``(max_displacement, max_rotation)`` allowed.
    effort_units : tuple of str
        The unit of each entry of ``efforts``, and of ``squeeze`` unless
        ``squeeze_at_contacts`` (newtons then), per closing
        joint in actuator order: ``"N"`` for a prismatic joint, ``"N·m"`` for
        a revolute one (empty: newtons assumed).
    seat_displacement, seat_rotation : float
        Where seating left the object, before any gravity: distance (m) of
        its origin from its planned place and rotation angle (rad) from its
        planned orientation, in the hand frame (NaN with ``seat=0``).
    seat_speed : float
        Speed (m/s) of the object's origin at the end of seating.  An object
        the squeeze holds has settled there; one the fingers' closing motions
        push out of the hand is still moving (the Allegro hand's thumbless
        grasps of the YCB sugar box at 0.7 N·m: 0.17-0.53 m/s here, against
        0.012 and 0.045 m/s for its two best grasps with the thumb; see the
        planning guide).  NaN with ``seat=0``.
    max_displacement_from_seat, max_rotation_from_seat : float
        Largest distance (m) and rotation angle (rad) of the object, in the
        hand frame, from where seating left it, over settling and the turned
        gravity (NaN with ``seat=0``).  ``held`` counts from the planned pose,
        so a multi-finger hand that seats the object 10 mm away from it is
        "dropped" whatever follows; these say whether the seated grasp then
        held still.
    hydroelastic_modulus : float or None
        The modulus (Pa) of the hand's compliant hydroelastic geometries, or
        None: the contact the models declare.
    hydroelastic_refused : int
        Collision geometries of the hand and the object that Drake refused to
        make hydroelastic (they kept point contact; a half-space, say).
    squeeze_caps : tuple of float
        What each closing joint was set to press with, in actuator order:
        ``squeeze``, or its actuator's effort limit where that is smaller (an
        actuator applies no more; ``squeeze_capped`` says so, and the summary
        line names the cap).  With ``squeeze_at_contacts``, newtons at the
        contacts: what the effort limit presses them with where it caps the
        motor (a joint that presses no contact: ``squeeze``).  Empty in a
        record made before it existed.
    squeeze_at_contacts : bool
        Whether ``squeeze`` was newtons at the fingers' contacts
        (:func:`~drakegrasp.planning.shake.shake_test`'s default: a revolute
        motor aimed at the torque that presses them with it,
        :mod:`drakegrasp.planning.squeeze`) rather than each joint's own
        effort.  False in a record made before it existed.
    seated_q_hand : (n_h,) float
        The candidate's joints (``joint_names``, its order) where seating
        left them, rad or m, clipped to their limits (Drake overshoots a limit
        by a little); empty with ``seat=0``.
    seated_X_WO : (4, 4) float or None
        The object's pose where seating left it, in the world the candidate
        was planned in (its hand base welded at ``X_WH``); None with
        ``seat=0``.  :meth:`seated` makes both a candidate to analyse.
    joint_names : tuple of str
        The shaken candidate's joints (scoped names); empty in a record made
        before it existed.
    X_WH : (4, 4) float or None
        The shaken candidate's hand pose (where its base was welded), world
        frame; None in a record made before it existed.  :meth:`seated`
        accepts only the candidate with these joints and this pose.
    gains : tuple of (float, float)
        ``(stiffness, damping)`` of each closing joint's position control, in
        actuator order (as ``efforts``): as given, or the per-joint defaults
        of :func:`~drakegrasp.planning.shake.shake_test`.  Empty in a record
        made before it existed.
    object_mass : float
        The object's mass (kg) that gravity pulled on and the simulation
        moved: the model's, or ``shake_test``'s ``object_mass``.  NaN in a
        record made before it existed.
    gravity : float
        The magnitude (m/s²) of the turned gravity: that of the gravity field
        of the plant ``add_models`` built, so the object weighed
        ``object_mass × gravity`` newtons.  NaN in a record made before it
        existed (those shook with 9.81).
    contact_period : float
        The period (s) of the object's stiffest mode (translations and
        rotations about its centre of mass together) on the planned
        contacts' point-contact stiffness
        (:func:`~drakegrasp.planning.shake.contact_period`), which
        ``time_step=None`` takes at least
        :data:`~drakegrasp.planning.shake.CONTACT_PERIOD_STEPS` steps per;
        ``inf`` where not told (hydroelastic fingers, a stiffness the models
        do not state), NaN in a record made before it existed.
    """

    held: bool
    max_displacement: float
    max_rotation: float
    phases: tuple
    squeeze: float
    efforts: tuple[float, ...]
    time_step: float
    duration: float
    wall_time: float
    bounds: tuple[float, float]
    effort_units: tuple[str, ...] = ()
    seat_displacement: float = float("nan")
    seat_rotation: float = float("nan")
    seat_speed: float = float("nan")
    max_displacement_from_seat: float = float("nan")
    max_rotation_from_seat: float = float("nan")
    hydroelastic_modulus: float | None = None
    hydroelastic_refused: int = 0
    squeeze_caps: tuple[float, ...] = ()
    seated_q_hand: tuple[float, ...] = ()
    seated_X_WO: np.ndarray | None = None
    joint_names: tuple[str, ...] = ()
    X_WH: np.ndarray | None = None
    gains: tuple[tuple[float, float], ...] = ()
    object_mass: float = float("nan")
    squeeze_at_contacts: bool = False
    gravity: float = float("nan")
    contact_period: float = float("nan")

    def seated(self, candidate):
        """``candidate`` with the hand's joints and the object where seating left them.

        Its :meth:`~drakegrasp.planning.candidates.GraspCandidate.apply` puts
        the seated grasp in a context, for
        :func:`~drakegrasp.analyze_grasp` (the grasp a multi-finger hand
        really holds, millimetres from the planned one; its ``contacts``
        and scores stay the plan's).  The seated bodies overlap by
        millimetres (compliant hydroelastic pads: 1.1-4.3 mm for the Allegro
        hand on the soup can at 1e6 Pa; Drake's point contact too: about 2 mm
        for a Barrett-like hand of 1.5 N·m), which the analysis refuses as
        penetration unless given ``allow_penetration=True``.  A ``<mimic>``
        follower is set exactly from its leader (Drake's coupler drifts
        micro-radians off it).

        Raises
        ------
        InvalidOptionError
            The test ran with ``seat=0`` (nothing seated); ``candidate`` is not
            the one shaken (other joints, or another hand pose); or the record
            holds no finite joint values or rigid pose (a record built by
            hand).
        """
        if self.seated_X_WO is None:
            raise InvalidOptionError(
                "this shake test ran with seat=0: nothing was seated"
            )
        names = tuple(candidate.joint_names)
        if len(names) != len(self.seated_q_hand) or (
            self.joint_names and names != tuple(self.joint_names)
        ):
            shaken = list(self.joint_names) or f"{len(self.seated_q_hand)} joints"
            raise InvalidOptionError(
                f"the candidate's joints {list(names)} are not those of the "
                f"candidate shaken ({shaken})"
            )
        if self.X_WH is not None and not np.allclose(
            candidate.X_WH.GetAsMatrix4(), _pose("X_WH", self.X_WH), rtol=0, atol=1e-9
        ):
            raise InvalidOptionError(
                "the candidate's hand pose X_WH is not that of the candidate shaken"
            )
        q = np.array(self.seated_q_hand, dtype=float)
        if not np.all(np.isfinite(q)):
            raise InvalidOptionError(f"seated_q_hand must be finite, got {q.tolist()}")
        X_WO = _pose("seated_X_WO", self.seated_X_WO)
        return replace(candidate, q_hand=q, X_WO=RigidTransform(X_WO))

    @property
    def squeeze_unit(self) -> str:
        """The unit of ``squeeze``: "N", "N·m", or both named when mixed.

        "N" with ``squeeze_at_contacts``: newtons at the contacts.
        """
        if self.squeeze_at_contacts:
            return "N"
        return squeeze_unit_of(self.effort_units)

    @property
    def squeeze_capped(self) -> bool:
        """Whether an effort limit held a closing joint below ``squeeze``."""
        return any(cap < self.squeeze for cap in self.squeeze_caps)

    @property
    def held_from_seat(self) -> bool:
        """Whether the object stayed within both bounds of where seating left it.

        Over settling and the turned gravity: whether the seated grasp held.

        A multi-finger hand's fingers do not stop where the plan put them: they
        seat the object a few millimetres and degrees away (5-20 mm and up to
        35° for the Allegro hand on YCB objects) and then hold it there, or
        push it on out of the hand.  ``held`` counts from the plan and calls
        the first "dropped"; this tells the two apart.  An object the squeeze
        keeps pushing is not held: it is still moving when the fingers have
        seated and goes on past the bounds (the Allegro hand's thumbless grasps
        of the sugar box, moving at 0.15-0.5 m/s when seated, end up metres
        away under the turned gravity).  With ``seat=0`` (nothing to seat) it
        is ``held``.
        """
        if np.isnan(self.max_displacement_from_seat):
            return self.held
        return bool(
            self.max_displacement_from_seat <= self.bounds[0]
            and self.max_rotation_from_seat <= self.bounds[1]
        )

    def to_dict(self) -> dict:
        """JSON-ready dictionary (``held_from_seat`` included)."""
        return jsonable(dict(vars(self), held_from_seat=self.held_from_seat))

    def __str__(self) -> str:
        """One line, led by ``held_from_seat`` ("held from the seat").

        The gravity is named when it is not the standard 9.81 m/s² (a moon's,
        a scaled scene's).

        With seating, the motion from the seat comes first and the motion from
        the plan's pose after it (``held``, which ``shake_candidates(
        held_from="plan")`` ranks by, counts from there).
        """
        bounds = (
            f"(bounds {self.bounds[0] * 1e3:g} mm, {np.degrees(self.bounds[1]):g} deg)"
        )
        plan = motion_text(self.max_displacement, self.max_rotation)
        if np.isnan(self.seat_displacement):
            motion = f"moved at most {plan} {bounds}"
            tail = ""
        else:
            seated = (
                f"seated {motion_text(self.seat_displacement, self.seat_rotation)} "
                f"from the plan, moving at {self.seat_speed * 1e3:.3g} mm/s"
            )
            if np.isnan(self.max_displacement_from_seat):  # an older record
                motion = f"{seated}; moved at most {plan} from the plan {bounds}"
                tail = ""
            else:
                since = motion_text(
                    self.max_displacement_from_seat, self.max_rotation_from_seat
                )
                motion = f"{seated}, then at most {since} from there {bounds}"
                tail = f"; from the plan's pose at most {plan}" + (
                    "" if self.held else ", beyond the bounds"
                )
        verdict = "held" if self.held_from_seat else "dropped"
        if not np.isnan(self.max_displacement_from_seat):
            verdict += " from the seat"  # not `held`, which counts from the plan
        unit = self.squeeze_unit
        if "," in unit:  # a mixed hand's: kept apart from the line's commas
            unit = f"({unit})"
        where = " at the contacts" if self.squeeze_at_contacts else ""
        return (
            f"{verdict}: {motion}"
            f" over {self.duration:g} s, squeeze {self.squeeze:g} {unit}{where}"
            + (
                f" (capped at {_limits(self.squeeze_caps, self.squeeze)} {unit}"
                + (" at the contacts)" if self.squeeze_at_contacts else ")")
                if self.squeeze_capped
                else ""
            )
            + f", {len(self.phases)} gravity directions"
            + (
                ""
                if self.hydroelastic_modulus is None
                else f", hydroelastic fingers ({self.hydroelastic_modulus:g} Pa"
                + (
                    f"; {self.hydroelastic_refused} geometries kept point contact)"
                    if self.hydroelastic_refused
                    else ")"
                )
            )
            + (
                f", gravity {self.gravity:g} m/s²"
                if np.isfinite(self.gravity) and self.gravity != GRAVITY
                else ""
            )
            + f"{tail}; {self.wall_time:.2f} s wall"
        )


def motion_text(displacement: float, rotation: float, digits: int = 2) -> str:
    """A motion as "12.34 mm and 5.67 deg"; beyond a metre, only its distance.

    ``displacement`` in metres and ``rotation`` in radians, real and >= 0
    (else ``InvalidOptionError``); either NaN (not measured: ``seat=0``)
    reads "not measured".
    """
    displacement = real_scalar("displacement", displacement)
    rotation = real_scalar("rotation", rotation)
    if np.isnan(displacement) or np.isnan(rotation):
        return "not measured"
    if displacement < 0 or rotation < 0:
        raise InvalidOptionError(
            f"a motion is >= 0, got displacement {displacement!r} m and rotation "
            f"{rotation!r} rad"
        )
    if displacement > 1.0:  # an object that fell: its angle says nothing
        if displacement >= 1e6:  # a diverged simulation: no 300-digit figure
            return f"{displacement:.3g} m (out of the hand)"
        return f"{displacement:.{digits}f} m (out of the hand)"
    return (
        f"{displacement * 1e3:.{digits}f} mm and {np.degrees(rotation):.{digits}f} deg"
    )


def squeeze_unit_of(units: tuple[str, ...]) -> str:
    """The squeeze's unit for a summary line: one unit, or both when mixed.

    :func:`~drakegrasp.closure.load_problem.effort_unit_of` of the joints'
    ``units``: ``"N·m, N at prismatic joints"`` when mixed, and ``"N"`` for
    none (a result recorded before ``effort_units``, of a parallel jaw).
    """
    return effort_unit_of(units, default="N")


def _pose(name: str, X) -> np.ndarray:
    """``X`` as a (4, 4) homogeneous rigid transform, else an error naming ``name``."""
    try:
        M = np.asarray(X, dtype=float)
    except (TypeError, ValueError):
        M = np.full(0, np.nan)
    ok = M.shape == (4, 4) and bool(np.all(np.isfinite(M)))
    if ok:
        R = M[:3, :3]
        ok = (
            np.allclose(R.T @ R, np.eye(3), atol=1e-6)
            and np.linalg.det(R) > 0
            and np.array_equal(M[3], [0.0, 0.0, 0.0, 1.0])
        )
    if not ok:
        raise InvalidOptionError(
            f"{name} must be a finite (4, 4) rigid transform, got {describe(X)}"[:200]
        )
    return M


def _limits(caps, squeeze: float) -> str:
    """The cap of a capped squeeze, in words.

    ``the effort limit: 140``, or ``the effort limits: 0.5-1.12`` where the
    capped joints' limits differ (the other joints press with ``squeeze``).
    """
    below = sorted({c for c in caps if c < squeeze})
    if len(below) <= 1:
        return f"the effort limit: {min(caps):g}"
    return f"the effort limits: {below[0]:g}-{below[-1]:g}"
