"""The move that centres coupled fingers (:mod:`drakegrasp.planning.centring`)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.math import RigidTransform
from scipy.spatial.transform import Rotation

from drakegrasp.planning.centring import (
    chains_to_centre,
    close_centred,
    equalising_move,
    facing_chains,
)

TOL = 1e-4


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def test_two_fingers_across_parallel_faces_move_half_the_difference():
    # The far finger is 12 mm short, the near one touches: the hand moves
    # 6 mm towards the far one, after which both are 6 mm off.
    n = _unit([1.0, 0.0, 0.0])  # from the short finger towards the object
    t = equalising_move([0.012, 0.0], [n, -n], TOL)
    np.testing.assert_allclose(t, [0.006, 0.0, 0.0], atol=1e-15)


def test_equal_gaps_need_no_move_and_fingers_facing_one_way_get_none():
    n = _unit([0.0, 0.0, 1.0])
    assert equalising_move([0.003, 0.003], [n, -n], TOL) is None
    # both lines the same way: no move closes one gap without the other
    assert equalising_move([0.003, 0.0], [n, n], TOL) is None
    assert equalising_move([0.003, np.nan], [n, -n], TOL) is None
    assert equalising_move([0.003], [n], TOL) is None


def test_each_closing_group_is_equalised_apart():
    # two pinches closing apart: each pair's gaps are evened, not all four
    x, y = np.eye(3)[0], np.eye(3)[1]
    t = equalising_move([0.004, 0.0, 0.002, 0.0], [x, -x, y, -y], TOL, [0, 0, 1, 1])
    np.testing.assert_allclose(t, [0.002, 0.001, 0.0], atol=1e-15)


lines3 = st.lists(
    st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(
        lambda v: np.linalg.norm(v) > 0.2
    ),
    min_size=2,
    max_size=3,
)


@settings(max_examples=200, deadline=None)
@given(lines=lines3, gaps=st.lists(st.floats(0, 0.05), min_size=3, max_size=3))
def test_the_move_equalises_the_gaps_and_is_the_least(lines, gaps):
    n = np.array([_unit(v) for v in lines])
    psi = np.array(gaps[: len(n)])
    t = equalising_move(psi, n, TOL)
    # the gaps less their mean, against the lines less theirs (any chain order)
    A, b = n - n.mean(axis=0), psi - psi.mean()
    if t is None:
        return
    after = psi - n @ t
    # equal where the lines tell the move apart, else the least-squares fit
    # over the directions the lines tell apart by more than 1e-6 (an
    # independent solver: scipy's truncated pseudo-inverse)
    best = scipy.linalg.pinv(A, atol=1e-6, rtol=0.0) @ b
    assert np.linalg.norm(A @ t - b) <= np.linalg.norm(A @ best - b) + 1e-12
    if np.linalg.matrix_rank(A, tol=1e-6) == len(A) - 1:  # the most k chains allow
        np.testing.assert_allclose(after, after[0], atol=1e-9)
    # the least: no part along what the lines cannot see
    _, s, Vt = np.linalg.svd(A)
    unseen = Vt[np.sum(s > 1e-6) :]  # the cut of equalising_move: absolute
    np.testing.assert_allclose(unseen @ t, 0, atol=1e-12)


@settings(max_examples=100, deadline=None)
@given(
    lines=lines3,
    gaps=st.lists(st.floats(0, 0.05), min_size=3, max_size=3),
    quat=st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
        lambda q: np.linalg.norm(q) > 0.1
    ),
    order=st.permutations([0, 1, 2]),
)
def test_the_move_turns_with_the_scene_and_ignores_the_chains_order(
    lines, gaps, quat, order
):
    n = np.array([_unit(v) for v in lines])
    psi = np.array(gaps[: len(n)])
    t = equalising_move(psi, n, TOL)
    R = Rotation.from_quat(quat).as_matrix()
    k = [i for i in order if i < len(n)]
    u = equalising_move(psi[k], (n @ R.T)[k], TOL)
    assert (t is None) == (u is None)
    if t is not None:
        np.testing.assert_allclose(u, R @ t, atol=1e-9)


def test_only_chains_closing_with_a_touching_one_are_centred():
    groups = [0, 0, 1, 2, 2]
    assert chains_to_centre(groups, {0}) == [0, 1]
    assert chains_to_centre(groups, {0, 1}) == []  # both touch
    assert chains_to_centre(groups, {2}) == []  # a finger of its own
    assert chains_to_centre(groups, {2, 4}) == [3, 4]
    assert chains_to_centre(groups, set()) == []


class _Pinch:
    """A one-dimensional pinch: an object [e - w, e + w], pads closing to ±a/2."""

    def __init__(self, e, w=0.025, tilt=0.0):
        self.e, self.w, self.tilt, self.calls = e, w, tilt, 0

    def _x(self, X_WH):
        return X_WH.translation()[0]

    def close(self, X_WH, q_pre):
        self.calls += 1
        e = self.e - self._x(X_WH)  # the object's offset from the hand
        # both pads close together until the nearer one is 0.09 tol away
        self.gap = (2 * abs(e) + 0.9 * TOL, 0.9 * TOL)  # (far, near)
        self.short = 0 if e > 0 else 1  # the pad on -x is short when e > 0
        if abs(2 * e) <= 0.1 * TOL:
            return ["contacts"], np.zeros(2), None, {0, 1}
        return None, None, "one finger touches", {1 - self.short}

    def gaps(self, chains):
        psi = np.zeros(2)
        psi[self.short], psi[1 - self.short] = self.gap
        lines = np.array([[1.0, 0, self.tilt], [-1.0, 0, self.tilt]])
        return psi, lines / np.linalg.norm(lines, axis=1, keepdims=True)


@pytest.mark.parametrize("e", [-0.012, -0.003, 0.0, 0.004, 0.012])
def test_close_centred_centres_a_pinch_and_keeps_the_pose_it_closed_at(e):
    pinch = _Pinch(e)
    found, q, reason, X = close_centred(
        pinch.close, pinch.gaps, [0, 0], TOL, RigidTransform([0.0, 0.0, 0.1]), None
    )
    assert reason is None and found == ["contacts"]
    np.testing.assert_allclose(X.translation(), [e, 0.0, 0.1], atol=1e-12)
    assert pinch.calls == (1 if e == 0 else 2)


def test_close_centred_gives_the_first_reason_when_it_cannot_centre(monkeypatch):
    from drakegrasp.planning import centring

    pinch = _Pinch(0.01)
    monkeypatch.setattr(centring, "CENTRING_STEPS", 0)
    found, q, reason, X = close_centred(
        pinch.close, pinch.gaps, [0, 0], TOL, RigidTransform(), None
    )
    assert (found, q, reason) == (None, None, "one finger touches")
    assert pinch.calls == 1


class _BarredPinch(_Pinch):
    """The pinch with a bar behind each pad (chains 2, 3 behind 0, 1).

    Each bar's nearest point lies 9 mm further from the object than its pad's,
    below the pad's line (its line to the object tilted 37° down).
    """

    def gaps(self, chains):
        psi, lines = super().gaps(chains)
        bars = np.array([[0.8, 0.0, -0.6], [-0.8, 0.0, -0.6]])
        return np.append(psi, psi + 0.009), np.vstack([lines, bars])


@pytest.mark.parametrize("e", [-0.012, 0.004])
def test_a_bar_behind_its_pad_is_not_centred_with_it(e):
    # Four chains in one group: equalised with the pads, the bars' gaps pull
    # the hand down towards them (the move evens four gaps in least squares,
    # not the pads').  Of each side (a pad and its bar turn alike) only the
    # nearest is centred: one move, exactly onto the object's centre.
    pinch = _BarredPinch(e)
    args = (pinch.close, pinch.gaps, [0] * 4, TOL, RigidTransform([0.0, 0.0, 0.1]))
    found, _, reason, X = close_centred(*args, None, [0, 1, 0, 1])
    assert reason is None and found == ["contacts"] and pinch.calls == 2
    np.testing.assert_allclose(X.translation(), [e, 0.0, 0.1], atol=1e-12)
    _, _, _, X = close_centred(*args, None)  # every chain its own side
    assert abs(X.translation()[2] - 0.1) > 1e-3


def test_facing_chains_keeps_the_nearest_measured_chain_of_each_side():
    assert facing_chains([0.02, 0.0, 0.011, 0.03], [0, 1, 0, 1]) == [1, 2]
    assert facing_chains([np.nan, 0.0, 0.011, np.nan], [0, 1, 0, 1]) == [1, 2]
    assert facing_chains([0.01, 0.01], [0, 0]) == [0]  # the first of equal ones
    assert facing_chains([np.nan, np.nan], [0, 1]) == []
    assert facing_chains([], []) == []
    from drakegrasp.errors import InvalidOptionError

    for psi, sides in [([0.0, 0.1], [0]), ([0.0, 0.1], [0.0, 1.0]), ("ab", [0, 1])]:
        with pytest.raises(InvalidOptionError):
            facing_chains(psi, sides)


@pytest.mark.parametrize(
    "psi, lines, tol, groups",
    [
        ([0.01, 0.0], [[1, 0, 0]], TOL, None),  # a line short
        ([0.01, 0.0], [[1, 0], [-1, 0]], TOL, None),  # planar lines
        ([[0.01, 0.0]], [[1, 0, 0], [-1, 0, 0]], TOL, None),  # psi not a vector
        ("0.01 0", [[1, 0, 0], [-1, 0, 0]], TOL, None),
        ([0.01, 1j], [[1, 0, 0], [-1, 0, 0]], TOL, None),
        ([0.01, 0.0], [[1, 0, 0], [-1, 0, 0]], 0.0, None),
        ([0.01, 0.0], [[1, 0, 0], [-1, 0, 0]], float("nan"), None),
        ([0.01, 0.0], [[1, 0, 0], [-1, 0, 0]], "1e-4", None),
        ([0.01, 0.0], [[1, 0, 0], [-1, 0, 0]], TOL, [0]),
        ([0.01, 0.0], [[1, 0, 0], [-1, 0, 0]], TOL, [0.5, 1.5]),
    ],
)
def test_hostile_arguments_are_refused_by_name(psi, lines, tol, groups):
    from drakegrasp.errors import InvalidOptionError

    with pytest.raises(InvalidOptionError):
        equalising_move(psi, lines, tol, groups)


def test_a_touching_chain_the_hand_lacks_is_refused():
    from drakegrasp.errors import InvalidOptionError

    with pytest.raises(InvalidOptionError, match="touched names chains"):
        chains_to_centre([0, 0], {2})


def test_a_move_that_would_widen_the_spread_is_not_made():
    # six chains in one group: no move evens them, and the least-squares fit
    # narrows their variance while it widens their spread (found by the fuzz
    # suite: 18.2 mm to 19.8 mm)
    rng = np.random.default_rng(3)
    widened = 0
    for _ in range(300):
        n = rng.normal(size=(6, 3))
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        psi = rng.uniform(0.0, 0.03, 6)
        A, b = n - n.mean(axis=0), psi - psi.mean()
        fit = scipy.linalg.pinv(A, atol=1e-6, rtol=0.0) @ b
        widened += np.ptp(psi - n @ fit) >= np.ptp(psi)
        t = equalising_move(psi, n, TOL)
        if t is not None:
            assert np.ptp(psi - n @ t) < np.ptp(psi)
    assert widened > 0  # the case exists among the draws


def test_close_centred_keeps_the_first_reason_when_a_move_fails_later():
    # the sample's own reason is counted, not that of a pose it was moved to
    closes = iter(
        [
            (None, None, "one finger touches", {1}),
            (None, None, "hand collides with the object", set()),
        ]
    )
    gaps = (np.array([0.02, 1e-4]), np.array([[1.0, 0, 0], [-1.0, 0, 0]]))
    found, q, reason, X = close_centred(
        lambda X, q: next(closes), lambda chains: gaps, [0, 0], TOL,
        RigidTransform(), None,
    )  # fmt: skip
    assert reason == "one finger touches"
    assert X.translation()[0] > 0  # the pose tried last: moved
