"""The one tree of errors that drakegrasp raises.

Every error is a :class:`GraspError`, so ``except drakegrasp.GraspError`` catches
all of them.  Messages name the offending value and what would be valid.
"""

from __future__ import annotations

import sys
from typing import Any

MAX_MESSAGE = 10_000
"""Characters of a message beyond which :class:`GraspError` cuts it.

Messages name the offending value; a value whose ``repr`` is megabytes long
(a user's own type) must not make a megabyte message, in a log or on a
terminal.  Messages cut a value themselves, to about 120 characters
(:func:`~drakegrasp.core.validation.describe`); this bound is the last guard.
"""


def outside_stacklevel() -> int:
    """``warnings.warn``'s ``stacklevel`` for the user's line, from the caller.

    Called by the function that calls ``warnings.warn``: the level of the
    first frame outside drakegrasp and ``dataclasses``, however deep in the
    library the warning was raised (a ``plan_grasps`` call and a direct
    call of the class that warns point at the user's own line alike).  It
    lives beside :class:`GraspWarning` so that every module may use it,
    those that import nothing else of drakegrasp's too.
    """
    stacklevel = 1
    frame = sys._getframe(1)
    while frame is not None and _inside(frame.f_globals.get("__name__", "")):
        frame = frame.f_back
        stacklevel += 1
    return stacklevel


def _inside(module: str) -> bool:
    """Whether a frame of ``module`` is drakegrasp's or dataclasses' own."""
    return module == "dataclasses" or module.split(".")[0] == "drakegrasp"


def cut_message(text: str, limit: int = MAX_MESSAGE) -> str:
    """``text`` as a plain str of at most ``limit`` characters, saying what it cut.

    A cut text fits ``limit`` with its note, so cutting it again changes nothing.
    A ``str`` subclass is read by ``str.__str__`` (its own ``__str__`` may
    raise or lie); any other value by ``str()``, or as its type's name when
    that raises or returns no str: an error's text never fails to be made.
    """
    text = _plain_text(text)
    if len(text) <= limit:
        return text
    kept = max(limit - 50, 0)  # room for the note
    return f"{text[:kept]}... ({len(text) - kept} characters cut)"


def _plain_text(value) -> str:
    """``value`` as a plain str (see :func:`cut_message`)."""
    if issubclass(type(value), str):
        return str.__str__(value)
    try:
        shown = str(value)
    except Exception:  # noqa: BLE001 - a value's own __str__
        shown = None
    if issubclass(type(shown), str):
        return str.__str__(shown)
    return f"<{type_name(value)}>"


def type_name(value) -> str:
    """The name of ``value``'s type, or ``"object"`` if even that misbehaves."""
    name = getattr(type(value), "__name__", None)
    return str.__str__(name) if issubclass(type(name), str) else "object"


def _cut_args(args: tuple) -> tuple:
    """An exception's or warning's arguments, each ``str`` one cut and plain."""
    return tuple(cut_message(a) if issubclass(type(a), str) else a for a in args)


class GraspError(Exception):
    """Base class of every error raised by drakegrasp.

    A message longer than :data:`MAX_MESSAGE` characters is cut to at most that
    length, saying how much was cut; so is every other ``str`` argument (the
    text of an error of several arguments shows them all), each a plain str.
    """

    def __init__(self, *args: Any):
        super().__init__(*_cut_args(args))


class GraspWarning(UserWarning):
    """Base class of every warning drakegrasp issues (but deprecations).

    ``warnings.simplefilter("ignore", drakegrasp.GraspWarning)`` silences them
    all, and ``"error"`` makes each an exception.  Its text is cut as a
    :class:`GraspError`'s is: a warning may name a user's bodies or values,
    of any length.  Deprecations are :class:`DeprecationWarning`, as Python's
    tools expect.
    """

    def __init__(self, *args: Any):
        super().__init__(*_cut_args(args))


class KernelsVariableWarning(GraspWarning):
    """``DRAKEGRASP_KERNELS`` holds neither ``auto`` nor ``jit`` (a misspelling).

    The batch kernels then run through numba's JIT, which may compile for tens
    of seconds where the ahead-of-time kernels would have loaded at once
    (:mod:`drakegrasp.batch.aot`).  Said once per process, at the caller's
    line, when a batch call first chooses numba's route (before any worker
    process runs) or a kernel first looks for its ahead-of-time entry.
    """


class InvalidContactError(GraspError, ValueError):
    """A contact, or a set of contacts, is not well formed.

    Raised for a zero or non-finite normal, a negative friction coefficient, an
    unknown contact model, mixed planar and spatial contacts, a soft finger in
    the plane, and the like.
    """


class InvalidGraspError(GraspError, ValueError):
    """A grasp-level input is not well formed (reference point, length, Jacobian)."""


class InvalidOptionError(GraspError, ValueError):
    """Options passed to a function conflict or are out of range."""


class InvalidArgumentError(GraspError, TypeError):
    """A call does not fit the function's signature.

    Raised, where Python would raise a bare :class:`TypeError`, for an unknown
    or misspelled keyword (the message names the closest one the function
    takes), more positional arguments than the function takes (the message
    names the keyword-only ones), and a missing or twice-given argument.
    """


class BatchFileError(InvalidOptionError):
    """A batch input or output file cannot be read or written as asked.

    Raised for a missing, damaged, truncated or non-``.npz`` input, an output
    that is the input, or an existing output without ``overwrite``.
    """


class NoContactsError(GraspError):
    """The hand does not touch the object (or a grasp has no contacts)."""


class InvalidPoseError(GraspError):
    """The plant's configuration is physically impossible for a grasp.

    The common base of :class:`PenetrationError` and :class:`JointLimitError`;
    ``analyze_grasp(..., check_pose=False)`` analyses such a pose anyway and
    marks the report invalid.

    Parameters
    ----------
    problem : str
        What is wrong with the pose.
    remedy : str, optional
        How to analyse it anyway, in the caller's words (a Python argument,
        a command-line flag); the message is ``"problem (remedy)"``.  ``""``
        or None: no remedy.

    Attributes
    ----------
    problem, remedy : str
        Plain strings cut to :data:`MAX_MESSAGE` characters, as the message is
        (they may name a user's bodies and joints, of any length).
    """

    def __init__(self, problem: str, *, remedy: str | None = ""):
        problem = cut_message(problem)
        remedy = "" if remedy is None else cut_message(remedy)
        super().__init__(f"{problem} ({remedy})" if remedy else problem)
        self.problem = problem
        self.remedy = remedy

    def with_remedy(self, remedy: str) -> InvalidPoseError:
        """The same error, of the same type, with another remedy."""
        return type(self)(self.problem, remedy=remedy)


class PenetrationError(InvalidPoseError):
    """A hand body penetrates the object deeper than the distance tolerance."""


class JointLimitError(InvalidPoseError):
    """A joint of the hand is outside its position limits."""


class CouplingError(InvalidPoseError):
    """The hand's joints break a coupling (a ``<mimic>``, or ``couplings=``)."""


class ModelError(GraspError):
    """A model, scene file or body could not be found or loaded."""


class SceneError(ModelError, ValueError):
    """A scene file is malformed, or references a file it may not.

    Raised for YAML that is not valid, too large or uses anchors and aliases,
    a ``drakegrasp:`` key or value of the wrong type, an unknown package, and a
    model file outside the scene's directory and its packages (see
    :mod:`drakegrasp.plant.scene`).
    """


class SolverError(GraspError):
    """A solver failed for a reason other than infeasibility.

    Attributes
    ----------
    program : pydrake.solvers.MathematicalProgram or None
        The program that was being solved.
    result : pydrake.solvers.MathematicalProgramResult or None
        What the solver returned.
    """

    def __init__(self, message: str, *, program: Any = None, result: Any = None):
        super().__init__(message)
        self.program = program
        self.result = result


class InvalidContextError(GraspError, ValueError):
    """A context that belongs neither to the plant nor to the diagram holding it."""


class UnreachableError(GraspError):
    """Closing the hand left too few fingers touching the object.

    Attributes
    ----------
    closure : HandClosure or None
        Where every finger stopped (the context is left unchanged).
    """

    def __init__(self, message: str, *, closure: Any = None):
        super().__init__(message)
        self.closure = closure
