"""∂ψ/∂v and the hand Jacobian J against finite differences and the identity G_nᵀ."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.multibody.tree import JacobianWrtVariable

from drakegrasp.core.grasp import normal_grasp_matrix
from drakegrasp.plant import grasp_from_plant
from drakegrasp.plant.jacobians import PLANES
from drakegrasp.plant.scene import list_scenes

SCENE_NAMES = [info.name for info in list_scenes()]

# Central differences of ψ.  On the convex mesh, Drake's signed distance is
# noisy at the finite-difference scale (GJK: ~1e-5 m when separated; EPA: ~3e-9
# m when penetrating), so for that scene ψ is the exact sphere-to-prism
# distance: the fingertip centre's largest signed distance to the six side
# planes (30 + 60 k deg, 25 mm from the axis), minus the 10 mm tip radius.
HEX_NORMALS = np.array(
    [[np.cos(a), np.sin(a), 0.0] for a in np.radians(30.0 + 60.0 * np.arange(6))]
)


def _hex_psi(plant, ctx, contact, object_body):
    X_OW = plant.EvalBodyPoseInWorld(ctx, object_body).inverse()
    X_WF = plant.EvalBodyPoseInWorld(ctx, plant.get_body(contact.finger_body_index))
    centre = X_OW.multiply(X_WF.multiply([0.0, 0.0, 0.025]))  # distal tip centre
    return float(np.max(HEX_NORMALS @ centre - 0.025) - 0.01)


def _analysis(scene, **overrides):
    options = scene.analysis_options()
    options.update(overrides)
    return grasp_from_plant(scene.plant, scene.plant_context, **options)


def _contact_psi(plant, ctx, contact, object_body, n_O0):
    """ψ of one contact at the configuration in ``ctx``.

    A point contact: Drake's signed distance of its geometry pair.  A patch
    vertex: the gap, along the (object-fixed) normal, between the object-fixed
    point on the face and the finger-fixed corner point.
    """
    if object_body.name() == "hex_prism":
        return _hex_psi(plant, ctx, contact, object_body)
    if contact.patch_vertex is None:
        query = plant.get_geometry_query_input_port().Eval(ctx)
        return query.ComputeSignedDistancePairClosestPoints(
            contact.object_geometry, contact.finger_geometry
        ).distance
    X_WO = plant.EvalBodyPoseInWorld(ctx, object_body)
    finger = plant.get_body(contact.finger_body_index)
    X_WF = plant.EvalBodyPoseInWorld(ctx, finger)
    p_Ca = X_WO.multiply(contact.p_OC)
    p_Cb = X_WF.multiply(contact.p_FC)
    return float((X_WO.rotation().matrix() @ n_O0) @ (p_Ca - p_Cb))


@pytest.mark.parametrize("name", SCENE_NAMES)
def test_dpsi_dv_matches_finite_differences_through_the_qdot_map(
    scene_cache, tools, name
):
    scene = scene_cache(name)
    plant = scene.plant
    nv = plant.num_velocities()
    root0, ctx0 = tools.fresh_context(scene)
    data = grasp_from_plant(plant, ctx0, **scene.analysis_options())
    assert data.dpsi_dv.shape == (len(data.contacts), nv)
    for c in data.contacts:  # the independent ψ is zero where Drake says contact
        assert abs(_contact_psi(plant, ctx0, c, scene.object_body, c.nhat_O)) < 1e-6
    if scene.object_body.is_floating_base_body():
        assert plant.num_positions() == nv + 1  # quaternion: nq = 7, nv = 6
    eps = 1e-6
    fd = np.zeros_like(data.dpsi_dv)
    for k in range(nv):
        values = []
        for sign in (1.0, -1.0):
            ctx = plant.GetMyContextFromRoot(root := root0.Clone())
            dv = np.zeros(nv)
            dv[k] = sign * eps
            plant.SetPositions(ctx, tools.step_q(plant, ctx, dv))
            values.append(
                [
                    _contact_psi(plant, ctx, c, scene.object_body, c.nhat_O)
                    for c in data.contacts
                ]
            )
        del root
        fd[:, k] = (np.array(values[0]) - np.array(values[1])) / (2 * eps)
    np.testing.assert_allclose(data.dpsi_dv, fd, atol=1e-6)
    # Not a trivially-zero Jacobian: every contact moves with some velocity.
    assert np.all(np.abs(data.dpsi_dv).max(axis=1) > 0.1)


def _object_twist_jacobian(plant, ctx, body, plane):
    """Rows [v_O; ω] (spatial) or [v_a, v_b, ω_n] (planar), in frame O, per v."""
    Js = plant.CalcJacobianSpatialVelocity(
        ctx,
        JacobianWrtVariable.kV,
        body.body_frame(),
        np.zeros(3),
        plant.world_frame(),
        body.body_frame(),
    )  # Drake's order: [ω; v]
    T = np.vstack([Js[3:], Js[:3]])
    if plane is None:
        return T
    a, b = PLANES[plane]
    normal_axis = ({0, 1, 2} - {a, b}).pop()
    return T[[a, b, 3 + normal_axis]]


@pytest.mark.parametrize("name", SCENE_NAMES)
def test_object_columns_of_dpsi_dv_are_the_normal_grasp_matrix(scene_cache, name):
    scene = scene_cache(name)
    plant, ctx = scene.plant, scene.plant_context
    data = _analysis(scene)
    obj = np.setdiff1d(np.arange(plant.num_velocities()), data.hand_velocity_indices)
    assert obj.size == (3 if data.plane else 6)
    T = _object_twist_jacobian(plant, ctx, scene.object_body, data.plane)[:, obj]
    # The object's generalized velocities span every twist (T is invertible), and
    # ψ̇ = G_nᵀ [v_p; ω] with p the object's origin, in frame O.
    assert np.linalg.matrix_rank(T) == obj.size
    Gn = normal_grasp_matrix(data.grasp)
    np.testing.assert_allclose(data.dpsi_dv[:, obj], Gn.T @ T, atol=1e-9)


@pytest.mark.parametrize("name", SCENE_NAMES)
def test_hand_jacobian_matches_finite_differences_of_finger_points(
    scene_cache, tools, name
):
    scene = scene_cache(name)
    plant = scene.plant
    data = _analysis(scene)
    J, cols = data.hand_jacobian, data.hand_velocity_indices
    assert J.shape == (data.grasp.num_components, cols.size)
    eps = 1e-6
    fd = np.zeros_like(J)
    for j, k in enumerate(cols):
        positions = []
        for sign in (1.0, -1.0):
            root, ctx = tools.stepped_context(scene, k, sign * eps)
            X_OW = plant.EvalBodyPoseInWorld(ctx, scene.object_body).inverse()
            pts = []
            for c in data.contacts:
                X_WF = plant.EvalBodyPoseInWorld(
                    ctx, plant.get_body(c.finger_body_index)
                )
                pts.append(X_OW.multiply(X_WF.multiply(c.p_FC)))
            positions.append(np.array(pts))
        velocity = (positions[0] - positions[1]) / (2 * eps)  # (N, 3) in O
        rows = []
        for c, v in zip(data.grasp.contacts, velocity, strict=True):
            if data.plane is not None:
                v = v[list(PLANES[data.plane])]
            rows.append((c.frame.T @ v)[: c.num_components])
        fd[:, j] = np.concatenate(rows)
    np.testing.assert_allclose(J, fd, atol=1e-7)
    assert np.abs(J).max() > 0.02  # fingers do move their contact points


def test_soft_finger_row_is_the_finger_spin_about_the_normal(scene_cache, tools):
    scene = scene_cache("three_finger_sphere")
    plant = scene.plant
    data = _analysis(scene, contact_model="soft_finger")
    J, cols = data.hand_jacobian, data.hand_velocity_indices
    assert J.shape == (12, 9)
    eps = 1e-6
    for j, k in enumerate(cols):
        R = []
        for sign in (1.0, -1.0):
            root, ctx = tools.stepped_context(scene, k, sign * eps)
            R_OW = (
                plant.EvalBodyPoseInWorld(ctx, scene.object_body).rotation().inverse()
            )
            R.append(
                [
                    (
                        R_OW
                        @ plant.EvalBodyPoseInWorld(
                            ctx, plant.get_body(c.finger_body_index)
                        ).rotation()
                    ).matrix()
                    for c in data.contacts
                ]
            )
        for i, c in enumerate(data.contacts):
            W = (R[0][i] - R[1][i]) @ R[0][i].T / (2 * eps)  # ≈ skew(ω) in O
            omega = np.array([W[2, 1], W[0, 2], W[1, 0]])
            assert J[4 * i + 3, j] == pytest.approx(c.nhat_O @ omega, abs=1e-6)
    # The first three rows of each block equal the hard-finger Jacobian.
    hard = _analysis(scene).hand_jacobian
    keep = [r for r in range(12) if r % 4 != 3]
    np.testing.assert_allclose(J[keep], hard, atol=1e-12)


def test_frictionless_jacobian_keeps_the_normal_rows(scene_cache):
    scene = scene_cache("three_finger_sphere")
    hard = _analysis(scene).hand_jacobian
    frictionless = _analysis(scene, contact_model="frictionless").hand_jacobian
    np.testing.assert_allclose(frictionless, hard[::3], atol=1e-12)


def test_hand_columns_of_dpsi_dv_are_minus_the_normal_rows_of_J(scene_cache):
    # With the palm fixed, only the fingers move at the contacts in the hand
    # columns: ψ̇ = -nᵀ v_finger = -(normal row of J).
    for name in SCENE_NAMES:
        data = _analysis(scene_cache(name))
        normal_rows = data.hand_jacobian[data.grasp.normal_indices()]
        np.testing.assert_allclose(
            data.dpsi_dv[:, data.hand_velocity_indices], -normal_rows, atol=1e-12
        )
