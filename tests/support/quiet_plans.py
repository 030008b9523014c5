"""``plan_grasps`` on a planning scene, its warnings silenced."""

from __future__ import annotations

import warnings

from drakegrasp.planning import plan_grasps


def plan_quietly(scene, **options):
    """``plan_grasps`` of ``scene``'s object with its hand and ``options``.

    Friction mismatches and the like are silenced: the tests that use it
    check what the plan returns or refuses, not what it warns of.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            **options,
        )  # fmt: skip
