"""Generated two-sided pinches (``fuzz_pinch``): sides, rolled sampling, shaken mass.

432 inputs, seeded, in about 25 s: 36 generated pinches (revolute and
prismatic, pads of random size and offset, multipliers -1 or not, the right
side written about a turned axis, frame or bracket, four-bar links with and
without geometry, a side without geometry, pads one behind the other, open
pads narrower than the object), each with its ``chain_sides`` and pinch
judged against its description, planned on the shipped box, cylinder,
sphere or prism (every other one also in a rigidly moved scene), every
third on a cloud of the box; 48 shakes crossing hostile and valid
``object_mass`` values, massless models, ``shake_test`` and
``shake_candidates`` on a plan, a slice or a list; 300 ``facing_chains``
inputs.  ``python tests/fuzz/fuzz_pinch.py`` prints the table.

The defects the families found (``fuzz_pinch.FINDINGS``) are not fixed
here: each has a strict xfail built on its reproducer, which a fix turns
into a pass (then drop its mark), and a generated case that shows a defect
no finding names fails the first test.
"""

import dataclasses
import warnings

import fuzz_pinch
import numpy as np
import pytest
from coupled_hands import one_motor_pinch_urdf

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError

SHORT = dict(fuzz_pinch.SHAKE)  # 0.6 s simulated: the mass is judged, not the hold


@pytest.fixture(scope="module")
def outcomes(checkout_env):  # the batch kernels compiled before the workers run
    fuzz_pinch.CHECKED.clear()
    families, bad, _ = fuzz_pinch.run()
    return families, bad, dict(fuzz_pinch.CHECKED)


def _shown(bad, key):
    return [row for row in bad if fuzz_pinch.finding(*row) == key]


def test_no_raw_error_hang_crash_or_wrong_answer_but_the_findings(outcomes):
    _, bad, _ = outcomes
    unknown = [row for row in bad if fuzz_pinch.finding(*row) is None]
    assert not unknown, "\n".join(f"{o}: [{f}] {n}: {d}" for f, n, o, d in unknown)


def test_every_family_ran_and_the_oracles_saw_enough(outcomes):
    families, _, checked = outcomes
    sizes = fuzz_pinch.SIZES
    assert set(families) == {
        "pinch sides", "pinch plan", "pinch cloud", "pinch shake", "facing_chains",
    }  # fmt: skip
    assert sum(families["pinch sides"].values()) == sizes["hands"]
    assert sum(families["pinch plan"].values()) == sizes["hands"]
    assert sum(families["pinch cloud"].values()) == -(-sizes["hands"] // 3)
    assert sum(families["pinch shake"].values()) == sizes["shakes"]
    assert sum(families["facing_chains"].values()) == sizes["facing_chains"]
    shake = families["pinch shake"]
    assert shake["clear GraspError"] > 0 and shake["plausible verdict"] > 0
    # (31 pinches, 131 candidates, 18 moved samplers, 4 exact moved plans of
    # 17 candidates, 26 cloud candidates, 25 shakes judged at the seeds)
    assert checked["sides"] == sizes["hands"] and checked["pinches"] >= 20
    assert checked["candidates"] >= 80 and checked["cloud candidates"] >= 10
    assert checked["moved samplers"] >= 15
    assert checked["moved plans"] >= 3 and checked["moved candidates"] >= 10
    assert checked["shakes"] >= 15


# ---------------------------------------------------------------- findings


@pytest.fixture(scope="module")
def pinch_plans(tmp_path_factory):
    """The shipped one-motor pinch planned for 20 kg on the 0.2 kg box, and
    for 0.3 kg on a massless box."""
    from drakegrasp.planning import plan_grasps, planning_scene

    folder = tmp_path_factory.mktemp("pinch_mass")
    hand = folder / "pinch.urdf"
    hand.write_text(one_motor_pinch_urdf())
    light = folder / "massless.sdf"
    light.write_text(fuzz_pinch._massless_sdf())
    out = {}
    for name, url, mass in (
        ("box", fuzz_pinch.BOX, 20.0),
        ("massless", str(light), 0.3),
    ):
        scene = planning_scene(url, hand_url=str(hand))
        result = plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=20, mu=0.5, seed=0, robustness_samples=2, certify=0,
            object_mass=mass,
        )  # fmt: skip
        assert len(result) >= 2
        out[name] = (scene, result)
    return out


def test_p1_a_refusal_of_sides_or_groups_is_one_line(outcomes):
    from drakegrasp.planning.centring import equalising_move, facing_chains

    _, bad, _ = outcomes
    shown = _shown(bad, "P1")
    assert not shown, f"{len(shown)} generated cases, first: {shown[0]}"
    lines = np.tile([1.0, 0.0, 0.0], (20, 1))
    for call in (
        lambda: facing_chains(np.zeros(3), np.array([object()] * 3)),
        lambda: facing_chains(np.zeros(20), np.arange(20.0)),  # floats, not ints
        lambda: equalising_move(np.zeros(20), lines, 1e-3, np.arange(20.0)),
    ):
        with pytest.raises(dg.GraspError) as refused:
            call()
        assert "\n" not in str(refused.value), repr(str(refused.value))


def test_p2_a_slice_or_list_of_a_plan_shakes_the_mass_planned_for(
    outcomes, pinch_plans
):
    from drakegrasp.planning import shake_candidates

    _, bad, _ = outcomes
    shown = _shown(bad, "P2")
    assert not shown, f"{len(shown)} generated cases, first: {shown[0]}"
    scene, result = pinch_plans["box"]  # planned for 20 kg; the model is 0.2 kg
    assert result.settings["object_mass"] == 20.0
    whole = shake_candidates(scene.add_models, result, top=1, **SHORT)
    assert whole[0].result.object_mass == 20.0  # the plan's: as documented
    for given in (result[:1], [c for c in result if c.is_closure] or list(result)):
        shaken = shake_candidates(scene.add_models, given, top=1, **SHORT)
        # shaken at 0.2 kg (and "object 0.2 kg" in its summary)
        assert shaken[0].result.object_mass == 20.0, str(shaken).splitlines()[0]


def test_p3_a_tiny_object_mass_is_refused_up_front_or_shaken(outcomes, pinch_plans):
    from drakegrasp.planning import shake_test

    _, bad, _ = outcomes
    shown = _shown(bad, "P3")
    assert not shown, f"{len(shown)} generated cases, first: {shown[0]}"
    scene, result = pinch_plans["box"]
    for mass in (1e-12, 1e-300):  # finite, > 0, a finite weight: accepted
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                shaken = shake_test(
                    scene.add_models, result[0], object_mass=mass, **SHORT
                )
        except dg.GraspError as e:
            # now a SolverError blaming the fingers' gains, or a ModelError
            # blaming the model, once Drake's step failed
            assert isinstance(e, InvalidOptionError) and "object_mass" in str(e), (
                f"{mass:g} kg: {type(e).__name__}: {str(e)[:200]}"
            )
        else:
            assert shaken.object_mass == mass
            assert np.isfinite(shaken.max_displacement)


def test_p4_a_massless_shake_whose_ball_overflows_is_refused(outcomes, pinch_plans):
    from drakegrasp.planning import shake_test

    _, bad, _ = outcomes
    shown = _shown(bad, "P4")
    assert not shown, f"{len(shown)} generated cases, first: {shown[0]}"
    scene, result = pinch_plans["massless"]
    for change in (
        {"torque_scale": 1e200},  # the ball's radius: its inertia overflows
        {"reference_point": np.array([1e200, 0.0, 0.0])},  # shifted to there
    ):
        candidate = dataclasses.replace(result[0], **change)
        # torque_scale nan, 0, -1 or inf is refused with a ModelError; these
        # raise Drake's RuntimeError (SpatialInertia::IsPhysicallyValid)
        with pytest.raises(dg.GraspError):
            shake_test(scene.add_models, candidate, object_mass=0.3, **SHORT)
