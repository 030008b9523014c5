"""Joint limits that would stop Drake are refused before Drake sees them.

Drake stops the whole process on such a joint (a failed internal condition,
not an exception): ``drakegrasp plan --hand`` printed Drake's failure text
instead of one line.
"""

from __future__ import annotations

import subprocess
import sys

import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from drakegrasp.errors import ModelError
from drakegrasp.plant.couplings import add_models
from drakegrasp.plant.scene import load_scene

LINK = '<link name="{0}"><inertial><mass value="0.1"/><inertia ixx="1e-5" ' \
    'iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>'  # fmt: skip


def _urdf(kind="prismatic", lower="0.04", upper="0.0"):
    bounds = "".join(
        f' {k}="{v}"' for k, v in (("lower", lower), ("upper", upper)) if v is not None
    )
    limit = f'<limit{bounds} effort="1" velocity="1"/>'
    return (
        f'<robot name="r">{LINK.format("a")}{LINK.format("b")}'
        f'<joint name="slide" type="{kind}"><parent link="a"/><child link="b"/>'
        f'<axis xyz="0 1 0"/>{limit}</joint></robot>'
    )


def _sdf(lower="<lower>0.5</lower>", upper="<upper>-0.5</upper>"):
    return (
        '<sdf version="1.9"><model name="m"><link name="a"/><link name="b"/>'
        '<joint name="hinge" type="revolute"><parent>a</parent><child>b</child>'
        f"<axis><xyz>0 0 1</xyz><limit>{lower}{upper}</limit></axis></joint>"
        "</model></sdf>"
    )


_PLANTS: list = []  # a Parser does not keep its plant alive


def _parser():
    _PLANTS.append(MultibodyPlant(0.001))
    return Parser(_PLANTS[-1])


@pytest.mark.parametrize(
    "text, kind",
    [
        (_urdf(), "urdf"),
        (_urdf(kind="continuous"), "urdf"),
        (_urdf(lower="0.5abc", upper="0.25"), "urdf"),  # Drake reads 0.5
        (_sdf(), "sdf"),
    ],
)
def test_reversed_limits_are_refused_by_name(text, kind):
    with pytest.raises(ModelError, match="joint '(slide|hinge)'.*above its upper"):
        add_models(_parser(), text=text, kind=kind)


@pytest.mark.parametrize(
    "text",
    [
        _sdf(lower="<lower>nan</lower>", upper="<upper>1</upper>"),
        _sdf(lower="<lower>-1</lower>", upper="<upper> NaN</upper>"),
        _sdf(lower="<lower>0.5 0.6</lower>", upper="<upper>nan</upper>"),
    ],
)
def test_a_limit_that_is_not_a_number_is_refused(text):
    # Drake's SDFormat parser passes NaN on, and its Joint() stops the process
    with pytest.raises(ModelError, match="joint 'hinge'.*not a number"):
        add_models(_parser(), text=text, kind="sdf")


def test_reversed_limits_in_a_file_name_the_file(tmp_path):
    path = tmp_path / "hand.urdf"
    path.write_text(_urdf())
    with pytest.raises(ModelError, match="hand.urdf"):
        add_models(_parser(), path)


@pytest.mark.parametrize(
    "text, kind",
    [
        (_urdf(lower="0.0", upper="0.04"), "urdf"),
        (_sdf(lower=""), "sdf"),  # the default lower limit is -1e16
        (_sdf(lower="", upper=""), "sdf"),
        # as Drake reads them: a missing bound is none, a value its leading
        # number, the limits of a fixed joint are not read
        (_urdf(lower=None, upper="-0.5"), "urdf"),
        (_urdf(lower="1_0", upper="5"), "urdf"),
        (_urdf(kind="fixed"), "urdf"),
        (_sdf(lower="", upper="<upper>-1e17</upper>"), "sdf"),
    ],
)
def test_valid_limits_load(text, kind):
    assert add_models(_parser(), text=text, kind=kind)


def test_the_command_line_says_one_line(tmp_path):
    path = tmp_path / "jaw.urdf"
    path.write_text(_urdf())
    run = subprocess.run(
        [sys.executable, "-m", "drakegrasp", "plan", "--hand", str(path), "--num", "5"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert run.returncode != 0
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("drakegrasp: error: joint 'slide'")


def _write_ball(folder) -> None:
    """The scenes' object: a 20 mm sphere, ``ball.sdf`` in ``folder``."""
    (folder / "ball.sdf").write_text(
        '<sdf version="1.9"><model name="ball"><link name="body"><collision '
        'name="c"><geometry><sphere><radius>0.02</radius></sphere></geometry>'
        "</collision></link></model></sdf>"
    )


def test_a_scene_with_reversed_limits_is_refused_naming_scene_and_file(tmp_path):
    (tmp_path / "jaw.urdf").write_text(_urdf())
    _write_ball(tmp_path)
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        "directives:\n- add_model:\n    name: jaw\n    file: jaw.urdf\n"
        "- add_weld:\n    parent: world\n    child: jaw::a\n"
        "- add_model:\n    name: ball\n    file: ball.sdf\n"
        "drakegrasp:\n  object_body: ball::body\n  hand: jaw\n  mu: 0.5\n"
    )
    with pytest.raises(ModelError, match=r"scene.yaml.*'slide' in jaw.urdf"):
        load_scene(scene)


_INCLUDE_CHILD = """
import sys
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from drakegrasp.errors import ModelError
from drakegrasp.plant.couplings import add_models
plant = MultibodyPlant(0.001)  # a Parser does not keep its plant alive
try:
    add_models(Parser(plant), sys.argv[1])
except ModelError as e:
    print("refused:", e)
"""


def test_a_file_an_sdformat_model_includes_is_read_too(tmp_path):
    # only the top document was read: the included one stopped the process
    (tmp_path / "bad.urdf").write_text(_urdf())
    holder = tmp_path / "holder.sdf"
    holder.write_text(
        "<sdf version='1.9'><model name='holder'><link name='mount'/><include>"
        f"<uri>file://{tmp_path}/bad.urdf</uri></include></model></sdf>"
    )
    run = subprocess.run(
        [sys.executable, "-c", _INCLUDE_CHILD, str(holder)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr[-300:]  # now: Drake's Failure, exit 1
    assert run.stdout.startswith("refused: joint 'slide' in file://")
    assert "bad.urdf (included by" in run.stdout


def test_a_scene_file_its_directives_include_is_read_too(tmp_path):
    # add_directives were not followed: Drake's own failure text came out
    (tmp_path / "jaw.urdf").write_text(_urdf())
    (tmp_path / "more.yaml").write_text(
        "directives:\n- add_model:\n    name: jaw\n    file: package://here/jaw.urdf\n"
    )
    _write_ball(tmp_path)
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        "directives:\n- add_directives:\n    file: package://here/more.yaml\n"
        "- add_model:\n    name: ball\n    file: ball.sdf\n"
        "drakegrasp:\n  object_body: ball::body\n  hand: jaw\n  mu: 0.5\n"
    )
    with pytest.raises(ModelError, match=r"scene.yaml.*'slide' in jaw.urdf.*swap"):
        load_scene(scene, package_map={"here": str(tmp_path)})
