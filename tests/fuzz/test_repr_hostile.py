"""Values whose repr, str or format raise, lie or are huge: still a GraspError.

Messages name the offending value.  A value that is a user's own object, or a
user's ``float``/``str``/``ndarray`` subclass that passes an ``isinstance``
check, may have a ``__repr__`` that raises, returns an int or returns 10**7
characters; the message must still be built, be short, and be a
:class:`~drakegrasp.GraspError` (``describe`` in ``core/validation.py``; the
last guard is ``GraspError`` cutting a huge message).  Each public entry point
here gets each such object (``hostile.repr_hostile``) in each argument
position; it either answers or refuses with a short GraspError.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import drakegrasp as dg

sys.path.insert(0, str(Path(__file__).resolve().parent))
import hostile  # noqa: E402

SHORT = 2_000
"""Characters a refusal's message may take, whatever the value's repr."""

HOSTILE = hostile.repr_hostile()
IDS = [f"{type(v).__name__}-{i}" for i, v in enumerate(HOSTILE)]


def _contact():
    return dg.Contact([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], mu=0.5)


def _grasp():
    return dg.core.examples.spatial_two_fingers(0.5)


def _calls():
    """``(name, call)``: ``call(value)`` puts ``value`` in one argument position."""
    P = np.zeros((2, 3, 3))
    N = np.tile([0.0, 0.0, 1.0], (2, 3, 1))
    c = [0.0, 0.0, 1.0]
    n = [0.0, 0.0, -1.0]
    yield "Contact(position)", lambda v: dg.Contact(v, n, mu=0.5)
    yield "Contact(normal)", lambda v: dg.Contact(c, v, mu=0.5)
    yield "Contact(mu)", lambda v: dg.Contact(c, n, mu=v)
    yield "Contact(contact_model)", lambda v: dg.Contact(c, n, contact_model=v)
    yield (
        "Contact(torsional_friction)",
        lambda v: dg.Contact(c, n, mu=0.5, contact_model="soft_finger",
                             torsional_friction=v),
    )  # fmt: skip
    yield "Grasp(contacts)", lambda v: dg.Grasp(v)
    yield "Grasp([contact, v])", lambda v: dg.Grasp([_contact(), v])
    yield (
        "Grasp(reference_point)",
        lambda v: dg.Grasp([_contact()], reference_point=v),
    )
    yield (
        "Grasp(characteristic_length)",
        lambda v: dg.Grasp([_contact()], characteristic_length=v),
    )
    yield "grasp_matrix", lambda v: dg.grasp_matrix(v)
    yield "force_closure(grasp)", lambda v: dg.force_closure(v)
    for key in ("hand_jacobian", "num_generators", "tol", "rank_tol", "formulation"):
        yield (
            f"force_closure({key})",
            lambda v, key=key: dg.force_closure(_grasp(), **{key: v}),
        )
    yield "form_closure(grasp)", lambda v: dg.form_closure(v)
    for key in ("tol", "rank_tol"):
        yield (
            f"form_closure({key})",
            lambda v, key=key: dg.form_closure(_grasp(), **{key: v}),
        )
    yield (
        "batch_force_closure(positions)",
        lambda v: dg.batch_force_closure(v, N, mu=0.5),
    )
    yield "batch_force_closure(normals)", lambda v: dg.batch_force_closure(P, v, mu=0.5)
    for key in (
        "mu", "contact_model", "num_generators", "torsional_friction",
        "reference_points", "characteristic_lengths", "tol", "rank_tol",
        "chunk_size", "progress", "metrics", "workers", "kernel", "options",
    ):  # fmt: skip
        keywords = {"mu": 0.5}
        yield (
            f"batch_force_closure({key})",
            lambda v, key=key, keywords=keywords: dg.batch_force_closure(
                P, N, **{**keywords, key: v}
            ),
        )
    for name in dg.AnalysisOptions.__dataclass_fields__:
        yield (
            f"AnalysisOptions({name})",
            lambda v, name=name: dg.AnalysisOptions(**{name: v}),
        )
    for name in dg.BatchOptions.__dataclass_fields__:
        yield (
            f"BatchOptions({name})",
            lambda v, name=name: dg.BatchOptions(**{name: v}),
        )
    for metric in (
        "grasp_quality", "min_singular_value", "wrench_ellipsoid_volume",
        "grasp_singular_values", "distance_to_singularity",
        "manipulability_volume",
    ):  # fmt: skip
        yield f"{metric}(grasp)", lambda v, m=metric: getattr(dg, m)(v)
    yield "grasp_quality(norm)", lambda v: dg.grasp_quality(_grasp(), norm=v)
    yield (
        "grasp_quality(num_generators)",
        lambda v: dg.grasp_quality(_grasp(), num_generators=v),
    )


CALLS = list(_calls())


def _refuses_briefly(call, value) -> None:
    try:
        call(value)
    except dg.GraspError as error:
        message = str(error)
        assert type(message) is str
        assert len(message) <= SHORT, f"a {len(message)}-character message"


@pytest.mark.parametrize("value", HOSTILE, ids=IDS)
@pytest.mark.parametrize(("name", "call"), CALLS, ids=[n for n, _ in CALLS])
def test_the_numpy_entry_points_refuse_a_hostile_repr_with_a_short_graspError(
    name, call, value
):
    _refuses_briefly(call, value)


@pytest.fixture(scope="module")
def jaw():
    return dg.load_scene("parallel_jaw_box")


def _plant_calls(scene):
    plant, context, body = scene.plant, scene.plant_context, scene.object_body
    for function in (dg.analyze_grasp, dg.grasp_from_plant, dg.find_contacts):
        name = function.__name__
        yield f"{name}(plant)", lambda v, f=function: f(v, context, body)
        yield f"{name}(plant_context)", lambda v, f=function: f(plant, v, body)
        yield f"{name}(object_body)", lambda v, f=function: f(plant, context, v)
    for key in (
        "hand", "mu", "contact_model", "plane", "patches", "distance_tolerance",
        "num_generators", "tol", "load", "object_mass", "torque_limits",
        "couplings", "options",
    ):  # fmt: skip
        yield (
            f"analyze_grasp({key})",
            lambda v, key=key: dg.analyze_grasp(plant, context, body, **{key: v}),
        )


def test_the_plant_entry_points_refuse_a_hostile_repr_with_a_short_graspError(jaw):
    for name, call in _plant_calls(jaw):
        for value in HOSTILE:
            try:
                _refuses_briefly(call, value)
            except AssertionError as failure:
                raise AssertionError(f"{name} with {IDS[HOSTILE.index(value)]}") from (
                    failure
                )
            except Exception as error:
                raise AssertionError(
                    f"{name} with {IDS[HOSTILE.index(value)]}: raw "
                    f"{type(error).__name__}"
                ) from error


@pytest.mark.parametrize(
    "options",
    [
        lambda v: dg.AnalysisOptions(distance_tolerance=v).distance_tolerance,
        lambda v: dg.AnalysisOptions(coupling_tolerance=v).coupling_tolerance,
    ],
)
def test_a_valid_float_subclass_is_taken_whatever_its_repr(options):
    # A float subclass whose repr raises is a valid tolerance: its message,
    # built before the check, raised the repr's error for a valid value.
    assert options(hostile.FloatReprRaises(5e-4)) == 5e-4


@pytest.mark.parametrize("value", HOSTILE, ids=IDS)
def test_plot_colours_with_a_hostile_repr_are_refused_by_name(value):
    # matplotlib's is_color_like formats a value it cannot read with its repr.
    import drakegrasp.visualization as viz

    grasp = dg.core.examples.planar_two_finger_square(0.5)
    _refuses_briefly(lambda v: viz.plot_planar_grasp(grasp, colors={"x": v}), value)


def test_a_models_folder_that_is_a_hostile_str_subclass_is_read_as_its_text():
    # pathlib calls str() on a str subclass, whose own __str__ may raise.
    from drakegrasp.planning.scenes import planning_scene

    box = "package://drake_models/ycb/003_cracker_box.sdf"
    with pytest.raises(dg.ModelError, match="drake_models folder 'x'"):
        planning_scene(box, models_dir=hostile.StrFormatRaises("x"))


@pytest.mark.parametrize(
    "outline",
    [{hostile.ReprRaises(): 1}, {1: 2, "a": 3}, hostile.DictReprRaises(a=1)],
    ids=["key-repr-raises", "unsortable-keys", "dict-repr-raises"],
)
def test_a_circle_outline_of_odd_keys_is_refused_by_name(outline):
    # The message listed sorted(outline): a key's repr raised, and keys of
    # several types could not be sorted (a bare TypeError).
    import drakegrasp.visualization as viz

    grasp = dg.core.examples.planar_two_finger_square(0.5)
    with pytest.raises(dg.InvalidOptionError, match="keys 'center' and 'radius'"):
        viz.plot_planar_grasp(grasp, outline=outline)
