"""``drakegrasp plan``: text, JSON and Parquet outputs, errors in one line."""

from __future__ import annotations

import json

import pytest

from drakegrasp.cli import main


def test_plan_prints_ranked_candidates(capsys):
    assert main(["plan", "--num", "60", "--top", "3", "--seed", "2"]) == 0
    out = capsys.readouterr().out
    assert "grasp candidates of box::box from 60 samples" in out
    assert out.count("  #") == 3


def test_plan_json_is_the_result_cut_to_top(capsys):
    assert main(["plan", "cylinder", "--num", "40", "--top", "2", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["num_sampled"] == 40 and len(data["candidates"]) <= 2
    kept = data["num_sampled"] - sum(data["rejections"].values())
    assert kept >= len(data["candidates"])


def test_plan_parquet_round_trip(tmp_path, capsys):
    pq = pytest.importorskip("pyarrow.parquet")
    out = tmp_path / "plan.parquet"
    assert main(["plan", "--num", "40", "--out", str(out)]) == 0
    table = pq.read_table(out).to_pydict()
    n = int(capsys.readouterr().out.split()[1])
    assert len(table["score"]) == n
    assert table["score"] == sorted(table["score"], reverse=True)
    assert {"p_WH_0", "R_WH_8", "q_hand_1"} <= set(table)


def test_plan_errors_are_one_line(capsys, tmp_path):
    assert main(["plan", "no_such_object", "--num", "5"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("drakegrasp: error:") and err.count("\n") == 1
    assert main(["plan", "--num", "5", "--out", str(tmp_path / "x.csv")]) == 1
    assert ".parquet" in capsys.readouterr().err
    assert main(["plan", "--num", "-3"]) == 1
    assert "num_candidates" in capsys.readouterr().err
