"""The steps of :func:`~drakegrasp.plant.closing.close_hand` (its docstring says how).

Each finger's working state and the loop that advances every finger at once,
one kinematics update per step, each step bounded by conservative advancement
(:mod:`drakegrasp.plant.advancement`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from pydrake.multibody.tree import JacobianWrtVariable

from drakegrasp.errors import PenetrationError
from drakegrasp.plant.advancement import advancement_bound, finger_speed_bound
from drakegrasp.plant.fingers import Finger, HandStructure

STALL_STEPS = 20
"""A finger stalls after this many accepted steps without progress (see below)."""
STALL_PROGRESS = 0.01
"""Progress: ``ψ − ψ*`` falls below this fraction of itself under the best so far."""
STALL_DISTANCE = 10.0
"""Only a finger farther than this many contact tolerances from the object stalls."""
STALL_WANDER = 0.5
"""A stalled finger's net motion over those steps is below this fraction of its path."""


@dataclass
class FingerState:
    """Working state of one finger during the search."""

    finger: Finger
    q_good: np.ndarray  # ψ > tol here (the last accepted point)
    q_trial: np.ndarray
    reach: np.ndarray  # (n_pairs, n_h), see drakegrasp.plant.advancement
    d: np.ndarray = field(default_factory=lambda: np.zeros(0))
    psi_good: float = np.inf
    alpha: float = 0.0
    status: str = ""
    psi: float = np.inf
    closest_body: object = None
    iterations: int = 0
    lower_good: np.ndarray | None = None  # (n_pairs,) ψ_p at q_good, or below it
    best: float = np.inf  # smallest ψ of an accepted point
    since_best: int = 0  # accepted points since ψ last fell clearly below best
    trail: list = field(default_factory=list)  # the last accepted points, oldest first
    speed: np.ndarray | None = None  # (n_pairs,) V_p along d


class Measured:
    """A finger's pair distances at its trial point, measured where they matter.

    ``lower`` bounds every pair's distance from below (conservative
    advancement: ``ψ_p >= ψ_p(q_good) − α V_p``); a pair is measured (one
    Drake call) only when its bound, less ``margin``, does not prove it
    irrelevant to the answer asked for (:meth:`nearest`,
    :meth:`advancement`).  The answers are those of measuring every pair.
    ``lower=None`` measures every pair at once.
    """

    def __init__(self, query, pairs, lower: np.ndarray | None, margin: float):
        self.query, self.pairs, self.margin = query, pairs, margin
        n = len(pairs)
        self.results: list = [None] * n
        self.every = np.full(n, np.inf)
        self.known = np.zeros(n, dtype=bool)
        self.rows = np.arange(n)
        self.lower = np.full(n, -np.inf) if lower is None else lower
        if lower is None:
            self.measure(np.arange(n))

    def measure(self, ks) -> None:
        """Ask Drake for the pairs ``ks``."""
        f = self.query.ComputeSignedDistancePairClosestPoints
        for k in ks:
            go, gf, _ = self.pairs[k]
            r = self.results[k] = f(go, gf)
            self.every[k] = r.distance
        self.known[ks] = True

    def nearest(self, subset: np.ndarray | None = None) -> int | None:
        """:func:`nearest` of every pair (of ``subset``), as if all were measured."""
        ks = self.rows if subset is None else subset
        if not len(ks):
            return None
        known, every, lower = self.known, self.every, self.lower
        if not known[ks].any():
            self.measure([ks[lower[ks].argmin()]])
        while True:  # unmeasured pairs count as inf in every
            j = every[ks].argmin()
            need = ks[~known[ks] & (lower[ks] - self.margin <= every[ks[j]])]
            if not len(need):
                k = int(ks[j])
                return k if every[k] < np.inf else None
            self.measure(need)

    def advancement(self, speed: np.ndarray, target: float) -> float:
        """:func:`advancement_bound` over every pair, as if all were measured."""
        moving = speed > 0
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = np.maximum(self.lower - self.margin - target, 0.0) / speed
        while True:
            k = self.known
            alpha = advancement_bound(self.every[k], speed[k], target)
            need = np.flatnonzero(~k & moving & (bound < alpha))
            if not len(need):
                return alpha
            self.measure(need)

    def lower_bounds(self) -> np.ndarray:
        """(n_pairs,) the measured distances, the bounds elsewhere."""
        return np.where(self.known, self.every, self.lower)


def pair_distances(query, pairs) -> tuple[list, np.ndarray]:
    """Drake's closest points of every pair, and their signed distances (metres)."""
    f = query.ComputeSignedDistancePairClosestPoints
    results = [f(go, gf) for go, gf, _ in pairs]
    every = np.fromiter((r.distance for r in results), float, len(results))
    return results, every


def nearest(every: np.ndarray, subset: np.ndarray | None = None) -> int | None:
    """The first pair (of ``subset``) at the smallest finite distance, or None."""
    ks = np.arange(len(every)) if subset is None else subset
    if len(ks) == 0:
        return None
    psi = every[ks]
    psi = np.where(np.isnan(psi), np.inf, psi)
    k = int(np.argmin(psi))  # the first of equal distances, as a loop with <
    return int(ks[k]) if psi[k] < np.inf else None


def witness(query, plant, context, pair, result):
    """(ψ, n̂_W from finger to object, finger body, witness p_BC) of one pair."""
    go, gf, body = pair
    if result.id_A == go:
        n_W, p_GC = np.asarray(result.nhat_BA_W), result.p_BCb
    else:  # Drake swapped the pair
        n_W, p_GC = -np.asarray(result.nhat_BA_W), result.p_ACa
    p_WC = query.GetPoseInWorld(gf).multiply(p_GC)
    p_BC = plant.EvalBodyPoseInWorld(context, body).inverse().multiply(p_WC)
    return float(result.distance), n_W, body, np.asarray(p_BC)


def closest(query, plant, context, pairs):
    """The closest pair and the distance of every pair.

    Returns
    -------
    (ψ, n̂_W from finger to object, finger body, witness p_BCb, ψ of every pair)
        ``(inf, None, None, None, ψs)`` when there is no pair.
    """
    results, every = pair_distances(query, pairs)
    k = nearest(every)
    if k is None:
        return np.inf, None, None, None, every
    return (*witness(query, plant, context, pairs[k], results[k]), every)


def stalled(st, q, psi: float, target: float, tol: float) -> bool:
    """Whether a finger circles a point where its distance stopped shrinking.

    The test of :meth:`Search._stalled` for a finger accepted at ``q`` with
    distance ``psi``; ``st`` holds its ``trail`` (list), ``best`` (start
    inf) and ``since_best`` (start 0), and is updated.  ``target`` is the
    closing's target distance, ``tol`` the contact tolerance (metres).
    """
    st.trail = [*st.trail[-STALL_STEPS:], q]
    first = st.best == np.inf
    if first or psi < st.best - STALL_PROGRESS * (st.best - target):
        st.best, st.since_best = psi, 0
        return False
    st.since_best += 1
    if st.since_best < STALL_STEPS or psi <= STALL_DISTANCE * tol:
        return False
    trail = np.array(st.trail)
    path = np.sum(np.max(np.abs(np.diff(trail, axis=0)), axis=1))
    net = np.max(np.abs(trail[-1] - trail[0]))
    return bool(net < STALL_WANDER * path)


def unit_step(d, q, lower, upper) -> np.ndarray:
    """A closing direction over the hand's joints, ready to step along.

    Components that would push a joint at ``q`` past its limit (``lower``,
    ``upper``, rad or m) are dropped, the rest scaled to a largest component
    of 1, and round-off (below 1e-9 of it) set to 0; all zeros when nothing is
    left to move (largest component at most 1e-12).
    """
    blocked = ((d > 0) & (q >= upper)) | ((d < 0) & (q <= lower))
    d = np.where(blocked, 0.0, d)
    scale = np.max(np.abs(d), initial=0.0)
    if scale <= 1e-12:
        return np.zeros_like(d)
    d = d / scale
    return np.where(np.abs(d) < 1e-9, 0.0, d)  # round-off, not a motion


def _path_end(q, d, lower, upper) -> float:
    """Largest α at which a joint with d != 0 still moves (capped at 1e3).

    Python floats over the few joints of a hand (IEEE arithmetic, as numpy's):
    called once per step of every finger.
    """
    best = 0.0
    rows = zip(q.tolist(), d.tolist(), lower.tolist(), upper.tolist(), strict=True)
    for qj, dj, lo, hi in rows:
        if dj > 0:
            t = (hi - qj) / dj  # inf on overflow, as numpy
        elif dj < 0:
            t = (lo - qj) / dj
        else:
            continue
        if not math.isfinite(t):
            t = 1e3
        if t > best:
            best = t
    return best


class Search:
    """The steps of every finger (see the module docstring)."""

    def __init__(
        self, plant, context, hand: HandStructure, tol, user_d, max_it, split=None
    ):
        self.plant, self.context, self.hand = plant, context, hand
        self.tol, self.target = tol, 0.5 * tol
        self.user_d, self.max_iterations = user_d, max_it
        self.split = split  # touching state -> the state of its free part, or None
        self._tips: dict[int, np.ndarray | None] = {}  # id(finger) -> tip rows
        self._joints = {}  # id(finger) -> its joints' positions in q
        self._mine = {}  # id(finger) -> (n_h,) bool, its joints
        for f in hand.fingers:
            self._know(f)

    def _know(self, f: Finger) -> None:
        self._joints[id(f)] = np.array(f.joints, dtype=int)
        mine = np.zeros(len(self.hand.lower), dtype=bool)
        mine[list(f.joints)] = True
        self._mine[id(f)] = mine

    def run(self, states: list[FingerState], q_all: np.ndarray, q0: np.ndarray) -> int:
        """Step until every finger has a status; the number of steps.

        With ``split``, the free part of a finger that comes to touch (joints
        that move none of its touching bodies, coupled to none that does) is
        appended to ``states`` and closes on from where the finger stopped.
        """
        hand, steps = self.hand, 0
        while not all(st.status for st in states):
            q = q0.copy()
            for st in states:  # a free part after its finger: its joints win
                j = self._joints[id(st.finger)]
                q[j] = st.q_trial[j]
            q_all[hand.position_indices] = hand.coupling.apply(q)
            self.plant.SetPositions(self.context, q_all)
            query = self.plant.get_geometry_query_input_port().Eval(self.context)
            parts = []
            for st in states:
                if not st.status:
                    self.advance(st, query)
                    if st.status == "touching" and self.split is not None:
                        part = self.split(st, q)
                        if part is not None:
                            self._know(part.finger)
                            parts.append(part)
            states.extend(parts)
            steps += 1
        # Where each finger stopped (a finger that ran out of steps goes back
        # to its last point clear of the object).
        q = q0.copy()
        for st in states:
            q[list(st.finger.joints)] = st.q_trial[list(st.finger.joints)]
        q_all[hand.position_indices] = hand.coupling.apply(q)
        self.plant.SetPositions(self.context, q_all)
        return steps

    def advance(self, st: FingerState, query) -> None:
        """Classify the finger's trial point, then aim its next one."""
        pairs = st.finger.pairs
        lower = None
        if st.lower_good is not None:  # every pair moved at most α V_p nearer
            lower = st.lower_good - st.alpha * st.speed
        # A pair is skipped only when its bound, less the contact tolerance,
        # shows it cannot change the answer.
        seen = Measured(query, pairs, lower, self.tol)
        k = seen.nearest()
        psi = np.inf if k is None else float(seen.every[k])
        body = None if k is None else pairs[k][2]
        st.psi, st.closest_body = psi, body
        first = st.iterations == 0
        if body is None:  # no collision geometry that can touch the object
            st.status = "fixed"
        elif 0.0 <= psi <= self.tol or (first and -self.tol <= psi <= self.tol):
            st.status = "touching"
        elif first and psi < 0.0:  # a caller's unchecked pre-shape: no clear
            raise PenetrationError(  # point to go back to
                f"{st.finger.name} starts {-psi * 1e3:.4g} mm inside the object "
                f"({body.name()}): open the hand before closing"
            )
        elif st.iterations >= self.max_iterations:  # back to the last clear point
            st.status = "not converged"
            st.q_trial, st.psi = st.q_good.copy(), st.psi_good
        elif psi < 0.0:  # the step went in: regula falsi back to the surface
            alpha = st.alpha * (st.psi_good - self.target) / (st.psi_good - psi)
            st.alpha = float(np.clip(alpha, 0.1 * st.alpha, 0.9 * st.alpha))
            st.q_trial = self._at(st, st.alpha)
            st.iterations += 1
        else:  # clear of the object: accept the point, aim the next step
            st.q_good, st.psi_good = st.q_trial.copy(), psi
            if self._stalled(st, psi):
                st.status = "not converged"
                return
            st.d = self.direction(st, query, seen)
            alpha_end = _path_end(st.q_good, st.d, self.hand.lower, self.hand.upper)
            if alpha_end <= 1e-12:
                mine = list(st.finger.joints)
                unmoved = self.user_d is not None and not np.any(self.user_d[mine])
                st.status = "fixed" if unmoved else "at limit"
                return
            speed = finger_speed_bound(st.reach, self.hand.coupling.tangent(st.d))
            alpha_ca = seen.advancement(speed, self.target)
            st.lower_good, st.speed = seen.lower_bounds(), speed
            st.alpha = min(alpha_ca, st.finger.max_step, alpha_end)
            st.q_trial = self._at(st, st.alpha)
            st.iterations += 1

    def _stalled(self, st: FingerState, psi: float) -> bool:
        """Whether the finger circles a point where its distance stopped shrinking.

        A steepest-descent path that reaches a stationary point of the tip's
        distance (a finger curled past the object, or pressed to a limit
        beside it) steps back and forth around it without coming nearer; it
        would end with ``max_iterations``, at another clear point of the same
        neighbourhood.  It stops when, over the last :data:`STALL_STEPS`
        accepted points, ``ψ − ψ*`` never fell below ``1 − STALL_PROGRESS``
        times its best, the finger's net motion (largest joint change) was
        below :data:`STALL_WANDER` times the length of its path (it turned
        back), and ``ψ > STALL_DISTANCE · tol``.  A finger that sweeps on
        (a fixed direction, or a curl past a thin obstacle that bounds its
        steps) or converges onto the object is never stopped.
        """
        return stalled(st, st.q_good, psi, self.target, self.tol)

    def _tip_rows(self, finger) -> np.ndarray | None:
        """Rows of ``finger.pairs`` that are its ``tip_pairs``, in order.

        None when a tip pair is not among the pairs (then it is measured apart).
        """
        if id(finger) not in self._tips:
            where = {(p[0], p[1]): k for k, p in enumerate(finger.pairs)}
            rows = [where.get((p[0], p[1])) for p in finger.tip_pairs]
            ok = None not in rows and rows == sorted(rows)
            self._tips[id(finger)] = np.array(rows, dtype=int) if ok else None
        return self._tips[id(finger)]

    def _at(self, st: FingerState, alpha: float) -> np.ndarray:
        return np.clip(st.q_good + alpha * st.d, self.hand.lower, self.hand.upper)

    def _dpsi(self, n_W, body, p_BC) -> np.ndarray:
        """``∂ψ/∂q`` over the closing joints (object fixed; one-dof, q̇ = v)."""
        J = self.plant.CalcJacobianTranslationalVelocity(
            self.context,
            JacobianWrtVariable.kV,
            body.body_frame(),
            p_BC,
            self.plant.world_frame(),
            self.plant.world_frame(),
        )
        return -(n_W @ J[:, self.hand.velocity_indices])

    def direction(
        self, st: FingerState, query, measured: Measured | None = None
    ) -> np.ndarray:
        """The finger's direction, zero on joints blocked by a limit.

        ``measured``: the finger's pairs at ``st.q_good`` when the caller has
        them (the tip's are among them).
        """
        hand, finger = self.hand, st.finger
        mine = self._mine[id(finger)]
        if self.user_d is not None:
            d = np.where(mine, self.user_d, 0.0)
        else:  # steepest descent of the fingertip's distance, here
            rows = None if measured is None else self._tip_rows(finger)
            if rows is None:
                tip = closest(query, self.plant, self.context, finger.tip_pairs)
                if tip[2] is None:
                    return np.zeros(len(mine))
                n_W, body, p_BC = tip[1:4]
            else:
                k = measured.nearest(rows)
                if k is None:
                    return np.zeros(len(mine))
                _, n_W, body, p_BC = witness(
                    query, self.plant, self.context, finger.pairs[k],
                    measured.results[k],
                )  # fmt: skip
            d = np.where(
                mine, -hand.coupling.pull_back(self._dpsi(n_W, body, p_BC)), 0.0
            )
        return unit_step(d, st.q_good, hand.lower, hand.upper)
