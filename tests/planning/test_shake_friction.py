"""A shake says so when the plan's μ is not the friction Drake simulates.

``plan --mu 10 --shake`` planned "0.2 N per finger" and shook at the
models' μ = 1 without a word.  The shake keeps simulating the models'
friction (what a real hand meets) and warns when the plan assumed another.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from drakegrasp.planning import plan_grasps, planning_scene, shake_test
from drakegrasp.plant.friction import FrictionMismatchWarning, hand_object_friction

BOX = "package://drakegrasp/objects/box.sdf"
FLAT = "package://drakegrasp/hands/parallel_jaw_flat.sdf"


@pytest.fixture(scope="module")
def scene():
    # the shipped jaw: the default hand (the WSG-50) needs drake_models
    return planning_scene(BOX, hand_url=FLAT)


def _best(scene, mu):
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=30, mu=mu, seed=0,
    )  # fmt: skip
    return result[0]


def _models_mu(scene) -> float:
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    mus = hand_object_friction(
        scene.plant, ctx, scene.object_body, scene.hand, rule="dynamic"
    )
    assert np.ptp(mus) == 0  # one friction for every hand-object pair
    return float(mus[0])


def test_a_plan_at_another_mu_warns_with_both_figures(scene):
    mu = _models_mu(scene)
    with pytest.warns(FrictionMismatchWarning, match=f"mu = {3 * mu:g}.*mu = {mu:g}"):
        shake_test(scene.add_models, _best(scene, 3 * mu))


def test_a_plan_at_the_models_mu_does_not(scene):
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrictionMismatchWarning)
        shake_test(scene.add_models, _best(scene, _models_mu(scene)))


def test_the_command_line_gives_the_advice_as_a_flag(capsys):
    from drakegrasp.cli import main

    assert main(["plan", "--num", "30", "--top", "1", "--shake", "1", "--mu", "3"]) == 0
    warned = [w for w in capsys.readouterr().err.splitlines() if "mu = 3" in w]
    assert len(warned) == 1 and "plan with --mu plant," in warned[0]


@pytest.mark.parametrize(
    "pairs, warned",
    [((1.0, 1.0), False), ((1.0, 2.0), False), ((0.5, 1.0), True), ((2.0, 3.0), True)],
)
def test_the_smallest_pair_friction_is_what_a_plan_may_take(monkeypatch, pairs, warned):
    # `--mu plant` plans with the smallest pair friction: where the pairs
    # differ, its shake warned and advised `--mu plant`, which it was
    import drakegrasp.planning.shake as shake

    monkeypatch.setattr(shake, "hand_object_friction", lambda *a: np.array(pairs))

    class Candidate:
        contact_options = {"mu": 1.0}

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        shake._warn_friction(None, None, None, None, Candidate())
    assert (
        any(issubclass(w.category, FrictionMismatchWarning) for w in caught) is warned
    )
