"""numba's ``njit`` when numba is installed, a stand-in decorator when not.

numba is an optional dependency (``pip install drakegrasp[fast]``).  The batch
kernels (:mod:`~drakegrasp.batch.lp.block_kernel`,
:mod:`~drakegrasp.batch.lp.fused_kernel`, :mod:`~drakegrasp.batch.epsilon.kernel`)
decorate their functions with :func:`njit` from here; ``AVAILABLE`` says
whether they are compiled, and callers take the pure-numpy routes when not.
"""

from __future__ import annotations

__all__ = ["AVAILABLE", "njit"]

try:  # pragma: no cover - exercised when numba is installed
    from numba import njit

    AVAILABLE = True
except ImportError:  # pragma: no cover
    AVAILABLE = False

    def njit(*args, **kwargs):
        """Stand-in decorator when numba is absent (the kernel is then unused)."""

        def wrap(fn):
            return fn

        return wrap
