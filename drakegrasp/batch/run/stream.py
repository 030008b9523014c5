"""The chunk stream: a batch cut into chunks, each checked and solved, in order.

Chunks are sized by the memory they need (:func:`chunk_size_for`), read from
the inputs (memory-mapped pages are released as the stream moves on), checked
where they are solved, and run in this process or in worker processes
(:mod:`drakegrasp.batch.run.workers`); results come back in input order.
"""

from __future__ import annotations

import mmap
from collections.abc import Callable, Iterator

import numpy as np

from drakegrasp.batch.inputs import (
    check_chunk_positions,
    chunk_unit_normals,
    positive_int,
    read_shape,
    shape_of,
)
from drakegrasp.batch.run.workers import map_ordered, resolve_workers
from drakegrasp.core.validation import check_flag, real_array, refuse_structured
from drakegrasp.errors import InvalidContactError, InvalidOptionError

__all__ = [
    "CHUNK_BYTES",
    "DEFAULT_CHUNK_SIZE",
    "GRASP_BYTES_MAX",
    "MIN_CHUNK_CONTACTS",
    "PARALLEL_MIN_WORK",
    "TARGET_CHUNKS",
    "chunk_size_for",
    "cone_generators",
    "grasp_bytes",
    "progress_bar",
    "stream",
]

DEFAULT_CHUNK_SIZE = None
"""``chunk_size=None``: chunks are sized by bytes (``CHUNK_BYTES``)."""

PARALLEL_MIN_WORK = 200_000
"""With ``workers=None``, batches of fewer than this many contacts (``K N``) run
in this process: starting worker processes costs about 0.5 s."""

CHUNK_BYTES = 32 * 2**20
"""Working memory aimed at per chunk (estimated for the numpy route; the
compiled pass works grasp by grasp): a flat peak whatever ``K`` and ``N``, and
chunks long enough that a worker pool's per-chunk cost in the parent (about
0.5 ms) stays small: with 16 MiB, two workers ran 1.2× one on planar pairs at
1.9 million grasps/s, with 32 MiB 1.6×."""

TARGET_CHUNKS = 24
"""A batch too small to fill ``CHUNK_BYTES`` chunks is cut into about this many
(never below ``MIN_CHUNK_CONTACTS``), so that the workers finish together: the
last chunk runs alone, and with 5 chunks on 2 workers the best speedup is
5/3 = 1.67, with 24 it is 2."""

MIN_CHUNK_CONTACTS = 6144
"""Contacts below which a chunk is not cut further: each chunk costs about
0.5 ms besides its grasps (measured: 3 contacts per grasp, 170k grasps/s in
chunks of 256 grasps, 255k in 1024, 265k in 2048)."""


GRASP_BYTES_MAX = 2**32
"""Most working memory one grasp may need (:func:`grasp_bytes`): 4 GiB.

A chunk holds at least one grasp, so a grasp past this is refused before
anything is read or allocated, naming its contacts, generators and bytes:
unchecked, one grasp of 10**7 contacts went on to ask for about 30 GB.  It
admits about 780,000 hard contacts with 8 generators (a grasp of 100,000
runs in about 5 s and 400 MB)."""


def grasp_bytes(N: int, n_g: int) -> int:
    """Bytes one grasp of ``N`` contacts needs at the peak of its LP (an upper bound).

    ``8 N (256 + 48 (n_g + 1))``: the grasp matrix, its QR and row space, the
    facet rows (at most ``2 n_g + 2`` a contact, a soft finger's) with the
    interior-point method's slacks, multipliers and work.  Measured as the
    peak virtual memory of one grasp of 50,000 contacts with 8 generators:
    2,763 bytes a contact (spatial hard fingers; ``1419 + 168 n_g`` for
    ``n_g`` 4–16), 5,285 (soft fingers), 1,146 (planar), 878 (frictionless);
    this bound is 5,504.
    """
    return 8 * max(1, int(N)) * (256 + 48 * (max(1, int(n_g)) + 1))


def _bounded_chunk_size(chunk_size: int, N: int, n_g: int) -> int:
    """Grasps per chunk, capped so that a chunk's facet rows stay near 64 MB.

    The facet rows of a chunk hold about ``chunk * N * 2 n_g * 4`` floats;
    without a cap, ``num_generators = 256`` and 4096 grasps of ten contacts
    would need gigabytes.  Memory then stays proportional to the real work.
    """
    per_grasp = max(1, N) * (2 * n_g + 2) * 4 * 8
    return max(1, min(chunk_size, _CHUNK_BYTES // per_grasp))


_CHUNK_BYTES = 64 * 2**20


def progress_bar(iterable=None, *, total: int | None = None, desc: str, unit: str):
    """A tqdm progress bar, or a clear error when the optional tqdm is missing.

    Raises
    ------
    InvalidOptionError
        tqdm is not installed (``pip install "drakegrasp[progress]"``).
    """
    try:
        from tqdm.auto import tqdm
    except ImportError as exc:
        raise InvalidOptionError(
            "progress=True needs the optional package tqdm, which is not "
            'installed: pip install "drakegrasp[progress]"'
        ) from exc
    return tqdm(iterable, total=total, desc=desc, unit=unit)


def _chunks(K: int, chunk_size: int, progress: bool, desc: str) -> Iterator[slice]:
    bar = None
    if check_flag("progress", progress):
        bar = progress_bar(total=K, desc=desc, unit="grasp")
    try:
        for start in range(0, K, chunk_size):
            stop = min(K, start + chunk_size)
            yield slice(start, stop)
            if bar is not None:
                bar.update(stop - start)
    finally:
        if bar is not None:
            bar.close()


def cone_generators(n_g: int, d: int, contact_model: str | None = None) -> int:
    """The generators a contact's cone has, for :func:`grasp_bytes`.

    ``num_generators`` shapes only a spatial cone with friction: a planar
    cone has its 2 edges, a frictionless contact its normal alone (1).  A
    ``contact_model`` of None (not known: form closure, or not yet read) is
    taken as friction.
    """
    if contact_model == "frictionless":
        return 1
    if d == 2:
        return min(2, max(1, int(n_g)))
    return n_g


def chunk_size_for(
    N: int,
    d: int,
    chunk_size: int | None,
    n_g: int = 8,
    K: int | None = None,
    *,
    contact_model: str | None = None,
) -> int:
    """Grasps per chunk: ``chunk_size``, or as many as fit in ``CHUNK_BYTES``.

    A grasp's working set is dominated by its grasp matrix, row-space basis
    and equality rows (``~3 (w + 1) M`` numbers, ``M <= 4N`` components) and
    its facet slacks and multipliers (``~12 r`` numbers, ``r <= 16N`` rows).
    Given the batch size ``K``, a batch that fills fewer than
    ``TARGET_CHUNKS`` such chunks is cut into ``TARGET_CHUNKS`` (chunks of at
    least ``MIN_CHUNK_CONTACTS`` contacts).  The size depends on the inputs
    only, never on the number of workers.

    ``contact_model`` (``"frictionless"``, ...; None: one with friction) and
    ``d`` say which cones ``n_g`` shapes (:func:`cone_generators`), for the
    bound on one grasp's memory only: the chunk size does not depend on it.

    Raises
    ------
    InvalidContactError
        One grasp needs more than ``GRASP_BYTES_MAX`` (:func:`grasp_bytes` of
        its cones' generators).
    """
    cone = cone_generators(n_g, d, contact_model)
    need = grasp_bytes(N, cone)
    if need > GRASP_BYTES_MAX:
        many = cone == n_g and n_g > 1  # num_generators shapes these cones
        raise InvalidContactError(
            f"one grasp of {N} contacts"
            + (f" with num_generators={n_g}" if many else "")
            + f" needs about {need / 2**30:.3g} GiB of working memory ({need} "
            f"bytes), above the {GRASP_BYTES_MAX / 2**30:.3g} GiB a grasp may "
            "take (drakegrasp.batch.run.stream.GRASP_BYTES_MAX); give grasps of "
            f"at most {_most_contacts(cone)} contacts"
            + (", or fewer generators" if many else "")
        )
    if chunk_size is not None:
        size = positive_int("chunk_size", chunk_size, 1)
    else:
        w = 6 if d == 3 else 3
        per_grasp = 8 * (3 * (w + 1) * 3 * N + 12 * 8 * N + 64)
        size = int(min(65536, max(64, CHUNK_BYTES // per_grasp)))
        if K is not None:
            floor = -(-MIN_CHUNK_CONTACTS // max(1, N))
            size = min(size, max(floor, -(-int(K) // TARGET_CHUNKS)))
    return _bounded_chunk_size(size, N, n_g)


def _most_contacts(n_g: int) -> int:
    """The most contacts a grasp with ``n_g`` generators may have."""
    return GRASP_BYTES_MAX // grasp_bytes(1, n_g)


def _release_pages(a, stop: int) -> None:
    """Drop the pages of a memory-mapped input read so far from this process.

    A file-backed page stays in the process's resident set once read; over a
    file of 10^7 grasps that would grow the RSS by the whole input.  The pages
    stay in the OS's page cache (they are re-read from there if needed).
    """
    mm = getattr(a, "_mmap", None)
    if getattr(a, "mode", None) not in ("r", "r+"):  # never drop copy-on-write pages
        return
    if mm is None or not hasattr(mm, "madvise") or not hasattr(mmap, "MADV_DONTNEED"):
        return
    row = int(np.prod(a.shape[1:], dtype=np.int64)) * a.itemsize
    offset = int(a.offset) if hasattr(a, "offset") else 0
    end = (offset + stop * row) // mmap.PAGESIZE * mmap.PAGESIZE
    if end > 0:
        try:
            mm.madvise(mmap.MADV_DONTNEED, 0, min(end, len(mm)))
        except (OSError, ValueError):  # pragma: no cover - advice only
            pass


def stream(
    positions,
    normals,
    *,
    kind: str,
    task: Callable,
    chunk_size: int | None,
    progress: bool,
    workers,
    n_g: int = 1,
    contact_model: str | None = None,
) -> Iterator[tuple[slice, dict[str, np.ndarray]]]:
    """Validated chunks through ``task`` (which builds one chunk's work), in order.

    ``n_g`` and ``contact_model`` (the checked option's value) size the
    chunks and bound one grasp's memory (:func:`chunk_size_for`).
    """
    K, N, d = shape_of("positions", positions)
    refuse_structured("normals", normals)
    normal_shape = read_shape(
        "normals", normals, "an array of the shape of positions",
        error=InvalidContactError,
    )  # fmt: skip
    if normal_shape != (K, N, d):
        raise InvalidContactError(
            f"normals must have the shape of positions {(K, N, d)}, got {normal_shape}"
        )
    size = chunk_size_for(N, d, chunk_size, n_g, K, contact_model=contact_model)
    n_workers = resolve_workers(workers)
    if workers is None and K * N < PARALLEL_MIN_WORK:
        n_workers = 1  # starting processes would cost more than they save
    n_workers = min(n_workers, -(-K // size))
    slices: list[slice] = []

    def tasks():
        for sl in _chunks(K, size, progress, f"{kind} closure"):
            P, Nrm = _read(positions, sl), _read(normals, sl)
            _release_pages(positions, sl.stop)
            _release_pages(normals, sl.stop)
            slices.append(sl)
            fn, args, options = task(P, Nrm, sl)
            # the checks run where the chunk is solved (in parallel with others)
            yield _checked_chunk, (fn, sl.start, *args), options

    for i, arrays in enumerate(map_ordered(tasks(), n_workers)):
        yield slices[i], arrays


def _read(a, sl: slice):
    """One chunk of an input, as an array that owns or shares plain memory."""
    x = a[sl]
    if isinstance(x, np.memmap):
        return np.array(x)  # its pages are released before the chunk is used
    return x


def _checked_chunk(fn: Callable, start: int, P, Nrm, *args, **options):
    """Check a chunk's positions and normals (normalised), then ``fn`` on them."""
    P = real_array("positions", P)
    check_chunk_positions(P, start)
    Nrm = chunk_unit_normals(real_array("normals", Nrm), start)
    return fn(P, Nrm, *args, **options)
