"""The prose about ``drakegrasp plan`` and ``warmup`` says what the commands do.

The reference part of the CLI guide is generated from the parser; the prose
around it (README, the CLI and planning guides) is not, and it had drifted: it
said plan needs a scene whose hand is not welded (every shipped scene welds
it, and plan now frees it), said nothing of ``--mu plant`` or of the tqdm
extra that ``--progress`` needs, and described warmup's JIT route only.
"""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGES = {
    "README.md": ROOT / "README.md",
    "cli": ROOT / "docs" / "guide" / "cli.md",
    "planning": ROOT / "docs" / "guide" / "planning.md",
}


def _text(page: str) -> str:
    return " ".join(PAGES[page].read_text(encoding="utf-8").split())


@pytest.mark.parametrize("page", list(PAGES))
def test_no_page_asks_for_an_unwelded_hand(page):
    assert "The hand's base must be free" not in _text(page)


@pytest.mark.parametrize("page", list(PAGES))
def test_every_page_says_progress_needs_the_extra(page):
    assert 'pip install "drakegrasp[progress]"' in _text(page)


@pytest.mark.parametrize("page", list(PAGES))
def test_every_page_shows_mu_plant_and_shipped_scenes_for_plan(page):
    text = _text(page)
    assert "--mu M|plant" in text or "--mu plant" in text
    assert "shipped" in text and "weld" in text


@pytest.mark.parametrize("page", ["README.md", "cli"])
def test_warmup_prose_names_the_ahead_of_time_route(page):
    assert "ahead of time" in _text(page)


def _usage_block() -> str:
    from drakegrasp import cli

    doc = cli.__doc__
    return doc[doc.index("Usage::") : doc.index("Every option's default")]


def _commands():
    from drakegrasp import cli

    _, sub = cli.build_parser()
    return sub.choices


@pytest.mark.parametrize("command", ["analyze", "scenes", "batch", "warmup", "plan"])
def test_the_module_usage_names_every_option_of_each_command(command):
    """Five options of ``batch`` and seven of ``analyze`` were missing once."""
    parser = _commands()[command]
    block = _usage_block()
    line = block[block.index(f"drakegrasp {command}") :]
    nxt = line.find("drakegrasp ", 1)
    line = line if nxt < 0 else line[:nxt]
    for action in parser._actions:
        if (action.help or "").startswith("deprecated"):
            continue  # named below the usage block
        for flag in action.option_strings:
            if flag in ("-h", "--help") or flag.startswith("--no-"):
                continue
            assert flag in line, f"{command} {flag} is not in cli.py's usage"


def test_the_batch_defaults_are_the_librarys():
    import argparse

    from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS, DEFAULT_TOL

    batch = _commands()["batch"]
    by_dest = {a.dest: a for a in batch._actions if isinstance(a, argparse.Action)}
    assert by_dest["num_generators"].default == DEFAULT_NUM_GENERATORS
    assert by_dest["tol"].default == DEFAULT_TOL
    text = " ".join(batch.format_help().split())
    assert f"default {DEFAULT_NUM_GENERATORS}" in text
    assert f"default {DEFAULT_TOL:g}" in text
