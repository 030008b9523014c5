"""Ghost hands of planned candidates in Meshcat (local, headless) and the score
histogram: what is drawn where, in which colour, and what is refused."""

from __future__ import annotations

import json

import numpy as np
import pytest

from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.visualization.candidates import (
    CANDIDATES_PREFIX,
    draw_candidates,
    plot_score_distribution,
    score_colors,
)


@pytest.fixture(scope="module")
def planned(drake_models_dir):
    # the default hand is Drake's WSG-50: skip, not download, without drake_models
    scene = planning_scene(
        "package://drakegrasp/objects/box.sdf", models_dir=drake_models_dir
    )
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=60, mu=0.5, seed=4, robustness_samples=4,
    )  # fmt: skip
    return scene, result


def test_score_colors_run_red_to_green():
    c = score_colors([0.0, 0.5, 1.0], alpha=0.3)
    np.testing.assert_allclose(c[0, :3], [0.85, 0.2, 0.15])
    np.testing.assert_allclose(c[1, :3], [0.95, 0.8, 0.2])
    np.testing.assert_allclose(c[2, :3], [0.2, 0.7, 0.3])
    assert (c[:, 3] == 0.3).all()
    # affine in the scores: the colours of 2 s + 7 are those of s
    s = np.array([0.1, 0.4, 0.35, 0.9])
    np.testing.assert_allclose(score_colors(2 * s + 7), score_colors(s))
    np.testing.assert_allclose(score_colors([3.0, 3.0])[:, :3], [[0.2, 0.7, 0.3]] * 2)
    with pytest.raises(InvalidOptionError, match="finite"):
        score_colors([np.nan])
    with pytest.raises(InvalidOptionError, match="alpha"):
        score_colors([1.0], alpha=2.0)


def test_ghost_hands_sit_at_the_planned_poses(meshcat, planned):
    scene, result = planned
    before = scene.plant.GetPositions(scene.plant.GetMyContextFromRoot(scene.context))
    drawing = draw_candidates(meshcat, scene.plant, scene.context, result, top=4)
    assert len(drawing.paths) == 4
    assert drawing.paths[0] == f"{CANDIDATES_PREFIX}/0"
    np.testing.assert_array_equal(drawing.scores, [c.score for c in result[:4]])
    # the best is the greenest: colours follow the scores
    assert drawing.colors[0, 1] >= drawing.colors[-1, 1]
    msgpack = pytest.importorskip("msgpack")
    for k, c in enumerate(result[:4]):
        base = c.hand_base.rpartition("::")[2]
        path = f"{CANDIDATES_PREFIX}/{k}/{base}"
        assert meshcat.HasPath(path)
        # the base's ghost is at the candidate's X_WH (Meshcat stores 4x4
        # column-major; a test-only read of what the browser would receive)
        packed = msgpack.unpackb(meshcat._GetPackedTransform(path))
        X = np.array(packed["matrix"], float).reshape(4, 4).T
        np.testing.assert_allclose(X, c.X_WH.GetAsMatrix4(), atol=1e-12)
    # the user's context is left as it was
    after = scene.plant.GetPositions(scene.plant.GetMyContextFromRoot(scene.context))
    np.testing.assert_array_equal(before, after)
    json.dumps(drawing.to_dict())
    assert "4 ghost hands" in str(drawing)
    # drawing again replaces: fewer candidates leave no stale ghosts
    draw_candidates(meshcat, scene.plant, scene.context, result, top=2)
    assert meshcat.HasPath(f"{CANDIDATES_PREFIX}/1")
    assert not meshcat.HasPath(f"{CANDIDATES_PREFIX}/2")


def test_bad_arguments(meshcat, planned):
    scene, result = planned
    with pytest.raises(InvalidOptionError, match="Meshcat"):
        draw_candidates(None, scene.plant, scene.context, result)
    with pytest.raises(InvalidOptionError, match="top"):
        draw_candidates(meshcat, scene.plant, scene.context, result, top=-1)
    assert draw_candidates(meshcat, scene.plant, scene.context, (), top=3).paths == ()


def test_score_histogram(plt, planned):
    _, result = planned
    ax = plot_score_distribution(result, bins=12, top=5)
    heights = [p.get_height() for p in ax.patches]
    assert sum(heights) == len(result)  # every candidate counted once
    cut = [line for line in ax.get_lines() if line.get_linestyle() == "--"]
    assert cut and cut[0].get_xdata()[0] == sorted(c.score for c in result)[-5]
    with pytest.raises(InvalidOptionError, match="bins"):
        plot_score_distribution(result, bins=0)
