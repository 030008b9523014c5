"""Headless matplotlib for the picture tests; figures closed after each test."""

import os

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture
def plt():
    """matplotlib.pyplot on the Agg backend (skips when matplotlib is missing)."""
    matplotlib = pytest.importorskip("matplotlib", reason="matplotlib not installed")
    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot

    yield pyplot
    pyplot.close("all")
