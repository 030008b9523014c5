"""The run: chunks, their stream, worker processes and shared memory.

One chunk of grasps start to finish and the verdict-only run of chunks
(:mod:`~drakegrasp.batch.run.chunk`), the chunk stream
(:mod:`~drakegrasp.batch.run.stream`), worker processes and the shared memory
that feeds them.
"""

from drakegrasp._lazy import lazy_exports

_SUBMODULES = (
    "chunk",
    "shared_arrays",
    "stream",
    "workers",
)

__getattr__, __dir__ = lazy_exports(__name__, globals(), {}, submodules=_SUBMODULES)
