"""Re-verify a :class:`~drakegrasp.certificates.Certificate` by direct evaluation.

Nothing here calls a solver: each witness is checked against its definition with
the grasp matrix and the cones (see :mod:`drakegrasp.certificates`), so a wrong
sign in a program, a dual, or a mapping between frames shows up as a violation.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from drakegrasp.certificate_kinds import (
    BALANCE,
    ESCAPE_TWIST,
    UNCONTROLLABLE,
    UNRESISTED_WRENCH,
    CertificateCheck,
)
from drakegrasp.cone_support import cone_support
from drakegrasp.contact import ContactModel
from drakegrasp.errors import InvalidOptionError
from drakegrasp.friction_cone import ConeLayout
from drakegrasp.grasp import (
    Grasp,
    check_hand_jacobian,
    grasp_matrix,
    normalised_grasp_matrix,
)

if TYPE_CHECKING:
    from drakegrasp.certificates import Certificate

__all__ = ["check_certificate"]

_RANK_TOL = 1e-9
"""Relative singular value of the full-rank check (the programs' default)."""


def check_certificate(
    cert: Certificate,
    grasp: Grasp,
    *,
    hand_jacobian: np.ndarray | None = None,
    tol: float,
) -> CertificateCheck:
    """See :meth:`drakegrasp.certificates.Certificate.check`."""
    if cert.kind == ESCAPE_TWIST:
        violation, slack, detail = _check_twist(cert, grasp)
    elif cert.kind == UNRESISTED_WRENCH:
        violation, slack, detail = _check_wrench(cert, grasp)
    elif cert.kind == UNCONTROLLABLE:
        J = _check_jacobian(grasp, hand_jacobian)
        violation, slack, detail = _check_uncontrollable(cert, grasp, J)
    else:
        assert cert.kind == BALANCE
        violation, slack, detail = _check_balance(cert, grasp)
    return CertificateCheck(
        holds=bool(violation <= tol),
        violation=float(violation),
        slack=float(slack),
        tol=float(tol),
        detail=detail,
    )


def _directions(cert: Certificate) -> list[np.ndarray]:
    out = [np.asarray(cert.direction, dtype=float)]
    if cert.two_sided:
        out += list(np.asarray(cert.null_basis, dtype=float).T)
    return out


def _check_twist(cert: Certificate, grasp: Grasp):
    G_n = grasp_matrix(grasp)[:, grasp.normal_indices()]
    col = np.linalg.norm(G_n, axis=0)
    violation, slack = 0.0, np.inf
    for v in _directions(cert):
        size = np.linalg.norm(v)
        if not size > 0.0:
            return np.inf, 0.0, "the twist is zero"
        rates = (G_n.T @ v) / (col * size)
        if cert.two_sided:  # both ±v escape: every contact slides
            violation = max(violation, float(np.max(np.abs(rates))))
            slack = 0.0
        else:
            violation = max(violation, float(max(0.0, -rates.min())))
            slack = min(slack, float(rates.min()))
    sides = "±v and the null basis" if cert.two_sided else "v"
    return violation, slack, f"G_nᵀ v >= 0 evaluated for {sides}"


def _check_wrench(cert: Certificate, grasp: Grasp):
    G = grasp_matrix(grasp)
    scale = np.linalg.norm(G, 2)
    ys = [np.asarray(cert.separating_twist, dtype=float)]
    ws = [np.asarray(cert.direction, dtype=float)]
    if cert.two_sided:
        ys += list(np.asarray(cert.separating_basis, dtype=float).T)
        ws += list(np.asarray(cert.null_basis, dtype=float).T)
    violation, slack = 0.0, np.inf
    for y, w in zip(ys, ws, strict=True):
        size = np.linalg.norm(y)
        if not (size > 0.0 and np.linalg.norm(w) > 0.0):
            return np.inf, 0.0, "the wrench or its hyperplane normal is zero"
        # the unresisted wrench lies strictly on the other side of the plane
        side = float(y @ w) / (size * np.linalg.norm(w))
        violation = max(violation, max(0.0, -side))
        for x in (y, -y) if cert.two_sided else (y,):
            sigma = cone_support(
                grasp, x, cones=cert.cones, num_generators=cert.num_generators
            )
            worst = float(sigma.max()) / (scale * size)
            violation = max(violation, max(0.0, worst))
            # both signs are witnesses: G_iᵀ y = 0, the slack is 0 by definition
            slack = 0.0 if cert.two_sided else min(slack, -worst)
    return (
        violation,
        slack,
        f"max over the {cert.cones} cones of yᵀ G f (f_n = 1), and yᵀ w > 0",
    )


def _relative_residual(A: np.ndarray, f: np.ndarray) -> float:
    scale = np.linalg.norm(A, 2) * np.linalg.norm(f)
    return float(np.linalg.norm(A @ f) / scale) if scale > 0 else 0.0


def _check_uncontrollable(cert: Certificate, grasp: Grasp, J: np.ndarray):
    f = cert.stacked_forces()
    G = grasp_matrix(grasp)
    f_n = f[grasp.normal_indices()]
    total = float(np.sum(np.abs(f_n)))
    if not total > 0.0:
        return np.inf, 0.0, "the internal force is zero"
    res = max(_relative_residual(G, f), _relative_residual(J.T, f))
    violation = max(res, max(0.0, -float(f_n.min())) / total)
    return (
        violation,
        float(f_n.min()) / total,
        f"‖G f‖, ‖Jᵀ f‖ = {res:.1e} relative, min f_n / Σ f_n",
    )


def _cone_slack(grasp: Grasp, cert: Certificate) -> np.ndarray:
    """Per contact, how far its force lies inside its cone (N)."""
    if cert.cones == "normals":
        return np.array([f[0] for f in cert.contact_forces])
    layout = ConeLayout.of(grasp, cert.num_generators)
    b = grasp.characteristic_length
    out = []
    for f, cone, c in zip(
        cert.contact_forces, layout.cones, grasp.contacts, strict=True
    ):
        x = np.asarray(f)[list(cone.components)]
        if cert.cones == "exact" and cone.components in ((0, 1, 2), (0, 1, 2, 3)):
            used = np.linalg.norm(x[1:3]) / c.mu
            if c.model is ContactModel.SOFT_FINGER and len(x) == 4:
                used += abs(x[3]) / (b * c.torsional_friction)
            out.append(x[0] - used)
        else:
            out.append(float(np.min(cone.facets @ x)))
    return np.array(out)


def _check_balance(cert: Certificate, grasp: Grasp):
    f = cert.stacked_forces()
    if cert.cones == "normals":
        cols = grasp.normal_indices()
        f = f[cols]
    else:
        cols = ConeLayout.of(grasp, cert.num_generators).columns
        f = f[cols]
    G = grasp_matrix(grasp)[:, cols]
    total = float(np.sum(np.concatenate(cert.contact_forces)[grasp.normal_indices()]))
    if not total > 0.0:
        return np.inf, 0.0, "the internal force is zero"
    inside = _cone_slack(grasp, cert).min() / total
    A = normalised_grasp_matrix(grasp)[:, cols]
    norms = np.linalg.norm(A, axis=0)
    s = np.linalg.svd(A / np.where(norms > 0, norms, 1.0), compute_uv=False)
    ratio = s[-1] / s[0] if s.size >= grasp.wrench_dim else 0.0
    rank_short = 0.0 if ratio > _RANK_TOL else 1.0
    violation = max(_relative_residual(G, f), max(0.0, -inside), rank_short)
    return (
        violation,
        inside,
        f"G f = 0, f inside the {cert.cones} cones, σ_min/σ_max(Ḡ) = {ratio:.2g}",
    )


def _check_jacobian(grasp, hand_jacobian):
    if hand_jacobian is None:
        raise InvalidOptionError(
            "checking an uncontrollable internal force needs hand_jacobian "
            "(it must satisfy Jᵀ f = 0)"
        )
    return check_hand_jacobian(grasp, hand_jacobian)
