r"""Vectorised contact frames, grasp matrices and friction-cone facets (numpy only).

The single-grasp path builds one :class:`~drakegrasp.Grasp` at a time; here the
same objects are built for a stack of ``K`` grasps with ``N`` contacts each, with
exactly the conventions of :mod:`drakegrasp.core.contact`,
:mod:`drakegrasp.core.grasp` and :mod:`drakegrasp.core.friction_cone`
(``docs/conventions.md``):

* contact frames come from :func:`drakegrasp.contact_frames` (same ``t1``);
* ``G_i = [R_i; S(c_i - p) R_i]`` restricted to the contact's *effective*
  components, a soft finger adding the column ``[0; n_i]``;
* facet rows are unit rows positive on the cone axis, ``∝ s_k × s_{k+1}`` for a
  spatial hard finger with the generators
  ``s_k = [1, μ cos(2πk/n_g), μ sin(2πk/n_g)]``.

Every contact gets a *kind*, the set of force components its cone lets be
non-zero (a hard finger with ``μ = 0`` is frictionless, exactly as
:meth:`drakegrasp.Contact.effective_components`).  Grasps whose contacts have the
same kinds share one *layout* and are processed together.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.batch.build.kinds import (
    FRICTIONLESS,
    KIND_COMPONENTS,
    PLANAR_HARD,
    SOFT_FULL,
    SOFT_TORSION,
    SPATIAL_HARD,
)
from drakegrasp.core.contact import ContactModel, contact_frames
from drakegrasp.core.deprecation import renamed_keyword
from drakegrasp.core.friction_cone import soft_finger_facets, torsion_only_facets
from drakegrasp.core.validation import LENGTH_MIN, safe_norm

__all__ = [
    "KIND_COMPONENTS",
    "batched_characteristic_lengths",
    "batched_grasp_matrix",
    "batched_normal_grasp_matrix",
    "contact_kinds",
    "kind_facets",
]


@renamed_keyword("model", "contact_model")
def contact_kinds(
    mu: np.ndarray, torsional_friction: np.ndarray, *, contact_model: str, dim: int
) -> np.ndarray:
    """Kind code of every contact from its model and coefficients.

    Parameters
    ----------
    mu, torsional_friction : (K, N) float
        Friction coefficients ``μ >= 0`` and ``ν >= 0``.
    contact_model : ContactModel or str
        ``"frictionless"``, ``"hard_finger"`` or ``"soft_finger"``, read as
        :meth:`ContactModel.parse <drakegrasp.ContactModel.parse>` reads it.
    dim : {2, 3}

    Returns
    -------
    kinds : (K, N) int8
        Codes ``FRICTIONLESS`` … ``SOFT_FULL``; see ``KIND_COMPONENTS``.
    """
    contact_model = ContactModel.parse(contact_model).value
    shape = np.shape(mu)
    if contact_model == "frictionless":
        return np.full(shape, FRICTIONLESS, dtype=np.int8)
    friction = mu > 0.0
    if dim == 2:  # soft fingers are rejected upstream in the plane
        return np.where(friction, PLANAR_HARD, FRICTIONLESS).astype(np.int8)
    kinds = np.where(friction, SPATIAL_HARD, FRICTIONLESS).astype(np.int8)
    if contact_model == "soft_finger":
        torsion = torsional_friction > 0.0
        kinds[torsion & friction] = SOFT_FULL
        kinds[torsion & ~friction] = SOFT_TORSION
    return kinds


def batched_characteristic_lengths(
    positions: np.ndarray, reference_points: np.ndarray
) -> np.ndarray:
    """Default characteristic length ``b`` of each grasp, as :class:`Grasp` does.

    Parameters
    ----------
    positions : (K, N, d) float
        Contact points, metres.
    reference_points : (K, d) float
        Reference points ``p``, metres.

    Returns
    -------
    b : (K,) float
        Largest ``‖c_i - p‖``; 1 m when every contact sits at ``p`` (below
        the smallest valid length, ``LENGTH_MIN``).
    """
    offsets = positions - reference_points[:, None, :]
    b = np.linalg.norm(offsets, axis=-1).max(axis=1)
    tiny = b < 1e-150  # squares may have underflowed: a scaled norm, as Grasp's
    if np.any(tiny):
        b[tiny] = safe_norm(offsets[tiny], axis=-1).max(axis=1)
    return np.where(b >= LENGTH_MIN, b, 1.0)


def _wrench_columns(r: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Wrenches ``[u; r × u]`` (planar ``[u; r_x u_y - r_y u_x]``).

    ``r`` (..., d) lever arms and ``u`` (..., d) force directions; returns
    (..., 6) or (..., 3).
    """
    if r.shape[-1] == 2:
        m = r[..., 0] * u[..., 1] - r[..., 1] * u[..., 0]
        return np.concatenate([u, m[..., None]], axis=-1)
    return np.concatenate([u, np.cross(r, u)], axis=-1)


def batched_grasp_matrix(
    positions: np.ndarray,
    normals: np.ndarray,
    reference_points: np.ndarray,
    layout: tuple[int, ...],
) -> tuple[np.ndarray, np.ndarray]:
    """Effective grasp matrices of a stack of grasps sharing one layout.

    Parameters
    ----------
    positions : (K, N, d) float
        Contact points ``c_i``, metres, in the grasp frame.
    normals : (K, N, d) float
        Unit inward normals, in the grasp frame.
    reference_points : (K, d) float
        Points ``p`` about which moments are taken.
    layout : tuple of N kind codes
        Kind of each contact (see :func:`contact_kinds`).

    Returns
    -------
    G : (K, w, M) float
        ``w = 6`` (spatial) or 3 (planar); columns are the effective components
        of each contact in contact order (normal first), as in the single-grasp
        programs' restricted ``G``.
    normal_columns : (N,) int
        Column of each contact's ``f_n`` in ``G``.
    """
    K, N, d = positions.shape
    # Every frame column of every contact at once: U[k, i, j] = R_i e_j.
    U = np.swapaxes(contact_frames(normals), -1, -2)  # (K, N, d, d)
    r = (positions - reference_points[:, None, :])[:, :, None, :]
    w = 6 if d == 3 else 3
    width = 4 if d == 3 else d  # a soft finger's torsion column is component 3
    cols = np.zeros((K, N, width, w))
    cols[:, :, :d, :d] = U
    if d == 3:
        u0, u1, u2 = U[..., 0], U[..., 1], U[..., 2]
        r0, r1, r2 = r[..., 0], r[..., 1], r[..., 2]
        cols[:, :, :3, 3] = r1 * u2 - r2 * u1  # r × u, as np.cross
        cols[:, :, :3, 4] = r2 * u0 - r0 * u2
        cols[:, :, :3, 5] = r0 * u1 - r1 * u0
        cols[:, :, 3, 3:] = U[:, :, 0]  # soft finger: pure moment about n
    else:
        cols[:, :, :, 2] = r[..., 0] * U[..., 1] - r[..., 1] * U[..., 0]
    contact, component, normal_columns = [], [], []
    for i, kind in enumerate(layout):
        normal_columns.append(len(contact))
        for comp in KIND_COMPONENTS[kind]:
            contact.append(i)
            component.append(comp)
    G = np.swapaxes(cols[:, contact, component, :], 1, 2)
    return np.ascontiguousarray(G), np.array(normal_columns, dtype=int)


def batched_normal_grasp_matrix(
    positions: np.ndarray, normals: np.ndarray, reference_points: np.ndarray
) -> np.ndarray:
    """Normal grasp matrices ``G_n`` of a stack of grasps.

    Parameters
    ----------
    positions, normals : (K, N, d) float
        Contact points (metres) and unit inward normals, in the grasp frame.
    reference_points : (K, d) float

    Returns
    -------
    G_n : (K, w, N) float
        Column ``i`` is ``[n_i; (c_i - p) × n_i]``.
    """
    r = positions - reference_points[:, None, :]
    return np.swapaxes(_wrench_columns(r, normals), -1, -2)


def _two_sided(slope: np.ndarray) -> np.ndarray:
    """Facets ``[[a, 1], [a, -1]] / sqrt(1 + a²)`` of ``|x| <= a f_n``, (K, 2, 2)."""
    F = np.empty(slope.shape + (2, 2))
    F[..., 0] = slope[..., None]
    F[..., 0, 1] = 1.0
    F[..., 1, 1] = -1.0
    return F / np.sqrt(1.0 + slope**2)[..., None, None]


def _ring(mu: np.ndarray, num_generators: int) -> np.ndarray:
    """Ring generators ``[1, μ cos θ_k, μ sin θ_k]``, θ_k = 2πk/n_g: (K, n_g, 3)."""
    theta = 2.0 * np.pi * np.arange(1, num_generators + 1) / num_generators
    S = np.empty(mu.shape + (num_generators, 3))
    S[..., 0] = 1.0
    S[..., 1] = mu[..., None] * np.cos(theta)
    S[..., 2] = mu[..., None] * np.sin(theta)
    return S


def _unit_rows(F: np.ndarray) -> np.ndarray:
    return F / np.linalg.norm(F, axis=-1, keepdims=True)


def kind_facets(
    kind: int, mu: np.ndarray, torsion: np.ndarray | None, num_generators: int
) -> np.ndarray:
    """Unit facet rows of one contact's effective cone, for a stack of grasps.

    Parameters
    ----------
    kind : int
        Kind code of the contact.
    mu : (K,) float
        Friction coefficients.
    torsion : (K,) float or None
        ``b ν`` (metres), the soft-finger moment slope; ignored (may be None)
        for the other kinds.
    num_generators : int
        ``n_g`` of the spatial ring.

    Returns
    -------
    F : (K, r_i, k_i) float
        Rows over the kind's effective components, as
        :func:`drakegrasp.core.friction_cone.effective_cone` builds them.
    """
    K = mu.shape[0]
    if kind == FRICTIONLESS:
        return np.ones((K, 1, 1))
    if kind == PLANAR_HARD:
        return _two_sided(mu)
    if kind == SOFT_TORSION:
        # Soft-finger rows are defined once, in friction_cone (they are not
        # unit rows: a soft finger must never score below a hard one).
        return torsion_only_facets(torsion)
    if kind == SOFT_FULL:
        return soft_finger_facets(mu, torsion, num_generators)
    S = _ring(mu, num_generators)
    S_next = np.roll(S, -1, axis=-2)
    return _unit_rows(np.cross(S, S_next))
