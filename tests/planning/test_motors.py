"""The torque a multi-finger grasp needs: a second LP, and the shake test.

The torque capacity ``β(u)`` is checked against the same program written here
over the cones' generators and solved by scipy's HiGHS; the torque needed
against physics: on the YCB soup can, Drake's Allegro hand at 0.5 N·m per
joint holds a candidate that needs well below that and drops one that needs
well above.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from grasp_builders import generator_matrix
from scipy.optimize import linprog

import drakegrasp as dg
from drakegrasp.closure.payload import max_load
from drakegrasp.core.friction_cone import friction_cone_generators
from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning import plan_grasps, planning_scene, shake_test
from drakegrasp.planning.cloud import CloudContact
from drakegrasp.planning.motors import (
    TORQUE_CHECK,
    finger_jacobian,
    motor_limit,
    torque_capacity,
    torque_needed,
    with_torques_needed,
)
from drakegrasp.planning.weight import WEIGHT_DIRECTIONS

ALLEGRO = (
    "package://drake_models/allegro_hand_description/sdf/"
    "allegro_hand_description_right.sdf"
)
SOUP = "package://drake_models/ycb/005_tomato_soup_can.sdf"
SHAKE = dict(stiffness=20.0, damping=1.0)


@pytest.fixture(scope="module")
def allegro_on_soup(drake_models_dir):
    scene = planning_scene(SOUP, hand_url=ALLEGRO, models_dir=drake_models_dir)
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    scene.plant.GetJointByName("joint_12").set_angle(ctx, 1.0)  # thumb opposed
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=100, mu=1.0, seed=0, robustness_samples=8,
    )  # fmt: skip
    weight = scene.object_body.get_mass(ctx) * 9.81
    return scene, [c for c in result if c.is_closure], weight, result


def _beta_by_generators(candidate, J, u) -> float:
    """max β: G S λ + β [u; 0] = 0, |Jᵀ S λ| <= 1, λ >= 0 (scipy HiGHS)."""
    grasp = candidate.grasp
    G = dg.grasp_matrix(grasp)
    S = generator_matrix(grasp)
    n = S.shape[1]
    A_eq = np.hstack([G @ S, np.concatenate([u, np.zeros(3)])[:, None]])
    T = J.T @ S
    A_ub = np.vstack([np.hstack([T, np.zeros((len(T), 1))]),
                      np.hstack([-T, np.zeros((len(T), 1))])])  # fmt: skip
    cost = np.zeros(n + 1)
    cost[-1] = -1.0
    res = linprog(
        cost, A_ub=A_ub, b_ub=np.ones(len(A_ub)), A_eq=A_eq, b_eq=np.zeros(6),
        bounds=[(0, None)] * (n + 1), method="highs",
    )  # fmt: skip
    assert res.status == 0
    return float(res.x[-1])


def test_torque_capacity_matches_a_second_lp(allegro_on_soup):
    scene, closed, _, _ = allegro_on_soup
    for candidate in closed[:3]:
        J = finger_jacobian(scene.plant, scene.context, candidate, scene.object_body)
        assert J.shape == (3 * candidate.num_contacts, 16)
        beta = torque_capacity(scene.plant, scene.context, candidate, scene.object_body)
        expected = [_beta_by_generators(candidate, J, u) for u in WEIGHT_DIRECTIONS]
        np.testing.assert_allclose(beta, expected, rtol=1e-6, atol=1e-9)
        # A second formulation: drakegrasp's payload program (facet rows,
        # normalised), one direction at a time.
        payload = [
            max_load(
                candidate.grasp,
                np.concatenate([u, np.zeros(3)]),
                hand_jacobian=J,
                torque_limits=1.0,
                cones="polyhedral",
                certify=False,
            ).alpha  # fmt: skip
            for u in WEIGHT_DIRECTIONS
        ]
        np.testing.assert_allclose(beta, payload, rtol=1e-6, atol=1e-9)


def test_torque_needed_scales_with_the_weight_and_leaves_the_context(
    allegro_on_soup,
):
    scene, closed, weight, result = allegro_on_soup
    q = scene.plant.GetPositions(scene.plant.GetMyContextFromRoot(scene.context))
    one = torque_needed(scene.plant, scene.context, closed[0], scene.object_body,
                        weight=weight)  # fmt: skip
    two = torque_needed(scene.plant, scene.context, closed[0], scene.object_body,
                        weight=2 * weight)  # fmt: skip
    assert two == pytest.approx(2 * one, rel=1e-9)
    after = scene.plant.GetPositions(scene.plant.GetMyContextFromRoot(scene.context))
    np.testing.assert_array_equal(after, q)
    assert np.isnan(
        torque_needed(
            scene.plant,
            scene.context,
            closed[0],
            scene.object_body,
            weight=float("nan"),
        )  # fmt: skip
    )
    with pytest.raises(dg.InvalidOptionError, match="weight"):
        torque_needed(scene.plant, scene.context, closed[0], scene.object_body,
                      weight=-1.0)  # fmt: skip


def test_plan_grasps_sets_it_on_the_best(allegro_on_soup):
    scene, closed, weight, result = allegro_on_soup
    top = [c for c in closed if not np.isnan(c.torque_needed)]
    assert 0 < len(top) <= TORQUE_CHECK
    checked = result.candidates[:TORQUE_CHECK]  # every force-closure one of them
    assert [c.sample for c in top] == [c.sample for c in checked if c.is_closure]
    for c in top[:2]:
        assert c.torque_needed == pytest.approx(
            torque_needed(
                scene.plant, scene.context, c, scene.object_body, weight=weight
            ),  # fmt: skip
            rel=1e-9,
        )
        assert "N·m per motor" in str(c)
        assert c.to_dict()["torque_needed"] == pytest.approx(c.torque_needed)
        # The JSON names the geometries of each contact and whose surface its
        # normal is (review r22: a contact on a model's marker sphere could
        # not be told from one on a face without re-planning in Python).
        for row, contact in zip(c.to_dict()["contacts"], c.contacts, strict=True):
            assert row["finger_geometry"] == contact.finger_geometry_name
            assert row["object_geometry"] == contact.object_geometry_name
            assert row["normal_source"] == contact.normal_source


def test_torque_needed_predicts_the_shake_test(allegro_on_soup):
    scene, closed, weight, result = allegro_on_soup
    needed = [
        torque_needed(scene.plant, scene.context, c, scene.object_body, weight=weight)
        for c in closed[:20]
    ]
    pairs = list(zip(closed[:20], needed, strict=True))
    light = next(c for c, t in pairs if t < 0.35)
    heavy = next(c for c, t in pairs if 1.5 < t < np.inf)
    assert shake_test(scene.add_models, light, squeeze=0.5, **SHAKE).held
    assert not shake_test(scene.add_models, heavy, squeeze=0.5, **SHAKE).held


def _with_palm_contact(scene, candidate):
    """``candidate`` plus a contact of the palm (hand_root) on the object's
    surface point nearest the palm, its normal pointing from the palm."""
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    saved = plant.GetPositions(ctx).copy()
    try:
        candidate.apply(plant, ctx, object_body=scene.object_body)
        palm = plant.GetBodyByName("hand_root")
        X_WO = candidate.X_WO
        p_OP = X_WO.inverse().multiply(
            plant.EvalBodyPoseInWorld(ctx, palm).translation()
        )
        centre = np.asarray(candidate.reference_point)
        n_O = (centre - p_OP) / np.linalg.norm(centre - p_OP)
        p_OC = centre - 0.03 * n_O  # on the can's side, facing the palm
        X_WF = plant.EvalBodyPoseInWorld(ctx, palm)
        p_FC = X_WF.inverse().multiply(X_WO.multiply(p_OC))
        inspector = plant.get_geometry_query_input_port().Eval(ctx).inspector()
    finally:
        plant.SetPositions(ctx, saved)
    first = candidate.contacts[0]
    palm_geometry = plant.GetCollisionGeometriesForBody(palm)[0]  # on its body
    contact = dataclasses.replace(
        first, p_OC=p_OC, nhat_O=n_O, p_FC=p_FC,
        finger_body=plant.GetModelInstanceName(palm.model_instance()) + "::hand_root",
        finger_body_index=palm.index(),
        finger_geometry=palm_geometry,
        finger_geometry_name=inspector.GetName(palm_geometry),
    )  # fmt: skip
    return dataclasses.replace(candidate, contacts=(*candidate.contacts, contact))


def test_a_palm_contact_is_passive_in_the_torque_capacity(allegro_on_soup):
    # A helper's review: the torque LP let a palm contact (rows of J zero)
    # push with any force, so finger friction could buy its push, as the
    # weight capacity's palm did before it was made passive
    scene, closed, weight, result = allegro_on_soup
    c = closed[0]
    with_palm = _with_palm_contact(scene, c)
    J = finger_jacobian(scene.plant, scene.context, with_palm, scene.object_body)
    assert not np.any(J[-3:])  # the palm: no finger joint moves it
    alone = torque_capacity(scene.plant, scene.context, c, scene.object_body)
    passive = torque_capacity(
        scene.plant, scene.context, with_palm, scene.object_body
    )  # fmt: skip
    # a free palm, solved here: the generators' LP without the palm's row
    grasp = with_palm.grasp
    S = np.hstack(
        [
            np.vstack([np.zeros((3 * i, 8)), friction_cone_generators(k, 8),
                       np.zeros((3 * (grasp.num_contacts - i - 1), 8))])
            for i, k in enumerate(grasp.contacts)
        ]
    )  # fmt: skip
    G = dg.grasp_matrix(grasp)
    free = []
    for u in WEIGHT_DIRECTIONS:
        n = S.shape[1]
        res = linprog(
            np.r_[np.zeros(n), -1.0],
            A_ub=np.vstack([np.c_[J.T @ S, np.zeros(len(J.T))],
                            np.c_[-J.T @ S, np.zeros(len(J.T))]]),
            b_ub=np.ones(2 * len(J.T)),
            A_eq=np.c_[G @ S, np.r_[u, 0, 0, 0]], b_eq=np.zeros(6),
            bounds=[(0, None)] * n + [(0, 1e6)], method="highs",
        )  # fmt: skip
        free.append(-res.fun)
    free = np.minimum(free, 1e6)
    assert np.all(passive >= alone * (1 - 1e-6) - 1e-9)  # idle is allowed
    assert np.all(np.minimum(passive, 1e6) <= free * (1 + 1e-6) + 1e-9)
    # where the weight pulls the object off the palm, the palm adds nothing
    n_palm = with_palm.contacts[-1].nhat_O
    away = [k for k, u in enumerate(WEIGHT_DIRECTIONS) if u @ n_palm > 0.5]
    assert away and passive[away] == pytest.approx(alone[away], rel=1e-5)
    assert np.any(free[away] > alone[away] * 1.01)  # what the free palm bought


def test_the_seated_grasp_is_analysed_as_drake_left_it(allegro_on_soup):
    # A helper's review: a state read off the shake test's simulation was
    # refused (joint_13 5e-6 rad past its limit, against a tolerance of
    # 1e-8), and the seated pose had to be fished out of a private function.
    scene, closed, weight, result = allegro_on_soup
    light = next(
        c
        for c in closed[:20]
        if torque_needed(scene.plant, scene.context, c, scene.object_body,
                         weight=weight) < 0.35
    )  # fmt: skip
    shaken = shake_test(scene.add_models, light, squeeze=0.5, **SHAKE)
    assert shaken.held_from_seat
    seated = shaken.seated(light)
    assert len(seated.q_hand) == len(light.q_hand)
    moved = np.linalg.norm(
        seated.X_WO.translation() - light.X_WO.translation()
    )  # fmt: skip
    assert moved == pytest.approx(shaken.seat_displacement, abs=1e-9)
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    before = scene.plant.GetPositions(ctx).copy()
    seated.apply(scene.plant, ctx, object_body=scene.object_body)
    try:
        report = dg.analyze_grasp(
            scene.plant, ctx, scene.object_body, hand=scene.hand, mu=1.0,
            load="gravity", torque_limits="plant",
        )  # fmt: skip
        assert report.pose.valid, str(report.pose)
        assert report.load.holds, str(report.load)  # as Drake held it
    finally:
        scene.plant.SetPositions(ctx, before)
    with pytest.raises(dg.InvalidOptionError, match="seat=0"):
        shake_test(scene.add_models, light, squeeze=0.5, seat=0.0, **SHAKE).seated(
            light
        )


def test_a_weight_the_actuators_cannot_hold_is_said(allegro_on_soup):
    scene, closed, weight, result = allegro_on_soup
    assert result.reason == ""  # the can holds at 0.7 N·m
    heavy = with_torques_needed(
        result, scene.plant, scene.context, scene.object_body,
        weight=20 * weight, top=10, started=0.0,
    )  # fmt: skip
    needed = [c.torque_needed for c in heavy[:10] if c.is_closure]
    assert min(needed) > 0.7  # the Allegro SDF's effort limit
    assert "hold none of the" in heavy.reason
    assert f"{min(needed):.3g} N·m" in heavy.reason
    assert heavy.reason in str(heavy)


def _as_cloud_candidate(scene, candidate, at_finger=False):
    """The candidate with cloud contacts (no finger body index, no ``p_FC``).

    ``at_finger``: each contact's point is its finger's witness point (in O)
    instead of the object's, so the cloud route's finger point is exactly the
    body route's.
    """
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    saved = plant.GetPositions(ctx).copy()
    candidate.apply(plant, ctx, object_body=scene.object_body)
    contacts = []
    for k in candidate.contacts:
        p_OC = k.p_OC
        if at_finger:
            X_WF = plant.EvalBodyPoseInWorld(ctx, plant.get_body(k.finger_body_index))
            p_OC = candidate.X_WO.inverse().multiply(X_WF.multiply(k.p_FC))
        contacts.append(
            CloudContact(
                p_OC=np.array(p_OC),
                nhat_O=np.array(k.nhat_O),
                psi=k.psi,
                finger_body=k.finger_body,
            )  # fmt: skip
        )
    plant.SetPositions(ctx, saved)
    return dataclasses.replace(candidate, contacts=tuple(contacts))


def test_a_cloud_candidates_jacobian_is_the_body_routes(allegro_on_soup):
    """Frame O given as the candidate's X_WO (object_body=None, the cloud
    route): with each contact at its finger's point, J is hand_jacobian's."""
    scene, closed, _, _ = allegro_on_soup
    for candidate in closed[:3]:
        cloudlike = _as_cloud_candidate(scene, candidate, at_finger=True)
        J_body = finger_jacobian(
            scene.plant, scene.context, candidate, scene.object_body
        )
        J_cloud = finger_jacobian(scene.plant, scene.context, cloudlike, None)
        np.testing.assert_allclose(J_cloud, J_body, rtol=1e-9, atol=1e-12)


def test_a_cloud_candidates_torque_needed_is_the_body_routes(allegro_on_soup):
    """The same contacts as cloud contacts (the object's points, the finger
    bodies' names, X_WO): torque_needed within 3 % of the body route's (the
    finger point moves by at most the distance tolerance)."""
    scene, closed, weight, _ = allegro_on_soup
    for candidate in closed[:5]:
        body = torque_needed(
            scene.plant, scene.context, candidate, scene.object_body, weight=weight
        )
        cloud = torque_needed(
            scene.plant, scene.context, _as_cloud_candidate(scene, candidate), None,
            weight=weight,
        )  # fmt: skip
        assert cloud == pytest.approx(body, rel=0.03)


def _weakest_first(result):
    """``result`` with its 30 best in reverse order, uncertified."""
    head = list(result.candidates[:30])[::-1]
    return dataclasses.replace(
        result,
        candidates=(
            *(dataclasses.replace(c, closure=None) for c in head),
            *result.candidates[30:],
        ),
    )


def test_candidates_the_motors_hold_come_first(allegro_on_soup):
    """with_torques_needed moves the checked candidates whose torque_needed is
    within the smallest effort limit (the Allegro SDF's 0.7 N·m) ahead of the
    others, each group in the order it came, and certifies the new head."""
    scene, _, weight, result = allegro_on_soup
    shuffled = _weakest_first(result)
    kw = dict(weight=weight, top=10, started=0.0, check=30)
    plain = with_torques_needed(
        shuffled, scene.plant, scene.context, scene.object_body,
        motors_first=False, **kw,
    )  # fmt: skip
    assert [c.sample for c in plain] == [c.sample for c in shuffled]
    ranked = with_torques_needed(
        shuffled, scene.plant, scene.context, scene.object_body, **kw
    )
    assert motor_limit(scene.plant, ranked[0]) == pytest.approx(0.7)
    held = [c.torque_needed <= 0.7 for c in ranked]
    assert 0 < sum(held) < 30
    assert held == sorted(held, reverse=True)  # every held one first
    order = {c.sample: k for k, c in enumerate(shuffled)}
    for group in ([c for c in ranked if c.torque_needed <= 0.7],
                  [c for c in ranked if not c.torque_needed <= 0.7]):  # fmt: skip
        assert [order[c.sample] for c in group] == sorted(
            order[c.sample] for c in group
        )
    # an infeasible candidate that came first is now behind a feasible one
    first_bad = next(k for k, c in enumerate(shuffled) if c.torque_needed > 0.7)
    assert first_bad < order[ranked[0].sample]
    assert all(c.closure is not None for c in ranked[:10])


def test_a_torque_limit_ranks_by_the_torque_applied(allegro_on_soup):
    """torque_limit= (N·m): the candidates whose torque_needed is within the
    torque the user will apply come first, not those within the 0.7 N·m effort
    limit; a limit above the effort limit is capped by it; a limit no
    candidate meets is said in the reason."""
    scene, _, weight, result = allegro_on_soup
    shuffled = _weakest_first(result)
    kw = dict(weight=weight, top=10, started=0.0, check=30)
    effort = with_torques_needed(
        shuffled, scene.plant, scene.context, scene.object_body, **kw
    )
    needed = sorted(c.torque_needed for c in effort if c.torque_needed <= 0.7)
    limit = needed[len(needed) // 2]  # half of the motors' candidates need more
    assert 0 < limit < 0.7 and needed[-1] > limit
    ranked = with_torques_needed(
        shuffled, scene.plant, scene.context, scene.object_body,
        torque_limit=limit, **kw,
    )  # fmt: skip
    held = [c.torque_needed <= limit for c in ranked]
    assert held == sorted(held, reverse=True) and 0 < sum(held) < len(needed)
    assert [c.sample for c in ranked] != [c.sample for c in effort]
    assert all(c.closure is not None for c in ranked[:10])
    capped = with_torques_needed(
        shuffled, scene.plant, scene.context, scene.object_body,
        torque_limit=5.0, **kw,
    )  # fmt: skip
    assert [c.sample for c in capped] == [c.sample for c in effort]
    tiny = with_torques_needed(
        shuffled, scene.plant, scene.context, scene.object_body,
        torque_limit=1e-3, **kw,
    )  # fmt: skip
    assert "torque_limit 0.001 N·m holds none of the" in tiny.reason


def test_plan_grasps_takes_the_torque_applied(allegro_on_soup):
    """plan_grasps(..., torque_limit=) ranks by it (and records it); without
    it the effort limit ranks, and the candidates are the same."""
    scene, closed, weight, result = allegro_on_soup
    needed = [c.torque_needed for c in result if c.torque_needed <= 0.7]
    # a candidate that needs less than the one ranked before it: at its
    # torque, the one before goes behind it
    limit = next(t for a, t in zip(needed[:-1], needed[1:], strict=True) if t < a)
    gentle = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=100, mu=1.0, seed=0, robustness_samples=8,
        torque_limit=limit,
    )  # fmt: skip
    held = [c.torque_needed <= limit for c in gentle]
    assert held == sorted(held, reverse=True) and sum(held) > 0
    assert [c.sample for c in gentle] != [c.sample for c in result]
    assert sorted(c.sample for c in gentle) == sorted(c.sample for c in result)
    assert gentle.settings["torque_limit"] == limit
    assert "torque_limit" not in result.settings


@pytest.mark.parametrize(
    "bad", [0.0, -0.5, float("nan"), float("inf"), True, "0.5", [0.5]]
)
def test_a_bad_torque_limit_is_refused(allegro_on_soup, bad):
    scene = allegro_on_soup[0]
    with pytest.raises(InvalidOptionError, match="torque_limit"):
        plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=5, mu=1.0, torque_limit=bad,
        )  # fmt: skip


def test_a_parallel_jaw_takes_no_torque_limit(wsg_scene):
    scene = wsg_scene()
    with pytest.raises(InvalidOptionError, match="torque_limit applies to multi"):
        plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=5, mu=0.5, torque_limit=0.5,
        )  # fmt: skip


def test_a_torque_limit_orders_a_hand_without_effort_limits(
    allegro_on_soup, monkeypatch
):
    """A plant whose actuators give no finite limit (motor_limit inf) keeps
    the score's order, unless torque_limit says what the hand applies."""
    scene, _, weight, result = allegro_on_soup
    monkeypatch.setattr(
        "drakegrasp.planning.motors.motor_limit", lambda plant, c: np.inf
    )
    head = list(result.candidates[:30])[::-1]  # the weakest first
    shuffled = dataclasses.replace(result, candidates=(*head, *result.candidates[30:]))
    kw = dict(weight=weight, top=10, started=0.0, check=30)
    free = with_torques_needed(
        shuffled, scene.plant, scene.context, scene.object_body, **kw
    )
    assert [c.sample for c in free] == [c.sample for c in shuffled]
    assert free.reason == ""
    ranked = with_torques_needed(
        shuffled, scene.plant, scene.context, scene.object_body,
        torque_limit=0.5, **kw,
    )  # fmt: skip
    held = [c.torque_needed <= 0.5 for c in ranked]
    assert held == sorted(held, reverse=True) and 0 < sum(held) < 30


@pytest.mark.parametrize(
    "option",
    [
        {"preshape": [0.01, 0.01]},
        {"synergy": "curl"},
        {"synergy_range": (0.0, 0.5)},
        {"approach": [0.0, 0.0, 1.0]},
        {"standoff": (0.0, 0.01)},
        {"tilt": 0.1},
        {"min_fingers": 3},
    ],
    ids=lambda o: next(iter(o)),
)
def test_a_parallel_jaw_refuses_every_multi_finger_option(option):
    # They were ignored without a word: a jaw opens fully along its chord.
    from drakegrasp.planning import planning_scene

    scene = planning_scene(  # drakegrasp's own jaw: no drake_models needed
        "package://drakegrasp/objects/box.sdf",
        hand_url="package://drakegrasp/hands/parallel_jaw_flat.sdf",
    )
    name = next(iter(option))
    with pytest.raises(InvalidOptionError, match=f"{name} applies to multi-finger"):
        plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=5, mu=0.5, **option,
        )  # fmt: skip


def test_a_parallel_jaw_takes_the_multi_finger_defaults_spelt_out():
    from drakegrasp.planning import planning_scene
    from drakegrasp.planning.multifinger import DEFAULT_TILT

    scene = planning_scene(  # drakegrasp's own jaw: no drake_models needed
        "package://drakegrasp/objects/box.sdf",
        hand_url="package://drakegrasp/hands/parallel_jaw_flat.sdf",
    )
    args = (scene.plant, scene.context, scene.object_body)
    plain = plan_grasps(*args, hand=scene.hand, num_candidates=20, mu=0.5, seed=1)
    spelt = plan_grasps(
        *args, hand=scene.hand, num_candidates=20, mu=0.5, seed=1,
        synergy_range=[0.0, 1.0], tilt=DEFAULT_TILT, min_fingers=2,
    )  # fmt: skip
    assert [c.d_star for c in plain] == [c.d_star for c in spelt]
