"""Call every public callable with hostile values; print the raw exceptions.

    python tests/fuzz/report_public.py [--seed N] [--budget SECONDS] [--limit S]

For ``--budget`` seconds (default 150) it picks a public callable at random
(one of ``PUBLIC`` of ``tests/core/test_calls.py``: every name of every
package's table, and the example grasps), fills its parameters with values
drawn from :data:`HOSTILE`, the hostile objects of ``hostile.objects``
(dunders that raise or lie, masked arrays, odd dtypes, huge broadcast shapes,
and ``hostile.path_hostile``'s paths: path-likes whose ``__fspath__`` raises
or lies, a NUL, a lone surrogate, names too long, ``str`` subclasses whose
``==``, ``__hash__``, ``strip`` or ``encode`` raise or lie, and an object
whose ``__class__`` claims ``str``) and the scene's objects (for
a parameter that :func:`scene_values` knows, often a valid value instead, so
that the call gets past its first check), calls it and draws a few items of
what it yields.  A :class:`~drakegrasp.GraspError` is the refusal the library
promises.  Anything else is a *raw kind*, keyed by the callable, the
exception's type and the ``file:line`` that raised it (the innermost frame
inside drakegrasp, so a hostile object's own dunder is not the key); a call
still running after ``--limit`` seconds (default 4) is the kind ``TIMEOUT``,
and a GraspError whose message is longer than :data:`LONG` characters (a huge
``repr`` carried into it whole) is the kind ``LONG_MESSAGE``.

It prints the number of calls, then one line per raw kind: how many calls
met it, its key, and the first such call (arguments and message).  The
exit status is 1 if there is any raw kind.  The same seed on the same code
makes the same choices, though how many calls fit the budget depends on the
machine.

The scene is Drake's cracker box before the Schunk gripper
(``package://drake_models``; set ``DRAKEGRASP_DRAKE_MODELS`` to a local
copy).  Warm numba's cache first (``drakegrasp warmup``): the time limit can
interrupt a kernel being compiled, which shows as ``TIMEOUT`` or numba's
"no compiled object yet".
"""

from __future__ import annotations

import argparse
import collections
import importlib
import inspect
import os
import random
import signal
import sys
import time
import traceback
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "core"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import hostile as hostile_objects  # noqa: E402

import drakegrasp as dg  # noqa: E402
from drakegrasp.planning.scenes import planning_scene  # noqa: E402

BOX = "package://drake_models/ycb/003_cracker_box.sdf"

# Callables that start workers, clusters or simulations: a call can take
# minutes, and the fuzz suite's sandboxed families cover them
# (report_surfaces.py).
SKIP = {
    "analyze_poses",
    "evaluate_on_cluster",
    "load_scene",
    "plan_grasps",
    "shake_candidates",
    "shake_test",
    "stream_file_on_cluster",
}


def scene_values(drake_models: str | None) -> tuple[dict, list]:
    """Valid values by parameter name, and the scene's objects to misplace."""
    scene = planning_scene(BOX, models_dir=drake_models)
    plant = scene.plant
    context = plant.GetMyContextFromRoot(scene.context)
    grasp = dg.examples.spatial_two_fingers(0.5)
    planar = dg.examples.planar_two_finger_square(0.5)
    good = {
        "grasp": [grasp, planar],
        "plant": [plant],
        "plant_context": [context],
        "object_body": [scene.object_body, "003_cracker_box::base_link_cracker"],
        "hand": [scene.hand, None],
        "mu": [0.5],
        "positions": [np.zeros((2, 3, 3))],
        "normals": [np.tile([0.0, 0.0, 1.0], (2, 3, 1))],
        "contact": [grasp.contacts[0]],
        "hand_jacobian": [np.ones((6, 2))],
    }
    misplaced = [
        grasp, planar, [grasp], plant, plant.world_body(), scene.object_body,
        context, scene.context, scene.hand, dg.AnalysisOptions(),
        dg.BatchOptions(),
    ]  # fmt: skip
    return good, misplaced


HOSTILE = [
    None, "", "x", "hard_finger", b"x", 0, -1, 1, 2**70, -(2**70), True, 1.5,
    float("nan"), float("inf"), -0.0, 1e308, 5e-324, 1j,
    [], {}, (), set(), [1, "a"], [[1, 2], [3]], [None], ["x", "y"], {"a": 1},
    np.array([]), np.zeros((0, 3)), np.zeros((2, 0, 3)), np.full(3, np.nan),
    np.ones((2, 3, 3)), np.ones(3, dtype=np.float32), np.array(["a"]),
    np.array([1, 2, 3], dtype=object), np.int64(3), np.float16(2),
    np.bool_(True), np.ma.masked_array([1, 2, 3], [0, 1, 0]),
    object(), lambda *a, **k: None, type, float, Ellipsis,
    "package://nope/x.sdf", "/nonexistent/x.npz", "/dev/null", ".",
]  # fmt: skip
"""Values of the wrong kind, edge numbers, odd arrays and paths (with the
scene's objects, :func:`scene_values`, they are what a parameter is given)."""


MEMORY = 3 << 30
"""Bytes of data a call may add (the huge broadcast shapes of the hostile pool
would otherwise take the machine's memory): beyond it, ``MemoryError``."""


def _cap_memory(extra: int) -> None:
    """Limit the process's data segment to what it holds now plus ``extra``."""
    import resource

    with open("/proc/self/status") as status:
        held = next(int(line.split()[1]) << 10 for line in status if "VmData" in line)
    resource.setrlimit(resource.RLIMIT_DATA, (held + extra, resource.RLIM_INFINITY))


LONG = 10_000
"""Characters beyond which a GraspError's message counts as a raw kind."""


def _shown(value, width: int = 120) -> str:
    """``repr(value)`` cut to ``width``, or its type if the repr raises or lies.

    The report's own printing must survive the hostile objects it passes.
    """
    try:
        text = repr(value)
        if type(text) is not str:
            raise TypeError("not a str")  # noqa: TRY301
    except Exception:  # noqa: BLE001 - a hostile __repr__
        return f"<{type(value).__name__}: repr raised>"
    return text[:width]


class LONG_MESSAGE(Exception):  # noqa: N801 - the kind's name in the report
    """A GraspError whose message is longer than :data:`LONG` characters."""


class _Timeout(BaseException):
    """Raised by SIGALRM: a BaseException, so no ``except Exception`` eats it."""


def _alarm(*_):
    raise _Timeout


def _arguments(function, rng: random.Random, good: dict, hostile: list):
    """Positional and keyword arguments for one call, or None (no signature)."""
    try:
        parameters = inspect.signature(function).parameters.values()
    except (TypeError, ValueError):
        return None
    args, keywords = [], {}
    for p in parameters:
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            continue
        if p.default is not p.empty and rng.random() >= 0.3:
            continue  # an optional parameter keeps its default
        if p.name in good and rng.random() < 0.6:
            value = rng.choice(good[p.name])
        else:
            value = rng.choice(hostile)
        by_keyword = p.kind is p.KEYWORD_ONLY or (
            p.kind is p.POSITIONAL_OR_KEYWORD and rng.random() < 0.3
        )
        if by_keyword or keywords:
            keywords[p.name] = value
        else:
            args.append(value)
    return args, keywords


def _call(function, args, keywords, limit: float) -> BaseException | None:
    """Call ``function`` (drawing 3 items of an iterator); what it raised, if any."""
    signal.setitimer(signal.ITIMER_REAL, limit)
    try:
        result = function(*args, **keywords)
        if inspect.isgenerator(result) or hasattr(result, "__next__"):
            for _ in zip(range(3), result, strict=False):
                pass
    except dg.GraspError as error:
        if len(str(error)) > LONG:
            long = LONG_MESSAGE(f"{len(str(error))} characters: {str(error)[:100]}")
            return long.with_traceback(error.__traceback__)
        return None
    except BaseException as error:  # noqa: BLE001 - what the report counts
        return error
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
    return None


def _kind(name: str, error: BaseException) -> tuple[str, str, str]:
    if isinstance(error, _Timeout):
        return name, "TIMEOUT", ""
    frames = traceback.extract_tb(error.__traceback__)
    ours = [f for f in frames if f"{os.sep}drakegrasp{os.sep}" in f.filename]
    frame = (ours or frames)[-1]  # where the library let it through
    return name, type(error).__name__, f"{Path(frame.filename).name}:{frame.lineno}"


def run(seed: int, budget: float, limit: float):
    """``(calls, {kind: (count, first call)})`` of one run."""
    from test_calls import PUBLIC

    good, misplaced = scene_values(os.environ.get("DRAKEGRASP_DRAKE_MODELS"))
    hostile = HOSTILE + hostile_objects.objects() + misplaced
    targets = [
        (name, getattr(importlib.import_module(package), name))
        for package, name in PUBLIC
        if name not in SKIP
    ]
    _cap_memory(MEMORY)
    rng = random.Random(seed)
    kinds: dict = {}
    counts = collections.Counter()
    calls = 0
    old = signal.signal(signal.SIGALRM, _alarm)
    start = time.perf_counter()
    try:
        while time.perf_counter() - start < budget:
            name, function = rng.choice(targets)
            arguments = _arguments(function, rng, good, hostile)
            if arguments is None:
                continue
            error = _call(function, *arguments, limit)
            calls += 1
            if error is not None:
                key = _kind(name, error)
                counts[key] += 1
                args, keywords = arguments
                kinds.setdefault(
                    key,
                    (
                        [_shown(a) for a in args],
                        {k: _shown(v) for k, v in keywords.items()},
                        str(error)[:200],
                    ),
                )
    finally:
        signal.signal(signal.SIGALRM, old)
    return calls, {key: (counts[key], first) for key, first in kinds.items()}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--budget", type=float, default=150.0, help="seconds")
    parser.add_argument("--limit", type=float, default=4.0, help="seconds a call")
    options = parser.parse_args()
    warnings.simplefilter("ignore")  # the exceptions are what we count
    calls, kinds = run(options.seed, options.budget, options.limit)
    print(f"calls {calls}, raw kinds {len(kinds)}")
    for key, (count, first) in sorted(kinds.items()):
        print(f"{count} {key} {first!r:.400}")
    return 1 if kinds else 0


if __name__ == "__main__":
    sys.exit(main())
