"""Textbook grasps with known answers, for demos, tutorials and tests (numpy only).

Every function returns a :class:`~drakegrasp.Grasp` whose verdicts are known in
closed form; the docstrings say what they are and why.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import Contact, ContactModel
from drakegrasp.core.deprecation import renamed_keyword
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.validation import (
    check_length,
    describe,
    integer_or_none,
    real_scalar,
)
from drakegrasp.errors import InvalidGraspError

__all__ = [
    "cube_seven_contacts",
    "equator_fingers",
    "planar_square_four_contacts",
    "planar_two_finger_square",
    "spatial_two_fingers",
]


@checked_call
def planar_two_finger_square(
    mu: float, *, half_width: float = 1.0, offset: float = 0.5
) -> Grasp:
    """Two planar hard fingers on opposite faces of a square, offset vertically.

    The left finger touches ``(-h, -offset)`` and the right ``(h, offset)``, so
    the line between them makes the angle ``atan(offset / h)`` with the normals
    (``atan(1/2)`` by default).  Force closure and antipodality hold exactly when
    ``mu > offset / h``.

    Parameters
    ----------
    mu : float
        Friction coefficient of both fingers.
    half_width : float, optional
        Half the side of the square ``h``, metres.
    offset : float, optional
        Vertical offset of each finger from the centre, metres.

    Returns
    -------
    Grasp
        Planar, reference point at the square's centre.
    """
    h = check_length("half_width", half_width)
    offset = real_scalar("offset", offset, error=InvalidGraspError)
    if not np.isfinite(offset):
        raise InvalidGraspError(
            f"offset must be finite (metres), got {describe(offset)}"
        )
    return Grasp(
        [
            Contact([-h, -offset], [1.0, 0.0], mu=mu),
            Contact([h, offset], [-1.0, 0.0], mu=mu),
        ]
    )


@checked_call
def planar_square_four_contacts(half_width: float = 1.0) -> Grasp:
    """Four frictionless contacts in first-order form closure on a square.

    Two contacts on the left/right faces at heights ``±h/2`` and two on the
    top/bottom faces: the normal-force wrenches positively span the plane's
    wrench space, the fewest contacts that can (Somov: 4 in the plane).

    Parameters
    ----------
    half_width : float, optional
        Half the side of the square, metres.

    Returns
    -------
    Grasp
        Planar, frictionless, reference point at the centre.
    """
    h = check_length("half_width", half_width)
    return Grasp(
        [
            Contact([h, h / 2], [-1, 0], contact_model=ContactModel.FRICTIONLESS),
            Contact([-h, -h / 2], [1, 0], contact_model=ContactModel.FRICTIONLESS),
            Contact([-h / 2, -h], [0, 1], contact_model=ContactModel.FRICTIONLESS),
            Contact([h / 2, h], [0, -1], contact_model=ContactModel.FRICTIONLESS),
        ]
    )


_CUBE_CONTACTS = (  # (position on the cube [-1, 1]^3, inward normal)
    ((1.0, -0.5, 0.0), (-1, 0, 0)),
    ((-1.0, 0.0, 0.0), (1, 0, 0)),
    ((0.0, 1.0, 0.5), (0, -1, 0)),
    ((0.5, -1.0, 0.0), (0, 1, 0)),
    ((0.0, 0.0, 1.0), (0, 0, -1)),
    ((-0.5, 0.0, -1.0), (0, 0, 1)),
    ((0.5, -0.5, -1.0), (0, 0, 1)),
)


@checked_call
def cube_seven_contacts(half_width: float = 1.0) -> Grasp:
    """Seven frictionless contacts in first-order form closure on a cube.

    One contact on each face and a second one on the bottom face, placed so that
    ``G_n`` has rank 6 and its one-dimensional null space is spanned by a
    strictly positive vector: the fewest contacts that can immobilise a body in
    space (Somov: 7).

    Parameters
    ----------
    half_width : float, optional
        Half the side of the cube, metres.

    Returns
    -------
    Grasp
        Spatial, frictionless, reference point at the centre.
    """
    half_width = check_length("half_width", half_width)
    return Grasp(
        [
            Contact(
                np.array(p) * half_width, n, contact_model=ContactModel.FRICTIONLESS
            )
            for p, n in _CUBE_CONTACTS
        ]
    )


_MAX_FINGERS = 10_000  # a picture, not a stress test: 10**9 would take hours


@checked_call
@renamed_keyword("model", "contact_model")
def equator_fingers(
    mu: float,
    *,
    num_fingers: int = 3,
    radius: float = 1.0,
    contact_model: ContactModel | str = ContactModel.HARD_FINGER,
    torsional_friction: float = 0.0,
) -> Grasp:
    """Fingers evenly spaced on a sphere's equator, pushing towards the centre.

    With three hard fingers 120° apart, any ``mu > 0`` gives force closure
    (the three tangential planes contain the vertical; friction resists
    vertical forces and moments); with ``mu = 0`` the normals all pass through
    the centre and no moment can be resisted.

    Parameters
    ----------
    mu : float
    num_fingers : int, optional
        How many, in [1, 10000] (an integral float such as ``3.0`` counts).
    radius : float, optional
        Sphere radius, metres.
    contact_model : ContactModel or str, optional
    torsional_friction : float, optional

    Returns
    -------
    Grasp
        Spatial, reference point at the sphere's centre.
    """
    count = integer_or_none(num_fingers, integral_floats=True)
    if count is None or not 1 <= count <= _MAX_FINGERS:
        raise InvalidGraspError(
            f"num_fingers must be an integer in [1, {_MAX_FINGERS}], "
            f"got {describe(num_fingers)}"
        )
    radius = check_length("radius", radius)
    angles = 2.0 * np.pi * np.arange(count) / count
    contacts = []
    for a in angles:
        outward = np.array([np.cos(a), np.sin(a), 0.0])
        contacts.append(
            Contact(
                radius * outward,
                -outward,
                mu=mu,
                contact_model=contact_model,
                torsional_friction=torsional_friction,
            )
        )
    return Grasp(contacts)


@checked_call
@renamed_keyword("model", "contact_model")
def spatial_two_fingers(
    mu: float,
    *,
    half_width: float = 0.05,
    contact_model: ContactModel | str = ContactModel.HARD_FINGER,
    torsional_friction: float = 0.0,
) -> Grasp:
    """Two fingers squeezing a box along x, as a parallel-jaw gripper does.

    Hard fingers never give force closure (``rank G = 5``: nothing resists a
    moment about the line between them); soft fingers with torsional friction
    do.

    Parameters
    ----------
    mu : float
    half_width : float, optional
        Half the box's width along x, metres.
    contact_model : ContactModel or str, optional
    torsional_friction : float, optional

    Returns
    -------
    Grasp
    """
    half_width = check_length("half_width", half_width)
    return Grasp(
        [
            Contact(
                [-half_width, 0, 0],
                [1, 0, 0],
                mu=mu,
                contact_model=contact_model,
                torsional_friction=torsional_friction,
            ),
            Contact(
                [half_width, 0, 0],
                [-1, 0, 0],
                mu=mu,
                contact_model=contact_model,
                torsional_friction=torsional_friction,
            ),
        ]
    )
