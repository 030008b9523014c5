"""Large task arrays through shared memory (drakegrasp.batch.run.shared_arrays).

The transport must be invisible: the worker sees the same bytes, dtype,
shape and memory order as after pickling, results come back the same, a task
rerun after a worker died finds its inputs intact, and no segment outlives the
pool.
"""

from __future__ import annotations

import os
import signal
import time
from multiprocessing import shared_memory

import numpy as np
import pytest

from drakegrasp.batch.run import workers as parallel
from drakegrasp.batch.run.shared_arrays import (
    RESULT_ROOM,
    SHARE_MIN_BYTES,
    SharedArray,
    Slabs,
    load_result,
    resolve,
    store_result,
)


def _arrays(rng):
    big = rng.normal(size=(SHARE_MIN_BYTES // 8 + 5, 3))
    return {
        "c_order": big,
        "f_order": np.asfortranarray(rng.normal(size=(3000, 7))),
        "strided": big[::2, 1:],  # neither C nor F: arrives C-ordered, as pickled
        "ints": rng.integers(-5, 5, size=(40000,), dtype=np.int64),
        "bools": rng.random((70000,)) < 0.5,
        "small": rng.normal(size=(10, 3)),  # pickled as before
        "objects": np.array([None, "x"] * 40000, dtype=object),  # never shared
        "scalar": 3.5,
    }


def _same(a, b):
    """Same value, dtype, shape and memory order (what unpickling gives)."""
    if not isinstance(a, np.ndarray):
        return a == b
    layout = ("C_CONTIGUOUS", "F_CONTIGUOUS")
    return (
        a.dtype == b.dtype
        and a.shape == b.shape
        and all(a.flags[f] == b.flags[f] for f in layout)
        and (np.array_equal(a, b) if a.dtype.hasobject else a.tobytes() == b.tobytes())
    )


def test_pack_and_resolve_give_the_pickled_arrays_back():
    rng = np.random.default_rng(9100)
    data = _arrays(rng)
    slabs = Slabs()
    try:
        args, kwargs, shm = slabs.pack(tuple(data.values()), {"kw": data["c_order"]})
        room = kwargs.pop(RESULT_ROOM)
        assert shm is not None and room[0] == shm.name
        kinds = dict(zip(data, args, strict=True))
        for name in ("c_order", "f_order", "strided", "ints", "bools"):
            assert isinstance(kinds[name], SharedArray), name
        for name in ("small", "objects", "scalar"):
            assert not isinstance(kinds[name], SharedArray), name
        for (name, a), h in zip(data.items(), args, strict=True):
            b = resolve(h)
            assert _same(a if name != "strided" else np.ascontiguousarray(a), b), name
            if isinstance(h, SharedArray):
                assert b.flags.writeable and b.base is None  # a private copy
        assert np.array_equal(resolve(kwargs["kw"]), data["c_order"])
        # results go after the inputs, and come back the same
        result = {"d": rng.normal(size=(20000,)), "n": np.arange(5), "t": "text"}
        stored = store_result(result, room)
        assert isinstance(stored["d"], SharedArray) and stored["d"].offset >= room[1]
        back = load_result(stored, slabs)
        assert back["d"].tobytes() == result["d"].tobytes() and back["t"] == "text"
        np.testing.assert_array_equal(back["n"], result["n"])
        # the inputs are intact after the results were written (a rerun reads them)
        assert np.array_equal(resolve(args[0]), data["c_order"])
        slabs.release(shm)
        _, _, again = slabs.pack((data["c_order"],), {})
        assert again is shm  # reused once released
    finally:
        slabs.close()
    with pytest.raises(FileNotFoundError):
        shared_memory.SharedMemory(name=shm.name)


def _double(x, pause=0.0):
    time.sleep(pause)
    return {"y": 2 * x, "pid": np.array([os.getpid()])}


def test_workers_get_and_return_large_arrays_unchanged():
    rng = np.random.default_rng(9200)
    xs = [rng.normal(size=(20000, 3)) for _ in range(9)]
    tasks = [(_double, (x,), {}) for x in xs]
    one = list(parallel.map_ordered(iter(tasks), 1))
    two = list(parallel.map_ordered(iter(tasks), 2))
    for a, b, x in zip(one, two, xs, strict=True):
        assert a["y"].tobytes() == b["y"].tobytes() == (2 * x).tobytes()
    assert len({int(r["pid"][0]) for r in two}) == 2  # both workers took tasks
    slabs = parallel._SLABS
    assert slabs._all and len(slabs._free) == len(slabs._all)  # all given back
    names = list(slabs._all)
    parallel.shutdown_pool()
    assert not slabs._all
    for name in names:
        with pytest.raises(FileNotFoundError):
            shared_memory.SharedMemory(name=name)


def test_a_worker_killed_mid_run_leaves_its_tasks_inputs_intact():
    rng = np.random.default_rng(9300)
    xs = [rng.normal(size=(30000, 2)) for _ in range(8)]
    tasks = ((_double, (x,), {"pause": 0.15}) for x in xs)
    out = []
    for r in parallel.map_ordered(tasks, 2):
        if not out:  # a worker dies while the others' tasks are in flight
            os.kill(int(r["pid"][0]), signal.SIGKILL)
        out.append(r)
    for r, x in zip(out, xs, strict=True):
        assert r["y"].tobytes() == (2 * x).tobytes()
    killed = int(out[0]["pid"][0])
    assert killed not in parallel._POOL["pool"]._processes  # a new pool took over
    parallel.shutdown_pool()


def test_without_shared_memory_the_arrays_are_pickled(monkeypatch):
    """No (or a full) /dev/shm: the task keeps its arrays and still runs."""

    def refuse(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(shared_memory, "SharedMemory", refuse)
    x = np.random.default_rng(9400).normal(size=(20000, 3))
    slabs = Slabs()
    args, kwargs, shm = slabs.pack((x,), {})
    assert shm is None and args[0] is x and RESULT_ROOM not in kwargs
    out = list(parallel.map_ordered(iter([(_double, (x,), {})] * 3), 2))
    assert all(r["y"].tobytes() == (2 * x).tobytes() for r in out)
    parallel.shutdown_pool()
