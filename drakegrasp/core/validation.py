r"""Input validation shared by every public entry point (numpy only).

One module decides what a valid input is, so the single-grasp programs, the
quality metrics, the batch engine and the command line accept and refuse the
same values with the same messages.  Every check raises a
:class:`~drakegrasp.GraspError` subclass naming the bad value and the valid
range.

The valid ranges (documented once, here):

==========================  ===================================================
quantity                    valid values
==========================  ===================================================
positions, reference point  real, finite, every coordinate ``|x| <=``
                            :data:`POSITION_BOUND` (1e20 m).  Moments are then
                            finite and LAPACK never sees ``inf``/``NaN`` (an
                            overflowing ``G`` made its SVD loop forever).
normals                     real, finite, not all zero; normalised without
                            overflow (divided by their largest component
                            first), so ``[-1e155, 0, 0]`` is ``[-1, 0, 0]``.
``mu``, ``ν``               0, or in [:data:`COEFFICIENT_MIN`,
                            :data:`COEFFICIENT_MAX`] = [1e-12, 1e12].  Every
                            verdict and metric is right inside this range (the
                            fuzz suite checks it against a well-scaled copy);
                            outside it the cones are numerically a ray or a
                            half-space and the answer would not be trustworthy.
``tol``                     real in [:data:`TOL_MIN`, :data:`TOL_MAX`] =
                            [1e-10, 0.5]: ``d*`` is at most 1 (LP1's reaches 1
                            up to round-off, so a threshold near 1 would decide
                            on noise) and the solvers resolve it to about 1e-10.
``rank_tol``                real in [:data:`RANK_TOL_MIN`, :data:`RANK_TOL_MAX`]
                            = [1e-14, 1e-3].
``num_generators``          integer in [3, :data:`MAX_NUM_GENERATORS`] = [3, 256]
                            (256 generators inscribe the Coulomb cone to 0.008 %;
                            10**9 once allocated 7.45 GiB).
``angle_tol``               real in [0, :data:`MAX_ANGLE_TOL`] = [0, 0.01] rad.
lengths (``b``, scales)     real in [:data:`LENGTH_MIN`, :data:`LENGTH_BOUND`]
                            = [2.2e-308, 1e30] (below, a length is subnormal:
                            a moment over it overflows).
hand Jacobian entries       real, finite, ``|J_ij| <=`` :data:`JACOBIAN_BOUND`.
==========================  ===================================================

Arrays must have a real numeric dtype: complex arrays are refused (numpy would
silently drop the imaginary part), as are strings, ``None``, booleans and
object arrays; so are masked arrays with masked entries (the mask would be
dropped) and arrays of more than
:data:`~drakegrasp.core.tolerances.MAX_ARRAY_ENTRIES` entries.
"""

from __future__ import annotations

import decimal
import itertools
import numbers
import operator
import os
import sys

import numpy as np

from drakegrasp.core.tolerances import (
    MAX_ARRAY_ENTRIES,
    MAX_DISTANCE_TOLERANCE,
    MAX_ITEMS,
    MOMENT_ARMS,
)
from drakegrasp.errors import (
    InvalidContactError,
    InvalidGraspError,
    InvalidOptionError,
    type_name,
)

__all__ = [
    "COEFFICIENT_MAX",
    "COEFFICIENT_MIN",
    "JACOBIAN_BOUND",
    "LENGTH_BOUND",
    "LENGTH_MIN",
    "MAX_ANGLE_TOL",
    "MAX_NUM_GENERATORS",
    "NAME_MAX",
    "PATH_MAX",
    "POSITION_BOUND",
    "RANK_TOL_MAX",
    "RANK_TOL_MIN",
    "TOL_MAX",
    "TOL_MIN",
    "check_angle_tol",
    "check_coefficient",
    "check_coefficient_array",
    "check_contact",
    "check_distance_tolerance",
    "check_flag",
    "check_grasp",
    "check_length",
    "check_num_generators",
    "check_positions",
    "check_rank_tol",
    "check_tol",
    "describe",
    "integer_or_none",
    "items_of",
    "outside_moment_arms",
    "path_text",
    "plain_str",
    "real_array",
    "real_scalar",
    "refuse_structured",
    "safe_norm",
    "unit_vectors",
]

POSITION_BOUND = 1e20
"""Largest absolute coordinate (metres) of a contact position or reference point."""

COEFFICIENT_MIN = 1e-12
"""Smallest non-zero friction coefficient ``μ`` or torsional coefficient ``ν``."""

COEFFICIENT_MAX = 1e12
"""Largest friction coefficient ``μ`` or torsional coefficient ``ν``."""

TOL_MIN = 1e-10
"""Smallest threshold ``tol`` on ``d*`` (the solvers resolve ``d*`` to ~1e-10)."""

TOL_MAX = 0.5
"""Largest threshold ``tol`` on ``d*`` (``d*`` never exceeds 1)."""

RANK_TOL_MIN = 1e-14
"""Smallest relative singular-value threshold ``rank_tol``."""

RANK_TOL_MAX = 1e-3
"""Largest relative singular-value threshold ``rank_tol``."""

MAX_NUM_GENERATORS = 256
"""Most generators of a linearised spatial Coulomb cone."""

MAX_ANGLE_TOL = 1e-2
"""Largest slack (rad) of the antipodal angle test."""

LENGTH_BOUND = 1e30
"""Largest characteristic length or torque scale (metres)."""

LENGTH_MIN = sys.float_info.min
"""Smallest characteristic length or torque scale (metres): the smallest normal
double, 2.2e-308.  Below it ``m / b`` overflows for a moment of 1 N·m, and a
certificate's direction scaled by ``b`` came out NaN."""

JACOBIAN_BOUND = 1e100
"""Largest absolute entry of a hand Jacobian."""


DESCRIBE_WIDTH = 120
"""Characters of a value's ``repr`` that :func:`describe` keeps."""


def describe(value) -> str:
    """``repr(value)`` on one line, cut to 120 characters, for a message.

    A ``repr`` that raises, returns something other than a ``str`` or is
    huge is no reason to lose the message or to make it huge: the value is
    then named by its type, and a long ``repr`` is cut before it is read
    (a user's ``float`` or ``str`` subclass may carry any of these, even
    after an ``isinstance`` check).
    """
    try:
        text = repr(value)
        # A str subclass passes repr(); read it as a plain str, whose
        # methods its own cannot override.
        text = str.__getitem__(text, slice(0, 4 * DESCRIBE_WIDTH))
    except Exception as err:  # noqa: BLE001 - a hostile __repr__
        return f"<{type_name(value)} whose repr() raised {type_name(err)}>"
    text = " ".join(text.split())
    if len(text) <= DESCRIBE_WIDTH:
        return text
    return text[: DESCRIBE_WIDTH - 3] + "..."


def plain_str(value):
    """``value``, a ``str`` subclass as the plain ``str`` it holds.

    A user's ``str`` subclass passes an ``isinstance`` check, but its own
    ``__str__``, ``__format__`` or ``__fspath__`` may raise or lie where
    pathlib, a message or Drake read it, and its ``==``, ``__hash__``,
    ``strip`` or ``encode`` may raise or lie where a word or a name is
    compared; ``str.__str__`` reads the characters alone.  Anything that is
    not a ``str`` is returned unchanged, so ``type(x) is str`` afterwards
    tells a string from an object whose ``__class__`` merely claims ``str``
    (``isinstance`` believes the claim).  Read a user's word or name through
    it once, where it enters, and use what it returns.
    """
    # type(), not isinstance(): a __class__ property can claim str, and
    # str.__str__ would then raise on what is no str at all.
    return str.__str__(value) if issubclass(type(value), str) else value


def _system_limit(name: str, default: int) -> int:
    """``os.pathconf("/", name)``, or ``default`` where the system does not say."""
    try:
        value = os.pathconf("/", name)
    except (AttributeError, OSError, ValueError):  # no pathconf, or no such name
        return default
    return value if value > 0 else default  # -1: no limit given


PATH_MAX = _system_limit("PC_PATH_MAX", 4096)
"""The system's ``PATH_MAX`` (4096 on Linux, 1024 on macOS): bytes in a path,
the NUL that ends it counted, so :func:`path_text` takes at most
``PATH_MAX - 1``; the system refuses a longer one (``ENAMETOOLONG``)."""

NAME_MAX = 255
"""Bytes in one name of a path (ext4, APFS, NTFS): a longer one names no file."""


def path_text(
    name: str,
    value,
    *,
    error: type = InvalidOptionError,
    must: str = "a file path (a str or an os.PathLike)",
    empty: bool = False,
) -> str:
    """The plain ``str`` of a path given as ``value``, or a refusal naming ``name``.

    The one reader of a user's file, folder or model path (or ``package://``
    URL): every entry point asks it before pathlib, ``open`` or Drake see the
    value.  A ``str`` subclass is read by ``str.__str__`` (its own
    ``__str__``, ``__format__`` or ``__fspath__`` may raise or lie); an
    ``os.PathLike`` by its ``__fspath__``, whose exception or answer of the
    wrong type is refused by name.  What then reaches the file system cannot
    raise anything but an ``OSError`` of the file itself: a NUL character, a
    character the file system cannot encode (a lone surrogate), a path of
    :data:`PATH_MAX` bytes or more or a name in it longer than
    :data:`NAME_MAX` bytes are refused here (pathlib raised a bare
    ``ValueError``, ``UnicodeEncodeError`` or ``OSError`` for them, from
    ``is_file()`` too).

    Parameters
    ----------
    name : str
        The parameter, for the message.
    value : str or os.PathLike
    error : type, optional
        The :class:`~drakegrasp.GraspError` subclass to raise (default
        :class:`~drakegrasp.InvalidOptionError`).
    must : str, optional
        What ``value`` must be, for the message.
    empty : bool, optional
        Take ``""`` (default: refuse it; pathlib reads it as the current
        folder).

    Returns
    -------
    str
        The path's characters, a plain ``str``.
    """
    kind = type(value)
    if issubclass(kind, str):
        text = str.__str__(value)
    elif hasattr(kind, "__fspath__") and not issubclass(kind, bytes):
        try:
            text = kind.__fspath__(value)
        except Exception as err:  # noqa: BLE001 - a user's __fspath__
            raise error(
                f"{name} must be {must}: its __fspath__() raised {type_name(err)}"
            ) from None
        if not issubclass(type(text), str):
            raise error(
                f"{name} must be {must}: its __fspath__() returned a "
                f"{type_name(text)}, not a str"
            )
        text = str.__str__(text)
    else:
        raise error(f"{name} must be {must}, got {type_name(value)} {describe(value)}")
    if not text and not empty:
        raise error(f"{name} is empty; it must be {must}")
    problem = _path_problem(text)
    if problem:
        raise error(f"{name} {describe(text)} {problem}")
    return text


def _path_problem(text: str) -> str:
    """Why the file system cannot take ``text`` as a path, or ""."""
    if "\0" in text:
        return "holds a NUL character, which no path can hold"
    try:
        encoded = text.encode(sys.getfilesystemencoding(), "surrogateescape")
    except UnicodeError:
        return "holds a character the file system cannot encode (a lone surrogate?)"
    if len(encoded) >= PATH_MAX:  # PATH_MAX counts the NUL that ends the path
        return (
            f"is too long: {len(encoded)} bytes, where a path holds at most "
            f"{PATH_MAX - 1}"
        )
    longest = max(len(part) for part in encoded.split(b"/"))
    if longest > NAME_MAX:
        return (
            f"holds a name too long: {longest} bytes, where a file or folder "
            f"name holds {NAME_MAX}"
        )
    return ""


def real_scalar(name: str, value, *, error: type = InvalidOptionError) -> float:
    """``value`` as a float, refusing every non-real or non-number type.

    Parameters
    ----------
    name : str
        Name of the input, for the message.
    value : int or float
        Also a numpy real scalar, a 0-d real array, a
        ``fractions.Fraction`` or a ``decimal.Decimal`` (as an
        array of them is read).
    error : type, optional
        The :class:`~drakegrasp.GraspError` subclass to raise.

    Returns
    -------
    float
        May be non-finite; range checks are the caller's.
    """
    if isinstance(value, (bool, np.bool_)) or value is None:
        raise error(f"{name} must be a real number, got {describe(value)}")
    if isinstance(value, np.ndarray):
        if value.shape != () or value.dtype.kind not in "iuf":
            raise error(
                f"{name} must be a real number, got an array of shape "
                f"{value.shape} and dtype {value.dtype}"
            )
        return float(value)
    if not isinstance(value, numbers.Real | decimal.Decimal):
        raise error(
            f"{name} must be a real number, got {describe(value)} "
            f"({type(value).__name__})"
        )
    try:
        return float(value)
    except Exception as err:  # noqa: BLE001 - whatever a hostile __float__ raises
        raise error(
            f"{name} must be a real number, got {describe(value)} "
            f"({type(value).__name__}), whose float() raised "
            f"{type(err).__name__}: {err}"
        ) from None


def refuse_structured(name: str, value, *, error: type = InvalidContactError) -> None:
    """Refuse a NumPy structured (record) array, or a sequence of them, as ``name``.

    Its fields would be read as one more axis, or not at all (``np.asarray``
    keeps the record dtype), so the caller's shape or dtype message would
    point at the wrong fault.  A plain array, or anything without a dtype,
    passes.

    Raises
    ------
    GraspError
        ``error`` naming ``name``, the fields and the conversion to use.
    """
    item = value
    try:
        if isinstance(value, (list, tuple)) and len(value) > 0:
            item = value[0]  # a sequence of per-grasp arrays
        dtype = getattr(item, "dtype", None)
        fields = dtype.names if isinstance(dtype, np.dtype) else None
    except Exception:  # noqa: BLE001 - a hostile __len__ or dtype: named later
        return
    if fields is None:
        return
    raise error(
        f"{name} must be a plain float array, not a structured (record) array "
        f"with fields ({', '.join(fields)}) of dtype {dtype}: convert it first, "
        "e.g. numpy.lib.recfunctions.structured_to_unstructured(a, dtype=float) "
        "when its fields are the coordinates"
    )


def real_array(name: str, value, *, error: type = InvalidContactError) -> np.ndarray:
    """``value`` as a float64 array, refusing complex, string and object data.

    Parameters
    ----------
    name : str
    value : array-like of real numbers
    error : type, optional
        The :class:`~drakegrasp.GraspError` subclass to raise.

    Returns
    -------
    ndarray of float64
        A new array (or a read-only view of a float64 input); may hold
        non-finite values, which the caller checks.

    Raises
    ------
    GraspError
        ``error`` for what is not an array of real numbers (also a masked
        array with masked entries, or an object whose conversion raises), and
        for more than :data:`~drakegrasp.core.tolerances.MAX_ARRAY_ENTRIES`
        entries (a broadcast array of 10**9 rows), before it is read.
    """
    if value is None or isinstance(value, (str, bytes)):
        raise error(f"{name} must be an array of real numbers, got {describe(value)}")
    if np.ma.isMaskedArray(value) and np.ma.is_masked(value):
        raise error(
            f"{name} must be an array of real numbers, got a masked array with "
            f"{int(np.ma.count_masked(value))} masked entries (their hidden values "
            "would be read as data); fill them (.filled()) or drop them first"
        )
    try:
        a = np.asarray(value)
    except (TypeError, ValueError) as err:  # ragged nested sequences
        raise error(
            f"{name} must be a rectangular array of real numbers ({err})"
        ) from None
    except Exception as err:  # noqa: BLE001 - a hostile __len__, __iter__, __array__
        raise error(
            f"{name} must be an array of real numbers, got {describe(value)} "
            f"({type(value).__name__}), which raised {type(err).__name__}: {err} "
            "when read as an array"
        ) from None
    if a.size > MAX_ARRAY_ENTRIES:
        raise error(
            f"{name} has shape {a.shape}: {a.size} entries, more than the "
            f"{MAX_ARRAY_ENTRIES} drakegrasp reads in memory "
            "(drakegrasp.core.tolerances.MAX_ARRAY_ENTRIES); stream a batch "
            "that large from a file"
        )
    if a.dtype.kind == "O":
        try:
            a = np.asarray(a.tolist(), dtype=float)
        except Exception:  # noqa: BLE001 - None, strings, a hostile __float__
            raise error(
                f"{name} must be an array of real numbers, got {describe(value)}"
            ) from None
    if a.dtype.kind == "c":
        raise error(
            f"{name} must be real; got a complex array (its imaginary part would "
            "be dropped silently)"
        )
    refuse_structured(name, a, error=error)
    if a.dtype.kind not in "iuf":
        raise error(
            f"{name} must be an array of real numbers, got dtype {a.dtype} "
            f"({describe(value)})"
        )
    if not isinstance(value, np.ndarray) and _holds_bool(value):
        # numpy reads [0, True] as [0, 1]: a flag is not a number
        raise error(
            f"{name} must be an array of real numbers, got a True/False in "
            f"{describe(value)}"
        )
    return a.astype(float, copy=False)


def items_of(name: str, value, must: str, *, error: type = InvalidOptionError) -> list:
    """The items of a caller's iterable, read once into a list.

    Parameters
    ----------
    name : str
        Name of the input, for the message.
    value : iterable
        Read once (a generator is consumed).
    must : str
        What ``name`` must be, for the message ("a sequence of drakegrasp.Grasp").
    error : type, optional
        The :class:`~drakegrasp.GraspError` subclass to raise.

    Returns
    -------
    list

    Raises
    ------
    GraspError
        ``error`` for a string, bytes, a 0-d array (numpy's "iteration over a
        0-d array") or anything else not iterable, for an iterable whose
        ``__iter__``, ``__len__`` or items raise (the message names ``name``,
        the type and what was raised), and for more than
        :data:`~drakegrasp.core.tolerances.MAX_ITEMS` items (an array by its
        length, before a view per row is made; an endless generator as it is
        read).
    """
    if isinstance(value, (str, bytes)) or (
        isinstance(value, np.ndarray) and value.ndim == 0
    ):
        raise error(f"{name} must be {must}, got {describe(value)}")
    too_many = error(
        f"{name} must be {must}; got more than {MAX_ITEMS} items "
        "(drakegrasp.core.tolerances.MAX_ITEMS; a larger batch is given as arrays)"
    )
    if isinstance(value, np.ndarray) and len(value) > MAX_ITEMS:
        raise too_many
    try:
        items = list(itertools.islice(value, MAX_ITEMS + 1))
    except Exception as err:  # noqa: BLE001 - not iterable, or a hostile __iter__
        raise error(
            f"{name} must be {must}, got {describe(value)} "
            f"({type(value).__name__}), which raised {type(err).__name__}: {err} "
            "when its items were read"
        ) from None
    if len(items) > MAX_ITEMS:
        raise too_many
    return items


def _holds_bool(value) -> bool:
    """Whether a (nested) list or tuple holds a ``bool`` anywhere."""
    if isinstance(value, bool | np.bool_):
        return True
    if isinstance(value, list | tuple):
        return any(_holds_bool(v) for v in value)
    return False


def check_positions(name: str, value, *, error: type = InvalidContactError):
    """Positions (any shape): real, finite, ``|x| <= POSITION_BOUND`` m.

    Returns
    -------
    ndarray of float64
    """
    a = real_array(name, value, error=error)
    if not np.all(np.isfinite(a)):
        raise error(f"{name} {_short(a)} is not finite")
    if a.size and float(np.max(np.abs(a))) > POSITION_BOUND:
        raise error(
            f"{name} {_short(a)} has a coordinate beyond the valid bound "
            f"|x| <= {POSITION_BOUND:g} m (drakegrasp.core.validation.POSITION_BOUND)"
        )
    return a


def _short(a: np.ndarray) -> str:
    if a.size <= 6:
        return str(a.tolist())
    return f"(shape {a.shape})"


def outside_moment_arms(extent, length) -> np.ndarray:
    """Where a grasp's extent over a length leaves the range ``MOMENT_ARMS``.

    The one rule of every metric that divides moments by a length (an explicit
    ``torque_scale`` or a characteristic length): the quality metrics, the
    batch engine's metrics and the planner's torque scale.

    Parameters
    ----------
    extent : float or (k,) float
        Each grasp's extent, metres (how it is measured is the caller's).
    length : float or (k,) float
        The length its moments are divided by, metres.

    Returns
    -------
    bool or (k,) bool
        True where ``extent / length`` lies outside
        :data:`~drakegrasp.core.tolerances.MOMENT_ARMS`; never for an extent
        below :data:`LENGTH_MIN` (every contact at the reference point: any
        length does).
    """
    low, high = MOMENT_ARMS
    extent = np.asarray(extent, dtype=float)
    length = np.asarray(length, dtype=float)
    return (extent >= LENGTH_MIN) & ~(
        (low * length <= extent) & (extent <= high * length)
    )


def safe_norm(a: np.ndarray, axis: int = -1) -> np.ndarray:
    """Euclidean norm along ``axis`` without overflow or underflow.

    The vectors are divided by their largest absolute component first, so
    ``[1e200, 1e200]`` has norm ``1.414e200`` (not ``inf``) and ``[1e-200, 0]``
    has norm ``1e-200`` (not 0).
    """
    a = np.asarray(a, dtype=float)
    m = np.max(np.abs(a), axis=axis, keepdims=True)
    safe = np.where(m > 0.0, m, 1.0)
    return (m * np.linalg.norm(a / safe, axis=axis, keepdims=True)).squeeze(axis)


def unit_vectors(name: str, value, *, error: type = InvalidContactError):
    """Normalise vectors along the last axis without overflow.

    Parameters
    ----------
    name : str
    value : (..., d) array-like of real numbers
        Finite vectors, none all zero.

    Returns
    -------
    (..., d) float
        Unit vectors: each vector is divided by its largest absolute component
        and then by its norm, so a huge finite vector keeps its direction.

    Raises
    ------
    InvalidContactError
        For a non-finite entry or a zero vector, naming the first bad one, or a
        scalar / an empty last axis.
    """
    a = real_array(name, value, error=error)
    if a.ndim == 0 or a.shape[-1] == 0:
        raise error(f"{name} must be vectors along its last axis, got shape {a.shape}")
    if a.size == 0:
        return a.copy()
    # Component by component along the last axis (a batch has millions of
    # short vectors, where a reduction over that axis is slow).  The largest
    # |x| is NaN when some x is NaN and inf when some is inf, so one bound on
    # it checks finiteness and non-zero length at once.
    m = np.abs(a[..., 0])
    for j in range(1, a.shape[-1]):
        m = np.maximum(m, np.abs(a[..., j]))
    good = (m > 0.0) & (m < np.inf)
    if not good.all():
        finite = np.all(np.isfinite(a), axis=-1)
        idx = tuple(int(i) for i in np.argwhere(~good)[0])
        where = f" at index {idx}" if idx else ""
        v = a[idx].tolist()
        what = "is not finite" if not finite[idx] else "has zero length"
        raise error(
            f"{name}{where} {v} {what}; a contact normal must be a finite, "
            "non-zero vector pointing into the object"
        )
    scaled = a / m[..., None]
    norm2 = scaled[..., 0] * scaled[..., 0]  # summed left to right, as np.linalg.norm
    for j in range(1, a.shape[-1]):
        norm2 += scaled[..., j] * scaled[..., j]
    scaled /= np.sqrt(norm2)[..., None]
    return scaled


def check_coefficient(name: str, value, *, error: type = InvalidContactError) -> float:
    """A friction coefficient: 0 or in ``[COEFFICIENT_MIN, COEFFICIENT_MAX]``."""
    x = real_scalar(name, value, error=error)
    if x == 0.0:
        return 0.0
    if not (COEFFICIENT_MIN <= x <= COEFFICIENT_MAX):
        raise error(_coefficient_message(name, x))
    return x


def _coefficient_message(name: str, x: float) -> str:
    return (
        f"{name} must be finite and 0 or in [{COEFFICIENT_MIN:g}, "
        f"{COEFFICIENT_MAX:g}] (drakegrasp.core.validation.COEFFICIENT_MIN/MAX), "
        f"got {x!r}"
    )


def check_coefficient_array(
    name: str, value: np.ndarray, *, start: int = 0, error: type = InvalidContactError
) -> np.ndarray:
    """A (k, N) array of coefficients, each 0 or in the valid range.

    ``start`` is the index of the first row in the caller's numbering (a batch
    chunk), for the message.
    """
    x = real_array(name, value, error=error)
    ok = (x == 0.0) | ((x >= COEFFICIENT_MIN) & (x <= COEFFICIENT_MAX))
    if not np.all(ok):
        k, *rest = (int(i) for i in np.argwhere(~ok)[0])
        where = f" of grasp {start + k}" + (f", contact {rest[0]}" if rest else "")
        value = float(x[(k, *rest)])
        raise error(f"{name}{where} is {value!r}; " + _coefficient_message(name, value))
    return x


def _threshold(value, name: str, low: float, high: float, must: str) -> float:
    """``value`` as a real in ``[low, high]``; the error says it ``must`` be so."""
    x = real_scalar(name, value)
    if not (low <= x <= high):
        raise InvalidOptionError(f"{name} must be {must}, got {describe(value)}")
    return x


def check_tol(value, name: str = "tol") -> float:
    """Threshold on ``d*``: real in ``[TOL_MIN, TOL_MAX]``."""
    return _threshold(
        value, name, TOL_MIN, TOL_MAX,
        f"finite and > 0, a real number in [{TOL_MIN:g}, {TOL_MAX:g}] "
        "(d* is at most 1 and resolved to about 1e-10)",
    )  # fmt: skip


def check_rank_tol(value, name: str = "rank_tol") -> float:
    """Relative singular-value threshold: real in ``[RANK_TOL_MIN, RANK_TOL_MAX]``."""
    return _threshold(
        value, name, RANK_TOL_MIN, RANK_TOL_MAX,
        f"a real number in [{RANK_TOL_MIN:g}, {RANK_TOL_MAX:g}] "
        "(singular values below rank_tol * sigma_max count as zero)",
    )  # fmt: skip


def integer_or_none(value, *, integral_floats: bool = False) -> int | None:
    """``value`` as an int, or None if it is not one.

    Python and numpy integers count; bools never do; floats with an integral
    value (``8.0``) only with ``integral_floats``.
    """
    if isinstance(value, (bool, np.bool_)):
        return None
    try:
        return int(operator.index(value))
    except Exception:  # noqa: BLE001 - not an integer, or a hostile __index__
        pass
    if integral_floats and isinstance(value, (float, np.floating)):
        try:
            x = float(value)
        except Exception:  # noqa: BLE001 - a float subclass's hostile __float__
            return None
        if x.is_integer():
            return int(x)
    return None


def check_num_generators(value, name: str = "num_generators") -> int:
    """Generators of a spatial cone: an integer in ``[3, MAX_NUM_GENERATORS]``."""
    n = integer_or_none(value, integral_floats=True)
    if n is None or not (3 <= n <= MAX_NUM_GENERATORS):
        raise InvalidOptionError(
            f"{name} must be an integer >= 3 and <= {MAX_NUM_GENERATORS} "
            f"(drakegrasp.core.validation.MAX_NUM_GENERATORS), got {describe(value)}"
        )
    return int(n)


def check_angle_tol(value, name: str = "angle_tol") -> float:
    """Slack of the antipodal angle test: real in ``[0, MAX_ANGLE_TOL]`` rad."""
    x = real_scalar(name, value)
    if not (0.0 <= x <= MAX_ANGLE_TOL):
        raise InvalidOptionError(
            f"{name} must be a real number in [0, {MAX_ANGLE_TOL:g}] rad, got "
            f"{describe(value)}"
        )
    return x


def check_length(name: str, value, *, error: type = InvalidGraspError) -> float:
    """A length (metres): real, in ``[LENGTH_MIN, LENGTH_BOUND]``."""
    x = real_scalar(name, value, error=error)
    if not (LENGTH_MIN <= x <= LENGTH_BOUND):
        raise error(
            f"{name} must be a finite length in [{LENGTH_MIN:.3g}, "
            f"{LENGTH_BOUND:g}] metres, got {describe(value)}"
        )
    return x


def _instance(value, module: str, cls: str, name: str, error: type):
    """``value`` if it is a ``module.cls``, else ``error`` naming ``name``.

    No import of ``module`` (it imports this one: a cycle): an instance can
    only exist once that module is loaded, so the class is looked up there.
    """
    loaded = sys.modules.get(module)
    if loaded is None or not isinstance(value, getattr(loaded, cls)):
        raise error(
            f"{name} must be a drakegrasp.{cls}, got {describe(value)} "
            f"({type(value).__name__})"
        )
    return value


def check_grasp(value, name: str = "grasp"):
    """``value`` if it is a :class:`~drakegrasp.Grasp`, else InvalidGraspError."""
    return _instance(value, "drakegrasp.core.grasp", "Grasp", name, InvalidGraspError)


def check_contact(value, name: str = "contact"):
    """``value`` if it is a :class:`~drakegrasp.Contact`, else InvalidContactError."""
    return _instance(
        value, "drakegrasp.core.contact", "Contact", name, InvalidContactError
    )


def check_flag(name: str, value) -> bool:
    """A boolean option: ``True``/``False``, nothing else.

    Parameters
    ----------
    name : str
        Name of the option, for the message.
    value : bool
        Also a numpy boolean (``np.bool_``) or a 0-d boolean array
        (``np.array(True)``, what ``np.asarray`` of a flag gives), as
        :func:`real_scalar` takes a 0-d real array.  Not ``1``, ``None``, a
        string or an array of any other shape or dtype.

    Returns
    -------
    bool
    """
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, np.ndarray) and value.shape == () and value.dtype == bool:
        return bool(value)
    raise InvalidOptionError(f"{name} must be True or False, got {describe(value)}")


def check_distance_tolerance(value) -> float:
    """``distance_tolerance`` as a float, once it is in ``(0, 0.01]`` (metres).

    The bound is
    :data:`~drakegrasp.core.tolerances.MAX_DISTANCE_TOLERANCE` (10 mm): pairs
    farther apart than it would count as touching.

    Raises
    ------
    InvalidOptionError
        For anything else (also a string or None), naming the value; above
        the bound, giving it in metres and in millimetres.
    """
    message = (
        f"distance_tolerance must be finite and > 0, at most "
        f"{MAX_DISTANCE_TOLERANCE:g} m (metres), got {describe(value)}"
    )
    try:  # a real number only: float() would also read "1e-4" and True
        tol = real_scalar("distance_tolerance", value)
    except InvalidOptionError:
        raise InvalidOptionError(message) from None
    if not tol > 0 or tol == float("inf"):
        raise InvalidOptionError(message)
    if tol > MAX_DISTANCE_TOLERANCE:
        mm = tol * 1e3
        mm = f"{mm:g} mm" if mm != float("inf") else "over 1e308 mm"
        raise InvalidOptionError(
            f"distance_tolerance {tol:g} m ({mm}) is above the "
            f"largest accepted, {MAX_DISTANCE_TOLERANCE:g} m "
            f"({MAX_DISTANCE_TOLERANCE * 1e3:g} mm): bodies that far apart would "
            "count as touching; the unit is metres (the default 0.1 mm is 1e-4)"
        )
    return tol
