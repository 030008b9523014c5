"""The batch kernels compiled ahead of time, when the install built them.

``pip install .`` compiles the engine's entry kernels (those called from
Python) with numba's ahead-of-time compiler into the extension module
``drakegrasp.batch._aot_kernels`` (:mod:`drakegrasp.batch.aot_build`; a
minute of CPU at install, once).  A process then loads them in milliseconds,
without importing numba or compiling anything: the first batch call of a
fresh install is as fast as any later one.

The extension is used only when it is known to hold today's kernels for this
machine.  Its manifest (``_aot_kernels.json`` beside it) records

* the SHA-256 of the kernels' source files (:data:`SOURCES`), so an edited
  kernel is never served stale code;
* the CPU model and features LLVM saw at build time: the code is generated
  for that CPU, exactly as numba's JIT generates it (so results are bitwise
  those of the JIT), and would be unsafe on another.

Otherwise (no extension, another CPU, other sources, or
``DRAKEGRASP_KERNELS=jit`` in the environment) the kernels run through
numba's JIT and its on-disk cache (:mod:`drakegrasp.batch.compiled`), and
:func:`status` says why.

Arguments reach a compiled entry only when they are exactly of its declared
types (C-contiguous, aligned, writable arrays of the declared dtype and
dimension; Python ``float``/``int``/``bool`` scalars): anything else takes
the JIT, which specialises on what it gets.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import json
import os
import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = [
    "ENV",
    "MANIFEST",
    "MODULE",
    "SOURCES",
    "ArgSpec",
    "accepts",
    "export_name",
    "host_cpu",
    "lookup",
    "misspelt",
    "parse_signature",
    "source_digest",
    "status",
]

MODULE = "drakegrasp.batch._aot_kernels"
"""The extension module the install builds."""

MANIFEST = "_aot_kernels.json"
"""The manifest beside it (in ``drakegrasp/batch``)."""

ENV = "DRAKEGRASP_KERNELS"
"""Environment variable: ``jit`` skips the ahead-of-time kernels; ``auto`` uses them."""

SOURCES = (
    "build/kinds.py",
    "build/construction_kernel.py",
    "lp/active_set.py",
    "lp/block_kernel.py",
    "lp/block_ops.py",
    "lp/fused_kernel.py",
    "lp/householder.py",
    "lp/ipm_kernel.py",
    "lp/vertex_kernel.py",
    "epsilon/kernel.py",
    "epsilon/polytope.py",
)
"""Source files of the kernels, relative to ``drakegrasp/batch``."""

_HERE = Path(__file__).resolve().parent

_DTYPES = {"f8": np.float64, "i8": np.int64, "i1": np.int8, "b1": np.bool_}
_SCALARS = {"f8": (float,), "i8": (int,), "b1": (bool,)}


@dataclass(frozen=True)
class ArgSpec:
    """One argument of an entry kernel's declared signature.

    Attributes
    ----------
    code : str
        numba's spelling, e.g. ``"f8[:, :, ::1]"`` or ``"i8"``.
    dtype : str
        ``"f8"``, ``"i8"``, ``"i1"`` or ``"b1"``.
    ndim : int
        0 for a scalar, else the array's dimension (C-contiguous).
    readonly : bool
        A read-only array is accepted too (written ``readonly f8[::1]``: the
        kernel never writes to it).
    """

    code: str
    dtype: str
    ndim: int
    readonly: bool = False


def parse_signature(text: str) -> tuple[ArgSpec, ...]:
    """The arguments of a signature such as ``"f8[:, ::1], i8, readonly f8[::1]"``.

    Raises
    ------
    ValueError
        For a type outside ``f8 i8 i1 b1`` (arrays C-contiguous, ``::1`` last).
    """
    specs = []
    for raw in _split(text):
        readonly = raw.startswith("readonly ")
        code = raw.removeprefix("readonly ").replace(" ", "")
        dtype, _, dims = code.partition("[")
        if dtype not in _DTYPES or (not dims and dtype not in _SCALARS):
            raise ValueError(f"unsupported kernel argument type {raw!r}")
        if dims:
            axes = dims.rstrip("]").split(",")
            if axes[-1] != "::1" or any(a != ":" for a in axes[:-1]):
                raise ValueError(f"kernel arrays must be C-contiguous: {raw!r}")
            ndim = len(axes)
        else:
            ndim = 0
        if readonly and not ndim:
            raise ValueError(f"only a kernel array can be readonly: {raw!r}")
        specs.append(ArgSpec(code=code, dtype=dtype, ndim=ndim, readonly=readonly))
    return tuple(specs)


def _split(text: str) -> list[str]:
    """Top-level comma split (commas inside ``[...]`` belong to an array)."""
    parts, depth, current = [], 0, []
    for ch in text:
        depth += (ch == "[") - (ch == "]")
        if ch == "," and depth == 0:
            parts.append("".join(current).strip())
            current = []
        else:
            current.append(ch)
    parts.append("".join(current).strip())
    return [p for p in parts if p]


def accepts(specs: tuple[ArgSpec, ...], args: tuple) -> bool:
    """Whether ``args`` are exactly of the declared types (see the module doc)."""
    if len(args) != len(specs):
        return False
    for spec, x in zip(specs, args, strict=True):
        if spec.ndim == 0:
            if type(x) not in _SCALARS[spec.dtype]:
                return False
            continue
        if not (
            type(x) is np.ndarray
            and x.ndim == spec.ndim
            and x.dtype == _DTYPES[spec.dtype]
            and x.flags.c_contiguous
            and x.flags.aligned
            and (spec.readonly or x.flags.writeable)
        ):
            return False
    return True


def export_name(key: str) -> str:
    """Name of kernel ``key`` (``module.function``) inside the extension."""
    return key.removeprefix("drakegrasp.batch.").replace(".", "__")


def source_digest(root: Path = _HERE) -> str:
    """SHA-256 of the kernels' sources (:data:`SOURCES`) under ``root``."""
    h = hashlib.sha256()
    for rel in SOURCES:
        h.update(rel.encode() + b"\0")
        h.update((root / rel).read_bytes())
    return h.hexdigest()


def host_cpu() -> str:
    """LLVM's name and features of this CPU (what numba's JIT compiles for)."""
    import llvmlite.binding as ll

    return f"{ll.get_host_cpu_name()} {ll.get_host_cpu_features().flatten()}"


_lock = threading.Lock()
_state: dict = {}


def _load() -> tuple[object | None, str]:
    """The extension module if usable, and a sentence saying which route runs.

    A misspelt :data:`ENV` is recorded (:func:`misspelt`), not warned about
    here: this module imports nothing of drakegrasp, so
    :mod:`drakegrasp.batch.compiled` says it, once per process, as a
    :class:`~drakegrasp.KernelsVariableWarning`.
    """
    choice = os.environ.get(ENV, "auto").strip().lower() or "auto"
    if choice not in ("auto", "jit"):
        _state["misspelt"] = True
        return None, f"{ENV}={choice!r} is not 'auto' or 'jit'; numba's JIT runs"
    if choice == "jit":
        return None, f"{ENV}=jit: numba's JIT runs"
    try:
        spec = importlib.util.find_spec(MODULE)
    except (ImportError, ValueError):
        spec = None
    manifest_path = _HERE / MANIFEST
    if spec is None or not manifest_path.exists():
        return None, "no ahead-of-time kernels were built: numba's JIT runs"
    try:
        manifest = json.loads(manifest_path.read_text())
        if manifest.get("sources") != source_digest():
            return None, "the ahead-of-time kernels are of other sources: JIT runs"
        if manifest.get("cpu") != host_cpu():
            return None, "the ahead-of-time kernels are for another CPU: JIT runs"
        module = importlib.import_module(MODULE)
    except (OSError, ValueError, ImportError) as exc:
        return None, f"the ahead-of-time kernels could not be loaded ({exc}): JIT runs"
    return module, f"ahead-of-time kernels ({Path(module.__file__).name})"


def _module():
    with _lock:
        if "module" not in _state:
            _state["module"], _state["status"] = _load()
        return _state["module"]


def lookup(key: str):
    """The compiled entry of kernel ``key``, or None (not built, not usable)."""
    module = _module()
    return None if module is None else getattr(module, export_name(key), None)


def status() -> str:
    """Which route the batch kernels take in this process, and why."""
    _module()
    return _state["status"]


def misspelt() -> bool:
    """Whether :data:`ENV` held neither ``auto`` nor ``jit`` when it was read.

    It is read once per process (with the route, :func:`status`).
    """
    _module()
    return _state.get("misspelt", False)


def _reset() -> None:
    """Forget the loaded state (tests that change :data:`ENV`)."""
    with _lock:
        _state.clear()
