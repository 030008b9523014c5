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


# -- defect 6: an array header that claims more than the member holds -----------


@pytest.mark.parametrize("compression", [zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED])
def test_a_header_claiming_a_huge_shape_is_refused(tmp_path, compression):
    path = _archive(
        tmp_path / "grasps.npz", _header((10**14, 3, 3)) + b"\0" * 72,
        compression=compression,
    )  # fmt: skip
    message = r"grasps\.npz.*damaged: positions claims shape \(100000000000000, 3, 3\)"
    with pytest.raises(BatchFileError, match=message):
        read_grasps(path)
    with pytest.raises(BatchFileError, match=r"\(7200000000000000 bytes\) in 72 bytes"):
        evaluate_file(path, tmp_path / "out.npz", mu=0.5)


def test_a_header_claiming_one_grasp_too_many_is_refused(tmp_path):
    positions, _ = _grasps(2)
    data = _npy(positions)
    path = _archive(tmp_path / "g.npz", _header((3, 3, 3)) + data[-positions.nbytes :])
    with pytest.raises(BatchFileError, match=r"positions claims shape \(3, 3, 3\)"):
        read_grasps(path)


def test_a_huge_header_in_a_directory_is_refused(tmp_path):
    source = tmp_path / "grasps"
    source.mkdir()
    np.save(source / "normals.npy", _grasps()[1])
    (source / "positions.npy").write_bytes(_header((10**14, 3, 3)) + b"\0" * 72)
    with pytest.raises(BatchFileError, match=r"damaged: positions claims shape"):
        read_grasps(source)


def test_compressed_and_stored_archives_still_read(tmp_path):
    P, Nrm = _grasps(4)
    for save in (np.savez, np.savez_compressed):
        path = tmp_path / f"{save.__name__}.npz"
        save(path, positions=P, normals=Nrm, mu=np.float64(0.5))
        data = read_grasps(path)
        np.testing.assert_array_equal(data["positions"], P)
        np.testing.assert_array_equal(data["normals"], Nrm)
        assert data["mu"] == 0.5


def test_the_command_names_the_file_and_the_array_in_one_line(tmp_path):
    path = _archive(tmp_path / "grasps.npz", _header((10**14, 3, 3)) + b"\0" * 72)
    run = _cli("batch", path, tmp_path / "out.npz", "--mu", "0.5")
    assert run.returncode != 0
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1, run.stderr
    assert "grasps.npz" in lines[0] and "positions claims shape" in lines[0]


def test_an_archive_larger_than_memory_is_refused_by_name(tmp_path, monkeypatch):
    P, Nrm = _grasps()
    np.savez(tmp_path / "g.npz", positions=P, normals=Nrm)

    def out_of_memory(*args, **kwargs):
        raise MemoryError("Unable to allocate 6.39 PiB")

    monkeypatch.setattr(np.lib.format, "read_array", out_of_memory)
    with pytest.raises(BatchFileError, match=r"g\.npz.*more than the free memory"):
        read_grasps(tmp_path / "g.npz")
