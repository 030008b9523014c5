"""A cloud's chords: the screened search against every point measured directly.

Usage::

    python benchmarks/bench_cloud_chord.py [--points 20000] [--lines 5700]
        [--repeat 3]

A sphere-like cloud of ``--points`` points (80 mm radius, 2.5 spacings of
line radius) and ``--lines`` lines through points near its middle, in random
directions: about the lines a pinch's roll casts in a 300-sample plan (19 per
sample).  Times :meth:`drakegrasp.planning.cloud.CloudSurface.chord` (one
matrix product screens the points, the few on a line are measured) against
the direct route it replaced (every point against every line, 64 lines at a
time), checks that the two agree bit for bit, and prints the best of
``--repeat`` runs and their ratio.  Timings are not asserted anywhere.
"""

from __future__ import annotations

import os

# one core: numpy's BLAS must not spin threads of its own (their CPU time counts)
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from drakegrasp.planning.cloud import CloudSurface  # noqa: E402


def direct(surface: CloudSurface, p: np.ndarray, d: np.ndarray, chunk: int = 64):
    """Every point against every line: ``(t_in, t_out, n_out)``."""
    K, rho = len(p), surface.line_radius
    t_in, t_out, n_out = np.zeros(K), np.full(K, np.nan), np.zeros((K, 3))
    for s in range(0, K, chunk):
        v = surface.points[None] - p[s : s + chunk, None]
        t = np.einsum("kmi,ki->km", v, d[s : s + chunk])
        near = np.linalg.norm(v - t[..., None] * d[s : s + chunk, None], axis=2) <= rho
        t_in[s : s + chunk] = np.where(near & (t < -rho), t, 0.0).min(axis=1)
        after = np.where(near & (t > rho), t, -np.inf)
        j = np.argmax(after, axis=1)
        best = after[np.arange(len(j)), j]
        t_out[s : s + chunk] = np.where(np.isfinite(best), best, np.nan)
        n_out[s : s + chunk] = surface.normals[j]
    return t_in, t_out, n_out


def _best(f, repeat):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return min(times), out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=20000)
    parser.add_argument("--lines", type=int, default=5700)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    rng = np.random.default_rng(0)
    n = rng.normal(size=(args.points, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    surface = CloudSurface(0.08 * n, n, origin=np.zeros(3))
    p = 0.4 * surface.points[rng.integers(0, args.points, args.lines)]
    d = rng.normal(size=(args.lines, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    slow, want = _best(lambda: direct(surface, p, d), args.repeat)
    fast, got = _best(lambda: surface.chord(p, d), args.repeat)
    same = all(
        np.array_equal(a, b, equal_nan=True) for a, b in zip(got, want, strict=True)
    )
    print(f"{args.points} points, {args.lines} lines, best of {args.repeat}")
    print(f"  every point measured: {slow:8.3f} s")
    print(f"  screened (chord):     {fast:8.3f} s   ({slow / fast:.1f}x faster)")
    print(f"  bitwise equal: {same}")
    return 0 if same else 1


if __name__ == "__main__":
    raise SystemExit(main())
