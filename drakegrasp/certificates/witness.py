r"""Compute the certificates of the closure verdicts (``pydrake.solvers`` only).

The witness of a "no" comes from the normalised balance matrix ``Ḡ = T G``
(:func:`~drakegrasp.core.grasp.invariant_grasp_matrix`) on which every rank is
decided, then is mapped to the grasp frame: ``Ḡᵀ u = Gᵀ (Tᵀ u)``, so a dual
vector ``u`` of ``Ḡ`` is the physical twist ``Tᵀ u`` (an escape twist, or the
normal of a separating hyperplane in wrench space), and the wrench that
``u`` names in the normalised wrench space (moments about the contacts'
centroid over their spread) is ``T⁻¹ u``: the unresisted wrench, free of the
choice of reference point.

* Rank deficient: ``u`` spans the left null space of ``Ḡ`` (from its SVD).
* Full rank: a small program over ``u`` (6 or 3 unknowns and a slack ``s``),
  the alternative of LP1/LP2 (Stiemke's theorem):

  .. math:: \max s \;\;\text{s.t.}\;\; \sigma_i(u) + s \le 0 \;\;\forall i,\quad
            -\textstyle\sum_i a_{n,i}(u) = 1

  with ``a_i = Ḡ_iᵀ u`` and ``σ_i`` the support of contact ``i``'s cone
  (:func:`~drakegrasp.certificates.certificate.cone_support`; linear for polyhedral
  cones, second-order for exact ones).  The normalisation is possible exactly
  when a witness exists (``a_n,i`` averages ``a_i`` over the cone's
  generators), and ``s*`` is how firmly the worst-resisted direction is
  unresisted.  Form closure is the frictionless case with the signs flipped
  (``G_nᵀ v >= s``).  This program has ``w + 1`` unknowns, far fewer than
  LP1/LP2, and only runs for a "no".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.solvers import (
    MathematicalProgram,
    SolutionResult,
)

from drakegrasp._solvers import solve
from drakegrasp.certificates.certificate import (
    BALANCE,
    ESCAPE_TWIST,
    UNCONTROLLABLE,
    UNRESISTED_WRENCH,
    Certificate,
    support_of,
)
from drakegrasp.core.friction_cone import ConeLayout
from drakegrasp.core.grasp import Grasp, grasp_matrix, invariant_grasp_matrix
from drakegrasp.core.linalg import equilibrated, left_null_space
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import safe_norm

__all__ = [
    "GraspFrame",
    "balance_certificate",
    "null_space_certificate",
    "escape_twist",
    "normalising_transform",
    "uncontrollable_force",
    "unresisted_wrench",
]

_ACCEPT = -1e-9
"""A witness program's ``s*`` above this is a witness (boundary included)."""


def normalising_transform(grasp: Grasp) -> np.ndarray:
    """``T`` with ``invariant_grasp_matrix(grasp) = T @ grasp_matrix(grasp)``.

    Returns
    -------
    (6, 6) or (3, 3) float
        Moments moved from ``p`` to the contacts' centroid, then divided by the
        contacts' spread ``L``.
    """
    d = grasp.dim
    P = grasp.positions
    centroid = P.mean(axis=0)
    spread = float(np.max(np.linalg.norm(P - centroid, axis=1)))
    if not (np.isfinite(spread) and spread > 0.0):
        spread = 1.0
    r = grasp.reference_point - centroid  # m_c = m_p + r × f
    k = grasp.wrench_dim
    T = np.eye(k)
    if d == 3:
        T[3:, :3] = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    else:
        T[2, :2] = [-r[1], r[0]]
    T[d:] /= spread
    return T


def _where(grasp: Grasp) -> dict:
    return {
        "reference_point": np.array(grasp.reference_point),
        "characteristic_length": float(grasp.characteristic_length),
    }


def _scale_twist(grasp: Grasp, v: np.ndarray) -> np.ndarray:
    b, d = grasp.characteristic_length, grasp.dim
    return v / safe_norm(np.concatenate([v[:d], b * v[d:]]))


def _scale_wrench(grasp: Grasp, w: np.ndarray) -> np.ndarray:
    b, d = grasp.characteristic_length, grasp.dim
    return w / safe_norm(np.concatenate([w[:d], w[d:] / b]))


def _readable(N: np.ndarray) -> np.ndarray:
    """The same span as the orthonormal ``N``, axis directions first.

    In the normalised coordinates the unit vectors are translations (forces)
    along the frame's axes and rotations (moments) about axes through the
    contacts' centroid; those that lie in the span come first, so a report
    reads "translate along y" rather than a mixture.
    """
    picked = []
    rest = N
    for j in range(N.shape[0]):
        e = np.zeros(N.shape[0])
        e[j] = 1.0
        along = rest.T @ e
        if rest.shape[1] and np.linalg.norm(along) > 1.0 - 1e-9:
            # the axis as the span holds it (within 1e-9 of it; the axis
            # itself when it lies in the span to round-off, which keeps the
            # wording's axes exact), and the span less it: one column fewer.
            # Thresholded, an axis only nearly in the span left its small part
            # behind as a column more; taken as it was, it tilted the span by
            # up to 4.5e-5 rad: witnesses failing their own check
            v = rest @ along
            v /= np.linalg.norm(v)
            if np.linalg.norm(v - e) <= 1e-12:
                v = e
            picked.append(v)
            U, _, _ = np.linalg.svd(rest - np.outer(v, v @ rest), full_matrices=False)
            rest = U[:, : rest.shape[1] - 1]
    return np.column_stack(picked + [rest]) if picked else N


def _physical_basis(grasp, A, rank, *, wrench: bool):
    """Twists ``Tᵀ u`` (and wrenches ``T⁻¹ u``) for ``u`` spanning ``N(Aᵀ)``."""
    T = normalising_transform(grasp)
    U = _readable(left_null_space(A, rank=rank, equilibrate=True))
    twists = np.column_stack([_scale_twist(grasp, x) for x in (T.T @ U).T])
    if not wrench:
        return twists, None
    wrenches = np.linalg.solve(T, U)
    return twists, np.column_stack([_scale_wrench(grasp, x) for x in wrenches.T])


@dataclass(frozen=True)
class GraspFrame:
    """What a null-space witness needs of a grasp (a batch row has no Grasp).

    Attributes
    ----------
    positions : (N, d) float
        Contact points, metres.
    reference_point : (d,) float
    characteristic_length : float
    """

    positions: np.ndarray
    reference_point: np.ndarray
    characteristic_length: float

    @property
    def dim(self) -> int:
        """2 (planar) or 3."""
        return int(self.positions.shape[1])

    @property
    def wrench_dim(self) -> int:
        """3 (planar) or 6."""
        return 3 if self.dim == 2 else 6


def null_space_certificate(
    grasp: Grasp | GraspFrame,
    A: np.ndarray,
    rank: int,
    *,
    G_n: np.ndarray | None = None,
    cones: str = "normals",
    num_generators: int = DEFAULT_NUM_GENERATORS,
) -> Certificate:
    """The witness of a rank-deficient "no": a basis of ``N(Aᵀ)``, both signs.

    Parameters
    ----------
    grasp : Grasp or GraspFrame
    A : (w, m) float
        The normalised balance matrix (``Ḡ_n`` or ``Ḡ`` over the allowed
        components); only its column span matters.
    rank : int
        Its rank, as decided (``< w``).
    G_n : (w, N) float, optional
        The physical ``G_n``: given for form closure, whose witness is an escape
        twist with ``contact_rates = G_nᵀ v``; omitted for force closure.
    cones : str, optional
        The force-closure cones the witness refers to.
    num_generators : int, optional

    Returns
    -------
    Certificate
    """
    twists, wrenches = _physical_basis(grasp, A, rank, wrench=G_n is None)
    if G_n is not None:
        v = twists[:, 0]
        return Certificate(
            ESCAPE_TWIST, "normals", v, twists, contact_rates=G_n.T @ v, **_where(grasp)
        )
    return Certificate(
        UNRESISTED_WRENCH,
        cones,
        wrenches[:, 0],
        wrenches,
        separating_twist=twists[:, 0],
        separating_basis=twists,
        contact_rates=np.zeros(len(grasp.positions)),
        num_generators=num_generators,
        **_where(grasp),
    )


def escape_twist(grasp: Grasp, rank: int) -> Certificate | None:
    """Escape twist of a grasp that is not in first-order form closure.

    Parameters
    ----------
    grasp : Grasp
    rank : int
        ``rank(G_n)`` as the verdict decided it.

    Returns
    -------
    Certificate or None
        None when no ``v`` with ``G_nᵀ v >= 0`` exists (LP1's "no" was within
        ``tol`` of the boundary).
    """
    A = invariant_grasp_matrix(grasp)[:, grasp.normal_indices()]
    G_n = grasp_matrix(grasp)[:, grasp.normal_indices()]
    if rank < grasp.wrench_dim:
        return null_space_certificate(grasp, A, rank, G_n=G_n)
    k = grasp.wrench_dim
    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(k + 1, "u")
    # A_ᵀ u - s >= 0 (no contact penetrates), Σ (A_ᵀ u) = 1, max s.
    rows = np.hstack([A.T, -np.ones((A.shape[1], 1))])
    prog.AddLinearConstraint(rows, np.zeros(len(rows)), np.full(len(rows), np.inf), x)
    total = np.append(A.sum(axis=1), 0.0)[None, :]
    prog.AddLinearEqualityConstraint(total, [1.0], x)
    prog.AddLinearCost(np.append(np.zeros(k), -1.0), x)
    return _finish(prog, x, grasp, conic=False, kind="twist", G=G_n)


def _finish(prog, x, grasp, *, conic, kind, G=None, cones="normals", ng=8):
    """Solve a witness program; the certificate, or None if there is none."""
    result = solve(prog, "socp" if conic else "lp")
    if result.get_solution_result() != SolutionResult.kSolutionFound:
        return None
    sol = result.GetSolution(x)
    if not sol[-1] > _ACCEPT:
        return None
    T = normalising_transform(grasp)
    u = T.T @ sol[:-1]
    if kind == "twist":
        v = _scale_twist(grasp, u)
        return Certificate(
            ESCAPE_TWIST,
            "normals",
            v,
            np.zeros((len(v), 0)),
            contact_rates=G.T @ v,
            **_where(grasp),
        )
    y = _scale_twist(grasp, u)  # the hyperplane's normal: yᵀ G f <= 0
    w = _scale_wrench(grasp, np.linalg.solve(T, sol[:-1]))
    # a_i(y) = A_iᵀ ū / c with the same scale c that took u to y
    blocks, layout = G
    c = np.linalg.norm(u) / np.linalg.norm(y)
    b = grasp.characteristic_length
    support = np.array(
        [
            support_of(Ai @ sol[:-1] / c, cone, contact, cones, b)
            for Ai, cone, contact in zip(
                blocks, layout.cones, grasp.contacts, strict=True
            )
        ]
    )
    return Certificate(
        UNRESISTED_WRENCH,
        cones,
        w,
        np.zeros((len(w), 0)),
        separating_twist=y,
        separating_basis=np.zeros((len(w), 0)),
        contact_rates=support,
        num_generators=ng,
        **_where(grasp),
    )


def unresisted_wrench(
    grasp: Grasp, rank: int, *, cones: str, num_generators: int = DEFAULT_NUM_GENERATORS
) -> Certificate | None:
    """Unresisted wrench of a grasp that is not in force closure.

    Parameters
    ----------
    grasp : Grasp
    rank : int
        Rank of ``G`` over the components the cones allow, as decided.
    cones : {"polyhedral", "exact"}
    num_generators : int, optional
        Generators of the polyhedral cones.

    Returns
    -------
    Certificate or None
        None when the program finds no separating direction (the verdict's
        "no" was within ``tol`` of the boundary).
    """
    layout = ConeLayout.of(grasp, num_generators)
    A = invariant_grasp_matrix(grasp)[:, layout.columns]
    if rank < grasp.wrench_dim:
        return null_space_certificate(
            grasp, A, rank, cones=cones, num_generators=num_generators
        )
    k = grasp.wrench_dim
    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(k + 1, "u")
    starts = list(layout.normal_positions) + [len(layout.columns)]
    normal_sum = np.zeros(k + 1)
    blocks, linear = [], []
    for i, (cone, c) in enumerate(zip(layout.cones, grasp.contacts, strict=True)):
        Ai = A[:, starts[i] : starts[i + 1]].T  # a_i = Ai u, contact components
        blocks.append(Ai)
        normal_sum[:k] -= Ai[0]
        round_cone = cone.components in ((0, 1, 2), (0, 1, 2, 3))
        if cones == "exact" and round_cone:
            _add_exact_support(prog, x, Ai, c, grasp.characteristic_length)
        else:  # generatorsᵀ a + s <= 0
            S = cone.generators
            linear.append(np.hstack([S.T @ Ai, np.ones((S.shape[1], 1))]))
    if linear:
        rows = np.vstack(linear)
        prog.AddLinearConstraint(
            rows, np.full(len(rows), -np.inf), np.zeros(len(rows)), x
        )
    prog.AddLinearEqualityConstraint(normal_sum[None, :], [1.0], x)
    prog.AddLinearCost(np.append(np.zeros(k), -1.0), x)
    conic = bool(prog.lorentz_cone_constraints())
    return _finish(
        prog,
        x,
        grasp,
        conic=conic,
        kind="wrench",
        G=(blocks, layout),
        cones=cones,
        ng=num_generators,
    )


def _add_exact_support(prog, x, Ai, contact, b) -> None:
    """``a_n + μ ‖a_t‖ + s <= 0`` (and ``a_n + bν |a_m| + s <= 0``, soft)."""
    k = Ai.shape[1]
    # z = [-a_n - s; μ a_t] in the Lorentz cone.
    Z = np.zeros((3, k + 1))
    Z[0, :k], Z[0, k] = -Ai[0], -1.0
    Z[1:, :k] = contact.mu * Ai[1:3]
    prog.AddLorentzConeConstraint(Z, np.zeros(3), x)
    if Ai.shape[0] == 4:
        bn = b * contact.torsional_friction
        for sign in (1.0, -1.0):
            row = np.append(Ai[0] + sign * bn * Ai[3], 1.0)[None, :]
            prog.AddLinearConstraint(row, [-np.inf], [0.0], x)


def uncontrollable_force(
    grasp: Grasp, contact_forces: tuple[np.ndarray, ...]
) -> Certificate:
    """LP3's optimal forces as the witness of an LP3 failure."""
    return Certificate(
        UNCONTROLLABLE, "normals", contact_forces=tuple(contact_forces), **_where(grasp)
    )


def balance_certificate(
    grasp: Grasp,
    contact_forces: tuple[np.ndarray, ...],
    *,
    cones: str,
    rank: int,
    num_generators: int = DEFAULT_NUM_GENERATORS,
) -> Certificate:
    """A "yes": the balancing forces and the basis of ``N(G)`` they came from.

    Parameters
    ----------
    grasp : Grasp
    contact_forces : tuple of ndarray
        The verdict's optimal forces (LP1's for the normal-force route).
    cones : {"normals", "polyhedral", "exact"}
    rank : int
        Rank of the balance matrix, as decided.
    num_generators : int, optional

    Returns
    -------
    Certificate
        ``internal_basis`` (M, k): orthonormal basis of the null space of the
        normalised ``G`` over the allowed components, zero rows elsewhere.
    """
    if cones == "normals":
        cols = grasp.normal_indices()
    else:
        cols = ConeLayout.of(grasp, num_generators).columns
    A_s, scale = equilibrated(invariant_grasp_matrix(grasp)[:, cols])
    # N(A) = D N(A D): the null space of the equilibrated matrix, pulled back.
    null = scale[:, None] * np.linalg.svd(A_s)[2][rank:].T
    basis = np.zeros((grasp.num_components, null.shape[1]))
    if null.shape[1]:
        basis[cols] = np.linalg.qr(null)[0]
    return Certificate(
        BALANCE,
        cones,
        contact_forces=tuple(contact_forces),
        internal_basis=basis,
        num_generators=num_generators,
        **_where(grasp),
    )
