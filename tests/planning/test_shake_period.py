"""The shake's contact period is the rigid body's stiffest mode, not a translation's.

``contact_period`` solves ``K v = ω² M v`` for the object's twist about its
centre of mass (``K = Σ k_i w_i w_iᵀ``, ``w_i = [r_i × n_i; n_i]``, ``M =
blockdiag(I_Bcm, m 1)``).  Checked against a box held at two antipodal
contacts off its centre of mass (by hand: ``ω² = 2k (1/m + h²/I)``), against
scipy's generalized eigensolver, under a rigid motion of contacts and
inertia, under scaling of the stiffness, and for inertias Drake cannot
simulate (a point mass, a thin rod's axis).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import scipy.linalg
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.multibody.tree import SpatialInertia, UnitInertia
from pydrake.systems.framework import DiagramBuilder

from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning import plan_grasps, planning_scene
from drakegrasp.planning.shake import _mode_period, contact_period
from drakegrasp.plant.models import new_parser

K_PAIR = 5e5  # N/m: Drake's default point stiffness (1e6) of two geometries in series
BOX = (0.2, 2.0833333333333337e-04)  # the shipped box: kg, Ixx = Iyy (kg m²)


def _by_scipy(k, p, n, mass, com, inertia) -> float:
    """The second route: scipy's generalized eigensolver on K and M as written."""
    r = p - com
    w = np.hstack([np.cross(r, n), n])
    K = w.T @ (k[:, None] * w)
    M = scipy.linalg.block_diag(inertia, mass * np.eye(3))
    return 2 * math.pi / math.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True)[-1])


def _random_grasp(rng, n=5):
    p = rng.uniform(-0.05, 0.05, (n, 3))
    normals = rng.normal(size=(n, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    A = rng.normal(size=(3, 3))
    inertia = 1e-4 * (A @ A.T + 0.1 * np.eye(3))
    return (
        rng.uniform(1e5, 1e6, n),
        p,
        normals,
        0.3,
        rng.uniform(-0.01, 0.01, 3),
        inertia,
    )


def test_two_antipodal_contacts_off_the_centre_of_mass_by_hand():
    # contacts at (±a, 0, h) pressing along ∓x: w_2 = -w_1 = [0, h, 0, 1, 0, 0],
    # one mode, translation along x turning about y: ω² = 2k (1/m + h²/I_yy)
    m, I_yy = BOX
    for h in (0.0, 0.02, 0.04):
        p = np.array([[0.025, 0.0, h], [-0.025, 0.0, h]])
        n = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
        inertia = np.diag([I_yy, I_yy, 8.333333333333336e-05])
        got = _mode_period(np.full(2, K_PAIR), p, n, m, np.zeros(3), inertia)
        want = 2 * math.pi / math.sqrt(2 * K_PAIR * (1 / m + h * h / I_yy))
        assert got == pytest.approx(want, rel=1e-12)
    # at 40 mm off the middle it turns 1.6 times as fast as it slides
    translation = 2 * math.pi * math.sqrt(m / (2 * K_PAIR))
    assert translation / got == pytest.approx(math.sqrt(1 + 0.04**2 * m / I_yy))


@pytest.mark.parametrize("seed", range(5))
def test_the_generalized_eigensolver_agrees(seed):
    grasp = _random_grasp(np.random.default_rng(seed))
    assert _mode_period(*grasp) == pytest.approx(_by_scipy(*grasp), rel=1e-10)


@pytest.mark.parametrize("seed", range(5))
def test_a_rigid_motion_of_contacts_and_inertia_leaves_the_period(seed):
    rng = np.random.default_rng(seed)
    k, p, n, m, com, inertia = _random_grasp(rng)
    R = scipy.linalg.expm(np.cross(np.eye(3), rng.normal(size=3)))  # a rotation
    t = rng.normal(size=3)
    moved = _mode_period(k, p @ R.T + t, n @ R.T, m, R @ com + t, R @ inertia @ R.T)
    order = rng.permutation(len(k))
    permuted = _mode_period(k[order], p[order], n[order], m, com, inertia)
    base = _mode_period(k, p, n, m, com, inertia)
    assert moved == pytest.approx(base, rel=1e-10)
    assert permuted == pytest.approx(base, rel=1e-12)


@pytest.mark.parametrize("s", [1e-3, 0.25, 4.0, 1e4])
def test_stiffness_scaled_by_s_scales_the_period_by_one_over_its_root(s):
    k, p, n, m, com, inertia = _random_grasp(np.random.default_rng(7))
    base = _mode_period(k, p, n, m, com, inertia)
    assert _mode_period(s * k, p, n, m, com, inertia) == pytest.approx(
        base / math.sqrt(s), rel=1e-12
    )


def test_the_mode_is_never_slower_than_the_stiffest_translation():
    for seed in range(20):
        k, p, n, m, com, inertia = _random_grasp(np.random.default_rng(seed))
        translation = 2 * math.pi * math.sqrt(m / np.linalg.eigvalsh((n.T * k) @ n)[-1])
        assert _mode_period(k, p, n, m, com, inertia) <= translation * (1 + 1e-12)


def test_a_point_mass_has_the_period_of_its_translations():
    # no rotational inertia: its rotations have no period (Drake refuses to
    # simulate such a free body); they are held, and the translations count
    k, p, n, m, com, _ = _random_grasp(np.random.default_rng(3))
    translation = 2 * math.pi * math.sqrt(m / np.linalg.eigvalsh((n.T * k) @ n)[-1])
    for inertia in (np.zeros((3, 3)), np.full((3, 3), np.nan)):
        got = _mode_period(k, p, n, m, com, inertia)
        assert got == pytest.approx(translation, rel=1e-12)


def test_a_thin_rod_holds_the_turn_about_its_own_axis():
    # no inertia about z: the period is that of the five other modes with the
    # turn about z held (scipy on K and M without that row and column)
    k, p, n, m, com, _ = _random_grasp(np.random.default_rng(4))
    rod = np.diag([2e-4, 2e-4, 0.0])
    r = p - com
    w = np.hstack([np.cross(r, n), n])
    keep = [0, 1, 3, 4, 5]
    K = (w.T @ (k[:, None] * w))[np.ix_(keep, keep)]
    M = np.diag([2e-4, 2e-4, m, m, m])
    want = 2 * math.pi / math.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True)[-1])
    got = _mode_period(k, p, n, m, com, rod)
    assert 0 < got < math.inf
    assert got == pytest.approx(want, rel=1e-10)


def test_contacts_that_resist_nothing_have_no_period():
    p = np.array([[0.01, 0.0, 0.0]])
    n = np.array([[1.0, 0.0, 0.0]])
    assert _mode_period(np.zeros(1), p, n, 0.1, np.zeros(3), np.eye(3)) == math.inf


@pytest.fixture(scope="module")
def box_plant(drake_models_dir):
    """The WSG-50 and the shipped box in a finalized plant, and a candidate."""
    scene = planning_scene(
        "package://drakegrasp/objects/box.sdf", models_dir=drake_models_dir
    )
    result = plan_grasps(
        scene.plant, scene.context, scene.object_body, hand=scene.hand,
        num_candidates=30, mu=1.0, seed=0,
    )  # fmt: skip
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=1e-3)
    scene.add_models(plant, new_parser(plant, "test"))
    plant.Finalize()
    diagram = builder.Build()
    ctx = plant.GetMyContextFromRoot(diagram.CreateDefaultContext())
    inspector = plant.get_geometry_query_input_port().Eval(ctx).inspector()
    body = plant.GetBodyByName("box")
    return plant, inspector, body, result[0]


def test_the_plants_period_is_the_hand_computed_one(box_plant):
    # two contacts 30 mm off the box's middle, on the WSG-50's two fingers
    plant, inspector, body, candidate = box_plant
    h = 0.03
    left, right = (
        next(c for c in candidate.contacts if c.finger_body.endswith(side))
        for side in ("left_finger", "right_finger")
    )
    contacts = (
        dataclasses.replace(left, p_OC=np.array([-0.025, 0.0, h]),
                            nhat_O=np.array([1.0, 0.0, 0.0])),
        dataclasses.replace(right, p_OC=np.array([0.025, 0.0, h]),
                            nhat_O=np.array([-1.0, 0.0, 0.0])),
    )  # fmt: skip
    held = dataclasses.replace(candidate, contacts=contacts)
    m, I_yy = BOX
    want = 2 * math.pi / math.sqrt(2 * K_PAIR * (1 / m + h * h / I_yy))
    assert contact_period(plant, inspector, body, held, m) == pytest.approx(
        want, rel=1e-9
    )
    # the inertia given is the one counted: twice the mass, twice as slow
    # in every mode, the same shape of inertia
    assert contact_period(plant, inspector, body, held, 4 * m) == pytest.approx(
        2 * want, rel=1e-9
    )


def test_the_plants_period_agrees_with_scipy_on_a_planned_grasp(box_plant):
    plant, inspector, body, candidate = box_plant
    p = np.array([c.p_OC for c in candidate.contacts])
    n = np.array([c.nhat_O for c in candidate.contacts])
    inertia = body.default_spatial_inertia().CalcRotationalInertia()
    want = _by_scipy(
        np.full(len(p), K_PAIR), p, n, BOX[0], np.zeros(3),
        inertia.CopyToFullMatrix3(),
    )  # fmt: skip
    assert contact_period(plant, inspector, body, candidate, BOX[0]) == (
        pytest.approx(want, rel=1e-9)
    )
    # a point mass at its centre of mass (an inertia given): its translations
    point = SpatialInertia(BOX[0], np.zeros(3), UnitInertia(0.0, 0.0, 0.0))
    translation = (
        2 * math.pi * math.sqrt(BOX[0] / np.linalg.eigvalsh(K_PAIR * n.T @ n)[-1])
    )
    assert contact_period(
        plant, inspector, body, candidate, BOX[0], M_BBo_B=point
    ) == pytest.approx(translation, rel=1e-12)


@pytest.mark.parametrize("mass", [0.0, -1.0, math.nan, math.inf])
def test_a_mass_that_is_no_finite_positive_number_is_refused(box_plant, mass):
    plant, inspector, body, candidate = box_plant
    with pytest.raises(InvalidOptionError, match="mass must be a finite number > 0"):
        contact_period(plant, inspector, body, candidate, mass)


@pytest.mark.parametrize(
    "edit",
    [
        {"nhat_O": np.full(3, np.nan)},
        {"p_OC": np.array([np.inf, 0.0, 0.0])},
        {"p_OC": np.zeros(2)},
    ],
)
def test_a_contact_that_is_no_finite_point_and_normal_has_no_period(box_plant, edit):
    # was numpy's LinAlgError ("Eigenvalues did not converge") out of
    # shake_test for a parallel jaw; the shake refuses such a contact where
    # it presses with it (the default squeeze of a turning finger)
    plant, inspector, body, candidate = box_plant
    first = dataclasses.replace(candidate.contacts[0], **edit)
    bad = dataclasses.replace(candidate, contacts=(first, *candidate.contacts[1:]))
    assert contact_period(plant, inspector, body, bad, BOX[0]) == math.inf
