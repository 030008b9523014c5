r"""How much weight a parallel-jaw grasp holds per newton of squeeze, in one LP.

A gripper presses each finger with a set force ``S``; the object's weight
``m g`` acts at its centre of mass (:func:`centre_of_mass`; the planner gives
the contacts relative to it, whatever the model's body frame) in a direction
``u`` that a shake test turns around.  The grasp holds when the
contact forces, inside their (polyhedral) friction cones and with each
finger's normal forces summing to at most ``S``, can balance ``m g u``.  By
linearity the answer scales with ``S``, so each grasp has a **weight
capacity**

.. math::

    \alpha(u) = \max \alpha \;\text{s.t.}\;
    \sum_{i,k} \lambda_{ik} w_{ik} + \alpha \begin{bmatrix} u \\ 0 \end{bmatrix} = 0,
    \quad \sum_{i \in \text{finger } f} \sum_k \lambda_{ik} \le 1
    \;(\text{every finger } f),
    \quad \lambda \ge 0,

with ``w_ik`` the primitive wrenches about O (unit normal force, generator
``k`` of contact ``i``, moments divided by the object's torque scale, which
changes no ``α``), and :math:`\alpha_{\min} = \min_u \alpha(u)` over a set of
directions in O.  The squeeze that holds the object's weight in every such
direction is :math:`m g / \alpha_{\min}`.  (A per-finger bound, not the L1
bound of ε: it is what a gripper's actuators set.)  It is a lower bound of the
squeeze a real pad needs: the LP shares a finger's force among its contacts at
will, a rigid pad as its geometry and compliance dictate.

**A palm is passive** (``palm=``, the label of the bodies no motor drives:
the planner's welded palm).  A palm pushes the object only as hard as
something presses the object into it: the load, or a finger's normal force.
Friction does not count: a finger's friction may pull the object into the
palm in the LP, but nothing sets that pull in a real hand (it is a passive
internal force, as the hand's Jacobian would show), and the palm's friction
that such a pull would buy is not there.  So along each distinct normal
``e`` of the palm's contacts (a face) that carries force, the contacts'
normal forces and the weight together press the object into that face,
friction aside:

.. math::

    \sum_{j} (n_j \cdot e) \sum_k \lambda_{jk} + \alpha\, (u \cdot e) \le 0

(``j`` over every contact, palm and fingers: for a flat palm, the palm's
normal forces are at most the weight's share into it plus the fingers'
signed pushes into it; a V-shaped palm gets one row per face, so a ball
resting in the V bears on both faces as it does; two faces that oppose each
other exactly, a slot's walls, take nothing from each other's rows, so they
squeeze nothing between them).  A face's row holds only while that face
carries force, so ``α`` is the best over the sets of faces that carry it
(:func:`palm_faces`; the empty set: the palm idle).  The
palm keeps its squeeze bound too, so no capacity rises and each stays
finite.  For a
parallel jaw, whose squeeze is across the palm's normal, the palm then holds
only the weight's share that presses into it.  Without it the LP had Drake's
Franka hand hold the cracker box by its palm at 11.8 N a finger, and the
WSG-50 two hex-prism grasps at 1.19 N and 1.49 N; in Drake they drop at
20 N and at 1.1 times those.  The model is conservative where the palm is a
lever's stop (the load's *moment* turning the object into the palm, as on a
handle held at one end): that reaction is not counted.

The LPs of all grasps and directions are solved at once by the batch engine's
exact active-set method (its interior-point method where that cannot certify),
in their dual form (nine variables each for a parallel jaw, one more for
each palm face that carries force);
:func:`build_weight_capacity_program` builds the
primal LP of one grasp (its directions as independent blocks: the sum of their
``α`` is maximised, which maximises each) for inspection, for a second route
through drakegrasp's solver gateway and for the tests.

:func:`fan_capacity` is the capacity of a grasp on a point cloud whose edge
contacts' normals are known only within a fan: its mean over normals drawn
along each fan.
"""

from __future__ import annotations

import numpy as np
from pydrake.solvers import MathematicalProgram

from drakegrasp._solvers import require_solution, solve
from drakegrasp.batch import compiled
from drakegrasp.batch.build.wrenches import batched_primitive_wrenches
from drakegrasp.batch.lp.ipm import solve_max_last, solve_max_last_active
from drakegrasp.batch.run.workers import check_workers, map_ordered, resolve_workers
from drakegrasp.core.deprecation import keyword_only, renamed_keyword
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import (
    check_num_generators,
    describe,
    plain_str,
    real_array,
    unit_vectors,
)
from drakegrasp.errors import InvalidContactError, InvalidOptionError
from drakegrasp.planning.checks import (
    checked_contacts,
    checked_count,
    checked_directions,
    checked_fingers,
    checked_friction,
    checked_palm,
    checked_rng,
    checked_samples,
    checked_torque_scale,
)

__all__ = [
    "MAX_PALM_FACES",
    "WEIGHT_CHUNK",
    "WEIGHT_DIRECTIONS",
    "build_weight_capacity_program",
    "centre_of_mass",
    "fan_capacity",
    "num_groups",
    "palm_faces",
    "palm_rows",
    "weight_capacity",
]


def centre_of_mass(plant_context, body, surface=None) -> np.ndarray:
    """Where an object body's weight acts: its centre of mass in its frame O.

    The planner takes every moment about this point (a model's body frame
    need not sit there: a mesh's origin, a link's joint).  A massless model
    (planned with ``object_mass=``) has none: the area centroid of its
    collision ``surface`` stands in for it.

    Parameters
    ----------
    plant_context : Context
        The plant's own context.
    body : RigidBody
    surface : ObjectSurface, optional
        The body's collision surface (frame O), for a massless body.

    Returns
    -------
    (3,) float
        ``p_OBcm``, frame O, metres: the model's; for a massless body the
        surface's centroid (O's origin without a ``surface``).
    """
    if body.get_mass(plant_context) > 0.0:
        p = np.asarray(body.CalcCenterOfMassInBodyFrame(plant_context), dtype=float)
        if np.all(np.isfinite(p)):
            return p
    return np.zeros(3) if surface is None else surface.centroid()


def _directions() -> np.ndarray:
    axes = np.vstack([np.eye(3), -np.eye(3)])
    diagonals = np.array(
        [[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float
    )
    return np.vstack([axes, diagonals / np.sqrt(3.0)])


WEIGHT_DIRECTIONS = _directions()
"""The 14 weight directions in O: the axes and the cube's diagonals."""

_FALLBACKS = {"clp": 0}
"""Grasps whose weight LPs neither the IPM nor the active-set method settled and
were solved through Clp, since import (read by the tests)."""

WEIGHT_CHUNK = 512
"""Grasps per task of :func:`weight_capacity` (the same for any worker count)."""


def build_weight_capacity_program(
    W: np.ndarray,
    groups: np.ndarray,
    directions: np.ndarray = WEIGHT_DIRECTIONS,
    *,
    passive: tuple[np.ndarray, np.ndarray] | None = None,
):
    """The LP of one grasp's weight capacity in every direction (one block each).

    Parameters
    ----------
    W : (M, 6) float
        Primitive wrenches of the grasp about O (contact-major).
    groups : (M,) int
        The finger of each wrench (0, 1; 2 for any other hand body, a palm,
        bounded alike; a multi-finger hand numbers its fingers 0 to F - 1 and
        its palm F).  Each label is one group with its own bound.
    directions : (D, 3) float
        Unit weight directions, frame O.
    passive : ((R, M) float, (R, D) float), optional
        The passive palm's rows ``(a, c)`` of :func:`palm_rows` for this
        grasp: ``a_r·λ <= c_rd α`` in direction ``d``'s block.  None: no palm
        rows.

    Returns
    -------
    prog : MathematicalProgram
    alpha : (D,) array of Variable
        ``α`` of each direction.
    """
    W = real_array("W", W, error=InvalidOptionError)
    groups = real_array("groups", groups, error=InvalidOptionError)
    directions = checked_directions("directions", directions)
    if W.ndim != 2 or W.shape[1] != 6 or groups.shape != (len(W),):
        raise InvalidOptionError(
            f"W must be (M, 6) and groups (M,), got {W.shape} and {groups.shape}"
        )
    if not np.all(np.isfinite(W)):
        raise InvalidOptionError("W must be finite")
    if passive is not None:
        passive = _checked_passive(passive, len(W), len(directions))
    prog, alpha, _ = _program(W, groups.astype(int), directions, passive=passive)
    return prog, alpha


def _checked_passive(passive, M: int, D: int):
    """``(a, c)``: (R, M) and (R, D) finite arrays, else InvalidOptionError."""
    try:
        a, c = passive
    except (TypeError, ValueError):
        raise InvalidOptionError(
            f"passive must be a pair (a, c) of palm_rows, got {type(passive).__name__}"
        ) from None
    a = real_array("passive's a", a, error=InvalidOptionError)
    c = real_array("passive's c", c, error=InvalidOptionError)
    if a.ndim != 2 or a.shape[1] != M or c.shape != (len(a), D):
        raise InvalidOptionError(
            f"passive must be (a, c) of shapes (R, {M}) and (R, {D}), got "
            f"{a.shape} and {c.shape}"
        )
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(c))):
        raise InvalidOptionError("passive's a and c must be finite")
    return a, c


def palm_rows(
    normals: np.ndarray, fingers: np.ndarray, palm: int, per: int, directions
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The passive palm's rows of each grasp's LPs (see the module's note).

    One row per distinct normal ``e`` of the palm's contacts:
    ``Σ_j (n_j·e) f_j + α (u·e) <= 0``, written ``a·λ <= c α``.

    Parameters
    ----------
    normals : (K, N, 3) float
        Inward contact normals, frame O (finite, non-zero; normalised here).
    fingers : (K, N) int
        Finger labels; ``palm`` marks the palm's contacts.
    palm : int
        The palm's label (:func:`~drakegrasp.planning.checks.checked_palm`).
    per : int
        Primitive wrenches per contact (their order is contact-major), >= 1.
    directions : (D, 3) float
        Weight directions, frame O (finite, non-zero; normalised here).

    Returns
    -------
    a : (K, R, N * per) float
        Each wrench's coefficient ``n_j·e`` (every wrench has a unit normal
        force; 0 for a palm contact facing ``e``'s face exactly), ``R`` the
        most distinct palm normals of any grasp (a grasp with fewer has rows
        of zeros, which hold trivially).
    c : (K, R, D) float
        ``-u·e``: the share of a unit weight pressing into the palm along
        ``e``.
    face : (K, N) int
        The row (face) of each palm contact, -1 for the others: a face's row
        holds only while the face carries force (:func:`palm_faces`).
    has : (K,) bool
        Grasps with a palm contact; the others have no row.
    """
    normals = unit_vectors("normals", normals)
    K, N, _ = normals.shape
    fingers = checked_fingers(fingers, (K, N))
    palm = checked_palm(palm)
    if palm is None:
        raise InvalidOptionError("palm_rows needs a palm label, got None")
    per = checked_count("per", per, 1)
    directions = checked_directions("directions", directions)
    on = fingers == palm  # (K, N)
    has = on.any(axis=1)
    distinct = [_distinct(normals[k][on[k]]) for k in range(K)]
    R = max((len(f) for f in distinct), default=0)
    E = np.zeros((K, max(R, 1), 3))
    for k, f in enumerate(distinct):
        E[k, : len(f)] = f
    a = np.einsum("kjx,krx->krj", normals, E)  # (K, R, N)
    # each palm contact's face: the distinct normal it is (-1: not the palm's)
    face = np.where(on, np.argmax(a, axis=1), -1)
    # A palm face exactly opposite e (a slot's other wall) would let the two
    # walls squeeze the object between them, a preload nothing sets: it
    # takes nothing from e's row.
    a = np.where(on[:, None, :] & (a < -1.0 + _OPPOSED), 0.0, a)
    c = -np.einsum("dx,krx->krd", directions, E)  # (K, R, D)
    return np.repeat(a, per, axis=2), c, face, has


_OPPOSED = 1e-6
"""Palm normals whose dot product is below ``-1 + _OPPOSED`` face each other."""


def _distinct(n: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """The faces of ``n`` (unit vectors): rows within ``tol`` of a face's first.

    Each face is the normalised mean of its rows, so that the contacts'
    order does not choose it: two palm normals 1 mrad apart made one face
    whose row was whichever came first, and a permutation of the contacts
    moved a capacity by 4e-4 (hypothesis).
    """
    firsts: list[np.ndarray] = []
    members: list[list[np.ndarray]] = []
    for v in n:
        for first, group in zip(firsts, members, strict=True):
            if float(v @ first) >= 1.0 - tol:
                group.append(v)
                break
        else:
            firsts.append(v)
            members.append([v])
    faces = [np.sum(g, axis=0) for g in members]
    return np.array([f / np.linalg.norm(f) for f in faces]).reshape(-1, 3)


def num_groups(groups: np.ndarray) -> int:
    """Groups of squeeze-bounded forces: 3 (two jaws and a palm) or more."""
    return max(3, int(np.max(groups, initial=0)) + 1)


def _memberships(groups: np.ndarray, G: int) -> np.ndarray:
    return (np.clip(groups, 0, G - 1)[None, :] == np.arange(G)[:, None]).astype(float)


def _program(W, groups, directions, G=None, passive=None):
    """The program, its α variables and the (equality, bound) bindings per block.

    With ``passive = (a, c)`` ((R, M), (R, D)) each block also gets the
    palm's rows ``a_r·λ - c_rd α <= 0`` (:func:`palm_rows`).
    """
    M, w = W.shape
    D = len(directions)
    G = num_groups(groups) if G is None else G
    prog = MathematicalProgram()
    lam = prog.NewContinuousVariables(D, M, "lambda")
    alpha = prog.NewContinuousVariables(D, "alpha")
    member = _memberships(groups, G)
    bindings = []
    for d, A in enumerate(_equalities(W, directions)):
        bindings.append(
            (
                prog.AddLinearEqualityConstraint(
                    A, np.zeros(w), np.r_[lam[d], alpha[d]]
                ),
                prog.AddLinearConstraint(
                    member, np.full(G, -np.inf), np.ones(G), lam[d]
                ),
            )
        )
        if passive is not None:
            a, c = passive
            prog.AddLinearConstraint(
                np.hstack([a, -c[:, d : d + 1]]), np.full(len(a), -np.inf),
                np.zeros(len(a)), np.r_[lam[d], alpha[d]],
            )  # fmt: skip
    prog.AddBoundingBoxConstraint(0.0, np.inf, lam.ravel())
    prog.AddBoundingBoxConstraint(0.0, np.inf, alpha)
    prog.AddLinearCost(-np.ones(D), 0.0, alpha)
    return prog, alpha, bindings


def _equalities(W: np.ndarray, directions: np.ndarray) -> list[np.ndarray]:
    """``[W^T | (u; 0)]`` of each direction: (6, M + 1) each."""
    w = W.shape[1]
    out = []
    for u in directions:
        A = np.zeros((w, W.shape[0] + 1))
        A[:, :-1] = W.T
        A[:3, -1] = u
        out.append(A)
    return out


@keyword_only("mu", after=3)
@renamed_keyword("model", "contact_model")
def weight_capacity(
    positions: np.ndarray,
    normals: np.ndarray,
    fingers: np.ndarray,
    *,
    mu: float,
    torque_scale: float,
    contact_model: str = "hard_finger",
    torsional_friction: float | None = None,
    directions: np.ndarray = WEIGHT_DIRECTIONS,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    solver: str = "batch",
    workers: int | None = 1,
    palm: int | None = None,
) -> np.ndarray:
    """(K, D) weight capacities ``α(u)`` of ``K`` grasps of ``N`` contacts.

    Every argument is checked here, before any LP, and a bad one raises a
    :class:`~drakegrasp.GraspError` naming it.

    Parameters
    ----------
    positions, normals : (K, N, 3) float
        Contacts (metres, finite) and inward normals (finite, non-zero;
        normalised here) in O; moments about O's origin, where the weight acts
        (the planner passes the contacts relative to the centre of mass).
        ``K >= 0`` grasps of ``N >= 1`` contacts.
    fingers : (K, N) int
        Finger (0 or 1) of each contact, 2 for another hand body (a palm,
        whose normal forces are bounded by the squeeze too, and passive with
        ``palm=2``); a multi-finger hand numbers its ``F`` fingers 0 to
        ``F - 1`` and its palm ``F``.
        Integers in ``[0,`` :data:`~drakegrasp.planning.checks.MAX_FINGER_LABEL` ``]``.
    mu : float
        Coulomb friction coefficient, 0 or in ``[1e-12, 1e12]`` (the range of
        :mod:`drakegrasp.core.validation`); a larger ``μ`` never lowers a
        capacity.
    torque_scale : float
        Metres dividing the moments (conditioning only; a soft finger's torsion
        bound is ``torque_scale · ν``, as in ε): a length in ``[2.2e-308,
        1e30]``, and each grasp's extent (its largest contact coordinate) over
        it in ``[1e-4, 1e12]`` unless all its contacts are at O (the moments
        must stay within the LPs' resolution).
    contact_model : {"hard_finger", "frictionless", "soft_finger"}, optional
    torsional_friction : float, optional
        ``ν`` of soft fingers, 0 or in ``[1e-12, 1e12]``; ``None`` (default):
        0, and refused with ``contact_model="soft_finger"``, as
        :func:`~drakegrasp.batch.batch_force_closure` does.
    directions : (D, 3) float, optional
        Weight directions in O, ``D >= 1``, finite and non-zero; normalised
        here (a capacity is per unit weight: only the direction counts).
        Default :data:`WEIGHT_DIRECTIONS`.
    num_generators : int, optional
        Generators of each linearised cone, in ``[3, 256]``.
    solver : {"batch", "drake"}, optional
        ``"batch"`` (default): the dual LPs of all grasps and directions at
        once in the batch engine, exactly by its active-set method
        (:func:`~drakegrasp.batch.lp.ipm.solve_max_last_active`; its
        interior-point method where that cannot certify); ``"drake"``: the LP of
        :func:`build_weight_capacity_program` per grasp through the solver
        gateway (Clp; slower, about 1 ms per direction).
    workers : int or None, optional
        Worker processes of the batch engine's pool (default 1; None: every
        core) over chunks of :data:`WEIGHT_CHUNK` grasps.  Each grasp's LPs
        are solved alone, so the numbers are the same for any count.
    palm : int, optional
        The label of the contacts on bodies no motor drives (the planner
        passes its palm's: 2 for a parallel jaw, ``F`` for a hand of ``F``
        fingers): each of its faces pressed only by the load and the
        contacts' normal forces (see the module's note), so a capacity never
        rises with it.  Default
        None: every label is squeezed alike.

    Returns
    -------
    alpha : (K, D) float
        Newtons of weight held per newton of squeeze on each finger.

    Raises
    ------
    InvalidContactError
        Bad ``positions``, ``normals``, ``fingers``, ``mu``,
        ``contact_model`` or ``torsional_friction``.
    InvalidOptionError
        Bad ``torque_scale``, ``directions``, ``num_generators``, ``solver``,
        ``workers`` or ``palm``, or moments that overflow (positions far beyond
        ``torque_scale``).
    """
    positions, normals = checked_contacts(positions, normals)
    K, N, _ = positions.shape
    fingers = checked_fingers(fingers, (K, N))
    mu, contact_model, torsional_friction = checked_friction(
        mu, contact_model, torsional_friction
    )
    torque_scale = checked_torque_scale(torque_scale, positions)
    directions = checked_directions("directions", directions)
    num_generators = check_num_generators(num_generators)
    solver = plain_str(solver)
    if type(solver) is not str or solver not in ("batch", "drake"):
        raise InvalidOptionError(
            f"solver must be 'batch' or 'drake', got {describe(solver)}"
        )
    check_workers(workers)
    palm = checked_palm(palm)
    if K == 0:
        return np.zeros((0, len(directions)))
    options = dict(
        mu=mu, torque_scale=torque_scale, contact_model=contact_model,
        torsional_friction=torsional_friction, directions=directions,
        num_generators=num_generators, solver=solver, palm=palm,
    )  # fmt: skip
    if K <= WEIGHT_CHUNK:
        return _capacity(positions, normals, fingers, **options)
    tasks = (
        (_capacity, (positions[i : i + WEIGHT_CHUNK], normals[i : i + WEIGHT_CHUNK],
                     fingers[i : i + WEIGHT_CHUNK]), options)
        for i in range(0, K, WEIGHT_CHUNK)
    )  # fmt: skip
    return np.vstack(list(map_ordered(tasks, resolve_workers(workers))))


def _capacity(positions, normals, fingers, *, mu, torque_scale, contact_model,
              torsional_friction, directions, num_generators, solver,
              palm=None):  # fmt: skip
    """:func:`weight_capacity` of one chunk of grasps, in this process."""
    K, N, _ = positions.shape
    with np.errstate(over="ignore", invalid="ignore"):  # checked below
        W = batched_primitive_wrenches(
            positions,
            normals,
            np.full((K, N), float(mu)),
            np.full((K, N), float(torsional_friction or 0.0)),
            np.zeros((K, 3)),
            np.full(K, float(torque_scale)),
            contact_model=contact_model,
            num_generators=num_generators,
        )
    if not np.all(np.isfinite(W)):  # Drake aborts on a non-finite coefficient
        raise InvalidOptionError(
            f"the moments overflow: contacts up to "
            f"{float(np.max(np.abs(positions))):g} m from O over torque_scale = "
            f"{torque_scale:g} m (with mu = {mu:g}) exceed the float range; give "
            "a torque_scale nearer the grasp's size"
        )
    per = W.shape[1] // N
    groups = np.repeat(fingers, per, axis=1)
    directions = np.asarray(directions, float)
    run = _batch_capacity if solver == "batch" else _drake_capacity
    if palm is None:
        return run(W, groups, directions)
    a, c, face, has = palm_rows(normals, fingers, palm, per, directions)
    out = np.empty((K, len(directions)))
    if not np.all(has):  # no palm row: the LPs and numbers of palm=None
        out[~has] = run(W[~has], groups[~has], directions)
    # Each grasp's sets of active faces are those of its own faces: a grasp
    # is judged alike whatever grasps share its call.
    count = face.max(axis=1) + 1  # (K,) distinct palm normals per grasp
    for R in np.unique(count[has]):
        k = np.flatnonzero(count == R)
        faces = np.repeat(face[k], per, axis=1)  # per wrench
        best = np.zeros((len(k), len(directions)))
        for active in palm_faces(int(R)):
            # the faces outside `active` carry nothing (their wrenches left
            # out); each active one at most what presses the object into it
            idle = (faces >= 0) & ~np.isin(faces, active)
            Wa = np.where(idle[..., None], 0.0, W[k])
            rows = None if not active else (a[k][:, active], c[k][:, active])
            best = np.maximum(best, run(Wa, groups[k], directions, rows))
        out[k] = best
    return out


MAX_PALM_FACES = 4
"""Distinct palm normals whose every subset gets its own LP
(:func:`palm_faces`); beyond it all of them are taken at once or none."""


def palm_faces(R: int) -> list[list[int]]:
    """The sets of palm faces that may carry force, each one LP.

    A face's row holds only while it carries force (an idle face is pressed
    by nothing), so the capacity is the best over the sets of active faces:
    every subset of ``R <= MAX_PALM_FACES`` faces (``[]``: the palm idle),
    else none and all.
    """
    if R > MAX_PALM_FACES:
        return [[], list(range(R))]
    return [[r for r in range(R) if mask >> r & 1] for mask in range(1 << R)]


def _drake_capacity(
    W: np.ndarray, groups: np.ndarray, directions, passive=None
) -> np.ndarray:
    """The primal LP of each grasp through the solver gateway (one program).

    ``passive``: ``(a, c)`` of :func:`palm_rows` for these grasps, or None.
    """
    K, _, w = W.shape
    out = np.zeros((K, len(directions)))
    G = num_groups(groups)
    if passive is not None:  # the palm's row differs per grasp: one program each
        for k in range(K):
            prog, alpha, _ = _program(
                W[k], groups[k], directions, G, (passive[0][k], passive[1][k])
            )
            result = require_solution(prog, solve(prog, "lp"), "the weight-capacity LP")
            out[k] = np.maximum(result.GetSolution(alpha), 0.0)
        return out
    prog, alpha, bindings = _program(W[0], groups[0], directions, G)
    for k in range(K):  # one program, its coefficients updated per grasp
        if k:
            member = _memberships(groups[k], G)
            for (eq, bound), A in zip(
                bindings, _equalities(W[k], directions), strict=True
            ):
                eq.evaluator().UpdateCoefficients(A, np.zeros(w))
                bound.evaluator().UpdateCoefficients(
                    member, np.full(G, -np.inf), np.ones(G)
                )
        result = require_solution(prog, solve(prog, "lp"), "the weight-capacity LP")
        out[k] = np.maximum(result.GetSolution(alpha), 0.0)
    return out


def _complement(v: np.ndarray) -> np.ndarray:
    """(D, w, w - 1) orthonormal bases of the complements of unit rows ``v``."""
    D, w = v.shape
    out = np.empty((D, w, w - 1))
    for d in range(D):
        Q, _ = np.linalg.qr(np.column_stack([v[d], np.eye(w)]))
        out[d] = Q[:, 1:w]
    return out


def _batch_capacity(
    W: np.ndarray, groups: np.ndarray, directions: np.ndarray, passive=None
):
    """The dual LPs of every grasp and direction, solved in the compiled path.

    The dual of the capacity LP, with ``y = v + P z`` (``P`` a basis of the
    complement of ``v = (u; 0)``, so ``yᵀv = 1``), is
    ``min Σ_f s_f`` s.t. ``s_f >= -yᵀw_j`` (``j`` in group ``f``), ``s >= 0``:
    ``w - 1 + G + 1`` variables ``(z, s, ζ)`` (nine for a parallel jaw, ``G``
    the groups) with ``ζ <= -Σ s`` maximised, the form of
    :func:`~drakegrasp.batch.lp.ipm.solve_max_last`.  ``α = -ζ*``.  Each LP is
    solved exactly by the active-set method
    (:func:`~drakegrasp.batch.lp.ipm.solve_max_last_active`) from the feasible
    point of :func:`_feasible_start`: about half the interior-point method's
    time on these LPs, and exact on the degenerate ones (pads on opposite flat
    faces, coplanar or duplicated contacts) whose normal matrices grow too
    ill-conditioned for the interior-point method to converge.  An LP it does
    not certify goes to the interior-point method (without numba the two
    swap roles: :func:`_solve_duals`), and a grasp neither settles to the
    primal through the solver gateway (counted in ``_FALLBACKS``).

    With a passive palm (``passive = (a, c)`` of :func:`palm_rows`) each of
    the primal's rows ``a_r·λ - c_r α <= 0`` adds a dual variable
    ``s_r >= 0`` (not in the objective: the rows' bounds are 0) before ``ζ``;
    the α column's condition becomes ``yᵀv = 1 + Σ_r c_r s_r``, so
    ``y = (1 + Σ_r c_r s_r) v + P z`` and each generator row gains
    ``-(a_rj + c_r v·w_j) s_r``.  ``s = 0`` keeps the start feasible.
    """
    K, M, w = W.shape
    D = len(directions)
    G = num_groups(groups)
    v = np.hstack([directions, np.zeros((D, w - 3))])  # (D, w)
    P = _complement(v)  # (D, w, w-1)
    extra = 0 if passive is None else passive[0].shape[1]
    n = (w - 1) + G + extra + 1
    B = np.zeros((K, D, M + G + extra + 1, n))
    h = np.zeros((K, D, M + G + extra + 1))
    # generator rows: -(Pᵀ w_j)·z - s_f <= v·w_j
    B[:, :, :M, : w - 1] = -(W[:, None] @ P[None])  # (K, D, M, w - 1)
    g = np.clip(groups, 0, G - 1)
    onehot = (g[..., None] == np.arange(G)).astype(float)  # (K, M, G)
    B[:, :, :M, w - 1 : w - 1 + G] = -onehot[:, None]
    h[:, :, :M] = (W @ v.T).transpose(0, 2, 1)
    # s >= 0
    for f in range(G):
        B[:, :, M + f, w - 1 + f] = -1.0
    if passive is not None:  # the palm's dual variables s_r >= 0
        a, c = passive  # (K, R, M), (K, R, D)
        for r in range(extra):
            B[:, :, :M, w - 1 + G + r] = (
                -a[:, r, None, :] - c[:, r, :, None] * h[:, :, :M]
            )
            B[:, :, M + G + r, w - 1 + G + r] = -1.0
    # ζ + Σ s_f <= 0 (the palm faces' s_r are not in the objective)
    B[:, :, -1, w - 1 : w - 1 + G] = 1.0
    B[:, :, -1, n - 1] = 1.0
    rows = M + G + extra + 1
    B = B.reshape(K * D, rows, n)
    h = h.reshape(K * D, rows)
    member = np.repeat(onehot, D, axis=0)  # (K D, M, G)
    value, left = _solve_duals(
        B, h, lambda rows: _feasible_start(h[rows], member[rows], n, extra)
    )
    alpha = np.maximum(-value, 0.0).reshape(K, D)
    grasps = np.unique(left // D)
    if len(grasps):  # neither settled it: the primal through Clp
        _FALLBACKS["clp"] += len(grasps)
        some = None if passive is None else (passive[0][grasps], passive[1][grasps])
        alpha[grasps] = _drake_capacity(W[grasps], groups[grasps], directions, some)
    return alpha


def _solve_duals(B: np.ndarray, h: np.ndarray, start):
    """``(value, unsettled rows)`` of the stacked dual LPs (see below).

    Compiled: the active-set method on every LP (exact, about half the
    interior-point method's time here), the interior-point method on those it
    does not certify.  Without numba (its kernels would run in Python): the
    numpy interior-point method on all, the active-set method on the few it
    does not converge on.  ``start(rows)`` gives feasible points of ``rows``.
    """
    rows = np.arange(len(B))
    routes = ("active", "ipm") if compiled.AVAILABLE else ("ipm", "active")
    value = np.zeros(len(B))
    for route in routes:
        if not len(rows):
            break
        Bs, hs = (B, h) if len(rows) == len(B) else (B[rows], h[rows])
        if route == "active":
            sol = solve_max_last_active(Bs, hs, start(rows))
        else:
            with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
                # a degenerate dual may diverge (overflow): it is not converged
                sol = solve_max_last(Bs, hs, kernel="auto")
        value[rows] = sol.value
        rows = rows[~sol.converged]
    return value, rows


def _feasible_start(
    h: np.ndarray, member: np.ndarray, n: int, extra: int = 0
) -> np.ndarray:
    """A feasible point ``(z, s, ζ)`` of each dual LP of :func:`_batch_capacity`.

    ``z = 0`` (``y = v``), each ``s_f`` the largest ``-v·w_j`` of its group
    (at least 0), the palm faces' ``s_r = 0`` and ``ζ = -Σ s_f``: every row
    holds, with equality where the maximum is attained.

    Parameters
    ----------
    h : (L, M + G + 1) float
        Right-hand sides; the first ``M`` are ``v·w_j``.
    member : (L, M, G) float
        One-hot group of each wrench.
    n : int
        Variables ``w - 1 + G + extra + 1``.
    extra : int
        The palm faces' ``s_r`` (just before ``ζ``); 0 without a palm.
    """
    L, M, G = member.shape
    x0 = np.zeros((L, n))
    neg = -h[:, :M]
    worst = np.zeros((L, G))  # per group, over a contiguous axis (faster)
    for f in range(G):
        worst[:, f] = np.where(member[:, :, f] > 0, neg, -np.inf).max(axis=1)
    s = slice(n - 1 - extra - G, n - 1 - extra)
    x0[:, s] = np.maximum(worst, 0.0)
    x0[:, n - 1] = -x0[:, s].sum(axis=1)
    return x0


def _slerp(a: np.ndarray, b: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Unit vectors a fraction ``t`` along the great-circle arcs from ``a`` to ``b``.

    ``a``, ``b`` : (..., 3) unit; ``t`` : (...) in [0, 1].  Where ``a = b`` (or
    opposite: no unique arc) the result is ``a``.
    """
    cos = np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)
    omega = np.arccos(cos)
    sin = np.sin(omega)
    ok = sin > 1e-9
    safe = np.where(ok, sin, 1.0)
    wa = np.where(ok, np.sin((1.0 - t) * omega) / safe, 1.0)
    wb = np.where(ok, np.sin(t * omega) / safe, 0.0)
    return wa[..., None] * a + wb[..., None] * b


@keyword_only("mu", after=4)
@renamed_keyword("model", "contact_model")
def fan_capacity(
    positions, normals, fans, fingers, *, mu, samples, rng, torque_scale, contact_model,
    torsional_friction, palm=None,
):  # fmt: skip
    r"""(K,) weight capacity of grasps whose edge contacts' normals are unknown.

    On a point cloud a contact at an edge (a fold of the sampled surface,
    where the finger meets two faces) has no one normal the cloud can tell:
    the true contact normal lies between the faces' normals, set by where
    the finger sits on the edge to a fraction of a millimetre (on 3,000
    points of the YCB soup can, the true can's normal differed from the
    cloud's by more than 30° at 20 of 113 contacts, all within 3 mm of a
    rim).  Each such contact carries its *fan*, the arc of normals from
    ``a`` to ``b``
    (:class:`~drakegrasp.planning.cloud.CloudContact`); the capacity is the
    mean, over ``samples`` copies, of the worst-direction weight capacity
    (:func:`~drakegrasp.planning.weight.weight_capacity`) with each edge
    contact's normal drawn uniformly along its arc,
    :math:`\hat n = \mathrm{slerp}(a, b, t)`, :math:`t \sim U(0, 1)`, one
    draw per contact and copy (a copy that is not force closure holds 0).

    Parameters
    ----------
    positions, normals : (K, N, 3) float
        Contacts (m, finite) and inward normals (finite, non-zero; normalised
        here), frame O.
    fans : (K, N, 2, 3) float
        Each contact's fan ends (inward normals, finite and non-zero;
        normalised here), all NaN for a contact without one (its normal
        stays).
    fingers : (K, N) int
        Finger labels (the palm ``F``), as for ``weight_capacity``.
    mu : float
        0 or in ``[1e-12, 1e12]``, as for ``weight_capacity``.
    samples : int
        Copies per grasp (the robustness samples), an integer ``>= 0``; 0
        gives the nominal capacity.  The copies' points (``K * samples * N *
        3`` floats) at most :data:`~drakegrasp.planning.checks.MAX_COPY_BYTES`.
    rng : numpy.random.Generator
        Draws the fans' normals (only with ``samples > 0``).
    torque_scale, contact_model, torsional_friction, palm
        As for :func:`~drakegrasp.planning.weight.weight_capacity`.

    Returns
    -------
    (K,) float
        Newtons of weight held per newton of squeeze on each finger.

    Raises
    ------
    GraspError
        An argument out of its range, naming it (checked before any draw).
    """
    positions, normals = checked_contacts(positions, normals)
    K, N, _ = positions.shape
    fans = _checked_fans(fans, (K, N, 2, 3))
    fingers = checked_fingers(fingers, (K, N))
    mu, contact_model, torsional_friction = checked_friction(
        mu, contact_model, torsional_friction
    )
    samples = checked_samples(samples, K, N)
    rng = checked_rng(rng)
    torque_scale = checked_torque_scale(torque_scale, positions)  # before any draw
    palm = checked_palm(palm)
    S = max(samples, 1)
    has = np.all(np.isfinite(fans), axis=(2, 3))  # (K, N)
    t = rng.uniform(size=(K, S, N)) if samples else np.zeros((K, S, N))
    drawn = _slerp(fans[:, None, :, 0], fans[:, None, :, 1], t)  # (K, S, N, 3)
    Nrm = np.where(has[:, None, :, None], drawn, normals[:, None])
    if not samples:
        Nrm = np.broadcast_to(normals[:, None], Nrm.shape)
    alpha = weight_capacity(
        np.repeat(positions, S, axis=0), Nrm.reshape(K * S, N, 3),
        np.repeat(fingers, S, axis=0), mu=mu, torque_scale=torque_scale,
        contact_model=contact_model, torsional_friction=torsional_friction,
        palm=palm,
    ).min(axis=1)  # fmt: skip
    return np.where(np.isfinite(alpha), alpha, 0.0).reshape(K, S).mean(axis=1)


def _checked_fans(fans, shape: tuple) -> np.ndarray:
    """``fans`` of :func:`fan_capacity`: unit ends, or all NaN (no fan)."""
    a = real_array("fans", fans)
    if a.shape != shape:
        raise InvalidContactError(
            f"fans must have shape (K, N, 2, 3) = {shape}, two ends per contact, "
            f"got shape {a.shape}"
        )
    none = np.all(np.isnan(a), axis=(2, 3))[..., None, None]  # (K, N, 1, 1)
    try:  # each end a contact normal: the message names grasp, contact, end
        ends = unit_vectors("fans", np.where(none, 1.0, a))
    except InvalidContactError as err:
        raise InvalidContactError(
            f"{err}; a contact without a fan has both ends all NaN"
        ) from None
    return np.where(none, np.nan, ends)
