"""Result files out: ``.npz`` or Parquet, written whole or chunk by chunk.

:func:`write_chunks` consumes the ``(slice, arrays)`` stream of
:func:`~drakegrasp.batch.stream_force_closure` and writes it with the writer
of its format (:class:`~drakegrasp.batch.files.npz.NpzWriter`,
:class:`~drakegrasp.batch.files.parquet.ParquetWriter`);
:func:`~drakegrasp.batch.files.driver.write_result` writes a whole result the
same way, as one chunk.  Only the chunk in hand is held, plus a few running
totals for the summary.

Output: the per-grasp arrays of the result (``is_closure``, ``d_star``,
``rank``, ``margin``, ``converged``, force closure's ``normal_certificate``
and the metrics; the same columns for no grasps) plus ``kind``, ``tol`` and
``required_rank``.  The suffix is matched case-insensitively and the file is
written under exactly the name given (``OUT.NPZ`` stays ``OUT.NPZ``).

No data is lost:

* the output is written to a temporary file in the same directory and renamed
  into place (:func:`placed`), so an interrupted or failed run leaves any
  earlier file intact and no partial file behind;
* an output that is the input (the same path, or the same file through a
  symbolic or hard link) is refused (:func:`check_output`);
* an existing output is refused unless ``overwrite=True``
  (``drakegrasp batch --overwrite``), checked before any grasp is analysed.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import tempfile
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drakegrasp.batch.columns import result_arrays
from drakegrasp.batch.files.npz import NpzWriter
from drakegrasp.batch.files.parquet import ParquetWriter
from drakegrasp.batch.files.reader import as_path
from drakegrasp.core.calls import checked_call
from drakegrasp.core.files import unexaminable
from drakegrasp.core.validation import (
    NAME_MAX,
    describe,
    integer_or_none,
    plain_str,
    real_scalar,
)
from drakegrasp.errors import BatchFileError, InvalidOptionError

__all__ = [
    "FORMATS",
    "BatchSummary",
    "check_output",
    "format_of",
    "placed",
    "unwritable",
    "write_chunks",
]

FORMATS = ("npz", "parquet")


@checked_call
@dataclass
class BatchSummary:
    """Running totals of a streamed batch (what a summary line needs).

    Attributes
    ----------
    kind : str
    count, closed, near, not_converged : int
        Grasps, grasps in closure, grasps within ``tol`` of the boundary, LPs
        that did not converge.
    d_min, d_max, d_sum : float
        Smallest, largest and summed ``d*``.
    tol : float
    """

    kind: str
    tol: float
    count: int = 0
    closed: int = 0
    near: int = 0
    not_converged: int = 0
    d_min: float = np.inf
    d_max: float = -np.inf
    d_sum: float = 0.0

    def add(self, arrays: dict[str, np.ndarray]) -> None:
        """Fold one chunk's arrays into the totals."""
        d = arrays["d_star"]
        m = arrays["margin"]
        self.count += int(d.size)
        self.closed += int(arrays["is_closure"].sum())
        self.near += int(np.sum((m > -0.999) & (m < 1.0)))
        self.not_converged += int((~arrays["converged"]).sum())
        if d.size:
            self.d_min = min(self.d_min, float(d.min()))
            self.d_max = max(self.d_max, float(d.max()))
            self.d_sum += float(d.sum())

    def __str__(self) -> str:
        K = self.count
        lines = [
            f"{self.kind} closure of {K} grasps: {self.closed} closed, "
            f"{K - self.closed} not (tol {self.tol:g}, {self.near} within tol of "
            "the boundary)"
        ]
        if K:
            lines.append(
                f"d*: min {self.d_min:.6g}, mean {self.d_sum / K:.6g}, "
                f"max {self.d_max:.6g}"
            )
        if self.not_converged:
            lines.append(f"{self.not_converged} LPs did not converge")
        return "\n".join(lines)


def format_of(path: str | os.PathLike, fmt: str | None = None) -> str:
    """``fmt``, or the format the suffix of ``path`` names (``.npz``/``.parquet``).

    A ``fmt`` that contradicts the suffix is refused, not obeyed: a Parquet
    file called ``.npz`` would fool every reader that trusts the name.
    """
    path = as_path("path", path)
    suffix = path.suffix.lower().lstrip(".")
    if fmt is not None:
        fmt = plain_str(fmt)
        if type(fmt) is not str or fmt not in FORMATS:
            raise InvalidOptionError(
                f"format must be one of {', '.join(FORMATS)}, got {describe(fmt)}"
            )
        if suffix in FORMATS and suffix != fmt:
            raise InvalidOptionError(
                f"output file {str(path)!r} ends in .{suffix} but the format is "
                f"{fmt!r} (--format {fmt}); name it .{fmt} or leave the format out"
            )
        return fmt
    if suffix not in FORMATS:
        raise InvalidOptionError(
            f"output file {str(path)!r} must end in .npz or .parquet (or pass "
            "format='npz' / 'parquet')"
        )
    return suffix


def check_output(
    output: Path,
    inputs: Sequence[Path],
    *,
    overwrite: bool,
    remedy: str = "pass overwrite=True (drakegrasp batch --overwrite)",
) -> tuple[Path, str]:
    """Refuse an output that is an input or exists (unless overwrite); its suffix.

    ``remedy`` completes the message that refuses an existing output ("...
    exists; {remedy} to replace it"): the caller's own way to allow it.
    """
    suffix = output.suffix.lower()
    if suffix not in (".npz", ".parquet"):
        raise BatchFileError(
            f"output file {str(output)!r} must end in .npz (or .parquet with pyarrow)"
        )
    # pathlib's exists() and is_dir() raise PermissionError inside a folder
    # this process may not search: such a path is refused by name first
    for what, path in (("output file", output), *(("input", p) for p in inputs)):
        why = unexaminable(path)
        if why:
            raise BatchFileError(f"{what} {str(path)!r} {why}")
    for source in inputs:
        same = output.resolve() == source.resolve()
        if not same and output.exists() and source.exists():
            same = os.path.samefile(output, source)
        if same:
            raise BatchFileError(
                f"output file {str(output)!r} is the input file {str(source)!r}; "
                "writing the results would destroy the grasps: choose another "
                "output"
            )
    if output.is_dir():
        raise BatchFileError(f"output {str(output)!r} is a directory, not a file")
    if output.exists() and not overwrite:
        raise BatchFileError(
            f"output file {str(output)!r} exists; {remedy} to replace it"
        )
    if not output.parent.is_dir():
        what = "is not a directory" if output.parent.exists() else "does not exist"
        raise BatchFileError(f"output directory {str(output.parent)!r} {what}")
    why = unwritable(output.parent)
    if why:
        raise BatchFileError(f"output directory {str(output.parent)!r}: {why}")
    return output, suffix


def unwritable(folder: Path) -> str:
    """Why no file can be written in ``folder``, or "" (a file made and removed).

    Checked before a long run, so that it is refused up front rather than
    after the work (``/proc``, a read-only mount, no permission).
    """
    try:
        handle, probe = tempfile.mkstemp(dir=folder, prefix=".drakegrasp-probe-")
    except OSError as e:
        return f"no file can be written there ({e.strerror or e})"
    os.close(handle)
    with contextlib.suppress(OSError):
        os.unlink(probe)
    return ""


def _link_or_rename(tmp: str, path: Path) -> None:
    """Move tmp to path without replacing a file that appeared meanwhile."""
    try:
        os.link(tmp, path)  # atomic, and fails if path exists
    except FileExistsError:
        raise
    except OSError:  # a file system without hard links
        if path.exists():
            raise FileExistsError(path) from None
        os.replace(tmp, path)
        return
    os.unlink(tmp)


def _new_sibling(path: Path) -> str:
    """Create an empty ``.NAME.XXXX.partial`` beside ``path``; return its name.

    Like ``tempfile.mkstemp`` (exclusive creation, a random name) but with the
    mode an ordinary file gets, 0666 less the umask (0644 under umask 022):
    mkstemp's 0600 would make the results unreadable to the user's group.
    """
    # The name is cut so the temporary one fits where the output's does: a
    # name of 234-255 bytes (the usual limit) gained 22 and could not be made.
    name = path.name
    while name and len(os.fsencode(name)) > NAME_MAX - len(".0123456789ab.partial") - 1:
        name = name[:-1]
    for _ in range(100):
        tmp = path.parent / f".{name}.{secrets.token_hex(6)}.partial"
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            continue
        except OSError as err:  # the user's path, not our temporary name
            raise BatchFileError(
                f"cannot write {str(path)!r}: {err.strerror or err} (the output "
                f"is written beside it first, in {str(path.parent)!r})"
            ) from None
        os.close(fd)
        return str(tmp)
    raise BatchFileError(  # pragma: no cover - 100 collisions of 48 random bits
        f"could not create a temporary file beside {str(path)!r}"
    )


@contextlib.contextmanager
def placed(path: Path, *, overwrite: bool) -> Iterator[str]:
    """A temporary sibling of ``path`` to write; renamed onto ``path`` on success.

    The file is synced before the rename.  Without ``overwrite``, a file that
    appeared at ``path`` meanwhile is kept and the call fails; on any failure
    the temporary file is removed and an earlier ``path`` is untouched.
    """
    tmp = _new_sibling(path)
    try:
        yield tmp
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        if overwrite:
            os.replace(tmp, path)
        else:
            _link_or_rename(tmp, path)
    except FileExistsError:
        raise BatchFileError(
            f"output file {str(path)!r} appeared while writing; pass "
            "overwrite=True to replace it"
        ) from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


@checked_call
def write_chunks(
    chunks: Iterable[tuple[slice, dict[str, np.ndarray]]],
    path: str | os.PathLike,
    *,
    K: int,
    kind: str,
    tol: float,
    required_rank: int,
    fmt: str | None = None,
    metrics: Sequence[str] = (),
) -> BatchSummary:
    """Write a stream of chunk results to ``path``; return the summary.

    Parameters
    ----------
    chunks : iterable of (slice, dict of str to (k,) array)
        Consecutive chunks covering ``0 … K`` in order, as
        :func:`~drakegrasp.batch.stream_force_closure` yields them.
    path : str or path-like
        The file to write (replaced if it exists).
    K : int
        Total number of grasps.
    kind, tol, required_rank
        Stored beside the arrays.
    fmt : {"npz", "parquet"}, optional
        Default: from the suffix of ``path``.
    metrics : sequence of str, optional
        The run's metrics (default none), for a file of no grasps (``K = 0``),
        which then holds the columns a run of ``K > 0`` would (those that
        ``drakegrasp.batch.columns.result_arrays`` lists: ``normal_certificate``
        for force closure, and the metrics).

    Returns
    -------
    BatchSummary

    Raises
    ------
    BatchFileError
        For a ``path`` that is not a file path or cannot be written, also
        part-way (a full disk): the file there before is left as it was.
    InvalidOptionError
        For a ``K``, ``kind``, ``tol`` or ``required_rank`` of the wrong kind,
        or chunks that are not ``(slice, arrays)`` pairs covering ``0 … K`` in
        order.
    """
    path = as_path("path", path)
    fmt = format_of(path, fmt)
    kind = _check_meta(K, kind, tol, required_rank)
    try:
        items = iter(chunks)
    except TypeError:
        raise InvalidOptionError(
            "chunks must be an iterable of (slice, arrays) pairs, got "
            + type(chunks).__name__
        ) from None
    meta = {"kind": kind, "tol": tol, "required_rank": required_rank}
    writer = _on_disk(path, NpzWriter if fmt == "npz" else ParquetWriter, path, K, meta)
    summary = BatchSummary(kind=kind, tol=tol)
    expected = 0
    written = False
    try:
        for item in items:
            sl, arrays = _chunk(item)
            if sl.start != expected:
                raise InvalidOptionError(
                    f"chunk {sl} out of order (expected {expected})"
                )
            expected = sl.stop
            _on_disk(path, writer.write, arrays)
            summary.add(arrays)
            written = True
        if expected != K:
            raise InvalidOptionError(f"the chunks covered {expected} of {K} grasps")
        if not written:  # no grasps: the columns of any K, with no rows
            out, out_metrics = result_arrays(0, kind, metrics)
            _on_disk(path, writer.write, {**out, **out_metrics})
        _on_disk(path, writer.close)
    except BaseException:
        writer.abort()
        raise
    return summary


def _on_disk(path: Path, call, *args):
    """``call(*args)``, a file system error named as the output's.

    The writer's own steps only: an ``OSError`` raised by the chunks (an
    input read as it streams) is the input's, and passes as it is.
    """
    try:
        return call(*args)
    except OSError as err:
        raise BatchFileError(
            f"cannot write {str(path)!r}: {err.strerror or err}"
        ) from None


def _check_meta(K, kind, tol, required_rank) -> str:
    """Refuse what :func:`write_chunks` would store wrongly beside the arrays.

    Returns ``kind`` as the plain ``str`` it holds.
    """
    n = integer_or_none(K)
    if n is None or n < 0:
        raise InvalidOptionError(f"K must be an integer >= 0, got {describe(K)}")
    kind = plain_str(kind)
    if type(kind) is not str or kind not in ("force", "form"):
        raise InvalidOptionError(
            f"kind must be 'force' or 'form', got {describe(kind)}"
        )
    real_scalar("tol", tol)
    if integer_or_none(required_rank) is None:
        raise InvalidOptionError(
            f"required_rank must be an integer, got {describe(required_rank)}"
        )
    return kind


def _chunk(item) -> tuple[slice, dict]:
    """One ``(slice, arrays)`` item of :func:`write_chunks`'s stream, checked."""
    if (
        not isinstance(item, tuple | list)
        or len(item) != 2
        or not isinstance(item[0], slice)
        or not isinstance(item[1], Mapping)
    ):
        raise InvalidOptionError(
            "each chunk must be a pair (slice, dict of result arrays), as "
            f"stream_force_closure yields them; got {describe(item)}"
        )
    return item
