"""Fixtures of the planning tests: planning scenes, built once per session.

Also makes the shared helpers of tests/planning importable (``cloud_support``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from drakegrasp.planning import planning_scene

OWN_HAND = "package://drakegrasp/hands/parallel_jaw_flat.sdf"

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)


@pytest.fixture(scope="session")
def wsg_scene(drake_models_dir):
    """Drake's WSG-50 (free) and the YCB sugar box (skips without drake_models)."""

    def make(name="004_sugar_box", X_WO=None):
        return planning_scene(
            f"package://drake_models/ycb/{name}.sdf",
            X_WO=X_WO,
            models_dir=drake_models_dir,
        )

    return make


@pytest.fixture(scope="session")
def own_scene():
    """drakegrasp's flat-pad parallel jaw (free) and one of its objects."""

    def make(name="box", X_WO=None, hand=OWN_HAND):
        return planning_scene(
            f"package://drakegrasp/objects/{name}.sdf", hand_url=hand, X_WO=X_WO
        )

    return make


@pytest.fixture
def fingerless_scene(tmp_path):
    """The shipped box and a "hand" that is a bare palm: no one-dof finger joint."""
    paddle = tmp_path / "nofinger.sdf"
    paddle.write_text(
        '<?xml version="1.0"?><sdf version="1.9"><model name="paddle">'
        '<link name="palm">'
        "<collision name='c'><geometry><box><size>0.05 0.05 0.05</size></box>"
        "</geometry></collision></link></model></sdf>"
    )
    return planning_scene("package://drakegrasp/objects/box.sdf", hand_url=str(paddle))


@pytest.fixture
def hand_file_scene(tmp_path):
    """A planning scene of an object and a hand written to a file from its text.

    ``make(object_url, text, name="hand.sdf")``: the hand's model file (SDF or
    URDF, by ``name``'s suffix) holds ``text``.
    """

    def make(object_url, text: str, name: str = "hand.sdf"):
        path = tmp_path / name
        path.write_text(text)
        return planning_scene(object_url, hand_url=str(path))

    return make
