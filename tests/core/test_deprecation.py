"""Old spellings keep working for a while, warn with the new one, and never mix.

The renames of this round (listed on the docs' Changes page): ``model=`` is
``contact_model=`` everywhere, ``mu`` is keyword-only in the batch functions,
and ``normalised_grasp_matrix`` (``T G``) is ``invariant_grasp_matrix``.
"""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.core.deprecation import keyword_only, renamed_keyword
from drakegrasp.core.examples import equator_fingers


def _arrays(k=3):
    g = equator_fingers(0.5)
    return np.array([g.positions] * k), np.array([g.normals] * k), g


def test_contact_model_alias_warns_and_means_the_same():
    new = dg.Contact([0, 0, 0], [1, 0, 0], mu=0.5, contact_model="frictionless")
    with pytest.warns(DeprecationWarning, match="contact_model="):
        old = dg.Contact([0, 0, 0], [1, 0, 0], mu=0.5, model="frictionless")
    assert old.contact_model is new.contact_model is dg.ContactModel.FRICTIONLESS
    with pytest.warns(DeprecationWarning, match="Contact.contact_model"):
        assert old.model is dg.ContactModel.FRICTIONLESS
    with pytest.warns(DeprecationWarning, match=r"^Contact\.with_\(\): model=") as w:
        assert new.with_(model="hard_finger").contact_model is (
            dg.ContactModel.HARD_FINGER
        )
    assert w[0].filename == __file__  # the user's line


def test_both_spellings_at_once_are_refused():
    # An argument conflict is an option error wherever it is made.
    with pytest.raises(dg.InvalidOptionError, match="contact_model= only"):
        dg.Contact(
            [0, 0, 0], [1, 0, 0], model="frictionless", contact_model="hard_finger"
        )
    P, N, _ = _arrays()
    with pytest.raises(dg.InvalidOptionError, match="contact_model= only"):
        dg.batch_force_closure(
            P, N, mu=0.5, model="hard_finger", contact_model="hard_finger"
        )
    with pytest.raises(dg.InvalidArgumentError, match="unknown keyword modle="):
        dg.Contact([0, 0, 0], [1, 0, 0], modle="frictionless")


def test_batch_keywords_old_and_new_agree_bitwise():
    P, N, g = _arrays()
    new = dg.batch_force_closure(P, N, mu=0.5, contact_model="soft_finger",
                                 torsional_friction=0.1)  # fmt: skip
    with pytest.warns(DeprecationWarning) as record:
        old = dg.batch_force_closure(
            P, N, 0.5, model="soft_finger", torsional_friction=0.1
        )
    messages = " ".join(str(w.message) for w in record)
    assert "mu=" in messages and "contact_model=" in messages
    assert np.array_equal(old.d_star, new.d_star)
    assert np.array_equal(old.is_closure, new.is_closure)
    with pytest.warns(DeprecationWarning):
        soft = g.with_friction(model="soft_finger", torsional_friction=0.1)
    assert soft.contacts[0].contact_model is dg.ContactModel.SOFT_FINGER


def test_mu_given_twice_or_too_many_positionals_is_refused():
    # A call that does not fit the signature: Python raises TypeError for
    # both, and so does every other such call of drakegrasp (checked_call's
    # InvalidArgumentError); these were InvalidOptionError (a ValueError)
    # only, and stay one.
    P, N, _ = _arrays()
    with pytest.raises(dg.InvalidArgumentError, match="both by position") as e:
        dg.batch_force_closure(P, N, 0.5, mu=0.5)
    assert isinstance(e.value, dg.InvalidOptionError | TypeError | ValueError)
    with pytest.raises(dg.InvalidArgumentError, match="positional") as e:
        dg.batch_force_closure(P, N, 0.5, "hard_finger")
    assert isinstance(e.value, dg.InvalidOptionError)

    def python_itself(a, b, *, mu):
        return a, b, mu

    for call in (lambda f: f(P, N, 0.5, mu=0.5), lambda f: f(P, N, 0.5, 1)):
        with pytest.raises(TypeError):
            call(python_itself)


def test_invariant_grasp_matrix_is_the_old_normalised_one():
    _, _, g = _arrays()
    with pytest.warns(DeprecationWarning, match="invariant_grasp_matrix"):
        old = dg.normalised_grasp_matrix(g)
    assert np.array_equal(old, dg.invariant_grasp_matrix(g))
    # And it is not G_n: the names said different things four letters apart.
    assert dg.invariant_grasp_matrix(g).shape != dg.normal_grasp_matrix(g).shape


def test_decorators_refuse_wrong_targets():
    with pytest.raises(TypeError):
        renamed_keyword("a", "b")(lambda x: x)
    with pytest.raises(TypeError):
        keyword_only("x", after=0)(lambda x: x)


def test_signatures_show_the_new_spelling():
    import inspect

    params = inspect.signature(dg.batch_force_closure).parameters
    assert params["mu"].kind is inspect.Parameter.KEYWORD_ONLY
    assert "contact_model" in params and "model" not in params


def test_warnings_point_at_the_callers_line():
    """Stacked wrappers still attribute the warning to the user's file."""
    P, N, _ = _arrays()
    with pytest.warns(DeprecationWarning) as record:
        dg.batch_force_closure(P, N, 0.5, model="hard_finger")
    assert {w.filename for w in record} == {__file__}
    with pytest.warns(DeprecationWarning) as record:
        dg.Contact([0, 0, 0], [1, 0, 0], model="frictionless").model  # noqa: B018
    assert {w.filename for w in record} == {__file__}


def _public_functions():
    """``(module, name, function)`` of every public function of the package."""
    import importlib
    import inspect
    import pkgutil

    names = [
        info.name
        for info in pkgutil.walk_packages(dg.__path__, "drakegrasp.")
        if not info.name.endswith("__main__") and ".models" not in info.name
    ]
    for module_name in sorted(names):
        module = importlib.import_module(module_name)
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            if inspect.isfunction(obj):
                yield module_name, name, obj


def test_no_public_function_spells_the_contact_model_model():
    import inspect

    found = [
        f"{module}.{name}"
        for module, name, function in _public_functions()
        if "model" in inspect.signature(function).parameters
    ]
    assert found == []


def test_no_public_function_takes_a_scalar_mu_by_position_after_other_arguments():
    import inspect

    found = []
    for module, name, function in _public_functions():
        parameters = list(inspect.signature(function).parameters.values())
        for i, p in enumerate(parameters):
            if p.name == "mu" and i > 0 and p.kind is not p.KEYWORD_ONLY:
                scalar = p.annotation in ("float", float)
                # an unannotated mu with a default is a choice, not a data array
                if scalar or (p.annotation is p.empty and p.default is not p.empty):
                    found.append(f"{module}.{name}")
    assert found == []


@pytest.mark.parametrize(
    "module, name, after",
    [
        ("drakegrasp.planning.weight", "weight_capacity", 3),
        ("drakegrasp.planning.ranking", "verdicts", 2),
        ("drakegrasp.planning.ranking", "robustness", 3),
        ("drakegrasp.planning.ranking", "perturbed_copies", 3),
        ("drakegrasp.planning.ranking", "grouped_verdicts", 2),
        ("drakegrasp.planning.reclose", "reclosed_robustness", 4),
        ("drakegrasp.planning.weight", "fan_capacity", 4),
    ],
)
def test_planning_stages_take_mu_by_keyword_after_their_arrays(module, name, after):
    import importlib
    import inspect

    function = getattr(importlib.import_module(module), name)
    parameters = list(inspect.signature(function).parameters.values())
    assert parameters[after].name == "mu"
    assert parameters[after].kind is inspect.Parameter.KEYWORD_ONLY
    assert all(p.kind is p.POSITIONAL_OR_KEYWORD for p in parameters[:after])


def test_planning_and_batch_stages_accept_the_old_spellings_with_a_warning():
    from drakegrasp.batch.build.construction import batched_characteristic_lengths
    from drakegrasp.batch.epsilon.routes import epsilon_l1_batch
    from drakegrasp.planning.weight import weight_capacity

    P, N, _ = _arrays(2)
    fingers = np.tile(np.arange(P.shape[1]), (2, 1))
    new = weight_capacity(
        P, N, fingers, mu=0.5, torque_scale=0.05, contact_model="hard_finger"
    )
    with pytest.warns(DeprecationWarning) as record:
        old = weight_capacity(
            P, N, fingers, 0.5, torque_scale=0.05, model="hard_finger"
        )
    messages = " ".join(str(w.message) for w in record)
    assert "mu=" in messages and "contact_model=" in messages
    assert np.array_equal(old, new)
    mu, nu = np.full(P.shape[:2], 0.5), np.zeros(P.shape[:2])
    p = np.zeros((2, 3))
    b = batched_characteristic_lengths(P, p)
    args = (P, N, mu, nu, p, b)
    new = epsilon_l1_batch(*args, contact_model="hard_finger", num_generators=8)
    with pytest.warns(DeprecationWarning, match="contact_model="):
        old = epsilon_l1_batch(*args, model="hard_finger", num_generators=8)
    assert np.array_equal(old, new) and np.all(new > 0)
    with pytest.raises(dg.InvalidOptionError, match="contact_model= only"):
        epsilon_l1_batch(
            *args, model="hard_finger", contact_model="hard_finger", num_generators=8
        )


def test_keyword_only_moves_a_whole_old_positional_tail():
    @keyword_only("mu", "clearance", after=1)
    def f(x, *, mu, clearance=0.0):
        return x, mu, clearance

    assert f(1, mu=0.5, clearance=2.0) == (1, 0.5, 2.0)
    with pytest.warns(DeprecationWarning, match="mu, clearance by position"):
        assert f(1, 0.5, 2.0) == (1, 0.5, 2.0)
    with pytest.warns(DeprecationWarning, match="passing mu by position"):
        assert f(1, 0.5, clearance=3.0) == (1, 0.5, 3.0)
    with pytest.raises(dg.InvalidArgumentError, match="clearance both"):
        f(1, 0.5, 2.0, clearance=3.0)
    with pytest.raises(dg.InvalidArgumentError, match="got 4 positional"):
        f(1, 0.5, 2.0, 4.0)
    with pytest.raises(TypeError):
        keyword_only(after=0)
    with pytest.raises(TypeError):
        keyword_only("mu", "x", after=1)(f.__wrapped__)


def test_sample_poses_takes_its_scalars_by_keyword():
    import inspect

    from drakegrasp.planning.placement import sample_poses

    params = inspect.signature(sample_poses).parameters
    for name in ("mu", "clearance", "rng", "tol"):
        assert params[name].kind is inspect.Parameter.KEYWORD_ONLY


def test_the_new_keyword_by_position_and_the_old_one_is_refused():
    from drakegrasp.batch.build.wrenches import wrenches_per_contact

    with pytest.raises(dg.InvalidOptionError, match="both model= .* contact_model"):
        wrenches_per_contact("hard_finger", 3, 8, model="soft_finger")
    with pytest.warns(DeprecationWarning):
        assert wrenches_per_contact(dim=3, num_generators=8, model="soft_finger") == 10


@pytest.mark.parametrize("given", [dg.ContactModel.HARD_FINGER, "hard_finger"])
def test_model_does_not_replace_a_hard_finger_the_caller_wrote(given):
    with pytest.raises(dg.InvalidOptionError, match="contact_model= only"):
        dg.Contact([0, 0, 0], [1, 0, 0], contact_model=given, model="frictionless")
    c = dg.Contact([0, 0, 0], [1, 0, 0], mu=0.5)
    with pytest.raises(dg.InvalidOptionError, match="contact_model= only"):
        c.with_(contact_model=given, model="frictionless")
    assert c.contact_model is dg.ContactModel.HARD_FINGER  # the default unchanged


@pytest.mark.parametrize("cls", [dg.AnalysisOptions, dg.BatchOptions])
def test_options_objects_take_model_as_the_deprecated_alias(cls):
    with pytest.warns(DeprecationWarning, match=rf"{cls.__name__}\(\): model="):
        old = cls(model="frictionless")
    assert old == cls(contact_model="frictionless")
    with pytest.raises(dg.InvalidOptionError, match="both model="):
        cls(model="frictionless", contact_model="hard_finger")


@pytest.mark.parametrize(
    "spelling",
    ["SOFT_FINGER", "Soft-Finger", " soft_finger", dg.ContactModel.SOFT_FINGER],
)
def test_every_entry_point_reads_a_contact_model_as_contact_model_parse_does(spelling):
    from drakegrasp.batch.build.construction import contact_kinds
    from drakegrasp.batch.build.wrenches import (
        batched_primitive_wrenches,
        wrenches_per_contact,
    )

    P, N, g = _arrays(2)
    mu, nu = np.full((2, 3), 0.5), np.full((2, 3), 0.1)
    args = (P, N, mu, nu, np.zeros((2, 3)), np.ones(2))
    expected = batched_primitive_wrenches(
        *args, contact_model="soft_finger", num_generators=8
    )
    got = batched_primitive_wrenches(*args, contact_model=spelling, num_generators=8)
    np.testing.assert_array_equal(got, expected)
    assert wrenches_per_contact(spelling, 3, 8) == 10
    np.testing.assert_array_equal(
        contact_kinds(mu, nu, contact_model=spelling, dim=3),
        contact_kinds(mu, nu, contact_model="soft_finger", dim=3),
    )
    assert dg.ContactModel.parse(spelling) is dg.ContactModel.SOFT_FINGER


def test_every_entry_point_refuses_an_unknown_contact_model_by_name():
    from drakegrasp.batch.build.construction import contact_kinds
    from drakegrasp.batch.build.wrenches import wrenches_per_contact

    mu = np.full((1, 3), 0.5)
    for call in (
        lambda: wrenches_per_contact("sticky", 3, 8),
        lambda: contact_kinds(mu, mu, contact_model="sticky", dim=3),
        lambda: dg.AnalysisOptions(contact_model="sticky"),
        lambda: dg.BatchOptions(contact_model="sticky"),
    ):
        with pytest.raises(
            dg.InvalidContactError, match="unknown contact model 'sticky'"
        ):
            call()


def test_dataclasses_replace_with_the_old_keyword_replaces_the_model(recwarn):
    # dataclasses.replace passes every field by name: model= came with the
    # current contact_model= and was refused as "both".
    import dataclasses
    import warnings

    for options in (dg.AnalysisOptions(), dg.BatchOptions()):
        with pytest.warns(DeprecationWarning, match="contact_model=") as record:
            new = dataclasses.replace(options, model="frictionless")
        assert new.contact_model is dg.ContactModel.FRICTIONLESS
        # attributed to this file, not to dataclasses or drakegrasp
        assert record[0].filename == __file__
        with pytest.warns(DeprecationWarning):
            assert options.replace(model="frictionless") == new
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert dataclasses.replace(dg.AnalysisOptions(), mu=0.3).mu == 0.3


def test_replace_refuses_both_spellings_and_a_contact_is_replaced_too():
    # The replace detection dropped a contact_model the user gave with model=.
    import dataclasses

    o = dg.AnalysisOptions(mu=0.5)
    for call in (
        lambda: o.replace(model="frictionless", contact_model="soft_finger"),
        lambda: dataclasses.replace(
            o, model="frictionless", contact_model="soft_finger"
        ),
        lambda: dg.BatchOptions().replace(
            model="frictionless", contact_model="soft_finger"
        ),
    ):
        with pytest.raises(dg.InvalidOptionError, match="both model="):
            call()
    c = dg.Contact([0, 0, 1], [0, 0, -1], mu=0.5)
    with pytest.warns(DeprecationWarning) as record:
        f = dataclasses.replace(c, model="frictionless")
    assert f.contact_model is dg.ContactModel.FRICTIONLESS
    assert record[0].filename == __file__
    with pytest.raises(dg.InvalidOptionError, match="both model="):
        dataclasses.replace(c, model="frictionless", contact_model="soft_finger")
