"""Sphinx configuration of the drakegrasp documentation site.

Build it from the repository root with the ``docs`` extra installed::

    pip install -e ".[docs]"
    python -m sphinx -W --keep-going -n docs docs/_build/html

The tutorials are the notebooks of ``tutorials/``: they are copied into
``docs/tutorials/`` (git-ignored) when the build starts and executed once by
myst-nb.  References to pydrake objects resolve to Drake's online API pages
through the local extension ``_ext/offline_links.py`` (the build machine has no
network, so intersphinx cannot fetch Drake's inventory).
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(DOCS / "_ext"))

import drakegrasp  # noqa: E402

project = "drakegrasp"
author = "the drakegrasp developers"
copyright = "the drakegrasp developers"  # noqa: A001  (Sphinx's setting name)
version = release = drakegrasp.__version__

extensions = [
    "sphinx.ext.autodoc",
    "numpydoc",
    "sphinx.ext.mathjax",
    # MathJax copied into _static: the pages render their formulas offline.
    "sphinx-mathjax-offline",
    "sphinx.ext.doctest",
    "sphinxarg.ext",
    "myst_nb",
    "drakegrasp_refs",
    "offline_links",
]

exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints"]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}

# Every cross-reference must resolve (the tests build with -n -W).
nitpicky = True

# -- API reference ----------------------------------------------------------
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"  # the numpy docstrings state types, shapes and units
autodoc_class_signature = "separated"
# numpydoc renders the Parameters/Returns sections.  Their type column is prose
# ("(N, 3) float, metres, in frame O"), so only the words listed in the aliases
# below become links: drakegrasp's public classes and the pydrake classes we take.
numpydoc_show_class_members = False
numpydoc_xref_param_type = True
numpydoc_xref_ignore = "all"


def _xref_aliases() -> dict[str, str]:
    import inspect

    from offline_links import SHORT_NAMES

    aliases = dict(SHORT_NAMES)
    for name in drakegrasp.__all__:
        obj = getattr(drakegrasp, name)
        if inspect.isclass(obj):
            aliases[name] = f"{obj.__module__}.{obj.__qualname__}"
    return aliases


numpydoc_xref_aliases = _xref_aliases()

# -- MyST and the notebooks -------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
nb_execution_mode = os.environ.get("DRAKEGRASP_DOCS_EXECUTE", "force")
# The notebooks run with the short loops the tests use (the same code path CI
# checks, and a few seconds per notebook); the kernels inherit this process's
# environment.  MPLBACKEND=Agg (set by some test runs) would replace the
# notebook's inline backend and leave the pages without figures.
os.environ["DRAKEGRASP_TUTORIAL_TEST"] = "1"
os.environ.pop("MPLBACKEND", None)
nb_execution_timeout = 600
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True

# -- HTML -------------------------------------------------------------------
html_theme = "furo"
html_title = f"drakegrasp {release}"
html_static_path: list[str] = []


def _needs_drake_models(notebook: Path) -> bool:
    """True for a tutorial that loads Drake's real hands (``package://drake_models``)."""
    return "package://drake_models" in notebook.read_text()


def _copy_tutorials() -> list[str]:
    """Copy ``tutorials/NN_*.ipynb`` next to the pages that list them.

    Where ``$DRAKEGRASP_DOCS_EXECUTED`` names a folder holding an executed copy
    of a tutorial (the test suite runs each tutorial once and passes its runs
    here), that copy is used and not executed again.  Returns the names used so.
    """
    target = DOCS / "tutorials"
    target.mkdir(exist_ok=True)
    for old in target.glob("*.ipynb"):
        old.unlink()
    executed = os.environ.get("DRAKEGRASP_DOCS_EXECUTED")
    done = []
    for notebook in sorted((ROOT / "tutorials").glob("[0-9][0-9]_*.ipynb")):
        run = Path(executed) / notebook.name if executed else None
        if run is not None and run.is_file():
            shutil.copy2(run, target / notebook.name)
            done.append(notebook.name)
        else:
            shutil.copy2(notebook, target / notebook.name)
    return done


_EXECUTED = _copy_tutorials()

# Tutorials on Drake's real hands need the drake_models package: a local copy
# named by DRAKEGRASP_DRAKE_MODELS (the tests set it when one exists), or a
# download, which an offline build cannot make.  Without the variable they are
# rendered unexecuted rather than failing the build.
nb_execution_excludepatterns = (
    []
    if os.environ.get("DRAKEGRASP_DRAKE_MODELS")
    else [
        f"tutorials/{p.name}"
        for p in sorted((DOCS / "tutorials").glob("*.ipynb"))
        if _needs_drake_models(p)
    ]
) + [f"tutorials/{name}" for name in _EXECUTED]
