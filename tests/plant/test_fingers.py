"""A finger's tip found from the plant alone is the tip its object pairs name.

:func:`drakegrasp.plant.fingers.tip_bodies` serves point clouds, where no object
geometry exists to pair the finger's geometry with.  On real hands with an
object, ``Finger.tip_pairs`` (found from the pairs) is an independent route to
the same bodies.
"""

from __future__ import annotations

import pytest

from drakegrasp.plant.fingers import tip_bodies

from .conftest import structure_of


@pytest.mark.parametrize(
    "hand, fingers, tip_names",
    [
        ("wsg", 2, {"left_finger", "right_finger"}),
        ("franka", 2, {"panda_leftfinger", "panda_rightfinger"}),
        ("allegro", 4, {"link_3", "link_7", "link_11", "link_15"}),
    ],
)
def test_the_tip_from_the_plant_alone_is_the_tip_of_the_pairs(
    real_hands, hand, fingers, tip_names
):
    scene = getattr(real_hands, hand)()
    structure = structure_of(scene)
    assert len(structure.fingers) == fingers
    names = set()
    for finger in structure.fingers:
        alone = tip_bodies(scene.plant, structure, finger)
        from_pairs = {int(b.index()) for _, _, b in finger.tip_pairs}
        assert alone, finger.name
        assert {int(b.index()) for b in alone} == from_pairs, finger.name
        # in the finger's own body order, each body once
        order = [int(b.index()) for b in finger.bodies]
        got = [int(b.index()) for b in alone]
        assert got == sorted(got, key=order.index) and len(set(got)) == len(got)
        names |= {b.name() for b in alone}
    assert names == tip_names
