"""Frozen result types of the closure programs."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.deferred import deferrable
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import ZERO_FRACTION, near_threshold

if TYPE_CHECKING:
    from drakegrasp.certificates.certificate import Certificate

__all__ = ["ClosureResult", "InternalForceResult"]


@checked_call
@dataclass(frozen=True)
class InternalForceResult:
    """LP3: an internal force with positive normals in ``N(G) ∩ N(Jᵀ)``, if any.

    Attributes
    ----------
    passes : bool
        True when ``d* <= max(tol, resolution)``: the hand can control every
        internal force, so the check of ``N(G) ∩ N(Jᵀ) = {0}`` (as LP3 poses
        it) passes.
    d_star : float
        Optimal ``d`` of LP3 (dimensionless; the normal forces are normalised by
        ``Σ f_n <= N``).
    margin : float
        ``(t - d*) / t`` with ``t = max(tol, resolution)``: positive when
        passing; uncertain when ``t/1000 < d* < 2 t``.
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
    certificate : Certificate or None
        When LP3 fails, the uncontrollable internal force (LP3's optimal forces:
        ``f ∈ N(G) ∩ N(Jᵀ)`` with every ``f_n > 0``); None when it passes.
    resolution : float
        The smallest normal component LP3's optimal force resolves:
        ``rank_tol`` times its largest component.  LP3 leaves the tangential
        components free, and on a nearly degenerate grasp the solver can
        return a "squeeze" whose tangential components are 1e11 and whose
        normals are 1e-6: normals 1e-17 of the force's size, below the
        round-off of the force itself and far below the numerical null space's
        resolution (``rank_tol``).  Such a ``d*`` says nothing, and whether it
        fell above or below ``tol`` depended on the machine; a squeeze must
        have normals above both ``tol`` and this to fail LP3.
    passes_within_friction : bool or None
        When LP3 fails: whether it would pass over the squeezes the contacts
        can carry, every contact force in its closed, exact Coulomb cone
        (``build_internal_force_program(within_friction=True)``).  True means
        every uncontrollable squeeze LP3 found would make a contact slide: the
        joints feel every squeeze the contacts can hold (a WSG-50's two tip
        spheres per pad whose normals lean 0.39° from the joint axis: LP3's
        squeeze presses 21,500 times harder along the surfaces than into
        them, and the planned grasp held in Drake).  None when LP3 passes.
        Reported beside the verdict, never in its place.
    d_star_within_friction : float or None
        That program's optimal ``d`` (None when LP3 passes).

    Notes
    -----
    Two facts, under two names.  **LP3 (uncontrollable squeezing)** asks for
    an internal force with *positive normal components* that no joint torque
    can change; **dim N(G) ∩ N(Jᵀ)** counts every such force, whatever the
    signs of its normals.  The verdict (``passes``, and ``is_closure`` of a
    force-closure result with a hand) follows LP3, as the source's test does:
    an uncontrollable force that would pull a finger off the object cannot be
    held as a squeeze, so it does not make the grasp slip.  Example: the
    three-finger equator grasp with a hand that drives only one finger has
    ``dim N(G) ∩ N(Jᵀ) = 2`` (the two undriven fingers can trade forces the
    hand cannot feel) yet passes LP3: no squeeze with all three normals
    positive escapes the driven finger.  The dimension is reported beside the
    verdict, never in its place.
    """

    passes: bool
    d_star: float
    margin: float
    null_space_dim: int
    contact_forces: tuple[np.ndarray, ...]
    solver: str
    status: str
    tol: float
    certificate: Certificate | None = None
    resolution: float = 0.0
    d_star_within_friction: float | None = None
    passes_within_friction: bool | None = None

    @property
    def threshold(self) -> float:
        """``max(tol, resolution)``: LP3 passes when ``d*`` is at most this."""
        return max(self.tol, self.resolution)

    @property
    def near_boundary(self) -> bool:
        """True when ``t/1000 < d* < 2 t`` (``t``: :attr:`threshold`): not certain."""
        return near_threshold(-self.margin)

    @property
    def null_space_trivial(self) -> bool:
        """True when ``N(G) ∩ N(Jᵀ) = {0}`` by rank."""
        return self.null_space_dim == 0

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        d = {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}
        d["null_space_trivial"] = self.null_space_trivial
        d["near_boundary"] = self.near_boundary
        return d

    def __str__(self) -> str:
        return "\n".join(self.report_lines())

    def report_lines(self) -> list[str]:
        """Two lines: LP3's verdict, and the null-space dimension under its name."""
        if self.passes and self.d_star > self.tol:
            lp3 = (
                f"LP3 (uncontrollable squeezing): passes, decided by d* = "
                f"{self.d_star:.3g} <= {self.resolution:.3g}, the resolution of "
                "its optimal force (rank_tol times its largest component): "
                "normals that small are round-off, not a squeeze"
            )
        elif self.passes:
            zero = _zero_text(self.d_star, self.tol)
            lp3 = (
                f"LP3 (uncontrollable squeezing): passes, decided by d* = {zero} "
                f"<= tol {self.tol:g}: every squeeze with f_n > 0 is felt by "
                "the joints"
            )
        else:
            lp3 = (
                f"LP3 (uncontrollable squeezing): FAILS, decided by d* = "
                f"{self.d_star:.3g} > tol {self.tol:g}: a squeeze with every "
                "f_n > 0 that no joint torque can change"
            )
        if self.near_boundary:
            lp3 += "  [within tol of the boundary]"
        if self.passes_within_friction is not None:
            lp3 += (
                "; within the friction cones none exists (d* = "
                f"{_zero_text(self.d_star_within_friction, self.tol)}): every "
                "such squeeze would make a contact slide, and the joints feel "
                "every squeeze the contacts can carry"
                if self.passes_within_friction
                else "; one exists within the friction cones too (d* = "
                f"{self.d_star_within_friction:.3g})"
            )
        dim = self.null_space_dim
        null = (
            f"dim N(G) ∩ N(Jᵀ) = {dim} (null-space condition: "
            + ("holds" if dim == 0 else "fails")
            + "; reported beside LP3, not used by the verdict)"
        )
        return [lp3, null]


@checked_call
@dataclass(frozen=True)
class ClosureResult:
    """Verdict of a form- or force-closure program.

    Attributes
    ----------
    kind : str
        ``"form closure"``, ``"force closure"`` or ``"force closure (exact cones)"``.
    is_closure : bool
        The verdict: ``rank == required_rank`` and either ``d* > tol`` or the
        normal-force route (see ``decided_by``); with a hand Jacobian, LP3
        must pass too.  It follows LP3 (uncontrollable squeezing), not the
        stricter null-space condition ``dim N(G) ∩ N(Jᵀ) = 0``, which is
        reported beside it (see :class:`InternalForceResult`: a hand driving
        one finger of the equator grasp has dimension 2 and passes LP3).
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
    decided_by : str
        What decided the verdict: ``"rank"`` (the rank is short: ``d*`` and
        ``margin`` played no part), ``"d*"`` (full rank, and the program's own
        ``d* > tol`` or the lack of it), ``"normal forces"`` or ``"LP3"``
        (frictional closure holds but the hand cannot control a squeeze).
        ``d`` is a distance to the cone boundaries, so it vanishes as
        ``μ -> 0`` even for a grasp in form closure; when ``G`` has full rank
        and ``d* <= tol``, force closure is also proved by balancing normal
        forces with ``f_n > tol`` (LP1), which lie inside every cone with
        ``μ > 0``.  Then ``margin`` and ``contact_forces`` are LP1's, and
        ``d_star`` stays the program's.
    certificate : Certificate or None
        The verdict's witness (:mod:`drakegrasp.certificates.certificate`), in the grasp
        frame about the reference point: an escape twist (form closure "no"),
        an unresisted wrench (force closure "no"), LP3's uncontrollable
        internal force (``decided_by == "LP3"``) or the balancing internal
        force of a "yes".  None only for a "no" within ``tol`` of the boundary,
        where no separating direction exists.  Re-verify it with
        ``result.certificate.check(grasp)``.

    Notes
    -----
    What no verdict needs is computed on first read and then kept
    (``drakegrasp.core.deferred``): the certificate; ``d_star``, ``margin``,
    ``contact_forces``, ``solver`` and ``status`` when the rank decided the
    verdict (``decided_by == "rank"``: the program is built and solved then);
    ``internal_forces`` when frictional closure fails.  The values are those
    an eager computation stores, ``to_dict()``, ``str()`` and pickling compute
    them, and a :class:`~drakegrasp.SolverError` of a deferred program is
    raised at the read.
    """

    kind: str
    is_closure: bool
    d_star: float = deferrable()
    rank: int
    required_rank: int
    margin: float = deferrable()
    contact_forces: tuple[np.ndarray, ...] = deferrable()
    solver: str = deferrable()
    status: str = deferrable()
    tol: float
    formulation: str
    frictional_closure: bool
    internal_forces: InternalForceResult | None = deferrable(None)
    decided_by: str = "d*"
    certificate: Certificate | None = deferrable(None)

    @property
    def near_boundary(self) -> bool:
        """True when ``tol/1000 < d* < 2 tol``: the verdict is not certain.

        ``d*`` at or below ``tol/1000`` is the solver's zero (Clp reports ``d*``
        to about 1e-10): a certain "no".
        """
        return near_threshold(self.margin)

    def __bool__(self) -> bool:
        return self.is_closure

    def to_dict(self) -> dict:
        """JSON-ready dictionary (non-finite numbers become ``None``).

        ``certificate`` is the witness's own dictionary; ``why`` is its one-line
        reading for a "no" (None for a "yes").
        """
        d = {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}
        d["near_boundary"] = self.near_boundary
        d["why"] = self.why()
        return d

    def why(self) -> str | None:
        """One line that says why the verdict is "no" (None for a "yes")."""
        if self.is_closure:
            return None
        if self.certificate is None:
            return (
                "no witness exists at this tol (the verdict lies within tol of "
                "the boundary)"
            )
        if self.near_boundary:
            # The witness holds within the check's tolerance, not with room:
            # the grasp may be barely in closure (μ = 0.5000001 read "cannot
            # resist a counter-clockwise moment" as a fact).
            return (
                f"{self.certificate.describe()} (within tol of the boundary: "
                f"d* = {self.d_star:.3g}, tol = {self.tol:g}; not certain)"
            )
        return self.certificate.describe()

    def __str__(self) -> str:
        return "\n".join(self.report_lines())

    def _decision_text(self) -> str:
        rank = f"rank {self.rank}/{self.required_rank}"
        d, tol = self.d_star, self.tol
        if self.decided_by == "rank":
            return (
                f"decided by rank: {rank} < {self.required_rank} "
                f"(d* = {d:.3g} not used)"
            )
        if self.decided_by == "normal forces":
            return (
                f"decided by normal forces (LP1): they balance with margin "
                f"{self.margin:+.3g} tol, {rank}; this program's d* = "
                f"{_zero_text(d, tol)} shrinks with mu and did not decide"
            )
        if self.decided_by == "LP3":
            return (
                "decided by LP3: frictional closure holds "
                f"({rank}), but the hand cannot control a squeeze"
            )
        if self.frictional_closure:
            return (
                f"decided by d* = {d:.3g} > tol {tol:g} (margin {self.margin:+.3g} "
                f"tol), {rank}"
            )
        return f"decided by d* = {_zero_text(d, tol)} <= tol {tol:g}, {rank}"

    def report_lines(self, *, internal_forces: bool = True) -> list[str]:
        """The report: verdict and what decided it, why, solver (and LP3)."""
        verdict = "YES" if self.is_closure else "no"
        lines = [f"{self.kind}: {verdict}, {self._decision_text()}"]
        if self.near_boundary and self.decided_by == "d*":
            lines[0] += "  [within tol of the boundary]"
        why = self.why()
        if why is not None:
            lines.append("  why: " + why)
        lines.append(f"  solver {self.solver} ({self.status}), {self.formulation}")
        if internal_forces and self.internal_forces is not None:
            lines += ["  " + line for line in self.internal_forces.report_lines()]
        return lines


def _zero_text(d_star: float, tol: float) -> str:
    """``d*`` as text, saying when it is the solver's zero rather than a value."""
    if math.isfinite(d_star) and abs(d_star) <= ZERO_FRACTION * tol:
        return "0 (solver zero)"
    return f"{d_star:.3g}"
