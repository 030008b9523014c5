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
