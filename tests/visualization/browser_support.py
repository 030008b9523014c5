"""Headless Chromium screenshots of Meshcat, for the browser tests.

Meshcat serves its page (three.js bundled in the Drake wheel, no CDN) on
localhost; Chromium renders it with SwiftShader (software WebGL).  Helpers:
take a screenshot, decode the PNG (stdlib only), find a colour's pixels and
project world points to pixels with Meshcat's default camera.
"""

import os
import signal
import struct
import subprocess
import zlib
from pathlib import Path

import numpy as np
import pytest

CHROMIUM = Path("/usr/bin/chromium")
WIDTH, HEIGHT = 800, 600

SKIP_WITHOUT_CHROMIUM = pytest.mark.skipif(
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
    url: str,
    path: Path,
    profile: Path,
    budget_ms: int = 4000,
    attempts: int = 3,
    drawn=None,
) -> np.ndarray:
    """Open ``url`` in headless Chromium and return its screenshot as RGB.

    A page that had not drawn its 3-D scene when the virtual-time budget ran
    out is a flat image (a standard deviation under 5 grey levels; every
    Meshcat scene, even an empty one, has its grid and shading).  On a loaded
    machine that happened in CI once (89 % of pixels off the empty scene's);
    such a shot is taken again, up to ``attempts`` times, with twice the
    budget each time.  ``drawn(img)``, if given, says whether the scene's
    last objects are in the picture: a page can show its grid before the
    objects Meshcat sends it arrive (once in CI, on a machine running the
    suite twice over: no force arrow at all, on top or hidden), and such a
    shot is taken again too.  What the scene shows once drawn is never
    retried: a test whose objects never appear still fails.
    """
    for attempt in range(attempts):
        img = _screenshot(url, path, profile, budget_ms * 2**attempt)
        if img.std() > 5.0 and (drawn is None or drawn(img)):
            break
    return img


def _screenshot(url: str, path: Path, profile: Path, budget_ms: int) -> np.ndarray:
    """One headless Chromium screenshot of ``url``, as RGB."""
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
