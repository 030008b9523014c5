r"""The largest external wrench a grasp resists with bounded contact forces (LP)."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
from pydrake.solvers import MathematicalProgram

from drakegrasp._solvers import require_solution, solve
from drakegrasp.closure.load_problem import check_direction
from drakegrasp.core.friction_cone import ConeLayout
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import real_array
from drakegrasp.errors import InvalidOptionError
from drakegrasp.quality._common import _check_grasp

__all__ = [
    "MaxWrenchResult",
    "MaxWrenchVariables",
    "build_max_resistible_wrench_program",
    "max_resistible_wrench",
]


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
        are pointed and ``f_n`` is bounded).
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


def max_resistible_wrench(
    grasp: Grasp,
    direction: np.ndarray,
    *,
    max_normal_force: float | np.ndarray,
    num_generators: int = DEFAULT_NUM_GENERATORS,
) -> MaxWrenchResult:
    """Largest ``α`` such that the grasp resists the external wrench ``α · direction``.

    Builds the LP of :func:`build_max_resistible_wrench_program` and solves it
    with Clp.

    Parameters
    ----------
    grasp : Grasp
    direction : (6,) or (3,) float
        External wrench direction ``[f; m]`` about ``p``, in the grasp frame.
    max_normal_force : float or (N,) float
        Bound on each contact's normal force, N.
    num_generators : int, optional
        Generators of each spatial Coulomb cone (default 8).

    Returns
    -------
    MaxWrenchResult

    Raises
    ------
    SolverError
        If Clp is unavailable or fails (the LP is always feasible and bounded).
    """
    prog, v = build_max_resistible_wrench_program(
        grasp,
        direction,
        max_normal_force=max_normal_force,
        num_generators=num_generators,
    )
    result = require_solution(prog, solve(prog, "lp"), "the max-resistible-wrench LP")
    status = result.get_solution_result()
    name = result.get_solver_id().name()
    d = check_direction(grasp, direction)
    alpha = max(float(result.GetSolution(v.alpha)), 0.0)
    full = np.zeros(grasp.num_components)
    full[v.columns] = result.GetSolution(v.forces)
    forces = tuple(full[sl].copy() for sl in grasp.component_slices())
    return MaxWrenchResult(
        alpha=alpha,
        direction=d,
        wrench=alpha * d,
        contact_forces=forces,
        max_normal_force=_check_max_normal_force(grasp, max_normal_force),
        num_generators=int(num_generators),
        solver=name,
        status=status.name,
    )
