r"""Ranking by physics: the planner's best candidates shaken, those that held first.

The planner ranks from the planned contacts (closure, ε, robustness, the
weight held per newton of squeeze, the torque the motors need, and which way
the closing motions push: :mod:`~drakegrasp.planning.opposition`).  What it
does not see is how the object moves once the fingers meet it: it seats a
few millimetres off the plan, touches links the plan did not list, and a
grasp whose torque figures say it holds may still slip (the Allegro hand's
soup-can grasps within its 0.7 N·m held about two times in three in the
planning guide's runs).  :func:`shake_candidates` runs
:func:`~drakegrasp.planning.shake.shake_test` on the first ``top`` candidates
and re-orders them: those that held, in the planner's order, then those that
dropped, then those Drake could not simulate, each with its
:class:`~drakegrasp.planning.shake_result.ShakeResult` or the error's one line.

"Held" is :attr:`~drakegrasp.planning.shake_result.ShakeResult.held_from_seat` by
default (``held_from="seat"``): the object stays within the bounds of where
the fingers seated it, which is what holding means for a hand whose fingers do
not stop where the plan put them; ``held_from="plan"`` counts from the planned
pose (``ShakeResult.held``).
"""

from __future__ import annotations

import inspect
import itertools
import math
import time
import warnings
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from drakegrasp.core.calls import checked_call, unknown_names
from drakegrasp.core.deprecation import outside_stacklevel
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import describe, plain_str, real_scalar
from drakegrasp.errors import (
    GraspWarning,
    InvalidGraspError,
    InvalidOptionError,
    ModelError,
    SolverError,
)
from drakegrasp.planning.candidates import (
    GraspCandidate,
    GraspCandidates,
    check_candidate,
    pose_dict,
)
from drakegrasp.planning.shake import check_shake_options, recorded_mass, shake_test
from drakegrasp.planning.shake_result import ShakeResult, _limits, motion_text
from drakegrasp.planning.squeeze import checked_contacts
from drakegrasp.plant.validation import check_rigid_transform

__all__ = [
    "HELD_FROM",
    "GravityMismatchWarning",
    "ShakenCandidate",
    "ShakenCandidates",
    "check_settings",
    "shake_candidates",
]

HELD_FROM = ("seat", "plan")
"""What "held" counts from: where seating left the object, or the planned pose."""


class GravityMismatchWarning(GraspWarning):
    """The shake's plant has another gravity than the one the plan was made in.

    :func:`~drakegrasp.planning.planner.plan_grasps` records the magnitude it
    weighed the object with (``settings["gravity"]``); the shake turns the
    weight of the plant ``add_models`` builds (``ShakeResult.gravity``).  A
    plan made in a plant whose gravity was set outside ``add_models`` (a moon
    scene built by hand) is then shaken with another weight.
    """


def _check_gravity(candidates, result: ShakeResult) -> None:
    """Warn when ``result`` shook at another |g| than ``candidates`` were planned at.

    The recorded gravity is any real scalar (a float, a numpy float64, an
    int from JSON: ``settings["gravity"]`` of a plan read back); none, or one
    that is not a finite real number, is not compared.
    """
    settings = getattr(candidates, "settings", None)
    recorded = settings.get("gravity") if isinstance(settings, dict) else None
    try:
        planned = real_scalar('settings["gravity"]', recorded)
    except InvalidOptionError:  # none recorded (a list of candidates), or no number
        return
    shaken = result.gravity
    if not math.isfinite(planned) or math.isclose(planned, shaken, rel_tol=1e-9):
        return
    warnings.warn(
        f"the candidates were planned in a plant of gravity {planned:g} m/s², "
        f"but the plant add_models builds has {shaken:g} m/s²: the shake weighs "
        "the object with the latter; set the planning plant's gravity in "
        "add_models to shake the plan's weight",
        GravityMismatchWarning,
        stacklevel=outside_stacklevel(),  # checked_call wraps shake_candidates
    )


_OPTIONS = {
    name: p.default
    for name, p in inspect.signature(shake_test).parameters.items()
    if p.kind is inspect.Parameter.KEYWORD_ONLY
}
"""``shake_test``'s keyword options and their defaults (one source: its signature)."""


@dataclass(frozen=True, eq=False)
class ShakenCandidate:
    """One candidate and what the shake test made of it.

    Attributes
    ----------
    candidate : GraspCandidate
    planned_rank : int
        Its place in the planner's order (0: the planner's best).
    result : ShakeResult or None
        The simulation's figures; None when Drake could not simulate it.
    held : bool
        Whether it held, counted as ``held_from`` says (False when not
        simulated).
    error : str
        Why Drake could not simulate it (its ``SolverError``, or a
        ``ModelError`` past the first candidate, one line); empty otherwise.
    """

    candidate: GraspCandidate
    planned_rank: int
    result: ShakeResult | None
    held: bool
    error: str = ""

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "planned_rank": self.planned_rank,
            "held": self.held,
            "error": self.error,
            "result": None if self.result is None else self.result.to_dict(),
            "candidate": self.candidate.to_dict(),
        }

    def __str__(self) -> str:
        """One line; a drop the plan expected names the candidate's ``concerns``."""
        if self.result is None:
            return f"plan #{self.planned_rank}: not simulated ({self.error})"
        r = self.result
        seated = (
            ""
            if np.isnan(r.seat_displacement)
            else (
                f", seated {motion_text(r.seat_displacement, r.seat_rotation, 1)} "
                "from the plan, then within "
                + motion_text(r.max_displacement_from_seat, r.max_rotation_from_seat, 1)
            )
        )
        said = self.candidate.concerns
        expected = (
            f"; as the plan said: {'; '.join(said)}" if said and not self.held else ""
        )
        return (
            f"plan #{self.planned_rank}: {'held' if self.held else 'dropped'} "
            f"(at most {motion_text(r.max_displacement, r.max_rotation, 1)} "
            f"from the plan{seated}){expected}"
        )


@checked_call
@dataclass(frozen=True, eq=False)
class ShakenCandidates(Sequence):
    """Shaken candidates: those that held first, each group in the planner's order.

    A sequence of :class:`ShakenCandidate`.

    Attributes
    ----------
    shaken : tuple of ShakenCandidate
        Held (planner's order), then dropped (planner's order), then not
        simulated (planner's order).
    held_from : str
        ``"seat"`` or ``"plan"``: what "held" counts from.
    options : dict
        The shake test's options, defaults filled in, for the record.
    wall_time : float
        Seconds.
    """

    shaken: tuple[ShakenCandidate, ...]
    held_from: str
    options: dict
    wall_time: float

    def __getitem__(self, index):
        return self.shaken[index]

    def __len__(self) -> int:
        return len(self.shaken)

    @property
    def held(self) -> tuple[GraspCandidate, ...]:
        """The candidates that held, in the planner's order."""
        return tuple(s.candidate for s in self.shaken if s.held)

    @property
    def best(self) -> GraspCandidate | None:
        """The planner's best candidate among those that held (None: none held)."""
        return self.shaken[0].candidate if self.shaken and self.shaken[0].held else None

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "held_from": self.held_from,
            "options": jsonable(self.options),
            "wall_time": self.wall_time,
            "shaken": [s.to_dict() for s in self.shaken],
        }

    def __str__(self) -> str:
        n_held = sum(s.held for s in self.shaken)
        modulus = self.options.get("hydroelastic_modulus")
        fingers = "" if modulus is None else f"hydroelastic fingers, {modulus:g} Pa; "
        results = [s.result for s in self.shaken if s.result is not None]
        capped = [r for r in results if r.squeeze_capped]
        unit = f" {results[0].squeeze_unit}" if results else ""
        squeeze = self.options.get("squeeze")
        if squeeze is None and results:  # the default: newtons at the contacts
            squeeze = results[0].squeeze
        where = " at the contacts" if results and results[0].squeeze_at_contacts else ""
        squeeze = "" if squeeze is None else f"squeeze {squeeze:g}{unit}{where}"
        if capped:
            caps = [c for r in capped for c in r.squeeze_caps]
            squeeze += f" capped at {_limits(caps, capped[0].squeeze)}{unit}{where}"
        gains = ", ".join(
            f"{name} {self.options[name]:g}"
            for name in ("stiffness", "damping")
            if self.options.get(name) is not None
        )
        if not gains and results and results[0].gains:  # the per-joint defaults
            stiff, damp = (list(v) for v in zip(*results[0].gains, strict=True))
            gains = f"stiffness {_span(stiff)}, damping {_span(damp)}"
        masses = {r.object_mass for r in results if np.isfinite(r.object_mass)}
        mass = f"object {max(masses):.4g} kg" if len(masses) == 1 else ""
        used = "".join(f"{x}; " for x in (mass, squeeze, gains) if x)
        lines = [
            f"{n_held} of {len(self)} shaken candidates held (counted from the "
            f"{self.held_from}; {used}{fingers}{self.wall_time:.1f} s)"
        ]
        lines += [f"  {s}" for s in self.shaken]
        return "\n".join(lines)


def _span(values) -> str:
    """``4000``, or ``7-20`` where the joints' values differ."""
    low, high = min(values), max(values)
    return f"{low:g}" if low == high else f"{low:g}-{high:g}"


def _checked_top(top) -> int:
    if (
        isinstance(top, bool)
        or not isinstance(top, int | np.integer)
        or not 0 < int(top) <= 10_000
    ):
        raise InvalidOptionError(
            "top must be a whole number of candidates from 1 to 10000, got "
            f"{describe(top)}"
        )
    return int(top)


def _first_candidates(
    candidates, top: int, at_contacts: bool = False
) -> list[GraspCandidate]:
    """The first ``top`` candidates (an endless iterator is read ``top`` deep).

    Each checked; with ``at_contacts`` (the default squeeze) its contacts too.
    """
    if isinstance(candidates, GraspCandidate):
        raise InvalidOptionError(
            "candidates must be several candidates (plan_grasps' result or a "
            "list); for one, call shake_test"
        )
    if not isinstance(candidates, Iterable) or isinstance(candidates, str | bytes):
        raise InvalidOptionError(
            "candidates must be plan_grasps' result or a sequence of "
            f"GraspCandidate, got {type(candidates).__name__}"
        )
    chosen = list(itertools.islice(candidates, top))
    for k, c in enumerate(chosen):
        if not isinstance(c, GraspCandidate):
            raise InvalidOptionError(
                f"candidates[{k}] must be a GraspCandidate from plan_grasps, got "
                f"{type(c).__name__}"
            )
        try:  # all of them before any is simulated: no run lost at the fifth
            check_candidate(c)
            recorded_mass(c)
            if at_contacts:
                checked_contacts(c)
        except InvalidGraspError as e:
            raise InvalidGraspError(f"candidates[{k}]: {e}") from e
    return chosen


def _recorded(settings: dict) -> dict:
    """The options as JSON can hold them.

    A pose as its dictionary, a ``BodyIndex`` as its repr (a ``RigidBody``
    never gets here: each shake builds a fresh plant, which refuses it).
    """
    out = dict(settings)
    if out["X_WO"] is not None:
        out["X_WO"] = pose_dict(out["X_WO"])
    body = out["object_body"]
    if body is not None and not isinstance(body, str | int | np.integer):
        out["object_body"] = repr(body)
    return out


def check_settings(top, held_from, options: dict) -> dict:
    """Check :func:`shake_candidates`' settings; return the options, defaults filled in.

    Parameters
    ----------
    top, held_from
        As :func:`shake_candidates` takes them.
    options : dict
        Keyword options of :func:`~drakegrasp.planning.shake.shake_test`.

    Returns
    -------
    dict
        Every keyword option of ``shake_test``: ``options`` over its defaults.

    Raises
    ------
    InvalidOptionError
        As :func:`shake_candidates` raises it for its settings.
    """
    _checked_top(top)
    held_from = plain_str(held_from)
    if type(held_from) is not str or held_from not in HELD_FROM:
        raise InvalidOptionError(
            f"held_from must be one of {', '.join(HELD_FROM)}, got "
            f"{describe(held_from)}"
        )
    unknown = sorted(set(options) - set(_OPTIONS))
    if unknown:
        # shake_candidates' own keywords, then shake_test's options
        accepted = ["top", "held_from", *sorted(_OPTIONS)]
        raise InvalidOptionError(
            "shake_candidates(): " + unknown_names(unknown, accepted, noun="option")
        )
    settings = {**_OPTIONS, **options}
    check_shake_options(
        **{k: v for k, v in settings.items() if k not in ("object_body", "X_WO")}
    )
    if settings["X_WO"] is not None:
        check_rigid_transform("X_WO", settings["X_WO"])
    return settings


@checked_call
def shake_candidates(
    add_models: Callable,
    candidates: GraspCandidates | Sequence[GraspCandidate],
    *,
    top: int = 10,
    held_from: str = "seat",
    **options,
) -> ShakenCandidates:
    """Shake the planner's best candidates in Drake; put those that held first.

    Parameters
    ----------
    add_models : callable
        ``add_models(plant, parser) -> (hand, object_body)``, as for
        :func:`~drakegrasp.planning.shake.shake_test` (a
        :class:`~drakegrasp.planning.scenes.PlanningScene`'s ``add_models``).
    candidates : GraspCandidates or sequence of GraspCandidate
        Best first: :func:`~drakegrasp.planning.planner.plan_grasps`' result.
    top : int, optional
        How many of the first candidates to shake (default 10; fewer when
        there are fewer), 1 to 10000.  Each is one simulation of
        ``seat + settle + len(directions) * phase`` seconds (2.8 s of
        simulated time at the defaults: at ``time_step=1e-3``, about 1 s of
        wall time for the Allegro hand with point contact and 2.6 s with
        hydroelastic fingers; 0.6 s and 1.6 s for drakegrasp's flat jaw).
    held_from : {"seat", "plan"}, optional
        What "held" counts from: where seating left the object (default; a
        multi-finger hand seats it a few millimetres from the plan and holds
        it there), or the planned pose.
    **options
        :func:`~drakegrasp.planning.shake.shake_test`'s keyword options
        (``squeeze``, ``stiffness``, ``damping``, ``directions``, the phases,
        the bounds, ``hydroelastic_modulus``, ``X_WO``, ``object_body`` by
        name or ``BodyIndex``: each shake builds a fresh plant), the same for
        every candidate; checked before anything is simulated.  Light
        revolute fingers need light gains (the Allegro hand:
        ``squeeze=0.7, stiffness=10, damping=0.1``); flat pads need
        ``hydroelastic_modulus`` (see :mod:`drakegrasp.plant.hydroelastic`).
        ``object_mass`` defaults to each candidate's own (the mass it was
        planned for: the shake tests the plan's weight).

    Returns
    -------
    ShakenCandidates
        The shaken candidates: held, then dropped, then those Drake could not
        simulate (its ``SolverError``, a ``ModelError`` past the first
        candidate, or the ``InvalidGraspError`` of one whose closing the
        default squeeze finds pressing none of its contacts, is recorded in
        one line, and the others are still shaken); each group in the
        planner's order.

    Raises
    ------
    InvalidOptionError
        ``top`` not a whole number from 1 to 10000, ``held_from`` not one of
        :data:`HELD_FROM`, an option ``shake_test`` does not take, or one it
        refuses (before any simulation), or ``candidates`` that are not
        candidates.
    InvalidGraspError
        A candidate whose joint values or poses are not finite or do not
        match its joints, or, at the default squeeze, whose contacts are not
        finite points and unit normals, named by its place (all are checked
        before any is simulated).
    ModelError
        As :func:`~drakegrasp.planning.shake.shake_test` raises it for the
        first candidate: a model that does not match the candidates (the
        others would share it), or, with ``time_step`` None, an object whose
        contacts ask for a step under
        :data:`~drakegrasp.planning.shake.MIN_TIME_STEP` (a later candidate's
        such refusal is recorded, and the rest still run).

    Warns
    -----
    GravityMismatchWarning
        ``candidates`` from :func:`~drakegrasp.planning.planner.plan_grasps`
        planned at another ``|g|`` (their ``settings["gravity"]``) than the
        plant ``add_models`` builds has: the shake turns that plant's weight.
    """
    if not callable(add_models):
        raise InvalidOptionError(
            "add_models must be a function add_models(plant, parser) -> (hand, "
            f"object_body), got {type(add_models).__name__}"
        )
    held_from = plain_str(held_from)  # compared below: its own == may lie
    settings = check_settings(top, held_from, options)
    chosen = _first_candidates(
        candidates, int(top), at_contacts=settings["squeeze"] is None
    )
    t0 = time.perf_counter()
    shaken = []
    for k, c in enumerate(chosen):
        try:
            result = shake_test(add_models, c, **options)
        except (SolverError, ModelError, InvalidGraspError) as e:
            if k == 0 and isinstance(e, ModelError):
                raise  # the models and the candidates do not match: every one
            # Drake could not simulate this one, or the default squeeze presses
            # none of its contacts: recorded, the rest still run
            shaken.append(ShakenCandidate(c, k, None, False, str(e)))
            continue
        if not any(s.result is not None for s in shaken):
            _check_gravity(candidates, result)  # one plant for all: once
        held = result.held_from_seat if held_from == "seat" else result.held
        shaken.append(ShakenCandidate(c, k, result, bool(held)))

    def group(s: ShakenCandidate) -> int:
        return 0 if s.held else (1 if s.result is not None else 2)

    shaken.sort(key=lambda s: (group(s), s.planned_rank))
    return ShakenCandidates(
        shaken=tuple(shaken),
        held_from=held_from,
        options=_recorded(settings),
        wall_time=time.perf_counter() - t0,
    )
