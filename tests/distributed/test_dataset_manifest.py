"""A dataset's files that are damaged in their values or are not files at all.

A manifest of valid JSON with values of the wrong type (``"job": 5``,
``"rows": 3``) raised raw ``AttributeError``/``TypeError``; a manifest or a
shard that is a named pipe would block the reader.  Each is the documented
:class:`~drakegrasp.BatchFileError`, naming the key or the file.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from special_files import needs_mkfifo, watched_fifo

pytest.importorskip("pyarrow", reason="pyarrow is an optional extra")

from drakegrasp import BatchFileError  # noqa: E402
from drakegrasp.distributed import read_dataset  # noqa: E402
from drakegrasp.distributed.dataset import (  # noqa: E402
    MANIFEST,
    prepare_dataset,
    shard_is_done,
    write_shard,
)


def _dataset(path, manifest=None):
    """A one-shard dataset of job "x" (3 rows), with ``manifest`` if given."""
    path.mkdir(exist_ok=True)
    arrays = {"is_closure": np.zeros(3, bool), "d_star": np.arange(3.0)}
    write_shard(path / "part-00000.parquet", arrays, "x")
    if manifest is not None:
        (path / MANIFEST).write_text(json.dumps(manifest))
    return path


@pytest.mark.parametrize(
    ("manifest", "key"),
    [
        ({"job": 5, "rows": [3]}, "'job'"),
        ({"job": None, "rows": [3]}, "'job'"),
        ({"rows": [3]}, "'job'"),
        ({"job": "x", "rows": 3}, "'rows'"),
        ({"job": "x", "rows": None}, "'rows'"),
        ({"job": "x"}, "'rows'"),
        ({"job": "x", "rows": ["3"]}, "'rows'"),
        ({"job": "x", "rows": [3.0]}, "'rows'"),
        ({"job": "x", "rows": [True]}, "'rows'"),
        ({"job": "x", "rows": [-1]}, "'rows'"),
        ([3], "JSON object"),
    ],
)
def test_a_manifest_with_a_wrong_value_is_named(tmp_path, manifest, key):
    out = _dataset(tmp_path / "d", manifest)
    with pytest.raises(BatchFileError, match=f"damaged {MANIFEST}.*{key}"):
        read_dataset(out)


def test_a_well_formed_manifest_reads(tmp_path):
    out = _dataset(tmp_path / "d", {"job": "x", "rows": [3]})
    assert read_dataset(out)["d_star"].tolist() == [0.0, 1.0, 2.0]


def test_invalid_json_is_still_a_damaged_manifest(tmp_path):
    out = _dataset(tmp_path / "d")
    (out / MANIFEST).write_text("{not json")
    with pytest.raises(BatchFileError, match=f"damaged {MANIFEST}.*JSON"):
        read_dataset(out)


def test_a_manifest_of_wrong_values_is_another_job_to_a_run(tmp_path):
    out = _dataset(tmp_path / "d", {"job": "x", "rows": None})
    new = {"job": "x", "rows": [3]}
    with pytest.raises(BatchFileError, match="an unreadable manifest"):
        prepare_dataset(out, new, overwrite=False)
    prepare_dataset(out, new, overwrite=True)
    assert json.loads((out / MANIFEST).read_text()) == new


@needs_mkfifo
def test_a_manifest_that_is_a_pipe_is_refused_unopened(tmp_path):
    out = _dataset(tmp_path / "d")
    with watched_fifo(out / MANIFEST) as pipe:
        with pytest.raises(BatchFileError, match=f"damaged {MANIFEST}.*named pipe"):
            read_dataset(out)
        with pytest.raises(BatchFileError, match="an unreadable manifest"):
            prepare_dataset(out, {"job": "x", "rows": [3]}, overwrite=False)
    assert pipe.opened == 0


@needs_mkfifo
def test_a_shard_that_is_a_pipe_is_refused_unopened(tmp_path):
    out = _dataset(tmp_path / "d")
    with watched_fifo(out / "part-00001.parquet") as pipe:
        with pytest.raises(BatchFileError, match=r"part-00001\.parquet.*named pipe"):
            read_dataset(out)
        assert not shard_is_done(pipe.path, "x", 3)
    assert pipe.opened == 0


def test_a_dataset_that_is_a_file_is_not_called_missing(tmp_path):
    (tmp_path / "d").write_text("")
    with pytest.raises(BatchFileError, match="is not a directory"):
        read_dataset(tmp_path / "d")


@pytest.mark.parametrize("given", [None, 5, b"out", ""])
def test_a_dataset_directory_that_is_no_path_is_refused(given):
    # read_dataset(None) raised Python's TypeError (fuzzer)
    with pytest.raises(BatchFileError, match="must be a dataset directory.s path"):
        read_dataset(given)
