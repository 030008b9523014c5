"""The batch engine on a Dask cluster: partitions of grasps, Parquet shards, restarts.

The outer ring: the engine (:mod:`drakegrasp.batch`) knows nothing of Dask.
Here the grasps are cut into *partitions*, each a whole number of the engine's
chunks and starting on a chunk boundary, so every chunk is computed exactly as
the local engine computes it and the results are bitwise the same.  Each
partition runs the engine in one Dask task (``workers=1`` inside it: Dask's
workers are the parallelism) and either returns its arrays or writes them as
one Parquet shard ``part-NNNNN.parquet`` of a dataset directory, by writing a
temporary file and renaming it into place.  A shard therefore exists only when
complete: a restarted run skips the shards it finds, and a task that Dask
retries after a worker died rewrites the same shard, so nothing is lost or
duplicated.

Plant-based evaluation on a cluster is the other half of this folder
(:mod:`drakegrasp.distributed.plant_side`).

Needs the optional extra ``dask`` (``dask[distributed]``, and ``pyarrow`` for
the Parquet shards).  See ``docs/distributed.md`` for pointing it at a cluster.
"""

from __future__ import annotations

import os
import uuid
from pathlib import Path

import numpy as np

from drakegrasp.batch.api import collect, stream_force_closure, stream_form_closure
from drakegrasp.batch.inputs import check_metrics
from drakegrasp.batch.run.stream import chunk_size_for
from drakegrasp.core.tolerances import DEFAULT_TOL
from drakegrasp.core.validation import check_num_generators
from drakegrasp.distributed.client import client_for
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "evaluate_on_cluster",
    "read_dataset",
    "stream_file_on_cluster",
]

_ARRAY_OPTIONS = ("mu", "torsional_friction", "reference_points",
                  "characteristic_lengths")  # fmt: skip


def _slice_option(value, sl: slice, K: int):
    """A per-grasp option sliced to a partition; scalars and rows pass through."""
    shape = np.shape(value)
    if value is None or shape == () or shape[0] != K:
        return value
    return np.asarray(value[sl])


def _partition(kind, positions, normals, arrays, options, shard, chunk_size):
    """One partition through the local engine; write its shard or return arrays."""
    run = stream_force_closure if kind == "force" else stream_form_closure
    args = (positions, normals) + ((arrays.pop("mu"),) if kind == "force" else ())
    parts = [a for _, a in run(*args, **arrays, **options, chunk_size=chunk_size,
                               workers=1)]  # fmt: skip
    names = parts[0].keys() if parts else ()
    out = {n: np.concatenate([p[n] for p in parts]) for n in names}
    if shard is None:
        return out
    import pyarrow as pa
    import pyarrow.parquet as pq

    shard = Path(shard)
    tmp = shard.with_name(f".{shard.name}.{os.getpid()}.tmp")
    pq.write_table(pa.table(out), tmp)
    os.replace(tmp, shard)  # the shard appears only when complete
    return str(shard)


def evaluate_on_cluster(
    client,
    positions,
    normals,
    mu=None,
    *,
    kind: str = "force",
    output_dir: str | os.PathLike | None = None,
    partition_chunks: int = 4,
    chunk_size: int | None = None,
    **options,
):
    """Decide closure for ``K`` grasps on a Dask cluster.

    Parameters
    ----------
    client : distributed.Client or str
        A client, or a scheduler address such as ``"tcp://host:8786"``.
    positions, normals : (K, N, d) array-like or dask.array.Array
        As in :func:`drakegrasp.batch_force_closure`; a Dask array is cut
        into the partitions below and each block is computed on the cluster.
    mu : float or array, optional
        Friction (force closure); per-grasp arrays are cut like ``positions``.
    kind : {"force", "form"}, optional
    output_dir : path, optional
        Write one Parquet shard per partition to this directory (a dataset
        that ``pandas.read_parquet`` or :func:`read_dataset` reads) instead of
        returning the results; shards already present are skipped.
    partition_chunks : int, optional
        Engine chunks per partition (default 4).
    chunk_size : int, optional
        The engine's chunk size (default: sized by bytes, as locally).
    **options
        The other keyword options of :func:`drakegrasp.batch_force_closure`
        (or :func:`~drakegrasp.batch_form_closure`), e.g. ``model``, ``tol``,
        ``torsional_friction``, ``reference_points``.

    Returns
    -------
    BatchClosureResult or list of str
        The result, bitwise equal to the local engine's; or, with
        ``output_dir``, the shard paths in order.
    """
    if kind not in ("force", "form"):
        raise InvalidOptionError(f"kind must be 'force' or 'form', got {kind!r}")
    if kind == "force" and mu is None:
        raise InvalidOptionError("force closure needs mu")
    client = client_for(client)
    K, N, d = np.shape(positions)
    # the local engine's chunks (same n_g and K), so partitions align with them
    n_g = 1
    if kind == "force":
        n_g = check_num_generators(options.get("num_generators", 8))
    size = chunk_size_for(N, d, chunk_size, n_g, K)
    step = size * int(partition_chunks)
    arrays = {k: options.pop(k) for k in _ARRAY_OPTIONS if k in options}
    if kind == "force":
        arrays["mu"] = mu
    if output_dir is not None:
        output_dir = Path(output_dir)
        output_dir.mkdir(parents=True, exist_ok=True)
    futures, done_paths = [], {}
    run = uuid.uuid4().hex  # task keys unique to this call
    for j, start in enumerate(range(0, K, step)):
        sl = slice(start, min(K, start + step))
        shard = None if output_dir is None else output_dir / f"part-{j:05d}.parquet"
        if shard is not None and shard.exists():
            done_paths[j] = str(shard)
            continue
        P, Nrm = positions[sl], normals[sl]
        if hasattr(P, "dask"):  # a Dask array block: computed on the cluster
            P, Nrm = client.compute(P), client.compute(Nrm)
        else:
            P, Nrm = np.asarray(P), np.asarray(Nrm)
        part = {k: _slice_option(v, sl, K) for k, v in arrays.items()}
        futures.append((j, sl, client.submit(
            _partition, kind, P, Nrm, part, options, shard, size,
            key=f"drakegrasp-partition-{j}-{run}", pure=False,
        )))  # fmt: skip
    results = {j: f.result() for j, _, f in futures}
    if output_dir is not None:
        results.update(done_paths)
        return [results[j] for j in sorted(results)]
    chunks = ((sl, results[j]) for j, sl, _ in futures)
    tol = float(options.get("tol", DEFAULT_TOL))
    names = check_metrics(options.get("metrics", ()))
    return collect(K, d, kind, tol, names, chunks)


def read_dataset(output_dir: str | os.PathLike) -> dict[str, np.ndarray]:
    """The arrays of a dataset of :func:`evaluate_on_cluster`, shards in order."""
    import pyarrow.parquet as pq

    shards = sorted(Path(output_dir).glob("part-*.parquet"))
    tables = [pq.read_table(s) for s in shards]
    if not tables:
        return {}
    return {
        name: np.concatenate([t.column(name).to_numpy() for t in tables])
        for name in tables[0].column_names
    }


def stream_file_on_cluster(
    input_path, output_path, *, scheduler: str, fmt: str | None = None,
    workers=None, progress: bool = False, kind: str = "force", mu=None,
    **options,
):  # fmt: skip
    """``drakegrasp batch --scheduler ADDRESS``: a file's grasps on a cluster.

    ``output_path`` becomes a Parquet dataset directory, one shard per
    partition (a rerun skips complete shards).  Returns a
    :class:`~drakegrasp.batch.BatchSummary`.
    """
    from drakegrasp.batch.files.reader import read_grasps
    from drakegrasp.batch.files.writer import BatchSummary

    del workers, progress, fmt  # the cluster decides; output is always a dataset
    data = read_grasps(input_path)
    for name in _ARRAY_OPTIONS:
        if name in data and options.get(name) is None:
            options[name] = data[name]
    if kind == "force" and mu is None:
        mu = data.get("mu")
    options = {k: v for k, v in options.items() if v is not None}
    evaluate_on_cluster(scheduler, data["positions"], data["normals"], mu,
                        kind=kind, output_dir=output_path, **options)  # fmt: skip
    arrays = read_dataset(output_path)
    summary = BatchSummary(kind=kind, tol=float(options.get("tol", DEFAULT_TOL)))
    summary.add(arrays)
    return summary


# --------------------------------------------------------------------------
# Plant-based evaluation: one scene per worker process, positions shipped.
