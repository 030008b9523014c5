"""Arguments of the scene readers that are not what they take, refused in words.

``load_scene(3)`` raised pathlib's TypeError, ``package_map={"foo": 3}``
another, ``ros_package_path="no"`` was taken as true, a directory was "no such
file", and a file's ``mu: 1e38`` passed the file's check to be refused by the
analysis without the file's name.
"""

from __future__ import annotations

import pytest

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError, ModelError, SceneError
from drakegrasp.plant.scene import DEFAULT_SCENE, read_scene_info, scene_path

DEFAULT = scene_path(DEFAULT_SCENE).read_text()
NO_SCENE = "must be a scene file.s path or a shipped scene.s name"


@pytest.mark.parametrize(
    "scene", [3, b"parallel_jaw_box", object(), 1.5, ["parallel_jaw_box"]]
)
def test_a_scene_that_is_no_path_is_refused(scene):
    with pytest.raises(InvalidOptionError, match=NO_SCENE):
        dg.load_scene(scene)
    with pytest.raises(InvalidOptionError, match=NO_SCENE):
        read_scene_info(scene)


def test_a_directory_is_named_as_one(tmp_path):
    with pytest.raises(ModelError, match="is a directory, not a scene file"):
        dg.load_scene(tmp_path)


@pytest.mark.parametrize(
    ("packages", "said"),
    [
        ({"foo": 3}, "package 'foo': the directory must be a str"),
        ({"foo": b"/tmp"}, "package 'foo': the directory must be a str"),
        ([3], "package: the directory must be a str"),
        (5, "packages must be a PackageMap"),
        (b"/tmp", "packages must be a PackageMap"),
    ],
)
def test_packages_that_are_no_directories_are_refused(packages, said):
    with pytest.raises(SceneError, match=said):
        dg.load_scene(DEFAULT_SCENE, package_map=packages)


def test_an_empty_package_folder_is_the_current_one(tmp_path, monkeypatch):
    # As pathlib reads "" and os.path.dirname gives it for a bare file name
    # (os.path.dirname("package.xml")); the one path reader refused it.
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    from drakegrasp.plant.scene_refs import add_packages

    (tmp_path / "package.xml").write_text(
        '<package format="2"><name>here</name></package>'
    )
    monkeypatch.chdir(tmp_path)
    plant = MultibodyPlant(0.0)
    packages = add_packages(Parser(plant), {"mine": ""}, ros_package_path=False)
    assert packages.GetPath("mine") == str(tmp_path.resolve())
    plant = MultibodyPlant(0.0)
    packages = add_packages(Parser(plant), [""], ros_package_path=False)
    assert packages.GetPath("here") == str(tmp_path.resolve())


@pytest.mark.parametrize("flag", ["no", 1, None])
def test_ros_package_path_is_a_flag(flag):
    with pytest.raises(InvalidOptionError, match="ros_package_path"):
        dg.load_scene(DEFAULT_SCENE, ros_package_path=flag)


@pytest.mark.parametrize("key", ["mu", "torsional_friction"])
@pytest.mark.parametrize("value", ["1e38", "1e-13", "1.0e+13"])
def test_a_coefficient_out_of_range_is_refused_by_the_file(tmp_path, key, value):
    path = tmp_path / "scene.yaml"
    text = DEFAULT.replace(
        "  mu: 0.5", f"  mu: {value}" if key == "mu" else "  mu: 0.5"
    )
    text = text.replace(
        "  torsional_friction: 0.1",
        f"  torsional_friction: {value}"
        if key != "mu"
        else "  torsional_friction: 0.1",
    )
    path.write_text(text)
    match = rf"scene '.*scene\.yaml': drakegrasp\.{key} must be finite and 0 or in"
    with pytest.raises(SceneError, match=match):
        read_scene_info(path)


@pytest.mark.parametrize("value", ["0", "0.0", "1e-12", "1e12"])
def test_the_range_s_ends_and_zero_are_taken(tmp_path, value):
    path = tmp_path / "scene.yaml"
    path.write_text(DEFAULT.replace("  mu: 0.5", f"  mu: {value}"))
    assert read_scene_info(path).mu == float(value)


SOFT = DEFAULT.replace("contact_model: hard_finger", "contact_model: soft_finger")
SOFT_WITHOUT_NU = SOFT.replace("  torsional_friction: 0.1\n", "")


def test_the_loader_s_nu_completes_a_soft_finger_file_without_one(tmp_path):
    path = tmp_path / "soft.yaml"
    path.write_text(SOFT_WITHOUT_NU)
    with pytest.raises(
        SceneError, match=r"load_scene\(\.\.\., torsional_friction=NU\)"
    ):
        dg.load_scene(path)
    scene = dg.load_scene(path, torsional_friction=0.05)
    assert scene.options.torsional_friction == scene.info.torsional_friction == 0.05
    # and replaces a file's own
    path.write_text(SOFT)
    assert dg.load_scene(path, torsional_friction=0.0).options.torsional_friction == 0


@pytest.mark.parametrize("nu", [-1.0, float("nan"), 1e13, "0.1", True])
def test_the_loader_s_nu_is_checked(tmp_path, nu):
    path = tmp_path / "soft.yaml"
    path.write_text(SOFT_WITHOUT_NU)
    with pytest.raises(InvalidOptionError, match="torsional_friction"):
        dg.load_scene(path, torsional_friction=nu)


def test_analyze_completes_the_file_with_its_flag(tmp_path, capsys):
    from drakegrasp.cli import main

    path = tmp_path / "soft.yaml"
    path.write_text(SOFT_WITHOUT_NU)
    assert main(["analyze", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "give --torsional-friction NU" in err
    assert "load_scene" not in err
    assert main(["analyze", str(path), "--torsional-friction", "0.05"]) == 0
    assert "nu = 0.05" in capsys.readouterr().out
    assert main(["plan", str(path), "--num", "5"]) == 1  # plan has the flag too
    err = capsys.readouterr().err
    assert "load_scene" not in err and "give --torsional-friction NU" in err
