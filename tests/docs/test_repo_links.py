"""Every link of the README, the tutorials and the docs resolves inside the repo.

A public clone has nothing beside it: no ``../shared/`` folder.  These tests scan
the Markdown files, the notebook sources and the package's docstrings for
relative links and file references, and check that each resolves to a file of
the repository.  They also run each Python block of the README on its own, as a
reader who copies one block would.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

MARKDOWN = [
    ROOT / "README.md",
    *sorted((ROOT / "tutorials").glob("*.md")),
    *sorted((ROOT / "benchmarks").glob("*.md")),
    *sorted((ROOT / "models").glob("*.md")),
    *sorted(p for p in (ROOT / "docs").rglob("*.md") if "_build" not in p.parts),
]
SOURCES = [
    *sorted((ROOT / "drakegrasp").rglob("*.py")),
    *sorted((ROOT / "tutorials").glob("*.py")),
    *sorted((ROOT / "tutorials").glob("*.ipynb")),
]
LINK = re.compile(r"\]\(([^)\s]+)\)")


def _ids(paths):
    return [str(p.relative_to(ROOT)) for p in paths]


@pytest.mark.parametrize("path", MARKDOWN, ids=_ids(MARKDOWN))
def test_markdown_links_resolve_inside_the_repo(path):
    bad = []
    for target in LINK.findall(path.read_text()):
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue  # a URL or an anchor on the same page
        resolved = (path.parent / target.split("#", 1)[0]).resolve()
        if not resolved.is_relative_to(ROOT) or not resolved.exists():
            bad.append(target)
    assert not bad, f"{path.name}: links outside the repository or missing: {bad}"


@pytest.mark.parametrize("path", MARKDOWN + SOURCES, ids=_ids(MARKDOWN + SOURCES))
def test_nothing_points_at_the_shared_folder(path):
    text = path.read_text()
    # The conventions live in docs/conventions.md; no file outside the repo.
    assert "CONVENTIONS" not in text and "../shared" not in text


def test_the_conventions_page_the_docstrings_name_exists():
    assert (ROOT / "docs" / "conventions.md").is_file()
    named = [p for p in SOURCES if "docs/conventions.md" in p.read_text()]
    assert named  # the package's docstrings point there


def _readme_blocks():
    text = (ROOT / "README.md").read_text()
    return re.findall(r"```python\n(.*?)```", text, re.S)


@pytest.mark.parametrize("index", range(len(_readme_blocks())))
def test_each_readme_python_block_runs_alone(index, capsys, request):
    block = _readme_blocks()[index]
    if "drake_models" in block:
        # Drake's models: the local copy, or a skip with the reason (a fresh
        # clone without ../shared and without a network must stay green).
        request.getfixturevalue("drake_models_dir")
    exec(compile(block, f"README.md block {index + 1}", "exec"), {})


def test_the_speed_summary_has_one_source():
    """README's Speed table is the one summary: the docs include it, none copies it."""
    readme = (ROOT / "README.md").read_text()
    start, end = "<!-- speed-summary:start -->", "<!-- speed-summary:end -->"
    assert readme.count(start) == 1 and readme.count(end) == 1
    table = readme[readme.index(start) : readme.index(end)]
    assert "| what | figure |" in table
    docs = (ROOT / "docs" / "benchmarks.md").read_text()
    assert f":start-after: {start}" in docs and f":end-before: {end}" in docs
    for path in [
        ROOT / "benchmarks" / "README.md",
        *sorted((ROOT / "docs").rglob("*.md")),
    ]:
        assert "| what | figure |" not in path.read_text(), f"{path} copies the summary"
