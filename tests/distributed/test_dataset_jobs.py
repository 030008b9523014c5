"""Hostile inputs to the Dask driver (issue 21): jobs, shards, options, poses.

A dataset directory resumes only its own job; truncated or foreign shards are
computed again and never read raw; options are validated before any task;
per-grasp friction follows the local engine's shape rules whatever the
partitions; plant configurations Drake would die on are refused clearly.
Every verdict is compared bitwise with the local engine.
"""

from __future__ import annotations

import gc
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("distributed", reason="dask is an optional extra")
pytest.importorskip("pyarrow", reason="pyarrow is an optional extra")

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "batch"))
from batch_support import random_grasps  # noqa: E402

from drakegrasp import BatchFileError, GraspError, InvalidOptionError  # noqa: E402
from drakegrasp.batch import batch_force_closure  # noqa: E402
from drakegrasp.cli import main  # noqa: E402
from drakegrasp.distributed import (  # noqa: E402
    analyze_poses,
    evaluate_on_cluster,
    read_dataset,
)
from drakegrasp.distributed.dataset import MANIFEST, write_shard  # noqa: E402


def _grasps(seed, K, N=3):
    rng = np.random.default_rng(seed)
    P, Nrm = random_grasps(rng, K, N, 3)
    return P, Nrm, rng.uniform(0.2, 0.9, (K, N))


def _same(got: dict, want) -> None:
    arrays = want.to_arrays()
    assert sorted(got) == sorted(arrays)
    for name, a in arrays.items():
        assert got[name].tobytes() == a.tobytes(), name


def test_scheduler_reads_the_files_mu_array(client, tmp_path, capsys):
    # "got multiple values for argument 'mu'" for the documented input file.
    P, Nrm, mu = _grasps(1, 200)
    path = tmp_path / "g.npz"
    np.savez(path, positions=P, normals=Nrm, mu=mu)
    out = tmp_path / "ds"
    address = client.scheduler.address
    assert main(["batch", str(path), str(out), "--scheduler", address]) == 0
    _same(read_dataset(out), batch_force_closure(P, Nrm, mu=mu, workers=1))
    assert "force closure of 200 grasps" in capsys.readouterr().out
    # --mu overrides the file's array, as without --scheduler: another job
    out2 = tmp_path / "ds2"
    cmd = ["batch", str(path), str(out2), "--scheduler", address, "--mu", "0.3"]
    assert main(cmd) == 0
    _same(read_dataset(out2), batch_force_closure(P, Nrm, mu=0.3, workers=1))


def test_a_rerun_resumes_only_its_own_job(client, tmp_path):
    P, Nrm, mu = _grasps(2, 53)
    out = tmp_path / "ds"
    kw = {"chunk_size": 10, "partition_chunks": 1, "output_dir": out}
    first = evaluate_on_cluster(client, P, Nrm, mu=mu, **kw)
    assert len(first) == 6 and (out / MANIFEST).exists()
    # another mu, fewer grasps, another tol, form closure: all refused
    others = [
        ((P, Nrm), {"mu": 0.5}),
        ((P[:12], Nrm[:12]), {"mu": mu[:12]}),
        ((P, Nrm), {"mu": mu, "tol": 1e-6}),
        ((P, Nrm), {"kind": "form"}),
    ]
    for args, extra in others:
        with pytest.raises(BatchFileError, match="another job"):
            evaluate_on_cluster(client, *args, **kw, **extra)
    assert sorted(p.name for p in out.glob("part-*")) == [Path(p).name for p in first]
    # with overwrite the 12-grasp job replaces the 53-grasp one entirely
    evaluate_on_cluster(client, P[:12], Nrm[:12], mu=mu[:12], overwrite=True, **kw)
    _same(read_dataset(out), batch_force_closure(P[:12], Nrm[:12], mu=mu[:12]))
    assert len(list(out.glob("part-*.parquet"))) == 2


def test_a_finished_run_removes_the_temporaries_of_killed_writers(client, tmp_path):
    # A worker killed mid-write leaves ``.part-j.parquet.<pid>.tmp``; the CI
    # caught one surviving a run whose shard j had been rewritten elsewhere.
    P, Nrm, mu = _grasps(3, 40)
    out = tmp_path / "ds"
    kw = {"chunk_size": 10, "partition_chunks": 1, "output_dir": out}
    first = evaluate_on_cluster(client, P, Nrm, mu=mu, **kw)
    orphans = [out / ".part-00001.parquet.4242.tmp", out / ".part-00003.parquet.7.tmp"]
    for p in orphans:
        p.write_bytes(b"PAR1 half a shard")
    Path(first[1]).unlink()  # a rerun recomputes shard 1 and skips shard 3
    stranger = out / ".part-00009.parquet.5.tmp"  # no partition of this job
    stranger.write_bytes(b"")
    again = evaluate_on_cluster(client, P, Nrm, mu=mu, **kw)
    assert again == first
    assert not any(p.exists() for p in orphans)
    assert stranger.exists()  # only this job's partitions are swept
    _same(read_dataset(out), batch_force_closure(P, Nrm, mu=mu, workers=1))


def test_the_cli_replaces_another_job_only_with_overwrite(client, tmp_path, capsys):
    P, Nrm, mu = _grasps(3, 53)
    big, small = tmp_path / "big.npz", tmp_path / "small.npz"
    np.savez(big, positions=P, normals=Nrm, mu=mu)
    np.savez(small, positions=P[:12], normals=Nrm[:12], mu=mu[:12])
    out = tmp_path / "ds"
    cmd = ["--scheduler", client.scheduler.address, "--chunk-size", "10"]
    assert main(["batch", str(big), str(out), *cmd]) == 0
    capsys.readouterr()
    assert main(["batch", str(small), str(out), *cmd]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "another job" in err and "--overwrite" in err
    assert main(["batch", str(small), str(out), *cmd, "--overwrite"]) == 0
    printed = capsys.readouterr().out
    assert "force closure of 12 grasps" in printed  # this run's summary
    _same(read_dataset(out), batch_force_closure(P[:12], Nrm[:12], mu=mu[:12]))


def test_shards_without_a_manifest_are_refused(client, tmp_path):
    P, Nrm, mu = _grasps(4, 40)
    out = tmp_path / "ds"
    out.mkdir()
    write_shard(out / "part-00000.parquet", {"d_star": np.zeros(3)}, "old")
    with pytest.raises(BatchFileError, match="unknown job"):
        evaluate_on_cluster(client, P, Nrm, mu=mu, output_dir=out)
    evaluate_on_cluster(client, P, Nrm, mu=mu, output_dir=out, overwrite=True)
    _same(read_dataset(out), batch_force_closure(P, Nrm, mu=mu))


def test_truncated_and_foreign_shards_are_computed_again(client, tmp_path):
    P, Nrm, mu = _grasps(5, 60)
    kw = {"chunk_size": 10, "partition_chunks": 2}
    out, other = tmp_path / "ds", tmp_path / "other"
    paths = evaluate_on_cluster(client, P, Nrm, mu=mu, output_dir=out, **kw)
    evaluate_on_cluster(client, P, Nrm, mu=0.5, output_dir=other, **kw)
    # a truncated shard, and a shard of another job under the right name
    data = Path(paths[0]).read_bytes()
    Path(paths[0]).write_bytes(data[: len(data) // 2])
    shutil.copy(other / "part-00001.parquet", paths[1])
    with pytest.raises(BatchFileError, match="truncated"):
        read_dataset(out)
    untouched = Path(paths[2]).stat().st_mtime_ns
    again = evaluate_on_cluster(client, P, Nrm, mu=mu, output_dir=out, **kw)
    assert again == paths
    assert Path(paths[2]).stat().st_mtime_ns == untouched  # a good shard is kept
    _same(read_dataset(out), batch_force_closure(P, Nrm, mu=mu))
    shutil.copy(other / "part-00001.parquet", paths[1])
    with pytest.raises(BatchFileError, match="another job"):
        read_dataset(out)
    evaluate_on_cluster(client, P, Nrm, mu=mu, output_dir=out, **kw)
    _same(read_dataset(out), batch_force_closure(P, Nrm, mu=mu))
    # a missing shard is named, not silently skipped
    Path(paths[1]).unlink()
    with pytest.raises(BatchFileError, match="incomplete"):
        read_dataset(out)


def test_read_dataset_orders_shards_by_number(tmp_path):
    # A legacy dataset (no manifest): part-100000 follows part-99999.
    write_shard(tmp_path / "part-99999.parquet", {"d_star": np.array([1.0])}, "j")
    write_shard(tmp_path / "part-100000.parquet", {"d_star": np.array([2.0])}, "j")
    assert read_dataset(tmp_path)["d_star"].tolist() == [1.0, 2.0]
    with pytest.raises(BatchFileError, match="does not exist"):
        read_dataset(tmp_path / "nowhere")


@pytest.mark.parametrize("bad", [-1, 0, 0.5, True, "2", None])
def test_partition_chunks_is_validated(client, bad):
    P, Nrm, _ = _grasps(6, 20)
    with pytest.raises(InvalidOptionError, match="partition_chunks"):
        evaluate_on_cluster(client, P, Nrm, mu=0.5, partition_chunks=bad)


def test_options_the_cluster_decides_are_refused(client):
    P, Nrm, _ = _grasps(6, 20)
    with pytest.raises(InvalidOptionError, match="workers"):
        evaluate_on_cluster(client, P, Nrm, mu=0.5, workers=2)


@pytest.mark.parametrize("name", ["mu", "torsional_friction"])
def test_per_grasp_friction_whatever_the_last_partition(client, name):
    # K = 23, partitions of 10: the last holds 3 = N grasps, where a (3,) slice
    # would be ambiguous; the whole (K,) array is not, as the local engine says.
    P, Nrm, _ = _grasps(7, 23)
    per_grasp = np.random.default_rng(8).uniform(0.2, 0.8, 23)
    mu = per_grasp if name == "mu" else 0.5
    extra = {}
    if name == "torsional_friction":
        extra = {"contact_model": "soft_finger", "torsional_friction": per_grasp}
    want = batch_force_closure(P, Nrm, mu=mu, workers=1, **extra)
    got = evaluate_on_cluster(client, P, Nrm, mu=mu, chunk_size=10,
                              partition_chunks=1, **extra)  # fmt: skip
    _same(got.to_arrays(), want)
    # K == N: the same refusal as the local engine's
    P3, N3 = P[:3], Nrm[:3]
    value = per_grasp[:3]
    args = (value, {}) if name == "mu" else (0.5, {**extra, name: value})
    with pytest.raises(InvalidOptionError, match="ambiguous"):
        batch_force_closure(P3, N3, mu=args[0], **args[1])
    with pytest.raises(InvalidOptionError, match="ambiguous"):
        evaluate_on_cluster(client, P3, N3, mu=args[0], **args[1])


@pytest.mark.parametrize("bad", [-1, 0, 0.5, True, None])
def test_analyze_poses_validates_block(client, bad):
    with pytest.raises(InvalidOptionError, match="block"):
        analyze_poses(client, "wsg_box", np.zeros((2, 9)), block=bad)


def test_analyze_poses_refuses_bad_configurations_clearly(client):
    from drakegrasp.plant.scene import DEFAULT_SCENE, load_scene

    scene = load_scene(DEFAULT_SCENE)
    q0 = scene.plant.GetPositions(scene.plant_context)
    nan = np.repeat(q0[None], 3, axis=0)
    nan[1, 0] = np.nan
    with pytest.raises(InvalidOptionError, match="configuration 1 is not finite"):
        analyze_poses(client, DEFAULT_SCENE, nan)
    for bad in (np.zeros(len(q0)), np.zeros((2, 2, len(q0))), [["a"] * len(q0)]):
        with pytest.raises(InvalidOptionError, match="shape"):
            analyze_poses(client, DEFAULT_SCENE, bad)
    short = np.repeat(q0[None, :-1], 2, axis=0)
    # the worker refuses it (Drake's SystemExit would kill the task)
    with pytest.raises(GraspError, match=f"has {len(q0)} positions"):
        analyze_poses(client, DEFAULT_SCENE, short)
    empty = analyze_poses(client, DEFAULT_SCENE, np.zeros((0, len(q0))))
    assert {k: v.shape for k, v in empty.items()} == {
        "is_force_closure": (0,),
        "d_star": (0,),
        "num_contacts": (0,),
        "error": (0,),
    }


def test_analyze_poses_gives_a_refused_configuration_its_own_row(client):
    # The first configuration without contact used to end the whole job.
    from drakegrasp import analyze_grasp
    from drakegrasp.plant.scene import DEFAULT_SCENE, load_scene

    scene = load_scene(DEFAULT_SCENE)
    q0 = scene.plant.GetPositions(scene.plant_context)
    q = np.repeat(q0[None], 3, axis=0)
    q[1, :2] = 0.035  # fingers open: no contact
    q[2, 0] = 0.022  # a finger 3 mm inside the box: an impossible pose
    got = analyze_poses(client, DEFAULT_SCENE, q, block=2)
    assert got["error"][0] == ""
    assert got["error"][1].startswith("NoContactsError: ")
    assert got["error"][2].startswith("PenetrationError: ")
    assert got["is_force_closure"].tolist()[1:] == [False, False]
    assert np.isnan(got["d_star"][1:]).all() and got["num_contacts"][1:].tolist() == [
        0,
        0,
    ]
    scene.plant.SetPositions(scene.plant_context, q[0])
    want = analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    assert got["d_star"][0] == want.force_closure.d_star
    assert got["is_force_closure"][0] == want.is_force_closure


@pytest.mark.parametrize(
    "bad", [None, 5, object(), "nonsense", "", "127.0.0.1:99999", "tcp://h:70000"]
)
def test_a_client_that_is_none_is_refused_at_once(bad):
    # None or a number failed later with a raw AttributeError; a malformed
    # address raised Dask's ValueError, a port out of range waited 30 s.
    P, Nrm, _ = _grasps(6, 4)
    with pytest.raises(InvalidOptionError, match="client must be|scheduler"):
        evaluate_on_cluster(bad, P, Nrm, mu=0.5)
    with pytest.raises(InvalidOptionError, match="client must be|scheduler"):
        analyze_poses(bad, "parallel_jaw_box", np.zeros((1, 9)))


def test_a_failed_connection_leaves_no_client_for_a_later_collection():
    # A half-made Client collected later, inside another Client's start, deadlocked
    # the suite (its close waits on the loop lock that the start holds).
    distributed = pytest.importorskip("distributed")
    from drakegrasp.distributed.client import client_for

    def clients():
        return sum(isinstance(o, distributed.Client) for o in gc.get_objects())

    gc.collect()
    before = clients()
    for address in ("nonsense", "also nonsense"):
        with pytest.raises(InvalidOptionError):
            client_for(address)
    assert clients() == before


def test_an_unreachable_scheduler_leaves_no_directory(tmp_path, monkeypatch):
    # The output used to be created before connecting: an empty directory
    # named like the output was left behind by every failed connection.
    from drakegrasp.distributed import batch_side

    def refuse(_client):
        raise GraspError("cannot reach the scheduler at tcp://nowhere:1")

    monkeypatch.setattr(batch_side, "connected", refuse)
    P, Nrm, mu = _grasps(3, 20)
    out = tmp_path / "nested" / "ds"
    with pytest.raises(GraspError, match="cannot reach"):
        evaluate_on_cluster("tcp://nowhere:1", P, Nrm, mu=mu, output_dir=out)
    assert not (tmp_path / "nested").exists()


def test_a_foreign_dataset_is_refused_before_connecting(tmp_path, monkeypatch):
    from drakegrasp.distributed import batch_side

    def unexpected(_client):
        raise AssertionError("connected before checking the output")

    out = tmp_path / "ds"
    out.mkdir()
    (out / MANIFEST).write_text('{"job": "another"}')
    monkeypatch.setattr(batch_side, "connected", unexpected)
    P, Nrm, mu = _grasps(4, 20)
    with pytest.raises(BatchFileError, match="overwrite=True"):
        evaluate_on_cluster("tcp://nowhere:1", P, Nrm, mu=mu, output_dir=out)
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST]


@pytest.mark.parametrize("where", ["under a file", "dangling link"])
def test_an_output_that_cannot_be_made_is_refused_before_connecting(
    tmp_path, monkeypatch, where
):
    from drakegrasp.distributed import batch_side

    def unexpected(_client):
        raise AssertionError("connected before checking the output")

    monkeypatch.setattr(batch_side, "connected", unexpected)
    if where == "under a file":
        (tmp_path / "afile").write_text("")
        out, says = tmp_path / "afile" / "ds", "is not a directory"
    else:
        out, says = tmp_path / "link", "symbolic link to nothing"
        out.symlink_to(tmp_path / "gone")
    P, Nrm, mu = _grasps(5, 10)
    with pytest.raises(BatchFileError, match=says):
        evaluate_on_cluster("tcp://nowhere:1", P, Nrm, mu=mu, output_dir=out)
