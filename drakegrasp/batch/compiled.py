"""The batch kernels: ahead-of-time code, else numba's JIT, and what the user sees.

numba is a core dependency: the batch kernels
(:mod:`~drakegrasp.batch.lp.block_kernel`, :mod:`~drakegrasp.batch.lp.fused_kernel`,
:mod:`~drakegrasp.batch.epsilon.kernel`, ...) decorate their functions with
:func:`njit` from here.  It returns a :class:`Kernel`, which runs

1. the kernel's ahead-of-time compiled entry (:mod:`drakegrasp.batch.aot`),
   when the install built one, the kernel declares its signature
   (``njit(entry="f8[:, ::1], i8, ...")``) and the arguments are exactly of
   it: nothing to import or compile, the first call is as fast as the next;
2. else numba's JIT dispatcher, created on first need (numba itself is
   imported only then), with ``cache=True``: a process compiles each kernel
   once per install and later processes load it from numba's on-disk cache
   (``NUMBA_CACHE_DIR`` when set, else numba's user-wide cache folder, e.g.
   ``~/.cache/numba``; never ``__pycache__`` beside the installed sources,
   where pip's uninstall left it behind: the leftover ``drakegrasp`` folder
   then shadowed the next install as an empty namespace package).

Where numba cannot be installed, :data:`AVAILABLE` is False, :func:`njit` is
a stand-in and the engine takes its numpy route, the reference the compiled
kernels are tested against; :func:`announce_numpy_route` says so once per
process (a :class:`NumbaMissingWarning`), never per call.

A JIT compile of every kernel takes about a minute of CPU.  When it happens
(an install without the ahead-of-time kernels, or arguments of another
type), it is not silent: the first time a drakegrasp kernel starts compiling
in a process, one line goes to stderr, and a long compile adds a progress
line every :data:`PROGRESS_EVERY` seconds with the number of functions
compiled so far.  ``drakegrasp warmup`` (:func:`drakegrasp.batch.warmup.warmup`)
pays the whole cost up front.
"""

from __future__ import annotations

import importlib.util
import os
import sys
import threading
import time
import warnings

from drakegrasp.batch import aot
from drakegrasp.errors import (
    GraspWarning,
    KernelsVariableWarning,
    outside_stacklevel,
)

__all__ = [
    "FASTMATH",
    "AVAILABLE",
    "PROGRESS_EVERY",
    "Kernel",
    "NumbaMissingWarning",
    "announce_numpy_route",
    "announce_misspelt_kernels",
    "compile_count",
    "kernels",
    "njit",
    "quiet_notice",
]

FASTMATH = False
"""The LP kernels' ``fastmath`` flag: off.  With ``contract`` (FMA) or ``reassoc``
the rounding of the compiled code depended on how numba compiled it (fresh in
this process, with the callees inlined, or loaded from its on-disk cache), so a
cold cache gave results that differed in the last bit between the local engine,
its worker processes and Dask workers.  IEEE arithmetic keeps them bitwise
equal."""

PROGRESS_EVERY = 5.0
"""Seconds between progress lines of a long compile (stderr)."""

AVAILABLE = importlib.util.find_spec("numba") is not None
"""Whether numba is installed: the kernels are compiled, else the numpy route runs."""


class NumbaMissingWarning(GraspWarning):
    """numba is not installed: the batch engine runs its (slower) numpy route."""


_said: set[type] = set()
"""The warnings said in this process (:func:`_first_time`)."""
_said_lock = threading.Lock()


def _first_time(category: type[GraspWarning]) -> bool:
    """Whether ``category`` is said for the first time in this process.

    Marks it said: each warning of the batch engine is said once per
    process.  The caller warns with it (a literal class, which the test of
    every ``warnings.warn`` call reads).
    """
    with _said_lock:
        if category in _said:
            return False
        _said.add(category)
        return True


def announce_numpy_route() -> None:
    """Warn, once per process, that the batch engine runs without numba.

    Called where ``kernel="auto"`` resolves to the numpy route; later calls
    return at once.
    """
    if _first_time(NumbaMissingWarning):
        warnings.warn(
            "numba is not installed, so drakegrasp's batch engine runs its "
            "numpy route: the same verdicts, about 5-10 times slower. numba is "
            "a dependency of drakegrasp; install it with `pip install numba` "
            "(this is said once per process)",
            NumbaMissingWarning,
            stacklevel=outside_stacklevel(),
        )


def announce_misspelt_kernels() -> None:
    """Warn, once per process, that ``DRAKEGRASP_KERNELS`` is misspelt.

    :mod:`drakegrasp.batch.aot` records the misspelling where it reads the
    variable (it imports nothing of drakegrasp); this says it as a
    :class:`~drakegrasp.KernelsVariableWarning` with aot's status sentence.
    Called where the batch engine resolves its kernel (in the caller's
    process and thread, before any worker runs a chunk: a worker's warning
    would never reach the caller's filters) and where a kernel first looks
    for its ahead-of-time entry; later calls return at once.  The warning
    points at the caller's own line, the first frame outside drakegrasp.
    """
    # a misspelt value would otherwise cost the compile (tens of seconds)
    # without a word
    if KernelsVariableWarning not in _said and aot.misspelt():
        if _first_time(KernelsVariableWarning):
            warnings.warn(
                aot.status(), KernelsVariableWarning, stacklevel=outside_stacklevel()
            )


class _CompileNotice:
    """One stderr line when a drakegrasp kernel first compiles; progress after.

    numba reports every compile of a dispatcher (nested: a kernel's callees
    compile inside it) as a ``numba:compile`` event; only dispatchers whose
    Python function lives in ``drakegrasp`` count.  Registered with numba when
    numba is first imported (:func:`_numba`).
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
                "40 s to two minutes, depending on the machine and its load; "
                "cached for later runs; `drakegrasp warmup` does it up front) ..."
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
_numba_lock = threading.RLock()
_numba_module = None


def _numba():
    """numba, imported on first need (about 0.4 s), with drakegrasp's hooks.

    The hooks: the compile notice listens to numba's compile events, and a
    :class:`Kernel` named inside another kernel types as its dispatcher, so
    numba compiles (or loads from its cache) the callee as usual.
    """
    global _numba_module
    with _numba_lock:
        if _numba_module is None:
            import numba
            from numba.core import event, types
            from numba.extending import typeof_impl

            class _Listener(event.Listener):
                def on_start(self, ev):
                    _NOTICE.on_start(ev)

                def on_end(self, ev):
                    _NOTICE.on_end(ev)

            @typeof_impl.register(Kernel)
            def _typeof_kernel(val, _context):
                return types.Dispatcher(val.dispatcher)

            event.register("numba:compile", _Listener())
            _cache_outside_the_package()
            _numba_module = numba
        return _numba_module


def _cache_outside_the_package() -> None:
    """Send numba's cache of drakegrasp's kernels to its user-wide folder.

    numba's default puts it in ``__pycache__`` beside the sources when that is
    writable, i.e. inside ``site-packages`` of a venv, where no uninstall
    removes it.  A locator placed before numba's in-tree one claims the files
    of this package (unless ``NUMBA_CACHE_DIR`` is set, which numba honours
    first); the user's own kernels keep numba's usual places.
    """
    try:
        from numba.core import caching, config
    except ImportError:  # another numba layout: its default places stay
        return
    impl = getattr(caching, "CacheImpl", None)
    base = getattr(caching, "UserWideCacheLocator", None)
    if impl is None or base is None or not hasattr(impl, "_locator_classes"):
        return
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

    class _PackageCacheLocator(base):
        @classmethod
        def from_function(cls, py_func, py_file):
            inside = os.path.abspath(py_file).startswith(package + os.sep)
            if config.CACHE_DIR or not inside:
                return None
            return super().from_function(py_func, py_file)

    classes = impl._locator_classes
    if not any(c.__name__ == "_PackageCacheLocator" for c in classes):
        classes.insert(0, _PackageCacheLocator)


_KERNELS: list[Kernel] = []
_MISSING = object()


class Kernel:
    """A batch kernel: its ahead-of-time entry where usable, else numba's JIT.

    Calling it runs the kernel.  Attributes other than those below (``stats``,
    ``signatures``, ``overloads``, ...) are those of the numba dispatcher,
    which is then created.

    Attributes
    ----------
    py_func : function
        The Python source of the kernel.
    options : dict
        numba's ``njit`` options (``cache``, ``error_model``, ``fastmath``).
    entry : str or None
        The declared signature of an entry kernel (called from Python), which
        the install compiles ahead of time; None for a callee.
    key : str
        ``module.function``.
    aot_calls, jit_calls : int
        Calls from Python served by the ahead-of-time entry and by the JIT.
    """

    def __init__(self, py_func, options: dict, entry: str | None):
        self.py_func = py_func
        self.options = options
        self.entry = entry
        self.key = f"{py_func.__module__}.{py_func.__qualname__}"
        self.__name__ = py_func.__name__
        self.__qualname__ = py_func.__qualname__
        self.__module__ = py_func.__module__
        self.__doc__ = py_func.__doc__
        self.__wrapped__ = py_func
        self._specs = aot.parse_signature(entry) if entry is not None else None
        self._aot = _MISSING if entry is not None else None
        self._dispatcher = None
        self.aot_calls = 0
        self.jit_calls = 0

    @property
    def dispatcher(self):
        """The numba JIT dispatcher of this kernel (numba is imported on first use)."""
        if self._dispatcher is None:
            numba = _numba()
            with _numba_lock:
                if self._dispatcher is None:
                    self._dispatcher = numba.njit(**self.options)(self.py_func)
        return self._dispatcher

    @property
    def compiled_entry(self):
        """The ahead-of-time compiled function, or None (the JIT runs)."""
        if self._aot is _MISSING:
            self._aot = aot.lookup(self.key)
            announce_misspelt_kernels()
        return self._aot

    def __call__(self, *args):
        """Run the kernel: its compiled entry if ``args`` fit it, else the JIT."""
        entry = self.compiled_entry
        if entry is not None and aot.accepts(self._specs, args):
            self.aot_calls += 1
            return entry(*args)
        self.jit_calls += 1
        return self.dispatcher(*args)

    def __getattr__(self, name):
        if name.startswith("__") or name in ("_dispatcher", "_aot", "_specs"):
            raise AttributeError(name)
        return getattr(self.dispatcher, name)

    def __repr__(self) -> str:
        return f"<drakegrasp kernel {self.key}>"

    def __reduce__(self):
        # By reference, as a function pickles: the kernel of that module.
        return (_kernel, (self.py_func.__module__, self.py_func.__qualname__))


def _kernel(module: str, qualname: str) -> Kernel:
    """The kernel ``qualname`` of ``module`` (unpickling a :class:`Kernel`)."""
    import importlib

    return getattr(importlib.import_module(module), qualname)


def njit(*args, entry: str | None = None, **options):
    """Decorate a batch kernel: ``@njit(cache=True, error_model="numpy", entry=...)``.

    Parameters
    ----------
    entry : str, optional
        The signature of a kernel called from Python, e.g.
        ``"f8[:, :, ::1], i8[::1], f8, b1[::1]"`` (C-contiguous arrays of
        float64, int64, int8, bool; Python scalars; ``readonly`` before an
        array the kernel never writes): the install compiles it ahead of time
        for exactly these types.
    **options
        numba's ``njit`` options.

    Returns
    -------
    Kernel
        Or, where numba is missing, the function itself (unused: the engine
        takes its numpy route).
    """

    def wrap(fn):
        if not AVAILABLE:  # pragma: no cover - exercised where numba is missing
            return fn
        kernel = Kernel(fn, options, entry)
        _KERNELS.append(kernel)
        return kernel

    if len(args) == 1 and callable(args[0]) and entry is None and not options:
        return wrap(args[0])
    if args:
        raise TypeError("njit takes keyword options only")
    return wrap


def kernels() -> tuple[Kernel, ...]:
    """Every kernel decorated so far (those of the imported kernel modules)."""
    return tuple(_KERNELS)


def quiet_notice() -> None:
    """Skip the one-line compile notice in this process (the caller reports)."""
    _NOTICE.announced = True


def compile_count() -> int:
    """Number of drakegrasp functions numba has compiled in this process.

    Loads from the on-disk cache and ahead-of-time entries do not count.
    """
    return _NOTICE.count
