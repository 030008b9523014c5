"""Fixtures shared by every test folder: where Drake's real models are, and the
tutorial notebooks executed once per session."""

from __future__ import annotations

import contextlib
import copy
import functools
import os
import re
import signal
import subprocess
import sys
import uuid
from pathlib import Path
from unittest import mock

import pytest

from drakegrasp.plant.models import DRAKE_MODELS_ENV

ROOT = Path(__file__).resolve().parents[1]

_SUPPORT = str(Path(__file__).resolve().parent / "support")
if _SUPPORT not in sys.path:  # helpers shared across test folders (odd_scenes)
    sys.path.insert(0, _SUPPORT)

# A shell starts a background job (``pytest &``, a CI step run beside another)
# with SIGINT ignored, and its children inherit that: the commands the signal
# tests start then ignored their Ctrl-C, as ``drakegrasp`` rightly does when
# started so (exit 0 where 130 was asked).  Those tests stand for a command run
# from a terminal: a handled SIGINT here becomes the default in every child.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def local_drake_models() -> Path | None:
    """The local ``drake_models`` copy: ``$DRAKEGRASP_DRAKE_MODELS``, else
    ``<repo>/../shared/drake_models``; None when neither is a directory."""
    for candidate in (
        os.environ.get(DRAKE_MODELS_ENV),
        ROOT.parent / "shared" / "drake_models",
    ):
        if candidate and Path(candidate).is_dir():
            return Path(candidate).resolve()
    return None


def pytest_configure(config):
    """Point ``package://drake_models`` at the local copy for the whole run.

    Code under test that calls ``use_local_drake_models(parser)`` (the README's
    real-hand block, tutorial 06, notebook kernels, which inherit the
    environment) then reads the local copy instead of downloading; an explicit
    ``$DRAKEGRASP_DRAKE_MODELS`` is left as it is.
    """
    path = local_drake_models()
    if path is not None:
        os.environ.setdefault(DRAKE_MODELS_ENV, str(path))


@pytest.fixture(scope="session")
def drake_models_dir() -> Path:
    """Folder of Drake's ``drake_models`` package; skips the test when absent."""
    path = local_drake_models()
    if path is None:
        pytest.skip(
            f"drake_models not found: set {DRAKE_MODELS_ENV} or put a copy at "
            "../shared/drake_models"
        )
    return path


@pytest.fixture(scope="session")
def numba_cache_lock(tmp_path_factory):
    """A lock on the checkout's numba cache, shared by pytest-xdist's workers.

    Each worker runs :func:`checkout_env`'s warmup once; two writing the
    cache at once can lose an entry of numba's index (read, changed and
    written back by each), so that a later process compiles what a test says
    it loads.  Hold ``numba_cache_lock()`` while a process may write the cache.
    A serial run needs no lock.
    """
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return contextlib.nullcontext
    path = tmp_path_factory.getbasetemp().parent / "numba-cache.lock"  # the run's

    @contextlib.contextmanager
    def held():
        import fcntl

        with open(path, "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            try:
                yield
            finally:
                fcntl.flock(lock, fcntl.LOCK_UN)

    return held


@pytest.fixture(scope="session")
def checkout_env(numba_cache_lock) -> dict:
    """The environment for a subprocess that runs this checkout's drakegrasp,
    with its batch kernels compiled (or loaded from numba's cache) first.

    The checkout has no ahead-of-time kernels, so a subprocess JIT-compiles
    them on a cold cache and says so on stderr.  Tests that signal a run
    within seconds and read its stderr killed it mid-compile, so nothing was
    cached and the next run's stderr held the compile notice beside its one
    line (CI, once, on a slower machine); ``drakegrasp warmup`` runs here once
    per session, before any of them.
    """
    env = dict(os.environ)
    paths = [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *paths])
    with numba_cache_lock():  # another worker's warmup may write it too
        done = subprocess.run(
            [sys.executable, "-m", "drakegrasp", "warmup"],
            capture_output=True,
            text=True,
            env=env,
            cwd=ROOT,
            timeout=900,
        )
    assert done.returncode == 0, done.stderr
    return env


@pytest.fixture(scope="session")
def local_drake_models_or_none() -> Path | None:
    """Folder of ``drake_models``, or None when absent (no skip)."""
    return local_drake_models()


# -- the suite on several cores (pytest-xdist) ---------------------------------------


@pytest.hookimpl(optionalhook=True)  # a hook of pytest-xdist's, absent without it
def pytest_xdist_make_scheduler(config, log):
    """With ``pytest -n N``, send each test file whole to one worker.

    A file's module-scoped fixtures (the fuzz families' scenes, a planned
    candidate set) are then built once, as in a serial run.  The files that
    read :func:`tutorial_runs` go to one worker together, so that each tutorial
    still executes once per run.  An explicit ``--dist`` other than ``load``
    (what ``-n`` implies) or ``loadfile`` is left to pytest-xdist.
    """
    if config.getoption("dist") not in ("load", "loadfile"):
        return None
    from xdist.scheduler import LoadFileScheduling

    tests = Path(__file__).resolve().parent

    @functools.cache
    def reads_tutorial_runs(scope: str) -> bool:
        path = tests.parent / scope
        return path.is_file() and bool(
            re.search(r"\btutorial_runs\b", path.read_text(encoding="utf-8"))
        )

    class _FileScheduling(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            scope = super()._split_scope(nodeid)
            return "tutorial runs" if reads_tutorial_runs(scope) else scope

    return _FileScheduling(config, log)


# -- seeded random grasps (core, closure and certificate tests) ---------------------


@pytest.fixture
def rng():
    """A seeded generator, the same sequence in every test that asks for it."""
    import numpy as np

    return np.random.default_rng(20261122)


@pytest.fixture
def make_contacts():
    """The function ``random_grasps.random_inward_contacts`` (tests/support)."""
    from random_grasps import random_inward_contacts

    return random_inward_contacts


@pytest.fixture
def helpers():
    """The grasp builders and reference routes of ``grasp_builders`` (tests/support)."""
    import grasp_builders

    return grasp_builders


# -- the tutorials, executed once ---------------------------------------------------

TUTORIALS = ROOT / "tutorials"

WARNINGS_AS_ERRORS = """\
import warnings

import pydrake.common.deprecation  # noqa: F401  (installs Drake's filter first)

warnings.simplefilter("error", DeprecationWarning)
"""
"""The cell prepended to every executed notebook (see tests/tutorials)."""

CELL_TIMEOUT = 600  # seconds per cell: a hang fails, a slow machine does not


class TutorialRuns:
    """Executes notebooks in kernels of this interpreter, each tutorial at most once.

    Each run is a copy of the notebook with :data:`WARNINGS_AS_ERRORS` prepended,
    executed in ``tutorials/`` with ``DRAKEGRASP_TUTORIAL_TEST=1`` (short loops),
    ``_DRAKE_DEPRECATION_IS_ERROR=1`` and matplotlib's inline backend (so the
    figures are outputs the documentation can show).  The documentation build
    renders these runs instead of executing the tutorials a second time.
    """

    def __init__(self, kernels: Path):
        from ipykernel.kernelspec import write_kernel_spec
        from jupyter_client.kernelspec import KernelSpecManager

        write_kernel_spec(path=str(kernels / "python3"))
        self._kernels = kernels
        self._specs = KernelSpecManager(
            kernel_dirs=[str(kernels)], ensure_native_kernel=False
        )
        self._runs: dict[Path, tuple[object, Exception | None]] = {}

    @staticmethod
    def needs_drake_models(notebook: Path) -> bool:
        """True for a tutorial that loads Drake's real hands or YCB objects."""
        return "drake_models" in notebook.read_text(encoding="utf-8")

    def execute(self, nb):
        """Execute a copy of ``nb`` (warnings cell first); raise on a failing cell."""
        import nbclient
        import nbformat
        from jupyter_client.manager import KernelManager

        executed = copy.deepcopy(nb)
        executed.cells.insert(0, nbformat.v4.new_code_cell(WARNINGS_AS_ERRORS))
        test_mode = dict(DRAKEGRASP_TUTORIAL_TEST="1", _DRAKE_DEPRECATION_IS_ERROR="1")
        with mock.patch.dict(os.environ, test_mode):  # the kernel inherits it
            os.environ.pop("MPLBACKEND", None)  # inline figures
            # the connection file beside the kernelspec, not a mkstemp file in
            # /tmp that jupyter_client leaves behind (14 per CI run)
            km = KernelManager(
                kernel_name="python3",
                kernel_spec_manager=self._specs,
                connection_file=str(self._kernels / f"kernel-{uuid.uuid4().hex}.json"),
            )
            assert km.kernel_spec.argv[0] == sys.executable
            nbclient.NotebookClient(
                executed,
                km=km,
                timeout=CELL_TIMEOUT,
                resources={"metadata": {"path": str(TUTORIALS)}},
            ).execute()
        return executed

    def run(self, notebook: Path):
        """``(executed notebook, None)``, or ``(None, the error)``; cached per path.

        The executed notebook has the warnings cell removed again, and its
        execution counts renumbered from 1, as a reader's run shows them.
        """
        import nbformat

        notebook = notebook.resolve()
        if notebook not in self._runs:
            try:
                executed = self.execute(nbformat.read(notebook, as_version=4))
            except Exception as error:  # noqa: BLE001  (reported by the caller)
                self._runs[notebook] = (None, error)
            else:
                executed.cells.pop(0)
                for cell in executed.cells:
                    if cell.get("execution_count"):
                        cell.execution_count -= 1
                    for out in cell.get("outputs", []):
                        if out.get("execution_count"):
                            out["execution_count"] -= 1
                self._runs[notebook] = (executed, None)
        return self._runs[notebook]


@pytest.fixture(scope="session")
def tutorial_runs(tmp_path_factory) -> TutorialRuns:
    """The session's :class:`TutorialRuns` (skips without nbclient or ipykernel)."""
    for module in ("nbformat", "nbclient", "ipykernel"):
        pytest.importorskip(module)
    return TutorialRuns(tmp_path_factory.mktemp("kernels"))
