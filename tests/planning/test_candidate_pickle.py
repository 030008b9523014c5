"""Planned candidates pickle: to another process and back, every attribute equal.

``pickle.dumps(candidate)`` raised ``TypeError: cannot pickle
'pydrake.multibody.tree.BodyIndex' object`` (a contact's finger body; its
two ``GeometryId`` were next), so candidates could not go to a
``multiprocessing`` or Dask worker.  A ``BodyIndex`` comes back as itself; a
``GeometryId`` as itself in the process that planned the candidate and as a
``ForeignGeometryId`` in any other, which drakegrasp's geometry readers refuse
(``drakegrasp.plant.handles``).
"""

from __future__ import annotations

import concurrent.futures
import copy
import dataclasses
import json
import multiprocessing
import pickle

import numpy as np
import pytest
from allegro_support import allegro_scene
from process_support import BOX, JAW, echo, inspect_candidates
from pydrake.geometry import GeometryId
from pydrake.math import RigidTransform
from pydrake.multibody.tree import BodyIndex

import drakegrasp as dg
from drakegrasp.errors import InvalidContactError
from drakegrasp.planning.candidates import GraspCandidate, GraspCandidates
from drakegrasp.plant import handles
from drakegrasp.plant.contacts import PlantContact
from drakegrasp.plant.curvature import contact_curvatures
from drakegrasp.plant.friction import plant_friction
from drakegrasp.plant.scene import DEFAULT_SCENE, load_scene

SHORT = dict(settle=0.05, phase=0.05, blend=0.02, seat=0.05, directions=[(1, 0, 0)])


def _plan(plant, context, body, hand, n=40):
    return dg.plan_grasps(
        plant, context, body, hand=hand, num_candidates=n, mu=0.5, seed=0,
        robustness_samples=4,
    )  # fmt: skip


@pytest.fixture(scope="module")
def jaw():
    """``drakegrasp plan``'s default: the flat jaw on the shipped box."""
    scene = dg.planning_scene(BOX, hand_url=JAW)
    result = _plan(scene.plant, scene.context, scene.object_body, scene.hand)
    assert len(result) >= 3
    return scene, result


@pytest.fixture(scope="module")
def default_scene():
    """The shipped default scene (``drakegrasp analyze``'s), its hand free."""
    scene = load_scene(DEFAULT_SCENE, close=False, free_hand=True)
    result = _plan(scene.plant, scene.plant_context, scene.object_body, scene.hand)
    assert len(result) >= 1
    return scene, result


@pytest.fixture(scope="module")
def wsg(wsg_scene):
    """Drake's WSG-50 on the YCB sugar box (skips without drake_models)."""
    scene = wsg_scene()
    return scene, _plan(scene.plant, scene.context, scene.object_body, scene.hand)


@pytest.fixture(scope="module")
def allegro(drake_models_dir):
    """Drake's Allegro hand on the YCB sugar box (skips without drake_models)."""
    scene = allegro_scene("004_sugar_box", drake_models_dir)
    result = _plan(scene.plant, scene.context, scene.object_body, scene.hand)
    assert any(np.isfinite(c.torque_needed) for c in result)  # its motors' figure
    return scene, result


# -- equality, attribute by attribute -----------------------------------------


def _same(a, b, where: str = "") -> None:
    """``a`` and ``b`` equal: arrays and floats bitwise (NaN included), poses
    exactly, dataclasses field by field, Drake handles by value and type."""
    assert type(a) is type(b), (where, type(a), type(b))
    if isinstance(a, np.ndarray):
        assert (a.dtype, a.shape) == (b.dtype, b.shape), where
        if a.dtype == object:  # str (the table's torque_unit): by value
            assert a.tolist() == b.tolist(), where
        else:
            assert a.tobytes() == b.tobytes(), where
    elif isinstance(a, float):
        assert np.float64(a).tobytes() == np.float64(b).tobytes(), (where, a, b)
    elif isinstance(a, RigidTransform):
        assert a.IsExactlyEqualTo(b), where
    elif isinstance(a, GeometryId | BodyIndex):
        assert a == b, where
    elif isinstance(a, dict):
        assert list(a) == list(b), where
        for k in a:
            _same(a[k], b[k], f"{where}[{k!r}]")
    elif isinstance(a, tuple | list):
        assert len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, f"{where}[{k}]")
    elif dataclasses.is_dataclass(a) and not isinstance(a, dg.ClosureResult):
        for f in dataclasses.fields(a):
            _same(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, dg.ClosureResult):  # its deferred parts computed by pickle
        assert json.dumps(a.to_dict()) == json.dumps(b.to_dict()), where
    else:
        assert a == b, (where, a, b)


def _same_candidate(a: GraspCandidate, b: GraspCandidate) -> None:
    _same(a, b, f"sample {a.sample}")
    assert json.dumps(a.to_dict()) == json.dumps(b.to_dict())
    assert str(a) == str(b)
    assert np.array_equal(dg.grasp_matrix(a.grasp), dg.grasp_matrix(b.grasp))


def _same_result(a: GraspCandidates, b: GraspCandidates) -> None:
    for name in ("rejections", "num_sampled", "object_body", "mu", "torque_scale",
                 "reason", "settings", "time"):  # fmt: skip
        _same(getattr(a, name), getattr(b, name), name)
    assert len(a) == len(b)
    for x, y in zip(a, b, strict=True):
        _same_candidate(x, y)
    assert a.to_json() == b.to_json() and str(a) == str(b)
    _same(a.table(), b.table(), "table")


# -- in this process ------------------------------------------------------------


@pytest.mark.parametrize("planned", ["jaw", "default_scene", "wsg", "allegro"])
def test_a_planned_result_pickles_with_every_attribute_equal(planned, request):
    _, result = request.getfixturevalue(planned)
    for protocol in (pickle.DEFAULT_PROTOCOL, pickle.HIGHEST_PROTOCOL):
        back = pickle.loads(pickle.dumps(result, protocol=protocol))
        _same_result(result, back)
        # in the process that planned them, the very ids of its scene graph
        for d in back:
            for m in d.contacts:
                assert isinstance(m.object_geometry, GeometryId)
                assert isinstance(m.finger_geometry, GeometryId)
                assert isinstance(m.finger_body_index, BodyIndex)
    one = pickle.loads(pickle.dumps(result[0]))
    _same_candidate(result[0], one)


def test_a_copied_candidate_is_equal_and_its_grasp_is_built_again(jaw):
    _, result = jaw
    c = result[0]
    c.grasp  # noqa: B018  (cached on the candidate: not pickled, built again)
    assert "grasp" in vars(c)
    back = pickle.loads(pickle.dumps(c))
    assert "grasp" not in vars(back)
    _same_candidate(c, back)
    _same_candidate(c, copy.deepcopy(c))


def test_a_copied_contact_keeps_its_handles(jaw):
    # copy.copy takes __reduce__ without rebuilding its arguments: the copy
    # held the handles' stand-ins (a foreign id in the planning process)
    _, result = jaw
    k = result[0].contacts[0]
    for twin in (copy.copy(k), copy.deepcopy(k)):
        assert type(twin.object_geometry) is GeometryId
        assert type(twin.finger_geometry) is GeometryId
        assert type(twin.finger_body_index) is BodyIndex
        assert twin.object_geometry == k.object_geometry
        assert twin.finger_body_index == k.finger_body_index
        _same(k, twin, "copy")


def test_an_unpickled_candidate_applies_and_shakes_as_the_planned_one(jaw):
    scene, result = jaw
    back = pickle.loads(pickle.dumps(result))
    ctx = scene.context.Clone()
    back[0].apply(scene.plant, ctx, object_body=scene.object_body)
    found = dg.find_contacts(
        scene.plant, ctx, scene.object_body, hand=scene.hand
    )  # fmt: skip
    assert np.array_equal([k.p_OC for k in found], [k.p_OC for k in back[0].contacts])
    plant_friction(scene.plant, ctx, back[0].contacts)  # its own geometries
    shaken = dg.shake_candidates(scene.add_models, back, top=2, squeeze=5.0, **SHORT)
    again = dg.shake_candidates(scene.add_models, result, top=2, squeeze=5.0, **SHORT)
    assert [s.planned_rank for s in shaken] == [s.planned_rank for s in again]
    assert [s.held for s in shaken] == [s.held for s in again]
    # and the shaken candidates pickle too, their results and candidates equal
    copied = pickle.loads(pickle.dumps(shaken))
    assert (copied.held_from, copied.options) == (shaken.held_from, shaken.options)
    for s, t in zip(shaken, copied, strict=True):
        _same(s.result, t.result, "result")
        _same_candidate(s.candidate, t.candidate)
        assert (s.planned_rank, s.held, s.error) == (t.planned_rank, t.held, t.error)
    assert copied.to_dict()["shaken"] == shaken.to_dict()["shaken"]


# -- in another process ---------------------------------------------------------


@pytest.fixture
def elsewhere(monkeypatch):
    """Unpickle as another process would: a process of another name."""

    def loads(data: bytes):
        with monkeypatch.context() as m:
            m.setattr(handles, "_SALT", "another interpreter")
            return pickle.loads(data)

    return loads


def test_in_another_process_a_geometry_id_is_foreign_and_refused(jaw, elsewhere):
    scene, result = jaw
    c = result[0]
    there = elsewhere(pickle.dumps(c))
    k, m = c.contacts[0], there.contacts[0]
    assert isinstance(m.object_geometry, handles.ForeignGeometryId)
    assert m.object_geometry.get_value() == k.object_geometry.get_value()
    assert m.finger_geometry.get_value() == k.finger_geometry.get_value()
    assert repr(m.finger_geometry).endswith("of another process>")
    assert m.finger_body_index == k.finger_body_index  # a plant's index: kept
    # everything else is the planned candidate's
    for f in dataclasses.fields(GraspCandidate):
        if f.name != "contacts":
            _same(getattr(c, f.name), getattr(there, f.name), f.name)
    for f in dataclasses.fields(PlantContact):
        if f.name not in ("object_geometry", "finger_geometry"):
            _same(getattr(k, f.name), getattr(m, f.name), f.name)
    assert json.dumps(there.to_dict()) == json.dumps(c.to_dict())
    assert str(there) == str(c)
    # a reader of the scene graph says why, instead of reading geometry 7 there
    ctx = scene.plant.GetMyContextFromRoot(scene.context)
    with pytest.raises(InvalidContactError, match="contact 0's object_geometry is"):
        plant_friction(scene.plant, ctx, there.contacts)
    with pytest.raises(InvalidContactError, match="find the contacts again"):
        contact_curvatures(
            scene.plant, ctx, there.contacts, object_body=scene.object_body
        )
    # either id alone foreign is refused (the object's, the finger's here)
    half = [dataclasses.replace(m, finger_geometry=k.finger_geometry)]
    with pytest.raises(InvalidContactError, match="object_geometry"):
        contact_curvatures(scene.plant, ctx, half, object_body=scene.object_body)
    # back home, the very GeometryId again
    home = pickle.loads(pickle.dumps(there))
    _same_candidate(c, home)
    assert home.contacts[0].object_geometry == k.object_geometry


def test_a_foreign_id_never_becomes_another_geometry_of_this_process(elsewhere):
    # an id made in another process whose number this process also uses
    mine = GeometryId.get_new_id()
    foreign = handles.ForeignGeometryId(mine.get_value(), "another interpreter")
    back = pickle.loads(pickle.dumps(foreign))
    assert back == foreign and not isinstance(back, GeometryId)


def test_candidates_go_to_a_spawned_process_and_come_back_equal(jaw):
    scene, result = jaw
    sent = list(result[:3])
    spawn = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=spawn) as pool:
        back = pool.submit(echo, sent).result(timeout=300)
        whole = pool.submit(echo, result).result(timeout=300)
        seen = pool.submit(inspect_candidates, sent).result(timeout=300)
    for a, b in zip(sent, back, strict=True):
        _same_candidate(a, b)
        assert b.contacts[0].object_geometry == a.contacts[0].object_geometry
    _same_result(result, whole)
    # what the worker saw: the same dictionaries, lines, grasps and verdicts
    assert seen["json"] == [json.dumps(c.to_dict(), sort_keys=True) for c in sent]
    assert seen["str"] == [str(c) for c in sent]
    for G, c in zip(seen["G"], sent, strict=True):
        assert np.array_equal(G, dg.grasp_matrix(c.grasp))
    assert seen["closure"] == [c.is_closure for c in sent]
    # its own geometry ids differ from ours: foreign there, and said so
    assert seen["ids"] == {"ForeignGeometryId", "BodyIndex"}
    assert seen["refused"].startswith("InvalidContactError: contact 0's")
    # applied to the worker's own plant, the contacts found there are the plan's
    for found, c in zip(seen["found"], sent, strict=True):
        assert [f[0] for f in found] == [k.finger_geometry_label for k in c.contacts]
        assert np.array_equal([f[1] for f in found], [k.p_OC for k in c.contacts])
        assert np.array_equal([f[2] for f in found], [k.nhat_O for k in c.contacts])
