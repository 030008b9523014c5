"""Hostile objects at the shared checks: dunders that raise, masks, 0-d flags.

An object whose ``__float__``, ``__array__``, ``__iter__``, ``__index__`` or
``__repr__`` raises passed that exception out of ``real_scalar``,
``real_array``, ``integer_or_none`` and the messages as it was (a
``RuntimeError`` from deep inside numpy's conversion).  A masked array lost
its mask: the hidden values were read as data.  ``check_flag`` took
``np.bool_`` but refused ``np.array(True)``, and ``prepare_dataset`` refused
``np.bool_`` too: one rule for a flag now, in ``check_flag``.
"""

from __future__ import annotations

import numbers

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.core import validation as v
from drakegrasp.errors import InvalidContactError, InvalidOptionError


class Hostile(RuntimeError):
    pass


def _raise(*_args, **_kwargs):
    raise Hostile("a hostile dunder")


class FloatRaises:
    __float__ = _raise
    __index__ = _raise


numbers.Real.register(FloatRaises)


class FloatSubclassRaises(float):
    __float__ = _raise


class ArrayRaises:
    __array__ = _raise


class IterRaises:
    def __len__(self):
        return 3

    __iter__ = _raise
    __getitem__ = _raise


class ReprRaises:
    __repr__ = _raise


@pytest.mark.parametrize("value", [FloatRaises(), FloatSubclassRaises(0.5)])
def test_a_float_that_raises_is_named(value):
    with pytest.raises(InvalidOptionError, match=r"^x must be a real number.*float"):
        v.real_scalar("x", value)
    with pytest.raises(InvalidOptionError, match="num_generators must be an integer"):
        v.check_num_generators(value)


@pytest.mark.parametrize(
    "value",
    [
        ArrayRaises(),
        IterRaises(),
        [IterRaises(), IterRaises()],
        np.array([0.5, FloatRaises()], dtype=object),
    ],
    ids=["array", "iter", "nested", "object-dtype"],
)
def test_an_array_like_that_raises_is_named(value):
    with pytest.raises(InvalidContactError, match=r"^p must be an array of real"):
        v.check_positions("p", value)


def test_a_masked_array_with_masked_entries_is_refused_not_unmasked():
    masked = np.ma.masked_array([[0.0, 0.0, 1.0]], mask=[[0, 1, 0]])
    with pytest.raises(InvalidContactError, match="1 masked entries"):
        v.real_array("normals", masked)
    with pytest.raises(dg.GraspError, match="masked"):
        dg.Contact(np.ma.masked_array([0.0, 9.0, 0.0], [0, 1, 0]), [1, 0, 0])
    # nothing masked: its data, as numpy reads it
    clear = np.ma.masked_array([0.5, 1.0], mask=False)
    np.testing.assert_array_equal(v.real_array("x", clear), [0.5, 1.0])


def test_a_message_survives_a_repr_that_raises():
    assert "ReprRaises whose repr() raised Hostile" in v.describe(ReprRaises())
    with pytest.raises(InvalidOptionError, match="flag must be True or False"):
        v.check_flag("flag", ReprRaises())


@pytest.mark.parametrize(
    ("value", "expected"),
    [(True, True), (np.bool_(False), False), (np.array(True), True)],
)
def test_a_flag_may_be_a_numpy_boolean_or_a_0d_boolean_array(value, expected):
    assert v.check_flag("flag", value) is expected


@pytest.mark.parametrize(
    "value", [np.array([True]), np.array(1), np.array(1.0), 1, None, "yes"]
)
def test_a_flag_of_another_shape_or_dtype_is_refused(value):
    with pytest.raises(InvalidOptionError, match="flag must be True or False"):
        v.check_flag("flag", value)


@pytest.mark.parametrize("value", [np.float32(0.5), np.array(0.5), np.int64(8)])
def test_numpy_scalars_pass_where_a_number_is_wanted(value):
    assert v.real_scalar("x", value) == float(value)


def test_prepare_dataset_takes_a_flag_as_check_flag_does(tmp_path):
    from drakegrasp.distributed.dataset import prepare_dataset

    for flag in (np.bool_(False), np.array(True)):
        assert prepare_dataset(tmp_path / "out", {}, overwrite=flag, create=False)
    with pytest.raises(InvalidOptionError, match="overwrite must be True or False"):
        prepare_dataset(tmp_path / "out", {}, overwrite=np.array([True]))


def test_items_of_reads_a_generator_once_and_names_what_raises():
    assert v.items_of("xs", (x for x in (1, 2)), "numbers") == [1, 2]
    with pytest.raises(InvalidOptionError, match=r"^xs must be numbers.*Hostile"):
        v.items_of("xs", IterRaises(), "numbers")
    with pytest.raises(InvalidOptionError, match=r"^xs must be numbers, got array"):
        v.items_of("xs", np.array(1.0), "numbers")


def test_a_huge_broadcast_array_is_refused_before_it_is_read():
    # np.broadcast_to costs nothing; reading it as floats took 22 GiB (and
    # the fuzz's check of it minutes), so it is refused by its size first.
    huge = np.broadcast_to(0.5, (10**9, 3))
    with pytest.raises(InvalidContactError, match=r"^p has shape \(1000000000, 3\)"):
        v.check_positions("p", huge)
    with pytest.raises(dg.GraspError, match="MAX_ARRAY_ENTRIES"):
        dg.Contact(huge, [0.0, 0.0, 1.0])
    with pytest.raises(dg.GraspError, match="MAX_ARRAY_ENTRIES"):
        dg.max_resistible_wrench(
            dg.examples.spatial_two_fingers(0.5), huge, max_normal_force=1.0
        )


def test_a_decimal_is_a_number_as_it_is_in_an_array():
    # [Decimal("0.5")] was read as an array of 0.5 while Decimal("0.5") alone
    # was refused as no real number.
    import decimal

    assert v.real_scalar("x", decimal.Decimal("0.5")) == 0.5
    assert v.check_coefficient("mu", decimal.Decimal("0.5")) == 0.5
    with pytest.raises(InvalidOptionError, match="x must be a real number"):
        v.real_scalar("x", decimal.Decimal("sNaN"))
    with pytest.raises(InvalidContactError, match="mu must be finite"):
        v.check_coefficient("mu", decimal.Decimal("NaN"))


def test_a_sequence_of_more_items_than_max_items_is_refused_as_it_is_counted():
    # tuple() of a 10**9-row array made a view per row (about 100 GB) and of
    # an endless generator never returned.
    import itertools

    from drakegrasp.core.tolerances import MAX_ITEMS

    contact = dg.examples.spatial_two_fingers(0.5).contacts[0]
    for endless in (np.broadcast_to(0.5, (10**9, 3)), itertools.repeat(contact)):
        with pytest.raises(dg.InvalidGraspError, match=f"more than {MAX_ITEMS}"):
            dg.Grasp(endless)
    with pytest.raises(InvalidOptionError, match="more than"):
        v.items_of("xs", itertools.repeat(0.5), "numbers")
