"""Every tutorial is a jupytext pair: a percent-format ``.py`` and its ``.ipynb``.

The ``.py`` file is the source a person edits (and reviews in a diff); the
``.ipynb`` is what Jupyter opens and what ``test_notebooks.py`` executes.  This
module finds every ``NN_*.py`` / ``NN_*.ipynb`` in ``tutorials/`` (not a fixed
list, so a new tutorial is checked the day it lands) and fails when one side is
missing or when their cells differ.  Fix a failure with
``jupytext --sync tutorials/NN_name.py``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

jupytext = pytest.importorskip("jupytext")
nbformat = pytest.importorskip("nbformat")

TUTORIALS = Path(__file__).resolve().parents[2] / "tutorials"
SOURCES = sorted(TUTORIALS.glob("[0-9][0-9]_*.py"))
NOTEBOOKS = sorted(TUTORIALS.glob("[0-9][0-9]_*.ipynb"))


def _cells(path: Path) -> list[tuple[str, str]]:
    """``(cell_type, source)`` of every cell, as jupytext reads ``path``."""
    nb = jupytext.read(path)
    return [(cell.cell_type, cell.source.strip("\n")) for cell in nb.cells]


def test_there_are_tutorials():
    assert SOURCES and NOTEBOOKS


def test_every_notebook_has_a_source_and_every_source_a_notebook():
    assert {p.stem for p in SOURCES} == {p.stem for p in NOTEBOOKS}


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_declares_its_pairing(notebook):
    nb = nbformat.read(notebook, as_version=4)
    formats = nb.metadata.get("jupytext", {}).get("formats", "")
    assert set(formats.split(",")) == {"ipynb", "py:percent"}, formats


@pytest.mark.parametrize("source", SOURCES, ids=lambda p: p.stem)
def test_source_is_percent_format(source):
    text = source.read_text()
    assert "format_name: percent" in text.split("# ---", 2)[1]
    assert "\n# %%" in text


@pytest.mark.parametrize("source", SOURCES, ids=lambda p: p.stem)
def test_pair_has_the_same_cells(source):
    notebook = source.with_suffix(".ipynb")
    if not notebook.exists():
        pytest.fail(f"{notebook.name} is missing", pytrace=False)
    from_py, from_ipynb = _cells(source), _cells(notebook)
    diffs = [
        i for i, (a, b) in enumerate(zip(from_py, from_ipynb, strict=False)) if a != b
    ]
    assert len(from_py) == len(from_ipynb) and not diffs, (
        f"{source.name} and {notebook.name} differ (cells {diffs}, "
        f"{len(from_py)} vs {len(from_ipynb)} cells): "
        f"run `jupytext --sync tutorials/{source.name}`"
    )


def test_a_changed_source_is_caught(tmp_path):
    # The check itself: editing one side alone must fail it.
    source = SOURCES[0]
    edited = tmp_path / source.name
    edited.write_text(source.read_text().replace("# %%", "# %%\nx = 1", 1))
    assert _cells(edited) != _cells(source.with_suffix(".ipynb"))
