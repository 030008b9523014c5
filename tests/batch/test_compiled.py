"""The JIT machinery: the on-disk cache is used, the numpy route is announced
once, the first compile says so, and ``drakegrasp warmup`` works.

The JIT is what runs where the install did not compile the kernels ahead of
time (:mod:`drakegrasp.batch.aot`, tested in ``test_aot.py``); the child
processes here force it with ``DRAKEGRASP_KERNELS=jit``.  Timings are never
asserted: a warm cache shows as numba's own counters (cache hits and misses
of a dispatcher, the functions compiled in a process).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from drakegrasp.batch import aot, compiled
from drakegrasp.batch.inputs import resolve_kernel

# The folder holding the drakegrasp this process imports: the checkout, or an
# installed copy (CI tests the installed package). A child process must import
# the same one: numba's cache is keyed by the kernels' source files.
ROOT = Path(compiled.__file__).resolve().parents[2]

pytestmark = pytest.mark.skipif(
    not compiled.AVAILABLE, reason="numba is not installed (the numpy route runs)"
)

# A small kernel with callees: compiling it from an empty cache takes a few
# seconds, loading it takes milliseconds.
_CHILD = r"""
import json, sys
import numpy as np
from drakegrasp.batch import compiled
from drakegrasp.batch.build import construction_kernel as ck
P = np.ascontiguousarray(np.random.default_rng(0).normal(size=(5, 3, 3)))
Nrm = P.copy()
out = np.empty(5)
ck._normalise(Nrm, P, out)
stats = ck._normalise.stats
print(json.dumps({
    "compiled": compiled.compile_count(),
    "hits": sum(stats.cache_hits.values()),
    "misses": sum(stats.cache_misses.values()),
    "out": out.tolist(),
}))
"""


def _child_env(cache_dir: Path, kernels: str = "jit") -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir), **{aot.ENV: kernels})
    env["PYTHONPATH"] = os.pathsep.join(
        [str(ROOT)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    )
    return env


def _run(code: str, env: dict, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", code, *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    )


def _notices(stderr: str) -> int:
    return sum("compiling the batch kernels" in line for line in stderr.splitlines())


def test_a_second_process_loads_from_the_cache_without_compiling(tmp_path):
    env = _child_env(tmp_path / "numba-cache")
    first = _run(_CHILD, env)
    second = _run(_CHILD, env)
    a, b = json.loads(first.stdout), json.loads(second.stdout)
    # The first process compiled (an empty cache misses), and said so once.
    assert a["misses"] >= 1 and a["hits"] == 0 and a["compiled"] >= 1
    assert _notices(first.stderr) == 1, first.stderr
    # The second loaded the same code: hits, no miss, nothing compiled, silent.
    assert b["hits"] >= 1 and b["misses"] == 0 and b["compiled"] == 0
    assert _notices(second.stderr) == 0, second.stderr
    assert a["out"] == b["out"]
    assert any((tmp_path / "numba-cache").rglob("*.nbi"))


def _kernel_dispatchers():
    import importlib

    from drakegrasp.batch.aot_build import KERNEL_MODULES

    for name in KERNEL_MODULES:
        module = importlib.import_module(name)
        for attr, value in vars(module).items():
            if isinstance(value, compiled.Kernel) and value.__module__ == name:
                yield f"{name}.{attr}", value.dispatcher


def test_every_kernel_is_cached_on_disk():
    from numba.core.caching import NullCache
    from numba.core.registry import CPUDispatcher

    found = dict(_kernel_dispatchers())
    assert len(found) >= 40  # the engine's kernels, not an empty scan
    assert all(isinstance(d, CPUDispatcher) for d in found.values())
    uncached = [n for n, d in found.items() if isinstance(d._cache, NullCache)]
    assert uncached == []


def test_the_cache_of_the_package_s_kernels_is_kept_outside_it(monkeypatch):
    # numba's default writes __pycache__/*.nbi beside the installed sources;
    # pip's uninstall left them, and the leftover drakegrasp folder shadowed
    # the next (editable) install as an empty namespace package.
    from numba.core import caching, config

    from drakegrasp.batch.build import construction_kernel as ck

    compiled._numba()
    monkeypatch.setattr(config, "CACHE_DIR", "")
    source = ck._normalise.py_func
    path = source.__code__.co_filename
    found = None
    for cls in caching.CacheImpl._locator_classes:
        found = cls.from_function(source, path)
        if found is not None:
            break
    package = Path(compiled.__file__).resolve().parents[1]
    assert type(found).__name__ == "_PackageCacheLocator"
    assert package not in Path(found.get_cache_path()).resolve().parents
    # NUMBA_CACHE_DIR still wins, and a user's own kernel keeps numba's rules.
    monkeypatch.setattr(config, "CACHE_DIR", "/tmp/elsewhere")
    first = caching.CacheImpl._locator_classes[0]
    assert first.from_function(source, path) is None

    def user_kernel():
        return 1

    monkeypatch.setattr(config, "CACHE_DIR", "")
    assert first.from_function(user_kernel, __file__) is None


def test_the_numpy_route_is_announced_once(monkeypatch):
    import drakegrasp.batch.inputs as inputs

    monkeypatch.setattr(inputs, "numba_available", lambda: False)
    monkeypatch.setattr(compiled, "_said", set())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert [resolve_kernel("auto") for _ in range(3)] == ["numpy"] * 3
        # An explicit choice of the numpy route is not announced.
        assert resolve_kernel("numpy") == "numpy"
    ours = [w for w in caught if issubclass(w.category, compiled.NumbaMissingWarning)]
    assert len(ours) == 1
    assert "numba is not installed" in str(ours[0].message)


def test_the_numpy_route_is_announced_at_the_users_line(monkeypatch):
    import drakegrasp.batch.inputs as inputs
    from drakegrasp.batch import batch_force_closure

    monkeypatch.setattr(inputs, "numba_available", lambda: False)
    monkeypatch.setattr(compiled, "_said", set())
    rng = np.random.default_rng(3)
    p = rng.normal(size=(4, 3, 3))
    n = -p + 0.3 * rng.normal(size=(4, 3, 3))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        batch_force_closure(p, n, mu=0.5, workers=1)
    ours = [w for w in caught if issubclass(w.category, compiled.NumbaMissingWarning)]
    # deep in the batch engine, the warning still points at this line
    assert [w.filename for w in ours] == [__file__]


_NO_NUMBA = r"""
import sys, json
sys.modules["numba"] = None  # as if numba could not be installed
import numpy as np
from drakegrasp.batch import batch_force_closure, compiled
assert not compiled.AVAILABLE
rng = np.random.default_rng(3)
p = rng.normal(size=(40, 3, 3)); n = -p + 0.3 * rng.normal(size=(40, 3, 3))
a = batch_force_closure(p, n, 0.5, workers=1)
b = batch_force_closure(p, n, 0.5, workers=1)
print(json.dumps({"a": a.is_closure.tolist(), "b": b.is_closure.tolist()}))
"""


def test_without_numba_the_engine_runs_numpy_and_says_so_once(tmp_path):
    from drakegrasp.batch import batch_force_closure

    out = _run(_NO_NUMBA, _child_env(tmp_path / "cache"))
    verdicts = json.loads(out.stdout)
    lines = [ln for ln in out.stderr.splitlines() if "numba is not installed" in ln]
    assert len(lines) == 1, out.stderr
    rng = np.random.default_rng(3)
    p = rng.normal(size=(40, 3, 3))
    n = -p + 0.3 * rng.normal(size=(40, 3, 3))
    reference = batch_force_closure(p, n, mu=0.5, workers=1, kernel="numpy")
    assert verdicts["a"] == verdicts["b"] == reference.is_closure.tolist()


@pytest.fixture
def jit_only(monkeypatch):
    """This process and its children run the JIT, as an install without the
    ahead-of-time kernels does."""
    monkeypatch.setenv(aot.ENV, "jit")
    aot._reset()
    for kernel in compiled.kernels():
        monkeypatch.setattr(kernel, "_aot", None)
    yield
    aot._reset()


@pytest.mark.usefixtures("checkout_env")  # the cache other workers write, warm
def test_warmup_compiles_every_route_then_a_new_process_compiles_nothing(
    capsys, jit_only, numba_cache_lock
):
    from drakegrasp.cli import main

    assert main(["warmup", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["available"] is True
    assert "JIT" in report["route"]
    names = [s["name"] for s in report["steps"]]
    for route in ("force closure", "epsilon", "form closure", "planar", "soft"):
        assert any(route in n for n in names), (route, names)
    # Run again in this process: every kernel is in memory, nothing compiles.
    assert main(["warmup", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["compiled"] == 0
    # A new process with the same cache loads everything from disk: the
    # package this test imports, a checkout or an installed copy (numba's
    # index is keyed by the sources' content, which an install keeps).  A
    # first new process writes the cache (this one may hold kernels compiled
    # by earlier tests under another NUMBA_CACHE_DIR, which it never writes
    # again); the second must compile nothing.
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(ROOT)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    )
    code = "from drakegrasp.cli import main; main()"
    with numba_cache_lock():  # no other worker writes the cache meanwhile
        writer = _run(code, env, "warmup", "--json")
        assert json.loads(writer.stdout)["available"] is True, writer.stderr
        fresh = _run(code, env, "warmup", "--json")
    again = json.loads(fresh.stdout)
    assert [s["name"] for s in again["steps"]] == names
    assert again["compiled"] == 0, again
    assert _notices(fresh.stderr) == 0


def test_warmup_prints_its_steps(capsys):
    from drakegrasp.cli import main

    assert main(["warmup"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("compiling the batch kernels")
    assert any(line.startswith("  force closure, spatial hard fingers") for line in out)
    assert out[-1].startswith("done: ")


def test_warmup_help_says_what_it_does_on_each_route():
    """The help names the ahead-of-time, JIT and numpy routes, as warmup runs them."""
    from drakegrasp.batch import aot
    from drakegrasp.cli import build_parser

    _, sub = build_parser()
    text = " ".join(sub.choices["warmup"].format_help().split())
    assert "compiled the kernels ahead of time" in text
    assert "nothing is compiled" in text  # the AOT route: tests/batch/test_aot.py
    assert f"{aot.ENV}=jit" in text and "numba's JIT compiles" in text
    assert "NUMBA_CACHE_DIR" in text
    assert "numpy route" in text  # WarmupReport(available=False)


def test_a_kernel_is_a_named_callable_that_pickles_by_reference():
    import pickle

    from drakegrasp.batch.lp import block_kernel

    kernel = block_kernel._stack
    assert isinstance(kernel, compiled.Kernel)
    assert kernel.key == "drakegrasp.batch.lp.block_kernel._stack"
    assert kernel.__name__ == "_stack" and kernel.__wrapped__ is kernel.py_func
    assert pickle.loads(pickle.dumps(kernel)) is kernel
    assert kernel in compiled.kernels()
