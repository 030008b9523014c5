r"""Curvatures at a contact and the Hessian of its signed distance (numpy only).

Second-order form closure (:mod:`drakegrasp.closure.second_order`) needs, at every
contact, how the signed distance ``ψ_i`` between the moving object and the
fixed finger bends along a rigid motion of the object.  This module holds the
geometry that decides it: the principal curvatures of the object's and the
finger's surfaces at the contact (:class:`SurfaceCurvature`,
:class:`ContactCurvature`) and the quadratic form ``H_i`` with

.. math::

    \psi_i(q(t)) = \psi_i(0) + t\, G_i^T v
        + \tfrac{t^2}{2}\left(G_i^T a + v^T H_i v\right) + O(t^3),

for the motion ``q(t)`` of the object whose rotation is ``exp(S(tω + t²α/2))``
about the reference point ``p`` and whose point ``p`` moves by
``t v_p + t² a_p / 2`` (``v = [v_p; ω]``, ``a = [a_p; α]``, grasp frame).
The derivation is in ``docs/second_order.md``.

**Curvature model.**  A principal curvature is positive where the surface is
convex (it bends away from the other body), negative where concave, zero where
flat and ``+inf`` across a sharp feature: a box edge is ``0`` along the edge
and ``inf`` across it, a box corner or a sharp point finger is ``inf`` in every
direction (a sphere of radius 0).  A spherical fingertip of radius ``r`` has
curvature ``1/r``; a fingertip with a spherical cavity of radius ``R``,
``-1/R``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.validation import (
    describe,
    items_of,
    real_array,
    real_scalar,
    unit_vectors,
)
from drakegrasp.errors import InvalidContactError

__all__ = [
    "ContactCurvature",
    "SurfaceCurvature",
    "contact_hessian",
    "contact_hessians",
]

DIRECTION_TOL = 1e-6
"""A principal direction may leave the tangent plane by at most this (cosine)."""

CURVATURE_BOUND = 1e100
"""Largest finite principal curvature (1/m).  Beyond it use ``+inf`` (a sharp
feature): the relative-curvature form squares curvatures, and ``1e308`` overflowed
it into ``inf`` and LAPACK errors.  The grasp-relative bound is
:data:`RELATIVE_CURVATURE_BOUND`."""

RELATIVE_CURVATURE_BOUND = 1e12
"""Largest finite ``|κ| b`` (curvature times the grasp's characteristic length).

A curvature this sharp relative to the grasp is a sharp feature to double
precision (its radius is ``1e-12`` of the grasp's size); the second-order form
would mix ``κ`` with terms of order 1 and lose every digit of the latter.
Describe such a feature by ``+inf``."""

ISOLATION_TOL = 1e-9
"""Relative curvature ``κ_o + κ_f`` (times ``b``) at or below this is not a point
contact: the surfaces conform along a line or an area."""


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a × b`` of two 3-vectors (np.cross costs ~20 µs on vectors this small)."""
    return np.array(
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    )


def _skew(x: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]])


@checked_call
@dataclass(frozen=True)
class SurfaceCurvature:
    """Principal curvatures of one surface at a contact point.

    Parameters
    ----------
    curvatures : (1,) or (2,) float, 1/metres
        One curvature (planar grasp) or the two principal curvatures (spatial).
        Positive convex, negative concave, ``+inf`` across a sharp edge.
    direction : (3,) float or None
        Spatial only: the principal direction of ``curvatures[0]``, a unit
        vector in the contact's tangent plane, in the grasp frame; the second
        direction is ``n × direction``.  May be None when both curvatures are
        equal (a sphere, a plane, a point).

    Notes
    -----
    Build these with :meth:`flat`, :meth:`point`, :meth:`convex`,
    :meth:`concave` and :meth:`edge` rather than by hand.
    """

    curvatures: tuple[float, ...]
    direction: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        values = real_array("principal curvatures", self.curvatures)
        k = tuple(float(x) for x in values.reshape(-1))
        if values.ndim > 1 or len(k) not in (1, 2):
            raise InvalidContactError(
                f"a surface has 1 (planar) or 2 (spatial) principal curvatures, "
                f"got {values.tolist()}"
            )
        for x in k:
            if (
                math.isnan(x)
                or x == -math.inf
                or (math.isfinite(x) and abs(x) > CURVATURE_BOUND)
            ):
                raise InvalidContactError(
                    f"principal curvature {x!r} is not valid: use a finite value "
                    f"with |κ| <= {CURVATURE_BOUND:g} 1/m (positive convex, "
                    "negative concave) or +inf across a sharp edge"
                )
        d = self.direction
        if d is not None:
            raw = real_array("a principal direction", d)
            if raw.shape != (3,):
                raise InvalidContactError(
                    f"a principal direction is a finite 3-vector, got shape "
                    f"{raw.shape}: {raw.reshape(-1).tolist()[:6]}"
                )
            # normalised without overflow or underflow; zero and NaN refused
            d = tuple(float(x) for x in unit_vectors("a principal direction", raw))
        if len(k) == 2 and d is None and k[0] != k[1]:
            raise InvalidContactError(
                f"principal curvatures {list(k)} differ, so the direction of the "
                "first one is needed"
            )
        object.__setattr__(self, "curvatures", k)
        object.__setattr__(self, "direction", d)

    @classmethod
    def flat(cls, *, planar: bool = False) -> SurfaceCurvature:
        """A flat face (curvature 0)."""
        return cls((0.0,) if planar else (0.0, 0.0))

    @classmethod
    def point(cls, *, planar: bool = False) -> SurfaceCurvature:
        """A sharp point (a point finger, a corner): ``+inf`` in every direction."""
        return cls((math.inf,) if planar else (math.inf, math.inf))

    @classmethod
    def convex(cls, radius: float, *, planar: bool = False) -> SurfaceCurvature:
        """A sphere (disc) of ``radius`` metres seen from outside: ``1/radius``."""
        k = 1.0 / _radius(radius)
        return cls((k,) if planar else (k, k))

    @classmethod
    def concave(cls, radius: float, *, planar: bool = False) -> SurfaceCurvature:
        """A spherical (circular) cavity of ``radius`` metres: ``-1/radius``."""
        k = -1.0 / _radius(radius)
        return cls((k,) if planar else (k, k))

    @classmethod
    def edge(cls, direction: np.ndarray, curvature: float = 0.0) -> SurfaceCurvature:
        """A sharp edge along ``direction`` (spatial), ``curvature`` along it."""
        return cls((curvature, math.inf), direction)

    @classmethod
    def from_shape_form(cls, form: np.ndarray, normal: np.ndarray) -> SurfaceCurvature:
        """Principal curvatures of the form ``II(x, x) = xᵀ form x`` on the tangents.

        Parameters
        ----------
        form : (3, 3) float, 1/m
            Symmetric; for an implicit surface ``F(x) = 0`` with ``F < 0``
            inside, ``∇²F / |∇F|`` (positive on a convex surface).
        normal : (3,) float
            Unit surface normal (either sign); ``form`` is restricted to the
            plane orthogonal to it.

        Returns
        -------
        SurfaceCurvature
            Spatial, with the direction of the first principal curvature.
        """
        n = np.asarray(normal, dtype=float)
        a = np.zeros(3)
        a[int(np.argmin(np.abs(n)))] = 1.0
        t1 = np.cross(n, a)
        t1 /= np.linalg.norm(t1)
        P = np.column_stack([t1, np.cross(n, t1)])
        F = np.asarray(form, dtype=float)
        k, V = np.linalg.eigh(P.T @ (0.5 * (F + F.T)) @ P)
        return cls((float(k[0]), float(k[1])), P @ V[:, 0])

    @property
    def planar(self) -> bool:
        """True for a planar (one-curvature) surface."""
        return len(self.curvatures) == 1

    def tangent_form(self, normal: np.ndarray, tangents: np.ndarray):
        """The curvature in a tangent basis: finite part and sharp directions.

        Parameters
        ----------
        normal : (3,) or (2,) float
            The contact normal (unit).
        tangents : (d, k) float
            Orthonormal tangent basis (columns), ``k = d - 1``.

        Returns
        -------
        K : (k, k) float
            The second fundamental form's finite part in the tangent basis.
        E : (m, k) float
            Orthonormal rows spanning the directions of infinite curvature.
        """
        if self.planar:
            (k,) = self.curvatures
            if math.isinf(k):
                return np.zeros((1, 1)), np.ones((1, 1))
            return np.array([[k]]), np.zeros((0, 1))
        n = np.asarray(normal, dtype=float)
        if self.direction is None:
            d1 = tangents[:, 0]
        else:
            d1 = np.asarray(self.direction)
            d1 = d1 / np.linalg.norm(d1)
            if abs(d1 @ n) > DIRECTION_TOL:
                raise InvalidContactError(
                    f"principal direction {np.round(d1, 6).tolist()} is not in the "
                    f"tangent plane of normal {np.round(n, 6).tolist()}"
                )
            d1 = d1 - (d1 @ n) * n
            d1 /= np.linalg.norm(d1)
        d2 = _cross(n, d1)
        K = np.zeros((2, 2))
        rows = []
        for k, d in zip(self.curvatures, (d1, d2), strict=True):
            e = tangents.T @ d
            if math.isinf(k):
                rows.append(e)
            else:
                K += k * np.outer(e, e)
        return K, np.array(rows).reshape(-1, 2)


def _radius(radius: float) -> float:
    r = real_scalar("a radius", radius, error=InvalidContactError)
    if not math.isfinite(r) or not r >= 1.0 / CURVATURE_BOUND:
        raise InvalidContactError(
            f"a radius must be finite and >= {1.0 / CURVATURE_BOUND:g} m "
            f"(1 / CURVATURE_BOUND), got {describe(radius)}"
        )
    return r


@checked_call
@dataclass(frozen=True)
class ContactCurvature:
    """The object's and the finger's curvature at one contact.

    Parameters
    ----------
    object : SurfaceCurvature
        The object's surface at the contact point.
    finger : SurfaceCurvature
        The finger's surface at the contact point (fixed during the motion).
    """

    object: SurfaceCurvature
    finger: SurfaceCurvature

    def __post_init__(self) -> None:
        for name in ("object", "finger"):
            value = getattr(self, name)
            if not isinstance(value, SurfaceCurvature):
                raise InvalidContactError(
                    f"ContactCurvature's {name} must be a SurfaceCurvature (build "
                    "one with SurfaceCurvature.flat/point/convex/concave/edge), got "
                    f"{type(value).__name__}"
                )
        if self.object.planar != self.finger.planar:
            raise InvalidContactError(
                "ContactCurvature's object and finger must both be planar (one "
                "curvature) or both spatial (two): got "
                f"{len(self.object.curvatures)} and {len(self.finger.curvatures)}"
            )

    @classmethod
    def point_finger(cls, object: SurfaceCurvature) -> ContactCurvature:
        """A sharp point finger on a surface of the object."""
        return cls(object, SurfaceCurvature.point(planar=object.planar))


def _relative_quadratic(
    contact_curvature: ContactCurvature,
    normal: np.ndarray,
    tangents: np.ndarray,
    length: float,
) -> np.ndarray:
    r"""The form ``M`` with ``ψ̈ - n·β = zᵀ M z``, ``z = [u_T; w_T]``.

    ``u_T`` is the tangential velocity of the object's material point at the
    contact and ``w_T = Tᵀ (n × ω)``.  ``M`` comes from minimising over the
    velocity ``σ`` of the closest point on the finger

    .. math:: (\sigma - u)^T K_o (\sigma - u) + 2 w^T (\sigma - u)
              + \sigma^T K_f \sigma

    with the sharp directions as constraints ``E_o(σ - u) = 0``, ``E_f σ = 0``.
    """
    Ko, Eo = contact_curvature.object.tangent_form(normal, tangents)
    Kf, Ef = contact_curvature.finger.tangent_form(normal, tangents)
    k = tangents.shape[1]
    eye = np.eye(k)
    B = np.zeros((3 * k, 3 * k))  # f = xᵀ B x, x = [σ; u; w]
    B[:k, :k], B[:k, k : 2 * k], B[k : 2 * k, :k] = Ko + Kf, -Ko, -Ko
    B[k : 2 * k, k : 2 * k] = Ko
    B[:k, 2 * k :] = B[2 * k :, :k] = eye
    B[k : 2 * k, 2 * k :] = B[2 * k :, k : 2 * k] = -eye
    L = np.zeros((3 * k, 2 * k))  # x = L z + R y
    L[k:] = np.eye(2 * k)
    m = len(Eo) + len(Ef)
    N = eye
    if m:
        C = np.vstack([Eo, Ef])
        u, s, vt = np.linalg.svd(C)
        if m > k or s[-1] <= 1e-9:
            raise InvalidContactError(
                "both surfaces are sharp in the same tangent direction (a point "
                "on an edge, parallel edges, a vertex on a vertex): the contact "
                "normal is not defined there, so neither is the second-order test"
            )
        D = np.zeros((m, 2 * k))
        D[: len(Eo), :k] = Eo
        L[:k] = vt[:m].T @ ((u.T @ D) / s[:, None])  # σ = C⁺ D z on the sharp rows
        N = vt[m:].T
    if N.shape[1] == 0:
        return L.T @ B @ L
    R = np.zeros((3 * k, N.shape[1]))
    R[:k] = N
    RBR = R.T @ B @ R
    kappa = np.linalg.eigvalsh(RBR)
    if kappa[0] * length <= ISOLATION_TOL:
        shown = np.round(kappa, 9).tolist()
        if kappa[0] > 0.0:  # positive, yet flat on the scale of the grasp's b
            raise InvalidContactError(
                f"the relative curvature κ_object + κ_finger, {shown} 1/m in the "
                f"smooth directions, times the grasp's length b = {length:g} m "
                f"is {kappa[0] * length:.3g} <= {ISOLATION_TOL:g} "
                "(ISOLATION_TOL): on that scale the surfaces conform, as flat on "
                "flat.  Give the grasp a characteristic_length of its own size "
                "(by default the largest distance from its reference point to a "
                "contact)"
            )
        raise InvalidContactError(
            "the relative curvature κ_object + κ_finger is not positive: "
            f"{shown} 1/m in the smooth "
            "directions.  Zero means the surfaces conform along a line or an "
            "area (flat on flat: describe the patch by its vertices, as "
            "drakegrasp.find_contacts does); negative means the finger's cavity "
            "is tighter than the object, which cannot touch at one point"
        )
    RBL = R.T @ B @ L
    return L.T @ B @ L - RBL.T @ np.linalg.solve(RBR, RBL)


def contact_hessian(
    grasp: Grasp, index: int, contact_curvature: ContactCurvature
) -> np.ndarray:
    r"""Second-order term ``H_i`` of contact ``index``'s signed distance.

    Parameters
    ----------
    grasp : Grasp
        Contacts and reference point ``p`` (grasp frame).
    index : int
        Which contact.
    contact_curvature : ContactCurvature
        Curvatures of object and finger at that contact (planar: one each).

    Returns
    -------
    H : (6, 6) or (3, 3) float, metres per (twist unit)²
        Symmetric; ``ψ̈_i = G_iᵀ a + vᵀ H_i v`` for the motion described in the
        module docstring (twists ``[v_p; ω]`` about ``p``).

    Notes
    -----
    With ``r = c_i - p``, ``u = v_p + ω × r`` and ``w = n × ω``:

    .. math::

        v^T H_i v = n \cdot \big(\omega \times (\omega \times r)\big)
            + \min_{\sigma}\; (\sigma - u)^T K_o (\sigma - u)
              + 2 w^T (\sigma - u) + \sigma^T K_f \sigma

    over tangent vectors ``σ``; for finite curvatures the minimum is
    ``uᵀ K_o K^{-1} K_f u − 2 wᵀ K^{-1} K_f u − wᵀ K^{-1} w`` with
    ``K = K_o + K_f``.
    """
    contact = grasp.contacts[index]
    n, c = contact.normal, contact.position
    r = c - grasp.reference_point
    planar = grasp.planar
    if contact_curvature.object.planar != planar or (
        contact_curvature.finger.planar != planar
    ):
        kind = "planar" if planar else "spatial"
        raise InvalidContactError(
            f"contact {index}: a {kind} grasp needs "
            f"{'one curvature' if planar else 'two principal curvatures'} per "
            "surface"
        )
    b = grasp.characteristic_length
    for surface, which in (
        (contact_curvature.object, "object"),
        (contact_curvature.finger, "finger"),
    ):
        finite = [abs(k) for k in surface.curvatures if math.isfinite(k)]
        if finite and max(finite) * b > RELATIVE_CURVATURE_BOUND:
            raise InvalidContactError(
                f"contact {index}: the {which}'s curvature {max(finite):g} 1/m times "
                f"the grasp's length b = {b:g} m is beyond "
                f"{RELATIVE_CURVATURE_BOUND:g} (RELATIVE_CURVATURE_BOUND): a "
                "feature that sharp is an edge or a point; give its curvature as "
                "+inf"
            )
    tangents = contact.frame[:, 1:]
    M = _relative_quadratic(contact_curvature, n, tangents, grasp.characteristic_length)
    if planar:
        t = tangents[:, 0]
        Z = np.array([[t[0], t[1], t @ np.array([-r[1], r[0]])], [0.0, 0.0, -1.0]])
        H = Z.T @ M @ Z
        H[2, 2] -= n @ r
        return 0.5 * (H + H.T)
    Tt = tangents.T
    Z = np.block([[Tt, -Tt @ _skew(r)], [np.zeros((2, 3)), Tt @ _skew(n)]])
    H = Z.T @ M @ Z
    H[3:, 3:] += 0.5 * (np.outer(n, r) + np.outer(r, n)) - (n @ r) * np.eye(3)
    return 0.5 * (H + H.T)


def contact_hessians(
    grasp: Grasp, curvatures: Sequence[ContactCurvature]
) -> np.ndarray:
    """:func:`contact_hessian` of every contact.

    Parameters
    ----------
    grasp : Grasp
    curvatures : sequence of ContactCurvature
        One per contact, in contact order.

    Returns
    -------
    H : (N, 6, 6) or (N, 3, 3) float
    """
    if isinstance(curvatures, (str, bytes)) or not hasattr(curvatures, "__iter__"):
        raise InvalidContactError(
            "curvatures must be a sequence of ContactCurvature (one per contact), "
            f"got a {type(curvatures).__name__}"
        )
    curvatures = tuple(
        items_of(
            "curvatures",
            curvatures,
            "a sequence of ContactCurvature (one per contact)",
            error=InvalidContactError,
        )
    )
    if len(curvatures) != grasp.num_contacts:
        raise InvalidContactError(
            f"curvatures has {len(curvatures)} entries but the grasp has "
            f"{grasp.num_contacts} contacts; give one ContactCurvature per contact"
        )
    for i, cc in enumerate(curvatures):
        if not isinstance(cc, ContactCurvature):
            raise InvalidContactError(
                f"curvatures[{i}] is a {type(cc).__name__}, not a ContactCurvature"
            )
    return np.array([contact_hessian(grasp, i, cc) for i, cc in enumerate(curvatures)])
