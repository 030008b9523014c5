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
    with pytest.warns(DeprecationWarning):
        assert new.with_(model="hard_finger").contact_model is (
            dg.ContactModel.HARD_FINGER
        )


def test_both_spellings_at_once_are_refused():
    with pytest.raises(dg.InvalidContactError, match="contact_model= only"):
        dg.Contact(
            [0, 0, 0], [1, 0, 0], model="frictionless", contact_model="hard_finger"
        )
    P, N, _ = _arrays()
    with pytest.raises(dg.InvalidOptionError, match="contact_model= only"):
        dg.batch_force_closure(
            P, N, mu=0.5, model="hard_finger", contact_model="hard_finger"
        )
    with pytest.raises(dg.InvalidContactError, match="unexpected keyword"):
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
    P, N, _ = _arrays()
    with pytest.raises(dg.InvalidOptionError, match="both by position"):
        dg.batch_force_closure(P, N, 0.5, mu=0.5)
    with pytest.raises(dg.InvalidOptionError, match="positional"):
        dg.batch_force_closure(P, N, 0.5, "hard_finger")


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
