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

from drakegrasp._lazy import lazy_exports

_SOURCES = {
    "drakegrasp.batch.api": (
        "DEFAULT_CHUNK_SIZE",
        "METRICS",
        "BatchClosureResult",
        "batch_force_closure",
        "batch_form_closure",
        "iter_batch_closure",
        "stream_force_closure",
        "stream_form_closure",
    ),
    "drakegrasp.batch.epsilon.driver": ("batch_epsilon_l1",),
    "drakegrasp.batch.files.driver": ("evaluate_file", "stream_file", "write_result"),
    "drakegrasp.batch.files.reader": ("read_grasps",),
    "drakegrasp.batch.files.writer": ("BatchSummary", "write_chunks"),
    "drakegrasp.batch.loads": ("batch_grasp_forces",),
    "drakegrasp.batch.options": ("BatchOptions",),
}

_SUBMODULES = (
    "aot",
    "aot_build",
    "api",
    "build",
    "columns",
    "compiled",
    "epsilon",
    "files",
    "inputs",
    "loads",
    "lp",
    "metrics",
    "options",
    "ragged",
    "run",
    "warmup",
    "witnesses",
)

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

__getattr__, __dir__ = lazy_exports(
    __name__, globals(), _SOURCES, submodules=_SUBMODULES
)
