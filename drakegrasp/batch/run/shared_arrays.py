"""A task's large arrays sent to a worker process through shared memory.

``concurrent.futures.ProcessPoolExecutor`` pickles a task's arguments and
writes them through a pipe.  For a chunk of grasps that is most of the
parent's work: measured on the 2-core development machine, a 558 KB argument
(3876 grasps of three contacts) cost the parent 1.4 ms per task, and tasks of
8.6 ms ran only 1.48× faster on two workers than on one (1.86× without the
argument).  Here the parent copies each large array of a task (at least
``SHARE_MIN_BYTES``) into a shared-memory segment it owns (:class:`Slabs`,
one per task in flight, reused), and the task carries a small
:class:`SharedArray` handle instead.  The worker copies the array out of the
segment before the task runs (:func:`resolve`), so the task sees a private
array exactly as it would after unpickling: same bytes, same dtype and
shape, writeable, nothing aliasing the segment.  A segment is reused only
after its task's result has come back.
"""

from __future__ import annotations

from multiprocessing import shared_memory
from typing import NamedTuple

import numpy as np

__all__ = [
    "RESULT_ROOM",
    "SHARE_MIN_BYTES",
    "SharedArray",
    "Slabs",
    "load_result",
    "resolve",
    "store_result",
]

SHARE_MIN_BYTES = 1 << 16
"""Arrays smaller than this are pickled with the task as before."""

_ALIGN = 64


class SharedArray(NamedTuple):
    """Where an array lies in a shared-memory segment (picklable, a few bytes)."""

    segment: str
    offset: int
    shape: tuple[int, ...]
    dtype: np.dtype
    order: str  # "F" for a Fortran-ordered array (as pickle keeps it), else "C"


def _shareable(a) -> bool:
    return (
        isinstance(a, np.ndarray)
        and a.nbytes >= SHARE_MIN_BYTES
        and not a.dtype.hasobject
    )


def _span(a: np.ndarray) -> int:
    """Bytes an array takes in a segment (aligned)."""
    return -(-a.nbytes // _ALIGN) * _ALIGN


def _put(shm, offset: int, a: np.ndarray) -> SharedArray:
    """Copy ``a`` into ``shm`` at ``offset``, in the memory order pickle keeps."""
    order = "F" if a.flags.f_contiguous and not a.flags.c_contiguous else "C"
    view = np.ndarray(a.shape, a.dtype, buffer=shm.buf, offset=offset, order=order)
    np.copyto(view, a)
    del view  # no buffer export may outlive the copy
    return SharedArray(shm.name, offset, a.shape, a.dtype, order)


def _get(shm, x: SharedArray) -> np.ndarray:
    """A private copy of the array behind ``x`` in ``shm``."""
    view = np.ndarray(x.shape, x.dtype, buffer=shm.buf, offset=x.offset, order=x.order)
    out = view.copy(order="K")
    del view
    return out


class Slabs:
    """The parent's shared-memory segments, one per task in flight."""

    def __init__(self) -> None:
        self._free: list[shared_memory.SharedMemory] = []
        self._all: dict[str, shared_memory.SharedMemory] = {}

    def pack(self, args: tuple, kwargs: dict):
        """``(args, kwargs, segment)`` with large arrays moved into ``segment``.

        ``segment`` is None when nothing was large enough; else give it back
        with :meth:`release` once the task's result has arrived.
        """
        big = [a for a in (*args, *kwargs.values()) if _shareable(a)]
        if not big:
            return args, kwargs, None
        need = sum(_span(a) for a in big)
        try:
            shm = self._take(2 * need)  # the inputs, then room for the results
        except OSError:  # no (or a full) /dev/shm: pickled through the pipe
            return args, kwargs, None
        cursor = 0

        def move(a):
            nonlocal cursor
            if not _shareable(a):
                return a
            handle = _put(shm, cursor, a)
            cursor += _span(a)
            return handle

        args = tuple(move(a) for a in args)
        kwargs = {k: move(v) for k, v in kwargs.items()}
        # The worker writes the result's large arrays after the inputs, so a
        # task rerun after a worker died still finds its inputs intact.
        kwargs[RESULT_ROOM] = (shm.name, cursor, shm.size)
        return args, kwargs, shm

    def _take(self, need: int) -> shared_memory.SharedMemory:
        for i, shm in enumerate(self._free):
            if shm.size >= need:
                return self._free.pop(i)
        if self._free:  # all too small: replace the smallest
            self._free.sort(key=lambda s: s.size)
            self._drop(self._free.pop(0))
        size = max(1 << 20, 1 << (need - 1).bit_length())
        shm = shared_memory.SharedMemory(create=True, size=size)
        self._all[shm.name] = shm
        return shm

    def release(self, shm) -> None:
        """Make a segment free for the next task (its result has arrived)."""
        if shm is not None and shm.name in self._all:
            self._free.append(shm)

    def read(self, x: SharedArray) -> np.ndarray:
        """A private copy of an array a worker left in one of these segments."""
        return _get(self._all[x.segment], x)

    def discard(self, shm) -> None:
        """Unlink a segment that a task still running may read: never reused."""
        if shm is not None and shm.name in self._all:
            self._drop(shm)

    def _drop(self, shm) -> None:
        self._all.pop(shm.name, None)
        shm.close()
        shm.unlink()

    def close(self) -> None:
        """Unlink every segment (the worker pool is being shut down)."""
        for shm in list(self._all.values()):
            self._drop(shm)
        self._free.clear()


_ATTACHED: dict[str, shared_memory.SharedMemory] = {}
_KEEP_ATTACHED = 16


def _attach(name: str) -> shared_memory.SharedMemory:
    shm = _ATTACHED.get(name)
    if shm is None:
        if len(_ATTACHED) >= _KEEP_ATTACHED:  # the parent replaced segments
            old = next(iter(_ATTACHED))
            _ATTACHED.pop(old).close()
        shm = shared_memory.SharedMemory(name=name)
        _ATTACHED[name] = shm
    return shm


RESULT_ROOM = "_drakegrasp_result_room"
"""Keyword that tells the worker where the result's large arrays may go."""


def store_result(result, room):
    """In the worker: a dict result's large arrays moved into ``room``.

    ``room = (segment, offset, size)`` from :meth:`Slabs.pack`; arrays that do
    not fit (or any other result) are returned to be pickled as before.
    """
    if room is None or not isinstance(result, dict):
        return result
    name, cursor, size = room
    shm = _attach(name)
    out = {}
    for key, a in result.items():
        if not _shareable(a) or cursor + _span(a) > size:
            out[key] = a  # pickled with the result
            continue
        out[key] = _put(shm, cursor, a)
        cursor += _span(a)
    return out


def load_result(result, slabs: Slabs):
    """In the parent: a result with its arrays copied out of shared memory."""
    if not isinstance(result, dict):
        return result
    return {k: slabs.read(v) if isinstance(v, SharedArray) else v
            for k, v in result.items()}  # fmt: skip


def resolve(x):
    """In the worker: a private copy of the array behind a handle, else ``x``."""
    if not isinstance(x, SharedArray):
        return x
    return _get(_attach(x.segment), x)
