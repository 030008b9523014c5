"""Generated hostile inputs for the Dask driver (``drakegrasp.distributed``).

The sandbox worker keeps one in-process Dask cluster (one worker thread) and
runs each case there: random batches (1..40 grasps of 2..4 contacts) with a
random friction shape (scalar, per grasp, per contact, wrong), partitioning
(``partition_chunks`` and ``chunk_size``, valid or hostile), clients that
are none (``None``, numbers, malformed addresses), options (valid,
hostile, or decided by the cluster), and dataset directories put through
reruns of the same job, of another job with or without ``overwrite``, of a
subset of the grasps, with a truncated or a foreign shard; and
``analyze_poses`` with hostile configurations and blocks.

The independent route is the local engine, bit for bit: every result and
every dataset read back must equal ``batch_force_closure`` (or
``batch_form_closure``) of the same inputs in the worker process, and every
``analyze_poses`` row must equal ``analyze_grasp`` of that configuration.
"""

from __future__ import annotations

import math
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
from fuzz_cases import Case
from hostile import opaque, pick
from sandbox import Sandbox

_CLIENT = []


def _client():
    if not _CLIENT:
        import distributed

        _CLIENT.append(
            distributed.Client(
                processes=False,
                n_workers=1,
                threads_per_worker=1,
                dashboard_address=None,
            )
        )
    return _CLIENT[0]


def _batch(seed: int, K: int, N: int, d: int):
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(K, N, d))
    P /= np.linalg.norm(P, axis=2, keepdims=True)
    return P, -P + 0.6 * rng.normal(size=(K, N, d)), rng


def _mu(shape: str, K: int, N: int, rng):
    return {
        "scalar": 0.5,
        "grasp": rng.uniform(0.2, 0.9, K if K != N else (K, 1)),
        "contact": rng.uniform(0.2, 0.9, (K, N)),
        "wrong": rng.uniform(0.2, 0.9, K + 1),
        "nan": np.full((K, N), math.nan),
    }[shape]


def _bitwise(got: dict, want) -> str:
    arrays = want.to_arrays()
    if sorted(got) != sorted(arrays):
        return f"columns {sorted(got)} != {sorted(arrays)}"
    for name, a in arrays.items():
        if np.asarray(got[name]).tobytes() != a.tobytes():
            return f"{name} differs from the local engine"
    return ""


def dask_case(spec: dict) -> dict:
    """Worker side: one driver call (and its reruns); differences from local."""
    import drakegrasp as dg
    from drakegrasp.distributed import evaluate_on_cluster, read_dataset

    client = spec["client"] if "client" in spec else _client()
    P, Nrm, rng = _batch(spec["seed"], spec["K"], spec["N"], 3)
    mu = _mu(spec["mu"], spec["K"], spec["N"], rng)
    kind, options = spec["kind"], dict(spec["options"])

    def local(P, Nrm, mu):
        keep = {k: v for k, v in options.items() if k not in ("partition_chunks",)}
        if kind == "form":
            return dg.batch_form_closure(P, Nrm, workers=1, **keep)
        return dg.batch_force_closure(P, Nrm, mu=mu, workers=1, **keep)

    def remote(P, Nrm, mu, **extra):
        m = None if kind == "form" else mu
        return evaluate_on_cluster(client, P, Nrm, mu=m, kind=kind, **options, **extra)

    dataset = spec["dataset"]
    if dataset is None:
        return {"diff": _bitwise(remote(P, Nrm, mu).to_arrays(), local(P, Nrm, mu))}
    with tempfile.TemporaryDirectory(prefix="drakegrasp-fuzz-dask-") as tmp:
        out = Path(tmp) / "ds"
        remote(P, Nrm, mu, output_dir=out)
        shards = sorted(out.glob("part-*"))
        if dataset == "rerun":
            remote(P, Nrm, mu, output_dir=out)
        elif dataset in ("other mu", "other mu overwrite"):
            mu = np.asarray(mu) * 0.5 if kind == "force" else mu
            P = P * (1.0 if kind == "force" else 2.0) + (
                0.0 if kind == "force" else 1.0
            )
            remote(P, Nrm, mu, output_dir=out, overwrite=dataset.endswith("overwrite"))
        elif dataset == "subset":
            k = max(1, spec["K"] // 2)
            P, Nrm = P[:k], Nrm[:k]
            mu = (
                mu[:k]
                if isinstance(mu, np.ndarray) and mu.shape[0] == spec["K"]
                else mu
            )
            remote(P, Nrm, mu, output_dir=out)
        elif dataset == "truncated":
            data = shards[-1].read_bytes()
            shards[-1].write_bytes(data[: len(data) // 2])
            remote(P, Nrm, mu, output_dir=out)
        elif dataset == "foreign":
            other = Path(tmp) / "other"
            P2, N2, _ = _batch(spec["seed"] + 1, spec["K"], spec["N"], 3)
            remote(P2, N2, mu, output_dir=other)
            shutil.copyfile(sorted(other.glob("part-*"))[0], shards[0])
            remote(P, Nrm, mu, output_dir=out)
        return {"diff": _bitwise(read_dataset(out), local(P, Nrm, mu))}


def poses_case(positions, block) -> dict:
    """Worker side: ``analyze_poses`` against ``analyze_grasp`` per row."""
    import drakegrasp as dg
    from drakegrasp.distributed import analyze_poses

    got = analyze_poses(_client(), "parallel_jaw_box", positions, block=block)
    scene = dg.load_scene()
    for i, q in enumerate(np.asarray(positions, dtype=float)):
        scene.plant.SetPositions(scene.plant_context, q)
        try:
            report = dg.analyze_grasp(
                scene.plant, scene.plant_context, **scene.analysis_options()
            )
            want = (report.force_closure.is_closure, report.force_closure.d_star, "")
        except dg.GraspError as e:
            want = (False, math.nan, type(e).__name__)
        have = (
            bool(got["is_force_closure"][i]),
            float(got["d_star"][i]),
            str(got["error"][i]).partition(":")[0],
        )
        if have[::2] != want[::2] or not (
            have[1] == want[1] or (math.isnan(have[1]) and math.isnan(want[1]))
        ):
            return {"diff": f"row {i}: {have} != analyze_grasp's {want}"}
    return {"diff": ""}


_OPTIONS = {
    "partition_chunks": ((1, 2, 7), (0, -1, 0.5, True, "2", None, math.nan)),
    "chunk_size": ((None, 1, 3, 50), (0, -1, 1.5, "4", True)),
    "tol": ((1e-6, 1e-7), (math.nan, -1.0, "x")),
    "contact_model": (("hard_finger", "frictionless"), ("soft", 3)),
    "workers": ((), (1, 2, None)),
    "progress": ((), (True,)),
    "kind": (("force", "form"), ("both", None, 1)),
}
_CLIENTS = (None, 5, "nonsense", "", "127.0.0.1:99999", "tcp://:0x", opaque(), [])
_DATASETS = (
    None,
    None,
    "fresh",
    "rerun",
    "other mu",
    "other mu overwrite",
    "subset",
    "truncated",
    "foreign",
)


def _no_diff(out) -> bool:
    return out["diff"] == ""


def dask_cases(sandbox: Sandbox, seed: int = 217, count: int = 60) -> Iterator[Case]:
    """Generated Dask-driver cases (see the module docstring)."""
    rng = np.random.default_rng(seed)
    for i in range(count):
        if i % 6 == 5:
            yield _poses_case(sandbox, rng, i)
            continue
        K, N = int(rng.integers(1, 41)), int(rng.integers(2, 5))
        spec = {
            "seed": int(rng.integers(1 << 30)),
            "K": K,
            "N": N,
            "kind": "force",
            "mu": pick(rng, ("scalar", "grasp", "contact")),
            "options": {"chunk_size": int(rng.integers(1, 9))},
            "dataset": pick(rng, _DATASETS),
        }
        expect = "answer"
        r = rng.random()
        if r < 0.08:  # no client, or an address that is none
            spec["client"] = pick(rng, _CLIENTS)
            expect = "refuse"
        elif r < 0.15:
            spec["mu"] = pick(rng, ("wrong", "nan"))
            expect = "refuse"
        elif r < 0.55:
            option = pick(rng, tuple(_OPTIONS))
            good, bad = _OPTIONS[option]
            if good and rng.random() < 0.5:
                value = pick(rng, good)
            else:
                value, expect = pick(rng, bad), "refuse"
            if option == "kind":
                spec["kind"] = value
            else:
                spec["options"][option] = value
        if spec["dataset"] in ("other mu", "subset") and expect == "answer":
            expect = "refuse"  # another job in the directory, without overwrite
        name = f"K={K} N={N} mu={spec['mu']} {spec['options']} kind={spec['kind']}"
        if "client" in spec:
            name += f" client={spec['client']!r}"
        yield Case(
            "Dask driver",
            f"{name} dataset={spec['dataset']}#{i}",
            lambda spec=spec: sandbox.call("fuzz_dask:dask_case", spec),
            expect,
            _no_diff if expect == "answer" else None,
        )


def _poses_case(sandbox, rng, i) -> Case:
    P = int(rng.integers(0, 4))
    q = np.tile([0.025, 0.025, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.065], (P, 1))
    q[:, :2] += rng.uniform(-0.002, 0.01, size=(P, 2))
    block, expect = int(rng.integers(1, 4)), "answer"
    what = int(rng.integers(5))
    if what == 1 and P:
        q[int(rng.integers(P)), int(rng.integers(9))] = pick(rng, (math.nan, math.inf))
        expect = "refuse"
    elif what == 2:
        q = q[:, :-1] if P else np.zeros((1, 8))
        expect = "refuse"
    elif what == 3:
        block, expect = pick(rng, (0, -1, 0.5, True, None, "2")), "refuse"
    return Case(
        "Dask driver",
        f"analyze_poses P={P} shape={q.shape} block={block!r}#{i}",
        lambda q=q, b=block: sandbox.call("fuzz_dask:poses_case", q, b),
        expect,
        _no_diff if expect == "answer" else None,
    )
