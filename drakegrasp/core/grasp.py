r"""A grasp (a set of contacts on one object) and its grasp matrices (numpy only).

.. math::

    G_i = \begin{bmatrix} R_i \\ S(c_i - p)\, R_i \end{bmatrix}, \qquad
    G = [G_1 \; \cdots \; G_N]

restricted to the force components of each contact model (a soft finger adds
the column :math:`[0; n_i]`).  Wrenches are ``[f; m]`` with moments about the
reference point ``p``; planar wrenches are ``[f_x, f_y, m_z]``.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import Contact, ContactModel
from drakegrasp.core.deprecation import renamed_keyword, warn_deprecated
from drakegrasp.core.validation import (
    JACOBIAN_BOUND,
    LENGTH_MIN,
    check_length,
    check_positions,
    items_of,
    real_array,
    safe_norm,
)
from drakegrasp.errors import InvalidContactError, InvalidGraspError

__all__ = [
    "Grasp",
    "check_hand_jacobian",
    "grasp_matrix",
    "normal_grasp_matrix",
    "invariant_grasp_matrix",
    "normalised_grasp_matrix",
    "scaled_for_metrics",
    "wrench_columns",
]


@checked_call
@dataclass(frozen=True, eq=False)
class Grasp:
    """Contacts on one object, all expressed in one frame.

    Parameters
    ----------
    contacts : sequence of Contact
        At least one contact; all planar or all spatial.
    reference_point : (3,) or (2,) float, optional
        Point ``p`` about which moments are taken, metres, in the grasp frame.
        Default: the frame's origin.
    characteristic_length : float, optional
        Length ``b`` > 0 (metres) that turns moments into forces in soft-finger
        cones and quality metrics.  Default: the largest distance from ``p`` to a
        contact (1 m if every contact is at ``p``), computed without overflow.
        The default follows ``p``, and a soft finger's torsion limit
        ``b ν f_n`` with it: pass a length to compare soft-finger answers about
        different reference points.

    Raises
    ------
    InvalidGraspError
        ``contacts`` not an iterable of :class:`Contact`, or empty; a
        reference point that is not a real finite ``d``-vector within
        :data:`~drakegrasp.core.validation.POSITION_BOUND`; a characteristic length
        outside ``[2.2e-308, 1e30]`` m.
    InvalidContactError
        Mixed planar and spatial contacts, or an item that is not a Contact.
    """

    contacts: tuple[Contact, ...]
    reference_point: np.ndarray
    characteristic_length: float

    def __init__(
        self,
        contacts: Iterable[Contact],
        *,
        reference_point: np.ndarray | None = None,
        characteristic_length: float | None = None,
    ) -> None:
        if isinstance(contacts, Contact):
            contacts = (contacts,)
        contacts = tuple(
            items_of(
                "contacts",
                contacts,
                "an iterable of drakegrasp.Contact",
                error=InvalidGraspError,
            )
        )
        if not contacts:
            raise InvalidGraspError("a grasp needs at least one contact, got none")
        for i, c in enumerate(contacts):
            if not isinstance(c, Contact):
                raise InvalidContactError(
                    f"contact {i} is a {type(c).__name__}, not a drakegrasp.Contact"
                )
        dims = {c.dim for c in contacts}
        if len(dims) > 1:
            planar = [i for i, c in enumerate(contacts) if c.planar]
            raise InvalidContactError(
                "a grasp's contacts must be all planar or all spatial; contacts "
                f"{planar} are planar and the others spatial"
            )
        dim = dims.pop()
        if reference_point is None:
            p = np.zeros(dim)
        else:
            p = np.array(
                check_positions(
                    "reference_point", reference_point, error=InvalidGraspError
                )
            ).reshape(-1)
            if p.shape != (dim,):
                raise InvalidGraspError(
                    f"reference_point must be a finite {dim}-vector like the "
                    f"contacts, got {np.asarray(reference_point).tolist()}"
                )
        p.flags.writeable = False
        if characteristic_length is None:
            offsets = np.array([c.position for c in contacts]) - p
            b = float(np.max(safe_norm(offsets, axis=-1)))
            b = b if b >= LENGTH_MIN else 1.0
        else:
            b = check_length("characteristic_length", characteristic_length)
        object.__setattr__(self, "contacts", contacts)
        object.__setattr__(self, "reference_point", p)
        object.__setattr__(self, "characteristic_length", b)

    @property
    def dim(self) -> int:
        """Dimension of the contacts: 2 (planar) or 3 (spatial)."""
        return self.contacts[0].dim

    @property
    def planar(self) -> bool:
        """True when the contacts are 2-D (wrenches have 3 rows)."""
        return self.dim == 2

    @property
    def num_contacts(self) -> int:
        """Number of contacts ``N``."""
        return len(self.contacts)

    @property
    def wrench_dim(self) -> int:
        """Rows of a wrench: 3 (planar) or 6 (spatial)."""
        return 3 if self.planar else 6

    @property
    def positions(self) -> np.ndarray:
        """Contact positions, (N, d), metres."""
        return np.array([c.position for c in self.contacts])

    @property
    def normals(self) -> np.ndarray:
        """Inward unit normals, (N, d)."""
        return np.array([c.normal for c in self.contacts])

    @property
    def num_components(self) -> int:
        """Total number of contact-force components (columns of ``G``)."""
        return self._slices[-1].stop

    def component_slices(self) -> list[slice]:
        """Slice of each contact's components in the stacked force vector."""
        return list(self._slices)

    def normal_indices(self) -> np.ndarray:
        """Index of each contact's ``f_n`` in the stacked force vector, (N,) int."""
        return np.array([s.start for s in self._slices], dtype=int)

    @functools.cached_property
    def _slices(self) -> tuple[slice, ...]:
        slices, start = [], 0
        for c in self.contacts:
            slices.append(slice(start, start + c.num_components))
            start += c.num_components
        return tuple(slices)

    def with_contacts(self, contacts: Sequence[Contact]) -> Grasp:
        """Same reference point and characteristic length, other contacts."""
        return Grasp(
            contacts,
            reference_point=self.reference_point,
            characteristic_length=self.characteristic_length,
        )

    @renamed_keyword("model", "contact_model")
    def with_friction(
        self,
        mu: float | None = None,
        *,
        contact_model: ContactModel | str | None = None,
        torsional_friction: float | None = None,
    ) -> Grasp:
        """Copy with every contact's friction and contact model set (those given).

        ``model=`` is a deprecated alias of ``contact_model=``.  Contacts made
        soft fingers need ``torsional_friction`` (:meth:`Contact.with_`).
        """
        changes = {}
        if mu is not None:
            changes["mu"] = mu
        if contact_model is not None:
            changes["contact_model"] = contact_model
        if torsional_friction is not None:
            changes["torsional_friction"] = torsional_friction
        return self.with_contacts([c.with_(**changes) for c in self.contacts])

    @functools.cached_property
    def _grasp_matrix(self) -> np.ndarray:
        """G, computed once (the grasp is immutable); read-only."""
        p = self.reference_point
        G = np.hstack([_contact_block(c, p) for c in self.contacts])
        G.flags.writeable = False
        return G

    @functools.cached_property
    def _invariant_grasp_matrix(self) -> np.ndarray:
        """``T G`` with moments about the centroid over the spread; read-only."""
        positions = self.positions
        centroid = positions.mean(axis=0)
        # safe_norm: squares of coordinates below 1e-154 m underflow, and a
        # spread of 0 dropped every moment row (the rank collapsed at 1e-163 m)
        spread = float(np.max(safe_norm(positions - centroid, axis=1)))
        if not (np.isfinite(spread) and spread > 0.0):
            spread = 1.0  # every contact at one point: all moments vanish anyway
        G = np.hstack([_contact_block(c, centroid) for c in self.contacts])
        G[self.dim :] /= spread
        G.flags.writeable = False
        return G

    def to_dict(self) -> dict:
        """JSON-ready dictionary of the grasp."""
        return {
            "contacts": [c.to_dict() for c in self.contacts],
            "reference_point": self.reference_point.tolist(),
            "characteristic_length": self.characteristic_length,
        }

    def __repr__(self) -> str:
        kind = "planar" if self.planar else "spatial"
        return (
            f"Grasp({self.num_contacts} {kind} contacts, "
            f"p={self.reference_point.tolist()}, b={self.characteristic_length:g})"
        )


def wrench_columns(
    position: np.ndarray, directions: np.ndarray, reference_point: np.ndarray
) -> np.ndarray:
    """Wrenches of unit forces applied at one point.

    Parameters
    ----------
    position : (d,) float
        Point of application ``c``, metres.
    directions : (d, k) float
        Force directions as columns.
    reference_point : (d,) float
        Point ``p`` about which moments are taken.

    Returns
    -------
    W : (6, k) or (3, k) float
        ``[u; (c - p) × u]`` for each column ``u`` (planar: ``m_z`` only).
    """
    r = np.asarray(position, dtype=float) - np.asarray(reference_point, dtype=float)
    u = np.asarray(directions, dtype=float)
    if r.size == 2:
        return np.vstack([u, r[0] * u[1] - r[1] * u[0]])
    # r × u written out: np.cross costs ~50 µs of overhead on arrays this small.
    moment = np.vstack(
        [
            r[1] * u[2] - r[2] * u[1],
            r[2] * u[0] - r[0] * u[2],
            r[0] * u[1] - r[1] * u[0],
        ]
    )
    return np.vstack([u, moment])


def _contact_block(contact: Contact, p: np.ndarray) -> np.ndarray:
    R = contact.frame
    k = contact.num_components
    if contact.contact_model is ContactModel.FRICTIONLESS:
        return wrench_columns(contact.position, R[:, :1], p)
    block = wrench_columns(contact.position, R, p)
    if k == 4:  # soft finger: a pure moment about the normal
        block = np.hstack([block, np.concatenate([np.zeros(3), R[:, 0]])[:, None]])
    return block


@checked_call
def grasp_matrix(grasp: Grasp) -> np.ndarray:
    r"""Grasp matrix ``G`` mapping contact forces to the object wrench.

    Parameters
    ----------
    grasp : Grasp
        The contacts, in the grasp frame.

    Returns
    -------
    G : (6, M) or (3, M) float
        ``w = G f`` with ``f`` the stacked contact forces in their contact frames
        (normal component first; ``M`` = total number of components) and ``w``
        the wrench ``[f; m]`` about the reference point, in the grasp frame.

    Notes
    -----
    .. math:: G_i = \begin{bmatrix} R_i \\ S(c_i - p) R_i \end{bmatrix}

    restricted to the components of the contact model; column order follows
    contact order.

    Examples
    --------
    Three hard fingers on a unit circle's equator: three columns each.

    >>> import numpy as np
    >>> import drakegrasp as dg
    >>> a = 2 * np.pi * np.arange(3) / 3
    >>> c = np.c_[np.cos(a), np.sin(a), np.zeros(3)]
    >>> grasp = dg.Grasp([dg.Contact(ci, -ci, mu=0.5) for ci in c])
    >>> dg.grasp_matrix(grasp).shape
    (6, 9)
    """
    return _require_grasp(grasp)._grasp_matrix.copy()


@checked_call
def normal_grasp_matrix(grasp: Grasp) -> np.ndarray:
    """Grasp matrix ``G_n`` of the normal components only.

    Parameters
    ----------
    grasp : Grasp

    Returns
    -------
    G_n : (6, N) or (3, N) float
        Column ``i`` is the wrench ``[n_i; (c_i - p) × n_i]`` of a unit normal
        push at contact ``i``.
    """
    return _require_grasp(grasp)._grasp_matrix[:, grasp.normal_indices()]


@checked_call
def invariant_grasp_matrix(grasp: Grasp) -> np.ndarray:
    r"""``G`` made invariant to units and to the reference point, for rank tests.

    Parameters
    ----------
    grasp : Grasp

    Returns
    -------
    G_bar : (6, M) or (3, M) float
        The columns of :func:`grasp_matrix`, in the same order, with moments
        taken about the contacts' centroid :math:`\bar c` and divided by their
        spread :math:`L = \max_i \lVert c_i - \bar c \rVert` (``L = 1`` when
        every contact is at one point).

    Notes
    -----
    .. math::

        \bar G = T G, \qquad
        T = \begin{bmatrix} I & 0 \\ 0 & I / L \end{bmatrix}
            \begin{bmatrix} I & 0 \\ S(p - \bar c) & I \end{bmatrix}

    ``T`` is invertible, so ``Ḡ`` has the null space, the rank and the row
    space of ``G``: every program's ``G f = 0`` and every rank verdict can use
    it.  Unlike ``G``, it does not change when the reference point moves, when
    the whole grasp moves rigidly, or when lengths change units (mm, m, km), so
    a relative singular-value threshold means the same thing for every grasp:
    moments about a point ``10⁶ b`` away, or in nanometres, no longer swamp or
    vanish beside the forces.
    """
    return _require_grasp(grasp)._invariant_grasp_matrix.copy()


@checked_call
def normalised_grasp_matrix(grasp: Grasp) -> np.ndarray:
    """Deprecated name of :func:`invariant_grasp_matrix` (``T G``).

    It was four letters away from :func:`normal_grasp_matrix` (``G_n``), which
    holds something else.
    """
    warn_deprecated(
        "normalised_grasp_matrix is deprecated; use invariant_grasp_matrix "
        "(normal_grasp_matrix is G_n, another matrix)"
    )
    return invariant_grasp_matrix(grasp)


def scaled_for_metrics(
    G: np.ndarray, b: float | np.ndarray, torsion_columns: np.ndarray
) -> np.ndarray:
    r"""``Ĝ = T G S``: the grasp matrix whose singular values the metrics read.

    Parameters
    ----------
    G : (..., 6, M) or (..., 3, M) float
        Grasp matrices (:func:`grasp_matrix`, or a stack of them), about the
        grasps' reference points.
    b : float or (...,) float
        The length ``b_s`` (metres) of each matrix.
    torsion_columns : (n,) int
        The columns of ``G`` that are a soft finger's torsional moment
        ``m_n`` (``[0; n]``), the same in every matrix of the stack.

    Returns
    -------
    (..., 6, M) or (..., 3, M) float
        A new array: ``T = diag(I, I / b_s)`` divides the moment rows by
        ``b_s``, and ``S`` multiplies each torsion column by ``b_s``, so that
        that column stays ``[0; n]``.

    Notes
    -----
    A soft finger's ``m_n`` is an input in N·m; written as ``m_n = b_s μ̃``
    with ``μ̃`` in N (as every other input), its column is ``[0; b_s n]`` and
    ``T`` brings it back to ``[0; n]``.  Every entry of ``Ĝ`` is then
    dimensionless and unchanged when lengths and ``b_s`` are scaled together;
    without ``S`` that column was ``[0; n / b_s]``, in 1/m.  Hard-finger,
    frictionless and planar grasps have no torsion column: ``Ĝ = T G``, to
    the bit.  The column is copied, not multiplied, so ``b_s = 1`` changes
    nothing either.
    """
    rows = slice(3, 6) if G.shape[-2] == 6 else slice(2, 3)
    out = np.array(G, dtype=float)
    b = np.asarray(b, dtype=float)[..., None, None]
    out[..., rows, :] /= b
    if len(torsion_columns):
        out[..., rows, torsion_columns] = G[..., rows, torsion_columns]
    return out


def _require_grasp(grasp) -> Grasp:
    if not isinstance(grasp, Grasp):
        raise InvalidGraspError(
            f"grasp must be a drakegrasp.Grasp, got {type(grasp).__name__}"
        )
    return grasp


def check_hand_jacobian(grasp: Grasp, hand_jacobian: np.ndarray) -> np.ndarray:
    """Validate a hand Jacobian against a grasp.

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_v) float
        One row per column of ``G`` (contact-frame components, contact order),
        one column per hand velocity.

    Returns
    -------
    J : (M, n_v) float
        The Jacobian as a float array.

    Raises
    ------
    InvalidGraspError
        On a wrong shape (naming the expected one), a non-real dtype, or
        non-finite or out-of-bound entries.
    """
    _require_grasp(grasp)
    J = real_array("hand_jacobian", hand_jacobian, error=InvalidGraspError)
    M = grasp.num_components
    if J.ndim != 2 or J.shape[0] != M or J.shape[1] < 1:
        raise InvalidGraspError(
            f"hand_jacobian must have shape ({M}, n_v) — one row per column of G "
            f"(contact-frame components) and one column per hand velocity — got "
            f"shape {J.shape}"
        )
    if not np.all(np.isfinite(J)):
        raise InvalidGraspError("hand_jacobian has non-finite entries")
    if float(np.max(np.abs(J))) > JACOBIAN_BOUND:
        raise InvalidGraspError(
            f"hand_jacobian has an entry beyond |J_ij| <= {JACOBIAN_BOUND:g} "
            "(drakegrasp.core.validation.JACOBIAN_BOUND)"
        )
    return J
