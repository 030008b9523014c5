r"""The check against physics: squeeze a planned grasp and turn gravity around it.

:func:`shake_test` builds a fresh discrete-time ``MultibodyPlant`` from the
user's own model function (the same one that built the planning plant), welds
the hand's base at the candidate's ``X_WH``, sets the fingers and the object
where the candidate put them, and simulates with Drake's ``Simulator``:

- the fingers are position-controlled by Drake's PD-controlled actuators
  (``JointActuator.set_controller_gains``, stiffness ``k``) aimed
  ``squeeze / k`` past the place where they touch, so each presses with
  ``squeeze`` newtons, or N·m for a revolute joint (within its effort
  limit; by default 20 N at a revolute finger's contacts, its torque from
  its lever arms: :mod:`drakegrasp.planning.squeeze`),
  less ``k`` times however far it closes on after that (pads that
  give, an object pushed along: ``ShakeResult.efforts`` are what the joints
  apply once seated, and :class:`SqueezeLostWarning` says when little is
  left), and resists being pushed open with stiffness ``k``, as a
  position-controlled gripper does (two
  force-controlled fingers would let gravity along the grasp axis carry
  object and fingers to a joint limit).  Where they touch is found in
  Drake, not taken from the plan: for ``seat`` seconds without gravity the
  fingers close on the object and, half-way, are re-aimed from where they
  stopped.  (Aimed from the planned joint values instead, a finger planned
  0.5 mm inside the object would press ``0.5 mm · k`` harder: 2 N more at
  the WSG-50's default gains);
- the object is free; gravity acts on the object only, as an external force
  ``m |g|`` at its centre of mass, where ``|g|`` is the magnitude of the
  gravity field of the plant ``add_models`` built (9.81 m/s² by Drake's
  default; read once, before that field is set to zero, so that the hand
  feels none): the weight that
  :func:`~drakegrasp.planning.planner.plan_grasps` and
  :func:`~drakegrasp.analyze_grasp` put on the object in that plant.  A
  plant without gravity is refused (``ModelError``): an object that weighs
  nothing is held by every grasp, so the test would say nothing.  The force
  is zero while the fingers seat; its direction is then held for
  ``settle`` seconds along the plant's gravity (the world's ``−z`` by
  Drake's default) and then turned through
  ``directions`` (each held for ``phase`` seconds; over the first ``blend``
  seconds of a phase gravity turns from the previous direction to the next
  at a constant rate along the great circle through them, about an axis
  perpendicular to both when they are opposite, so its magnitude stays
  ``m g``);
- contact, friction and stiffness are the plant's (the models' proximity
  properties: point contact where they declare no hydroelastic ones), or with
  ``hydroelastic_modulus`` the hand's geometries are made compliant
  hydroelastic and the object's rigid, unless its model makes it compliant
  (:mod:`drakegrasp.plant.hydroelastic`),
  so that a flat pad presses over a patch instead of at one point.

The object *holds* when its pose in the hand frame never moves more than
``max_displacement`` (metres) or ``max_rotation`` (radians) from the planned
one.  Gravity acting on the fingers is left out: the hand is held by its base
weld and actuators, and the grasp is what is tested.
"""

from __future__ import annotations

import math
import reprlib
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import (
    AddMultibodyPlantSceneGraph,
)
from pydrake.multibody.tree import PdControllerGains, SpatialInertia, UnitInertia
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from drakegrasp.core.calls import checked_call
from drakegrasp.core.deprecation import outside_stacklevel
from drakegrasp.core.validation import describe, unit_vectors
from drakegrasp.errors import (
    GraspError,
    GraspWarning,
    InvalidGraspError,
    InvalidOptionError,
    ModelError,
    SolverError,
)
from drakegrasp.planning.candidates import GraspCandidate, check_candidate
from drakegrasp.planning.shake_result import ShakeResult, squeeze_unit_of
from drakegrasp.planning.squeeze import DEFAULT_SQUEEZE, HOLD_LEVER, contact_levers
from drakegrasp.planning.turned_gravity import (
    DEFAULT_DIRECTIONS,
    GRAVITY,
    _gravity_field,
    _schedule,
    _TurnedGravity,
)
from drakegrasp.plant.couplings import motor_shares, plant_couplings
from drakegrasp.plant.fingers import (
    effort_unit,
    find_joint,
    hidden_drives,
    limit_towards,
)
from drakegrasp.plant.friction import (
    MU_RELATIVE_TOL,
    FrictionMismatchWarning,
    hand_object_friction,
)
from drakegrasp.plant.hydroelastic import (
    check_hydroelastic_modulus,
    use_hydroelastic_contact,
)
from drakegrasp.plant.models import new_parser
from drakegrasp.plant.validation import (
    check_rigid_transform,
    resolve_body,
    resolve_object_body,
)

__all__ = [
    "CONTACT_PERIOD_STEPS",
    "DAMPING_TIME",
    "DEFAULT_TIME_STEP",
    "MIN_SHAKEN_MASS",
    "MIN_TIME_STEP",
    "PASSED_DEPTH",
    "PRISMATIC_STIFFNESS",
    "REVOLUTE_AIM",
    "SEAT_TOLERANCE",
    "CoarseStepWarning",
    "SoftFingerShakeWarning",
    "SqueezeLostWarning",
    "check_shake_options",
    "contact_period",
    "recorded_mass",
    "shake_test",
]


class SqueezeLostWarning(GraspWarning):
    """The seated fingers press with a small share of the squeeze, the object at rest.

    (An object still moving at the seat is being pushed out: a drop the test
    rightly reports.)  A position-controlled finger aimed ``squeeze /
    stiffness`` past where it stopped presses with ``stiffness`` times what
    is left of that aim: where the fingers close on after aiming by most of
    it (compliant pads, a finger that touches nothing), the test judges a far
    weaker grip than asked for.  Drake's Allegro hand on the YCB soup can, at
    0.7 N·m: its joints' mean seated effort 0.33-0.38 N·m at stiffness 10
    N·m/rad (its five best grasps held), 0.03-0.07 N·m at 100 (all five
    dropped).

    Also when the object was not held and a squeezing joint stood at its
    position limit at the seat, aimed past it (within 5 % of its aim): its
    motor's effort then pressed the joint's stop, not the object.
    """


_LOST = 0.25
""":class:`SqueezeLostWarning` when the closing joints' seated efforts
(``ShakeResult.efforts``; a joint whose link touches nothing presses with
none) are on average under this share of the squeeze each was aimed at ..."""

_AT_STOP = 0.05
""":class:`SqueezeLostWarning` when the object was not held and a squeezing
joint had less than this share of its aim (``squeeze / stiffness``) left
before its position limit at the seat: its motor pressed the joint's stop, not
the object (a Robotiq-3-finger-like hand's scissor joint, planned 0.0225 rad
from its limit and aimed 0.067 rad past, reached the stop in 20 ms and its
sphere fell)."""

_PUSHED_OUT = 0.1
"""... and the object moves slower than this (m/s) at the seat: faster, the
squeeze is pushing it out of the hand (the Allegro hand's thumbless sugar-box
grasps: 0.17-0.53 m/s, against 0.012-0.045 for grasps that hold), a drop the
test is right to report."""


class SoftFingerShakeWarning(GraspWarning):
    """A candidate planned with soft fingers is shaken in point contact.

    The plan counted on each contact resisting a torque about its normal (up
    to ``b ν f_n``); Drake's point contact resists none, so the shake may
    drop a grasp that the plan's model holds.  Hydroelastic fingers
    (``hydroelastic_modulus=``) press over patches, which do resist it.
    """


def _warn_friction(plant, ctx, body, hand, candidate: GraspCandidate) -> None:
    """Warn when the plan's ``μ`` is not the friction Drake simulates here."""
    try:
        mu = float(candidate.contact_options.get("mu"))
        simulated = hand_object_friction(plant, ctx, body, hand)
    except (TypeError, ValueError, GraspError):
        return  # no planned μ, or friction the plant cannot tell: nothing to say
    if not (math.isfinite(mu) and len(simulated)):
        return
    lo, hi = float(np.min(simulated)), float(np.max(simulated))
    if abs(lo - mu) <= MU_RELATIVE_TOL * mu:
        return  # the smallest pair's: what `--mu plant` plans with (the rest hold more)
    warnings.warn(
        f"the candidate was planned with mu = {mu:g}, but Drake simulates the "
        "models' friction between hand and object, mu = "
        f"{lo:g}{'' if lo == hi else f' to {hi:g}'}: the shake tests the grasp "
        "at that friction (plan with the models' friction, or set their "
        "coulomb_friction to the plan's, to plan and shake alike)",
        FrictionMismatchWarning,
        stacklevel=outside_stacklevel(),
    )


def _scoped(plant, joint) -> str:
    return f"{plant.GetModelInstanceName(joint.model_instance())}::{joint.name()}"


def _speed(plant, context, body) -> float:
    """Speed (m/s) of ``body``'s origin in the world (the hand's base is welded)."""
    V = plant.EvalBodySpatialVelocityInWorld(context, body)
    return float(np.linalg.norm(V.translational()))


def _within_limits(joint, q: np.ndarray) -> float:
    """A one-dof joint's value in ``q``, clipped to its limits.

    Drake holds a joint at its limit with a stiff constraint and the state
    overshoots it a little; the seated pose is for an analysis, which
    refuses a joint beyond its limit.
    """
    value = float(q[joint.position_start()])
    low = float(joint.position_lower_limits()[0])
    high = float(joint.position_upper_limits()[0])
    return min(max(value, low), high)


def _angle(R: np.ndarray) -> float:
    return float(np.arccos(np.clip((np.trace(R) - 1) / 2, -1.0, 1.0)))


def _stopped(
    error: RuntimeError, t: float, stiffness: float, modulus: float | None = None
) -> GraspError:
    """The one-line error of a simulation Drake could not advance past ``t``.

    A contact solver that did not converge (SAP, TAMSI) is a ``SolverError``
    that names the gains; anything else Drake refused there (a contact model
    the geometries do not support, say) is a ``ModelError`` with Drake's first
    sentence.
    """
    lines = str(error).split("Reasons for")[0].strip().splitlines()  # then advice
    first = " ".join(lines[0].split()).rstrip(".") if lines else type(error).__name__
    where = f"the shake test's simulation stopped at t = {t:.3g} s ({first})"
    if modulus is not None:
        where += f" with hydroelastic fingers of {modulus:g} Pa"
    if "converge" not in first.lower():
        return ModelError(
            f"{where}: the model that add_models built cannot be simulated"
        )
    return SolverError(
        f"{where}: the fingers' position control (stiffness = {stiffness:g}) is "
        "likely too stiff for their inertia: light revolute fingers need far "
        "lower gains (the Allegro hand: squeeze=0.7, stiffness=10, damping=0.1, "
        "as plan --shake uses); "
        "a smaller time_step also helps"
    )


def _finite_or_nan(value) -> bool:
    """Whether a real number is finite or NaN (an int too large for a float is not)."""
    try:
        return not math.isinf(float(value))
    except OverflowError:
        return False


def _finite(value) -> bool:
    """Whether a real number is finite (a Python int too large for a float is not)."""
    try:
        return math.isfinite(float(value))
    except OverflowError:
        return False


def check_shake_options(
    *,
    squeeze,
    stiffness,
    damping,
    directions,
    settle,
    phase,
    seat,
    blend,
    time_step,
    max_displacement,
    max_rotation,
    hydroelastic_modulus=None,
    object_mass=None,
) -> np.ndarray:
    """Check :func:`shake_test`'s options before anything is simulated.

    Parameters
    ----------
    squeeze, stiffness, damping, directions, settle, phase, seat, blend
        As :func:`shake_test` takes them.
    time_step, max_displacement, max_rotation, hydroelastic_modulus
        As :func:`shake_test` takes them.
    object_mass
        As :func:`shake_test` takes it (None: the model's).

    Returns
    -------
    (k, 3) ndarray of float
        The gravity directions (world frame) scaled to unit length.

    Raises
    ------
    InvalidOptionError
        The first option that is not a finite number in its range (naming it
        and its unit), a time step longer than a tenth of a phase, or
        directions that are not finite non-zero 3-vectors, a
        ``hydroelastic_modulus`` that is neither None nor a finite number > 0,
        or an ``object_mass`` that is neither None nor a finite number > 0
        whose weight is a finite float.
    """
    check_hydroelastic_modulus(hydroelastic_modulus)
    gains = [
        (name, value, low, unit)
        for name, value, low, unit in (
            ("stiffness", stiffness, 0.0, "N/m or N·m/rad"),
            ("damping", damping, None, "N·s/m or N·m·s/rad"),
        )
        if value is not None  # None: shake_test's per-joint default
    ]
    mass = [] if object_mass is None else [("object_mass", object_mass, 0.0, "kg")]
    squeezes = []  # None: newtons at the contacts (shake_test)
    steps = [] if time_step is None else [("time_step", time_step, 0.0, "s")]
    if squeeze is not None:
        squeezes = [("squeeze", squeeze, 0.0, "N, or N·m for revolute joints")]
    for name, value, low, unit in (
        *gains,
        *mass,
        *squeezes,
        *steps,
        ("phase", phase, 0.0, "s"),
        ("settle", settle, None, "s"),
        ("blend", blend, None, "s"),
        ("seat", seat, None, "s"),
        ("max_displacement", max_displacement, None, "m"),
        ("max_rotation", max_rotation, None, "rad"),
    ):
        # low 0.0: must be > 0; None: must be >= 0.
        if not (
            isinstance(value, int | float | np.floating | np.integer)
            and not isinstance(value, bool)
            and _finite(value)
            and (value > 0 if low is not None else value >= 0)
        ):
            relation = "> 0" if low is not None else ">= 0"
            raise InvalidOptionError(
                f"{name} must be a finite number {relation} ({unit}), got {value!r}"
            )
    if object_mass is not None:
        _check_mass("object_mass", float(object_mass))
    if time_step is not None and time_step > phase / 10:
        raise InvalidOptionError(
            f"time_step must be at most a tenth of a phase ({phase / 10:g} s) to "
            f"resolve the shake, got {time_step!r}"
        )
    try:
        dirs = np.asarray(directions, dtype=float)
        if dirs.shape == (3,):
            dirs = dirs[None]  # one direction
    except (TypeError, ValueError):
        dirs = np.zeros((0, 0))
    if (
        dirs.ndim != 2
        or dirs.shape[0] == 0
        or dirs.shape[1] != 3
        or not np.all(np.isfinite(dirs))
        or not np.all(np.any(dirs != 0.0, axis=1))
    ):
        raise InvalidOptionError(
            "directions must be one or more finite non-zero 3-vectors, got "
            f"{directions!r}"
        )
    # Only their directions count, whatever their length (no overflow).
    dirs = unit_vectors("directions", dirs, error=InvalidOptionError)
    return dirs


MIN_SHAKEN_MASS = 1e-6
"""The lightest object (kg) the shake test simulates: a milligram.  Drake's
contact solver stopped on objects of 1e-12 kg against a gripper's gains (the
fuzz suite); no hand grasps anything that light.  On stiff point contacts an
object this light also asks for a step under :data:`MIN_TIME_STEP`, which
``time_step=None`` refuses: it is simulated at a ``time_step`` given."""


DEFAULT_TIME_STEP = 1e-3
"""The shake's time step (s) where the object's contacts do not ask for a
finer one (:data:`CONTACT_PERIOD_STEPS`) and a phase is at least ten of it
(``time_step=None`` takes a tenth of a shorter phase, as a given step must)."""

CONTACT_PERIOD_STEPS = 1.25
"""Steps per period of the object's stiffest mode on its contacts that the
shake takes at the least (``time_step=None`` picks the step so, down to
:data:`MIN_TIME_STEP`; a coarser given step is warned of,
:class:`CoarseStepWarning`).  The mode is the rigid body's, translations and
rotations about its centre of mass together (:func:`contact_period`).

Drake's SAP solver treats a contact whose period ``T = 2π / ω`` is below the
step as near-rigid and regularises it.  Measured with Drake 1.51's default
point contact (1e6 N/m per geometry, so 5e5 N/m a pair) at the default
squeeze of 20 N, 2.8 s of shaking: a 1 cm cube held by a three-finger hand at
its three planned contacts, 4 g (``T`` 0.30 ms), dropped and left the hand at
1 ms (T/h 0.30), turned 17.6° at 0.5 ms (0.60: dropped), 9.7° at 0.2 ms
(1.5), 6.2° at 0.1 ms and 3.9° at 0.05 ms (held); at 16 g (T 0.60 ms) 17.0°
at 1 ms (0.60: dropped), 8.9° at 0.5 ms and 5.3° at 0.2 ms (held).  The
WSG-50's tip spheres on a 5 g, 1 cm cube, 3.6 mm off its centre (T 0.33 ms;
its translation alone, the period counted once, 0.44 ms) threw it 5 m out of
the hand at 1 ms, 2.2 m at 0.5 ms and 0.26 m at 0.4 ms, and kept it within 9 mm at 0.45
ms and from 0.35 ms down (turning 179° about the line between its two point
contacts, which resist no torque about it: a drop that point contact makes,
at every step).  With a dense core (a tenth of that inertia, T 0.15 ms) it
was thrown 1.3-6 m at 0.25, 0.3 and 0.4-0.5 ms, steps its translation
resolves, and kept within 9.2 mm from 0.2 ms down; over inertias of 0.1 to
1.6 times the cube's (T 0.15-0.36 ms, 40 runs at 0.07-0.5 ms) the 11 throws
came at T/h of 0.91 or less, none at 0.93 or more.  Grasps that hold only
creep more at a coarser step: 32 grasps of light rods, plates and boxes (5
and 20 g, the turning mode up to 14 times faster than the translation) held
at the translation's step, at this one and at a quarter of it, the box with
a dense core creeping 0.45 mm and 0.60° at the first, 0.04 mm and 0.04° at
the second."""

MIN_TIME_STEP = 1e-5
"""The finest step (s) ``time_step=None`` picks.  Where the object's
contacts ask for a finer one (:data:`CONTACT_PERIOD_STEPS`) the shake refuses
up front (``ModelError``) rather than run for many minutes or hours: the
default 2.8 s shake is 280,000 steps at this one, measured at 48 s with the
WSG-50 (0.17 ms a step) and about 3 minutes with the Allegro hand (0.66 ms a
step), on one core.  On Drake's default point contact (5e5 N/m a pair) an
object of 4 mg held at two contacts in line with its centre of mass asks for
it (a period of 12.5 µs); a milligram on the WSG-50's contacts asks for 3.7
µs on a 1 cm cube and about 2.4 µs on the shipped box, where its eight tips
touch.  A ``time_step`` given below it is the caller's choice, and is run."""


def _resolving_step(period: float) -> float:
    """The step (s) that takes :data:`CONTACT_PERIOD_STEPS` per ``period``.

    Rounded down to two significant digits (0.26 ms for a period of 0.33
    ms); ``inf`` for an infinite period.
    """
    if not math.isfinite(period):
        return math.inf
    h = period / CONTACT_PERIOD_STEPS
    unit = 10.0 ** (math.floor(math.log10(h)) - 1)
    return math.floor(h / unit) * unit


class CoarseStepWarning(GraspWarning):
    """The given ``time_step`` does not resolve the object's contacts.

    The object's stiffest mode on its contacts (a translation, a rotation
    about its centre of mass, or both: :func:`contact_period`) has a period
    under :data:`CONTACT_PERIOD_STEPS` steps: Drake's contact solver
    regularises it, and the object creeps or is thrown out of the hand by the
    simulation, not by the grasp.  The message names the step that resolves
    it (``time_step=None`` picks it).
    """


_NO_INERTIA = 1e-12
"""A principal moment of inertia about the centre of mass at most this share
of the largest (or not finite) counts as none (:func:`contact_period`)."""


def _mode_period(
    k: np.ndarray,
    p_OC: np.ndarray,
    nhat_O: np.ndarray,
    mass: float,
    p_OBcm: np.ndarray,
    I_Bcm_O: np.ndarray,
) -> float:
    r"""The period (s) of the stiffest mode of a rigid body on point springs.

    Parameters
    ----------
    k : (N,) float
        Each spring's stiffness along its normal, N/m (> 0).
    p_OC : (N, 3) float
        Where each acts, metres, in the body's frame O.
    nhat_O : (N, 3) float
        Its unit normal, in frame O.
    mass : float
        The body's mass, kg (> 0).
    p_OBcm : (3,) float
        Its centre of mass, metres, in frame O.
    I_Bcm_O : (3, 3) float
        Its rotational inertia about the centre of mass, kg·m², in frame O.

    Returns
    -------
    float
        ``2π / ω``, seconds, of the largest root of :math:`K v = \omega^2 M v`
        in the body's twist ``v = [ω_O; v_Bcm_O]`` (rotation about the centre
        of mass, then its translation, frame O):

        .. math::

            K = \sum_i k_i w_i w_i^T, \quad
            w_i = \begin{bmatrix} r_i \times n_i \\ n_i \end{bmatrix}, \quad
            M = \begin{bmatrix} I_{Bcm} & 0 \\ 0 & m \mathbb{1} \end{bmatrix},

        ``r_i = p_OC_i − p_OBcm`` (``w_iᵀ v`` is how fast spring ``i``
        compresses).  ``inf`` where no spring resists any motion.  A rotation
        about a principal axis of no inertia (a moment at most
        ``_NO_INERTIA`` of the largest: a point mass, a thin rod's own
        axis) has no period, as no step resolves it (Drake refuses to
        simulate a free body without rotational inertia): it is held still,
        and the period is that of the other modes; a point mass's is that of
        its translations, :math:`2\pi \sqrt{m / \lambda_{max}(\sum_i k_i n_i
        n_i^T)}`.
    """
    r = p_OC - p_OBcm
    rows = np.hstack([np.cross(r, nhat_O), nhat_O])  # (N, 6): w_iᵀ
    if np.all(np.isfinite(I_Bcm_O)):
        moments, axes = np.linalg.eigh((I_Bcm_O + I_Bcm_O.T) / 2)
        turns = moments > _NO_INERTIA * max(float(moments[-1]), 0.0)
    else:
        moments, axes, turns = np.ones(3), np.eye(3), np.zeros(3, bool)
    # in coordinates M^(1/2) v (principal axes), M is the identity
    scaled = np.hstack(
        [
            (rows[:, :3] @ axes[:, turns]) / np.sqrt(moments[turns]),
            rows[:, 3:] / math.sqrt(mass),
        ]
    )
    K = scaled.T @ (k[:, None] * scaled)
    omega2 = float(np.max(np.linalg.eigvalsh(K)))
    return 2 * math.pi / math.sqrt(omega2) if omega2 > 0 else math.inf


def contact_period(
    plant, inspector, body, candidate, mass: float, *, M_BBo_B=None
) -> float:
    r"""The period (s) of the object's stiffest mode on the planned contacts.

    Each planned contact ``i`` (point ``p_OC``, normal ``n_i``, in the
    object's frame O) is a spring of Drake's point-contact stiffness ``k_i``
    (N/m), that of the finger body's and the object's geometries in series,
    as Drake combines them (``material/point_contact_stiffness``; the
    stiffest geometry of each body), between rigid fingers
    (position-controlled, and far heavier than a light object) and the
    object, a rigid body of mass ``m`` (kg) and rotational inertia
    ``I_Bcm`` about its centre of mass.  The period is that of the stiffest
    of its six modes, translations and rotations about its centre of mass
    together (:math:`K v = \omega^2 M v`, ``K = Σ k_i w_i w_iᵀ``, ``w_i =
    [r_i × n_i; n_i]``, ``r_i`` from the centre of mass, ``M =
    blockdiag(I_Bcm, m 1)``, all in frame O):

    .. math::

        T = 2\pi / \omega_{max}.

    A grasp whose contacts lie off the centre of mass, or spread over a pad
    wider than the object's radius of gyration, turns faster than it slides:
    the WSG-50's tip spheres 3.6 mm off the centre of a 5 g, 1 cm cube, 0.33
    ms against its translation's 0.44 ms (0.15 ms with a dense core, a tenth
    of the inertia).  Where every contact's line passes through the centre
    of mass it is the period of the stiffest translation,
    :math:`2\pi \sqrt{m / \lambda_{max}(\sum_i k_i n_i n_i^T)}`.

    Parameters
    ----------
    plant : MultibodyPlant
        Registered with a ``SceneGraph``; holds the object and the
        candidate's finger bodies (finalized or not).
    inspector : SceneGraphInspector
        The inspector of a context's geometry query (it holds the
        ``SceneGraphConfig``'s default proximity properties).
    body : RigidBody
        The object.
    candidate : GraspCandidate
        Its ``contacts`` (frame O) name their finger bodies.
    mass : float
        The object's mass, kg (finite, > 0).
    M_BBo_B : SpatialInertia, optional
        Where its centre of mass and the shape of its inertia (unit inertia)
        are read: about the body's origin Bo, in its frame B = O (the shake's
        object inertia).  None (default): the body's default spatial inertia.
        Its rotational inertia is taken at ``mass``.  A body of no
        rotational inertia (a massless model's, a point mass) turns without
        a period of its own: its rotations are held, and the period is that
        of its translations; an axis without inertia (a thin rod's own) is
        held alike, and the other modes count.

    Returns
    -------
    float
        Seconds; ``inf`` where it cannot be told (no contacts, a contact that
        is not a finite point and normal, or a geometry without a
        point-contact stiffness: Drake's own estimate then).  A
        hydroelastic pair presses with its patch's stiffness, not this one:
        :func:`shake_test` does not ask with ``hydroelastic_modulus``.

    Raises
    ------
    InvalidOptionError
        ``mass`` is not a finite number > 0.
    """
    if not (_finite(mass) and mass > 0):
        raise InvalidOptionError(
            f"mass must be a finite number > 0 (kg), got {describe(mass)}"
        )

    def stiffness(of) -> float:
        values = [
            inspector.GetProximityProperties(g).GetPropertyOrDefault(
                "material", "point_contact_stiffness", math.nan
            )
            for g in plant.GetCollisionGeometriesForBody(of)
        ]
        if not values or not all(map(_finite, values)):
            return math.nan
        return float(max(values))

    k_object = stiffness(body)
    contacts = [c for c in candidate.contacts if getattr(c, "finger_body", None)]
    try:
        p_OC = np.array([np.asarray(c.p_OC, dtype=float) for c in contacts])
        nhat_O = np.array([np.asarray(c.nhat_O, dtype=float) for c in contacts])
    except (TypeError, ValueError):  # ragged, or not numbers
        return math.inf
    if not (
        contacts
        and p_OC.shape == nhat_O.shape == (len(contacts), 3)
        and np.all(np.isfinite(p_OC))
        and np.all(np.isfinite(nhat_O))
        and k_object > 0
    ):
        return math.inf
    k = []
    for c in contacts:
        try:
            k_finger = stiffness(resolve_body(plant, c.finger_body))
        except GraspError:
            return math.inf
        if not k_finger > 0:
            return math.inf
        k.append(k_finger * k_object / (k_finger + k_object))
    M = body.default_spatial_inertia() if M_BBo_B is None else M_BBo_B
    p_OBcm = np.asarray(M.get_com(), dtype=float)
    G_Bcm = M.get_unit_inertia().ShiftToCenterOfMass(p_OBcm).CopyToFullMatrix3()
    return _mode_period(
        np.asarray(k, dtype=float),
        p_OC,
        nhat_O,
        float(mass),
        p_OBcm,
        float(mass) * G_Bcm,
    )


def _weightless(plant) -> str:
    """Why a plant without gravity is not shaken, and what to do."""
    g_W = np.asarray(plant.gravity_field().gravity_vector(), dtype=float)
    return (
        f"the plant that add_models built has gravity {g_W.tolist()} m/s²: "
        "the shake test turns the object's weight around the grasp, and an "
        "object that weighs nothing is held by every grasp, so the test would "
        "say nothing; give that plant the gravity to shake under in add_models "
        "(plant.mutable_gravity_field().set_gravity_vector([0, 0, -9.81]), or "
        "the acceleration the grasp must bear)"
    )


def _checked_weight(mass: float, g: float) -> float:
    """``m |g|`` (N), the turned gravity's magnitude, refused unless finite > 0.

    ``mass`` (kg) is checked at standard gravity before the plant is built
    (:func:`_check_mass`); in a plant of stronger gravity its weight may
    still be no float, and in one of subnormal gravity it may be 0.
    """
    weight = mass * g
    if not 0.0 < weight < math.inf:
        raise ModelError(
            f"the object's {mass:g} kg in the plant's gravity, {g:g} m/s², "
            f"weighs {weight:g} N: the shake test needs a finite weight > 0 "
            "(give the plant that add_models builds another gravity)"
        )
    return weight


def _check_mass(name: str, mass: float) -> None:
    """Refuse a mass (kg) the shake cannot simulate, naming ``name``.

    Its weight is taken at standard gravity (:data:`GRAVITY`): the plant's
    own is not known before ``add_models`` builds it, where
    :func:`_checked_weight` checks the weight again.
    """
    if not math.isfinite(mass * GRAVITY):
        raise InvalidOptionError(
            f"{name} = {mass:g} kg weighs more than a float holds (its weight "
            "m g is infinite)"
        )
    if mass < MIN_SHAKEN_MASS:
        raise InvalidOptionError(
            f"{name} = {mass:g} kg is lighter than the shake test simulates "
            f"({MIN_SHAKEN_MASS:g} kg, a milligram): Drake's contact solver "
            "cannot hold so light an object against the fingers"
        )


SEAT_TOLERANCE = 1e-3
"""How far (m) beyond its planned ``ψ`` a finger of a candidate planned on a
body may be from the shaken object, at the candidate's poses, before the
shake refuses it as another object than the one planned on (a box's grasp
shaken on a cylinder read "held")."""

_MIN_AIM = 1e-9
"""The least aim ``squeeze / stiffness`` (m or rad) past the touching place: a
joint position of order 1 carries about 16 digits, so a smaller offset is lost
in rounding and the finger presses with nothing (stiffness 1e20 at 20 N)."""


PRISMATIC_STIFFNESS = 4000.0
"""A prismatic finger's default stiffness, N/m (a 5 mm aim at 20 N)."""

REVOLUTE_AIM = 0.1
"""A revolute finger's default aim, rad: its stiffness is what presses with
its squeeze (within the effort limit) this far past its place."""

DAMPING_TIME = 0.0125
"""Default damping over stiffness, s (50 N·s/m at 4000 N/m)."""


def recorded_mass(candidate) -> float:
    """The mass (kg) ``candidate`` records it was planned for, checked; NaN: none.

    Raises
    ------
    InvalidGraspError
        A recorded mass that is neither NaN nor a finite number of at least
        :data:`MIN_SHAKEN_MASS` with a finite weight (a candidate edited by
        hand).
    """
    raw = getattr(candidate, "object_mass", math.nan)  # a record made before it
    if (
        isinstance(raw, bool)
        or not isinstance(raw, int | float | np.integer | np.floating)
        or not _finite_or_nan(raw)
        or raw <= 0
    ):
        raise InvalidGraspError(
            "the candidate's object_mass must be NaN (none recorded) or a "
            f"finite mass > 0 kg, got {reprlib.repr(raw)}"
        )
    planned = float(raw)
    if not math.isnan(planned):
        try:
            _check_mass("the candidate's object_mass", planned)
        except InvalidOptionError as e:
            raise InvalidGraspError(str(e)) from None
    return planned


def _planned_mass(planned: float, body) -> float | None:
    """The mass a candidate was planned for, ``planned`` (kg), or None: the model's.

    None where it records none (NaN: a point cloud or a massless body planned
    without ``object_mass``), or where it is the model's (to a relative
    1e-12).
    """
    model = body.default_mass()
    if math.isnan(planned) or (model > 0 and abs(planned - model) <= 1e-12 * model):
        return None
    return planned


def _object_inertia(body, object_mass, candidate):
    """``(mass, p_BoBcm_B, M_BBo_B or None)``: what the shake's object weighs.

    The model's mass and centre of mass (None: its inertia as it is); with
    ``object_mass`` the model's shape of inertia (unit inertia and centre of
    mass) scaled to that mass, or, for a massless model, which has no shape
    of inertia, a uniform ball of radius ``candidate.torque_scale`` (it holds
    the object) about ``candidate.reference_point`` (where the planner put
    the weight: its collision surface's centroid).
    """
    model = body.default_mass()
    if object_mass is None:
        if not model > 0:  # NaN too
            raise ModelError(
                f"the object {body.name()} has mass {model:g} kg in the model: "
                "gravity would pull on nothing and every grasp would hold; give "
                "object_mass= (kg), the mass the grasp was planned for"
            )
        return model, body.default_com(), None
    mass = float(object_mass)
    if model > 0:
        com = body.default_com()
        unit = body.default_unit_inertia()
    else:
        radius = float(candidate.torque_scale)
        com = np.asarray(candidate.reference_point, dtype=float)
        if not (math.isfinite(radius) and radius > 0 and np.all(np.isfinite(com))):
            raise ModelError(
                f"the object {body.name()} has no mass in the model, and the "
                "candidate no torque_scale to give it an inertia of (a candidate "
                "from plan_grasps has one): give the model its mass and inertia"
            )
        try:
            unit = UnitInertia.SolidSphere(radius).ShiftFromCenterOfMass(-com)
            return mass, com, SpatialInertia(mass, com, unit)
        except RuntimeError as e:  # not a physical inertia (it overflowed)
            raise ModelError(
                f"the object {body.name()} has no mass in the model, and the "
                f"candidate's torque_scale {radius:g} m and reference_point "
                f"{np.round(com, 6).tolist()} give no valid inertia (Drake: "
                f"{str(e).splitlines()[0][:120]}): give the model its mass and "
                "inertia"
            ) from None
    return mass, com, SpatialInertia(mass, com, unit)


def _gains(actuator, squeeze: float, stiffness, damping) -> tuple[float, float]:
    """``(stiffness, damping)`` of an actuator's position control.

    As given, else per the kind of its joint (:func:`shake_test`).
    """
    k = stiffness
    if k is None:
        if actuator.joint().type_name() == "prismatic":  # (before Finalize)
            k = PRISMATIC_STIFFNESS
        else:  # a joint that presses nothing still holds, as stiff as squeeze
            push = min(squeeze, actuator.effort_limit())
            k = (push if push > 0 else squeeze) / REVOLUTE_AIM
    d = k * DAMPING_TIME if damping is None else damping
    return float(k), float(d)


def _arms(plant, add_models, candidate, squeezers, couplings, by_name, X_WO):
    """``(arms, hold)`` of the default squeeze.

    ``arms``: per squeezer that turns a finger (its own joint, or one of the
    followers it drives, revolute: a slide may drive a linkage), its
    :class:`~drakegrasp.planning.squeeze.Arms` at the contacts in frame
    ``X_WO`` (the planned one), through the followers without a motor of
    their own (a follower with one presses with it).  A squeezer that only
    slides fingers is left out: its force is the squeeze.  ``hold``: the aim
    whose stiffness a revolute joint that moves no contact holds with, N·m:
    the squeeze at :data:`~drakegrasp.planning.squeeze.HOLD_LEVER`; with no
    finger that turns, the squeeze (N, or N·m), as an explicit one.

    Raises
    ------
    InvalidGraspError
        No squeezer presses the candidate's contacts when it closes (each
        closes no contact onto the object: contacts on the palm, say), or a
        contact is not a finite point and unit normal.
    """
    moved = [c for c in couplings if c[0] not in by_name]  # no motor of its own
    turning = {
        name: sign
        for name, sign in squeezers.items()
        if any(
            find_joint(plant, joint).type_name() != "prismatic"
            for joint in [name, *(f for f, leader, _, _ in moved if leader == name)]
        )
    }
    if not turning:  # a jaw's sliding fingers: the squeeze is their force
        return {}, DEFAULT_SQUEEZE
    arms = contact_levers(add_models, candidate, turning, moved, X_WO=X_WO)
    if len(turning) == len(squeezers) and not any(a.press for a in arms.values()):
        raise InvalidGraspError(
            f"none of the candidate's motors ({', '.join(turning)}) closes a "
            "finger onto the object at its contacts, so the default squeeze (20 N "
            "at the contacts) presses nothing: give squeeze= (N, or N·m per "
            "revolute joint)"
        )
    return arms, DEFAULT_SQUEEZE * HOLD_LEVER


def _squeezers(candidate, couplings, driven: dict, by_name: dict) -> dict:
    """The actuated joints that squeeze, each with the sign that closes it.

    A closing joint with an actuator squeezes; a ``<mimic>`` follower of
    another closing joint moves with it; a follower of a hidden drive (a
    leader that is no closing joint) is closed by the drive, moving the way
    that closes the follower times the sign of ``ρ``.
    """
    rho = {follower: r for follower, _, r, _ in couplings}
    out = {}
    for name, sign in zip(candidate.joint_names, candidate.closing_signs, strict=True):
        leader = driven.get(name)
        if name not in by_name and leader in candidate.joint_names:
            continue  # its coupler moves it with its leader
        if name not in by_name and leader is not None:
            drive_sign = sign * math.copysign(1.0, rho[name])
            if out.setdefault(leader, drive_sign) != drive_sign:
                raise ModelError(
                    f"the drive {leader} cannot close the candidate's fingers: "
                    "moving it closes one of the joints that follow it and "
                    "opens another"
                )
            continue
        if name not in by_name:
            raise ModelError(
                f"closing joint {name} has no actuator to squeeze with (give it "
                "one, a URDF <transmission> or an SDFormat <drake:actuator>, or "
                "couple it to an actuated joint with a <mimic> that drakegrasp "
                "reads: drakegrasp.plant.add_models in add_models; Drake's "
                "parser gives no actuator to a URDF joint whose effort limit "
                "is 0)"
            )
        out[name] = sign
    return out


def _known_couplings(plant) -> tuple:
    """The plant's recorded couplings; none where some constraint is unknown.

    (A bare ``Parser`` left a ``<mimic>`` unrecorded: then no follower is
    taken as driven, and one without an actuator is refused.)
    """
    try:
        return plant_couplings(plant)
    except InvalidOptionError:
        return ()


def _on_couplings(couplings, names, q: list) -> tuple[float, ...]:
    """``q`` over joints ``names`` with each follower set exactly from its leader.

    Drake's coupler constraint is compliant: a simulated follower drifts
    micro-radians off ``ρ q_leader + Δq``, more than the coupling tolerance
    that :func:`~drakegrasp.analyze_grasp` checks a pose against.
    """
    at = {name: k for k, name in enumerate(names)}
    for follower, leader, rho, offset in couplings:
        if follower in at and leader in at:
            q[at[follower]] = rho * q[at[leader]] + offset
    return tuple(float(x) for x in q)


def _check_planned_object(
    plant, ctx, body, candidate: GraspCandidate, X_WO: RigidTransform
) -> None:
    """Refuse an object whose surface is not where the candidate touched it.

    Each finger that touched the object in the plan (a candidate planned on
    a body: its contacts name their geometry) must be within its planned
    ``|ψ|`` plus :data:`SEAT_TOLERANCE` of the shaken object, the hand at
    the candidate's pose and a free object at the planned ``X_WO`` (put
    back where ``ctx`` had it after).  A candidate planned on a point cloud
    is let be (its surface is the cloud's, not the model's).
    """
    planned = [
        c for c in candidate.contacts if getattr(c, "object_geometry_name", None)
    ]
    if not planned:
        return
    placed = None
    if body.is_floating_base_body():
        placed = plant.GetFreeBodyPose(ctx, body)
        plant.SetFreeBodyPose(ctx, body, X_WO)
    try:
        _check_finger_gaps(plant, ctx, body, planned)
    finally:
        if placed is not None:
            plant.SetFreeBodyPose(ctx, body, placed)


def _distances(plant, query, finger, objects) -> list[float]:
    """Signed distances (m) between ``finger``'s geometries and ``objects``.

    Each pair that is not collision-filtered, as ``query`` measures it now; a
    pair Drake does not measure (its ``RuntimeError``) is left out.
    """
    inspector = query.inspector()
    out = []
    for gf in plant.GetCollisionGeometriesForBody(finger):
        for go in objects:
            if inspector.CollisionFiltered(go, gf):
                continue
            try:
                pair = query.ComputeSignedDistancePairClosestPoints(go, gf)
            except RuntimeError:  # a pair Drake does not measure: let be
                continue
            out.append(float(pair.distance))
    return out


def _check_finger_gaps(plant, ctx, body, planned: list) -> None:
    """:func:`_check_planned_object` at the poses ``ctx`` holds."""
    query = plant.get_geometry_query_input_port().Eval(ctx)
    objects = plant.GetCollisionGeometriesForBody(body)
    for name in sorted({c.finger_body for c in planned}):
        finger = resolve_body(plant, name)
        bound = SEAT_TOLERANCE + max(
            abs(c.psi) for c in planned if c.finger_body == name
        )
        gaps = _distances(plant, query, finger, objects)
        if gaps and abs(min(gaps)) > bound:
            gap = min(gaps)
            where = (
                f"{gap * 1e3:.3g} mm from" if gap > 0 else f"{-gap * 1e3:.3g} mm inside"
            )
            raise ModelError(
                f"the candidate's finger {name} touched the object in the plan, "
                f"but the shake's models put it {where} {_scoped(plant, body)} "
                f"at the candidate's poses (beyond {bound * 1e3:.3g} mm): shake "
                "it with the object and the hand it was planned with"
            )


PASSED_DEPTH = 1e-4
"""How deep (m) a finger's collision geometry may overlap the object at the
seat while pressing it with no force, before the shake refuses the run as one
whose fingers passed into the object (``_check_seated``).  Pressing, an
overlap is the contact's own compliance (0.04 mm at 20 N in Drake's default
point contact; 1-4 mm for compliant pads); pressing nothing, it is a finger
Drake no longer sees: the WSG-50's 1 mm tip spheres made hydroelastic at 1e6
Pa carry about ``E π r²`` = 3 N, and under a 20 N squeeze they closed 2.5 mm
into a 10 mm cube, wholly inside it, where a compliant geometry in a rigid one
has no contact surface: the cube fell 8 m, "dropped" by no grasp's fault.

Absolute, not scaled with the object: an overlap is set by the squeeze and
the contact's stiffness, not by the object's size.  Measured at the seat over
80 runs (top five grasps, point contact and hydroelastic fingers of 1e4-1e6
Pa, 20 N): point contact overlapped 0.04 mm a finger on a 5 mm cube (a
parallel jaw scaled 0.2), on the 10 mm cube (the WSG-50) and on a 1 m cube (a
jaw scaled 20) alike, 0.01 mm on the 50 mm box (the WSG-50's four tips a
finger); pressing hydroelastic fingers 1.0-9.1 mm, at every size; and a
finger pressing nothing overlapped only where it had passed in, 1.5-2.5 mm
deep in the 10 mm cube.  A bound proportional to size, 0.1 mm at 50 mm, would
be 2 mm at 1 m, where a finger that passes in goes no deeper than elsewhere
(its aim, squeeze / stiffness, bounds how far it closes on: 5 mm at the
defaults), and on a 5 mm object (10 µm) would change nothing, pressing
fingers being let be; only an object thinner than about twice this bound
could hide a finger passed into it."""


def _check_seated(plant, ctx, body, candidate, modulus, squeeze) -> None:
    """Refuse a run whose fingers went into the object while seating.

    Each finger body that touched the object in the plan (the candidate's
    contacts name it) must, at the end of seating, press the object (a
    contact force in Drake's ``ContactResults``) or not overlap it deeper
    than :data:`PASSED_DEPTH`: one that overlaps it pressing nothing passed
    into it (or through it), and what the test would see next is the
    simulation's failure, not a drop.  A candidate planned on a point cloud
    names no fingers on a body and is let be.

    Raises
    ------
    SolverError
        A finger passed into the object; the message names it, its depth and
        the remedies.
    """
    fingers = sorted(
        {
            c.finger_body
            for c in candidate.contacts
            if getattr(c, "object_geometry_name", None)
            and getattr(c, "finger_body", None)
        }
    )
    if not fingers:
        return
    results = plant.get_contact_results_output_port().Eval(ctx)
    query = plant.get_geometry_query_input_port().Eval(ctx)
    inspector = query.inspector()
    pressing = set()  # bodies that press the object
    for i in range(results.num_point_pair_contacts()):
        info = results.point_pair_contact_info(i)
        pair = {info.bodyA_index(), info.bodyB_index()}
        if body.index() in pair and np.linalg.norm(info.contact_force()) > 0:
            pressing |= pair
    for i in range(results.num_hydroelastic_contacts()):
        info = results.hydroelastic_contact_info(i)
        surface = info.contact_surface()
        pair = {
            plant.GetBodyFromFrameId(inspector.GetFrameId(g)).index()
            for g in (surface.id_M(), surface.id_N())
        }
        if body.index() in pair and np.linalg.norm(info.F_Ac_W().translational()) > 0:
            pressing |= pair
    objects = plant.GetCollisionGeometriesForBody(body)
    passed = []
    for name in fingers:
        finger = resolve_body(plant, name)
        if finger.index() in pressing:
            continue
        depths = [-d for d in _distances(plant, query, finger, objects)]
        if depths and max(depths) > PASSED_DEPTH:
            passed.append(f"{name} {max(depths) * 1e3:.3g} mm")
    if not passed:
        return
    if modulus is not None:
        cause = (
            f"its hydroelastic geometry ({modulus:g} Pa) gave way under the "
            f"squeeze ({squeeze:g}) until it lay inside the rigid object, where "
            "a compliant geometry has no contact surface (a compliant ball of "
            "radius r carries about modulus × π r² before it does)"
        )
        remedy = (
            "give a stiffer hydroelastic_modulus, a smaller squeeze, or point "
            "contact (hydroelastic_modulus=None)"
        )
    else:
        cause = "it closed past the object's surface faster than contact stopped it"
        remedy = (
            "give a smaller time_step, stiffer contact (the geometries' "
            "point_contact_stiffness) or a smaller squeeze"
        )
    raise SolverError(
        "the shake test's simulation lost the grasp while seating, which is no "
        f"drop: the finger{'' if len(passed) == 1 else 's'} "
        f"{', '.join(passed)} inside {_scoped(plant, body)}, pressing it with "
        f"no force (deeper than {PASSED_DEPTH * 1e3:g} mm): {cause}; {remedy}"
    )


def _at_stops(plant, ctx, squeezing, targets, efforts, units) -> list[str]:
    """The squeezing joints that stand at their limit, aimed past it, in words.

    A joint aimed past its position limit stops there: its motor's effort then
    goes into the stop, and the object keeps none of it (:data:`_AT_STOP`).
    """
    q = plant.GetPositions(ctx)
    stopped = []
    for actuator, effort, unit in zip(squeezing, efforts, units, strict=True):
        joint = actuator.joint()
        aim = targets[int(joint.index())]
        if joint.num_positions() != 1 or aim == 0.0:
            continue
        limit = limit_towards(joint, aim)
        room = math.copysign(1.0, aim) * (limit - q[joint.position_start()])
        if math.isfinite(limit) and room < _AT_STOP * abs(aim):
            stopped.append(
                f"{joint.name()!r} at its limit {limit:.4g} ({effort:.3g} {unit})"
            )
    return stopped


def _warn_at_stops(stopped: list[str]) -> None:
    """Say that a dropped object's squeeze went into joint stops, if it did."""
    if stopped:
        one = len(stopped) == 1
        warnings.warn(
            f"the object was not held, and at the seat the closing joint"
            f"{'' if one else 's'} "
            + "; ".join(stopped)
            + " stood aimed past the limit: "
            + ("that effort" if one else "those efforts")
            + " pressed the stop, not the object.  A grasp that leans on such a "
            "joint needs it to close further than the model allows: choose a "
            "candidate that leaves it room (or give the model its true range)",
            SqueezeLostWarning,
            stacklevel=outside_stacklevel(),
        )


def _shake_plant(add_models, step: float, object_body):
    """``add_models`` read into a new discrete plant of time step ``step`` (s).

    Returns ``(builder, plant, scene_graph, hand, object, g, down)``: the
    object ``object_body`` where given, ``g`` the magnitude (m/s²) of the
    gravity field ``add_models`` left the plant with and ``down`` its unit
    direction (3,) in the world frame, both from one read of the field made
    before the shake sets it to zero (so that the hand feels none).

    Raises
    ------
    ModelError
        ``add_models`` returned no ``(hand, object_body)`` pair, or left the
        plant without gravity or with one that is not finite.
    """
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=step)
    made = add_models(plant, new_parser(plant, "the shake test's plant"))
    if not (isinstance(made, tuple | list) and len(made) == 2):
        raise ModelError(
            f"add_models must return (hand, object_body), got {type(made).__name__}"
        )
    hand, obj = made
    if object_body is not None:
        obj = object_body
    g, g_W = _gravity_field(plant)
    if g == 0.0:
        raise ModelError(_weightless(plant))
    return builder, plant, scene_graph, hand, obj, g, g_W / g


def _period_before_finalize(plant, scene_graph, body, candidate, mass, M_BBo_B):
    """:func:`contact_period` on a plant not yet finalized (s).

    Read through a context of ``scene_graph`` alone, whose inspector holds
    its ``SceneGraphConfig``'s default proximity properties as the
    simulation's will: a step finer than the plant's is known before
    anything is built on the plant, which is then dropped unfinalized (Drake
    fixes a plant's step when it is made, and the step depends on the models
    ``add_models`` reads).
    """
    context = scene_graph.CreateDefaultContext()
    inspector = scene_graph.get_query_output_port().Eval(context).inspector()
    return contact_period(plant, inspector, body, candidate, mass, M_BBo_B=M_BBo_B)


def _too_fine(plant, body, mass, period, resolving, duration) -> str:
    """Why ``time_step=None`` refuses an object, and what the caller can do.

    Its contacts ask for a step under :data:`MIN_TIME_STEP`: ``resolving``
    (s) for a period ``period`` (s), over ``duration`` seconds of shaking.
    """
    steps = math.ceil(duration / resolving)
    return (
        f"the object {_scoped(plant, body)} ({mass:g} kg) on its planned point "
        f"contacts has a stiffest mode of period {period:.3g} s, which takes "
        f"time_step <= {resolving:.2g} s to resolve ({CONTACT_PERIOD_STEPS:g} "
        f"steps a period): under the shake's floor of {MIN_TIME_STEP:g} s "
        f"(MIN_TIME_STEP), {steps:,} steps for {duration:g} s of shaking, so "
        "time_step=None does not run it; give time_step= (the step you "
        "accept: smaller runs longer, larger lets Drake's contact solver "
        "regularise the contacts), a heavier object_mass, or softer contact "
        "(a lower point_contact_stiffness in the models' proximity "
        "properties, or hydroelastic_modulus= for compliant fingers)"
    )


@checked_call
def shake_test(
    add_models: Callable,
    candidate: GraspCandidate,
    *,
    squeeze: float | None = None,
    stiffness: float | None = None,
    damping: float | None = None,
    directions: Sequence[Sequence[float]] = DEFAULT_DIRECTIONS,
    settle: float = 0.3,
    phase: float = 0.4,
    seat: float = 0.1,
    blend: float = 0.1,
    time_step: float | None = None,
    max_displacement: float = 0.01,
    max_rotation: float = np.radians(10.0),
    object_body=None,
    X_WO: RigidTransform | None = None,
    hydroelastic_modulus: float | None = None,
    object_mass: float | None = None,
) -> ShakeResult:
    """Simulate a planned grasp in Drake and report whether the object stays put.

    Parameters
    ----------
    add_models : callable
        ``add_models(plant, parser) -> (hand, object_body)``: adds the hand (its
        base not welded) and the object to a fresh plant, as for planning;
        ``hand`` a model instance, ``object_body`` a body or its scoped name.
        Leave out supports such as a table: the test turns gravity around.
        The magnitude of the gravity field it leaves the plant with is the
        turned gravity's (``ShakeResult.gravity``; Drake's default 9.81 m/s²):
        set it here (``plant.mutable_gravity_field().set_gravity_vector``) to
        shake under the gravity the grasp was planned in, a moon's or a
        scaled scene's.  A field of zero is refused.
    candidate : GraspCandidate
        From :func:`~drakegrasp.planning.planner.plan_grasps`.
    squeeze : float or None, optional
        Force with which each finger presses, newtons (at most the actuator's
        effort limit); for a revolute joint (a multi-finger hand) the torque
        on each closing joint that closing moved, N·m.  None (default):
        :data:`~drakegrasp.planning.squeeze.DEFAULT_SQUEEZE` (20 N), a
        prismatic finger's force and, for a revolute joint, at the contacts:
        its motor is aimed at the torque that presses each finger body it
        closes on the object with 20 N there, ``20 N × Σ lever arms`` from the
        hand's Jacobian at the candidate's pose
        (:func:`~drakegrasp.planning.squeeze.contact_levers`: 2.15 N·m, 20
        N at each pad 54 mm from the axes, for the one motor of a
        Robotiq-2F-85-like hand that a squeeze of 20 N·m on each of its six
        joints aimed at 120 N·m, throwing the box out of the hand; a slide
        that drives turning fingers through its ``<mimic>`` followers alike).
        A joint whose closing presses no contact holds where it stands.  A
        candidate whose closing presses none of its contacts is refused
        (``InvalidGraspError``): give a number.  It
        is the press at rest, the position control's aim, not a cap: a
        finger that the object pushes back presses harder, up to the
        actuator's effort limit, where Drake clamps it (the Allegro hand's
        0.7 N·m under a 0.5 N·m squeeze); to test motors of a given strength,
        give the model that effort limit.
    stiffness, damping : float or None, optional
        Gains of the fingers' position control (N/m, N·s/m; per radian for
        revolute joints): each finger is aimed ``squeeze / stiffness`` past
        where it touches.  A finger presses with ``stiffness`` times what is
        left of its aim: where it closes on after aiming (compliant pads, an
        object pushed along) it presses with less (``ShakeResult.efforts``),
        and with nothing once it has closed on by the whole aim
        (:class:`SqueezeLostWarning`).  None (default): per joint,
        :data:`PRISMATIC_STIFFNESS` (4000 N/m: a 5 mm aim at 20 N) for a
        prismatic one and, for a revolute one, what aims it
        :data:`REVOLUTE_AIM` (0.1 rad) past its place (its pressing torque
        over 0.1 rad: 7 N·m/rad for the Allegro hand's 0.7 N·m; a fixed 4000
        N·m/rad aimed its light fingers 0.2 mrad past, lost at once as they
        closed on); at the default squeeze, what deflects it 0.1 rad under
        the squeeze at its contacts in any direction, its reach's torque over
        0.1 rad (:class:`~drakegrasp.planning.squeeze.Arms`; a finger that
        presses square on is aimed 0.1 rad past, a spread presses little and
        holds as stiffly as its reach asks), and for one that moves no
        contact the squeeze at
        :data:`~drakegrasp.planning.squeeze.HOLD_LEVER` over 0.1 rad, each
        within its effort limit; damping ``stiffness`` ×
        :data:`DAMPING_TIME` (50 N·s/m at 4000 N/m).  Given, one value for
        every joint (``plan --shake`` gives the Allegro hand 0.7 N·m,
        stiffness 10, damping 0.1).
    directions : sequence of (3,) float, optional
        World gravity directions after the settling phase (any finite,
        non-zero length: only the direction counts; consecutive ones may be
        opposite).  The grasp settles under the plant's own gravity
        direction: the world's −z by Drake's default.
    settle, phase, blend : float, optional
        Seconds: settling under the plant's gravity direction, each
        direction's hold, the blend between directions (gravity turns along
        the great circle from one direction to the next, its magnitude
        constant).
    seat : float, optional
        Seconds without gravity, before settling, in which the fingers close
        on the object: each is aimed ``squeeze / k`` past where it stands
        (the candidate's joint values), and after ``seat / 2`` re-aimed from
        where it stopped, so that it presses with
        ``squeeze`` whether the plan left it short of the surface or inside
        it.  0: aimed from the candidate's joint values.
    time_step : float or None, optional
        The discrete plant's step, seconds: at most a tenth of ``phase``.
        None (default) picks it: :data:`DEFAULT_TIME_STEP`, or a tenth of
        ``phase`` where that is shorter, or shorter still where the object's
        point contacts ask for it: :data:`CONTACT_PERIOD_STEPS` steps per
        period of its stiffest mode, translations and rotations about its
        centre of mass (``ShakeResult.contact_period``,
        :func:`contact_period`), down to :data:`MIN_TIME_STEP` (10 µs): an
        object whose contacts ask for a finer step (a few milligrams on
        Drake's default point contact) is refused before anything is
        simulated (``ModelError``), and runs with a ``time_step`` given.  A
        given step that does not resolve the contacts is warned of
        (:class:`CoarseStepWarning`); one below :data:`MIN_TIME_STEP` is run.
    max_displacement, max_rotation : float, optional
        Bounds on the object's motion in the hand frame: metres, radians.
    object_body : optional
        Overrides the object that ``add_models`` returns.
    X_WO : RigidTransform, optional
        The object's pose in the world at the start (default the candidate's
        ``X_WO``).  A candidate planned on a point cloud has the cloud's frame
        there (its centroid or, completed, its centre of symmetry, with the
        world's axes), not the object's: give the true pose of the object the
        cloud was taken from.
    hydroelastic_modulus : float or None, optional
        None (default): the contact the models declare (Drake's point contact
        where they declare no hydroelastic properties: one point per pair of
        geometries, so a flat pad on a flat face touches at one point and the
        object pivots between two such pads).  A modulus (Pa, finite > 0):
        the hand's collision geometries are made compliant hydroelastic with
        it and the object's rigid (unless its model makes it compliant: it
        keeps its own), so each pad presses over a patch, as it
        does on a real object (:mod:`drakegrasp.plant.hydroelastic`; 1e6 suits
        rubber pads).
    object_mass : float or None, optional
        The object's mass, kg (finite, at least :data:`MIN_SHAKEN_MASS`, with
        a finite weight), that gravity pulls on and the
        simulation moves; its inertia scales with it (the same shape and
        centre of mass, a uniform density).  None (default): the mass the
        candidate was planned for (``candidate.object_mass``: ``plan_grasps``'
        ``object_mass`` or the body's), so that the shake tests that plan;
        the model's (``add_models``' object) for a candidate that records
        none.  A massless model (a URDF link
        without ``<inertial>``) gets the inertia of a uniform ball that holds
        it (radius ``candidate.torque_scale``) about the point the planner
        took as its centre of mass (``candidate.reference_point``).

    Returns
    -------
    ShakeResult

    Raises
    ------
    InvalidOptionError
        Bad options (non-positive time step or squeeze, a zero direction, an
        ``X_WO`` that is not a finite rigid pose...).
    SolverError
        Drake's contact solver did not converge during the simulation (gains
        too stiff for the fingers' inertia, or too long a ``time_step``); the
        message gives the time and what to lower.
    ModelError
        ``add_models`` did not add the candidate's hand base or closing joints
        or welded the base itself, its object has no mass and no
        ``object_mass`` is given (gravity would pull on nothing and every grasp
        would hold), its plant has no gravity (the same: set the gravity to
        shake under in ``add_models``), a gravity that is not finite or in
        which the object's weight is no float, an object whose point
        contacts ask ``time_step=None`` for a step under
        :data:`MIN_TIME_STEP` (the message names it, its mass, the period and
        the remedies), or Drake refused to advance the model for another
        reason (its first sentence is in the message).
    InvalidGraspError
        The candidate's joint values or poses are not finite or do not match
        its closing joints (:func:`~drakegrasp.planning.candidates.check_candidate`),
        or, at the default squeeze, a contact is not a finite point and unit
        normal, or its closing presses none of its contacts.

    Warns
    -----
    SoftFingerShakeWarning
        The candidate was planned with soft fingers and the shake runs in
        point contact (no ``hydroelastic_modulus``), which resists no torque
        about a contact normal.
    FrictionMismatchWarning
        The candidate was planned with a ``μ`` other than the friction Drake
        simulates between the hand and the object (the models' own).
    SqueezeLostWarning
        At the seat, the closing joints press with under a quarter of their
        aim on average, the object at rest; or the object was not held and
        a squeezing joint stood at its position limit at the seat, aimed past
        it (its effort pressed the stop).
    """
    if not callable(add_models):
        raise InvalidOptionError(
            "add_models must be a function add_models(plant, parser) -> (hand, "
            f"object_body), got {type(add_models).__name__}"
        )
    if not isinstance(candidate, GraspCandidate):
        raise InvalidOptionError(
            "candidate must be a GraspCandidate from plan_grasps, got "
            f"{type(candidate).__name__}"
        )
    planned_X_WO = candidate.X_WO
    if X_WO is not None:
        candidate = replace(candidate, X_WO=check_rigid_transform("X_WO", X_WO))
    check_candidate(candidate)
    planned = recorded_mass(candidate)  # checked before anything is built
    dirs = check_shake_options(
        squeeze=squeeze, stiffness=stiffness, damping=damping,
        directions=directions, settle=settle, phase=phase, seat=seat,
        blend=blend, time_step=time_step, max_displacement=max_displacement,
        max_rotation=max_rotation, hydroelastic_modulus=hydroelastic_modulus,
        object_mass=object_mass,
    )  # fmt: skip
    modulus = check_hydroelastic_modulus(hydroelastic_modulus)
    ends = [seat + settle + (k + 1) * phase for k in range(len(dirs))]
    duration = ends[-1]  # simulated seconds, once
    t0 = time.perf_counter()
    # None: the default step, within a tenth of a phase as a given one must be
    step = min(DEFAULT_TIME_STEP, phase / 10) if time_step is None else time_step
    step = float(step)
    builder, plant, scene_graph, hand, obj, g, down = _shake_plant(
        add_models, step, object_body
    )
    body = resolve_object_body(plant, obj)
    if object_mass is None:
        object_mass = _planned_mass(planned, body)
    mass, com, inertia = _object_inertia(body, object_mass, candidate)
    period = math.inf  # a compliant patch's stiffness is not a point's
    if modulus is None:
        period = _period_before_finalize(
            plant, scene_graph, body, candidate, mass, inertia
        )
    resolving = _resolving_step(period)
    if time_step is None and resolving < step:  # the models read again at that step
        if resolving < MIN_TIME_STEP:
            raise ModelError(_too_fine(plant, body, mass, period, resolving, duration))
        step = resolving
        builder, plant, scene_graph, hand, obj, g, down = _shake_plant(
            add_models, step, object_body
        )
        body = resolve_object_body(plant, obj)
    base = resolve_body(plant, candidate.hand_base)
    actuators = [plant.get_joint_actuator(a) for a in plant.GetJointActuatorIndices()]
    by_name = {_scoped(plant, a.joint()): a for a in actuators}
    targets, gains, pushed = {}, {}, {}
    # a follower is driven by its leader's motor: a closing joint's, or a
    # hidden drive's (a leader that closes nothing itself)
    couplings = _known_couplings(plant)
    drives = hidden_drives(plant, couplings)
    actuated = [
        name for name in by_name if name in candidate.joint_names or name in drives
    ]
    driven, shares = motor_shares(
        couplings, candidate.joint_names, actuated, drives=drives
    )
    squeezers = _squeezers(candidate, couplings, driven, by_name)
    default = squeeze is None
    arms, hold = (
        _arms(plant, add_models, candidate, squeezers, couplings, by_name, planned_X_WO)
        if default
        else ({}, squeeze)
    )
    if default:
        squeeze = DEFAULT_SQUEEZE
    at_contacts = bool(arms)  # a turning motor aims at newtons at contacts
    for name, sign in squeezers.items():
        actuator = by_name[name]
        # a leader's motor also presses through the followers it drives: each
        # of them and the leader press with squeeze (within the effort limit);
        # by default a revolute motor with the torque that presses its
        # fingers' contacts with squeeze newtons (planning.squeeze)
        share = shares.get(name, 1.0)
        arm = arms.get(name)
        aim = squeeze * share if arm is None else squeeze * arm.press
        push = min(aim, actuator.effort_limit())
        # the squeeze each presses with, capped, in squeeze's unit: a joint's
        # share of its motor, or newtons at the contacts
        cap = squeeze if push >= aim else push / (share if arm is None else arm.press)
        # a turning finger holds as stiffly as the squeeze at its reach asks
        # (a spread presses little, a geared drive reaches little); one that
        # moves no contact as `hold` does
        held = hold if arm is None or not arm.reach else squeeze * arm.reach
        k, _ = gains[int(actuator.index())] = _gains(
            actuator, aim if arm is None else max(aim, held), stiffness, damping
        )
        if arm is not None and push / k < _MIN_AIM:  # round-off: it holds still
            push = 0.0
        pushed[int(actuator.index())] = (push, cap)
        if 0 < push / k < _MIN_AIM:
            raise InvalidOptionError(
                f"stiffness = {k:g} aims joint {name} {push / k:.3g} "
                f"past where it touches (squeeze {push:g} / stiffness): below what "
                f"a joint's position resolves ({_MIN_AIM:g}), so it would press "
                f"with nothing; give a stiffness below {push / _MIN_AIM:.3g}"
            )
        targets[int(actuator.joint().index())] = sign * push / k
    if not targets:
        raise ModelError(
            f"none of the candidate's closing joints {list(candidate.joint_names)} "
            "has an actuator to squeeze with"
        )
    for actuator in actuators:  # every actuator position-controlled (Drake's PD)
        k, d = gains.get(int(actuator.index())) or _gains(
            actuator, hold, stiffness, damping
        )
        actuator.set_controller_gains(PdControllerGains(p=k, d=d))
    try:
        plant.WeldFrames(plant.world_frame(), base.body_frame(), candidate.X_WH)
    except RuntimeError as e:  # add_models welded it already
        raise ModelError(
            f"add_models must leave the hand's base {candidate.hand_base} free (the "
            f"shake welds it at the candidate's X_WH); Drake: {str(e)[:160]}"
        ) from None
    plant.mutable_gravity_field().set_gravity_vector(np.zeros(3))
    refused = 0
    if modulus is not None:
        # the hand: its base's model instance and those of its closing joints
        instances = {base.model_instance()} | {
            a.joint().model_instance()
            for a in actuators
            if int(a.joint().index()) in targets
        }
        hand_bodies = [
            plant.get_body(i)
            for instance in sorted(instances, key=int)
            for i in plant.GetBodyIndices(instance)
            if i != body.index()
        ]
        refused = use_hydroelastic_contact(
            plant, scene_graph, hand_bodies, [body], modulus=modulus
        )
    plant.Finalize()
    weight = _checked_weight(mass, g)
    schedule = _schedule(seat, settle, phase, blend, dirs, down=down)
    gravity = builder.AddSystem(_TurnedGravity(body.index(), weight, com, schedule))
    builder.Connect(
        gravity.get_output_port(), plant.get_applied_spatial_force_input_port()
    )
    diagram = builder.Build()
    simulator = Simulator(diagram)
    root = simulator.get_mutable_context()
    ctx = plant.GetMyContextFromRoot(root)
    if inertia is not None:
        body.SetSpatialInertiaInBodyFrame(ctx, inertia)
    if step > resolving:
        warnings.warn(
            f"time_step = {step:g} s does not resolve the object's contacts: "
            f"their stiffest mode has a period of {period:.3g} s "
            f"({mass:g} kg on point contacts), under {CONTACT_PERIOD_STEPS:g} "
            "steps, so Drake's contact solver regularises them and the object "
            "may creep or be thrown out of the hand by the simulation; give "
            f"time_step <= {resolving:.2g} s "
            + (
                "(or None, which picks it)"
                if resolving >= MIN_TIME_STEP
                else f"(under MIN_TIME_STEP, {MIN_TIME_STEP:g} s, which None refuses)"
            ),
            CoarseStepWarning,
            stacklevel=outside_stacklevel(),
        )
    if modulus is None and candidate.contact_options.get("contact_model") == (
        "soft_finger"
    ):
        warnings.warn(
            "the candidate was planned with soft fingers (torsional_friction "
            f"{candidate.contact_options.get('torsional_friction')!r}), which "
            "resist a torque about each contact normal; Drake's point contact "
            "resists none, so this shake may drop a grasp the plan holds: give "
            "hydroelastic_modulus= (1e6 Pa, rubber) for fingers that press "
            "over patches",
            SoftFingerShakeWarning,
            stacklevel=outside_stacklevel(),
        )
    candidate.apply(plant, ctx, object_body=body)
    _check_planned_object(plant, ctx, body, candidate, planned_X_WO)
    _warn_friction(plant, ctx, body, hand, candidate)
    q_held = plant.GetPositions(ctx)

    def aim() -> None:
        # closing joints squeeze/k past where they stand now; others hold
        q_now = plant.GetPositions(ctx)
        desired = {}
        for actuator in actuators:
            joint = actuator.joint()
            i, start = int(joint.index()), joint.position_start()
            q_d = q_now[start] + targets[i] if i in targets else q_held[start]
            desired.setdefault(joint.model_instance(), []).append(
                (int(actuator.index()), q_d)
            )
        for instance, entries in desired.items():
            entries.sort()
            q_d = np.array([q for _, q in entries])
            plant.get_desired_state_input_port(instance).FixValue(
                ctx, np.concatenate([q_d, np.zeros_like(q_d)])
            )

    aim()
    plant.get_actuation_input_port().FixValue(ctx, np.zeros(plant.num_actuated_dofs()))
    H = base.body_frame()
    X_HO0 = plant.CalcRelativeTransform(ctx, H, body.body_frame())
    max_d = max_r = 0.0
    phases = []
    t, dt_check = 0.0, 0.01

    X_HO_seat = None  # where seating left the object, once it has
    max_ds = max_rs = float("nan")

    def advance(to: float) -> tuple[float, float]:
        nonlocal t, max_d, max_r, max_ds, max_rs
        d = r = 0.0
        while t < to - 1e-12:
            t = min(t + dt_check, to)
            try:
                simulator.AdvanceTo(t)
            except RuntimeError as e:  # Drake could not advance (see _stopped)
                if type(e) is not RuntimeError:  # RecursionError, NotImplemented...
                    raise
                t_now = simulator.get_context().get_time()
                stiffest = max((k for k, _ in gains.values()), default=math.nan)
                raise _stopped(e, t_now, stiffest, modulus) from e
            X_HO = plant.CalcRelativeTransform(ctx, H, body.body_frame())
            d = float(np.linalg.norm(X_HO.translation() - X_HO0.translation()))
            r = _angle(X_HO0.rotation().matrix().T @ X_HO.rotation().matrix())
            if not (math.isfinite(d) and math.isfinite(r)):  # max() would skip NaN
                raise SolverError(
                    f"the shake test's simulation went unstable at t = {t:.3g} s: "
                    "the object's pose is no longer finite; lower the gains or "
                    "the time_step"
                )
            max_d, max_r = max(max_d, d), max(max_r, r)
            if X_HO_seat is not None:
                ds = float(np.linalg.norm(X_HO.translation() - X_HO_seat.translation()))
                rs = _angle(X_HO_seat.rotation().matrix().T @ X_HO.rotation().matrix())
                max_ds, max_rs = max(max_ds, ds), max(max_rs, rs)
        return d, r

    seated = (float("nan"),) * 3
    seated_q, seated_X_WO = (), None
    if seat > 0:
        advance(seat / 2)
        aim()  # from where the fingers stopped on the object
        seated = (*advance(seat), _speed(plant, ctx, body))
        X_HO_seat = plant.CalcRelativeTransform(ctx, H, body.body_frame())
        max_ds = max_rs = 0.0
        q_now = plant.GetPositions(ctx)
        seated_q = _on_couplings(
            couplings, candidate.joint_names,
            [_within_limits(find_joint(plant, name), q_now)
             for name in candidate.joint_names],
        )  # fmt: skip
        seated_X_WO = plant.EvalBodyPoseInWorld(ctx, body).GetAsMatrix4()
        _check_seated(plant, ctx, body, candidate, modulus, squeeze)
    else:
        advance(settle)  # efforts are read once something has been simulated
    u = plant.get_net_actuation_output_port().Eval(ctx)
    squeezing = [a for a in actuators if int(a.joint().index()) in targets]
    efforts = tuple(abs(float(u[a.input_start()])) for a in squeezing)
    effort_units = tuple(effort_unit(a.joint()) for a in squeezing)
    # what each squeezing actuator was aimed to apply (its followers' too), and
    # the squeeze that is (a joint's share, or the newtons at its contacts)
    pushes = [pushed[int(a.index())][0] for a in squeezing]
    capped = tuple(float(pushed[int(a.index())][1]) for a in squeezing)
    used = tuple(gains[int(a.index())] for a in squeezing)
    aims = [c / k for c, (k, _) in zip(pushes, used, strict=True) if c > 0]
    at_rest = seat > 0 and seated[2] < _PUSHED_OUT  # else pushed out: physics
    kept = [e / c for e, c in zip(efforts, pushes, strict=True) if c > 0]
    if at_rest and kept and np.mean(kept) < _LOST:  # a share: units apart
        warnings.warn(
            f"at the seat the closing joints press with {np.mean(kept):.0%} of "
            f"the squeeze aimed for on average (their motors {np.mean(efforts):.3g} "
            f"{squeeze_unit_of(effort_units)} of {np.mean(pushes):.3g}, a motor's "
            + (
                "aim the torque that presses its fingers' contacts with the "
                f"squeeze, {squeeze:g} N"
                if at_contacts
                else "aim the squeeze times the joints it drives"
            )
            + "), the object at "
            f"rest: a position-controlled finger "
            f"presses with stiffness × what is left of its aim (what it is to "
            f"press with / stiffness, {min(aims):.3g} at the least), which the "
            f"fingers took up as they "
            f"closed on (pads that give, a finger that touched nothing); lower "
            f"the stiffness (or raise the squeeze) for the squeeze to hold",
            SqueezeLostWarning,
            stacklevel=outside_stacklevel(),
        )
    stopped = (
        _at_stops(plant, ctx, squeezing, targets, efforts, effort_units)
        if seat > 0
        else []
    )
    for end in ends:
        d, r = advance(end)
        phases.append(
            {
                "direction": schedule(end - 1e-9).tolist(),
                "displacement": d,
                "rotation": r,
            }
        )
    held = bool(max_d <= max_displacement and max_r <= max_rotation)
    if not held:
        _warn_at_stops(stopped)
    return ShakeResult(
        held=held,
        max_displacement=max_d,
        max_rotation=max_r,
        phases=tuple(phases),
        squeeze=float(squeeze),
        efforts=efforts,
        time_step=step,
        duration=duration,
        wall_time=time.perf_counter() - t0,
        bounds=(float(max_displacement), float(max_rotation)),
        effort_units=effort_units,
        seat_displacement=seated[0],
        seat_rotation=seated[1],
        seat_speed=seated[2],
        max_displacement_from_seat=max_ds,
        max_rotation_from_seat=max_rs,
        hydroelastic_modulus=modulus,
        hydroelastic_refused=refused,
        squeeze_caps=capped,
        squeeze_at_contacts=at_contacts,
        seated_q_hand=seated_q,
        seated_X_WO=seated_X_WO,
        joint_names=tuple(candidate.joint_names),
        X_WH=candidate.X_WH.GetAsMatrix4(),
        gains=used,
        object_mass=mass,
        gravity=g,
        contact_period=period,
    )
