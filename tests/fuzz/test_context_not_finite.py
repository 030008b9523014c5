"""A context whose positions are not finite: a GraspError, not an abort.

Drake aborts the whole process (``SetPositions(): condition 'AllFinite(q)'
failed``: no exception, not even a bare ``except`` catches it) when positions
that are not finite are written back into a context.  The planner, a
candidate's ``apply`` and ``finger_jacobian`` write back the positions they
found, so a NaN or an infinity in the object's pose or a finger joint killed
the caller's process (a notebook's kernel, a batch job).  Every entry point
resolves its context with ``plant_context_of``, which now refuses one with an
``InvalidPoseError`` naming the joint.

The calls run in a child process, so that a regression fails this test
instead of killing the test run.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.planning import planning_scene
from drakegrasp.plant.validation import plant_context_of

CHILD = textwrap.dedent(
    """
    import sys, warnings
    import numpy as np
    from pydrake.math import RigidTransform
    from pydrake.multibody.tree import PrismaticJoint
    import drakegrasp as dg
    from drakegrasp.planning.motors import finger_jacobian

    warnings.simplefilter("ignore")
    scene = dg.planning_scene(
        "package://drakegrasp/objects/box.sdf",
        hand_url="package://drakegrasp/hands/parallel_jaw.sdf",
    )
    plant, root = scene.plant, scene.context
    ctx = plant.GetMyContextFromRoot(root)
    best = dg.plan_grasps(
        plant, root, scene.object_body, hand=scene.hand, num_candidates=20,
        mu=0.5, seed=0,
    )[0]
    calls = {
        "plan_grasps": lambda: dg.plan_grasps(
            plant, root, scene.object_body, hand=scene.hand, num_candidates=5,
            mu=0.5, seed=0,
        ),
        "plan_grasps(point_cloud=)": lambda: dg.plan_grasps(
            plant, root, None, hand=scene.hand, num_candidates=5, mu=0.5,
            seed=0, point_cloud=np.random.default_rng(0).normal(size=(300, 3)) * 0.03,
        ),
        "apply": lambda: best.apply(plant, root, object_body=scene.object_body),
        "finger_jacobian": lambda: finger_jacobian(
            plant, root, best, scene.object_body
        ),
        "analyze_grasp": lambda: dg.analyze_grasp(
            plant, root, scene.object_body, hand=scene.hand, mu=0.5
        ),
    }
    joint = next(
        plant.get_joint(j) for j in plant.GetJointIndices()
        if isinstance(plant.get_joint(j), PrismaticJoint)
    )
    for where in ("object", "finger"):
        for bad in (np.nan, np.inf):
            q = plant.GetPositions(ctx).copy()
            if where == "object":
                X = RigidTransform([bad, 0, 0])
                plant.SetFreeBodyPose(ctx, scene.object_body, X)
            else:
                joint.set_translation(ctx, bad)
            for name, call in calls.items():
                try:
                    call()
                    print(name, where, bad, "returned")
                except dg.InvalidPoseError as e:
                    print(name, where, bad, "InvalidPoseError", str(e))
                except Exception as e:
                    print(name, where, bad, "raw", type(e).__name__, e)
                sys.stdout.flush()
            plant.SetPositions(ctx, q)
    print("done")
    """
)


def test_positions_not_finite_are_refused_by_name():
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    proc = subprocess.run(
        [sys.executable, "-c", CHILD], capture_output=True, text=True, env=env,
        timeout=600,
    )  # fmt: skip
    lines = proc.stdout.splitlines()
    assert proc.returncode == 0, proc.stderr[-2000:]  # before: Drake's abort
    assert lines[-1] == "done"
    answers = lines[:-1]
    assert len(answers) == 5 * 2 * 2
    for line in answers:
        assert " InvalidPoseError plant_context holds positions that are not " in line
        joint = "box" if " object " in line else "left_finger_joint"
        assert f"::{joint}' at [" in line, line


def _jaw_scene():
    """The shipped jaw and box: the scene, its plant, context and positions."""
    scene = planning_scene(
        "package://drakegrasp/objects/box.sdf",
        hand_url="package://drakegrasp/hands/parallel_jaw.sdf",
    )
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    return scene, scene.plant, ctx, scene.plant.GetPositions(ctx).copy()


def test_the_message_names_every_joint_that_is_not_finite():
    scene, plant, ctx, q = _jaw_scene()
    finite = plant_context_of(plant, scene.context)
    assert finite is ctx
    for j in plant.GetJointIndices():
        joint = plant.get_joint(j)
        if joint.num_positions() == 1:
            joint.set_translation(ctx, np.inf)
    with pytest.raises(dg.InvalidPoseError) as caught:
        plant_context_of(plant, scene.context)
    assert str(caught.value).count("at [inf]") == 2
    plant.SetPositions(ctx, q)
    assert plant_context_of(plant, scene.context) is ctx


def test_a_checked_context_set_to_nan_inside_its_block_is_refused():
    # the cache of checked_context returned the context before the check: a
    # NaN set inside the block reached plan_grasps' write-back (Drake's abort)
    from drakegrasp.plant.validation import checked_context

    scene, plant, ctx, q = _jaw_scene()
    joint = next(
        plant.get_joint(j)
        for j in plant.GetJointIndices()
        if plant.get_joint(j).num_positions() == 1
    )
    with checked_context(plant, ctx) as checked:
        joint.set_translation(checked, np.nan)
        with pytest.raises(dg.InvalidPoseError, match="not finite"):
            plant_context_of(plant, checked)
    plant.SetPositions(ctx, q)
