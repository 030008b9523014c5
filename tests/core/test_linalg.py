"""core.linalg against independent routes (scipy's rotation vectors, norms)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import drakegrasp as dg
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


def test_equilibrated_gives_unit_columns_keeps_zero_ones_and_stacks():
    from drakegrasp.core.linalg import equilibrated

    rng = np.random.default_rng(3)
    A = rng.normal(size=(6, 5)) * np.array([1e-150, 1.0, 1e160, 0.0, 3.0])
    A_s, scale = equilibrated(A)
    norms = np.linalg.norm(A_s, axis=0)
    np.testing.assert_allclose(norms[[0, 1, 2, 4]], 1.0, rtol=1e-14)
    assert norms[3] == 0.0 and scale[3] == 1.0
    np.testing.assert_allclose(A_s, A * scale, rtol=0, atol=0)
    # a stack is each matrix on its own, bit for bit
    stack = rng.normal(size=(4, 6, 5)) * rng.uniform(1e-3, 1e3, size=(4, 1, 5))
    S, scales = equilibrated(stack)
    for k in range(4):
        one, s_one = equilibrated(stack[k])
        np.testing.assert_array_equal(S[k], one)
        np.testing.assert_array_equal(scales[k], s_one)
    empty, s_empty = equilibrated(np.zeros((3, 0, 4)))
    assert empty.shape == (3, 0, 4) and np.all(s_empty == 1.0)


@pytest.mark.parametrize(
    ("A", "message"),
    [
        (np.array([1.0, 2.0]), "shape"),
        (np.float64(1.0), "shape"),
        (np.array([[np.inf, 1.0], [0.0, 1.0]]), "finite"),
        (np.array([[np.nan, 1.0], [0.0, 1.0]]), "finite"),
        (np.array([[1j, 1.0], [0.0, 1.0]]), "complex"),
        ("matrix", "real"),
    ],
)
def test_equilibrated_refuses_what_is_not_a_finite_real_matrix(A, message):
    from drakegrasp.core.linalg import equilibrated

    with pytest.raises(dg.InvalidOptionError, match=message):
        equilibrated(A)


@pytest.mark.parametrize("tiny", [1e-310, 5e-324])
def test_equilibrated_keeps_a_subnormal_column_a_unit_column(tiny):
    from drakegrasp.core.linalg import equilibrated

    with np.errstate(over="raise", invalid="raise", divide="raise"):
        A_s, scale = equilibrated(np.array([[tiny, 0.0], [tiny, 2.0]]))
    np.testing.assert_allclose(A_s, [[2**-0.5, 0.0], [2**-0.5, 1.0]], rtol=1e-15)
    assert scale[0] == np.inf and scale[1] == 0.5  # 1/|col| holds in no double
    lists, _ = equilibrated([[3.0, 0.0], [4.0, 1.0]])  # a nested list is a matrix
    np.testing.assert_allclose(lists, [[0.6, 0.0], [0.8, 1.0]], rtol=1e-15)


def test_row_space_of_a_wide_matrix_needs_no_square_factor():
    from drakegrasp.core.linalg import row_space

    rng = np.random.default_rng(0)
    A = rng.normal(size=(6, 4)) @ rng.normal(size=(4, 30_000))  # rank 4
    R = row_space(A)  # a full V would be 30,000 x 30,000: 7.2 GB
    assert R.shape == (4, 30_000)
    np.testing.assert_allclose(R @ R.T, np.eye(4), atol=1e-12)
    np.testing.assert_allclose(A @ R.T @ R, A, atol=1e-9 * np.abs(A).max())
