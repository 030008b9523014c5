"""An empty job on a cluster: a dataset of every column and no rows, as locally."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

distributed = pytest.importorskip("distributed", reason="dask is an optional extra")
pq = pytest.importorskip("pyarrow.parquet", reason="pyarrow is an optional extra")

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "batch"))
from batch_support import random_grasps  # noqa: E402

from drakegrasp.batch import batch_force_closure, batch_form_closure  # noqa: E402
from drakegrasp.cli import main  # noqa: E402
from drakegrasp.distributed import evaluate_on_cluster, read_dataset  # noqa: E402


@pytest.fixture(scope="module")
def small_client():
    """One in-process worker: the smallest cluster."""
    cluster = distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    )
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


def _columns(arrays: dict) -> list[tuple[str, str]]:
    return [(name, str(a.dtype)) for name, a in arrays.items()]


@pytest.mark.parametrize("kind", ["force", "form"])
def test_an_empty_file_on_a_cluster_has_the_columns_of_a_full_one(
    small_client, tmp_path, kind
):
    rng = np.random.default_rng(4)
    P, Nrm = random_grasps(rng, 3, 4, 3)
    full, empty = tmp_path / "full.npz", tmp_path / "empty.npz"
    np.savez(full, positions=P, normals=Nrm)
    np.savez(empty, positions=P[:0], normals=Nrm[:0])
    address = small_client.scheduler.address
    cmd = ["batch", "--kind", kind] + (["--mu", "0.5"] if kind == "force" else [])
    assert main([*cmd, str(full), str(tmp_path / "full"), "--scheduler", address]) == 0
    assert (
        main([*cmd, str(empty), str(tmp_path / "empty"), "--scheduler", address]) == 0
    )
    assert main([*cmd, str(empty), str(tmp_path / "local.parquet")]) == 0
    got = read_dataset(tmp_path / "empty")  # was {}: no shard at all
    want = pq.read_table(tmp_path / "local.parquet")
    assert [name for name, _ in _columns(got)] == want.column_names
    assert _columns(got) == _columns(read_dataset(tmp_path / "full"))
    assert all(a.shape == (0,) for a in got.values())
    # the full job's verdicts are the local engine's (form: the cone flags the
    # CLI always passes are ignored, as without --scheduler)
    local = (
        batch_force_closure(P, Nrm, mu=0.5, workers=1)
        if kind == "force"
        else batch_form_closure(P, Nrm, workers=1)
    )
    for name, a in local.to_arrays().items():
        assert read_dataset(tmp_path / "full")[name].tobytes() == a.tobytes()


def test_an_empty_job_with_metrics_writes_them_and_resumes(small_client, tmp_path):
    rng = np.random.default_rng(5)
    P, Nrm = random_grasps(rng, 3, 4, 3)
    metrics = {"metrics": ("sigma_min",)}
    out = tmp_path / "ds"
    paths = evaluate_on_cluster(small_client, P[:0], Nrm[:0], mu=0.5,
                                output_dir=out, **metrics)  # fmt: skip
    assert len(paths) == 1
    evaluate_on_cluster(small_client, P, Nrm, mu=0.5, output_dir=tmp_path / "full",
                        **metrics)  # fmt: skip
    got, full = read_dataset(out), read_dataset(tmp_path / "full")
    assert _columns(got) == _columns(full) and "sigma_min" in got
    again = evaluate_on_cluster(small_client, P[:0], Nrm[:0], mu=0.5,
                                output_dir=out, **metrics)  # fmt: skip
    assert again == paths
    result = evaluate_on_cluster(small_client, P[:0], Nrm[:0], mu=0.5, **metrics)
    assert result.metrics["sigma_min"].shape == (0,)
