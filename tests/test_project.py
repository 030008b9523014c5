"""The project's promises about itself: quick start, CI script, lint."""

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _quick_start_commands():
    text = (ROOT / "README.md").read_text()
    section = text.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    block = re.search(r"```bash\n(.*?)```", section, re.S).group(1)
    return [line for line in block.splitlines() if line.strip()]


def test_readme_quick_start_has_exactly_two_commands():
    commands = _quick_start_commands()
    assert len(commands) == 2
    assert commands[0].endswith("drakegrasp analyze")
    assert '".[test]"' in commands[1]
    assert re.search(r"&& pytest( -n auto)?$", commands[1])


class _ParallelRun:
    """The options ``pytest -n 2`` gives a scheduler (what the hook reads)."""

    def __init__(self, dist: str):
        self._values = {"dist": dist, "tx": ["2*popen"]}

    def getoption(self, name):
        return self._values[name]

    getvalue = getoption


def _scheduler(request, dist: str):
    (conftest,) = [
        p
        for p in request.config.pluginmanager.get_plugins()
        if str(getattr(p, "__file__", "")) == str(ROOT / "tests" / "conftest.py")
    ]
    return conftest.pytest_xdist_make_scheduler(_ParallelRun(dist), None)


def test_a_parallel_run_sends_files_whole_and_the_tutorial_runs_together(request):
    pytest.importorskip("xdist")
    scheduler = _scheduler(request, "load")
    scope = scheduler._split_scope
    docs = scope("tests/docs/test_docs_build.py::test_site_builds_without_warnings")
    tutorials = scope("tests/tutorials/test_notebooks.py::test_notebook_runs[x]")
    assert docs == tutorials  # each tutorial executes once per run
    assert scope("tests/test_project.py::test_a") != docs  # names it in a test name
    one = scope("tests/test_solvers.py::test_a")
    assert one == scope("tests/test_solvers.py::test_b") != docs
    assert one != scope("tests/test_architecture.py::test_a")
    assert _scheduler(request, "loadgroup") is None  # asked for: pytest-xdist's


def test_ci_runs_the_readme_test_command_verbatim():
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    assert _quick_start_commands()[1] in ci


@pytest.mark.skipif(
    importlib.util.find_spec("ruff") is None, reason="ruff is not installed"
)
def test_ruff_is_clean():
    for args in (["check"], ["format", "--check"]):
        run = subprocess.run(
            [sys.executable, "-m", "ruff", *args, "."],
            cwd=ROOT,
            capture_output=True,
            text=True,
        )
        assert run.returncode == 0, run.stdout + run.stderr


def test_readme_python_examples_run(capsys, request):
    """The README's blocks in order, in one namespace, as a reader runs them.

    The blocks that need Drake's ``drake_models`` run only where a local copy is
    (``tests/conftest.py``), so the rest still runs offline on a fresh clone;
    each of those blocks also runs alone in ``tests/docs/test_repo_links.py``.
    """
    text = (ROOT / "README.md").read_text()
    namespace: dict = {}
    models = request.getfixturevalue("local_drake_models_or_none")
    for block in re.findall(r"```python\n(.*?)```", text, re.S):
        if "drake_models" in block and models is None:
            continue
        exec(compile(block, "README.md", "exec"), namespace)
    out = capsys.readouterr().out
    assert "force closure: YES" in out and "form closure: no" in out


def test_setup_places_the_kernels_manifest_the_engine_reads():
    # setup.py cannot import drakegrasp.batch.aot (the build environment has
    # no Drake); the manifest's name it copies beside the kernels on an
    # editable install must be the one aot checks them against
    from drakegrasp.batch import aot

    text = (ROOT / "setup.py").read_text()
    assert re.search(r'^MANIFEST = "([^"]+)"', text, re.M).group(1) == aot.MANIFEST
    assert re.search(r'^KERNELS = "([^"]+)"', text, re.M).group(1) == aot.MODULE
