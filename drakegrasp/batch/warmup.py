"""Compile every batch kernel up front (``drakegrasp warmup``).

An install normally compiles the engine's entry kernels ahead of time
(:mod:`drakegrasp.batch.aot`); then this has nothing to compile and says
so.  Where it could not (or ``DRAKEGRASP_KERNELS=jit``), the batch kernels
compile on first use and are then cached on disk
(:mod:`drakegrasp.batch.compiled`).  A course or a cluster job that does not
want its first real call to wait runs :func:`warmup` once after installing:
it drives every route of the engine (the fused full-rank pass with the
active-set and interior-point solvers, the rank-deficient route, the
construction kernels of each contact model, the expanding-polytope ε) on a
few seeded grasps, so that each kernel compiles with the very signatures that
real calls use (all inputs reach the kernels as C-contiguous float64 and
int64 arrays, whatever their shape), and reports what it compiled and how
long it took.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from drakegrasp.core.serialize import jsonable

__all__ = ["WarmupStep", "WarmupReport", "warmup"]


@dataclass(frozen=True)
class WarmupStep:
    """One route of the engine exercised by :func:`warmup`.

    Attributes
    ----------
    name : str
        What ran, e.g. ``"force closure, spatial hard fingers, N = 3"``.
    seconds : float
        Wall time of the step, compiles or cache loads included, seconds.
    compiled : int
        Functions numba compiled during the step (0: all loaded from the cache).
    """

    name: str
    seconds: float
    compiled: int


@dataclass(frozen=True)
class WarmupReport:
    """What :func:`warmup` did.

    Attributes
    ----------
    available : bool
        Whether numba is installed (False: nothing to compile, the engine runs
        its numpy route).
    steps : tuple of WarmupStep
        The routes exercised, in order.
    cache_dir : str or None
        ``NUMBA_CACHE_DIR`` when set, else None (numba then writes beside the
        sources, or in its user-wide cache when they are read-only).
    route : str
        Which code the entry kernels run (:func:`drakegrasp.batch.aot.status`):
        the install's ahead-of-time kernels (nothing to compile), or numba's
        JIT and why.
    """

    available: bool
    steps: tuple[WarmupStep, ...]
    cache_dir: str | None
    route: str = ""

    @property
    def seconds(self) -> float:
        """Total wall time, seconds."""
        return sum(s.seconds for s in self.steps)

    @property
    def compiled(self) -> int:
        """Total functions compiled (0 when the cache was already warm)."""
        return sum(s.compiled for s in self.steps)

    def to_dict(self) -> dict:
        """A JSON-ready dict."""
        return jsonable(
            {
                "available": self.available,
                "cache_dir": self.cache_dir,
                "route": self.route,
                "seconds": self.seconds,
                "compiled": self.compiled,
                "steps": [
                    {"name": s.name, "seconds": s.seconds, "compiled": s.compiled}
                    for s in self.steps
                ],
            }
        )

    def __str__(self) -> str:
        if not self.available:
            return "numba is not installed: nothing to compile (numpy route)"
        width = max(len(s.name) for s in self.steps)
        lines = [
            f"  {s.name:<{width}}  {s.seconds:7.2f} s  {s.compiled:4d} compiled"
            for s in self.steps
        ]
        where = self.cache_dir or "numba's default cache"
        lines.insert(0, f"  kernels: {self.route}")
        lines.append(
            f"  {'total':<{width}}  {self.seconds:7.2f} s  {self.compiled:4d} "
            f"compiled (cache: {where})"
        )
        return "\n".join(lines)


def _grasps(K: int, N: int, d: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Seeded grasps: contacts on the unit sphere (circle), noisy inward normals."""
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(K, N, d))
    p /= np.linalg.norm(p, axis=-1, keepdims=True)
    n = -p + 0.3 * rng.normal(size=(K, N, d))
    # A few rank-deficient grasps (all contacts on one line through the
    # origin: the corner cases of the routes past the fused full-rank pass).
    p[:4] = p[:4, :1] * np.linspace(0.5, 1.5, N)[None, :, None]
    n[:4] = -p[:4]
    # And a few with a repeated contact: rank-deficient with a null space of
    # several dimensions, which the unfused interior-point pass solves.
    p[4:8, -1] = p[4:8, 0]
    n[4:8, -1] = n[4:8, 0]
    return p, n


def _steps() -> list[tuple[str, Callable[[], object]]]:
    from drakegrasp.batch.api import batch_force_closure, batch_form_closure
    from drakegrasp.batch.epsilon.driver import batch_epsilon_l1
    from drakegrasp.batch.lp.ipm import solve_max_last

    K = 64
    out: list[tuple[str, Callable[[], object]]] = []
    cases = [
        ("spatial hard fingers", 3, 3, "hard_finger", None),
        ("spatial hard fingers", 4, 3, "hard_finger", None),
        ("spatial hard fingers", 12, 3, "hard_finger", None),
        ("planar hard fingers", 3, 2, "hard_finger", None),
        ("planar hard fingers", 4, 2, "hard_finger", None),
        ("soft fingers", 3, 3, "soft_finger", 0.1),
        ("frictionless contacts", 7, 3, "frictionless", None),
    ]
    for label, N, d, contact_model, nu in cases:
        p, n = _grasps(K, N, d, seed=N * 10 + d)
        mu = 0.0 if contact_model == "frictionless" else np.linspace(0.2, 0.8, K)
        options = {
            "contact_model": contact_model,
            "torsional_friction": nu,
            "workers": 1,
        }
        out.append(
            (
                f"force closure, {label}, N = {N}",
                lambda p=p, n=n, mu=mu, o=options: batch_force_closure(
                    p, n, mu=mu, **o
                ),
            )
        )
        out.append(
            (
                f"epsilon (L1), {label}, N = {N}",
                lambda p=p, n=n, mu=mu, o=options: batch_epsilon_l1(p, n, mu=mu, **o),
            )
        )
    p, n = _grasps(K, 7, 3, seed=7)
    out.append(("form closure, N = 7", lambda: batch_form_closure(p, n, workers=1)))
    rng = np.random.default_rng(9)
    B = rng.normal(size=(K, 12, 9))
    B[:, :, -1] = np.abs(B[:, :, -1]) + 0.2
    h = rng.uniform(1.0, 2.0, (K, 12))
    out.append(
        (
            "interior point, one LP at a time (the planner's weight capacity)",
            lambda: solve_max_last(B, h, kernel="compiled"),
        )
    )
    return out


def warmup(*, progress: Callable[[WarmupStep], None] | None = None) -> WarmupReport:
    """Compile (or load from the cache) every batch kernel now.

    Parameters
    ----------
    progress : callable, optional
        Called with each :class:`WarmupStep` as it finishes (the CLI prints
        them).

    Returns
    -------
    WarmupReport
        The steps, their wall times and how many functions each compiled; a
        second run in a new process compiles 0 (the cache is warm).
    """
    import os

    from drakegrasp.batch import aot, compiled

    cache_dir = os.environ.get("NUMBA_CACHE_DIR") or None
    if not compiled.AVAILABLE:
        return WarmupReport(available=False, steps=(), cache_dir=cache_dir)
    route = aot.status()
    compiled.quiet_notice()  # the steps are the report
    steps = []
    for name, run in _steps():
        before = compiled.compile_count()
        t0 = time.perf_counter()
        run()
        step = WarmupStep(
            name=name,
            seconds=time.perf_counter() - t0,
            compiled=compiled.compile_count() - before,
        )
        steps.append(step)
        if progress is not None:
            progress(step)
    return WarmupReport(
        available=True, steps=tuple(steps), cache_dir=cache_dir, route=route
    )
