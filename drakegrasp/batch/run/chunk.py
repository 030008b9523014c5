r"""One chunk of grasps, start to finish: validated arrays in, result arrays out.

The chunk functions (:func:`force_chunk`, :func:`form_chunk`) are the unit of
work of the batch engine.  They are top-level and take only arrays and plain
options, so a chunk can run in this process or
in a worker process (:mod:`drakegrasp.batch.run.workers`) with bitwise the same
result: nothing in a chunk's computation depends on where it runs or on the
other chunks.

Ranks, row spaces and null spaces are decided on the normalised grasp matrix
of :mod:`drakegrasp.batch.build.rowspace` (moments about the contacts' centroid,
divided by their spread), so verdicts do not depend on units or on the
reference point; ``d*`` does not either, since ``N(G)`` is the same.  A soft
finger's torsion variable is measured in units of that spread, and its facet
column is scaled to match.

A planner that asks what fraction of perturbed copies of a grasp stay force
closure needs each copy's verdict, never its ``d*``: :func:`force_verdicts`
streams the LP2 chunks in their verdict-only mode, each LP stopping once its
verdict is proved.  It lives with the mode it runs, and the chunk's LP imports
nothing of the ε stage (:mod:`drakegrasp.batch.epsilon.routes`).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np

from drakegrasp.batch.build.construction import (
    FRICTIONLESS,
    KIND_COMPONENTS,
    PLANAR_HARD,
    SOFT_FULL,
    SOFT_TORSION,
    SPATIAL_HARD,
    batched_characteristic_lengths,
    batched_grasp_matrix,
    batched_normal_grasp_matrix,
    contact_kinds,
    kind_facets,
)
from drakegrasp.batch.build.rowspace import (
    _householder,
    _inverse_frobenius,
    normalised_positions,
)
from drakegrasp.batch.inputs import (
    _characteristic_lengths,
    _check_tol,
    _reference_points,
    check_chunk_coefficients,
    check_metrics,
    compiled_route,
    per_contact_getter,
    resolve_kernel,
    shape_of,
)
from drakegrasp.batch.lp.dstar import solve_dstar_blocks
from drakegrasp.batch.metrics import check_moment_arms, singular_value_metrics
from drakegrasp.batch.run.stream import DEFAULT_CHUNK_SIZE, stream
from drakegrasp.core.contact import ContactModel, missing_torsional_friction
from drakegrasp.core.deprecation import renamed_keyword
from drakegrasp.core.tolerances import (
    DEFAULT_NUM_GENERATORS,
    DEFAULT_RANK_TOL,
    DEFAULT_TOL,
)
from drakegrasp.core.validation import check_num_generators
from drakegrasp.errors import InvalidContactError, InvalidOptionError

__all__ = [
    "check_form_metrics",
    "finish",
    "force_chunk",
    "force_task",
    "force_verdicts",
    "form_chunk",
    "form_task",
]

_TORSION_COLUMN = {SOFT_FULL: 3, SOFT_TORSION: 1}


def group_layouts(kinds: np.ndarray):
    """Yield (layout tuple, row indices) for the distinct rows of ``kinds``."""
    if kinds.shape[0] == 0:
        return
    first = kinds[0]
    if (kinds == first).all():
        yield tuple(int(x) for x in first), np.arange(kinds.shape[0])
        return
    layouts, inverse = np.unique(kinds, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    for j, layout in enumerate(layouts):
        yield tuple(int(x) for x in layout), np.flatnonzero(inverse == j)


def _lp1(Gn: np.ndarray, rank_tol: float, kernel: str):
    """LP1 on stacked normalised normal grasp matrices ``G̃_n`` (k, w, N)."""
    K, _, N = Gn.shape
    slices = [slice(i, i + 1) for i in range(N)]
    ones = np.ones((1, 1, 1))
    return solve_dstar_blocks(
        Gn,
        [ones] * N,
        slices,
        np.arange(N),
        np.ones((K, N)),
        rank_tol=rank_tol,
        kernel=kernel,
    )


def _compiled(kernel: str) -> bool:
    """Whether a chunk's arrays are built by the compiled loops (numba)."""
    return compiled_route(kernel)


def _positions(P, compiled: bool):
    if compiled:
        from drakegrasp.batch.build.construction_kernel import (
            normalised_positions_stack,
        )

        return normalised_positions_stack(P)
    return normalised_positions(P)


def _subset(P, Nrm, p, rows):
    """The grasps ``rows`` (None: all) of the arrays, with ``p`` None as 0."""
    if rows is not None:
        P, Nrm, p = P[rows], Nrm[rows], None if p is None else p[rows]
    return P, Nrm, np.zeros((P.shape[0], P.shape[2])) if p is None else p


def _grasp_matrices(P, Nrm, p, layout, rows, compiled: bool):
    """``batched_grasp_matrix`` of grasps ``rows`` (None: all), ``p`` None: 0."""
    if compiled:
        from drakegrasp.batch.build.construction_kernel import grasp_matrix_stack

        return grasp_matrix_stack(P, Nrm, layout, reference_points=p, rows=rows)
    return batched_grasp_matrix(*_subset(P, Nrm, p, rows), layout)


def _normal_matrices(P, Nrm, p, rows, compiled: bool):
    """``G_n`` (k, w, N) of grasps ``rows`` (None: all) about ``p`` (None: 0)."""
    if compiled:
        layout = (FRICTIONLESS,) * P.shape[1]
        return _grasp_matrices(P, Nrm, p, layout, rows, True)[0]
    return batched_normal_grasp_matrix(*_subset(P, Nrm, p, rows))


def _normal_certificates(Pn, Nrm, kinds, rank, d_star, *, tol, rank_tol, kernel):
    """LP1's ``d*`` where only normal forces could prove force closure (else NaN).

    Those are the grasps with full rank, ``d* <= tol`` and some friction, the
    same that :func:`drakegrasp.force_closure` checks.
    """
    out = np.full(Pn.shape[0], np.nan)
    w = 6 if Pn.shape[2] == 3 else 3
    N = Pn.shape[1]
    rubs = kinds != FRICTIONLESS
    frictional = True if rubs.all() else rubs.any(axis=1)
    rows = np.flatnonzero((rank == w) & frictional & ~(d_star > tol))
    if rows.size == 0:
        return out
    compiled = _compiled(kernel)
    if N <= w:
        # Balancing normal forces need N(G_n) != {0}; with no more contacts than
        # wrench rows that is rare.  A QR (as in rowspace; compiled: a Cholesky
        # factor of G_nᵀ G_n with a rounding margin) certifies full column rank
        # for most grasps; the rest take the exact SVD rule.
        if compiled:
            from drakegrasp.batch.build.construction_kernel import normal_rank_certain

            rows = rows[~normal_rank_certain(Pn, Nrm, rows, rank_tol)]
        else:
            Gn = _normal_matrices(Pn, Nrm, None, rows, False)
            A = np.ascontiguousarray(np.transpose(Gn, (1, 2, 0)))  # (w, N, k)
            R, _ = _householder(A)
            norm = np.sqrt(np.einsum("kij,kij->k", Gn, Gn))
            rows = rows[~(_inverse_frobenius(R) * rank_tol * norm < 1.0)]
        if rows.size:
            Gn = _normal_matrices(Pn, Nrm, None, rows, compiled)
            sv = np.linalg.svd(Gn, compute_uv=False)
            deficient = sv[:, -1] <= rank_tol * sv[:, 0]
            rows, Gn = rows[deficient], Gn[deficient]
        if rows.size == 0:
            return out
    else:
        Gn = _normal_matrices(Pn, Nrm, None, rows, compiled)
    out[rows] = _lp1(Gn, rank_tol, kernel).d_star
    return out


@functools.lru_cache(maxsize=64)
def _shared_cone(kind: int, mu: float, n_g: int) -> np.ndarray:
    """Facets (1, r, c) of a contact whose μ every grasp of a stack shares.

    Kept across chunks (building one costs ~70 µs of numpy calls, as much as
    the LPs of ~30 three-finger grasps); read-only, so no caller can change
    the cached rows.
    """
    F = kind_facets(kind, np.array([mu]), None, n_g)
    F.flags.writeable = False
    return F


def _layout_lp(Pn, Nrm, spread, mu_c, torsion, layout, n_g, rank_tol, kernel, rows,
               verdict_tol=None):  # fmt: skip
    """LP2 for the grasps ``rows`` (None: all) that share one layout.

    Returns (d_star, rank, converged) of those grasps; ``torsion`` (None when
    no contact is soft) is ``b ν`` per contact.  ``verdict_tol``: see
    :func:`~drakegrasp.batch.lp.dstar.solve_dstar_blocks`.
    """
    G, normal_cols = _grasp_matrices(Pn, Nrm, None, layout, rows, _compiled(kernel))
    if rows is not None:
        spread, mu_c = spread[rows], mu_c[rows]
        torsion = None if torsion is None else torsion[rows]
    facets, slices, start, built = [], [], 0, []
    # Contacts with one μ for all grasps (whole-array test first: it is cheaper).
    if (mu_c == mu_c[:1, :1]).all():
        uniform = np.ones(mu_c.shape[1], dtype=bool)
    else:
        uniform = (mu_c == mu_c[:1]).all(axis=0)
    kappa = np.sqrt(1.0 + mu_c**2)  # ‖f_i‖ <= κ_i f_n (torsion columns below)
    for i, kind in enumerate(layout):
        k_i = len(KIND_COMPONENTS[kind])
        mu_i = mu_c[:, i]
        if kind in _TORSION_COLUMN:
            tor_i = torsion[:, i]
            kappa[:, i] = np.sqrt(1.0 + (mu_i + tor_i / spread) ** 2)
            F = kind_facets(kind, mu_i, tor_i, n_g).copy()
            F[:, :, _TORSION_COLUMN[kind]] *= spread[:, None]  # m_n = L m̃_n
        elif uniform[i]:  # one cone for all grasps
            F = _shared_cone(kind, float(mu_i[0]), n_g)
        else:
            # one μ per grasp, often the same for all its contacts (robustness
            # copies): an earlier contact's rows of the same kind and μ serve
            F = next(
                (
                    Fj
                    for kj, mu_j, Fj in built
                    if kj == kind and np.array_equal(mu_j, mu_i)
                ),
                None,
            )
            if F is None:
                F = kind_facets(kind, mu_i, None, n_g)
                built.append((kind, mu_i, F))
        facets.append(F)
        slices.append(slice(start, start + k_i))
        start += k_i
    sol = solve_dstar_blocks(
        G, facets, slices, normal_cols, kappa, rank_tol=rank_tol, kernel=kernel,
        verdict_tol=verdict_tol,
    )  # fmt: skip
    return sol.d_star, sol.rank, sol.converged


@renamed_keyword("model", "contact_model")
def force_chunk(
    P: np.ndarray,
    Nrm: np.ndarray,
    mu_c: np.ndarray,
    nu_c: np.ndarray,
    p: np.ndarray,
    b: np.ndarray | None,
    *,
    contact_model: str,
    num_generators: int,
    tol: float,
    rank_tol: float,
    metrics: Sequence[str],
    kernel: str = "auto",
    verdict_only: bool = False,
) -> dict[str, np.ndarray]:
    """LP2 (force closure) of one chunk of validated grasps.

    Parameters
    ----------
    P, Nrm : (k, N, d) float
        Contact points (metres) and unit inward normals.
    mu_c, nu_c : (k, N) float
        Friction and torsional friction coefficients (checked ``>= 0``).
    p : (k, d) float
        Reference points.
    b : (k,) float or None
        Characteristic lengths (None: the default of :class:`~drakegrasp.Grasp`).
    contact_model, num_generators, tol, rank_tol, metrics, kernel
        As in :func:`drakegrasp.batch.batch_force_closure`, ``metrics`` less
        ``"epsilon_l1"``: ε is a stage of its own
        (:func:`drakegrasp.batch.api.force_chunk_with_epsilon`).
    verdict_only : bool, optional
        Internal (:func:`force_verdicts`): each LP stops once its verdict is
        proved, so ``is_closure`` is exact but ``d_star`` and ``margin`` are
        only bounds on the right side of ``tol``.

    Returns
    -------
    dict of str to (k,) array
        ``is_closure``, ``d_star``, ``rank``, ``margin``, ``converged``,
        ``normal_certificate`` and the metrics.
    """
    if "epsilon_l1" in metrics:
        raise InvalidOptionError(
            "force_chunk gives the singular-value metrics; ε L1 (metric "
            "'epsilon_l1') is the ε stage's: batch.api.with_epsilon"
        )
    k, N, d = P.shape
    compiled = _compiled(kernel)
    if b is None and (contact_model == "soft_finger" or metrics):  # else b is unused
        b = batched_characteristic_lengths(P, p)
    Pn, spread = _positions(P, compiled)
    kinds = contact_kinds(mu_c, nu_c, contact_model=contact_model, dim=d)
    d_star = np.zeros(k)
    rank = np.zeros(k, dtype=int)
    converged = np.ones(k, dtype=bool)
    torsion = b[:, None] * nu_c if contact_model == "soft_finger" else None
    for layout, rows in group_layouts(kinds):
        d_star[rows], rank[rows], converged[rows] = _layout_lp(
            Pn,
            Nrm,
            spread,
            mu_c,
            torsion,
            layout,
            num_generators,
            rank_tol,
            kernel,
            rows if rows.size < k else None,
            tol if verdict_only else None,
        )
    normal = _normal_certificates(
        Pn, Nrm, kinds, rank, d_star, tol=tol, rank_tol=rank_tol, kernel=kernel
    )
    out = finish(d_star, rank, converged, normal, tol=tol, required=6 if d == 3 else 3)
    if metrics:
        full = {
            "frictionless": FRICTIONLESS,
            "hard_finger": SPATIAL_HARD if d == 3 else PLANAR_HARD,
            "soft_finger": SOFT_FULL,
        }[contact_model]
        Gfull, _ = _grasp_matrices(P, Nrm, p, (full,) * N, None, compiled)
        torsion = 4 * np.arange(N) + _TORSION_COLUMN[full] if full == SOFT_FULL else ()
        out.update(singular_value_metrics(Gfull, b, metrics, torsion))
    return out


def form_chunk(
    P: np.ndarray,
    Nrm: np.ndarray,
    p: np.ndarray,
    b: np.ndarray | None,
    *,
    tol: float,
    rank_tol: float,
    metrics: Sequence[str],
    kernel: str = "auto",
) -> dict[str, np.ndarray]:
    """LP1 (first-order form closure) of one chunk; see :func:`force_chunk`."""
    k, N, d = P.shape
    compiled = _compiled(kernel)
    Pn, _ = _positions(P, compiled)
    sol = _lp1(_normal_matrices(Pn, Nrm, None, None, compiled), rank_tol, kernel)
    out = finish(
        sol.d_star, sol.rank, sol.converged, None, tol=tol, required=6 if d == 3 else 3
    )
    if metrics:
        if b is None:
            b = batched_characteristic_lengths(P, p)
        Gn = _normal_matrices(P, Nrm, p, None, compiled)
        out.update(singular_value_metrics(Gn, b, metrics))
    return out


def finish(d_star, rank, converged, normal_d_star, *, tol: float, required: int):
    """Verdicts and margins from ``d*``, the ranks and the normal-force LP."""
    full = rank == required
    if normal_d_star is None:
        certified = None
        is_closure = full & (d_star > tol)
        margin = (d_star - tol) / tol
    else:
        certified = full & ~(d_star > tol) & (normal_d_star > tol)
        is_closure = full & (d_star > tol) | certified
        margin = (np.where(certified, normal_d_star, d_star) - tol) / tol
    out = {
        "is_closure": is_closure,
        "d_star": d_star,
        "rank": rank,
        "margin": margin,
        "converged": converged,
    }
    if certified is not None:
        out["normal_certificate"] = certified
    return out


# ------------------------------------------------ a run's task builders


@renamed_keyword("model", "contact_model")
def force_task(positions, mu, contact_model, num_generators, torsional_friction,
                reference_points, characteristic_lengths, tol, rank_tol, metrics,
                kernel):  # fmt: skip
    """Validate options once; return the chunk-task builder of LP2 and options."""
    contact_model = ContactModel.parse(contact_model).value
    K, N, d = shape_of("positions", positions)
    if contact_model == "soft_finger" and d == 2:
        raise InvalidContactError(
            "a soft-finger contact is spatial only; planar contacts are "
            "'frictionless' or 'hard_finger'"
        )
    options = {
        "contact_model": contact_model,
        "num_generators": check_num_generators(num_generators),
        "tol": _check_tol("tol", tol),
        "rank_tol": _check_tol("rank_tol", rank_tol),
        "metrics": check_metrics(metrics),
        "kernel": resolve_kernel(kernel),
    }
    get_mu = per_contact_getter("mu", mu, K, N)
    if torsional_friction is None:
        if contact_model == "soft_finger":
            raise missing_torsional_friction()
        torsional_friction = 0.0
    get_nu = per_contact_getter("torsional_friction", torsional_friction, K, N)
    get_p = _reference_points(reference_points, K, d)
    get_b = _characteristic_lengths(characteristic_lengths, K)

    def task(P, Nrm, sl):
        mu_c = get_mu(sl)
        check_chunk_coefficients("mu", mu_c, sl.start)
        nu_c = get_nu(sl)  # checked for every model, as mu and a scalar nu are
        check_chunk_coefficients("torsional_friction", nu_c, sl.start)
        p = np.ascontiguousarray(get_p(sl))
        b = None if get_b is None else np.ascontiguousarray(get_b(sl))
        if b is not None and options["metrics"]:
            check_moment_arms(P, p, b, sl.start)
        return force_chunk, (P, Nrm, mu_c, nu_c, p, b), options

    return task, options


def check_form_metrics(names: Sequence[str]) -> None:
    """Refuse a metric form closure cannot give (ε needs friction).

    Raises
    ------
    InvalidOptionError
        ``epsilon_l1`` among ``names`` (checked metric names).
    """
    if "epsilon_l1" in names:
        raise InvalidOptionError(
            "metric 'epsilon_l1' needs friction; use batch_force_closure"
        )


def form_task(positions, reference_points, characteristic_lengths, tol, rank_tol,
               metrics, kernel):  # fmt: skip
    """Validate options once; return the chunk-task builder of LP1 and options."""
    K, N, d = shape_of("positions", positions)
    options = {
        "tol": _check_tol("tol", tol),
        "rank_tol": _check_tol("rank_tol", rank_tol),
        "metrics": check_metrics(metrics),
        "kernel": resolve_kernel(kernel),
    }
    check_form_metrics(options["metrics"])
    get_p = _reference_points(reference_points, K, d)
    get_b = _characteristic_lengths(characteristic_lengths, K)

    def task(P, Nrm, sl):
        p = np.ascontiguousarray(get_p(sl))
        b = None if get_b is None else np.ascontiguousarray(get_b(sl))
        if b is not None and options["metrics"]:
            check_moment_arms(P, p, b, sl.start)
        return form_chunk, (P, Nrm, p, b), options

    return task, options


def force_verdicts(
    positions,
    normals,
    *,
    mu,
    contact_model="hard_finger",
    torsional_friction=None,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    workers=None,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
    kernel: str = "auto",
) -> np.ndarray:
    """``is_closure`` of LP2 for ``K`` grasps of ``N`` contacts, verdicts only.

    Internal, for counts of verdicts (:func:`drakegrasp.planning.ranking.robustness`
    and :func:`drakegrasp.planning.reclose.reclosed_robustness`): the same
    validation, chunks, workers and rules as
    :func:`drakegrasp.batch.batch_force_closure` (rank, normal-force
    certificate), whose ``is_closure`` it returns, but each LP stops as soon
    as its verdict is proved either way (a feasible point above the
    threshold, a dual bound below it, a rank-deficient ``G``: see
    :func:`drakegrasp.batch.lp.dstar.solve_dstar_blocks`'s ``verdict_tol``).

    Parameters
    ----------
    positions, normals : (K, N, d) float
        Contact points (metres) and unit inward normals, one frame per grasp.
    mu, contact_model, torsional_friction, num_generators
        As :func:`drakegrasp.batch.batch_force_closure`.
    workers, tol, rank_tol, kernel
        As :func:`drakegrasp.batch.batch_force_closure`.

    Returns
    -------
    (K,) bool
    """
    K = shape_of("positions", positions)[0]
    task, options = force_task(
        positions, mu, contact_model, num_generators, torsional_friction, None,
        None, tol, rank_tol, (), kernel,
    )  # fmt: skip

    def verdict_task(P, Nrm, sl):
        fn, args, opts = task(P, Nrm, sl)
        return fn, args, {**opts, "verdict_only": True}

    out = np.zeros(K, dtype=bool)
    for sl, arrays in stream(
        positions, normals, kind="force", task=verdict_task,
        chunk_size=DEFAULT_CHUNK_SIZE,
        progress=False, workers=workers, n_g=options["num_generators"],
        contact_model=options["contact_model"],
    ):  # fmt: skip
        out[sl] = arrays["is_closure"]
    return out
