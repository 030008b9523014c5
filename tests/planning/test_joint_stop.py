"""The shake test says when a squeezing joint stands at its limit at the seat.

A joint aimed past its position limit stops there, and its motor's effort
goes into the stop: the object keeps none of it.  A Robotiq-3-finger-like
hand's scissor joint, planned 0.0225 rad from its limit and aimed 0.067 rad
past, reached the stop within 20 ms and its sphere fell 4.2 m, with nothing
said.  Here the pinch of ``tests/support`` is given a knuckle limit 0.5 mrad
past a planned grasp's, as such a model would have it: the box slides out (18
mm), and the warning says why.  (2 mrad of room, squeezing the pads through
their compliance against the stop, still held it.)
"""

from __future__ import annotations

import re
import warnings

import pytest
from coupled_hands import one_motor_pinch_urdf, plan_on_box

from drakegrasp.planning import planning_scene, shake_test
from drakegrasp.planning.shake import SqueezeLostWarning

BOX = "package://drakegrasp/objects/box.sdf"
QUICK = dict(settle=0.2, phase=0.3, object_mass=0.2)
AT_STOP = "pressed the stop, not the object"
KNUCKLE = "one_motor_pinch::left_knuckle"
pytestmark = pytest.mark.filterwarnings(
    "ignore::drakegrasp.plant.friction.FrictionMismatchWarning"  # plan 0.5, Drake 1
)


@pytest.fixture(scope="module")
def pinch(tmp_path_factory):
    """The one-motor pinch planned on the box: its scene, best candidate and URDF."""
    tmp = tmp_path_factory.mktemp("stop")
    urdf = one_motor_pinch_urdf()
    scene, result = plan_on_box(tmp / "pinch.urdf", urdf)
    assert len(result) > 5, result.reason
    return tmp, urdf, scene, result[0]


def _shake(add_models, candidate):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = shake_test(add_models, candidate, **QUICK)
    return result, [
        str(w.message) for w in caught if issubclass(w.category, SqueezeLostWarning)
    ]


def _with_knuckle_limit(urdf: str, candidate, room: float) -> str:
    """``urdf`` whose left knuckle may close only ``room`` rad past the plan's."""
    i = candidate.joint_names.index(KNUCKLE)
    q, sign = float(candidate.q_hand[i]), float(candidate.closing_signs[i])
    joint = re.search(r'<joint name="left_knuckle".*?</joint>', urdf, re.S).group(0)
    lower, upper = (float(v) for v in re.search(
        r'lower="([^"]+)" upper="([^"]+)"', joint).groups())  # fmt: skip
    lower, upper = (lower, q + room) if sign > 0 else (q - room, upper)
    tight = re.sub(
        r'lower="[^"]+" upper="[^"]+"', f'lower="{lower!r}" upper="{upper!r}"', joint
    )
    return urdf.replace(joint, tight)


def _tight(tmp, urdf, best, room):
    path = tmp / f"tight_{room:g}.urdf"
    path.write_text(_with_knuckle_limit(urdf, best, room=room))
    return planning_scene(BOX, hand_url=str(path))


def _seated_knuckle(result, best) -> float:
    return result.seated_q_hand[best.joint_names.index(KNUCKLE)]


def _limit(best, room: float) -> float:
    """The knuckle's limit that :func:`_with_knuckle_limit` gives ``room`` for."""
    i = best.joint_names.index(KNUCKLE)
    return float(best.q_hand[i]) + float(best.closing_signs[i]) * room


def test_a_knuckle_at_its_limit_is_said_and_one_with_room_is_not(pinch):
    tmp, urdf, scene, best = pinch
    roomy, said = _shake(scene.add_models, best)
    assert roomy.held and not any(AT_STOP in m for m in said), said

    stopped, said = _shake(_tight(tmp, urdf, best, 0.0005).add_models, best)
    at_stop = [m for m in said if AT_STOP in m]
    assert len(at_stop) == 1, said
    assert not stopped.held
    head = "the object was not held, and at the seat the closing joint 'left_knuckle'"
    assert at_stop[0].startswith(head), at_stop
    # the effort it names is the motor's, which the result reports too
    assert f"({stopped.efforts[0]:.3g} N·m)" in at_stop[0], (at_stop, stopped.efforts)
    # where the result seats the knuckle, read apart from the warning: its limit
    limit = _limit(best, 0.0005)
    assert f"at its limit {limit:.4g} " in at_stop[0]
    assert _seated_knuckle(stopped, best) == pytest.approx(limit, abs=1e-9)


def test_a_grasp_held_against_a_stop_is_not_warned_of(pinch):
    """2 mrad of room: the knuckle seats at its limit too, the pads squeezed
    through their compliance against the stop, and the box holds; the stop
    explains only a drop."""
    tmp, urdf, _, best = pinch
    limit = _limit(best, 0.002)
    held, said = _shake(_tight(tmp, urdf, best, 0.002).add_models, best)
    assert _seated_knuckle(held, best) == pytest.approx(limit, abs=1e-9)
    assert held.held and not any(AT_STOP in m for m in said), said
