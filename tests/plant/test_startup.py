"""Lazy public names, and what ``import drakegrasp`` and ``drakegrasp analyze`` load.

The package resolves its public names on first access (``drakegrasp._lazy``),
so the command imports only the layers it uses.  These tests hold both
promises: every public name still resolves to the object its module defines,
and the deferred layers stay out of a fresh process that imports the package
or runs ``analyze`` (checked in ``sys.modules``, never by timing).
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import drakegrasp
import drakegrasp.plant
from drakegrasp.cli import main
from drakegrasp.plant import list_scenes

SCENE_NAMES = [info.name for info in list_scenes()]

# Never needed to load a scene and print its analysis (the quality layer is:
# analyze prints Ferrari-Canny epsilon).
DEFERRED = (
    "drakegrasp.batch",
    "drakegrasp.distributed",
    "drakegrasp.systems.monitor",
    "drakegrasp.visualization",
    "drakegrasp.plant.closing",
    "drakegrasp.plant.contact_results",
    "concurrent.futures",
    "dask",
    "hypothesis",
    "matplotlib",
    "multiprocessing",
    "numba",
    "pandas",
    "pyarrow",
    "pydrake.all",
    "pydrake.visualization",
    "scipy",
    "tqdm",
)

_LOADED = """
import io, json, sys, contextlib
args = json.loads(sys.argv[1])
if args is not None:
    from drakegrasp.cli import main
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(args) == 0
else:
    import drakegrasp
print(json.dumps(sorted(sys.modules)))
"""


def fresh_python(code: str, *args: str) -> str:
    """The output of ``code`` run by a fresh interpreter (which must succeed).

    It imports the same ``drakegrasp`` as this process (the source tree, or an
    installed copy: in CI the tests run from the checkout beside an installed
    package, whose scene paths differ).
    """
    root = str(Path(drakegrasp.__file__).resolve().parent.parent)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [root, env.get("PYTHONPATH")]))
    run = subprocess.run(
        [sys.executable, "-c", code, *args],
        capture_output=True,
        text=True,
        timeout=600,
        env=env,
        cwd=root,  # ``-c`` puts the working directory first on sys.path
    )
    assert run.returncode == 0, run.stderr
    return run.stdout


def loaded_modules(argv: list[str] | None) -> set[str]:
    """``sys.modules`` of a fresh interpreter after ``main(argv)`` (None: import)."""
    return set(json.loads(fresh_python(_LOADED, json.dumps(argv))))


def deferred_in(modules: set[str]) -> list[str]:
    return sorted(
        m for m in modules if any(m == d or m.startswith(d + ".") for d in DEFERRED)
    )


@pytest.mark.parametrize("package", [drakegrasp, drakegrasp.plant])
def test_every_public_name_resolves_to_its_modules_object(package):
    for name in package.__all__:
        assert getattr(package, name) is not None, name
    for module, names in package._SOURCES.items():
        defining = importlib.import_module(module)
        for name in names:
            assert getattr(package, name) is getattr(defining, name), name


@pytest.mark.parametrize("package", [drakegrasp, drakegrasp.plant])
def test_the_lazy_table_lists_exactly_the_public_names(package):
    listed = [name for names in package._SOURCES.values() for name in names]
    assert len(listed) == len(set(listed)), "a name is listed twice"
    modules = set(package.__all__) - set(listed)
    # What __all__ holds beyond the table can only be a submodule.
    assert modules <= set(package._SUBMODULES)
    assert set(listed) <= set(package.__all__)
    assert set(package.__all__) <= set(dir(package))


def test_public_names_and_submodules_resolve_in_a_fresh_interpreter():
    # The lazy route itself: nothing imported before the names are read.
    code = (
        "import drakegrasp, drakegrasp.plant\n"
        "from drakegrasp import *\n"
        "missing = [n for n in drakegrasp.__all__ if n not in globals()]\n"
        "assert not missing, missing\n"
        "for pkg in (drakegrasp, drakegrasp.plant):\n"
        "    for n in pkg.__all__:\n"
        "        getattr(pkg, n)\n"
        "    subs = pkg._SUBMODULES\n"
        "    subs = subs if isinstance(subs, dict) else "
        "{n: pkg.__name__ + '.' + n for n in subs}\n"
        "    for n, path in subs.items():\n"
        "        assert getattr(pkg, n).__name__ == path\n"
        "assert drakegrasp.batch.batch_force_closure is batch_force_closure\n"
        "assert drakegrasp.examples.__name__ == 'drakegrasp.core.examples'\n"
    )
    fresh_python(code)


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="'drakegrasp' has no attribute 'nope'"):
        drakegrasp.nope  # noqa: B018
    assert not hasattr(drakegrasp.plant, "nope")
    with pytest.raises(ImportError):
        exec("from drakegrasp import nope", {})


def test_import_drakegrasp_loads_no_layer():
    modules = loaded_modules(None)
    assert deferred_in(modules) == []
    assert "pydrake" not in modules and "numpy" not in modules
    assert "drakegrasp.plant" not in modules


def test_analyze_loads_only_what_it_uses():
    modules = loaded_modules(["analyze"])
    assert "drakegrasp.plant.analysis" in modules  # the check sees the run
    assert deferred_in(modules) == []


def test_batch_help_still_lists_the_engines_metrics(capsys):
    from drakegrasp.batch import METRICS

    with pytest.raises(SystemExit):
        main(["batch", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert f"metrics to add: {', '.join(METRICS)}" in out
    with pytest.raises(SystemExit) as stop:
        main(["batch", "in.npz", "out.npz", "--metrics", "nope"])
    assert stop.value.code == 2
    assert "invalid choice: 'nope'" in capsys.readouterr().err


_ANALYZE_ALL = """
import sys
from drakegrasp.cli import main
for argv in __import__("json").loads(sys.argv[1]):
    print("=====", *argv)
    assert main(argv) == 0
"""


def test_analyze_prints_the_same_in_a_fresh_process_as_in_a_loaded_one(capsys):
    # A fresh process resolves everything lazily; this one has imported every
    # layer.  The reports (text and JSON) of every shipped scene must agree.
    argvs = [["analyze", s, *j] for s in SCENE_NAMES for j in ([], ["--json"])]
    fresh = fresh_python(_ANALYZE_ALL, json.dumps(argvs))
    expected = []
    for argv in argvs:
        assert main(argv) == 0
        expected.append(f"===== {' '.join(argv)}\n" + capsys.readouterr().out)
    assert fresh == "".join(expected)
