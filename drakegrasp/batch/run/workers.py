"""Run chunks of a batch in worker processes, in order, with bounded memory.

Each chunk is an independent task (:mod:`drakegrasp.batch.run.chunk`) whose
result depends only on its own grasps, and chunk boundaries depend only on the
inputs and ``chunk_size``, never on the number of workers; results are
consumed in chunk order.  So the output is bitwise the same for any number of
workers.  Processes, not threads: the engine's inner loops (numpy on small
arrays, the numba kernel) hold the GIL for most of their time.

At most ``2 × workers`` chunks are in flight, so memory stays bounded by the
chunk size whatever the number of grasps.  Each chunk's input checks run in
the worker that solves it, so the parent only slices, sends and collects; its
large arrays go through shared memory (:mod:`drakegrasp.batch.run.shared_arrays`)
instead of the pool's pipe.
The worker processes are kept between calls (:func:`shutdown_pool`).

A kept pool never outlives its program: each worker watches its parent and
exits as soon as the parent is gone, however it ended (killed, ``os._exit``,
a crash), so no orphan keeps the program's stdout open (``| tee`` would wait
for ever) or its memory; the shared-memory segments are then unlinked by
Python's resource tracker, which exits with the last of them.  Workers ignore
a Ctrl-C or a hang-up sent to the whole process group: the parent decides,
stops them and cleans up.
"""

from __future__ import annotations

import atexit
import multiprocessing
import os
import signal
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool

from drakegrasp.batch.run.shared_arrays import (
    RESULT_ROOM,
    Slabs,
    load_result,
    resolve,
    store_result,
)
from drakegrasp.core.validation import describe, integer_or_none
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "MAX_WORKERS",
    "available_cores",
    "check_workers",
    "map_ordered",
    "resolve_workers",
    "shutdown_pool",
]

MAX_WORKERS = 256
"""Most worker processes a call may ask for, unless the machine has more cores.

The pool forks every worker at once: ``workers=100000`` with many chunks
forked as many processes as chunks, each a copy of the caller."""

PARENT_WATCH_PERIOD = 0.2
"""Seconds between a worker's checks that its parent is alive."""

Task = tuple[Callable, tuple, dict]


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity where the OS tells)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def check_workers(workers) -> int | None:
    """``workers`` checked: None (every core) or an int >= 1 (not resolved).

    At most :data:`MAX_WORKERS`, or the cores this process may run on where
    that is more (``None`` asks for every core).
    """
    if workers is None:
        return None
    n = integer_or_none(workers)  # bools are not counts (True was one worker)
    if n is None or n < 1:
        raise InvalidOptionError(
            "workers must be None (every core) or an integer >= 1, got "
            f"{describe(workers)}"
        )
    most = max(MAX_WORKERS, available_cores())
    if n > most:
        raise InvalidOptionError(
            f"workers must be at most {most} (drakegrasp.batch.run.workers."
            f"MAX_WORKERS, or every core), got {n}: each is a process forked at "
            "once; None runs one per core"
        )
    return n


def resolve_workers(workers) -> int:
    """``workers`` as a positive int: None means every available core."""
    n = check_workers(workers)
    return available_cores() if n is None else n


def _call(fn: Callable, args: tuple, kwargs: dict):
    room = kwargs.pop(RESULT_ROOM, None)
    args = tuple(resolve(a) for a in args)
    result = fn(*args, **{k: resolve(v) for k, v in kwargs.items()})
    return store_result(result, room)


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
    pool = _pool(workers)
    pending: deque = deque()  # (future, task, segment), in task order
    restarted = False

    def restart():
        # A worker died (killed, out of memory).  The chunks in flight are
        # pure functions of their inputs: run them again, in order, on a fresh
        # pool, once; a second death is raised.
        nonlocal pool, restarted
        _stop_pool()  # the segments stay: the chunks in flight are rerun from them
        if restarted:
            raise BrokenProcessPool("a batch worker died twice during one call")
        restarted = True
        pool = _pool(workers)
        for i, (_, task, shm) in enumerate(pending):
            pending[i] = (pool.submit(_call, *task), task, shm)

    def submit(task):
        fn, args, kwargs = task
        args, kwargs, shm = _SLABS.pack(args, kwargs)  # large arrays: shared memory
        task = (fn, args, kwargs)
        try:
            return pool.submit(_call, *task), task, shm
        except BrokenProcessPool:  # a worker died since the last submit
            restart()
            return pool.submit(_call, *task), task, shm

    def next_result():
        while True:
            try:
                return pending[0][0].result()
            except BrokenProcessPool:
                restart()

    def pop():
        result = load_result(next_result(), _SLABS)
        _SLABS.release(pending.popleft()[2])  # read by its worker, results copied
        return result

    try:
        for task in tasks:
            pending.append(submit(task))
            if len(pending) >= 2 * workers:
                yield pop()
        while pending:
            yield pop()
    finally:
        for fut, _, shm in pending:
            if fut.cancel() or fut.done():
                _SLABS.release(shm)
            else:  # still running: its segment must not be refilled
                _SLABS.discard(shm)


_POOL: dict = {}
_SLABS = Slabs()  # the parent's shared-memory segments, kept with the pool


def _pool(workers: int) -> ProcessPoolExecutor:
    """The worker pool of ``workers`` processes, started once and kept.

    Starting processes costs 10–50 ms and each new worker pays its first-call
    costs again (copy-on-write page faults, loading the compiled kernel), which
    at a few hundred thousand grasps per second is a tenth of a call or more;
    so the pool outlives the call and the next call with the same number of
    workers reuses it.  It is shut down at exit, when a worker dies, or when a
    call asks for a different number of workers.
    """
    pool = _POOL.get("pool")
    if pool is not None and _POOL.get("workers") == workers and _healthy(pool):
        return pool
    _stop_pool()  # its segments stay: chunks in flight may be rerun from them
    # fork where the OS has it: workers start in milliseconds with the parent's
    # modules loaded, and scripts need no ``if __name__ == "__main__"`` guard
    # (forkserver and spawn re-run the main module in every worker).
    _start_resource_tracker()
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    pool = ProcessPoolExecutor(
        max_workers=workers,
        mp_context=ctx,
        initializer=_init_worker,
        initargs=(os.getpid(),),
    )
    _POOL.update(pool=pool, workers=workers)
    return pool


def _start_resource_tracker() -> None:
    """Start Python's resource tracker now, deaf to a hang-up of the group.

    The tracker (one process per program) unlinks the shared-memory segments
    of a program that died.  It ignores SIGINT and SIGTERM but not SIGHUP: a
    closed terminal killed it, the program started another that knew none of
    the segments, and the run ended with a page of tracebacks on stderr.  An
    ignored signal stays ignored across ``exec``, so the tracker is started
    here with SIGHUP ignored (main thread only: elsewhere it starts as Python
    starts it, on the first segment).
    """
    from multiprocessing import resource_tracker

    if not hasattr(signal, "SIGHUP") or (
        threading.current_thread() is not threading.main_thread()
    ):
        return
    previous = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        resource_tracker.ensure_running()
    finally:
        signal.signal(signal.SIGHUP, previous)


def _init_worker(parent: int) -> None:
    """Run in each worker as it starts: outlive no parent, leave signals to it.

    A daemon thread checks every ``PARENT_WATCH_PERIOD`` that the process that
    started the pool is still this worker's parent (an orphan is adopted by
    another process) and ends the worker at once if not.  Unlike Linux's
    ``PR_SET_PDEATHSIG``, this does not fire when the thread that started the
    worker ends while the program goes on, and it works on every POSIX system.
    """
    # A Ctrl-C or a hang-up (a closed terminal) reaches the whole process
    # group: the parent decides and stops the pool (a worker killed by SIGHUP
    # broke the pool under the parent's cleanup).  SIGTERM ends a worker at
    # once (the parent's handler, which a fork copies, is for the parent; the
    # pool itself stops workers with SIGTERM when one died).
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "SIGHUP"):
        signal.signal(signal.SIGHUP, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_WATCH_PERIOD)
        os._exit(1)  # no cleanup of the parent's state: it is not ours

    if os.getppid() != parent:  # the parent died while this worker started
        os._exit(1)
    threading.Thread(target=watch, name="drakegrasp-parent-watch", daemon=True).start()


def _healthy(pool: ProcessPoolExecutor) -> bool:
    """Whether a kept pool can take work: not broken, no worker has exited.

    A worker killed between two calls is noticed by the pool's own thread only
    after a while; checking its processes here lets the next call start on a
    fresh pool instead of meeting ``BrokenProcessPool``.
    """
    if getattr(pool, "_broken", False):
        return False
    processes = getattr(pool, "_processes", None) or {}
    return all(p.exitcode is None for p in processes.values())


def _stop_pool(*, abandon: bool = False) -> None:
    pool = _POOL.pop("pool", None)
    _POOL.pop("workers", None)
    if pool is not None:
        if abandon or not _healthy(pool):
            _abandon(pool)
        try:
            # An abandoned pool is not waited for: its workers are dead and a
            # signal may have landed between creating its thread and starting
            # it ("cannot join thread before it is started").
            pool.shutdown(wait=not abandon, cancel_futures=True)
        except RuntimeError:
            if not abandon:
                raise


def _abandon(pool: ProcessPoolExecutor) -> None:
    """Stop a pool whose workers died without waiting on its queues.

    When a signal to the whole process group kills the workers while this
    process cancels its futures, the pool's own thread can fail on a cancelled
    future before it closes the task queue (CPython 3.11's ``terminate_broken``
    sets an exception on every pending future).  The queue's feeder thread then
    stays blocked on a pipe that no worker reads, and the interpreter waits for
    it at exit: the program hung after its cleanup.  So the surviving workers
    are killed here and the queue is told not to be waited for.
    """
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        if process.exitcode is None:
            process.kill()
    queue = getattr(pool, "_call_queue", None)
    if queue is not None:
        queue.cancel_join_thread()


def shutdown_pool(*, abandon: bool = False) -> None:
    """Stop the kept worker processes (if any); the next call starts new ones.

    Their shared-memory segments are unlinked too.  ``abandon=True`` (a program
    that was signalled to stop) kills the workers instead of letting them finish
    their chunks, and does not wait on the pool's task queue.
    """
    _stop_pool(abandon=abandon)
    _SLABS.close()


atexit.register(shutdown_pool)
