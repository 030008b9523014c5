r"""The largest external wrench a grasp resists with bounded contact forces (LP)."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from pydrake.solvers import MathematicalProgram

from drakegrasp._solvers import require_solution, solve
from drakegrasp.closure.load_problem import check_direction
from drakegrasp.core.calls import checked_call
from drakegrasp.core.friction_cone import ConeLayout
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import real_array, safe_norm
from drakegrasp.errors import InvalidOptionError
from drakegrasp.quality._common import _check_grasp

__all__ = [
    "MaxWrenchResult",
    "MaxWrenchVariables",
    "build_max_resistible_wrench_program",
    "max_resistible_wrench",
]


@checked_call
@dataclass(frozen=True)
class MaxWrenchVariables:
    """Decision variables of :func:`build_max_resistible_wrench_program`.

    Attributes
    ----------
    alpha : pydrake.symbolic.Variable
        The multiple ``α >= 0`` of the external wrench; the program maximises it.
    forces : (m,) ndarray of Variable
        The contact-force components the cones allow (contact frames).
    columns : (m,) int
        Where each entry of ``forces`` sits in the grasp's stacked force vector
        (columns of :func:`~drakegrasp.grasp_matrix`).
    normal_positions : (N,) int
        Index in ``forces`` of each contact's ``f_n``.
    """

    alpha: object
    forces: np.ndarray
    columns: np.ndarray
    normal_positions: np.ndarray


@checked_call
@dataclass(frozen=True)
class MaxWrenchResult:
    """Largest multiple of an external wrench that a grasp resists.

    Attributes
    ----------
    alpha : float
        The largest ``α >= 0`` such that contact forces in the polyhedral cones,
        each ``f_{n,i} <= max_normal_force_i``, balance the external wrench
        ``α · direction``.  Units: those making ``α · direction`` a wrench
        (``α`` in kg when ``direction`` is the gravity wrench of 1 kg).
    direction : (6,) or (3,) float
        The external wrench direction, ``[f; m]`` about ``p`` in the grasp frame.
    wrench : (6,) or (3,) float
        ``α · direction`` (N, N·m).
    contact_forces : tuple of ndarray
        Optimal force of each contact in its contact frame (normal first, the
        components of its model), N; they satisfy ``G f = -α · direction``.
    max_normal_force : (N,) float
        The per-contact bounds on ``f_n`` used, N.
    num_generators : int
        Generators of each spatial Coulomb cone.
    solver, status : str
        Solver name and its solution status.
    """

    alpha: float
    direction: np.ndarray
    wrench: np.ndarray
    contact_forces: tuple[np.ndarray, ...]
    max_normal_force: np.ndarray
    num_generators: int
    solver: str
    status: str

    def to_dict(self) -> dict:
        """JSON-ready dictionary (non-finite numbers become ``None``)."""
        return {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}

    def __str__(self) -> str:
        fn = ", ".join(f"{f[0]:.4g}" for f in self.contact_forces)
        return (
            f"max resistible wrench: alpha = {self.alpha:.6g} along "
            f"{np.round(self.direction, 6).tolist()}\n"
            f"  normal forces [{fn}] N (limits "
            f"{np.round(self.max_normal_force, 6).tolist()} N)\n"
            f"  solver {self.solver} ({self.status}), {self.num_generators} "
            "generators"
        )


def _check_max_normal_force(grasp: Grasp, max_normal_force) -> np.ndarray:
    N = grasp.num_contacts
    f = real_array("max_normal_force", max_normal_force, error=InvalidOptionError)
    if f.ndim == 0:
        f = np.full(N, float(f))
    if f.shape != (N,) or not np.all(np.isfinite(f)) or np.any(f < 0):
        raise InvalidOptionError(
            f"max_normal_force must be a finite number >= 0 or {N} of them (one per "
            f"contact), got {np.asarray(max_normal_force).tolist()}"
        )
    return f


_PLAIN_NORM = (1e-150, 1e150)
"""Largest entries of a direction whose squares neither overflow nor lose bits."""


def _norm(d: np.ndarray) -> float:
    """``‖d‖``: numpy's where its squares are plain floats, else scaled.

    In that range ``np.linalg.norm`` is exact to its last bit as before, so a
    direction of norm 1 gives ``d / 1.0``, the caller's LP; beyond it
    :func:`~drakegrasp.core.validation.safe_norm` neither overflows
    (``1e200``) nor underflows.
    """
    top = float(np.max(np.abs(d)))
    if _PLAIN_NORM[0] <= top <= _PLAIN_NORM[1]:
        return float(np.linalg.norm(d))
    return float(safe_norm(d))


@checked_call
def build_max_resistible_wrench_program(
    grasp: Grasp,
    direction: np.ndarray,
    *,
    max_normal_force: float | np.ndarray,
    num_generators: int = DEFAULT_NUM_GENERATORS,
) -> tuple[MathematicalProgram, MaxWrenchVariables]:
    r"""Build the LP for the largest resistible multiple of an external wrench.

    Parameters
    ----------
    grasp : Grasp
    direction : (6,) or (3,) float
        External wrench direction ``w_e = [f; m]`` about ``p``, grasp frame
        (e.g. the gravity wrench of 1 kg: ``[m g; (c_m - p) × m g]``).
    max_normal_force : float or (N,) float
        Bound ``f_max >= 0`` on each contact's normal force, N (one for all
        contacts or one per contact).
    num_generators : int, optional
        Generators ``n_g`` of each spatial Coulomb cone (default 8).

    Returns
    -------
    prog : MathematicalProgram
        .. math:: \max_{\alpha, f} \alpha \;\text{s.t.}\;
                  G f + \alpha\, w_e = 0,\; F_i f_i \ge 0,\;
                  0 \le f_{n,i} \le f_{\max,i},\; \alpha \ge 0

        over the force components each cone allows (``F_i`` the unit facet rows
        of the inscribed polyhedral cone; a hard finger with ``mu = 0`` has only
        ``f_n``).  Always feasible (``α = 0``, ``f = 0``) and bounded (the cones
        are pointed and ``f_n`` is bounded).  In the caller's units: the LP is
        homogeneous, and :func:`max_resistible_wrench` solves it at unit scale
        (``w_e / ‖w_e‖``, ``f_max / max_i f_max,i``).
    variables : MaxWrenchVariables
    """
    _check_grasp(grasp)
    d = check_direction(grasp, direction)
    fmax = _check_max_normal_force(grasp, max_normal_force)
    layout = ConeLayout.of(grasp, num_generators)
    columns, normals, G = layout.columns, layout.normal_positions, layout.G
    cones = layout.cones

    prog = MathematicalProgram()
    f = prog.NewContinuousVariables(len(columns), "f")
    alpha = prog.NewContinuousVariables(1, "alpha")[0]
    prog.AddLinearCost(-1.0 * alpha)
    prog.AddBoundingBoxConstraint(0.0, np.inf, alpha)
    prog.AddLinearEqualityConstraint(
        np.hstack([G, d[:, None]]), np.zeros(G.shape[0]), np.append(f, alpha)
    )
    start = 0
    for cone in cones:
        k = len(cone.components)
        # Unit rows: the same cone, better scaled (soft-finger margin rows are
        # not unit length, see friction_cone.soft_finger_facets).
        F = cone.facets / np.linalg.norm(cone.facets, axis=1, keepdims=True)
        prog.AddLinearConstraint(
            F, np.zeros(F.shape[0]), np.full(F.shape[0], np.inf), f[start : start + k]
        )
        start += k
    prog.AddBoundingBoxConstraint(np.zeros(len(normals)), fmax, f[normals])
    return prog, MaxWrenchVariables(alpha, f, columns, normals)


@checked_call
def max_resistible_wrench(
    grasp: Grasp,
    direction: np.ndarray,
    *,
    max_normal_force: float | np.ndarray,
    num_generators: int = DEFAULT_NUM_GENERATORS,
) -> MaxWrenchResult:
    """Largest ``α`` such that the grasp resists the external wrench ``α · direction``.

    The LP of :func:`build_max_resistible_wrench_program` is homogeneous: ``α``
    scales as ``max_normal_force / ‖direction‖`` and the forces as
    ``max_normal_force``.  It is solved with Clp at unit scale (the direction
    over its norm, the bounds over the largest of them: one LP, whatever the
    units), and ``α`` and the forces are scaled back, so every scale of the
    same problem gives the same ``α`` per unit (an unnormalised LP gave
    ``α / f_max = 1.81`` for 1.5 at ``f_max = 1e-7`` with forces that did not
    balance, 0 at ``‖direction‖ = 1e7`` and a solver failure at
    ``f_max = 1e30``).  At ``‖direction‖ = 1`` and ``max f_max = 1`` the LP
    is the one built in the caller's units.

    Parameters
    ----------
    grasp : Grasp
    direction : (6,) or (3,) float
        External wrench direction ``[f; m]`` about ``p``, in the grasp frame:
        finite, not all zeros.
    max_normal_force : float or (N,) float
        Bound on each contact's normal force, N: finite, ``>= 0``.  All zero:
        ``α = 0``.
    num_generators : int, optional
        Generators of each spatial Coulomb cone (default 8).

    Returns
    -------
    MaxWrenchResult
        The forces satisfy ``G f = -α · direction`` up to the solver's
        tolerance, relative to the largest ``max_normal_force``.

    Raises
    ------
    InvalidOptionError
        A bad ``direction`` or ``max_normal_force``, or one whose answer is
        past the float range: ``max(max_normal_force) / ‖direction‖`` outside
        ``[2.2e-308, 1.8e308]``, or ``α``, ``α · direction`` or a force that
        overflows (e.g. ``max_normal_force = 1e300`` with ``‖direction‖ =
        1e-300``).
    SolverError
        If Clp is unavailable or fails (the LP is always feasible and bounded).
    """
    d = check_direction(grasp, direction)
    fmax = _check_max_normal_force(grasp, max_normal_force)
    # Units: the direction's norm and the largest bound (1 when all are 0:
    # the LP is then α = 0 whatever its units).  Exactly 1 at unit scale.
    size = _norm(d)
    force = float(np.max(fmax))
    unit = force if force > 0.0 else 1.0
    prog, v = build_max_resistible_wrench_program(
        grasp,
        d / size,
        max_normal_force=fmax / unit,
        num_generators=num_generators,
    )
    result = require_solution(prog, solve(prog, "lp"), "the max-resistible-wrench LP")
    status = result.get_solution_result()
    name = result.get_solver_id().name()
    full = np.zeros(grasp.num_components)
    alpha = 0.0
    if force > 0.0:  # else f = 0 and α = 0 (the solver's 4e-12 is noise)
        alpha = max(float(result.GetSolution(v.alpha)), 0.0)
        full[v.columns] = result.GetSolution(v.forces)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        # Checked below: an overflow (inf, or inf times 0) is refused.
        ratio = np.float64(unit) / np.float64(size)
        alpha = float(alpha * ratio)
        full = unit * full
        wrench = alpha * d
    if not (
        np.finfo(float).tiny <= ratio <= np.finfo(float).max
        and math.isfinite(alpha)
        and np.all(np.isfinite(full))
        and np.all(np.isfinite(wrench))
    ):
        raise InvalidOptionError(
            f"max(max_normal_force) / ‖direction‖ = {force:g} / {size:g} = "
            f"{float(ratio):g} puts the answer past the float range (α = "
            f"{alpha:g}; α scales with that ratio, the forces with "
            "max_normal_force): the ratio must be within "
            f"[{np.finfo(float).tiny:g}, {np.finfo(float).max:g}] and α, "
            "α · direction and the forces finite; give both in units nearer "
            "each other"
        )
    forces = tuple(full[sl].copy() for sl in grasp.component_slices())
    return MaxWrenchResult(
        alpha=alpha,
        direction=d,
        wrench=wrench,
        contact_forces=forces,
        max_normal_force=fmax,
        num_generators=int(num_generators),
        solver=name,
        status=status.name,
    )
