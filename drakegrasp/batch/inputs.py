"""Inputs and options of the batch engine, validated once per call.

Arrays are checked chunk by chunk (:mod:`drakegrasp.batch.run.stream` calls the
per-chunk checks where the chunk is solved), so a memory-mapped input is never
loaded whole; options are checked once, when a run's task builder is made
(:func:`~drakegrasp.batch.run.chunk.force_task`,
:func:`~drakegrasp.batch.run.chunk.form_task`), and the kernel choice is
resolved there: the chunks receive ``"numba"`` or ``"numpy"``, never ``"auto"``.
"""

from __future__ import annotations

import importlib.util
import itertools
from collections.abc import Iterator, Sequence

import numpy as np

from drakegrasp.core.validation import (
    LENGTH_BOUND,
    LENGTH_MIN,
    POSITION_BOUND,
    check_coefficient,
    check_coefficient_array,
    check_positions,
    check_rank_tol,
    check_tol,
    describe,
    integer_or_none,
    items_of,
    plain_str,
    real_array,
    refuse_structured,
    unit_vectors,
)
from drakegrasp.errors import InvalidContactError, InvalidGraspError, InvalidOptionError

__all__ = [
    "KERNELS",
    "MAX_METRIC_NAMES",
    "METRICS",
    "check_kernel",
    "check_metrics",
    "per_contact_getter",
    "resolve_kernel",
    "shape_of",
]

METRICS = ("sigma_min", "isotropy", "ellipsoid_volume", "epsilon_l1")
"""Metric names that ``metrics=`` accepts; see :func:`batch_force_closure`."""


def positive_int(name: str, value, minimum: int) -> int:
    n = integer_or_none(value)
    if n is None or n < minimum:
        raise InvalidOptionError(
            f"{name} must be an integer >= {minimum}, got {describe(value)}"
        )
    return int(n)


def _check_tol(name: str, value) -> float:
    return check_rank_tol(value) if name == "rank_tol" else check_tol(value, name)


def read_shape(name: str, value, must: str, *, error: type) -> tuple[int, ...]:
    """``np.shape(value)``, or ``error`` saying what ``name`` must be if ragged."""
    try:
        return np.shape(value)
    except (ValueError, TypeError):  # inhomogeneous nested sequences
        raise error(
            f"{name} must be {must}; got a nested sequence of uneven shape"
        ) from None
    except Exception as err:  # noqa: BLE001 - a hostile __len__, __iter__, __array__
        raise error(
            f"{name} must be {must}; got {describe(value)} ({type(value).__name__}), "
            f"which raised {type(err).__name__}: {err} when its shape was read"
        ) from None


def shape_of(name: str, a) -> tuple[int, int, int]:
    """``(K, N, d)`` of a stacked input, or a clear error naming ``name``."""
    refuse_structured(name, a)
    shape = () if a is None else read_shape(
        name, a,
        "a (K, N, 2) or (K, N, 3) array, or a list of per-grasp (N_k, d) arrays",
        error=InvalidContactError,
    )  # fmt: skip
    if len(shape) != 3 or shape[2] not in (2, 3) or shape[1] < 1:
        raise InvalidContactError(
            f"{name} must have shape (K, N, 2) or (K, N, 3) with N >= 1, got {shape}"
        )
    return shape


def per_contact_getter(name: str, value, K: int, N: int, *, error=InvalidContactError):
    """A per-contact coefficient as a function of a chunk slice -> (k, N) array."""
    a = value
    must = "a scalar or a (K,), (K, 1), (1, N) or (K, N) array"
    shape = (
        tuple(a.shape)
        if hasattr(a, "shape")
        else read_shape(name, a, must, error=error)
    )
    if value is None or shape == ():
        x = check_coefficient(name, value, error=error)
        return lambda sl: np.full((sl.stop - sl.start, N), x)
    if shape == (K,) and K == N:
        raise InvalidOptionError(
            f"{name} of shape ({K},) is ambiguous because K == N == {K}: pass "
            f"shape ({K}, 1) for one value per grasp or (1, {N}) for one per contact"
        )
    if shape in ((K,), (K, 1)):
        return lambda sl: np.repeat(
            real_array(name, a[sl], error=error).reshape(-1, 1), N, axis=1
        )
    if shape == (1, N):
        row = real_array(name, a, error=error)
        return lambda sl: np.repeat(row, sl.stop - sl.start, axis=0)
    if shape == (K, N):
        return lambda sl: real_array(name, a[sl], error=error)
    raise error(
        f"{name} must be a scalar or of shape (K,) = ({K},), (K, 1), (1, N) = "
        f"(1, {N}) or (K, N) = ({K}, {N}); got shape {shape}"
    )


def check_chunk_coefficients(name: str, x: np.ndarray, start: int) -> None:
    check_coefficient_array(name, x, start=start)


def check_chunk_positions(P: np.ndarray, start: int) -> None:
    bad = ~(np.abs(P) <= POSITION_BOUND).all(axis=-1)  # NaN fails too
    if bad.any():
        k, i = np.argwhere(bad)[0]
        raise InvalidContactError(
            f"position of grasp {start + k}, contact {i} is {P[k, i].tolist()}: "
            "not finite or out of range; it must be finite with "
            f"|x| <= {POSITION_BOUND:g} m (drakegrasp.core.validation.POSITION_BOUND)"
        )


def chunk_unit_normals(Nrm: np.ndarray, start: int) -> np.ndarray:
    try:
        return unit_vectors("normal", Nrm)
    except InvalidContactError:
        scale = np.max(np.abs(Nrm), axis=-1)
        bad = ~np.isfinite(Nrm).all(axis=-1) | ~(scale > 0.0)
        k, i = np.argwhere(bad)[0]
        raise InvalidContactError(
            f"normal of grasp {start + k}, contact {i} is {Nrm[k, i].tolist()}; a "
            "contact normal must be a finite, non-zero vector pointing into the "
            "object"
        ) from None


def _refuse_grasp(
    bad: np.ndarray, values: np.ndarray, start: int, what: str, must: str
) -> None:
    """Raise :class:`~drakegrasp.InvalidGraspError` for the first grasp ``bad`` flags.

    ``bad`` is (k,) bool over a chunk that starts at grasp ``start``; the message
    names that grasp's ``what``, its value in ``values`` and what it ``must`` be.
    """
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise InvalidGraspError(
            f"{what} of grasp {start + k} is {values[k].tolist()}; it must be {must}"
        )


def _reference_points(value, K: int, d: int):
    if value is None:
        return lambda sl: np.zeros((sl.stop - sl.start, d))
    shape = read_shape(
        "reference_points", value, f"a ({d},) or (K, {d}) array",
        error=InvalidGraspError,
    )  # fmt: skip
    if shape == (d,):
        p = check_positions("reference_points", value, error=InvalidGraspError)
        return lambda sl: np.broadcast_to(p, (sl.stop - sl.start, d))
    if shape != (K, d):
        raise InvalidGraspError(
            f"reference_points must have shape ({d},) or (K, {d}) = ({K}, {d}), "
            f"got {shape}"
        )

    def get(sl):
        p = real_array("reference_points", value[sl], error=InvalidGraspError)
        bad = ~(np.abs(p) <= POSITION_BOUND).all(axis=1)
        _refuse_grasp(
            bad, p, sl.start, "reference point",
            f"finite with |x| <= {POSITION_BOUND:g} m",
        )  # fmt: skip
        return p

    return get


def _characteristic_lengths(value, K: int):
    if value is None:
        return None
    shape = read_shape(
        "characteristic_lengths",
        value,
        "a scalar or a (K,) array",
        error=InvalidGraspError,
    )
    if shape not in ((), (K,)):
        raise InvalidGraspError(
            f"characteristic_lengths must be a scalar or shape (K,) = ({K},), "
            f"got {shape}"
        )

    def get(sl):
        b = np.broadcast_to(
            real_array(
                "characteristic_lengths",
                value if shape == () else value[sl],
                error=InvalidGraspError,
            ),
            (sl.stop - sl.start,),
        )
        bad = ~(b >= LENGTH_MIN) | ~(b <= LENGTH_BOUND)
        _refuse_grasp(
            bad, b, sl.start, "characteristic length",
            f"finite and in [{LENGTH_MIN:.3g}, {LENGTH_BOUND:g}] m",
        )  # fmt: skip
        return b

    return get


MAX_METRIC_NAMES = 1024
"""Most names an iterator of metrics may yield (an endless one is refused)."""


def check_metrics(metrics: Sequence[str]) -> tuple[str, ...]:
    """``metrics`` as a tuple of known names (:data:`METRICS`), or a clear error.

    An iterator is read once, at most :data:`MAX_METRIC_NAMES` names.
    """
    if isinstance(metrics, str):
        metrics = (metrics,)
    if isinstance(metrics, Iterator):
        metrics = items_of(
            "metrics",
            itertools.islice(metrics, MAX_METRIC_NAMES + 1),
            f"a sequence of names from {', '.join(METRICS)}",
        )
        if len(metrics) > MAX_METRIC_NAMES:
            raise InvalidOptionError(
                f"metrics yields more than {MAX_METRIC_NAMES} names; give a "
                f"sequence of names from {', '.join(METRICS)}"
            )
    names = tuple(  # each read as the plain str it holds (its == may lie)
        plain_str(name)
        for name in items_of(
            "metrics", metrics, f"a sequence of names from {', '.join(METRICS)}"
        )
    )
    for name in names:
        if type(name) is not str or name not in METRICS:
            raise InvalidOptionError(
                f"unknown metric {describe(name)}; valid metrics are "
                f"{', '.join(METRICS)}"
            )
    return names


def numba_available() -> bool:
    """Whether numba is installed (checked without importing it: ~0.3 s)."""
    return importlib.util.find_spec("numba") is not None


def compiled_route(kernel: str) -> bool:
    """Whether the LP and construction loops of ``kernel`` are numba's.

    ``"numba"`` and ``"unfused"`` (the compiled loops without the fused
    kernel) are; ``"auto"``, which an internal function may still be given when
    called directly, is where numba is installed.  The entry points pass
    :func:`resolve_kernel`'s answer, never ``"auto"``.
    """
    return kernel in ("numba", "unfused") or (kernel == "auto" and numba_available())


KERNELS = ("auto", "numba", "numpy")
"""The kernel choices of the batch engine (``"auto"``: numba when installed)."""


def check_kernel(kernel: str) -> str:
    """``kernel`` if it is one of :data:`KERNELS` (not resolved)."""
    kernel = plain_str(kernel)
    if type(kernel) is not str or kernel not in KERNELS:
        raise InvalidOptionError(
            f"kernel must be 'auto', 'numba' or 'numpy', got {describe(kernel)}"
        )
    return kernel


def resolve_kernel(kernel: str) -> str:
    """``kernel`` checked, and ``"auto"`` resolved to ``"numba"`` or ``"numpy"``.

    A misspelt ``DRAKEGRASP_KERNELS`` is said here, where the numba route is
    chosen in the caller's process, not where a worker process first runs a
    kernel (:func:`~drakegrasp.batch.compiled.announce_misspelt_kernels`).
    """
    kernel = check_kernel(kernel)  # the plain str: a subclass's == may lie
    if kernel == "numba" and not numba_available():
        raise InvalidOptionError(
            "kernel='numba' needs numba, a dependency of drakegrasp that "
            "is not installed here (pip install numba); use kernel='numpy'"
        )
    if kernel == "auto" and not numba_available():
        from drakegrasp.batch.compiled import announce_numpy_route

        announce_numpy_route()  # once per process
        return "numpy"
    if kernel == "numpy":
        return kernel
    from drakegrasp.batch.compiled import announce_misspelt_kernels

    announce_misspelt_kernels()  # once per process
    return "numba"
