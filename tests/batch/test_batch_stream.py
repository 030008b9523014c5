"""Streaming results to files: .npz and .parquet written chunk by chunk agree
with the in-memory result, for any number of workers, from memory-mapped input."""

from __future__ import annotations

import numpy as np
import pytest
from batch_support import random_grasps

from drakegrasp.batch import batch_force_closure, batch_form_closure, stream_file
from drakegrasp.batch.files.writer import format_of
from drakegrasp.cli import main
from drakegrasp.errors import InvalidOptionError


@pytest.fixture
def npy_dir(tmp_path):
    rng = np.random.default_rng(8000)
    K, N = 1300, 4
    P, Nrm = random_grasps(rng, K, N, 3)
    mu = rng.uniform(0.1, 0.9, (K, N))
    d = tmp_path / "grasps"
    d.mkdir()
    for name, a in (("positions", P), ("normals", Nrm), ("mu", mu)):
        np.save(d / f"{name}.npy", a)
    return d, P, Nrm, mu


def test_npz_stream_matches_the_in_memory_result(npy_dir, tmp_path):
    d, P, Nrm, mu = npy_dir
    want = batch_force_closure(P, Nrm, mu=mu, metrics=["isotropy"])
    out = tmp_path / "out.npz"
    summary = stream_file(d, out, chunk_size=200, metrics=["isotropy"], workers=1)
    with np.load(out) as got:
        for name, a in want.to_arrays().items():
            assert got[name].dtype == a.dtype and np.array_equal(got[name], a), name
        assert str(got["kind"]) == "force" and float(got["tol"]) == want.tol
        assert int(got["required_rank"]) == 6
    assert summary.count == len(want) and summary.closed == want.is_closure.sum()
    assert summary.d_max == want.d_star.max()
    assert "force closure of 1300 grasps" in str(summary)


def test_parquet_stream_has_one_row_group_per_chunk(npy_dir, tmp_path):
    pq = pytest.importorskip("pyarrow.parquet", reason="pyarrow is an optional extra")
    d, P, Nrm, mu = npy_dir
    want = batch_form_closure(P, Nrm)
    out = tmp_path / "out.parquet"
    stream_file(d, out, kind="form", chunk_size=500, workers=1)
    f = pq.ParquetFile(out)
    assert f.num_row_groups == 3
    table = f.read()
    assert np.array_equal(table.column("d_star").to_numpy(), want.d_star)
    assert f.schema_arrow.metadata[b"kind"] == b"form"


def test_empty_input_writes_empty_arrays(tmp_path):
    src = tmp_path / "empty.npz"
    np.savez(src, positions=np.zeros((0, 3, 3)), normals=np.zeros((0, 3, 3)))
    out = tmp_path / "out.npz"
    assert stream_file(src, out, mu=0.5).count == 0
    with np.load(out) as got:
        assert got["d_star"].shape == (0,)


def test_cli_workers_and_format(npy_dir, tmp_path, capsys):
    d, P, Nrm, mu = npy_dir
    out = tmp_path / "o.npz"
    code = main(["batch", str(d), str(out), "--workers", "2", "--format", "npz",
                 "--chunk-size", "300"])  # fmt: skip
    assert code == 0
    want = batch_force_closure(P, Nrm, mu=mu, workers=1, chunk_size=300)
    with np.load(out) as got:
        assert got["d_star"].tobytes() == want.d_star.tobytes()
    assert "wrote" in capsys.readouterr().out


def test_format_is_checked():
    assert format_of("x.NPZ") == "npz" and format_of("x", "parquet") == "parquet"
    with pytest.raises(InvalidOptionError, match="must end in .npz or .parquet"):
        format_of("x.csv")
    with pytest.raises(InvalidOptionError, match="format must be one of"):
        format_of("x.npz", "csv")


@pytest.mark.parametrize("fmt", ["npz", "parquet"])
def test_a_stream_that_fails_leaves_the_earlier_file_and_nothing_else(
    npy_dir, tmp_path, fmt
):
    """``write_chunks`` of a stream that raises at its fourth chunk (a grasp
    the engine refuses).  The Parquet writer wrote row groups straight into
    the output: the earlier file was gone at the first chunk, and the failed
    run left a valid file of the first 600 grasps, which a reader takes for
    the whole run.  Both formats now reach the output's name only complete,
    as the ``.npz`` writer's archive did."""
    if fmt == "parquet":
        pytest.importorskip("pyarrow", reason="pyarrow is an optional extra")
    from drakegrasp.batch import stream_force_closure, write_chunks
    from drakegrasp.errors import InvalidContactError

    _, P, Nrm, mu = npy_dir
    P = np.array(P)
    P[700, 1] = np.nan
    out = tmp_path / f"out.{fmt}"
    out.write_bytes(b"the old results")
    chunks = stream_force_closure(P, Nrm, mu=mu, chunk_size=200, workers=1)
    with pytest.raises(InvalidContactError, match="grasp 700"):
        write_chunks(chunks, out, K=len(P), kind="force", tol=1e-6, required_rank=6)
    assert out.read_bytes() == b"the old results"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["grasps", f"out.{fmt}"]


@pytest.mark.parametrize("fmt", ["npz", "parquet"])
def test_a_file_that_cannot_be_finished_leaves_the_earlier_file(
    npy_dir, tmp_path, monkeypatch, fmt
):
    """The ``.npz`` archive was made at the output's name: a disk that filled
    while the arrays were copied into it left a truncated archive there, in
    place of the earlier file.  The disk's error was a bare ``OSError``; it is
    now the output's ``BatchFileError``, naming the file."""
    import errno
    import os
    import zipfile

    from drakegrasp.batch import stream_force_closure, write_chunks
    from drakegrasp.errors import BatchFileError

    def full(self, *args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    if fmt == "parquet":
        pq = pytest.importorskip("pyarrow.parquet", reason="pyarrow is optional")
        monkeypatch.setattr(pq.ParquetWriter, "write_table", full)
    else:
        monkeypatch.setattr(zipfile.ZipFile, "write", full)
    _, P, Nrm, mu = npy_dir
    out = tmp_path / f"out.{fmt}"
    out.write_bytes(b"the old results")
    chunks = stream_force_closure(P, Nrm, mu=mu, chunk_size=500, workers=1)
    with pytest.raises(BatchFileError, match=r"cannot write .*out\.\w+.*No space left"):
        write_chunks(chunks, out, K=len(P), kind="force", tol=1e-6, required_rank=6)
    assert out.read_bytes() == b"the old results"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["grasps", f"out.{fmt}"]


def test_an_input_that_fails_as_it_streams_is_not_named_as_the_output(tmp_path):
    """Only the writer's own steps are the output's errors: a chunk stream
    that raises ``OSError`` (an input read as it streams) passes as it is."""
    from drakegrasp.batch import write_chunks
    from drakegrasp.errors import BatchFileError

    def chunks():
        raise FileNotFoundError(2, "No such file or directory", "in.npz")
        yield

    with pytest.raises(FileNotFoundError) as info:
        write_chunks(chunks(), tmp_path / "out.npz", K=1, kind="force", tol=1e-6,
                     required_rank=6)  # fmt: skip
    assert not isinstance(info.value, BatchFileError)
    assert list(tmp_path.iterdir()) == []
