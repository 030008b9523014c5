"""The scene format's documentation runs: its examples load and analyse.

The page ``docs/scene_format.md`` and the shipped docstring of
``drakegrasp.plant.scene`` carry the same WSG-50 example; it must parse to the
same data, load with a local ``drake_models`` and give the grasp the page
describes (8 contacts, force closure).
"""

import re
import textwrap
from pathlib import Path

import pytest
import yaml

import drakegrasp.plant.scene as scene_module
from drakegrasp import analyze_grasp, load_scene
from drakegrasp.plant.models import DRAKE_MODELS_ENV
from drakegrasp.plant.scene import DEFAULT_SCENE, scene_path

ROOT = Path(__file__).resolve().parents[2]
PAGE = (ROOT / "docs" / "scene_format.md").read_text()


class _Loader(yaml.SafeLoader):
    pass


_Loader.add_multi_constructor("!", lambda loader, suffix, node: None)


def _page_yaml_after(heading: str) -> str:
    section = PAGE.split(heading, 1)[1]
    return re.search(r"```yaml\n(.*?)```", section, re.S).group(1)


def _docstring_example() -> str:
    doc = scene_module.__doc__.split("Example: Drake's WSG-50", 1)[1]
    block = doc.split("::\n\n", 1)[1]
    lines = []
    for line in block.splitlines():
        if line and not line.startswith("    "):
            break
        lines.append(line)
    return textwrap.dedent("\n".join(lines))


def test_page_and_docstring_carry_the_same_wsg_example():
    page = yaml.load(_page_yaml_after("## Example: Drake's WSG-50"), Loader=_Loader)
    doc = yaml.load(_docstring_example(), Loader=_Loader)
    assert page == doc
    assert "drake_models" in page["directives"][0]["add_model"]["file"]


def test_wsg_example_loads_and_grasps(tmp_path, drake_models_dir, monkeypatch):
    monkeypatch.setenv(DRAKE_MODELS_ENV, str(drake_models_dir))
    path = tmp_path / "wsg_box.yaml"
    path.write_text(_page_yaml_after("## Example: Drake's WSG-50"))
    scene = load_scene(path)
    report = analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    assert len(report.contacts) == 8
    assert {c.finger_body for c in report.contacts} == {
        "wsg::left_finger",
        "wsg::right_finger",
    }
    assert report.is_force_closure
    assert all(abs(c.psi) < 1e-5 for c in report.contacts)


def test_shape_of_a_file_is_the_default_scene(tmp_path):
    text = _page_yaml_after("## The shape of a file")
    page = yaml.load(text, Loader=_Loader)
    shipped = yaml.load(scene_path(DEFAULT_SCENE).read_text(), Loader=_Loader)
    assert page["directives"] == shipped["directives"]
    path = tmp_path / "shape.yaml"
    path.write_text(text)
    scene = load_scene(path)
    report = analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    assert len(report.contacts) == 2


def test_page_lists_every_drakegrasp_key():
    from drakegrasp.plant.scene_file import KEYS

    table = PAGE.split("### `drakegrasp:`", 1)[1].split("##", 1)[0]
    for key in KEYS:
        assert f"| `{key}` |" in table
    for key in KEYS:
        assert key in scene_module.__doc__


@pytest.mark.parametrize("path", ["models/README.md"])
def test_readme_points_to_the_format(path):
    assert "scene_format.md" in (ROOT / path).read_text()
