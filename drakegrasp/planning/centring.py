r"""Centring a hand whose coupled fingers stop short of the object.

A ``<mimic>`` across fingers (a Robotiq-style gripper: two knuckles on one
motor) makes them close as one: where the hand is off the object's centre,
the finger nearest the object touches first and stops the others short of
it.  On a table the object would slide until each of them touches.  Stage 3
of the multi-finger routes (:mod:`drakegrasp.planning.multifinger` on a body,
:mod:`drakegrasp.planning.cloud_hand` on a point cloud) does the same to the
hand: it moves the hand so that their gaps are equal and closes again from
the pre-shape, at most :data:`CENTRING_STEPS` times.  A candidate keeps the
pose its fingers closed at.

**The move.**  The chains of one closing group (kinematic chains that a
coupling closes as one, :func:`~drakegrasp.plant.fingers.finger_chains`)
have gaps ``ψ_c`` (m) to the object along unit lines ``n̂_c`` (world frame,
from the chain's nearest point towards the object's).  Moving the hand by
``t`` (m, world) with its joints held changes them to ``ψ_c − n̂_c·t`` to
first order.  :func:`equalising_move` returns the least ``t`` that makes them
equal, the least-squares solution of ``(n̂_c − n̄)·t = ψ_c − ψ̄`` (bars:
means over the group): for two fingers across parallel faces, half the
difference of their gaps towards the one short of the object.

**Sides.**  Only the nearest of the chains that move alike is centred
(:func:`chain_sides`, :func:`facing_chains`).  A parallelogram finger
written with ``<mimic>`` joints (a Robotiq 2F-85's inner knuckle: a bar
beside its pad's chain, turning with it, that no joint connects to it) is a
chain of the pads' closing group whose root turns as the pad's does: behind
the pad, it cannot touch first.  Centred with the pads, its gap kept every
move from evening theirs, and no sample of such a gripper was planned.  A
chain whose gap cannot be measured (no collision geometry) is left out.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence

import numpy as np
from pydrake.math import RigidTransform

from drakegrasp.core.validation import describe, real_array
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "CENTRING_STEPS",
    "PLANE_TOLERANCE",
    "SIDE_TOLERANCE",
    "CentredCloser",
    "chain_groups",
    "chain_sides",
    "chains_to_centre",
    "close_centred",
    "equalising_move",
    "facing_chains",
]

CENTRING_STEPS = 8
"""Times at most a hand whose coupled fingers stopped short is moved and closed
again.  Each move evens the gaps to first order only: fingers whose lines are
not opposed, or whose closing paths are arcs, take a few (a Robotiq-style
pinch on the shipped box: most within two to four), and a sample still short
after these is rejected as it was."""

_RCOND = 1e-6
"""Singular value of the centred lines ``n̂_c − n̄`` (unit lines: an absolute
figure) below which a direction is left unmoved: the lines do not tell it."""


def chain_groups(structure, chains: Sequence) -> list[int]:
    """The closing group of every chain: its finger's index in ``structure.fingers``.

    Parameters
    ----------
    structure : HandStructure
    chains : sequence of Finger
        :func:`~drakegrasp.plant.fingers.finger_chains` of ``structure``.

    Returns
    -------
    list of int
        One per chain: the finger of ``structure`` whose joints hold its own.
    """
    return [
        next(
            k
            for k, finger in enumerate(structure.fingers)
            if set(chain.joints) <= set(finger.joints)
        )
        for chain in chains
    ]


def chains_to_centre(groups: Sequence[int], touched: set[int]) -> list[int]:
    """The chains whose gaps are equalised, sorted; empty when none is short.

    Parameters
    ----------
    groups : sequence of int
        :func:`chain_groups`.
    touched : set of int
        The chains that touch.

    Returns
    -------
    list of int
        The chains of every closing group in which one chain touches and
        another does not.

    Raises
    ------
    InvalidOptionError
        ``touched`` names a chain the hand lacks.
    """
    if not set(touched) <= set(range(len(groups))):
        raise InvalidOptionError(
            f"touched names chains {sorted(set(touched) - set(range(len(groups))))} "
            f"of a hand with {len(groups)}"
        )
    short = {
        groups[c]
        for c in range(len(groups))
        if c not in touched and any(groups[t] == groups[c] for t in touched)
    }
    return [c for c, g in enumerate(groups) if g in short]


def chain_sides(plant_context, structure, chains: Sequence) -> list[int]:
    """A side per chain: a bar beside a finger, turning with it, shares its side.

    Parameters
    ----------
    plant_context : Context
        The plant's context (its pose of the hand: the joints' axes are
        compared in the world frame).
    structure : HandStructure
    chains : sequence of Finger
        :func:`~drakegrasp.plant.fingers.finger_chains` of ``structure``.

    Returns
    -------
    list of int
        One label per chain, numbered from 0 in the chains' order.  Two
        chains share one when they are joined through chains each beside the
        next: one is beside another when they are of one closing group and
        their root joints (the joints of the chain that no other joint of it
        carries) are revolute, turn alike as the group closes (the same world
        axis times the same ``<mimic>`` rate, to :data:`SIDE_TOLERANCE` of the
        larger:
        exported URDFs round an axis or an angle differently from joint to
        joint) and lie in one plane of motion (their pins coincide, or lie
        apart along the axis by at most :data:`PLANE_TOLERANCE` of their
        distance across it): a bar of a four-bar finger.  Two fingers side
        by side on one hinge line, opposed fingers (their joints turn the
        other way), prismatic ones and other kinds each have a side of their
        own.
    """
    groups = chain_groups(structure, chains)
    rate = structure.coupling.tangent(np.ones(len(structure.joints)))
    motions = []
    for chain in chains:
        k = _root(structure, chain)
        joint = structure.joints[k]
        if joint.type_name() != "revolute":  # a side of its own
            motions.append(None)
            continue
        X_WF = joint.frame_on_parent().CalcPoseInWorld(plant_context)
        w = X_WF.rotation().matrix() @ joint.revolute_axis()
        motions.append((rate[k] * w, X_WF.translation()))
    # the sides: the chains joined through pairs that lie beside each other
    # (transitively, so that the partition does not depend on their order)
    side = list(range(len(chains)))

    def find(c: int) -> int:
        while side[c] != c:
            c = side[c]
        return c

    for c, d in itertools.combinations(range(len(chains)), 2):
        if (
            groups[c] == groups[d]
            and motions[c] is not None
            and motions[d] is not None
            and _beside(motions[c], motions[d])
        ):
            side[find(d)] = find(c)
    labels: dict[int, int] = {}
    return [labels.setdefault(find(c), len(labels)) for c in range(len(chains))]


SIDE_TOLERANCE = 1e-4
"""Relative difference below which two root joints turn alike
(:func:`chain_sides`): 1e-4 rad between axes, a rate 1e-4 apart."""

PLANE_TOLERANCE = 0.1
"""How far along their axis two pins turning alike may lie apart, over their
distance across it, and still be in one plane of motion (:func:`chain_sides`:
a bar and its finger).  Fingers side by side on one hinge line lie apart
along it only; a bar 25 mm from its finger across the axis is not beside a
finger 24 mm along it."""


def _root(structure, chain) -> int:
    """The position (in ``structure.joints``) of the chain's root joint."""
    bodies = {int(b.index()) for b in chain.bodies}
    for k in chain.joints:
        if int(structure.joints[k].parent_body().index()) not in bodies:
            return k
    return chain.joints[0]


def _beside(a, b) -> bool:
    """Whether two root joints ``(ω, origin)`` turn alike in one plane of motion.

    Their pins may coincide; apart, they lie along the axis by at most
    :data:`PLANE_TOLERANCE` of their distance across it.
    """
    (w_a, o_a), (w_b, o_b) = a, b
    scale = max(float(np.linalg.norm(w_a)), float(np.linalg.norm(w_b)))
    if not scale > 0 or np.linalg.norm(w_a - w_b) > SIDE_TOLERANCE * scale:
        return False
    axis = w_a / np.linalg.norm(w_a)
    v = o_b - o_a
    along = abs(float(v @ axis))
    return along <= PLANE_TOLERANCE * float(np.linalg.norm(v - (v @ axis) * axis))


def facing_chains(psi, sides: Sequence[int]) -> list[int]:
    """The nearest measured chain of each side (:func:`chain_sides`).

    Parameters
    ----------
    psi : (k,) float
        The chains' gaps to the object, metres; NaN where a gap cannot be
        measured (that chain is left out).
    sides : (k,) int
        Each chain's side.

    Returns
    -------
    list of int
        Indices into ``psi``, ascending: of each side's measured chains the
        one with the least gap (the first of equal ones).

    Raises
    ------
    InvalidOptionError
        ``psi`` not a vector of real numbers or ``sides`` not one integer
        per gap.
    """
    psi = real_array("psi", psi, error=InvalidOptionError)
    if psi.ndim != 1:
        raise InvalidOptionError(f"psi must be a vector of gaps, got shape {psi.shape}")
    sides = _integers("sides", sides, len(psi))
    nearest: dict[int, int] = {}
    for c in np.flatnonzero(np.isfinite(psi)):
        s = int(sides[c])
        if s not in nearest or psi[c] < psi[nearest[s]]:
            nearest[s] = int(c)
    return sorted(nearest.values())


def equalising_move(psi, lines, tol: float, groups=None) -> np.ndarray | None:
    """The least move of the hand (m, world) after which the gaps are equal.

    Parameters
    ----------
    psi : (k,) float
        The chains' gaps to the object, metres.
    lines : (k, 3) float
        Unit lines, world frame, from each chain's nearest point towards the
        object's.
    tol : float
        The distance tolerance (m): gaps within ``1e-3 tol`` of each other are
        equal already.
    groups : (k,) int, optional
        The chains' closing groups: the gaps are equalised within each
        (default: one group).

    Raises
    ------
    InvalidOptionError
        ``psi`` not a vector of real numbers, ``lines`` not ``(k, 3)`` real
        numbers beside it, ``groups`` not ``k`` integers, ``tol`` not a
        finite number > 0.

    Returns
    -------
    (3,) float or None
        The least-squares solution of ``(n̂_c − n̄)·t = ψ_c − ψ̄`` (bars: means
        over the chain's group), which neither the chains' order nor a
        rotation of the scene changes.  None when the gaps are equal already,
        a gap or line is not finite, the lines see no move (fingers facing
        one way), the move would be longer than the gaps differ, or it would
        not narrow the widest spread of a group's gaps or would widen any
        (more chains than a move can even: the least-squares fit may).
    """
    psi, lines, groups = _checked(psi, lines, tol, groups)
    if len(psi) < 2 or not (np.all(np.isfinite(psi)) and np.all(np.isfinite(lines))):
        return None
    A, b = lines.copy(), psi.copy()
    spread = 0.0
    for g in np.unique(groups):
        mine = groups == g
        A[mine] -= lines[mine].mean(axis=0)
        b[mine] -= psi[mine].mean()
        spread = max(spread, float(np.ptp(psi[mine])))
    if spread <= 1e-3 * tol:
        return None
    # least squares, least norm; directions the unit lines tell apart by less
    # than _RCOND are left unmoved (an absolute cut: the lines are unit)
    U, sv, Vt = np.linalg.svd(A, full_matrices=False)
    seen = sv > _RCOND
    t = Vt[seen].T @ ((U[:, seen].T @ b) / sv[seen])
    size = float(np.linalg.norm(t))
    if not np.isfinite(size) or size <= 1e-3 * tol or size > spread:
        return None
    after = psi - lines @ t
    before_after = [
        (float(np.ptp(psi[groups == g])), float(np.ptp(after[groups == g])))
        for g in np.unique(groups)
    ]
    # more chains than a move can even: the fit may leave the widest spread
    # as it was, or widen a group's
    widest = max(a for _, a in before_after)
    if widest > spread - 1e-3 * tol or any(a > b for b, a in before_after):
        return None
    return t


def _checked(psi, lines, tol, groups):
    """The arguments of :func:`equalising_move` as arrays, or a clear refusal."""
    psi = real_array("psi", psi, error=InvalidOptionError)
    lines = real_array("lines", lines, error=InvalidOptionError)
    if psi.ndim != 1 or lines.shape != (len(psi), 3):
        raise InvalidOptionError(
            f"psi must be k gaps and lines (k, 3) unit lines, got shapes "
            f"{psi.shape} and {lines.shape}"
        )
    if (
        isinstance(tol, bool)
        or not isinstance(tol, int | float | np.integer | np.floating)
        or not math.isfinite(tol)
        or tol <= 0
    ):
        raise InvalidOptionError(
            f"tol must be a finite number > 0 (m), got {describe(tol)}"
        )
    if groups is None:
        return psi, lines, np.zeros(len(psi), int)
    return psi, lines, _integers("groups", groups, len(psi))


def _integers(name: str, values, n: int) -> np.ndarray:
    """``values`` as ``n`` integers, one per gap, else a refusal naming ``name``."""
    try:
        g = np.asarray(values)
    except (TypeError, ValueError):  # ragged
        raise InvalidOptionError(
            f"{name} must be {n} integers, one per gap, got a ragged "
            f"{type(values).__name__}"
        ) from None
    if g.shape != (n,) or (n and g.dtype.kind not in "iu"):
        raise InvalidOptionError(  # one line: no array's repr
            f"{name} must be {n} integers, one per gap, got {g.dtype} values "
            f"of shape {g.shape}"
        )
    return g


def close_centred(
    close: Callable,
    gaps: Callable,
    groups: Sequence[int],
    tol: float,
    X_WH,
    q_pre,
    sides: Sequence[int] | None = None,
):
    """Close the hand at ``X_WH``, centring it while coupled chains stop short.

    Parameters
    ----------
    close : callable
        ``close(X_WH, q_pre) -> (contacts, q, reason, touched)``: one closing
        from the pre-shape at a hand pose; ``reason`` None when kept,
        ``touched`` the set of chains that touch.
    gaps : callable
        ``gaps(chains) -> (psi (k,), lines (k, 3))`` of the closed hand (NaN
        where a chain's gap cannot be measured), or None when none can.
    groups : sequence of int
        :func:`chain_groups`.
    tol : float
        Distance tolerance (m).
    X_WH : RigidTransform
        The sampled pose of the hand's base.
    q_pre : (n_h,) float
        The pre-shape.
    sides : sequence of int, optional
        :func:`chain_sides`: of the chains of one side only the nearest is
        centred (default: every chain a side of its own).

    Returns
    -------
    tuple
        ``(contacts, q, reason, X_WH)``: the kept closing's contacts, joints
        and pose, reason None; or None, None, the first closing's rejection
        reason and the last pose tried.
    """
    first = None
    side = list(range(len(groups))) if sides is None else sides
    for step in range(CENTRING_STEPS + 1):
        found, q, reason, touched = close(X_WH, q_pre)
        if reason is None:
            return found, q, None, X_WH
        first = first or reason
        chains = chains_to_centre(groups, touched)
        if step == CENTRING_STEPS or not chains:
            break
        move = _move(
            gaps(chains), [groups[c] for c in chains], [side[c] for c in chains], tol
        )
        if move is None:
            break
        X_WH = RigidTransform(X_WH.rotation(), X_WH.translation() + move)
    return None, None, first, X_WH


def _move(measured, groups: list[int], sides: list[int], tol) -> np.ndarray | None:
    """:func:`equalising_move` of the facing chains of ``measured``, or None."""
    if measured is None:
        return None
    psi, lines = (np.asarray(a, dtype=float) for a in measured)
    facing = facing_chains(psi, sides)
    if len(facing) < 2:
        return None
    return equalising_move(psi[facing], lines[facing], tol, [groups[k] for k in facing])


class CentredCloser:
    """A closer whose :meth:`run` centres coupled fingers (stage 3 of both routes).

    A subclass gives ``_close(X_WH, q_pre) -> (contacts, q, reason,
    touched)`` and ``_gaps(chains)`` as :func:`close_centred` takes them, and
    ``group`` (:func:`chain_groups`), ``side`` (:func:`chain_sides`, or
    None) and ``tol`` (m).
    """

    X_WH = None
    side = None

    def run(self, X_WH, q_pre):
        """(contacts, closed q, None) or (None, None, reason); the pose in ``X_WH``.

        Coupled fingers stopped short of the object are centred
        (:func:`close_centred`); the pose the hand closed at (or was last
        tried at) is left in ``self.X_WH``.
        """
        found, q, reason, self.X_WH = close_centred(
            self._close, self._gaps, self.group, self.tol, X_WH, q_pre, self.side
        )
        return found, q, reason
