"""An error's text attributes are cut and plain, as its message is.

``GraspError`` cuts a message longer than ``MAX_MESSAGE`` and reads a ``str``
subclass as the plain str it holds; ``InvalidPoseError.problem`` and
``.remedy`` kept what they were given, whole (a pose check of a thousand
joints, or of a model whose names are megabytes long, carried it all), and a
second ``str`` argument of any error was not cut at all.
"""

from __future__ import annotations

import ast
import builtins
import sys
from pathlib import Path

import pytest

import drakegrasp as dg
from drakegrasp.errors import MAX_MESSAGE, cut_message
from drakegrasp.plant.pose import JointLimitViolation, PoseCheck

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "fuzz"))
import hostile  # noqa: E402

HUGE = "j" * 1_000_000

POSE_ERRORS = [
    dg.InvalidPoseError,
    dg.PenetrationError,
    dg.JointLimitError,
    dg.CouplingError,
]


def _bounded_plain(text) -> None:
    assert type(text) is str
    assert len(text) <= MAX_MESSAGE


@pytest.mark.parametrize("cls", POSE_ERRORS)
def test_a_pose_error_cuts_its_problem_and_remedy(cls):
    error = cls(HUGE, remedy=HUGE)
    _bounded_plain(error.problem)
    _bounded_plain(error.remedy)
    _bounded_plain(str(error))
    assert error.problem.startswith("jjj") and "characters cut" in error.problem
    again = error.with_remedy("add --no-check-pose")
    assert type(again) is cls
    assert again.problem == error.problem
    assert again.remedy == "add --no-check-pose"
    _bounded_plain(str(again))


@pytest.mark.parametrize(
    "value",
    [hostile.StrFormatRaises("hand::finger"), hostile.StrReprRaises("hand::finger")],
    ids=["str-raises", "repr-raises"],
)
def test_a_pose_error_holds_a_str_subclass_as_plain_text(value):
    error = dg.JointLimitError(value, remedy=value)
    assert type(error.problem) is str and error.problem == "hand::finger"
    assert type(error.remedy) is str and error.remedy == "hand::finger"
    assert str(error) == "hand::finger (hand::finger)"


def test_a_pose_check_of_a_huge_joint_name_raises_a_bounded_problem():
    # The raise site: every violation joined, each naming its joint whole.
    check = PoseCheck(
        joint_limit_violations=tuple(
            JointLimitViolation(f"hand::{'j' * 50_000}_{k}", 2.0, -1.0, 1.0)
            for k in range(3)
        )
    )
    with pytest.raises(dg.JointLimitError) as refused:
        check.raise_if_invalid()
    _bounded_plain(refused.value.problem)
    _bounded_plain(str(refused.value))
    assert refused.value.problem.startswith("impossible pose: hand::jjj")


def test_every_str_argument_of_an_error_is_cut():
    error = dg.ModelError("short", HUGE, 3)
    assert error.args[0] == "short"
    _bounded_plain(error.args[1])
    assert error.args[2] == 3
    assert len(str(error)) <= 3 * MAX_MESSAGE


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (hostile.StrFormatRaises("x"), "x"),
        (3, "3"),
        (hostile.StrRaises(), "<StrRaises>"),
        (hostile.ReprNotStr(), "<ReprNotStr>"),
    ],
    ids=["str-subclass", "int", "str-raises", "str-not-str"],
)
def test_cut_message_gives_plain_text_of_any_value(value, text):
    out = cut_message(value)
    assert type(out) is str
    assert out == text


class _StrNotStr:
    def __str__(self):
        return 42


def test_cut_message_names_a_value_whose_str_is_no_str():
    assert cut_message(_StrNotStr()) == "<_StrNotStr>"


@pytest.mark.parametrize(
    "error",
    [
        dg.GraspError(HUGE),
        dg.ModelError("short", HUGE, 3),
        dg.SceneError(hostile.StrFormatRaises("scene")),
        dg.InvalidPoseError(HUGE, remedy=HUGE),
        dg.PenetrationError("fingers inside", remedy="pass check_pose=False"),
        dg.JointLimitError(HUGE),
        dg.SolverError(HUGE, program=None, result=None),
        dg.UnreachableError(HUGE, closure=None),
    ],
    ids=lambda e: type(e).__name__,
)
def test_a_cut_error_pickles_to_the_same_class_and_text(error):
    # A Dask or multiprocessing worker sends its error back pickled: the
    # class is rebuilt from args (one message, already cut: cut again, the
    # same), then the attributes (problem, remedy) from its __dict__.
    import pickle

    back = pickle.loads(pickle.dumps(error))
    assert type(back) is type(error)
    assert back.args == error.args and str(back) == str(error)
    assert back.__dict__ == error.__dict__
    if isinstance(error, dg.InvalidPoseError):
        assert back.with_remedy("x").problem == error.problem


@pytest.mark.parametrize("remedy", ["", None])
def test_a_pose_error_without_a_remedy_is_its_problem_alone(remedy):
    # None read as the text "None": the message was "p (None)".
    error = dg.PenetrationError("fingers inside", remedy=remedy)
    assert str(error) == "fingers inside" and error.remedy == ""
    assert error.with_remedy(None).args == error.args


def _warning_classes():
    """Every warning class drakegrasp defines, by importing its modules."""
    import importlib
    import pkgutil

    import drakegrasp

    found = set()
    for info in pkgutil.walk_packages(drakegrasp.__path__, "drakegrasp."):
        if info.name.endswith("__main__") or ".batch._aot" in info.name:
            continue
        try:
            module = importlib.import_module(info.name)
        except ImportError:  # an optional extra (dask, pyarrow, meshcat)
            continue
        for value in vars(module).values():
            if (
                isinstance(value, type)
                and issubclass(value, Warning)
                and value.__module__.startswith("drakegrasp")
            ):
                found.add(value)
    return sorted(found, key=lambda c: c.__name__)


def test_every_drakegrasp_warning_is_a_grasp_warning():
    # One filter silences or raises them all, as except GraspError catches
    # every error; the nine warnings were UserWarnings of their own.
    classes = _warning_classes()
    assert len(classes) >= 10, classes  # GraspWarning and its nine
    assert all(issubclass(c, dg.GraspWarning) for c in classes), classes
    assert all(issubclass(c, UserWarning) for c in classes)


def _warn_calls():
    """``(module, line, category expression)`` of every ``warnings.warn`` call."""
    import importlib

    import drakegrasp

    package = Path(drakegrasp.__file__).resolve().parent
    for path in sorted(package.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        name = ".".join(
            ("drakegrasp", *path.relative_to(package).with_suffix("").parts)
        )
        for node in ast.walk(tree):
            if not (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Attribute)
                and node.func.attr in ("warn", "warn_explicit")
                and isinstance(node.func.value, ast.Name)
                and node.func.value.id == "warnings"
            ):
                continue
            category = node.args[1] if len(node.args) > 1 else None
            for keyword in node.keywords:
                if keyword.arg == "category":
                    category = keyword.value
            module = importlib.import_module(name.removesuffix(".__init__"))
            yield module, node.lineno, category


def test_every_warning_drakegrasp_issues_is_a_grasp_warning_or_a_deprecation():
    # batch.aot warned about a misspelt DRAKEGRASP_KERNELS with a bare
    # RuntimeWarning: a filter on GraspWarning missed it, and the class scan
    # above (classes drakegrasp defines) could not see it.
    calls = list(_warn_calls())
    assert len(calls) >= 15, calls  # the scan finds the calls there are
    wrong = []
    for module, line, category in calls:
        # a category named in the module (a Name), never the default UserWarning
        kind = None
        if isinstance(category, ast.Name):
            kind = getattr(module, category.id, getattr(builtins, category.id, None))
        if not (
            isinstance(kind, type)
            and (issubclass(kind, dg.GraspWarning) or kind is DeprecationWarning)
        ):
            wrong.append(f"{module.__name__}:{line}")
    assert not wrong, wrong


def test_a_grasp_warning_is_cut_as_an_error_is():
    import warnings

    from drakegrasp.planning.shake import CoarseStepWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.warn(HUGE, CoarseStepWarning, stacklevel=1)
    _bounded_plain(str(caught[0].message))
    with warnings.catch_warnings():
        warnings.simplefilter("error", dg.GraspWarning)
        with pytest.raises(CoarseStepWarning, match="characters cut"):
            warnings.warn(HUGE, CoarseStepWarning, stacklevel=1)
