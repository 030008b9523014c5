"""A passive palm in the weight capacity (``weight_capacity(palm=)``).

A welded palm pushes the object only as hard as the load or a finger's normal
force presses the object into it.  Checked against a primal written out here
from the contacts (scipy's HiGHS), against the closed forms of a jaw over a
palm, and for its invariances: it never raises a capacity, it leaves grasps
without a palm contact bitwise alone, and it follows the contacts' order and
a rigid motion.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from drakegrasp import InvalidOptionError
from drakegrasp.core.contact import Contact
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.planning.weight import (
    WEIGHT_DIRECTIONS,
    build_weight_capacity_program,
    palm_rows,
    weight_capacity,
)
from drakegrasp.quality import primitive_wrenches


def _highs_with_palm(P, N, fingers, palm, u, *, mu, b):
    """α(u) with a passive palm, written from the contacts (scipy's HiGHS).

    The best over the sets of palm faces (distinct palm normals) that carry
    force: the other faces' contacts carry nothing, and along each active
    face's normal e the contacts' normal forces and the weight press the
    object into it, friction aside (a palm contact facing e exactly, the
    other wall of a slot, counts 0).  Every group, the palm included, is
    bounded by the squeeze.
    """
    import itertools

    grasp = Grasp([Contact(p, n, mu=mu) for p, n in zip(P, N, strict=True)])
    per_contact = primitive_wrenches(grasp, torque_scale=b)
    W = np.vstack(per_contact)
    owner = np.concatenate([np.full(len(w), i) for i, w in enumerate(per_contact)])
    g = np.asarray(fingers)[owner]
    M = len(W)
    on = np.asarray(fingers) == palm
    faces = []
    for i in np.flatnonzero(on):
        if all(N[i] @ e < 1 - 1e-6 for e in faces):
            faces.append(N[i])
    face_of = {
        int(i): next(r for r, e in enumerate(faces) if N[i] @ e >= 1 - 1e-6)
        for i in np.flatnonzero(on)
    }
    groups = [np.r_[(g == f).astype(float), 0.0] for f in range(max(3, g.max() + 1))]
    best = 0.0
    for size in range(len(faces) + 1):
        for active in itertools.combinations(range(len(faces)), size):
            rows, rhs = list(groups), [1.0] * len(groups)
            for r in active:
                e = faces[r]
                row = np.zeros(M + 1)
                for j in range(M):
                    i = owner[j]
                    dot = N[i] @ e
                    row[j] = 0.0 if on[i] and dot < -1 + 1e-6 else dot
                row[-1] = u @ e
                rows.append(row)
                rhs.append(0.0)
            bounds = [
                (0, 0) if on[owner[j]] and face_of[int(owner[j])] not in active
                else (0, None)
                for j in range(M)
            ]  # fmt: skip
            res = linprog(
                np.r_[np.zeros(M), -1.0], A_ub=np.array(rows), b_ub=rhs,
                A_eq=np.hstack([W.T, np.r_[u, 0, 0, 0][:, None]]),
                b_eq=np.zeros(6), bounds=[*bounds, (0, None)], method="highs",
            )  # fmt: skip
            assert res.status == 0
            best = max(best, -res.fun)
    return best


def _jaw_over_palm(rng, K):
    """Two pads of two contacts across x, a palm of two contacts below (+z)."""
    P = np.zeros((K, 6, 3))
    N = np.zeros((K, 6, 3))
    for k in range(K):
        r, b, h = rng.uniform(0.02, 0.05), rng.uniform(0.005, 0.02), 0.04
        P[k] = [[-r, 0, b], [-r, 0, -b], [r, 0, b], [r, 0, -b],
                [-0.01, 0, -h], [0.01, 0, -h]]  # fmt: skip
        N[k] = [[1, 0, 0]] * 2 + [[-1, 0, 0]] * 2 + [[0, 0, 1]] * 2
    P += rng.normal(0, 0.003, P.shape)
    N += rng.normal(0, 0.05, N.shape)
    N /= np.linalg.norm(N, axis=2, keepdims=True)
    return P, N, np.tile([0, 0, 1, 1, 2, 2], (K, 1))


@pytest.mark.parametrize("solver", ["batch", "drake"])
def test_agrees_with_the_primal_written_from_the_contacts(solver):
    rng = np.random.default_rng(21)
    P, N, F = _jaw_over_palm(rng, 4)
    P[2:] = rng.normal(0, 0.03, (2, 6, 3))  # and two grasps of no jaw at all
    a = weight_capacity(P, N, F, mu=1.0, torque_scale=0.05, solver=solver, palm=2)
    for k in range(len(P)):
        ref = [
            _highs_with_palm(P[k], N[k], F[k], 2, u, mu=1.0, b=0.05)
            for u in WEIGHT_DIRECTIONS
        ]
        assert a[k] == pytest.approx(ref, rel=1e-6, abs=1e-7)


def test_a_jaws_palm_adds_nothing_sideways_and_bears_what_presses_into_it():
    # the jaw squeezes across x, the palm's normal is +z: a sideways weight
    # presses nothing into the palm, so the jaw holds it alone; the old model
    # let the pads' friction pull the box into the palm and use its friction
    rng = np.random.default_rng(22)
    P, N, F = _jaw_over_palm(rng, 6)
    N[:, :4, 2] = 0.0  # pads exactly across the palm's normal
    N[:, 4:] = [0.0, 0.0, 1.0]
    N /= np.linalg.norm(N, axis=2, keepdims=True)
    dirs = np.array([[0.0, 1, 0], [0, -1, 0], [1, 0, 0], [0, 0, -1], [0, 0, 1]])
    kw = dict(mu=1.0, torque_scale=0.05, directions=dirs)
    old = weight_capacity(P, N, F, **kw)
    new = weight_capacity(P, N, F, **kw, palm=2)
    jaw = weight_capacity(P[:, :4], N[:, :4], F[:, :4], **kw)
    # sideways (±y, +x) and away from the palm (+z): the jaw's own capacity
    sideways = [0, 1, 2, 4]
    assert new[:, sideways] == pytest.approx(jaw[:, sideways], rel=1e-6, abs=1e-8)
    assert np.all(old[:, :2] > jaw[:, :2] + 0.05)  # the optimism it removes
    # into the palm (-z): the palm bears the weight; nothing is lost there
    assert new[:, 3] == pytest.approx(old[:, 3], rel=1e-6, abs=1e-8)
    assert np.all(new[:, 3] > jaw[:, 3] + 0.5)


def test_a_palm_alone_holds_nothing_it_is_not_pressed_against():
    # a welded slot and floor, no finger: along the slot nothing presses the
    # object into any wall, so nothing holds it there (0.729 when the palm
    # was squeezed like a finger)
    P = np.array([[[0, 0.02, 0], [0, -0.02, 0], [0.01, 0.02, 0], [0.01, -0.02, 0],
                   [0, 0, -0.02]]])  # fmt: skip
    N = np.array([[[0, -1.0, 0], [0, 1, 0], [0, -1, 0], [0, 1, 0], [0, 0, 1]]])
    F = np.full((1, 5), 2)
    kw = dict(mu=1.0, torque_scale=0.05, directions=[[1.0, 0, 0], [0, 0, -1]])
    assert weight_capacity(P, N, F, **kw)[0, 0] > 0.7
    along, down = weight_capacity(P, N, F, **kw, palm=2)[0]
    assert along == pytest.approx(0.0, abs=1e-12)
    assert down == pytest.approx(1.0)  # the floor bears it


def test_a_ball_in_a_v_shaped_palm_bears_on_both_faces():
    # A helper's review of the second form: bounded by the largest single
    # face's share, a ball resting in a 45-degree V (the weight's reaction
    # alpha / cos 45 on the faces) held 1.0 where the palm squeezed like a
    # finger held 1.249; the faces' own rows let it bear as it does
    r = 0.03
    s45 = np.sqrt(0.5)
    P = np.array([[[0, -r, 0], [0, r, 0], [r * s45, 0, -r * s45],
                   [-r * s45, 0, -r * s45]]])  # fmt: skip
    N = -P / r
    F = np.array([[0, 1, 2, 2]])
    kw = dict(mu=0.2, torque_scale=0.05, directions=[[0.0, 0, -1]])
    squeezed = weight_capacity(P, N, F, **kw)
    passive = weight_capacity(P, N, F, **kw, palm=2)
    assert passive == pytest.approx(squeezed, rel=1e-6)
    ref = _highs_with_palm(P[0], N[0], F[0], 2, np.array([0.0, 0, -1]), mu=0.2, b=0.05)
    assert passive[0, 0] == pytest.approx(ref, rel=1e-6)


def test_fingers_pushing_off_the_palm_buy_it_no_force():
    # a slab between jaw pads tilted 0.2 rad, one pad pushing it into the
    # palm and the other as much off it: no net push into the palm, so a
    # sideways weight is the jaw's alone (2.097 when each pushing finger
    # counted without the other's pull)
    t = 0.2
    P = np.array([[[-0.03, 0, 0.01], [-0.03, 0, -0.01], [0.03, 0, 0.01],
                   [0.03, 0, -0.01], [0, 0, -0.04]]])  # fmt: skip
    n0, n1 = [np.cos(t), 0, -np.sin(t)], [-np.cos(t), 0, np.sin(t)]
    N = np.array([[n0, n0, n1, n1, [0, 0, 1.0]]])
    F = np.array([[0, 0, 1, 1, 2]])
    kw = dict(mu=1.0, torque_scale=0.05, directions=[[0.0, 1, 0]])
    jaw = weight_capacity(P[:, :4], N[:, :4], F[:, :4], **kw)
    got = weight_capacity(P, N, F, **kw, palm=2)
    assert got == pytest.approx(jaw, rel=1e-6)
    ref = _highs_with_palm(P[0], N[0], F[0], 2, np.array([0.0, 1, 0]), mu=1.0, b=0.05)
    assert got[0, 0] == pytest.approx(ref, rel=1e-6)


def test_nearly_opposed_palm_normals_agree_across_routes():
    # a slot whose walls tilt 8e-8 off opposite: the first model's mean
    # normal was 1e-7 long, its row badly scaled, and the batch route
    # certified capacities up to 10.7 where the program found 0
    P = np.array([[[-0.0292872, 0.0027126, 0.0008796],
                   [0.0262880, -0.0006953, 0.0003813],
                   [0.0003210, 0.0173969, -0.0333309],
                   [0.0010753, -0.0193496, -0.0299784]]])  # fmt: skip
    e = 7.855353126764793e-08
    N = np.array([[[1.0, 0, 0], [-1, 0, 0], [0, -1, e], [0, 1, e]]])
    F = np.array([[0, 1, 2, 2]])
    kw = dict(mu=5.0, torque_scale=0.05, palm=2)
    batch = weight_capacity(P, N, F, **kw)
    program = weight_capacity(P, N, F, **kw, solver="drake")
    # (capacities of order μ e = 4e-7 sit at the solvers' tolerances)
    assert batch == pytest.approx(program, rel=1e-6, abs=1e-5)
    ref = [_highs_with_palm(P[0], N[0], F[0], 2, u, mu=5.0, b=0.05)
           for u in WEIGHT_DIRECTIONS]  # fmt: skip
    assert batch[0] == pytest.approx(ref, rel=1e-6, abs=1e-5)


def test_a_finger_pressing_towards_the_palm_lets_it_push_back():
    # one finger above (normal -z) presses the object onto the palm (normal
    # +z): the palm's normal force may match the finger's, as in the old model
    P = np.array([[[0, 0, 0.03], [0.01, 0, -0.03], [-0.01, 0, -0.03],
                   [0, 0.01, -0.03]]])  # fmt: skip
    N = np.array([[[0, 0, -1.0], [0, 0, 1], [0, 0, 1], [0, 0, 1]]])
    F = np.array([[0, 1, 1, 1]])  # finger 0 above, the palm (label 1) below
    kw = dict(mu=0.5, torque_scale=0.05)
    old = weight_capacity(P, N, F, **kw)
    new = weight_capacity(P, N, F, **kw, palm=1)
    assert new == pytest.approx(old, rel=1e-6, abs=1e-8)
    # sideways each side's friction, μ times its 1 N: 1.0; the worst diagonal 0.72
    assert np.min(new) > 0.4


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), mu=st.sampled_from([0.3, 0.7, 1.0, 2.0]))
# two palm normals 1 mrad apart, one face whose row was whichever came first:
# a permutation moved a capacity by 4e-4 (found by hypothesis in CI)
@example(seed=41550, mu=0.3)
# a capacity of 0 on a degenerate LP: 2.5e-13 in a batch of three, 2.1e-6 after
# a permutation, where Clp (the fallback, and solver="drake" alike) stops
# (found by hypothesis in CI)
@example(seed=32385, mu=0.3)
def test_never_raises_a_capacity_and_follows_order_and_rigid_motion(seed, mu):
    rng = np.random.default_rng(seed)
    P, N, F = _jaw_over_palm(rng, 3)
    P[1] = rng.normal(0, 0.03, (6, 3))  # a grasp of no particular shape
    kw = dict(mu=mu, torque_scale=0.05)
    old = weight_capacity(P, N, F, **kw)
    new = weight_capacity(P, N, F, **kw, palm=2)
    assert np.all(new <= old + 1e-7)
    perm = rng.permutation(6)
    shuffled = weight_capacity(P[:, perm], N[:, perm], F[:, perm], **kw, palm=2)
    # abs: Clp's accuracy on a degenerate capacity LP (2.1e-6 where 0 is exact)
    assert shuffled == pytest.approx(new, rel=1e-6, abs=1e-5)
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    R = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip
    turned = weight_capacity(
        P @ R.T, N @ R.T, F, **kw, palm=2, directions=WEIGHT_DIRECTIONS @ R.T
    )
    # A linearised cone turns with its normal only up to its generators' roll:
    # each inscribed 8-gon lies between the cones of mu cos(pi/8) and mu, so
    # the turned grasp holds what the unturned one holds at mu cos(pi/8), and
    # no more than at mu / cos(pi/8), direction by direction.  (A 10 % band
    # on the least direction failed at seed 112, mu 0.3: 0.3295 against
    # 0.3702, within these bounds.)
    c = np.cos(np.pi / DEFAULT_NUM_GENERATORS)
    inner = weight_capacity(P, N, F, **{**kw, "mu": mu * c}, palm=2)
    outer = weight_capacity(P, N, F, **{**kw, "mu": mu / c}, palm=2)
    jaws = [0, 2]
    assert np.all(turned[jaws] >= inner[jaws] - 1e-7)
    assert np.all(turned[jaws] <= outer[jaws] + 1e-7)
    # frictionless contacts have no generators to roll: exactly invariant
    # (twelve contacts round a ball, the palm's four below it)
    d = rng.normal(size=(1, 12, 3))
    d[0, 8:] = [0.0, 0.0, -1.0] + rng.normal(0, 0.3, (4, 3))
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    ball = np.array([[0] * 4 + [1] * 4 + [2] * 4])
    kw = dict(mu=0.0, torque_scale=0.05, contact_model="frictionless", palm=2)
    flat = weight_capacity(0.04 * d, -d, ball, **kw)
    turned = weight_capacity(
        0.04 * d @ R.T, -d @ R.T, ball, **kw, directions=WEIGHT_DIRECTIONS @ R.T
    )
    assert turned == pytest.approx(flat, rel=1e-6, abs=1e-8)


def test_grasps_without_a_palm_contact_keep_their_numbers_bitwise():
    rng = np.random.default_rng(23)
    P, N, F = _jaw_over_palm(rng, 5)
    F[1:3] = [0, 0, 1, 1, 0, 1]  # no contact of the palm's label
    kw = dict(mu=0.8, torque_scale=0.05)
    old = weight_capacity(P, N, F, **kw)
    new = weight_capacity(P, N, F, **kw, palm=2)
    assert np.array_equal(new[1:3], old[1:3])
    assert not np.array_equal(new[[0, 3, 4]], old[[0, 3, 4]])


@pytest.mark.parametrize("solver", ["batch", "drake"])
def test_a_grasps_capacity_does_not_depend_on_the_grasps_beside_it(solver):
    # A jaw over a palm with a floor (+z) and a wall (+y): two faces, so every
    # set of them is tried.  Beside it in one call, a grasp whose palm has
    # five faces (more than MAX_PALM_FACES: only none and all are tried) made
    # the first grasp's sets "none and all" too (fuzz, round 27).
    P = np.array(
        [
            [-0.03, 0, 0.01],
            [-0.03, 0, -0.01],
            [0.03, 0, 0.01],
            [0.03, 0, -0.01],
            [0, 0, -0.04],
            [0, -0.03, 0],
            [-0.03, 0, 0.01],
        ]
    )
    N = np.array(
        [[1, 0, 0], [1, 0, 0], [-1, 0, 0], [-1, 0, 0], [0, 0, 1], [0, 1, 0], [1, 0, 0]],
        float,
    )
    F = np.array([0, 0, 1, 1, 2, 2, 0])
    Pb = np.array(
        [
            [-0.03, 0, 0],
            [0.03, 0, 0],
            [0, 0, -0.03],
            [0, 0.03, 0],
            [0, -0.03, 0],
            [0.02, 0.02, -0.02],
            [-0.02, -0.02, -0.02],
        ]
    )
    Nb = -Pb / np.linalg.norm(Pb, axis=1, keepdims=True)
    Fb = np.array([0, 1, 2, 2, 2, 2, 2])  # fmt: skip
    kw = dict(mu=0.5, torque_scale=0.05, palm=2, solver=solver)
    alone = weight_capacity(P[None], N[None], F[None], **kw)[0]
    beside = weight_capacity(np.stack([P, Pb]), np.stack([N, Nb]), np.stack([F, Fb]),
                             **kw)  # fmt: skip
    np.testing.assert_allclose(beside[0], alone, rtol=1e-7, atol=1e-9)
    # a set of one face matters here: 1.316 and 1.184 N/N, not none-or-both's 0.816
    np.testing.assert_allclose(alone[7:10], [1.3163, 1.1839, 0.8165], atol=1e-4)


def test_the_program_for_inspection_has_the_palms_row():
    from pydrake.solvers import Solve

    rng = np.random.default_rng(24)
    P, N, F = _jaw_over_palm(rng, 1)
    grasp = Grasp([Contact(p, n, mu=1.0) for p, n in zip(P[0], N[0], strict=True)])
    per_contact = primitive_wrenches(grasp, torque_scale=0.05)
    W = np.vstack(per_contact)
    per = len(per_contact[0])
    groups = np.repeat(F[0], per)
    a, c, face, has = palm_rows(N, F, 2, per, WEIGHT_DIRECTIONS)
    assert has.tolist() == [True] and a.shape[1] == 2  # the palm's two normals
    prog, alpha = build_weight_capacity_program(
        W, groups, WEIGHT_DIRECTIONS, passive=(a[0], c[0])
    )
    result = Solve(prog)
    assert result.is_success()
    # each set of faces that carry force: the others' wrenches left out
    faces = np.repeat(face[0], per)
    best = np.zeros(len(WEIGHT_DIRECTIONS))
    for active in ([], [0], [1], [0, 1]):
        idle = (faces >= 0) & ~np.isin(faces, active)
        prog_a, alpha_a = build_weight_capacity_program(
            np.where(idle[:, None], 0.0, W), groups, WEIGHT_DIRECTIONS,
            passive=(a[0][active], c[0][active]) if active else None,
        )  # fmt: skip
        best = np.maximum(best, Solve(prog_a).GetSolution(alpha_a))
    assert np.all(result.GetSolution(alpha) <= best + 1e-7)
    want = weight_capacity(P, N, F, mu=1.0, torque_scale=0.05, palm=2)[0]
    assert best == pytest.approx(want, rel=1e-6, abs=1e-7)
    plain, alpha0 = build_weight_capacity_program(W, groups, WEIGHT_DIRECTIONS)
    looser = Solve(plain).GetSolution(alpha0)
    assert np.all(best <= looser + 1e-7)


@pytest.mark.parametrize("palm", [True, -1, 1.5, "2", 64, np.nan, [2]])
def test_a_bad_palm_label_is_named(palm):
    P, N, F = _jaw_over_palm(np.random.default_rng(25), 1)
    with pytest.raises(InvalidOptionError, match="palm must be None or a finger"):
        weight_capacity(P, N, F, mu=1.0, torque_scale=0.05, palm=palm)


def test_drake_drops_a_palm_grasp_between_the_two_models(drake_models_dir, monkeypatch):
    # Drake's WSG-50 on drakegrasp's hex prism, mu = 1 (the plant's): with
    # the palm squeezed like a finger, two candidates resting on the palm
    # ranked first and third, at 1.19 N and 1.49 N a finger.  In Drake each
    # drops at 1.1 times that and holds at 1.5 times the passive palm's need
    # (2.10 N and 2.30 N).
    from drakegrasp.planning import plan_grasps, planning_scene, ranking, shake_test

    scene = planning_scene(
        "package://drakegrasp/objects/hex_prism.sdf", models_dir=drake_models_dir
    )

    def plan():
        return plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=300, mu=1.0, seed=0, workers=1,
        )  # fmt: skip

    passive = plan()
    squeezed = ranking.weight_capacity
    monkeypatch.setattr(
        ranking, "weight_capacity", lambda *a, palm=None, **k: squeezed(*a, **k)
    )
    before = {c.sample: c for c in plan()}
    monkeypatch.undo()
    moved = [
        c for c in passive if c.squeeze_needed > 1.2 * before[c.sample].squeeze_needed
    ]
    assert len(moved) >= 2
    palm = "Schunk_Gripper::body"
    assert all(any(k.finger_body == palm for k in c.contacts) for c in moved)
    for c in moved[:2]:
        old = before[c.sample].squeeze_needed
        low = shake_test(scene.add_models, c, squeeze=1.1 * old)
        high = shake_test(scene.add_models, c, squeeze=1.5 * c.squeeze_needed)
        assert not low.held_from_seat, (c.sample, str(low))
        assert high.held_from_seat, (c.sample, str(high))
