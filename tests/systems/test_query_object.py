"""``query_object=``: analyse a plant context that no scene graph feeds.

A Drake ``System`` (the grasp monitor) holds its own plant context whose
geometry query port is not connected; it passes the scene graph's query object
from one of its input ports instead.  The answer must be the one the connected
context gives.
"""

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError


@pytest.fixture(scope="module")
def scene():
    return dg.load_scene("parallel_jaw_flat_box")


def _private_context(scene):
    """A fresh plant context with the scene's state: no scene graph behind it."""
    context = scene.plant.CreateDefaultContext()
    scene.plant.SetPositionsAndVelocities(
        context, scene.plant.GetPositionsAndVelocities(scene.plant_context)
    )
    return context


def _query(scene):
    return scene.plant.get_geometry_query_input_port().Eval(scene.plant_context)


def test_unconnected_context_needs_a_query_object(scene):
    with pytest.raises(dg.InvalidContextError, match="GetMyContextFromRoot"):
        dg.find_contacts(
            scene.plant, _private_context(scene), object_body=scene.object_body
        )


def test_query_object_gives_the_connected_answer(scene):
    options = scene.analysis_options()
    reference = dg.analyze_grasp(scene.plant, scene.plant_context, **options)
    report = dg.analyze_grasp(
        scene.plant, _private_context(scene), query_object=_query(scene), **options
    )
    assert len(report.contacts) == len(reference.contacts) == 8
    for a, b in zip(report.contacts, reference.contacts, strict=True):
        np.testing.assert_array_equal(a.p_OC, b.p_OC)
        np.testing.assert_array_equal(a.nhat_O, b.nhat_O)
    np.testing.assert_array_equal(report.J, reference.J)
    assert report.force_closure.d_star == reference.force_closure.d_star


def test_query_object_of_the_wrong_type(scene):
    with pytest.raises(InvalidOptionError, match="query_object must be"):
        dg.find_contacts(
            scene.plant,
            scene.plant_context,
            object_body=scene.object_body,
            query_object="scene_graph",
        )


def test_query_object_at_another_state_is_refused(scene):
    # The same scene graph's query, evaluated where a finger stands 5 mm off:
    # its distances and the context's Jacobians would describe two grasps.
    plant = scene.plant
    context = _private_context(scene)
    moved = plant.GetPositions(scene.plant_context).copy()
    joint = next(
        plant.get_joint(j)
        for j in plant.GetJointIndices()
        if plant.get_joint(j).type_name() == "prismatic"
    )
    moved[joint.position_start()] += 0.005
    saved = plant.GetPositions(scene.plant_context).copy()
    plant.SetPositions(scene.plant_context, moved)
    try:
        query = _query(scene)
        with pytest.raises(InvalidOptionError, match="another state") as info:
            dg.analyze_grasp(
                plant, context, query_object=query, **scene.analysis_options()
            )
        assert "5 mm" in str(info.value)
        found = dg.find_contacts(
            plant, scene.plant_context, object_body=scene.object_body, hand=scene.hand
        )
        with pytest.raises(InvalidOptionError, match="another state"):
            # given contacts, the query is still read (the pose, mu="plant")
            dg.analyze_grasp(
                plant, context, query_object=query, contacts=found,
                **scene.analysis_options(),
            )  # fmt: skip
        plant.SetPositions(context, moved)  # the same state: accepted
        report = dg.find_contacts(
            plant, context, object_body=scene.object_body, query_object=query
        )
        assert len(report) == 4  # the moved finger is off the box
    finally:
        plant.SetPositions(scene.plant_context, saved)


def test_query_object_checks_every_body_when_none_are_named(scene):
    # bodies=None is the default: every body of the plant with geometry (it
    # raised pydrake's TypeError, reading bodies by a bare int)
    from drakegrasp.plant.validation import checked_query_object

    plant = scene.plant
    saved = plant.GetPositions(scene.plant_context).copy()
    context = _private_context(scene)
    inspector = checked_query_object(plant, _query(scene), context)
    assert inspector.SourceIsRegistered(plant.get_source_id())
    moved = saved.copy()
    moved[-1] += 0.003  # the last coordinate: the object's z (a free body)
    plant.SetPositions(scene.plant_context, moved)
    try:
        with pytest.raises(InvalidOptionError, match="another state"):
            checked_query_object(plant, _query(scene), context)
    finally:
        plant.SetPositions(scene.plant_context, saved)
