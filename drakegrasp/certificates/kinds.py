"""The kinds of certificate, and how a re-check reports.

A low room of its own so that the certificate type and its check
(:mod:`drakegrasp.certificates.certificate`) and its text
(:mod:`drakegrasp.certificates.text`) both import from here and never from each
other in a circle: the text reads a certificate through the :class:`Witness`
protocol, and only the certificate type imports the text.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Protocol

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import describe, plain_str
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "BALANCE",
    "DEFAULT_CHECK_TOL",
    "INTERIOR_SLACK",
    "ESCAPE_TWIST",
    "UNCONTROLLABLE",
    "UNRESISTED_WRENCH",
    "CertificateCheck",
    "Witness",
]

ESCAPE_TWIST = "escape twist"
"""Kind of the witness of a form-closure "no"."""
UNRESISTED_WRENCH = "unresisted wrench"
"""Kind of the witness of a force-closure "no"."""
UNCONTROLLABLE = "uncontrollable internal force"
"""Kind of the witness of an LP3 failure."""
BALANCE = "balancing internal force"
"""Kind of the witness of a "yes"."""
_KINDS = (ESCAPE_TWIST, UNRESISTED_WRENCH, UNCONTROLLABLE, BALANCE)
_CONES = ("normals", "polyhedral", "exact")

DEFAULT_CHECK_TOL = 1e-7
"""Relative tolerance of :meth:`drakegrasp.certificates.certificate.Certificate.check`.

Violations are scaled to 1 before they are compared with it.
"""

INTERIOR_SLACK = 64 * 2.0**-52
"""How far inside every cone (relative to ``Σ f_n``) a balancing internal force
must lie to be strictly inside, ≈ 1.4e-14.

A force on a cone's boundary computes within a few roundings of 0, of either
sign: the planar square's boundary witness read ``-1e-17`` with one numpy
build and ``+2.8e-17`` with another (numpy 2.4), and held there.  A witness
this close to a boundary proves nothing either way; one strictly inside by
more than roundoff (``1e-7`` at ``μ = 0.5000001``) still holds.
"""


@checked_call
@dataclass(frozen=True)
class CertificateCheck:
    """How well a certificate holds on a grasp, evaluated without a solver.

    Attributes
    ----------
    holds : bool
        ``violation <= tol``.
    violation : float
        Largest relative violation of the witness's defining inequalities
        (dimensionless; 0 when every inequality holds).  For an escape twist:
        ``max_i max(0, −(G_nᵀ v)_i) / (‖G_{n,i}‖ ‖v‖)``; for a wrench, the
        largest cone support ``max_f wᵀ G_i f`` per unit ``f_n`` over
        ``‖G_i‖ ‖w‖``; for internal forces, the residuals ``‖G f‖`` and
        ``‖Jᵀ f‖`` relative to ``‖G‖ ‖f‖`` and the cone slack.
    slack : float
        How firmly it holds, on the same scale: the smallest separation speed
        (escape twist), ``−max`` support (unresisted wrench), the smallest
        normal force over ``Σ f_n`` (internal forces).  0 on the boundary.
    tol : float
        Tolerance used.
    detail : str
        One line saying what was evaluated.
    """

    holds: bool
    violation: float
    slack: float
    tol: float
    detail: str

    @classmethod
    def evaluated(
        cls, violation: float, slack: float, tol: float, detail: str
    ) -> CertificateCheck:
        """The report of a check that computed ``violation`` and ``slack``.

        A non-finite violation (NaN never passes a comparison) is reported as
        ``inf`` with slack 0, so that it fails.
        """
        if not math.isfinite(violation):
            violation, slack = math.inf, 0.0
        return cls(
            holds=bool(violation <= tol),
            violation=float(violation),
            slack=float(slack),
            tol=float(tol),
            detail=detail,
        )

    def __bool__(self) -> bool:
        return self.holds

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}

    def __str__(self) -> str:
        verdict = "holds" if self.holds else "FAILS"
        return (
            f"witness {verdict}: violation {self.violation:.2g}, "
            f"slack {self.slack + 0.0:.3g} (tol {self.tol:g}); {self.detail}"
        )


def check_kind_and_cones(
    kind: str, cones: str, kinds: tuple[str, ...], cone_kinds: tuple[str, ...]
) -> tuple[str, str]:
    """``(kind, cones)`` as plain strs, once both are known.

    Raises
    ------
    InvalidOptionError
        Unless both are known (a ``str`` subclass is read as the plain ``str``
        it holds: its own ``==`` may raise or lie).
    """
    kind = plain_str(kind)
    if type(kind) is not str or kind not in kinds:
        raise InvalidOptionError(f"kind must be one of {kinds}, got {describe(kind)}")
    cones = plain_str(cones)
    if type(cones) is not str or cones not in cone_kinds:
        raise InvalidOptionError(
            f"cones must be one of {cone_kinds}, got {describe(cones)}"
        )
    return kind, cones


class Witness(Protocol):
    """What the check and the wording read of a certificate.

    :class:`~drakegrasp.certificates.certificate.Certificate` has these fields;
    its check and :mod:`~drakegrasp.certificates.text` are written against this
    protocol, so the text never imports the type that calls it.
    """

    kind: str
    cones: str
    direction: np.ndarray | None
    null_basis: np.ndarray
    separating_twist: np.ndarray | None
    separating_basis: np.ndarray
    contact_forces: tuple[np.ndarray, ...] | None
    internal_basis: np.ndarray | None
    num_generators: int
    reference_point: np.ndarray | None
    characteristic_length: float

    @property
    def two_sided(self) -> bool:
        """True when the witness direction ``-w`` is a witness too."""
        ...

    def separating(self, tol: float = ...) -> np.ndarray:
        """Which contacts the twist separates."""
        ...

    def stacked_forces(self) -> np.ndarray:
        """The balancing forces as one vector."""
        ...
