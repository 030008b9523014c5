"""Grasp files that are not what they claim: pipes, devices and lying headers.

A named pipe given as the input blocked the reader forever; a tiny ``.npz``
whose array header claims a huge shape made numpy allocate petabytes (a raw
``MemoryError`` that named neither file nor array).  Both are refused at once
with a :class:`~drakegrasp.BatchFileError` that says what is wrong, read by
``stat`` and the array headers alone.
"""

from __future__ import annotations

import io
import os
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from special_files import needs_mkfifo, watched_fifo

from drakegrasp.batch import evaluate_file, read_grasps
from drakegrasp.errors import BatchFileError


def _grasps(K=2):
    return np.zeros((K, 3, 3)), -np.eye(3)[None].repeat(K, 0)


def _header(shape, descr="<f8") -> bytes:
    out = io.BytesIO()
    header = {"descr": descr, "fortran_order": False, "shape": shape}
    np.lib.format.write_array_header_1_0(out, header)
    return out.getvalue()


def _npy(a) -> bytes:
    out = io.BytesIO()
    np.save(out, a)
    return out.getvalue()


def _archive(path, positions: bytes, *, compression=zipfile.ZIP_STORED):
    _, normals = _grasps()
    with zipfile.ZipFile(path, "w", compression) as z:
        z.writestr("positions.npy", positions)
        z.writestr("normals.npy", _npy(normals))
    return path


def _cli(*argv, timeout=120):
    return subprocess.run(
        [sys.executable, "-m", "drakegrasp", *map(str, argv)],
        capture_output=True, text=True, timeout=timeout,
    )  # fmt: skip


# -- defect 5: a named pipe as the input ---------------------------------------


@needs_mkfifo
def test_a_named_pipe_is_refused_without_being_opened(tmp_path):
    with watched_fifo(tmp_path / "grasps.npz") as pipe:
        with pytest.raises(BatchFileError, match=r"grasps\.npz.*named pipe"):
            read_grasps(pipe.path)
        with pytest.raises(BatchFileError, match="not a regular file"):
            evaluate_file(pipe.path, tmp_path / "out.npz", mu=0.5)
    assert pipe.opened == 0
    assert not (tmp_path / "out.npz").exists()


@needs_mkfifo
def test_a_named_pipe_among_a_directorys_npy_files_is_refused(tmp_path):
    source = tmp_path / "grasps"
    source.mkdir()
    np.save(source / "normals.npy", _grasps()[1])
    with watched_fifo(source / "positions.npy") as pipe:
        with pytest.raises(BatchFileError, match=r"positions\.npy.*named pipe"):
            read_grasps(source)
    assert pipe.opened == 0


def test_a_device_is_refused(tmp_path):
    if not os.path.exists(os.devnull) or os.path.isfile(os.devnull):
        pytest.skip("no null device")
    (tmp_path / "grasps.npz").symlink_to(os.devnull)
    with pytest.raises(BatchFileError, match="device, not a regular file"):
        evaluate_file(tmp_path / "grasps.npz", tmp_path / "out.npz", mu=0.5)


@needs_mkfifo
def test_the_command_refuses_a_named_pipe_in_one_line(tmp_path):
    with watched_fifo(tmp_path / "grasps.npz") as pipe:
        run = _cli("batch", pipe.path, tmp_path / "out.npz", "--mu", "0.5")
    assert pipe.opened == 0
    assert run.returncode != 0
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and "named pipe" in lines[0], run.stderr
