r"""Form and force closure of many grasps at once, streamed in chunks.

:func:`batch_force_closure` and :func:`batch_form_closure` take ``K`` grasps of
``N`` contacts as stacked arrays and return a :class:`BatchClosureResult` of
arrays.  Verdicts and ``d*`` follow the single-grasp programs of
:mod:`drakegrasp.closure.verdicts` exactly (same frames, effective cones, unit
facet rows, budget ``Σ f_n <= N``, rank threshold and ``tol``); only the solver
differs: each chunk's LPs are solved on the null space of ``G`` by compiled
kernels (an exact active-set method for small null spaces, a block
interior-point method for the rest; :mod:`drakegrasp.batch.margin`).  ``d*``
agrees with the ``MathematicalProgram`` path to about 1e-8 absolute.

The inputs are processed ``chunk_size`` grasps at a time: only one chunk's
matrices exist at any moment, and inputs may be memory-mapped arrays.
"""

from __future__ import annotations

import mmap
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from drakegrasp.batch.chunks import force_chunk, form_chunk
from drakegrasp.batch.parallel import map_ordered, resolve_workers
from drakegrasp.core.contact import ContactModel
from drakegrasp.core.tolerances import DEFAULT_RANK_TOL, DEFAULT_TOL, ZERO_FRACTION
from drakegrasp.core.validation import (
    LENGTH_BOUND,
    POSITION_BOUND,
    check_coefficient,
    check_coefficient_array,
    check_flag,
    check_num_generators,
    check_positions,
    check_rank_tol,
    check_tol,
    integer_or_none,
    real_array,
    unit_vectors,
)
from drakegrasp.errors import InvalidContactError, InvalidGraspError, InvalidOptionError

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "METRICS",
    "BatchClosureResult",
    "batch_force_closure",
    "batch_form_closure",
    "iter_batch_closure",
    "stream_force_closure",
    "stream_form_closure",
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


METRICS = ("sigma_min", "isotropy", "ellipsoid_volume", "epsilon_l1")
"""Metric names that ``metrics=`` accepts; see :func:`batch_force_closure`."""


@dataclass(frozen=True)
class BatchClosureResult:
    """Closure verdicts of ``K`` grasps, as arrays.

    The arrays are read-only.

    Attributes
    ----------
    kind : str
        ``"form"`` (LP1 on ``G_n``) or ``"force"`` (LP2 on ``G``).
    is_closure : (K,) bool
        ``rank == required_rank`` and (``d_star > tol`` or a normal-force
        certificate), as :func:`drakegrasp.force_closure` decides.
    d_star : (K,) float
        Optimal margin of the LP (dimensionless; normal forces normalised by
        ``Σ f_n <= N``).  Reported whatever the rank.
    rank : (K,) int
        Numerical rank of ``G`` (effective components) or ``G_n``.
    required_rank : int
        6 (spatial) or 3 (planar).
    margin : (K,) float
        ``(d* - tol) / tol`` as ``margin`` of :class:`~drakegrasp.ClosureResult`, with
        LP1's ``d*`` where the normal-force certificate decided.  The verdict
        is uncertain where ``tol/1000 < d* < 2 tol``.
    converged : (K,) bool
        False where neither the batched interior-point method (within its
        iteration cap) nor the per-grasp HiGHS fallback solved the LP; the
        verdict then rests on the last iterate.  True for every grasp in all
        the tests and benchmarks so far.
    tol : float
        Threshold on ``d*``.
    metrics : dict of str to (K,) float
        The requested metrics, see :func:`batch_force_closure`.
    normal_certificate : (K,) bool
        True where force closure was proved by balancing normal forces (LP1
        with ``d* > tol``) although the LP2 ``d*`` was at most ``tol``: ``d`` is a
        distance to the cone boundaries and vanishes as ``μ -> 0``, while such
        forces lie inside every cone with ``μ > 0`` (see
        ``certificate`` of :class:`~drakegrasp.ClosureResult`).
    """

    kind: str
    is_closure: np.ndarray
    d_star: np.ndarray
    rank: np.ndarray
    required_rank: int
    margin: np.ndarray
    converged: np.ndarray
    tol: float
    metrics: dict[str, np.ndarray] = field(default_factory=dict)
    normal_certificate: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.is_closure.shape[0])

    def __getitem__(self, name: str) -> np.ndarray:
        """A result array or metric by name (``result["d_star"]``)."""
        arrays = self.to_arrays()
        if name not in arrays:
            raise KeyError(f"no array {name!r}; available: {sorted(arrays)}")
        return arrays[name]

    def to_arrays(self) -> dict[str, np.ndarray]:
        """All per-grasp arrays by name (results first, then metrics)."""
        out = {
            "is_closure": self.is_closure,
            "d_star": self.d_star,
            "rank": self.rank,
            "margin": self.margin,
            "converged": self.converged,
        }
        if self.normal_certificate is not None:
            out["normal_certificate"] = self.normal_certificate
        out.update(self.metrics)
        return out

    def to_dict(self) -> dict:
        """JSON-ready dictionary (arrays become lists)."""
        out = {
            "kind": self.kind,
            "required_rank": self.required_rank,
            "tol": self.tol,
        }
        for k, v in self.to_arrays().items():
            out[k] = v.tolist()
        return out

    def __str__(self) -> str:
        K = len(self)
        n = int(self.is_closure.sum())
        near = int(np.sum((self.margin > ZERO_FRACTION - 1.0) & (self.margin < 1.0)))
        lines = [
            f"{self.kind} closure of {K} grasps: {n} closed, {K - n} not "
            f"(tol {self.tol:g}, {near} within tol of the boundary)"
        ]
        if K:
            lines.append(
                f"d*: min {self.d_star.min():.6g}, median "
                f"{np.median(self.d_star):.6g}, max {self.d_star.max():.6g}"
            )
        if not self.converged.all():
            lines.append(f"{int((~self.converged).sum())} LPs did not converge")
        for name, v in self.metrics.items():
            lines.append(f"{name}: mean {np.nanmean(v) if K else np.nan:.6g}")
        return "\n".join(lines)


# --------------------------------------------------------------------------
# Input checks (per chunk, so memory-mapped inputs are never loaded whole)


def _positive_int(name: str, value, minimum: int) -> int:
    n = integer_or_none(value)
    if n is None or n < minimum:
        raise InvalidOptionError(
            f"{name} must be an integer >= {minimum}, got {value!r}"
        )
    return int(n)


def _check_tol(name: str, value) -> float:
    return check_rank_tol(value) if name == "rank_tol" else check_tol(value, name)


def _bounded_chunk_size(chunk_size: int, N: int, n_g: int) -> int:
    """Grasps per chunk, capped so that a chunk's facet rows stay near 64 MB.

    The facet rows of a chunk hold about ``chunk * N * 2 n_g * 4`` floats;
    without a cap, ``num_generators = 256`` and 4096 grasps of ten contacts
    would need gigabytes.  Memory then stays proportional to the real work.
    """
    per_grasp = max(1, N) * (2 * n_g + 2) * 4 * 8
    return max(1, min(chunk_size, _CHUNK_BYTES // per_grasp))


_CHUNK_BYTES = 64 * 2**20


def _shape_of(name: str, a) -> tuple[int, int, int]:
    shape = np.shape(a) if a is not None else ()
    if len(shape) != 3 or shape[2] not in (2, 3) or shape[1] < 1:
        raise InvalidContactError(
            f"{name} must have shape (K, N, 2) or (K, N, 3) with N >= 1, got {shape}"
        )
    return shape


def _per_contact(name: str, value, K: int, N: int, *, error=InvalidContactError):
    """A per-contact coefficient as a function of a chunk slice -> (k, N) array."""
    a = value
    shape = tuple(a.shape) if hasattr(a, "shape") else np.shape(a)
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


def _check_coefficients(name: str, x: np.ndarray, start: int) -> None:
    check_coefficient_array(name, x, start=start)


def _check_positions(P: np.ndarray, start: int) -> None:
    bad = ~(np.abs(P) <= POSITION_BOUND).all(axis=-1)  # NaN fails too
    if bad.any():
        k, i = np.argwhere(bad)[0]
        raise InvalidContactError(
            f"position of grasp {start + k}, contact {i} is {P[k, i].tolist()}: "
            "not finite or out of range; it must be finite with "
            f"|x| <= {POSITION_BOUND:g} m (drakegrasp.core.validation.POSITION_BOUND)"
        )


def _unit_normals(Nrm: np.ndarray, start: int) -> np.ndarray:
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


def _reference_points(value, K: int, d: int):
    if value is None:
        return lambda sl: np.zeros((sl.stop - sl.start, d))
    shape = np.shape(value)
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
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise InvalidGraspError(
                f"reference point of grasp {sl.start + k} is {p[k].tolist()}; it "
                f"must be finite with |x| <= {POSITION_BOUND:g} m"
            )
        return p

    return get


def _characteristic_lengths(value, K: int):
    if value is None:
        return None
    shape = np.shape(value)
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
        bad = ~(b > 0.0) | ~(b <= LENGTH_BOUND)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise InvalidGraspError(
                f"characteristic length of grasp {sl.start + k} is {float(b[k])}; it "
                f"must be finite and in (0, {LENGTH_BOUND:g}] m"
            )
        return b

    return get


def _check_metrics(metrics: Sequence[str]) -> tuple[str, ...]:
    if isinstance(metrics, str):
        metrics = (metrics,)
    try:
        names = tuple(metrics)
    except TypeError:
        raise InvalidOptionError(
            f"metrics must be a sequence of names from {', '.join(METRICS)}, got "
            f"{metrics!r}"
        ) from None
    for name in names:
        if name not in METRICS:
            raise InvalidOptionError(
                f"unknown metric {name!r}; valid metrics are {', '.join(METRICS)}"
            )
    return names


def _chunks(K: int, chunk_size: int, progress: bool, desc: str) -> Iterator[slice]:
    bar = None
    if check_flag("progress", progress):
        try:
            from tqdm.auto import tqdm
        except ImportError as exc:
            raise InvalidOptionError(
                "progress=True needs the optional package tqdm, which is not "
                'installed: pip install "drakegrasp[progress]"'
            ) from exc
        bar = tqdm(total=K, desc=desc, unit="grasp")
    try:
        for start in range(0, K, chunk_size):
            stop = min(K, start + chunk_size)
            yield slice(start, stop)
            if bar is not None:
                bar.update(stop - start)
    finally:
        if bar is not None:
            bar.close()


# --------------------------------------------------------------------------
# Drivers


def chunk_size_for(
    N: int, d: int, chunk_size: int | None, n_g: int = 8, K: int | None = None
) -> int:
    """Grasps per chunk: ``chunk_size``, or as many as fit in ``CHUNK_BYTES``.

    A grasp's working set is dominated by its grasp matrix, row-space basis
    and equality rows (``~3 (w + 1) M`` numbers, ``M <= 4N`` components) and
    its facet slacks and multipliers (``~12 r`` numbers, ``r <= 16N`` rows).
    Given the batch size ``K``, a batch that fills fewer than
    ``TARGET_CHUNKS`` such chunks is cut into ``TARGET_CHUNKS`` (chunks of at
    least ``MIN_CHUNK_CONTACTS`` contacts).  The size depends on the inputs
    only, never on the number of workers.
    """
    if chunk_size is not None:
        size = _positive_int("chunk_size", chunk_size, 1)
    else:
        w = 6 if d == 3 else 3
        per_grasp = 8 * (3 * (w + 1) * 3 * N + 12 * 8 * N + 64)
        size = int(min(65536, max(64, CHUNK_BYTES // per_grasp)))
        if K is not None:
            floor = -(-MIN_CHUNK_CONTACTS // max(1, N))
            size = min(size, max(floor, -(-int(K) // TARGET_CHUNKS)))
    return _bounded_chunk_size(size, N, n_g)


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


def _stream(
    positions,
    normals,
    *,
    kind: str,
    task: Callable,
    chunk_size: int | None,
    progress: bool,
    workers,
    n_g: int = 1,
) -> Iterator[tuple[slice, dict[str, np.ndarray]]]:
    """Validated chunks through ``task`` (which builds one chunk's work), in order."""
    K, N, d = _shape_of("positions", positions)
    if np.shape(normals) != (K, N, d):
        raise InvalidContactError(
            f"normals must have the shape of positions {(K, N, d)}, got "
            f"{np.shape(normals)}"
        )
    size = chunk_size_for(N, d, chunk_size, n_g, K)
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
    _check_positions(P, start)
    Nrm = _unit_normals(real_array("normals", Nrm), start)
    return fn(P, Nrm, *args, **options)


def _collect(K: int, d: int, kind: str, tol: float, names, chunks):
    """One :class:`BatchClosureResult` from streamed chunk results."""
    out = {
        "is_closure": np.zeros(K, dtype=bool),
        "d_star": np.zeros(K),
        "rank": np.zeros(K, dtype=int),
        "margin": np.zeros(K),
        "converged": np.ones(K, dtype=bool),
    }
    if kind == "force":
        out["normal_certificate"] = np.zeros(K, dtype=bool)
    out_metrics = {name: np.full(K, np.nan) for name in names}
    for sl, arrays in chunks:
        for name, target in (*out.items(), *out_metrics.items()):
            target[sl] = arrays[name]
    for a in (*out.values(), *out_metrics.values()):
        a.flags.writeable = False
    return BatchClosureResult(
        kind=kind,
        is_closure=out["is_closure"],
        d_star=out["d_star"],
        rank=out["rank"],
        required_rank=3 if d == 2 else 6,
        margin=out["margin"],
        converged=out["converged"],
        tol=tol,
        metrics=out_metrics,
        normal_certificate=out.get("normal_certificate"),
    )


def _check_kernel(kernel: str) -> str:
    if kernel not in ("auto", "numba", "numpy"):
        raise InvalidOptionError(
            f"kernel must be 'auto', 'numba' or 'numpy', got {kernel!r}"
        )
    if kernel == "numba":
        from drakegrasp.batch.margin import numba_available

        if not numba_available():
            raise InvalidOptionError(
                "kernel='numba' needs the optional package numba "
                "(pip install drakegrasp[fast]); use kernel='numpy'"
            )
    return kernel


def _force_task(positions, mu, model, num_generators, torsional_friction,
                reference_points, characteristic_lengths, tol, rank_tol, metrics,
                kernel):  # fmt: skip
    """Validate options once; return the chunk-task builder of LP2 and options."""
    model = ContactModel.parse(model).value
    K, N, d = _shape_of("positions", positions)
    if model == "soft_finger" and d == 2:
        raise InvalidContactError(
            "a soft-finger contact is spatial only; planar contacts are "
            "'frictionless' or 'hard_finger'"
        )
    options = {
        "model": model,
        "num_generators": check_num_generators(num_generators),
        "tol": _check_tol("tol", tol),
        "rank_tol": _check_tol("rank_tol", rank_tol),
        "metrics": _check_metrics(metrics),
        "kernel": _check_kernel(kernel),
    }
    get_mu = _per_contact("mu", mu, K, N)
    if torsional_friction is None:
        if model == "soft_finger":
            raise InvalidContactError(
                "model='soft_finger' needs torsional_friction (nu: the moment "
                "about the normal is bounded by b * nu * f_n); pass nu > 0, or 0 "
                "for soft fingers that act as hard fingers"
            )
        torsional_friction = 0.0
    get_nu = _per_contact("torsional_friction", torsional_friction, K, N)
    get_p = _reference_points(reference_points, K, d)
    get_b = _characteristic_lengths(characteristic_lengths, K)
    soft = model == "soft_finger"

    def task(P, Nrm, sl):
        mu_c = get_mu(sl)
        _check_coefficients("mu", mu_c, sl.start)
        nu_c = get_nu(sl)
        if soft:
            _check_coefficients("torsional_friction", nu_c, sl.start)
        p = np.ascontiguousarray(get_p(sl))
        b = None if get_b is None else np.ascontiguousarray(get_b(sl))
        return force_chunk, (P, Nrm, mu_c, nu_c, p, b), options

    return task, options


def _form_task(positions, reference_points, characteristic_lengths, tol, rank_tol,
               metrics, kernel):  # fmt: skip
    """Validate options once; return the chunk-task builder of LP1 and options."""
    K, N, d = _shape_of("positions", positions)
    options = {
        "tol": _check_tol("tol", tol),
        "rank_tol": _check_tol("rank_tol", rank_tol),
        "metrics": _check_metrics(metrics),
        "kernel": _check_kernel(kernel),
    }
    if "epsilon_l1" in options["metrics"]:
        raise InvalidOptionError(
            "metric 'epsilon_l1' needs friction; use batch_force_closure"
        )
    get_p = _reference_points(reference_points, K, d)
    get_b = _characteristic_lengths(characteristic_lengths, K)

    def task(P, Nrm, sl):
        p = np.ascontiguousarray(get_p(sl))
        b = None if get_b is None else np.ascontiguousarray(get_b(sl))
        return form_chunk, (P, Nrm, p, b), options

    return task, options


def stream_force_closure(
    positions,
    normals,
    mu,
    *,
    model: ContactModel | str = "hard_finger",
    num_generators: int = 8,
    torsional_friction=None,
    reference_points=None,
    characteristic_lengths=None,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
    chunk_size: int | None = DEFAULT_CHUNK_SIZE,
    progress: bool = False,
    metrics: Sequence[str] = (),
    workers: int | None = None,
    kernel: str = "auto",
) -> Iterator[tuple[slice, dict[str, np.ndarray]]]:
    """:func:`batch_force_closure` one chunk at a time: yields ``(slice, arrays)``.

    The arrays are those of :meth:`BatchClosureResult.to_arrays` for the grasps
    ``slice`` of the input, in order; only the chunks in flight are held, so a
    writer can stream any number of grasps in bounded memory.  Options are
    validated before the first chunk is read.
    """
    task, options = _force_task(
        positions, mu, model, num_generators, torsional_friction, reference_points,
        characteristic_lengths, tol, rank_tol, metrics, kernel,
    )  # fmt: skip
    return _stream(
        positions,
        normals,
        kind="force",
        task=task,
        chunk_size=chunk_size,
        progress=progress,
        workers=workers,
        n_g=options["num_generators"],
    )


def stream_form_closure(
    positions,
    normals,
    *,
    reference_points=None,
    characteristic_lengths=None,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
    chunk_size: int | None = DEFAULT_CHUNK_SIZE,
    progress: bool = False,
    metrics: Sequence[str] = (),
    workers: int | None = None,
    kernel: str = "auto",
) -> Iterator[tuple[slice, dict[str, np.ndarray]]]:
    """:func:`batch_form_closure` one chunk at a time.

    See :func:`stream_force_closure`.
    """
    task, _ = _form_task(
        positions, reference_points, characteristic_lengths, tol, rank_tol, metrics,
        kernel,
    )  # fmt: skip
    return _stream(
        positions,
        normals,
        kind="form",
        task=task,
        chunk_size=chunk_size,
        progress=progress,
        workers=workers,
    )


def batch_force_closure(
    positions: np.ndarray,
    normals: np.ndarray,
    mu: float | np.ndarray,
    *,
    model: ContactModel | str = "hard_finger",
    num_generators: int = 8,
    torsional_friction: float | np.ndarray | None = None,
    reference_points: np.ndarray | None = None,
    characteristic_lengths: float | np.ndarray | None = None,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
    chunk_size: int | None = DEFAULT_CHUNK_SIZE,
    progress: bool = False,
    metrics: Sequence[str] = (),
    workers: int | None = None,
    kernel: str = "auto",
) -> BatchClosureResult:
    r"""Frictional force closure (LP2) of ``K`` grasps at once.

    Parameters
    ----------
    positions : (K, N, 3) or (K, N, 2) float
        Contact points ``c_i``, metres, in each grasp's frame.  Any array-like
        that supports slicing along the first axis (e.g. ``numpy.memmap``).
    normals : (K, N, d) float
        Contact normals pointing into the object; normalised here.  A zero or
        non-finite normal raises :class:`~drakegrasp.InvalidContactError`
        naming the grasp and contact.
    mu : float, (K,) or (K, N) float
        Coulomb friction coefficients: 0 or in ``[1e-12, 1e12]`` (the range of
        :mod:`drakegrasp.core.validation`, the same as the single-grasp path).  A
        hard finger with ``μ = 0`` acts as frictionless, as in the single-grasp
        path.
    model : {"hard_finger", "frictionless", "soft_finger"}, optional
        Contact model of every contact (soft fingers are spatial only).
    num_generators : int, optional
        Generators ``n_g >= 3`` of each linearised spatial cone (default 8).
    torsional_friction : float, (K,) or (K, N) float, optional
        ``ν`` of soft fingers (moment bound ``b ν f_n``), 0 or in
        ``[1e-12, 1e12]``.  ``None`` (default) means not given: required with
        ``model="soft_finger"`` (an explicit 0 makes soft fingers act as hard
        ones), 0 otherwise, as :class:`~drakegrasp.Contact` does.
    reference_points : (d,) or (K, d) float, optional
        Point ``p`` about which moments are taken; default the origin.
    characteristic_lengths : float or (K,) float, optional
        ``b > 0`` metres, for soft-finger cones and the scaled metrics; default
        the largest ``‖c_i - p‖`` of each grasp (1 m if all are at ``p``), as
        :class:`~drakegrasp.Grasp` does.
    tol : float, optional
        Closure needs ``d* > tol`` (default 1e-6, as the single path).
    rank_tol : float, optional
        Singular values ``<= rank_tol * σ_max`` of the normalised ``G``
        (moments about the contacts' centroid divided by their spread) count
        as zero, so the rank does not depend on units or on ``p``.
    chunk_size : int, optional
        Grasps processed together; memory use grows with it, not with ``K``.
        Default (None): as many as fit in ``CHUNK_BYTES`` for this ``N``,
        and at most so many that a chunk's facet rows stay near 64 MB (large
        ``num_generators``).
    progress : bool, optional
        Show a tqdm progress bar (needs the optional package ``tqdm``).
    metrics : sequence of str, optional
        Any of ``"sigma_min"``, ``"isotropy"``, ``"ellipsoid_volume"`` —
        singular-value indices of ``G`` (full rows; moment rows divided by
        ``b``): ``σ_min``, ``σ_min/σ_max`` and ``∏ σ_i`` (the wrench
        ellipsoid's volume over the unit ball's) — and ``"epsilon_l1"``, the
        Ferrari–Canny L1 ε of :func:`drakegrasp.quality.ferrari_canny`,
        computed as :func:`~drakegrasp.batch.batch_epsilon_l1` does (a compiled
        kernel; Qhull per grasp with ``kernel="numpy"`` or without numba).
    workers : int, optional
        Worker processes; default (None) every available core.  Results are
        bitwise the same for any number (:mod:`drakegrasp.batch.parallel`).
    kernel : {"auto", "numba", "numpy"}, optional
        Interior-point implementation: the compiled one (needs numba) or the
        numpy reference; ``"auto"`` takes numba when installed.  The same
        choice for ``"epsilon_l1"``.

    Returns
    -------
    BatchClosureResult
        ``is_closure``, ``d_star``, ``rank`` (of ``G`` over the effective
        components), ``margin``, ``converged`` and the metrics, all (K,).

    Notes
    -----
    The same LP as :func:`drakegrasp.force_closure` (facet formulation):

    .. math::

        \max d \;\text{s.t.}\; G f = 0,\; F f - \mathbf 1 d \ge 0,\; d \ge 0,\;
        \textstyle\sum f_n \le N ,

    reduced on ``N(G)`` and solved for a whole chunk by a batched Mehrotra
    interior-point method (:mod:`drakegrasp.batch.reduction`).
    """
    K, N, d = _shape_of("positions", positions)
    _, options = _force_task(
        positions, mu, model, num_generators, torsional_friction, reference_points,
        characteristic_lengths, tol, rank_tol, metrics, kernel,
    )  # fmt: skip
    chunks = stream_force_closure(
        positions, normals, mu, model=model, num_generators=num_generators,
        torsional_friction=torsional_friction, reference_points=reference_points,
        characteristic_lengths=characteristic_lengths, tol=tol, rank_tol=rank_tol,
        chunk_size=chunk_size, progress=progress, metrics=metrics, workers=workers,
        kernel=kernel,
    )  # fmt: skip
    return _collect(K, d, "force", options["tol"], options["metrics"], chunks)


def batch_form_closure(
    positions: np.ndarray,
    normals: np.ndarray,
    *,
    reference_points: np.ndarray | None = None,
    characteristic_lengths: float | np.ndarray | None = None,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
    chunk_size: int | None = DEFAULT_CHUNK_SIZE,
    progress: bool = False,
    metrics: Sequence[str] = (),
    workers: int | None = None,
    kernel: str = "auto",
) -> BatchClosureResult:
    r"""First-order form closure (LP1 and ``rank(G_n)``) of ``K`` grasps at once.

    Parameters
    ----------
    positions, normals : (K, N, d) float
        Contact points (metres) and inward normals (normalised here), as in
        :func:`batch_force_closure`.
    reference_points : (d,) or (K, d) float, optional
        Moment reference ``p``; default the origin.
    characteristic_lengths : float or (K,) float, optional
        ``b`` for the scaled singular-value metrics (default as
        :class:`~drakegrasp.Grasp`).
    tol, rank_tol, chunk_size, progress, workers, kernel : optional
        As in :func:`batch_force_closure`.
    metrics : sequence of str, optional
        ``"sigma_min"``, ``"isotropy"``, ``"ellipsoid_volume"`` of ``G_n``.

    Returns
    -------
    BatchClosureResult
        ``kind = "form"``; ``rank`` is ``rank(G_n)``.

    Notes
    -----
    The same LP as :func:`drakegrasp.form_closure`:

    .. math::

        \max d \;\text{s.t.}\; G_n f_n = 0,\; f_n - \mathbf 1 d \ge 0,\;
        d \ge 0,\; \mathbf 1^T f_n \le N .
    """
    K, N, d = _shape_of("positions", positions)
    _, options = _form_task(
        positions, reference_points, characteristic_lengths, tol, rank_tol, metrics,
        kernel,
    )  # fmt: skip
    chunks = stream_form_closure(
        positions, normals, reference_points=reference_points,
        characteristic_lengths=characteristic_lengths, tol=tol, rank_tol=rank_tol,
        chunk_size=chunk_size, progress=progress, metrics=metrics, workers=workers,
        kernel=kernel,
    )  # fmt: skip
    return _collect(K, d, "form", options["tol"], options["metrics"], chunks)


def iter_batch_closure(
    chunks: Iterable[Mapping[str, np.ndarray] | tuple],
    *,
    kind: str = "force",
    **options,
) -> Iterator[BatchClosureResult]:
    """Closure of a stream of grasp chunks, one result per chunk, lazily.

    For inputs that do not fit in memory at once (a generator reading a large
    file, a grasp sampler): only the current chunk and its result are held.

    Parameters
    ----------
    chunks : iterable
        Each item is a tuple ``(positions, normals)`` or ``(positions, normals,
        mu)``, or a mapping with those keys (and optionally ``mu``,
        ``torsional_friction``, ``reference_points``,
        ``characteristic_lengths``), with the shapes of
        :func:`batch_force_closure` for that chunk.
    kind : {"force", "form"}, optional
        :func:`batch_force_closure` (needs ``mu``) or :func:`batch_form_closure`.
    **options
        Keyword options of that function, applied to every chunk.

    Yields
    ------
    BatchClosureResult
        The result of each chunk, in order.  Error messages index grasps within
        their chunk.
    """
    if kind not in ("force", "form"):
        raise InvalidOptionError(f"kind must be 'force' or 'form', got {kind!r}")
    for item in chunks:
        if isinstance(item, Mapping):
            arrays = dict(item)
        else:
            names = ("positions", "normals", "mu")[: len(item)]
            arrays = dict(zip(names, item, strict=True))
        try:
            P, Nrm = arrays.pop("positions"), arrays.pop("normals")
        except KeyError as exc:
            raise InvalidOptionError(
                f"each chunk needs positions and normals; got {sorted(arrays)}"
            ) from exc
        if kind == "form":
            arrays.pop("mu", None)
            arrays.pop("torsional_friction", None)
            yield batch_form_closure(P, Nrm, **arrays, **options)
        else:
            if "mu" not in arrays:
                raise InvalidOptionError("force closure chunks need mu")
            mu = arrays.pop("mu")
            yield batch_force_closure(P, Nrm, mu, **arrays, **options)
