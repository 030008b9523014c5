"""Compile the batch kernels ahead of time: the extension ``pip install .`` builds.

:func:`build` compiles every entry kernel (a :class:`~drakegrasp.batch.compiled.Kernel`
declared with ``entry=``) with numba's ahead-of-time compiler (``numba.pycc``)
into the extension module :data:`drakegrasp.batch.aot.MODULE`, and writes its
manifest (:data:`drakegrasp.batch.aot.MANIFEST`).  The project's ``setup.py``
calls it while building the package; it can also be run by hand in a checkout::

    python -m drakegrasp.batch.aot_build [OUTPUT_DIR]   # default: drakegrasp/batch

How the code stays bitwise that of the JIT: each entry is exported through a
one-line wrapper that calls the kernel, so numba compiles the kernel and its
callees exactly as its JIT does (same options, same typing, same LLVM
optimisation, as a callee linked into the wrapper), and the object code is
generated for this machine's CPU model *and* features, which is what the JIT
targets (numba's ahead-of-time compiler would otherwise take the CPU model's
default features).  The manifest pins the CPU and the sources; elsewhere the
JIT runs.
"""

from __future__ import annotations

import contextlib
import importlib
import json
import sys
import time
from pathlib import Path

from drakegrasp.batch import aot, compiled

__all__ = ["KERNEL_MODULES", "build", "main"]

KERNEL_MODULES = tuple(
    "drakegrasp.batch." + rel.removesuffix(".py").replace("/", ".")
    for rel in aot.SOURCES
)
"""The modules of the kernels (the files of :data:`drakegrasp.batch.aot.SOURCES`)."""


def _numba_type(spec: aot.ArgSpec):
    from numba import types

    scalar = {
        "f8": types.float64,
        "i8": types.int64,
        "i1": types.int8,
        "b1": types.boolean,
    }[spec.dtype]
    return scalar if spec.ndim == 0 else types.Array(scalar, spec.ndim, "C")


def _wrapper(kernel: compiled.Kernel, n: int):
    """``def w(a0, ..., a{n-1}): return kernel(a0, ...)``, the exported function."""
    names = ", ".join(f"a{i}" for i in range(n))
    scope = {"kernel": kernel.dispatcher, "__name__": "drakegrasp.batch.aot_entry"}
    exec(f"def entry({names}):\n    return kernel({names})\n", scope)  # noqa: S102
    return scope["entry"]


@contextlib.contextmanager
def _host_features():
    """Generate ahead-of-time code for this CPU's features, as the JIT does."""
    from numba.core import codegen

    original = codegen.AOTCPUCodegen._customize_tm_features
    codegen.AOTCPUCodegen._customize_tm_features = (
        codegen.JITCPUCodegen._customize_tm_features
    )
    try:
        yield
    finally:
        codegen.AOTCPUCodegen._customize_tm_features = original


def build(output_dir: str | Path, *, log=print) -> Path:
    """Compile the entry kernels into ``output_dir``; return the extension's path.

    Parameters
    ----------
    output_dir : str or Path
        The folder of the installed ``drakegrasp/batch`` (or of the checkout).
    log : callable, optional
        Receives one line per stage.

    Returns
    -------
    Path
        The extension module written; its manifest is beside it.
    """
    import warnings

    import numba

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pycc's pending-deprecation notice
        from numba.pycc import CC

    output_dir = Path(output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    for name in KERNEL_MODULES:
        importlib.import_module(name)
    entries = [k for k in compiled.kernels() if k.entry is not None]
    cc = CC(aot.MODULE.rsplit(".", 1)[1])
    cc.output_dir = str(output_dir)
    cc.target_cpu = "host"
    compiled.quiet_notice()
    t0 = time.perf_counter()
    kernels = {}
    for kernel in entries:
        argtypes = tuple(_numba_type(s) for s in aot.parse_signature(kernel.entry))
        kernel.dispatcher.compile(argtypes)
        restype = kernel.dispatcher.overloads[argtypes].signature.return_type
        cc.export(aot.export_name(kernel.key), restype(*argtypes))(
            _wrapper(kernel, len(argtypes))
        )
        kernels[kernel.key] = kernel.entry
        log(f"  typed {kernel.key} ({time.perf_counter() - t0:.0f} s)")
    with _host_features(), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cc.compile()
    path = output_dir / cc._output_file
    manifest = {
        "format": 1,
        "numba": numba.__version__,
        "cpu": aot.host_cpu(),
        "sources": aot.source_digest(Path(aot.__file__).resolve().parent),
        "kernels": kernels,
    }
    (output_dir / aot.MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n")
    seconds = time.perf_counter() - t0
    log(f"  wrote {path.name} ({len(entries)} kernels, {seconds:.0f} s)")
    return path


def main(argv: list[str] | None = None) -> int:
    """``python -m drakegrasp.batch.aot_build [OUTPUT_DIR]``."""
    argv = sys.argv[1:] if argv is None else argv
    target = Path(argv[0]) if argv else Path(aot.__file__).resolve().parent
    build(target)
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
