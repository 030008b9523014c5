"""Scene files from untrusted sources: bounded YAML, checked types, confined files.

Every refusal must be a SceneError (a ModelError, hence a GraspError) that
names the key or the URL and what is valid, and must come quickly: the alias
bomb below would expand to ~1.6 GB.
"""

import os
import shutil
import time
from pathlib import Path

import pytest
from pydrake.multibody.parsing import PackageMap

from drakegrasp import GraspError, ModelError, analyze_grasp, load_scene
from drakegrasp.cli import main
from drakegrasp.errors import SceneError
from drakegrasp.plant.models import models_dir
from drakegrasp.plant.scene import DEFAULT_SCENE, read_scene_info, scene_path
from drakegrasp.plant.scene_file import MAX_DEPTH, MAX_NODES, MAX_SCENE_BYTES

DEFAULT = scene_path(DEFAULT_SCENE).read_text()


def _write(tmp_path: Path, text: str, name: str = "scene.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_alias_bomb_is_refused_fast(tmp_path, tools):
    text = tools.alias_bomb("drakegrasp: {object_body: box::box, mu: 0.5}\n")
    assert len(text) < 1300  # expanded: 12**8 strings of 100 bytes, > 40 GB
    path = _write(tmp_path, text)
    start = time.perf_counter()
    with pytest.raises(SceneError, match="anchor 'a0' at line 1") as info:
        load_scene(path)
    assert time.perf_counter() - start < 2.0
    assert "may not use anchors or aliases" in str(info.value)
    assert str(path) in str(info.value)


def test_an_alias_alone_is_refused(tmp_path):
    text = DEFAULT.replace("  mu: 0.5", "  mu: *m")
    with pytest.raises(SceneError, match="alias 'm'"):
        read_scene_info(_write(tmp_path, text))


def test_deep_nesting_and_size_limits(tmp_path):
    deep = "x: " + "[" * (MAX_DEPTH + 5) + "]" * (MAX_DEPTH + 5) + "\n"
    with pytest.raises(SceneError, match="nested deeper than"):
        read_scene_info(_write(tmp_path, deep, "deep.yaml"))
    very_deep = "x: " + "[" * 50000 + "]" * 50000 + "\n"
    with pytest.raises(SceneError):
        read_scene_info(_write(tmp_path, very_deep, "very_deep.yaml"))
    big = DEFAULT + "#" + "x" * MAX_SCENE_BYTES + "\n"
    with pytest.raises(SceneError, match="the limit is"):
        read_scene_info(_write(tmp_path, big, "big.yaml"))


def test_a_file_of_too_many_values_is_refused_fast(tmp_path):
    # 200,000 numbers fit in 1 MiB; the three readings of the file composed
    # them for about a minute before torque_limits refused their count.
    many = "[" + ", ".join(["1.0"] * 200_000) + "]"
    text = DEFAULT.replace(
        "  mu: 0.5", f"  mu: 0.5\n  load: gravity\n  torque_limits: {many}"
    )
    path = _write(tmp_path, text)
    start = time.perf_counter()
    with pytest.raises(SceneError, match=f"more than {MAX_NODES} values"):
        load_scene(path)
    assert time.perf_counter() - start < 5.0


def test_an_integer_of_too_many_digits_names_its_line(tmp_path):
    # Python's int() refuses over 4300 digits; the message said "not valid
    # YAML: ... use sys.set_int_max_str_digits()", advice for a programmer.
    path = _write(tmp_path, DEFAULT.replace("  mu: 0.5", "  mu: " + "1" * 5000))
    with pytest.raises(SceneError, match=r"integer of 5000 digits at line \d+"):
        load_scene(path)


@pytest.mark.parametrize(
    "old, new, fragment",
    [
        ("  mu: 0.5", "  mu: 0.5\n  plane: [yz]", "plane must be one of"),
        ("  mu: 0.5", "  mu: 0.5\n  plane: {a: 1}", "plane must be one of"),
        ("  mu: 0.5", "  mu: 0.5\n  1: 2", "unknown key(s) 1 in"),
        ("  mu: 0.5", "  mu: 0.5\n  [a]: 2", "not valid YAML"),
        ("  mu: 0.5", "  mu: true", "mu must be a number, got True"),
        ("  mu: 0.5", "  mu: [0.5]", "mu must be a number"),
        ("  mu: 0.5", "  mu: .nan", "mu must be finite"),
        ("object_body: box::box", "object_body: [box]", "object_body must be"),
        ("  hand: gripper", "  hand: [1, 2]", "hand must be a model-instance"),
        ("  hand: gripper", "  hand: []", "hand is an empty list"),
        ("  hand: gripper", "  hand: {a: b}", "hand must be"),
        ("contact_model: hard_finger", "contact_model: 3", "contact_model must be"),
        ("contact_model: hard_finger", "contact_model: sticky", "unknown contact"),
        ("  torsional_friction: 0.1", "  torsional_friction: x", "must be a number"),
    ],
)
def test_bad_drakegrasp_values_name_the_key(tmp_path, old, new, fragment):
    assert old in DEFAULT
    path = _write(tmp_path, DEFAULT.replace(old, new))
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert fragment in str(info.value)


@pytest.mark.parametrize(
    "content",
    [b"\x00\xff\xfe garbage", b"directives: [\n", b"\tdrakegrasp: x\n", b"- 1\n"],
)
def test_corrupt_files_are_scene_errors(tmp_path, content):
    path = tmp_path / "corrupt.yaml"
    path.write_bytes(content)
    with pytest.raises(SceneError):
        load_scene(path)


def test_scene_errors_are_model_and_grasp_errors():
    assert issubclass(SceneError, ModelError) and issubclass(SceneError, GraspError)


# -- references ----------------------------------------------------------


def _box_scene(url: str) -> str:
    return DEFAULT.replace("package://drakegrasp/objects/box.sdf", url)


def test_package_url_that_climbs_out_is_refused(tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    shutil.copy(models_dir() / "objects" / "box.sdf", outside / "evil.sdf")
    rel = os.path.relpath(outside / "evil.sdf", models_dir())
    assert rel.startswith("..")
    path = _write(tmp_path, _box_scene(f"package://drakegrasp/{rel}"))
    with pytest.raises(SceneError, match="leaves the package 'drakegrasp'"):
        load_scene(path)
    # The check is what stops it: trusted, the same file loads.
    scene = load_scene(path, allow_any_file=True)
    assert analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    with pytest.raises(SceneError, match="leaves the package"):
        load_scene(_write(tmp_path, _box_scene("package://drakegrasp/../x.sdf"), "b"))


def test_files_outside_the_scene_directory_are_refused(tmp_path):
    box = models_dir() / "objects" / "box.sdf"
    scene_dir = tmp_path / "scene"
    scene_dir.mkdir()
    with pytest.raises(SceneError, match="outside the scene's directory"):
        load_scene(_write(scene_dir, _box_scene(f"file://{box}")))
    with pytest.raises(SceneError, match="only package:// and file://"):
        load_scene(_write(scene_dir, _box_scene("https://example.com/box.sdf")))
    # A symbolic link inside the directory that points out is outside too.
    (scene_dir / "link.sdf").symlink_to(box)
    with pytest.raises(SceneError, match="outside the scene's directory"):
        load_scene(_write(scene_dir, _box_scene(f"file://{scene_dir}/link.sdf")))
    # A file in the scene's own directory is fine, by URL or relative path.
    shutil.copy(box, scene_dir / "box.sdf")
    scene = load_scene(_write(scene_dir, _box_scene(f"file://{scene_dir}/box.sdf")))
    assert scene.object_body.name() == "box"
    (scene_dir / "models").mkdir()
    shutil.copy(box, scene_dir / "models" / "box.sdf")
    scene = load_scene(_write(scene_dir, _box_scene("models/box.sdf"), "rel.yaml"))
    assert scene.object_body.name() == "box"
    with pytest.raises(SceneError, match="outside the scene's directory"):
        load_scene(_write(scene_dir, _box_scene("../scene/../box.sdf"), "up.yaml"))


def test_included_directive_files_are_checked(tmp_path):
    inner = tmp_path / "inner.yaml"
    inner.write_text(
        "directives:\n- add_model:\n    name: extra\n"
        "    file: package://drakegrasp/../../../outside/evil.sdf\n"
    )
    text = DEFAULT.replace(
        "directives:\n",
        f"directives:\n- add_directives:\n    file: file://{inner}\n",
    )
    with pytest.raises(SceneError, match="inner.yaml.*leaves the package"):
        load_scene(_write(tmp_path, text))


# -- user packages --------------------------------------------------------


@pytest.fixture
def user_package(tmp_path):
    folder = tmp_path / "mypkg_src"
    folder.mkdir()
    shutil.copy(models_dir() / "objects" / "box.sdf", folder / "box.sdf")
    (folder / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="2"><name>mypkg</name>'
        "<version>0.0.1</version><description>test</description>"
        "<maintainer email='a@b.c'>a</maintainer><license>BSD</license></package>\n"
    )
    scene = _write(tmp_path, _box_scene("package://mypkg/box.sdf"), "mine.yaml")
    return folder, scene


def test_unknown_package_says_how_to_register_it(user_package, monkeypatch):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    _, scene = user_package
    with pytest.raises(SceneError, match="unknown package 'mypkg'") as info:
        load_scene(scene)
    assert "--package mypkg=DIR" in str(info.value)
    # The advice works as written (it once named a keyword load_scene lacks).
    assert "load_scene(..., package_map={'mypkg': DIR})" in str(info.value)
    folder, _ = user_package
    assert load_scene(scene, package_map={"mypkg": folder}) is not None


@pytest.mark.parametrize("kind", ["mapping", "directory", "package_map"])
def test_user_packages(user_package, monkeypatch, kind):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    folder, scene = user_package
    if kind == "mapping":
        packages = {"mypkg": folder}
    elif kind == "directory":
        packages = [folder]
    else:
        packages = PackageMap.MakeEmpty()
        packages.Add("mypkg", str(folder))
    loaded = load_scene(scene, package_map=packages)
    report = analyze_grasp(
        loaded.plant, loaded.plant_context, **loaded.analysis_options()
    )
    shipped = load_scene(DEFAULT_SCENE)
    reference = analyze_grasp(
        shipped.plant, shipped.plant_context, **shipped.analysis_options()
    )
    assert len(report.contacts) == len(reference.contacts) == 2
    assert report.force_closure.d_star == pytest.approx(reference.force_closure.d_star)


def test_ros_package_path_is_honoured(user_package, monkeypatch, tmp_path):
    folder, scene = user_package
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"{tmp_path / 'nothing'}:{folder.parent}")
    assert load_scene(scene).object_body.name() == "box"
    with pytest.raises(SceneError, match="unknown package"):
        load_scene(scene, ros_package_path=False)


def test_bad_package_arguments(tmp_path):
    with pytest.raises(SceneError, match="is not a directory"):
        load_scene(package_map={"mypkg": tmp_path / "missing"})
    with pytest.raises(SceneError, match="holds no package.xml"):
        load_scene(package_map=[tmp_path])
    with pytest.raises(SceneError, match="built in"):
        load_scene(package_map={"drakegrasp": tmp_path})


def test_cli_package_option(user_package, monkeypatch, capsys):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    folder, scene = user_package
    assert main(["analyze", str(scene)]) == 1
    assert "unknown package 'mypkg'" in capsys.readouterr().err
    assert main(["analyze", str(scene), "--package", f"mypkg={folder}"]) == 0
    assert "box::box" in capsys.readouterr().out
    with pytest.raises(SystemExit) as info:
        main(["analyze", str(scene), "--package", "mypkg"])
    assert info.value.code == 2
    assert "NAME=DIR" in capsys.readouterr().err


def test_cli_allow_any_file(tmp_path, capsys):
    outside = tmp_path / "outside"
    outside.mkdir()
    shutil.copy(models_dir() / "objects" / "box.sdf", outside / "evil.sdf")
    rel = os.path.relpath(outside / "evil.sdf", models_dir())
    path = _write(tmp_path, _box_scene(f"package://drakegrasp/{rel}"))
    assert main(["analyze", str(path)]) == 1
    err = capsys.readouterr().err
    assert "leaves the package 'drakegrasp'" in err and err.count("\n") == 1
    assert main(["analyze", str(path), "--allow-any-file"]) == 0
    assert "box::box" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("torsion", "given"), [("", None), ("\n  torsional_friction: 0", 0.0)]
)
def test_a_files_absent_nu_is_not_given_and_its_zero_is_a_valid_nu(
    tmp_path, torsion, given
):
    text = DEFAULT.replace("  torsional_friction: 0.1\n", "").replace(
        "contact_model: hard_finger", "contact_model: soft_finger" + torsion
    )
    path = _write(tmp_path, text)
    if given is None:  # refused when read, naming the file and the key
        for read in (read_scene_info, load_scene):
            with pytest.raises(SceneError) as info:
                read(path)
            assert str(path) in str(info.value)
            assert "drakegrasp.torsional_friction is absent" in str(info.value)
        # a hard-finger file without nu: absent, not 0
        hard = DEFAULT.replace("  torsional_friction: 0.1\n", "")
        assert read_scene_info(_write(tmp_path, hard)).torsional_friction is None
        return
    info = read_scene_info(path)
    assert info.torsional_friction == given
    scene = load_scene(path)
    # nu = 0: the soft fingers act as hard ones, by either route
    report = analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    assert scene.options.torsional_friction == 0.0
    hard = analyze_grasp(
        scene.plant,
        scene.plant_context,
        **{**scene.analysis_options(), "contact_model": "hard_finger"},
    )
    assert report.force_closure.is_closure == hard.force_closure.is_closure


def test_mu_plant_in_a_scene_is_the_plants_friction(tmp_path, capsys):
    # `mu: plant` was refused ("mu must be a number") where --mu plant and
    # analyze_grasp(mu="plant") take it
    from drakegrasp import analyze_grasp
    from drakegrasp.cli import main

    path = _write(tmp_path, DEFAULT.replace("  mu: 0.5", "  mu: plant"))
    scene = load_scene(path)
    assert scene.info.mu == "plant"
    report = analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    by_name = analyze_grasp(
        scene.plant, scene.plant_context, scene.object_body, hand=scene.hand,
        mu="plant", contact_model=scene.info.contact_model,
        torsional_friction=scene.info.torsional_friction,
    )  # fmt: skip
    assert report.force_closure.is_closure == by_name.force_closure.is_closure
    assert report.force_closure.d_star == by_name.force_closure.d_star
    assert main(["analyze", str(path)]) == 0
    assert main(["plan", str(path), "--num", "10", "--top", "1"]) == 0
    assert "mu = " in capsys.readouterr().out
    with pytest.raises(SceneError, match="mu must be a number"):
        load_scene(_write(tmp_path, DEFAULT.replace("  mu: 0.5", "  mu: plants")))


@pytest.mark.parametrize(
    "tol, mm", [("0.02", "20 mm"), ("1", "1000 mm"), ("10", "10000 mm")]
)
def test_a_scene_distance_tolerance_above_ten_mm_is_refused(tmp_path, tol, mm):
    # distance_tolerance: 0.02 made the palm 15 mm below the box 4 contacts
    # and the verdict force closure, "pose: valid"
    path = _write(
        tmp_path,
        DEFAULT.replace("  mu: 0.5", f"  mu: 0.5\n  distance_tolerance: {tol}"),
    )
    for read in (load_scene, read_scene_info):
        with pytest.raises(SceneError) as info:
            read(path)
        message = str(info.value)
        assert str(path) in message and "drakegrasp.distance_tolerance" in message
        assert f"({mm}) is above the largest accepted, 0.01 m (10 mm)" in message
        assert "the unit is metres" in message
    ok = DEFAULT.replace("  mu: 0.5", "  mu: 0.5\n  distance_tolerance: 0.01")
    assert read_scene_info(_write(tmp_path, ok)).distance_tolerance == 0.01
