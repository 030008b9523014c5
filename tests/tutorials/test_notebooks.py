"""Run every tutorial notebook top to bottom, in test mode, with nbclient.

Each notebook executes in a kernel of *this* interpreter (a kernelspec written
for ``sys.executable``, so CI's virtual environment is the one used), in the
``tutorials/`` directory, with ``DRAKEGRASP_TUTORIAL_TEST=1`` (short loops),
``MPLBACKEND=Agg`` and deprecation warnings turned into errors by a cell that is
prepended to the executed copy only.  The committed notebooks must have their
outputs cleared.

pydrake installs its own ``"once"`` filter for ``DrakeDeprecationWarning`` when
``pydrake.common.deprecation`` is first imported, which would take precedence
over a filter set before it; so the prepended cell imports that module first, and
``_DRAKE_DEPRECATION_IS_ERROR=1`` (Drake's switch for testing notebooks) makes
Drake's own filter an error filter too.
"""

from __future__ import annotations

import copy
import sys
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

from ipykernel.kernelspec import write_kernel_spec  # noqa: E402
from jupyter_client.kernelspec import KernelSpecManager  # noqa: E402
from jupyter_client.manager import KernelManager  # noqa: E402

TUTORIALS = Path(__file__).resolve().parents[2] / "tutorials"
NOTEBOOKS = sorted(TUTORIALS.glob("[0-9][0-9]_*.ipynb"))
EXPECTED = [
    "01_grasp_matrix.ipynb",
    "02_form_closure.ipynb",
    "03_force_closure.ipynb",
    "04_hand_jacobian_lp3.ipynb",
    "05_antipodal_parallel_jaw.ipynb",
    "06_real_hand.ipynb",
    "07_grasp_in_simulation.ipynb",
    "08_why_not.ipynb",
    "09_find_grasps.ipynb",
    "10_grasp_under_load.ipynb",
]
# Drake's real hands and YCB objects: read from the sources, so a new tutorial that
# names drake_models skips without a local copy instead of trying to download.
NEEDS_DRAKE_MODELS = {
    p.name for p in NOTEBOOKS if "drake_models" in p.read_text(encoding="utf-8")
}

WARNINGS_AS_ERRORS = """\
import warnings

import pydrake.common.deprecation  # noqa: F401  (installs Drake's filter first)

warnings.simplefilter("error", DeprecationWarning)
"""

CELL_TIMEOUT = 600  # seconds per cell: a hang fails, a slow machine does not


def test_all_tutorials_are_present():
    assert [p.name for p in NOTEBOOKS] == EXPECTED


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_committed_notebook_has_cleared_outputs(path):
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    dirty = [
        i
        for i, cell in enumerate(nb.cells)
        if cell.cell_type == "code"
        and (cell.get("outputs") or cell.get("execution_count") is not None)
    ]
    assert not dirty, f"{path.name}: cells {dirty} have outputs or execution counts"


@pytest.fixture(scope="module")
def kernel_spec_manager(tmp_path_factory):
    """A kernelspec "python3" that launches ``sys.executable -m ipykernel_launcher``."""
    kernels = tmp_path_factory.mktemp("kernels")
    write_kernel_spec(path=str(kernels / "python3"))
    return KernelSpecManager(kernel_dirs=[str(kernels)], ensure_native_kernel=False)


@pytest.fixture
def test_env(monkeypatch):
    monkeypatch.setenv("DRAKEGRASP_TUTORIAL_TEST", "1")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.setenv("_DRAKE_DEPRECATION_IS_ERROR", "1")


def _execute(nb, kernel_spec_manager):
    """Execute a copy of ``nb`` (warnings cell prepended) in ``tutorials/``."""
    executed = copy.deepcopy(nb)
    executed.cells.insert(0, nbformat.v4.new_code_cell(WARNINGS_AS_ERRORS))
    km = KernelManager(kernel_name="python3", kernel_spec_manager=kernel_spec_manager)
    assert km.kernel_spec.argv[0] == sys.executable
    client = nbclient.NotebookClient(
        executed,
        km=km,
        timeout=CELL_TIMEOUT,
        resources={"metadata": {"path": str(TUTORIALS)}},
    )
    client.execute()
    return executed


def test_deprecation_warnings_fail_a_notebook(kernel_spec_manager, test_env):
    # The harness itself: a Drake deprecation (raised after pydrake's own
    # filters are installed) and a plain DeprecationWarning must both fail.
    for source in (
        "from pydrake.common.deprecation import DrakeDeprecationWarning\n"
        "warnings.warn('old', DrakeDeprecationWarning)",
        "import pydrake.all\nwarnings.warn('old', DeprecationWarning)",
    ):
        nb = nbformat.v4.new_notebook()
        nb.cells = [nbformat.v4.new_code_cell(source)]
        with pytest.raises(nbclient.exceptions.CellExecutionError, match="old"):
            _execute(nb, kernel_spec_manager)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs(path, kernel_spec_manager, test_env, request, monkeypatch):
    if path.name in NEEDS_DRAKE_MODELS:
        # The kernel inherits the variable: dg.use_local_drake_models(parser)
        # then reads the local copy instead of downloading (skips if absent).
        models = request.getfixturevalue("drake_models_dir")
        monkeypatch.setenv("DRAKEGRASP_DRAKE_MODELS", str(models))
    nb = nbformat.read(path, as_version=4)
    try:
        executed = _execute(nb, kernel_spec_manager)
    except nbclient.exceptions.CellExecutionError as e:
        pytest.fail(f"{path.name} failed:\n{e}", pytrace=False)
    errors = [
        out
        for cell in executed.cells
        if cell.cell_type == "code"
        for out in cell.get("outputs", [])
        if out.get("output_type") == "error"
    ]
    assert not errors
