"""ε L1 as a stage after the LP: neither stage imports the other; the API joins them."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from drakegrasp.batch.api import force_chunk_with_epsilon, with_epsilon
from drakegrasp.batch.epsilon.routes import epsilon_l1_batch
from drakegrasp.batch.run.chunk import force_chunk, force_task
from drakegrasp.errors import InvalidOptionError

OPTIONS = dict(
    contact_model="hard_finger", num_generators=8, tol=1e-6, rank_tol=1e-9,
    kernel="numpy",
)  # fmt: skip


def _chunk(K=40, N=3, seed=3):
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(K, N, 3)) * 0.05
    Nrm = -P / np.linalg.norm(P, axis=2, keepdims=True)
    return P, Nrm, np.full((K, N), 0.5), np.zeros((K, N)), np.zeros((K, 3))


def test_the_lp_chunk_refuses_epsilon_instead_of_dropping_it():
    P, Nrm, mu, nu, p = _chunk()
    with pytest.raises(InvalidOptionError, match="with_epsilon"):
        force_chunk(P, Nrm, mu, nu, p, None, metrics=("epsilon_l1",), **OPTIONS)


def test_the_api_adds_the_epsilon_stage_to_the_lp_chunk_unchanged():
    P, Nrm, mu, nu, p = _chunk()
    metrics = ("sigma_min", "epsilon_l1", "isotropy")
    both = force_chunk_with_epsilon(P, Nrm, mu, nu, p, None, metrics=metrics, **OPTIONS)
    lp = force_chunk(P, Nrm, mu, nu, p, None, metrics=metrics[::2], **OPTIONS)
    assert list(both) == [*lp, "epsilon_l1"]
    for name, value in lp.items():
        np.testing.assert_array_equal(both[name], value)
    b = np.linalg.norm(P - p[:, None], axis=2).max(axis=1)
    eps = epsilon_l1_batch(
        P, Nrm, mu, nu, p, b, contact_model="hard_finger", num_generators=8,
        kernel="numpy",
    )  # fmt: skip
    np.testing.assert_allclose(both["epsilon_l1"], eps, rtol=1e-12)
    assert np.any(both["epsilon_l1"] > 0)


def test_with_epsilon_keeps_the_task_arguments():
    P, Nrm, mu, nu, p = _chunk()
    task, options = force_task(
        P, 0.5, "hard_finger", 8, None, None, None, 1e-6, 1e-9, ("epsilon_l1",),
        "numpy",
    )  # fmt: skip
    sl = slice(0, len(P))
    fn, args, opts = with_epsilon(task)(P, Nrm, sl)
    plain_fn, plain_args, plain_opts = task(P, Nrm, sl)
    assert fn is force_chunk_with_epsilon and plain_fn is force_chunk
    assert opts is plain_opts
    for a, b in zip(args, plain_args, strict=True):
        if a is None:
            assert b is None
        else:
            np.testing.assert_array_equal(a, b)
    assert set(fn(*args, **opts)) >= {"is_closure", "d_star", "epsilon_l1"}


def _reached(graph, start):
    seen, todo = set(), [start]
    while todo:
        for module in graph.get(todo.pop(), ()):
            if module not in seen:
                seen.add(module)
                todo.append(module)
    return seen


def _import_graph():
    spec = importlib.util.spec_from_file_location(
        "_architecture", Path(__file__).resolve().parents[1] / "test_architecture.py"
    )
    architecture = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(architecture)
    return architecture.graph()


def test_the_lp_chunk_and_its_verdict_only_run_import_nothing_of_epsilon():
    # Every import counts, function-level ones too: the chunk once reached the
    # Qhull route of quality.epsilon through batch.metrics.
    reached = _reached(_import_graph(), "drakegrasp.batch.run.chunk")
    assert "drakegrasp.batch.run.stream" in reached  # force_verdicts' stream
    assert not {m for m in reached if ".epsilon" in m or ".quality" in m}


def test_the_epsilon_stage_imports_nothing_of_the_lp():
    graph = _import_graph()
    reached = _reached(graph, "drakegrasp.batch.epsilon.routes")
    assert "drakegrasp.batch.epsilon.kernel" in reached  # the walk sees its imports
    assert not {m for m in reached if ".batch.run" in m or ".batch.lp" in m}
    # The API is where they meet.
    assert {"drakegrasp.batch.run.chunk", "drakegrasp.batch.epsilon.routes"} <= graph[
        "drakegrasp.batch.api"
    ]


def test_the_verdict_only_run_loads_nothing_of_epsilon():
    code = (
        "import sys; from drakegrasp.batch.run.chunk import force_verdicts; "
        "print(sorted(m for m in sys.modules if 'epsilon' in m or 'quality' in m))"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "[]"
