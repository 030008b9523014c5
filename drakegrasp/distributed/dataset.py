"""A Parquet dataset of one job: its manifest, its shards, reading it back.

:func:`~drakegrasp.distributed.evaluate_on_cluster` with ``output_dir`` writes
one shard ``part-NNNNN.parquet`` per partition.  A restart must resume only
shards of the *same* job, so the directory also holds a manifest,
``_drakegrasp-job.json``: the job's identity (a SHA-256 fingerprint of every
input array and option, and the partition layout) and the number of rows of
each shard.  Each shard carries the job's identity in its Parquet schema
metadata too, so a shard copied from another job is told apart even under the
right name.

* :func:`prepare_dataset` opens a directory for a job: a new or same-job
  directory is kept; a directory holding another job's manifest or shards
  without a manifest is refused, or with ``overwrite`` emptied of them.
* :func:`shard_is_done` says whether a shard is a complete shard of this job
  (readable, its identity, its number of rows); anything else, a truncated
  or foreign file, is computed again.
* :func:`read_dataset` reads the shards in partition order (by number, so
  ``part-100000`` follows ``part-99999``) and raises
  :class:`~drakegrasp.BatchFileError` for a missing, damaged or foreign shard.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import reprlib
from pathlib import Path

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.files import MISSING, not_a_file, unexaminable, unlistable
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import check_flag, path_text
from drakegrasp.errors import BatchFileError

__all__ = [
    "MANIFEST",
    "job_manifest",
    "prepare_dataset",
    "read_dataset",
    "remove_orphan_temporaries",
    "shard_is_done",
    "shard_path",
    "write_shard",
]

MANIFEST = "_drakegrasp-job.json"
"""The manifest's file name inside a dataset directory (Parquet readers such as
``pandas.read_parquet`` skip names starting with ``_``)."""

_JOB_KEY = b"drakegrasp_job"
_SHARD = re.compile(r"part-(\d+)\.parquet")
_FORMAT = 1  # the manifest's layout version
_HASH_BLOCK = 1 << 24  # bytes hashed at a time (memory-mapped inputs stay mapped)


def shard_path(output_dir: Path, j: int) -> Path:
    """The shard of partition ``j`` (``part-00007.parquet``)."""
    return output_dir / f"part-{j:05d}.parquet"


def _shards(output_dir: Path) -> dict[int, Path]:
    """The shard files of a directory by partition number."""
    found = {}
    for p in output_dir.iterdir():
        m = _SHARD.fullmatch(p.name)
        if m:
            found[int(m.group(1))] = p
    return found


def _hash_array(h, name: str, value) -> None:
    """Fold one input (name, dtype, shape, bytes) into the hash ``h``."""
    if hasattr(value, "dask"):  # a Dask array: its graph's deterministic token
        from dask.base import tokenize

        h.update(f"{name}:dask:{value.dtype}:{value.shape}:".encode())
        h.update(tokenize(value).encode())
        return
    a = np.asarray(value)
    h.update(f"{name}:{a.dtype.str}:{a.shape}:".encode())
    flat = a.reshape(-1) if a.flags.c_contiguous else np.ascontiguousarray(a).ravel()
    step = max(1, _HASH_BLOCK // max(1, a.itemsize))
    for s in range(0, flat.size, step):
        h.update(flat[s : s + step].tobytes())


def job_manifest(*, kind: str, shape, arrays: dict, options: dict,
                 step: int, chunk_size: int, rows: list[int]) -> dict:  # fmt: skip
    """The manifest of a job: what identifies it, and its shards' sizes.

    Parameters
    ----------
    kind : {"force", "form"}
    shape : (K, N, d)
    arrays : dict of str to array-like
        ``positions``, ``normals`` and the per-grasp options (``mu`` ...).
    options : dict
        The engine's other options (``contact_model``, ``tol``, ...).
    step, chunk_size : int
        Grasps per partition and per engine chunk.
    rows : list of int
        Grasps in each partition.
    """
    h = hashlib.sha256()
    for name in sorted(arrays):
        if arrays[name] is not None:
            _hash_array(h, name, arrays[name])
    settings = {
        "kind": kind,
        "shape": [int(n) for n in shape],
        "step": int(step),
        "chunk_size": int(chunk_size),
        "options": {k: jsonable(_plain(v)) for k, v in sorted(options.items())},
    }
    h.update(json.dumps(settings, sort_keys=True, default=str).encode())
    return {"format": _FORMAT, "job": h.hexdigest(), **settings,
            "rows": [int(r) for r in rows]}  # fmt: skip


def _plain(value):
    """An option as JSON would hold it (enums by value)."""
    return getattr(value, "value", value)


def _read_manifest(output_dir: Path) -> dict | None:
    """The manifest of ``output_dir``: None if there is none, {} if damaged."""
    return _manifest(output_dir)[0]


def _manifest(output_dir: Path) -> tuple[dict | None, str]:
    """The manifest (None: none; {}: damaged) and why it is damaged ("" if not).

    Damaged: not a regular file (never opened: a pipe would block), not
    readable, not a JSON object, or a key the readers use (``job``, a string;
    ``rows``, a list of row counts) missing or of the wrong type.
    """
    path = output_dir / MANIFEST
    why = not_a_file(path)
    if why == MISSING:
        return None, ""
    if why:
        return {}, why
    try:
        data = json.loads(path.read_text())
    except OSError as err:
        return {}, f"cannot be read ({err.strerror or err})"
    except ValueError as err:  # UnicodeDecodeError too
        return {}, f"is not valid JSON ({err})"
    if not isinstance(data, dict):
        return {}, f"holds a JSON {type(data).__name__}, not a JSON object"
    job, rows = data.get("job"), data.get("rows")
    if not isinstance(job, str):
        return {}, f"has 'job' {reprlib.repr(job)}, not a string"
    if not isinstance(rows, list):
        return {}, f"has 'rows' {reprlib.repr(rows)}, not a list of row counts"
    for j, r in enumerate(rows):
        if type(r) is not int or r < 0:
            return {}, f"has 'rows'[{j}] {reprlib.repr(r)}, not a row count"
    return data, ""


def _differences(old: dict, new: dict) -> str:
    if not old:
        return "an unreadable manifest"
    keys = ("kind", "shape", "step", "chunk_size", "options")
    changed = [k for k in keys if old.get(k) != new.get(k)]
    if not changed:
        changed = ["the input arrays (positions, normals, mu, ...)"]
    return "another job (differs in " + ", ".join(changed) + ")"


def _check_creatable(output_dir: Path) -> None:
    """Refuse a directory that ``mkdir(parents=True)`` could not make.

    Its nearest existing ancestor must be a directory this process may write
    in, and the path itself not a dangling symbolic link (which ``exists()``
    calls absent).
    """
    if output_dir.is_symlink():
        raise BatchFileError(
            f"output {str(output_dir)!r} is a symbolic link to nothing; name a "
            "directory"
        )
    parent = output_dir.parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise BatchFileError(
            f"cannot create the output directory {str(output_dir)!r}: "
            f"{str(parent)!r} is not a directory"
        )
    if not os.access(parent, os.W_OK | os.X_OK):
        raise BatchFileError(
            f"cannot create the output directory {str(output_dir)!r}: "
            f"{str(parent)!r} is not writable"
        )


def _check_examinable(output_dir: Path) -> None:
    """Refuse a dataset directory whose existence or names cannot be read.

    Inside a folder this process may not search, pathlib's ``exists()`` and
    ``is_dir()`` raised a bare ``PermissionError``, and ``iterdir`` in one it
    may not read.
    """
    why = unexaminable(output_dir)
    if not why and output_dir.is_dir():
        why = unlistable(output_dir)  # iterdir raised PermissionError
    if why:
        raise BatchFileError(f"dataset directory {str(output_dir)!r} {why}")


def prepare_dataset(
    output_dir, manifest: dict, *, overwrite: bool, create: bool = True
) -> Path:
    """Open ``output_dir`` for the job of ``manifest``; return it as a Path.

    A new directory, or one holding this job's manifest, is kept as it is
    (its complete shards are resumed).  One holding another job's manifest,
    or shards without a manifest, is refused, or with ``overwrite`` its
    shards are removed and the new manifest written.  With ``create=False``
    only the refusals are checked: nothing is created, removed or written
    (a run checks its output before it connects, and opens it after).

    Raises
    ------
    BatchFileError
        The directory is a file, or holds another job without ``overwrite``.
    """
    overwrite = check_flag("overwrite", overwrite)
    output_dir = Path(path_text("output_dir", output_dir, error=BatchFileError))
    _check_examinable(output_dir)
    if output_dir.exists() and not output_dir.is_dir():
        raise BatchFileError(
            f"output {str(output_dir)!r} is a file; a cluster run writes a "
            "dataset directory of Parquet shards: name a directory"
        )
    if not create and not output_dir.exists():
        _check_creatable(output_dir)
        return output_dir
    if create:
        output_dir.mkdir(parents=True, exist_ok=True)
    old = _read_manifest(output_dir)
    if old is not None and old.get("job") == manifest["job"]:
        return output_dir
    shards = _shards(output_dir)
    if old is not None or shards:
        what = (
            _differences(old, manifest)
            if old is not None
            else f"{len(shards)} shard(s) of an unknown job (no {MANIFEST})"
        )
        if not overwrite:
            raise BatchFileError(
                f"output directory {str(output_dir)!r} holds {what}; pass "
                "overwrite=True (drakegrasp batch --overwrite) to replace its "
                "shards, or choose another directory"
            )
        if create:
            for p in shards.values():
                p.unlink()
            for p in output_dir.glob(".part-*.tmp"):
                p.unlink()
    if not create:
        return output_dir
    tmp = output_dir / f".{MANIFEST}.{os.getpid()}.tmp"
    tmp.write_text(json.dumps(manifest, indent=1, sort_keys=True))
    os.replace(tmp, output_dir / MANIFEST)
    return output_dir


def write_shard(shard: Path, arrays: dict[str, np.ndarray], job: str) -> str:
    """Write a partition's arrays as a Parquet shard tagged with ``job``.

    Written to a temporary sibling and renamed into place, so the shard
    appears only when complete.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.table(arrays).replace_schema_metadata({_JOB_KEY: job.encode()})
    tmp = shard.with_name(f".{shard.name}.{os.getpid()}.tmp")
    try:
        pq.write_table(table, tmp)
        os.replace(tmp, shard)
    finally:
        if tmp.exists():
            tmp.unlink()
    return str(shard)


def remove_orphan_temporaries(output_dir: Path, indices) -> int:
    """Remove the half-written files left beside finished shards.

    A worker killed while writing partition ``j`` leaves its temporary
    ``.part-0000j.parquet.<pid>.tmp``; the partition is then recomputed and
    written by another worker, so once shard ``j`` is complete any such file
    is an orphan.  Only the temporaries of ``indices`` (partitions whose
    shards are complete) are touched, never another partition's.

    Returns
    -------
    int
        How many files were removed.
    """
    removed = 0
    for j in indices:
        shard = shard_path(output_dir, j)
        for p in output_dir.glob(f".{shard.name}.*.tmp"):
            try:
                p.unlink()
            except FileNotFoundError:  # its writer finished or removed it
                continue
            removed += 1
    return removed


def _shard_problem(shard: Path, job: str | None, rows: int | None) -> str | None:
    """Why ``shard`` is not a complete shard of ``job`` with ``rows`` rows."""
    import pyarrow.parquet as pq

    why = not_a_file(shard)
    if why:
        return why
    try:
        meta = pq.read_metadata(shard)
    except (OSError, ValueError) as err:  # pyarrow's errors derive from these
        return f"is unreadable or truncated ({type(err).__name__}: {err})"
    if job is not None:
        tag = (meta.schema.to_arrow_schema().metadata or {}).get(_JOB_KEY)
        if tag != job.encode():
            return "belongs to another job"
    if rows is not None and meta.num_rows != rows:
        return f"holds {meta.num_rows} rows where this job's partition has {rows}"
    return None


def shard_is_done(shard: Path, job: str, rows: int) -> bool:
    """Whether ``shard`` is a complete shard of ``job`` with ``rows`` rows."""
    return shard.exists() and _shard_problem(shard, job, rows) is None


@checked_call
def read_dataset(output_dir: str | os.PathLike) -> dict[str, np.ndarray]:
    """The arrays of a dataset of :func:`evaluate_on_cluster`, shards in order.

    Parameters
    ----------
    output_dir : path
        A dataset directory.  With its manifest, every partition's shard must
        be present, of the manifest's job and size; without one (a dataset of
        an earlier version), the shards found are read in order.

    Returns
    -------
    dict of str to (K,) array
        The result arrays (``is_closure``, ``d_star``, ...), empty for a
        directory without shards.

    Raises
    ------
    BatchFileError
        No such directory; a missing, damaged, truncated or foreign shard.
    """
    import pyarrow.parquet as pq

    output_dir = Path(
        path_text("output_dir", output_dir, error=BatchFileError,
                  must="a dataset directory's path (a str or an os.PathLike)")
    )  # fmt: skip
    _check_examinable(output_dir)
    if not output_dir.is_dir():
        what = "is not a directory" if output_dir.exists() else "does not exist"
        raise BatchFileError(f"dataset directory {str(output_dir)!r} {what}")
    shards = _shards(output_dir)
    manifest, damage = _manifest(output_dir)
    if damage:
        raise BatchFileError(
            f"dataset {str(output_dir)!r} has a damaged {MANIFEST} (it {damage}); "
            "run the job again with overwrite"
        )
    job, expected = None, None
    if manifest is not None:
        job, expected = manifest["job"], manifest["rows"]
        missing = [j for j in range(len(expected)) if j not in shards]
        extra = sorted(set(shards) - set(range(len(expected))))
        if missing or extra:
            bad = missing or extra
            raise BatchFileError(
                f"dataset {str(output_dir)!r} is incomplete: shard(s) "
                f"{bad[:5]} {'missing' if missing else 'not of its job'}; run the "
                "job again to finish it"
            )
    tables = []
    for j in sorted(shards):
        problem = _shard_problem(
            shards[j], job, None if expected is None else expected[j]
        )
        if problem is not None:
            raise BatchFileError(
                f"shard {str(shards[j])!r} {problem}; run the job again to replace it"
            )
        try:
            tables.append(pq.read_table(shards[j]))
        except (OSError, ValueError) as err:
            raise BatchFileError(
                f"shard {str(shards[j])!r} cannot be read ({err}); run the job "
                "again to replace it"
            ) from None
    if not tables:
        return {}
    names = tables[0].column_names
    for j, t in zip(sorted(shards), tables, strict=True):
        if t.column_names != names:
            raise BatchFileError(
                f"shard {str(shards[j])!r} has columns {t.column_names}, the "
                f"first shard {names}: they are not of one job"
            )
    return {
        name: np.concatenate([t.column(name).to_numpy() for t in tables])
        for name in names
    }
