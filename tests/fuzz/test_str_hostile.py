"""Words and names given as ``str`` subclasses that raise or lie, or as no str.

A choice (``kind="force"``, ``plane="xy"``, ``mu="plant"``), a joint, body or
model-instance name and a hand's pre-shape word are compared, hashed and cut
in Python.  A ``str`` subclass passes ``isinstance(x, str)`` while its own
``==``, ``__hash__``, ``strip``, ``rpartition`` or ``encode`` raise or lie;
an object whose ``__class__`` claims ``str`` passes it too, and ``str``'s
own methods then raise a bare TypeError.  Each reader reads the value once
as the plain ``str`` it holds (``str.__str__``), or refuses it by name:

- a subclass holding a valid word answers as the plain word does (its lies
  change nothing: ``StrLies("inside")``, equal to everything, was taken for
  ``"outside"`` by ``side == "outside"``);
- one holding no valid word, and the pretender, are a GraspError naming the
  parameter, in a short message.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

import drakegrasp as dg
from drakegrasp.batch.api import batch_force_closure, iter_batch_closure
from drakegrasp.batch.files.writer import format_of
from drakegrasp.batch.inputs import resolve_kernel
from drakegrasp.certificates.kinds import check_kind_and_cones
from drakegrasp.closure.programs import build_force_closure_program, check_formulation
from drakegrasp.planning import planning_scene
from drakegrasp.planning.approach import OPEN
from drakegrasp.planning.candidates import GraspCandidate
from drakegrasp.plant.couplings import (
    add_coupler_constraint,
    plant_couplings,
    recorded_couplings,
)
from drakegrasp.plant.fingers import find_joint
from drakegrasp.plant.validation import (
    hand_bodies,
    model_instance,
    resolve_body,
    scoped_name,
)
from drakegrasp.visualization.geometry import side_sign

sys.path.insert(0, str(Path(__file__).resolve().parent))
import hostile  # noqa: E402
from quiet_plans import plan_quietly  # noqa: E402

SHORT = 2_000
"""Characters a refusal's message may take, whatever the value."""

KINDS = [type(v).__name__ for v in hostile.str_hostile("x")]


def _grasp():
    return dg.core.examples.equator_fingers(0.5)


class _Meshcat:
    """Takes every Meshcat call and does nothing (no server, no port)."""

    def __getattr__(self, name):
        return lambda *args, **kwargs: None


def _batch_kernel(kernel):
    g = _grasp()
    return batch_force_closure(
        g.positions[None], g.normals[None], mu=0.5, kernel=kernel
    ).is_closure.tolist()


def _batch_kind(kind):
    g = _grasp()
    chunk = (g.positions[None], g.normals[None])
    return next(iter_batch_closure([chunk], kind=kind)).is_closure.tolist()


# (parameter, call, a valid word, another valid word): call(word) is a plain
# value to compare; the two words answer differently, so a lie would show.
WORDS = [
    ("side", side_sign, "inside", "outside"),
    ("plane", lambda v: dg.AnalysisOptions(plane=v).plane, "xy", "yz"),
    ("patches", lambda v: dg.AnalysisOptions(patches=v).patches, "witness", None),
    ("mu", lambda v: dg.AnalysisOptions(mu=v).mu, "plant", None),
    ("load", lambda v: dg.AnalysisOptions(load=v).load, "gravity", None),
    ("kernel", lambda v: dg.BatchOptions(kernel=v).kernel, "numpy", "auto"),
    ("metric", lambda v: dg.BatchOptions(metrics=[v]).metrics, "isotropy", None),
    ("format", lambda v: format_of("out", v), "parquet", "npz"),
    ("norm", lambda v: dg.ferrari_canny(_grasp(), norm=v), "Linf", "L1"),
    ("kind", _batch_kind, "form", None),  # "force" takes mu, "form" refuses it
    ("formulation", check_formulation, "generators", "facets"),
    # the callers of the checks above: each must use what its check returns
    (
        "formulation",
        lambda v: dg.force_closure(_grasp(), formulation=v).formulation,
        "generators",
        "facets",
    ),
    (
        "formulation",
        lambda v: build_force_closure_program(_grasp(), formulation=v)[0].num_vars(),
        "generators",
        "facets",
    ),
    ("kernel", resolve_kernel, "numpy", "auto"),
    ("kernel", _batch_kernel, "numpy", None),
    (
        "kind",
        lambda v: check_kind_and_cones(v, "exact", ("force", "form"), ("exact",)),
        "form",
        "force",
    ),
    (
        "cone",
        lambda v: dg.visualization.draw_grasp(_Meshcat(), _grasp(), cone=v).paths,
        "pyramid",
        "exact",
    ),
]
WORD_IDS = [f"{name}-{i}" for i, (name, *_) in enumerate(WORDS)]


@pytest.mark.parametrize(("name", "call", "word", "other"), WORDS, ids=WORD_IDS)
def test_a_word_of_a_hostile_str_subclass_answers_as_the_plain_word(
    name, call, word, other
):
    plain = call(word)
    if other is not None:
        assert call(other) != plain  # the two words tell the answers apart
    for kind, value in zip(KINDS, hostile.str_hostile(word), strict=True):
        if kind == "ClaimsStr":
            continue  # holds no word: refused below
        answer = call(value)
        assert answer == plain, kind
        assert type(answer) is type(plain), kind  # a plain str, never the subclass


@pytest.mark.parametrize(("name", "call", "word", "other"), WORDS, ids=WORD_IDS)
def test_a_hostile_str_that_holds_no_word_is_refused_by_name(name, call, word, other):
    values = [*hostile.str_hostile("nope"), "\ud800", "a\0b", "x" * hostile.HUGE]
    for value in values:
        with pytest.raises(dg.GraspError, match=name) as refused:
            call(value)
        assert len(str(refused.value)) <= SHORT, type(value).__name__


# -------------------------------------------------- joint, body, instance names

HAND = "angular_gripper"
LEFT, RIGHT = f"{HAND}::left_hinge", f"{HAND}::right_hinge"
NO_NAMES = ["\ud800", "a\0b", "x" * hostile.HUGE, "\ud800::x", f"{HAND}::\udcff"]
NOT_STR = [b"left_hinge", 3, None, 1.5, hostile.ClaimsStr(), ["left_hinge"]]


@pytest.fixture(scope="module")
def gripper(tmp_path_factory):
    from coupled_hands import angular_gripper_urdf

    path = tmp_path_factory.mktemp("angular") / "angular_gripper.urdf"
    path.write_text(angular_gripper_urdf())
    return path


@pytest.fixture(scope="module")
def scene(gripper):
    return planning_scene("package://drakegrasp/objects/cylinder.sdf", hand_url=gripper)


def _refused_briefly(call, value, error=dg.GraspError):
    with pytest.raises(error) as refused:
        call(value)
    assert len(str(refused.value)) <= SHORT, type(value).__name__


def test_a_joint_name_of_a_hostile_str_subclass_names_the_same_joint(scene):
    plant = scene.plant
    for name in (LEFT, "left_hinge"):
        joint = find_joint(plant, name)
        for value in hostile.str_hostile(name)[:-1]:  # but the pretender
            assert find_joint(plant, value).index() == joint.index()


def test_a_joint_name_that_names_no_joint_is_refused(scene):
    plant = scene.plant
    for value in [*hostile.str_hostile("nope"), *NO_NAMES, *NOT_STR]:
        _refused_briefly(lambda v: find_joint(plant, v), value, dg.InvalidOptionError)


def test_hostile_coupling_names_are_refused_or_read_as_the_names_they_hold(
    scene, gripper
):
    plant = scene.plant
    calls = {
        "plant_couplings(follower)": lambda v: plant_couplings(
            plant, [(v, LEFT, 1.0, 0.0), (LEFT, "x", 1.0, 0.0)]
        ),
        "plant_couplings(leader)": lambda v: plant_couplings(
            plant, [(RIGHT, v, 1.0, 0.0), ("x", RIGHT, 1.0, 0.0)]
        ),
        "analyze_grasp(couplings)": lambda v: dg.analyze_grasp(
            plant,
            scene.context,
            object_body=scene.object_body,
            hand=scene.hand,
            mu=0.5,
            couplings=[(v, LEFT, 1.0, 0.0)],
            check_pose=False,
        ),  # fmt: skip
    }

    def coupler(v):
        fresh = MultibodyPlant(0.0)
        Parser(fresh).AddModels(str(gripper))
        return add_coupler_constraint(fresh, v, LEFT, 1.0)

    calls["add_coupler_constraint"] = coupler
    for name, call in calls.items():
        for value in [*hostile.str_hostile("nope"), *NO_NAMES, *NOT_STR]:
            try:
                call(value)
            except dg.GraspError as error:
                assert len(str(error)) <= SHORT, (name, type(value).__name__)
            except Exception as error:  # noqa: BLE001 - named, then failed
                pytest.fail(f"{name}({type(value).__name__}): {error!r}"[:300])
    # a hostile subclass of the right name couples the same joints
    fresh = MultibodyPlant(0.0)
    Parser(fresh).AddModels(str(gripper))
    add_coupler_constraint(fresh, hostile.StrEqRaises(RIGHT), LEFT, -1.0)
    assert recorded_couplings(fresh) == ((RIGHT, LEFT, -1.0, 0.0),)
    assert all(type(n) is str for n in recorded_couplings(fresh)[0][:2])


def test_hostile_body_and_instance_names_are_refused_or_read_plainly(scene):
    plant, obj = scene.plant, scene.object_body
    body = scoped_name(plant, obj)
    for value in hostile.str_hostile(body)[:-1]:
        assert resolve_body(plant, value).index() == obj.index()
    for value in hostile.str_hostile(HAND)[:-1]:
        assert model_instance(plant, value) == scene.hand
        assert [b.index() for b in hand_bodies(plant, obj, value)] == [
            b.index() for b in hand_bodies(plant, obj, HAND)
        ]
    for value in [*hostile.str_hostile("nope"), *NO_NAMES, *NOT_STR]:
        _refused_briefly(lambda v: resolve_body(plant, v), value)
        _refused_briefly(lambda v: model_instance(plant, v), value)
        if value is not None:  # hand=None: every free body but the object
            _refused_briefly(lambda v: hand_bodies(plant, obj, v), value)


def _candidate(**change) -> GraspCandidate:
    fields = dict(
        sample=0, hand_base=f"{HAND}::base", X_WH=None, X_WO=None,
        q_hand=np.zeros(2), joint_names=(LEFT, RIGHT), closing_signs=(1.0, 1.0),
        opening=0.0, contacts=(), reference_point=np.zeros(3),
        contact_options={}, is_closure=False, d_star=0.0, rank=0, epsilon=0.0,
        robustness=0.0, score=0.0,
    )  # fmt: skip
    fields.update(change)
    return GraspCandidate(**fields)


def test_a_candidates_joint_names_are_plain_strs_or_refused():
    names = tuple(hostile.str_hostile(LEFT)[:-1])
    candidate = _candidate(joint_names=names, motors=names[:1], held_joints=())
    assert all(type(n) is str and n == LEFT for n in candidate.joint_names)
    assert candidate.motors == (LEFT,) and type(candidate.motors[0]) is str
    held = _candidate(held_joints=((hostile.StrHashRaises("x::y"), 0.1),))
    assert type(held.held_joints[0][0]) is str
    for value in [*hostile.str_hostile(LEFT), hostile.ClaimsStr(), b"x", None]:
        if type(value) is not hostile.ClaimsStr and isinstance(value, str):
            with pytest.raises(dg.InvalidGraspError, match="name a joint twice"):
                _candidate(motors=(value, LEFT))
        else:
            with pytest.raises(dg.InvalidGraspError, match="motors must be"):
                _candidate(motors=(value,))


# ---------------------------------------------- a hand's pre-shape and synergy

PLAN = dict(num_candidates=4, mu=0.5, seed=0, robustness_samples=2)


def _plan(scene, **options):
    return plan_quietly(scene, **{**PLAN, **options})


@pytest.mark.parametrize("option", ["preshape", "synergy"])
def test_a_hostile_preshape_or_synergy_word_is_refused_by_name(scene, option):
    # A lone surrogate was refused when probed by hand, not fuzzed; a str
    # subclass's == raised, or (StrLies) took any word for "open"/"curl".
    word = OPEN if option == "preshape" else "curl"
    values = [
        *hostile.str_hostile(word + "ed"), "\ud800", "a\0b", "x" * hostile.HUGE,
        "\ud800" * 3, b"open", hostile.ClaimsStr(),
    ]  # fmt: skip
    for value in values:
        with pytest.raises(dg.InvalidOptionError, match=f"^{option} ") as refused:
            _plan(scene, **{option: value})
        assert len(str(refused.value)) <= SHORT, type(value).__name__


def test_a_preshape_word_of_a_hostile_subclass_plans_as_the_plain_word(scene):
    plain = _plan(scene, preshape=OPEN, synergy="curl")
    for preshape, synergy in zip(
        hostile.str_hostile(OPEN)[:-1], hostile.str_hostile("curl")[:-1], strict=True
    ):
        plan = _plan(scene, preshape=preshape, synergy=synergy)
        assert plan.settings["hand"] == plain.settings["hand"], type(preshape)
        assert [c.score for c in plan] == [c.score for c in plain]
