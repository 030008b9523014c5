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

:meth:`~drakegrasp.certificates.Certificate.check` evaluates these definitions
on the grasp and returns a :class:`CertificateCheck` that says by how much the
witness holds.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

from drakegrasp.certificate_check import check_certificate
from drakegrasp.certificate_kinds import (
    _CONES,
    _KINDS,
    BALANCE,
    DEFAULT_CHECK_TOL,
    ESCAPE_TWIST,
    UNCONTROLLABLE,
    UNRESISTED_WRENCH,
    CertificateCheck,
)
from drakegrasp.certificate_text import describe_certificate
from drakegrasp.cone_support import cone_support, support_of
from drakegrasp.errors import InvalidOptionError
from drakegrasp.grasp import Grasp
from drakegrasp.results import _jsonable

__all__ = [
    "BALANCE",
    "ESCAPE_TWIST",
    "UNCONTROLLABLE",
    "UNRESISTED_WRENCH",
    "Certificate",
    "CertificateCheck",
    "cone_support",
    "support_of",
]


@dataclass(frozen=True, eq=False)
class Certificate:
    """A witness of a closure verdict, in the grasp frame about ``p``.

    Attributes
    ----------
    kind : str
        One of the kinds in :mod:`drakegrasp.certificate_kinds`:
        :data:`~drakegrasp.certificate_kinds.ESCAPE_TWIST`,
        :data:`~drakegrasp.certificate_kinds.UNRESISTED_WRENCH`,
        :data:`~drakegrasp.certificate_kinds.UNCONTROLLABLE` or
        :data:`~drakegrasp.certificate_kinds.BALANCE` (see the module docstring).
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
    num_generators: int = 8
    reference_point: np.ndarray | None = None
    characteristic_length: float = 1.0

    def __eq__(self, other):
        if isinstance(other, str):
            raise TypeError(
                "a Certificate is a witness, not a string: compare "
                'ClosureResult.decided_by ("d*", "rank", "normal forces", '
                f'"LP3") with {other!r} instead'
            )
        return self is other

    __hash__ = object.__hash__

    def __post_init__(self):
        if self.kind not in _KINDS:
            raise InvalidOptionError(f"kind must be one of {_KINDS}, got {self.kind!r}")
        if self.cones not in _CONES:
            raise InvalidOptionError(
                f"cones must be one of {_CONES}, got {self.cones!r}"
            )

    @property
    def two_sided(self) -> bool:
        """True when both ``±direction`` are witnesses (rank-deficient case)."""
        return self.null_basis.shape[-1] > 0

    def separating(self, tol: float = 1e-9) -> np.ndarray:
        """Escape twist: (N,) bool, contacts that separate (``G_nᵀ v > tol``)."""
        if self.contact_rates is None:
            return np.zeros(0, dtype=bool)
        return self.contact_rates > tol

    def sliding(self, tol: float = 1e-9) -> np.ndarray:
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
            Needed for :data:`~drakegrasp.certificate_kinds.UNCONTROLLABLE`
            (``Jᵀ f = 0``).
        tol : float, optional
            Relative tolerance on the violation.

        Returns
        -------
        CertificateCheck
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
        d = {f.name: _jsonable(getattr(self, f.name)) for f in fields(self)}
        d["two_sided"] = self.two_sided
        return d
