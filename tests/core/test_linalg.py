"""core.linalg's rotations against an independent route (scipy's rotation vectors)."""

import numpy as np
from scipy.spatial.transform import Rotation

from drakegrasp.core.linalg import rotations_about


def test_rotations_about_agree_with_scipy_and_are_rotations():
    rng = np.random.default_rng(7)
    axes = rng.normal(size=(50, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = rng.uniform(-np.pi, np.pi, 50)
    R = rotations_about(axes, angles)
    ref = Rotation.from_rotvec(axes * angles[:, None]).as_matrix()
    np.testing.assert_allclose(R, ref, atol=1e-14)
    identity = np.broadcast_to(np.eye(3), R.shape)
    np.testing.assert_allclose(R @ np.swapaxes(R, -1, -2), identity, atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-14)
    # Batched shapes: (2, 25) axes and angles give (2, 25, 3, 3), the same values.
    batched = rotations_about(axes.reshape(2, 25, 3), angles.reshape(2, 25))
    np.testing.assert_array_equal(batched.reshape(50, 3, 3), R)
