"""numba's ``njit`` for the batch kernels, and what the user sees while it compiles.

numba is a core dependency: the batch kernels
(:mod:`~drakegrasp.batch.lp.block_kernel`, :mod:`~drakegrasp.batch.lp.fused_kernel`,
:mod:`~drakegrasp.batch.epsilon.kernel`, ...) decorate their functions with
:func:`njit` from here, with ``cache=True``, so a process compiles each kernel
once per install and later processes load it from numba's on-disk cache
(``NUMBA_CACHE_DIR``, or ``__pycache__`` beside the sources when writable).

Where numba cannot be installed, :data:`AVAILABLE` is False, :func:`njit` is
a stand-in and the engine takes its numpy route, the reference the compiled
kernels are tested against; :func:`announce_numpy_route` says so once per
process (a :class:`NumbaMissingWarning`), never per call.

A compile of every kernel takes about a minute of CPU, and it happens inside
the first batch call of a fresh install.  So it is not silent: the first
time a drakegrasp kernel starts compiling in a process, one line goes to
stderr, and a long compile adds a progress line every
:data:`PROGRESS_EVERY` seconds with the number of functions compiled so far.
``drakegrasp warmup`` (:func:`drakegrasp.batch.warmup.warmup`) pays the whole
cost up front.
"""

from __future__ import annotations

import importlib.util
import sys
import threading
import time
import warnings

__all__ = [
    "AVAILABLE",
    "PROGRESS_EVERY",
    "NumbaMissingWarning",
    "announce_numpy_route",
    "compile_count",
    "njit",
    "quiet_notice",
]

PROGRESS_EVERY = 5.0
"""Seconds between progress lines of a long compile (stderr)."""

AVAILABLE = importlib.util.find_spec("numba") is not None
"""Whether numba is installed: the kernels are compiled, else the numpy route runs."""


class NumbaMissingWarning(UserWarning):
    """numba is not installed: the batch engine runs its (slower) numpy route."""


_announced = False
_announce_lock = threading.Lock()


def announce_numpy_route() -> None:
    """Warn, once per process, that the batch engine runs without numba.

    Called where ``kernel="auto"`` resolves to the numpy route; later calls
    return at once.
    """
    global _announced
    with _announce_lock:
        if _announced:
            return
        _announced = True
    warnings.warn(
        "numba is not installed, so drakegrasp's batch engine runs its numpy "
        "route: the same verdicts, about 5-10 times slower. numba is a "
        "dependency of drakegrasp; install it with `pip install numba` "
        "(this is said once per process)",
        NumbaMissingWarning,
        stacklevel=3,
    )


if AVAILABLE:  # pragma: no branch - numba is a core dependency
    from numba import njit
    from numba.core import event as _event

    class _CompileNotice(_event.Listener):
        """One stderr line when a drakegrasp kernel first compiles; progress after.

        numba reports every compile of a dispatcher (nested: a kernel's callees
        compile inside it) as a ``numba:compile`` event; only dispatchers whose
        Python function lives in ``drakegrasp`` count.
        """

        def __init__(self, stream=None):
            self.stream = stream
            self.count = 0
            self.depth = 0
            self.started = None
            self.last_line = 0.0
            self.announced = False

        def _write(self, text: str) -> None:
            stream = self.stream if self.stream is not None else sys.stderr
            try:
                print(f"drakegrasp: {text}", file=stream, flush=True)
            except (OSError, ValueError):  # a closed stderr must not break a kernel
                pass

        @staticmethod
        def _ours(ev) -> bool:
            dispatcher = ev.data.get("dispatcher") if ev.data else None
            py_func = getattr(dispatcher, "py_func", None)
            return getattr(py_func, "__module__", "").startswith("drakegrasp.")

        def on_start(self, ev) -> None:
            if not self._ours(ev):
                return
            now = time.perf_counter()
            if self.depth == 0 and self.started is None:
                self.started = now
                self.last_line = now
            self.depth += 1
            if not self.announced:
                self.announced = True
                self._write(
                    "compiling the batch kernels with numba (once per install, "
                    "about a minute; cached for later runs; `drakegrasp warmup` "
                    "does it up front) ..."
                )

        def on_end(self, ev) -> None:
            if not self._ours(ev):
                return
            self.depth = max(0, self.depth - 1)
            self.count += 1
            now = time.perf_counter()
            if self.started is not None and now - self.last_line >= PROGRESS_EVERY:
                self.last_line = now
                self._write(
                    f"... compiled {self.count} functions in {now - self.started:.0f} s"
                )

    _NOTICE = _CompileNotice()
    _event.register("numba:compile", _NOTICE)

else:  # pragma: no cover - exercised where numba cannot be installed
    _NOTICE = None

    def njit(*args, **kwargs):
        """Stand-in decorator when numba is absent (the kernel is then unused)."""

        def wrap(fn):
            return fn

        if len(args) == 1 and callable(args[0]) and not kwargs:
            return args[0]
        return wrap


def quiet_notice() -> None:
    """Skip the one-line compile notice in this process (the caller reports)."""
    if _NOTICE is not None:
        _NOTICE.announced = True


def compile_count() -> int:
    """Number of drakegrasp functions numba has compiled in this process.

    Loads from the on-disk cache do not count; 0 without numba.
    """
    return 0 if _NOTICE is None else _NOTICE.count
