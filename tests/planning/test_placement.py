"""Poses rejected without Drake: the open hand surely penetrates the object.

:meth:`~drakegrasp.planning.placement.BodyCloser.sure_collisions` decides in
numpy, before any Drake query, that some open hands penetrate the object; each
such pose must be one that Drake's closing rejects for the same reason, and
planning must give the same candidates and the same rejection counts with and
without it.
"""

from __future__ import annotations

import numpy as np
import pytest

from drakegrasp.planning import plan_grasps
from drakegrasp.planning.gripper import parallel_jaw
from drakegrasp.planning.placement import BodyCloser, sample_poses
from drakegrasp.planning.planner import object_surface
from drakegrasp.plant.contacts import DEFAULT_DISTANCE_TOLERANCE

TOL = DEFAULT_DISTANCE_TOLERANCE


def _closer_and_poses(scene, n=600, seed=3):
    plant = scene.plant
    ctx = plant.GetMyContextFromRoot(scene.context)
    body = scene.object_body
    gripper = parallel_jaw(plant, ctx, body, scene.hand)
    surface = object_surface(plant, ctx, body)
    X_WO = plant.EvalBodyPoseInWorld(ctx, body)
    rng = np.random.default_rng(seed)
    poses, _ = sample_poses(
        surface, gripper, X_WO, n, mu=1.0, clearance=5e-3, rng=rng, tol=TOL
    )
    closer = BodyCloser(plant, ctx, body, scene.hand, gripper, TOL)
    return closer, poses, surface, X_WO


def _drake_reason(closer, poses, k):
    from pydrake.math import RigidTransform, RotationMatrix

    X_WH = RigidTransform(RotationMatrix(poses["R_WH"][k]), poses["p_WH"][k])
    return closer.close_on_body(X_WH, float(poses["opening"][k]))[2]


@pytest.mark.parametrize("name", ["003_cracker_box", "004_sugar_box"])
def test_sure_collisions_are_drakes_collisions_wsg(wsg_scene, name):
    closer, poses, surface, X_WO = _closer_and_poses(wsg_scene(name))
    sure = closer.sure_collisions(poses, surface, X_WO)
    assert sure.sum() >= 20  # the check does reject poses (else it tests nothing)
    reasons = [_drake_reason(closer, poses, k) for k in range(len(sure))]
    colliding = np.array([r == "hand collides with the object" for r in reasons])
    assert np.all(colliding[sure])  # the same truth as Drake's
    assert colliding.sum() > sure.sum()  # unsure ones are left to Drake


def test_sure_collisions_are_drakes_collisions_own_jaw(own_scene):
    for name in ("box", "hex_prism"):
        closer, poses, surface, X_WO = _closer_and_poses(own_scene(name), n=400)
        sure = closer.sure_collisions(poses, surface, X_WO)
        assert sure.sum() >= 10
        reasons = [_drake_reason(closer, poses, k) for k in np.flatnonzero(sure)]
        assert all(r == "hand collides with the object" for r in reasons)


def test_same_candidates_and_counts_without_the_numpy_check(wsg_scene, monkeypatch):
    scene = wsg_scene("003_cracker_box")
    args = (scene.plant, scene.context, scene.object_body)
    kwargs = dict(hand=scene.hand, num_candidates=300, mu=1.0, seed=5)
    fast = plan_grasps(*args, **kwargs)

    def unsure(self, poses, surface, X_WO):
        return np.zeros(len(poses["opening"]), bool)

    monkeypatch.setattr(BodyCloser, "sure_collisions", unsure)
    slow = plan_grasps(*args, **kwargs)
    assert fast.rejections == slow.rejections
    assert fast.rejections["hand collides with the object"] > 0
    assert len(fast) == len(slow) > 0
    for a, b in zip(fast, slow, strict=True):
        assert a.sample == b.sample
        assert np.array_equal(a.X_WH.GetAsMatrix34(), b.X_WH.GetAsMatrix34())
        assert np.array_equal(a.q_hand, b.q_hand)
        same = [a.d_star, a.epsilon, a.robustness, a.score]
        assert np.array_equal(same, [b.d_star, b.epsilon, b.robustness, b.score])
