"""A planned grasp written as a scene file analyses as planned.

``grasp_scene_text`` (and ``drakegrasp plan --scene-out``) write a
candidate as the scene ``drakegrasp analyze`` loads: the hand welded at
``X_WH`` with every joint set, the object at ``X_WO``.  The second route is
the scene loader and ``analyze_grasp`` on what it builds, against the plan's
own contacts and verdict.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest
import yaml
from coupled_hands import coupled_jaw_urdf

import drakegrasp as dg
from drakegrasp.cli import main
from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.planning.grasp_scene import grasp_scene_text
from drakegrasp.plant.models import models_dir
from drakegrasp.plant.scene import load_scene, read_scene_info

BOX = "package://drakegrasp/objects/box.sdf"
FLAT = "package://drakegrasp/hands/parallel_jaw_flat.sdf"
ALLEGRO = (
    "package://drake_models/allegro_hand_description/sdf/"
    "allegro_hand_description_right.sdf"
)
SOUP = "package://drake_models/ycb/005_tomato_soup_can.sdf"


def _plan(scene, n=40, mu=0.5):
    return plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=n, mu=mu, seed=0, robustness_samples=4,
    )  # fmt: skip


def _as_planned(tmp_path, scene, result, hand_file, object_file, top=3):
    """Each of the ``top`` best written, loaded and analysed as planned."""
    assert len(result) >= top
    for k, c in enumerate(result[:top]):
        path = tmp_path / f"grasp_{k}.yaml"
        path.write_text(
            grasp_scene_text(
                scene.plant,
                scene.context,
                c,
                object_body=scene.object_body,
                hand_file=hand_file,
                object_file=object_file,
                mu=result.mu,
                folder=tmp_path,
            )  # fmt: skip
        )
        loaded = load_scene(path)
        report = dg.analyze_grasp(
            loaded.plant, loaded.plant_context, loaded.object_body,
            hand=loaded.hand, mu=result.mu,
        )  # fmt: skip
        assert report.force_closure.is_closure == c.is_closure
        assert len(report.contacts) == len(c.contacts)
        got = np.array([p.p_OC for p in report.contacts])
        want = np.array([p.p_OC for p in c.contacts])
        np.testing.assert_allclose(got, want, atol=1e-9)
        np.testing.assert_allclose(
            loaded.plant.EvalBodyPoseInWorld(
                loaded.plant_context, loaded.object_body
            ).GetAsMatrix4(),
            c.X_WO.GetAsMatrix4(),
            atol=1e-12,
        )


def test_the_flat_jaw_on_the_box(tmp_path):
    scene = planning_scene(BOX, hand_url=FLAT)
    _as_planned(tmp_path, scene, _plan(scene), FLAT, BOX)


def test_files_by_path_are_written_relative_to_the_scene(tmp_path):
    # a one-motor jaw of one's own, in the scene's folder: found from there
    hand = tmp_path / "jaw.urdf"
    hand.write_text(coupled_jaw_urdf(offset=-0.002))
    moved = dg.planning_scene(BOX, hand_url=str(hand))
    result = _plan(moved)
    text = grasp_scene_text(
        moved.plant, moved.context, result[0], object_body=moved.object_body,
        hand_file=hand, object_file=BOX, mu=result.mu, folder=tmp_path,
    )  # fmt: skip
    assert "file: jaw.urdf" in text
    _as_planned(tmp_path, moved, result, hand, BOX)


def test_an_empty_folder_is_the_current_one(tmp_path, monkeypatch):
    # os.path.dirname("grasp.yaml") is "": the scene's folder is the current
    # one, as it was before every path went through one reader (which refused
    # "" for files and folders alike); a package's folder likewise.
    box = tmp_path / "box.sdf"
    box.write_text((models_dir() / "objects" / "box.sdf").read_text())
    monkeypatch.chdir(tmp_path)
    scene = planning_scene("package://mine/box.sdf", hand_url=FLAT,
                           package_map={"mine": ""})  # fmt: skip
    result = _plan(scene, n=10)
    texts = [
        grasp_scene_text(
            scene.plant,
            scene.context,
            result[0],
            object_body=scene.object_body,
            hand_file=FLAT,
            object_file="box.sdf",
            mu=result.mu,
            folder=folder,
        )  # fmt: skip
        for folder in (os.path.dirname("grasp.yaml"), tmp_path)
    ]
    assert texts[0] == texts[1]
    assert "file: box.sdf" in texts[0]


def test_the_allegro_hand_on_the_soup_can(tmp_path, drake_models_dir):
    scene = planning_scene(SOUP, hand_url=ALLEGRO, models_dir=drake_models_dir)
    ctx = scene.plant.GetMyMutableContextFromRoot(scene.context)
    scene.plant.GetJointByName("joint_12").set_angle(ctx, 1.0)  # thumb opposed
    _as_planned(tmp_path, scene, _plan(scene, n=60, mu=1.0), ALLEGRO, SOUP, top=2)


def test_the_command_line_writes_and_analyze_reads_it(tmp_path, capsys):
    out = tmp_path / "best.yaml"
    argv = ["plan", "--num", "40", "--top", "1", "--scene-out", str(out)]
    assert main(argv) == 0
    assert f"wrote candidate #0 to {out}" in capsys.readouterr().out
    assert main(["analyze", str(out)]) == 0
    assert "force closure: YES" in capsys.readouterr().out
    # an existing file is kept unless --overwrite
    assert main(argv) != 0
    assert "pass --overwrite" in capsys.readouterr().err
    assert main([*argv, "--overwrite"]) == 0


@pytest.mark.parametrize(
    "argv, says",
    [
        (["parallel_jaw_box"], "a scene's own file places its hand"),
        (["box", "--scene-out", "x.txt"], "must name a .yaml file"),
    ],
)
def test_the_command_line_refuses_what_it_cannot_write(tmp_path, capsys, argv, says):
    if "--scene-out" not in argv:
        argv = [*argv, "--scene-out", str(tmp_path / "x.yaml")]
    assert main(["plan", "--num", "5", *argv]) != 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and says in err[0]


def test_plan_mu_plant_is_written_as_the_number_planned(tmp_path, capsys):
    # --mu plant plans with the dynamic coefficient; a scene's mu: plant reads
    # the static one (a continuous plant): the scene held 25 % more load than
    # the plan, and than a discrete simulation, without a word
    box = tmp_path / "box.sdf"
    text = (models_dir() / "objects" / "box.sdf").read_text()
    geometry = "<geometry><box><size>0.05 0.05 0.1</size></box></geometry>\n"
    assert text.count(geometry) == 2  # collision, then visual
    box.write_text(
        text.replace(
            geometry,
            geometry + "        <drake:proximity_properties><drake:mu_dynamic>0.4"
            "</drake:mu_dynamic><drake:mu_static>1.0</drake:mu_static>"
            "</drake:proximity_properties>\n",
            1,
        )
    )
    dynamic = 2 * 0.4 * 1.0 / (0.4 + 1.0)  # Drake's combination with the pads' 1
    out = tmp_path / "best.yaml"
    argv = ["plan", str(box), "--num", "40", "--top", "1", "--mu", "plant"]
    assert main([*argv, "--scene-out", str(out)]) == 0
    capsys.readouterr()
    written = out.read_text()  # the drakegrasp: section (the rest has Drake's tags)
    section = yaml.safe_load(written[written.index("\ndrakegrasp:") :])["drakegrasp"]
    assert section["mu"] == pytest.approx(dynamic, rel=1e-12)
    assert "--mu plant's, the models' dynamic" in section["description"]
    assert main(["analyze", str(out), "--load", "gravity"]) == 0
    said = capsys.readouterr().out
    assert f"mu = {dynamic:g} is the models' dynamic friction" in said
    assert "pass mu='plant'" not in said


def test_a_scene_keeps_the_mass_planned_for(tmp_path, capsys):
    # the scene kept the model's mass: analyze --load gravity of a plan for
    # --mass 0.5 weighed the model's, and stderr said to give a wrench
    out = tmp_path / "soft.yaml"
    argv = ["plan", "cylinder", "--hand", "rounded", "--num", "60", "--top", "1",
            "--contact-model", "soft_finger", "--torsional-friction", "0.1",
            "--mass", "0.5", "--scene-out", str(out)]  # fmt: skip
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert "--mass" not in err and "characteristic-length" not in err
    info = read_scene_info(out)
    assert info.load == "gravity" and info.object_mass == 0.5
    assert main(["analyze", str(out), "--json"]) == 0
    load = json.loads(capsys.readouterr().out)["load"]
    assert load["object_mass"] == 0.5 and load["source"] == "gravity"
    assert np.linalg.norm(load["wrench"][:3]) == pytest.approx(0.5 * 9.81, rel=1e-12)
    # a wrench given on the command line replaces the weight and its mass
    assert main(["analyze", str(out), "--json", "--load", "0,0,-1,0,0,0"]) == 0
    load = json.loads(capsys.readouterr().out)["load"]
    assert load["object_mass"] is None and load["wrench"] == [0, 0, -1, 0, 0, 0]
    # the model's own mass planned for: no load written, as before
    plain = tmp_path / "plain.yaml"
    assert main([*argv[:-4], "--scene-out", str(plain)]) == 0
    capsys.readouterr()
    assert read_scene_info(plain).object_mass is None
    assert read_scene_info(plain).load is None


def test_a_massless_models_scene_keeps_the_weight_where_it_was_planned(
    tmp_path, capsys
):
    # a massless model has no centre of mass to weigh object_mass at: the
    # plan weighed it at its collision centroid (here 10 mm off the origin),
    # while load: gravity would weigh it at the origin (review)
    obj = tmp_path / "obj.urdf"
    obj.write_text(
        '<?xml version="1.0"?><robot name="box"><link name="box"><collision>'
        '<origin xyz="0.01 0 0"/><geometry><box size="0.05 0.05 0.1"/>'
        "</geometry></collision></link></robot>"
    )
    out = tmp_path / "m.yaml"
    argv = ["plan", str(obj), "--num", "40", "--top", "1", "--mass", "0.3",
            "--json", "--scene-out", str(out)]  # fmt: skip
    assert main(argv) == 0
    planned = json.loads(capsys.readouterr().out)["candidates"][0]
    info = read_scene_info(out)
    assert info.object_mass is None
    weight = np.array([0.0, 0.0, -0.3 * 9.81])  # the object as planned: O = W
    expected = np.concatenate([weight, np.cross(planned["reference_point"], weight)])
    assert planned["reference_point"][0] == pytest.approx(0.01, abs=1e-12)
    np.testing.assert_allclose(info.load, expected, rtol=1e-12, atol=1e-15)
    scene = load_scene(out)
    with pytest.raises(dg.InvalidOptionError, match="no mass, so no centre of mass"):
        dg.analyze_grasp(
            scene.plant, scene.plant_context, scene.object_body, hand=scene.hand,
            mu=0.5, load="gravity", object_mass=0.3,
        )  # fmt: skip


@pytest.mark.parametrize(
    "extra, says",
    [
        ("  object_mass: 2.0\n", "drakegrasp.object_mass (2 kg) is the mass that"),
        ("  load: gravity\n  object_mass: -2\n", "object_mass must be a finite"),
        ("  load: gravity\n  object_mass: .nan\n", "object_mass must be a finite"),
        ("  load: gravity\n  object_mass: heavy\n", "object_mass"),
        ("  load: [0, 0, -1, 0, 0, 0]\n  object_mass: 2\n", "needs load 'gravity'"),
    ],
)
def test_a_scenes_object_mass_is_checked_naming_the_key(tmp_path, extra, says):
    text = (models_dir() / "scenes" / "parallel_jaw_box.yaml").read_text()
    assert text.rstrip().splitlines()[-1].startswith("  ")  # in drakegrasp:
    path = tmp_path / "scene.yaml"
    path.write_text(text.rstrip("\n") + "\n" + extra)
    with pytest.raises(dg.SceneError) as info:
        read_scene_info(path)
    assert says in str(info.value)


def test_a_soft_finger_scene_keeps_the_planned_torsion_length(tmp_path, capsys):
    # the scene kept no torsion length: analyze of a soft-finger plan's scene
    # took the grasp's own and gave epsilon 0.04375 where the plan said 0.0900
    out = tmp_path / "soft.yaml"
    argv = ["plan", "cylinder", "--hand", "rounded", "--num", "60", "--top", "1",
            "--contact-model", "soft_finger", "--torsional-friction", "0.1",
            "--json", "--scene-out", str(out)]  # fmt: skip
    assert main(argv) == 0
    planned = json.loads(capsys.readouterr().out)["candidates"][0]
    written = out.read_text()
    section = yaml.safe_load(written[written.index("\ndrakegrasp:") :])["drakegrasp"]
    assert section["characteristic_length"] == planned["torque_scale"]
    assert main(["analyze", str(out), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["epsilon"]["epsilon"] == pytest.approx(planned["epsilon"], rel=1e-9)
    info = read_scene_info(out)
    assert info.characteristic_length == planned["torque_scale"]
    assert (
        load_scene(out).analysis_options()["characteristic_length"]
        == (planned["torque_scale"])
    )


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc")
@pytest.mark.parametrize(
    "flag, name", [("--scene-out", "x.yaml"), ("--out", "x.parquet")]
)
def test_an_unwritable_folder_is_refused_before_planning(capsys, flag, name):
    # /proc takes no new file: the plan ran first, then failed to write
    assert main(["plan", "--num", "5", flag, f"/proc/{name}"]) != 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no file can be written there" in err[0]


def test_plan_reads_its_own_packages(tmp_path, capsys):
    # --package was for scenes only: a hand's package:// URL was "unknown"
    folder = tmp_path / "mypkg"
    folder.mkdir()
    root = models_dir()
    (folder / "hand.sdf").write_text((root / "hands/parallel_jaw_flat.sdf").read_text())
    (folder / "box.sdf").write_text((root / "objects/box.sdf").read_text())
    out = tmp_path / "pk.yaml"
    argv = ["plan", "package://mypkg/box.sdf", "--hand", "package://mypkg/hand.sdf",
            "--package", f"mypkg={folder}", "--num", "30", "--top", "1",
            "--scene-out", str(out)]  # fmt: skip
    assert main(argv) == 0
    capsys.readouterr()
    assert main(["analyze", str(out), "--package", f"mypkg={folder}"]) == 0
    assert "force closure: YES" in capsys.readouterr().out
    with pytest.raises(dg.InvalidOptionError, match="is not a folder"):
        planning_scene(BOX, package_map={"mypkg": tmp_path / "none"})


def test_a_package_folder_under_home_is_read_as_a_scene_files_is(tmp_path, monkeypatch):
    # load_scene expanded "~" in a package's folder and planning_scene did
    # not: "~/mine" was "not a folder" there.  One reader does both now.
    (tmp_path / "mine").mkdir()
    box = tmp_path / "mine" / "box.sdf"
    box.write_text((models_dir() / "objects" / "box.sdf").read_text())
    monkeypatch.setenv("HOME", str(tmp_path))
    scene = planning_scene(
        "package://mine/box.sdf", hand_url=FLAT, package_map={"mine": "~/mine"}
    )
    assert scene.object_body.name() == "box"
    with pytest.raises(dg.InvalidOptionError, match="is not a folder"):
        planning_scene(BOX, hand_url=FLAT, package_map={"mine": "~/none"})
