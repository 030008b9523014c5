"""Run every tutorial notebook top to bottom, in test mode, with nbclient.

The runs are the session's :class:`TutorialRuns` (``tests/conftest.py``), which
the documentation build renders too, so each tutorial executes once per test
session.  Each notebook executes in a kernel of *this* interpreter (a kernelspec
written for ``sys.executable``, so CI's virtual environment is the one used), in
the ``tutorials/`` directory, with ``DRAKEGRASP_TUTORIAL_TEST=1`` (short loops)
and deprecation warnings turned into errors by a cell that is prepended to the
executed copy only.  The committed notebooks must have their outputs cleared.

pydrake installs its own ``"once"`` filter for ``DrakeDeprecationWarning`` when
``pydrake.common.deprecation`` is first imported, which would take precedence
over a filter set before it; so the prepended cell imports that module first, and
``_DRAKE_DEPRECATION_IS_ERROR=1`` (Drake's switch for testing notebooks) makes
Drake's own filter an error filter too.
"""

from __future__ import annotations

from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

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


def test_deprecation_warnings_fail_a_notebook(tutorial_runs):
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
            tutorial_runs.execute(nb)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs(path, tutorial_runs, request):
    if path.name in NEEDS_DRAKE_MODELS:
        # The kernel inherits $DRAKEGRASP_DRAKE_MODELS (tests/conftest.py sets it
        # to the local copy): dg.use_local_drake_models(parser) reads it instead
        # of downloading.  Without a copy the tutorial skips.
        request.getfixturevalue("drake_models_dir")
    executed, error = tutorial_runs.run(path)
    if error is not None:
        pytest.fail(f"{path.name} failed:\n{error}", pytrace=False)
    errors = [
        out
        for cell in executed.cells
        if cell.cell_type == "code"
        for out in cell.get("outputs", [])
        if out.get("output_type") == "error"
    ]
    assert not errors
    # Every code cell ran, numbered from 1 (the warnings cell is not among them).
    code = [c for c in executed.cells if c.cell_type == "code" and c.source.strip()]
    assert [c.execution_count for c in code] == list(range(1, len(code) + 1))
