r"""Second-order form closure (Rimon–Burdick) as a small semidefinite program.

When first-order form closure fails but the normal forces can balance,
``λ >= 0, λ != 0, G_n λ = 0``, the object may still be immobilised by the
curvature of the surfaces at the contacts.  Let ``S`` be the contacts that carry
force in some equilibrium and ``W = {v : G_iᵀ v = 0, i ∈ S}`` the motions that
roll or slide at every one of them to first order.  For ``v ∈ W`` and an
equilibrium λ, the acceleration terms cancel in the weighted sum of the signed
distances (:mod:`drakegrasp.core.curvature`):

.. math:: \sum_i \lambda_i \psi_i(q(t)) = \tfrac{t^2}{2}\, v^T
          \Big(\sum_i \lambda_i H_i\Big) v + O(t^3),

so if some λ makes ``Σ λ_i H_i`` negative definite on ``W``, every motion
penetrates some finger: the grasp is immobilised to second order.  Deciding it
is the SDP

.. math:: \max t \;\; \text{s.t.}\;\; -\textstyle\sum_i \lambda_i A_i \succeq t I,
          \;\; \lambda \ge 0,\;\; G_n \lambda = 0,\;\; \mathbf 1^T \lambda = 1,

with ``A_i = b B^T H_i B`` on an orthonormal basis ``B`` of ``W`` in the
normalised twist coordinates ``[v_c; b ω]`` (``c`` the contacts' centroid,
``b`` the characteristic length), so that ``t*`` is dimensionless and its sign
does not depend on units or on the reference point.  Contacts are treated as
frictionless whatever their model.  The derivation is ``docs/second_order.md``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np
from pydrake.solvers import (
    MathematicalProgram,
    SolutionResult,
)

from drakegrasp._solvers import solve
from drakegrasp.certificates.kinds import BALANCE, ESCAPE_TWIST
from drakegrasp.closure.constraints import (
    add_linear_constraint,
    add_linear_equality_constraint,
)
from drakegrasp.closure.programs import add_balance
from drakegrasp.closure.results import ClosureResult
from drakegrasp.closure.verdicts import form_closure
from drakegrasp.core.calls import checked_call
from drakegrasp.core.curvature import ContactCurvature, _skew, contact_hessians
from drakegrasp.core.grasp import Grasp, normal_grasp_matrix
from drakegrasp.core.linalg import left_null_space
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import DEFAULT_RANK_TOL, near_threshold, relative_margin
from drakegrasp.core.validation import (
    TOL_MAX,
    TOL_MIN,
    check_grasp,
    check_rank_tol,
    describe,
    real_scalar,
)
from drakegrasp.errors import (
    GraspError,
    InvalidGraspError,
    InvalidOptionError,
    SolverError,
)

__all__ = [
    "DEFAULT_SECOND_ORDER_TOL",
    "ESCAPE_TOL",
    "SecondOrderResult",
    "SecondOrderVariables",
    "build_second_order_program",
    "equilibrium_support",
    "second_order_form_closure",
]

DEFAULT_SECOND_ORDER_TOL = 1e-6
"""Second-order closure needs ``t* > tol`` (``t*`` dimensionless, see above)."""

ESCAPE_TOL = DEFAULT_SECOND_ORDER_TOL
"""Largest shortfall an escape may have: it holds when ``escape_margin >= -min(tol,
ESCAPE_TOL)``.  A numerical zero of the margin, not the verdict's ``tol``: a
larger ``tol`` calls more grasps "not immobilised", but never takes a motion
that penetrates a finger for an escape."""

_ESCAPE_BOX = 10.0  # bound on the normalised escape acceleration


def _twist_scaling(grasp: Grasp) -> np.ndarray:
    """``T`` with ``v = T ν``: raw twist about ``p`` from ``ν = [v_c; b ω]``."""
    b = grasp.characteristic_length
    r = grasp.reference_point - grasp.positions.mean(axis=0)
    if grasp.planar:
        return np.array([[1.0, 0.0, -r[1] / b], [0.0, 1.0, r[0] / b], [0, 0, 1 / b]])
    T = np.eye(6)
    T[:3, 3:] = -_skew(r) / b
    T[3:, 3:] /= b
    return T


def equilibrium_support(
    grasp: Grasp, *, rank_tol: float = DEFAULT_RANK_TOL
) -> tuple[int, ...]:
    """Contacts whose normal force is positive in some equilibrium.

    Parameters
    ----------
    grasp : Grasp
    rank_tol : float, optional
        ``G_n λ = 0`` is imposed on ``G_n``'s numerical row space.

    Returns
    -------
    tuple of int
        The largest support ``S`` of ``λ >= 0, G_n λ = 0`` (empty when no
        equilibrium exists), from one LP: ``max Σ s`` s.t. ``G_n λ = 0``,
        ``λ >= s``, ``0 <= s <= 1``, ``λ <= 1e6``.  Contacts outside ``S`` can
        separate to first order (Goldman–Tucker).
    """
    N = grasp.num_contacts
    prog = MathematicalProgram()
    lam = prog.NewContinuousVariables(N, "lambda")
    s = prog.NewContinuousVariables(N, "s")
    add_balance(prog, normal_grasp_matrix(grasp), lam, rank_tol)
    prog.AddBoundingBoxConstraint(0.0, 1.0, s)
    prog.AddBoundingBoxConstraint(0.0, 1e6, lam)
    add_linear_constraint(
        prog,
        np.hstack([np.eye(N), -np.eye(N)]),
        np.zeros(N),
        np.full(N, np.inf),
        np.append(lam, s),
    )
    prog.AddLinearCost(-np.ones(N), 0.0, s)
    result = solve(prog, "lp")
    if result.get_solution_result() != SolutionResult.kSolutionFound:
        raise SolverError(
            "the equilibrium-support LP failed with "
            f"{result.get_solution_result().name} (it is always feasible)",
            program=prog,
            result=result,
        )
    return tuple(int(i) for i in np.flatnonzero(result.GetSolution(s) > 0.5))


@dataclass(frozen=True)
class SecondOrderVariables:
    """Decision variables and data of the second-order program.

    Attributes
    ----------
    multipliers : ndarray of Variable, (len(support),)
        ``λ_i`` of the contacts in ``support``.
    t : pydrake.symbolic.Variable
        The eigenvalue bound that the program maximises.
    support : (s,) int
        Contacts that carry force in some equilibrium.
    basis : (3 or 6, dim W) float
        Orthonormal basis of ``W`` in normalised twists ``ν = [v_c; b ω]``.
    scaling : (3 or 6, 3 or 6) float
        ``T`` with raw twist (about ``p``) ``v = T ν``.
    matrices : (s, dim W, dim W) float
        ``A_i = b Bᵀ Tᵀ H_i T B`` of the support's contacts (dimensionless).
    hessians : (N, 3 or 6, 3 or 6) float
        ``H_i`` in raw twists about ``p`` (metres per twist unit squared).
    lmi : Binding
        The constraint ``-Σ λ_i A_i - t I ⪰ 0``.
    """

    multipliers: np.ndarray
    t: object
    support: np.ndarray
    basis: np.ndarray
    scaling: np.ndarray
    matrices: np.ndarray
    hessians: np.ndarray
    lmi: object


def build_second_order_program(
    grasp: Grasp,
    curvatures: Sequence[ContactCurvature],
    *,
    support: Sequence[int] | None = None,
    rank_tol: float = DEFAULT_RANK_TOL,
    hessians: np.ndarray | None = None,
) -> tuple[MathematicalProgram, SecondOrderVariables]:
    """Build the SDP of second-order form closure.

    Parameters
    ----------
    grasp : Grasp
    curvatures : sequence of ContactCurvature
        Object and finger curvature at each contact, in contact order.
    support : sequence of int, optional
        The contacts that carry force in some equilibrium; default
        :func:`equilibrium_support` (which solves one LP).
    rank_tol : float, optional
        Relative singular-value threshold for ``W`` and ``G_n λ = 0``.
    hessians : (N, 3 or 6, 3 or 6) float, optional
        :func:`~drakegrasp.core.curvature.contact_hessians` of ``grasp`` and
        ``curvatures``, when already computed.

    Returns
    -------
    prog : MathematicalProgram
        ``max t`` s.t. ``-Σ λ_i A_i ⪰ t I``, ``λ >= 0``, ``G_n λ = 0``,
        ``Σ λ = 1`` over the support's multipliers.
    variables : SecondOrderVariables

    Raises
    ------
    InvalidGraspError
        When the support is empty (no equilibrium) or ``W = {0}``.
    """
    H = contact_hessians(grasp, curvatures) if hessians is None else hessians
    if support is None:
        support = equilibrium_support(grasp, rank_tol=rank_tol)
    S = np.array(sorted(set(int(i) for i in support)), dtype=int)
    if S.size == 0:
        raise InvalidGraspError(
            "no equilibrium λ >= 0, λ != 0 with G_n λ = 0: nothing to test at "
            "second order"
        )
    T = _twist_scaling(grasp)
    Gs = T.T @ normal_grasp_matrix(grasp)[:, S]
    B = left_null_space(Gs, rank_tol=rank_tol)
    if B.shape[1] == 0:
        raise InvalidGraspError("W = {0}: the grasp is decided at first order")
    b = grasp.characteristic_length
    A = np.array([b * B.T @ T.T @ H[i] @ T @ B for i in S])
    A = 0.5 * (A + A.transpose(0, 2, 1))
    prog = MathematicalProgram()
    lam = prog.NewContinuousVariables(len(S), "lambda")
    t = prog.NewContinuousVariables(1, "t")[0]
    prog.AddBoundingBoxConstraint(0.0, np.inf, lam)
    add_linear_equality_constraint(prog, np.ones((1, len(S))), [1.0], lam)
    add_balance(prog, Gs, lam, rank_tol)
    k = B.shape[1]
    lmi = prog.AddLinearMatrixInequalityConstraint(
        [np.zeros((k, k))] + [-Ai for Ai in A] + [-np.eye(k)], np.append(lam, t)
    )
    prog.AddLinearCost(-t)
    return prog, SecondOrderVariables(lam, t, S, B, T, A, H, lmi)


@checked_call
@dataclass(frozen=True)
class SecondOrderResult:
    """Verdict of second-order form closure.

    Attributes
    ----------
    is_closure : bool or None
        Immobilised to first order (``order == 1``) or to second (``2``);
        None when nothing was decided (:attr:`decided`: a contact without a
        curvature model, see :meth:`undecided`).
    order : int or None
        1, 2, or None when not immobilised (or not decided) at second order.
    t_star : float
        Optimal ``t`` (dimensionless: the least eigenvalue of ``-Σ λ_i A_i``
        on ``W``); ``inf`` for first-order closure, NaN with no equilibrium.
    multipliers : (N,) float
        ``λ*`` (``Σ λ = 1``; zero outside ``support``).
    dim_w : int
        ``dim W`` (0 for first-order closure, -1 when not decided).
    support : tuple of int
        Contacts that carry force in some equilibrium.
    escape_twist : (3,) or (6,) float or None
        For a "no": a motion ``v = [v_p; ω]`` (about the reference point, grasp
        frame, unit in normalised twists) that no contact resists to second
        order together with ``escape_acceleration``.
    escape_acceleration : (3,) or (6,) float or None
        ``a`` with ``G_iᵀ a + vᵀ H_i v >= escape_margin`` at every contact that
        ``v`` does not separate to first order.
    escape_margin : float
        That bound (dimensionless, times ``b``); NaN without an escape.
    escape_verified : bool
        True when the escape holds (``escape_margin >= -min(tol, ESCAPE_TOL)``,
        :data:`ESCAPE_TOL`).
    margin : float
        ``(t* - tol) / tol``.
    tol : float
    solver, status : str
    reason : str
        One sentence that says why.
    """

    is_closure: bool | None
    order: int | None
    t_star: float
    multipliers: np.ndarray
    dim_w: int
    support: tuple[int, ...]
    escape_twist: np.ndarray | None
    escape_acceleration: np.ndarray | None
    escape_margin: float
    escape_verified: bool
    margin: float
    tol: float
    solver: str
    status: str
    reason: str

    @classmethod
    def undecided(
        cls, num_contacts: int, reason: str, *, tol: float = DEFAULT_SECOND_ORDER_TOL
    ) -> SecondOrderResult:
        """A result that decides nothing, for contacts without a curvature model.

        Its ``is_closure`` is None, not False: nothing says the grasp is not
        immobilised.
        """
        return cls(
            is_closure=None,
            order=None,
            t_star=math.nan,
            multipliers=np.zeros(num_contacts),
            dim_w=-1,
            support=(),
            escape_twist=None,
            escape_acceleration=None,
            escape_margin=math.nan,
            escape_verified=False,
            margin=math.nan,
            tol=tol,
            solver="",
            status="not solved",
            reason=f"not decided: {reason}",
        )

    @property
    def decided(self) -> bool:
        """False for a result of :meth:`undecided` (no program was solved)."""
        return self.is_closure is not None

    @property
    def near_boundary(self) -> bool:
        """True when ``t*`` is within ``tol`` of 0: higher orders decide."""
        return math.isfinite(self.t_star) and near_threshold(self.margin)

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        d = {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}
        d["near_boundary"] = self.near_boundary
        d["decided"] = self.decided
        return d

    def __str__(self) -> str:
        if not self.decided:
            return f"second-order form closure: not decided\n  {self.reason}"
        verdict = {1: "YES (first order)", 2: "YES (second order)"}.get(
            self.order, "no"
        )
        lam = np.round(self.multipliers, 4).tolist()
        # no equilibrium to test: the program of t* was not solved
        t_star = (
            f"t* = {self.t_star:.6g}" if math.isfinite(self.t_star) else "t* not solved"
        )
        line = (
            f"second-order form closure: {verdict}, {t_star}, "
            f"dim W = {self.dim_w}, λ* = {lam}, solver {self.solver} "
            f"({self.status})"
        )
        return line + "\n  " + self.reason


def _check_tol(tol: float) -> float:
    t = real_scalar("tol", tol)
    if not TOL_MIN <= t <= TOL_MAX:  # NaN fails too
        raise InvalidOptionError(
            f"tol must be finite and > 0, a real number in [{TOL_MIN:g}, "
            f"{TOL_MAX:g}] (a numerical zero for the dimensionless t*, as for d*), "
            f"got {describe(tol)}"
        )
    return t


def _check_first_order(first_order, grasp: Grasp) -> None:
    """Refuse a ``first_order`` that is not :func:`form_closure` of ``grasp``.

    Its verdict decides the answer outright ("yes" at first order), so it is
    checked, not trusted: it must be a form-closure result over ``grasp``'s
    contacts whose certificate (balancing normal forces for a "yes", an escape
    twist for a "no") holds on ``grasp``.
    """
    what = (
        "first_order must be the ClosureResult of drakegrasp.form_closure on this "
        "grasp, or None"
    )
    if not isinstance(first_order, ClosureResult):
        raise InvalidOptionError(f"{what}; got a {type(first_order).__name__}")
    if first_order.kind != "form closure":
        raise InvalidOptionError(
            f"{what}; got a {first_order.kind!r} result (friction does not count "
            "in form closure)"
        )
    forces = first_order.contact_forces
    if forces is None or len(forces) != grasp.num_contacts:
        count = "no" if forces is None else len(forces)
        raise InvalidOptionError(
            f"{what}; it has {count} contact forces, the grasp "
            f"{grasp.num_contacts} contacts"
        )
    cert = first_order.certificate
    want = BALANCE if first_order.is_closure else ESCAPE_TWIST
    held = False
    if cert is not None and cert.kind == want and cert.cones == "normals":
        try:
            held = cert.check(grasp).holds
        except GraspError:  # shapes of another grasp
            held = False
    if not held:
        verdict = "form closure" if first_order.is_closure else "no form closure"
        raise InvalidOptionError(
            f"{what}: its certificate of {verdict} does not hold on this grasp, so "
            "it was computed for another grasp (or edited)"
        )


@checked_call
def second_order_form_closure(
    grasp: Grasp,
    curvatures: Sequence[ContactCurvature],
    *,
    tol: float = DEFAULT_SECOND_ORDER_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
    first_order: ClosureResult | None = None,
) -> SecondOrderResult:
    """Decide second-order form closure of a frictionless grasp (Rimon–Burdick).

    Parameters
    ----------
    grasp : Grasp
        Contacts in the grasp frame; friction is ignored.
    curvatures : sequence of ContactCurvature
        One per contact: object and finger principal curvatures (1/m) and
        directions in the grasp frame (planar: one curvature each).
    tol : float, optional
        Closure needs ``t* > tol``; a real number in [1e-10, 0.5]. An escape
        motion is reported only when it holds to ``min(tol, ESCAPE_TOL)``.
    rank_tol : float, optional
        Relative singular-value threshold for ranks and ``W``.
    first_order : ClosureResult, optional
        :func:`~drakegrasp.form_closure` of the same grasp, if already known.

    Returns
    -------
    SecondOrderResult
        A "yes" is certain to second order (the multipliers are the
        certificate).  A "no" carries an escape motion when one exists in
        ``W``; ``escape_verified`` False means the test is inconclusive there
        (no single λ blocks every motion, yet none escapes along the
        candidate directions).
    """
    check_grasp(grasp)
    tol = _check_tol(tol)
    rank_tol = check_rank_tol(rank_tol)
    if first_order is not None:
        _check_first_order(first_order, grasp)
    H = contact_hessians(grasp, curvatures)  # validates before any solve
    N = grasp.num_contacts
    if first_order is None:
        first_order = form_closure(grasp, rank_tol=rank_tol)
    if first_order.is_closure:
        lam = np.concatenate(first_order.contact_forces)
        return SecondOrderResult(
            True,
            1,
            math.inf,
            lam / lam.sum(),
            0,
            tuple(range(N)),
            None,
            None,
            math.nan,
            False,
            math.inf,
            tol,
            first_order.solver,
            first_order.status,
            "first-order form closure: W = {0}",
        )
    support = equilibrium_support(grasp, rank_tol=rank_tol)
    if not support:
        return _no_equilibrium(grasp, tol)
    prog, var = build_second_order_program(
        grasp, curvatures, support=support, rank_tol=rank_tol, hessians=H
    )
    result = solve(prog, "sdp")
    status = result.get_solution_result()
    solver = result.get_solver_id().name()
    if status != SolutionResult.kSolutionFound:
        raise SolverError(
            f"{solver} failed with status {status.name} on the second-order SDP "
            "(always feasible and bounded, so this is numerical)",
            program=prog,
            result=result,
        )
    t_star = float(result.GetSolution(var.t))
    lam = np.zeros(N)
    lam[var.support] = np.clip(result.GetSolution(var.multipliers), 0.0, None)
    k = var.basis.shape[1]
    common = dict(
        multipliers=lam,
        dim_w=k,
        support=tuple(int(i) for i in var.support),
        margin=relative_margin(t_star, tol),
        tol=tol,
        solver=solver,
        status=status.name,
        t_star=t_star,
    )
    if t_star > tol:
        return SecondOrderResult(
            is_closure=True,
            order=2,
            escape_twist=None,
            escape_acceleration=None,
            escape_margin=math.nan,
            escape_verified=False,
            reason=f"immobilised to second order: Σ λ_i H_i is negative definite "
            f"on W (dim {k}); every motion in W penetrates a finger",
            **common,
        )
    dual = _dual_matrix(result.GetDualSolution(var.lmi), k)
    escape = _find_escape(grasp, var, H, lam, dual, min(tol, ESCAPE_TOL))
    if escape is None:
        reason = (
            "not immobilised by any single λ, but no candidate motion escapes "
            "either: inconclusive at second order"
        )
        if t_star > 0:
            reason = (
                f"t* = {t_star:.3g} > 0 but not above tol = {tol:g}: not called "
                "immobilised at this tolerance, and no motion escapes to second "
                "order (a smaller tol decides)"
            )
        return SecondOrderResult(
            is_closure=False,
            order=None,
            escape_twist=None,
            escape_acceleration=None,
            escape_margin=math.nan,
            escape_verified=False,
            reason=reason,
            **common,
        )
    v, a, s_star = escape
    how = "higher orders decide" if t_star > -tol else "it escapes to second order"
    return SecondOrderResult(
        is_closure=False,
        order=None,
        escape_twist=v,
        escape_acceleration=a,
        escape_margin=s_star,
        escape_verified=True,
        reason=f"not immobilised: the motion v = {np.round(v, 4).tolist()} "
        f"penetrates no finger to second order ({how})",
        **common,
    )


def _dual_matrix(values: np.ndarray, k: int) -> np.ndarray:
    """The LMI's dual from its upper triangle, row-major (= lower, column-major)."""
    X = np.zeros((k, k))
    iu = np.triu_indices(k)
    X[iu] = np.asarray(values, dtype=float).reshape(-1)[: len(iu[0])]
    return X + np.triu(X, 1).T


def _find_escape(grasp, var: SecondOrderVariables, H, lam, dual, tol):
    """A motion in W that no contact resists to second order, or None.

    ``tol``: the shortfall an escape may have, ``min(tol, ESCAPE_TOL)`` of the
    verdict (a numerical zero).

    Candidates: the eigenvectors of ``-Σ λ*_i A_i`` at its least eigenvalue and
    the dual matrix's leading eigenvector.  Each one's sign is chosen so that
    contacts outside the support separate (or roll) to first order, and an LP
    then looks for an acceleration that keeps every other contact closed.
    """
    M = -np.einsum("i,ijk->jk", lam[var.support], var.matrices)
    w, V = np.linalg.eigh(M)
    candidates = [V[:, j] for j in range(len(w)) if w[j] <= w[0] + 10 * tol]
    if np.all(np.isfinite(dual)) and np.trace(dual) > 0:
        candidates.append(np.linalg.eigh(dual)[1][:, -1])
    T, B = var.scaling, var.basis
    Gt = T.T @ normal_grasp_matrix(grasp)
    b = grasp.characteristic_length
    best = None
    for c in candidates:
        for sign in (1.0, -1.0):
            nu = sign * B @ c
            g = Gt.T @ nu
            if np.min(g) < -1e-9:
                continue
            found = _escape_acceleration(Gt, np.abs(g) <= 1e-9, H, T, nu, b)
            if found is not None and (best is None or found[1] > best[2]):
                best = (T @ nu, T @ found[0], found[1])
            if best is not None and best[2] >= -tol:
                return best  # an escape that holds: no need to try the others
    if best is None or best[2] < -tol:
        return None
    return best


def _escape_acceleration(Gt, closed, H, T, nu, b):
    """LP: ``max s - ε |ã|₁`` s.t. ``G̃_iᵀ ã + b νᵀ H̃_i ν >= s`` on closed contacts.

    The small ``ε`` picks the least acceleration among the near-optimal ones
    (an LP vertex at the box's corner would make third-order terms large).
    Returns ``ã`` and ``min_i (G̃_iᵀ ã + b νᵀ H̃_i ν)``.
    """
    idx = np.flatnonzero(closed)
    h = np.array([b * nu @ T.T @ H[i] @ T @ nu for i in idx])
    n = Gt.shape[0]
    prog = MathematicalProgram()
    a = prog.NewContinuousVariables(n, "a")
    z = prog.NewContinuousVariables(n, "abs_a")
    s = prog.NewContinuousVariables(1, "s")[0]
    prog.AddBoundingBoxConstraint(-_ESCAPE_BOX, _ESCAPE_BOX, a)
    prog.AddBoundingBoxConstraint(-np.inf, 1.0, s)
    eye = np.eye(n)
    add_linear_constraint(
        prog,
        np.block([[eye, eye], [-eye, eye]]),
        np.zeros(2 * n),
        np.full(2 * n, np.inf),
        np.append(a, z),
    )
    A = np.hstack([Gt[:, idx].T, -np.ones((len(idx), 1))])
    add_linear_constraint(prog, A, -h, np.full(len(idx), np.inf), np.append(a, s))
    prog.AddLinearCost(np.append(np.full(n, 1e-3), -1.0), 0.0, np.append(z, s))
    result = solve(prog, "lp")
    if result.get_solution_result() != SolutionResult.kSolutionFound:
        return None
    acc = np.asarray(result.GetSolution(a))
    return acc, float(np.min(Gt[:, idx].T @ acc + h)) if len(idx) else 1.0


def _no_equilibrium(grasp: Grasp, tol: float) -> SecondOrderResult:
    """No equilibrium: a first-order escape (``G̃ᵀ ν > 0``) from one LP."""
    T = _twist_scaling(grasp)
    Gt = T.T @ normal_grasp_matrix(grasp)
    n, N = Gt.shape
    prog = MathematicalProgram()
    nu = prog.NewContinuousVariables(n, "nu")
    s = prog.NewContinuousVariables(1, "s")[0]
    prog.AddBoundingBoxConstraint(-1.0, 1.0, nu)
    prog.AddBoundingBoxConstraint(-np.inf, 1.0, s)
    add_linear_constraint(
        prog,
        np.hstack([Gt.T, -np.ones((N, 1))]),
        np.zeros(N),
        np.full(N, np.inf),
        np.append(nu, s),
    )
    prog.AddLinearCost(-s)
    result = solve(prog, "lp")
    v = np.asarray(result.GetSolution(nu))
    v = T @ (v / np.linalg.norm(v))
    s_star = float(result.GetSolution(s))
    return SecondOrderResult(
        is_closure=False,
        order=None,
        t_star=math.nan,
        multipliers=np.zeros(N),
        dim_w=n,
        support=(),
        escape_twist=v,
        escape_acceleration=np.zeros(n),
        escape_margin=s_star,
        escape_verified=s_star > 0,
        margin=-math.inf,
        tol=tol,
        solver=result.get_solver_id().name(),
        status=result.get_solution_result().name,
        reason="no equilibrium λ >= 0, λ != 0 with G_n λ = 0: the twist v = "
        f"{np.round(v, 4).tolist()} separates every contact to first order",
    )
