"""The metrics refuse a characteristic length out of scale with the grasp.

Every metric divides moments by ``b`` (the grasp's characteristic length, or
an explicit ``torque_scale``).  An explicit ``torque_scale`` was already held
to ``MOMENT_ARMS``; a Grasp built with ``characteristic_length=1e-15`` for
contacts a metre apart gave ε = 0 without a word (single grasp and batch), and
``1e-300`` a σ_min of 0.  The closure verdicts take any length (they are tested
at every valid one in ``tests/certificates/test_characteristic_length_range.py``);
the metrics now refuse, naming the length, in one range for both routes.
"""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.core.tolerances import MOMENT_ARMS

LOW, HIGH = MOMENT_ARMS


def _scaled(b: float) -> dg.Grasp:
    g = dg.examples.equator_fingers(mu=0.5)
    return dg.Grasp(
        g.contacts, reference_point=g.reference_point, characteristic_length=b
    )


def _extent(g: dg.Grasp) -> float:
    return float(np.max(np.linalg.norm(g.positions - g.reference_point, axis=1)))


METRICS = {
    "ferrari_canny": lambda g: dg.ferrari_canny(g),
    "min_singular_value": lambda g: dg.min_singular_value(g),
    "isotropy": lambda g: dg.isotropy(g),
    "grasp_quality": lambda g: dg.grasp_quality(g),
}


@pytest.mark.parametrize("name", sorted(METRICS))
@pytest.mark.parametrize("b", [1e-300, 1e-15, 1e6, 1e14, 1e30])
def test_a_length_out_of_scale_is_refused_by_name(name, b):
    g = _scaled(b)
    assert dg.force_closure(g).is_closure  # the verdict stands at any length
    with pytest.raises(
        dg.InvalidOptionError, match=r"characteristic_length = .* out of scale"
    ):
        METRICS[name](g)


def test_the_refusal_was_a_silent_zero_and_the_range_is_the_torque_scales():
    """The same bounds as an explicit ``torque_scale``: in range both give one ε."""
    g = _scaled(1.0)
    e = _extent(g)
    for b in (e / HIGH * 1.01, e / LOW * 0.99, 1e-9, 1e-3):
        eps_b = dg.ferrari_canny(_scaled(b))
        assert eps_b > 0.0
        assert eps_b == dg.ferrari_canny(g, torque_scale=b)
    for b in (e / HIGH / 1.01, e / LOW * 1.01):
        with pytest.raises(dg.InvalidOptionError, match="characteristic_length"):
            dg.ferrari_canny(_scaled(b))
        with pytest.raises(dg.InvalidOptionError, match="torque_scale"):
            dg.ferrari_canny(g, torque_scale=b)


def test_an_explicit_torque_scale_overrides_an_absurd_characteristic_length():
    g = _scaled(1e-15)
    assert dg.ferrari_canny(g, torque_scale=1.0) == dg.ferrari_canny(_scaled(1.0))


def test_contacts_at_the_reference_point_take_any_length():
    c = dg.Contact([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], mu=0.5)
    g = dg.Grasp([c, c], characteristic_length=1e-300)
    assert dg.min_singular_value(g) >= 0.0


def _stack(k: int = 3):
    g = dg.examples.equator_fingers(mu=0.5)
    return np.stack([g.positions] * k), np.stack([g.normals] * k)


@pytest.mark.parametrize("b", [1e-15, 1e14, [1.0, 1.0, 1e-15]])
def test_batch_epsilon_refuses_naming_the_grasp(b):
    P, N = _stack()
    index = 2 if np.ndim(b) else 0
    with pytest.raises(dg.InvalidGraspError, match=f"grasp {index} is .* out of scale"):
        dg.batch_epsilon_l1(P, N, mu=0.5, characteristic_lengths=b)


def test_batch_epsilon_in_range_agrees_with_the_single_grasp():
    P, N = _stack()
    b = np.array([1e-9, 1e-3, 10.0])
    eps = dg.batch_epsilon_l1(P, N, mu=0.5, characteristic_lengths=b)
    single = [dg.ferrari_canny(_scaled(x)) for x in b]
    np.testing.assert_allclose(eps, single, rtol=1e-6)


def test_a_ragged_batch_names_the_grasp_by_its_place_in_the_input():
    g = dg.examples.equator_fingers(mu=0.5)
    P = [g.positions[:2], g.positions, g.positions[:2], g.positions]
    N = [g.normals[:2], g.normals, g.normals[:2], g.normals]
    # Grasp 2 is in the first group (two contacts), grasp 1 in the second:
    # the message must name 1, the first in the input.
    b = [1.0, 1e-15, 1e-15, 1.0]
    for call in (
        lambda: dg.batch_epsilon_l1(P, N, mu=0.5, characteristic_lengths=b),
        lambda: dg.batch_force_closure(
            P, N, mu=0.5, characteristic_lengths=b, metrics=("sigma_min",)
        ),
    ):
        with pytest.raises(dg.InvalidGraspError, match="grasp 1 is 1e-15 m"):
            call()


@pytest.mark.parametrize(
    "options",
    [
        {"metrics": ("sigma_min",)},
        {"metrics": ["isotropy"]},
        {"options": dg.BatchOptions(metrics=("epsilon_l1",))},
    ],
)
def test_batch_closure_metrics_refuse_but_the_verdicts_do_not(options):
    P, N = _stack()
    plain = dg.batch_force_closure(P, N, mu=0.5, characteristic_lengths=1e-15)
    assert plain.is_closure.all()
    with pytest.raises(dg.InvalidGraspError, match="grasp 0 is 1e-15 m"):
        dg.batch_force_closure(P, N, mu=0.5, characteristic_lengths=1e-15, **options)
    form = dict(options)
    if "options" in form or "epsilon_l1" in form.get("metrics", ()):
        form = {"metrics": ("sigma_min",)}
    assert not dg.batch_form_closure(
        P, N, characteristic_lengths=1e-15
    ).is_closure.any()
    with pytest.raises(dg.InvalidGraspError, match="grasp 0 is 1e-15 m"):
        dg.batch_form_closure(P, N, characteristic_lengths=1e-15, **form)


def test_hostile_metrics_values_still_get_their_own_error():
    """The ragged pre-check reads ``metrics`` before it is validated."""
    g = dg.examples.equator_fingers(mu=0.5)
    P = [g.positions[:2], g.positions]
    N = [g.normals[:2], g.normals]
    with pytest.raises(dg.GraspError):
        dg.batch_force_closure(P, N, mu=0.5, metrics=5)
    with pytest.raises(dg.GraspError):
        dg.batch_force_closure(P, N, mu=0.5, metrics=[["a", "b"], ["c"]])


def test_the_batch_check_reads_positions_as_the_engine_does():
    """Nested lists are positions like arrays (the check ran on the raw input
    and raised ``AttributeError``); bad positions get the engine's own message,
    not a numpy error or a moment-arm refusal."""
    P, N = _stack()
    eps = dg.batch_epsilon_l1(
        P.tolist(), N.tolist(), mu=0.5, characteristic_lengths=1.0
    )
    np.testing.assert_array_equal(eps, dg.batch_epsilon_l1(P, N, mu=0.5))
    r = dg.batch_force_closure(
        P.tolist(),
        N.tolist(),
        mu=0.5,
        characteristic_lengths=1.0,
        metrics=("isotropy",),
    )
    assert r.is_closure.all()
    for bad in (P.astype(str), P * 1e200):
        with pytest.raises(dg.InvalidContactError, match="position"):
            dg.batch_epsilon_l1(bad, N, mu=0.5, characteristic_lengths=1.0)


def test_a_subnormal_extent_takes_the_default_length_everywhere():
    """Contacts within LENGTH_MIN of the reference point: the Grasp's default
    length is 1 m, which the metrics take (as for contacts at the point), on
    every route and kernel."""
    g0 = dg.examples.equator_fingers(mu=0.5)
    tiny = [dg.Contact(c.position * 1e-310, c.normal, mu=0.5) for c in g0.contacts]
    g = dg.Grasp(tiny)
    assert g.characteristic_length == 1.0
    assert dg.ferrari_canny(g) >= 0.0 and dg.min_singular_value(g) >= 0.0
    P, N = g.positions[None], g.normals[None]
    for kernel in ("auto", "numpy"):
        dg.batch_epsilon_l1(P, N, mu=0.5, kernel=kernel)
        dg.batch_force_closure(P, N, mu=0.5, metrics=("sigma_min",), kernel=kernel)


@pytest.mark.parametrize("empty", [{}, set(), (), []])
def test_empty_metrics_ask_for_none_on_both_routes(empty):
    g = dg.examples.equator_fingers(mu=0.5)
    P = [g.positions[:2], g.positions]
    N = [g.normals[:2], g.normals]
    r = dg.batch_force_closure(
        P, N, mu=0.5, characteristic_lengths=[1.0, 1e-15], metrics=empty
    )
    assert list(r.is_closure) == [False, True]


def test_a_one_shot_iterator_of_metrics_serves_every_group():
    """A ragged batch calls the engine once per contact count; ``iter([...])``
    was used up by the first group and the merge raised ``KeyError``."""
    g = dg.examples.equator_fingers(mu=0.5)
    P = [g.positions[:2], g.positions, g.positions]
    N = [g.normals[:2], g.normals, g.normals]
    r = dg.batch_force_closure(P, N, mu=0.5, metrics=iter(["isotropy"]))
    listed = dg.batch_force_closure(P, N, mu=0.5, metrics=["isotropy"])
    np.testing.assert_array_equal(r.metrics["isotropy"], listed.metrics["isotropy"])


def test_an_endless_iterator_of_metrics_is_refused_not_read_forever():
    import itertools

    g = dg.examples.equator_fingers(mu=0.5)
    P, N = _stack()
    ragged_P = [g.positions[:2], g.positions]
    ragged_N = [g.normals[:2], g.normals]
    for positions, normals in ((P, N), (ragged_P, ragged_N)):
        with pytest.raises(dg.InvalidOptionError, match="more than 1024 names"):
            dg.batch_force_closure(
                positions, normals, mu=0.5, metrics=itertools.repeat("isotropy")
            )


def test_other_ragged_options_still_refuse_iterators():
    """Only ``metrics`` is read from an iterator; ``mu=itertools.repeat(0.5)``
    is refused at once, as on the stacked route (it was read forever when
    every iterator option was materialised)."""
    import itertools

    g = dg.examples.equator_fingers(mu=0.5)
    ragged_P = [g.positions[:2], g.positions]
    ragged_N = [g.normals[:2], g.normals]
    with pytest.raises(dg.InvalidContactError, match="mu"):
        dg.batch_force_closure(ragged_P, ragged_N, mu=itertools.repeat(0.5))


@pytest.mark.parametrize("rows", [0, -1, 2.5, "3"])
def test_the_whole_batch_check_refuses_bad_rows(rows):
    from drakegrasp.batch.metrics import check_moment_arms_of_batch

    P, _ = _stack(7)
    with pytest.raises(dg.InvalidOptionError, match="rows"):
        check_moment_arms_of_batch(P, None, 1e-15, rows=rows)


@pytest.mark.parametrize("rows", [1, 3, 6, 7, 8])
def test_the_whole_batch_check_names_the_first_grasp_for_any_rows(rows):
    from drakegrasp.batch.metrics import check_moment_arms_of_batch

    P, _ = _stack(7)
    b = np.ones(7)
    b[[4, 6]] = 1e-15
    with pytest.raises(dg.InvalidGraspError, match="grasp 4 is"):
        check_moment_arms_of_batch(P, None, b, rows=rows)
    check_moment_arms_of_batch(P[:0], None, 1e-15, rows=rows)  # K = 0
