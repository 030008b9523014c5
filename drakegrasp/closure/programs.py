r"""Form closure, force closure and the hand's internal forces as Drake programs.

Every program is built by a ``build_*_program`` function that returns the
``MathematicalProgram`` and its decision variables, so a user can inspect or
extend it, and solved by the function of the same name without ``build_``:

* LP1 (first-order form closure), over the normal forces ``f_n``:

  .. math:: \max d \;\; \text{s.t.}\;\; G_n f_n = 0,\; f_n - \mathbf 1 d \ge 0,\;
            d \ge 0,\; \mathbf 1^T f_n \le N

* LP2 (frictional force closure), over the stacked contact forces ``f``:

  .. math:: \max d \;\; \text{s.t.}\;\; G f = 0,\; F f - \mathbf 1 d \ge 0,\;
            d \ge 0,\; \textstyle\sum_i f_{n,i} \le N

* LP3 (internal forces the hand cannot control; ``d^* = 0`` passes):

  .. math:: \max d \;\; \text{s.t.}\;\; G f = 0,\; J^T f = 0,\; E f - \mathbf 1 d
            \ge 0,\; d \ge 0,\; \textstyle\sum_i f_{n,i} \le N

* The exact-cone program: LP2 with each Coulomb cone as a second-order cone, ``d``
  being the distance of each contact force to its cone's boundary (so the
  polyhedral ``d*``, inscribed, never exceeds the exact one).

Components that a degenerate cone forbids (the tangential force of a hard finger
with ``mu = 0``) are not variables at all: such a contact behaves exactly as a
frictionless one.  This module imports ``pydrake.solvers`` only, never the plant.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.solvers import MathematicalProgram

from drakegrasp.closure.constraints import (
    EXACT_CONE_COMPONENTS,
    add_contact_cones,
    add_linear_constraint,
    add_linear_equality_constraint,
)
from drakegrasp.core.calls import checked_call
from drakegrasp.core.deferred import WeakMemo
from drakegrasp.core.friction_cone import ConeLayout
from drakegrasp.core.grasp import (
    Grasp,
    check_hand_jacobian,
    invariant_grasp_matrix,
)
from drakegrasp.core.linalg import (
    equilibrated,
    matrix_rank,
    row_space,
    unit_columns,
)
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS, DEFAULT_RANK_TOL
from drakegrasp.core.validation import (
    check_flag,
    check_grasp,
    check_rank_tol,
    describe,
    plain_str,
)
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "OBJECTIVE_SCALE",
    "ProgramVariables",
    "add_balance",
    "balance_matrix",
    "balance_rank",
    "balance_rows",
    "build_exact_force_closure_program",
    "build_force_closure_program",
    "build_form_closure_program",
    "build_internal_force_program",
    "lp3_is_conic",
]

OBJECTIVE_SCALE = 1e4
"""The programs minimise ``-OBJECTIVE_SCALE * d`` rather than ``-d``.

Clp's optimality test has an absolute dual tolerance of 1e-7, so with cost
``-d`` it stops as soon as ``d`` cannot grow by more than about 1e-7 and can
report ``d* = 1e-12`` where the true value is 9e-8.  Scaling the objective
moves that error to about 1e-10 without changing the optimum.
"""

_FORMULATIONS = ("facets", "generators")


@checked_call
@dataclass(frozen=True)
class ProgramVariables:
    """Decision variables of a closure program.

    Attributes
    ----------
    d : pydrake.symbolic.Variable
        The margin variable that the program maximises.
    forces : ndarray of Variable or Expression, (m,)
        The contact-force components that are free in the program (for the
        generator formulation, linear expressions of ``weights``).
    columns : (m,) int
        Where each entry of ``forces`` sits in the grasp's stacked force vector
        (columns of :func:`~drakegrasp.grasp_matrix`; for LP1, the contact index).
    weights : ndarray of Variable or None
        The program's own variables when ``forces`` are linear expressions of
        them: generator weights ``λ >= 0`` (generator formulation), or the
        scaled components of a grasp with soft-finger torsion (``m_n / (b ν)``,
        see :class:`~drakegrasp.core.friction_cone.ConeLayout`).
    generators : (m, len(weights)) float or None
        The matrix with ``forces = generators @ weights``: the block-diagonal
        generators ``S``, or ``diag(ConeLayout.scales)``; a
        ``scipy.sparse`` matrix when it has more than 250,000 entries.
    """

    d: object
    forces: np.ndarray
    columns: np.ndarray
    weights: np.ndarray | None = None
    generators: np.ndarray | None = None


def check_program_options(grasp: Grasp, rank_tol: float) -> float:
    """Validate the grasp and ``rank_tol`` of a public program (see validation)."""
    check_grasp(grasp)
    return check_rank_tol(rank_tol)


def check_formulation(formulation: str) -> str:
    """``formulation`` as the plain ``str`` it holds, if it is a known one.

    Callers use what it returns: a ``str`` subclass's own ``==`` may lie.

    Raises
    ------
    InvalidOptionError
        Unless ``formulation`` holds one of ``"facets"``, ``"generators"``.
    """
    formulation = plain_str(formulation)
    if type(formulation) is not str or formulation not in _FORMULATIONS:
        raise InvalidOptionError(
            f"formulation must be one of {_FORMULATIONS}, got {describe(formulation)}"
        )
    return formulation


def _margin_program(num_forces: int) -> tuple[MathematicalProgram, np.ndarray, object]:
    """Program with forces ``f`` (m,), ``d >= 0``, cost ``-OBJECTIVE_SCALE d``."""
    prog = MathematicalProgram()
    f = prog.NewContinuousVariables(num_forces, "f")
    d = prog.NewContinuousVariables(1, "d")[0]
    prog.AddBoundingBoxConstraint(0.0, np.inf, d)
    prog.AddLinearCost(-OBJECTIVE_SCALE * d)
    return prog, f, d


def _add_normal_budget(prog, normal_forces, num_contacts: int) -> None:
    """``Σ f_n <= N`` (the normalisation of LP1–LP3)."""
    add_linear_constraint(
        prog,
        np.ones((1, len(normal_forces))),
        [-np.inf],
        [float(num_contacts)],
        normal_forces,
    )


_DENSE_LIMIT = 250_000
"""Margin matrices with more entries than this are passed to Drake as sparse."""


def _add_margin_rows(prog, A, x, d) -> None:
    """``A x - 1 d >= 0``; ``A`` dense or scipy-sparse (large block diagonals).

    A thousand contacts with 64 generators make a 64,000 x 3,000 facet matrix:
    1.5 GB dense, 1.5 MB of non-zeros.  Dense matrices go through
    :func:`~drakegrasp.closure.constraints.add_linear_constraint`, which keeps
    pydrake from importing scipy.sparse on the first call.
    """
    if hasattr(A, "tocsc"):  # scipy.sparse
        from scipy import sparse

        M = sparse.hstack([A, -np.ones((A.shape[0], 1))], format="csc")
        prog.AddLinearConstraint(
            M, np.zeros(A.shape[0]), np.full(A.shape[0], np.inf), np.append(x, d)
        )
        return
    A = np.atleast_2d(A)
    add_linear_constraint(
        prog,
        np.hstack([A, -np.ones((A.shape[0], 1))]),
        np.zeros(A.shape[0]),
        np.full(A.shape[0], np.inf),
        np.append(x, d),
    )


def _selection(rows: np.ndarray, n: int):
    """Rows ``rows`` of the n x n identity, sparse when large."""
    if len(rows) * n <= _DENSE_LIMIT:
        return np.eye(n)[rows]
    from scipy import sparse

    return sparse.csr_matrix(
        (np.ones(len(rows)), (np.arange(len(rows)), rows)), shape=(len(rows), n)
    )


def _margin_facets(layout: ConeLayout):
    """``F diag(scales)``: dense when small, a sparse block diagonal when large."""
    rows = sum(c.facets.shape[0] for c in layout.cones)
    if rows * len(layout.columns) <= _DENSE_LIMIT:
        return layout.facet_matrix() * layout.scales
    from scipy import sparse

    F = sparse.block_diag([c.facets for c in layout.cones], format="csr")
    return F @ sparse.diags(layout.scales)


def _generators(layout: ConeLayout):
    """``S``: dense when small, a sparse block diagonal when large.

    Dense, a thousand contacts' ``S`` is a 3,000 x 8,000 matrix (190 MB) of
    which 24,000 entries are not zero.
    """
    rows = sum(c.generators.shape[0] for c in layout.cones)
    cols = sum(c.generators.shape[1] for c in layout.cones)
    if rows * cols <= _DENSE_LIMIT:
        return layout.generator_matrix()
    from scipy import sparse

    return sparse.block_diag([c.generators for c in layout.cones], format="csr")


def _diagonal(scales: np.ndarray):
    """``diag(scales)``: dense when small, sparse when large."""
    if scales.size**2 <= _DENSE_LIMIT:
        return np.diag(scales)
    from scipy import sparse

    return sparse.diags(scales, format="csr")


def _block_forces(layout: ConeLayout, weights: np.ndarray) -> np.ndarray:
    """``S @ weights`` for symbolic weights, one contact's block at a time.

    The same expressions as the product with the whole ``S`` (a zero
    coefficient adds no term), in time linear in the number of contacts
    instead of quadratic: 400 contacts took 8.6 s to build.
    """
    out, start = [], 0
    # Object-dtype matmul can re-raise a floating-point flag left set by a
    # previous native solve; symbolic products themselves cannot be invalid.
    with np.errstate(invalid="ignore"):
        for cone in layout.cones:
            k = cone.generators.shape[1]
            out.append(cone.generators @ weights[start : start + k])
            start += k
    return np.concatenate(out)


def _scaled_variables(d, x, layout: ConeLayout) -> ProgramVariables:
    """Variables whose forces are ``scales * x`` (see ``ConeLayout.scales``).

    Without a soft finger's torsion every scale is 1 and ``forces`` are the
    program's variables; otherwise ``forces = diag(scales) @ weights`` (written
    entrywise: the same expressions, without a product quadratic in size).
    """
    if np.all(layout.scales == 1.0):
        return ProgramVariables(d, x, layout.columns)
    with np.errstate(invalid="ignore"):  # see _block_forces
        forces = layout.scales * x
    return ProgramVariables(
        d, forces, layout.columns, weights=x, generators=_diagonal(layout.scales)
    )


PER_GRASP = WeakMemo()
"""What the programs of one (immutable) grasp share: cone layouts, ranks, rows."""


def per_grasp(grasp: Grasp, key: tuple, compute):
    """``compute()``, once per grasp and ``key`` (kept while the grasp lives).

    LP2 and the exact-cone program impose the same ``G f = 0`` rows and read
    the same rank and cone layout; a grasp is immutable, so they are computed
    once.
    """
    return PER_GRASP.value(grasp, key, compute)


def _read_only(*arrays) -> None:
    for a in arrays:
        if isinstance(a, np.ndarray):
            a.flags.writeable = False


def cone_layout(grasp: Grasp, num_generators: int) -> ConeLayout:
    """:meth:`ConeLayout.of`, once per grasp and number of generators.

    Its arrays are made read-only: programs of the same grasp share them (and
    ``ProgramVariables.columns`` is one of them).
    """

    def compute():
        layout = ConeLayout.of(grasp, num_generators)
        _read_only(layout.columns, layout.normal_positions, layout.G, layout.scales)
        return layout

    return per_grasp(grasp, ("layout", num_generators), compute)


def _layout_key(layout: ConeLayout) -> tuple:
    scales = None if layout.scales is None else layout.scales.tobytes()
    return layout.columns.tobytes(), scales


def add_balance(
    prog,
    A: np.ndarray,
    x,
    rank_tol: float,
    *,
    scales: np.ndarray | None = None,
    rows: np.ndarray | None = None,
) -> None:
    """``A x = 0``, imposed on the numerical row space of ``A`` (see below).

    ``A`` is a normalised balance matrix (:func:`balance_matrix`), whose columns
    are first scaled to unit length (``A_s = A D``).  The rows added are an
    orthonormal basis of ``V_rᵀ D⁻¹``, with ``V_r`` the right singular vectors of
    ``A_s`` whose singular values exceed ``rank_tol σ_max``.  They span ``A``'s
    row space when ``A`` has full rank (the same constraint), and otherwise
    leave ``x`` free in exactly the numerical null space that the reported rank
    counts.  Imposing a nearly rank-deficient ``A x = 0`` literally (contacts
    measured to 1e-8 m) made Clp declare an always-feasible LP infeasible.
    ``rows``: those rows, already computed by :func:`balance_rows`.
    """
    if rows is None:
        rows = balance_rows(A, rank_tol, scales)
    if rows.shape[0]:
        add_linear_equality_constraint(prog, rows, np.zeros(rows.shape[0]), x)


def balance_rows(
    A: np.ndarray, rank_tol: float, scales: np.ndarray | None = None
) -> np.ndarray:
    """The orthonormal rows that :func:`add_balance` imposes (see there)."""
    A_s, scale = equilibrated(A)
    # A x = A_s (D⁻¹ x) with D = diag(scale): impose V_rᵀ D⁻¹ x = 0.
    rows = row_space(A_s, rank_tol) / scale
    if scales is not None:  # x holds scaled components: A f = A diag(scales) x
        rows = rows * scales
    if rows.shape[0]:
        rows = np.linalg.qr(rows.T)[0].T
    return rows


def _shared_balance_rows(grasp: Grasp, layout: ConeLayout, rank_tol: float):
    """:func:`balance_rows` of ``G`` on the layout's scaled columns, per grasp."""

    def compute():
        rows = balance_rows(
            balance_matrix(grasp, layout.columns), rank_tol, layout.scales
        )
        _read_only(rows)
        return rows

    return per_grasp(grasp, ("balance rows", rank_tol, *_layout_key(layout)), compute)


@checked_call
def build_form_closure_program(
    grasp: Grasp,
    *,
    rank_tol: float = DEFAULT_RANK_TOL,
) -> tuple[MathematicalProgram, ProgramVariables]:
    """Build LP1, the first-order form-closure program, over normal forces.

    Parameters
    ----------
    grasp : Grasp
        Every contact is treated as frictionless (form closure ignores friction).
    rank_tol : float, optional
        ``G_n f_n = 0`` is imposed on ``G_n``'s numerical row space at this
        relative singular-value threshold (``V_rᵀ f_n = 0``; the same constraint
        when ``G_n`` has full rank).

    Returns
    -------
    prog : MathematicalProgram
        ``max d`` s.t. ``G_n f_n = 0``, ``f_n - 1 d >= 0``, ``d >= 0``,
        ``1ᵀ f_n <= N``.
    variables : ProgramVariables
        ``forces`` are the normal forces ``f_n`` (N,); ``columns`` the contact
        indices.
    """
    rank_tol = check_program_options(grasp, rank_tol)
    N = grasp.num_contacts
    prog, f, d = _margin_program(N)
    add_balance(prog, normal_balance_matrix(grasp), f, rank_tol)
    _add_margin_rows(prog, _selection(np.arange(N), N), f, d)
    _add_normal_budget(prog, f, N)
    return prog, ProgramVariables(d, f, np.arange(N))


@checked_call
def build_force_closure_program(
    grasp: Grasp,
    *,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    formulation: str = "facets",
    rank_tol: float = DEFAULT_RANK_TOL,
) -> tuple[MathematicalProgram, ProgramVariables]:
    """Build LP2, the frictional force-closure program on polyhedral cones.

    Parameters
    ----------
    grasp : Grasp
    num_generators : int, optional
        Generators ``n_g`` of each spatial Coulomb cone (default 8).
    formulation : {"facets", "generators"}, optional
        ``"facets"`` (H-form, default): ``max d`` s.t. ``G f = 0``,
        ``F f - 1 d >= 0``, ``d >= 0``, ``Σ f_n <= N``.  ``"generators"``
        (V-form): ``f = S λ`` and ``max d`` s.t. ``G S λ = 0``, ``λ - 1 d >= 0``,
        ``d >= 0``, ``Σ f_n <= N``; its ``d*`` has another scale, but the
        verdict (``d* > 0`` with full rank) is the same.
    rank_tol : float, optional
        ``G f = 0`` is imposed on ``G``'s numerical row space at this threshold
        (the same constraint when ``G`` has full rank).

    Returns
    -------
    prog : MathematicalProgram
    variables : ProgramVariables
        ``forces`` cover the components the cones allow (see ``columns``).
    """
    rank_tol = check_program_options(grasp, rank_tol)
    formulation = check_formulation(formulation)  # the plain str it holds
    layout = cone_layout(grasp, num_generators)
    N = grasp.num_contacts
    if formulation == "facets":
        prog, f, d = _margin_program(len(layout.columns))
        rows = _shared_balance_rows(grasp, layout, rank_tol)
        add_balance(prog, None, f, rank_tol, rows=rows)
        _add_margin_rows(prog, _margin_facets(layout), f, d)
        _add_normal_budget(prog, f[layout.normal_positions], N)
        return prog, _scaled_variables(d, f, layout)
    S = _generators(layout)
    prog, lam, d = _margin_program(S.shape[1])
    A = balance_matrix(grasp, layout.columns)
    AS = A @ S if isinstance(S, np.ndarray) else (S.T @ A.T).T  # dense either way
    add_balance(prog, AS, lam, rank_tol)
    _add_margin_rows(prog, _selection(np.arange(S.shape[1]), S.shape[1]), lam, d)
    # Every generator has unit normal component, so Σ f_n = Σ λ.
    _add_normal_budget(prog, lam, N)
    forces = _block_forces(layout, lam)
    return prog, ProgramVariables(d, forces, layout.columns, weights=lam, generators=S)


@checked_call
def build_exact_force_closure_program(
    grasp: Grasp,
    *,
    rank_tol: float = DEFAULT_RANK_TOL,
) -> tuple[MathematicalProgram, ProgramVariables]:
    """Build the force-closure program on exact Coulomb cones (an SOCP).

    Parameters
    ----------
    grasp : Grasp
    rank_tol : float, optional
        ``G f = 0`` is imposed on ``G``'s numerical row space at this threshold.

    Returns
    -------
    prog : MathematicalProgram
        ``max d`` s.t. ``G f = 0``, ``d >= 0``, ``Σ f_n <= N`` and, per contact,
        the ball of radius ``d`` around ``f_i`` inside its cone:
        hard finger ``‖f_t‖ <= μ f_n - sqrt(1 + μ²) d``; soft finger, for both
        signs ``σ``, ``‖f_t‖ <= μ f_n - σ μ m_n / (b ν) - sqrt(1 + μ²) d``
        (the hard-finger margin of the normal force left after torsion, so a
        soft finger never scores below a hard one); frictionless
        ``f_n >= d``; planar cones (exact polyhedra) as facets.
    variables : ProgramVariables
    """
    rank_tol = check_program_options(grasp, rank_tol)
    layout = cone_layout(grasp, DEFAULT_NUM_GENERATORS)
    N = grasp.num_contacts
    prog, f, d = _margin_program(len(layout.columns))
    # f holds scaled components (a soft finger's m_n / (b ν)): ConeLayout.scales.
    rows = _shared_balance_rows(grasp, layout, rank_tol)
    add_balance(prog, None, f, rank_tol, rows=rows)
    _add_normal_budget(prog, f[layout.normal_positions], N)
    add_contact_cones(prog, grasp.contacts, layout, f, grasp.characteristic_length, d=d)
    return prog, _scaled_variables(d, f, layout)


def lp3_is_conic(grasp: Grasp) -> bool:
    """Whether LP3 within friction has a Lorentz cone (spatial, with friction)."""
    layout = cone_layout(grasp, DEFAULT_NUM_GENERATORS)
    return any(c.components in EXACT_CONE_COMPONENTS for c in layout.cones)


@checked_call
def build_internal_force_program(
    grasp: Grasp,
    hand_jacobian: np.ndarray,
    *,
    rank_tol: float = DEFAULT_RANK_TOL,
    within_friction: bool = False,
) -> tuple[MathematicalProgram, ProgramVariables]:
    """Build LP3: an internal force with positive normals that the hand cannot feel.

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_v) float
        Hand Jacobian ``J``: rows in the order of the columns of
        :func:`~drakegrasp.grasp_matrix` (contact-frame components), columns the
        hand's generalized velocities.
    rank_tol : float, optional
        Relative singular-value threshold that defines the numerical null space.
    within_friction : bool, optional
        Also keep every contact force in its closed, exact Coulomb cone (a
        second-order cone program when a contact is spatial with friction):
        a squeeze the contacts can carry.  Not LP3 (which bounds the normals
        only, as the conventions fix it) but a fact reported beside it when
        it fails (``passes_within_friction`` of
        :class:`~drakegrasp.InternalForceResult`).

    Returns
    -------
    prog : MathematicalProgram
        ``max d`` s.t. ``G f = 0``, ``Jᵀ f = 0``, ``E f - 1 d >= 0``, ``d >= 0``,
        ``Σ f_n <= N`` (and ``f ∈ FC`` with ``within_friction``).  ``d* = 0``
        passes.
    variables : ProgramVariables

    Notes
    -----
    The two equalities are imposed as ``V_rᵀ f = 0``, with ``V_r`` the right
    singular vectors of ``A = [G; Jᵀ]`` whose singular values exceed
    ``rank_tol σ_max``: ``f`` ranges over the same numerical null space
    ``N(G) ∩ N(Jᵀ)`` whose dimension the result reports.  Imposing ``A f = 0``
    literally would let a singular value of 1e-12 (contacts measured to 1e-7 m)
    exclude an internal force that the rank count says exists.
    """
    rank_tol = check_program_options(grasp, rank_tol)
    J = check_hand_jacobian(grasp, hand_jacobian)
    within_friction = check_flag("within_friction", within_friction)
    layout = cone_layout(grasp, DEFAULT_NUM_GENERATORS)
    N = grasp.num_contacts
    prog, f, d = _margin_program(len(layout.columns))
    A = np.vstack(
        [balance_matrix(grasp, layout.columns), unit_columns(J[layout.columns]).T]
    )
    if not within_friction:
        add_balance(prog, A, f, rank_tol)
        _add_margin_rows(prog, _selection(layout.normal_positions, len(f)), f, d)
        _add_normal_budget(prog, f[layout.normal_positions], N)
        return prog, ProgramVariables(d, f, layout.columns)
    # f holds scaled components (a soft finger's m_n / (b ν)): ConeLayout.scales
    add_balance(prog, A, f, rank_tol, scales=layout.scales)
    _add_margin_rows(prog, _selection(layout.normal_positions, len(f)), f, d)
    _add_normal_budget(prog, f[layout.normal_positions], N)
    add_contact_cones(prog, grasp.contacts, layout, f, grasp.characteristic_length)
    return prog, _scaled_variables(d, f, layout)


def balance_matrix(grasp: Grasp, columns: np.ndarray) -> np.ndarray:
    """Columns ``columns`` of the normalised ``G`` (same null space as ``G``).

    Every rank, row space and null space below is computed on
    :func:`~drakegrasp.core.grasp.invariant_grasp_matrix`, so no verdict depends on
    units, on the reference point or on where the grasp sits in its frame.
    """
    return invariant_grasp_matrix(grasp)[:, columns]


def normal_balance_matrix(grasp: Grasp) -> np.ndarray:
    """The normalised ``G_n``: one column per contact normal."""
    return balance_matrix(grasp, grasp.normal_indices())


def balance_rank(A: np.ndarray, rank_tol: float) -> int:
    """Numerical rank of a balance matrix, on equilibrated columns."""
    return matrix_rank(equilibrated(A)[0], rank_tol=rank_tol)
