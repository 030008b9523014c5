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
