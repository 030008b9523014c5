"""The public call boundary: a call that does not fit a signature is named.

Python refuses a misspelled keyword, a missing argument or one positional
argument too many with a bare :class:`TypeError`, and names only the first
wrong keyword.  Every public function, constructor and method of drakegrasp is
wrapped by :func:`checked_call`, so such a call raises
:class:`~drakegrasp.errors.InvalidArgumentError` instead: a
:class:`~drakegrasp.GraspError` (caught with every other drakegrasp error) and
a :class:`TypeError` (caught as before).  Its message names the function,
every keyword it does not take with the closest one it does, and which
parameters are keyword-only.

The options objects (:class:`~drakegrasp.AnalysisOptions`,
:class:`~drakegrasp.BatchOptions`) are wrapped by :func:`checked_fields`
instead: an unknown field is an unknown option, an
:class:`~drakegrasp.InvalidOptionError`, as it always was.

A call that fits pays one more Python frame (about 0.2 µs,
``benchmarks/bench_call_check.py``): the signature is read only after Python
has refused the call, and a :class:`TypeError` raised by the function's own
work (the arguments fit) passes through unchanged.
"""

from __future__ import annotations

import difflib
import functools
import inspect
from collections.abc import Callable
from typing import Any, TypeVar

from drakegrasp.errors import GraspError, InvalidArgumentError, InvalidOptionError

__all__ = ["call_problem", "checked_call", "checked_fields", "unknown_names"]

T = TypeVar("T")

_POSITIONAL = (
    inspect.Parameter.POSITIONAL_ONLY,
    inspect.Parameter.POSITIONAL_OR_KEYWORD,
)


def checked_call(target: T) -> T:
    """Refuse calls that do not fit ``target``'s signature with a named error.

    Parameters
    ----------
    target : function or class
        A public function, or a class: its own ``__init__`` (a named tuple:
        ``__new__``) and every public method it defines (instance, class and
        static methods; not properties) are wrapped.  For a dataclass, apply
        this above ``@dataclass``; for a function, above its other decorators
        (the signature checked is the one they show: ``options=`` of
        ``takes_batch_options``), whose old spellings
        (:func:`~drakegrasp.core.deprecation.renamed_keyword`,
        :func:`~drakegrasp.core.deprecation.keyword_only`) are read as the new
        ones.

    Returns
    -------
    function or class
        ``target``, whose calls raise
        :class:`~drakegrasp.errors.InvalidArgumentError` (see
        :func:`call_problem` for the wording) where Python would raise a
        :class:`TypeError` for the arguments.
    """
    if not inspect.isclass(target):
        return _checked(target, f"{target.__qualname__}()")
    if "__init__" in target.__dict__:
        target.__init__ = _checked(
            target.__init__, f"{target.__qualname__}()", method=True
        )
    elif "__new__" in target.__dict__:  # a named tuple
        new = _checked(target.__new__, f"{target.__qualname__}()", method=True)
        target.__new__ = staticmethod(new)
    else:
        raise TypeError(f"{target.__qualname__} defines no constructor to check")
    return _checked_methods(target)


def checked_fields(what: str) -> Callable[[T], T]:
    """Like :func:`checked_call`, for an options dataclass: unknown is an option.

    Parameters
    ----------
    what : str
        What one field is, for the message ("analysis option").

    Returns
    -------
    decorator
        Wraps the dataclass's ``__init__`` (apply it above ``@dataclass``) so
        that an unknown keyword, too many positional arguments or a field
        given twice raise :class:`~drakegrasp.InvalidOptionError` naming them
        ("unknown analysis option tol_= (did you mean tol=?)"); its public
        methods as :func:`checked_call` does.
    """

    def decorate(cls: T) -> T:
        cls.__init__ = _checked(  # type: ignore[misc]
            cls.__init__,  # type: ignore[misc]
            f"{cls.__qualname__}()",  # type: ignore[attr-defined]
            method=True,
            error=InvalidOptionError,
            noun=what,
        )
        return _checked_methods(cls)

    return decorate


def _checked_methods(cls: T) -> T:
    """``cls`` with every public method it defines wrapped (see checked_call)."""
    for name, member in list(vars(cls).items()):
        if name.startswith("_"):
            continue
        where = f"{cls.__qualname__}.{name}()"  # type: ignore[attr-defined]
        if isinstance(member, staticmethod):
            wrapped = staticmethod(_checked(member.__func__, where))
        elif isinstance(member, classmethod):
            wrapped = classmethod(_checked(member.__func__, where, method=True))
        elif inspect.isfunction(member):
            wrapped = _checked(member, where, method=True)
        else:  # a property, a constant, a nested class
            continue
        setattr(cls, name, wrapped)
    return cls


def _checked(
    function: Callable,
    where: str,
    *,
    method: bool = False,
    error: type[GraspError] = InvalidArgumentError,
    noun: str = "keyword",
) -> Callable:
    """``function`` whose ill-fitting calls raise ``error`` (see call_problem)."""

    @functools.wraps(function)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return function(*args, **kwargs)
        except GraspError:  # ours already (a TypeError too, some): it stands
            raise
        except TypeError:
            if method and not args:  # a method read off its class, no instance
                raise error(
                    f"{where}: called without an object to call it on"
                ) from None
            given = args[1:] if method else args
            problem = call_problem(function, given, kwargs, method=method, noun=noun)
            if problem is None:  # the arguments fit: the body's own TypeError
                raise
            raise error(f"{where}: {problem}") from None

    return wrapper


def _new_spellings(
    function: Callable, args: tuple, kwargs: dict[str, Any]
) -> tuple[tuple, dict[str, Any]]:
    """The call in today's spellings, as ``function``'s deprecation wrappers see it.

    :func:`~drakegrasp.core.deprecation.renamed_keyword` and
    :func:`~drakegrasp.core.deprecation.keyword_only` record on their wrapper
    the old keywords (``_old_keywords``: old to new) and the positional
    places that are now keywords (``_old_positionals``: their first place and
    names); a call in those spellings is judged as the wrapper passes it on.
    """
    renamed = getattr(function, "_old_keywords", {})
    if renamed:
        kwargs = {renamed.get(name, name): value for name, value in kwargs.items()}
    after, names = getattr(function, "_old_positionals", (None, ()))
    if after is not None and after < len(args) <= after + len(names):
        kwargs = {**kwargs, **dict(zip(names, args[after:], strict=False))}
        args = args[:after]
    return args, kwargs


@functools.cache
def _signature(function: Callable, method: bool) -> inspect.Signature:
    """``function``'s signature, without ``self`` (or ``cls``) for a method."""
    signature = inspect.signature(function)
    if method:
        parameters = list(signature.parameters.values())[1:]
        signature = signature.replace(parameters=parameters)
    return signature


def call_problem(
    function: Callable,
    args: tuple,
    kwargs: dict[str, Any],
    *,
    method: bool = False,
    noun: str = "keyword",
) -> str | None:
    """What is wrong with calling ``function(*args, **kwargs)``, or None.

    Parameters
    ----------
    function : callable
        The function (for a method, unbound: ``args`` then leaves out
        ``self`` and ``method`` is True).
    args : tuple
        The positional arguments.
    kwargs : dict
        The keyword arguments.
    method : bool, optional
        ``function``'s first parameter is ``self``, not among ``args``.
    noun : str, optional
        What a keyword is, for the message ("keyword", "analysis option").

    Returns
    -------
    str or None
        None if the arguments fit the signature.  Otherwise one sentence:
        a positional-only parameter given by name; every unknown keyword
        with the closest accepted one (or the accepted ones, if none is
        close); the number of positional parameters, by name, and the
        keyword-only ones; an argument given both by position and by name;
        or every required argument that is missing.
    """
    args, kwargs = _new_spellings(function, args, kwargs)
    signature = _signature(function, method)
    parameters = list(signature.parameters.values())
    kinds = {p.kind for p in parameters}
    keywords = [
        p.name
        for p in parameters
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
    ]
    if inspect.Parameter.VAR_KEYWORD not in kinds:
        by_position = {p.name for p in parameters if p.kind is p.POSITIONAL_ONLY}
        wrong = [
            f"{name} is positional only: give it by position"
            for name in kwargs
            if name in by_position
        ]
        unknown = [n for n in kwargs if n not in keywords and n not in by_position]
        if unknown:
            wrong.append(unknown_names(unknown, keywords, noun=noun))
        if wrong:
            return "; ".join(wrong)
    positional = [p.name for p in parameters if p.kind in _POSITIONAL]
    if inspect.Parameter.VAR_POSITIONAL not in kinds and len(args) > len(positional):
        by_keyword = [p.name for p in parameters if p.kind is p.KEYWORD_ONLY]
        named = f" ({', '.join(positional)})" if positional else ""
        message = (
            f"takes {len(positional)} positional argument"
            f"{'' if len(positional) == 1 else 's'}{named} but {len(args)} "
            f"{'was' if len(args) == 1 else 'were'} given"
        )
        if by_keyword:
            message += "; by keyword only: " + ", ".join(f"{n}=" for n in by_keyword)
        return message
    twice = [
        p.name
        for p in parameters[: len(args)]
        if p.kind is p.POSITIONAL_OR_KEYWORD and p.name in kwargs
    ]
    if twice:
        return f"got {', '.join(twice)} both by position and by name"
    missing = [
        p.name
        for place, p in enumerate(parameters)
        if p.default is p.empty
        and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
        and not (p.kind in _POSITIONAL and place < len(args))
        and not (p.kind is not p.POSITIONAL_ONLY and p.name in kwargs)
    ]
    if missing:
        return f"missing {', '.join(missing)} (required)"
    return None


def unknown_names(
    names: list[str], accepted: list[str], *, noun: str = "keyword"
) -> str:
    """A sentence naming each of ``names`` with the closest of ``accepted``.

    Parameters
    ----------
    names : list of str
        The names given that are not accepted.
    accepted : list of str
        The names that are, in the order to list them.
    noun : str, optional
        What a name is ("keyword", "option").

    Returns
    -------
    str
        ``"unknown keyword tol_= (did you mean tol=?)"`` for each name, joined
        by ``"; "``; where none is close (a difflib ratio of at least 0.6,
        letter case aside), the accepted names instead of the guess.
    """
    by_case = {name.lower(): name for name in accepted}
    said = []
    for name in names:
        close = difflib.get_close_matches(name.lower(), list(by_case), n=1, cutoff=0.6)
        if close:
            hint = f"did you mean {by_case[close[0]]}=?"
        elif accepted:
            hint = "it takes " + ", ".join(f"{option}=" for option in accepted)
        else:
            hint = f"it takes no {noun}s"
        said.append(f"unknown {noun} {name}= ({hint})")
    return "; ".join(said)
