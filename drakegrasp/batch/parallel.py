"""Run chunks of a batch in worker processes, in order, with bounded memory.

Each chunk is an independent task (:mod:`drakegrasp.batch.chunks`) whose
result depends only on its own grasps, and chunk boundaries depend only on the
inputs and ``chunk_size``, never on the number of workers; results are
consumed in chunk order.  So the output is bitwise the same for any number of
workers.  Processes, not threads: the engine's inner loops (numpy on small
arrays, the numba kernel) hold the GIL for most of their time.

At most ``2 × workers`` chunks are in flight, so memory stays bounded by the
chunk size whatever the number of grasps.
"""

from __future__ import annotations

import multiprocessing
import os
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor

from drakegrasp.errors import InvalidOptionError

__all__ = ["available_cores", "map_ordered", "resolve_workers"]

Task = tuple[Callable, tuple, dict]


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity where the OS tells)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def resolve_workers(workers) -> int:
    """``workers`` as a positive int: None means every available core."""
    if workers is None:
        return available_cores()
    try:
        n = int(workers)
    except (TypeError, ValueError):
        n = None
    if n is None or n != workers or n < 1:
        raise InvalidOptionError(
            f"workers must be None (every core) or an integer >= 1, got {workers!r}"
        )
    return n


def _call(fn: Callable, args: tuple, kwargs: dict):
    return fn(*args, **kwargs)


def map_ordered(tasks: Iterable[Task], workers: int) -> Iterator:
    """Results of ``fn(*args, **kwargs)`` for each task, in task order.

    Parameters
    ----------
    tasks : iterable of (fn, args, kwargs)
        Picklable top-level functions and their arguments; consumed lazily.
    workers : int
        1 runs every task here; more starts that many worker processes
        (``fork`` where available, else ``spawn``).

    Yields
    ------
    object
        Each task's result.  An exception in a task is raised here.
    """
    if workers <= 1:
        for fn, args, kwargs in tasks:
            yield fn(*args, **kwargs)
        return
    # fork where the OS has it: workers start in milliseconds with the parent's
    # modules loaded, and scripts need no ``if __name__ == "__main__"`` guard
    # (forkserver and spawn re-run the main module in every worker).
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
        pending: deque = deque()
        try:
            for fn, args, kwargs in tasks:
                pending.append(pool.submit(_call, fn, args, kwargs))
                if len(pending) >= 2 * workers:
                    yield pending.popleft().result()
            while pending:
                yield pending.popleft().result()
        finally:
            for fut in pending:
                fut.cancel()
