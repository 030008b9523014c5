"""Estimated cloud normals: sharp at a box's edges, outward, refused when absent."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.perception import BaseField, Fields, PointCloud

from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning.cloud import read_cloud
from drakegrasp.planning.cloud_normals import estimate_normals

HALF = np.array([0.04, 0.03, 0.08])  # a 80 x 60 x 160 mm box


def _box_surface(n: int, seed: int = 0):
    """Area-uniform points on the box's faces and each one's face normal."""
    rng = np.random.default_rng(seed)
    faces = []
    for axis in range(3):
        other = [a for a in range(3) if a != axis]
        area = 4 * HALF[other[0]] * HALF[other[1]]
        for sign in (-1.0, 1.0):
            faces.append((axis, sign, other, area))
    areas = np.array([f[3] for f in faces])
    pick = rng.choice(len(faces), size=n, p=areas / areas.sum())
    points, normals = np.zeros((n, 3)), np.zeros((n, 3))
    for i, f in enumerate(pick):
        axis, sign, other, _ = faces[f]
        points[i, axis] = sign * HALF[axis]
        points[i, other] = rng.uniform(-HALF[other], HALF[other])
        normals[i, axis] = sign
    return points, normals


def _angles(a, b):
    return np.degrees(np.arccos(np.clip(np.abs(np.sum(a * b, axis=1)), 0.0, 1.0)))


def _face_errors(points, normals):
    """Angle (deg) to the nearest normal of a face whose plane passes within
    a third of the spacing of the point (either face, that close to an edge)."""
    from scipy.spatial import cKDTree

    spacing = np.median(cKDTree(points).query(points, k=2)[0][:, 1])
    err = np.full(len(points), 180.0)
    for axis in range(3):
        for sign in (-1.0, 1.0):
            on = np.abs(points[:, axis] - sign * HALF[axis]) <= spacing / 3
            face = np.zeros(3)
            face[axis] = sign
            err[on] = np.minimum(err[on], _angles(normals[on], face[None]))
    return err


def _drake_normals(points):
    cloud = PointCloud(len(points), Fields(BaseField.kXYZs | BaseField.kNormals))
    cloud.mutable_xyzs()[:] = points.T
    cloud.EstimateNormals(0.01, 30, parallelize=False)
    return np.asarray(cloud.normals()).T


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_normals_stay_sharp_at_a_box_edges(seed):
    # A neighbourhood at an edge holds two faces: its own plane is tilted
    # between them (Drake's EstimateNormals, 1 cm and 30 points: 28 % of the
    # points more than 10 deg off, up to 74 deg).  The flattest plane that
    # passes through a point is a face's: 1.7-2.5 % more than 10 deg off, the
    # points within about 1.5 mm of an edge that took the other face's.
    points, _ = _box_surface(4000, seed=seed)
    err = _face_errors(points, estimate_normals(points))
    drake = _face_errors(points, _drake_normals(points))
    assert np.percentile(err, 90) < 0.1
    assert np.mean(err > 10.0) < 0.05 < 0.25 < np.mean(drake > 10.0)


def test_read_cloud_turns_estimated_normals_outward():
    points, true = _box_surface(3000, seed=1)
    got, normals, dropped = read_cloud(points)
    assert dropped == 0 and len(got) == len(points)
    assert np.all(np.sum(normals * got, axis=1) > 0)  # away from the centroid
    assert np.mean(np.sum(normals * true, axis=1) > 0.99) > 0.9
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-12)


@pytest.mark.parametrize("seed", [0, 1])
def test_normals_do_not_depend_on_rigid_motion_or_units(seed):
    points, _ = _box_surface(2000, seed=seed)
    rng = np.random.default_rng(seed)
    R, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    moved = 1e3 * points @ R.T + rng.normal(size=3)  # millimetres, turned
    base = estimate_normals(points)
    err = _angles(estimate_normals(moved), base @ R.T)
    assert err.max() < 1e-4  # degrees: arccos near 1 reads rounding as 1e-6


def test_points_on_a_line_have_no_normal():
    line = np.outer(np.linspace(0.0, 0.1, 50), [1.0, 2.0, 3.0])
    assert np.all(np.isnan(estimate_normals(line)))
    with pytest.raises(InvalidOptionError, match="finite, non-zero normal"):
        read_cloud(line)


RADIUS, HEIGHT = 0.033, 0.10  # a soup can's side


def _cylinder_side(n: int, seed: int = 0):
    """Area-uniform points on a cylinder's side (axis z) and their normals."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.0, 2 * np.pi, n)
    normals = np.stack([np.cos(a), np.sin(a), np.zeros(n)], axis=1)
    points = RADIUS * normals
    points[:, 2] = rng.uniform(-HEIGHT / 2, HEIGHT / 2, n)
    return points, normals


def _flattest_plane_only(points):
    """The estimate without its quadric step: each point's chosen patch plane."""
    from drakegrasp.planning import cloud_normals

    saved = cloud_normals.NORMAL_CURVED_F
    cloud_normals.NORMAL_CURVED_F = np.inf
    try:
        return estimate_normals(points)
    finally:
        cloud_normals.NORMAL_CURVED_F = saved


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_curved_face_seen_from_one_side_keeps_its_normals(seed):
    # A camera sees half the can; at the silhouette every patch is one-sided,
    # and the flattest patch chosen is off-centre anywhere on a curved face.
    # A plane gives the normal of the patch's centre: 4-5 deg off on average,
    # about 14 at the silhouette; the quadric's normal at the point is exact
    # to its second-order term.
    points, true = _cylinder_side(2200, seed=seed)
    seen = points[:, 0] > 0  # a camera far along +x
    points, true = points[seen], true[seen]
    err = _angles(estimate_normals(points), true)
    plane = _angles(_flattest_plane_only(points), true)
    assert err.mean() < 0.1 and err.max() < 1.0, (err.mean(), err.max())
    assert plane.mean() > 2.0  # what the quadric step corrects


def test_scan_lines_that_leave_the_quadric_undetermined_keep_the_plane():
    # Two scan rings of a cylinder 2 mm apart: every patch lies on two
    # parallel lines of its plane, a conic, on which no quadric is unique
    # (its curvature across the lines is free).  Those patches keep their
    # planes rather than a curvature the points do not show.
    a = np.linspace(0.0, np.pi, 400)
    rings = [
        np.stack([RADIUS * np.cos(a), RADIUS * np.sin(a), np.full_like(a, z)], 1)
        for z in (0.0, 0.002)
    ]
    points = np.concatenate(rings)
    true = points * [1.0, 1.0, 0.0] / RADIUS
    normals = estimate_normals(points)
    np.testing.assert_array_equal(normals, _flattest_plane_only(points))
    assert _angles(normals, true).max() < 5.0


@pytest.mark.parametrize("seed", [0, 1])
def test_curved_normals_do_not_depend_on_rigid_motion_or_units(seed):
    points, _ = _cylinder_side(1500, seed=seed)
    rng = np.random.default_rng(seed)
    R, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    moved = 1e3 * points @ R.T + rng.normal(size=3)  # millimetres, turned
    base = estimate_normals(points)
    err = _angles(estimate_normals(moved), base @ R.T)
    assert err.max() < 1e-3


def test_repeated_points_count_once():
    # Fused frames of a still camera repeat points: ten copies of each filled
    # every neighbourhood with two places (a line) and left no normal at all.
    points, true = _cylinder_side(600, seed=3)
    repeated = np.repeat(points, 10, axis=0)
    normals = estimate_normals(repeated)
    np.testing.assert_array_equal(normals, np.repeat(estimate_normals(points), 10, 0))
    assert _angles(normals, np.repeat(true, 10, axis=0)).max() < 2.0


@pytest.mark.parametrize("size", [8, 9, 10])
def test_a_small_noisy_plane_is_not_taken_for_a_quadric_by_chance(size):
    # A cloud of fewer than twenty points fits each patch with fewer residual
    # degrees of freedom, and chance alone exceeds the 20-point F threshold
    # (5.6) far more often: eight points on a plane with 0.1 mm noise took
    # quadrics fitted to the noise, normals on average 1.8 times as far off
    # as the plane's (up to 12 deg).  The test's own F(3, k - 6) point keeps
    # them within a few percent of the plane.
    tilt, plane_tilt = [], []
    for seed in range(100):
        rng = np.random.default_rng(seed)
        xy = rng.uniform(0.0, 0.01 * np.sqrt(size), (size, 2))
        points = np.c_[xy, rng.normal(0.0, 1e-4, size)]
        up = np.tile([0.0, 0.0, 1.0], (size, 1))
        tilt.append(_angles(estimate_normals(points), up))
        plane_tilt.append(_angles(_flattest_plane_only(points), up))
    ratio = np.mean(tilt) / np.mean(plane_tilt)
    assert ratio < 1.15, ratio


@pytest.mark.parametrize("jitter", [1e-12, 1e-9])
def test_points_repeated_with_round_off_jitter_count_once(jitter):
    # Twenty-five copies of each point of a flat grid, 1e-12 m apart: every
    # neighbourhood held one point's copies, whose "plane" fitted the jitter
    # (normals 55-60 deg off on average, up to 90).  Points closer than
    # single precision resolves at the cloud's extent are one point.
    g = np.stack(np.meshgrid(np.arange(10), np.arange(10)), -1).reshape(-1, 2)
    points = np.repeat(np.c_[0.005 * g, np.zeros(100)], 25, axis=0)
    points += np.random.default_rng(0).normal(0.0, jitter, points.shape)
    up = np.tile([0.0, 0.0, 1.0], (len(points), 1))
    assert _angles(estimate_normals(points), up).max() < 1e-3


@pytest.mark.parametrize("jitter", [1e-7, 1e-6, 1e-5])
def test_copies_farther_apart_than_round_off_read_as_noise(jitter):
    # The same 25 copies 1e-7 to 1e-5 m apart are distinct points, and each
    # 20-point neighbourhood still held one point's copies (median 59 deg
    # off).  Their scatter reads as noise against the patch's spread, and the
    # patches grow past the copies (NORMAL_ANGLE_TARGET) to span the grid.
    g = np.stack(np.meshgrid(np.arange(10), np.arange(10)), -1).reshape(-1, 2)
    points = np.repeat(np.c_[0.005 * g, np.zeros(100)], 25, axis=0)
    points += np.random.default_rng(0).normal(0.0, jitter, points.shape)
    up = np.tile([0.0, 0.0, 1.0], (len(points), 1))
    err = _angles(estimate_normals(points), up)
    assert np.median(err) < 0.1 and np.percentile(err, 99) < 1.0


def test_a_hundred_thousand_copies_of_one_spot_stay_cheap():
    # Merging near copies must not list every pair of them (10^10 here).
    g = np.stack(np.meshgrid(np.arange(20), np.arange(20)), -1).reshape(-1, 2)
    grid = np.c_[0.005 * g, np.zeros(400)]
    spot = grid[0] + np.random.default_rng(1).normal(0.0, 1e-12, (100_000, 3))
    normals = estimate_normals(np.vstack([grid, spot]))
    assert np.abs(normals[:, 2]).min() > 1.0 - 1e-9


def _noisy_box(n, sigma, seed=0):
    """The box's points moved along their face normals by N(0, σ²), metres."""
    points, normals = _box_surface(n, seed=seed)
    rng = np.random.default_rng(seed + 100)
    return points + rng.normal(0.0, sigma, n)[:, None] * normals, normals


def _inner(points, normals, margin=0.012):
    """Points at least ``margin`` (m) from every edge of their face."""
    room = np.where(normals != 0.0, np.inf, HALF - np.abs(points))
    return room.min(axis=1) >= margin


def test_noisy_cloud_grows_its_neighbourhoods_to_the_target_error():
    # 3,000 points (about 3 mm apart) with 0.1 mm of noise across the faces:
    # 20-point planes are 0.3 deg off, and a parallel jaw closing along such
    # a normal touches a face along its pad's edge.  The patches grow until
    # the expected error is NORMAL_ANGLE_TARGET (0.1 deg).
    from drakegrasp.planning import cloud_normals

    points, true = _noisy_box(3000, 1e-4)
    inner = _inner(points, true)
    fixed, fixed_error, _ = cloud_normals._patch_normals(
        points, cloud_normals.NORMAL_NEIGHBOURS
    )
    before = _angles(fixed[inner], true[inner])
    after = _angles(estimate_normals(points)[inner], true[inner])
    # the error estimated from the quadrics' residuals is the measured one
    assert np.degrees(fixed_error) == pytest.approx(np.median(before), rel=0.3)
    assert np.median(before) > 0.25
    assert np.median(after) < np.degrees(cloud_normals.NORMAL_ANGLE_TARGET)
    assert np.percentile(after, 90) < 0.5 * np.percentile(before, 90)


def test_noise_free_cloud_keeps_twenty_point_patches():
    from drakegrasp.planning import cloud_normals

    points, _ = _box_surface(3000, seed=3)
    fixed, error, _ = cloud_normals._patch_normals(
        points, cloud_normals.NORMAL_NEIGHBOURS
    )
    assert np.degrees(error) < 1e-3
    np.testing.assert_array_equal(estimate_normals(points), fixed)


def test_noise_estimate_scales_with_the_noise_not_the_units():
    from drakegrasp.planning import cloud_normals

    errors = []
    for sigma in (1e-4, 2e-4, 4e-4):
        points, _ = _noisy_box(3000, sigma, seed=4)
        errors.append(
            cloud_normals._patch_normals(points, cloud_normals.NORMAL_NEIGHBOURS)[1]
        )
        millimetres = cloud_normals._patch_normals(
            1e3 * points, cloud_normals.NORMAL_NEIGHBOURS
        )[1]
        assert millimetres == pytest.approx(errors[-1], rel=1e-6)  # radians
    ratios = np.array(errors[1:]) / np.array(errors[:-1])
    np.testing.assert_allclose(ratios, 2.0, rtol=0.15)


@pytest.mark.parametrize("scale", [1e-150, 1e-30, 1.0, 1e5])
def test_noisy_cloud_at_any_scale_grows_the_same_patches(scale):
    # The error estimate is a ratio of squares (noise over in-plane spread):
    # at 1e-150 m their products would underflow and ask for no growth, or
    # overflow into an inf that no neighbourhood size can hold.
    from drakegrasp.planning import cloud_normals

    points, _ = _noisy_box(1500, 2e-4, seed=5)
    base = estimate_normals(points)
    err = _angles(estimate_normals(points * scale), base)
    error = cloud_normals._patch_normals(
        points * scale, cloud_normals.NORMAL_NEIGHBOURS
    )[1]
    assert error == pytest.approx(
        cloud_normals._patch_normals(points, cloud_normals.NORMAL_NEIGHBOURS)[1],
        rel=1e-6,
    )
    assert np.all(np.isfinite(base)) and np.percentile(err, 99) < 1e-3


@pytest.mark.parametrize("given", [False, True], ids=["estimated", "given"])
def test_a_plan_on_a_cloud_says_how_its_normals_were_estimated(given):
    # A user planning from a camera sees the noise read from the cloud and
    # the patches it asked for (the shipped gripper: no drake_models needed).
    from drakegrasp.planning import plan_grasps, planning_scene

    sigma = 2e-4
    points, normals = _noisy_box(3000, sigma, seed=6)
    hand = planning_scene(None, hand_url="package://drakegrasp/hands/parallel_jaw.sdf")
    result = plan_grasps(
        hand.plant, hand.context, None, hand=hand.hand, num_candidates=5,
        mu=0.5, seed=0, point_cloud=points,
        cloud_normals=normals if given else None,
    )  # fmt: skip
    fit = result.settings["cloud_normals"]
    if given:
        assert fit is None and "cloud normals estimated" not in str(result)
        return
    assert fit["noise"] == pytest.approx(sigma, rel=0.25)  # metres
    assert 20 < fit["neighbours"] <= 100
    assert fit["error_deg"] < 0.2
    line = f"cloud normals estimated over {fit['neighbours']} points a patch"
    assert line in str(result)


def test_finite_points_with_non_finite_normals_are_named_as_such():
    # All 300 points were finite; the refusal said "0 finite points of 300".
    points, normals = _box_surface(300)
    with pytest.raises(
        InvalidOptionError, match="cloud_normals row that is not finite"
    ):
        read_cloud(points, normals * np.nan)
    missing = points.copy()
    missing[2:] = np.nan  # the points themselves missing: as before
    with pytest.raises(InvalidOptionError, match="finite points of 300"):
        read_cloud(missing)


@pytest.mark.parametrize("normals", [None, "given"])
def test_a_cloud_of_one_point_repeated_is_refused(normals):
    # It passed the three-point check and planned nothing, with no reason.
    points = np.tile([0.01, 0.02, 0.03], (100, 1))
    given = None if normals is None else np.tile([0.0, 0.0, 1.0], (100, 1))
    with pytest.raises(InvalidOptionError, match="all lie at one place"):
        read_cloud(points, given)
