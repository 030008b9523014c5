r"""Primitive wrenches of a stack of grasps, vectorised (numpy only).

The batch counterpart of :func:`drakegrasp.quality.primitive_wrenches`: the
wrench ``w_ik = S G_i s_k`` of every friction-cone generator ``s_k`` of every
contact, moments divided by the torque scale ``b``, with the frames of
:func:`drakegrasp.contact_frames` and the generators of
:mod:`drakegrasp.core.friction_cone` (``s_k = [1, μ cos(2πk/n_g), μ sin(2πk/n_g)]``,
a soft finger adding ``[1, 0, 0, ±b ν]``).

A stack needs one count of wrenches per contact, so contacts with fewer
generators than the largest repeat one of theirs: a frictionless contact (or
a hard finger with ``μ = 0``) repeats its normal wrench, a soft finger with
``ν = 0`` repeats its first ring generator and one with ``μ = 0`` its two
torsion generators.  Repeated points leave a convex hull unchanged.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.core.contact import ContactModel, contact_frames
from drakegrasp.core.deprecation import renamed_keyword

__all__ = ["batched_primitive_wrenches", "wrenches_per_contact"]


@renamed_keyword("model", "contact_model")
def wrenches_per_contact(contact_model: str, dim: int, num_generators: int) -> int:
    """Rows per contact of :func:`batched_primitive_wrenches`.

    ``1`` (frictionless), ``2`` (planar hard finger), ``n_g`` (spatial hard
    finger) or ``n_g + 2`` (soft finger).  ``contact_model`` is read as
    :meth:`ContactModel.parse <drakegrasp.ContactModel.parse>` reads it.
    """
    contact_model = ContactModel.parse(contact_model).value
    if contact_model == "frictionless":
        return 1
    if dim == 2:
        return 2
    return num_generators + (2 if contact_model == "soft_finger" else 0)


def _moments(r: np.ndarray, F: np.ndarray) -> np.ndarray:
    """``r × F`` for lever arms (k, N, 1, d) and forces (k, N, m, d)."""
    if r.shape[-1] == 2:
        return (r[..., 0] * F[..., 1] - r[..., 1] * F[..., 0])[..., None]
    rx, ry, rz = r[..., 0], r[..., 1], r[..., 2]
    fx, fy, fz = F[..., 0], F[..., 1], F[..., 2]
    return np.stack([ry * fz - rz * fy, rz * fx - rx * fz, rx * fy - ry * fx], -1)


@renamed_keyword("model", "contact_model")
def batched_primitive_wrenches(
    positions: np.ndarray,
    normals: np.ndarray,
    mu: np.ndarray,
    torsional_friction: np.ndarray,
    reference_points: np.ndarray,
    torque_scales: np.ndarray,
    *,
    contact_model: str,
    num_generators: int,
) -> np.ndarray:
    r"""Scaled primitive wrenches of ``k`` grasps of ``N`` contacts.

    Parameters
    ----------
    positions, normals : (k, N, d) float
        Contact points (metres) and unit inward normals, in the grasp frame.
    mu, torsional_friction : (k, N) float
        ``μ >= 0`` and ``ν >= 0`` (``ν`` is used by soft fingers only).
    reference_points : (k, d) float
        Points ``p`` about which moments are taken, metres.
    torque_scales : (k,) float
        ``b > 0`` metres: moments are divided by it, and a soft finger's
        torsion bound is ``b ν`` (the grasp's characteristic length).
    contact_model : {"frictionless", "hard_finger", "soft_finger"}
    num_generators : int
        ``n_g`` of each spatial cone.

    Returns
    -------
    W : (k, N m, w) float
        ``w = 6`` (spatial) or 3 (planar); rows ``i m … i m + m - 1`` are
        contact ``i``'s wrenches ``[f; (c_i - p) × f / b]`` in the order of
        :func:`drakegrasp.quality.primitive_wrenches`, padded by repetition to
        ``m`` (:func:`wrenches_per_contact`).

    Notes
    -----
    .. math:: w_{i,k} = \operatorname{diag}(I, I / b)\, G_i\, s_k
    """
    contact_model = ContactModel.parse(contact_model).value
    k, N, d = positions.shape
    m = wrenches_per_contact(contact_model, d, num_generators)
    R = contact_frames(normals)  # (k, N, d, d), columns n, t1 (, t2)
    n = R[..., 0]
    r = (positions - reference_points[:, None, :]) / torque_scales[:, None, None]
    mu_eff = np.zeros_like(mu) if contact_model == "frictionless" else mu
    if contact_model == "frictionless":
        F = n[:, :, None, :]
    elif d == 2:
        sign = np.array([1.0, -1.0])
        F = (
            n[:, :, None, :]
            + (mu_eff[..., None, None] * sign[:, None]) * R[:, :, None, :, 1]
        )
    else:
        theta = 2.0 * np.pi * np.arange(1, num_generators + 1) / num_generators
        F = n[:, :, None, :] + mu_eff[..., None, None] * (
            np.cos(theta)[:, None] * R[:, :, None, :, 1]
            + np.sin(theta)[:, None] * R[:, :, None, :, 2]
        )
    ring = np.concatenate([F, _moments(r[:, :, None, :], F)], axis=-1)
    if contact_model != "soft_finger":
        return np.ascontiguousarray(
            np.broadcast_to(ring, (k, N, m, ring.shape[-1])).reshape(k, N * m, -1)
        )
    W = np.empty((k, N, m, 2 * d))
    W[:, :, :num_generators] = ring
    # Torsion generators [1, 0, 0, ±b ν]: moments ±ν n after dividing by b.
    axis_w = np.concatenate([n, _moments(r, n)], axis=-1)  # (k, N, 6)
    torsion = torsional_friction[..., None] * n
    plus, minus = axis_w.copy(), axis_w.copy()
    plus[..., 3:] += torsion
    minus[..., 3:] -= torsion
    has_torsion = (torsional_friction > 0.0)[..., None]
    has_ring = (mu > 0.0)[..., None, None]
    W[:, :, num_generators] = np.where(has_torsion, plus, ring[:, :, 0])
    W[:, :, num_generators + 1] = np.where(has_torsion, minus, ring[:, :, 0])
    # Without friction the ring collapses onto the axis, between the two
    # torsion generators: repeat those instead (the axis is not a generator).
    only_torsion = ~has_ring & has_torsion[..., None]
    W[:, :, :num_generators] = np.where(
        only_torsion, plus[:, :, None, :], W[:, :, :num_generators]
    )
    return W.reshape(k, N * m, 2 * d)
