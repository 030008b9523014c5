"""The batch engine on a Dask cluster: partitions of grasps, Parquet shards, restarts.

The outer ring: the engine (:mod:`drakegrasp.batch`) knows nothing of Dask.
Here the grasps are cut into *partitions*, each a whole number of the engine's
chunks and starting on a chunk boundary, so every chunk is computed exactly as
the local engine computes it and the results are bitwise the same.  Each
partition runs the engine in one Dask task (``workers=1`` inside it: Dask's
workers are the parallelism) and either returns its arrays or writes them as
one Parquet shard ``part-NNNNN.parquet`` of a dataset directory, by writing a
temporary file and renaming it into place.  A shard therefore exists only when
complete, and the dataset's manifest (:mod:`~drakegrasp.distributed.dataset`)
names its job: a restarted run of the same job skips its complete shards, a
directory of another job is refused (or replaced with ``overwrite``), and a
task that Dask retries after a worker died rewrites the same shard, so nothing
is lost or duplicated.

Plant-based evaluation on a cluster is the other half of this folder
(:mod:`drakegrasp.distributed.plant_side`).

Needs the optional extra ``dask`` (``dask[distributed]``, and ``pyarrow`` for
the Parquet shards).  See ``docs/distributed.md`` for pointing it at a cluster.
"""

from __future__ import annotations

import inspect
import os
import re
import uuid
from collections.abc import Callable
from pathlib import Path

import numpy as np

from drakegrasp.batch.api import collect, stream_force_closure, stream_form_closure
from drakegrasp.batch.columns import result_arrays
from drakegrasp.batch.inputs import (
    check_metrics,
    per_contact_getter,
    positive_int,
    shape_of,
)
from drakegrasp.batch.metrics import check_moment_arms_of_batch
from drakegrasp.batch.options import (
    FRICTION_OPTIONS,
    OPTION_NAMES,
    BatchOptions,
    checked_options,
    refuse_given_twice,
)
from drakegrasp.batch.run.chunk import check_form_metrics
from drakegrasp.batch.run.stream import chunk_size_for
from drakegrasp.core.calls import checked_call, unknown_names
from drakegrasp.core.contact import ContactModel
from drakegrasp.core.deprecation import keyword_only
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS, DEFAULT_TOL
from drakegrasp.core.validation import (
    check_num_generators,
    describe,
    path_text,
    plain_str,
)
from drakegrasp.distributed.client import connected, results_or_cancel
from drakegrasp.distributed.dataset import (
    job_manifest,
    prepare_dataset,
    read_dataset,
    remove_orphan_temporaries,
    shard_is_done,
    shard_path,
    write_shard,
)
from drakegrasp.errors import (
    BatchFileError,
    GraspError,
    InvalidArgumentError,
    InvalidContactError,
    InvalidOptionError,
)

__all__ = [
    "evaluate_on_cluster",
    "stream_file_on_cluster",
]

_ARRAY_OPTIONS = ("mu", "torsional_friction", "reference_points",
                  "characteristic_lengths")  # fmt: skip
_PER_CONTACT = ("mu", "torsional_friction")
_RESERVED = ("workers", "progress")  # the cluster decides these


def _per_grasp_arrays(arrays: dict, K: int, N: int) -> dict:
    """Per-contact options checked whole and made partition-proof.

    A per-grasp ``(K,)`` array is refused as ambiguous when ``K == N``, as the
    local engine refuses it, and otherwise reshaped to ``(K, 1)``: a
    partition's slice ``(k,)`` would be ambiguous whenever ``k == N``.
    """
    out = dict(arrays)
    for name in _PER_CONTACT:
        value = out.get(name)
        if value is None:
            continue
        per_contact_getter(name, value, K, N)  # the local engine's shape rules
        if np.shape(value) == (K,):
            out[name] = (value if hasattr(value, "reshape") else np.asarray(value)
                         ).reshape(K, 1)  # fmt: skip
    return out


def _slice_option(value, sl: slice, K: int):
    """A per-grasp option sliced to a partition; scalars and rows pass through."""
    shape = np.shape(value)
    if value is None or shape == () or shape[0] != K:
        return value
    return np.asarray(value[sl])


_GRASP_NAMED = re.compile(r"\bgrasp (\d+)\b")
"""A grasp named by its index in an engine's message ("grasp 5")."""


def _in_the_input(error: GraspError, start: int) -> GraspError:
    """``error`` naming grasps by their place in the input, not in the partition.

    The engine names a faulty grasp by its index in the arrays it was given;
    a partition's first grasp is grasp ``start`` of the input.
    """
    text = _GRASP_NAMED.sub(lambda m: f"grasp {int(m.group(1)) + start}", str(error))
    return type(error)(text)


def _partition(
    kind, positions, normals, arrays, options, shard, chunk_size, job, start=0
):
    """One partition through the local engine; write its shard or return arrays.

    ``start`` is the index of the partition's first grasp in the input: an
    error names the grasp by its place there.
    """
    run = stream_force_closure if kind == "force" else stream_form_closure
    try:
        parts = [a for _, a in run(positions, normals, **arrays, **options,
                                   chunk_size=chunk_size, workers=1)]  # fmt: skip
    except GraspError as e:
        if start == 0:  # already named by its place in the input
            raise
        raise _in_the_input(e, start) from e
    if parts:
        out = {n: np.concatenate([p[n] for p in parts]) for n in parts[0]}
    else:  # the one partition of an empty job: every column, no rows
        arrays, metrics = result_arrays(0, kind, options.get("metrics", ()))
        out = {**arrays, **metrics}
    if shard is None:
        return out
    return write_shard(Path(shard), out, job)


@checked_call
@keyword_only("mu", after=3)
def evaluate_on_cluster(
    client,
    positions,
    normals,
    *,
    mu=None,
    kind: str = "force",
    output_dir: str | os.PathLike | None = None,
    overwrite: bool = False,
    partition_chunks: int = 4,
    chunk_size: int | None = None,
    options: BatchOptions | None = None,
    **keywords,
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
        that ``pandas.read_parquet`` or
        :func:`~drakegrasp.distributed.dataset.read_dataset` reads) instead of
        returning the results.  The directory's manifest names the job (a
        fingerprint of the inputs and options, see
        :mod:`~drakegrasp.distributed.dataset`): a rerun of the same job skips
        its complete shards and recomputes truncated or foreign ones; a
        directory of another job is refused unless ``overwrite``.
    overwrite : bool, optional
        Replace the shards of another job found in ``output_dir``.
    partition_chunks : int, optional
        Engine chunks per partition (an integer >= 1, default 4).
    chunk_size : int, optional
        The engine's chunk size (default: sized by bytes, as locally).
    options : BatchOptions, optional
        The engine's options as one object, instead of their keywords (its
        ``workers`` and ``progress`` must stay at their defaults: the
        cluster's workers are the parallelism).
    **keywords
        The other keyword options of :func:`drakegrasp.batch_force_closure`
        (or :func:`~drakegrasp.batch_form_closure`), e.g. ``contact_model``, ``tol``,
        ``torsional_friction``, ``reference_points``.

    Returns
    -------
    BatchClosureResult or list of str
        The result, bitwise equal to the local engine's; or, with
        ``output_dir``, the shard paths in order.

    Raises
    ------
    InvalidOptionError
        A bad option (``partition_chunks``, ``kind``, ``workers``, ...).
    BatchFileError
        ``output_dir`` holds another job and ``overwrite`` is not set.
    InvalidContactError, InvalidGraspError
        With metrics, a numpy or memory-mapped input whose positions are bad or
        whose ``characteristic_lengths`` are out of scale with its grasps
        (:func:`~drakegrasp.batch.metrics.check_moment_arms_of_batch`), before
        connecting; other faults of the input come from the partitions.
    """
    kind = plain_str(kind)
    if type(kind) is not str or kind not in ("force", "form"):
        raise InvalidOptionError(
            f"kind must be 'force' or 'form', got {describe(kind)}"
        )
    if output_dir is not None:
        output_dir = Path(
            path_text("output_dir", output_dir, error=BatchFileError,
                      must="a directory path (a str or an os.PathLike)")
        )  # fmt: skip
    _refuse_unknown(keywords, kind, evaluate_on_cluster)
    options, chunk_size = _engine_options(options, keywords, kind, chunk_size)
    if "metrics" in options:  # read once: an iterator would reach no partition
        options["metrics"] = check_metrics(options["metrics"])
    if kind == "force" and mu is None:
        raise InvalidOptionError("force closure needs mu")
    reserved = sorted(set(_RESERVED) & set(options))
    if reserved:
        raise InvalidOptionError(
            f"{', '.join(reserved)} cannot be given on a cluster: each partition "
            "runs in one Dask task, and the cluster's workers are the parallelism"
        )
    per_partition = positive_int("partition_chunks", partition_chunks, 1)
    K, N, d = shape_of("positions", positions)
    if np.shape(normals) != (K, N, d):
        raise InvalidContactError(
            f"normals must have the shape of positions {(K, N, d)}, got "
            f"{np.shape(normals)}"
        )
    # the local engine's chunks (same n_g and K), so partitions align with them
    n_g, model = 1, None
    if kind == "force":
        n_g = check_num_generators(
            options.get("num_generators", DEFAULT_NUM_GENERATORS)
        )
        try:  # as the engine reads it; a bad one is refused by the partitions
            model = ContactModel.parse(options.get("contact_model", "hard_finger"))
            model = model.value
        except GraspError:
            model = None
    size = chunk_size_for(N, d, chunk_size, n_g, K, contact_model=model)
    step = size * per_partition
    arrays = {k: options.pop(k) for k in _ARRAY_OPTIONS if k in options}
    if kind == "force":
        arrays["mu"] = mu
    arrays = _per_grasp_arrays(arrays, K, N)
    names = options.get("metrics", ())
    if kind == "form":
        check_form_metrics(names)
    if names and not hasattr(positions, "dask"):
        # Named in the input and refused before connecting, not per partition
        # (an input with several faults may be refused for another one first
        # than locally, where each chunk is checked in turn).
        check_moment_arms_of_batch(
            positions, arrays.get("reference_points"),
            arrays.get("characteristic_lengths"),
        )  # fmt: skip
    # An empty job still writes one shard, of no rows: its dataset has the
    # columns of any other (as a local file of no grasps has).
    starts = list(range(0, K, step)) or ([0] if output_dir is not None else [])
    job = None
    if output_dir is not None:
        manifest = job_manifest(
            kind=kind, shape=(K, N, d),
            arrays={"positions": positions, "normals": normals, **arrays},
            options=options, step=step, chunk_size=size,
            rows=[min(K, s + step) - s for s in starts],
        )  # fmt: skip
        prepare_dataset(output_dir, manifest, overwrite=overwrite, create=False)
        job = manifest["job"]
    # The output is checked before connecting and opened after: a scheduler
    # that cannot be reached leaves no dataset directory behind (an empty one
    # named like the output blocked every later run).
    with connected(client) as client:
        if output_dir is not None:
            output_dir = prepare_dataset(output_dir, manifest, overwrite=overwrite)
        futures, done_paths = [], {}
        run = uuid.uuid4().hex  # task keys unique to this call
        for j, start in enumerate(starts):
            sl = slice(start, min(K, start + step))
            shard = None if output_dir is None else shard_path(output_dir, j)
            if shard is not None and shard_is_done(shard, job, sl.stop - sl.start):
                done_paths[j] = str(shard)
                continue
            P, Nrm = positions[sl], normals[sl]
            if hasattr(P, "dask"):  # a Dask array block: computed on the cluster
                P, Nrm = client.compute(P), client.compute(Nrm)
            else:
                P, Nrm = np.asarray(P), np.asarray(Nrm)
            part = {k: _slice_option(v, sl, K) for k, v in arrays.items()}
            futures.append((j, sl, client.submit(
                _partition, kind, P, Nrm, part, options, shard, size, job, start,
                key=f"drakegrasp-partition-{j}-{run}", pure=False,
            )))  # fmt: skip
        # A block computed on the cluster is held by its partition alone, so
        # it is released with it (a failed run's error holds this frame).
        P = Nrm = None
        done = results_or_cancel(client, [f for _, _, f in futures])
        results = {j: r for (j, _, _), r in zip(futures, done, strict=True)}
    if output_dir is not None:
        results.update(done_paths)
        # every shard is complete: a worker killed mid-write left a temporary
        remove_orphan_temporaries(output_dir, results)
        return [results[j] for j in sorted(results)]
    chunks = ((sl, results[j]) for j, sl, _ in futures)
    tol = float(options.get("tol", DEFAULT_TOL))
    return collect(K, d, kind, tol, names, chunks)


def _refuse_unknown(
    keywords: dict, kind: str, caller: Callable, *, passed: tuple[str, ...] = ()
) -> None:
    """Refuse keywords that no function of a cluster run takes, at once.

    ``caller`` passes ``keywords`` on to :func:`evaluate_on_cluster` (or is
    it), which passes them on to the engine of ``kind``; the partitions would
    refuse an unknown one, each on its worker, after the cluster was reached.
    This names them (with the closest accepted one) first.  ``passed``: the
    arguments of ``evaluate_on_cluster`` that ``caller`` sets itself.
    """
    run = stream_force_closure if kind == "force" else stream_form_closure
    named = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    accepted = [
        name
        for function in dict.fromkeys((caller, evaluate_on_cluster, run))
        for name, p in inspect.signature(function).parameters.items()
        if p.kind in named and name not in ("positions", "normals", *passed)
    ]
    accepted = list(dict.fromkeys(accepted))
    # model=: the engine's old spelling of contact_model=, renamed (with its
    # warning) where the engine runs
    old = ("model",) if "contact_model" in accepted else ()
    unknown = [name for name in keywords if name not in (*accepted, *old)]
    if unknown:
        where = f"{caller.__qualname__}()"
        raise InvalidArgumentError(f"{where}: " + unknown_names(unknown, accepted))


def _engine_options(
    options: BatchOptions | None, keywords: dict, kind: str, chunk_size
) -> tuple[dict, int | None]:
    """The engine's keywords of a cluster run: ``keywords``, or ``options``'s.

    Only the options that differ from :class:`BatchOptions`'s defaults are
    passed on, as if given as keywords (a job's fingerprint does not change
    with the way its options were given); form closure drops the friction
    options.  ``workers`` and ``progress`` other than their defaults are
    refused by the caller, as keywords are.
    """
    if options is None:
        return keywords, chunk_size
    where = "evaluate_on_cluster()"
    checked_options(options, where)
    given = [*keywords, *(["chunk_size"] if chunk_size is not None else [])]
    refuse_given_twice(OPTION_NAMES, given, where)
    merged = dict(keywords)
    default = BatchOptions()
    for name, value in options.keywords().items():
        if value == getattr(default, name):
            continue
        if kind == "form" and name in FRICTION_OPTIONS:
            continue
        if name == "chunk_size":
            chunk_size = value
            continue
        merged[name] = value.value if isinstance(value, ContactModel) else value
    return merged, chunk_size


@checked_call
def stream_file_on_cluster(
    input_path, output_path, *, scheduler: str, fmt: str | None = None,
    workers=None, progress: bool = False, kind: str = "force", mu=None,
    torsional_friction=None, overwrite: bool = False, **options,
):  # fmt: skip
    """``drakegrasp batch --scheduler ADDRESS``: a file's grasps on a cluster.

    ``output_path`` becomes a Parquet dataset directory, one shard per
    partition: a rerun of the same job resumes it, a directory of another
    job is refused unless ``overwrite`` (then its shards are replaced).
    ``mu`` and ``torsional_friction``, when given, override the file's
    arrays, as in :func:`~drakegrasp.batch.stream_file`.

    Returns
    -------
    BatchSummary
        Of this run's dataset (every shard of this job).
    """
    from drakegrasp.batch.files.reader import as_path, engine_options, read_grasps
    from drakegrasp.batch.files.writer import BatchSummary

    del workers, progress, fmt  # the cluster decides; output is always a dataset
    if kind == "form":  # as stream_file: form closure ignores the cone options
        for name in FRICTION_OPTIONS:
            options.pop(name, None)
    _refuse_unknown(
        options, kind, stream_file_on_cluster, passed=("client", "output_dir")
    )
    source = as_path("input", input_path)
    output = as_path("output", output_path)
    data = read_grasps(source)
    extra = engine_options(
        data, source, kind=kind, mu=mu, torsional_friction=torsional_friction
    )
    mu = extra.pop("mu", None)
    options.update({k: v for k, v in extra.items() if v is not None})
    options = {k: v for k, v in options.items() if v is not None}
    evaluate_on_cluster(scheduler, data["positions"], data["normals"], mu=mu,
                        kind=kind, output_dir=output,
                        overwrite=overwrite, **options)  # fmt: skip
    arrays = read_dataset(output)
    summary = BatchSummary(kind=kind, tol=float(options.get("tol", DEFAULT_TOL)))
    if arrays:
        summary.add(arrays)
    return summary


# --------------------------------------------------------------------------
# Plant-based evaluation: one scene per worker process, positions shipped.
