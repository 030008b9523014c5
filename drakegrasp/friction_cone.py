"""Polyhedral friction cones in generator (V) and facet (H) form (numpy only).

Generators are inscribed in the exact Coulomb cone:
``s_k = [1, μ cos(2πk/n_g), μ sin(2πk/n_g)]``, ``k = 1 … n_g``; a soft finger adds
``[1, 0, 0, ±b ν]``.  Facet rows have unit length and give a positive value on the
cone's axis ``[1, 0, 0, …]``.  See ``docs/conventions.md``.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from drakegrasp.contact import Contact
from drakegrasp.errors import InvalidOptionError
from drakegrasp.grasp import Grasp, grasp_matrix

__all__ = [
    "DEFAULT_NUM_GENERATORS",
    "ConeLayout",
    "EffectiveCone",
    "effective_cone",
    "friction_cone_facets",
    "friction_cone_generators",
]

DEFAULT_NUM_GENERATORS = 8


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
    n = int(num_generators)
    if n != num_generators or n < 3:
        raise InvalidOptionError(
            f"num_generators must be an integer >= 3, got {num_generators!r}"
        )
    return n


def _torsion_scale(contact: Contact, characteristic_length: float | None) -> float:
    if characteristic_length is None:
        raise InvalidOptionError(
            "a soft finger with torsional_friction > 0 needs the grasp's "
            "characteristic_length b (its moment bound is b * nu * f_n)"
        )
    b = float(characteristic_length)
    if not np.isfinite(b) or b <= 0:
        raise InvalidOptionError(
            "characteristic_length must be finite and > 0, got "
            f"{characteristic_length!r}"
        )
    return b * contact.torsional_friction


def _two_sided(slope: float) -> tuple[np.ndarray, np.ndarray]:
    """Cone |x| <= slope * f_n in two components: generators and facets."""
    S = np.array([[1.0, 1.0], [slope, -slope]])
    F = np.array([[slope, 1.0], [slope, -1.0]]) / np.hypot(1.0, slope)
    return S, F


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


def _bipyramid_facets(mu: float, n_g: int, torsion: float) -> np.ndarray:
    """Facets of the soft-finger cone: triangles (s_k, s_{k+1}, [1, 0, 0, ±τ]).

    The facet through the ring edge ``k`` and the apex ``±τ`` is
    ``μ c τ f_n - τ u_k·f_t ∓ μ c m_n >= 0`` with ``c = cos(π/n_g)``.
    """
    a = mu * np.cos(np.pi / n_g)
    u = _facet_directions(n_g)
    # Divided by max(a, τ) so that tiny μ or τ cannot underflow the products.
    m = max(a, torsion)
    rows = [
        np.column_stack(
            [
                np.full(n_g, min(a, torsion)),
                -(torsion / m) * u,
                np.full(n_g, -s * a / m),
            ]
        )
        for s in (1.0, -1.0)
    ]
    F = np.vstack(rows)
    return F / np.linalg.norm(F, axis=1, keepdims=True)


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
        S, F = _two_sided(torsion)
    elif comps == (0, 1, 2):
        S = _circle_generators(mu, n_g)
        F = _pyramid_facets(mu, n_g)
    else:  # (0, 1, 2, 3)
        ring = _circle_generators(mu, n_g)
        F = _bipyramid_facets(mu, n_g, torsion)
        apexes = np.array([[1.0, 1.0], [0, 0], [0, 0], [torsion, -torsion]])
        S = np.hstack([np.vstack([ring, np.zeros(n_g)]), apexes])
    S.flags.writeable = False
    F.flags.writeable = False
    return EffectiveCone(comps, S, F)


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
        the bipyramid spanned by the generators (``+b ν`` apex first).

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
    """

    columns: np.ndarray
    cones: tuple[EffectiveCone, ...]
    normal_positions: np.ndarray
    G: np.ndarray

    @staticmethod
    def of(grasp: Grasp, num_generators: int = DEFAULT_NUM_GENERATORS) -> ConeLayout:
        """Layout of ``grasp`` with ``num_generators`` per spatial Coulomb cone."""
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
        return ConeLayout(columns, cones, np.array(normals, dtype=int), G)

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
