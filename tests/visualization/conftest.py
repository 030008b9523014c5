"""Headless matplotlib and Meshcat for the picture tests (figures closed after each)."""

import os
import sys
from pathlib import Path

import pytest
from pydrake.geometry import Meshcat, MeshcatParams

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:  # the browser tests share browser_support.py
    sys.path.insert(0, _HERE)

os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture
def plt():
    """matplotlib.pyplot on the Agg backend (skips when matplotlib is missing)."""
    matplotlib = pytest.importorskip("matplotlib", reason="matplotlib not installed")
    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot

    yield pyplot
    pyplot.close("all")


_ALIVE: list[Meshcat] = []
"""Every Meshcat the tests made, kept until the interpreter exits.

Drake aborts the process when a Meshcat is destroyed on a thread other than
the one that made it (``~Impl(): condition 'IsThread(main_thread_id_)'``).
A module's Meshcat outlives its module in reference cycles (a test's frame,
``pytest.raises``' exception, its traceback), and a garbage collection that
a Dask worker thread of the session's cluster happened to run destroyed it
there: the suite ended in "Fatal Python error: Aborted".  Kept reachable, it
is destroyed by the main thread at exit."""


@pytest.fixture(scope="module")
def meshcat():
    """A local Meshcat server (no browser needed), one per test module."""
    params = MeshcatParams()
    params.show_stats_plot = False
    _ALIVE.append(Meshcat(params))
    return _ALIVE[-1]
