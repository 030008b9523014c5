"""A call that does not fit a public signature raises a named GraspError.

Every public function and constructor is wrapped by ``checked_call`` (or, for
the options objects, ``checked_fields``).  These tests read
every public name of every package's table, so a new public function without
the wrapper fails here.
"""

from __future__ import annotations

import enum
import functools
import importlib
import inspect
import pickle
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import drakegrasp as dg
from drakegrasp.core.calls import call_problem, checked_call, checked_fields

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_architecture import PACKAGES  # noqa: E402

BOGUS = "not_a_keyword_of_drakegrasp"


def _public_callables():
    """(module, name) of every public function and constructible class."""
    found = {}
    for package in sorted(PACKAGES):
        module = importlib.import_module(package)
        tables = vars(module).get("_SOURCES", {}).values()
        for name in sorted({n for names in tables for n in names}):
            value = getattr(module, name)
            if inspect.isclass(value):
                if issubclass(value, (BaseException, enum.Enum)):
                    continue
            elif not callable(value):
                continue
            found.setdefault((value.__module__, value.__qualname__), (package, name))
    examples = importlib.import_module("drakegrasp.core.examples")
    found |= {
        (None, name): ("drakegrasp.core.examples", name) for name in examples.__all__
    }
    return sorted(found.values())


PUBLIC = _public_callables()


def test_the_public_tables_were_read():
    assert len(PUBLIC) > 150


# Public functions that pass ``**options`` on: each refuses an unknown one
# where it is passed (test_forwarded_keywords_are_named_too).
FORWARDING = {
    "add_grasp_monitor",
    "analyze_poses",
    "evaluate_on_cluster",
    "iter_batch_closure",
    "shake_candidates",
    "stream_file_on_cluster",
}


def _takes_any_keyword(value) -> bool:
    if inspect.isclass(value):
        return False  # a constructor's own signature is checked (a named tuple's too)
    parameters = inspect.signature(inspect.unwrap(value)).parameters.values()
    return any(p.kind is p.VAR_KEYWORD for p in parameters)


def test_the_forwarding_functions_are_those_taking_any_keyword():
    found = {
        name
        for package, name in PUBLIC
        if _takes_any_keyword(getattr(importlib.import_module(package), name))
    }
    assert found == FORWARDING


@pytest.mark.parametrize(
    ("package", "name"), [(p, n) for p, n in PUBLIC if n not in FORWARDING]
)
def test_every_public_callable_names_an_unknown_keyword(package, name):
    value = getattr(importlib.import_module(package), name)
    with pytest.raises(dg.GraspError, match=f"unknown .*{BOGUS}=") as caught:
        value(**{BOGUS: 1})
    assert name in str(caught.value)
    # Still what Python raises for such a call (or, for an options object, an
    # option error, as before).
    assert isinstance(caught.value, (TypeError, dg.InvalidOptionError))


def _public_methods():
    """(class's package, class name, method name) of every public method."""
    found = []
    for package, name in PUBLIC:
        value = getattr(importlib.import_module(package), name)
        if not inspect.isclass(value):
            continue
        for method, member in vars(value).items():
            if method.startswith("_"):
                continue
            function = getattr(member, "__func__", member)
            if not inspect.isfunction(function):
                continue  # a property, a constant
            if not _takes_any_keyword(function):
                found.append((package, name, method))
    return found


METHODS = _public_methods()


def test_the_public_methods_were_read():
    assert len(METHODS) > 60


@pytest.mark.parametrize(("package", "name", "method"), METHODS)
def test_every_public_method_names_an_unknown_keyword(package, name, method):
    cls = getattr(importlib.import_module(package), name)
    member = vars(cls)[method]
    call = getattr(cls, method)
    if inspect.isfunction(member):  # an instance method, read off the class
        call = functools.partial(call, object())
    with pytest.raises(dg.InvalidArgumentError, match=f"unknown .*{BOGUS}=") as caught:
        call(**{BOGUS: 1})
    assert str(caught.value).startswith(f"{name}.{method}(): ")


@pytest.mark.parametrize(("package", "name"), PUBLIC)
def test_every_public_function_pickles_as_itself(package, name):
    # The Dask driver ships functions by reference: the wrapper must be what
    # the module's name holds.
    value = getattr(importlib.import_module(package), name)
    assert pickle.loads(pickle.dumps(value)) is value


def test_forwarded_keywords_are_named_too():
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.framework import DiagramBuilder

    import drakegrasp.batch as db
    import drakegrasp.distributed as dd

    P = np.zeros((2, 3, 3))
    N = np.tile([0.0, 0.0, 1.0], (2, 3, 1))
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    plant.Finalize()
    calls = {
        # GraspMonitor's own keywords
        "GraspMonitor()": lambda: dg.add_grasp_monitor(
            builder, plant, scene_graph, **{BOGUS: 1}
        ),
        "AnalysisOptions()": lambda: dd.analyze_poses(
            None, "scene.yaml", np.zeros((1, 3)), **{BOGUS: 1}
        ),
        # before the client is asked for: the engine would refuse it late
        "evaluate_on_cluster()": lambda: dd.evaluate_on_cluster(
            None, P, N, mu=0.5, **{BOGUS: 1}
        ),
        "batch_form_closure()": lambda: next(
            db.iter_batch_closure([(P, N)], kind="form", **{BOGUS: 1})
        ),
        "shake_candidates()": lambda: dg.shake_candidates(print, [], **{BOGUS: 1}),
        # before the file is read
        "stream_file_on_cluster()": lambda: dd.stream_file_on_cluster(
            "missing.npz", "out", scheduler="tcp://host:8786", **{BOGUS: 1}
        ),
    }
    for where, call in calls.items():
        with pytest.raises(dg.GraspError, match=f"unknown .*{BOGUS}=") as caught:
            call()
        assert str(caught.value).startswith(where)


def test_a_cluster_run_of_form_closure_refuses_friction_keywords_at_once():
    import drakegrasp.distributed as dd

    P = np.zeros((2, 3, 3))
    with pytest.raises(dg.InvalidArgumentError, match="unknown keyword contact_model="):
        dd.evaluate_on_cluster(None, P, P, kind="form", contact_model="hard_finger")
    with pytest.raises(dg.InvalidArgumentError, match="did you mean output_dir=?"):
        dd.evaluate_on_cluster(None, P, P, mu=0.5, ouput_dir="out")


def test_a_misspelled_keyword_names_the_closest_one():
    contacts = dg.examples.planar_square_four_contacts().contacts
    with pytest.raises(dg.InvalidArgumentError) as caught:
        dg.Grasp(contacts, refrence_point=[0, 0])
    assert "Grasp(): unknown keyword refrence_point=" in str(caught.value)
    assert "did you mean reference_point=?" in str(caught.value)
    assert isinstance(caught.value, TypeError)


def test_a_keyword_in_the_wrong_case_is_matched():
    grasp = dg.examples.planar_square_four_contacts()
    with pytest.raises(dg.InvalidArgumentError, match="did you mean tol=?"):
        dg.force_closure(grasp, TOL=1e-6)


def test_every_unknown_keyword_is_named_not_only_the_first():
    grasp = dg.examples.planar_square_four_contacts()
    with pytest.raises(dg.InvalidArgumentError) as caught:
        dg.force_closure(grasp, toll=1e-6, rank_toll=1e-9)
    message = str(caught.value)
    assert "toll= (did you mean tol=?)" in message
    assert "rank_toll= (did you mean rank_tol=?)" in message


def test_too_many_positional_arguments_name_the_keyword_only_ones():
    grasp = dg.examples.planar_square_four_contacts()
    with pytest.raises(dg.InvalidArgumentError) as caught:
        dg.force_closure(grasp, 1e-6)
    assert str(caught.value).startswith(
        "force_closure(): takes 1 positional argument (grasp) but 2 were given; "
        "by keyword only: "
    )
    assert "tol=" in str(caught.value)


def test_every_missing_argument_is_named():
    with pytest.raises(dg.InvalidArgumentError, match=r"missing positions, normals"):
        dg.batch_force_closure(mu=0.5)


def test_the_batch_functions_check_calls_behind_their_ragged_wrapper():
    P = np.zeros((2, 3, 3))
    with pytest.raises(dg.InvalidArgumentError, match="3 were given"):
        dg.batch_form_closure(P, P, 3)
    with pytest.raises(dg.InvalidArgumentError, match="missing positions"):
        dg.batch_form_closure(normals=P)


def test_options_objects_keep_their_option_error():
    with pytest.raises(dg.InvalidOptionError) as caught:
        dg.AnalysisOptions(toll=1e-6)
    assert "unknown analysis option toll= (did you mean tol=?)" in str(caught.value)
    assert not isinstance(caught.value, TypeError)
    with pytest.raises(dg.InvalidOptionError, match="both by position and by name"):
        dg.BatchOptions("hard_finger", contact_model="hard_finger")


def test_old_spellings_still_pass_the_check():
    with pytest.warns(DeprecationWarning, match="model= is deprecated"):
        contact = dg.Contact([0, 0, 0], [0, 0, 1], mu=0.5, model="frictionless")
    assert contact.contact_model is dg.ContactModel.FRICTIONLESS


def test_a_type_error_of_the_body_passes_unchanged():
    @checked_call
    def add(a, b=1):
        return a + b

    with pytest.raises(TypeError) as caught:
        add("x")  # fits the signature; "x" + 1 fails inside
    assert type(caught.value) is TypeError
    assert add(1) == 2
    with pytest.raises(dg.InvalidArgumentError, match="did you mean b=?"):
        add(1, bb=2)


def test_the_signature_and_name_are_the_wrapped_functions():
    assert str(inspect.signature(dg.grasp_matrix)) == str(
        inspect.signature(inspect.unwrap(dg.grasp_matrix))
    )
    assert dg.grasp_matrix.__name__ == "grasp_matrix"
    assert dg.grasp_matrix.__doc__.startswith(inspect.unwrap(dg.grasp_matrix).__doc__)


def _sample(a, b=0, /, c=1, *, d, e=2):
    return a, b, c, d, e


@pytest.mark.parametrize(
    ("args", "kwargs", "expected"),
    [
        ((1,), {"d": 3}, None),
        ((1, 2, 3), {"d": 3, "e": 4}, None),
        ((1,), {"d": 3, "ee": 4}, "unknown keyword ee= (did you mean e=?)"),
        ((1,), {"d": 3, "zzz": 4}, "unknown keyword zzz= (it takes c=, d=, e=)"),
        ((1,), {"d": 3, "b": 4}, "b is positional only: give it by position"),
        ((1, 2, 3, 4), {"d": 3}, "takes 3 positional arguments (a, b, c) but 4"),
        ((1, 2, 3), {"c": 3, "d": 3}, "got c both by position and by name"),
        ((), {}, "missing a, d (required)"),
    ],
)
def test_call_problem_against_python_itself(args, kwargs, expected):
    problem = call_problem(_sample, args, kwargs)
    # The independent route: Python's own binding of the same call.
    try:
        _sample(*args, **kwargs)
        fits = True
    except TypeError:
        fits = False
    assert (problem is None) == fits
    if expected is None:
        assert problem is None
    else:
        assert problem.startswith(expected)


def test_a_function_taking_any_keyword_has_no_unknown_one():
    def anything(a, *args, **kwargs):
        return a

    def by_position(a, /, **kwargs):
        return a

    assert call_problem(anything, (1, 2, 3), {"x": 1}) is None
    assert call_problem(anything, (), {"x": 1}) == "missing a (required)"
    # a positional-only name given by name lands in **kwargs: a is still missing
    assert by_position(1, a=2) == 1
    assert call_problem(by_position, (1,), {"a": 2}) is None
    assert call_problem(by_position, (), {"a": 2}) == "missing a (required)"


def test_a_class_without_a_constructor_of_its_own_is_refused():
    class Bare:
        pass

    with pytest.raises(TypeError, match="defines no constructor"):
        checked_call(Bare)


def test_checked_fields_names_the_noun():
    from dataclasses import dataclass

    @checked_fields("setting")
    @dataclass(frozen=True)
    class Settings:
        speed: float = 1.0

    with pytest.raises(dg.InvalidOptionError, match=r"unknown setting sped= \(did"):
        Settings(sped=2.0)
    assert Settings(2.0).speed == 2.0


_IDENTIFIER = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,20}", fullmatch=True)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(names=st.lists(_IDENTIFIER, min_size=1, max_size=4, unique=True))
def test_call_problem_agrees_with_python_on_any_keywords(names):
    kwargs = dict.fromkeys(names, 1)
    problem = call_problem(_sample, (1,), {"d": 1, **kwargs})
    try:
        _sample(1, **{"d": 1, **kwargs})
        fits = True
    except TypeError:
        fits = False
    assert (problem is None) == fits
    for name in names:
        if name in ("a", "b"):
            assert f"{name} is positional only" in problem
        elif name not in ("c", "d", "e"):
            assert f"unknown keyword {name}=" in problem


# What a review of the first version found (each failed on it).


def test_a_cluster_run_from_a_file_takes_evaluate_on_clusters_keywords():
    import drakegrasp.distributed as dd

    with pytest.raises(dg.BatchFileError, match="does not exist"):  # past the check
        dd.stream_file_on_cluster(
            "/nonexistent.npz", "out", scheduler="tcp://x:1", partition_chunks=2
        )
    # what it sets itself on evaluate_on_cluster is not among them
    with pytest.raises(dg.InvalidArgumentError, match="did you mean output_path="):
        dd.stream_file_on_cluster(
            "/nonexistent.npz", "out", scheduler="tcp://x:1", output_dir="x"
        )
    with pytest.raises(dg.InvalidArgumentError, match="unknown keyword client="):
        dd.stream_file_on_cluster("/nonexistent.npz", "out", scheduler="x", client=1)


def test_a_form_closure_cluster_run_refuses_the_old_spelling_of_a_friction_option():
    import drakegrasp.distributed as dd

    P = np.zeros((2, 3, 3))
    with pytest.raises(dg.InvalidArgumentError, match="unknown keyword model="):
        dd.evaluate_on_cluster(None, P, P, kind="form", model="hard_finger")


def test_an_old_spelling_is_read_as_the_new_one_when_the_call_is_judged():
    grasp = dg.examples.planar_square_four_contacts()
    with (
        pytest.warns(DeprecationWarning),
        pytest.raises(dg.InvalidArgumentError) as caught,
    ):
        grasp.with_friction(0.5, 1, model="hard_finger")  # one positional too many
    assert "takes 1 positional argument (mu) but 2 were given" in str(caught.value)
    assert " model=" not in str(caught.value)
    with (
        pytest.warns(DeprecationWarning),
        pytest.raises(dg.InvalidArgumentError) as caught,
    ):
        grasp.with_friction(model="hard_finger", mu_=1)
    assert str(caught.value) == (
        "Grasp.with_friction(): unknown keyword mu_= (did you mean mu=?)"
    )
    P = np.zeros((2, 3, 3))
    with pytest.warns(DeprecationWarning), pytest.raises(dg.InvalidArgumentError) as c:
        dg.batch_force_closure(P, P, 0.5, bogus=1)  # mu by position: the old way
    assert "unknown keyword bogus=" in str(c.value) and "mu" not in str(c.value)[:60]


def test_the_batch_functions_name_their_options_keyword():
    P = np.zeros((2, 3, 3))
    with pytest.raises(dg.InvalidArgumentError, match="did you mean options=?"):
        dg.batch_form_closure(P, P, optoins=dg.BatchOptions())
    with pytest.raises(dg.InvalidArgumentError, match="did you mean options=?"):
        dg.evaluate_file("x.npz", optoins=dg.BatchOptions())


def test_shake_candidates_names_its_own_keywords():
    with pytest.raises(dg.InvalidOptionError) as caught:
        dg.shake_candidates(print, [], held_frm="seat")
    assert str(caught.value) == (
        "shake_candidates(): unknown option held_frm= (did you mean held_from=?)"
    )


def test_one_argument_was_given_and_a_method_needs_its_object():
    with pytest.raises(dg.InvalidArgumentError, match="but 1 was given$"):
        dg.plant.models_dir([])  # the check is above functools.cache
    with pytest.raises(dg.InvalidArgumentError, match="called without an object"):
        dg.Grasp.with_friction(mu=0.5)
