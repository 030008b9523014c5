"""The holding state in a pick with real models: the WSG-50 and the YCB sugar box.

A firm grip (fingers commanded 10 mm past the box, ~10 N per pad with μ = 1)
lifts the 0.514 kg box 8 cm; a weak one (1.5 mm past, ~1.5 N per pad: two
pads carry at most ~3 N < 5.04 N) slides up the box, which stays on the
ground, until the pads leave it.  What the box did is read from the logged
plant states, apart from the monitor (``holding_support.timeline``).  The
monitor reads μ from the plant (``mu="plant"``).
"""

import numpy as np
import pytest
from wsg_pick_support import (
    BOX_HALF_HEIGHT,
    FIRM,
    LIFT,
    LIFT_START,
    WEAK,
    wsg_pick_timeline,
)

from drakegrasp.systems.monitor import GraspMonitor

NEAR = -5e-4  # squeeze: the fingers stop 0.5 mm short of the box faces
PADS_OFF = 1.45  # s: by then the weak pick's pads have slid off the box top
MODES = ["contact_results", "geometry"]


def _run(models_dir, squeeze, contacts):
    return wsg_pick_timeline(models_dir, squeeze=squeeze, contacts=contacts)


@pytest.mark.parametrize("contacts", MODES)
def test_firm_wsg_pick_is_holding_throughout_the_lift(drake_models_dir, contacts):
    line = _run(drake_models_dir, FIRM, contacts)
    airborne = line.height > BOX_HALF_HEIGHT + 5e-4
    assert airborne.sum() > 50
    assert line.height.max() > BOX_HALF_HEIGHT + LIFT - 2e-3  # lifted 8 cm
    assert line.displacement[line.times >= LIFT_START].max() < 2e-3  # it held
    held = [s for s, up in zip(line.states, airborne, strict=True) if up]
    assert set(held) == {"holding"}, held


@pytest.mark.parametrize("contacts", MODES)
def test_weak_wsg_pick_is_flagged_before_it_moves_5_mm_and_dropped_after(
    drake_models_dir, contacts
):
    line = _run(drake_models_dir, WEAK, contacts)
    flagged, moved, dropped = line.slip_times(after=LIFT_START)
    print(
        f"WSG-50 + sugar box, {contacts}: flagged {flagged:.3f} s, moved 5 mm "
        f"{moved:.3f} s, dropped {dropped:.3f} s"
    )
    assert line.height.max() < BOX_HALF_HEIGHT + 5e-4  # it never left the ground
    assert moved < LIFT_START + 0.2  # the fingers slid along it
    assert flagged < moved < dropped < PADS_OFF
    # The pads chatter along the box (contact in ~1 sample of 8), yet the state
    # never flickers: it only grows more alarming from the lift to the end.
    codes = line.codes(LIFT_START, 2.0)
    assert np.all(np.diff(codes) >= 0), line.states
    assert line.states[-1] == "dropped"  # the pads have left the box


@pytest.mark.parametrize("contacts", MODES)
def test_box_between_fingers_that_stop_short_of_it_is_never_holding(
    drake_models_dir, contacts
):
    # The pads stop 0.5 mm short of the box: within the 1 mm distance
    # tolerance, so the geometric analysis sees contacts, but nothing presses.
    line = _run(drake_models_dir, NEAR, contacts)
    assert line.height.max() < BOX_HALF_HEIGHT + 5e-4  # it stays on the ground
    assert set(line.states) == {"no contact"}, set(line.states)
    if contacts == "geometry":
        assert line.verdicts[GraspMonitor.NUM_CONTACTS].max() > 0
