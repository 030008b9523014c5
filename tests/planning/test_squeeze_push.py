"""The squeeze push: whether a candidate's closing motions oppose each other,
and the ranking that puts the grasps whose squeeze pushes the object out of
the hand after the others (``drakegrasp.planning.opposition``,
``motors.with_squeeze_push``), and a candidate's ``concerns``."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from allegro_support import allegro_scene, has_thumb

import drakegrasp as dg
import drakegrasp.planning.motors as motors
from drakegrasp.core.contact import contact_frame
from drakegrasp.core.linalg import rotations_about
from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning.opposition import (
    PASSIVE_SPEED,
    SQUEEZE_PUSH_MAX,
    closing_directions,
    push_text,
    squeeze_push_of,
)

THREE = "package://drakegrasp/hands/three_finger_hand.sdf"
THREE_OPEN = [-0.4, 0.0, 0.0] * 3


def _cone(theta: float, k: int = 3, axis=(0.0, 0.0, 1.0)) -> np.ndarray:
    """``k`` unit vectors at angle ``theta`` about ``axis``, evenly around it."""
    a = 2 * np.pi * np.arange(k) / k
    d = np.c_[
        np.sin(theta) * np.cos(a), np.sin(theta) * np.sin(a), np.full(k, np.cos(theta))
    ]
    R = contact_frame(np.asarray(axis, float))  # columns [axis, t1, t2]
    return d @ np.c_[R[:, 1], R[:, 2], R[:, 0]].T


def _brute_force(D: np.ndarray, n: int = 40_000) -> float:
    """``max(0, max_u min_i d_i·u)`` over a Fibonacci sphere of ``n`` points."""
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = np.pi * (1 + 5**0.5) * k
    U = np.c_[np.sqrt(1 - z**2) * np.cos(phi), np.sqrt(1 - z**2) * np.sin(phi), z]
    return max(0.0, float(np.max(np.min(U @ D.T, axis=1))))


# --- the figure: analytic cases, invariances, a second formulation -----------


def test_opposite_directions_push_nowhere():
    # a parallel jaw's fingers close towards each other
    assert squeeze_push_of([[1, 0, 0], [-1, 0, 0]]) == 0.0
    tetrahedron = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]]) / 3**0.5
    assert squeeze_push_of(tetrahedron) == 0.0


@pytest.mark.parametrize("theta_deg", [0.0, 10.0, 30.0, 45.0, 60.0, 85.0])
def test_directions_within_a_cone_push_along_its_axis_by_its_cosine(theta_deg):
    theta = np.radians(theta_deg)
    assert squeeze_push_of(_cone(theta)) == pytest.approx(np.cos(theta), abs=1e-9)
    assert squeeze_push_of(_cone(theta, k=7, axis=(1, -2, 0.5))) == pytest.approx(
        np.cos(theta), abs=1e-9
    )


def test_one_direction_pushes_fully():
    assert squeeze_push_of([[0.0, 0.6, 0.8]]) == pytest.approx(1.0)


def test_the_push_is_unchanged_by_a_rotation_and_an_order():
    rng = np.random.default_rng(7)
    for _ in range(20):
        D = rng.standard_normal((5, 3)) + [0.0, 0.0, 2.5]  # leaning along +z
        D /= np.linalg.norm(D, axis=1, keepdims=True)
        axis = rng.standard_normal((1, 3))
        R = rotations_about(axis / np.linalg.norm(axis), rng.uniform(0, np.pi, 1))[0]
        r = squeeze_push_of(D)
        assert squeeze_push_of(D @ R.T) == pytest.approx(r, abs=1e-9)
        assert squeeze_push_of(D[rng.permutation(5)]) == pytest.approx(r, abs=1e-9)


def test_the_push_is_the_best_common_direction_found_by_search():
    # max_u min_i d_i·u, searched over 40,000 directions, is within the grid's
    # resolution of the hull's distance from the origin (and never above it)
    rng = np.random.default_rng(3)
    for lean in (0.0, 0.5, 1.5, 4.0):
        D = rng.standard_normal((4, 3)) + [lean, 0.0, 0.0]
        D /= np.linalg.norm(D, axis=1, keepdims=True)
        r, searched = squeeze_push_of(D), _brute_force(D)
        assert searched <= r + 1e-9
        assert r == pytest.approx(searched, abs=0.02)


@pytest.mark.parametrize(
    "bad", [np.zeros((0, 3)), np.ones((3, 2)), [[np.nan, 0, 1]], "abc", [[1, 0, 0j]]]
)
def test_what_is_not_directions_is_refused(bad):
    with pytest.raises(InvalidOptionError, match="directions"):
        squeeze_push_of(bad)


def test_the_push_reads_directions_of_any_length_as_their_unit_vectors():
    # two orthogonal rows of length 10 read 1 (clipped), of length 0.1 read
    # 0.07: the hull of the rows, not of their directions
    rng = np.random.default_rng(11)
    D = rng.standard_normal((5, 3)) + [0.0, 2.0, 0.0]
    unit = D / np.linalg.norm(D, axis=1, keepdims=True)
    lengths = 10.0 ** rng.uniform(-200, 200, (5, 1))
    assert squeeze_push_of(D * lengths) == pytest.approx(
        squeeze_push_of(unit), abs=1e-12
    )
    for scale in (10.0, 0.1):
        assert squeeze_push_of(np.eye(3)[:2] * scale) == pytest.approx(0.5**0.5)


def test_a_zero_direction_is_refused_not_read_as_opposing():
    # it put the origin in the hull: push 0, "the motions oppose"
    with pytest.raises(InvalidOptionError, match=r"directions\[1\] is zero"):
        squeeze_push_of([[1.0, 0, 0], [0, 0, 0], [0.9, 0.1, 0]])


# --- which way each contact is pushed ----------------------------------------


def test_closing_directions_read_each_contacts_rows():
    n = np.array([0.0, 0.0, 1.0])
    R = contact_frame(n)
    # hard finger (3 rows): moves along t1 and n; frictionless (1 row): pulled
    # back along n; soft finger (4 rows): its torsion row is no translation; a
    # palm contact (zero rows): pushes back along its normal
    J = np.zeros((3 + 1 + 4 + 3, 2))
    J[0:3, 0] = [1.0, 1.0, 0.0]  # [n, t1, t2] per unit of joint 0
    J[3, 1] = -2.0
    J[4:8, 0] = [0.0, 0.0, 3.0, 100.0]
    out = closing_directions(np.asarray(J), np.array([R] * 4), [3, 1, 4, 3], [1.0, 1.0])
    assert out[0] == pytest.approx((R[:, 0] + R[:, 1]) / 2**0.5)
    assert out[1] == pytest.approx(-n)
    assert out[2] == pytest.approx(R[:, 2])
    assert out[3] == pytest.approx(n)
    # the sign that closed a joint turns its push; 0 leaves the joint still
    flipped = closing_directions(J, np.array([R] * 4), [3, 1, 4, 3], [-1.0, 0.0])
    assert flipped[0] == pytest.approx(-out[0]) and flipped[1] == pytest.approx(n)
    slow = closing_directions(
        J * PASSIVE_SPEED / 10, np.array([R] * 4), [3, 1, 4, 3], [1, 1]
    )
    assert slow == pytest.approx(np.tile(n, (4, 1)))


def test_closing_directions_refuse_what_does_not_fit():
    R = np.eye(3)[None]
    with pytest.raises(InvalidOptionError, match="closing_directions"):
        closing_directions(np.zeros((3, 2)), R, [3], [1.0])  # 2 joints, 1 sign
    with pytest.raises(InvalidOptionError, match="closing_directions"):
        closing_directions(np.zeros((2, 1)), R, [2], [1.0])  # no such contact
    with pytest.raises(InvalidOptionError, match="finite"):
        closing_directions(np.full((3, 1), np.nan), R, [3], [1.0])


def test_closing_directions_are_unit_however_large_the_motion():
    # |v| overflowed to inf below the float range's top: a zero "unit" direction
    out = closing_directions(np.eye(3), np.eye(3)[None], [3], [1e308, 1e308, 1.0])
    assert out[0] == pytest.approx([0.5**0.5, 0.5**0.5, 0.0])
    with pytest.raises(InvalidOptionError, match="overflows"):
        closing_directions(np.ones((3, 3)), np.eye(3)[None], [3], [1e308, 1e308, 1])


def test_closing_directions_refuse_a_nan_sign_and_a_frame_that_is_no_rotation():
    # a NaN sign made the contact "passive" (its normal), a zero frame gave the
    # zero vector as its direction, which squeeze_push_of read as opposing
    R = np.eye(3)[None]
    with pytest.raises(InvalidOptionError, match="finite"):
        closing_directions(np.eye(3), R, [3], [np.nan, 1.0, 1.0])
    with pytest.raises(InvalidOptionError, match="orthonormal"):
        closing_directions(np.eye(3), R * 0.0, [3], [0.0, 0.0, 0.0])
    with pytest.raises(InvalidOptionError, match="components"):
        closing_directions(np.eye(3), R, [3.5], [1.0, 1.0, 1.0])


def test_push_text_reads_any_real_number_and_refuses_the_rest():
    # push_text(1) and a float32 0.9 said nothing: only a Python float was read
    assert "squeeze_push 1.00" in push_text(1)
    assert "squeeze_push 0.90" in push_text(np.float32(0.9))
    assert push_text(SQUEEZE_PUSH_MAX) == "" and push_text(math.nan) == ""
    for bad in ("0.9", None, 1.5, -0.2):
        with pytest.raises(InvalidOptionError, match="squeeze_push"):
            push_text(bad)


# --- the ranking: pushers after the other force-closure candidates -----------


@pytest.fixture(scope="module")
def three_on_box():
    scene = dg.planning_scene("package://drakegrasp/objects/box.sdf", hand_url=THREE)
    result = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=1.0, seed=3, robustness_samples=8, preshape=THREE_OPEN,
    )  # fmt: skip
    return scene, result


def test_a_three_finger_hands_grasps_oppose(three_on_box):
    # its fingers close on the object from three sides: nothing moves
    _, result = three_on_box
    pushes = [c.squeeze_push for c in result if c.is_closure]
    assert pushes and max(pushes) < 0.5
    assert all(math.isnan(c.squeeze_push) for c in result if not c.is_closure)
    assert result.settings["pushed_last"] == dict(
        bound=SQUEEZE_PUSH_MAX, checked=len(pushes), count=0
    )
    assert "push the object one way" not in str(result)


def _uncertified(result):
    return dataclasses.replace(
        result,
        candidates=tuple(
            dataclasses.replace(c, closure=None, squeeze_push=math.nan) for c in result
        ),
    )


def test_a_candidate_whose_squeeze_pushes_it_out_is_not_ranked_above_one_that_opposes(
    three_on_box, monkeypatch
):
    """with_squeeze_push, given pushes (the hand's own oppose, so they are
    stood in for): the force-closure candidates above SQUEEZE_PUSH_MAX come
    after every other force-closure candidate and before those that are not
    force closure, each group in the order it came; the new head is
    certified; the result says how many moved."""
    scene, result = three_on_box
    closed = [c for c in result if c.is_closure]
    assert len(closed) >= 6 and not result[len(closed)].is_closure
    pushes = {
        c.sample: 0.95 if k in (0, 2, 3) else 0.1 * (k % 5)
        for k, c in enumerate(closed)
    }

    def push(plant, context, candidate, object_body):
        return pushes[candidate.sample]

    monkeypatch.setattr(motors, "squeeze_push", push)
    given = _uncertified(result)
    ranked = motors.with_squeeze_push(
        given, scene.plant, scene.context, scene.object_body, top=4, started=0.0
    )
    samples = [c.sample for c in ranked]
    opposed = [c.sample for c in closed if pushes[c.sample] <= SQUEEZE_PUSH_MAX]
    pushing = [closed[0].sample, closed[2].sample, closed[3].sample]
    others = [c.sample for c in result if not c.is_closure]
    assert samples == [*opposed, *pushing, *others]
    # no pusher above an opposed candidate, whatever the score said
    k = samples.index(pushing[0])
    assert all(c.squeeze_push <= SQUEEZE_PUSH_MAX for c in ranked[:k])
    assert all(c.closure is not None for c in ranked[:4])
    assert ranked.settings["pushed_last"] == dict(
        bound=SQUEEZE_PUSH_MAX, checked=len(closed), count=3
    )
    assert "the 3 of the" in str(ranked) and ranked.reason == ""
    assert all(any("push the object one way" in w for w in c.concerns)
               for c in ranked if c.sample in pushing)  # fmt: skip
    kept = motors.with_squeeze_push(
        given, scene.plant, scene.context, scene.object_body, top=4, started=0.0,
        push_last=False,
    )  # fmt: skip
    assert [c.sample for c in kept] == [c.sample for c in result]


def test_when_every_candidate_pushes_the_reason_says_so(three_on_box, monkeypatch):
    scene, result = three_on_box
    monkeypatch.setattr(motors, "squeeze_push", lambda *a: 0.9)
    ranked = motors.with_squeeze_push(
        _uncertified(result), scene.plant, scene.context, scene.object_body, top=4,
        started=0.0,
    )  # fmt: skip
    assert "push the object one way" in ranked.reason
    assert [c.sample for c in ranked] == [c.sample for c in result]


# --- a candidate's concerns ---------------------------------------------------


def test_concerns_name_what_the_plan_says_against_holding(three_on_box):
    _, result = three_on_box
    c = next(c for c in result if c.is_closure)
    quiet = dataclasses.replace(
        c, torque_needed=0.5, torque_capacity=2.0, torque_limit=0.7, squeeze_push=0.2
    )
    assert quiet.concerns == ()
    heavy = dataclasses.replace(quiet, torque_needed=1.25, torque_capacity=0.8)
    (concern,) = heavy.concerns
    assert "1.25 N·m per motor (torque_needed)" in concern and "0.7" in concern
    assert str(heavy).endswith(concern)
    pushed = dataclasses.replace(heavy, squeeze_push=0.9)
    assert len(pushed.concerns) == 2 and "squeeze_push 0.90 > 0.7" in pushed.concerns[1]
    unknown = dataclasses.replace(c, torque_needed=9.0, torque_limit=math.nan)
    assert unknown.concerns == ()  # no limit known: nothing to hold it to
    not_closed = next(c for c in result if not c.is_closure)
    assert not_closed.concerns[0].startswith("not force closure")
    assert "not force closure" not in str(not_closed)  # it says "no closure"
    assert pushed.to_dict()["concerns"] == list(pushed.concerns)
    assert pushed.to_dict()["squeeze_push"] == 0.9


# --- Drake's Allegro hand ---------------------------------------------------------


@pytest.fixture(scope="module")
def allegro_on_sugar(drake_models_dir):
    """The YCB sugar box as if 0.25 kg, so that the hand's 0.7 N·m holds some."""
    scene = allegro_scene("004_sugar_box", drake_models_dir)
    result = dg.plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=150, mu=1.0, seed=0, object_mass=0.25,
    )  # fmt: skip
    return scene, result


def test_the_allegro_hands_thumbless_grasps_push_one_way(allegro_on_sugar):
    # its index, middle and ring curl the same way; with the thumb they oppose
    _, result = allegro_on_sugar
    closed = [c for c in result if not math.isnan(c.squeeze_push)]
    assert len(closed) >= 8
    for c in closed:
        assert (c.squeeze_push > SQUEEZE_PUSH_MAX) == (not has_thumb(c)), c
    first = next(k for k, c in enumerate(result) if c.squeeze_push > SQUEEZE_PUSH_MAX)
    assert all(c.is_closure and has_thumb(c) for c in result[:first])
    assert all(c.torque_limit == pytest.approx(0.7) for c in closed)


def test_the_allegro_hands_first_grasps_hold_and_those_it_put_last_are_pushed_out(
    allegro_on_sugar,
):
    """In Drake, at the shake's default squeeze (20 N at the contacts, each
    joint within its 0.7 N·m): the planner's first two grasps of the light
    sugar box hold, and the two thumbless ones that the torque figures alone
    ranked third and fourth (both within the 0.7 N·m) are pushed out of the
    hand while seating, before any load (measured 0.49 and 0.70 m/s).
    About 3 s."""
    scene, result = allegro_on_sugar
    pushers = [c for c in result if c.squeeze_push > SQUEEZE_PUSH_MAX]
    within = [c for c in pushers if c.torque_needed <= c.torque_limit][:2]
    assert len(within) == 2  # the motors hold them, by the torque figures
    first = dg.shake_candidates(scene.add_models, result, top=2)
    last = dg.shake_candidates(scene.add_models, within, top=2)
    assert len(first.held) == 2
    assert not last.held
    assert all(s.result.seat_speed > 0.1 for s in last)  # pushed, not dropped
    # each drop is named with what the plan said of it
    assert all(
        "; as the plan said: " in str(s) and "squeeze_push" in str(s) for s in last
    )
    assert all("as the plan said" not in str(s) for s in first)
