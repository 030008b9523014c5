"""A hand whose base frame is a bare mount plans as the hand without it.

Many URDFs root a hand at a link without geometry, fixed to the palm link
somewhere else and turned (``mount`` below).  The planner read the palm from
the free base's own collision geometry, so such a palm was the mount's
origin: a pivoting jaw under a turned mount found 0 candidates of 40
samples (1 of 150, against 61 without the mount); and a pinch's closing
axis, from boxes along the base frame's axes, came out 0.46 deg off, one
tip sphere of each pad 0.13 mm off the face (4 force-closure candidates of
63, against 43 of 61).  The route for parallel jaws read its approach from
the same palm.  Moving the base frame is a change of coordinates: the plan
is the same.
"""

from __future__ import annotations

import numpy as np
from coupled_hands import pivot_jaw_urdf

from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.plant.models import models_dir

BOX = "package://drakegrasp/objects/box.sdf"
MOUNT = ("0.3 -0.2 0.5", "1.2 0.4 -2.0")


def _plan(hand):
    scene = planning_scene(BOX, hand_url=hand)
    return plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=40, mu=1.0, seed=0, robustness_samples=4,
    )  # fmt: skip


def test_a_pivoting_jaw_under_a_turned_mount_plans_as_without(tmp_path):
    bare, mounted = tmp_path / "bare.urdf", tmp_path / "mounted.urdf"
    bare.write_text(pivot_jaw_urdf())
    mounted.write_text(pivot_jaw_urdf(mount=MOUNT))
    want, got = _plan(bare), _plan(mounted)
    closure = [sum(c.is_closure for c in r) for r in (want, got)]
    assert closure[0] >= 10
    # the hand's grasp frame is rolled otherwise about the approach, so the
    # samples differ a little: the same best grasp, about as many of them
    assert abs(closure[1] - closure[0]) <= 0.2 * closure[0]
    np.testing.assert_allclose(got[0].score, want[0].score, rtol=1e-3)


def test_a_parallel_jaw_under_a_turned_mount_plans_as_without(tmp_path):
    flat = (models_dir() / "hands" / "parallel_jaw_flat.sdf").read_text()
    xyz, rpy = MOUNT
    mount = (
        f'<link name="mount"><pose>{xyz} {rpy}</pose><inertial><mass>0.1</mass>'
        "<inertia><ixx>1e-4</ixx><iyy>1e-4</iyy><izz>1e-4</izz><ixy>0</ixy>"
        "<ixz>0</ixz><iyz>0</iyz></inertia></inertial></link>"
        '<joint name="mount_weld" type="fixed"><parent>mount</parent>'
        "<child>palm</child></joint>"
    )
    tag = '<model name="parallel_jaw_flat">'
    assert tag in flat
    mounted = tmp_path / "mounted.sdf"
    mounted.write_text(flat.replace(tag, tag + mount, 1))
    want = _plan("package://drakegrasp/hands/parallel_jaw_flat.sdf")
    got = _plan(mounted)
    assert len(want) > 10 and len(got) == len(want)
    np.testing.assert_allclose(
        [c.score for c in got], [c.score for c in want], rtol=1e-9, atol=1e-12
    )
