"""A mass whose weight is a float but whose squeeze or torque needed is not.

``plan --mass 1e308`` is refused (``m g`` is inf), but ``--mass 1.7e307``
weighs 1.67e308 N, and dividing that by a weight capacity below 1 left the
float range: numpy warned "overflow encountered in scalar divide" (a
``drakegrasp: warning:`` line, or with warnings as errors "unexpected
RuntimeWarning ... a bug in drakegrasp", exit 1), and the candidates and the
motors' line read "squeeze inf N per finger" and "they need at least inf N",
inf being the planner's word for "no squeeze holds it".  A torque beyond
range read "torque inf N·m" alike, and a squeeze just within it (``--mass
1e300``) printed 302 digits.  Such a figure exists but no float holds it: it
is inf, and said "more than 1.8e+308 ..., beyond float range".
"""

from __future__ import annotations

import json
import math
import re
import sys
import warnings

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.cli import main

HUGE = 1.7e307  # kg: 1.67e308 N, a float; over a capacity below 1, none
BEYOND = "more than 1.8e+308 N per finger, beyond float range"
ALLEGRO = ["--hand", "allegro"]
SUGAR = "package://drake_models/ycb/004_sugar_box.sdf"


def _plan(capsys, *argv: str) -> tuple[str, str]:
    """``drakegrasp plan`` in this process, RuntimeWarnings as errors."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        code = main(["plan", "--num", "50", *argv])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "warning" not in err and "overflow" not in err, err
    return out, err


def _lines(out: str) -> list[str]:
    return [line for line in out.splitlines() if line.startswith("  #")]


def test_a_squeeze_beyond_float_range_is_said_so_not_inf(capsys):
    out, _ = _plan(capsys, "--mass", str(HUGE))
    lines = _lines(out)
    assert lines and all(BEYOND in line for line in lines), out
    assert "inf N" not in out and "nan" not in out.lower()
    # the motors' line: no "at least inf"
    assert f"they need {BEYOND} (squeeze_needed)" in out


def test_a_large_finite_squeeze_has_three_digits_not_three_hundred(capsys):
    out, _ = _plan(capsys, "--mass", "1e300", "--top", "3")
    assert re.search(r"\d{12}", out) is None, out
    assert re.search(r"squeeze 1\.\d\de\+301 N per finger", out), out


def test_the_json_and_the_table_keep_the_capacity_that_says_why(capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert main(["plan", "--num", "50", "--mass", str(HUGE), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    closed = [c for c in data["candidates"] if c["is_closure"]]
    assert closed
    for c in closed:  # JSON has no inf: null beside a capacity > 0
        assert c["squeeze_needed"] is None and c["weight_capacity"] > 0
    assert BEYOND in data["reason"]


def test_the_library_gives_inf_with_a_capacity_and_no_warning():
    from drakegrasp.planning.needed import beyond_float_range

    scene = dg.planning_scene(
        "package://drakegrasp/objects/box.sdf",
        hand_url="package://drakegrasp/hands/parallel_jaw_flat.sdf",
    )
    kw = dict(num_candidates=40, mu=0.5, seed=0, robustness_samples=4)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        huge = dg.plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            object_mass=HUGE, **kw,
        )  # fmt: skip
        light = dg.plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            object_mass=1.0, **kw,
        )  # fmt: skip
    by_sample = {d.sample: d for d in light}
    beyond = 0
    for c in huge:
        d = by_sample[c.sample]  # the same candidate: only the mass differs
        assert np.array_equal(c.weight_capacity, d.weight_capacity, equal_nan=True)
        if not c.is_closure:
            continue
        assert d.squeeze_needed == pytest.approx(9.81 / d.weight_capacity)
        if HUGE * 9.81 > sys.float_info.max * c.weight_capacity:
            beyond += 1  # the true figure, HUGE g / capacity, is no float
            assert c.squeeze_needed == math.inf
            assert beyond_float_range(c.squeeze_needed, c.weight_capacity)
        else:
            assert c.squeeze_needed == pytest.approx(HUGE * 9.81 / c.weight_capacity)
    assert beyond
    assert "beyond float range" in str(huge) and "inf N" not in str(huge)


@pytest.fixture
def models(drake_models_dir, monkeypatch):
    monkeypatch.setenv("DRAKEGRASP_DRAKE_MODELS", str(drake_models_dir))


def test_the_allegro_hand_says_its_squeeze_beyond_range_too(capsys, models):
    out, _ = _plan(capsys, *ALLEGRO, "--mass", str(HUGE), "--top", "3")
    closed = [line for line in _lines(out) if "force closure" in line]
    assert closed and all(BEYOND in line for line in closed), out
    assert "inf N" not in out


def test_a_torque_beyond_float_range_is_said_so_not_inf(capsys, models):
    # the sugar box's one force-closure candidate needs 0.95 N·m per N: its
    # torque for 1.75e307 kg (1.72e308 N) is past the float range
    out, _ = _plan(capsys, SUGAR, *ALLEGRO, "--mass", "1.75e307", "--top", "1")
    words = "more than 1.8e+308 N·m per motor, beyond float range"
    assert f"torque {words}" in _lines(out)[0], out
    assert f"it needs {words} (torque_needed)" in out
    assert "inf N" not in out


def test_the_wsg_on_a_ycb_object(capsys, models):
    out, _ = _plan(capsys, SUGAR, "--hand", "wsg", "--mass", str(HUGE))
    assert all(BEYOND in line for line in _lines(out)), out
    assert "inf N" not in out


def test_torque_capacity_and_torque_needed_agree(drake_models_dir):
    from allegro_support import allegro_scene

    scene = allegro_scene("004_sugar_box", drake_models_dir)
    result = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=50, mu=0.5, seed=0, robustness_samples=4, object_mass=2.0,
    )  # fmt: skip
    checked = [c for c in result if not np.isnan(c.torque_needed)]
    assert checked
    for c in checked:
        assert c.torque_capacity > 0
        assert c.torque_needed == pytest.approx(2.0 * 9.81 / c.torque_capacity)
        assert c.to_dict()["torque_capacity"] == c.torque_capacity
    assert np.array_equal(
        result.table()["torque_capacity"],
        [c.torque_capacity for c in result],
        equal_nan=True,
    )


# -- the one rule ---------------------------------------------------------------


@pytest.mark.parametrize(
    "load, capacity, needed, beyond",
    [
        (9.81, 0.5, 19.62, False),
        (1.67e308, 0.9, math.inf, True),  # a figure no float holds
        (1.0, 0.0, math.inf, False),  # none holds
        (1.0, math.inf, 0.0, False),  # nothing needed
        (math.nan, 0.5, math.nan, False),  # the weight unknown
        (1.0, math.nan, math.nan, False),  # not computed
        (np.float64(1.67e308), np.float64(0.9), math.inf, True),  # numpy in
    ],
)
def test_needed_for(load, capacity, needed, beyond):
    from drakegrasp.planning.needed import beyond_float_range, needed_for

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = needed_for(load, capacity)
    assert type(got) is float
    assert got == pytest.approx(needed, nan_ok=True)
    assert beyond_float_range(got, float(capacity)) is beyond


@pytest.mark.parametrize(
    "needed, capacity, spec, text",
    [
        (12.345, 0.9, ".1f", "12.3 N"),
        (1.0834e301, 0.9, ".1f", "1.08e+301 N"),
        (math.inf, 0.9, ".1f", "more than 1.8e+308 N, beyond float range"),
        (math.inf, 0.0, ".1f", "inf N"),
        (0.25, 4.0, ".3g", "0.25 N"),
    ],
)
def test_needed_text(needed, capacity, spec, text):
    from drakegrasp.planning.needed import needed_text

    assert needed_text(needed, capacity, "N", spec) == text


def test_needed_for_reads_none_holds_before_an_unknown_weight():
    # a capacity of 0 holds no weight, known or not (a cloud planned without
    # the object's mass); no weight needs no effort; a capacity not computed
    # says nothing
    from drakegrasp.planning.needed import needed_for

    assert needed_for(float("nan"), 0.0) == math.inf
    assert needed_for(float("nan"), -1e-17) == math.inf  # an LP's rounding
    assert needed_for(0.0, 0.0) == 0.0
    assert math.isnan(needed_for(9.81, float("nan")))
    assert math.isnan(needed_for(float("nan"), 0.5))


@pytest.mark.parametrize(
    "load, capacity", [(-1.0, 1.0), ("2", 1.0), (True, 1.0), (None, 1.0), (1.0, "a")]
)
def test_needed_for_refuses_what_is_not_a_weight_or_capacity(load, capacity):
    from drakegrasp.planning.needed import needed_for

    with pytest.raises(dg.InvalidOptionError):
        needed_for(load, capacity)


def test_needed_text_says_beyond_float_range_only_of_a_positive_figure():
    from drakegrasp.planning.needed import needed_text

    assert "beyond float range" not in needed_text(-math.inf, 1.0, "N")
    with pytest.raises(dg.InvalidOptionError, match="spec"):
        needed_text(1.0, 1.0, "N", spec="q")
    with pytest.raises(dg.InvalidOptionError, match="capacity"):
        needed_text(1.0, None, "N")


def test_torque_is_said_per_motor_and_the_old_name_warns():
    from drakegrasp.planning.needed import per_joint, per_motor

    assert per_motor("N·m") == "N·m per motor"
    assert per_motor("N") == "N per motor"
    mixed = "N·m, N at prismatic joints"
    assert per_motor(mixed) == "N·m per motor, N at prismatic joints"
    with pytest.warns(DeprecationWarning, match="use per_motor"):
        assert per_joint(mixed) == "N·m per joint, N at prismatic joints"
