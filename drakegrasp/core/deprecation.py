"""Old spellings of public keywords, kept for a while with a warning.

A renamed keyword or an argument that became keyword-only keeps working: the
old call does what it did and warns once per call site with a
:class:`DeprecationWarning` that names the new spelling.  Giving both the old
and the new spelling is refused.  The renames are listed on the docs' Changes
page.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import sys
import warnings
from collections.abc import Callable
from typing import TypeVar

from drakegrasp.errors import (
    InvalidArgumentError,
    InvalidOptionError,
    outside_stacklevel,
)

__all__ = ["keyword_only", "outside_stacklevel", "renamed_keyword", "warn_deprecated"]

F = TypeVar("F", bound=Callable)


def warn_deprecated(message: str, *, stacklevel: int | None = None) -> None:
    """Warn with a :class:`DeprecationWarning` attributed to the user's line.

    ``stacklevel`` counts as ``warnings.warn`` does, from this function (3:
    the caller of the function that calls this one).  ``None``, the default,
    attributes the warning to the first frame outside drakegrasp and
    ``dataclasses``, however many wrappers are stacked (the check of a public
    call's arguments, a ``dataclasses.replace``, an internal call that passes
    the user's keyword on: none is where the old spelling was written).
    """
    if stacklevel is None:
        stacklevel = outside_stacklevel()
    warnings.warn(message, DeprecationWarning, stacklevel=stacklevel)


def renamed_keyword(old: str, new: str) -> Callable[[F], F]:
    """Accept the keyword ``old`` as a deprecated alias of ``new``.

    Parameters
    ----------
    old, new : str
        The old and the current keyword names; ``new`` must be a parameter of
        the decorated function.

    Returns
    -------
    decorator
        Wraps a function so that ``f(..., old=x)`` warns and calls
        ``f(..., new=x)``; ``f(..., old=x, new=y)`` (``new`` by position or by
        name) raises :class:`~drakegrasp.InvalidOptionError`.  A class gets its
        ``__init__`` wrapped.
    """

    def decorate(function: F) -> F:
        if inspect.isclass(function):
            cls = function
            where = f"{cls.__qualname__}()"
            cls.__init__ = _renamed(
                cls.__init__, old, new, where, dataclass=dataclasses.is_dataclass(cls)
            )
            return cls
        return _renamed(function, old, new, f"{function.__qualname__}()")

    return decorate


def _renamed(
    function: F, old: str, new: str, where: str, *, dataclass: bool = False
) -> F:
    """``function`` taking ``old=`` for ``new=`` (see :func:`renamed_keyword`).

    ``dataclass``: ``function`` is a dataclass's ``__init__``, which
    ``dataclasses.replace(x, old=v)`` calls with every init field by name,
    ``new`` included (x's own value).  Such
    a call is recognised by its caller, ``dataclasses``' own frame, and the
    value of ``new`` by being x's very object: ``old`` then replaces it.  A
    ``new`` the user gave is another object, refused with ``old`` as in any
    other call (x's own object given again cannot be told apart: ``old``
    wins, with its warning).
    """
    parameters = list(inspect.signature(function).parameters.values())
    names = [p.name for p in parameters]
    if new not in names:
        raise TypeError(f"{function.__qualname__} has no parameter {new!r}")
    # Where ``new`` sits among the positional parameters (None if it cannot
    # be given by position): a call may give it there and ``old=`` as well.
    place = names.index(new)
    positional = (
        inspect.Parameter.POSITIONAL_ONLY,
        inspect.Parameter.POSITIONAL_OR_KEYWORD,
    )
    if parameters[place].kind not in positional:
        place = None

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        if old in kwargs:
            if dataclass and new in kwargs:
                replaced = _replaced_object(sys._getframe(1))
                if replaced is not None and kwargs[new] is getattr(
                    replaced, new, kwargs
                ):
                    kwargs.pop(new)  # x's own value, filled in by replace
            if new in kwargs or (place is not None and len(args) > place):
                by_position = "" if place is None else f" (or {new} by position)"
                raise InvalidOptionError(
                    f"{where} got both {old}= (deprecated) and {new}="
                    f"{by_position}; give {new}= only"
                )
            warn_deprecated(
                f"{where}: {old}= is deprecated; use {new}=", stacklevel=None
            )
            kwargs[new] = kwargs.pop(old)
        return function(*args, **kwargs)

    # Read by drakegrasp.core.calls, which names what is wrong with a call:
    # ``old=`` is a keyword of this function (it does not import this module,
    # which would put the core one level deeper).
    wrapper._old_keywords = {**getattr(function, "_old_keywords", {}), old: new}
    return wrapper  # type: ignore[return-value]


def _replaced_object(frame):
    """The object a ``dataclasses.replace`` running in ``frame`` copies, or None.

    ``frame`` is the caller of a dataclass's constructor: ``dataclasses.replace``
    (its local ``obj``) when the constructor is called to replace fields;
    None for any other caller.
    """
    if frame is None or frame.f_globals.get("__name__") != "dataclasses":
        return None
    return frame.f_locals.get("obj", frame.f_locals.get("self"))


class _PositionalError(InvalidArgumentError, InvalidOptionError):
    """A call that gives keyword-only options by position, one too many or twice.

    Python raises ``TypeError`` for such a call, as drakegrasp does for every
    other call that does not fit a signature; these refusals were an
    :class:`~drakegrasp.InvalidOptionError` (a ``ValueError``) when ``mu``
    became keyword-only, and stay one, as numpy's ``AxisError`` is both a
    ``ValueError`` and an ``IndexError``.
    """


def keyword_only(*names: str, after: int) -> Callable[[F], F]:
    """Accept ``names`` positionally (deprecated) where they are now keyword-only.

    Parameters
    ----------
    *names : str
        The keyword-only parameters that used to be positional, in their old
        order.
    after : int
        How many positional parameters come before them.

    Returns
    -------
    decorator
        Wraps a function so that positional arguments from place ``after`` on
        warn and are passed as ``names[0]=``, ``names[1]=``, ...; more
        positional arguments than that, or a value given both ways, raise
        :class:`~drakegrasp.InvalidArgumentError` (a ``TypeError``, as Python
        raises for such a call, and as :func:`~drakegrasp.core.calls.checked_call`
        raises for the other calls that do not fit a signature) that is still
        the :class:`~drakegrasp.InvalidOptionError` (a ``ValueError``) it was.
    """
    if not names:
        raise TypeError("keyword_only needs at least one parameter name")

    def decorate(function: F) -> F:
        parameters = inspect.signature(function).parameters
        for name in names:
            parameter = parameters.get(name)
            if (
                parameter is None
                or parameter.kind is not inspect.Parameter.KEYWORD_ONLY
            ):
                raise TypeError(
                    f"{function.__qualname__}: {name!r} is not keyword-only"
                )
        where = f"{function.__qualname__}()"
        spelled = ", ".join(f"{name}=" for name in names)

        @functools.wraps(function)
        def wrapper(*args, **kwargs):
            if len(args) > after:
                extra = args[after:]
                if len(extra) > len(names):
                    raise _PositionalError(
                        f"{where} takes {after} positional arguments and "
                        f"{spelled} by keyword; got {len(args)} positional"
                    )
                moved = names[: len(extra)]
                for name in moved:
                    if name in kwargs:
                        raise _PositionalError(
                            f"{where} got {name} both by position and as {name}="
                        )
                warn_deprecated(
                    f"{where}: passing {', '.join(moved)} by position is "
                    f"deprecated; write {', '.join(f'{n}=...' for n in moved)}",
                    stacklevel=None,
                )
                kwargs.update(zip(moved, extra, strict=True))
                args = args[:after]
            return function(*args, **kwargs)

        # Read by drakegrasp.core.calls (see _renamed): positional arguments
        # from place ``after`` on are these keywords.
        wrapper._old_positionals = (after, names)
        return wrapper  # type: ignore[return-value]

    return decorate
