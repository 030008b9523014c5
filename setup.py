"""Build step beyond pyproject.toml: the batch kernels, compiled ahead of time.

Everything else about the package is declared in ``pyproject.toml``.  Here
``build_ext`` compiles the batch engine's entry kernels with numba's
ahead-of-time compiler into ``drakegrasp/batch/_aot_kernels*.so`` (about a
minute of CPU, once per install; see :mod:`drakegrasp.batch.aot_build`), so the
first batch call of a fresh install does not wait for numba's JIT.

If that cannot be done (numba or a C compiler missing, an unsupported
platform) the install still succeeds and says so: the kernels then compile on
first use, as before.  ``DRAKEGRASP_BUILD_KERNELS=0`` skips the step.
"""

import os
import sys
import tempfile
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
KERNELS = "drakegrasp.batch._aot_kernels"
MANIFEST = "_aot_kernels.json"  # drakegrasp.batch.aot.MANIFEST


def _kernel_package_only() -> None:
    """Import ``drakegrasp.batch``'s kernel modules without its ``__init__``.

    The build environment holds numba and numpy, not the runtime dependencies
    (Drake, scipy, ...) that ``drakegrasp/batch/__init__.py`` imports for the
    engine's API; the kernels need none of them.
    """
    import types

    import drakegrasp  # light: lazy exports only

    batch = types.ModuleType("drakegrasp.batch")
    batch.__path__ = [str(HERE / "drakegrasp" / "batch")]
    sys.modules["drakegrasp.batch"] = batch
    drakegrasp.batch = batch


class BuildKernels(build_ext):
    """``build_ext`` that compiles the kernels with numba instead of a C source."""

    def build_extension(self, ext):
        """Compile the kernels (never fails the build: the JIT is the fallback)."""
        if ext.name != KERNELS:
            return super().build_extension(ext)
        if os.environ.get("DRAKEGRASP_BUILD_KERNELS", "1").strip() == "0":
            print("drakegrasp: DRAKEGRASP_BUILD_KERNELS=0, kernels left to the JIT")
            return None
        target = Path(self.get_ext_fullpath(ext.name)).parent
        print("drakegrasp: compiling the batch kernels ahead of time (about a minute)")
        sys.path.insert(0, str(HERE))
        with tempfile.TemporaryDirectory(prefix="drakegrasp-numba-") as cache:
            # The JIT's cache of this build process is of no use afterwards.
            os.environ.setdefault("NUMBA_CACHE_DIR", cache)
            try:
                _kernel_package_only()
                from drakegrasp.batch.aot_build import build

                build(target, log=lambda line: print(f"drakegrasp: {line}"))
            except Exception as exc:  # noqa: BLE001 - the install must go on
                print(
                    "drakegrasp: WARNING: the batch kernels could not be compiled "
                    f"ahead of time ({type(exc).__name__}: {exc}); they will "
                    "compile on first use instead (`drakegrasp warmup`)",
                    file=sys.stderr,
                )
            finally:
                sys.path.remove(str(HERE))
        return None

    def copy_extensions_to_source(self):
        """Also put the kernels' manifest beside them (an editable install).

        ``pip install -e`` copies each extension into the source tree; the
        manifest that :mod:`drakegrasp.batch.aot` checks the kernels against
        stayed in ``build/``, so the kernels built were never used.
        """
        super().copy_extensions_to_source()
        build_py = self.get_finalized_command("build_py")
        for ext in self.extensions:
            if ext.name != KERNELS or not hasattr(self, "_get_inplace_equivalent"):
                continue
            inplace_file, regular_file = self._get_inplace_equivalent(build_py, ext)
            manifest = Path(regular_file).parent / MANIFEST
            if os.path.exists(regular_file) and manifest.exists():
                self.copy_file(str(manifest), str(Path(inplace_file).parent / MANIFEST))

    def get_outputs(self):
        """The extension when it was built (a failed or skipped build has none)."""
        return [p for p in super().get_outputs() if os.path.exists(p)]


setup(
    ext_modules=[Extension(KERNELS, sources=[])],
    cmdclass={"build_ext": BuildKernels},
)
