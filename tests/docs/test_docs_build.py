"""The documentation site builds with no warning, and its links stay in the repo.

One Sphinx build (HTML, nitpicky, warnings as errors, ``--keep-going`` so one
run lists every problem) into a temporary directory, shared by the tests below.
It executes the guide's code cells, and renders the tutorials as the session's
tutorial runs left them (``tests/conftest.py``: each tutorial executes once, in
its short test mode, for this build and ``tests/tutorials`` alike), so a broken
example fails here.  The docstring examples
run through Sphinx's doctest builder on the same sources.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("sphinx")
pytest.importorskip("numpydoc")
pytest.importorskip("myst_nb")
pytest.importorskip("sphinxarg")

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
RUNS = "tutorial_runs"  # where the build's folder keeps the tutorial runs it renders


def _sphinx(builder: str, out: Path, **env: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "sphinx",
            "-b",
            builder,
            "-W",
            "--keep-going",
            "-n",
            "-q",
            "-d",
            str(out / "doctrees"),
            str(DOCS),
            str(out / builder),
        ],
        cwd=ROOT,
        env={**os.environ, **env},
        capture_output=True,
        text=True,
    )


def _tutorial_runs(tutorial_runs, folder: Path) -> Path:
    """Write the session's successful tutorial runs into ``folder``.

    A tutorial that needs ``drake_models`` runs only with a local copy (without
    one, docs/conf.py renders it unexecuted); a failed run is left out, so the
    build executes that tutorial itself and fails on it here too.
    """
    import nbformat

    folder.mkdir()
    for notebook in sorted((ROOT / "tutorials").glob("[0-9][0-9]_*.ipynb")):
        if tutorial_runs.needs_drake_models(notebook) and not os.environ.get(
            "DRAKEGRASP_DRAKE_MODELS"
        ):
            continue
        executed, error = tutorial_runs.run(notebook)
        if error is None:
            nbformat.write(executed, folder / notebook.name)
    return folder


@pytest.fixture(scope="module")
def built(tmp_path_factory, tutorial_runs):
    """The output directory of one HTML build (its doctrees are reused below)."""
    out = tmp_path_factory.mktemp("docs")
    runs = _tutorial_runs(tutorial_runs, out / RUNS)
    run = _sphinx("html", out, DRAKEGRASP_DOCS_EXECUTED=str(runs))
    assert run.returncode == 0, run.stdout + run.stderr
    return out


@pytest.fixture(scope="module")
def html(built):
    return built / "html"


def test_site_builds_without_warnings(html):
    assert (html / "index.html").is_file()


@pytest.mark.parametrize(
    "page",
    [
        "conventions",
        "guide/arrays",
        "guide/plant",
        "guide/real_hands",
        "scene_format",
        "guide/cli",
        "guide/batch",
        "api/index",
        "benchmarks",
        "tutorials/index",
    ],
)
def test_page_exists(html, page):
    assert (html / f"{page}.html").is_file()


def test_benchmarks_page_shows_the_scale_plot(html):
    """The log-log plot bench_scale.py writes is on the benchmarks page."""
    page = (html / "benchmarks.html").read_text()
    images = re.findall(r'<img[^>]+src="([^"]*scale[^"]*\.png)"', page)
    assert images, "benchmarks.html has no scale plot"
    source = (ROOT / "benchmarks" / "results" / "scale.png").read_bytes()
    assert (html / images[0]).read_bytes() == source


def test_every_tutorial_is_rendered_with_its_outputs(html):
    notebooks = sorted((ROOT / "tutorials").glob("[0-9][0-9]_*.ipynb"))
    assert notebooks
    models = bool(os.environ.get("DRAKEGRASP_DRAKE_MODELS"))
    for notebook in notebooks:
        if not models and "package://drake_models" in notebook.read_text():
            continue  # docs/conf.py renders it unexecuted without drake_models
        page = (html / "tutorials" / f"{notebook.stem}.html").read_text()
        assert "cell_output" in page, f"{notebook.name} rendered without outputs"
    # At least one figure (the notebooks draw with matplotlib).
    assert list((html / "_images").glob("*.png"))


def test_cli_reference_is_generated_from_the_parser(html):
    from drakegrasp.cli import build_parser

    parser, subparsers = build_parser()
    page = (html / "guide" / "cli.html").read_text()
    for name, sub in subparsers.choices.items():
        assert name in page
        for action in sub._actions:
            if action.help == argparse.SUPPRESS or action.dest == "help":
                continue
            for option in action.option_strings:
                assert option in page, f"{name} {option} missing from the CLI page"


def test_api_reference_documents_every_public_name(html):
    import drakegrasp

    text = "".join(p.read_text() for p in (html / "api").glob("*.html"))
    missing = [
        name
        for name in drakegrasp.__all__
        if name not in ("examples", "__version__")
        and f'id="{_canonical(getattr(drakegrasp, name), name)}"' not in text
    ]
    assert not missing


def test_every_public_module_has_an_api_page():
    # A module added later (by anyone) must be added to docs/api/ too.
    api = "".join(p.read_text() for p in (DOCS / "api").glob("*.rst"))
    documented = set(re.findall(r"^\.\. automodule:: (\S+)$", api, re.M))
    modules = set()
    for path in (ROOT / "drakegrasp").rglob("*.py"):
        parts = path.relative_to(ROOT).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if any(p.startswith("_") for p in parts):
            continue  # private modules and __main__
        modules.add(".".join(parts))
    assert modules - documented == set()
    # And the other way: a module moved or merged leaves no page entry behind
    # (only the full site build would see it, as an import error).
    assert documented - modules == set()


def _canonical(obj, name):
    module = getattr(obj, "__module__", None)
    qualname = getattr(obj, "__qualname__", None)
    if module and qualname:
        return f"{module}.{qualname}"
    # A constant: documented in the module the lazy table reads it from.
    import drakegrasp

    for source, names in drakegrasp._SOURCES.items():
        if name in names:
            return f"{source}.{name}"
    return name


def test_links_stay_inside_the_site(html):
    # Every relative link of every page resolves to a built file; nothing points
    # outside the repository (no ../shared, no file://).
    bad = []
    for page in html.rglob("*.html"):
        for href in re.findall(r'href="([^"#?]+)[^"]*"', page.read_text()):
            if href.startswith(("http://", "https://", "mailto:")):
                continue
            if href.startswith("file:") or not (page.parent / href).resolve().exists():
                bad.append(f"{page.relative_to(html)} -> {href}")
    assert not bad, bad[:20]


def test_docstring_examples_run(built):
    # Sphinx's doctest builder on the environment the HTML build pickled (no
    # second execution of the notebooks): every ``>>>`` example of every
    # docstring in the API reference runs and must print what it shows.  It
    # gets the same tutorial runs, so the doctrees stay current.
    run = _sphinx("doctest", built, DRAKEGRASP_DOCS_EXECUTED=str(built / RUNS))
    assert run.returncode == 0, run.stdout + run.stderr
    report = (built / "doctest" / "output.txt").read_text()
    tested = re.search(r"(\d+) tests?\b", report)
    assert tested and int(tested.group(1)) >= 4, report
    assert "0 failures in tests" in report, report
