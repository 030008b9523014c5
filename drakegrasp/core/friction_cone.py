"""Polyhedral friction cones in generator (V) and facet (H) form (numpy only).

Generators are inscribed in the exact Coulomb cone:
``s_k = [1, μ cos(2πk/n_g), μ sin(2πk/n_g)]``, ``k = 1 … n_g``; a soft finger adds
``[1, 0, 0, ±b ν]``.  Facet rows give a positive value on the cone's axis
``[1, 0, 0, …]``; they have unit length except a soft finger's, whose rows are
the hard-finger rows applied to the normal force left after torsion (see
:func:`soft_finger_facets`: so a soft finger never scores below a hard one).
See ``docs/conventions.md``.

Support functions (:func:`cone_support`, :func:`support_of`) give
``max wᵀ G_i f_i`` over a contact's cone with ``f_n = 1``: they re-check an
unresisted-wrench certificate without a solver and help find one.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import Contact, ContactModel
from drakegrasp.core.grasp import Grasp, grasp_matrix
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import (
    check_contact,
    check_grasp,
    check_length,
    check_num_generators,
)
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "DEFAULT_NUM_GENERATORS",
    "ConeLayout",
    "EffectiveCone",
    "cone_support",
    "effective_cone",
    "friction_cone_facets",
    "friction_cone_generators",
    "soft_finger_facets",
    "support_of",
    "torsion_only_facets",
]


@dataclass(frozen=True)
class EffectiveCone:
    """A contact's cone restricted to the components it lets be non-zero.

    Attributes
    ----------
    components : tuple of int
        Indices (into the contact's force vector) of the kept components.
    generators : (len(components), m) float
        Generators as columns, in the kept components.
    facets : (r, len(components)) float
        Unit facet rows, positive on the axis; ``facets @ f >= 0`` is the cone.
    """

    components: tuple[int, ...]
    generators: np.ndarray
    facets: np.ndarray


def _check_num_generators(num_generators: int) -> int:
    return check_num_generators(num_generators)


def _torsion_scale(contact: Contact, characteristic_length: float | None) -> float:
    if characteristic_length is None:
        raise InvalidOptionError(
            "a soft finger with torsional_friction > 0 needs the grasp's "
            "characteristic_length b (its moment bound is b * nu * f_n)"
        )
    b = check_length(
        "characteristic_length", characteristic_length, error=InvalidOptionError
    )
    return b * contact.torsional_friction


def _two_sided(slope: float) -> tuple[np.ndarray, np.ndarray]:
    """Cone |x| <= slope * f_n in two components: generators and facets."""
    S = np.array([[1.0, 1.0], [slope, -slope]])
    F = np.array([[slope, 1.0], [slope, -1.0]]) / np.hypot(1.0, slope)
    return S, F


def torsion_only_facets(torsion: np.ndarray) -> np.ndarray:
    """Facet rows of a soft finger without tangential friction, on ``(f_n, m_n)``.

    Parameters
    ----------
    torsion : (K,) float
        ``τ = b ν > 0`` (metres).

    Returns
    -------
    F : (K, 2, 2) float
        Rows ``[1, ∓1/τ]``: the value is ``f_n - |m_n| / τ``, the normal force
        left once the torsion has taken its share (see
        :func:`soft_finger_facets`).  At ``m_n = 0`` it is the frictionless
        row ``[1]``, so such a finger never scores below a frictionless one.
    """
    tau = np.asarray(torsion, dtype=float)
    F = np.empty(tau.shape + (2, 2))
    F[..., 0] = 1.0
    F[..., 0, 1] = -1.0 / tau
    F[..., 1, 1] = 1.0 / tau
    return F


def soft_finger_facets(mu: np.ndarray, torsion: np.ndarray, n_g: int) -> np.ndarray:
    r"""Facet rows of the soft-finger cone on ``(f_n, f_t1, f_t2, m_n)``.

    Parameters
    ----------
    mu : (K,) float
        Friction coefficients, ``> 0``.
    torsion : (K,) float
        ``τ = b ν > 0`` (metres).
    n_g : int
        Generators of the Coulomb ring.

    Returns
    -------
    F : (K, 2 n_g, 4) float
        Row ``k`` (``+τ`` apex first, then ``-τ``):
        ``[μ c, -u_k, ∓μ c / τ] / sqrt(1 + μ² c²)`` with ``c = cos(π/n_g)``.

    Notes
    -----
    The cone is the bipyramid spanned by the generators ``s_k`` (``m_n = 0``)
    and ``[1, 0, 0, ±τ]`` — the linearised
    ``‖f_t‖/μ + |m_n|/τ <= f_n`` — and every row's value is the hard-finger
    facet row applied to ``(f_n - |m_n|/τ, f_t)``:

    .. math:: F_k f = h_k^T (f_n - |m_n|/	au,\; f_t), \qquad
              h_k = [\mu c, -u_k] / \sqrt{1 + \mu^2 c^2}

    so the LP margin ``d`` of a soft finger is the hard-finger margin of the
    force that remains once the torsion has taken its share of the normal
    force.  This is the documented definition (``docs/conventions.md``, "Monotonicity"):
    rows scaled to unit length would tilt the facets out of the ``m_n = 0``
    slice and make ``d`` vanish with ``τ`` (``d* = 0.0002`` where hard fingers
    give 0.121 at ``ν = 0.01``).  With these rows a soft finger's ``d*`` is
    never below the hard finger's (any hard solution, with ``m_n = 0``, is a
    soft one with the same ``d``) and grows with ``ν``.
    """
    mu = np.asarray(mu, dtype=float)
    tau = np.asarray(torsion, dtype=float)
    a = mu * np.cos(np.pi / n_g)
    u = _facet_directions(n_g)
    scale = 1.0 / np.hypot(1.0, a)
    F = np.empty(mu.shape + (2 * n_g, 4))
    for half, sign in enumerate((1.0, -1.0)):
        rows = F[..., half * n_g : (half + 1) * n_g, :]
        rows[..., 0] = (a * scale)[..., None]
        rows[..., 1:3] = -u * scale[..., None, None]
        rows[..., 3] = (-sign * a * scale / tau)[..., None]
    return F


def _circle_generators(mu: float, n_g: int) -> np.ndarray:
    angles = 2.0 * np.pi * np.arange(1, n_g + 1) / n_g
    return np.vstack([np.ones(n_g), mu * np.cos(angles), mu * np.sin(angles)])


def _facet_directions(n_g: int) -> np.ndarray:
    """Unit tangent directions ``u_k`` bisecting generators ``k`` and ``k + 1``."""
    phi = 2.0 * np.pi * (np.arange(1, n_g + 1) + 0.5) / n_g
    return np.column_stack([np.cos(phi), np.sin(phi)])


def _pyramid_facets(mu: float, n_g: int) -> np.ndarray:
    """Rows ``∝ s_k × s_{k+1}``: ``[μ cos(π/n_g), -u_k] / norm``.

    Written in closed form rather than as cross products so that it stays exact
    for any ``μ > 0`` (the cross product underflows for tiny ``μ``).
    """
    a = mu * np.cos(np.pi / n_g)
    F = np.column_stack([np.full(n_g, a), -_facet_directions(n_g)])
    return F / np.hypot(1.0, a)


def effective_cone(
    contact: Contact,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    *,
    characteristic_length: float | None = None,
) -> EffectiveCone:
    """The polyhedral cone of a contact over its effective components.

    A hard finger with ``mu = 0`` keeps only ``f_n`` (its cone is a ray), so a
    program built on this never sees degenerate facet rows.

    Parameters
    ----------
    contact : Contact
    num_generators : int, optional
        ``n_g >= 3`` generators of the linearised Coulomb cone (spatial only;
        planar cones are exact with 2 generators).
    characteristic_length : float, optional
        ``b``, metres; required for a soft finger with torsional friction.

    Returns
    -------
    EffectiveCone
    """
    check_contact(contact)
    n_g = _check_num_generators(num_generators)
    comps = contact.effective_components()
    torsion = 0.0
    if 3 in comps:
        torsion = _torsion_scale(contact, characteristic_length)
    return _cone(comps, contact.mu if 1 in comps else 0.0, n_g, torsion)


@functools.lru_cache(maxsize=1024)
def _cone(comps: tuple[int, ...], mu: float, n_g: int, torsion: float) -> EffectiveCone:
    """The cone of given components, μ, n_g and torsion bound ``b ν``; cached.

    Grasps repeat the same few cones, so each is computed once; its arrays are
    read-only.
    """
    if comps == (0,):
        S, F = np.ones((1, 1)), np.ones((1, 1))
    elif comps == (0, 1):  # planar hard finger
        S, F = _two_sided(mu)
    elif comps == (0, 3):  # soft finger without tangential friction
        S = np.array([[1.0, 1.0], [torsion, -torsion]])
        F = torsion_only_facets(np.array(torsion))
    elif comps == (0, 1, 2):
        S = _circle_generators(mu, n_g)
        F = _pyramid_facets(mu, n_g)
    else:  # (0, 1, 2, 3)
        ring = _circle_generators(mu, n_g)
        F = soft_finger_facets(np.array(mu), np.array(torsion), n_g)
        apexes = np.array([[1.0, 1.0], [0, 0], [0, 0], [torsion, -torsion]])
        S = np.hstack([np.vstack([ring, np.zeros(n_g)]), apexes])
    S.flags.writeable = False
    F.flags.writeable = False
    return EffectiveCone(comps, S, F)


@checked_call
def friction_cone_generators(
    contact: Contact,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    *,
    characteristic_length: float | None = None,
) -> np.ndarray:
    """Generators ``S_i`` of the (inscribed) polyhedral friction cone.

    Parameters
    ----------
    contact : Contact
    num_generators : int, optional
        Number ``n_g`` of generators around a spatial Coulomb cone (default 8).
    characteristic_length : float, optional
        ``b``, metres; required for a soft finger with ``torsional_friction > 0``.

    Returns
    -------
    S : (k, m) float
        Generators as columns in the contact frame (``k`` = the contact's number
        of force components).  Frictionless, or any model with ``mu = 0`` and no
        torsion: the single ray ``[1, 0, …]``.  Planar hard finger: ``[1, ±μ]``.
        Spatial hard finger: ``[1, μ cos(2πk/n_g), μ sin(2πk/n_g)]``,
        ``k = 1 … n_g``.  Soft finger: those with ``m_n = 0`` and
        ``[1, 0, 0, ±b ν]``.
    """
    cone = effective_cone(
        contact, num_generators, characteristic_length=characteristic_length
    )
    S = np.zeros((contact.num_components, cone.generators.shape[1]))
    S[list(cone.components), :] = cone.generators
    return S


@checked_call
def friction_cone_facets(
    contact: Contact,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    *,
    characteristic_length: float | None = None,
) -> np.ndarray:
    """Facet (H-) form ``F_i`` of the polyhedral friction cone: ``F_i f_i >= 0``.

    Parameters
    ----------
    contact : Contact
    num_generators : int, optional
        Number ``n_g`` of generators around a spatial Coulomb cone (default 8).
    characteristic_length : float, optional
        ``b``, metres; required for a soft finger with ``torsional_friction > 0``.

    Returns
    -------
    F : (r, k) float
        One unit row per facet, positive on the cone's axis.  Frictionless:
        ``[[1]]``.  Planar: ``[[μ, 1], [μ, -1]] / sqrt(1 + μ²)``.  Spatial hard
        finger: rows ``∝ s_k × s_{k+1}``.  Soft finger: the ``2 n_g`` triangles of
        the bipyramid spanned by the generators (``+b ν`` apex first), scaled
        as in :func:`soft_finger_facets` (not to unit length); without
        friction, ``[1, ∓1/(b ν)]`` (:func:`torsion_only_facets`).

    Notes
    -----
    A degenerate cone (a model with ``mu = 0``, or a soft finger with ``ν = 0``)
    has no interior: the components it forbids appear as pairs of rows ``±e_j``
    (which are zero, not positive, on the axis).  The closure programs never use
    such rows; they drop the forbidden components instead
    (:func:`effective_cone`).
    """
    cone = effective_cone(
        contact, num_generators, characteristic_length=characteristic_length
    )
    k = contact.num_components
    F = np.zeros((cone.facets.shape[0], k))
    F[:, list(cone.components)] = cone.facets
    dropped = [j for j in range(k) if j not in cone.components]
    if dropped:
        eye = np.eye(k)[dropped]
        F = np.vstack([F, eye, -eye])
    return F


@dataclass(frozen=True)
class ConeLayout:
    """The force components a grasp's cones allow, their cones, and ``G`` on them.

    Programs use only these components, so a degenerate cone (``mu = 0``) never
    brings a tangential variable or a facet row without interior.

    Attributes
    ----------
    columns : (m,) int
        Indices of the kept components in the grasp's stacked force vector.
    cones : tuple of EffectiveCone
        Each contact's cone over its kept components.
    normal_positions : (N,) int
        Position of each contact's ``f_n`` within ``columns``.
    G : (w, m) float
        The grasp matrix restricted to ``columns``.
    scales : (m,) float
        A well-scaled program variable ``x_j`` is the force component
        ``scales_j x_j``: ``b min(ν, 1)`` for a soft finger's moment ``m_n``
        (whose natural size is ``b ν f_n``, from 1e-21 to 1e21 N·m across the
        valid ranges), 1 elsewhere.  Programs use ``G diag(scales)`` and
        ``F diag(scales)``, whose ``m_n`` coefficients are then at most
        ``μ cos(π/n_g)`` and ``b`` instead of ``1/(b ν)``.
    """

    columns: np.ndarray
    cones: tuple[EffectiveCone, ...]
    normal_positions: np.ndarray
    G: np.ndarray
    scales: np.ndarray | None = None

    @staticmethod
    def of(grasp: Grasp, num_generators: int = DEFAULT_NUM_GENERATORS) -> ConeLayout:
        """Layout of ``grasp`` with ``num_generators`` per spatial Coulomb cone."""
        check_grasp(grasp)
        b = grasp.characteristic_length
        cones = tuple(
            effective_cone(c, num_generators, characteristic_length=b)
            for c in grasp.contacts
        )
        columns, normals = [], []
        for s, cone in zip(grasp.component_slices(), cones, strict=True):
            normals.append(len(columns))
            columns.extend(s.start + j for j in cone.components)
        columns = np.array(columns, dtype=int)
        G = grasp_matrix(grasp)[:, columns]
        scales = np.ones(len(columns))
        for contact, cone, start in zip(grasp.contacts, cones, normals, strict=True):
            if 3 in cone.components:
                # b min(ν, 1): the margin rows' m_n coefficient μ c s/(b ν)
                # and G's m_n column s [0; n] both stay at most μ c and b.
                scales[start + cone.components.index(3)] = b * min(
                    contact.torsional_friction, 1.0
                )
        return ConeLayout(columns, cones, np.array(normals, dtype=int), G, scales)

    def facet_matrix(self) -> np.ndarray:
        """``F``: block-diagonal unit facet rows over ``columns``."""
        return _block_diag([cone.facets for cone in self.cones])

    def generator_matrix(self) -> np.ndarray:
        """``S``: block-diagonal generators (columns) over ``columns``."""
        return _block_diag([cone.generators for cone in self.cones])


def _block_diag(blocks: list[np.ndarray]) -> np.ndarray:
    rows = sum(b.shape[0] for b in blocks)
    cols = sum(b.shape[1] for b in blocks)
    out = np.zeros((rows, cols))
    r = c = 0
    for b in blocks:
        out[r : r + b.shape[0], c : c + b.shape[1]] = b
        r, c = r + b.shape[0], c + b.shape[1]
    return out


# ------------------------------------------------ support functions


def cone_support(
    grasp: Grasp,
    w: np.ndarray,
    *,
    cones: str,
    num_generators: int = DEFAULT_NUM_GENERATORS,
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
    if contact.contact_model is ContactModel.SOFT_FINGER and len(a) == 4:
        value = max(value, b * contact.torsional_friction * abs(a[3]))
    return float(a[0] + value)
