"""``drakegrasp plan --shake K``: the first K candidates shaken in Drake and
listed again, those that held first; its options refused in one line before
any planning."""

from __future__ import annotations

import inspect
import json

import pytest

from drakegrasp.cli import PLAN_SHAKE_DEFAULTS, SHAKE_FLAGS, build_parser, main
from drakegrasp.planning.shake import (
    DAMPING_TIME,
    PRISMATIC_STIFFNESS,
    REVOLUTE_AIM,
    shake_test,
)
from drakegrasp.planning.squeeze import DEFAULT_SQUEEZE


def test_the_default_hand_holds_the_box_with_hydroelastic_pads(capsys):
    """The flat-pad jaw (plan's default hand) on the box: its pads become
    compliant (1e6 Pa) by default, and its top three hold within a
    millimetre.  With the models' own point contact the box pivots between
    the pads (``tests/plant/test_hydroelastic.py``)."""
    argv = ["plan", "--num", "200", "--top", "0", "--shake", "3"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    head = "3 of 3 shaken candidates held (counted from the seat; object "
    assert head in out and " kg; squeeze " in out
    assert "; stiffness " in out and "; hydroelastic " in out
    assert out.count("  plan #") == 3


def test_json_carries_the_shake(capsys):
    argv = ["plan", "--num", "100", "--top", "1", "--shake", "1", "--json"]
    assert main([*argv, "--hydroelastic", "none", "--squeeze", "5"]) == 0
    data = json.loads(capsys.readouterr().out)
    shaken = data["shaken"]
    assert shaken["options"]["hydroelastic_modulus"] is None
    assert shaken["options"]["squeeze"] == 5.0
    assert len(shaken["shaken"]) == 1
    assert shaken["shaken"][0]["result"]["squeeze"] == 5.0


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--squeeze", "3"], "--squeeze is an option of the shake test"),
        (["--hydroelastic", "1e6"], "--hydroelastic is an option of the shake test"),
        (["--shake", "0"], "--shake must be a whole number of candidates from 1"),
        (["--shake", "20000"], "--shake must be a whole number of candidates"),
        (["parallel_jaw_flat_box", "--shake", "2"], "--shake is for an object"),
    ],
)
def test_refused_in_one_line_before_planning(capsys, argv, message):
    assert main(["plan", "--num", "10", *argv]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0], err


@pytest.mark.parametrize(
    "argv",
    [
        ["--shake", "2", "--hydroelastic", "0"],
        ["--shake", "2", "--hydroelastic", "abc"],
        ["--shake", "2", "--squeeze", "-1"],
        ["--shake", "2", "--stiffness", "nan"],
        ["--shake", "2", "--damping", "-0.1"],
        ["--shake", "-1"],
    ],
)
def test_bad_values_are_usage_errors(capsys, argv):
    with pytest.raises(SystemExit) as info:
        main(["plan", *argv])
    assert info.value.code == 2
    assert "error: argument" in capsys.readouterr().err


def test_the_help_quotes_the_shake_tests_own_defaults():
    defaults = {
        name: p.default for name, p in inspect.signature(shake_test).parameters.items()
    }
    _, sub = build_parser()
    text = " ".join(sub.choices["plan"].format_help().split())
    # the squeeze defaults to newtons at the contacts (a revolute motor's
    # torque from its lever arms): the help quotes the library's figure
    assert defaults["squeeze"] is None
    at_contacts = "for a revolute joint at the contacts"
    assert f"default {DEFAULT_SQUEEZE:g} N, {at_contacts}" in text
    # the gains default per joint: the help quotes the library's constants
    assert defaults["stiffness"] is None and defaults["damping"] is None
    assert f"{PRISMATIC_STIFFNESS:g} N/m for a prismatic one" in text
    assert f"squeeze / {REVOLUTE_AIM:g} rad" in text
    assert f"stiffness times {DAMPING_TIME:g} s" in text
    assert defaults["hydroelastic_modulus"] is None
    assert set(SHAKE_FLAGS) <= set(defaults)
    for options in PLAN_SHAKE_DEFAULTS.values():
        assert set(options) <= set(SHAKE_FLAGS)


@pytest.mark.parametrize(
    ("argv", "says"),
    [
        # the pads take up the 20 µm aim: the squeeze is lost at the seat
        (["--stiffness", "1e6"], "at the seat the closing joints press with"),
        # soft fingers shaken in point contact: the advice in flags
        (
            ["--contact-model", "soft_finger", "--torsional-friction", "0.1",
             "--hydroelastic", "none"],
            "give --hydroelastic 1e6 (Pa, rubber)",
        ),
    ],
)  # fmt: skip
def test_a_shakes_warning_is_one_line_in_flags(capsys, argv, says):
    # Python's form named shake_ranking.py:366 and repeated the calling line
    # (at the models' friction: a plan at another mu is warned of too)
    argv = ["plan", "--num", "40", "--top", "2", "--shake", "2", "--mu", "plant", *argv]
    assert main(argv) == 0
    err = capsys.readouterr().err.splitlines()
    # (a first run may also say that numba compiled the kernels)
    warned = [line for line in err if "warning" in line.lower()]
    assert len(warned) == 1 and warned[0].startswith("drakegrasp: warning: "), err
    assert says in warned[0] and ".py" not in warned[0]
