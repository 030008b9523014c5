"""One object for the choices of a batch run: :class:`BatchOptions`.

The twin of :class:`~drakegrasp.AnalysisOptions` for the batch engine: the
options every batch entry point shares (contact model, cone size, thresholds,
metrics, kernel, chunking, workers, progress), checked when the object is
made, so a bad choice is refused before any array is read (the engine checks
its keywords again when a run starts: the same checks, which pass them
unchanged).  The per-grasp data (positions, normals,
``mu``, ``torsional_friction``, reference points, characteristic lengths)
stay arguments of the call: they are arrays, not choices.

Every entry point that takes these options as keywords also takes
``options=BatchOptions(...)``; a call gives one or the other for each option,
never both.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields
from typing import Any, TypeVar

from drakegrasp.batch.inputs import (
    _check_tol,
    check_kernel,
    check_metrics,
    positive_int,
)
from drakegrasp.batch.run.stream import DEFAULT_CHUNK_SIZE
from drakegrasp.batch.run.workers import check_workers
from drakegrasp.core.calls import checked_fields
from drakegrasp.core.contact import ContactModel
from drakegrasp.core.deprecation import renamed_keyword
from drakegrasp.core.tolerances import (
    DEFAULT_NUM_GENERATORS,
    DEFAULT_RANK_TOL,
    DEFAULT_TOL,
)
from drakegrasp.core.validation import check_flag, check_num_generators
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "BatchOptions",
    "checked_options",
    "refuse_given_twice",
    "takes_batch_options",
]

F = TypeVar("F", bound=Callable)


@renamed_keyword("model", "contact_model")
@checked_fields("batch option")
@dataclass(frozen=True)
class BatchOptions:
    """Every choice of a batch run besides its arrays, checked once.

    Parameters
    ----------
    contact_model : ContactModel or str, optional
        Contact model of every contact (default hard finger); stored as a
        :class:`~drakegrasp.ContactModel`.  Form closure (LP1) ignores it.
    num_generators : int, optional
        Generators ``n_g >= 3`` of each linearised spatial cone (default 8).
    tol : float, optional
        Closure needs ``d* > tol`` (default 1e-6).
    rank_tol : float, optional
        Relative threshold of the rank tests (default 1e-9).
    metrics : sequence of str, optional
        Metrics to add (:data:`~drakegrasp.batch.inputs.METRICS`); stored as a tuple.
    kernel : {"auto", "numba", "numpy"}, optional
        The LP and ε kernels; ``"auto"`` (default) takes numba when installed,
        decided when the run starts.
    chunk_size : int, optional
        Grasps per chunk; default (None) sized by the engine's memory budget.
    workers : int, optional
        Worker processes; default (None) every available core, but a batch
        of fewer than :data:`~drakegrasp.batch.run.stream.PARALLEL_MIN_WORK`
        contacts (``K N``) then runs in this process.
    progress : bool, optional
        Show a tqdm progress bar.

    Raises
    ------
    InvalidOptionError, InvalidContactError
        A value out of range, naming the option.
    """

    contact_model: ContactModel | str = ContactModel.HARD_FINGER
    num_generators: int = DEFAULT_NUM_GENERATORS
    tol: float = DEFAULT_TOL
    rank_tol: float = DEFAULT_RANK_TOL
    metrics: Sequence[str] = ()
    kernel: str = "auto"
    chunk_size: int | None = DEFAULT_CHUNK_SIZE
    workers: int | None = None
    progress: bool = False

    def __post_init__(self) -> None:
        checked = {
            "contact_model": ContactModel.parse(self.contact_model),
            "num_generators": check_num_generators(self.num_generators),
            "tol": _check_tol("tol", self.tol),
            "rank_tol": _check_tol("rank_tol", self.rank_tol),
            "metrics": check_metrics(self.metrics),
            "chunk_size": None
            if self.chunk_size is None
            else positive_int("chunk_size", self.chunk_size, 1),
            "kernel": check_kernel(self.kernel),
            "workers": check_workers(self.workers),
            "progress": check_flag("progress", self.progress),
        }
        for name, value in checked.items():
            object.__setattr__(self, name, value)

    def replace(self, **changes: Any) -> BatchOptions:
        """A copy with ``changes`` (checked again); unknown names are refused.

        The constructor refuses them (``checked_fields``), naming the closest
        option; ``model=`` (deprecated) reaches it too, which warns and
        renames it.
        """
        return dataclasses.replace(self, **changes)

    def keywords(self) -> dict[str, Any]:
        """The options as keyword arguments of the batch functions."""
        return {name: getattr(self, name) for name in OPTION_NAMES}


OPTION_NAMES: tuple[str, ...] = tuple(f.name for f in fields(BatchOptions))
"""The fields of :class:`BatchOptions`, in order."""

FRICTION_OPTIONS = ("contact_model", "num_generators")
"""The options that only friction programs read (form closure ignores them)."""

_DEFAULT = BatchOptions()


def checked_options(options: Any, where: str) -> BatchOptions:
    """``options`` if it is a :class:`BatchOptions`; refused, naming ``where``."""
    if not isinstance(options, BatchOptions):
        raise InvalidOptionError(
            f"{where}: options must be a drakegrasp.BatchOptions, got "
            f"{type(options).__name__}"
        )
    return options


def refuse_given_twice(names: Sequence[str], given: Sequence[str], where: str) -> None:
    """Refuse options ``names`` of an options object also given as keywords."""
    both = sorted(set(names) & set(given))
    if both:
        raise InvalidOptionError(
            f"{where}: {both} given both as keywords and in options; give "
            "each option one way (options.replace(...) changes a copy)"
        )


def takes_batch_options(function: F) -> F:
    """Let a batch entry point take ``options=BatchOptions(...)``.

    The wrapped function keeps its keywords; ``options`` fills those of them
    that are fields of :class:`BatchOptions`.  Giving an option both ways is
    refused, and so is an option the function has no keyword for, unless it is
    the default (a function without ``mu``, i.e. form closure, also ignores
    the friction options ``contact_model`` and ``num_generators``): a choice is
    never dropped without a word.
    """
    signature = inspect.signature(function)
    names = tuple(n for n in OPTION_NAMES if n in signature.parameters)
    ignored = FRICTION_OPTIONS if "mu" not in signature.parameters else ()
    absent = tuple(n for n in OPTION_NAMES if n not in names and n not in ignored)
    where = f"{function.__qualname__}()"

    @functools.wraps(function)
    def wrapper(*args, options: BatchOptions | None = None, **kwargs):
        if options is None:
            return function(*args, **kwargs)
        checked_options(options, where)
        unused = [n for n in absent if getattr(options, n) != getattr(_DEFAULT, n)]
        if unused:
            raise InvalidOptionError(
                f"{where} does not take {unused}; leave them at their defaults "
                "in options (options.replace(...))"
            )
        refuse_given_twice(names, kwargs, where)
        return function(*args, **kwargs, **{n: getattr(options, n) for n in names})

    option = inspect.Parameter(
        "options", inspect.Parameter.KEYWORD_ONLY, default=None,
        annotation="BatchOptions | None",
    )  # fmt: skip
    params = list(signature.parameters.values())
    at = next(
        (i for i, p in enumerate(params) if p.kind is inspect.Parameter.VAR_KEYWORD),
        len(params),
    )
    wrapper.__signature__ = signature.replace(
        parameters=[*params[:at], option, *params[at:]]
    )
    return wrapper  # type: ignore[return-value]
