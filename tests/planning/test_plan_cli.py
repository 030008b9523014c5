"""``drakegrasp plan``: text, JSON and Parquet outputs, errors in one line."""

from __future__ import annotations

import json
import sys

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


@pytest.mark.parametrize("argv", [["--num", "0"], ["--num", "1", "--seed", "3"]])
def test_plan_parquet_of_an_empty_result(tmp_path, capsys, argv):
    # an empty result (no samples, or all rejected) is a normal outcome: a
    # zero-row file with the columns and types of a full one, exit status 0
    pq = pytest.importorskip("pyarrow.parquet")
    full, empty = tmp_path / "full.parquet", tmp_path / "empty.parquet"
    assert main(["plan", "--num", "20", "--out", str(full)]) == 0
    assert main(["plan", *argv, "--out", str(empty)]) == 0
    assert "wrote 0 candidates" in capsys.readouterr().out
    table = pq.read_table(empty)
    assert table.num_rows == 0
    assert table.schema == pq.read_table(full).schema


def test_plan_out_refuses_an_existing_file_unless_overwrite(tmp_path, capsys):
    # --out once replaced an existing file silently (batch's policy now)
    pq = pytest.importorskip("pyarrow.parquet")
    out = tmp_path / "results.parquet"
    out.write_text("precious results")
    assert main(["plan", "--num", "5", "--out", str(out)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "exists; pass --overwrite to replace it" in err[0]
    assert out.read_text() == "precious results"
    assert main(["plan", "--num", "5", "--out", str(out), "--overwrite"]) == 0
    assert pq.read_table(out).num_rows == int(capsys.readouterr().out.split()[1])
    assert [p.name for p in tmp_path.iterdir()] == ["results.parquet"]
    assert main(["plan", "--num", "5", "--overwrite"]) == 1
    assert "--overwrite is for --out" in capsys.readouterr().err


def test_plan_out_is_written_atomically(tmp_path, capsys, monkeypatch):
    # a write that fails half-way leaves the earlier file and no partial one
    pq = pytest.importorskip("pyarrow.parquet")
    out = tmp_path / "results.parquet"
    out.write_text("precious results")

    def fail(table, where, **kw):
        with open(where, "w") as f:
            f.write("half a file")
        raise OSError("disk full")

    monkeypatch.setattr(pq, "write_table", fail)
    assert main(["plan", "--num", "5", "--out", str(out), "--overwrite"]) == 1
    assert "disk full" in capsys.readouterr().err
    assert out.read_text() == "precious results"
    assert [p.name for p in tmp_path.iterdir()] == ["results.parquet"]


def test_plan_mass_scales_the_squeeze_needed(capsys):
    # squeeze_needed is the weight over the weight capacity: linear in the mass
    runs = []
    for mass in ("0.1", "0.4"):
        argv = ["plan", "--num", "60", "--top", "3", "--json", "--mass", mass]
        assert main(argv) == 0
        runs.append(json.loads(capsys.readouterr().out)["candidates"])
    light, heavy = ([c["squeeze_needed"] for c in run] for run in runs)
    assert light and heavy == pytest.approx([4 * v for v in light], rel=1e-9)


def test_plan_torque_limit_is_for_multi_finger_hands(capsys):
    # the default hand is a parallel jaw: its squeeze is in newtons
    assert main(["plan", "--num", "20", "--torque-limit", "0.5"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--torque-limit applies to multi-finger hands" in err[0]
    assert "torque_limit" not in err[0]


def test_plan_a_multi_finger_hand_within_a_torque(
    capsys, drake_models_dir, monkeypatch
):
    monkeypatch.setenv("DRAKEGRASP_DRAKE_MODELS", str(drake_models_dir))
    allegro = (
        "package://drake_models/allegro_hand_description/sdf/"
        "allegro_hand_description_right.sdf"
    )
    argv = [
        "plan", "package://drake_models/ycb/005_tomato_soup_can.sdf",
        "--hand", allegro, "--num", "60", "--mass", "0.35",
        "--torque-limit", "0.5", "--json",
    ]  # fmt: skip
    assert main(argv) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["settings"]["torque_limit"] == 0.5
    needed = [c["torque_needed"] for c in data["candidates"] if c["is_closure"]]
    assert needed and all(v > 0 for v in needed)
    # (the ranking within the limit: tests/planning/test_motors.py)


def test_plan_errors_are_one_line(capsys, tmp_path):
    assert main(["plan", "no_such_object", "--num", "5"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("drakegrasp: error:") and err.count("\n") == 1
    assert main(["plan", "--num", "5", "--out", str(tmp_path / "x.csv")]) == 1
    assert ".parquet" in capsys.readouterr().err
    assert main(["plan", "--num", "-3"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("drakegrasp: error: --num must be") and "num_cand" not in err


_PLAN_SCENE = """
directives:
- add_model:
    name: gripper
    file: package://drakegrasp/hands/parallel_jaw_flat.sdf
- add_model:
    name: box
    file: package://drakegrasp/objects/box.sdf
    default_free_body_pose:
      box:
        translation: [0.0, 0.0, 0.1]
- add_model:
    name: table
    file: package://drakegrasp/objects/box.sdf
    default_free_body_pose:
      box:
        translation: [0.0, 0.0, {table_z}]
drakegrasp:
  description: a free flat jaw, the box, and a second box as a table under it
  object_body: box::box
  hand: gripper
  mu: 0.7
"""


def _scene_file(tmp_path, table_z):
    path = tmp_path / "plan_scene.yaml"
    path.write_text(_PLAN_SCENE.format(table_z=table_z))
    return str(path)


def test_plan_a_scene_uses_its_hand_object_mu_and_surroundings(tmp_path, capsys):
    far = _scene_file(tmp_path, -5.0)  # the second box far away: no obstacle
    assert main(["plan", far, "--num", "80", "--seed", "1", "--json"]) == 0
    alone = json.loads(capsys.readouterr().out)
    assert alone["object_body"] == "box::box" and alone["mu"] == 0.7
    assert alone["rejections"].get("hand collides with the scene", 0) == 0
    # the other box just below the object: poses from below now hit the scene
    assert main(["plan", _scene_file(tmp_path, 0.0), "--num", "80", "--seed", "1",
                 "--json", "--mu", "0.4"]) == 0  # fmt: skip
    near = json.loads(capsys.readouterr().out)
    assert near["mu"] == 0.4
    assert near["rejections"].get("hand collides with the scene", 0) > 0
    assert near["num_sampled"] == alone["num_sampled"] == 80


def test_plan_a_scene_refuses_hand(tmp_path, capsys):
    path = _scene_file(tmp_path, -5.0)
    assert main(["plan", path, "--hand", "wsg", "--num", "5"]) == 1
    assert "--hand is for an object" in capsys.readouterr().err
    # (a shipped scene, whose hand is welded to the world, plans:
    # test_plan_cli_scenes.py)


def _preshape_seen(monkeypatch):
    """The thumb's angle in the context ``plan_grasps`` receives, recorded."""
    import drakegrasp.planning as planning
    from drakegrasp.plant.validation import plant_context_of

    seen = {}
    real = planning.plan_grasps

    def spy(plant, context, *args, **kwargs):
        ctx = plant_context_of(plant, context)
        seen["joint_12"] = plant.GetJointByName("joint_12").get_angle(ctx)
        return real(plant, context, *args, **kwargs)

    monkeypatch.setattr(planning, "plan_grasps", spy)
    return seen


@pytest.mark.parametrize(
    ("extra", "angle"),
    [([], 1.0), (["--preshape", "joint_12=0.5"], 0.5),
     (["--preshape", "allegro_hand_right::joint_12=1.2"], 1.2)],
)  # fmt: skip
def test_plan_allegro_starts_with_its_thumb_opposed(
    capsys, drake_models_dir, monkeypatch, extra, angle
):
    # The model's zero is outside the thumb joint's limits: clipped, the thumb
    # lay beside the index finger (box, 100 poses: 0 force closure, now 2).
    monkeypatch.setenv("DRAKEGRASP_DRAKE_MODELS", str(drake_models_dir))
    seen = _preshape_seen(monkeypatch)
    argv = ["plan", "box", "--hand", "Allegro", "--num", "3", *extra]
    assert main(argv) == 0, capsys.readouterr().err
    assert seen["joint_12"] == angle
    assert "grasp candidates of box::box from 3 samples" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "says"),
    [
        (["--hand", "allegro", "--preshape", "joint_12=3"],
         "--preshape joint_12=3 is outside the joint's limits [0.263, 1.396]"),
        (["--hand", "allegro", "--preshape", "thumb=1"],
         "--preshape thumb: no joint of the hand is named 'thumb'"),
        (["--hand", "allegro", "--preshape", "box::joint_12=1"],
         "no joint of the hand is named 'box::joint_12'"),
        (["--hand", "wsg", "--preshape", "left_finger_sliding_joint=0.01"],
         "--preshape is for multi-finger hands"),
    ],
)  # fmt: skip
def test_plan_preshape_errors_name_the_flag(
    capsys, drake_models_dir, monkeypatch, extra, says
):
    monkeypatch.setenv("DRAKEGRASP_DRAKE_MODELS", str(drake_models_dir))
    assert main(["plan", "box", "--num", "3", *extra]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and says in err


@pytest.mark.parametrize("bad", ["joint_12", "joint_12=nan", "=1", "joint_12=inf"])
def test_plan_preshape_must_be_joint_equals_a_finite_value(capsys, bad):
    with pytest.raises(SystemExit) as exit_:
        main(["plan", "--preshape", bad])
    assert exit_.value.code == 2
    assert "expected JOINT=VALUE" in capsys.readouterr().err


def test_a_mass_whose_weight_overflows_is_refused_in_one_line(capsys):
    # --mass 1e308: m g = inf, and the plan printed "squeeze inf N per finger"
    # with exit 0 (fuzz, round 27)
    assert main(["plan", "--num", "5", "--mass", "1e308"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--mass = 1e+308 kg weighs more" in err[0], err


@pytest.mark.parametrize("argv", [["--num", "0"], ["--num", "1", "--seed", "3"]])
def test_an_empty_plan_with_scene_out_writes_no_file(tmp_path, capsys, argv):
    # --out was written, then --scene-out refused: the failed command left
    # its parquet file behind
    out, scene = tmp_path / "e.parquet", tmp_path / "e.yaml"
    assert main(["plan", *argv, "--out", str(out), "--scene-out", str(scene)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no candidate to write" in err[0]
    assert not out.exists() and not scene.exists()


def test_plan_reads_drake_models_from_package_offline(
    drake_models_dir, monkeypatch, capsys
):
    # The offline hint says "--package drake_models=DIR"; plan refused it
    # ("PackageMap::Add() cannot add 'drake_models' because the existing path
    # is remote") while analyze took it.  Now the user's folder wins.
    # (DRAKE_ALLOW_NETWORK=none would stop Drake's Parser itself: its default
    # package map registers drake_models as a download when it is made)
    monkeypatch.delenv("DRAKEGRASP_DRAKE_MODELS", raising=False)
    args = ["plan", "--hand", "wsg", "--num", "30", "--json"]
    package = f"drake_models={drake_models_dir}"
    assert main([*args, "--package", package]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["candidates"]


def test_a_package_given_two_folders_is_refused(tmp_path, capsys):
    # the last one won, silently: a scene read the other folder's files
    one, two = tmp_path / "one", tmp_path / "two"
    one.mkdir()
    two.mkdir()
    for command in (["analyze", "three_finger_sphere"], ["plan", "box"]):
        code = main([*command, "--package", f"p={one}", "--package", f"p={two}"])
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 1 and len(err) == 1, err
        assert "--package p is given twice" in err[0]
    # the same folder twice is one package
    assert main(["analyze", "three_finger_sphere", "--package", f"p={one}",
                 "--package", f"p={one}"]) == 0  # fmt: skip


def test_out_parquet_without_pyarrow_is_refused_before_planning(
    tmp_path, monkeypatch, capsys
):
    # it planned everything (7.9 s for --num 3000) and then refused
    import drakegrasp.cli as cli

    monkeypatch.setitem(sys.modules, "pyarrow", None)
    monkeypatch.setitem(sys.modules, "pyarrow.parquet", None)

    def planned(*_):
        raise AssertionError("planned before refusing --out")

    monkeypatch.setattr(cli, "_plan_setup", planned)
    assert main(["plan", "box", "--out", str(tmp_path / "c.parquet")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "drakegrasp[parquet]" in err[0], err
    assert not (tmp_path / "c.parquet").exists()
