"""Closure of many grasps at once: arrays in, arrays out, streamed in chunks.

:func:`batch_force_closure` (LP2) and :func:`batch_form_closure` (LP1) decide
closure for ``K`` grasps with ``N`` contacts each, with the conventions and
verdicts of :mod:`drakegrasp.closure.verdicts`; :func:`batch_epsilon_l1` gives their
Ferrari–Canny L1 ε; :func:`iter_batch_closure` consumes a stream of chunks
lazily; :func:`batch_grasp_forces` finds the grasp forces of many grasps
under load (a loop over the single-grasp program,
:mod:`~drakegrasp.batch.loads`); :func:`evaluate_file` runs the closure
functions on a ``.npz`` file (the ``drakegrasp batch`` command).

Modules: :mod:`~drakegrasp.batch.construction` (vectorised frames, grasp
matrices and cone facets), :mod:`~drakegrasp.batch.reduction` (null-space
reduction of LP1/LP2), :mod:`~drakegrasp.batch.ipm` (batched interior-point
method), :mod:`~drakegrasp.batch.engine` (chunked drivers),
:mod:`~drakegrasp.batch.epsilon` (batch ε: :mod:`~drakegrasp.batch.wrenches`,
:mod:`~drakegrasp.batch.epsilon_kernel`, :mod:`~drakegrasp.batch.polytope`),
:mod:`~drakegrasp.batch.io` (files), :mod:`~drakegrasp.batch.writers` (results
streamed to .npz/.parquet in flat memory), :mod:`~drakegrasp.batch.parallel`
(worker processes).
"""

from drakegrasp.batch.engine import (
    DEFAULT_CHUNK_SIZE,
    METRICS,
    BatchClosureResult,
    batch_force_closure,
    batch_form_closure,
    iter_batch_closure,
    stream_force_closure,
    stream_form_closure,
)
from drakegrasp.batch.epsilon import batch_epsilon_l1
from drakegrasp.batch.io import evaluate_file, read_grasps, write_result
from drakegrasp.batch.loads import BatchGraspForceResult, batch_grasp_forces
from drakegrasp.batch.writers import BatchSummary, stream_file, write_chunks

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "METRICS",
    "BatchClosureResult",
    "BatchGraspForceResult",
    "BatchSummary",
    "batch_epsilon_l1",
    "batch_force_closure",
    "batch_form_closure",
    "batch_grasp_forces",
    "evaluate_file",
    "iter_batch_closure",
    "read_grasps",
    "stream_file",
    "stream_force_closure",
    "stream_form_closure",
    "write_chunks",
    "write_result",
]
