"""Scene files that tried to escape their folder, crash Drake or be read two ways.

Issue 21: the reference policy was enforced on PyYAML's reading of a scene while
Drake loaded its own.  Each case here is refused from Drake's reading (or
because the two readings disagree), and the outside model is never loaded:
the same scene with ``allow_any_file=True`` shows the file is otherwise
loadable, so the refusal is the check's, not a broken file's.  Include loops
ran Drake into a stack overflow (SIGSEGV), so those cases run in a child
process, which must exit cleanly with a SceneError.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from drakegrasp import load_scene
from drakegrasp.errors import SceneError
from drakegrasp.plant.models import models_dir
from drakegrasp.plant.scene import DEFAULT_SCENE, read_scene_info, scene_path
from drakegrasp.plant.scene_refs import MAX_INCLUDED_FILES

DEFAULT = scene_path(DEFAULT_SCENE).read_text()
BOX_URL = "package://drakegrasp/objects/box.sdf"


@pytest.fixture
def outside(tmp_path) -> Path:
    """A loadable model outside the scene's directory (tmp/scene)."""
    folder = tmp_path / "outside"
    folder.mkdir()
    shutil.copy(models_dir() / "objects" / "box.sdf", folder / "evil.sdf")
    (tmp_path / "scene").mkdir()
    return folder / "evil.sdf"


def _write(folder: Path, text: str, name: str = "scene.yaml") -> Path:
    path = folder / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("host", ["localhost", "evil.example.com", "127.0.0.1"])
def test_file_url_with_a_host_is_read_as_drake_reads_it(outside, host):
    scene_dir = outside.parent.parent / "scene"
    url = f"file://{host}{outside}"
    path = _write(scene_dir, DEFAULT.replace(BOX_URL, url))
    with pytest.raises(SceneError, match="outside the scene's directory"):
        load_scene(path)
    assert load_scene(path, allow_any_file=True).object_body.name() == "box"


def test_file_url_with_a_host_inside_the_scene_directory_loads(outside):
    scene_dir = outside.parent.parent / "scene"
    shutil.copy(outside, scene_dir / "box.sdf")
    url = f"file://localhost{scene_dir}/box.sdf"
    scene = load_scene(_write(scene_dir, DEFAULT.replace(BOX_URL, url)))
    assert scene.object_body.name() == "box"


@pytest.mark.parametrize("tag", ["!!set", "!!omap", "!anything", "!!map"])
def test_a_tag_on_a_directive_does_not_hide_its_file(outside, tag):
    scene_dir = outside.parent.parent / "scene"
    text = DEFAULT.replace(
        "directives:\n",
        f"directives:\n- add_model: {tag} {{name: evil, file: 'file://{outside}'}}\n",
    )
    path = _write(scene_dir, text)
    with pytest.raises(SceneError):
        load_scene(path)


@pytest.mark.parametrize("tag", ["!!set", "!anything"])
def test_a_tag_on_add_directives_does_not_hide_its_file(outside, tag):
    scene_dir = outside.parent.parent / "scene"
    inner = _write(
        outside.parent,
        f"directives:\n- add_model: {{name: evil, file: 'file://{outside}'}}\n",
        "inner.yaml",
    )
    text = DEFAULT.replace(
        "directives:\n",
        f"directives:\n- add_directives: {tag} {{file: 'file://{inner}'}}\n",
    )
    with pytest.raises(SceneError):
        load_scene(_write(scene_dir, text))


def test_a_quoted_value_across_duplicate_sections_hides_nothing(outside):
    scene_dir = outside.parent.parent / "scene"
    hidden = textwrap.dedent(
        f"""\
        drakegrasp: "x
        directives:
        - add_model: {{name: evil, file: 'file://{outside}'}}
        "
        """
    )
    path = _write(scene_dir, hidden + DEFAULT)
    with pytest.raises(SceneError, match="given twice"):
        load_scene(path)
    with pytest.raises(SceneError, match="given twice"):
        load_scene(path, allow_any_file=True)


def test_a_quoted_multi_line_value_is_cut_with_its_section(outside):
    # Not a duplicate: the directive-looking lines sit in a value of the section
    # (a double-quoted scalar folds them into one line), which the cut removes
    # whole, so Drake never reads them; the old line-based cut let them through.
    scene_dir = outside.parent.parent / "scene"
    text = DEFAULT.replace(
        '  description: "Parallel',
        f'  description: "x\ndirectives:\n- add_model: {{name: evil, file: '
        f"'file://{outside}'}}\n  Parallel",
    )
    scene = load_scene(_write(scene_dir, text))
    assert not scene.plant.HasModelInstanceNamed("evil")
    assert scene.info.description.startswith("x directives: - add_model:")


@pytest.mark.parametrize(
    "text",
    [
        "a: 1\na: 2\n",
        "drakegrasp: {mu: 0.5, mu: 0.6, object_body: box::box}\n",
        "directives:\n- add_model: {name: a, file: x, file: y}\n",
    ],
)
def test_keys_given_twice_are_refused(tmp_path, text):
    with pytest.raises(SceneError, match="given twice"):
        read_scene_info(_write(tmp_path, text))


def _child(code: str, timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**__import__("os").environ, "PYTHONPATH": str(Path.cwd())},
    )


def _load_in_child(path: Path, allow_any_file: bool) -> subprocess.CompletedProcess:
    code = textwrap.dedent(
        f"""
        import sys
        from drakegrasp import load_scene
        from drakegrasp.errors import SceneError
        try:
            load_scene({str(path)!r}, allow_any_file={allow_any_file})
        except SceneError as e:
            print("SceneError:", e)
            sys.exit(3)
        """
    )
    return _child(code)


@pytest.mark.parametrize("allow_any_file", [False, True])
def test_a_scene_that_includes_itself_is_refused_not_crashed(tmp_path, allow_any_file):
    path = tmp_path / "loop.yaml"
    path.write_text(
        DEFAULT.replace(
            "directives:\n",
            f"directives:\n- add_directives:\n    file: file://{path}\n",
        )
    )
    r = _load_in_child(path, allow_any_file)
    assert r.returncode == 3, (r.returncode, r.stderr[-2000:])
    assert "loop" in r.stdout


@pytest.mark.parametrize("allow_any_file", [False, True])
def test_two_files_including_each_other_are_refused(tmp_path, allow_any_file):
    a, b = tmp_path / "a.yaml", tmp_path / "b.yaml"
    a.write_text(f"directives:\n- add_directives:\n    file: file://{b}\n")
    b.write_text(f"directives:\n- add_directives:\n    file: file://{a}\n")
    path = _write(
        tmp_path,
        DEFAULT.replace(
            "directives:\n", f"directives:\n- add_directives:\n    file: file://{a}\n"
        ),
    )
    r = _load_in_child(path, allow_any_file)
    assert r.returncode == 3, (r.returncode, r.stderr[-2000:])
    assert "a.yaml -> b.yaml -> a.yaml" in r.stdout


def _including(tmp_path: Path, included: Path) -> Path:
    """The default scene with ``included`` added first to its directives."""
    line = f"- add_directives:\n    file: file://{included}\n"
    return _write(tmp_path, DEFAULT.replace("directives:\n", "directives:\n" + line))


@pytest.mark.parametrize("allow_any_file", [False, True])
def test_the_include_limit_counts_loads_not_files(tmp_path, allow_any_file):
    # 31 files, each including the next twice: 2**31 loads of 31 distinct files.
    n = MAX_INCLUDED_FILES - 1
    files = [tmp_path / f"f{i}.yaml" for i in range(n)]
    files[-1].write_text("directives: []\n")
    for here, nxt in zip(files, files[1:], strict=False):
        line = f"- add_directives:\n    file: file://{nxt}\n"
        here.write_text("directives:\n" + line * 2)
    path = _including(tmp_path, files[0])
    start = time.perf_counter()
    with pytest.raises(SceneError, match="loads more than"):
        load_scene(path, allow_any_file=allow_any_file)
    assert time.perf_counter() - start < 30  # loose: it used to run forever


def test_a_diamond_within_the_limit_still_loads_each_time(tmp_path):
    empty = _write(tmp_path, "directives: []\n", "empty.yaml")
    line = f"- add_directives:\n    file: file://{empty}\n"
    path = _write(
        tmp_path, DEFAULT.replace("directives:\n", "directives:\n" + line * 3)
    )
    assert load_scene(path).object_body.name() == "box"


@pytest.mark.parametrize("allow_any_file", [False, True])
def test_included_files_refuse_aliases_even_when_trusted(
    tmp_path, allow_any_file, tools
):
    bomb = _write(tmp_path, tools.alias_bomb("directives: []\n"), "bomb.yaml")
    path = _including(tmp_path, bomb)
    start = time.perf_counter()
    with pytest.raises(SceneError, match="alias|anchor"):
        load_scene(path, allow_any_file=allow_any_file)
    assert time.perf_counter() - start < 30


@pytest.mark.parametrize(
    "mu, expected",
    [("5e-1", 0.5), ("5E-1", 0.5), ("1e0", 1.0), ("+.5", 0.5), ("1", 1.0), ("05", 5.0)],
)
def test_numbers_are_read_as_yaml_1_2(tmp_path, mu, expected):
    text = DEFAULT.replace("  mu: 0.5", f"  mu: {mu}\n  distance_tolerance: 1e-3")
    info = read_scene_info(_write(tmp_path, text))
    assert info.mu == expected and info.distance_tolerance == 0.001
    assert load_scene(_write(tmp_path, text, "s2.yaml")).info.mu == expected


@pytest.mark.parametrize(
    "mu", ["yes", "on", "1_000", "1:30", "2001-12-14", "0b101", "1" + "0" * 400]
)
def test_yaml_1_1_only_numbers_are_not_numbers(tmp_path, mu):
    text = DEFAULT.replace("  mu: 0.5", f"  mu: {mu}")
    with pytest.raises(SceneError, match="mu must be"):
        read_scene_info(_write(tmp_path, text))


@pytest.mark.parametrize(
    "description",
    ['"\\e[2J\\e[31mred"', '"bell\\a"', '"tab\\there"', '"rtl\\u202Eevil"', '"a\\nb"'],
)
def test_descriptions_with_terminal_escapes_are_refused(tmp_path, description):
    text = DEFAULT.replace(
        DEFAULT.split("description: ")[1].split("\n")[0], description
    )
    with pytest.raises(SceneError, match="control character"):
        read_scene_info(_write(tmp_path, text))
