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


@pytest.fixture(scope="module")
def meshcat():
    """A local Meshcat server (no browser needed), one per test module."""
    params = MeshcatParams()
    params.show_stats_plot = False
    return Meshcat(params)
