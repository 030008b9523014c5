"""A hand's passive joints are named when the planner holds them locked.

A one-dof joint without an actuator that follows no other turns freely in
Drake; the planner keeps it where the context puts it.  On a three-finger
hand whose distal joints were passive, 2 of the 4 best box grasps dropped in
Drake and all 4 held with those joints welded, without a word from the plan.
"""

from __future__ import annotations

import warnings

import pytest
from coupled_hands import spread_hand_urdf

from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.planning.approach import multi_finger_hand
from drakegrasp.planning.multifinger import PassiveJointWarning
from drakegrasp.plant.fingers import passive_joints
from drakegrasp.plant.validation import hand_bodies

CYLINDER = "package://drakegrasp/objects/cylinder.sdf"
MIMIC = '<mimic joint="f1_proximal_joint" multiplier="0.5" offset="0"/>'
DISTAL = "spread_hand::f1_distal_joint"  # passive without the <mimic>


def _scene(tmp_path, passive: bool):
    text = spread_hand_urdf()
    assert text.count(MIMIC) == 1
    path = tmp_path / f"hand_{passive}.urdf"
    path.write_text(text.replace(MIMIC, "") if passive else text)
    return planning_scene(CYLINDER, hand_url=str(path))


def _plan(scene):
    return plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=10, mu=0.5, seed=0, robustness_samples=4,
    )  # fmt: skip


@pytest.mark.parametrize("passive", [False, True])
def test_passive_joints_are_the_hands_joints_no_motor_moves(tmp_path, passive):
    scene = _scene(tmp_path, passive)
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    hand = multi_finger_hand(scene.plant, ctx, scene.object_body, scene.hand)
    bodies = hand_bodies(scene.plant, scene.object_body, scene.hand)
    found = passive_joints(scene.plant, bodies, hand.structure)
    assert [j.name() for j in found] == (["f1_distal_joint"] if passive else [])
    assert not set(found) & set(hand.structure.joints)


def test_planning_a_hand_with_a_passive_joint_names_it(tmp_path):
    with pytest.warns(PassiveJointWarning, match=r"spread_hand::f1_distal_joint") as w:
        _plan(_scene(tmp_path, passive=True))
    # attributed to the user's line (here, _plan's call of plan_grasps)
    assert [r.filename for r in w if r.category is PassiveJointWarning] == [__file__]


def test_a_hand_whose_joints_all_move_with_motors_plans_without_it(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("error", PassiveJointWarning)
        _plan(_scene(tmp_path, passive=False))


def test_an_open_hand_that_collides_everywhere_is_told_to_open(tmp_path, capsys):
    # the spread hand curled shut (its flexion joints at their upper limits)
    # penetrates the cylinder at every sampled pose
    from drakegrasp.cli import main
    from drakegrasp.planning.planner import OPEN_HAND_HINT

    shut = [f"f{k}_proximal_joint" for k in (1, 2, 3)]
    scene = _scene(tmp_path, passive=False)
    ctx = scene.plant.GetMyMutableContextFromRoot(scene.context)
    for name in shut:
        scene.plant.GetJointByName(name).set_angle(ctx, 2.0)
    result = _plan(scene)
    assert len(result) == 0
    assert set(result.rejections) == {"hand collides with the object"}
    assert result.reason.endswith(OPEN_HAND_HINT)
    argv = ["plan", "cylinder", "--hand", str(tmp_path / "hand_False.urdf")]
    argv += ["--num", "10", *(f"--preshape={name}=2.0" for name in shut)]
    assert main(argv) == 0
    said = capsys.readouterr().out
    assert "open it (--preshape open, or --preshape JOINT=VALUE)" in said
    # the flag the words name is taken (what it opens: test_open_preshape.py)
    assert main([*argv, "--preshape", "open"]) == 0


def test_a_joint_without_a_motor_that_others_follow_is_passive_with_them(tmp_path):
    # f1's flexion loses its transmission: it and the distal joint that
    # follows it (<mimic> 0.5) are moved by no motor
    text = spread_hand_urdf()
    motor = '<transmission name="t_f1_proximal_joint">'
    start = text.index(motor)
    end = text.index("</transmission>", start) + len("</transmission>")
    path = tmp_path / "hand.urdf"
    path.write_text(text[:start] + text[end:])
    scene = planning_scene(CYLINDER, hand_url=str(path))
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    hand = multi_finger_hand(scene.plant, ctx, scene.object_body, scene.hand)
    bodies = hand_bodies(scene.plant, scene.object_body, scene.hand)
    found = passive_joints(scene.plant, bodies, hand.structure)
    assert [j.name() for j in found] == ["f1_proximal_joint", "f1_distal_joint"]
    with pytest.warns(PassiveJointWarning, match="f1_proximal_joint"):
        _plan(scene)


@pytest.fixture(scope="module")
def bent_plan(tmp_path_factory):
    """A plan of the hand whose f1 distal joint is passive, bent to 0.3 rad."""
    scene = _scene(tmp_path_factory.mktemp("bent"), passive=True)
    ctx = scene.plant.GetMyMutableContextFromRoot(scene.context)
    scene.plant.GetJointByName("f1_distal_joint").set_angle(ctx, 0.3)
    with pytest.warns(PassiveJointWarning):
        result = plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=60, mu=0.5, seed=0, robustness_samples=4,
        )  # fmt: skip
    return scene, result


@pytest.fixture(scope="module")
def bent(bent_plan):
    """The best force-closure candidate of that plan."""
    scene, result = bent_plan
    closure = [c for c in result if c.is_closure]
    assert closure
    return scene, closure[0]


def test_a_candidate_records_the_joints_the_plan_held(bent):
    scene, candidate = bent
    held = dict(candidate.held_joints)
    assert held == {"spread_hand::f1_distal_joint": 0.3}
    assert not set(held) & set(candidate.joint_names)
    assert candidate.to_dict()["held_joints"] == held
    # a fresh context of the same models starts the joint at its default, 0
    ctx = scene.plant.CreateDefaultContext()
    candidate.apply(scene.plant, ctx)
    assert scene.plant.GetJointByName("f1_distal_joint").get_angle(ctx) == 0.3


COLUMNS = [
    "rank_in_result", "sample", "score", "weight_capacity", "squeeze_needed",
    "torque_needed", "torque_capacity", "torque_unit", "num_motors",
    "torque_limit", "squeeze_push", "epsilon", "robustness",
    "is_closure", "d_star", "num_contacts", "opening", "p_WH", "R_WH", "q_hand",
]  # fmt: skip
"""``GraspCandidates.table()``'s columns for candidates that held no joint."""


HELD = "held_joints:"  # a held joint's column: HELD + "model::joint"


def _held_columns(table) -> dict:
    """The held-joint columns of a table, by joint name."""
    return {
        name.removeprefix(HELD): values
        for name, values in table.items()
        if name.startswith(HELD)
    }


def test_the_table_has_a_column_for_each_held_joint(bent_plan):
    # to_dict() had held_joints, table() (plan --out) did not: a file of the
    # plan lost where the passive joint was held
    import dataclasses

    import numpy as np

    _, result = bent_plan
    table = result.table()
    held = _held_columns(table)
    assert list(table) == [*COLUMNS, HELD + DISTAL]
    for k, candidate in enumerate(result):
        row = {name: values[k] for name, values in held.items()}
        assert row == dict(candidate.held_joints) == {DISTAL: 0.3}
    from drakegrasp.planning.candidates import HELD_JOINT_COLUMN

    assert HELD_JOINT_COLUMN == HELD
    # a joint one candidate held and another did not: NaN in the other's row
    first, second = result[0], result[1]
    mixed = dataclasses.replace(
        result,
        candidates=(
            dataclasses.replace(first, held_joints=(("spread_hand::a", 0.5),)),
            dataclasses.replace(second, held_joints=(("spread_hand::b", -0.25),)),
        ),
    )
    held = _held_columns(mixed.table())
    assert list(held) == ["spread_hand::a", "spread_hand::b"]
    assert held["spread_hand::a"].tolist()[0] == 0.5
    assert held["spread_hand::b"].tolist()[1] == -0.25
    assert np.isnan(held["spread_hand::a"][1]) and np.isnan(held["spread_hand::b"][0])
    # none held: the table of before, no held-joint column
    none = dataclasses.replace(
        result,
        candidates=tuple(dataclasses.replace(c, held_joints=()) for c in result),
    )
    assert list(none.table()) == COLUMNS


def _same_schema(empty: dict, full: dict) -> None:
    """``empty`` has ``full``'s columns, in its order, dtypes and widths, no rows."""
    assert list(empty) == list(full)
    for name, column in full.items():
        assert empty[name].dtype == column.dtype, name
        assert empty[name].shape == (0, *column.shape[1:]), name


def test_an_empty_result_has_the_held_joint_columns_of_a_full_one(bent_plan, tmp_path):
    # an empty result had no held-joint column, a full one of the same hand
    # one per held joint: a file of each did not share a schema
    scene, result = bent_plan
    with pytest.warns(PassiveJointWarning):
        empty = plan_grasps(
            scene.plant, scene.context, scene.object_body, hand=scene.hand,
            num_candidates=0, mu=0.5, seed=0, robustness_samples=4,
        )  # fmt: skip
    assert len(empty) == 0
    _same_schema(empty.table(), result.table())
    assert HELD + DISTAL in empty.table()
    # the jaw's route too: the dial beside it is held
    jaw = _dial_jaw(tmp_path, "")

    def plan(n):
        return plan_grasps(
            jaw.plant, jaw.context, jaw.object_body, hand=jaw.hand,
            num_candidates=n, mu=0.5, seed=0, robustness_samples=4,
        )  # fmt: skip

    full = plan(20).table()
    assert HELD + "coupled_jaw::dial_joint" in full
    _same_schema(plan(0).table(), full)


def test_a_held_joint_value_that_is_no_number_is_named(bent_plan):
    # an edited candidate's held value reached numpy: a raw ValueError, "could
    # not convert string to float", naming neither candidate nor joint
    import dataclasses

    from drakegrasp.errors import InvalidGraspError

    _, result = bent_plan
    for bad in ("0.3x", None, True, [0.3]):
        edited = dataclasses.replace(
            result,
            candidates=(
                result[0],
                dataclasses.replace(result[1], held_joints=((DISTAL, bad),)),
            ),
        )
        with pytest.raises(InvalidGraspError) as info:
            edited.table()
        assert f"candidate 1's held joint {DISTAL!r}" in str(info.value)
        assert repr(bad) in str(info.value)
    for bad in (5, ((DISTAL,),), (("x", 1.0, 2.0),), ((3, 1.0),)):  # not pairs
        edited = dataclasses.replace(
            result, candidates=(dataclasses.replace(result[0], held_joints=bad),)
        )
        with pytest.raises(InvalidGraspError, match="candidate 0's held_joints"):
            edited.table()


def test_the_table_has_each_candidates_torque_unit(bent_plan):
    # GraspCandidate.torque_unit had no column: a file of a sliding hand's
    # plan gave torque_needed without saying it was in newtons
    import dataclasses

    _, result = bent_plan
    sliding = dataclasses.replace(result[1], torque_unit="N")
    edited = dataclasses.replace(result, candidates=(result[0], sliding, *result[2:]))
    table = edited.table()
    names = list(table)
    assert names.index("torque_unit") == names.index("torque_capacity") + 1
    assert table["torque_unit"].dtype == object
    expected = [c.torque_unit for c in edited]
    assert table["torque_unit"].tolist() == expected
    assert expected[:2] == ["N·m", "N"]


def test_plan_out_writes_the_held_joints(tmp_path, capsys):
    # the file has a column per held joint, named with the joint: a reader
    # gets back each candidate's held_joints
    pq = pytest.importorskip("pyarrow.parquet")
    from drakegrasp.cli import main

    _scene(tmp_path, passive=True)  # writes the hand's file
    out = tmp_path / "plan.parquet"
    argv = ["plan", "cylinder", "--hand", str(tmp_path / "hand_True.urdf")]
    argv += ["--num", "20", "--preshape", "f1_distal_joint=0.3", "--out", str(out)]
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert DISTAL in captured.err  # the passive joint's warning
    n = int(captured.out.split()[1])
    assert n > 0
    held = _held_columns(pq.read_table(out).to_pydict())
    assert held == {DISTAL: [0.3] * n}


def test_a_shake_starts_from_the_hand_that_was_planned(bent):
    # the shake's own plant put the joint at its default (0): the finger that
    # touched stood 4.07 mm off the cylinder and the shake was refused
    from drakegrasp.planning import shake_test
    from drakegrasp.planning.shake import FrictionMismatchWarning

    scene, candidate = bent
    fingers = {c.finger_body for c in candidate.contacts}
    assert "spread_hand::f1_distal" in fingers
    with pytest.warns(FrictionMismatchWarning):  # the plan's mu 0.5, Drake's 1
        result = shake_test(
            scene.add_models, candidate, squeeze=2.0, directions=[(0.0, 0.0, -1.0)]
        )
    assert len(result.seated_q_hand) == len(candidate.joint_names)  # it ran


def test_held_joints_are_checked_before_drake_sees_them(bent):
    import dataclasses
    import pickle

    from drakegrasp.errors import InvalidGraspError, ModelError

    scene, candidate = bent
    ctx = scene.plant.CreateDefaultContext()
    for bad in (
        (("spread_hand::f1_distal_joint", float("nan")),),
        (("spread_hand::f1_distal_joint", 10**400),),  # an int beyond a double
        (("x", "1"),),
        (("x", True),),
        5,
        ((candidate.joint_names[0], 0.0),),  # q_hand's joint: closed or held
    ):
        edited = dataclasses.replace(candidate, held_joints=bad)
        with pytest.raises(InvalidGraspError, match="held_joints"):
            edited.apply(scene.plant, ctx)
    other = dataclasses.replace(candidate, held_joints=(("spread_hand::nope", 0.1),))
    with pytest.raises(ModelError, match="'spread_hand::nope' is not a one-dof"):
        other.apply(scene.plant, ctx)
    dataclasses.replace(other, held_joints=()).apply(scene.plant, ctx)  # the remedy
    # a candidate pickled before the field existed reads as holding none
    state = pickle.loads(pickle.dumps(candidate)).__dict__
    state.pop("held_joints")
    old = object.__new__(type(candidate))
    old.__dict__.update(state)
    assert old.held_joints == ()


DIAL = (
    '<link name="dial"><inertial><mass value="0.01"/><inertia ixx="1e-6" '
    'iyy="1e-6" izz="1e-6" ixy="0" ixz="0" iyz="0"/></inertial></link>'
    '<joint name="dial_joint" type="revolute"><parent link="palm"/><child '
    'link="dial"/><origin xyz="0 0 -0.05"/><axis xyz="0 0 1"/><limit lower="-3" '
    'upper="3" effort="1" velocity="1"/>{mimic}</joint>'
)


def _dial_jaw(tmp_path, mimic: str):
    from coupled_hands import coupled_jaw_urdf

    path = tmp_path / "jaw.urdf"
    path.write_text(
        coupled_jaw_urdf().replace("</robot>", DIAL.format(mimic=mimic) + "</robot>")
    )
    return planning_scene("package://drakegrasp/objects/box.sdf", hand_url=str(path))


def test_a_free_joint_beside_a_jaw_is_held(tmp_path):
    # a dial without collision geometry, no motor and no mimic: the jaw's
    # planner leaves it where it was, and the candidates say so
    scene = _dial_jaw(tmp_path, "")
    ctx = scene.plant.GetMyMutableContextFromRoot(scene.context)
    scene.plant.GetJointByName("dial_joint").set_angle(ctx, 1.25)
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=20, mu=0.5, seed=0, robustness_samples=4,
    )  # fmt: skip
    assert len(result) > 0
    for candidate in result:
        assert candidate.joint_names == (
            "coupled_jaw::left_slide", "coupled_jaw::right_slide"
        )  # fmt: skip
        assert candidate.held_joints == (("coupled_jaw::dial_joint", 1.25),)


def test_joints_a_coupling_ties_to_the_closing_ones_move_with_them(tmp_path):
    # a dial turned by the leader's slide moves as the hand closes: its value
    # at the plan's start is not the closed hand's, so it is never held
    from drakegrasp.planning.planner import _coupling_links, _linked

    mimic = '<mimic joint="left_slide" multiplier="10" offset="0"/>'
    plant = _dial_jaw(tmp_path, mimic).plant
    links = _coupling_links(plant)
    tied = {"coupled_jaw::left_slide", "coupled_jaw::right_slide"}
    assert _linked({"coupled_jaw::right_slide"}, links) == tied | {
        "coupled_jaw::dial_joint"
    }
    assert _linked({"coupled_jaw::other"}, links) == {"coupled_jaw::other"}
    free = _dial_jaw(tmp_path, "").plant
    assert _linked({"coupled_jaw::left_slide"}, _coupling_links(free)) == tied


def test_a_jaws_rows_carry_the_unit_of_its_sliding_joints():
    # a jaw's candidates kept the default "N·m" though its joints slide: the
    # table's torque_unit column said N·m on every jaw row
    scene = planning_scene(
        "package://drakegrasp/objects/box.sdf",
        hand_url="package://drakegrasp/hands/parallel_jaw.sdf",
    )
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=10, mu=0.5, seed=0,
    )  # fmt: skip
    assert len(result) > 0
    assert set(result.table()["torque_unit"].tolist()) == {"N"}


def test_a_hand_that_collides_nearly_everywhere_is_told_to_open_too():
    # A hand shut at its pre-shape also misses the object from a few poses
    # (an SDH-like hand: 94 collided, 6 missed of 100): the hint needed all
    # 100 to collide, and said nothing.
    from drakegrasp.planning.planner import _opens_too_little

    collides = "hand collides with the object"
    misses = "fingers miss the object"
    assert _opens_too_little({collides: 94, misses: 6}, 100)
    assert _opens_too_little({"hand collides with the cloud": 90}, 100)
    assert not _opens_too_little({collides: 89, misses: 11}, 100)
    assert not _opens_too_little({}, 0)
