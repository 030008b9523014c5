"""Hostile values that cross into a sandboxed worker, and the pools they come from.

The sandbox speaks JSON, which carries NaN, ±inf, huge integers, strings,
``None`` and nesting, but not complex numbers, arrays of a given dtype and
memory layout, or arbitrary objects.  :func:`encode` wraps those in tagged
dictionaries and :func:`decode` rebuilds them on the worker side, so an array
arrives there as a Fortran-ordered, non-contiguous, read-only, negatively
strided, broadcast (zero-stride) or memory-mapped array of the dtype the
generator chose, exactly what the public function receives.
"""

from __future__ import annotations

import math
import os
import tempfile

import numpy as np

LAYOUTS = ("C", "F", "noncontiguous", "readonly", "reversed", "broadcast", "memmap")
TAG = "__hostile__"


def encode(value):
    """A JSON-able description of ``value`` (see the module docstring)."""
    if isinstance(value, Hostile):
        return value.spec
    if isinstance(value, complex):
        return {TAG: "complex", "re": value.real, "im": value.imag}
    if isinstance(value, np.ndarray):
        return array(value).spec
    if isinstance(value, np.generic):
        return {TAG: "scalar", "dtype": value.dtype.str, "value": encode(value.item())}
    if isinstance(value, list | tuple):
        out = [encode(v) for v in value]
        return out if isinstance(value, list) else {TAG: "tuple", "items": out}
    if isinstance(value, dict):
        return {k: encode(v) for k, v in value.items()}
    return value


def decode(value):
    """The worker-side value of an :func:`encode` description."""
    if isinstance(value, list):
        return [decode(v) for v in value]
    if not isinstance(value, dict):
        return value
    kind = value.get(TAG)
    if kind is None:
        return {k: decode(v) for k, v in value.items()}
    if kind == "complex":
        return complex(value["re"], value["im"])
    if kind == "tuple":
        return tuple(decode(v) for v in value["items"])
    if kind == "object":
        return object()
    if kind == "scalar":
        return np.dtype(value["dtype"]).type(decode(value["value"]))
    assert kind == "array", kind
    return _build(value)


class Hostile:
    """A value that only the worker can build (an array of a given layout...)."""

    def __init__(self, spec: dict):
        self.spec = spec

    def __repr__(self) -> str:
        s = self.spec
        if s.get(TAG) == "array":
            return f"array({s['dtype']}, {s['layout']}, shape={s['shape']})"
        return f"Hostile({s.get(TAG)})"


def opaque() -> Hostile:
    """A plain ``object()`` on the worker side."""
    return Hostile({TAG: "object"})


def array(values, *, dtype=None, layout: str = "C") -> Hostile:
    """``values`` as an array of ``dtype`` with the given memory layout."""
    a = np.asarray(values)
    dtype = np.dtype(dtype or a.dtype)
    flat = a.ravel().tolist()
    if dtype.kind == "c":
        flat = [encode(complex(x)) for x in flat]
    elif dtype.kind == "O":
        flat = [encode(x) for x in flat]
    return Hostile(
        {
            TAG: "array",
            "dtype": dtype.str if dtype.kind != "O" else "O",
            "shape": list(a.shape),
            "values": flat,
            "layout": layout,
        }
    )


def _build(spec: dict) -> np.ndarray:
    dtype = np.dtype(spec["dtype"])
    shape = tuple(spec["shape"])
    values = [decode(v) for v in spec["values"]]
    if dtype.kind == "O":
        a = np.empty(len(values), dtype=object)
        a[:] = values
        a = a.reshape(shape)
    else:
        a = np.array(values, dtype=dtype).reshape(shape)
    layout = spec["layout"]
    if layout == "C":
        return np.ascontiguousarray(a)
    if layout == "F":
        return np.asfortranarray(a)
    if layout == "noncontiguous":  # every other element of a twice-longer array
        big = np.zeros((2 * a.size,) if a.ndim else (2,), dtype=dtype)
        big[::2] = a.ravel()
        return big[::2].reshape(shape) if a.ndim <= 1 else _strided(a)
    if layout == "readonly":
        a = np.ascontiguousarray(a)
        a.flags.writeable = False
        return a
    if layout == "reversed":  # negative strides along the first axis
        if a.ndim == 0 or a.shape[0] == 0:
            return a
        return np.ascontiguousarray(a[::-1])[::-1]
    if layout == "broadcast":  # zero strides where a leading axis repeats
        if a.ndim == 0 or a.shape[0] == 0 or not np.all(a == a[:1]):
            return a
        return np.broadcast_to(a[:1], a.shape)
    assert layout == "memmap", layout
    fd, path = tempfile.mkstemp(suffix=".dat", prefix="drakegrasp-fuzz-")
    os.close(fd)
    m = np.memmap(path, dtype=dtype, mode="w+", shape=shape if a.size else (1,))
    if a.size:
        m[...] = a
        m.flush()
    os.unlink(path)  # the mapping stays valid; nothing is left behind
    return m if a.size else a


def describe(a) -> dict:
    """Worker side: what arrived (for the codec's own test)."""
    return {
        "dtype": a.dtype.str if a.dtype.kind != "O" else "O",
        "shape": list(a.shape),
        "c": bool(a.flags.c_contiguous),
        "f": bool(a.flags.f_contiguous),
        "writeable": bool(a.flags.writeable),
        "strides": list(a.strides),
        "memmap": isinstance(a, np.memmap),
        "values": np.asarray(a, dtype=float).ravel().tolist()
        if a.dtype.kind in "iuf"
        else None,
    }


def _strided(a: np.ndarray) -> np.ndarray:
    """A copy of ``a`` viewed with a step of 2 in its last axis."""
    big = np.zeros((*a.shape[:-1], 2 * a.shape[-1]), dtype=a.dtype)
    big[..., ::2] = a
    return big[..., ::2]


# ------------------------------------------------------------------ pools

NAN, INF = math.nan, math.inf
BAD_REALS = (NAN, INF, -INF, "0.5", None, 1j, [0.5], True, opaque())
BAD_COUNTS = (0, -1, 1.5, "2", None, True, NAN, 1j, 10**30, [2])


def pick(rng: np.random.Generator, pool):
    """One element of ``pool``, chosen by ``rng``."""
    return pool[int(rng.integers(len(pool)))]


# ------------------------------------------------------- hostile objects


class HostileError(Exception):
    """What a hostile object's dunder raises: no library code expects it."""


def _boom(*_args, **_kwargs):
    raise HostileError("a hostile dunder")


class LenRaises(list):
    """A list of three floats whose ``len()`` raises."""

    __len__ = _boom


class IterRaises:
    """A sequence that claims 3 items and raises when iterated or indexed."""

    def __len__(self):
        return 3

    __iter__ = _boom
    __getitem__ = _boom


class LyingLength:
    """``len()`` says 3; iteration and indexing give 2 floats."""

    def __len__(self):
        return 3

    def __iter__(self):
        return iter([0.5, 0.5])

    def __getitem__(self, i):
        return [0.5, 0.5][i]


class ArrayRaises:
    """An array-like whose ``__array__`` raises."""

    __array__ = _boom


class FloatRaises:
    """A registered :class:`numbers.Real` whose ``float()`` raises."""

    __float__ = _boom
    __index__ = _boom


class FloatSubclassRaises(float):
    """A float (0.5) whose ``__float__`` raises."""

    __float__ = _boom


class BoolRaises:
    """An object whose truth value raises."""

    __bool__ = _boom


class EqHashRaises:
    """An object that cannot be compared or hashed."""

    __eq__ = _boom
    __hash__ = _boom


class ArraySubclass(np.ndarray):
    """A numpy subclass (what a library's own array type is)."""


class ReprRaises:
    """An object whose ``repr()`` raises (a message that names it must not)."""

    __repr__ = _boom


class ReprNotStr:
    """An object whose ``__repr__`` returns an int: ``repr()`` raises TypeError."""

    def __repr__(self):
        return 42


HUGE = 10**7
"""Characters of a huge ``repr``: a message must not carry them all."""


class ReprHuge:
    """An object whose ``repr()`` is 10**7 characters long."""

    def __repr__(self):
        return "x" * HUGE


class StrRaises:
    """An object whose ``str()`` raises (its ``repr`` is fine)."""

    __str__ = _boom

    def __repr__(self):
        return "StrRaises()"


class FormatRaises:
    """An object whose ``format()`` raises, so ``f"{x}"`` and ``f"{x:g}"`` do."""

    __format__ = _boom

    def __repr__(self):
        return "FormatRaises()"


class FloatReprRaises(float):
    """A float (0.5) that passes ``isinstance(x, float)``; repr, str, format raise."""

    __repr__ = _boom
    __str__ = _boom
    __format__ = _boom


class FloatReprHuge(float):
    """A float (0.5) whose ``repr()`` and ``str()`` are 10**7 characters long."""

    def __repr__(self):
        return "5" * HUGE

    __str__ = __repr__


class IntReprRaises(int):
    """An int (2) whose repr, str and format raise."""

    __repr__ = _boom
    __str__ = _boom
    __format__ = _boom


class StrReprRaises(str):
    """A str whose ``repr()`` raises (its ``str()`` and format are a str's)."""

    __repr__ = _boom


class StrFormatRaises(str):
    """A str whose ``str()`` and ``format()`` raise (its ``repr`` is fine)."""

    __str__ = _boom
    __format__ = _boom


class ArrayReprRaises(np.ndarray):
    """A numpy array subclass whose repr, str and format raise."""

    __repr__ = _boom
    __str__ = _boom
    __format__ = _boom


class ListReprRaises(list):
    """A list whose repr, str and format raise."""

    __repr__ = _boom
    __str__ = _boom
    __format__ = _boom


class TupleReprRaises(tuple):
    """A tuple whose repr, str and format raise."""

    __repr__ = _boom
    __str__ = _boom
    __format__ = _boom


class DictReprRaises(dict):
    """A dict whose repr, str and format raise."""

    __repr__ = _boom
    __str__ = _boom
    __format__ = _boom


def repr_hostile() -> list:
    """Fresh objects whose repr, str or format raise, lie or are huge.

    Some are plain objects; the others also pass for what a parameter wants
    (a float, an int, a str, an array, a list, a tuple, a dict), so a check
    can let them through and a message built later still meets their repr.
    """
    objects = [
        ReprRaises(), ReprNotStr(), ReprHuge(), StrRaises(), FormatRaises(),
        FloatReprRaises(0.5), FloatReprRaises("nan"), FloatReprHuge(0.5),
        FloatReprHuge(-1.0), IntReprRaises(2), IntReprRaises(-1),
        StrReprRaises("x"), StrReprRaises("hard_finger"),
        StrReprRaises("package://nope/x.sdf"), StrFormatRaises("x"),
        np.ones(3).view(ArrayReprRaises), np.ones((2, 3, 3)).view(ArrayReprRaises),
        np.array(0.5).view(ArrayReprRaises), np.zeros((0, 3)).view(ArrayReprRaises),
        ListReprRaises([0.5, 0.5, 0.5]), ListReprRaises([ReprRaises()]),
        TupleReprRaises((0.5, 0.5, 0.5)), DictReprRaises(), DictReprRaises(a=1),
        [ReprRaises(), 0.5, 0.5], {"x": ReprRaises()}, {ReprRaises(): 1},
        np.array([ReprRaises(), 0.5, 0.5], dtype=object),
        np.array([ReprHuge()], dtype=object),
    ]  # fmt: skip
    return objects


class FspathRaises:
    """An ``os.PathLike`` whose ``__fspath__`` raises."""

    __fspath__ = _boom

    def __repr__(self):
        return "FspathRaises()"


class FspathReturns:
    """An ``os.PathLike`` whose ``__fspath__`` returns ``value`` (any type)."""

    def __init__(self, value):
        self.value = value

    def __fspath__(self):
        return self.value

    def __repr__(self):
        return f"FspathReturns({type(self.value).__name__})"


class PathReprRaises:
    """An ``os.PathLike`` of a file that is not there; its repr, str, format raise."""

    def __fspath__(self):
        return "/nonexistent/drakegrasp-hostile.npz"

    __repr__ = _boom
    __str__ = _boom
    __format__ = _boom


class StrFspathRaises(str):
    """A str whose ``__fspath__``, ``__str__`` and ``__format__`` raise."""

    __fspath__ = _boom
    __str__ = _boom
    __format__ = _boom


class ClaimsStr:
    """No str, though ``isinstance(x, str)`` says so: its ``__class__`` claims str.

    ``str``'s own methods refuse it (``str.strip(x)`` raises a bare
    TypeError); only ``type(x)`` tells the truth.
    """

    __class__ = property(lambda self: str)  # noqa: PLE0237 - the lie under test

    def __repr__(self):
        return "ClaimsStr()"


_STR_METHODS = (
    "strip", "lstrip", "rstrip", "split", "rsplit", "partition", "rpartition",
    "startswith", "endswith", "replace", "lower", "upper", "casefold", "find",
    "rfind", "index", "join", "encode", "expandtabs", "format", "isidentifier",
    "__contains__", "__getitem__", "__iter__", "__add__", "__radd__", "__mod__",
    "__mul__", "__lt__", "__le__", "__gt__", "__ge__",
)  # fmt: skip


class StrMethodsRaise(str):
    """A str whose every method a reader may call raises (its repr is a str's)."""

    __fspath__ = _boom


for _name in _STR_METHODS:
    setattr(StrMethodsRaise, _name, _boom)


class StrEqRaises(str):
    """A str that cannot be compared: ``==``, ``!=`` raise (it hashes as a str)."""

    __eq__ = _boom
    __ne__ = _boom
    __hash__ = str.__hash__


class StrHashRaises(str):
    """A str that cannot be hashed (a dict key, a set member)."""

    __hash__ = _boom


class StrLenRaises(str):
    """A str whose ``len()`` and truth value raise."""

    __len__ = _boom
    __bool__ = _boom


class StrEncodeRaises(str):
    """A str whose ``encode`` raises (a UTF-8 check would meet it)."""

    encode = _boom


class StrLies(str):
    """A str whose methods lie: equal to everything, empty, stripped to a name.

    A check that asks it (``x == "open"``, ``x.strip()``, ``len(x)``, its
    ``__fspath__``) would take it for something it does not hold.
    """

    def __eq__(self, other):
        return True

    def __ne__(self, other):
        return False

    __hash__ = str.__hash__

    def __len__(self):
        return 0

    def strip(self, *args):
        return "box"

    lstrip = rstrip = strip

    def encode(self, *args, **kwargs):
        return b"box"

    def __fspath__(self):
        return "/nonexistent/lie.npz"

    def __str__(self):
        return "box"


def str_hostile(text: str) -> list:
    """Fresh ``str`` subclasses of ``text`` whose methods raise or lie, and a fake.

    Each holds ``text`` (but :class:`ClaimsStr`, which holds nothing): a
    reader that reads it as a plain ``str`` once (``str.__str__``) sees
    ``text``; one that calls its methods meets a raise or a lie.
    """
    kinds = (StrMethodsRaise, StrEqRaises, StrHashRaises, StrLenRaises,
             StrEncodeRaises, StrLies, StrFspathRaises, StrFormatRaises)  # fmt: skip
    return [kind(text) for kind in kinds] + [ClaimsStr()]


def path_hostile() -> list:
    """Fresh paths, file names and URLs that no check may let escape raw.

    ``os.PathLike`` objects whose ``__fspath__`` raises or returns no str
    (an int, bytes, a hostile str subclass, 10**7 characters); ``str``
    subclasses whose ``__str__``, ``__format__``, ``__fspath__`` or ``repr``
    raise, of an existing and of a missing file; and plain
    strings that pathlib, ``os.stat`` or Drake refuse with a bare exception:
    huge (10**7 characters), longer than ``PATH_MAX``, a name longer than
    ``NAME_MAX``, a NUL character, a lone surrogate, ``~nobody`` (pathlib's
    ``expanduser`` raised ``RuntimeError``), empty, and bytes; and
    :func:`str_hostile`'s subclasses (methods that raise or lie, and an
    object whose ``__class__`` claims str) of a missing file, a folder, a
    lone surrogate and a NUL.
    """
    return [
        FspathRaises(), FspathReturns(42), FspathReturns(None),
        FspathReturns(b"/tmp"), FspathReturns(StrFormatRaises("x")),
        FspathReturns("x" * HUGE), FspathReturns("\0"), PathReprRaises(),
        StrFspathRaises("/nonexistent/x.npz"), StrFspathRaises("."),
        StrFormatRaises("/nonexistent/x.sdf"), StrFormatRaises("/tmp"),
        StrReprRaises("/nonexistent/x.yaml"), StrFormatRaises("package://x/y.sdf"),
        "x" * HUGE, "/" + "d/" * 2100, "y" * 300, "/tmp/" + "z" * 300 + ".npz",
        "a\0b", "\ud800", "/tmp/\udfff.npz", "~drakegrasp-nobody/x",
        "", b"/tmp", bytearray(b"/tmp"),
        *str_hostile("/nonexistent/x.npz"), *str_hostile("/tmp"),
        *str_hostile("\ud800"), *str_hostile("a\0b"),
    ]  # fmt: skip


def _register():
    import numbers

    numbers.Real.register(FloatRaises)


_register()


def objects() -> list:
    """Hostile objects, fresh: dunders that raise or lie, odd numpy kinds.

    For the in-process fuzz of the public calls (``report_public.py``): they
    cannot cross the JSON sandbox.  The generator is consumed by its first
    use, as a caller's would be.
    """
    import decimal
    import fractions

    selfish: list = []
    selfish.append(selfish)
    return [
        LenRaises([0.5, 0.5, 0.5]), IterRaises(), LyingLength(), ArrayRaises(),
        FloatRaises(), FloatSubclassRaises(0.5), BoolRaises(), EqHashRaises(),
        selfish, (x for x in (0.5, 0.5, 0.5)), np.ones(3).view(ArraySubclass),
        np.ma.masked_array([0.5, 0.5, 0.5], [0, 1, 0]), np.array(0.5),
        np.array(True), np.bool_(False), np.float32(0.5), np.int64(8),
        np.ones(3, dtype=np.float16), np.ones(3, dtype=np.longdouble),
        np.ones(3, dtype=complex), np.array([0.5, FloatRaises()], dtype=object),
        fractions.Fraction(1, 2), decimal.Decimal("0.5"), decimal.Decimal("sNaN"),
        np.broadcast_to(0.5, (10**9, 3)), np.ones((4, 3))[::2],
        _readonly(np.ones((2, 3))), [[0.5, 0.5, 0.5], LyingLength()],
        *repr_hostile(), *path_hostile(),
    ]  # fmt: skip


def _readonly(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a
