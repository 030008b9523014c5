"""LP2 verdicts of many grasps, for counting them (robustness), in the batch engine.

A planner that asks what fraction of perturbed copies of a grasp stay force
closure needs each copy's verdict, never its ``d*``: :func:`force_verdicts`
runs the chunks of :func:`drakegrasp.batch.batch_force_closure` with each LP
stopping once its verdict is proved.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.batch.inputs import shape_of
from drakegrasp.batch.run.chunk import force_task
from drakegrasp.batch.run.stream import DEFAULT_CHUNK_SIZE, stream
from drakegrasp.core.tolerances import (
    DEFAULT_NUM_GENERATORS,
    DEFAULT_RANK_TOL,
    DEFAULT_TOL,
)

__all__ = ["force_verdicts"]


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
    ):  # fmt: skip
        out[sl] = arrays["is_closure"]
    return out
