"""Values that a result computes on first access, identical to computing them at once.

A verdict that the rank already decides does not need its program's ``d*``, and
nobody needs a certificate or a second-order analysis until they read it; both
cost more than the verdict.  :func:`defer` wraps such a computation in a
:class:`Deferred`, and a result type declares the fields that may hold one with
:class:`deferrable` (a data descriptor, which ``dataclasses`` accepts as a
field's default).  Reading the field runs the computation once and keeps its
value, so the attribute, ``to_dict()``, ``str()``, ``==`` and ``repr`` see
exactly what an eager computation would have stored.  Pickling and copying
resolve a pending value first: the copy holds plain values only.

Only work whose inputs were captured at the call (arrays, grasps, numbers,
never a plant context that the caller may change) is deferred, so a late read
can never see another state.  An exception raised by a deferred computation
(say a :class:`~drakegrasp.SolverError`) is raised at the read, and again at
every later read.
"""

from __future__ import annotations

import contextlib
import dataclasses
import weakref
from collections.abc import Callable, Iterator
from typing import Any

__all__ = [
    "Deferred",
    "WeakMemo",
    "computed_eagerly",
    "defer",
    "deferrable",
    "parts",
    "pending",
    "replace",
    "resolve",
]

_EAGER = [False]


class Deferred:
    """``fn(*args, **kwargs)``, computed on the first :meth:`value` and kept."""

    __slots__ = ("_call", "_value", "_done")

    def __init__(self, fn: Callable[..., Any], /, *args, **kwargs) -> None:
        self._call = (fn, args, kwargs)
        self._value = None
        self._done = False

    def value(self) -> Any:
        """The value (computed now if it was not yet)."""
        if not self._done:
            fn, args, kwargs = self._call
            self._value = fn(*args, **kwargs)
            self._done = True
            self._call = None  # drop the inputs once they are used
        return self._value

    @property
    def done(self) -> bool:
        """True once the value has been computed."""
        return self._done

    def __reduce__(self):
        # A pickled (or copied) Deferred becomes its value: no callable crosses.
        return (_identity, (self.value(),))

    def __repr__(self) -> str:
        return f"Deferred({self._value!r})" if self._done else "Deferred(<pending>)"


def _identity(value):
    return value


def _item(source: Deferred, index: int):
    return source.value()[index]


def defer(fn: Callable[..., Any], /, *args, **kwargs) -> Any:
    """A :class:`Deferred` of ``fn(*args, **kwargs)``.

    Inside :func:`computed_eagerly` the value itself, computed at once.
    """
    if _EAGER[0]:
        return fn(*args, **kwargs)
    return Deferred(fn, *args, **kwargs)


def parts(source: Any, count: int) -> tuple:
    """The ``count`` items of a tuple, each deferred when ``source`` is."""
    if isinstance(source, Deferred):
        return tuple(Deferred(_item, source, i) for i in range(count))
    items = tuple(source)
    if len(items) != count:
        raise ValueError(f"expected {count} items, got {len(items)}")
    return items


def resolve(value: Any) -> Any:
    """``value``, or its value when it is a :class:`Deferred`."""
    return value.value() if isinstance(value, Deferred) else value


@contextlib.contextmanager
def computed_eagerly() -> Iterator[None]:
    """Within the block, :func:`defer` computes at once (tests compare both).

    A process-wide switch, for tests and benchmarks: not for threads that
    want different behaviour at the same time.
    """
    before = _EAGER[0]
    _EAGER[0] = True
    try:
        yield
    finally:
        _EAGER[0] = before


class deferrable:  # noqa: N801 (used like dataclasses.field)
    """Descriptor of a dataclass field that may be given a :class:`Deferred`.

    Parameters
    ----------
    default : optional
        The field's default; without it the field is required.
    """

    def __init__(self, default: Any = dataclasses.MISSING) -> None:
        self._default = default
        self._name = self._slot = ""

    def __set_name__(self, owner, name: str) -> None:
        self._name = name
        self._slot = f"_deferrable_{name}"

    def __get__(self, obj, owner=None):
        if obj is None:  # dataclasses read the default here
            if self._default is dataclasses.MISSING:
                raise AttributeError(self._name)
            return self._default
        value = self.raw(obj)
        if isinstance(value, Deferred):
            value = value.value()
            obj.__dict__[self._slot] = value
        return value

    def __set__(self, obj, value) -> None:
        # reached through object.__setattr__ in a frozen dataclass's __init__
        obj.__dict__[self._slot] = value

    def raw(self, obj) -> Any:
        """The stored value, pending or not (no computation)."""
        try:
            return obj.__dict__[self._slot]
        except KeyError:  # unpickled from a version without deferred fields
            return obj.__dict__[self._name]


def _slot_of(cls, name: str) -> deferrable | None:
    for klass in cls.__mro__:
        if name in klass.__dict__:
            slot = klass.__dict__[name]
            return slot if isinstance(slot, deferrable) else None
    return None


def pending(obj, name: str) -> bool:
    """True when field ``name`` of ``obj`` holds a value not computed yet."""
    slot = _slot_of(type(obj), name)
    if not isinstance(slot, deferrable):
        return False
    value = slot.raw(obj)
    return isinstance(value, Deferred) and not value.done


_INIT_FIELDS: dict[type, tuple] = {}


def _init_fields(cls) -> tuple:
    """``(name, deferrable or None)`` of each ``__init__`` field of a dataclass."""
    found = _INIT_FIELDS.get(cls)
    if found is None:
        found = _INIT_FIELDS[cls] = tuple(
            (f.name, _slot_of(cls, f.name)) for f in dataclasses.fields(cls) if f.init
        )
    return found


def replace(obj, **changes):
    """``dataclasses.replace`` that keeps pending fields pending."""
    kwargs = {}
    for name, slot in _init_fields(type(obj)):
        if name in changes:
            kwargs[name] = changes.pop(name)
        elif slot is not None:
            kwargs[name] = slot.raw(obj)
        else:
            kwargs[name] = getattr(obj, name)
    if changes:
        raise TypeError(f"{type(obj).__name__} has no fields {sorted(changes)}")
    return type(obj)(**kwargs)


class WeakMemo(weakref.WeakKeyDictionary):
    """Values computed once per (owner, key), kept while the owner lives.

    For what an immutable owner (a grasp, a finalized plant's topology)
    decides alone.  The owner is held weakly, so a value must not refer back
    to it (that would keep it alive).  Exceptions are raised, never kept.
    """

    def value(self, owner, key, compute: Callable[[], Any]) -> Any:
        """``compute()`` the first time for ``owner`` and ``key``, then kept."""
        store = self.get(owner)
        if store is None:
            store = self[owner] = {}
        try:
            known = key in store
        except Exception:  # noqa: BLE001 - unhashable, or a hostile __hash__/__eq__
            # compute() judges the argument, uncached
            return compute()
        if not known:
            store[key] = compute()
        return store[key]
