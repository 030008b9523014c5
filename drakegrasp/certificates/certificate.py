r"""Certificates: checkable witnesses of every closure verdict (numpy only).

A verdict says "yes" or "no"; its certificate says why, in a form that anyone
can re-verify with a few matrix products and without a solver.

Frames, orders and units follow ``docs/conventions.md``: every twist and wrench is
expressed in the grasp frame, about the grasp's reference point ``p``.

* A twist ``v = [v_p; ω]`` (``[vx, vy, ω]`` planar) is the object's velocity:
  ``v_p`` (m/s) the velocity of the point ``p``, ``ω`` (rad/s) the angular
  velocity.  It pairs with a wrench ``w = [f; m]`` by power ``wᵀ v`` (W).
  Twists are scaled to ``‖[v_p; b ω]‖ = 1`` (``b`` the characteristic length).
* A wrench ``w = [f; m]`` (N, N·m; ``[fx, fy, mz]`` planar), moment about ``p``,
  scaled to ``‖[f; m / b]‖ = 1``.

The four kinds:

``"escape twist"`` (form closure "no")
    ``v ≠ 0`` with ``G_nᵀ v >= 0``: no contact penetrates to first order.  By
    Stiemke's theorem (a sharp form of Gordan's) such a ``v`` exists exactly
    when no strictly positive normal forces balance, i.e. when LP1 fails.
    Contacts with ``(G_nᵀ v)_i > 0`` separate, the others slide.  When
    ``G_n`` is rank deficient, ``v`` lies in ``N(G_nᵀ)`` and both ``±v``
    escape (``two_sided``).
``"unresisted wrench"`` (force closure "no")
    ``y ≠ 0`` (``separating_twist``, the ``w`` of ``docs/conventions.md``) with
    ``yᵀ G f <= 0`` for every ``f`` in the contact cones (polyhedral or
    exact): every wrench the fingers can apply lies in a closed half-space, a
    hyperplane through the origin separates them from ``direction``
    (``yᵀ direction > 0``), so the grasp cannot resist an external wrench
    along ``−direction``.  ``y`` pairs with wrenches by power, so it is a
    twist; ``direction`` is the wrench that ``y`` names in the wrench metric
    about the contacts' centroid (``‖[f; m/L]‖``), which does not depend on
    the reference point: a moment about the line between two fingers reads as
    a moment, not as a force far away.  Rank deficient: ``y`` spans
    ``N(Gᵀ)`` and both signs are unresisted.
``"uncontrollable internal force"`` (LP3 fails)
    ``f ∈ N(G) ∩ N(Jᵀ)`` with every normal component positive: a squeeze that
    no joint torque can change.
``"balancing internal force"`` (a "yes")
    ``G`` of full rank and ``f`` with ``G f = 0`` strictly inside every cone;
    ``internal_basis`` spans ``N(G)`` over the components the cones allow (the
    internal forces the margin was found among).

:meth:`~drakegrasp.certificates.certificate.Certificate.check` evaluates these
definitions on the grasp and returns a :class:`CertificateCheck` that says by how
much the witness holds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

from drakegrasp.certificates._matching import ReadWitness, check_tolerance, read_witness
from drakegrasp.certificates.kinds import (
    _CONES,
    _KINDS,
    BALANCE,
    DEFAULT_CHECK_TOL,
    ESCAPE_TWIST,
    INTERIOR_SLACK,
    UNCONTROLLABLE,
    UNRESISTED_WRENCH,
    CertificateCheck,
    Witness,
    check_kind_and_cones,
)
from drakegrasp.certificates.text import describe_certificate
from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import ContactModel
from drakegrasp.core.friction_cone import ConeLayout, cone_support, support_of
from drakegrasp.core.grasp import (
    Grasp,
    check_hand_jacobian,
    grasp_matrix,
    invariant_grasp_matrix,
)
from drakegrasp.core.linalg import equilibrated
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS, DEFAULT_RANK_TOL
from drakegrasp.core.validation import describe
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "BALANCE",
    "ESCAPE_TWIST",
    "UNCONTROLLABLE",
    "UNRESISTED_WRENCH",
    "CONTACT_RATE_TOL",
    "Certificate",
    "CertificateCheck",
    "cone_support",
    "support_of",
]

CONTACT_RATE_TOL = 1e-9
"""Default threshold on the normal rates ``G_nᵀ v`` of an escape twist ``v``.

A contact separates where its rate exceeds it and slides where ``|rate|`` does
not; the twist has unit size (its linear part and ``b`` times its angular
part, ``b`` the grasp's characteristic length), so the rates are of order one
and 1e-9 is their round-off.
"""


@checked_call
@dataclass(frozen=True, eq=False)
class Certificate:
    """A witness of a closure verdict, in the grasp frame about ``p``.

    Attributes
    ----------
    kind : str
        One of the kinds in :mod:`drakegrasp.certificates.kinds`:
        :data:`~drakegrasp.certificates.kinds.ESCAPE_TWIST`,
        :data:`~drakegrasp.certificates.kinds.UNRESISTED_WRENCH`,
        :data:`~drakegrasp.certificates.kinds.UNCONTROLLABLE` or
        :data:`~drakegrasp.certificates.kinds.BALANCE` (see the module docstring).
    cones : str
        ``"normals"`` (form closure), ``"polyhedral"`` or ``"exact"``: which
        cones the witness refers to.
    direction : (6,) or (3,) float or None
        The escape twist ``[v_p; ω]`` (``‖[v_p; b ω]‖ = 1``) or the unresisted
        wrench ``[f; m]`` (``‖[f; m/b]‖ = 1``); None for internal forces.
    null_basis : (6, k) or (3, k) float
        Rank-deficient case: a basis of ``N(G_nᵀ)`` (twists) or ``N(Gᵀ)``
        (wrenches), each column scaled like ``direction``; both signs of every
        column are witnesses.  ``k = 0`` when the rank is full.
    separating_twist : (6,) or (3,) float or None
        Unresisted wrench: ``y`` with ``yᵀ G f <= 0`` on the cones (the normal
        of the separating hyperplane in wrench space), scaled like a twist.
    separating_basis : (6, k) or (3, k) float
        Rank-deficient case: ``y`` for each column of ``null_basis``.
    contact_rates : (N,) float or None
        Escape twist: ``(G_nᵀ v)_i``, the separation speed of each contact
        (m/s).  Unresisted wrench: ``max yᵀ G_i f_i`` over the cone with
        ``f_n = 1`` (W per N: ``<= 0`` everywhere).
    contact_forces : tuple of ndarray or None
        Internal forces (LP3's or the verdict's optimal forces), per contact in
        its contact frame, normal first, over the full components of its model.
    internal_basis : (M, k) float or None
        ``BALANCE``: orthonormal basis of the internal forces ``N(G)`` over the
        components the cones allow (zero rows elsewhere), normalised ``G``.
    num_generators : int
        Generators of the polyhedral cones the witness refers to.
    reference_point : (3,) or (2,) float or None
        The grasp's ``p`` (metres, grasp frame), for :meth:`describe`.
    characteristic_length : float
        The grasp's ``b`` (metres) used in the scaling of ``direction``.
    """

    kind: str
    cones: str
    direction: np.ndarray | None = None
    null_basis: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    separating_twist: np.ndarray | None = None
    separating_basis: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    contact_rates: np.ndarray | None = None
    contact_forces: tuple[np.ndarray, ...] | None = None
    internal_basis: np.ndarray | None = None
    num_generators: int = DEFAULT_NUM_GENERATORS
    reference_point: np.ndarray | None = None
    characteristic_length: float = 1.0

    def __eq__(self, other):
        if isinstance(other, str):
            raise TypeError(
                "a Certificate is a witness, not a string: compare "
                'ClosureResult.decided_by ("d*", "rank", "normal forces", '
                f'"LP3") with {describe(other)} instead'
            )
        return self is other

    __hash__ = object.__hash__

    def __post_init__(self):
        kind, cones = check_kind_and_cones(self.kind, self.cones, _KINDS, _CONES)
        object.__setattr__(self, "kind", kind)
        object.__setattr__(self, "cones", cones)

    @property
    def two_sided(self) -> bool:
        """True when both ``±direction`` are witnesses (rank-deficient case)."""
        return self.null_basis.shape[-1] > 0

    def separating(self, tol: float = CONTACT_RATE_TOL) -> np.ndarray:
        """Escape twist: (N,) bool, contacts that separate (``G_nᵀ v > tol``)."""
        if self.contact_rates is None:
            return np.zeros(0, dtype=bool)
        return self.contact_rates > tol

    def sliding(self, tol: float = CONTACT_RATE_TOL) -> np.ndarray:
        """Escape twist: (N,) bool, contacts that slide (``|G_nᵀ v| <= tol``)."""
        if self.contact_rates is None:
            return np.zeros(0, dtype=bool)
        return np.abs(self.contact_rates) <= tol

    def stacked_forces(self) -> np.ndarray:
        """The internal force as one (M,) vector in ``G``'s column order."""
        if self.contact_forces is None:
            return np.zeros(0)
        return np.concatenate(self.contact_forces)

    def check(
        self,
        grasp: Grasp,
        *,
        hand_jacobian: np.ndarray | None = None,
        tol: float = DEFAULT_CHECK_TOL,
    ) -> CertificateCheck:
        """Re-verify the witness on ``grasp`` by direct evaluation (no solver).

        Parameters
        ----------
        grasp : Grasp
            The grasp the verdict was computed for.
        hand_jacobian : (M, n_v) float, optional
            Needed for :data:`~drakegrasp.certificates.kinds.UNCONTROLLABLE`
            (``Jᵀ f = 0``).
        tol : float, optional
            Relative tolerance on the violation, in (0, 1).

        Returns
        -------
        CertificateCheck
            A witness with a NaN or infinite component fails (violation
            ``inf``).

        Raises
        ------
        InvalidOptionError
            When ``tol`` is not in (0, 1), or the certificate belongs to another
            grasp (another number of contacts, dimension or contact models:
            its arrays have other shapes).
        """
        return check_certificate(self, grasp, hand_jacobian=hand_jacobian, tol=tol)

    def describe(self) -> str:
        """One sentence that says why the verdict is what it is.

        For example "the object can rotate about z through (0, 0, 0.02) m
        without penetrating any finger" or "cannot resist a force along −x
        through (0, 0, 0) m".  Points are in the grasp frame.
        """
        return describe_certificate(self)

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        d = {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}
        d["two_sided"] = self.two_sided
        return d


# ------------------------------------------------ the solver-free check


def check_certificate(
    cert: Witness,
    grasp: Grasp,
    *,
    hand_jacobian: np.ndarray | None = None,
    tol: float,
) -> CertificateCheck:
    """See :meth:`drakegrasp.certificates.certificate.Certificate.check`."""
    tol = check_tolerance(tol)
    read = read_witness(cert, grasp)
    J = _check_jacobian(grasp, hand_jacobian) if read.kind == UNCONTROLLABLE else None
    if not read.finite:
        violation, slack, detail = np.inf, 0.0, "the witness is not finite"
    elif read.kind == ESCAPE_TWIST:
        violation, slack, detail = _check_twist(read, grasp)
    elif read.kind == UNRESISTED_WRENCH:
        violation, slack, detail = _check_wrench(read, grasp)
    elif read.kind == UNCONTROLLABLE:
        violation, slack, detail = _check_uncontrollable(read, grasp, J)
    else:
        assert read.kind == BALANCE
        violation, slack, detail = _check_balance(read, grasp)
        if math.isfinite(violation) and not slack > INTERIOR_SLACK:
            # "Strictly inside every cone": a force on a cone's boundary (or
            # outside it by less than tol) proves no force closure; it held for
            # the boundary grasp whose "no" witness held too.  On the boundary
            # the slack is roundoff of either sign, hence the floor.
            return CertificateCheck(
                holds=False,
                violation=float(max(violation, -slack)),
                slack=float(slack),
                tol=float(tol),
                detail=(
                    f"{detail}; not strictly inside every cone (slack "
                    f"{slack:.2g} <= {INTERIOR_SLACK:.2g}, roundoff of the boundary)"
                ),
            )
    return CertificateCheck.evaluated(violation, slack, tol, detail)


def _unit_scaled(x: np.ndarray) -> np.ndarray:
    """``x`` over its largest absolute entry: norms of it cannot overflow."""
    m = float(np.max(np.abs(x))) if x.size else 0.0
    return x / m if m > 0.0 else x


def _directions(cert: ReadWitness) -> list[np.ndarray]:
    out = [cert.direction]
    if cert.two_sided:
        out += list(cert.null_basis.T)
    return [_unit_scaled(v) for v in out]


def _check_twist(cert: ReadWitness, grasp: Grasp):
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


def _check_wrench(cert: ReadWitness, grasp: Grasp):
    G = grasp_matrix(grasp)
    scale = np.linalg.norm(G, 2)
    ys = [cert.separating_twist]
    ws = [cert.direction]
    if cert.two_sided:
        ys += list(cert.separating_basis.T)
        ws += list(cert.null_basis.T)
    violation, slack = 0.0, np.inf
    for y, w in zip(map(_unit_scaled, ys), map(_unit_scaled, ws), strict=True):
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


def _check_uncontrollable(cert: ReadWitness, grasp: Grasp, J: np.ndarray):
    f = _unit_scaled(cert.stacked_forces())
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


def _cone_slack(
    grasp: Grasp, cert: ReadWitness, forces: list[np.ndarray]
) -> np.ndarray:
    """Per contact, how far its force (one of ``forces``) lies inside its cone."""
    if cert.cones == "normals":
        return np.array([f[0] for f in forces])
    layout = ConeLayout.of(grasp, cert.num_generators)
    b = grasp.characteristic_length
    out = []
    for f, cone, c in zip(forces, layout.cones, grasp.contacts, strict=True):
        x = f[list(cone.components)]
        if cert.cones == "exact" and cone.components in ((0, 1, 2), (0, 1, 2, 3)):
            used = np.linalg.norm(x[1:3]) / c.mu
            if c.contact_model is ContactModel.SOFT_FINGER and len(x) == 4:
                used += abs(x[3]) / (b * c.torsional_friction)
            out.append(x[0] - used)
        else:
            out.append(float(np.min(cone.facets @ x)))
    return np.array(out)


def _check_balance(cert: ReadWitness, grasp: Grasp):
    stacked = cert.stacked_forces()
    scale = float(np.max(np.abs(stacked)))
    if not scale > 0.0:
        return np.inf, 0.0, "the internal force is zero"
    forces = [f / scale for f in cert.contact_forces]
    stacked = stacked / scale
    if cert.cones == "normals":
        cols = grasp.normal_indices()
    else:
        cols = ConeLayout.of(grasp, cert.num_generators).columns
    f = stacked[cols]
    G = grasp_matrix(grasp)[:, cols]
    total = float(np.sum(stacked[grasp.normal_indices()]))
    if not total > 0.0:
        return np.inf, 0.0, "the internal force is zero"
    inside = _cone_slack(grasp, cert, forces).min() / total
    A_s, _ = equilibrated(invariant_grasp_matrix(grasp)[:, cols])
    s = np.linalg.svd(A_s, compute_uv=False)
    ratio = s[-1] / s[0] if s.size >= grasp.wrench_dim else 0.0
    rank_short = 0.0 if ratio > DEFAULT_RANK_TOL else 1.0
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
