"""Rank, row spaces and null spaces: the linear algebra every verdict rests on.

All of it is the singular value decomposition with one relative threshold
(:data:`~drakegrasp.core.tolerances.DEFAULT_RANK_TOL`): a singular value counts
when it exceeds ``rank_tol * σ_max``.  Balance matrices are *equilibrated*
(columns scaled to unit length) before their rank is read, so a variable's unit
(a soft finger's torsional moment in N·m beside forces in N) never decides what
counts as zero; scaling columns changes neither the rank nor, pulled back, the
null space.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.tolerances import DEFAULT_RANK_TOL
from drakegrasp.core.validation import check_rank_tol, real_array, safe_norm
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "FULL_SVD_MAX_COLUMNS",
    "ZERO_COLUMN",
    "equilibrated",
    "left_null_space",
    "matrix_rank",
    "rotations_about",
    "row_space",
    "unit_columns",
]

ZERO_COLUMN = 1e-12
"""Relative norm below which :func:`unit_columns` drops a column as zero."""

FULL_SVD_MAX_COLUMNS = 64
"""Columns up to which an SVD computes the full square factor.

Up to it (21 hard fingers, 16 soft) the full factor keeps LAPACK on the path
every recorded d* was computed with (the thin path differs in the last bits,
up to 5.5e-11 on seeded grasps).  Beyond it the thin factor is taken: the full
one costs n² (measured on 6 x n: 0.54 ms against 0.048 ms at n = 192, 29 ms
against 0.14 ms at 768) and a full ``V`` of a 6 x 30,000 matrix is 7.2 GB.
"""


@checked_call
def matrix_rank(A: np.ndarray, *, rank_tol: float = DEFAULT_RANK_TOL) -> int:
    """Numerical rank: singular values above ``rank_tol * σ_max``.

    Parameters
    ----------
    A : (m, n) float
    rank_tol : float, optional
        Relative threshold on the singular values.

    Returns
    -------
    int

    Raises
    ------
    InvalidOptionError
        ``A`` not a real finite 2-D array (LAPACK's SVD can loop forever on
        ``inf``/``NaN``), or ``rank_tol`` outside its valid range.
    """
    A = real_array("A", A, error=InvalidOptionError)
    if A.ndim != 2 or not np.all(np.isfinite(A)):
        raise InvalidOptionError(
            f"matrix_rank needs a finite 2-D array, got shape {A.shape}"
            + ("" if A.ndim != 2 else " with non-finite entries")
        )
    rank_tol = check_rank_tol(rank_tol)
    if A.size == 0:
        return 0
    s = np.linalg.svd(A, compute_uv=False)
    if s[0] == 0.0:
        return 0
    return int(np.sum(s > rank_tol * s[0]))


def equilibrated(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``A diag(scale)`` with unit columns, and ``scale`` (zero columns kept).

    Parameters
    ----------
    A : (..., m, n) float
        A finite real matrix, or a stack of matrices (each scaled on its own).

    Returns
    -------
    A_s : (..., m, n) float
        ``A`` with every non-zero column scaled to unit length.
    scale : (..., n) float
        ``1 / ‖A_j‖`` per column (1 for a zero column; ``inf`` for a column
        whose norm is subnormal, below 2.2e-308, whose reciprocal no double
        holds: ``A_s`` still has it as a unit column, as it has a column whose
        norm exceeds the largest double).

    Raises
    ------
    InvalidOptionError
        ``A`` not a real array of at least two dimensions, or not finite.
    """
    A = real_array("A", A, error=InvalidOptionError)
    if A.ndim < 2:
        raise InvalidOptionError(
            f"equilibrated needs a matrix or a stack of matrices, got shape {A.shape}"
        )
    if A.size == 0:
        return A.copy(), np.ones(A.shape[:-2] + A.shape[-1:])
    # The norm of each column divided by its largest |entry| first (safe_norm):
    # a soft finger's torsion column of a grasp 1e-168 m across holds
    # 1/spread ~ 1e168, whose square overflows the plain norm to inf.
    peak = np.max(np.abs(A), axis=-2)
    if not np.all(np.isfinite(peak)):
        raise InvalidOptionError("equilibrated needs a finite matrix, got inf or NaN")
    norms = safe_norm(A, axis=-2)
    scale = np.ones_like(norms)
    with np.errstate(over="ignore", divide="ignore"):
        np.divide(1.0, norms, out=scale, where=norms > 0.0)
    A_s = A * scale[..., None, :]
    # A subnormal column (1/norm overflows) or one whose norm exceeds the
    # largest double (its scale underflowed to 0): scaled in two steps instead.
    odd = np.isinf(scale) | np.isinf(norms)
    if odd.any():
        reduced = A / np.where(odd, peak, 1.0)[..., None, :]
        length = np.linalg.norm(reduced, axis=-2)
        with np.errstate(over="ignore", under="ignore"):
            two_step = (1.0 / np.where(odd, peak, 1.0)) / length
        scale = np.where(odd, two_step, scale)
        A_s = np.where(odd[..., None, :], reduced / length[..., None, :], A_s)
    return A_s, scale


def row_space(A: np.ndarray, rank_tol: float = DEFAULT_RANK_TOL) -> np.ndarray:
    """Orthonormal basis (rows) of the numerical row space of ``A``.

    Parameters
    ----------
    A : (m, n) float
    rank_tol : float, optional

    Returns
    -------
    (r, n) float
        The right singular vectors whose singular values exceed
        ``rank_tol σ_max`` (``r = 0`` for a zero matrix).
    """
    # The full factor's LAPACK path for the usual small grasps (its bits are
    # the ones every verdict was recorded with); the thin one past
    # FULL_SVD_MAX_COLUMNS, where the n x n factor would take gigabytes.
    _, s, vt = np.linalg.svd(A, full_matrices=A.shape[-1] <= FULL_SVD_MAX_COLUMNS)
    if s.size == 0 or s[0] == 0.0:
        return np.zeros((0, A.shape[1]))
    return vt[: int(np.sum(s > rank_tol * s[0]))]


def left_null_space(
    A: np.ndarray,
    *,
    rank: int | None = None,
    rank_tol: float = DEFAULT_RANK_TOL,
    equilibrate: bool = False,
) -> np.ndarray:
    """Orthonormal basis (columns) of the numerical left null space ``N(Aᵀ)``.

    Parameters
    ----------
    A : (m, n) float
    rank : int, optional
        The rank to use; by default the number of singular values above
        ``rank_tol σ_max``.
    rank_tol : float, optional
        Relative threshold when ``rank`` is not given.
    equilibrate : bool, optional
        Scale ``A``'s columns to unit length first (:func:`equilibrated`): the
        same null space, read without regard to the columns' units.

    Returns
    -------
    (m, m - rank) float
        The left singular vectors beyond the rank; the identity when ``A`` has
        no columns.
    """
    if A.shape[1] == 0:
        return np.eye(A.shape[0])
    if equilibrate:
        A = equilibrated(A)[0]
    u, s, _ = np.linalg.svd(A)
    if rank is None:
        rank = int(np.sum(s > rank_tol * s[0])) if s.size and s[0] > 0 else 0
    return u[:, rank:]


def unit_columns(J: np.ndarray) -> np.ndarray:
    """``J`` with its columns scaled to unit length, numerically zero ones dropped.

    ``N(Jᵀ)`` is unchanged (each row of ``Jᵀ`` is only rescaled), but a joint
    measured in other units, or a Jacobian scaled by 1e9, no longer decides which
    singular values of ``[G; Jᵀ]`` count as zero.  A column below
    :data:`ZERO_COLUMN` times the largest (a joint that moves no contact, up to
    round-off) is dropped rather than blown up to a spurious constraint.

    Parameters
    ----------
    J : (m, n) float

    Returns
    -------
    (m, k) float, k <= n
    """
    # A scaled norm: at |J_ij| ~ 1e-200 the squares underflow and every
    # joint was dropped.
    norms = safe_norm(J, axis=0) if J.size else np.zeros(J.shape[1])
    if norms.size == 0 or not norms.max() > 0.0:
        return J[:, :0]
    keep = norms > ZERO_COLUMN * norms.max()
    return J[:, keep] / norms[keep]


def rotations_about(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rotation matrices about unit axes by angles (Rodrigues' formula).

    Parameters
    ----------
    axes : (..., 3) float
        Unit rotation axes.
    angles : (...) float
        Angles, radians, right-handed about each axis.

    Returns
    -------
    R : (..., 3, 3) float
        ``I + sin θ K + (1 - cos θ) K²`` with ``K`` the cross-product matrix of
        the axis.
    """
    x, y, z = axes[..., 0], axes[..., 1], axes[..., 2]
    zero = np.zeros_like(x)
    K = np.stack(
        [
            np.stack([zero, -z, y], -1),
            np.stack([z, zero, -x], -1),
            np.stack([-y, x, zero], -1),
        ],
        -2,
    )
    s, c = np.sin(angles)[..., None, None], np.cos(angles)[..., None, None]
    return np.eye(3) + s * K + (1 - c) * (K @ K)
