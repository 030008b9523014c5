"""A message names a user's value without running into its hostile repr.

``describe`` is what every message uses for a value that can be any object;
``GraspError`` itself cuts a message that still came out huge.
"""

from __future__ import annotations

import pickle
import re

import pytest

import drakegrasp as dg
from drakegrasp.core.validation import describe

MAX_MESSAGE = 10_000  # drakegrasp.errors.MAX_MESSAGE


class _SplitRaises(str):
    """A str whose own methods raise: what a hostile ``__repr__`` may return."""

    def split(self, *_args, **_kwargs):
        raise RuntimeError("a hostile split")

    def __len__(self):
        raise RuntimeError("a hostile len")


class _ReprGivesHostileStr:
    def __repr__(self):
        return _SplitRaises("hostile " * 10)


class _ReprHuge:
    def __repr__(self):
        return "x" * 10**7


def test_describe_reads_a_str_subclass_from_repr_as_a_plain_str():
    assert describe(_ReprGivesHostileStr()).startswith("hostile hostile")


def test_describe_cuts_a_huge_repr_to_120_characters():
    text = describe(_ReprHuge())
    assert len(text) == 120
    assert text.endswith("...")


@pytest.mark.parametrize(
    "error",
    [
        dg.GraspError,
        dg.InvalidContactError,
        dg.InvalidOptionError,
        dg.SceneError,
        dg.SolverError,
        dg.UnreachableError,
    ],
)
def test_a_huge_message_is_cut_and_says_so(error):
    caught = error("got " + "5" * 10**7)
    assert len(str(caught)) <= MAX_MESSAGE
    assert str(caught).startswith("got 555")
    assert re.search(r"\.\.\. \(\d+ characters cut\)$", str(caught))
    again = pickle.loads(pickle.dumps(caught))
    assert str(again) == str(caught)  # a cut message is not cut twice


def test_a_pose_error_keeps_its_problem_and_remedy_and_cuts_its_message():
    caught = dg.PenetrationError("deep " * 10**6, remedy="check_pose=False")
    assert len(str(caught)) <= MAX_MESSAGE
    assert caught.remedy == "check_pose=False"


def test_a_short_message_and_no_message_are_unchanged():
    assert str(dg.InvalidOptionError("tol must be > 0")) == "tol must be > 0"
    assert dg.GraspError().args == ()
    assert dg.GraspError("a", 1).args == ("a", 1)
