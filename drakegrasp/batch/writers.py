"""Stream batch results to a file chunk by chunk, in memory flat in ``K``.

:func:`write_chunks` consumes the ``(slice, arrays)`` stream of
:func:`~drakegrasp.batch.stream_force_closure` and writes it to the path it is
given (choosing a temporary name and renaming it into place is the caller's
business, see :mod:`drakegrasp.batch.io`):

* ``.npz``: each result array is appended, chunk by chunk, to its own ``.npy``
  file in a scratch directory beside the output (the header is written first,
  since ``K`` is known); the files are then copied block by block into an
  uncompressed zip archive that ``numpy.load`` reads like
  ``numpy.savez``'s, with the 0-d arrays ``kind``, ``tol`` and
  ``required_rank``.
* ``.parquet`` (optional extra ``parquet``: pyarrow): one row group per chunk,
  one column per array, ``kind``/``tol``/``required_rank`` in the schema
  metadata; ``pandas.read_parquet`` loads it directly.

Only the chunk in hand is held, plus a few running totals for the summary.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import zipfile
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drakegrasp.core.tolerances import DEFAULT_RANK_TOL, DEFAULT_TOL
from drakegrasp.errors import InvalidOptionError

__all__ = ["FORMATS", "BatchSummary", "format_of", "stream_file", "write_chunks"]

FORMATS = ("npz", "parquet")


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
    """``fmt``, or the format the suffix of ``path`` names (``.npz``/``.parquet``)."""
    if fmt is not None:
        if fmt not in FORMATS:
            raise InvalidOptionError(
                f"format must be one of {', '.join(FORMATS)}, got {fmt!r}"
            )
        return fmt
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in FORMATS:
        raise InvalidOptionError(
            f"output file {str(path)!r} must end in .npz or .parquet (or pass "
            "format='npz' / 'parquet')"
        )
    return suffix


class _NpzWriter:
    def __init__(self, path: Path, K: int, meta: dict):
        self.path, self.K, self.meta = path, K, meta
        self.scratch = Path(tempfile.mkdtemp(prefix=".batch-", dir=path.parent))
        self.files: dict[str, object] = {}
        self.names: list[str] = []

    def write(self, arrays: dict[str, np.ndarray]) -> None:
        for name, a in arrays.items():
            if name not in self.files:
                f = open(self.scratch / f"{name}.npy", "wb")  # noqa: SIM115
                header = {"descr": np.lib.format.dtype_to_descr(a.dtype),
                          "fortran_order": False, "shape": (self.K,)}  # fmt: skip
                np.lib.format.write_array_header_1_0(f, header)
                self.files[name] = f
                self.names.append(name)
            self.files[name].write(np.ascontiguousarray(a).tobytes())

    def close(self) -> None:
        for f in self.files.values():
            f.close()
        with zipfile.ZipFile(self.path, "w", zipfile.ZIP_STORED, allowZip64=True) as z:
            for key, value in self.meta.items():
                tmp = self.scratch / f"{key}.npy"
                np.save(tmp, np.array(value))
                z.write(tmp, f"{key}.npy")
            for name in self.names:
                z.write(self.scratch / f"{name}.npy", f"{name}.npy")
        shutil.rmtree(self.scratch, ignore_errors=True)

    def abort(self) -> None:
        for f in self.files.values():
            f.close()
        shutil.rmtree(self.scratch, ignore_errors=True)


class _ParquetWriter:
    def __init__(self, path: Path, K: int, meta: dict):
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError as exc:
            raise InvalidOptionError(
                "writing .parquet needs the optional package pyarrow "
                "(pip install drakegrasp[parquet]); write .npz instead"
            ) from exc
        self.pa, self.pq, self.path = pa, pq, path
        self.meta = {k: repr(v) if isinstance(v, float) else str(v)
                     for k, v in meta.items()}  # fmt: skip
        self.writer = None

    def write(self, arrays: dict[str, np.ndarray]) -> None:
        table = self.pa.table(dict(arrays))
        if self.writer is None:
            schema = table.schema.with_metadata(self.meta)
            self.writer = self.pq.ParquetWriter(self.path, schema)
        self.writer.write_table(table.replace_schema_metadata(self.meta))

    def close(self) -> None:
        if self.writer is None:  # no grasps: an empty table with the metadata
            self.pq.write_table(self.pa.table({}).replace_schema_metadata(self.meta),
                                self.path)  # fmt: skip
        else:
            self.writer.close()

    def abort(self) -> None:
        if self.writer is not None:
            self.writer.close()


def write_chunks(
    chunks: Iterable[tuple[slice, dict[str, np.ndarray]]],
    path: str | os.PathLike,
    *,
    K: int,
    kind: str,
    tol: float,
    required_rank: int,
    fmt: str | None = None,
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

    Returns
    -------
    BatchSummary
    """
    path = Path(path)
    fmt = format_of(path, fmt)
    meta = {"kind": kind, "tol": tol, "required_rank": required_rank}
    writer = (_NpzWriter if fmt == "npz" else _ParquetWriter)(path, K, meta)
    summary = BatchSummary(kind=kind, tol=tol)
    expected = 0
    try:
        for sl, arrays in chunks:
            if sl.start != expected:
                raise ValueError(f"chunk {sl} out of order (expected {expected})")
            expected = sl.stop
            writer.write(arrays)
            summary.add(arrays)
        if expected != K:
            raise ValueError(f"the chunks covered {expected} of {K} grasps")
        if K == 0:
            writer.write(
                {
                    "is_closure": np.zeros(0, dtype=bool),
                    "d_star": np.zeros(0),
                    "rank": np.zeros(0, dtype=int),
                    "margin": np.zeros(0),
                    "converged": np.zeros(0, dtype=bool),
                }
            )
        writer.close()
    except BaseException:
        writer.abort()
        raise
    return summary


def stream_file(
    input_path: str | os.PathLike,
    output_path: str | os.PathLike,
    *,
    kind: str = "force",
    mu: float | None = None,
    model: str = "hard_finger",
    num_generators: int = 8,
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
    import drakegrasp.batch.io as io
    from drakegrasp.batch.engine import stream_force_closure, stream_form_closure
    from drakegrasp.core.validation import check_flag

    overwrite = check_flag("overwrite", overwrite)
    source = io._as_path("input", input_path)
    inputs = [source, *(sorted(source.glob("*.npy")) if source.is_dir() else [])]
    output, _ = io._check_output(
        io._as_path("output", output_path), inputs, overwrite=overwrite
    )
    fmt = format_of(output, fmt)
    data = io.read_grasps(source)
    positions, normals = data["positions"], data["normals"]
    common = {
        "chunk_size": chunk_size,
        "progress": progress,
        "metrics": metrics,
        "workers": workers,
    }
    common.update(io._file_options(data, tol=tol, rank_tol=rank_tol))
    if kind == "force":
        chunks = stream_force_closure(
            positions,
            normals,
            io._friction_of(data, input_path, mu),
            model=model,
            num_generators=num_generators,
            torsional_friction=io._torsion_of(data, torsional_friction),
            **common,
        )
    elif kind == "form":
        chunks = stream_form_closure(positions, normals, **common)
    else:
        raise InvalidOptionError(f"kind must be 'force' or 'form', got {kind!r}")
    d = np.shape(positions)[-1]
    fd, tmp = tempfile.mkstemp(
        dir=output.parent, prefix=f".{output.name}.", suffix=".partial"
    )
    os.close(fd)
    try:
        summary = write_chunks(
            chunks,
            tmp,
            K=int(np.shape(positions)[0]),
            kind=kind,
            tol=float(tol),
            required_rank=6 if d == 3 else 3,
            fmt=fmt,
        )
        if overwrite:
            os.replace(tmp, output)
        else:
            io._link_or_rename(tmp, output)
    except FileExistsError:
        raise io.BatchFileError(
            f"output file {str(output)!r} appeared while writing; pass "
            "overwrite=True to replace it"
        ) from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return summary
