"""Generated coupled hands (``fuzz_coupled``): no raw error, hang or wrong answer.

256 calls on 64 generated hands (32 pinches, 32 spread hands of random
sizes, limits, mimic multipliers, offsets, efforts and transmissions: each
closed twice, planned on a body and on a cloud) and 600 ``equalising_move``
inputs, seeded, in about 35 s; ``python tests/fuzz/fuzz_coupled.py`` prints
the table.

The four defects the families found in their first run
(``fuzz_coupled.FINDINGS``) are fixed; each keeps a test of its own built on
its reproducer, and a generated case that shows one again fails.
"""

import fuzz_coupled
import numpy as np
import pytest

import drakegrasp as dg


@pytest.fixture(scope="module")
def outcomes(checkout_env):  # the batch kernels compiled before the workers run
    fuzz_coupled.CHECKED.clear()
    families, bad, _ = fuzz_coupled.run()
    return families, bad, dict(fuzz_coupled.CHECKED)


def _shown(bad, key):
    return [row for row in bad if fuzz_coupled.finding(*row) == key]


def test_no_raw_error_hang_crash_or_wrong_answer(outcomes):
    # the four findings of the first run (fuzz_coupled.FINDINGS) are fixed:
    # a case that shows one again fails here too
    _, bad, _ = outcomes
    assert not bad, "\n".join(
        f"{o}: [{f}] {n}: {d} ({fuzz_coupled.finding(f, n, o, d)})"
        for f, n, o, d in bad
    )


def test_every_route_refused_and_answered_and_the_oracles_saw_enough(outcomes):
    families, _, checked = outcomes
    sizes = fuzz_coupled.SIZES
    assert set(families) == {
        "coupled pinch", "coupled spread", "equalising_move",
        "equalising_move shapes",
    }  # fmt: skip
    for kind in fuzz_coupled.KINDS:
        counts = families[f"coupled {kind}"]
        assert sum(counts.values()) == 4 * sizes[kind]
        assert counts["clear GraspError"] > 0 and counts["plausible verdict"] > 0
    assert (
        sum(sum(families[f].values()) for f in families if "equal" in f)
        == (sizes["equalising_move"])
    )
    # (37 closings, 225 candidates on bodies, 183 on clouds at the seeds)
    assert checked["closed hands"] >= 30
    assert checked["candidates"] >= 150 and checked["cloud candidates"] >= 120
    assert checked["contacts on a chain"] >= 600


# ---------------------------------------------------------------- findings


def test_f1_equalising_move_refuses_hostile_arrays(outcomes):
    from drakegrasp.planning.centring import equalising_move

    _, bad, _ = outcomes
    assert not _shown(bad, "F1")
    psi, lines = np.array([0.01, 0.02]), np.array([[1.0, 0, 0], [-1.0, 0, 0]])
    for args in (
        (None, lines, 1e-4),
        (psi, [[1.0, 0.0, 0.0], [0.0, 1.0]], 1e-4),
        (psi, lines[:, :2], 1e-4),
        (psi, lines, "1e-4"),
        (psi, lines, 1e-4, [0, 0, 0]),
    ):
        try:
            t = equalising_move(*args)
        except dg.GraspError:
            continue
        assert t is None or np.shape(t) == (3,)


def test_f2_a_hand_whose_limits_leave_its_motor_no_value_is_refused(outcomes, tmp_path):
    from coupled_hands import one_motor_pinch_urdf

    from drakegrasp.planning import planning_scene

    _, bad, _ = outcomes
    assert not _shown(bad, "F2")
    # right_knuckle = -left_knuckle in [-0.8, -0.5] needs left_knuckle >= 0.5,
    # left_pad_joint = -left_knuckle in [-0.3, 0] needs it <= 0.3
    text = one_motor_pinch_urdf()
    knuckle = 'xyz="0.055 0 0.06"/><axis xyz="0 1 0"/><limit lower="-0.8" upper="0"'
    pad = 'link="left_pad"/><origin xyz="0 0 0.05"/><axis xyz="0 1 0"/><limit '
    pad += 'lower="-0.8"'
    assert text.count(knuckle) == text.count(pad) == 1
    text = text.replace(knuckle, knuckle.replace('upper="0"', 'upper="-0.5"'))
    text = text.replace(pad, pad.replace('lower="-0.8"', 'lower="-0.3"'))
    path = tmp_path / "pinch.urdf"
    path.write_text(text)
    scene = planning_scene("package://drakegrasp/objects/box.sdf", hand_url=str(path))
    for seed in (0, 2):  # both raised the ValueError
        try:
            dg.plan_grasps(
                scene.plant, scene.context, scene.object_body, hand=scene.hand,
                num_candidates=20, mu=0.5, seed=seed, robustness_samples=2,
            )  # fmt: skip
        except dg.GraspError:
            pass


def test_f3_the_centring_move_does_not_spread_the_gaps(outcomes):
    from drakegrasp.planning.centring import equalising_move

    _, bad, _ = outcomes
    assert not _shown(bad, "F3")
    # six chains of an earlier draw of fuzz_coupled: spread 18.2 mm -> 19.8 mm
    psi = np.array(
        [
            0.02612933844915267,
            0.02620691119235856,
            0.00800386214975783,
            0.02231139871985573,
            0.01277238859337603,
            0.02491534833160252,
        ]
    )
    lines = np.array([
        [0.5352707576052976, -0.12181497837245968, -0.8358506607622966],
        [0.03384504796250527, 0.9332322320736559, -0.35767598989481786],
        [0.7390656221039439, 0.5269810751218141, -0.4196104773329277],
        [-0.5810164766417334, -0.7941416247552225, 0.1782103636210903],
        [-0.9198320672260556, -0.22852117897265922, -0.31888405238203277],
        [0.43625028032917484, -0.2632774837054972, 0.8604479411832061],
    ])  # fmt: skip
    t = equalising_move(psi, lines, 1e-3)
    assert t is None or np.ptp(psi - lines @ t) <= np.ptp(psi)


# an earlier draw of fuzz_coupled (a spread hand, cloud on the hex prism), its hostile
# parts put back to nominal (couplings 1 and 0.5, efforts 5, motors on the leaders)
F4_HAND = {
    "kind": "spread",
    "palm_radius": 0.05592438138869439,
    "fingers": {
        "f3": {"xyz": [0.03592438138869439, 0.0, 0.0], "yaw": np.pi, "axis": None},
        "f1": {"xyz": [-0.03592438138869439, 0.013412032680686777, 0.0],
               "yaw": 0.0, "axis": [0, 0, -1]},
        "f2": {"xyz": [-0.03592438138869439, -0.013412032680686777, 0.0],
               "yaw": 0.0, "axis": [0, 0, 1]},
    },
    "links": [0.04487639294041268, 0.031170163853760063, 0.00624953305431385],
    "joints": {
        "f1_spread": {"limits": [-0.3035007409019502, 1.0238600034959133]},
        "f2_spread": {"limits": [-0.3035007409019502, 1.0238600034959133]},
        "f3_proximal_joint": {"limits": [-0.3136232150897083, 1.196465902127977]},
        "f3_distal_joint": {"limits": [-0.15681160754485415, 0.5982329510639885]},
        "f1_proximal_joint": {"limits": [-0.05587477602892804, 2.1127111982960014]},
        "f1_distal_joint": {"limits": [-0.02793738801446402, 1.0563555991480007]},
        "f2_proximal_joint": {"limits": [-0.3838164769907054, 1.2530164467469227]},
        "f2_distal_joint": {"limits": [-0.1919082384953527, 0.6265082233734613]},
    },
    "couplings": [
        ["f2_spread", "f1_spread", 1.0, 0.0],
        ["f3_distal_joint", "f3_proximal_joint", 0.5, 0.0],
        ["f1_distal_joint", "f1_proximal_joint", 0.5, 0.0],
        ["f2_distal_joint", "f2_proximal_joint", 0.5, 0.0],
    ],
    "efforts": dict.fromkeys(
        ["f1_spread", "f2_spread", "f1_proximal_joint", "f1_distal_joint",
         "f2_proximal_joint", "f2_distal_joint", "f3_proximal_joint",
         "f3_distal_joint"], 5.0,
    ),
    "transmissions": ["f1_spread", "f1_proximal_joint", "f2_proximal_joint",
                      "f3_proximal_joint"],
    "hostile": [],
}  # fmt: skip
F4_PRESHAPE = {
    "f1_spread": -0.30262656643687563, "f2_spread": -0.30262656643687563,
    "f1_proximal_joint": 0.4160143308907347, "f1_distal_joint": 0.20800716544536735,
    "f2_proximal_joint": -0.2871918249165376, "f2_distal_joint": -0.1435959124582688,
    "f3_proximal_joint": 0.06030255838917259, "f3_distal_joint": 0.030151279194586295,
}  # fmt: skip


def test_f4_no_cloud_candidate_has_a_link_inside_the_object(outcomes):
    from sandbox import Sandbox

    _, bad, _ = outcomes
    shown = _shown(bad, "F4")
    assert not shown, "\n".join(f"[{f}] {n}: {d}" for f, n, _, d in shown)
    spec = {
        "hand": F4_HAND,
        "object": "hex_prism",
        "object_pose": {"p": [0.0, 0.0, 0.0], "rpy": [0.0, 0.0, 0.0]},
        "pose": {"p": [0.0, 0.0, 1.0], "rpy": [0.0, 0.0, 0.0]},  # not read
        "q": F4_PRESHAPE,
        "cloud_seed": 1,
        "cloud_points": 1500,
        "kwargs": {
            "num_candidates": 12, "mu": 0.8, "seed": 1, "robustness_samples": 2,
            "certify": 0, "distance_tolerance": 1e-3, "object_mass": 0.2,
        },
    }  # fmt: skip
    assert not fuzz_coupled.configuration_faults(F4_HAND, F4_PRESHAPE)
    with Sandbox(timeout=60.0) as box:
        out = box.call("fuzz_coupled:cloud_case", spec)
    # f1_distal 28 mm inside the prism (no cloud point inside the link)
    assert fuzz_coupled.planned_right(F4_HAND)(out)
