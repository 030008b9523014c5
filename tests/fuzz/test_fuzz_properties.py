"""Hypothesis fuzzing: hostile arrays, invariances and monotonicity.

Hostile values (NaN, inf, huge, tiny, complex, wrong shapes and types) must give
a clear GraspError or a right answer; verdicts must not change with units
(1e-9 to 1e9 m), the reference point (up to 1e6 b away), the scale of J, or
the length of the normals; a more capable contact never scores lower.  All
examples are derandomized so CI sees the same ones every run.
"""

import math
import warnings

import fuzz_cases
import fuzz_oracles as oracle
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import drakegrasp as dg
from drakegrasp.core import validation as V

SETTINGS = settings(
    derandomize=True,
    max_examples=40,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)

hostile_floats = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([1e308, -1e308, 1e200, 1e155, 1e-300, 5e-324, -0.0, 0.0]),
)
hostile_vectors = st.one_of(
    st.lists(hostile_floats, min_size=1, max_size=5),
    st.lists(
        st.complex_numbers(allow_nan=False, allow_infinity=False, max_magnitude=1e10),
        min_size=3,
        max_size=3,
    ),
    st.lists(st.text(max_size=3), min_size=3, max_size=3),
    st.sampled_from([None, "abc", [[1.0, 0.0], [0.0]], {"x": 1}, b"\x00\x01", True]),
)
coefficients = st.one_of(st.just(0.0), st.floats(V.COEFFICIENT_MIN, V.COEFFICIENT_MAX))
log_mu = st.one_of(st.just(0.0), st.floats(-12, 12).map(lambda e: 10.0**e))


def _outcome(call, expect="either", check=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        outcome, detail = fuzz_cases.run_case(
            fuzz_cases.Case("hypothesis", "", call, expect, check)
        )
    assert outcome in ("clear GraspError", "plausible verdict"), f"{outcome}: {detail}"
    return outcome


def _valid(v) -> bool:
    try:
        a = np.asarray(v)
    except (TypeError, ValueError):
        return False
    if a.dtype.kind not in "iuf" or a.shape not in ((2,), (3,)):
        return False
    a = a.astype(float)
    return bool(np.all(np.isfinite(a)) and np.max(np.abs(a)) <= V.POSITION_BOUND)


@SETTINGS
@given(position=hostile_vectors, normal=hostile_vectors)
def test_contact_refuses_or_normalises_right(position, normal):
    def check(c):
        # Only valid inputs may be answered, and then exactly.
        n = np.asarray(normal, dtype=float)
        return (
            _valid(position)
            and np.array_equal(c.position, np.asarray(position, dtype=float))
            and np.allclose(c.normal, oracle.unit(n), atol=1e-15)
        )

    _outcome(lambda: dg.Contact(position, normal), check=check)


@SETTINGS
@given(
    mu=st.one_of(hostile_floats, st.sampled_from(["0.3", None, 1j, [0.3]])),
    nu=hostile_floats,
)
def test_coefficients_in_range_or_refused(mu, nu):
    def check(c):
        ok = [
            isinstance(x, float)
            and (x == 0 or V.COEFFICIENT_MIN <= x <= V.COEFFICIENT_MAX)
            for x in (mu, nu)
        ]
        return all(ok) and c.mu == mu and c.torsional_friction == nu

    _outcome(
        lambda: dg.Contact(
            [0, 0, 1],
            [0, 0, -1],
            mu=mu,
            contact_model="soft_finger",
            torsional_friction=nu,
        ),
        check=check,
    )


@SETTINGS
@given(
    value=st.one_of(
        hostile_floats, st.sampled_from([None, "abc", 1j, True, 10**9, 2, 2.5])
    ),
    option=st.sampled_from(["tol", "rank_tol", "num_generators"]),
    fn=st.sampled_from(
        [dg.force_closure, dg.form_closure, dg.force_closure_exact, dg.lp2_d_star]
    ),
)
def test_options_refused_or_answered_in_range(value, option, fn):
    import inspect

    if option not in inspect.signature(fn).parameters:
        return
    g = fuzz_cases._valid_grasp()

    def check(result):
        checker = {
            "tol": V.check_tol,
            "rank_tol": V.check_rank_tol,
            "num_generators": V.check_num_generators,
        }
        checker[option](value)  # a valid value: answered, not refused
        return True

    _outcome(lambda: fn(g, **{option: value}), check=check)


@SETTINGS
@given(
    P=st.lists(
        st.lists(hostile_floats, min_size=3, max_size=3), min_size=1, max_size=4
    ),
    mu=st.one_of(hostile_floats, st.sampled_from([None, "x", 1j])),
)
def test_batch_refuses_or_answers_hostile_arrays(P, mu):
    g = fuzz_cases._valid_grasp()
    P = np.array(P, dtype=float)[None]
    N = np.repeat(g.normals[: P.shape[1]][None], 1, 0) if P.shape[1] <= 3 else None
    if N is None:
        return
    _outcome(lambda: dg.batch_force_closure(P, N, mu=mu))


def _random_grasp(rng, num, dim=3, mu=0.5, model="hard_finger", nu=None, spread=0.35):
    p = rng.normal(size=(num, dim))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    n = -p + spread * rng.normal(size=(num, dim))
    kw = {"torsional_friction": nu} if nu is not None else {}
    return dg.Grasp(
        [dg.Contact(p[i], n[i], mu=mu, contact_model=model, **kw) for i in range(num)]
    )


def _moved(g, unit, ref_scale, rng, normal_scale=1.0):
    ref = rng.normal(size=g.dim) * ref_scale
    contacts = [
        c.with_(position=c.position * unit, normal=c.normal * normal_scale)
        for c in g.contacts
    ]
    # b is part of a soft finger's model (its torsion bound is b ν), and its
    # default depends on p: keep it, scaled with the units.
    return dg.Grasp(
        contacts,
        reference_point=ref * g.characteristic_length * unit,
        characteristic_length=g.characteristic_length * unit,
    )


@SETTINGS
@given(
    seed=st.integers(0, 2**32 - 1),
    unit_exp=st.floats(-9, 9),
    ref_exp=st.floats(0, 6),
    normal_exp=st.floats(-150, 150),
    mu=log_mu,
    num=st.integers(2, 5),
    model=st.sampled_from(["hard_finger", "soft_finger", "frictionless"]),
)
def test_verdicts_invariant_to_units_reference_and_normal_length(
    seed, unit_exp, ref_exp, normal_exp, mu, num, model
):
    rng = np.random.default_rng(seed)
    nu = 0.3 if model == "soft_finger" else None
    g = _random_grasp(rng, num, mu=mu, model=model, nu=nu)
    h = _moved(g, 10.0**unit_exp, 10.0**ref_exp, rng, 10.0**normal_exp)
    for fn in (dg.force_closure, dg.form_closure, dg.force_closure_exact):
        a, b = fn(g), fn(h)
        assert a.rank == b.rank
        if not (a.near_boundary or b.near_boundary):
            assert a.is_closure == b.is_closure
            assert b.d_star == pytest.approx(a.d_star, abs=1e-6)


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), scale_exp=st.floats(-9, 9))
def test_lp3_invariant_to_the_scale_of_j(seed, scale_exp):
    rng = np.random.default_rng(seed)
    g = _random_grasp(rng, 3)
    J = rng.normal(size=(g.num_components, int(rng.integers(1, 10))))
    a = dg.internal_forces(g, J)
    b = dg.internal_forces(g, J * 10.0**scale_exp)
    assert a.null_space_dim == b.null_space_dim and a.passes == b.passes


@pytest.mark.parametrize("scale", [1e-200, 1e-300, 1e-160])
def test_a_jacobian_whose_squares_underflow_keeps_its_joints(scale):
    # |J_ij| ~ 1e-200: the column norms (sums of squares) underflowed to 0, so
    # internal_forces dropped every joint (d* = 1 where J gives 0) and
    # max_load read the torque rows 1e-200 x <= 2e-200 as no limit, holding
    # 2.6 times the payload with torques past the limits.
    rng = np.random.default_rng(5)
    g = fuzz_cases._valid_grasp()
    J = rng.normal(size=(g.num_components, 4))
    a, b = dg.internal_forces(g, J), dg.internal_forces(g, J * scale)
    assert a.null_space_dim == b.null_space_dim and a.passes == b.passes
    assert b.d_star == pytest.approx(a.d_star, abs=1e-6)
    d = rng.normal(size=6)
    ref = dg.max_load(g, d, hand_jacobian=J, torque_limits=2.0, max_normal_force=5)
    tiny = dg.max_load(
        g, d, hand_jacobian=J * scale, torque_limits=2.0 * scale, max_normal_force=5
    )
    assert tiny.alpha == pytest.approx(ref.alpha, rel=1e-5)
    assert np.all(np.abs(tiny.joint_torques) <= 2.0 * scale * (1 + 1e-6))


@SETTINGS
@given(seed=st.integers(0, 2**32 - 1), mu=log_mu, num=st.integers(2, 5))
def test_single_path_agrees_with_the_scipy_lp_for_every_mu(seed, mu, num):
    rng = np.random.default_rng(seed)
    g = _random_grasp(rng, num, mu=mu)
    want = oracle.closure_verdict(g.positions, g.normals, [mu] * num)
    if want is not None:
        assert dg.force_closure(g).is_closure == want[0]


@settings(SETTINGS, max_examples=12)
@given(
    seed=st.integers(0, 2**32 - 1),
    mu=st.floats(-12, 12).map(lambda e: 10.0**e),
    nu=st.floats(-12, 12).map(lambda e: 10.0**e),
    more=st.floats(1.0, 1e6),
    num=st.integers(3, 6),
)
def test_a_more_capable_contact_never_scores_lower(seed, mu, nu, more, num):
    """soft >= hard >= frictionless; larger mu, nu >= smaller: verdicts, d*, ε."""
    rng = np.random.default_rng(seed)
    hard = _random_grasp(rng, num, mu=mu, spread=0.2)
    fl = hard.with_friction(contact_model="frictionless")
    soft = hard.with_friction(contact_model="soft_finger", torsional_friction=nu)
    softer = soft.with_friction(torsional_friction=min(nu * more, V.COEFFICIENT_MAX))
    rough = hard.with_friction(min(mu * more, V.COEFFICIENT_MAX))
    chain = [fl, hard, soft, softer]
    for fn in (dg.force_closure, dg.force_closure_exact):
        r = [fn(g) for g in chain]
        assert [x.is_closure for x in r] == sorted(x.is_closure for x in r)
        assert r[2].d_star >= r[1].d_star - 1e-7 and r[3].d_star >= r[2].d_star - 1e-7
        assert fn(rough).is_closure >= r[1].is_closure
    assert dg.force_closure(rough).d_star >= dg.force_closure(hard).d_star - 1e-7
    eps = [dg.ferrari_canny(g) for g in (fl, hard, rough, soft, softer)]
    tol = 1e-9 * max(1.0, max(eps))
    assert eps[0] <= eps[1] + tol and eps[1] <= eps[2] + tol
    assert eps[1] <= eps[3] + tol and eps[3] <= eps[4] + tol


@pytest.mark.parametrize("mu", [1e-12, 1e-9, 1e-6])
def test_epsilon_of_thin_cones_is_linear_in_mu(mu):
    # The equator grasp's ε grows linearly with μ for small μ (its wrench set
    # is μ thin in four directions): ε(μ)/μ at 1e-12 ... 1e-6 matches the
    # well-conditioned value at 1e-3 (Qhull on raw points gave 0 below 1e-8).
    from drakegrasp.core import examples as ex

    slope = dg.ferrari_canny(ex.equator_fingers(1e-3)) / 1e-3
    eps = dg.ferrari_canny(ex.equator_fingers(mu))
    assert dg.force_closure(ex.equator_fingers(mu)).is_closure
    assert eps / mu == pytest.approx(slope, rel=2e-3)
    assert eps == pytest.approx(4.472e-1 * mu, rel=1e-3)


def test_soft_finger_epsilon_with_huge_torsion_is_at_least_hard():
    # Issue 9: ν >= 1e9 gave ε = 0 where hard fingers give 0.276.
    from drakegrasp.core import examples as ex

    hard = ex.equator_fingers(0.5)
    e_hard = dg.ferrari_canny(hard)
    assert e_hard == pytest.approx(0.2759, abs=5e-5)
    previous = e_hard
    for nu in (1e-3, 1.0, 1e3, 1e9, 1e12):
        e = dg.ferrari_canny(
            hard.with_friction(contact_model="soft_finger", torsional_friction=nu)
        )
        assert e >= previous - 1e-9
        previous = e


def test_soft_finger_d_star_with_small_torsion_is_at_least_hard():
    # Issue 9: ν = 0.01 gave d* = 0.0002 where hard fingers give 0.121.
    rng = np.random.default_rng(4)
    for _ in range(5):
        hard = _random_grasp(rng, 4, mu=0.3)
        d_hard = dg.force_closure(hard).d_star
        for nu in (1e-12, 1e-6, 0.01, 1.0):
            soft = hard.with_friction(
                contact_model="soft_finger", torsional_friction=nu
            )
            assert dg.force_closure(soft).d_star >= d_hard - 1e-8
            assert math.isfinite(dg.force_closure_exact(soft).d_star)


@pytest.mark.parametrize("mu", [1e-12, 1e-6, 1e-3, 0.3, 1.0, 10.0, 1e3, 1e6, 1e12])
def test_batch_agrees_with_the_single_path_across_the_mu_range(mu):
    # Issue 9: mu >= 1e78 gave 0/60 closed with converged=True in batch; now mu
    # is refused outside [1e-12, 1e12] and agrees with the single path inside.
    rng = np.random.default_rng(int(mu * 1e3) % 2**32)
    K, N = 25, 4
    p = rng.normal(size=(K, N, 3))
    p /= np.linalg.norm(p, axis=2, keepdims=True)
    n = -p + 0.4 * rng.normal(size=(K, N, 3))
    batch = dg.batch_force_closure(p, n, mu=mu)
    single = [
        dg.force_closure(
            dg.Grasp([dg.Contact(p[k, i], n[k, i], mu=mu) for i in range(N)])
        )
        for k in range(K)
    ]
    assert batch.converged.all()
    np.testing.assert_array_equal(batch.is_closure, [r.is_closure for r in single])
    np.testing.assert_allclose(batch.d_star, [r.d_star for r in single], atol=1e-6)


@pytest.mark.parametrize(
    "limits",
    [
        {"torque_limits": 0.0},
        {"torque_limits": 5e-324},
        {"max_squeeze": 0.0},
        {"max_squeeze": 0.0, "torque_limits": 0.0},
    ],
    ids=["passive", "subnormal torque", "no squeeze", "both"],
)
def test_max_load_with_every_limit_zero_is_zero_or_inf(limits):
    # Homogeneous: α d held for one α > 0 is held for all.  Passive joints
    # or max_squeeze = 0 gave α = 9.6e-11 and 4.1e-11 (solver noise), and a
    # 5e-324 N·m limit (0 N on its column) the same, where 1e-300 scales.
    rng = np.random.default_rng(1)
    g = fuzz_cases._valid_grasp()
    J = rng.normal(size=(g.num_components, 4))
    w = np.array([0.0, 0.0, -9.81, 0.01, 0.0, 0.0])
    r = dg.max_load(g, w, hand_jacobian=J, **limits)
    assert r.alpha == 0.0
    small = dg.max_load(g, w, hand_jacobian=J, torque_limits=1e-300)
    assert 0.0 < small.alpha < 1e-299


def test_a_jacobian_without_torque_limits_gets_a_certificate():
    # hand_jacobian with no torque_limits: the dual's certificate priced its
    # joint multipliers against torque_limits=None and raised IndexError.
    rng = np.random.default_rng(1)
    g = fuzz_cases._valid_grasp()
    J = rng.normal(size=(g.num_components, 4))
    w = [0.0, 0.0, -9.81, 0.01, 0.0, 0.0]
    r = dg.max_load(g, w, hand_jacobian=J, max_squeeze=1.0)
    assert r.alpha == pytest.approx(dg.max_load(g, w, max_squeeze=1.0).alpha)
    assert r.certificate.check(g, hand_jacobian=J).holds
    f = dg.grasp_forces(g, w, hand_jacobian=J, max_squeeze=1.0)
    assert not f.feasible and f.certificate.check(g, hand_jacobian=J).holds


_CALLABLES = {
    "grasp_matrix": dg.grasp_matrix,
    "force_closure": dg.force_closure,
    "form_closure": dg.form_closure,
    "grasp_quality": dg.grasp_quality,
    "batch_force_closure": dg.batch_force_closure,
    "batch_form_closure": dg.batch_form_closure,
    "Contact": dg.Contact,
    "Grasp": dg.Grasp,
    "AnalysisOptions": dg.AnalysisOptions,
    "BatchOptions": dg.BatchOptions,
}


@SETTINGS
@given(
    name=st.sampled_from(sorted(_CALLABLES)),
    num_args=st.integers(0, 6),
    keywords=st.lists(
        st.one_of(
            st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,12}", fullmatch=True),
            st.sampled_from(["mu", "tol", "Tol", "mu_", "contact_modle", "grasp"]),
        ),
        max_size=3,
        unique=True,
    ),
    value=st.one_of(hostile_floats, st.sampled_from([None, "abc", 1j, True])),
)
def test_a_call_of_any_shape_is_answered_or_refused_clearly(
    name, num_args, keywords, value
):
    # Any number of positional arguments and any keywords, known or not, with
    # hostile values: a clear GraspError naming the function, or an answer.
    fn = _CALLABLES[name]
    g = fuzz_cases._valid_grasp()
    args = [g, *[value] * (num_args - 1)] if num_args else []
    kwargs = dict.fromkeys(keywords, value)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        outcome, detail = fuzz_cases.run_case(
            fuzz_cases.Case("calls", "", lambda: fn(*args, **kwargs), "either", None)
        )
    assert outcome in ("clear GraspError", "plausible verdict"), f"{outcome}: {detail}"
