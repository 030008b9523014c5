"""One sample of the grasp monitor: its verdict vector and its full record."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.serialize import jsonable
from drakegrasp.systems.finger_loads import FingerLoad
from drakegrasp.systems.holding import HoldingMemory, holding_code

__all__ = ["HOLDING_NAMES", "VERDICT_NAMES", "GraspSample", "verdict_names"]

VERDICT_NAMES = (
    "status",
    "force_closure",
    "form_closure",
    "antipodal",
    "num_contacts",
    "d_star",
    "epsilon",
)
"""Names of the analysis elements of the ``verdicts`` output (indices 0 … 6)."""

HOLDING_NAMES = (
    "holding",
    "friction_use",
    "slip_speed",
    "relative_speed",
    "contact_gap",
)
"""Names of the grip elements of the ``verdicts`` output (indices 7 … 11).

``holding``: the code of the holding state (its index in
:data:`~drakegrasp.systems.holding.HOLDING_STATES`); ``friction_use``: the
largest ``‖f_t‖/(μ f_n)`` over the fingers (NaN in geometry mode);
``slip_speed``: the largest slip speed, m/s; ``relative_speed``: the largest
speed of the object's centre of mass relative to a touching finger, m/s (NaN
without contact); ``contact_gap``: samples without contact over which the
hysteresis kept a grip and its analysis (0 when the sample has contact, and
for a touch kept without its analysis).
"""


def verdict_names(finger_bodies) -> tuple[str, ...]:
    """All names of the ``verdicts`` vector of a monitor of these finger bodies.

    :data:`VERDICT_NAMES`, :data:`HOLDING_NAMES`, then per finger body (scoped
    name ``model::body``) ``friction_use[<body>]`` and ``slip_speed[<body>]``.
    """
    per_finger = []
    for name in finger_bodies:
        per_finger += [f"friction_use[{name}]", f"slip_speed[{name}]"]
    return VERDICT_NAMES + HOLDING_NAMES + tuple(per_finger)


def analysis_verdicts(report: Any, status: float, epsilon: float):
    """The seven analysis elements (:data:`VERDICT_NAMES`)."""
    if report is None:
        return np.array([status, 0, 0, 0, 0, 0, 0], dtype=float)
    antipodal = report.antipodal is not None and report.antipodal.is_antipodal
    return np.array(
        [
            status,
            float(report.force_closure.is_closure),
            float(report.form_closure.is_closure),
            float(antipodal),
            float(report.grasp.num_contacts),
            float(report.force_closure.d_star),
            epsilon,
        ]
    )


def grip_verdicts(
    holding: str,
    loads: tuple[FingerLoad, ...],
    relative_speed: float,
    gap: int,
) -> np.ndarray:
    """The grip elements: :data:`HOLDING_NAMES`, then two per finger."""
    uses = [f.friction_use for f in loads]
    known = [u for u in uses if not np.isnan(u)]
    use = max(known) if known else np.nan
    slip = max((f.slip_speed for f in loads), default=0.0)
    head = [holding_code(holding), use, slip, relative_speed, float(gap)]
    tail = [x for f in loads for x in (f.friction_use, f.slip_speed)]
    return np.array(head + tail, dtype=float)


@checked_call
@dataclass(frozen=True, eq=False)
class GraspSample:
    """One evaluation of the monitor.

    Attributes
    ----------
    time : float
        Simulation time of the sample, seconds.
    status : str
        ``"ok"``, ``"no contact"``, ``"invalid"`` (a pose the analysis refuses,
        e.g. deep penetration, or a non-finite state; see ``message``) or
        ``"not sampled"`` (before the first sample).
    message : str
        Why there is no report (the error's message), else ``""``.
    report : GraspReport or None
        The full analysis when ``status == "ok"``.
    epsilon : float
        Ferrari–Canny ε (L1 norm, moments divided by ``b``); 0 when not in
        force closure or not computed.
    holding : str
        The holding state (:data:`~drakegrasp.systems.holding.HOLDING_STATES`);
        an ``"invalid"`` sample keeps that of the last valid sample (the
        initial ``"no contact"`` before any), as it keeps its loads.
    loads : tuple of FingerLoad
        Per finger body: force, friction in use, slip.
    relative_speed : float
        Largest speed of the object's centre of mass relative to a touching
        finger, m/s (NaN without contact).
    sliding_speed : float
        Largest speed of the object's centre of mass along (normal component
        removed) the touching fingers, or without contact the fingers that
        touched it last, m/s.
    anchors : tuple of FingerAnchor
        Where the object sat on each touching finger (in the finger's frame),
        or on the fingers that touched it last while there is no contact.
    contact_gap : int
        Consecutive samples without contact over which the hysteresis kept a
        grip (the analysis shown is then the last one with contact); 0
        otherwise, a kept ``touching`` included (its analysis is not kept).
    memory : HoldingMemory
        What the holding state machine carries to the next sample (the
        state, samples without contact, the hysteresis count, the last grip).
    names : tuple of str
        Names of ``verdicts``' elements.
    verdicts : (len(names),) float
        The vector output.
    state : (nq + nv,) float
        The plant state the sample analysed.
    seconds : float
        Wall time the evaluation took.
    """

    time: float
    status: str
    message: str
    report: Any  # a GraspReport or None (not imported: a sample only reads it)
    epsilon: float
    holding: str
    loads: tuple[FingerLoad, ...]
    relative_speed: float
    sliding_speed: float
    contact_gap: int
    memory: HoldingMemory
    anchors: tuple
    names: tuple[str, ...]
    verdicts: np.ndarray
    state: np.ndarray
    seconds: float

    def __deepcopy__(self, memo) -> GraspSample:
        # Drake copies abstract state values (by deepcopy for Python objects)
        # whenever it clones a context; a sample is never mutated, so sharing
        # it is safe and avoids copying its report and contacts every clone.
        return self

    @property
    def is_force_closure(self) -> bool:
        """Force closure (with LP3) in this sample."""
        return self.report is not None and self.report.is_force_closure

    def to_dict(self) -> dict:
        """JSON-ready dictionary (the report's own ``to_dict`` nested)."""
        return {
            "time": self.time,
            "status": self.status,
            "message": self.message,
            "holding": self.holding,
            "verdicts": jsonable(
                dict(zip(self.names, (float(x) for x in self.verdicts), strict=True))
            ),
            "epsilon": self.epsilon,
            "loads": jsonable(list(self.loads)),
            "relative_speed": jsonable(self.relative_speed),
            "sliding_speed": jsonable(self.sliding_speed),
            "contact_gap": self.contact_gap,
            "memory": self.memory.to_dict(),
            "state": jsonable(self.state),
            "seconds": self.seconds,
            "report": None if self.report is None else self.report.to_dict(),
        }

    def __str__(self) -> str:
        v = dict(zip(self.names, self.verdicts, strict=True))
        grip = f"{self.holding}"
        if not np.isnan(v["friction_use"]):
            grip += f", friction in use {v['friction_use']:.2f}"
        grip += f", slip {1e3 * v['slip_speed']:.3g} mm/s"
        if self.sliding_speed > v["slip_speed"]:  # the object along the fingers
            grip += f", sliding {1e3 * self.sliding_speed:.3g} mm/s along the fingers"
        if self.contact_gap:
            grip += f", contact missing for {self.contact_gap} sample(s), held"
        if self.report is None:
            if self.status == "invalid":  # no evidence: the grip is kept
                grip = f"grip of the last valid sample kept: {grip}"
            head = f"t = {self.time:.4g} s: {self.status}" + (
                f" ({self.message})" if self.message else ""
            )
            return f"{head}; {grip}"
        yes = {True: "YES", False: "no"}
        # ε of a force-closure grasp is positive: 0 there means not computed.
        eps = (
            "eps not computed"
            if v["force_closure"] and v["epsilon"] == 0.0
            else f"eps = {v['epsilon']:.4g}"
        )
        return (
            f"t = {self.time:.4g} s: {grip}; {int(v['num_contacts'])} contacts, "
            f"force closure {yes[bool(v['force_closure'])]}, form closure "
            f"{yes[bool(v['form_closure'])]}, d* = {v['d_star']:.4g}, {eps}"
        )
