"""``drakegrasp plan``: a name that is no shipped object or hand says what is."""

from __future__ import annotations

import pytest

from drakegrasp.cli import PLAN_HANDS, main


@pytest.mark.parametrize("name", ["boxx", "/etc/passwd", "cylinder.step"])
def test_an_unknown_object_lists_the_shipped_ones(capsys, name):
    assert main(["plan", name, "--num", "5"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"object {name!r} is not a shipped object" in err
    for shipped in ("box", "cylinder", "hex_prism", "sphere"):
        assert shipped in err


def test_an_unknown_hand_lists_the_short_names(capsys):
    assert main(["plan", "box", "--hand", "wsgg", "--num", "5"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "--hand 'wsgg' is not one of" in err
    assert all(name in err for name in PLAN_HANDS)


def test_short_names_still_plan(capsys):
    assert main(["plan", "sphere", "--hand", "rounded", "--num", "10"]) == 0
    assert "grasp candidates of sphere::sphere" in capsys.readouterr().out
