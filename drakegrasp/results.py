"""Frozen result types of the closure programs."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

__all__ = ["AntipodalResult", "ClosureResult", "InternalForceResult"]


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return [_jsonable(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (np.floating, float)):
        x = float(value)
        return x if math.isfinite(x) else None
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    if hasattr(value, "to_dict"):
        return value.to_dict()
    return value


ZERO_FRACTION = 1e-3
"""``d*`` below ``ZERO_FRACTION * tol`` is the solver's zero, not a near miss."""


def _relative_margin(value: float, tol: float) -> float:
    """(value - tol) / tol: positive above the threshold, |m| < 1 within tol."""
    if not math.isfinite(value):
        return -math.inf
    return (value - tol) / tol


def _near(margin: float) -> bool:
    """True when ``d*`` lies in ``(ZERO_FRACTION tol, 2 tol)``: not certain."""
    return ZERO_FRACTION - 1.0 < margin < 1.0


@dataclass(frozen=True)
class InternalForceResult:
    """LP3: an internal force with positive normals in ``N(G) ∩ N(Jᵀ)``, if any.

    Attributes
    ----------
    passes : bool
        True when ``d* <= tol``: the hand can control every internal force, so
        the check of ``N(G) ∩ N(Jᵀ) = {0}`` (as LP3 poses it) passes.
    d_star : float
        Optimal ``d`` of LP3 (dimensionless; the normal forces are normalised by
        ``Σ f_n <= N``).
    margin : float
        ``(tol - d*) / tol``: positive when passing; uncertain when
        ``tol/1000 < d* < 2 tol``.
    null_space_dim : int
        ``dim(N(G) ∩ N(Jᵀ))`` from the rank of ``[G; Jᵀ]`` (over the force
        components the cones allow).
    contact_forces : tuple of ndarray
        Optimal forces per contact, in contact frames (an uncontrollable internal
        force when ``passes`` is False).
    solver, status : str
        Solver name and its solution status.
    tol : float
        Threshold on ``d*``.
    """

    passes: bool
    d_star: float
    margin: float
    null_space_dim: int
    contact_forces: tuple[np.ndarray, ...]
    solver: str
    status: str
    tol: float

    @property
    def near_boundary(self) -> bool:
        """True when ``tol/1000 < d* < 2 tol``: the verdict is not certain."""
        return _near(-self.margin)

    @property
    def null_space_trivial(self) -> bool:
        """True when ``N(G) ∩ N(Jᵀ) = {0}`` by rank."""
        return self.null_space_dim == 0

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        d = {f.name: _jsonable(getattr(self, f.name)) for f in fields(self)}
        d["null_space_trivial"] = self.null_space_trivial
        d["near_boundary"] = self.near_boundary
        return d

    def __str__(self) -> str:
        verdict = "passes" if self.passes else "FAILS"
        near = "  (within tol of the boundary)" if self.near_boundary else ""
        return (
            f"LP3 (internal forces the hand cannot control): {verdict}, "
            f"d* = {self.d_star:.6g}, dim N(G)∩N(Jᵀ) = {self.null_space_dim}, "
            f"solver {self.solver} ({self.status}){near}"
        )


@dataclass(frozen=True)
class ClosureResult:
    """Verdict of a form- or force-closure program.

    Attributes
    ----------
    kind : str
        ``"form closure"``, ``"force closure"`` or ``"force closure (exact cones)"``.
    is_closure : bool
        The verdict: ``rank == required_rank`` and either ``d* > tol`` or the
        normal-force certificate (see ``certificate``); with a hand
        Jacobian, LP3 must pass too.
    d_star : float
        Optimal ``d`` of LP1/LP2/SOCP: how far the best internal force lies inside
        the cones (the distance of each contact force to its cone's facets), with
        ``Σ f_n <= N``.  Dimensionless.  NaN when the solver reported
        infeasibility.
    rank : int
        Rank of ``G_n`` (form closure) or of ``G`` over the force components the
        cones allow (force closure).
    required_rank : int
        6 (spatial) or 3 (planar).
    margin : float
        ``(d* - tol) / tol``: positive when ``d* > tol``.  The verdict is
        uncertain (:attr:`near_boundary`) when ``tol/1000 < d* < 2 tol``.
    contact_forces : tuple of ndarray
        Optimal force of each contact in its contact frame, normal first
        (components of the contact's model; form closure: ``[f_n]`` only).
    solver, status : str
        Solver name and its solution status.
    tol : float
        Threshold on ``d*``.
    formulation : str
        ``"normals"`` (LP1), ``"facets"``, ``"generators"`` or ``"exact"``.
    frictional_closure : bool
        The verdict ignoring the hand: ``rank`` full and ``d* > tol`` or the
        normal-force certificate (equal to ``is_closure`` when no hand Jacobian
        was given).
    internal_forces : InternalForceResult or None
        LP3, when a hand Jacobian was given.
    certificate : str
        What proved the verdict: ``"d*"`` (the program's own ``d* > tol``, or
        the lack of it) or ``"normal forces"``.  ``d`` is a distance to the cone
        boundaries, so it vanishes as ``μ -> 0`` even for a grasp in form
        closure; when ``G`` has full rank and ``d* <= tol``, force closure is
        also proved by balancing normal forces with ``f_n > tol`` (LP1), which
        lie inside every cone with ``μ > 0``.  Then ``margin`` and
        ``contact_forces`` are LP1's, and ``d_star`` stays the program's.
    """

    kind: str
    is_closure: bool
    d_star: float
    rank: int
    required_rank: int
    margin: float
    contact_forces: tuple[np.ndarray, ...]
    solver: str
    status: str
    tol: float
    formulation: str
    frictional_closure: bool
    internal_forces: InternalForceResult | None = field(default=None)
    certificate: str = "d*"

    @property
    def near_boundary(self) -> bool:
        """True when ``tol/1000 < d* < 2 tol``: the verdict is not certain.

        ``d*`` at or below ``tol/1000`` is the solver's zero (Clp reports ``d*``
        to about 1e-10): a certain "no".
        """
        return _near(self.margin)

    def __bool__(self) -> bool:
        return self.is_closure

    def to_dict(self) -> dict:
        """JSON-ready dictionary (non-finite numbers become ``None``)."""
        d = {f.name: _jsonable(getattr(self, f.name)) for f in fields(self)}
        d["near_boundary"] = self.near_boundary
        return d

    def __str__(self) -> str:
        verdict = "YES" if self.is_closure else "no"
        lines = [
            f"{self.kind}: {verdict}",
            f"  rank {self.rank}/{self.required_rank}, d* = {self.d_star:.6g} "
            f"(tol {self.tol:g}, margin {self.margin:+.3g} tol)"
            + ("  [within tol of the boundary]" if self.near_boundary else ""),
            f"  solver {self.solver} ({self.status}), {self.formulation}",
        ]
        if self.certificate != "d*":
            lines.insert(2, f"  proved by {self.certificate} (LP1), margin as LP1's")
        if self.internal_forces is not None:
            lines.append("  " + str(self.internal_forces))
        return "\n".join(lines)


@dataclass(frozen=True)
class AntipodalResult:
    """Antipodal check of a two-contact grasp.

    Attributes
    ----------
    is_antipodal : bool
        The segment between the contacts lies inside both friction cones.
    angles : (2,) float
        Angle (rad) between ``c_2 - c_1`` and ``n_1``, and between ``c_1 - c_2``
        and ``n_2``.
    mu : (2,) float
        Friction coefficient used at each contact.
    margins : (2,) float
        ``atan(μ_i) - angle_i`` (rad): positive inside the cone.
    min_mu : float
        Smallest friction coefficient for which the pair is antipodal,
        ``tan(max angle)`` (``inf`` when an angle reaches 90°).
    """

    is_antipodal: bool
    angles: np.ndarray
    mu: np.ndarray
    margins: np.ndarray
    min_mu: float

    def __bool__(self) -> bool:
        return self.is_antipodal

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return {f.name: _jsonable(getattr(self, f.name)) for f in fields(self)}

    def __str__(self) -> str:
        verdict = "YES" if self.is_antipodal else "no"
        deg = np.degrees(self.angles)
        mdeg = np.degrees(self.margins)
        return (
            f"antipodal: {verdict}  (angles {deg[0]:.3f}°, {deg[1]:.3f}°; margins "
            f"{mdeg[0]:+.3f}°, {mdeg[1]:+.3f}°; needs mu >= {self.min_mu:.4g})"
        )
