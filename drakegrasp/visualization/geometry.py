"""What the pictures draw, as plain arrays (numpy only).

The Meshcat and matplotlib drawings share these helpers, so the geometry of a
picture (where a cone edge points, where a force arrow starts) can be checked
without a renderer.

Drawing side
------------
A contact's normal points **into the object**, so its friction cone
``{f : ‖f_t‖ ≤ μ f_n}`` (placed with its apex at the contact point) lies inside
the object, where an object's mesh would hide it.  Every drawing therefore takes
``side``:

``"outside"`` (default)
    the cone is reflected through the contact point (apex at ``c``, opening away
    from the object, on the finger's side) and a force ``f`` is an arrow that
    **ends** at ``c``: it starts at ``c - s f`` (``s`` = force scale), i.e. the
    finger pushes.  Every drawn force lies inside the drawn cone.
``"inside"``
    the cone opens along ``+n`` into the object and arrows **start** at ``c``.

Either way an arrow's direction is the force ``f`` itself (in the grasp frame).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import Contact
from drakegrasp.core.friction_cone import friction_cone_generators
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.validation import (
    COEFFICIENT_MAX,
    LENGTH_BOUND,
    LENGTH_MIN,
    check_coefficient,
    check_contact,
    check_grasp,
    describe,
    integer_or_none,
    items_of,
    plain_str,
    real_array,
    real_scalar,
)
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "DRAW_LENGTH_MAX",
    "DRAW_LENGTH_MIN",
    "MAX_CONE_SEGMENTS",
    "contact_forces_in_grasp_frame",
    "contact_pose_3d",
    "cone_edge_directions",
    "exact_cone_mesh",
    "normalize_contact_forces",
    "positive_length",
    "pyramid_mesh",
    "side_sign",
]

SIDES = ("outside", "inside")

DRAW_LENGTH_MAX = LENGTH_BOUND
"""Largest length (metres) a drawing takes: 1e30, the largest characteristic
length a grasp may have (:data:`drakegrasp.core.validation.LENGTH_BOUND`).

Sizes, heights, radii, arrow lengths and a camera's padding are refused above
it, so every default (a fraction of a valid ``b``) is in range and every number
a drawing computes stays finite: positions are at most
:data:`~drakegrasp.core.validation.POSITION_BOUND` (1e20 m) and ``μ`` at most
1e12, so a drawn vertex is below 1e43 m and its square below 1e87 (a size of
1e300 overflowed a norm to ``inf`` and Drake refused the arrow)."""

DRAW_LENGTH_MIN = LENGTH_MIN
"""Smallest length (metres) a drawing takes: the smallest normal double,
2.2e-308 (:data:`drakegrasp.core.validation.LENGTH_MIN`).  The fractions of a
length that a drawing uses (a triad's radius is 0.2 times a sphere's) then stay
> 0, which Drake's shapes demand."""

MAX_CONE_SEGMENTS = 1024
"""Most triangles around the axis of :func:`exact_cone_mesh` (the drawings use
16 and 48; 10**9 once tried to allocate 48 GB)."""


def merge_palette(
    defaults: Mapping[str, Any], overrides: Mapping[str, Any] | None
) -> dict[str, Any]:
    """Default colours with the caller's overrides; unknown keys are an error.

    Parameters
    ----------
    defaults : mapping of str to colour
    overrides : mapping of str to colour, optional

    Returns
    -------
    dict of str to colour
    """
    merged = dict(defaults)
    if overrides:
        unknown = set(overrides) - set(merged)
        if unknown:
            raise InvalidOptionError(
                f"unknown colour key(s) {sorted(unknown)}; valid keys are "
                f"{sorted(merged)}"
            )
        merged.update(overrides)
    return merged


def side_sign(side: str) -> float:
    """``-1.0`` for ``side="outside"`` and ``+1.0`` for ``side="inside"``.

    Raises
    ------
    InvalidOptionError
        If ``side`` is neither.
    """
    side = plain_str(side)
    if type(side) is not str or side not in SIDES:
        raise InvalidOptionError(
            f"side must be 'outside' or 'inside', got {describe(side)}"
        )
    return -1.0 if side == "outside" else 1.0


def positive_length(name: str, value: Any, *, unit: str = "metres") -> float:
    """``value`` as a length a drawing can take, or InvalidOptionError.

    Parameters
    ----------
    name : str
        Name of the argument, for the message.
    value : int or float
        A real number (numpy real scalars too; not a string, a bool or None).
    unit : str, optional
        Its unit, for the message (a force scale is in m/N).

    Returns
    -------
    float
        In ``[DRAW_LENGTH_MIN, DRAW_LENGTH_MAX]`` = [2.2e-308, 1e30] metres.

    Raises
    ------
    InvalidOptionError
        For anything else (NaN, ``inf``, 0, a negative number, a string...),
        naming ``name`` and the valid range.
    """
    x = real_scalar(name, value)
    if not (DRAW_LENGTH_MIN <= x <= DRAW_LENGTH_MAX):
        raise InvalidOptionError(
            f"{name} must be finite and > 0, a real number in [{DRAW_LENGTH_MIN:.3g}, "
            f"{DRAW_LENGTH_MAX:g}] {unit} "
            "(drakegrasp.visualization.geometry.DRAW_LENGTH_MIN/MAX), got "
            f"{describe(value)}"
        )
    return x


def check_sign(value: Any) -> float:
    """``sign`` of a cone drawing: ``+1.0`` or ``-1.0`` (InvalidOptionError else)."""
    x = real_scalar("sign", value)
    if x not in (1.0, -1.0):
        raise InvalidOptionError(
            f"sign must be +1 (the cone opens along +x) or -1 (reflected through "
            f"the apex), got {describe(value)}"
        )
    return x


@checked_call
def contact_pose_3d(contact: Contact) -> tuple[np.ndarray, np.ndarray]:
    """Contact frame and position of a contact, lifted to 3-D.

    Parameters
    ----------
    contact : Contact
        Planar or spatial.

    Returns
    -------
    R_GC : (3, 3) float
        Columns ``[n, t1, t2]`` of the contact frame in the grasp frame G.  A
        planar contact ``R = [n, t]`` in the z = 0 plane becomes
        ``[[n, t, 0], [0, 0, 1]]`` (right-handed, since ``n × t = +z``).
    p_GC : (3,) float
        Contact point, metres, in G (``z = 0`` for a planar contact).
    """
    check_contact(contact)
    R = np.asarray(contact.frame, dtype=float)
    c = np.asarray(contact.position, dtype=float)
    if contact.planar:
        R3 = np.eye(3)
        R3[:2, :2] = R
        return R3, np.array([c[0], c[1], 0.0])
    return R.copy(), c.copy()


@checked_call
def normalize_contact_forces(grasp: Grasp, forces: Any) -> list[np.ndarray] | None:
    """Per-contact force arrays from a closure result or a sequence of arrays.

    Parameters
    ----------
    grasp : Grasp
        The grasp the forces belong to.
    forces : ClosureResult, sequence of array_like, or None
        An object with a ``contact_forces`` attribute (a
        :class:`~drakegrasp.ClosureResult`) or one array per contact, each the
        force in that contact's frame, normal component first.  An array may
        hold fewer components than the contact's model (form closure reports
        ``[f_n]`` only): the missing ones are zero.

    Returns
    -------
    list of ndarray or None
        One array per contact with exactly ``contact.num_components`` entries
        (newtons; a soft finger's last entry is a moment, N·m); None when
        ``forces`` is None or the result holds no forces.

    Raises
    ------
    InvalidOptionError
        If the number of arrays differs from the number of contacts, or an
        array has too many components or non-finite entries.
    """
    check_grasp(grasp)
    if forces is None:
        return None
    if hasattr(forces, "contact_forces"):
        forces = forces.contact_forces
        if forces is None:
            return None
    if isinstance(forces, (str, bytes)) or not isinstance(forces, Iterable):
        raise InvalidOptionError(
            "forces must be a ClosureResult or one array of force components per "
            f"contact, got {describe(forces)} ({type(forces).__name__})"
        )
    forces = items_of(
        "forces",
        forces,
        "a ClosureResult or one array of force components per contact",
    )
    if not forces:
        return None
    if len(forces) != grasp.num_contacts:
        raise InvalidOptionError(
            f"got {len(forces)} contact forces for a grasp with "
            f"{grasp.num_contacts} contacts; pass one array per contact"
        )
    out = []
    for i, (f, contact) in enumerate(zip(forces, grasp.contacts, strict=True)):
        a = real_array(f"force of contact {i}", f, error=InvalidOptionError).reshape(-1)
        k = contact.num_components
        if a.size > k or a.size == 0:
            raise InvalidOptionError(
                f"contact {i} ({contact.contact_model.value}) has {k} force components "
                f"({', '.join(contact.component_names)}), got {a.tolist()}"
            )
        if not np.all(np.isfinite(a)):
            raise InvalidOptionError(
                f"force of contact {i} is not finite: {a.tolist()}"
            )
        full = np.zeros(k)
        full[: a.size] = a
        out.append(full)
    return out


@checked_call
def contact_forces_in_grasp_frame(
    grasp: Grasp, forces: Sequence[np.ndarray]
) -> np.ndarray:
    """Contact forces mapped from contact frames to the grasp frame.

    Parameters
    ----------
    grasp : Grasp
    forces : sequence of ndarray
        As returned by :func:`normalize_contact_forces` (also what it takes:
        each array is checked by it).

    Returns
    -------
    f_G : (N, d) float
        ``R_i [f_n, f_t…]`` for each contact (the soft-finger moment ``m_n`` is
        not a force and is left out), newtons, in the grasp frame; ``d`` is 2 for
        a planar grasp and 3 otherwise.

    Raises
    ------
    InvalidOptionError
        If ``forces`` is not one array of at most ``num_components`` finite
        real numbers per contact.
    """
    given = forces
    forces = normalize_contact_forces(grasp, forces)
    if forces is None:
        raise InvalidOptionError(
            "forces must be one array of force components per contact, got "
            f"{describe(given)}"
        )
    rows = []
    for contact, f in zip(grasp.contacts, forces, strict=True):
        R = np.asarray(contact.frame, dtype=float)
        d = contact.dim
        local = np.zeros(d)
        m = min(d, f.size)
        local[:m] = f[:m]
        rows.append(R @ local)
    return np.array(rows, dtype=float).reshape(grasp.num_contacts, grasp.dim)


@checked_call
def cone_edge_directions(contact: Contact) -> np.ndarray:
    """Unit edge rays of a planar contact's (exact) friction cone.

    Parameters
    ----------
    contact : Contact
        A planar contact.

    Returns
    -------
    U : (2, 2) float
        Rows are the unit vectors along ``R [1, +μ]`` and ``R [1, -μ]`` in the
        grasp frame (both equal ``n`` for a frictionless contact or ``μ = 0``).
    """
    check_contact(contact)
    if not contact.planar:
        raise InvalidOptionError(
            "cone_edge_directions is for planar contacts; got a spatial contact "
            f"{contact!r}"
        )
    mu = contact.mu if 1 in contact.effective_components() else 0.0
    local = np.array([[1.0, mu], [1.0, -mu]]) / np.hypot(1.0, mu)
    return local @ np.asarray(contact.frame, dtype=float).T


@checked_call
def exact_cone_mesh(
    mu: float, height: float, *, num_segments: int = 32, sign: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Lateral surface of the Coulomb cone ``‖f_t‖ ≤ μ f_n`` as triangles.

    Parameters
    ----------
    mu : float
        Friction coefficient: ``> 0``, in [1e-12, 1e12] (0, a ray, is accepted
        too), the range of a contact's ``μ``
        (:data:`drakegrasp.core.validation.COEFFICIENT_MIN`/``MAX``).
    height : float
        Extent along the cone's axis, metres, in ``[DRAW_LENGTH_MIN,
        DRAW_LENGTH_MAX]`` (see :func:`positive_length`).
    num_segments : int, optional
        Triangles around the axis, an integer in ``[3, MAX_CONE_SEGMENTS]`` =
        [3, 1024].
    sign : float, optional
        ``+1`` opens the cone along ``+x``, ``-1`` reflects it through the apex
        (see the module notes on ``side``); nothing else.

    Returns
    -------
    vertices : (num_segments + 1, 3) float
        In the contact frame (x = normal, y = t1, z = t2): the apex (row 0) at
        the origin, then the rim points ``sign · h [1, μ cos θ_k, μ sin θ_k]``.
    faces : (num_segments, 3) int
        Triangles ``(apex, k, k+1)`` indexing ``vertices``.

    Raises
    ------
    InvalidOptionError
        For a ``mu``, ``height``, ``num_segments`` or ``sign`` outside its
        range (NaN, a negative ``mu``, a string...), naming it.
    """
    mu = check_coefficient("mu", mu, error=InvalidOptionError)
    height = positive_length("height", height)
    n = integer_or_none(num_segments, integral_floats=True)
    if n is None or not (3 <= n <= MAX_CONE_SEGMENTS):
        raise InvalidOptionError(
            f"num_segments must be an integer >= 3 and <= {MAX_CONE_SEGMENTS} "
            "(drakegrasp.visualization.geometry.MAX_CONE_SEGMENTS), got "
            f"{describe(num_segments)}"
        )
    sign = check_sign(sign)
    theta = 2.0 * np.pi * np.arange(n) / n
    rim = np.column_stack([np.full(n, 1.0), mu * np.cos(theta), mu * np.sin(theta)]) * (
        sign * height
    )
    vertices = np.vstack([np.zeros(3), rim])
    k = np.arange(n)
    faces = np.column_stack([np.zeros(n, dtype=int), 1 + k, 1 + (k + 1) % n])
    return vertices, faces


def pyramid_generators(
    contact: Contact, num_generators: int, *, characteristic_length: float
) -> np.ndarray:
    """Force generators ``[1, μ cos, μ sin]`` of the linearised cone, (3, n_g).

    The soft finger's pure-moment generators ``[1, 0, 0, ±bν]`` are left out (a
    moment about the normal has no arrow in the picture).  Empty (3, 0) when
    the contact has no friction.
    """
    S = friction_cone_generators(
        contact, num_generators, characteristic_length=characteristic_length
    )
    if contact.num_components < 3 or 1 not in contact.effective_components():
        return np.zeros((3, 0))
    S = S[:3]
    keep = np.linalg.norm(S[1:3], axis=0) > 0.0
    return S[:, keep]


@checked_call
def pyramid_mesh(
    generators: np.ndarray, height: float, *, sign: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Side faces of the polyhedral cone spanned by ``generators``.

    Parameters
    ----------
    generators : (3, m) float
        ``m >= 3`` generators ``s_k`` in the contact frame, ordered around the
        axis, each with first component 1 (any finite first component > 0:
        each is divided by it; the others at most 1e12 times it).
    height : float
        Extent along the axis, metres: edge ``k`` ends at ``sign · h s_k``
        (a length as :func:`positive_length` takes).
    sign : float, optional
        ``+1`` or ``-1`` (reflection through the apex).

    Returns
    -------
    vertices : (m + 1, 3) float
        Apex (row 0) then the edge ends, in the contact frame.
    faces : (m, 3) int
        Triangles ``(apex, k, k+1)``.

    Raises
    ------
    InvalidOptionError
        For generators that are not a finite (3, m) array with first row > 0,
        or a bad ``height`` or ``sign``.
    """
    S = real_array("generators", generators, error=InvalidOptionError)
    if S.ndim != 2 or S.shape[0] != 3 or S.shape[1] < 3:
        raise InvalidOptionError(
            "generators must be a (3, m) array with m >= 3 (one column per edge "
            f"of the pyramid), got shape {S.shape}"
        )
    with np.errstate(all="ignore"):
        edges = S / S[0]
    if not (
        np.all(np.isfinite(S))
        and np.all(S[0] > 0.0)
        and np.all(np.abs(edges) <= COEFFICIENT_MAX)
    ):
        raise InvalidOptionError(
            "generators must be finite, each with a first (normal) component > 0 "
            f"and the others at most {COEFFICIENT_MAX:g} times it (mu <= "
            f"{COEFFICIENT_MAX:g}), got {describe(S.tolist())}"
        )
    height = positive_length("height", height)
    sign = check_sign(sign)
    m = S.shape[1]
    vertices = np.vstack([np.zeros(3), (sign * height) * edges.T])
    k = np.arange(m)
    faces = np.column_stack([np.zeros(m, dtype=int), 1 + k, 1 + (k + 1) % m])
    return vertices, faces
