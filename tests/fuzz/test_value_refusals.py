"""Values of the wrong kind that reached a function's work as a bare TypeError.

Each call fits its signature (so ``checked_call`` rightly passes it on); the
value itself is wrong, and must be refused with a GraspError naming it.
``python tests/fuzz/report_public.py`` calls every public callable with such
values for a while and lists what still escapes as a raw exception; the cases
it found are here.
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest

import drakegrasp as dg
import drakegrasp.core.examples as examples
import drakegrasp.plant as dp
from drakegrasp.planning import scene_from_models

BOX = "package://drake_models/ycb/003_cracker_box.sdf"
HOSTILE = [None, "1", -1.0, float("nan"), 1e400, [1, 2], 0.0, 1j, True, 10**9]


def _example_calls():
    for name in examples.__all__:
        signature = inspect.signature(getattr(examples, name))
        for parameter in signature.parameters:
            for value in HOSTILE:
                yield name, parameter, value


@pytest.mark.parametrize(("name", "parameter", "value"), list(_example_calls()))
def test_the_example_grasps_refuse_or_answer(name, parameter, value):
    function = getattr(examples, name)
    keywords = {
        p.name: (0.5 if p.name == "mu" else p.default)
        for p in inspect.signature(function).parameters.values()
        if p.default is not p.empty or p.name == "mu"
    }
    keywords[parameter] = value
    try:
        grasp = function(**keywords)
    except dg.GraspError as error:
        assert parameter in str(error) or "mu" in str(error), str(error)
    else:  # accepted: a grasp of the value given
        assert isinstance(grasp, dg.Grasp)


def test_a_billion_fingers_are_refused_not_built():
    with pytest.raises(dg.InvalidGraspError, match=r"num_fingers .* \[1, 10000\]"):
        examples.equator_fingers(0.5, num_fingers=10**9)
    # an integral float counts, as for num_generators
    assert len(examples.equator_fingers(0.5, num_fingers=4.0).contacts) == 4


@pytest.mark.parametrize("half_width", [0.0, -1.0])
def test_an_example_of_no_size_or_turned_inside_out_is_refused(half_width):
    # -1 put every contact on the far face with its normal pointing out
    with pytest.raises(
        dg.InvalidGraspError, match="half_width must be a finite length"
    ):
        examples.cube_seven_contacts(half_width)


@pytest.mark.parametrize("plant", [None, [], "plant"])
def test_plant_functions_refuse_what_is_not_a_plant(plant):
    with pytest.raises(dg.ModelError, match="plant must be a pydrake MultibodyPlant"):
        dp.plant_couplings(plant)
    with pytest.raises(dg.ModelError, match="plant must be a pydrake MultibodyPlant"):
        dp.hand_bodies(plant, None)


def test_hand_bodies_refuses_what_is_not_a_body():
    from pydrake.multibody.plant import MultibodyPlant

    plant = MultibodyPlant(0.0)
    plant.Finalize()
    with pytest.raises(dg.InvalidOptionError, match="object_body must be"):
        dp.hand_bodies(plant, [])


@pytest.mark.parametrize(
    ("recipe", "message"),
    [
        (None, "add_models must be a function"),
        (lambda plant, parser: None, "must return .hand model instance"),
        (lambda plant, parser: (None, 3), "scoped name 'model::body'"),
        (lambda plant, parser: (None, "nothing::here"), "no body named"),
    ],
)
def test_a_scene_recipe_that_returns_the_wrong_thing_is_named(recipe, message):
    with pytest.raises(dg.GraspError, match=message):
        scene_from_models(recipe)


def test_a_scene_recipe_may_return_a_list_as_the_shake_reads_it(drake_models_dir):
    from drakegrasp.planning import planning_scene

    built = planning_scene(BOX, models_dir=drake_models_dir)
    as_list = scene_from_models(
        lambda plant, parser: list(built.add_models(plant, parser))
    )
    assert as_list.object_body.name() == built.object_body.name()


def test_hand_helpers_take_a_body_name_and_the_diagrams_context(drake_models_dir):
    # hand_bodies resolves the object body; the helpers that call it must use
    # that body too, and read the plant's context inside the diagram's.
    import json

    from drakegrasp.planning import multi_finger_hand, parallel_jaw
    from drakegrasp.planning.multifinger import hand_is_parallel_jaw

    scene = dg.planning_scene(BOX, models_dir=drake_models_dir)
    name = "003_cracker_box::base_link_cracker"
    plant_context = scene.plant.GetMyContextFromRoot(scene.context)
    assert hand_is_parallel_jaw(scene.plant, scene.context, name, scene.hand)
    by_name = parallel_jaw(scene.plant, scene.context, name, scene.hand).to_dict()
    by_body = parallel_jaw(
        scene.plant, plant_context, scene.object_body, scene.hand
    ).to_dict()
    same = json.dumps(by_name, sort_keys=True, default=str)
    assert same == json.dumps(by_body, sort_keys=True, default=str)
    assert multi_finger_hand(scene.plant, scene.context, name, scene.hand)


ARRAYS = [np.array([1, 2, 3], dtype=object), np.zeros((0, 3)), np.array(["a", "b"])]


@pytest.mark.parametrize("value", ARRAYS, ids=["objects", "empty", "strings"])
def test_a_choice_given_as_an_array_is_refused_by_name(value):
    # `value not in ("auto", ...)` compared an array element by element and
    # numpy refused to call the answer true or false (a bare ValueError).
    import drakegrasp.batch as db
    from drakegrasp.batch.files.writer import format_of

    P = np.zeros((2, 3, 3))
    N = np.tile([0.0, 0.0, 1.0], (2, 3, 1))
    calls = {
        "kernel": lambda: dg.BatchOptions(kernel=value),
        "unknown metric": lambda: dg.BatchOptions(
            metrics=np.ones((2, 2)) + 0 * value.size
        ),
        "kind": lambda: next(db.iter_batch_closure([(P, N)], kind=value)),
        "format": lambda: format_of("out.npz", value),  # stream_file's --format
    }
    for name, call in calls.items():
        with pytest.raises(dg.GraspError, match=name):
            call()


@pytest.mark.parametrize("value", [[[1, 2], [3]], [8], np.array([1.0, 1.0, 1.0])])
def test_an_unhashable_option_is_judged_not_memoised(value):
    # The per-grasp memo keyed its results on the options, and a list is not
    # a key: a bare TypeError ('unhashable type') before the option's check.
    grasp = dg.examples.spatial_two_fingers(0.5)
    planar = dg.examples.planar_two_finger_square(0.6)
    for call in (
        lambda: dg.force_closure(grasp, num_generators=value),
        lambda: dg.grasp_quality(planar, num_generators=value),
    ):
        with pytest.raises(dg.InvalidOptionError, match="num_generators must be"):
            call()


def _planar():
    return dg.examples.planar_two_finger_square(0.5)


def _spatial():
    return dg.examples.spatial_two_fingers(0.5)


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda v: v.contact_pose_3d(b"x"), dg.InvalidContactError, "contact must"),
        (
            lambda v: v.cone_edge_directions(_planar()),
            dg.InvalidContactError,
            "contact must be a drakegrasp.Contact, got Grasp",
        ),
        (
            lambda v: v.normalize_contact_forces(3, [1.0]),
            dg.InvalidGraspError,
            "grasp must",
        ),
        (
            lambda v: v.contact_forces_in_grasp_frame("x", [1.0]),
            dg.InvalidGraspError,
            "grasp must",
        ),
        (
            lambda v: v.contact_forces_in_grasp_frame(_spatial(), object()),
            dg.InvalidOptionError,
            "forces must be",
        ),
        (
            lambda v: v.contact_forces_in_grasp_frame(_spatial(), np.zeros((0, 3))),
            dg.InvalidOptionError,
            "forces must be",
        ),
        (
            lambda v: v.contact_forces_in_grasp_frame(_spatial(), np.zeros((2, 0))),
            dg.InvalidOptionError,
            "contact 0 .* has 3 force components",
        ),
        (
            lambda v: v.wrench_space_points([1]),
            dg.InvalidGraspError,
            "grasp must",
        ),
        (
            lambda v: v.wrench_space_points(_planar(), scale_moments=np.ones(3)),
            dg.InvalidOptionError,
            "scale_moments must be True or False",
        ),
        (
            lambda v: v.plot_planar_grasp(_planar(), outline=[1, "a"]),
            dg.InvalidOptionError,
            "outline must be an array of real numbers",
        ),
        (
            lambda v: v.plot_planar_grasp(
                _planar(), outline={"center": "ab", "radius": 1}
            ),
            dg.InvalidOptionError,
            "circle center must be",
        ),
        (
            lambda v: v.plot_planar_grasp(_planar(), show_labels=np.zeros(3)),
            dg.InvalidOptionError,
            "show_labels must be True or False",
        ),
    ],
)
def test_a_drawing_helper_names_a_value_of_the_wrong_kind(call, error, message):
    # Each reached an attribute, a zip or an `if` of an array: a bare
    # AttributeError, ValueError or IndexError instead of the value's name.
    import drakegrasp.visualization as v

    with pytest.raises(error, match=message):
        call(v)


def test_contact_forces_in_grasp_frame_takes_what_normalize_gives():
    import drakegrasp.visualization as v

    grasp = _spatial()
    forces = v.normalize_contact_forces(grasp, [[1.0], [1.0, 0.1, 0.0]])
    f_G = v.contact_forces_in_grasp_frame(grasp, forces)
    np.testing.assert_array_equal(f_G, [[1.0, 0.0, 0.0], [-1.0, 0.1, 0.0]])


RAGGED = [[1.0, 2.0], [3.0]]


@pytest.mark.parametrize(
    ("keywords", "error", "name"),
    [
        ({"mu": RAGGED}, dg.InvalidContactError, "mu"),
        (
            {"mu": 0.5, "torsional_friction": RAGGED},
            dg.InvalidContactError,
            "torsional",
        ),
        ({"mu": 0.5, "reference_points": RAGGED}, dg.InvalidGraspError, "reference"),
        ({"mu": 0.5, "characteristic_lengths": RAGGED}, dg.InvalidGraspError, "char"),
        ({"mu": 0.5, "normals": RAGGED}, dg.InvalidContactError, "normals"),
    ],
)
def test_a_ragged_nested_per_grasp_value_is_named(keywords, error, name):
    # np.shape of [[1, 2], [3]] raised numpy's bare "inhomogeneous shape".
    keywords = dict(keywords)
    P = np.zeros((2, 3, 3))
    N = keywords.pop("normals", np.tile([0.0, 0.0, 1.0], (2, 3, 1)))
    with pytest.raises(error, match=rf"^{name}.* must be .*uneven shape"):
        dg.batch_force_closure(P, N, **keywords)


@pytest.mark.parametrize(
    ("chunks", "message"),
    [
        (None, "chunks must be an iterable"),
        ([None], "chunk 0 must be a tuple"),
        ([(1, 2, 3, 4)], "chunk 0 must be a tuple .* length 4"),
    ],
)
def test_iter_batch_closure_names_a_chunk_of_the_wrong_kind(chunks, message):
    import drakegrasp.batch as db

    with pytest.raises(dg.InvalidOptionError, match=message):
        next(db.iter_batch_closure(chunks))


@pytest.mark.parametrize(
    ("change", "error", "message"),
    [
        ({"path": b"out.npz"}, dg.BatchFileError, "path must be a file path"),
        ({"path": 3.0}, dg.BatchFileError, "path must be a file path"),
        ({"path": "missing/out.npz"}, dg.BatchFileError, "cannot write"),
        ({"K": "x"}, dg.InvalidOptionError, "K must be an integer"),
        ({"kind": float("nan")}, dg.InvalidOptionError, "kind must be"),
        ({"tol": object()}, dg.InvalidOptionError, "tol must be a real number"),
        ({"required_rank": None}, dg.InvalidOptionError, "required_rank must be"),
        ({"chunks": None}, dg.InvalidOptionError, "chunks must be an iterable"),
        ({"chunks": [1]}, dg.InvalidOptionError, "each chunk must be a pair"),
        ({"K": 3}, dg.InvalidOptionError, "covered 0 of 3 grasps"),
    ],
)
def test_write_chunks_names_what_it_cannot_write(tmp_path, change, error, message):
    # Path(), tempfile and the loop over chunks raised bare TypeError,
    # FileNotFoundError, AttributeError and ValueError.
    from drakegrasp.batch import write_chunks

    arguments = {"chunks": [], "path": "out.npz", "K": 0, "kind": "form"}
    arguments.update({"tol": 1e-6, "required_rank": 6}, **change)
    arguments["path"] = (
        tmp_path / arguments["path"]
        if isinstance(arguments["path"], str)
        else arguments["path"]
    )
    with pytest.raises(error, match=message):
        write_chunks(arguments.pop("chunks"), arguments.pop("path"), **arguments)
    assert [p.name for p in tmp_path.iterdir()] == []  # nothing left behind


def test_batch_grasp_forces_names_hand_jacobians_that_are_no_sequence():
    from drakegrasp.batch import batch_grasp_forces

    grasp = _spatial()
    with pytest.raises(dg.InvalidOptionError, match="hand_jacobians must be"):
        batch_grasp_forces([grasp], np.zeros(6), hand_jacobians=float)


def test_build_internal_force_program_names_a_flag_that_is_an_array():
    grasp = _spatial()
    with pytest.raises(dg.InvalidOptionError, match="within_friction must be True"):
        dg.build_internal_force_program(
            grasp, np.ones((6, 2)), within_friction=np.zeros((0, 3))
        )


@pytest.mark.parametrize(
    ("recipe", "message"),
    [
        (float, "add_models must be a function"),
        (type, "add_models must be a function"),
        (lambda plant: None, r"must take two arguments.* takes \(plant\)"),
    ],
)
def test_a_scene_recipe_that_is_a_class_or_takes_other_arguments_is_named(
    recipe, message
):
    # float(plant, parser) raised the bare TypeError of the call.
    with pytest.raises(dg.InvalidOptionError, match=message):
        scene_from_models(recipe)


@pytest.fixture(scope="module")
def box_scene(drake_models_dir):
    """The cracker box, the Schunk gripper and what the plant helpers take."""
    from drakegrasp.planning import planning_scene
    from drakegrasp.plant.fingers import hand_structure
    from drakegrasp.plant.validation import hand_bodies, query_object_of

    scene = planning_scene(BOX, models_dir=drake_models_dir)
    plant, body = scene.plant, scene.object_body
    context = plant.GetMyContextFromRoot(scene.context)
    query = query_object_of(plant, context)
    hand = hand_structure(
        plant, body, hand_bodies(plant, body, scene.hand), inspector=query.inspector()
    )
    return plant, context, body, hand, query


def _settle(box, **change):
    from drakegrasp.plant.settle import settle_object

    plant, context, body, hand, _ = box
    arguments = {"plant": plant, "plant_context": context, "object_body": body}
    arguments.update(hand=hand, pushing=np.zeros(len(hand.joints)), bodies=[])
    arguments["distance_tolerance"] = 1e-4
    arguments.update(change)
    return settle_object(**arguments)


@pytest.mark.parametrize(
    ("change", "error", "message"),
    [
        ({"plant": {"a": 1}}, dg.ModelError, "plant must be a pydrake"),
        ({"object_body": 1.5}, dg.InvalidOptionError, "object_body must be"),
        ({"hand": 1e308}, dg.InvalidOptionError, "hand must be a HandStructure"),
        ({"pushing": b"x"}, dg.InvalidOptionError, "pushing must be an array"),
        ({"bodies": np.ones(3)}, dg.InvalidOptionError, r"bodies\[0\] must be"),
        ({"distance_tolerance": "x"}, dg.InvalidOptionError, "distance_tolerance"),
        ({"max_iterations": 0}, dg.InvalidOptionError, "max_iterations must be"),
    ],
)
def test_settle_object_names_an_argument_of_the_wrong_kind(
    box_scene, change, error, message
):
    # It called methods of whatever it got: a bare AttributeError.
    with pytest.raises(error, match=message):
        _settle(box_scene, **change)


def test_plant_helpers_name_a_hand_query_or_flag_of_the_wrong_kind(box_scene):
    from drakegrasp.plant.jaws import parallel_jaws

    plant, context, body, hand, query = box_scene
    with pytest.raises(dg.ModelError, match="plant must be a pydrake"):
        parallel_jaws(set(), context, hand, query)
    with pytest.raises(dg.InvalidOptionError, match="hand must be a HandStructure"):
        parallel_jaws(plant, context, np.ones(3), query)
    with pytest.raises(dg.InvalidOptionError, match="query_object must be"):
        parallel_jaws(plant, context, hand, None)
    assert parallel_jaws(plant, context, hand, query) is not None  # the Schunk's
    with pytest.raises(dg.InvalidOptionError, match="query_object must be"):
        dp.contact_curvatures(
            plant, context, [], object_body=body, query_object=np.zeros(3)
        )
    with pytest.raises(dg.InvalidOptionError, match="allow_penetration must be"):
        dp.find_contacts(
            plant, context, body, allow_penetration=np.ma.masked_array([1, 2, 3])
        )


def test_coupling_and_model_helpers_name_an_argument_of_the_wrong_kind(box_scene):
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    finalized = box_scene[0]
    with pytest.raises(dg.ModelError, match="plant must be a pydrake"):
        dp.add_coupler_constraint(0, None, None, 1.0)
    with pytest.raises(dg.ModelError, match="before plant.Finalize"):
        dp.add_coupler_constraint(finalized, None, None, 1.0)
    fresh = MultibodyPlant(0.0)
    with pytest.raises(dg.InvalidOptionError, match="coupling joint None is not"):
        dp.add_coupler_constraint(fresh, None, None, 1.0)
    with pytest.raises(dg.InvalidOptionError, match="parser must be a pydrake Parser"):
        dp.add_models(0, "hand.urdf")
    with pytest.raises(dg.InvalidOptionError, match="file_name must be a string"):
        dp.add_models(Parser(fresh), np.float16(2.0))
    with pytest.raises(dg.InvalidOptionError, match="url must be a string"):
        dp.add_models(Parser(fresh), url={"a": 1})


class _IterRaises:
    """Claims three items; iterating or indexing raises."""

    def __len__(self):
        return 3

    def __iter__(self):
        raise RuntimeError("a hostile __iter__")

    __getitem__ = __iter__


class _HashRaises:
    def __hash__(self):
        raise RuntimeError("a hostile __hash__")

    __eq__ = __hash__


def _hostile_sequence_calls():
    import drakegrasp.batch as db
    import drakegrasp.visualization as v

    grasp, planar = _spatial(), _planar()
    P, N = np.zeros((2, 3, 3)), np.tile([0.0, 0.0, 1.0], (2, 3, 1))
    return {
        "grasps": lambda x: db.batch_grasp_forces(x, np.zeros(6)),
        "forces": lambda x: v.contact_forces_in_grasp_frame(planar, x),
        "curvatures": lambda x: dg.second_order_form_closure(planar, curvatures=x),
        "metrics": lambda x: dg.batch_force_closure(P, N, mu=0.5, metrics=x),
        "positions": lambda x: dg.batch_force_closure(x, N, mu=0.5),
        "contacts": lambda x: dg.Grasp(x),
        "chunks": lambda x: next(db.iter_batch_closure(x)),
        "antipodal": lambda x: dg.is_antipodal(x),
        "num_generators": lambda x: dg.lp2_d_star(grasp, num_generators=x),
    }


@pytest.mark.parametrize("value", [_IterRaises(), np.array(True), _HashRaises()])
@pytest.mark.parametrize("name", sorted(_hostile_sequence_calls()))
def test_a_sequence_that_raises_or_is_0d_is_named(name, value):
    # list()/tuple()/np.shape of it, or the memo's `key in store`, raised the
    # object's own RuntimeError or numpy's "iteration over a 0-d array".
    with pytest.raises(dg.GraspError):
        _hostile_sequence_calls()[name](value)


class _LenRaises(list):
    def __len__(self):
        raise RuntimeError("a hostile __len__")


def test_the_last_hostile_sequences_of_the_fuzz_are_named():
    # is_ragged asked `not positions` of a list whose __len__ raised;
    # batch_grasp_forces listed a 10**9-row hand_jacobians (a view per row:
    # MemoryError) before comparing its length; plot_score_distribution
    # caught only TypeError from iterating the candidates.
    import drakegrasp.batch as db
    import drakegrasp.visualization as v

    N = np.tile([0.0, 0.0, 1.0], (2, 3, 1))
    with pytest.raises(dg.InvalidContactError, match="positions must"):
        dg.batch_force_closure(_LenRaises([[0.0] * 3] * 3), N, mu=0.5)
    huge = np.broadcast_to(0.5, (10**9, 6, 2))
    with pytest.raises(dg.InvalidOptionError, match="must hold 1 Jacobians"):
        db.batch_grasp_forces([_spatial()], np.zeros(6), hand_jacobians=huge)
    with pytest.raises(dg.InvalidOptionError, match="hand_jacobians must be"):
        db.batch_grasp_forces([_spatial()], np.zeros(6), hand_jacobians=np.array(1))
    with pytest.raises(dg.InvalidOptionError, match="candidates must be"):
        v.plot_score_distribution(_IterRaises())


def test_the_shared_checks_answer_every_hostile_object_of_the_fuzz():
    # report_public.py draws these objects for every public callable; the
    # checks every entry point shares must accept or name each of them.
    import hostile

    from drakegrasp.core import validation as v

    checks = [
        lambda x: v.real_scalar("x", x),
        lambda x: v.check_positions("x", x),
        lambda x: v.unit_vectors("x", x),
        lambda x: v.check_flag("x", x),
        lambda x: v.check_num_generators(x),
        lambda x: v.items_of("x", x, "a sequence"),
        lambda x: v.describe(x),
    ]
    for value in hostile.objects():
        for check in checks:
            try:
                check(value)
            except dg.GraspError:
                pass
