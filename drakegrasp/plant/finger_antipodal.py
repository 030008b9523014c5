r"""Antipodal per finger: the two patches of a two-finger hand.

A real gripper touches with several contacts per finger (the WSG-50's four tip
spheres, a flat pad's corners), so the two-contact test of
:func:`~drakegrasp.is_antipodal` does not apply to its grasp.  Here each
finger's contacts make a **patch**: the convex hull ``P_k`` of its contact
points, with the patch normal ``n_k`` (the unit mean of its contacts'
normals, into the object).  The two patches are antipodal when some line
between them lies inside both friction cones:

.. math:: \min_{x_1 \in P_1,\ x_2 \in P_2}\ \max\big(\angle(x_2 - x_1, n_1),\
          \angle(x_1 - x_2, n_2)\big) \le \arctan\mu .

For single-contact patches this is exactly the two-contact test.  The best
line is found exactly: the directions ``x_2 − x_1`` fill the cone spanned by
the differences ``v_{ij} = p_{2j} − p_{1i}`` of the contact points; the largest
of the two angles is quasi-convex in the direction, so its minimum is the
bisector of ``n_1`` and ``−n_2`` when that lies in the cone (found by the
conic combinations of three differences), and otherwise lies on the cone's
boundary, an arc between two differences, searched by golden sections to
1e-12 of the arc.  The result carries the two angles of that line through
:class:`~drakegrasp.AntipodalResult`.

**Fingers.**  A finger is the chain of bodies under one joint whose parent no
one-dof joint moves (the root joint of :mod:`drakegrasp.plant.fingers`); a
body that no one-dof joint moves (a palm) belongs to no finger.  The report
answers whenever the hand has exactly two fingers: with the patches' verdict
when both touch, and with "no, only one finger touches" otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex, JointIndex

from drakegrasp.core.antipodal import AntipodalResult, is_antipodal
from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import Contact
from drakegrasp.core.serialize import jsonable
from drakegrasp.plant.validation import scoped_name

__all__ = ["FingerAntipodal", "finger_antipodal", "finger_of", "patch_line"]

_GOLDEN = 0.5 * (np.sqrt(5.0) - 1.0)


def finger_of(plant: MultibodyPlant, bodies) -> dict[int, int | None]:
    """Body index -> index of its finger's root body (None: no finger, a palm)."""
    inboard = {}
    for i in range(plant.num_joints()):
        joint = plant.get_joint(JointIndex(i))
        inboard[int(joint.child_body().index())] = joint

    def moved(b: int) -> bool:
        j = inboard.get(b)
        return j is not None and j.num_velocities() == 1

    out: dict[int, int | None] = {}
    for body in bodies:
        b = int(body.index())
        if not moved(b):
            out[b] = None
            continue
        while moved(int(inboard[b].parent_body().index())):
            b = int(inboard[b].parent_body().index())
        out[int(body.index())] = b
    return out


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _worst_angle(u: np.ndarray, n1: np.ndarray, m2: np.ndarray) -> np.ndarray:
    """max(∠(u, n1), ∠(u, m2)) for rows u (not necessarily unit)."""

    def angle(a, b):
        return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), a @ b)

    return np.maximum(angle(u, n1), angle(u, m2))


def patch_line(
    points_1: np.ndarray,
    normal_1: np.ndarray,
    points_2: np.ndarray,
    normal_2: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """The line between two patches that is deepest inside both friction cones.

    Parameters
    ----------
    points_1, points_2 : (k, 3) float
        Contact points of each patch (any frame, the same for both).
    normal_1, normal_2 : (3,) float
        Unit patch normals, into the object.

    Returns
    -------
    x_1, x_2 : (3,) float
        Points of the two patches' convex hulls whose line minimises the
        larger of ``∠(x_2 − x_1, n_1)`` and ``∠(x_1 − x_2, n_2)``.
    """
    P1, P2 = np.asarray(points_1, float), np.asarray(points_2, float)
    n1, m2 = normal_1, -normal_2
    i1, i2 = np.meshgrid(np.arange(len(P1)), np.arange(len(P2)), indexing="ij")
    i1, i2 = i1.ravel(), i2.ravel()
    V = P2[i2] - P1[i1]  # (k, 3) generators of the cone of directions
    weights = _inside_bisector(V, n1, m2)
    if weights is None:
        weights = _best_on_arcs(V, n1, m2)
    w = weights / weights.sum()
    x1 = np.zeros(3)
    x2 = np.zeros(3)
    for k in np.flatnonzero(w):
        x1 = x1 + w[k] * P1[i1[k]]
        x2 = x2 + w[k] * P2[i2[k]]
    return x1, x2


def _inside_bisector(V, n1, m2) -> np.ndarray | None:
    """Conic weights of the bisector of n1 and m2 if it lies in cone(V), else None."""
    s = n1 + m2
    if np.linalg.norm(s) < 1e-12:
        return None  # the normals agree: no line enters both cones
    b = s / np.linalg.norm(s)
    k = len(V)
    for idx in ([i] for i in range(k)):
        if np.linalg.norm(np.cross(V[idx[0]], b)) <= 1e-12 * np.linalg.norm(V[idx[0]]):
            if V[idx[0]] @ b > 0:
                w = np.zeros(k)
                w[idx[0]] = 1.0
                return w
    if k < 3:
        return None
    triples = np.array(
        [(a, c, d) for a in range(k) for c in range(a + 1, k) for d in range(c + 1, k)]
    )
    M = np.transpose(V[triples], (0, 2, 1))  # (t, 3, 3), columns the generators
    det = np.linalg.det(M)
    scale = np.prod(np.linalg.norm(V[triples], axis=2), axis=1)
    ok = np.abs(det) > 1e-9 * scale
    if not np.any(ok):
        return None
    mu = np.linalg.solve(M[ok], np.broadcast_to(b, (int(ok.sum()), 3))[..., None])[
        ..., 0
    ]
    inside = np.all(mu >= -1e-12, axis=1)
    if not np.any(inside):
        return None
    t = int(np.flatnonzero(inside)[0])
    w = np.zeros(k)
    w[triples[ok][t]] = np.maximum(mu[t], 0.0)
    return w


def _best_on_arcs(V, n1, m2) -> np.ndarray:
    """Conic weights of the best direction on the arcs between generators."""
    k = len(V)
    U = _unit(V)
    values = _worst_angle(U, n1, m2)
    best = (float(values.min()), np.eye(k)[int(np.argmin(values))])
    if k < 2:
        return best[1]
    a, c = np.triu_indices(k, 1)
    keep = np.einsum("ij,ij->i", U[a], U[c]) > -1 + 1e-9  # not antiparallel
    a, c = a[keep], c[keep]
    lo, hi = np.zeros(len(a)), np.ones(len(a))

    def f(s):
        return _worst_angle((1 - s)[:, None] * U[a] + s[:, None] * U[c], n1, m2)

    for _ in range(60):  # golden sections: the bracket shrinks to 1e-12
        x1 = hi - _GOLDEN * (hi - lo)
        x2 = lo + _GOLDEN * (hi - lo)
        left = f(x1) <= f(x2)
        hi = np.where(left, x2, hi)
        lo = np.where(left, lo, x1)
    s = 0.5 * (lo + hi)
    arc_values = f(s)
    j = int(np.argmin(arc_values))
    if arc_values[j] < best[0]:
        w = np.zeros(k)
        # a direction (1 - s) U_a + s U_c as a conic combination of V
        w[a[j]] += (1 - s[j]) / np.linalg.norm(V[a[j]])
        w[c[j]] += s[j] / np.linalg.norm(V[c[j]])
        return w
    return best[1]


@checked_call
@dataclass(frozen=True, eq=False)
class FingerAntipodal:
    """The antipodal test of a two-finger hand, one patch per finger.

    Attributes
    ----------
    fingers : tuple of str
        The two fingers (scoped names of their root bodies).
    contacts : tuple of tuple of int
        Per finger, the indices of its contacts in the grasp (palm contacts
        belong to neither).
    result : AntipodalResult or None
        The two-contact test on the best line between the patches (its angles
        are those of that line against the patch normals); None when a finger
        does not touch.
    p_O : (2, 3) float or None
        The best line's ends, on the patches, in the object frame O.
    nhat_O : (2, 3) float or None
        The patch normals (into the object), in O.
    reason : str
        Why the answer is what it is, in words.
    """

    fingers: tuple[str, str]
    contacts: tuple[tuple[int, ...], tuple[int, ...]]
    result: AntipodalResult | None
    p_O: np.ndarray | None
    nhat_O: np.ndarray | None
    reason: str

    @property
    def is_antipodal(self) -> bool:
        """Both fingers touch and a line between their patches is in both cones."""
        return self.result is not None and self.result.is_antipodal

    def __bool__(self) -> bool:
        return self.is_antipodal

    @property
    def angles(self) -> np.ndarray | None:
        """(2,) angles (rad) of the best line, or None."""
        return None if self.result is None else self.result.angles

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {
            "fingers": list(self.fingers),
            "contacts": [list(c) for c in self.contacts],
            "is_antipodal": self.is_antipodal,
            "result": None if self.result is None else self.result.to_dict(),
            "p_O": jsonable(self.p_O),
            "nhat_O": jsonable(self.nhat_O),
            "reason": self.reason,
        }

    def __str__(self) -> str:
        if self.result is None:
            return f"antipodal (per finger): no, {self.reason}"
        lines = str(self.result).splitlines()
        lines[0] = lines[0].replace(
            "antipodal (geometric test)", "antipodal (per finger)"
        )
        return "\n".join([lines[0], f"  {self.reason}", *lines[1:]])


def finger_antipodal(
    plant: MultibodyPlant,
    contacts,
    grasp,
    hand_bodies,
) -> FingerAntipodal | None:
    """The per-finger antipodal test of a two-finger hand, or None.

    Parameters
    ----------
    plant : MultibodyPlant
    contacts : sequence of PlantContact
        In grasp order (object frame O).
    grasp : Grasp
        Spatial; its contacts give each contact's friction coefficient.
    hand_bodies : sequence of RigidBody
        The hand's bodies (:func:`~drakegrasp.plant.validation.hand_contact_bodies`).

    Returns
    -------
    FingerAntipodal or None
        None unless the hand has exactly two fingers (or the grasp is planar).
    """
    if grasp.planar:
        return None
    roots = finger_of(plant, hand_bodies)
    with_geometry = sorted(
        {
            r
            for b, r in roots.items()
            if r is not None
            and plant.GetCollisionGeometriesForBody(plant.get_body(BodyIndex(b)))
        }
    )
    if len(with_geometry) != 2:
        return None
    names = tuple(
        scoped_name(plant, plant.get_body(BodyIndex(r))) for r in with_geometry
    )
    groups = tuple(
        tuple(
            i
            for i, c in enumerate(contacts)
            if roots.get(int(c.finger_body_index)) == r
        )
        for r in with_geometry
    )
    palm = len(contacts) - sum(len(g) for g in groups)
    aside = f"; {palm} palm contact(s) set aside" if palm else ""
    if not all(groups):
        touching = [n for n, g in zip(names, groups, strict=True) if g]
        who = f"only {touching[0]} touches" if touching else "no finger touches"
        return FingerAntipodal(names, groups, None, None, None, who + aside)
    points = [np.array([contacts[i].p_OC for i in g]) for g in groups]
    normals = [_unit(np.sum([contacts[i].nhat_O for i in g], axis=0)) for g in groups]
    x1, x2 = patch_line(points[0], normals[0], points[1], normals[1])
    mus = [min(grasp.contacts[i].mu for i in g) for g in groups]
    result = is_antipodal(
        [Contact(x1, normals[0], mu=mus[0]), Contact(x2, normals[1], mu=mus[1])]
    )
    reason = (
        f"patches of {len(groups[0])} and {len(groups[1])} contacts, best line "
        f"between them{aside}"
    )
    return FingerAntipodal(
        names, groups, result, np.array([x1, x2]), np.array(normals), reason
    )
