"""Review r22: the holding state against the box's own motion, in SAP.

An audit against independent truth (the box's height and the fingers' normal
force from the plant's contact results) found, with Drake's SAP, that:

* a sliding grip read "no contact": SAP opens a sliding contact at μ times its
  slip speed while it still pushes, and the monitor took that for separation
  (a 1 kg box at μ = 1, 4.7 N per finger);
* a slip that the hand caught again read "dropped": the fingers chattered apart
  faster than the box slid, so it looked at rest, 18 mm along them;
* a re-grip pressing the pads deeper than the distance tolerance gave "invalid"
  samples that counted as lost contact, and then "dropped" (1.5 kg, 147 N).

Each scenario runs in about 2-4 s.
"""

from __future__ import annotations

import numpy as np
import pytest
from slip_support import let_go, regrip, simulate


def test_a_sliding_grip_at_mu_1_is_slipping_until_dropped_never_no_contact():
    # Squeeze eased from 2x what holds to 0 over 2 s: the box slips near 2.0 s.
    squeeze = let_go(1.0, 1.0, ramp=2.0)
    run = simulate(mu=1.0, mass=1.0, squeeze=squeeze, duration=2.4, modes=("geometry",))
    slipping = run.first("geometry", ("slipping",), after=1.0)
    dropped = run.first("geometry", ("dropped",), after=1.0)
    assert np.isfinite(slipping) and slipping < dropped
    between = run.states("geometry", slipping, dropped)
    assert "no contact" not in between, between
    # Independent truth: slipping is said before the box has fallen 1 mm, and
    # while the fingers still press on it.
    fell = run.times[np.argmax(run.height < run.height[0] - 1e-3)]
    assert slipping <= fell
    assert run.squeeze[np.searchsorted(run.times, slipping)] > 1.0


@pytest.mark.parametrize(
    ("mu", "mass"),
    [(1.0, 1.0), (0.2, 1.5)],
    ids=["chatter mu 1", "deep re-grip"],
)
def test_a_slip_the_hand_catches_is_never_dropped(mu, mass):
    run = simulate(mu=mu, mass=mass, squeeze=regrip(mu, mass), duration=1.7)
    # Independent truth: the box slid (more than 10 mm), never left the hand
    # (the fingers press on it in every 50 ms), and ends held, at rest.
    slid = run.height[0] - run.height[-1]
    assert slid > 0.01
    late = run.times > 1.2
    windows = run.squeeze[late][: late.sum() // 5 * 5].reshape(-1, 5).max(axis=1)
    assert windows.min() > 1.0
    assert abs(run.height[-1] - run.height[-5]) < 1e-4
    for mode in ("geometry", "contact_results"):
        states = run.states(mode)
        assert "dropped" not in states, (mode, states)
        assert "slipping" in run.states(mode, 1.0, 1.5), mode
        assert states[-1] == "holding", (mode, states)
