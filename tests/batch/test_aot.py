"""The ahead-of-time kernels: declared signatures, the argument check, the manifest,
and a real build whose results are bitwise those of the JIT.

Timings are never asserted; a load without compiling shows as numba's own
counters and as numba never being imported.
"""

from __future__ import annotations

import importlib
import json
import os
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.batch import aot, compiled
from drakegrasp.batch.aot_build import KERNEL_MODULES

pytestmark = pytest.mark.skipif(
    not compiled.AVAILABLE, reason="numba is not installed (the numpy route runs)"
)

PACKAGE = Path(compiled.__file__).resolve().parents[1]


def _entries() -> list[compiled.Kernel]:
    for name in KERNEL_MODULES:
        importlib.import_module(name)
    return [k for k in compiled.kernels() if k.entry is not None]


# -- signatures and the argument check ------------------------------------------


def test_signatures_parse_to_dtype_dimension_and_readonly():
    specs = aot.parse_signature("f8[:, :, ::1], i8, readonly i1[::1], b1")
    assert [(s.dtype, s.ndim, s.readonly) for s in specs] == [
        ("f8", 3, False),
        ("i8", 0, False),
        ("i1", 1, True),
        ("b1", 0, False),
    ]


@pytest.mark.parametrize(
    "bad", ["f4[::1]", "f8[:, :]", "f8[::1, :]", "readonly f8", "i1", "object"]
)
def test_unsupported_signatures_are_refused(bad):
    with pytest.raises(ValueError, match="kernel"):
        aot.parse_signature(bad)


def test_only_exactly_typed_arguments_are_accepted():
    specs = aot.parse_signature("f8[:, ::1], i8, f8, b1, readonly f8[::1]")
    a = np.zeros((3, 2))
    ro = np.zeros(4)
    ro.flags.writeable = False
    assert aot.accepts(specs, (a, 1, 0.5, True, ro))
    assert aot.accepts(specs, (a, 1, 0.5, False, np.zeros(4)))
    wrong = [
        (a.T, 1, 0.5, True, ro),  # not C-contiguous
        (a[:, :1], 1, 0.5, True, ro),  # a strided view
        (a.astype(np.float32), 1, 0.5, True, ro),  # another dtype
        (a[0], 1, 0.5, True, ro),  # another dimension
        (a, 1.0, 0.5, True, ro),  # a float for an int
        (a, True, 0.5, True, ro),  # a bool for an int
        (a, np.int64(1), 0.5, True, ro),  # a numpy scalar
        (a, 1, 1, True, ro),  # an int for a float
        (a, 1, 0.5, 1, ro),  # an int for a bool
        (a, 1, 0.5, True),  # an argument missing
        ([[0.0]], 1, 0.5, True, ro),  # not an array
    ]
    for args in wrong:
        assert not aot.accepts(specs, args), args
    frozen = a.copy()
    frozen.flags.writeable = False  # a kernel may write where not declared readonly
    assert not aot.accepts(specs, (frozen, 1, 0.5, True, ro))


def test_every_entry_declares_one_type_per_parameter():
    entries = _entries()
    assert len(entries) >= 9
    for kernel in entries:
        specs = aot.parse_signature(kernel.entry)
        assert len(specs) == kernel.py_func.__code__.co_argcount, kernel.key


def test_the_routes_call_kernels_from_python_only_through_their_entries(monkeypatch):
    """Every kernel call the engine makes from Python fits the declared entry.

    The compiled entries are stood in for by the JIT dispatchers, so the check
    does not need a build: a call with other types (a strided array, a numpy
    scalar) would take the JIT and count in ``jit_calls``.
    """
    from drakegrasp.batch.warmup import _steps

    _entries()
    kernels = list(compiled.kernels())
    for k in kernels:
        monkeypatch.setattr(k, "_aot", k.dispatcher if k.entry else None)
        monkeypatch.setattr(k, "aot_calls", 0)
        monkeypatch.setattr(k, "jit_calls", 0)
    for _, run in _steps():
        run()
    served = {k.key: k.aot_calls for k in kernels if k.aot_calls}
    assert {k.key: k.jit_calls for k in kernels if k.jit_calls} == {}
    # The routes reach the construction, fused, unfused and ε entries.
    for name in ("_normalise", "_grasp_stack3", "_grasp_stack2", "_full_rank_stack"):
        assert any(key.endswith(name) for key in served), (name, served)
    assert "drakegrasp.batch.epsilon.kernel._stack" in served
    assert "drakegrasp.batch.lp.block_kernel._stack" in served


def test_read_only_inputs_are_served_by_the_entries(monkeypatch):
    """Dask hands its workers read-only arrays: they take the entries too.

    ``_normalise`` declared a writable ``P``, so read-only positions took the
    JIT: numba was imported, compiled for a second and wrote its cache.
    """
    _entries()
    kernels = list(compiled.kernels())
    for k in kernels:
        monkeypatch.setattr(k, "_aot", k.dispatcher if k.entry else None)
        monkeypatch.setattr(k, "jit_calls", 0)
    rng = np.random.default_rng(5)
    P = rng.normal(size=(40, 3, 3))
    N = -P + 0.3 * rng.normal(size=P.shape)
    R, mu = 0.1 * rng.normal(size=(40, 3)), np.full(40, 0.5)
    for a in (P, N, R, mu):
        a.flags.writeable = False
    dg.batch_force_closure(P, N, mu=mu, reference_points=R, metrics=("epsilon_l1",))
    dg.batch_epsilon_l1(P, N, mu=mu, reference_points=R)
    assert {k.key: k.jit_calls for k in kernels if k.jit_calls} == {}


# -- the manifest ----------------------------------------------------------------


def test_the_source_digest_follows_every_kernel_source(tmp_path):
    for rel in aot.SOURCES:
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(PACKAGE / "batch" / rel, tmp_path / rel)
    digest = aot.source_digest(tmp_path)
    assert digest == aot.source_digest()
    for rel in aot.SOURCES:
        path = tmp_path / rel
        text = path.read_bytes()
        path.write_bytes(text + b"\n")
        assert aot.source_digest(tmp_path) != digest, rel
        path.write_bytes(text)


def test_jit_is_forced_by_the_environment(monkeypatch):
    monkeypatch.setenv(aot.ENV, "jit")
    aot._reset()
    try:
        assert aot.lookup("drakegrasp.batch.epsilon.kernel._stack") is None
        assert "JIT" in aot.status() and not aot.misspelt()
        monkeypatch.setenv(aot.ENV, "fast")
        aot._reset()
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # aot records it; compiled says it
            assert "'fast' is not 'auto' or 'jit'" in aot.status()
        assert aot.misspelt()
    finally:
        monkeypatch.delenv(aot.ENV)
        aot._reset()


def test_a_misspelt_variable_is_a_grasp_warning_said_once(monkeypatch):
    monkeypatch.setenv(aot.ENV, "fast")
    monkeypatch.setattr(compiled, "_said", set())
    aot._reset()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for _ in range(3):
                compiled.announce_misspelt_kernels()
        monkeypatch.setattr(compiled, "_said", set())
        with warnings.catch_warnings():
            warnings.simplefilter("error", dg.GraspWarning)
            with pytest.raises(dg.KernelsVariableWarning, match="'fast'"):
                compiled.announce_misspelt_kernels()
            compiled.announce_misspelt_kernels()  # said (raised) once
    finally:
        monkeypatch.delenv(aot.ENV)
        aot._reset()
    assert [w.category for w in caught] == [dg.KernelsVariableWarning]
    assert issubclass(dg.KernelsVariableWarning, dg.GraspWarning)
    assert str(caught[0].message) == (
        "DRAKEGRASP_KERNELS='fast' is not 'auto' or 'jit'; numba's JIT runs"
    )


_MISSPELT = r"""
import json, sys, warnings
import numpy as np
import drakegrasp as dg
from drakegrasp.batch import batch_force_closure
workers = int(sys.argv[1])
rng = np.random.default_rng(3)
p = rng.normal(size=(40, 3, 3)); n = -p + 0.3 * rng.normal(size=(40, 3, 3))
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    a = batch_force_closure(p, n, mu=0.5, workers=workers, chunk_size=8)
    b = batch_force_closure(p, n, mu=0.5, workers=workers, chunk_size=8)
said = [w for w in caught if issubclass(w.category, dg.GraspWarning)]
with warnings.catch_warnings():
    warnings.simplefilter("error", dg.GraspWarning)
    c = batch_force_closure(p, n, mu=0.5, workers=workers, chunk_size=8)
print(json.dumps({
    "said": [(w.category.__name__, str(w.message), w.filename) for w in said],
    "same": a.is_closure.tolist() == b.is_closure.tolist() == c.is_closure.tolist(),
}))
"""


@pytest.mark.parametrize("workers", [1, 2])
def test_a_misspelt_variable_is_said_once_in_a_process_that_runs_kernels(
    checkout_env, workers
):
    # aot imports nothing of drakegrasp: the engine says it for it, in the
    # caller's process before any worker runs (workers=2 ran every chunk in
    # worker processes, and the caller heard nothing), at the caller's line
    # (it pointed into drakegrasp/batch/build/construction_kernel.py)
    env = dict(checkout_env, **{aot.ENV: "fast"})
    out = subprocess.run(
        [sys.executable, "-c", _MISSPELT, str(workers)],
        env=env, capture_output=True, text=True, timeout=600, check=True,
    )  # fmt: skip
    said = json.loads(out.stdout)
    assert said["same"]
    assert said["said"] == [
        [
            "KernelsVariableWarning",
            "DRAKEGRASP_KERNELS='fast' is not 'auto' or 'jit'; numba's JIT runs",
            "<string>",
        ]
    ]


# -- a real build ------------------------------------------------------------------

_CHILD = r"""
import json, sys
import numpy as np
import drakegrasp.batch as b
from drakegrasp.batch import aot, compiled
K = 300
out = {"route": aot.status(), "hash": [], "file": aot.__file__}
for seed, N, d, model in ((0, 3, 3, "hard_finger"), (1, 4, 2, "hard_finger"),
                          (2, 3, 3, "soft_finger"), (3, 12, 3, "hard_finger")):
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(K, N, d))
    p /= np.linalg.norm(p, axis=-1, keepdims=True)
    n = -p + 0.3 * rng.normal(size=(K, N, d))
    p[:15] = p[:15, :1] * np.linspace(0.5, 1.5, N)[None, :, None]
    n[:15] = -p[:15]
    opts = {"contact_model": model, "torsional_friction": 0.05 if model == "soft_finger"
            else None, "workers": 1}
    mu = rng.uniform(0.1, 1.0, K)
    r = b.batch_force_closure(p, n, mu=mu, **opts)
    e = b.batch_epsilon_l1(p, n, mu=mu, **opts)
    for a in (r.d_star, r.rank, r.is_closure, r.margin, r.converged, e):
        out["hash"].append(np.ascontiguousarray(a).tobytes().hex())
if sys.argv[1:] == ["warmup"]:
    from drakegrasp.batch.warmup import warmup
    report = warmup()
    out["warmup"] = [report.compiled, report.route]
out["numba_imported"] = "numba" in sys.modules
out["compiled"] = compiled.compile_count()
out["aot_calls"] = sum(k.aot_calls for k in compiled.kernels())
out["jit_calls"] = sum(k.jit_calls for k in compiled.kernels())
print(json.dumps(out))
"""


def _child(root: Path, cache: Path, *args: str, **env) -> dict:
    environ = {k: v for k, v in os.environ.items() if k != aot.ENV}
    environ.update(NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(root), **env)
    done = subprocess.run(
        [sys.executable, "-c", _CHILD, *args],
        env=environ,
        cwd=root,  # not the checkout, which `-c` would put first on the path
        capture_output=True,
        text=True,
        timeout=1200,
        check=True,
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def _installed_build() -> bool:
    """True when the package under test carries an extension built from its sources.

    An install (CI's ``pip install``) builds one; a source checkout has none.
    """
    batch = PACKAGE / "batch"
    manifest = batch / aot.MANIFEST
    built = list(batch.glob("_aot_kernels*.so")) + list(batch.glob("_aot_kernels*.pyd"))
    return (
        bool(built)
        and manifest.is_file()
        and (json.loads(manifest.read_text()).get("sources") == aot.source_digest())
    )


def test_a_built_extension_runs_bitwise_as_the_jit_without_importing_numba(tmp_path):
    # A copy of the package with its extension: the one an install built (no
    # second minute-long build of the same sources), else built here as an
    # install builds it.
    root = tmp_path / "site"
    reuse = _installed_build()
    shutil.copytree(
        PACKAGE,
        root / "drakegrasp",
        ignore=shutil.ignore_patterns(
            "__pycache__", *(() if reuse else ("_aot_kernels*",))
        ),
    )
    batch = root / "drakegrasp" / "batch"
    log = "(the installed build)"
    if not reuse:
        log = subprocess.run(
            [sys.executable, "-m", "drakegrasp.batch.aot_build", str(batch)],
            cwd=root,
            env=dict(
                os.environ, PYTHONPATH=str(root), NUMBA_CACHE_DIR=str(tmp_path / "b")
            ),
            capture_output=True,
            text=True,
            timeout=1200,
            check=True,
        ).stdout
    assert list(batch.glob("_aot_kernels*.so")) or list(batch.glob("_aot_kernels*.pyd"))
    manifest = json.loads((batch / aot.MANIFEST).read_text())
    assert manifest["sources"] == aot.source_digest()
    assert set(manifest["kernels"]) == {k.key for k in _entries()}, log

    fast = _child(root, tmp_path / "c1")
    assert fast["file"].startswith(str(root)), fast["file"]
    assert fast["route"].startswith("ahead-of-time kernels"), fast["route"]
    assert not fast["numba_imported"]  # nothing to import, nothing to compile
    assert fast["compiled"] == 0 and fast["jit_calls"] == 0 and fast["aot_calls"] > 0
    # Every route of `drakegrasp warmup` is served: nothing to compile.
    warm = _child(root, tmp_path / "c1", "warmup")
    assert warm["warmup"] == [0, fast["route"]] and warm["jit_calls"] == 0

    # The JIT (from the cache a build here left: it typed the entries with the JIT).
    jit = _child(root, tmp_path / "b", **{aot.ENV: "jit"})
    assert jit["numba_imported"] and jit["aot_calls"] == 0 and jit["jit_calls"] > 0
    assert fast["hash"] == jit["hash"]  # bit for bit

    # Edited kernel sources are never served the stale extension.
    kernel = batch / "epsilon" / "kernel.py"
    kernel.write_text(kernel.read_text() + "\n# edited\n")
    stale = _child(root, tmp_path / "b")
    assert "other sources" in stale["route"] and stale["aot_calls"] == 0
    assert stale["hash"] == jit["hash"]


_ISOLATED = r"""
import importlib, sys
for name in ("pydrake", "scipy", "yaml"):  # not in pip's build environment
    sys.modules[name] = None
root = sys.argv[1]
source = open(root + "/setup.py").read().split("\nsetup(")[0]
scope = {"__file__": root + "/setup.py", "__name__": "setup_helpers"}
exec(compile(source, "setup.py", "exec"), scope)
sys.path.insert(0, root)
scope["_kernel_package_only"]()
from drakegrasp.batch.aot_build import KERNEL_MODULES
for name in KERNEL_MODULES:
    importlib.import_module(name)
from drakegrasp.batch import compiled
print(sum(k.entry is not None for k in compiled.kernels()), "numba" in sys.modules)
"""


def test_the_install_build_needs_only_numba_and_numpy(tmp_path):
    """setup.py reaches every entry kernel without Drake, scipy or PyYAML."""
    root = Path(compiled.__file__).resolve().parents[2]
    if not (root / "setup.py").exists():
        pytest.skip("an installed copy: setup.py is in the source tree only")
    done = subprocess.run(
        [sys.executable, "-c", _ISOLATED, str(root)],
        cwd=tmp_path,
        env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.split() == [str(len(_entries())), "False"]
