"""Numbers outside what double precision can resolve, on the plant side (issue 21).

* Bodies so far from the world origin that position round-off exceeds the
  distance tolerance are refused (Drake's distances overflowed at 1e300 m and
  reported a 6 mm penetration); up to the documented bound the pose check
  answers as it does near the origin (the independent route: the same scene
  translated back to the origin).
* ``patch_polygon`` with a NaN normal (a zero-area hydroelastic surface) or
  non-finite points raises an ``InvalidContactError``, which the monitor's
  handler catches as a ``GraspError``.
* ``close_hand(min_fingers=...)`` above the hand's number of fingers says so
  before searching, an ``UnreachableError`` without a closure (the message
  ended in "could not reach it: ").
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.errors import InvalidContactError, InvalidPoseError
from drakegrasp.plant.contact_results import patch_polygon
from drakegrasp.plant.pose import RESOLUTION_MARGIN


def _moved(offset: float):
    scene = dg.load_scene()
    plant, ctx = scene.plant, scene.plant_context
    X = plant.EvalBodyPoseInWorld(ctx, scene.object_body)
    if offset:
        plant.SetFreeBodyPose(
            ctx,
            scene.object_body,
            type(X)(X.rotation(), X.translation() + [offset, 0.0, 0.0]),
        )
    return scene


@pytest.mark.parametrize("offset", [1e300, -1e200, 1e20, 1e10])
def test_bodies_beyond_the_resolvable_range_are_refused(offset):
    scene = _moved(offset)
    with pytest.raises(InvalidPoseError, match="double precision resolves"):
        dg.analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())


def test_the_bound_follows_the_distance_tolerance():
    tol = 1e-4
    bound = tol / (np.finfo(float).eps * RESOLUTION_MARGIN)
    assert 1e8 < bound < 1e9  # 4.5e8 m at the default tolerance


@pytest.mark.parametrize("offset", [10.0, 1e3, 1e6])
def test_far_but_resolvable_objects_answer_as_at_the_origin(offset):
    # Object moved away from the gripper: the verdict is "no contacts" there;
    # the pose check never reports a penetration that is not there.
    scene = _moved(offset)
    with pytest.raises(dg.NoContactsError):
        dg.analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    near = _moved(0.0)  # in contact at the origin: the pose check passes there
    report = dg.analyze_grasp(near.plant, near.plant_context, **near.analysis_options())
    assert report.data.grasp.num_contacts == 2


SQUARE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)


@pytest.mark.parametrize(
    "normal",
    [
        [math.nan, math.nan, math.nan],
        [0.0, 0.0, math.nan],
        [0.0, 0.0, 0.0],
        [math.inf, 0.0, 0.0],
        [1j, 0, 0],
        [0.0, 1.0],
    ],
)
def test_patch_polygon_refuses_an_undefined_normal(normal):
    with pytest.raises(InvalidContactError, match="normal"):
        patch_polygon(SQUARE, normal)


@pytest.mark.parametrize(
    "points", [np.full((3, 3), np.nan), np.zeros((0, 3)), np.ones((2, 2)), "abc"]
)
def test_patch_polygon_refuses_bad_points(points):
    with pytest.raises(InvalidContactError):
        patch_polygon(points, [0.0, 0.0, 1.0])


@pytest.mark.parametrize("scale", [1e-12, 1.0, 1e12])
def test_patch_polygon_normalises_a_valid_normal(scale):
    got = patch_polygon(SQUARE, [0.0, 0.0, scale])
    assert got.shape == (4, 3)
    np.testing.assert_allclose(sorted(map(tuple, got)), sorted(map(tuple, SQUARE)))


def test_min_fingers_above_the_number_of_fingers_says_so():
    scene = dg.load_scene()
    with pytest.raises(dg.UnreachableError, match="exceeds the hand's 2 fingers") as e:
        dg.close_hand(
            scene.plant,
            scene.plant_context,
            scene.object_body,
            hand=scene.hand,
            min_fingers=3,
        )
    assert e.value.closure is None  # refused before any search


def test_the_widest_distance_tolerance_or_a_huge_load_warns_of_nothing():
    # Each printed numpy's overflow warning (and its source line) on a run
    # that succeeds: the patch clipper's sign test fp * fq < 0 overflowed at a
    # 1e300 m tolerance (now refused: at most MAX_DISTANCE_TOLERANCE), the
    # payload's proof of "unbounded" at a 1e300 N load.
    import warnings

    from drakegrasp.core.tolerances import MAX_DISTANCE_TOLERANCE

    scene = dg.load_scene()
    args = (scene.plant, scene.plant_context, scene.object_body)
    with pytest.raises(dg.InvalidOptionError, match="above the largest accepted"):
        dg.analyze_grasp(*args, hand=scene.hand, mu=0.5, distance_tolerance=1e300)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        wide = dg.analyze_grasp(
            *args, hand=scene.hand, mu=0.5, distance_tolerance=MAX_DISTANCE_TOLERANCE
        )
        heavy = dg.analyze_grasp(
            *args, hand=scene.hand, mu=0.5, load=[0, 0, -1e300, 0, 0, 0]
        )
    assert wide.grasp.num_contacts >= 2
    assert heavy.load.holds and heavy.load.payload.alpha == math.inf
