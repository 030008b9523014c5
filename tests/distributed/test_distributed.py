"""drakegrasp.distributed on a LocalCluster of 2 worker processes.

Compared bitwise with the local engine; a Parquet dataset with one shard per
partition; a rerun skips complete shards; a worker killed mid-run loses and
duplicates nothing; plant-based evaluation builds each worker's scene once.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

distributed = pytest.importorskip("distributed", reason="dask is an optional extra")
pytest.importorskip("pyarrow", reason="pyarrow is an optional extra")

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "batch"))
from batch_support import random_grasps  # noqa: E402

from drakegrasp.batch import batch_force_closure, batch_form_closure  # noqa: E402
from drakegrasp.distributed import (  # noqa: E402
    analyze_poses,
    cached_scenes,
    evaluate_on_cluster,
    read_dataset,
)


@pytest.fixture(scope="module")
def grasps():
    rng = np.random.default_rng(9000)
    K, N = 5000, 5
    P, Nrm = random_grasps(rng, K, N, 3)
    mu = rng.uniform(0.1, 0.9, (K, N))
    return P, Nrm, mu


def test_results_are_bitwise_the_local_engine(client, grasps):
    P, Nrm, mu = grasps
    local = batch_force_closure(P, Nrm, mu=mu, chunk_size=300, workers=1)
    remote = evaluate_on_cluster(client, P, Nrm, mu=mu, chunk_size=300,
                                 partition_chunks=3)  # fmt: skip
    for name, a in local.to_arrays().items():
        assert a.tobytes() == remote.to_arrays()[name].tobytes(), name
    form = evaluate_on_cluster(client, P, Nrm, kind="form", chunk_size=700)
    want = batch_form_closure(P, Nrm, chunk_size=700, workers=1)
    assert form.d_star.tobytes() == want.d_star.tobytes()


def test_positional_mu_warns_and_means_the_same(client, grasps):
    """``mu`` is keyword-only after the arrays, as in the batch functions."""
    from drakegrasp import InvalidArgumentError

    P, Nrm, mu = (a[:200] for a in grasps)
    new = evaluate_on_cluster(client, P, Nrm, mu=mu, chunk_size=100)
    with pytest.warns(DeprecationWarning, match="mu="):
        old = evaluate_on_cluster(client, P, Nrm, mu, chunk_size=100)
    assert old.d_star.tobytes() == new.d_star.tobytes()
    with pytest.raises(InvalidArgumentError, match="both by position"):
        evaluate_on_cluster(client, P, Nrm, mu, mu=mu)


def test_dask_array_input(client, grasps):
    da = pytest.importorskip("dask.array")
    P, Nrm, mu = grasps
    local = batch_force_closure(P, Nrm, mu=0.5, chunk_size=500, workers=1)
    remote = evaluate_on_cluster(client, da.from_array(P, chunks=(1000, 5, 3)),
                                 da.from_array(Nrm, chunks=(1000, 5, 3)), mu=0.5,
                                 chunk_size=500)  # fmt: skip
    assert remote.d_star.tobytes() == local.d_star.tobytes()


def test_dataset_shards_and_restart(client, grasps, tmp_path):
    P, Nrm, mu = grasps
    out = tmp_path / "ds"
    paths = evaluate_on_cluster(client, P, Nrm, mu=mu, chunk_size=250,
                                partition_chunks=4, output_dir=out)  # fmt: skip
    assert len(paths) == 5 and all(Path(p).exists() for p in paths)
    local = batch_force_closure(P, Nrm, mu=mu, chunk_size=250, workers=1)
    got = read_dataset(out)
    assert got["d_star"].tobytes() == local.d_star.tobytes()
    # a rerun recomputes only the missing shard
    Path(paths[2]).unlink()
    before = {p: os.stat(p).st_mtime_ns for p in paths if Path(p).exists()}
    again = evaluate_on_cluster(client, P, Nrm, mu=mu, chunk_size=250,
                                partition_chunks=4, output_dir=out)  # fmt: skip
    assert again == paths
    assert all(os.stat(p).st_mtime_ns == t for p, t in before.items())
    assert read_dataset(out)["d_star"].tobytes() == local.d_star.tobytes()


def test_a_worker_killed_mid_run_loses_and_duplicates_nothing(client, tmp_path):
    rng = np.random.default_rng(9100)
    K, N = 24000, 8
    P, Nrm = random_grasps(rng, K, N, 3)
    local = batch_force_closure(P, Nrm, mu=0.5, chunk_size=500, workers=1)
    out = tmp_path / "killed"
    pids = list(client.run(os.getpid).values())
    killed = []

    def kill_one():
        while not list(out.glob("part-*.parquet")):  # wait for the first shard
            time.sleep(0.05)
        os.kill(pids[0], signal.SIGKILL)
        killed.append(pids[0])

    t = threading.Thread(target=kill_one, daemon=True)
    t0 = time.perf_counter()
    t.start()
    paths = evaluate_on_cluster(client, P, Nrm, mu=0.5, chunk_size=500,
                                partition_chunks=2, output_dir=out)  # fmt: skip
    t.join(timeout=60)
    assert killed, "the worker was not killed during the run"
    print(
        f"\n{K} grasps, {len(paths)} shards, one worker killed: "
        f"{time.perf_counter() - t0:.1f} s"
    )
    assert len(paths) == len(set(paths)) == -(-K // 1000)
    assert sorted(out.glob("part-*.parquet")) == [Path(p) for p in paths]
    assert not list(out.glob(".*tmp"))  # no partial shard left behind
    got = read_dataset(out)
    assert got["d_star"].tobytes() == local.d_star.tobytes()
    client.wait_for_workers(2, timeout=60)  # the nanny restarts the worker


def test_plant_scenes_are_built_once_per_worker(client):
    from drakegrasp.plant.scene import DEFAULT_SCENE, load_scene

    scene = load_scene(DEFAULT_SCENE)
    q0 = scene.plant.GetPositions(scene.plant_context)
    Q = np.repeat(q0[None], 6, axis=0)
    got = analyze_poses(client, DEFAULT_SCENE, Q, block=2)
    from drakegrasp.plant.analysis import analyze_grasp

    want = analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    assert (got["is_force_closure"] == want.is_force_closure).all()
    np.testing.assert_allclose(got["d_star"], want.force_closure.d_star, atol=1e-9)
    loaded = client.run(cached_scenes)  # every worker loaded it at most once
    assert all(names in ([], [DEFAULT_SCENE]) for names in loaded.values())
    assert any(loaded.values())


def test_plant_side_takes_an_options_object(client):
    """``options=`` replaces the scene's; keywords change whichever is used."""
    from drakegrasp import AnalysisOptions, InvalidOptionError
    from drakegrasp.plant.analysis import analyze_grasp
    from drakegrasp.plant.scene import DEFAULT_SCENE, load_scene

    scene = load_scene(DEFAULT_SCENE)
    q0 = scene.plant.GetPositions(scene.plant_context)
    Q = np.repeat(q0[None], 2, axis=0)
    opts = scene.options.replace(mu=0.2, num_generators=4)
    want = analyze_grasp(scene.plant, scene.plant_context, scene.object_body,
                         hand=scene.hand, options=opts)  # fmt: skip
    got = analyze_poses(client, DEFAULT_SCENE, Q, options=opts)
    assert got["d_star"].tolist() == [want.force_closure.d_star] * 2
    again = analyze_poses(
        client, DEFAULT_SCENE, Q, options=scene.options.replace(mu=0.9), mu=0.2,
        num_generators=4,
    )  # fmt: skip
    assert again["d_star"].tobytes() == got["d_star"].tobytes()
    # checked before any task is sent
    with pytest.raises(InvalidOptionError, match="AnalysisOptions"):
        analyze_poses(client, DEFAULT_SCENE, Q, options={"mu": 0.2})
    with pytest.raises(InvalidOptionError, match="unknown analysis option"):
        analyze_poses(client, DEFAULT_SCENE, Q, options=AnalysisOptions(), mew=0.2)


def test_batch_side_takes_a_batch_options(client, grasps, tmp_path):
    """Bitwise the keywords' run, and the same job (a rerun resumes it)."""
    from drakegrasp import BatchOptions, InvalidOptionError

    P, Nrm, mu = (a[:300] for a in grasps)
    opts = BatchOptions(tol=1e-5, metrics=("sigma_min",), chunk_size=100)
    a = evaluate_on_cluster(client, P, Nrm, mu=mu, options=opts)
    b = evaluate_on_cluster(client, P, Nrm, mu=mu, tol=1e-5,
                            metrics=("sigma_min",), chunk_size=100)  # fmt: skip
    for name, x in a.to_arrays().items():
        assert x.tobytes() == b.to_arrays()[name].tobytes(), name
    out = tmp_path / "ds"
    first = evaluate_on_cluster(client, P, Nrm, mu=mu, options=opts, output_dir=out)
    again = evaluate_on_cluster(client, P, Nrm, mu=mu, tol=1e-5, output_dir=out,
                                metrics=("sigma_min",), chunk_size=100)  # fmt: skip
    assert again == first  # the keywords' job is the options' job
    form = evaluate_on_cluster(client, P, Nrm, kind="form", options=opts)
    ref = batch_form_closure(
        P, Nrm, tol=1e-5, metrics=("sigma_min",), chunk_size=100, workers=1
    )
    assert form.d_star.tobytes() == ref.d_star.tobytes()
    # tol and metrics reach form closure too (margin reads tol; sigma_min is there)
    assert form.to_arrays().keys() == ref.to_arrays().keys()
    for name, x in form.to_arrays().items():
        assert x.tobytes() == ref.to_arrays()[name].tobytes(), name
    with pytest.raises(InvalidOptionError, match="cannot be given on a cluster"):
        evaluate_on_cluster(client, P, Nrm, mu=mu, options=opts.replace(workers=2))
    with pytest.raises(InvalidOptionError, match="given both"):
        evaluate_on_cluster(client, P, Nrm, mu=mu, options=opts, chunk_size=50)


def test_a_length_out_of_scale_is_named_in_the_input_before_connecting(grasps):
    """With metrics, a characteristic length out of scale with its grasp was
    refused inside a Dask task, after the data had been shipped, naming the
    grasp by its place in the partition ("grasp 5" for grasp 25).  It is
    refused before connecting (no client is reached: the address is unused),
    named as the local engine names it."""
    import drakegrasp as dg

    P, Nrm, mu = grasps
    K = 40
    b = np.full(K, 0.1)
    b[25] = 1e-15
    with pytest.raises(dg.InvalidGraspError, match="grasp 25 is 1e-15 m"):
        evaluate_on_cluster(
            "tcp://127.0.0.1:1", P[:K], Nrm[:K], mu=mu[:K], chunk_size=10,
            partition_chunks=1, characteristic_lengths=b, metrics=("isotropy",),
        )  # fmt: skip
    with pytest.raises(dg.InvalidGraspError, match="grasp 25 is 1e-15 m"):
        batch_force_closure(
            P[:K], Nrm[:K], mu=mu[:K], characteristic_lengths=b, metrics=("isotropy",)
        )


@pytest.mark.parametrize("where", [25, 5])
@pytest.mark.parametrize("fault", ["length", "position"])
def test_a_dask_array_input_names_the_faulty_grasp_by_its_place_in_the_input(
    client, grasps, fault, where
):
    """A Dask array's blocks are checked inside their partitions, where the
    engine numbers grasps from the partition's start: grasp 25 was named
    "grasp 5".  The message now names it as the local engine does.  In the
    first partition (grasp 5) the error is the engine's own: re-raised from
    itself, it once made a cause cycle that Dask's traceback pickling
    followed until memory ran out."""
    da = pytest.importorskip("dask.array")
    import drakegrasp as dg

    P, Nrm, mu = grasps
    K = 40
    P = np.array(P[:K])
    b = np.full(K, 0.1)
    if fault == "length":
        b[where] = 1e-15
        error, match = dg.InvalidGraspError, rf"grasp {where} is 1e-15 m"
    else:
        P[where, 1] = np.nan
        error, match = dg.InvalidContactError, rf"position of grasp {where}, contact 1"
    kw = dict(characteristic_lengths=b, metrics=("isotropy",))
    with pytest.raises(error, match=match):
        batch_force_closure(P, Nrm[:K], mu=mu[:K], **kw)
    with pytest.raises(error, match=match) as info:
        evaluate_on_cluster(
            client, da.from_array(P, chunks=(10, -1, -1)),
            da.from_array(Nrm[:K], chunks=(10, -1, -1)), mu=mu[:K],
            chunk_size=10, partition_chunks=1, **kw,
        )  # fmt: skip
    assert info.value.__cause__ is not info.value


def test_an_iterator_of_metrics_reaches_every_partition(client, grasps):
    """The early check read ``metrics`` and left the partitions an exhausted
    iterator: the metric columns vanished without a word."""
    P, Nrm, mu = grasps
    K = 60
    kw = dict(mu=mu[:K], chunk_size=10, partition_chunks=1, characteristic_lengths=0.5)
    listed = evaluate_on_cluster(client, P[:K], Nrm[:K], metrics=["isotropy"], **kw)
    once = evaluate_on_cluster(client, P[:K], Nrm[:K], metrics=iter(["isotropy"]), **kw)
    assert list(once.metrics) == ["isotropy"]
    np.testing.assert_array_equal(once.metrics["isotropy"], listed.metrics["isotropy"])


def test_form_closure_on_a_cluster_refuses_epsilon_before_the_lengths(grasps):
    """As locally: the metric form closure cannot give is named first."""
    import drakegrasp as dg

    P, Nrm, _ = grasps
    with pytest.raises(dg.InvalidOptionError, match="'epsilon_l1' needs friction"):
        evaluate_on_cluster(
            "tcp://127.0.0.1:1", P[:20], Nrm[:20], kind="form",
            characteristic_lengths=1e-15, metrics=["epsilon_l1"],
        )  # fmt: skip


def _keys(dask_scheduler) -> list[str]:
    return [str(k) for k in dask_scheduler.tasks]


def _tasks_left(client, before: set) -> set:
    """The scheduler's tasks not in ``before``, once they settle.

    A released task leaves the scheduler shortly after its client lets it go:
    the keys are read until no new one is left or 30 s have passed.
    """
    deadline = time.monotonic() + 30.0
    left = set(client.run_on_scheduler(_keys)) - before
    while left and time.monotonic() < deadline:
        time.sleep(0.1)
        left = set(client.run_on_scheduler(_keys)) - before
    return left


@pytest.mark.parametrize("source", ["numpy", "dask"])
def test_a_failed_partition_leaves_no_task_on_the_cluster(client, source):
    """One bad grasp in the first partition of 80: the error came back at
    once, but the failed future's error (kept by Dask, and held here by
    ``pytest.raises`` as a notebook holds its last error) held the call's
    frame and so every other future: the queued partitions went on computing
    and the finished ones kept their results on the workers, never released
    until the client closed; so did the last block of a Dask array input.
    Every partition is cancelled with the error."""
    import drakegrasp as dg

    rng = np.random.default_rng(9200)
    P, Nrm = random_grasps(rng, 20000, 8, 3)
    P[3, 0, 0] = np.nan
    if source == "dask":
        da = pytest.importorskip("dask.array")
        P, Nrm = (da.from_array(a, chunks=(250, -1, -1)) for a in (P, Nrm))
    before = set(client.run_on_scheduler(_keys))
    with pytest.raises(dg.InvalidContactError, match="grasp 3, contact 0") as info:
        evaluate_on_cluster(client, P, Nrm, mu=0.5, chunk_size=250,
                            partition_chunks=1)  # fmt: skip
    assert not _tasks_left(client, before)
    del info


def test_a_failed_block_of_poses_leaves_no_task_on_the_cluster(client):
    """As above for ``analyze_poses``: a scene the workers cannot load fails
    every block, and none is left on the cluster."""
    import drakegrasp as dg

    before = set(client.run_on_scheduler(_keys))
    with pytest.raises(dg.GraspError) as info:
        analyze_poses(client, "no_such_scene_anywhere", np.zeros((40, 3)), block=1)
    assert not _tasks_left(client, before)
    del info
