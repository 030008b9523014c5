r"""Does the hand hold its object?  The holding state of a grasp, with hysteresis.

The closure verdicts of :class:`~drakegrasp.GraspMonitor` are geometric: they
say what the contact positions, normals and μ *could* resist.  Whether the
simulated hand *does* hold its object is read from the plant's physics
(:mod:`drakegrasp.systems.sensing`: contact forces, slip speeds, the object's
motion against the fingers and its distance from the hand) and judged here,
one sample at a time, by :func:`next_holding_state`.

**The states** (:data:`HOLDING_STATES`) are ordered by how alarming they are,
and their codes on the vector port follow that order:

==============  ==============================================================
``no contact``  no hand body touches the object (before a grasp, after a
                release)
``touching``    contact, but not a grip that holds: not force closure, or,
                when the analysis has a load section (``load=``), one that
                does not hold that load
``holding``     a grip that holds whose contacts stick, friction in use at
                or below ``risk``
``at risk``     such a grasp with friction in use above ``risk`` at a contact
``slipping``    a contact slips faster than ``slip_speed``, or, without
                contact, the object moves along the fingers that last held it
                faster than that (and more along them than away from them)
``dropped``     the object has left the fingers that last held it, *along*
                them: contact has been lost for ``hold_samples + 1`` samples,
                and either the object still slides along them (faster than
                ``slip_speed``, more along than away from them) and is
                farther than ``release_distance`` from every hand body, or it
                is displaced along them by more than ``release_distance``
                since the last contact and has come to rest against them (or
                is out of reach); displaced but still moving against fingers
                within reach (fingers that chatter apart faster than it
                slides) it is ``slipping``
==============  ==============================================================

A hand that opens moves its fingers away along their normals while the object
stays: that is a release, ``no contact``, never ``dropped``, however the grip
was doing before (a box set down on the ground loads the fingers' friction
fully just before they open).

**The hysteresis**, in full (``n = hold_samples``):

1. A move to a *more* alarming state is immediate: the early warning is the
   point of ``at risk`` and ``slipping``.  The one exception is ``dropped``,
   gated as above, so with ``n >= 1`` (the default) a single sample without
   contact never reads as a drop.
2. A move from ``touching``, ``holding``, ``at risk``, ``slipping`` or
   ``dropped`` to a *less* alarming state needs ``n + 1`` consecutive samples
   whose evidence is less alarming than the state shown; the state then
   becomes the latest sample's evidence.  So neither a grip nor a touch
   flickers to ``no contact`` at one missing frame (a contact solver may
   report a resting point contact on one step and not the next), nor a grip
   back to ``holding`` at one sticking frame of a slide, nor out of
   ``dropped`` at one touch.
3. While a grip's contact is missing for at most ``n`` samples, the monitor
   also keeps showing the last analysis with contact (``contact_gap`` counts
   these bridged samples).

A sample's *evidence* is what it alone shows: with contact, ``slipping`` (slip
above the threshold), else ``touching`` (no grip that holds), else ``at risk``
or ``holding`` by friction in use; without contact after a grip, within the
window ``slipping`` if the object moves along the fingers, else ``no
contact``; after it, ``dropped`` as in the table, else ``slipping`` if it
slides along the fingers within reach (a finger chattering along it), else
``no contact`` (a release: the object at rest where the fingers left it).
Motions along the fingers are measured in the frames of the fingers that
touched the object last (:func:`~drakegrasp.systems.sensing.motion_against`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import describe, real_scalar
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "HOLDING_STATES",
    "HoldingMemory",
    "HoldingThresholds",
    "holding_code",
    "next_holding_state",
]

HOLDING_STATES = (
    "no contact",
    "touching",
    "holding",
    "at risk",
    "slipping",
    "dropped",
)
"""The holding states, least to most alarming, in the order of their codes on
the vector port (0 … 5); see :mod:`drakegrasp.systems.holding` for their rules."""

_RANK = {name: k for k, name in enumerate(HOLDING_STATES)}
_GRIPPED = ("holding", "at risk", "slipping")
# left towards a milder state only by hysteresis
_STICKY = ("touching", *_GRIPPED, "dropped")


@checked_call
@dataclass(frozen=True)
class HoldingThresholds:
    """When a grip is at risk, slips, or has left the hand; and the hysteresis.

    Attributes
    ----------
    risk : float
        Friction in use ``‖f_t‖/(μ f_n)`` above which a contact is at risk
        (dimensionless, in (0, 1]; default 0.8).
    slip_speed : float
        Slip speed above which a contact slips, m/s (default 5 mm/s; a
        regularised friction model such as SAP's creeps at ~1e-4 m/s when it
        sticks).  Also the speed of the object along the fingers, without
        contact, above which it is slipping away.
    separation_speed : float
        In ``contacts="geometry"``, a pair within the distance tolerance whose
        points move apart faster than this (m/s, default 5 mm/s) is not a
        contact.
    hold_samples : int
        The hysteresis, in samples (default 1): a grip's state is kept through
        up to ``hold_samples`` samples without contact, and any move to a less
        alarming state needs ``hold_samples + 1`` consecutive samples of
        evidence for it.  0 turns the hysteresis off.
    release_distance : float
        Metres (default 2 mm): an object sliding along the fingers farther
        than this from every hand body has left the hand, and one that has
        come to rest farther than this along the fingers from where they last
        touched it was dropped, not released.  It must exceed every gap at
        which a contact still counts (the monitor refuses it at or below its
        ``distance_tolerance``) and the chatter of a sliding finger (~0.3 mm
        on the WSG-50's pads).
    max_penetration : float
        Metres (default 5 mm): a sample whose hand sinks deeper into the
        object than this is ``"invalid"`` even where penetration is allowed
        (a simulation's contacts penetrate to make their force: the WSG-50
        squeezing with 20 N sinks 0.145 mm; fingers 15 mm inside a box are
        no grip to judge).
    """

    risk: float = 0.8
    slip_speed: float = 5e-3
    separation_speed: float = 5e-3
    hold_samples: int = 1
    release_distance: float = 2e-3
    max_penetration: float = 5e-3

    def __post_init__(self):
        for name in (
            "risk",
            "slip_speed",
            "separation_speed",
            "release_distance",
            "max_penetration",
        ):
            value = real_scalar(name, getattr(self, name))  # numpy reals too
            object.__setattr__(self, name, value)  # a float, whatever was given
            if not (np.isfinite(value) and value > 0):
                raise InvalidOptionError(f"{name} must be finite and > 0, got {value}")
        if not 0 < self.risk <= 1:
            raise InvalidOptionError(f"risk must be in (0, 1], got {self.risk}")
        h = self.hold_samples
        if isinstance(h, bool) or not isinstance(h, int | np.integer) or h < 0:
            raise InvalidOptionError(
                f"hold_samples must be an int >= 0, got {describe(h)}"
            )

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return jsonable(self.__dict__)


@dataclass(frozen=True)
class HoldingMemory:
    """What the holding state machine carries from one sample to the next.

    Attributes
    ----------
    state : str
        The state shown (one of :data:`HOLDING_STATES`).
    lost : int
        Consecutive samples without contact (0 in a sample with contact).
    milder : int
        Consecutive samples whose evidence was less alarming than ``state``
        (the hysteresis' count towards leaving it).
    last_grip : str
        The state shown at the last sample with contact.
    """

    state: str = "no contact"
    lost: int = 0
    milder: int = 0
    last_grip: str = "no contact"

    def bridged(self, thresholds: HoldingThresholds) -> int:
        """Samples without contact over which a grip's analysis is kept (else 0)."""
        keep = self.state in _GRIPPED and 0 < self.lost <= thresholds.hold_samples
        return self.lost if keep else 0

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return jsonable(self.__dict__)


def _evidence_in_contact(
    *,
    grasped: bool,
    friction_use: float,
    slip_speed: float,
    thresholds: HoldingThresholds,
) -> str:
    """What a sample with contact alone shows (rules in the module docstring)."""
    if slip_speed > thresholds.slip_speed:
        return "slipping"
    if not grasped:
        return "touching"
    if friction_use > thresholds.risk:  # False for NaN: geometry sees no force
        return "at risk"
    return "holding"


def _evidence_without_contact(
    memory: HoldingMemory,
    *,
    sliding: float,
    slid: float,
    relative: float,
    clearance: Callable[[], float],
    thresholds: HoldingThresholds,
) -> str:
    """What a sample without contact shows, after ``memory`` (module docstring)."""
    if memory.state == "dropped":
        return "dropped"
    if memory.state not in _GRIPPED:
        return "no contact"
    moving = sliding > thresholds.slip_speed
    if memory.lost + 1 > thresholds.hold_samples:  # contact lost for good
        if moving:  # sliding out: dropped once clear of the hand
            out = clearance() > thresholds.release_distance
            return "dropped" if out else "slipping"
        if slid <= thresholds.release_distance:
            return "no contact"  # released where the fingers left it
        # Moved off its place along the fingers: dropped once at rest there,
        # or out of reach.  Still moving against fingers within reach (they
        # chatter apart faster than it slides, so it slides "away" from them)
        # it is a grip in trouble, not yet a drop.
        if relative > thresholds.slip_speed and not (
            clearance() > thresholds.release_distance
        ):
            return "slipping"
        return "dropped"
    return "slipping" if moving else "no contact"


def next_holding_state(
    memory: HoldingMemory,
    *,
    touching: bool,
    grasped: bool,
    friction_use: float,
    slip_speed: float,
    sliding: float,
    slid: float,
    clearance: Callable[[], float],
    thresholds: HoldingThresholds,
    relative: float = 0.0,
) -> HoldingMemory:
    """One step of the holding state machine (rules in the module docstring).

    Parameters
    ----------
    memory : HoldingMemory
        After the previous sample (``HoldingMemory()`` before the first).
    touching : bool
        Some hand body touches the object in this sample.
    grasped : bool
        The analysed contacts hold: force closure, or the load section's
        verdict where the analysis has one.
    friction_use : float
        Largest ``‖f_t‖/(μ f_n)`` over the fingers; NaN when unknown (then
        never at risk).
    slip_speed : float
        Largest slip speed at a contact, m/s.
    sliding : float
        Speed of the object's centre of mass along the touching fingers, or
        without contact the fingers that touched it last, counted only where
        it moves more along a finger than away from it (``Motion.along`` of
        :func:`~drakegrasp.systems.sensing.motion_against`), m/s.
    slid : float
        Without contact: how far the centre of mass has moved along those
        fingers since the last contact, m (0 with contact).
    clearance : callable () -> float
        The object's distance from the hand, m
        (:func:`~drakegrasp.systems.sensing.hand_clearance`); called only
        without contact, once a grip's hysteresis window has passed, while the
        object slides along the fingers, or moves against them having slid
        along them by more than ``release_distance``.
    thresholds : HoldingThresholds
    relative : float, optional
        Without contact: the speed of the centre of mass against those fingers
        in any direction (``Motion.relative``), m/s; default 0 (at rest).  An
        object displaced along the fingers is dropped once at rest there; one
        still moving against them faster than ``slip_speed`` within reach
        (fingers chattering apart) is slipping.

    Returns
    -------
    HoldingMemory
        The state of this sample and the counts carried to the next.
    """
    if memory.state not in _RANK:
        raise InvalidOptionError(
            f"unknown holding state {memory.state!r}; one of {HOLDING_STATES}"
        )
    if touching:
        evidence = _evidence_in_contact(
            grasped=grasped,
            friction_use=friction_use,
            slip_speed=slip_speed,
            thresholds=thresholds,
        )
    else:
        evidence = _evidence_without_contact(
            memory, sliding=sliding, slid=slid, relative=relative,
            clearance=clearance, thresholds=thresholds,
        )  # fmt: skip
    state, milder = evidence, 0
    if memory.state in _STICKY and _RANK[evidence] < _RANK[memory.state]:
        milder = memory.milder + 1
        if milder <= thresholds.hold_samples:
            state = memory.state
        else:
            milder = 0
    return HoldingMemory(
        state=state,
        lost=0 if touching else memory.lost + 1,
        milder=milder,
        last_grip=state if touching else memory.last_grip,
    )


def holding_code(state: str) -> float:
    """The vector-port code of a holding state (its index in HOLDING_STATES)."""
    return float(_RANK[state])
