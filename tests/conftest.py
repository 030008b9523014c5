"""Fixtures shared by every test folder: where Drake's real models are."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from drakegrasp.plant.models import DRAKE_MODELS_ENV

ROOT = Path(__file__).resolve().parents[1]


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
def local_drake_models_or_none() -> Path | None:
    """Folder of ``drake_models``, or None when absent (no skip)."""
    return local_drake_models()
