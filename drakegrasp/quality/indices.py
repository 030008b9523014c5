r"""Singular-value indices of the grasp matrix ``G`` and of ``H = (G^+)^T J``."""

from __future__ import annotations

import math

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.grasp import Grasp, check_hand_jacobian
from drakegrasp.quality._common import (
    RANK_TOL,
    _check_grasp,
    _metric_grasp_matrix,
    _padded_singular_values,
    _torque_scale,
    _torsion_columns,
)

__all__ = [
    "distance_to_singularity",
    "grasp_singular_values",
    "hand_object_matrix",
    "hand_object_singular_values",
    "isotropy",
    "manipulability_volume",
    "min_singular_value",
    "uniformity_of_transformation",
    "wrench_ellipsoid_volume",
]


@checked_call
def grasp_singular_values(
    grasp: Grasp, *, torque_scale: float | None = None
) -> np.ndarray:
    r"""Singular values of the torque-scaled grasp matrix ``Ĝ = T G S``.

    Parameters
    ----------
    grasp : Grasp
    torque_scale : float, optional
        Length ``b_s`` (metres) dividing the moment rows (and measuring a
        soft finger's torsional moment, see Notes); default the grasp's
        characteristic length, ``1.0`` for the unscaled ``G``.
        An explicit length must be in ``[2.2e-308, 1e30]`` m with the grasp's
        extent (the largest distance from ``p`` to a contact) over it in
        ``[1e-4, 1e12]`` (any length when every contact is at ``p``), else
        :class:`~drakegrasp.InvalidOptionError`.

    Returns
    -------
    sigma : (6,) or (3,) float
        ``σ_1 >= … >= σ_D`` of ``Ĝ`` (``D`` = wrench dimension), zero-padded
        when ``G`` has fewer than ``D`` columns.  Dimensionless (newtons of
        scaled wrench per newton of contact force), so unchanged when the
        positions and ``b_s`` are given in another unit of length.

    Notes
    -----
    ``G`` is :func:`~drakegrasp.grasp_matrix` with every component of each
    contact model (a hard finger with ``mu = 0`` keeps its tangential columns:
    these indices describe the contact geometry, not friction).
    ``T = diag(I, I / b_s)`` divides the moment rows by ``b_s``; ``S`` is the
    identity but for each soft finger's torsional moment ``m_n``, an input in
    N·m, which it measures in units of ``b_s`` newtons (``m_n = b_s μ̃``): its
    column of ``Ĝ`` stays ``[0; n]``, where ``T G`` alone made it
    ``[0; n / b_s]``, in 1/m (:func:`~drakegrasp.core.grasp.scaled_for_metrics`;
    without soft fingers ``Ĝ = T G``).  The columns of ``Ĝ`` map orthonormal
    contact-frame components, so ``σ_i`` are the semi-axes of the wrench
    ellipsoid ``{Ĝ f̃ : ‖f̃‖ <= 1}`` (``f̃ = S^{-1} f``).
    """
    _check_grasp(grasp)
    b = _torque_scale(grasp, torque_scale)
    return _padded_singular_values(_metric_grasp_matrix(grasp, b))


@checked_call
def min_singular_value(grasp: Grasp, *, torque_scale: float | None = None) -> float:
    """Smallest singular value ``σ_min(Ĝ)``: the worst-direction wrench gain.

    The smallest wrench norm that a unit contact-force vector can produce in
    the least favourable direction; 0 when ``G`` is rank-deficient.  See
    :func:`grasp_singular_values` for ``Ĝ = T G S``, units and conventions.
    """
    return float(grasp_singular_values(grasp, torque_scale=torque_scale)[-1])


@checked_call
def isotropy(grasp: Grasp, *, torque_scale: float | None = None) -> float:
    """Grasp isotropy index ``σ_min(Ĝ) / σ_max(Ĝ)`` in ``[0, 1]``.

    1 when every wrench direction is produced equally well; 0 when ``G`` is
    rank-deficient.  Depends on the torque scale but not on the unit of
    length (soft fingers included); see :func:`grasp_singular_values`.
    """
    s = grasp_singular_values(grasp, torque_scale=torque_scale)
    return float(s[-1] / s[0]) if s[0] > 0 else 0.0


@checked_call
def wrench_ellipsoid_volume(
    grasp: Grasp, *, torque_scale: float | None = None
) -> float:
    r"""Volume index of the wrench ellipsoid: ``σ_1 σ_2 … σ_D = sqrt(det(Ĝ Ĝᵀ))``.

    The ellipsoid ``{Ĝ f̃ : ‖f̃‖ <= 1}`` (``Ĝ = T G S``) has semi-axes
    ``σ_i``, so its volume is ``V_D σ_1 … σ_D`` with ``V_D`` the volume of the
    unit ball (``π³/6`` in 6-D, ``4π/3`` in 3-D).  As in the grasp-quality
    literature the constant ``V_D`` is left out: the index is the product of
    the singular values (dimensionless; 0 when ``G`` is rank-deficient).  See
    :func:`grasp_singular_values` for the scaling (a soft finger's torsion
    column included).
    """
    return float(np.prod(grasp_singular_values(grasp, torque_scale=torque_scale)))


@checked_call
def hand_object_matrix(
    grasp: Grasp,
    hand_jacobian: np.ndarray,
    *,
    torque_scale: float | None = None,
) -> np.ndarray:
    r"""Hand-object matrix ``H = (Ĝ^+)^T S J``: hand velocities to object twist.

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_v) float
        Hand Jacobian ``J``: rows in the column order of ``G`` (contact-frame
        components, contact by contact), columns the hand's generalized
        velocities ``v``.
    torque_scale : float, optional
        Length ``b_s`` (metres); default the grasp's characteristic length,
        ``1.0`` for no scaling.
        An explicit length must be in ``[2.2e-308, 1e30]`` m with the grasp's
        extent (the largest distance from ``p`` to a contact) over it in
        ``[1e-4, 1e12]`` (any length when every contact is at ``p``), else
        :class:`~drakegrasp.InvalidOptionError`.

    Returns
    -------
    H : (6, n_v) or (3, n_v) float
        Maps ``v`` to the object twist ``[v; b_s ω]`` (planar
        ``[v_x, v_y, b_s ω]``) about ``p`` in the grasp frame: every row in
        metres per second per unit of ``v``.

    Notes
    -----
    The contact constraint (Prattichizzo & Trinkle, *Grasping*, Springer
    Handbook of Robotics) equates the contact velocities seen by the hand and
    by the object: ``J v = Gᵀ ν``.  Its least-squares solution for the twist
    is ``ν = (Gᵀ)^+ J v = (G^+)ᵀ J v``, and ``H = (G^+)ᵀ J`` is the matrix whose
    singular values give the hand-configuration indices of Roa & Suárez,
    *Grasp quality measures: review and performance* (Auton. Robots, 2015).
    With scaling (``Ĝ = T G S`` of :func:`grasp_singular_values`),
    ``S J v = S Gᵀ ν = Ĝᵀ (T^{-1} ν)``, so the twist becomes
    ``T^{-1} ν = [v; b_s ω]`` and a soft finger's row of ``J`` (its spin
    about the normal, rad/s) is multiplied by ``b_s``, into m/s as the other
    rows; without soft fingers ``S = I``.  The pseudo-inverse drops singular
    values below ``RANK_TOL σ_max``.
    """
    _check_grasp(grasp)
    J = check_hand_jacobian(grasp, hand_jacobian)
    b = _torque_scale(grasp, torque_scale)
    G = _metric_grasp_matrix(grasp, b)
    torsion = _torsion_columns(grasp)
    if torsion.size:  # S J: each soft finger's spin in m/s, as G's column
        J = J.copy()
        J[torsion] *= b
    G_pinv = np.linalg.pinv(G, rcond=RANK_TOL)
    return G_pinv.T @ J


@checked_call
def hand_object_singular_values(
    grasp: Grasp, hand_jacobian: np.ndarray, *, torque_scale: float | None = None
) -> np.ndarray:
    """Singular values ``σ_1 >= … >= σ_D`` of ``H`` (zero-padded to ``D`` rows).

    See :func:`hand_object_matrix`.  Units: metres per second of (scaled)
    object twist per unit of hand velocity.
    """
    return _padded_singular_values(
        hand_object_matrix(grasp, hand_jacobian, torque_scale=torque_scale)
    )


@checked_call
def distance_to_singularity(
    grasp: Grasp, hand_jacobian: np.ndarray, *, torque_scale: float | None = None
) -> float:
    """Distance from singular configurations: ``σ_min(H)`` (0 at a singularity).

    ``σ_min`` is the smallest of the ``D`` singular values of ``H``, so it is 0
    whenever the hand cannot move the object in some direction (including
    ``n_v < D``).  See :func:`hand_object_matrix`.
    """
    s = hand_object_singular_values(grasp, hand_jacobian, torque_scale=torque_scale)
    return float(s[-1])


@checked_call
def uniformity_of_transformation(
    grasp: Grasp, hand_jacobian: np.ndarray, *, torque_scale: float | None = None
) -> float:
    """Uniformity of transformation: ``σ_max(H) / σ_min(H) >= 1``; 1 is best.

    The condition number of ``H``; ``inf`` at a singular configuration.  See
    :func:`hand_object_matrix`.
    """
    s = hand_object_singular_values(grasp, hand_jacobian, torque_scale=torque_scale)
    return float(s[0] / s[-1]) if s[-1] > 0 else math.inf


@checked_call
def manipulability_volume(
    grasp: Grasp, hand_jacobian: np.ndarray, *, torque_scale: float | None = None
) -> float:
    r"""Manipulability-ellipsoid volume index ``σ_1 … σ_D = sqrt(det(H Hᵀ))``.

    The ellipsoid ``{H v : ‖v‖ <= 1}`` of object twists has volume
    ``V_D σ_1 … σ_D``; the unit-ball constant ``V_D`` is left out (as in
    :func:`wrench_ellipsoid_volume`).  0 at a singular configuration.  See
    :func:`hand_object_matrix`.
    """
    s = hand_object_singular_values(grasp, hand_jacobian, torque_scale=torque_scale)
    return float(np.prod(s))
