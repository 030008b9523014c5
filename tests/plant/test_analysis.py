"""analyze_grasp and load_scene: verdicts per scene, the core on the same contacts,
invariance to where the whole scene sits in the world, and every error path."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydrake.common.schema import Transform
from pydrake.common.yaml import yaml_load_typed
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import ModelDirectives, Parser, ProcessModelDirectives
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from drakegrasp import (
    Contact,
    Grasp,
    InvalidOptionError,
    ModelError,
    NoContactsError,
    PenetrationError,
    grasp_matrix,
)
from drakegrasp.closure.verdicts import force_closure, force_closure_exact, form_closure
from drakegrasp.core.antipodal import is_antipodal
from drakegrasp.plant import (
    DEFAULT_SCENE,
    analyze_grasp,
    grasp_from_plant,
    list_scenes,
    load_scene,
    register_models,
)
from drakegrasp.plant.scene import resolve_body, scene_path


def _ring(radius, z=0.0):
    """Contacts at azimuths 90, 210, 330 deg, normals toward the axis."""
    out = []
    for a in np.radians([90.0, 210.0, 330.0]):
        u = np.array([math.cos(a), math.sin(a), 0.0])
        u[np.abs(u) < 1e-12] = 0.0  # cos(90 deg) is 0, not 6e-17
        out.append((radius * u + [0, 0, z], -u))
    return out


# The contacts each scene's geometry makes, in the object frame, from the model
# dimensions (models/generator/make_models.py): pad height 55 mm above the palm,
# box centre 65 mm, cylinder centre 75 mm; 35 mm sphere; hexagonal prism 25 mm
# apothem; brick faces at 50 mm with Drake's fingertips at z = 20 mm and y = 0.
BY_HAND = {
    "parallel_jaw_box": [
        ([0, 0.025, -0.01], [0, -1, 0]),
        ([0, -0.025, -0.01], [0, 1, 0]),
    ],
    "parallel_jaw_cylinder": [
        ([0, 0.03, -0.02], [0, -1, 0]),
        ([0, -0.03, -0.02], [0, 1, 0]),
    ],
    "parallel_jaw_flat_box": [
        ([x, s * 0.025, z], [0, -s, 0])
        for s in (1, -1)
        for x in (-0.01, 0.01)
        for z in (-0.02, 0.0)
    ],
    "three_finger_sphere": _ring(0.035),
    "three_finger_hex_prism": _ring(0.025),
    "planar_gripper_brick": [
        ([-0.05, 0.02], [1, 0]),
        ([0.05, 0.02], [-1, 0]),
        ([0.0, -0.05], [0, 1]),
    ],
}

# What the geometry says: (form closure, force closure with hard fingers).
EXPECTED = {
    "parallel_jaw_box": (False, False),
    "parallel_jaw_cylinder": (False, False),
    "parallel_jaw_flat_box": (False, True),
    "three_finger_sphere": (False, True),
    "three_finger_hex_prism": (False, True),
    "planar_gripper_brick": (False, True),
}


def test_every_scene_has_an_expected_verdict():
    assert sorted(EXPECTED) == sorted(i.name for i in list_scenes())
    assert DEFAULT_SCENE in EXPECTED


def _report(scene, **overrides):
    options = scene.analysis_options()
    options.update(overrides)
    return analyze_grasp(scene.plant, scene.plant_context, **options)


def _by_hand(name, plant_contacts, *, mu, model="hard_finger", nu=0.0):
    """The hand-entered contacts, ordered like the plant's (nearest position)."""
    entries = BY_HAND[name]
    ordered = []
    for pc in plant_contacts:
        p = pc.p_OC if len(entries[0][0]) == 3 else pc.p_OC[1:]
        k = int(np.argmin([np.linalg.norm(np.array(e[0]) - p) for e in entries]))
        ordered.append(entries[k])
    assert len({id(e) for e in ordered}) == len(entries)  # a bijection
    return Grasp(
        [
            Contact(pos, n, mu=mu, contact_model=model, torsional_friction=nu)
            for pos, n in ordered
        ],
        reference_point=np.zeros(len(entries[0][0])),
    )


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_scene_verdicts_match_the_geometry_and_the_core(scene_cache, name):
    scene = scene_cache(name)
    report = _report(scene)
    form, force = EXPECTED[name]
    assert report.form_closure.is_closure is form
    assert report.force_closure.is_closure is force
    assert report.force_closure_exact.is_closure is force
    assert len(report.contacts) == len(BY_HAND[name])
    # The same contacts entered by hand give the same G and the same verdicts.
    grasp = _by_hand(name, report.contacts, mu=scene.info.mu)
    G = grasp_matrix(grasp)
    np.testing.assert_allclose(report.G, G, atol=1e-9)
    J = report.J
    core_force = force_closure(grasp, hand_jacobian=J)
    core_exact = force_closure_exact(grasp, hand_jacobian=J)
    core_form = form_closure(grasp)
    assert core_force.is_closure == report.force_closure.is_closure
    assert core_exact.is_closure == report.force_closure_exact.is_closure
    assert core_form.is_closure == report.form_closure.is_closure
    assert core_force.d_star == pytest.approx(report.force_closure.d_star, abs=1e-6)
    assert core_force.rank == report.force_closure.rank
    # LP3 on J passes for every shipped hand (each joint set controls the
    # internal forces it can reach).
    assert report.force_closure.internal_forces.passes
    if len(report.contacts) == 2:
        assert report.antipodal is not None
        assert report.antipodal.is_antipodal == is_antipodal(grasp).is_antipodal
    elif name.startswith("parallel_jaw"):  # two fingers: answered per finger
        assert report.antipodal.is_antipodal
        assert [len(c) for c in report.antipodal.contacts] == [4, 4]
    else:
        assert report.antipodal is None


def test_parallel_jaw_box_as_the_issue_describes(scene_cache):
    scene = scene_cache("parallel_jaw_box")
    hard = _report(scene, contact_model="hard_finger")
    assert len(hard.contacts) == 2
    assert hard.antipodal.is_antipodal
    assert not hard.force_closure.is_closure
    assert hard.force_closure.rank == 5  # no moment about the line between pads
    soft = _report(scene, contact_model="soft_finger", torsional_friction=0.1)
    assert soft.force_closure.is_closure and soft.force_closure_exact.is_closure
    assert soft.G.shape == (6, 8) and soft.J.shape == (8, 2)
    core = force_closure(
        _by_hand(
            "parallel_jaw_box", soft.contacts, mu=0.5, model="soft_finger", nu=0.1
        ),
        hand_jacobian=soft.J,
    )
    assert core.is_closure
    frictionless = _report(scene, contact_model="frictionless")
    assert not frictionless.force_closure.is_closure


def test_three_finger_sphere_mu_half(scene_cache):
    report = _report(scene_cache("three_finger_sphere"), mu=0.5)
    assert report.force_closure.is_closure
    lp3 = report.force_closure.internal_forces
    assert lp3.passes and lp3.null_space_dim == 0
    assert not _report(scene_cache("three_finger_sphere"), mu=0.0).force_closure


def test_planar_scene_uses_planar_wrenches(scene_cache):
    scene = scene_cache("planar_gripper_brick")
    report = _report(scene)
    assert report.grasp.planar
    assert report.G.shape == (3, 6)  # [f_y, f_z, m_x] x 3 contacts [f_n, f_t]
    assert report.J.shape == (6, 6)  # 3 fingers x 2 joints
    assert report.force_closure.required_rank == 3
    # Two opposed contacts at the same height are antipodal in the plane, so
    # the three-finger grasp is force closed for any mu > 0 ...
    assert _report(scene, mu=0.05).force_closure.is_closure
    # ... and not without friction (3 < 4 frictionless contacts).
    assert not _report(scene, mu=0.0).force_closure.is_closure
    # Without plane=..., the same contacts are spatial, with normals in x = 0.
    spatial = grasp_from_plant(
        scene.plant,
        scene.plant_context,
        object_body=scene.object_body,
        hand=scene.hand,
        mu=0.5,
    )
    assert not spatial.grasp.planar
    np.testing.assert_allclose(spatial.grasp.normals[:, 0], 0.0, atol=1e-12)
    np.testing.assert_allclose(
        spatial.grasp.normals[:, 1:], report.grasp.normals, atol=1e-12
    )


def _moved_scene(name, X):
    """The scene with every world weld and free-body pose premultiplied by X."""
    text = scene_path(name).read_text()
    directives = yaml_load_typed(
        schema=ModelDirectives, data=text, allow_yaml_with_no_schema=True
    )
    for d in directives.directives:
        if d.add_weld is not None and d.add_weld.parent == "world":
            old = (
                d.add_weld.X_PC.GetDeterministicValue()
                if d.add_weld.X_PC is not None
                else RigidTransform()
            )
            d.add_weld.X_PC = Transform(X.multiply(old))
        if d.add_model is not None and d.add_model.default_free_body_pose:
            poses = dict(d.add_model.default_free_body_pose)
            for body, pose in poses.items():
                poses[body] = Transform(X.multiply(pose.GetDeterministicValue()))
            d.add_model.default_free_body_pose = poses
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    parser = Parser(plant)
    register_models(parser)
    ProcessModelDirectives(directives, plant, parser)
    plant.Finalize()
    diagram = builder.Build()
    root = diagram.CreateDefaultContext()
    return diagram, plant, root, plant.GetMyContextFromRoot(root)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_results_do_not_depend_on_where_the_scene_is(scene_cache, name):
    scene = scene_cache(name)
    reference = _report(scene)
    rng = np.random.default_rng(7)
    X = RigidTransform(
        RollPitchYaw(rng.uniform(-math.pi, math.pi, 3)), rng.normal(size=3)
    )
    diagram, plant, root, ctx = _moved_scene(name, X)
    body = resolve_body(plant, scene.info.object_body)
    X_WO = plant.EvalBodyPoseInWorld(ctx, body)
    assert (
        np.linalg.norm(
            X_WO.translation()
            - scene.plant.EvalBodyPoseInWorld(
                scene.plant_context, scene.object_body
            ).translation()
        )
        > 0.1
    )
    options = scene.analysis_options()
    options["object_body"] = body
    options["hand"] = plant.GetModelInstanceByName(scene.info.hand)
    moved = analyze_grasp(plant, ctx, **options)
    np.testing.assert_allclose(moved.G, reference.G, atol=1e-9)
    np.testing.assert_allclose(moved.J, reference.J, atol=1e-9)
    for a, b in (
        (moved.form_closure, reference.form_closure),
        (moved.force_closure, reference.force_closure),
        (moved.force_closure_exact, reference.force_closure_exact),
    ):
        assert a.is_closure == b.is_closure
        assert a.d_star == pytest.approx(b.d_star, abs=1e-6)


def test_report_text_and_json(scene_cache):
    report = _report(scene_cache("parallel_jaw_box"))
    text = str(report)
    for expected in (
        "box::box",
        "gripper::left_finger",
        "form closure",
        "force closure",
        "LP3",
        "antipodal",
        "rank 5",
    ):
        assert expected in text
    data = json.loads(json.dumps(report.to_dict()))
    assert len(data["contacts"]) == 2
    assert data["force_closure"]["is_closure"] is False
    assert data["antipodal"]["is_antipodal"] is True
    assert np.array(data["G"]).shape == (6, 6)
    assert np.array(data["dpsi_dv"]).shape == (2, 8)


def test_hand_none_means_the_free_bodies_and_their_models_but_not_the_objects(
    scene_cache,
):
    scene = scene_cache("parallel_jaw_box")
    data = grasp_from_plant(
        scene.plant, scene.plant_context, object_body=scene.object_body, mu=0.5
    )
    # The welded palm belongs to the hand (it can touch); its weld adds no column.
    assert data.hand_bodies == (
        "gripper::palm",
        "gripper::left_finger",
        "gripper::right_finger",
    )
    assert data.hand_velocity_indices.size == 2
    scene = scene_cache("planar_gripper_brick")
    data = grasp_from_plant(
        scene.plant,
        scene.plant_context,
        object_body=scene.object_body,
        mu=0.5,
        plane="yz",
    )
    # The brick's dummy links (its planar joints) are not hand bodies.
    assert not any(b.startswith("brick::") for b in data.hand_bodies)
    assert data.hand_velocity_indices.size == 6


# ------------------------------------------------------------------ errors


def _write(tmp_path, text, name="scene.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def _default_text():
    return scene_path(DEFAULT_SCENE).read_text()


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda t: t + "  bogus: 1\n", "unknown key"),
        (lambda t: t.replace("  mu: 0.5\n", ""), "needs 'mu'"),
        (lambda t: t.replace("  mu: 0.5", "  mu: -1"), "mu must be finite and >= 0"),
        (lambda t: t.replace("  mu: 0.5", "  mu: lots"), "mu must be a number"),
        (lambda t: t.replace("hard_finger", "sticky"), "unknown contact model"),
        (lambda t: t + "  plane: xz\n", "plane must be one of"),
        (
            lambda t: t.replace("object_body: box::box", "object_body: box::lid"),
            "no body named 'box::lid'",
        ),
        (
            lambda t: t.replace("  hand: gripper", "  hand: claw"),
            "no model instance named 'claw'",
        ),
        (
            lambda t: t.replace("objects/box.sdf", "objects/nope.sdf"),
            "cannot load the models",
        ),
        (lambda t: t.replace("- add_weld:", "- add_welding:"), "bad model directives"),
        (lambda t: t.split("drakegrasp:")[0], "has no 'drakegrasp:' mapping"),
        (lambda t: "directives: [\n", "not valid YAML"),
        (lambda t: "- 1\n- 2\n", "must be a YAML mapping"),
    ],
)
def test_bad_scene_files(tmp_path, edit, message):
    path = _write(tmp_path, edit(_default_text()))
    with pytest.raises(ModelError, match=message):
        load_scene(path)


def test_unknown_scene_name_lists_the_shipped_ones():
    with pytest.raises(ModelError, match="parallel_jaw_box") as info:
        load_scene("no_such_scene")
    assert "not found" in str(info.value)


def test_open_and_closed_gripper(scene_cache, tools):
    scene = scene_cache("parallel_jaw_box")
    plant = scene.plant
    for q, error, text in (
        (0.030, NoContactsError, "closest finger geometry is gripper::.* at 5 mm"),
        (0.024, PenetrationError, "penetrates the object .* by 1 mm"),
    ):
        root, ctx = tools.fresh_context(scene)
        plant.GetJointByName("left_finger_joint").set_translation(ctx, q)
        plant.GetJointByName("right_finger_joint").set_translation(ctx, q)
        options = scene.analysis_options()
        with pytest.raises(error, match=text) as info:
            analyze_grasp(plant, ctx, **options)
        assert "box::box" in str(info.value)
    # One finger opened: the other still touches, a one-contact "grasp".
    root, ctx = tools.fresh_context(scene)
    plant.GetJointByName("left_finger_joint").set_translation(ctx, 0.030)
    report = analyze_grasp(plant, ctx, **scene.analysis_options())
    assert [c.finger_body for c in report.contacts] == ["gripper::right_finger"]
    assert not report.force_closure.is_closure


def test_bad_analysis_options(scene_cache):
    scene = scene_cache("parallel_jaw_box")
    plant, ctx = scene.plant, scene.plant_context
    base = {"object_body": scene.object_body, "hand": scene.hand, "mu": 0.5}
    with pytest.raises(InvalidOptionError, match="needs torsional_friction"):
        analyze_grasp(plant, ctx, contact_model="soft_finger", **base)
    with pytest.raises(InvalidOptionError, match="plane must be one of"):
        analyze_grasp(plant, ctx, plane="xyz", **base)
    with pytest.raises(InvalidOptionError, match="leaves the zx plane"):
        analyze_grasp(plant, ctx, plane="zx", **base)
    with pytest.raises(InvalidOptionError, match="no soft fingers"):
        analyze_grasp(
            plant,
            ctx,
            plane="xy",
            contact_model="soft_finger",
            torsional_friction=0.1,
            **base,
        )
    # The root context of the diagram works as the plant's own context.
    from_root = analyze_grasp(plant, scene.context, **base)
    assert from_root.force_closure.is_closure == (
        analyze_grasp(plant, scene.plant_context, **base).force_closure.is_closure
    )


@settings(derandomize=True, max_examples=6, deadline=None)
@given(
    rpy=st.tuples(*[st.floats(-math.pi, math.pi)] * 3),
    xyz=st.tuples(*[st.floats(-2.0, 2.0)] * 3),
)
def test_default_scene_invariance_property(rpy, xyz):
    scene = load_scene(DEFAULT_SCENE)
    reference = _report(scene)
    X = RigidTransform(RollPitchYaw(rpy), np.array(xyz))
    diagram, plant, root, ctx = _moved_scene(DEFAULT_SCENE, X)
    moved = analyze_grasp(
        plant,
        ctx,
        object_body="box::box",
        hand="gripper",
        mu=0.5,
        torsional_friction=0.1,
    )
    np.testing.assert_allclose(moved.G, reference.G, atol=1e-9)
    np.testing.assert_allclose(moved.data.psi, reference.data.psi, atol=1e-9)
    assert moved.force_closure.is_closure == reference.force_closure.is_closure
    assert moved.antipodal.is_antipodal


def test_public_signatures_follow_the_issue():
    import inspect

    from drakegrasp.plant import find_contacts

    for fn, required in (
        (find_contacts, ["object_body"]),
        (grasp_from_plant, ["object_body"]),
        (analyze_grasp, ["object_body"]),
    ):
        params = inspect.signature(fn).parameters
        names = list(params)
        # object_body may be positional (one rule for the plant layer); every
        # option after it is keyword-only.
        assert names[:3] == ["plant", "plant_context", "object_body"]
        assert params["object_body"].kind is inspect.Parameter.POSITIONAL_OR_KEYWORD
        for name in names[3:]:
            assert params[name].kind is inspect.Parameter.KEYWORD_ONLY, name
        for name in required:
            assert params[name].default is inspect.Parameter.empty
        assert params["hand"].default is None
        assert params["distance_tolerance"].default == 1e-4
    params = inspect.signature(grasp_from_plant).parameters
    # mu is required: as a keyword or in options=AnalysisOptions(mu=...).
    assert params["mu"].default is None and params["options"].default is None
    assert params["contact_model"].default == "hard_finger"


def test_scene_hand_as_body_list_and_tolerance(tmp_path):
    text = _default_text().replace(
        "  hand: gripper",
        "  hand: [gripper::left_finger]\n  distance_tolerance: 2.0e-4",
    )
    scene = load_scene(_write(tmp_path, text))
    assert scene.info.hand == ("gripper::left_finger",)
    assert scene.info.distance_tolerance == 2e-4
    assert [b.name() for b in scene.hand] == ["left_finger"]
    report = analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    assert [c.finger_body for c in report.contacts] == ["gripper::left_finger"]
    assert report.data.hand_velocity_indices.tolist() == [
        scene.plant.GetJointByName("left_finger_joint").velocity_start()
    ]


def test_analysis_options_are_one_validated_object(tmp_path, tools):
    from drakegrasp import AnalysisOptions, GraspError, InvalidOptionError, load_scene

    scene = load_scene("three_finger_sphere")
    keywords = analyze_grasp(
        scene.plant, scene.plant_context, **scene.analysis_options()
    )
    report = tools.analyze_scene(scene)
    # The same analysis either way, and the report keeps what it used.
    assert report.to_dict() == keywords.to_dict()
    assert report.options == keywords.options == scene.options
    # Invalid values are refused when the object is made, with the field named.
    for bad in (
        {"mu": -1},
        {"tol": 0},
        {"plane": "xz"},
        {"patches": "all"},
        {"check_pose": 1},
        {"num_generators": 2},
        {"load": "weight"},
        {"contact_model": "sticky"},
        {"distance_tolerance": float("nan")},
    ):
        name = next(iter(bad))
        with pytest.raises(GraspError, match=name.split("_")[0]):
            AnalysisOptions(**bad)
    with pytest.raises(InvalidOptionError, match="unknown analysis option"):
        scene.options.replace(friction=0.3)
    # Options and keywords together: refused rather than one silently ignored.
    with pytest.raises(InvalidOptionError, match=r"\['tol'\], not both"):
        analyze_grasp(
            scene.plant,
            scene.plant_context,
            scene.object_body,
            options=scene.options,
            tol=1e-3,
        )
    # mu is required, here or in the options.
    with pytest.raises(InvalidOptionError, match="needs mu"):
        analyze_grasp(scene.plant, scene.plant_context, scene.object_body)
    # A changed field changes the analysis.
    strict = tools.analyze_scene(scene, scene.options.replace(mu=0.0))
    assert not strict.force_closure.frictional_closure
    assert strict.options.mu == 0.0 and strict.to_dict()["options"]["mu"] == 0.0


def test_printing_a_report_checks_its_certificates_once(monkeypatch):
    from drakegrasp import load_scene
    from drakegrasp.certificates.certificate import Certificate

    scene = load_scene("three_finger_sphere")
    report = analyze_grasp(scene.plant, scene.plant_context, **scene.analysis_options())
    report.to_dict()  # the deferred parts (second order re-checks LP1's witness)
    calls = []
    original = Certificate.check

    def counted(self, *args, **kwargs):
        calls.append(self.kind)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Certificate, "check", counted)
    first, second = str(report), str(report)
    assert first == second and "re-checked" in first
    n = sum(
        r.certificate is not None
        for r in (report.form_closure, report.force_closure, report.force_closure_exact)
    )
    assert len(calls) == n > 0
