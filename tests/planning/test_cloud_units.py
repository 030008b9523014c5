"""A point cloud in millimetres gets a hint, and points left out are counted.

Planning on a YCB-sized cloud given in millimetres returned an empty result
("wider than the stroke") with no word of units; NaN points (a depth
camera's missing depth) were left out without a word.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.planning.cloud import (
    CLOUD_SMALL_EXTENT,
    CLOUD_UNITS_EXTENT,
    PointCloudWarning,
    read_cloud,
)

OWN_HAND = "package://drakegrasp/hands/parallel_jaw_flat.sdf"


def _ball(n=1500, radius=0.04, seed=0):
    u = np.random.default_rng(seed).standard_normal((n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return radius * u, u


def _quietly(*args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error", PointCloudWarning)
        return read_cloud(*args, **kw)


def test_a_cloud_in_metres_without_nan_reads_without_a_warning():
    p, n = _ball()
    points, normals, dropped = _quietly(p, n)
    assert dropped == 0 and len(points) == len(p)


def test_nan_points_left_out_are_counted_in_a_warning():
    p, n = _ball()
    p[::10] = np.nan
    with pytest.warns(PointCloudWarning, match="left out 150 of 1500 points") as w:
        points, normals, dropped = read_cloud(p, n)
    assert "planning on the other 1350" in str(w[0].message)
    assert dropped == 150 and len(points) == 1350
    # the same points and normals as the finite ones read alone
    alone = _quietly(p[np.isfinite(p[:, 0])], n[np.isfinite(p[:, 0])])
    np.testing.assert_array_equal(points, alone[0])
    np.testing.assert_array_equal(normals, alone[1])


def test_a_cloud_in_millimetres_gets_a_units_hint():
    p, n = _ball(radius=40.0)  # an 80 mm ball, in millimetres
    with pytest.warns(PointCloudWarning, match="millimetres, divide it by 1000"):
        points, normals, _ = read_cloud(p, n)
    np.testing.assert_array_equal(points, p)  # read as given, only warned of
    # at the threshold's scale: 5 m across is still metres
    box = _cube(CLOUD_UNITS_EXTENT)
    _quietly(box * 0.999, box)


def _cube(edge: float) -> np.ndarray:
    """The 8 corners of a cube ``edge`` metres on a side, centred at 0."""
    h = edge / 2
    return np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)])


@pytest.mark.parametrize(
    "radius, hint, starts",
    [
        (40.0, "millimetres, divide it by 1000", "point_cloud is 79.9"),
        # a 10 um ball: every pose was "no opposite surface", unsaid why
        (5e-6, "multiply it by 1000", "point_cloud is 0.00999"),
    ],
)
def test_planning_on_a_cloud_of_the_wrong_units_says_why_it_is_empty(
    radius, hint, starts
):
    scene = planning_scene(None, hand_url=OWN_HAND)
    p, n = _ball(radius=radius)
    with pytest.warns(PointCloudWarning, match=hint) as w:
        result = plan_grasps(
            scene.plant, scene.context, None, hand=scene.hand, num_candidates=10,
            mu=0.5, seed=0, robustness_samples=2, point_cloud=p, cloud_normals=n,
        )  # fmt: skip
    assert len(result) == 0
    (units,) = [str(x.message) for x in w if hint in str(x.message)]
    assert units.startswith(starts)  # the ball's sampled extent
    assert w[0].filename == __file__  # points at the caller's line


def test_a_cloud_of_a_millimetre_is_an_object_a_hand_may_grasp():
    box = _cube(CLOUD_SMALL_EXTENT)
    _quietly(box * 1.001, box)


def _drake_cloud(points, normals=None):
    from pydrake.perception import BaseField, Fields, PointCloud

    cloud = PointCloud(len(points), Fields(BaseField.kXYZs | BaseField.kNormals))
    cloud.mutable_xyzs()[:] = points.T
    if normals is not None:
        cloud.mutable_normals()[:] = normals.T
    return cloud


def test_a_drake_cloud_whose_normals_were_never_filled_plans_on_estimated_ones():
    # Drake fills a new normals field with NaN: every point was dropped and
    # the message blamed "a cloud_normals row", an argument never given
    p, n = _ball()
    cloud = _drake_cloud(p)
    with pytest.warns(PointCloudWarning, match="no finite normal"):
        points, normals, dropped = read_cloud(cloud)
    assert dropped == 0 and len(points) == len(p)
    stored = _quietly(p.astype(np.float32).astype(float))  # Drake keeps float32
    np.testing.assert_array_equal(points, stored[0])
    np.testing.assert_array_equal(normals, stored[1])  # estimated alike
    # some normals filled, the others NaN: the field is named, not the argument
    some = n.copy()
    some[2:] = np.nan
    with pytest.raises(InvalidOptionError, match="a point_cloud's normals field row"):
        read_cloud(_drake_cloud(p, some))


def test_a_stray_point_far_away_is_refused_naming_it():
    # a 2 mm cube's cloud and one point 30 m off: the torque scale became
    # 30 m and the ranking was refused for "characteristic_lengths", an
    # argument plan_grasps does not have
    scene = planning_scene(None, hand_url=OWN_HAND)
    p, n = _ball(radius=1e-3)
    cloud = np.r_[p, [[30.0, 0.0, 0.0]]]
    normals = np.r_[n, [[1.0, 0.0, 0.0]]]
    with pytest.raises(InvalidOptionError, match=r"the farthest, \[30.0, 0.0, 0.0\]"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PointCloudWarning)  # 30 m across
            plan_grasps(
                scene.plant, scene.context, None, hand=scene.hand,
                num_candidates=10, mu=0.5, seed=0, point_cloud=cloud,
                cloud_normals=normals,
            )  # fmt: skip
    # a long rod (1 m by 2 mm) and a one-sided view are far from the bound
    rod = np.c_[np.linspace(-0.5, 0.5, 2000), 1e-3 * _ball(2000)[0][:, :2]]
    _quietly(rod)
    half = p[p[:, 2] > 0]
    _quietly(half, n[p[:, 2] > 0])
