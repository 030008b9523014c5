"""Antipodal per finger for two-finger hands (issue 20, point 7).

The WSG-50's four tip spheres per finger and a flat pad's four corners gave
8 contacts and no antipodal answer.  Each finger's contacts now make a patch;
the best line between the patches is checked against a brute-force search
over the patches written here.
"""

from __future__ import annotations

import numpy as np
import pytest
from hand_models import Rig, box_object, mimic_gripper_urdf
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pydrake.math import RigidTransform

from drakegrasp import analyze_grasp, close_hand, is_antipodal
from drakegrasp.core.contact import Contact
from drakegrasp.plant import FingerAntipodal
from drakegrasp.plant.finger_antipodal import patch_line


def _angles(x1, x2, n1, n2):
    def angle(a, b):
        return np.arctan2(np.linalg.norm(np.cross(a, b)), a @ b)

    return angle(x2 - x1, n1), angle(x1 - x2, n2)


def _in_hull(x, points):
    """x is a convex combination of the points (least squares on the simplex)."""
    from scipy.optimize import nnls

    A = np.vstack([points.T, 1e3 * np.ones(len(points))])
    w, residual = nnls(A, np.r_[x, 1e3])
    return residual < 1e-9


@settings(derandomize=True, max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**31),
    k1=st.integers(1, 4),
    k2=st.integers(1, 4),
    tilt=st.floats(0.0, 0.6),
)
def test_the_best_line_beats_every_sampled_line(seed, k1, k2, tilt):
    rng = np.random.default_rng(seed)
    n1 = np.array([0.0, 0.0, 1.0])
    n2 = np.array([np.sin(tilt), 0.0, -np.cos(tilt)])
    P1 = rng.normal(0, 0.01, (k1, 3)) + [0, 0, -0.03]
    P2 = rng.normal(0, 0.01, (k2, 3)) + rng.normal(0, 0.01, 3) + [0, 0, 0.03]
    x1, x2 = patch_line(P1, n1, P2, n2)
    assert _in_hull(x1, P1) and _in_hull(x2, P2)
    best = max(_angles(x1, x2, n1, n2))
    # Half the samples spread over the patches, half near their edges and
    # corners (a sparse Dirichlet), where the best line of two polygons lies.
    W1 = np.vstack([rng.dirichlet(np.ones(k1), 10000),
                    rng.dirichlet(np.full(k1, 0.1), 10000)])  # fmt: skip
    W2 = np.vstack([rng.dirichlet(np.ones(k2), 10000),
                    rng.dirichlet(np.full(k2, 0.1), 10000)])  # fmt: skip
    D = W2 @ P2 - W1 @ P1
    corners = (P2[None, :, :] - P1[:, None, :]).reshape(-1, 3)
    D = np.vstack([D, corners])
    a1 = np.arctan2(np.linalg.norm(np.cross(D, n1), axis=1), D @ n1)
    a2 = np.arctan2(np.linalg.norm(np.cross(-D, n2), axis=1), -D @ n2)
    sampled = np.maximum(a1, a2).min()
    assert best <= sampled + 1e-9
    assert sampled - best < 0.05  # the samples come close to the exact optimum
    if k1 == k2 == 1:  # single contacts: the two-contact test itself
        pair = is_antipodal([Contact(P1[0], n1), Contact(P2[0], n2)], mu=0.5)
        np.testing.assert_allclose(_angles(x1, x2, n1, n2), pair.angles, atol=1e-15)


def test_mirror_symmetric_patches_have_equal_angles():
    P1 = np.array([[-0.01, -0.01, -0.03], [0.01, -0.01, -0.03], [0.0, 0.01, -0.03]])
    mirror = np.diag([1.0, 1.0, -1.0])
    P2 = (P1 + [0.02, 0.0, 0.0]) @ mirror
    n1 = np.array([np.sin(0.2), 0.0, np.cos(0.2)])
    n2 = mirror @ n1
    x1, x2 = patch_line(P1, n1, P2, n2)
    a1, a2 = _angles(x1, x2, n1, n2)
    assert a1 == pytest.approx(a2, abs=1e-12)


def _gripper(y=0.0, yaw=0.0):
    from pydrake.math import RollPitchYaw

    rig = Rig(
        [(mimic_gripper_urdf(), "urdf"), (box_object(), "sdf")],
        "box",
        RigidTransform(RollPitchYaw(0, 0, yaw), [0.0, y, 0.05]),
        weld_hand="palm",
    )
    close_hand(rig.plant, rig.ctx, rig.object, hand=rig.hand)
    return rig


def test_flat_pads_are_antipodal_per_finger():
    rig = _gripper()
    report = analyze_grasp(rig.plant, rig.ctx, rig.object, hand=rig.hand, mu=0.3)
    assert report.grasp.num_contacts == 8  # four patch corners per pad
    anti = report.antipodal
    assert isinstance(anti, FingerAntipodal)
    assert anti.fingers == ("mimic_gripper::left_jaw", "mimic_gripper::right_jaw")
    assert [len(c) for c in anti.contacts] == [4, 4]
    assert anti.is_antipodal
    np.testing.assert_allclose(anti.angles, 0.0, atol=1e-12)
    assert "antipodal (per finger): YES" in str(report)
    assert anti.to_dict()["is_antipodal"] is True


def test_one_touching_jaw_is_an_answer():
    rig = _gripper(y=0.004)
    report = analyze_grasp(rig.plant, rig.ctx, rig.object, hand=rig.hand, mu=0.3)
    anti = report.antipodal
    assert isinstance(anti, FingerAntipodal) and not anti.is_antipodal
    assert anti.result is None
    assert "only mimic_gripper::right_jaw touches" in str(report)


@settings(
    derandomize=True,
    max_examples=6,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(yaw=st.floats(-0.3, 0.3), x=st.floats(-0.02, 0.02))
def test_the_wsg_always_answers(real_hands, yaw, x):
    from pydrake.math import RollPitchYaw

    R = RollPitchYaw(np.pi / 2, yaw, np.pi / 2).ToRotationMatrix()
    scene = real_hands.wsg(X_WO=RigidTransform(R, [x, 0.09, 0.0]))
    close_hand(scene.plant, scene.ctx, scene.object, hand=scene.hand)
    report = analyze_grasp(
        scene.plant, scene.ctx, scene.object, hand=scene.hand, mu=0.5
    )
    assert report.antipodal is not None
    assert "antipodal" in str(report)
    if report.grasp.num_contacts > 2 and report.antipodal.result is not None:
        anti = report.antipodal
        # The best line ends on each finger's patch and its angles are its own.
        for ends, group in zip(anti.p_O, anti.contacts, strict=True):
            points = np.array([report.contacts[i].p_OC for i in group])
            assert _in_hull(ends, points)
        a = _angles(*anti.p_O, *anti.nhat_O)
        np.testing.assert_allclose(a, anti.angles, atol=1e-12)
