"""Old module paths still import: each gives the module it became, and warns.

The imports run in a child process: importing an old path puts it in
``sys.modules`` and on its package, which the other tests of a worker must not
see.
"""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

import drakegrasp

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "drakegrasp"

_CHILD = r"""
import importlib, json, pickle, sys, warnings
import drakegrasp
out = {}
for old, new in sorted(drakegrasp._MOVED.items()):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        exec(f"import {old}")  # an import statement, as a user writes it
    out[old] = {
        "same": sys.modules[old] is sys.modules[new],
        "name": sys.modules[old].__name__,
        "warnings": [
            [w.category.__name__, str(w.message), w.filename] for w in caught
        ],
    }
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    from drakegrasp.grasp import Grasp
    from drakegrasp.results import ClosureResult
out["from"] = Grasp is drakegrasp.Grasp and ClosureResult is drakegrasp.ClosureResult
# a pickle made before the move names the old module
out["pickle"] = pickle.loads(b"cdrakegrasp.contact\nContact\n.") is drakegrasp.Contact
try:
    importlib.import_module("drakegrasp.no_such_module")
    out["unknown"] = "imported"
except ModuleNotFoundError as error:
    out["unknown"] = str(error)
print(json.dumps(out))
"""


def _run(code: str, *args: str) -> subprocess.CompletedProcess:
    """``python [args] -c code`` in a fresh process (``code`` empty: no ``-c``)."""
    return subprocess.run(
        [sys.executable, *args, "-c", code] if code else [sys.executable, *args],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
    )


def _printed(code: str):
    """The JSON that ``code`` prints last, run in a fresh process."""
    done = _run(code)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_each_old_path_is_its_new_module_and_warns_at_the_import():
    out = _printed(_CHILD)
    for old, new in drakegrasp._MOVED.items():
        got = out[old]
        if old in drakegrasp._MOVED_NAMES:  # split: a module of its own
            assert not got["same"] and got["name"] == old, (old, got)
        else:
            assert got["same"] and got["name"] == new, (old, got)
        if old == "drakegrasp.examples":  # public: dg.examples
            assert got["warnings"] == [], got
            continue
        assert len(got["warnings"]) == 1, (old, got)
        category, message, filename = got["warnings"][0]
        assert category == "DeprecationWarning"
        assert f"{old} moved to {new}" in message
        assert filename == "<string>", filename  # the import statement's line
    assert out["from"] and out["pickle"]
    assert out["unknown"] == "No module named 'drakegrasp.no_such_module'"


def test_the_table_maps_gone_paths_to_modules_that_exist():
    """An old path is not a file (it would shadow nothing but itself), its new
    path is one, and its last part is no public name of its package, which
    the import would replace by the module."""
    for old, new in drakegrasp._MOVED.items():
        rel_old = Path(*old.split(".")[1:])
        assert not (PACKAGE / rel_old).with_suffix(".py").exists(), old
        assert not (PACKAGE / rel_old).is_dir(), old
        assert (PACKAGE / Path(*new.split(".")[1:])).with_suffix(".py").is_file(), new
        parent, _, child = old.rpartition(".")
        package = importlib.import_module(parent)
        public = {
            n for names in vars(package).get("_SOURCES", {}).values() for n in names
        }
        assert child not in public, old


_RELOAD = r"""
import importlib, importlib.util, json, sys, warnings
warnings.simplefilter("ignore")
import drakegrasp.grasp
new = sys.modules["drakegrasp.core.grasp"]
out = {"spec": new.__spec__.name,
       "find_spec": importlib.util.find_spec("drakegrasp.core.grasp").name}
new.grasp_matrix = None  # a reload runs the module again and restores it
importlib.reload(new)
out.update(name=new.__name__, package=new.__package__,
           rerun=new.grasp_matrix is not None)
print(json.dumps(out))
"""


def test_importing_an_old_path_leaves_the_new_modules_spec_and_reload_alone():
    # The import system gives the module a loader returns the old path's spec:
    # the new module's __spec__ was the old path's, importlib.reload (IPython's
    # autoreload) then ran nothing and renamed the module (__name__
    # "drakegrasp.grasp", __package__ "drakegrasp").
    out = _printed(_RELOAD)
    assert out == {
        "spec": "drakegrasp.core.grasp",
        "find_spec": "drakegrasp.core.grasp",
        "name": "drakegrasp.core.grasp",
        "package": "drakegrasp.core",
        "rerun": True,
    }, out


def test_running_an_old_path_as_a_script_names_the_new_one():
    # python -m drakegrasp.grasp ended in an AttributeError traceback of
    # runpy ('_MovedModules' object has no attribute 'get_code').
    done = _run("", "-m", "drakegrasp.grasp")
    assert done.returncode == 1
    assert "Traceback" not in done.stderr, done.stderr
    assert "drakegrasp.core.grasp" in done.stderr, done.stderr


_IMPORT_MODULE = r"""
import importlib, json, warnings
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    exec('importlib.import_module("drakegrasp.results")')
print(json.dumps([w.filename for w in caught]))
"""


def test_import_module_of_an_old_path_warns_at_the_callers_line():
    # importlib.import_module(old) warned at importlib/__init__.py, which the
    # default filters hide (DeprecationWarning shows in __main__ only).
    assert _printed(_IMPORT_MODULE) == ["<string>"]


_SPLIT = r"""
import json, pickle, warnings
warnings.simplefilter("ignore")
import drakegrasp as dg
from drakegrasp.batch.io import evaluate_file, read_grasps, write_result
from drakegrasp.batch.writers import stream_file, write_chunks
from drakegrasp.results import AntipodalResult, ClosureResult
from drakegrasp.batch.files import driver
out = {
    "io": evaluate_file is driver.evaluate_file
    and write_result is driver.write_result,
    "writers": stream_file is driver.stream_file,
    "results": AntipodalResult is dg.AntipodalResult
    and ClosureResult is dg.ClosureResult,
    # a result pickled before the house names its class's old module
    "pickle": pickle.loads(b"cdrakegrasp.results\nAntipodalResult\n.")
    is dg.AntipodalResult,
}
import drakegrasp.results as old
out["all"] = sorted(old.__all__)
print(json.dumps(out))
"""


def test_old_modules_that_were_split_keep_every_name_of_their_all():
    # batch.io, batch.writers and results were split over several modules; the
    # old path gave only the first, so names of the old __all__ (evaluate_file,
    # write_result, stream_file, AntipodalResult) were an ImportError, and a
    # pickled AntipodalResult did not load.
    out = _printed(_SPLIT)
    assert out == {
        "io": True,
        "writers": True,
        "results": True,
        "pickle": True,
        "all": ["AntipodalResult", "ClosureResult", "InternalForceResult"],
    }, out


def test_names_that_left_the_cloud_module_still_read_there_and_warn():
    # estimate_normals, the spacing constants and sphere_entry moved out of
    # planning.cloud into modules of their own; code that read them there
    # gets the same objects, with a warning that names the new module.
    import warnings

    from drakegrasp.planning import cloud, cloud_normals, cloud_spacing, cloud_tips

    modules = (cloud_normals, cloud_spacing, cloud_tips)
    moved = {name: module for module in modules for name in module.__all__}
    assert {"estimate_normals", "TWIN_JUMP", "sphere_entry"} <= set(moved)
    for name, module in moved.items():
        assert name not in cloud.__all__
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            value = getattr(cloud, name)
        assert value is getattr(module, name)
        assert [w.category for w in caught] == [DeprecationWarning], name
        assert f"{module.__name__}.{name}" in str(caught[0].message)
        assert caught[0].filename == __file__
    with pytest.raises(AttributeError, match="no_such_name"):
        cloud.no_such_name  # noqa: B018
