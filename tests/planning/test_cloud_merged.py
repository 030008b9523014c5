"""Scans merged as they were: every point has near twins, the surface is the same.

Two to ten scans of one object, merged with a registration error well under
their spacing, see each spot several times.  Their median nearest-neighbour
distance is the registration error; the spacing (and the line radius, the
surfels and the shadow built on it) must stay that of the surface, or most
grasp lines miss the far side.  The reference is the single scan.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest
from cloud_support import box_points, sample_cloud
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.planning.cloud import CloudSurface, PointCloudWarning

JAW = "package://drakegrasp/hands/parallel_jaw.sdf"


def _normals(points: np.ndarray, half=(0.025, 0.03, 0.05)) -> np.ndarray:
    """The box's outward normals at its points (the face each lies on)."""
    face = np.argmax(np.abs(points) / np.asarray(half), axis=1)
    n = np.zeros_like(points)
    n[np.arange(len(points)), face] = np.sign(points[np.arange(len(points)), face])
    return n


def _merged(points: np.ndarray, scans: int, error: float, seed: int = 1):
    """``scans`` copies of ``points``, each but the first off by ``error`` (m, std)."""
    rng = np.random.default_rng(seed)
    return np.concatenate(
        [points + (rng.normal(0.0, error, points.shape) if i else 0.0)
         for i in range(scans)]
    )  # fmt: skip


def _surface(points: np.ndarray) -> CloudSurface:
    return CloudSurface(points, _normals(points), origin=np.zeros(3))


def test_a_single_scan_keeps_its_nearest_neighbour_spacing():
    # the floor is for twins: a randomly sampled surface (nearest-neighbour
    # median about half its density spacing) and a grid keep the median
    # distance to the nearest point, bit for bit, and no warning
    grid = np.arange(-0.024, 0.0241, 0.002)
    y, z = np.meshgrid(grid, grid)
    square = np.c_[np.full(y.size, 0.025), y.ravel(), z.ravel()]
    for points in (
        box_points(300, 0),
        box_points(3000, 1),
        box_points(20000, 2),
        square,
    ):
        with warnings.catch_warnings():
            warnings.simplefilter("error", PointCloudWarning)
            surface = _surface(points)
        nearest = np.median(cKDTree(points).query(points, k=2)[0][:, 1])
        assert surface.spacing == nearest


@pytest.mark.parametrize(
    "scans, error",
    [(m, e) for m in (2, 4, 10, 20) for e in (1e-6, 1e-5, 1e-4)]
    + [(m, e) for m in (50, 100) for e in (1e-6, 1e-5, 3e-5)],
)
def test_merged_scans_keep_the_surface_spacing(scans, error):
    # the spacing is the distance past a spot's twins (to the nearest point
    # of another spot): what the single scan gives, a little less as the
    # twins spread.  Before, from 20 scans on, the 64 neighbours that sized a
    # spot no longer reached past it: 50 scans 0.1 mm apart took 0.29 of the
    # single scan's spacing, 100 scans 0.01 mm apart 0.002, without a warning.
    # (Twins spread over a quarter of the 1.5 mm spacing, as 50 scans 0.1 mm
    # apart are, show no jump: a noisy scan.)
    single = _surface(box_points(3000, 0))
    with pytest.warns(PointCloudWarning, match="near twins") as caught:
        merged = _surface(_merged(box_points(3000, 0), scans, error))
    assert 0.8 * single.spacing < merged.spacing < 1.05 * single.spacing
    assert merged.line_radius == pytest.approx(2.5 * merged.spacing)
    assert merged.seen == scans  # each spot's points
    message = str(caught[0].message)
    seen = int(re.search(r"a point has (\d+) within", message).group(1))
    assert seen == scans
    assert "VoxelizedDownSample(voxel_size=" in message


@pytest.mark.parametrize("scans, error", [(2, 1e-5), (4, 1e-4), (50, 3e-5)])
def test_the_suggested_voxel_leaves_one_scan(scans, error):
    # downsampled as the warning says, the cloud reads as one scan: no
    # warning again (at 1.5 spot spacings 50 scans 0.1 mm apart still had
    # twins), and about the single scan's spacing
    pytest.importorskip("pydrake.perception")
    from pydrake.perception import BaseField, Fields, PointCloud

    points = box_points(3000, 0)
    merged = _merged(points, scans, error)
    with pytest.warns(PointCloudWarning) as caught:
        _surface(merged)
    size = float(re.search(r"voxel_size=([0-9.e-]+)\)", str(caught[0].message))[1])
    cloud = PointCloud(len(merged), Fields(BaseField.kXYZs))
    cloud.mutable_xyzs()[:] = merged.T
    down = cloud.VoxelizedDownSample(voxel_size=size).xyzs().T
    with warnings.catch_warnings():
        warnings.simplefilter("error", PointCloudWarning)
        once = _surface(down)
    assert once.seen == 1
    assert (
        0.9 * _surface(points).spacing < once.spacing < 2.0 * _surface(points).spacing
    )
    assert len(down) > 0.6 * len(points)


def test_exact_repeats_are_one_point_without_a_warning():
    # repeated points (merged frames share them) were always one point
    points = box_points(3000, 0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", PointCloudWarning)
        repeated = _surface(np.repeat(points, 5, axis=0))
    assert repeated.spacing == _surface(points).spacing


@settings(max_examples=25, deadline=None)
@given(
    n=st.integers(400, 4000),
    scans=st.integers(2, 8),
    error=st.floats(1e-3, 0.02),  # of the single scan's spacing: no repeats
    scale=st.sampled_from([0.1, 1.0, 30.0]),
    seed=st.integers(0, 2**16),
)
def test_the_merged_spacing_follows_the_surface(n, scans, error, scale, seed):
    points = box_points(n, seed)
    single = _surface(points)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PointCloudWarning)
        merged = _surface(_merged(points, scans, error * single.spacing, seed))
        scaled = _surface(scale * _merged(points, scans, error * single.spacing, seed))
    assert 0.65 * single.spacing < merged.spacing < 1.05 * single.spacing
    # metres or any other unit: the spacing scales with the cloud
    assert scaled.spacing == pytest.approx(scale * merged.spacing, rel=1e-9)


@pytest.mark.parametrize("scans, error", [(2, 1e-4), (4, 1e-4), (50, 3e-5)])
def test_a_jaw_finds_the_far_side_of_merged_scans(scans, error):
    # before: 45 and 46 of 60 lines found no opposite surface, 0 and 5
    # candidates; 50 scans, their normals estimated among twins only (every
    # neighbour of a point in its own spot), 6 candidates of 3 x 60 poses
    # where one scan gives 69: each spot is now planned on as its mean point
    scene = planning_scene(None, hand_url=JAW)

    def plan(points, seed):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PointCloudWarning)
            return plan_grasps(
                scene.plant, scene.context, None, hand=scene.hand,
                num_candidates=60, mu=0.5, seed=seed, robustness_samples=0,
                point_cloud=points,
            )  # fmt: skip

    cloud = _merged(box_points(1500, 0), scans, error)
    single = [plan(box_points(1500, 0), seed) for seed in range(3)]
    merged = [plan(cloud, seed) for seed in range(3)]
    missed = sum(r.rejections.get("no opposite surface", 0) for r in merged)
    assert missed <= sum(r.rejections.get("no opposite surface", 0) for r in single) + 6
    assert sum(map(len, merged)) >= 0.8 * sum(map(len, single))  # 69 of 60 x 3
    assert merged[0].settings["cloud_dropped"] == 0  # gathered, not left out
    assert merged[0].settings["cloud_points"] <= 1500


def test_two_scans_of_the_sugar_box_plan_like_one(drake_models_dir):
    # the fuzzer's case: 42 candidates on one scan, 6 on two merged 0.01 mm apart
    full = planning_scene(
        "package://drake_models/ycb/004_sugar_box.sdf", models_dir=drake_models_dir
    )
    hand = planning_scene(None, models_dir=drake_models_dir)
    p, n = sample_cloud(full, 3000, 0)

    def plan(points, normals):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PointCloudWarning)
            return plan_grasps(
                hand.plant, hand.context, None, hand=hand.hand, num_candidates=100,
                mu=0.5, seed=0, robustness_samples=8, point_cloud=points,
                cloud_normals=normals,
            )  # fmt: skip

    single = plan(p, n)
    merged = plan(_merged(p, 2, 1e-5), np.r_[n, n])
    assert len(merged) >= 0.8 * len(single)
    assert sum(c.is_closure for c in merged) >= 0.8 * sum(c.is_closure for c in single)
    assert merged.rejections.get("no opposite surface", 0) <= 5


def _dense_spot() -> np.ndarray:
    """A box's cloud with 2,200 more points in a 2 mm spot on its +x face."""
    spot = np.random.default_rng(7).normal(0.0, 2e-3, (2200, 3))
    spot[:, 0] = 0.025
    return np.vstack([box_points(3000, 6), spot])


def _off_the_object(full, candidate) -> float:
    """How far (m) the farther finger of ``candidate`` stands off the true object."""
    plant, ctx = full.plant, full.context.Clone()
    candidate.apply(plant, ctx)
    query = plant.get_geometry_query_input_port().Eval(plant.GetMyContextFromRoot(ctx))
    mine = set(plant.GetCollisionGeometriesForBody(full.object_body))
    gaps = {}
    for pair in query.ComputeSignedDistancePairwiseClosestPoints(0.05):
        for a, b in ((pair.id_A, pair.id_B), (pair.id_B, pair.id_A)):
            if a in mine and b not in mine:
                body = plant.GetBodyFromFrameId(query.inspector().GetFrameId(b))
                gaps[body.name()] = min(gaps.get(body.name(), np.inf), pair.distance)
    return max(gaps.get("left_finger", np.inf), gaps.get("right_finger", np.inf))


@pytest.mark.parametrize("name", ["005_tomato_soup_can", "004_sugar_box"])
def test_merged_scans_put_the_fingertips_on_the_object(drake_models_dir, name):
    # the WSG-50's 1 mm tips meet a quadric fitted to the face's points; twins
    # let 2-4 spots pass for the 8 points of a fit, which then bulged, and
    # force-closure candidates stood 2-4.5 mm off the true object (4 scans
    # 0.1 mm apart: up to 4.9 mm); a fit now needs 8 spots' worth of points
    full = planning_scene(
        f"package://drake_models/ycb/{name}.sdf", models_dir=drake_models_dir
    )
    hand = planning_scene(None, models_dir=drake_models_dir)
    p, n = sample_cloud(full, 3000, 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PointCloudWarning)
        result = plan_grasps(
            hand.plant, hand.context, None, hand=hand.hand, num_candidates=100,
            mu=0.5, seed=0, robustness_samples=4,
            point_cloud=_merged(p, 4, 1e-4), cloud_normals=np.tile(n, (4, 1)),
        )  # fmt: skip
    closure = [c for c in result if c.is_closure]
    assert len(closure) >= 20
    off = [_off_the_object(full, c) for c in closure]
    assert max(off) < 1.5e-3, sorted(off)[-3:]


@pytest.mark.parametrize(
    "points",
    [
        pytest.param(box_points(58, 4), id="58 points"),
        pytest.param(box_points(150, 5), id="150 points"),
        pytest.param(np.c_[np.arange(100) * 1e-3, np.zeros((100, 2))], id="a line"),
        pytest.param(_dense_spot(), id="a dense spot"),
        pytest.param(
            np.r_[box_points(300, 6), box_points(300, 7) + [0.5, 0, 0]],
            id="two patches far apart",
        ),
    ],
)
def test_a_sparse_or_uneven_single_scan_is_not_taken_for_twins(points):
    # a small cloud's 64th neighbour lies across the object (a 58-point face
    # read as "twins of three", its line radius 53 mm against 10 mm); a
    # dense spot put a second point in the twin radius now and then; two
    # patches far apart are one jump, two "spots"
    normals = np.tile([1.0, 0.0, 0.0], (len(points), 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error", PointCloudWarning)
        surface = CloudSurface(points, normals, origin=np.zeros(3))
    distinct = np.unique(points, axis=0)
    nearest = np.median(cKDTree(distinct).query(distinct, k=2)[0][:, 1])
    assert surface.spacing == nearest
    assert surface.seen == 1


def test_the_twin_warning_names_the_callers_line():
    # the warning is raised deep in the planner; it names the user's call,
    # whichever route (jaw, multi-finger, the class itself) raised it
    points = _merged(box_points(3000, 0), 3, 1e-5)
    with pytest.warns(PointCloudWarning, match="near twins") as caught:
        _surface(points)
    assert caught[0].filename == __file__
    scene = planning_scene(None, hand_url=JAW)
    with pytest.warns(PointCloudWarning, match="near twins") as caught:
        plan_grasps(
            scene.plant, scene.context, None, hand=scene.hand, num_candidates=5,
            mu=0.5, seed=0, robustness_samples=0, point_cloud=points,
        )  # fmt: skip
    assert {w.filename for w in caught if "near twins" in str(w.message)} == {__file__}


def test_twins_of_two_patches_far_apart_are_told():
    # a small cloud's profile reaches across to the other patch: that jump
    # (at a patch's size) was larger than the twins' and hid it, the spacing
    # the registration error; twins are looked for up to a spot in 64 only
    rng = np.random.default_rng(0)
    patch = np.c_[np.zeros(300), rng.uniform(0.0, 0.03, (300, 2))]
    two = np.r_[patch, patch + [0.5, 0.0, 0.0]]
    merged = np.r_[two, two + rng.normal(0.0, 1e-4, two.shape)]
    normals = np.tile([1.0, 0.0, 0.0], (len(merged), 1))
    with pytest.warns(PointCloudWarning, match="near twins"):
        surface = CloudSurface(merged, normals, origin=np.zeros(3))
    single = CloudSurface(two, normals[: len(two)], origin=np.zeros(3))
    assert surface.seen == 2
    assert 0.7 * single.spacing < surface.spacing < 1.05 * single.spacing


def test_gathering_keeps_a_plates_two_faces_and_unoriented_normals():
    # a plate 0.5 mm thick sampled on both faces reads as sharp twins; its
    # faces' normals summed to 0 (read_cloud refused every point) and without
    # them its thickness was gone; normals of random sign cancelled (1,102 of
    # 2,997 spots of 4 scans of a sphere dropped)
    from drakegrasp.planning.cloud import read_cloud

    g = np.arange(0.0, 0.102, 0.002)
    x, y = (a.ravel() for a in np.meshgrid(g, g))
    top = np.c_[x, y, np.full(x.size, 0.0005)]
    bottom = np.c_[x, y, np.zeros(x.size)]
    plate = np.r_[top, bottom]
    up = np.tile([0.0, 0.0, 1.0], (len(top), 1))
    points, normals, dropped = read_cloud(plate, np.r_[up, -up])
    assert len(points) == len(plate) and dropped == 0
    assert np.ptp(points[:, 2]) == pytest.approx(0.0005)

    rng = np.random.default_rng(3)
    sphere = rng.normal(size=(3000, 3))
    sphere /= np.linalg.norm(sphere, axis=1, keepdims=True)
    scans = _merged(0.05 * sphere, 4, 1e-5)
    signs = rng.choice([-1.0, 1.0], size=(len(scans), 1))
    with pytest.warns(PointCloudWarning, match="near twins"):
        points, normals, dropped = read_cloud(scans, signs * np.tile(sphere, (4, 1)))
    assert dropped == 0 and len(points) >= 2900
    truth = points / np.linalg.norm(points, axis=1, keepdims=True)
    assert np.min(np.sum(normals * truth, axis=1)) > np.cos(np.radians(0.5))
