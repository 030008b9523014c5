"""Timelines of a simulated pick: holding states against the object's motion.

Shared by the holding tests and ``benchmarks/bench_monitor.py``.  Drake's
sample-and-hold means the verdict logged at ``t_{k+1}`` is the sample of the
state logged at ``t_k``; the timeline pairs them so that each row is one
sample: its time, its holding state and the object's displacement relative to
a finger at that same state.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drakegrasp.systems.holding import HOLDING_STATES
from drakegrasp.systems.monitor import GraspMonitor

FLAGS = ("slipping", "at risk")
MOVED = 5e-3  # m: the box has moved in the fingers (the 5 mm)


@dataclass
class Timeline:
    times: np.ndarray  # (K,) s, the samples' own times
    states: list  # (K,) holding state names
    displacement: np.ndarray  # (K,) m, object in the finger frame, from t_ref
    height: np.ndarray  # (K,) m, object origin above the ground
    verdicts: np.ndarray  # (n, K)

    def first(self, names, after: float) -> float:
        """Time of the first sample at or after ``after`` in one of ``names``."""
        for t, s in zip(self.times, self.states, strict=True):
            if t >= after and s in names:
                return float(t)
        return np.inf

    def slip_times(self, after: float) -> tuple[float, float, float]:
        """First times at or after ``after``: flagged, moved ``MOVED``, dropped.

        Flagged is a state of ``FLAGS``; each is ``inf`` if it never happens.
        """
        return (
            self.first(FLAGS, after=after),
            self.moved(MOVED, after=after),
            self.first(("dropped",), after=after),
        )

    def codes(self, start: float, stop: float) -> np.ndarray:
        """Holding-state codes (HOLDING_STATES indices) of samples in [start, stop)."""
        return np.array(
            [
                HOLDING_STATES.index(s)
                for t, s in zip(self.times, self.states, strict=True)
                if start <= t < stop
            ]
        )

    def moved(self, distance: float, after: float) -> float:
        """First sample time at or after ``after`` with displacement >= distance."""
        hit = np.flatnonzero((self.times >= after) & (self.displacement >= distance))
        return float(self.times[hit[0]]) if len(hit) else np.inf


def timeline(pick, *, finger: str, t_ref: float) -> Timeline:
    """The pick's samples, displacements measured in ``finger``'s frame."""
    context = pick.simulator.get_context()
    log = pick.verdict_log.FindLog(context)
    states = pick.state_log.FindLog(context)
    X, V, T = states.data(), log.data(), states.sample_times()
    plant = pick.plant
    plant_context = plant.CreateDefaultContext()
    box = plant.get_body(plant.GetBodyIndices(pick.box)[0])
    body = plant.GetBodyByName(finger, pick.gripper)
    p = []
    heights = []
    for x in X.T:
        plant.SetPositionsAndVelocities(plant_context, x)
        X_WO = plant.EvalBodyPoseInWorld(plant_context, box)
        X_FW = plant.EvalBodyPoseInWorld(plant_context, body).inverse()
        p.append(X_FW.multiply(X_WO.translation()))
        heights.append(X_WO.translation()[2])
    p = np.array(p)
    ref = p[np.flatnonzero(T >= t_ref)[0]]
    K = X.shape[1] - 1  # the last state has no logged sample yet
    codes = V[GraspMonitor.HOLDING, 1 : K + 1]
    return Timeline(
        times=T[:K],
        states=[HOLDING_STATES[int(c)] for c in codes],
        displacement=np.linalg.norm(p[:K] - ref, axis=1),
        height=np.array(heights[:K]),
        verdicts=V[:, 1 : K + 1],
    )
