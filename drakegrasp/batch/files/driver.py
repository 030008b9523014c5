"""The one file driver: a file of grasps in, a file of verdicts out.

:func:`stream_file` (the ``drakegrasp batch`` command) streams every chunk's
results to the output in memory flat in ``K``; :func:`evaluate_file` does the
same run and also returns the whole :class:`~drakegrasp.batch.BatchClosureResult`.
Both check the output against the input before any grasp is analysed
(:func:`~drakegrasp.batch.files.writer.check_output`), read the grasps with
:func:`~drakegrasp.batch.files.reader.read_grasps`, take the file's optional
arrays as engine options, and place the output atomically.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from pathlib import Path

from drakegrasp.batch.api import (
    BatchClosureResult,
    collect,
    force_chunks,
    form_chunks,
)
from drakegrasp.batch.files.reader import (
    as_path,
    engine_options,
    input_files,
    read_grasps,
)
from drakegrasp.batch.files.writer import (
    BatchSummary,
    check_output,
    format_of,
    placed,
    write_chunks,
)
from drakegrasp.batch.inputs import shape_of
from drakegrasp.batch.options import takes_batch_options
from drakegrasp.batch.run.stream import DEFAULT_CHUNK_SIZE
from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import ContactModel
from drakegrasp.core.deprecation import renamed_keyword
from drakegrasp.core.tolerances import (
    DEFAULT_NUM_GENERATORS,
    DEFAULT_RANK_TOL,
    DEFAULT_TOL,
)
from drakegrasp.core.validation import check_flag, describe, plain_str
from drakegrasp.errors import BatchFileError, InvalidOptionError

__all__ = ["evaluate_file", "stream_file", "write_result"]


def _file_run(
    input_path, output_path, *, kind, mu, contact_model, num_generators,
    torsional_friction, tol, rank_tol, chunk_size, progress, metrics, workers,
    kernel="auto", overwrite,
) -> tuple[Path, int, int, dict, Iterator]:  # fmt: skip
    """Check the output, read the file, validate once: the chunk stream.

    Returns ``(output, K, d, options, chunks)``, ``options`` the validated
    engine options (``tol``, ``metrics``, ...).
    """
    kind = plain_str(kind)
    if type(kind) is not str or kind not in ("force", "form"):
        raise InvalidOptionError(
            f"kind must be 'force' or 'form', got {describe(kind)}"
        )
    overwrite = check_flag("overwrite", overwrite)
    source = as_path("input", input_path)
    output = as_path("output", output_path)
    check_output(output, input_files(source), overwrite=overwrite)
    data = read_grasps(source)
    positions, normals = data["positions"], data["normals"]
    extra = engine_options(
        data, source, kind=kind, mu=mu, torsional_friction=torsional_friction
    )
    K, _, d = shape_of("positions", positions)
    p, b = extra["reference_points"], extra["characteristic_lengths"]
    if kind == "force":
        options, chunks = force_chunks(
            positions, normals, extra["mu"], contact_model, num_generators,
            extra["torsional_friction"], p, b, tol, rank_tol, metrics, kernel,
            chunk_size, progress, workers,
        )  # fmt: skip
    else:
        options, chunks = form_chunks(
            positions, normals, p, b, tol, rank_tol, metrics, kernel, chunk_size,
            progress, workers,
        )  # fmt: skip
    return output, K, d, options, chunks


@checked_call
@renamed_keyword("model", "contact_model")
@takes_batch_options
def evaluate_file(
    input_path: str | os.PathLike,
    output_path: str | os.PathLike,
    *,
    kind: str = "force",
    mu: float | None = None,
    contact_model: ContactModel | str = "hard_finger",
    num_generators: int = DEFAULT_NUM_GENERATORS,
    torsional_friction: float | None = None,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    progress: bool = False,
    metrics: Sequence[str] = (),
    overwrite: bool = False,
) -> BatchClosureResult:
    """Decide closure for every grasp of a file and write the verdicts.

    Parameters
    ----------
    input_path : str or path-like
        ``.npz`` archive of grasps, or a directory of ``.npy`` files (memory-
        mapped: bounded memory for any number of grasps); see the module
        docstring.
    output_path : str or path-like
        ``.npz`` (or ``.parquet`` with pyarrow) file to write; never the input.
    kind : {"force", "form"}, optional
        LP2 (:func:`batch_force_closure`) or LP1 (:func:`batch_form_closure`).
    mu : float, optional
        Friction coefficient for every contact; overrides the file's ``mu``.
        Force closure needs one or the other; form closure ignores both.
    contact_model, num_generators, tol, rank_tol, chunk_size, progress, metrics
        Optional, as in :func:`batch_force_closure`.
    torsional_friction : float, optional
        Overrides the file's ``torsional_friction``.  A soft-finger run needs
        one or the other (an explicit 0 makes the fingers act as hard ones).
    overwrite : bool, optional
        Replace an existing output (default: refuse, before any work).

    Returns
    -------
    BatchClosureResult
        What was written.

    Raises
    ------
    BatchFileError
        Unreadable, damaged or non-``.npz`` input; an output that is the input
        or that exists without ``overwrite``.
    GraspError
        Any invalid grasp or option (see :mod:`drakegrasp.core.validation`).
    """
    output, K, d, options, chunks = _file_run(
        input_path, output_path, kind=kind, mu=mu, contact_model=contact_model,
        num_generators=num_generators, torsional_friction=torsional_friction,
        tol=tol, rank_tol=rank_tol, chunk_size=chunk_size, progress=progress,
        metrics=metrics, workers=None, overwrite=overwrite,
    )  # fmt: skip
    result = collect(K, d, kind, options["tol"], options["metrics"], chunks)
    write_result(result, output, overwrite=overwrite)
    return result


@checked_call
@renamed_keyword("model", "contact_model")
@takes_batch_options
def stream_file(
    input_path: str | os.PathLike,
    output_path: str | os.PathLike,
    *,
    kind: str = "force",
    mu: float | None = None,
    contact_model: str = "hard_finger",
    num_generators: int = DEFAULT_NUM_GENERATORS,
    torsional_friction: float | None = None,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
    chunk_size: int | None = None,
    progress: bool = False,
    metrics=(),
    workers: int | None = None,
    fmt: str | None = None,
    overwrite: bool = False,
) -> BatchSummary:
    """:func:`~drakegrasp.batch.evaluate_file` in memory flat in ``K``.

    Reads the grasps as :func:`~drakegrasp.batch.read_grasps` does (a
    directory of ``.npy`` files is memory-mapped), decides closure chunk by
    chunk on ``workers`` processes, and streams every chunk's results to a
    temporary sibling of ``output_path`` (:func:`write_chunks`) that is renamed
    into place when complete; the results are never held whole.  The output
    rules of :func:`~drakegrasp.batch.evaluate_file` apply (never the input,
    an existing file only with ``overwrite``), checked before any work.

    Returns
    -------
    BatchSummary
        Counts and ``d*`` range of what was written.
    """
    output, K, d, options, chunks = _file_run(
        input_path, output_path, kind=kind, mu=mu, contact_model=contact_model,
        num_generators=num_generators, torsional_friction=torsional_friction,
        tol=tol, rank_tol=rank_tol, chunk_size=chunk_size, progress=progress,
        metrics=metrics, workers=workers, overwrite=overwrite,
    )  # fmt: skip
    fmt = format_of(output, fmt)
    with placed(output, overwrite=check_flag("overwrite", overwrite)) as tmp:
        summary = write_chunks(
            chunks,
            tmp,
            K=K,
            kind=kind,
            tol=float(options["tol"]),
            required_rank=6 if d == 3 else 3,
            fmt=fmt,
            metrics=options["metrics"],
        )
    return summary


@checked_call
def write_result(
    result: BatchClosureResult,
    path: str | os.PathLike,
    *,
    overwrite: bool = False,
) -> Path:
    """Write a batch result to ``.npz`` (or ``.parquet`` if pyarrow is present).

    Parameters
    ----------
    result : BatchClosureResult
    path : str or path-like
        Output file; its suffix (any case) picks the format, and the file is
        written under exactly this name.
    overwrite : bool, optional
        Replace an existing file (default: refuse).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    BatchFileError
        An existing file without ``overwrite``, a bad suffix, a missing
        directory; pyarrow missing for ``.parquet``.
    """
    if not isinstance(result, BatchClosureResult):
        raise BatchFileError(
            f"result must be a BatchClosureResult, got {type(result).__name__}"
        )
    overwrite = check_flag("overwrite", overwrite)
    path = as_path("output", path)
    check_output(path, (), overwrite=overwrite)
    arrays = result.to_arrays()
    K = len(result.d_star)
    with placed(path, overwrite=overwrite) as tmp:
        write_chunks(
            [(slice(0, K), arrays)],
            tmp,
            K=K,
            kind=result.kind,
            tol=result.tol,
            required_rank=result.required_rank,
            fmt=format_of(path),
        )
    return path
