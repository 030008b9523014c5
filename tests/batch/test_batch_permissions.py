"""Files and folders this process may not examine or list, refused by name.

pathlib's ``exists()`` and ``is_dir()`` raise ``PermissionError`` for a path
inside a folder the process may not search, and ``iterdir`` for a folder it
may not read, where ``glob`` lists nothing.  Measured as an unprivileged user
(root passes every permission check, so the tests deny ``stat`` and the
listings here): ``read_grasps``, ``evaluate_file``, ``stream_file``,
``write_result`` and ``read_dataset`` raised a bare ``PermissionError``, and a
grasp directory that could not be read "held []".
"""

from __future__ import annotations

import os

import numpy as np
import pytest

from drakegrasp.batch import (
    batch_force_closure,
    evaluate_file,
    read_grasps,
    stream_file,
    write_result,
)
from drakegrasp.errors import BatchFileError


def _deny(monkeypatch, folder, *, listing_only=False):
    """Make ``folder`` unsearchable (or, with ``listing_only``, unreadable)."""
    folder = str(folder)
    real_stat, real_scandir, real_listdir = os.stat, os.scandir, os.listdir

    def denied(path):
        raise PermissionError(13, "Permission denied", os.fspath(path))

    def inside(path) -> bool:
        return os.fspath(path).startswith(folder + os.sep)

    def stat(path, *args, **kwargs):
        if not listing_only and isinstance(path, (str, os.PathLike)) and inside(path):
            denied(path)
        return real_stat(path, *args, **kwargs)

    def scandir(path="."):
        if os.fspath(path) == folder or inside(path):
            denied(path)
        return real_scandir(path)

    def listdir(path="."):
        if os.fspath(path) == folder or inside(path):
            denied(path)
        return real_listdir(path)

    monkeypatch.setattr(os, "stat", stat)
    monkeypatch.setattr(os, "scandir", scandir)
    monkeypatch.setattr(os, "listdir", listdir)


def _grasps(folder):
    rng = np.random.default_rng(0)
    P = rng.normal(size=(4, 3, 3))
    N = -P / np.linalg.norm(P, axis=-1, keepdims=True)
    path = folder / "in.npz"
    np.savez(path, positions=P, normals=N)
    return path, P, N


def test_an_input_in_an_unsearchable_folder_is_refused_by_name(tmp_path, monkeypatch):
    locked = tmp_path / "locked"
    locked.mkdir()
    inside, _, _ = _grasps(locked)
    out = tmp_path / "out.npz"
    _deny(monkeypatch, locked)
    for call in (
        lambda: read_grasps(inside),
        lambda: evaluate_file(inside, out, mu=0.5),
        lambda: stream_file(inside, out, mu=0.5),
    ):
        with pytest.raises(BatchFileError, match="cannot be examined"):
            call()
    assert not out.exists()


def test_an_output_in_an_unsearchable_folder_is_refused_by_name(tmp_path, monkeypatch):
    source, P, N = _grasps(tmp_path)
    locked = tmp_path / "locked"
    locked.mkdir()
    result = batch_force_closure(P, N, mu=0.5)
    _deny(monkeypatch, locked)
    for call in (
        lambda: evaluate_file(source, locked / "out.npz", mu=0.5),
        lambda: stream_file(source, locked / "out.npz", mu=0.5),
        lambda: write_result(result, locked / "out.npz"),
    ):
        with pytest.raises(BatchFileError, match="output file .* cannot be examined"):
            call()


def test_a_grasp_directory_that_cannot_be_listed_is_no_empty_one(tmp_path, monkeypatch):
    folder = tmp_path / "arrays"
    folder.mkdir()
    rng = np.random.default_rng(1)
    P = rng.normal(size=(2, 3, 3))
    np.save(folder / "positions.npy", P)
    np.save(folder / "normals.npy", -P)
    assert set(read_grasps(folder)) == {"positions", "normals"}
    _deny(monkeypatch, folder, listing_only=True)
    with pytest.raises(BatchFileError, match="cannot be listed"):
        read_grasps(folder)
    with pytest.raises(BatchFileError, match="cannot be listed"):
        evaluate_file(folder, tmp_path / "out.npz", mu=0.5)


def test_a_dataset_that_cannot_be_examined_or_listed_is_refused(tmp_path, monkeypatch):
    pytest.importorskip("pyarrow", reason="pyarrow is an optional extra")
    from drakegrasp.distributed import read_dataset

    locked = tmp_path / "locked"
    (locked / "ds").mkdir(parents=True)
    with monkeypatch.context() as patch:
        _deny(patch, locked)
        with pytest.raises(BatchFileError, match="cannot be examined"):
            read_dataset(locked / "ds")
    _deny(monkeypatch, locked / "ds", listing_only=True)
    with pytest.raises(BatchFileError, match="cannot be listed"):
        read_dataset(locked / "ds")
