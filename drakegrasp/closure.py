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
from pydrake.solvers import (
    ClarabelSolver,
    ClpSolver,
    MathematicalProgram,
    MathematicalProgramResult,
    ScsSolver,
    SolutionResult,
)

from drakegrasp._deferred import WeakMemo, defer, parts, replace, resolve
from drakegrasp._dense_constraints import (
    add_linear_constraint,
    add_linear_equality_constraint,
)
from drakegrasp.errors import InvalidOptionError, SolverError
from drakegrasp.friction_cone import DEFAULT_NUM_GENERATORS, ConeLayout
from drakegrasp.grasp import (
    Grasp,
    check_hand_jacobian,
    normalised_grasp_matrix,
)
from drakegrasp.results import ClosureResult, InternalForceResult, _relative_margin
from drakegrasp.validation import check_grasp, check_rank_tol, check_tol, real_array
from drakegrasp.witness import (
    balance_certificate,
    escape_twist,
    uncontrollable_force,
    unresisted_wrench,
)

__all__ = [
    "DEFAULT_TOL",
    "OBJECTIVE_SCALE",
    "ProgramVariables",
    "build_exact_force_closure_program",
    "build_force_closure_program",
    "build_form_closure_program",
    "build_internal_force_program",
    "force_closure",
    "force_closure_exact",
    "form_closure",
    "internal_forces",
    "matrix_rank",
    "with_internal_forces",
]

DEFAULT_TOL = 1e-6
"""Default threshold on ``d*``: closure needs ``d* > tol`` (LP3 passes at ``<= tol``).

LP1–LP3 normalise the normal forces to ``Σ f_n <= N``, so ``d*`` is of order 0.1
for a good grasp; with :data:`OBJECTIVE_SCALE`, Clp reports ``d*`` to about 1e-10
(checked against closed forms), far below this threshold.
"""

OBJECTIVE_SCALE = 1e4
"""The programs minimise ``-OBJECTIVE_SCALE * d`` rather than ``-d``.

Clp's optimality test has an absolute dual tolerance of 1e-7, so with cost
``-d`` it stops as soon as ``d`` cannot grow by more than about 1e-7 and can
report ``d* = 1e-12`` where the true value is 9e-8.  Scaling the objective
moves that error to about 1e-10 without changing the optimum.
"""

DEFAULT_RANK_TOL = 1e-9
"""Singular values below ``rank_tol * σ_max`` count as zero in rank tests."""

_FORMULATIONS = ("facets", "generators")


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
        see :class:`~drakegrasp.friction_cone.ConeLayout`).
    generators : (m, len(weights)) float or None
        The matrix with ``forces = generators @ weights``: the block-diagonal
        generators ``S``, or ``diag(ConeLayout.scales)``.
    """

    d: object
    forces: np.ndarray
    columns: np.ndarray
    weights: np.ndarray | None = None
    generators: np.ndarray | None = None


def matrix_rank(A: np.ndarray, *, rank_tol: float = DEFAULT_RANK_TOL) -> int:
    """Numerical rank: singular values above ``rank_tol * σ_max``.

    Parameters
    ----------
    A : (m, n) float
    rank_tol : float, optional
        Relative threshold on the singular values.

    Returns
    -------
    int

    Raises
    ------
    InvalidOptionError
        ``A`` not a real finite 2-D array (LAPACK's SVD can loop forever on
        ``inf``/``NaN``), or ``rank_tol`` outside its valid range.
    """
    A = real_array("A", A, error=InvalidOptionError)
    if A.ndim != 2 or not np.all(np.isfinite(A)):
        raise InvalidOptionError(
            f"matrix_rank needs a finite 2-D array, got shape {A.shape}"
            + ("" if A.ndim != 2 else " with non-finite entries")
        )
    rank_tol = check_rank_tol(rank_tol)
    if A.size == 0:
        return 0
    s = np.linalg.svd(A, compute_uv=False)
    if s[0] == 0.0:
        return 0
    return int(np.sum(s > rank_tol * s[0]))


def _check_tol(tol: float) -> float:
    return check_tol(tol)


def _check_options(grasp: Grasp, rank_tol: float) -> float:
    """Validate the grasp and ``rank_tol`` of a public program (see validation)."""
    check_grasp(grasp)
    return check_rank_tol(rank_tol)


def _check_formulation(formulation: str) -> str:
    if not isinstance(formulation, str) or formulation not in _FORMULATIONS:
        raise InvalidOptionError(
            f"formulation must be one of {_FORMULATIONS}, got {formulation!r}"
        )
    return formulation


def _margin_program(
    num_forces: int, num_contacts: int
) -> tuple[MathematicalProgram, np.ndarray, object]:
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
    :func:`~drakegrasp._dense_constraints.add_linear_constraint`, which keeps
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


def _scaled_variables(d, x, layout: ConeLayout) -> ProgramVariables:
    """Variables whose forces are ``scales * x`` (see ``ConeLayout.scales``).

    Without a soft finger's torsion every scale is 1 and ``forces`` are the
    program's variables; otherwise ``forces = diag(scales) @ weights``.
    """
    if np.all(layout.scales == 1.0):
        return ProgramVariables(d, x, layout.columns)
    D = np.diag(layout.scales)
    with np.errstate(invalid="ignore"):  # see build_force_closure_program
        forces = D @ x
    return ProgramVariables(d, forces, layout.columns, weights=x, generators=D)


_PER_GRASP = WeakMemo()
"""What the programs of one (immutable) grasp share: cone layouts, ranks, rows."""


def _per_grasp(grasp: Grasp, key: tuple, compute):
    """``compute()``, once per grasp and ``key`` (kept while the grasp lives).

    LP2 and the exact-cone program impose the same ``G f = 0`` rows and read
    the same rank and cone layout; a grasp is immutable, so they are computed
    once.
    """
    return _PER_GRASP.value(grasp, key, compute)


def _read_only(*arrays) -> None:
    for a in arrays:
        if isinstance(a, np.ndarray):
            a.flags.writeable = False


def _layout(grasp: Grasp, num_generators: int) -> ConeLayout:
    """:meth:`ConeLayout.of`, once per grasp and number of generators.

    Its arrays are made read-only: programs of the same grasp share them (and
    ``ProgramVariables.columns`` is one of them).
    """

    def compute():
        layout = ConeLayout.of(grasp, num_generators)
        _read_only(layout.columns, layout.normal_positions, layout.G, layout.scales)
        return layout

    return _per_grasp(grasp, ("layout", num_generators), compute)


def _layout_key(layout: ConeLayout) -> tuple:
    scales = None if layout.scales is None else layout.scales.tobytes()
    return layout.columns.tobytes(), scales


def _add_balance(
    prog,
    A: np.ndarray,
    x,
    rank_tol: float,
    *,
    scales: np.ndarray | None = None,
    rows: np.ndarray | None = None,
) -> None:
    """``A x = 0``, imposed on the numerical row space of ``A`` (see below).

    ``A`` is a normalised balance matrix (:func:`_balance_matrix`), whose columns
    are first scaled to unit length (``A_s = A D``).  The rows added are an
    orthonormal basis of ``V_rᵀ D⁻¹``, with ``V_r`` the right singular vectors of
    ``A_s`` whose singular values exceed ``rank_tol σ_max``.  They span ``A``'s
    row space when ``A`` has full rank (the same constraint), and otherwise
    leave ``x`` free in exactly the numerical null space that the reported rank
    counts.  Imposing a nearly rank-deficient ``A x = 0`` literally (contacts
    measured to 1e-8 m) made Clp declare an always-feasible LP infeasible.
    ``rows``: those rows, already computed by :func:`_balance_rows`.
    """
    if rows is None:
        rows = _balance_rows(A, rank_tol, scales)
    if rows.shape[0]:
        add_linear_equality_constraint(prog, rows, np.zeros(rows.shape[0]), x)


def _balance_rows(
    A: np.ndarray, rank_tol: float, scales: np.ndarray | None = None
) -> np.ndarray:
    """The orthonormal rows that :func:`_add_balance` imposes (see there)."""
    A_s, scale = _equilibrated(A)
    # A x = A_s (D⁻¹ x) with D = diag(scale): impose V_rᵀ D⁻¹ x = 0.
    rows = _row_space(A_s, rank_tol) / scale
    if scales is not None:  # x holds scaled components: A f = A diag(scales) x
        rows = rows * scales
    if rows.shape[0]:
        rows = np.linalg.qr(rows.T)[0].T
    return rows


def _shared_balance_rows(grasp: Grasp, layout: ConeLayout, rank_tol: float):
    """:func:`_balance_rows` of ``G`` on the layout's scaled columns, per grasp."""

    def compute():
        rows = _balance_rows(
            _balance_matrix(grasp, layout.columns), rank_tol, layout.scales
        )
        _read_only(rows)
        return rows

    return _per_grasp(grasp, ("balance rows", rank_tol, *_layout_key(layout)), compute)


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
    rank_tol = _check_options(grasp, rank_tol)
    N = grasp.num_contacts
    prog, f, d = _margin_program(N, N)
    _add_balance(prog, _normal_balance_matrix(grasp), f, rank_tol)
    _add_margin_rows(prog, _selection(np.arange(N), N), f, d)
    _add_normal_budget(prog, f, N)
    return prog, ProgramVariables(d, f, np.arange(N))


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
    rank_tol = _check_options(grasp, rank_tol)
    _check_formulation(formulation)
    layout = _layout(grasp, num_generators)
    N = grasp.num_contacts
    if formulation == "facets":
        prog, f, d = _margin_program(len(layout.columns), N)
        rows = _shared_balance_rows(grasp, layout, rank_tol)
        _add_balance(prog, None, f, rank_tol, rows=rows)
        _add_margin_rows(prog, _margin_facets(layout), f, d)
        _add_normal_budget(prog, f[layout.normal_positions], N)
        return prog, _scaled_variables(d, f, layout)
    S = layout.generator_matrix()
    prog, lam, d = _margin_program(S.shape[1], N)
    _add_balance(prog, _balance_matrix(grasp, layout.columns) @ S, lam, rank_tol)
    _add_margin_rows(prog, _selection(np.arange(S.shape[1]), S.shape[1]), lam, d)
    # Every generator has unit normal component, so Σ f_n = Σ λ.
    _add_normal_budget(prog, lam, N)
    # Object-dtype matmul can re-raise a floating-point flag left set by a
    # previous native solve; symbolic products themselves cannot be invalid.
    with np.errstate(invalid="ignore"):
        forces = S @ lam
    return prog, ProgramVariables(d, forces, layout.columns, weights=lam, generators=S)


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
    rank_tol = _check_options(grasp, rank_tol)
    layout = _layout(grasp, DEFAULT_NUM_GENERATORS)
    N = grasp.num_contacts
    prog, f, d = _margin_program(len(layout.columns), N)
    # f holds scaled components (a soft finger's m_n / (b ν)): ConeLayout.scales.
    rows = _shared_balance_rows(grasp, layout, rank_tol)
    _add_balance(prog, None, f, rank_tol, rows=rows)
    _add_normal_budget(prog, f[layout.normal_positions], N)
    b = grasp.characteristic_length
    starts = list(layout.normal_positions) + [len(layout.columns)]
    for i, (contact, cone) in enumerate(zip(grasp.contacts, layout.cones, strict=True)):
        fi = f[starts[i] : starts[i + 1]]
        if cone.components not in ((0, 1, 2), (0, 1, 2, 3)):
            scale = layout.scales[starts[i] : starts[i + 1]]
            _add_margin_rows(prog, cone.facets * scale, fi, d)  # exact already
            continue
        mu = contact.mu
        signs = [0.0] if cone.components == (0, 1, 2) else [1.0, -1.0]
        for sign in signs:
            # z = A [fi; d]: z0 = μ f_n - σ μ m_n/(b ν) - sqrt(1+μ²) d,
            # z1:3 = f_t, with m_n = s m̃ (s = ConeLayout.scales): d is the
            # hard-cone margin of (f_n - |m_n| / (b ν), f_t), as the polyhedral
            # soft rows (friction_cone.soft_finger_facets).
            A = np.zeros((3, len(fi) + 1))
            A[0, 0] = mu
            if len(fi) == 4:
                s = layout.scales[starts[i] + 3]
                A[0, 3] = -sign * mu * s / (b * contact.torsional_friction)
            A[0, -1] = -np.sqrt(1.0 + mu * mu)
            A[1, 1] = A[2, 2] = 1.0
            # The same cone divided by sqrt(1 + μ²): coefficients at most 1, so
            # μ = 1e12 no longer makes Clarabel stall or SCS answer inaccurately.
            A /= np.hypot(1.0, mu)
            prog.AddLorentzConeConstraint(A, np.zeros(3), np.append(fi, d))
    return prog, _scaled_variables(d, f, layout)


def build_internal_force_program(
    grasp: Grasp,
    hand_jacobian: np.ndarray,
    *,
    rank_tol: float = DEFAULT_RANK_TOL,
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

    Returns
    -------
    prog : MathematicalProgram
        ``max d`` s.t. ``G f = 0``, ``Jᵀ f = 0``, ``E f - 1 d >= 0``, ``d >= 0``,
        ``Σ f_n <= N``.  ``d* = 0`` passes.
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
    rank_tol = _check_options(grasp, rank_tol)
    J = check_hand_jacobian(grasp, hand_jacobian)
    layout = _layout(grasp, DEFAULT_NUM_GENERATORS)
    N = grasp.num_contacts
    prog, f, d = _margin_program(len(layout.columns), N)
    A = np.vstack(
        [_balance_matrix(grasp, layout.columns), _unit_columns(J[layout.columns]).T]
    )
    _add_balance(prog, A, f, rank_tol)
    _add_margin_rows(prog, _selection(layout.normal_positions, len(f)), f, d)
    _add_normal_budget(prog, f[layout.normal_positions], N)
    return prog, ProgramVariables(d, f, layout.columns)


def _balance_matrix(grasp: Grasp, columns: np.ndarray) -> np.ndarray:
    """Columns ``columns`` of the normalised ``G`` (same null space as ``G``).

    Every rank, row space and null space below is computed on
    :func:`~drakegrasp.grasp.normalised_grasp_matrix`, so no verdict depends on
    units, on the reference point or on where the grasp sits in its frame.
    """
    return normalised_grasp_matrix(grasp)[:, columns]


def _normal_balance_matrix(grasp: Grasp) -> np.ndarray:
    """The normalised ``G_n``: one column per contact normal."""
    return _balance_matrix(grasp, grasp.normal_indices())


def _equilibrated(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``A diag(scale)`` with unit columns, and ``scale`` (zero columns kept).

    Scaling columns changes neither the rank nor, pulled back, the null space,
    but it makes a relative singular-value threshold blind to the units of each
    variable: a soft finger's torsional moment (N·m) beside forces (N), or a
    generator with a large torsion component.
    """
    norms = np.linalg.norm(A, axis=0)
    scale = np.ones_like(norms)
    np.divide(1.0, norms, out=scale, where=norms > 0.0)
    return A * scale, scale


def _balance_rank(A: np.ndarray, rank_tol: float) -> int:
    """Numerical rank of a balance matrix, on equilibrated columns."""
    return matrix_rank(_equilibrated(A)[0], rank_tol=rank_tol)


def _unit_columns(J: np.ndarray) -> np.ndarray:
    """``J`` with its columns scaled to unit length, numerically zero ones dropped.

    ``N(Jᵀ)`` is unchanged (each row of ``Jᵀ`` is only rescaled), but a joint
    measured in other units, or a Jacobian scaled by 1e9, no longer decides which
    singular values of ``[G; Jᵀ]`` count as zero.  A column below
    :data:`_ZERO_COLUMN` times the largest (a joint that moves no contact, up to
    round-off) is dropped rather than blown up to a spurious constraint.
    """
    norms = np.linalg.norm(J, axis=0)
    if norms.size == 0 or not norms.max() > 0.0:
        return J[:, :0]
    keep = norms > _ZERO_COLUMN * norms.max()
    return J[:, keep] / norms[keep]


_ZERO_COLUMN = 1e-12
"""Relative norm below which a column of ``J`` counts as zero in LP3."""


def _row_space(A: np.ndarray, rank_tol: float) -> np.ndarray:
    """Orthonormal basis (rows) of the numerical row space of ``A``."""
    _, s, vt = np.linalg.svd(A)
    if s.size == 0 or s[0] == 0.0:
        return np.zeros((0, A.shape[1]))
    return vt[: int(np.sum(s > rank_tol * s[0]))]


# ---------------------------------------------------------------- solving


def _solve(prog: MathematicalProgram, *, conic: bool) -> MathematicalProgramResult:
    solvers = (ClarabelSolver(), ScsSolver()) if conic else (ClpSolver(),)
    for solver in solvers:
        if solver.available() and solver.enabled():
            return solver.Solve(prog)
    raise SolverError(
        "no solver available for this program: need "
        + ("Clarabel or SCS" if conic else "Clp")
        + " (they ship with Drake's wheel)",
        program=prog,
    )


_VERDICTS = (SolutionResult.kSolutionFound, SolutionResult.kInfeasibleConstraints)


def _solve_margin(prog, variables: ProgramVariables, *, conic: bool):
    """Solve; return (d*, full-vector forces or None, solver, status)."""
    result = _solve(prog, conic=conic)
    status = result.get_solution_result()
    if conic and status not in _VERDICTS and ScsSolver().available():
        # Clarabel can stall on degenerate SOCPs (d* = 0 with no interior, e.g.
        # soft fingers with nu = 1e12); SCS, a first-order method, does not.
        result = ScsSolver().Solve(prog)
        status = result.get_solution_result()
    solver = result.get_solver_id().name()
    if status == SolutionResult.kSolutionFound:
        d_star = float(result.GetSolution(variables.d))
        if variables.weights is None:
            forces = result.GetSolution(variables.forces)
        else:
            forces = variables.generators @ result.GetSolution(variables.weights)
        return d_star, np.asarray(forces, dtype=float), solver, status.name
    if status in (SolutionResult.kInfeasibleConstraints,):
        return float("nan"), None, solver, status.name
    raise SolverError(
        f"{solver} failed with status {status.name} (the program is always "
        "feasible, so this is a numerical failure, not a verdict)",
        program=prog,
        result=result,
    )


def _split_forces(
    grasp: Grasp, columns: np.ndarray, values: np.ndarray | None
) -> tuple[np.ndarray, ...]:
    full = np.zeros(grasp.num_components)
    if values is not None:
        full[columns] = values
    return tuple(full[s].copy() for s in grasp.component_slices())


def form_closure(
    grasp: Grasp,
    *,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
) -> ClosureResult:
    """Decide first-order form closure: ``rank(G_n)`` full and LP1 ``d* > tol``.

    Parameters
    ----------
    grasp : Grasp
        Friction and contact models are ignored: form closure is frictionless.
    tol : float, optional
        Threshold on ``d*`` (dimensionless, see :data:`DEFAULT_TOL`).
    rank_tol : float, optional
        Relative singular-value threshold of the rank test.

    Returns
    -------
    ClosureResult
        ``contact_forces`` holds ``[f_n]`` per contact.

    Examples
    --------
    Four frictionless contacts on a square's sides hold it in the plane:

    >>> import drakegrasp as dg
    >>> result = dg.form_closure(dg.examples.planar_square_four_contacts())
    >>> result.is_closure, result.rank
    (True, 3)
    """
    rank_tol = _check_options(grasp, rank_tol)
    tol = _check_tol(tol)
    required = grasp.wrench_dim
    rank = _balance_rank(_normal_balance_matrix(grasp), rank_tol)
    # A short rank decides "no" alone: LP1 then runs when d* is first read.
    args = (grasp, tol, rank_tol)
    solution = (
        _form_closure_solution(*args)
        if rank == required
        else defer(_form_closure_solution, *args)
    )
    d_star, margin, forces, solver, status = parts(solution, 5)
    ok = rank == required and d_star > tol
    if ok:
        certificate = defer(
            balance_certificate, grasp, forces, cones="normals", rank=rank
        )
    else:
        certificate = defer(escape_twist, grasp, rank)
    return ClosureResult(
        kind="form closure",
        is_closure=bool(ok),
        d_star=d_star,
        rank=rank,
        required_rank=required,
        margin=margin,
        contact_forces=forces,
        solver=solver,
        status=status,
        tol=tol,
        formulation="normals",
        frictional_closure=bool(ok),
        decided_by="d*" if rank == required else "rank",
        certificate=certificate,
    )


def _form_closure_solution(grasp: Grasp, tol: float, rank_tol: float) -> tuple:
    """LP1 solved: ``(d*, margin, forces per contact, solver, status)``."""
    prog, variables = build_form_closure_program(grasp, rank_tol=rank_tol)
    d_star, forces, solver, status = _solve_margin(prog, variables, conic=False)
    if forces is None:
        forces = np.zeros(grasp.num_contacts)
    forces = tuple(np.array([x]) for x in forces)
    return d_star, _relative_margin(d_star, tol), forces, solver, status


def internal_forces(
    grasp: Grasp,
    hand_jacobian: np.ndarray,
    *,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
) -> InternalForceResult:
    """Solve LP3, which asks whether the hand controls every internal force.

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_v) float
        Rows in the order of the columns of ``G``; columns the hand's velocities.
    tol : float, optional
        LP3 passes when ``d* <= tol``.
    rank_tol : float, optional
        Relative singular-value threshold for ``dim(N(G) ∩ N(Jᵀ))``.

    Returns
    -------
    InternalForceResult
    """
    rank_tol = _check_options(grasp, rank_tol)
    tol = _check_tol(tol)
    prog, variables = build_internal_force_program(
        grasp, hand_jacobian, rank_tol=rank_tol
    )
    d_star, forces, solver, status = _solve_margin(prog, variables, conic=False)
    (equalities,) = prog.linear_equality_constraints() or (None,)
    rank = 0 if equalities is None else equalities.evaluator().num_constraints()
    null_dim = len(variables.columns) - rank
    passes = not (d_star > tol)  # NaN (infeasible) passes: no such force exists
    contact_forces = _split_forces(grasp, variables.columns, forces)
    return InternalForceResult(
        passes=bool(passes),
        d_star=d_star,
        margin=-_relative_margin(d_star, tol) if np.isfinite(d_star) else np.inf,
        null_space_dim=int(null_dim),
        contact_forces=contact_forces,
        solver=solver,
        status=status,
        tol=tol,
        certificate=None if passes else uncontrollable_force(grasp, contact_forces),
    )


def _margin_solution(grasp: Grasp, build, tol: float) -> tuple:
    """``build()``'s program solved: ``(d*, margin, forces, solver, status)``.

    ``build`` returns ``(prog, variables, conic)``.
    """
    prog, variables, conic = build()
    d_star, forces, solver, status = _solve_margin(prog, variables, conic=conic)
    contact_forces = _split_forces(grasp, variables.columns, forces)
    return d_star, _relative_margin(d_star, tol), contact_forces, solver, status


def _force_closure_result(
    grasp: Grasp,
    build,
    columns: np.ndarray,
    *,
    kind: str,
    formulation: str,
    hand_jacobian: np.ndarray | None,
    tol: float,
    rank_tol: float,
    num_generators: int = DEFAULT_NUM_GENERATORS,
) -> ClosureResult:
    """The verdict of the program ``build()`` makes over ``columns`` of ``G``.

    A short rank decides "no" alone, so the program is then built and solved
    only when its ``d*`` (or forces, solver, status) is first read; the
    certificate is computed when first read in every case.
    """
    required = grasp.wrench_dim
    rank = _per_grasp(
        grasp,
        ("rank", rank_tol, columns.tobytes()),
        lambda: _balance_rank(_balance_matrix(grasp, columns), rank_tol),
    )
    args = (grasp, build, tol)
    solution = (
        _margin_solution(*args) if rank == required else defer(_margin_solution, *args)
    )
    d_star, margin, contact_forces, solver, status = parts(solution, 5)
    frictional = bool(rank == required and d_star > tol)
    decided_by = "d*" if rank == required else "rank"
    if rank == required and not frictional:
        # d is a distance to the cone boundaries, so it vanishes with μ.  Normal
        # forces alone (f_t = 0) lie inside every cone with μ > 0: if they
        # balance with f_n > tol, the grasp is in force closure for any μ.
        normal = _normal_force_certificate(grasp, columns, tol=tol, rank_tol=rank_tol)
        if normal is not None:
            frictional, decided_by = True, "normal forces"
            margin, contact_forces = normal
    cones = "exact" if formulation == "exact" else "polyhedral"
    if frictional:
        # LP1's forces (f_t = 0) on the normal-force route: inside every cone
        # with μ > 0, and G (not G_n) is the matrix of full rank.
        certificate = defer(
            balance_certificate,
            grasp,
            contact_forces,
            cones=cones,
            rank=rank,
            num_generators=num_generators,
        )
    else:
        certificate = defer(
            unresisted_wrench, grasp, rank, cones=cones, num_generators=num_generators
        )
    result = ClosureResult(
        kind=kind,
        is_closure=frictional,
        d_star=d_star,
        rank=rank,
        required_rank=required,
        margin=margin,
        contact_forces=contact_forces,
        solver=solver,
        status=status,
        tol=tol,
        formulation=formulation,
        frictional_closure=frictional,
        decided_by=decided_by,
        certificate=certificate,
    )
    if hand_jacobian is None:
        return result
    if frictional:
        lp3 = internal_forces(grasp, hand_jacobian, tol=tol, rank_tol=rank_tol)
    else:  # the verdict is "no" whatever LP3 says: solve it when first read
        check_hand_jacobian(grasp, hand_jacobian)
        lp3 = defer(internal_forces, grasp, hand_jacobian, tol=tol, rank_tol=rank_tol)
    return with_internal_forces(result, lp3)


def with_internal_forces(
    result: ClosureResult, lp3: InternalForceResult
) -> ClosureResult:
    """The verdict with a hand: frictional closure and LP3 passing.

    Parameters
    ----------
    result : ClosureResult
        A force-closure result computed without the hand Jacobian.
    lp3 : InternalForceResult
        :func:`internal_forces` of the same grasp and hand Jacobian; one LP3
        can serve the polyhedral and the exact-cone verdicts alike.  It may be
        deferred (``drakegrasp._deferred.defer``); it is then computed
        here only when ``result`` holds frictional closure.

    Returns
    -------
    ClosureResult
        ``result`` with ``internal_forces = lp3`` and
        ``is_closure = frictional_closure and lp3.passes``.
    """
    changes = {}
    if result.frictional_closure:
        lp3 = resolve(lp3)  # the verdict needs it
    if result.frictional_closure and not lp3.passes:
        changes = {"decided_by": "LP3", "certificate": lp3.certificate}
    elif result.decided_by == "LP3":  # re-attaching: undo a previous LP3 verdict
        raise InvalidOptionError(
            "with_internal_forces needs a result computed without the hand "
            "Jacobian; this one was already decided by LP3"
        )
    return replace(
        result,
        internal_forces=lp3,
        is_closure=result.frictional_closure and lp3.passes,
        **changes,
    )


def _normal_force_certificate(
    grasp: Grasp, columns: np.ndarray, *, tol: float, rank_tol: float
) -> tuple[float, tuple[np.ndarray, ...]] | None:
    """LP1 on the contacts' normals, when some contact has friction.

    Returns the margin of LP1's ``d*`` and its forces (tangential parts zero) when
    ``d* > tol``, else None.
    """
    normals = grasp.normal_indices()
    if len(columns) == len(normals):  # every contact is frictionless already
        return None
    if _balance_rank(_normal_balance_matrix(grasp), rank_tol) == len(normals):
        return None  # N(G_n) = {0}: no non-zero normal forces balance
    prog, variables = build_form_closure_program(grasp, rank_tol=rank_tol)
    d_star, f_n, _, _ = _solve_margin(prog, variables, conic=False)
    if not d_star > tol:
        return None
    return _relative_margin(d_star, tol), _split_forces(grasp, normals, f_n)


def force_closure(
    grasp: Grasp,
    *,
    hand_jacobian: np.ndarray | None = None,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
    formulation: str = "facets",
) -> ClosureResult:
    """Decide force closure on polyhedral friction cones (LP2, and LP3 with a hand).

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_v) float, optional
        Hand Jacobian ``J`` (rows in ``G``'s column order).  When given, the
        verdict also needs LP3 to pass.
    num_generators : int, optional
        Generators of each spatial Coulomb cone (default 8; the cone is
        inscribed, so a polyhedral closure implies an exact one).
    tol : float, optional
        Closure needs ``d* > tol``.
    rank_tol : float, optional
        Relative singular-value threshold of the rank test.
    formulation : {"facets", "generators"}, optional
        H-form (default, ``d*`` as in the conventions) or V-form.

    Returns
    -------
    ClosureResult

    Examples
    --------
    The equator grasp of three hard fingers is in force closure:

    >>> import drakegrasp as dg
    >>> result = dg.force_closure(dg.examples.equator_fingers(0.5, num_fingers=3))
    >>> result.is_closure, result.rank, round(result.d_star, 4)
    (True, 6, 0.4194)
    """
    rank_tol = _check_options(grasp, rank_tol)
    tol = _check_tol(tol)
    _check_formulation(formulation)

    def build():
        prog, variables = build_force_closure_program(
            grasp,
            num_generators=num_generators,
            formulation=formulation,
            rank_tol=rank_tol,
        )
        return prog, variables, False

    return _force_closure_result(
        grasp,
        build,
        _layout(grasp, num_generators).columns,
        kind="force closure",
        formulation=formulation,
        hand_jacobian=hand_jacobian,
        tol=tol,
        rank_tol=rank_tol,
        num_generators=num_generators,
    )


def force_closure_exact(
    grasp: Grasp,
    *,
    hand_jacobian: np.ndarray | None = None,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
) -> ClosureResult:
    """Decide force closure with exact Coulomb cones (an SOCP, Clarabel or SCS).

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_v) float, optional
        When given, the verdict also needs LP3 to pass.
    tol : float, optional
        Closure needs ``d* > tol``; ``d*`` is each contact force's distance to
        its exact cone's boundary.
    rank_tol : float, optional
        Relative singular-value threshold of the rank test.

    Returns
    -------
    ClosureResult
    """
    rank_tol = _check_options(grasp, rank_tol)
    tol = _check_tol(tol)

    def build():
        prog, variables = build_exact_force_closure_program(grasp, rank_tol=rank_tol)
        return prog, variables, bool(prog.lorentz_cone_constraints())

    return _force_closure_result(
        grasp,
        build,
        _layout(grasp, DEFAULT_NUM_GENERATORS).columns,
        kind="force closure (exact cones)",
        formulation="exact",
        hand_jacobian=hand_jacobian,
        tol=tol,
        rank_tol=rank_tol,
    )
