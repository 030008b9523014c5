"""A real browser shows the Meshcat drawing: headless Chromium screenshots.

Meshcat serves its page (three.js bundled in the Drake wheel, no CDN) on
localhost.  Chromium renders it with SwiftShader (software WebGL) and writes a
screenshot; the test compares a screenshot of the empty scene with one after
``draw_grasp`` and checks that the drawing's colours appear where the grasp is,
that moving the drawing's prefix moves them, and that ``clear_grasp`` removes
them.  Skips only when ``/usr/bin/chromium`` is missing (``.ci/install-chromium``
installs Debian's package).

The screenshot with the grasp is printed and kept under pytest's tmp dir; when
``DRAKEGRASP_SCREENSHOT_DIR`` is set it is also copied there as
``meshcat_screenshot.png``.
"""

import os
import shutil
from pathlib import Path

import numpy as np
from browser_support import (
    CAMERA,
    HEIGHT,
    SKIP_WITHOUT_CHROMIUM,
    TARGET,
    WIDTH,
    centroid,
    colour_mask,
    distance_to_segment,
    project,
    screenshot,
)
from pydrake.geometry import Rgba, Sphere
from pydrake.math import RigidTransform

from drakegrasp import Contact, Grasp
from drakegrasp.closure.verdicts import force_closure
from drakegrasp.visualization import MESHCAT_COLORS, clear_grasp, draw_grasp

pytestmark = SKIP_WITHOUT_CHROMIUM


def test_chromium_shows_the_drawn_grasp(meshcat, tmp_path):
    r = 0.1
    angles = 2 * np.pi * np.arange(3) / 3 - np.pi / 2
    grasp = Grasp(
        [
            Contact(
                [r * np.cos(a), r * np.sin(a), 0], [-np.cos(a), -np.sin(a), 0], mu=0.6
            )
            for a in angles
        ]
    )
    result = force_closure(grasp)
    assert result.is_closure
    meshcat.SetObject("object", Sphere(r), Rgba(0.85, 0.82, 0.7, 1.0))
    # Camera in front of the object (-y) and above, looking at its centre:
    # world +x is screen right.
    meshcat.SetCameraPose(CAMERA, TARGET)
    url = meshcat.web_url()
    profile = tmp_path / "chromium-profile"

    empty = screenshot(url, tmp_path / "empty.png", profile)
    drawing = draw_grasp(meshcat, grasp, result=result, cone="both", keep_camera=True)
    drawn_path = tmp_path / "meshcat_screenshot.png"
    drawn = screenshot(url, drawn_path, profile)
    print(f"Meshcat screenshot with the grasp: {drawn_path}")
    target_dir = os.environ.get("DRAKEGRASP_SCREENSHOT_DIR")
    if target_dir:
        shutil.copy(drawn_path, Path(target_dir) / "meshcat_screenshot.png")

    # 1. The page rendered a 3-D scene at all (not a blank or error page).
    assert empty.std() > 5.0, "the empty Meshcat scene rendered as a flat image"

    # 2. The drawing changed a substantial region around the image centre,
    #    where the camera looks at the grasp.
    changed = np.abs(drawn.astype(int) - empty.astype(int)).sum(axis=2) > 60
    assert changed.mean() > 0.005, f"only {changed.mean():.4%} of pixels changed"
    cx, cy = centroid(changed)
    assert abs(cx - WIDTH / 2) < 0.15 * WIDTH and abs(cy - HEIGHT / 2) < 0.2 * HEIGHT

    # 3. The force arrows' magenta and the cones' blue appear only after drawing.
    force = colour_mask(drawn, MESHCAT_COLORS["force"])
    cone = colour_mask(drawn, MESHCAT_COLORS["cone"])
    assert colour_mask(empty, MESHCAT_COLORS["force"]).sum() == 0
    assert force.sum() > 150, f"{force.sum()} force-coloured pixels"
    # (The empty scene has a few: Meshcat's blue world z axis.)
    assert cone.sum() > colour_mask(empty, MESHCAT_COLORS["cone"]).sum() + 800
    # The arrows are where the camera model puts them: every arrow from
    # c - s f to c (world) projected to pixels has force-coloured pixels along
    # it, and nearly all force-coloured pixels lie on some projected arrow.
    segments = [
        project(np.array([c - drawing.force_scale * f, c]), CAMERA, TARGET)
        for c, f in zip(grasp.positions, drawing.forces_G, strict=True)
    ]
    ys, xs = np.nonzero(force)
    pixels = np.column_stack([xs, ys]).astype(float)
    dist = np.array([distance_to_segment(pixels, a, b) for a, b in segments])
    near = dist < 8.0
    assert near.any(axis=0).mean() > 0.9, "force colour away from the arrows"
    for i in range(grasp.num_contacts):
        # (Arrows 1 and 2 are seen partly through the translucent cones.)
        assert near[i].sum() >= 3, f"arrow {i} not visible at {segments[i]}"

    # 4. Moving the prefix (X_WG) moves the drawing: +x in world is screen right.
    meshcat.SetTransform("drakegrasp/grasp", RigidTransform([0.15, 0.0, 0.0]))
    moved = screenshot(url, tmp_path / "moved.png", profile)
    moved_force = colour_mask(moved, MESHCAT_COLORS["force"])
    assert moved_force.sum() > 100
    shift = centroid(moved_force) - centroid(force)
    assert shift[0] > 0.08 * WIDTH, f"arrows moved by {shift} px"

    # 5. clear_grasp removes it from the browser's scene as well.
    clear_grasp(meshcat)
    cleared = screenshot(url, tmp_path / "cleared.png", profile)
    assert colour_mask(cleared, MESHCAT_COLORS["force"]).sum() == 0
    residual = np.abs(cleared.astype(int) - empty.astype(int)).sum(axis=2) > 60
    assert residual.mean() < 0.2 * changed.mean()
