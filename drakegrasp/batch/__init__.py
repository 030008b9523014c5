"""Closure of many grasps at once: arrays in, arrays out, streamed in chunks.

:func:`batch_force_closure` (LP2) and :func:`batch_form_closure` (LP1) decide
closure for ``K`` grasps with ``N`` contacts each, with the conventions and
verdicts of :mod:`drakegrasp.closure.verdicts`; :func:`batch_epsilon_l1` gives
their Ferrari–Canny L1 ε; :func:`iter_batch_closure` consumes a stream of
chunks lazily; :func:`evaluate_file` and :func:`stream_file` run them on a file
(the ``drakegrasp batch`` command).

The folder reads as the pipeline, one stage per room:

* :mod:`~drakegrasp.batch.api`: the public functions and
  :class:`BatchClosureResult`; :mod:`~drakegrasp.batch.options`: their
  options as one object, :class:`BatchOptions`;
* :mod:`~drakegrasp.batch.inputs`: arrays and options checked, once, and the
  kernel choice resolved; :mod:`~drakegrasp.batch.ragged`: grasps with
  different numbers of contacts grouped by count;
* :mod:`~drakegrasp.batch.run`: the chunk stream, one chunk start to finish,
  worker processes and shared memory;
* :mod:`~drakegrasp.batch.build`: frames, grasp matrices, facets, ranks and
  wrenches of a chunk;
* :mod:`~drakegrasp.batch.lp`: ``d*`` from the compiled LP kernels;
* :mod:`~drakegrasp.batch.epsilon` and :mod:`~drakegrasp.batch.metrics`: ε and
  the singular-value metrics;
* :mod:`~drakegrasp.batch.witnesses`: certificates of the failing grasps;
* :mod:`~drakegrasp.batch.loads`: grasp forces under load, grasp by grasp;
* :mod:`~drakegrasp.batch.files`: one reader, one writer per format, one file
  driver.
"""

from drakegrasp.batch.api import (
    DEFAULT_CHUNK_SIZE,
    METRICS,
    BatchClosureResult,
    batch_force_closure,
    batch_form_closure,
    iter_batch_closure,
    stream_force_closure,
    stream_form_closure,
)
from drakegrasp.batch.epsilon.driver import batch_epsilon_l1
from drakegrasp.batch.files.driver import evaluate_file, stream_file, write_result
from drakegrasp.batch.files.reader import read_grasps
from drakegrasp.batch.files.writer import BatchSummary, write_chunks
from drakegrasp.batch.loads import batch_grasp_forces
from drakegrasp.batch.options import BatchOptions

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "METRICS",
    "BatchClosureResult",
    "BatchOptions",
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
