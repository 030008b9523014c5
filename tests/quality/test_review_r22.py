"""Review r22: the resistible wrench at every scale, ``torque_scale`` against the
grasp's extent, and the L∞ ε of :func:`grasp_quality` decided by its cost first.

Every numpy warning is an error here: a bad input must give a clear
:class:`~drakegrasp.GraspError`, never a warning or a silent wrong answer.
"""

import math
import time

import numpy as np
import pytest
from scipy.optimize import linprog
from scipy.spatial import ConvexHull

import drakegrasp as dg
from drakegrasp._solvers import solve
from drakegrasp.errors import InvalidOptionError
from drakegrasp.quality import build_max_resistible_wrench_program

pytestmark = pytest.mark.filterwarnings("error")

DOWN = np.array([0.0, 0.0, -1.0, 0.0, 0.0, 0.0])
SCALES = [1e-9, 1e-7, 1e-5, 1e-3, 1.0, 1e3, 1e5, 1e7, 1e9]


def _equator(**kw):
    return dg.examples.equator_fingers(0.5, **kw)


def _random_grasp(rng, num, dim=3, **kw):
    pos = rng.normal(size=(num, dim))
    nrm = -pos + 0.3 * rng.normal(size=(num, dim))
    return dg.Grasp(
        [dg.Contact(p, n, mu=0.6, **kw) for p, n in zip(pos, nrm, strict=True)]
    )


# --------------------------------------------------------------------------
# A. max_resistible_wrench: one answer per unit at every scale


def _alpha_by_linprog(grasp, direction, fmax, n_g=8):
    """α of the generator form with HiGHS: f_i = Σ_k λ_ik s_k, Σ_k λ_ik <= f_max,i.

    A second formulation (generators, not facets; scipy, not Drake/Clp),
    solved at unit scale only.
    """
    wrenches = dg.primitive_wrenches(grasp, num_generators=n_g, torque_scale=1.0)
    W = np.vstack(wrenches).T
    owner = np.concatenate([np.full(len(w), i) for i, w in enumerate(wrenches)])
    m = W.shape[1]
    c = np.zeros(m + 1)
    c[-1] = -1.0
    A_ub = np.zeros((grasp.num_contacts, m + 1))
    for i in range(grasp.num_contacts):
        A_ub[i, :m] = owner == i
    res = linprog(
        c,
        A_ub=A_ub,
        b_ub=np.broadcast_to(fmax, grasp.num_contacts),
        A_eq=np.hstack([W, np.asarray(direction, float)[:, None]]),
        b_eq=np.zeros(W.shape[0]),
        bounds=[(0, None)] * (m + 1),
        method="highs",
    )
    assert res.status == 0
    return res.x[-1]


def _check_forces(grasp, result, direction, fmax):
    """``G f = -α d``, every ``f_n <= f_max`` and every cone, relative to ``f_max``."""
    fmax = np.broadcast_to(np.asarray(fmax, float), grasp.num_contacts)
    top = float(np.max(fmax))
    f = np.concatenate(result.contact_forces)
    G = dg.grasp_matrix(grasp)
    residual = np.linalg.norm(G @ f + result.alpha * np.asarray(direction))
    assert residual <= 1e-9 * top
    assert np.array_equal(result.wrench, result.alpha * np.asarray(direction))
    for fc, c, bound in zip(result.contact_forces, grasp.contacts, fmax, strict=True):
        assert fc[0] <= bound + 1e-8 * top
        F = dg.friction_cone_facets(
            c, characteristic_length=grasp.characteristic_length
        )
        assert np.all(F @ fc >= -1e-8 * top)  # Clp's tolerance, at unit scale too


@pytest.mark.parametrize("scale", SCALES)
def test_alpha_per_newton_of_bound_is_the_same_at_every_scale(scale):
    # f_max = 1e-7 gave α / f_max = 1.81 (true 1.5) with forces that did not
    # balance (residual 1.06 f_max); f_max = 1e30 a SolverError.
    g = _equator()
    ref = _alpha_by_linprog(g, DOWN, 1.0)
    assert ref == pytest.approx(1.5, rel=1e-9)
    r = dg.max_resistible_wrench(g, DOWN, max_normal_force=scale)
    assert r.alpha / scale == pytest.approx(ref, rel=1e-9)
    _check_forces(g, r, DOWN, scale)


@pytest.mark.parametrize("scale", SCALES)
def test_alpha_times_the_direction_is_the_same_at_every_scale(scale):
    # ‖d‖ = 1e7 gave α = 0 (true 1.5e-7).
    g = _equator()
    d = DOWN * scale
    r = dg.max_resistible_wrench(g, d, max_normal_force=1.0)
    assert r.alpha * scale == pytest.approx(1.5, rel=1e-9)
    _check_forces(g, r, d, 1.0)


@pytest.mark.parametrize(
    "kind", ["hard", "soft", "planar", "unequal bounds"], ids=lambda k: k
)
def test_random_grasps_agree_with_linprog_at_every_pair_of_scales(kind):
    rng = np.random.default_rng(22)
    for _ in range(2):
        if kind == "soft":
            g = _random_grasp(
                rng, 3, contact_model="soft_finger", torsional_friction=0.3
            )
        elif kind == "planar":
            g = _random_grasp(rng, 3, dim=2)
        else:
            g = _random_grasp(rng, 3)
        d = rng.normal(size=g.wrench_dim)
        d /= np.linalg.norm(d)
        fmax = rng.uniform(0.5, 1.0, size=3) if kind == "unequal bounds" else 1.0
        ref = _alpha_by_linprog(g, d, fmax)
        for f_scale, d_scale in [(1e-9, 1e9), (1e9, 1e-9), (1e-6, 1e-6), (1e6, 1e3)]:
            r = dg.max_resistible_wrench(
                g, d * d_scale, max_normal_force=np.multiply(fmax, f_scale)
            )
            assert r.alpha * d_scale / f_scale == pytest.approx(ref, rel=1e-6, abs=1e-9)
            _check_forces(g, r, d * d_scale, np.multiply(fmax, f_scale))


def test_huge_bounds_are_solved_not_refused():
    g = _equator()
    for fmax in (1e30, 1e300):
        r = dg.max_resistible_wrench(g, DOWN, max_normal_force=fmax)
        assert r.status == "kSolutionFound"
        assert r.alpha / fmax == pytest.approx(1.5, rel=1e-9)


def test_zero_bounds_give_exactly_zero():
    # Was α = 4.2e-12 (the solver's noise) with forces to match.
    r = dg.max_resistible_wrench(_equator(), DOWN, max_normal_force=0.0)
    assert r.alpha == 0.0
    assert all(np.all(f == 0.0) for f in r.contact_forces)
    assert np.all(r.wrench == 0.0)


def test_unit_scale_is_the_callers_program_to_the_bit():
    # At ‖d‖ = 1 and max f_max = 1 the LP solved is the one built in the
    # caller's units: the same α and forces to the last bit.
    rng = np.random.default_rng(5)
    for g, d, fmax in [
        (_equator(), DOWN, 1.0),
        (_equator(), np.eye(6)[0], [1.0, 0.5, 0.25]),
        (_random_grasp(rng, 4), -np.eye(6)[4], 1.0),
    ]:
        prog, v = build_max_resistible_wrench_program(g, d, max_normal_force=fmax)
        direct = solve(prog, "lp")
        r = dg.max_resistible_wrench(g, d, max_normal_force=fmax)
        assert r.alpha == max(float(direct.GetSolution(v.alpha)), 0.0)
        full = np.zeros(g.num_components)
        full[v.columns] = direct.GetSolution(v.forces)
        assert np.array_equal(np.concatenate(r.contact_forces), full)


@pytest.mark.parametrize(
    "d_scale,fmax",
    [(1e-300, 1e300), (1e300, 1e-300), (1e-10, 1e300), (1e-310, 1.0)],
)
def test_answers_past_the_float_range_are_refused(d_scale, fmax):
    with pytest.raises(InvalidOptionError, match="max_normal_force.*direction"):
        dg.max_resistible_wrench(_equator(), DOWN * d_scale, max_normal_force=fmax)


# --------------------------------------------------------------------------
# B. torque_scale against the grasp's extent


def _metric_calls():
    J = np.random.default_rng(0).normal(size=(9, 4))
    return {
        "ferrari_canny": lambda g, b: dg.ferrari_canny(g, torque_scale=b),
        "ferrari_canny Linf": lambda g, b: dg.ferrari_canny(
            g, norm="Linf", torque_scale=b
        ),
        "primitive_wrenches": lambda g, b: dg.primitive_wrenches(g, torque_scale=b),
        "grasp_singular_values": lambda g, b: dg.grasp_singular_values(
            g, torque_scale=b
        ),
        "min_singular_value": lambda g, b: dg.min_singular_value(g, torque_scale=b),
        "isotropy": lambda g, b: dg.isotropy(g, torque_scale=b),
        "wrench_ellipsoid_volume": lambda g, b: dg.wrench_ellipsoid_volume(
            g, torque_scale=b
        ),
        "hand_object_matrix": lambda g, b: dg.hand_object_matrix(g, J, torque_scale=b),
        "distance_to_singularity": lambda g, b: dg.distance_to_singularity(
            g, J, torque_scale=b
        ),
        "grasp_quality": lambda g, b: dg.grasp_quality(g, torque_scale=b),
    }


@pytest.mark.parametrize("name", list(_metric_calls()))
@pytest.mark.parametrize("torque_scale", [1e-15, 1e-50, 1e-100, 2e4, 1e30])
def test_torque_scales_out_of_scale_with_the_grasp_are_refused(name, torque_scale):
    # ε was 0 for a force-closure grasp at 1e-15, σ_min 1.04e19 at 1e-50.
    g = _equator()  # contacts 1 m from the reference point
    with pytest.raises(InvalidOptionError) as info:
        _metric_calls()[name](g, torque_scale)
    text = str(info.value)
    assert "torque_scale" in text and f"{torque_scale:g}" in text
    assert "within 1 m" in text and "[0.0001, 1e+12]" in text
    assert "[1e-12, 10000] m" in text


def test_torque_scales_at_the_ends_of_the_range_are_right():
    g = _equator()  # extent 1 m: torque_scale in [1e-12, 1e4]
    # Independent route: the hull of the scaled primitive wrenches with scipy,
    # at a torque_scale well inside the range (ε converges as it shrinks).
    W = np.vstack(dg.primitive_wrenches(g, torque_scale=1e-4))
    hull = ConvexHull(W)
    ref = float(np.min(-hull.equations[:, -1]))
    assert dg.ferrari_canny(g, torque_scale=1e-12) == pytest.approx(ref, rel=1e-6)
    # σ of S G built by hand (moments over b), against the metric at the end.
    for b in (1e-12, 1e4):
        G = dg.grasp_matrix(g)
        G[3:] /= b
        want = np.linalg.svd(G, compute_uv=False)
        got = dg.grasp_singular_values(g, torque_scale=b)
        assert got == pytest.approx(want, rel=1e-9)
    assert dg.min_singular_value(g, torque_scale=1e-12) == pytest.approx(
        math.sqrt(3.0), rel=1e-9
    )


def test_any_torque_scale_when_every_contact_is_at_the_reference_point():
    g = dg.Grasp(
        [
            dg.Contact([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], mu=0.5),
            dg.Contact([0.0, 0.0, 0.0], [-1.0, 0.0, 0.0], mu=0.5),
        ]
    )
    for b in (1e-300, 1.0, 1e30):
        s = dg.grasp_singular_values(g, torque_scale=b)
        assert np.all(np.isfinite(s))


def test_the_extent_is_measured_from_the_reference_point():
    # Contacts 1 mm from p, 100 m from the frame's origin: the extent is 1 mm,
    # so 1e-12 m is in range (1e9) and 1e-16 m is not (1e13); measured from
    # the origin, 1e-12 m would have been refused too (1e14).
    contacts = [
        dg.Contact([100.0 + 1e-3 * x, 1e-3 * y, 0.0], [-x, -y, 0.0], mu=0.5)
        for x, y in [(1, 0), (-0.5, 0.866), (-0.5, -0.866)]
    ]
    g = dg.Grasp(contacts, reference_point=[100.0, 0.0, 0.0])
    assert np.all(np.isfinite(dg.grasp_singular_values(g, torque_scale=1e-12)))
    with pytest.raises(InvalidOptionError, match="within 0.001 m"):
        dg.grasp_singular_values(g, torque_scale=1e-16)


# --------------------------------------------------------------------------
# C. grasp_quality's L∞ ε: its cost decided before it is paid


def test_default_linf_is_skipped_where_its_second_pass_is_too_costly():
    # 3 equator fingers, 64 generators: the first pass (1.67 M candidates)
    # finds the symmetric grasp's dependent faces, the second needs 2.0 M.
    # Was an InvalidOptionError from the default linf=None.
    q = dg.grasp_quality(_equator(), num_generators=64)
    assert q.ferrari_canny_linf is None
    assert q.ferrari_canny_l1 > 0.28
    with pytest.raises(InvalidOptionError, match="needs 2009745 candidate"):
        dg.grasp_quality(_equator(), num_generators=64, linf=True)


def test_default_linf_of_soft_fingers_is_skipped_at_once():
    # Soft fingers with 32 generators: 13.3 M candidates in the first pass.
    g = _equator(contact_model="soft_finger", torsional_friction=0.2)
    start = time.perf_counter()
    q = dg.grasp_quality(g, num_generators=32)
    assert q.ferrari_canny_linf is None
    assert q.ferrari_canny_l1 == dg.ferrari_canny(g, num_generators=32)
    assert time.perf_counter() - start < 10.0


def test_explicit_linf_is_refused_before_the_l1_hull():
    # 3 hard fingers with 128 generators: the L1 hull alone takes 30 s; the
    # refusal (the same message, the same count) now comes from the models.
    g = _equator()
    start = time.perf_counter()
    with pytest.raises(InvalidOptionError) as direct:
        dg.ferrari_canny(g, norm="Linf", num_generators=128)
    with pytest.raises(InvalidOptionError) as summary:
        dg.grasp_quality(g, num_generators=128, linf=True)
    assert time.perf_counter() - start < 5.0
    text = (
        "the L∞ Ferrari–Canny metric of this grasp needs 12977670 candidate facet "
        "normals (more than LINF_MAX_CANDIDATES = 2000000); use norm='L1', fewer "
        "contacts or fewer generators"
    )
    assert str(direct.value) == text == str(summary.value)


def test_the_count_from_the_models_is_the_count_of_the_built_faces():
    from drakegrasp.quality import epsilon as E

    # Independent route: the faces Qhull finds on each contact's wrench set,
    # against the faces of its model, for every contact model.
    rng = np.random.default_rng(3)
    cases = [
        dict(contact_model="hard_finger", mu=0.5),
        dict(contact_model="hard_finger", mu=0.0),
        dict(contact_model="frictionless", mu=0.5),
        dict(contact_model="soft_finger", mu=0.5, torsional_friction=0.2),
        dict(contact_model="soft_finger", mu=0.0, torsional_friction=0.2),
        dict(contact_model="soft_finger", mu=0.5, torsional_friction=0.0),
    ]
    for kw in cases:
        for n_g in (3, 8, 17):
            pos = rng.normal(size=(4, 3))
            g = dg.Grasp([dg.Contact(p, -p, **kw) for p in pos])
            W = dg.primitive_wrenches(g, num_generators=n_g)
            A = E._whitening(np.vstack(W))
            A = np.eye(6) if A is None else A
            extent = float(np.max(np.linalg.norm(pos, axis=1)))
            for c, w in zip(g.contacts, W, strict=True):
                built = E._face_directions(np.vstack([np.zeros((1, 6)), w @ A.T]))
                model = E._model_face_counts(c, n_g, g.characteristic_length, extent)
                assert model == E._face_counts([built])[0], (kw, n_g)
    planar = _random_grasp(rng, 3, dim=2)
    W = dg.primitive_wrenches(planar)
    for c, w in zip(planar.contacts, W, strict=True):
        built = E._face_directions(np.vstack([np.zeros((1, 3)), w]))
        assert E._model_face_counts(c, 8, 1.0, 1.0) == E._face_counts([built])[0]


def test_results_that_worked_are_unchanged():
    rng = np.random.default_rng(8)
    grasps = [
        (_equator(), 8),
        (_equator(), 16),
        (_equator(contact_model="soft_finger", torsional_friction=0.2), 4),
        (dg.examples.planar_two_finger_square(0.6), 8),
        (_random_grasp(rng, 3), 8),
        (_random_grasp(rng, 4, dim=2), 8),
    ]
    for g, n_g in grasps:
        q = dg.grasp_quality(g, num_generators=n_g)
        assert q.ferrari_canny_l1 == dg.ferrari_canny(g, num_generators=n_g)
        assert q.ferrari_canny_linf == dg.ferrari_canny(
            g, norm="Linf", num_generators=n_g
        )
        assert q.ferrari_canny_linf is not None
    # Documented figures of the equator grasp, 8 generators (L1 and L∞).
    q = dg.grasp_quality(_equator())
    assert q.ferrari_canny_linf == pytest.approx(0.6708203932499367, rel=1e-12)


def test_a_grasp_out_of_force_closure_keeps_linf_zero_at_any_cost():
    # Three soft fingers pushing one face: no force closure, so ε_∞ = 0 as
    # ε_1 = 0, however many candidates its L∞ would need (13.3 M here).
    g = dg.Grasp(
        [
            dg.Contact(
                [1.0, y, z],
                [-1.0, 0.0, 0.0],
                mu=0.5,
                contact_model="soft_finger",
                torsional_friction=0.2,
            )
            for y, z in [(0.0, 0.0), (0.3, 0.1), (-0.2, 0.3)]
        ]
    )
    for linf in (None, True):
        q = dg.grasp_quality(g, num_generators=32, linf=linf)
        assert q.ferrari_canny_linf == 0.0 and q.ferrari_canny_l1 == 0.0
    assert dg.ferrari_canny(g, norm="Linf", num_generators=32) == 0.0
