"""AnalysisOptions and BatchOptions refuse what they cannot hold, when made."""

import numpy as np
import pytest

import drakegrasp as dg


@pytest.mark.parametrize("cls", [dg.AnalysisOptions, dg.BatchOptions])
def test_an_unknown_or_extra_argument_is_an_option_error_naming_it(cls):
    with pytest.raises(dg.InvalidOptionError, match=r"unknown \w+ option bogus="):
        cls(bogus=1)
    too_many = len(cls.__dataclass_fields__) + 1
    with pytest.raises(dg.InvalidOptionError, match=r"positional arguments .* but"):
        cls(*([None] * too_many))
    first = next(iter(cls.__dataclass_fields__))
    with pytest.raises(dg.InvalidOptionError, match="both by position and by name"):
        cls(cls().__getattribute__(first), **{first: cls().__getattribute__(first)})


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"load": [1.0, 2.0]}, "spatial wrench .* of 6 numbers"),
        ({"load": np.zeros(6), "plane": "xy"}, "planar wrench .* of 3 numbers"),
        ({"load": ["1", "2", "3", "4", "5", "6"]}, "load must be"),
        ({"torque_limits": [-1.0]}, "torque_limits must be .* >= 0"),
        ({"torque_limits": [np.nan]}, "torque_limits must be .* >= 0"),
        ({"torque_limits": [-np.inf]}, "torque_limits must be .* >= 0"),
        ({"torque_limits": [[1.0]]}, "1-D"),
        ({"torque_limits": [True]}, "torque_limits must be"),
    ],
)
def test_a_load_or_motor_limits_that_cannot_be_are_refused_when_made(options, message):
    with pytest.raises(dg.InvalidOptionError, match=message):
        dg.AnalysisOptions(**options)


def test_valid_loads_and_limits_are_kept_as_tuples_of_floats():
    o = dg.AnalysisOptions(load=np.arange(6), torque_limits=[0, 2.5, np.inf])
    assert o.load == (0.0, 1.0, 2.0, 3.0, 4.0, 5.0)
    assert o.torque_limits == (0.0, 2.5, float("inf"))
    planar = dg.AnalysisOptions(load=[0, -9.81, 0], plane="xy")
    assert planar.load == (0.0, -9.81, 0.0)
    assert dg.AnalysisOptions(load="gravity", torque_limits="plant").load == "gravity"


@pytest.mark.parametrize(
    "limit", [100, 100.0, 0, 1e-3, np.inf, np.float64(2.5), np.int64(7), np.array(3.0)]
)
def test_one_number_is_every_actuators_torque_limit_as_a_list_of_one_is(limit):
    # docs/scene_format.md says "or one for all"; a scalar was refused ("must
    # be a 1-D sequence ..., got 100") where [100] was taken.
    one = dg.AnalysisOptions(load="gravity", torque_limits=limit)
    assert one.torque_limits == dg.AnalysisOptions(torque_limits=[limit]).torque_limits
    assert one.torque_limits == (float(limit),)


@pytest.mark.parametrize("limit", [-1.0, -np.inf, np.nan, True, "100", 1j])
def test_a_scalar_torque_limit_that_cannot_be_is_refused_naming_it(limit):
    with pytest.raises(dg.InvalidOptionError, match=r"^torque_limits must be 'plant'"):
        dg.AnalysisOptions(torque_limits=limit)
