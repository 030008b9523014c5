"""Every jupytext source ``tutorials/NN_*.py`` matches its paired notebook.

The percent-format script is what a person edits; the ``.ipynb`` is generated
from it (``jupytext --sync tutorials/NN_name.py``) with outputs cleared.  The
two must hold the same cells, in the same order, with the same sources.
"""

from __future__ import annotations

from pathlib import Path

import pytest

jupytext = pytest.importorskip("jupytext")
nbformat = pytest.importorskip("nbformat")

TUTORIALS = Path(__file__).resolve().parents[2] / "tutorials"
SOURCES = sorted(
    p for p in TUTORIALS.glob("[0-9][0-9]_*.py") if p.with_suffix(".ipynb").exists()
)


def cells(nb):
    return [(c.cell_type, c.source.strip()) for c in nb.cells]


@pytest.mark.parametrize("source", SOURCES, ids=lambda p: p.stem)
def test_script_and_notebook_hold_the_same_cells(source):
    from_script = jupytext.read(source)
    notebook = nbformat.read(source.with_suffix(".ipynb"), as_version=4)
    assert cells(from_script) == cells(notebook), (
        f"{source.name} and its .ipynb differ: run jupytext --sync {source.name}"
    )


def test_the_real_hand_tutorial_is_paired():
    assert (TUTORIALS / "06_real_hand.py") in SOURCES
