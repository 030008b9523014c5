r"""Form and force closure of many grasps at once, streamed in chunks.

:func:`batch_force_closure` and :func:`batch_form_closure` take ``K`` grasps of
``N`` contacts as stacked arrays and return a :class:`BatchClosureResult` of
arrays.  Verdicts and ``d*`` follow the single-grasp programs of
:mod:`drakegrasp.closure.verdicts` exactly (same frames, effective cones, unit
facet rows, budget ``Σ f_n <= N``, rank threshold and ``tol``); only the solver
differs: each chunk's LPs are solved on the null space of ``G`` by compiled
kernels (an exact active-set method for small null spaces, a block
interior-point method for the rest; :mod:`drakegrasp.batch.lp.dstar`).  ``d*``
agrees with the ``MathematicalProgram`` path to about 1e-8 absolute.

The inputs are processed ``chunk_size`` grasps at a time: only one chunk's
matrices exist at any moment, and inputs may be memory-mapped arrays.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence, Sized
from dataclasses import dataclass, field

import numpy as np

from drakegrasp.batch.build.construction import batched_characteristic_lengths
from drakegrasp.batch.columns import result_arrays
from drakegrasp.batch.epsilon.routes import EPSILON_METRIC, epsilon_l1_batch
from drakegrasp.batch.inputs import METRICS, shape_of
from drakegrasp.batch.metrics import metric_moment_arms
from drakegrasp.batch.options import takes_batch_options
from drakegrasp.batch.ragged import accepts_ragged
from drakegrasp.batch.run.chunk import force_chunk, force_task, form_task
from drakegrasp.batch.run.stream import DEFAULT_CHUNK_SIZE, stream
from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import ContactModel
from drakegrasp.core.deprecation import keyword_only, renamed_keyword
from drakegrasp.core.tolerances import (
    DEFAULT_NUM_GENERATORS,
    DEFAULT_RANK_TOL,
    DEFAULT_TOL,
    ZERO_FRACTION,
)
from drakegrasp.core.validation import describe, plain_str
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "METRICS",
    "BatchClosureResult",
    "batch_force_closure",
    "batch_form_closure",
    "force_chunk_with_epsilon",
    "iter_batch_closure",
    "stream_force_closure",
    "stream_form_closure",
    "with_epsilon",
]


@checked_call
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


def collect(K: int, d: int, kind: str, tol: float, names, chunks):
    """One :class:`BatchClosureResult` from ``(slice or indices, arrays)`` parts."""
    out, out_metrics = result_arrays(K, kind, names)
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


def merge_results(
    K: int, d: int, parts: Sequence[tuple[np.ndarray, BatchClosureResult]]
) -> BatchClosureResult:
    """One result in input order from the results of a ragged batch's groups.

    Parameters
    ----------
    K, d : int
        Number of grasps and dimension (2 or 3).
    parts : sequence of (indices, BatchClosureResult)
        Each group's positions in the input and its result
        (:func:`drakegrasp.batch.ragged.run_groups`).
    """
    names = tuple(parts[0][1].metrics)
    chunks = ((idx, result.to_arrays()) for idx, result in parts)
    first = parts[0][1]
    return collect(K, d, first.kind, first.tol, names, chunks)


def force_chunk_with_epsilon(
    P: np.ndarray,
    Nrm: np.ndarray,
    mu_c: np.ndarray,
    nu_c: np.ndarray,
    p: np.ndarray,
    b: np.ndarray | None,
    *,
    metrics: Sequence[str],
    **options,
) -> dict[str, np.ndarray]:
    """LP2 of one chunk, then its ε L1: the two stages of a chunk that asks for ε.

    The LP stage (:func:`drakegrasp.batch.run.chunk.force_chunk`) and the ε
    stage (:func:`drakegrasp.batch.epsilon.routes.epsilon_l1_batch`) know
    nothing of each other; this is where they meet.  A top-level function, so
    a worker process runs it as it runs ``force_chunk``.

    Parameters
    ----------
    P, Nrm, mu_c, nu_c, p, b
        As :func:`drakegrasp.batch.run.chunk.force_chunk`.
    metrics : sequence of str
        Checked metric names, ``"epsilon_l1"`` among them; the others are
        ``force_chunk``'s.
    **options
        ``force_chunk``'s other keywords (``contact_model``, ``num_generators``,
        ``tol``, ``rank_tol``, ``kernel``).

    Returns
    -------
    dict of str to (k,) array
        ``force_chunk``'s arrays, then ``epsilon_l1``.
    """
    if b is None:  # the same default force_chunk gives a metric
        b = batched_characteristic_lengths(P, p)
    others = tuple(name for name in metrics if name != EPSILON_METRIC)
    out = force_chunk(P, Nrm, mu_c, nu_c, p, b, metrics=others, **options)
    out[EPSILON_METRIC] = epsilon_l1_batch(
        P, Nrm, mu_c, nu_c, p, b, contact_model=options["contact_model"],
        num_generators=options["num_generators"], kernel=options.get("kernel", "auto"),
    )  # fmt: skip
    return out


def with_epsilon(task: Callable) -> Callable:
    """An LP2 chunk-task builder whose chunks also give ε L1.

    ``task`` is the builder of :func:`drakegrasp.batch.run.chunk.force_task`
    (``(P, Nrm, slice) -> (function, args, options)``); the returned builder
    runs :func:`force_chunk_with_epsilon` on the same arguments instead.
    """

    def measured(P, Nrm, sl):
        _, args, options = task(P, Nrm, sl)
        return force_chunk_with_epsilon, args, options

    return measured


def force_chunks(
    positions, normals, mu, contact_model, num_generators, torsional_friction,
    reference_points, characteristic_lengths, tol, rank_tol, metrics, kernel,
    chunk_size, progress, workers,
) -> tuple[dict, Iterator[tuple[slice, dict[str, np.ndarray]]]]:  # fmt: skip
    """Validate the LP2 options once; return them and the stream of chunk results.

    The arguments are those of :func:`batch_force_closure`, in its order; the
    chunks are ``(slice, arrays)`` as :func:`stream_force_closure` yields them.
    """
    task, options = force_task(
        positions, mu, contact_model, num_generators, torsional_friction,
        reference_points, characteristic_lengths, tol, rank_tol, metrics, kernel,
    )  # fmt: skip
    if EPSILON_METRIC in options["metrics"]:
        task = with_epsilon(task)
    chunks = stream(
        positions, normals, kind="force", task=task, chunk_size=chunk_size,
        progress=progress, workers=workers, n_g=options["num_generators"],
        contact_model=options["contact_model"],
    )  # fmt: skip
    return options, chunks


def form_chunks(
    positions, normals, reference_points, characteristic_lengths, tol, rank_tol,
    metrics, kernel, chunk_size, progress, workers,
) -> tuple[dict, Iterator[tuple[slice, dict[str, np.ndarray]]]]:  # fmt: skip
    """:func:`force_chunks` for LP1 (:func:`batch_form_closure`'s arguments)."""
    task, options = form_task(
        positions, reference_points, characteristic_lengths, tol, rank_tol, metrics,
        kernel,
    )  # fmt: skip
    chunks = stream(
        positions, normals, kind="form", task=task, chunk_size=chunk_size,
        progress=progress, workers=workers,
    )  # fmt: skip
    return options, chunks


@checked_call
@renamed_keyword("model", "contact_model")
@keyword_only("mu", after=2)
@takes_batch_options
def stream_force_closure(
    positions,
    normals,
    *,
    mu: float | np.ndarray,
    contact_model: ContactModel | str = "hard_finger",
    num_generators: int = DEFAULT_NUM_GENERATORS,
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

    Parameters
    ----------
    positions : (K, N, 3) or (K, N, 2) float
        Contact points ``c_i``, metres, in each grasp's frame.  Any array-like
        that supports slicing along the first axis (e.g. ``numpy.memmap``); it
        is read one chunk at a time.  Stacked only: a list of per-grasp arrays
        with different ``N_k`` is refused (:func:`batch_force_closure` takes
        those).
    normals : (K, N, d) float
        Contact normals pointing into the object; normalised here.
    mu : float, (K,) or (K, N) float
        Coulomb friction coefficients (dimensionless), as in
        :func:`batch_force_closure`.
    contact_model : {"hard_finger", "frictionless", "soft_finger"}, optional
        Contact model of every contact (default ``"hard_finger"``).
    num_generators : int, optional
        Generators ``n_g >= 3`` of each linearised spatial cone (default 8).
    torsional_friction : float, (K,) or (K, N) float, optional
        ``ν`` of soft fingers (dimensionless; moment bound ``b ν f_n``);
        required with ``contact_model="soft_finger"``.
    reference_points : (d,) or (K, d) float, optional
        Point ``p`` (metres) about which moments are taken; default the origin.
    characteristic_lengths : float or (K,) float, optional
        ``b > 0`` (metres); default the largest ``‖c_i - p‖`` of each grasp.
    tol, rank_tol : float, optional
        Closure needs ``d* > tol`` (default 1e-6); relative threshold of the
        rank test (default 1e-9).
    chunk_size : int, optional
        Grasps per chunk, the unit that is yielded; default (None) sized by
        the engine's memory budget.
    progress : bool, optional
        Show a tqdm progress bar (needs ``tqdm``).
    metrics : sequence of str, optional
        Metrics to add to each chunk's arrays, as in
        :func:`batch_force_closure`.
    workers : int, optional
        Worker processes; default (None) every available core, but a batch
        of fewer than :data:`~drakegrasp.batch.run.stream.PARALLEL_MIN_WORK`
        contacts (``K N``) then runs in this process.
    kernel : {"auto", "numba", "numpy"}, optional
        The LP and ε kernels (default ``"auto"``: numba when installed).
    options : BatchOptions, optional
        The run's choices (``contact_model``, ``num_generators``, ``tol``,
        ``rank_tol``, ``metrics``, ``kernel``, ``chunk_size``, ``workers``,
        ``progress``) as one object instead of those keywords; an option
        given both ways raises :class:`~drakegrasp.InvalidOptionError`.

    Yields
    ------
    slice, dict of str to (k,) ndarray
        The grasps of the input that the chunk covers, and their
        ``is_closure``, ``d_star``, ``rank``, ``margin``, ``converged``,
        ``normal_certificate`` and requested metrics.
    """
    _, chunks = force_chunks(
        positions, normals, mu, contact_model, num_generators, torsional_friction,
        reference_points, characteristic_lengths, tol, rank_tol, metrics, kernel,
        chunk_size, progress, workers,
    )  # fmt: skip
    return chunks


@checked_call
@takes_batch_options
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

    Parameters
    ----------
    positions, normals : (K, N, 3) or (K, N, 2) float
        Contact points (metres) and inward normals (normalised here), stacked
        (not ragged), any array-like that slices along the first axis.
    reference_points : (d,) or (K, d) float, optional
        Moment reference ``p`` (metres); default the origin.
    characteristic_lengths : float or (K,) float, optional
        ``b > 0`` (metres) for the scaled singular-value metrics (default as
        :class:`~drakegrasp.Grasp`).
    tol, rank_tol, chunk_size, progress, workers, kernel : optional
        As in :func:`stream_force_closure`.
    metrics : sequence of str, optional
        ``"sigma_min"``, ``"isotropy"``, ``"ellipsoid_volume"`` of ``G_n``.
    options : BatchOptions, optional
        The run's choices as one object instead of the keywords above (an
        option given both ways raises
        :class:`~drakegrasp.InvalidOptionError`); its friction options
        ``contact_model`` and ``num_generators`` are ignored.

    Yields
    ------
    slice, dict of str to (k,) ndarray
        The grasps of the input that the chunk covers, and their
        ``is_closure``, ``d_star``, ``rank`` (of ``G_n``), ``margin``,
        ``converged`` and requested metrics.
    """
    _, chunks = form_chunks(
        positions, normals, reference_points, characteristic_lengths, tol, rank_tol,
        metrics, kernel, chunk_size, progress, workers,
    )  # fmt: skip
    return chunks


@checked_call
@renamed_keyword("model", "contact_model")
@keyword_only("mu", after=2)
@accepts_ragged(merge_results, check=metric_moment_arms)
@takes_batch_options
def batch_force_closure(
    positions: np.ndarray,
    normals: np.ndarray,
    *,
    mu: float | np.ndarray,
    contact_model: ContactModel | str = "hard_finger",
    num_generators: int = DEFAULT_NUM_GENERATORS,
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
    positions : (K, N, 3) or (K, N, 2) float, or list of K (N_k, d) float
        Contact points ``c_i``, metres, in each grasp's frame.  Any array-like
        that supports slicing along the first axis (e.g. ``numpy.memmap``).
        Grasps with different numbers of contacts come as a list of per-grasp
        arrays (ragged; :mod:`drakegrasp.batch.ragged`): they are run in groups
        of equal ``N_k`` and returned in input order.
    normals : (K, N, d) float, or list of K (N_k, d) float
        Contact normals pointing into the object; normalised here.  A zero or
        non-finite normal raises :class:`~drakegrasp.InvalidContactError`
        naming the grasp and contact.
    mu : float, (K,) or (K, N) float, or list of K (N_k,) float
        Coulomb friction coefficients: 0 or in ``[1e-12, 1e12]`` (the range of
        :mod:`drakegrasp.core.validation`, the same as the single-grasp path).  A
        hard finger with ``μ = 0`` acts as frictionless, as in the single-grasp
        path.  With ragged positions: a scalar, one per grasp (K,), or one
        array per grasp.
    contact_model : {"hard_finger", "frictionless", "soft_finger"}, optional
        Contact model of every contact (soft fingers are spatial only).
    num_generators : int, optional
        Generators ``n_g >= 3`` of each linearised spatial cone (default 8).
    torsional_friction : float, (K,) or (K, N) float, optional
        ``ν`` of soft fingers (moment bound ``b ν f_n``), 0 or in
        ``[1e-12, 1e12]``.  ``None`` (default) means not given: required with
        ``contact_model="soft_finger"`` (an explicit 0 makes soft fingers act as hard
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
        ``b``, a soft finger's torsion column kept ``[0; n]``, as
        :func:`~drakegrasp.grasp_singular_values`): ``σ_min``,
        ``σ_min/σ_max`` and ``∏ σ_i`` (the wrench ellipsoid's volume over
        the unit ball's) — and ``"epsilon_l1"``, the
        Ferrari–Canny L1 ε of :func:`drakegrasp.quality.ferrari_canny`,
        computed as :func:`~drakegrasp.batch.batch_epsilon_l1` does (a compiled
        kernel; Qhull per grasp with ``kernel="numpy"`` or without numba).
    workers : int, optional
        Worker processes; default (None) every available core, but a batch
        of fewer than :data:`~drakegrasp.batch.run.stream.PARALLEL_MIN_WORK`
        contacts (``K N``) then runs in this process.  Results are
        bitwise the same for any number (:mod:`drakegrasp.batch.run.workers`).
    kernel : {"auto", "numba", "numpy"}, optional
        Interior-point implementation: the compiled one (needs numba) or the
        numpy reference; ``"auto"`` takes numba when installed.  The same
        choice for ``"epsilon_l1"``.
    options : BatchOptions, optional
        The run's choices (``contact_model``, ``num_generators``, ``tol``,
        ``rank_tol``, ``metrics``, ``kernel``, ``chunk_size``, ``workers``,
        ``progress``) as one :class:`~drakegrasp.BatchOptions`, checked when
        it was made, instead of those keywords; an option given both ways
        raises :class:`~drakegrasp.InvalidOptionError`.

    Returns
    -------
    BatchClosureResult
        ``is_closure``, ``d_star``, ``rank`` (of ``G`` over the effective
        components), ``margin``, ``converged``, ``normal_certificate`` and the
        metrics, all (K,).

    Notes
    -----
    The same LP as :func:`drakegrasp.force_closure` (facet formulation):

    .. math::

        \max d \;\text{s.t.}\; G f = 0,\; F f - \mathbf 1 d \ge 0,\; d \ge 0,\;
        \textstyle\sum f_n \le N ,

    solved on ``N(G)`` for a whole chunk by the compiled kernels of
    :mod:`drakegrasp.batch.lp` (an exact active-set method for small null
    spaces, a block interior-point method for the rest).
    """
    K, N, d = shape_of("positions", positions)
    options, chunks = force_chunks(
        positions, normals, mu, contact_model, num_generators, torsional_friction,
        reference_points, characteristic_lengths, tol, rank_tol, metrics, kernel,
        chunk_size, progress, workers,
    )  # fmt: skip
    return collect(K, d, "force", options["tol"], options["metrics"], chunks)


@checked_call
@accepts_ragged(merge_results, check=metric_moment_arms)
@takes_batch_options
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
    positions, normals : (K, N, d) float, or lists of K (N_k, d) float
        Contact points (metres) and inward normals (normalised here), stacked
        or ragged, as in :func:`batch_force_closure`.
    reference_points : (d,) or (K, d) float, optional
        Moment reference ``p``; default the origin.
    characteristic_lengths : float or (K,) float, optional
        ``b`` for the scaled singular-value metrics (default as
        :class:`~drakegrasp.Grasp`).
    tol, rank_tol, chunk_size, progress, workers, kernel : optional
        As in :func:`batch_force_closure`.
    metrics : sequence of str, optional
        ``"sigma_min"``, ``"isotropy"``, ``"ellipsoid_volume"`` of ``G_n``.
    options : BatchOptions, optional
        The run's choices as one :class:`~drakegrasp.BatchOptions` instead of
        the keywords above (an option given both ways raises
        :class:`~drakegrasp.InvalidOptionError`); its friction options
        ``contact_model`` and ``num_generators`` are ignored.

    Returns
    -------
    BatchClosureResult
        ``kind = "form"``; ``rank`` is ``rank(G_n)``; no
        ``normal_certificate``.

    Notes
    -----
    The same LP as :func:`drakegrasp.form_closure`:

    .. math::

        \max d \;\text{s.t.}\; G_n f_n = 0,\; f_n - \mathbf 1 d \ge 0,\;
        d \ge 0,\; \mathbf 1^T f_n \le N .
    """
    K, N, d = shape_of("positions", positions)
    options, chunks = form_chunks(
        positions, normals, reference_points, characteristic_lengths, tol, rank_tol,
        metrics, kernel, chunk_size, progress, workers,
    )  # fmt: skip
    return collect(K, d, "form", options["tol"], options["metrics"], chunks)


@checked_call
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
        Keyword options of that function (``options=BatchOptions(...)``
        included), applied to every chunk.

    Yields
    ------
    BatchClosureResult
        The result of each chunk, in order.  Error messages index grasps within
        their chunk.
    """
    kind = plain_str(kind)
    if type(kind) is not str or kind not in ("force", "form"):
        raise InvalidOptionError(
            f"kind must be 'force' or 'form', got {describe(kind)}"
        )
    try:
        items = iter(chunks)
    except Exception:  # noqa: BLE001 - not iterable, or a hostile __iter__
        raise InvalidOptionError(
            "chunks must be an iterable of (positions, normals[, mu]) tuples or "
            f"mappings, got {type(chunks).__name__}"
        ) from None
    for c, item in enumerate(items):
        if isinstance(item, Mapping):
            arrays = dict(item)
        else:
            count = len(item) if isinstance(item, Sized) else None
            if count is None or count > 3:
                raise InvalidOptionError(
                    f"chunk {c} must be a tuple (positions, normals) or (positions, "
                    f"normals, mu), or a mapping with those keys; got "
                    + type(item).__name__
                    + ("" if count is None else f" of length {count}")
                )
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
            yield batch_force_closure(P, Nrm, mu=mu, **arrays, **options)
