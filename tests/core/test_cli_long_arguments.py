"""A huge command-line argument gets a one-line refusal of bounded length."""

from __future__ import annotations

import pytest
from cli_runs import run_cli

HUGE = "x" * 200_000


@pytest.mark.parametrize(
    "argv",
    [
        ["analyze", "--mu", HUGE],
        ["analyze", "--contact-model", HUGE],
        ["plan", "--hydroelastic", HUGE],
        ["plan", "--hand", HUGE],
        ["analyze", "--package", HUGE],
    ],
    ids=["mu", "contact-model", "modulus", "hand", "package"],
)
def test_a_huge_argument_is_refused_on_one_short_line(argv, capsys):
    status, err = run_cli(argv, capsys)
    assert status != 0
    assert err.count("\n") == 1, err[:300]
    assert len(err) <= 10_300, f"a {len(err)}-character refusal"
