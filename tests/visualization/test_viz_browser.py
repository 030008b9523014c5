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
import signal
import struct
import subprocess
import zlib
from pathlib import Path

import numpy as np
import pytest
from pydrake.geometry import Meshcat, MeshcatParams, Rgba, Sphere
from pydrake.math import RigidTransform

from drakegrasp import Contact, Grasp
from drakegrasp.closure import force_closure
from drakegrasp.visualization import MESHCAT_COLORS, clear_grasp, draw_grasp

CHROMIUM = Path("/usr/bin/chromium")
WIDTH, HEIGHT = 800, 600

pytestmark = pytest.mark.skipif(
    not CHROMIUM.exists(),
    reason="chromium is not installed (/usr/bin/chromium missing); "
    ".ci/install-chromium installs Debian's chromium package",
)


def read_png(path: Path) -> np.ndarray:
    """Decode an 8-bit RGB/RGBA non-interlaced PNG to (H, W, 3) uint8 (stdlib)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, color, _, _, interlace = header
    assert depth == 8 and color in (2, 6) and interlace == 0, header
    channels = 3 if color == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * channels
    out = np.zeros((height, stride), dtype=np.int32)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(height):
        start = y * (stride + 1)
        ftype = raw[start]
        line = np.frombuffer(raw, np.uint8, stride, start + 1).astype(np.int32)
        if ftype == 0:
            cur = line
        elif ftype == 2:
            cur = (line + prev) & 0xFF
        else:  # Sub, Average, Paeth depend on the left pixel: decode serially.
            cur = np.zeros(stride, dtype=np.int32)
            for x in range(stride):
                a = cur[x - channels] if x >= channels else 0
                b = prev[x]
                c = prev[x - channels] if x >= channels else 0
                if ftype == 1:
                    pred = a
                elif ftype == 3:
                    pred = (a + b) // 2
                else:
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (line[x] + pred) & 0xFF
        out[y] = cur
        prev = cur
    return out.reshape(height, width, channels)[:, :, :3].astype(np.uint8)


def screenshot(
    url: str, path: Path, profile: Path, budget_ms: int = 4000
) -> np.ndarray:
    """Open ``url`` in headless Chromium and return its screenshot as RGB."""
    cmd = [
        str(CHROMIUM),
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--enable-unsafe-swiftshader",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--hide-scrollbars",
        f"--user-data-dir={profile}",
        f"--window-size={WIDTH},{HEIGHT}",
        f"--virtual-time-budget={budget_ms}",
        f"--screenshot={path}",
        url,
    ]
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
        text=True,
    )
    try:
        _, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        pytest.fail("chromium did not finish its screenshot within 60 s")
    assert path.exists(), f"chromium wrote no screenshot (rc {proc.returncode}):\n{err}"
    img = read_png(path)
    assert img.shape == (HEIGHT, WIDTH, 3)
    return img


def colour_mask(img: np.ndarray, rgba) -> np.ndarray:
    """Pixels whose hue is that of ``rgba`` (shading changes brightness only).

    Compares the direction of the RGB vector, after removing its grey part,
    with the colour's; the grey background has no such direction.
    """
    target = np.asarray(rgba[:3], dtype=float)
    target = target - target.mean()
    target /= np.linalg.norm(target)
    px = img.astype(float)
    chroma = px - px.mean(axis=2, keepdims=True)
    norm = np.linalg.norm(chroma, axis=2)
    cos = (chroma @ target) / np.maximum(norm, 1e-9)
    return (norm > 60.0) & (cos > 0.95)


CAMERA = np.array([0.0, -0.26, 0.3])
TARGET = np.zeros(3)
FOV_DEGREES = 75.0  # vertical field of view of Meshcat's default camera


def project(points: np.ndarray, camera: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Pixel coordinates (x right, y down) of world points, (k, 3) -> (k, 2).

    Pinhole model of Meshcat's default perspective camera placed with
    ``SetCameraPose(camera, target)`` (up vector: world +z as far as possible).
    """
    forward = (target - camera) / np.linalg.norm(target - camera)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = np.asarray(points, dtype=float) - camera
    x, y, z = d @ right, d @ up, d @ forward
    t = np.tan(np.deg2rad(FOV_DEGREES) / 2)
    u = WIDTH / 2 + (x / z) / (t * WIDTH / HEIGHT) * WIDTH / 2
    v = HEIGHT / 2 - (y / z) / t * HEIGHT / 2
    return np.column_stack([u, v])


def distance_to_segment(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distances of points ``p`` (k, 2) to the segment from ``a`` to ``b``."""
    ab = b - a
    s = np.clip(((p - a) @ ab) / max(float(ab @ ab), 1e-12), 0.0, 1.0)
    return np.linalg.norm(p - (a + s[:, None] * ab), axis=1)


def centroid(mask: np.ndarray) -> np.ndarray:
    ys, xs = np.nonzero(mask)
    return np.array([xs.mean(), ys.mean()])


@pytest.fixture(scope="module")
def meshcat():
    params = MeshcatParams()
    params.show_stats_plot = False
    return Meshcat(params)


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
    drawing = draw_grasp(meshcat, grasp, result=result, cone="both")
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
