"""Contact kinds of the batch engine: a small integer per effective cone.

A chunk's contacts are sorted into kinds by model and friction (a hard finger
with ``mu = 0`` acts as a frictionless one, a soft finger with ``mu = 0`` keeps
only its torsion); each kind has a fixed list of force components, indices
into the contact's force vector ``[f_n, f_t1, f_t2, m_n]``.
"""

from __future__ import annotations

__all__ = [
    "FRICTIONLESS",
    "KIND_COMPONENTS",
    "PLANAR_HARD",
    "SOFT_FULL",
    "SOFT_TORSION",
    "SPATIAL_HARD",
]

# Kind code -> effective components (indices into the contact's force vector).
FRICTIONLESS, PLANAR_HARD, SPATIAL_HARD, SOFT_TORSION, SOFT_FULL = range(5)
KIND_COMPONENTS: dict[int, tuple[int, ...]] = {
    FRICTIONLESS: (0,),
    PLANAR_HARD: (0, 1),
    SPATIAL_HARD: (0, 1, 2),
    SOFT_TORSION: (0, 3),
    SOFT_FULL: (0, 1, 2, 3),
}
