"""Grasp forces for many grasps: the single-grasp program, once per grasp.

:func:`batch_grasp_forces` runs :func:`~drakegrasp.grasp_forces` on each grasp
and gathers the answers in arrays.  It is a loop over the same validated
program, so its answers are those of the single path by construction (the
tests check it); it is not vectorised like the closure engine — about 3.5 ms
per grasp with four contacts (one SOCP, or an LP with
``cones="polyhedral"``, measured on 200 grasps, about 40 % of them refuted),
including a second program per infeasible grasp for its certificate.
Grasps may differ in their number of contacts.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from drakegrasp.closure.load_forces import GraspForceResult, grasp_forces
from drakegrasp.core.calls import checked_call
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import check_grasp, items_of, real_array
from drakegrasp.errors import InvalidOptionError

__all__ = ["BatchGraspForceResult", "batch_grasp_forces"]


@dataclass(frozen=True, eq=False)
class BatchGraspForceResult:
    """Grasp forces of ``K`` grasps.

    Attributes
    ----------
    feasible : (K,) bool
        Whether each grasp holds its load.
    squeeze : (K,) float
        Least (or chosen) total normal force, N; NaN where infeasible.
    torque_usage : (K,) float
        ``max_j |τ_j| / τ_max,j``; NaN without limits or where infeasible.
    results : tuple of GraspForceResult
        The full result of each grasp (forces, torques, certificates).
    """

    feasible: np.ndarray
    squeeze: np.ndarray
    torque_usage: np.ndarray
    results: tuple[GraspForceResult, ...]

    def __len__(self) -> int:
        return len(self.results)

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}

    def __str__(self) -> str:
        held = int(self.feasible.sum())
        return f"batch grasp forces: {held} of {len(self)} grasps hold their load"


def _per_grasp(name: str, value, K: int) -> list:
    if value is None:
        return [None] * K
    if isinstance(value, np.ndarray) and value.ndim >= 1 and value.dtype != object:
        return [value] * K  # one array for every grasp
    try:
        iter(value)
    except TypeError:
        return [value] * K  # a scalar: every grasp's (grasp_forces checks it)
    except Exception:  # noqa: BLE001, S110 - a hostile __iter__: items_of names it
        pass
    must = f"one value for all grasps or a sequence of {K} (one per grasp)"
    items = items_of(name, value, must, error=InvalidOptionError)
    if len(items) != K:
        raise InvalidOptionError(
            f"{name} must be one value for all grasps or a sequence of {K} (one "
            f"per grasp), got {len(items)}"
        )
    return items


@checked_call
def batch_grasp_forces(
    grasps: Sequence[Grasp],
    wrenches: np.ndarray,
    *,
    hand_jacobians: Sequence[np.ndarray] | None = None,
    torque_limits: Sequence | np.ndarray | float | None = None,
    objective: str = "min_squeeze",
    cones: str = "exact",
    num_generators: int = DEFAULT_NUM_GENERATORS,
    max_normal_force: Sequence | float | None = None,
    max_squeeze: Sequence | float | None = None,
) -> BatchGraspForceResult:
    """:func:`~drakegrasp.grasp_forces` for each of ``K`` grasps.

    Parameters
    ----------
    grasps : sequence of Grasp
        ``K`` grasps (their contact counts may differ).
    wrenches : (D,) or (K, D) float
        One load for every grasp or one per grasp (grasp frames).
    hand_jacobians : sequence of (M_k, n_v) float, optional
        One per grasp.
    torque_limits : float, (n_v,) float, or a sequence of K of them, optional
        One array for every grasp (a numpy array) or one per grasp (a list).
    objective, cones, num_generators
        As in :func:`~drakegrasp.grasp_forces`.
    max_normal_force, max_squeeze : optional
        One value for every grasp or a list of ``K``.

    Returns
    -------
    BatchGraspForceResult
    """
    if isinstance(grasps, (str, bytes)) or not hasattr(grasps, "__iter__"):
        raise InvalidOptionError(
            f"grasps must be a sequence of drakegrasp.Grasp, got "
            f"{type(grasps).__name__}"
        )
    grasps = items_of("grasps", grasps, "a sequence of drakegrasp.Grasp")
    grasps = [check_grasp(g, f"grasps[{k}]") for k, g in enumerate(grasps)]
    K = len(grasps)
    W = real_array("wrenches", wrenches, error=InvalidOptionError)
    if W.ndim == 1:
        W = np.broadcast_to(W, (K, W.size))
    if W.ndim != 2 or W.shape[0] != K:
        raise InvalidOptionError(
            f"wrenches must have shape (D,) or ({K}, D), got {np.shape(wrenches)}"
        )
    if hand_jacobians is not None and (
        isinstance(hand_jacobians, (str, bytes))
        or not hasattr(hand_jacobians, "__iter__")
    ):
        raise InvalidOptionError(
            "hand_jacobians must be a sequence of one (M_k, n_v) Jacobian per "
            f"grasp, got {type(hand_jacobians).__name__}"
        )
    if (
        isinstance(hand_jacobians, np.ndarray)
        and hand_jacobians.ndim
        and len(hand_jacobians) != K
    ):
        Js = hand_jacobians  # refused by its length, before a view per row
    elif hand_jacobians is None:
        Js = [None] * K
    else:
        Js = items_of(
            "hand_jacobians",
            hand_jacobians,
            "a sequence of one (M_k, n_v) Jacobian per grasp",
        )
    if len(Js) != K:
        raise InvalidOptionError(
            f"hand_jacobians must hold {K} Jacobians (one per grasp), got {len(Js)}"
        )
    limits = _per_grasp("torque_limits", torque_limits, K)
    fmax = _per_grasp("max_normal_force", max_normal_force, K)
    smax = _per_grasp("max_squeeze", max_squeeze, K)
    results = tuple(
        grasp_forces(
            g,
            W[k],
            hand_jacobian=Js[k],
            torque_limits=limits[k],
            objective=objective,
            cones=cones,
            num_generators=num_generators,
            max_normal_force=fmax[k],
            max_squeeze=smax[k],
        )
        for k, g in enumerate(grasps)
    )
    return BatchGraspForceResult(
        feasible=np.array([r.feasible for r in results], dtype=bool),
        squeeze=np.array([r.squeeze for r in results], dtype=float),
        torque_usage=np.array([r.torque_usage for r in results], dtype=float),
        results=results,
    )
