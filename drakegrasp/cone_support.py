"""Support functions of the friction cones: ``max wᵀ G_i f_i`` with ``f_n = 1``.

Used to re-check an unresisted-wrench certificate without a solver
(:mod:`drakegrasp.certificate_check`) and to find one (:mod:`drakegrasp.witness`).
"""

from __future__ import annotations

import numpy as np

from drakegrasp.contact import ContactModel
from drakegrasp.friction_cone import ConeLayout
from drakegrasp.grasp import Grasp, grasp_matrix

__all__ = ["cone_support", "support_of"]


def cone_support(
    grasp: Grasp, w: np.ndarray, *, cones: str, num_generators: int = 8
) -> np.ndarray:
    r"""Per contact, the largest ``wᵀ G_i f_i`` over its cone with ``f_n = 1``.

    Parameters
    ----------
    grasp : Grasp
    w : (6,) or (3,) float
        A wrench-space direction (about ``p``, grasp frame).
    cones : {"normals", "polyhedral", "exact"}
        Frictionless normals, the polyhedral cones with ``num_generators``, or
        the exact Coulomb / soft-finger cones.
    num_generators : int, optional

    Returns
    -------
    (N,) float
        ``σ_i``: ``wᵀ G f <= 0`` on every cone exactly when ``max σ_i <= 0``.

    Notes
    -----
    With ``a = G_iᵀ w`` in the contact frame: frictionless ``a_n``; polyhedral
    ``max_k aᵀ s_k``; exact hard finger ``a_n + μ ‖a_t‖``; exact soft finger
    ``a_n + max(μ ‖a_t‖, b ν |a_m|)`` (the cone ``‖f_t‖/μ + |m_n|/(bν) <= f_n``
    has its extreme rays on the two norm balls).  Planar cones are exact
    polyhedra.
    """
    G = grasp_matrix(grasp)
    layout = ConeLayout.of(grasp, num_generators)
    b = grasp.characteristic_length
    out = np.empty(grasp.num_contacts)
    for i, (s, cone, c) in enumerate(
        zip(grasp.component_slices(), layout.cones, grasp.contacts, strict=True)
    ):
        a_full = G[:, s].T @ w
        if cones == "normals":
            out[i] = a_full[0]
        else:
            out[i] = support_of(a_full[list(cone.components)], cone, c, cones, b)
    return out


def support_of(a: np.ndarray, cone, contact, cones: str, b: float) -> float:
    """``max aᵀ f`` over one contact's cone with ``f_n = 1``.

    ``a`` is over the cone's components (``cone.components``); see
    :func:`cone_support` for the formulas.
    """
    if not (cones == "exact" and cone.components in ((0, 1, 2), (0, 1, 2, 3))):
        return float(np.max(cone.generators.T @ a))
    value = contact.mu * np.linalg.norm(a[1:3])
    if contact.model is ContactModel.SOFT_FINGER and len(a) == 4:
        value = max(value, b * contact.torsional_friction * abs(a[3]))
    return float(a[0] + value)
