r"""Antipodal two-contact grasps (numpy only).

Two contacts are antipodal when the segment between the contact points lies inside
both friction cones:

.. math:: \angle(c_2 - c_1, n_1) \le \arctan \mu_1, \qquad
          \angle(c_1 - c_2, n_2) \le \arctan \mu_2

with the normals pointing into the object.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import Contact, ContactModel
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import (
    check_angle_tol,
    check_coefficient,
    items_of,
)
from drakegrasp.errors import InvalidGraspError, InvalidOptionError

__all__ = ["DEFAULT_ANGLE_TOL", "AntipodalResult", "is_antipodal"]

DEFAULT_ANGLE_TOL = 1e-9
"""Angles may exceed ``atan μ`` by this much (rad) and still count as inside."""


@checked_call
@dataclass(frozen=True)
class AntipodalResult:
    """Antipodal check of a two-contact grasp.

    Attributes
    ----------
    is_antipodal : bool
        The segment between the contacts lies inside both friction cones.
    angles : (2,) float
        Angle (rad) between ``c_2 - c_1`` and ``n_1``, and between ``c_1 - c_2``
        and ``n_2``.
    mu : (2,) float
        Friction coefficient used at each contact.
    margins : (2,) float
        ``atan(μ_i) - angle_i`` (rad): positive inside the cone.
    min_mu : float
        Smallest friction coefficient for which the pair is antipodal,
        ``tan(max angle)`` (``inf`` when an angle reaches 90°).
    """

    is_antipodal: bool
    angles: np.ndarray
    mu: np.ndarray
    margins: np.ndarray
    min_mu: float

    def __bool__(self) -> bool:
        return self.is_antipodal

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}

    def __str__(self) -> str:
        verdict = "YES" if self.is_antipodal else "no"
        deg = np.degrees(self.angles)
        mdeg = np.degrees(self.margins)
        head = (
            f"antipodal (geometric test): {verdict}, decided by the angle margins "
            f"{mdeg[0]:+.3f}°, {mdeg[1]:+.3f}° (angles {deg[0]:.3f}°, "
            f"{deg[1]:.3f}° vs atan mu)"
        )
        if self.min_mu == 0.0:
            mu_text = "the fingers are collinear: antipodal for every mu >= 0"
        elif np.isinf(self.min_mu):
            mu_text = _no_mu_text(self.angles)
        else:
            mu_text = f"antipodal for mu >= {self.min_mu:.4g}"
        if np.all(np.abs(self.margins) < 1e-9):
            mu_text += "; on the cone boundary (margins 0°), not strictly inside"
        return (
            f"{head}\n  {mu_text}; antipodal is necessary, not sufficient: in "
            "space two point contacts without torsional friction (hard "
            "fingers) never resist a moment about the line between them, and "
            "with mu = 0 nothing resists sliding"
        )


def _no_mu_text(angles: np.ndarray) -> str:
    """Why no friction coefficient makes the pair antipodal (an angle >= 90°)."""
    outward = [i + 1 for i in range(2) if angles[i] > np.pi / 2]
    if len(outward) == 2:
        return (
            "not antipodal for any mu: both normals point away from the other "
            "contact (away from each other, out of the object); drakegrasp's "
            "normals point into the object, the direction the finger pushes "
            "(docs/conventions.md, Contacts): negate them if they came from an "
            "outward-normal source"
        )
    if outward:
        return (
            f"not antipodal for any mu: the normal of contact {outward[0]} points "
            "away from the other contact (out of the object); drakegrasp's "
            "normals point into the object, the direction the finger pushes "
            "(docs/conventions.md, Contacts): check its sign"
        )
    square = [i + 1 for i in range(2) if angles[i] >= np.pi / 2]
    which = " and ".join(f"contact {i}" for i in square)
    return (
        f"not antipodal for any mu: the normal of {which} is perpendicular to "
        "the line between the contacts"
    )


def _two_contacts(grasp_or_contacts: Grasp | Sequence[Contact]) -> tuple[Contact, ...]:
    if isinstance(grasp_or_contacts, Grasp):
        contacts = grasp_or_contacts.contacts
    else:
        contacts = tuple(
            items_of(
                "grasp_or_contacts",
                grasp_or_contacts,
                "a Grasp or a pair of Contact (the antipodal check)",
                error=InvalidGraspError,
            )
        )
    if len(contacts) != 2 or not all(isinstance(c, Contact) for c in contacts):
        raise InvalidGraspError(
            "the antipodal check takes exactly two contacts (a Grasp or a pair of "
            f"Contact), got {len(contacts)} item(s)"
        )
    if contacts[0].dim != contacts[1].dim:
        raise InvalidGraspError("the two contacts must both be planar or both spatial")
    return contacts


def _friction(contact: Contact) -> float:
    return 0.0 if contact.contact_model is ContactModel.FRICTIONLESS else contact.mu


def _angle(u: np.ndarray, v: np.ndarray) -> float:
    """Angle between two vectors, accurate near 0 and π (atan2 of |u×v|, u·v)."""
    cross = np.cross(u, v) if u.size == 3 else u[0] * v[1] - u[1] * v[0]
    return float(np.arctan2(np.linalg.norm(cross), np.dot(u, v)))


@checked_call
def is_antipodal(
    grasp_or_contacts: Grasp | Sequence[Contact],
    *,
    mu: float | None = None,
    angle_tol: float = DEFAULT_ANGLE_TOL,
) -> AntipodalResult:
    """Check whether two contacts are antipodal.

    Parameters
    ----------
    grasp_or_contacts : Grasp or sequence of two Contact
        Planar or spatial; normals point into the object.
    mu : float, optional
        Friction coefficient to use at both contacts.  Default: each contact's own
        ``mu`` (0 for a frictionless contact).
    angle_tol : float, optional
        Slack (rad) on the angle test, for contacts that are exactly collinear;
        in ``[0, 0.01]`` (:data:`~drakegrasp.core.validation.MAX_ANGLE_TOL`).

    Returns
    -------
    AntipodalResult
        Verdict, the two angles (rad), the margins ``atan μ_i - angle_i`` (rad)
        and the smallest ``μ`` that makes the pair antipodal.

    Examples
    --------
    Two fingers squeezing along a line tilted by 10° from both normals:

    >>> import numpy as np
    >>> import drakegrasp as dg
    >>> t = np.tan(np.radians(10.0))
    >>> pair = [dg.Contact([-1, -t, 0], [1, 0, 0]), dg.Contact([1, t, 0], [-1, 0, 0])]
    >>> result = dg.is_antipodal(pair, mu=0.2)
    >>> bool(result.is_antipodal), round(float(result.min_mu), 4)
    (True, 0.1763)
    """
    c1, c2 = _two_contacts(grasp_or_contacts)
    angle_tol = check_angle_tol(angle_tol)
    if mu is None:
        mus = np.array([_friction(c1), _friction(c2)])
    else:
        m = check_coefficient("mu", mu, error=InvalidOptionError)
        mus = np.array([m, m])
    line = c2.position - c1.position
    if not np.any(line):
        raise InvalidGraspError(
            f"the two contacts coincide at {c1.position.tolist()}; the antipodal "
            "line between them is undefined"
        )
    angles = np.array([_angle(line, c1.normal), _angle(-line, c2.normal)])
    margins = np.arctan(mus) - angles
    worst = float(angles.max())
    min_mu = float(np.tan(worst)) if worst < np.pi / 2 else float("inf")
    return AntipodalResult(
        is_antipodal=bool(np.all(margins >= -angle_tol)),
        angles=angles,
        mu=mus,
        margins=margins,
        min_mu=min_mu,
    )
