r"""The data every grasp-under-load program shares: limits, scales and constraints.

A load problem asks for contact forces ``f`` (contact frames, normal first) with

.. math::

    G f = -w,\quad f_i \in K_i,\quad |J^T f| \le \tau_{\max},\quad
    0 \le f_{n,i} \le f_{\max,i},\quad \textstyle\sum_i f_{n,i} \le s_{\max}

where ``w`` is the external wrench on the object (``[f; m]`` about ``p``, grasp
frame: gravity, a payload, a disturbance), so the contacts supply ``-w``
(the sign of :func:`~drakegrasp.max_resistible_wrench`), and ``τ = Jᵀ f`` are
the joint torques that press the fingers on with ``f`` (quasi-static: the hand
pushes ``f`` on the object, the object pushes ``-f`` back on the hand; the
hand's own weight is not part of ``τ``).

Every program is written in well-scaled variables so that no unit enters a
solver tolerance:

* balance on the normalised grasp matrix ``Ḡ = T G``
  (:func:`~drakegrasp.invariant_grasp_matrix`; moments about the centroid,
  over the spread), imposed as ``Ḡ f = -T w``;
* forces in units of a force scale ``F0`` (the load's size), so ``x = f / F0``;
* torques on the unit columns of ``J``: ``τ̃_j = τ_j / (c_j F0)`` with ``c_j``
  the column norm, against ``τ_max,j / (c_j F0)``;
* a soft finger's ``m_n`` scaled as in
  :class:`~drakegrasp.core.friction_cone.ConeLayout`;
* the tangential components of a contact with ``μ > FRICTION_SCALING`` in
  units of ``μ F0`` (:data:`FRICTION_SCALING`): its cone is then
  ``‖x_t‖ <= x_n``, where written in newtons (``μ = 1e12``) a solver read the
  ``x_t`` coefficient ``1/μ`` as 0 and returned forces far outside the cone or
  past the motors' limits; and its balance rows turned and scaled
  (:meth:`LoadProblem.balanced`): at ``μ = 1e-12`` the rows that only
  friction can balance have coefficients ``μ``, under every solver's
  tolerance, and a payload came out 4 % high.

Only the components a cone allows are variables (a hard finger with ``μ = 0``
has ``f_n`` alone).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, replace

import numpy as np

from drakegrasp.closure.constraints import (
    EXACT_CONE_COMPONENTS,
    add_contact_cones,
    add_linear_constraint,
    add_linear_equality_constraint,
)
from drakegrasp.core.friction_cone import ConeLayout
from drakegrasp.core.grasp import Grasp, check_hand_jacobian, grasp_matrix
from drakegrasp.core.linalg import FULL_SVD_MAX_COLUMNS
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS
from drakegrasp.core.validation import check_grasp as _check_grasp
from drakegrasp.core.validation import (
    check_num_generators,
    describe,
    plain_str,
    real_array,
    safe_norm,
)
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "CONES",
    "FEASIBILITY_TOL",
    "FRICTION_SCALING",
    "SATURATION_TOL",
    "LoadProblem",
    "check_direction",
    "check_wrench",
    "effort_unit_of",
    "load_problem",
    "saturating_joints",
]

SATURATION_TOL = 1e-6
"""A joint saturates when ``|τ_j| >= (1 - SATURATION_TOL) τ_max,j``."""

FRICTION_SCALING = 1e3
"""A contact with ``μ`` above this has tangential variables ``f_t / (μ F0)``.

Below it (every ordinary coefficient) the programs are those written in
newtons, so their answers do not move."""

FEASIBILITY_TOL = 1e-6
"""Relative tolerance of :meth:`LoadProblem.violation` (solvers reach ~1e-8)."""

_EPS = float(np.finfo(float).eps)

_LOAD_SHARE = 1e-3 / FEASIBILITY_TOL
"""A balance residual over 1e-3 of the load is a violation, whatever the
solvers' noise (:meth:`LoadProblem._balance_excess`)."""

_TERMS_ROUNDING = 1e3 * _EPS / FEASIBILITY_TOL
"""... or over 1e3 roundings of the balance's largest terms, where those
dwarf the load (a tiny μ's normal forces)."""

_SUBNORMAL_SIZE = 1e-280
"""Sizes (N) below which :meth:`LoadProblem.violation` stops being relative."""

CONES = ("exact", "polyhedral")
"""The cones a load problem may use: exact Coulomb / soft-finger, or inscribed."""


@dataclass(frozen=True, eq=False)
class LoadProblem:
    """A grasp, its cones and limits, validated and scaled once.

    Attributes
    ----------
    grasp : Grasp
    cones : {"exact", "polyhedral"}
    num_generators : int
    layout : ConeLayout
        The force components the cones allow (``layout.columns``).
    T : (D, D) float
        The normalising transform: ``Ḡ = T G``; a wrench ``w`` becomes
        ``T w`` and a dual twist ``ȳ`` becomes ``y = Tᵀ ȳ``.
    Gbar : (D, m) float
        ``T G`` on the layout's columns (unscaled components).
    hand_jacobian : (M, n_v) float or None
    Jt : (n_v, m) float
        ``(J[columns] / c)ᵀ``: unit-column torques per unit force (empty
        without a hand Jacobian).
    jscale : (n_v,) float
        ``c_j``, the column norms of ``J[columns]`` (1 for a zero column).
    torque_limits : (n_v,) float or None
        ``τ_max`` (``inf`` = no limit); None when not given.
    max_normal_force : (N,) float
        Per-contact bounds on ``f_n`` (``inf`` = none).
    max_squeeze : float
        Bound on ``Σ f_n`` (``inf`` = none).
    tangent_scale : float
        The largest ``μ`` that scales tangential variables (1 when none is
        above :data:`FRICTION_SCALING`): the size of a load the contacts hold
        per unit of normal force.
    balance_rows : (D, D) float or None
        ``B``: the balance is imposed as ``B Ḡ f = -B T w`` (None: ``B = I``).
        Set by :meth:`friction_scaled`; see :meth:`balanced`.
    balance_matrix : (D, m) float or None
        ``B Ḡ`` on the layout's columns, entries below the rounding of their
        own computation set to 0 (None: ``Ḡ``).
    """

    grasp: Grasp
    cones: str
    num_generators: int
    layout: ConeLayout
    T: np.ndarray
    Gbar: np.ndarray
    hand_jacobian: np.ndarray | None
    Jt: np.ndarray
    jscale: np.ndarray
    torque_limits: np.ndarray | None
    max_normal_force: np.ndarray
    max_squeeze: float
    tangent_scale: float = 1.0
    balance_rows: np.ndarray | None = None
    balance_matrix: np.ndarray | None = None

    @property
    def num_forces(self) -> int:
        """Number ``m`` of force variables (components the cones allow)."""
        return len(self.layout.columns)

    @property
    def needs_socp(self) -> bool:
        """True when an exact spatial friction cone makes the program an SOCP."""
        return self.cones == "exact" and any(
            c.components in EXACT_CONE_COMPONENTS for c in self.layout.cones
        )

    @property
    def kind(self) -> str:
        """The solver gateway's kind: ``"socp"`` or ``"lp"``."""
        return "socp" if self.needs_socp else "lp"

    def limited_joints(self) -> np.ndarray:
        """Indices of the joints with a finite torque limit."""
        if self.torque_limits is None:
            return np.zeros(0, dtype=int)
        return np.flatnonzero(np.isfinite(self.torque_limits))

    def bounded_contacts(self) -> np.ndarray:
        """Indices of the contacts with a finite bound on ``f_n``."""
        return np.flatnonzero(np.isfinite(self.max_normal_force))

    def force_scale(self, wrench: np.ndarray | None = None) -> float:
        """``F0``: the load's size when it has one, else the finite limits'.

        Parameters
        ----------
        wrench : (D,) float, optional
            The load in the grasp frame.
        """
        if wrench is not None:
            size = self.load_size(wrench)
            if size > 0.0:
                return size
        sizes = self.limit_sizes()
        sizes = sizes[sizes > 0.0]
        return float(np.max(sizes)) if sizes.size else 1.0

    def load_size(self, wrench: np.ndarray) -> float:
        """``max |T w|``: the size of the load ``wrench`` (N), normalised."""
        return float(np.max(np.abs(self.T @ wrench)))

    def limit_sizes(self) -> np.ndarray:
        """The finite limits in newtons: ``f_max``, ``s_max``, ``τ_max,j / c_j``.

        Returns
        -------
        (K,) float
            Per-contact bounds, the squeeze bound and the joints' torque
            limits over their Jacobian column norms (the normal force each
            allows), in that order; only the finite ones.
        """
        lim = self.limited_joints()
        return np.concatenate(
            [
                self.max_normal_force[np.isfinite(self.max_normal_force)],
                [self.max_squeeze] if math.isfinite(self.max_squeeze) else [],
                self.torque_limits[lim] / self.jscale[lim] if lim.size else [],
            ]
        )

    def stacked(self, x: np.ndarray, force_scale: float) -> np.ndarray:
        """Program values ``x`` as the (M,) stacked forces of the grasp, N."""
        full = np.zeros(self.grasp.num_components)
        full[self.layout.columns] = force_scale * self.layout.scales * x
        return full

    def per_contact(self, full: np.ndarray) -> tuple[np.ndarray, ...]:
        """(M,) stacked forces cut into one array per contact."""
        return tuple(full[s].copy() for s in self.grasp.component_slices())

    def joint_torques(self, full: np.ndarray) -> np.ndarray | None:
        """``τ = Jᵀ f`` of (M,) stacked forces (None without a hand Jacobian)."""
        if self.hand_jacobian is None:
            return None
        return self.hand_jacobian.T @ full

    def friction_scaled(self) -> LoadProblem:
        """The same problem with tangential variables in units of ``μ``.

        Every contact with ``μ`` far from 1 (above :data:`FRICTION_SCALING` or
        below its inverse) has ``f_t = μ F0 x_t``, so its cone reads
        ``‖x_t‖ <= x_n``, and the balance rows are turned and scaled
        (:meth:`balanced`); ``self`` when no contact has such a ``μ`` (or
        ``self`` is already the scaled twin).  Use it with a force unit ``F0``
        of the load's size over ``tangent_scale``.
        """
        mus = [c.mu for c in self.grasp.contacts]
        if self.balance_rows is not None or not any(_far_from_one(mu) for mu in mus):
            return self
        layout = self.layout
        scales = layout.scales.copy()
        for contact, cone, start in zip(
            self.grasp.contacts, layout.cones, layout.normal_positions, strict=True
        ):
            if _far_from_one(contact.mu):
                for j, component in enumerate(cone.components):
                    if component in (1, 2):
                        scales[start + j] *= contact.mu
        # The size of a load held per unit of normal force: the largest μ when
        # it is far from 1 (both ways: every μ tiny, or one huge), else 1.
        top = max(mus)
        ts = top if _far_from_one(top) else 1.0
        B, GB = _balance_rows(self.Gbar, scales, layout.normal_positions, ts)
        return replace(
            self,
            layout=replace(layout, scales=scales),
            tangent_scale=ts,
            balance_rows=B,
            balance_matrix=GB,
        )

    def balanced(self) -> tuple[np.ndarray, np.ndarray]:
        r"""``(B Ḡ, B)``: the balance rows a program imposes, on unscaled columns.

        ``B = diag(1/s) Uᵀ`` with ``U`` the left singular vectors of the
        normal columns ``Ḡ_n``: the rows ``Uᵀ Ḡ`` separate the wrenches the
        normal forces produce from those only friction produces (whose
        coefficients are ``μ`` times smaller), and ``s_k`` is the largest
        coefficient of row ``k`` on the scaled variables, so every row has
        coefficients of size 1.  Identity (``(Ḡ, I)``) unless friction-scaled.
        """
        if self.balance_rows is None:
            return self.Gbar, np.eye(self.Gbar.shape[0])
        return self.balance_matrix, self.balance_rows

    def violation(self, full: np.ndarray, wrench: np.ndarray) -> tuple[float, str]:
        """The largest relative violation of the constraints by forces ``full``.

        Each constraint's violation is divided by the size of the terms it
        sums (``|a|ᵀ|f|`` of its row, or its bound), so the answer does not
        depend on units or on ``μ``: a solver's answer is of order 1e-8.

        Parameters
        ----------
        full : (M,) float
            Stacked contact forces, N, contact frames.
        wrench : (D,) float
            The external wrench they must balance (``G f = -wrench``).

        Returns
        -------
        violation : float
            0 when every constraint holds exactly.
        what : str
            The constraint violated most ("balance", "cone 1", "joint 0", ...).
        """
        worst = [(0.0, "none")]

        def note(excess, size, what):
            # Below _SUBNORMAL_SIZE a float keeps too few digits for a
            # relative test (a 1e-320 N load): measure against that size.
            excess, size = float(excess), max(float(size), _SUBNORMAL_SIZE)
            if excess > 0.0:
                worst.append((excess / size, what))

        Gbar = self.T @ grasp_matrix(self.grasp)
        Tw = self.T @ wrench
        if any(_far_from_one(c.mu) for c in self.grasp.contacts):
            note(*self._balance_excess(Gbar, full, Tw), "balance")
        else:
            terms = np.abs(Gbar) @ np.abs(full) + np.abs(Tw)
            res = np.abs(Gbar @ full + Tw)
            note(np.max(res), max(float(np.max(terms)), 1e-300), "balance")
        # A cone is measured in tangential-force units (μ f_n against ‖f_t‖),
        # against the larger of its own terms and the problem's force size
        # (in friction-scaled units: μ times it for a tiny μ): a near-zero
        # force off by 1e-8 N is no violation, at μ = 1e12 an ‖f_t‖ of twice
        # μ f_n is one whatever f_n is, and at μ = 1e-12 so is an ‖f_t‖ of
        # twice μ f_n that is 1e-12 of the normal forces.
        ref = max(float(np.max(np.abs(full), initial=0.0)), float(np.max(np.abs(Tw))))
        b = self.grasp.characteristic_length
        for i, (contact, sl) in enumerate(
            zip(self.grasp.contacts, self.grasp.component_slices(), strict=True)
        ):
            f = full[sl]
            note(-f[0], max(float(safe_norm(f)), ref), f"cone {i}")
            mu = contact.mu
            if len(f) == 1 or mu == 0.0:
                continue
            cref = mu * ref if mu < 1.0 and _far_from_one(mu) else ref
            if self.cones == "polyhedral":
                cone = self.layout.cones[i]
                fc = f[list(cone.components)]
                rows = cone.facets * max(1.0, mu)
                size = max(float(np.max(np.abs(rows) @ np.abs(fc))), cref)
                note(np.max(-(rows @ fc)), size, f"cone {i}")
                continue
            ft = float(safe_norm(f[1 : min(len(f), 3)]))
            tors = 0.0
            if len(f) == 4 and f[3] != 0.0:
                tors = mu * abs(f[3]) / (b * contact.torsional_friction)
            # ‖f_t‖ + μ |m_n|/(b ν) <= μ f_n.
            size = max(ft + tors + mu * abs(f[0]), cref)
            note(ft + tors - mu * f[0], size, f"cone {i}")
        if self.torque_limits is not None:
            tau = self.hand_jacobian.T @ full
            size = np.abs(self.hand_jacobian.T) @ np.abs(full)
            hand = float(np.max(size, initial=0.0))
            for j in self.limited_joints():
                lim = self.torque_limits[j]
                # at least the hand's largest torque terms times the tolerance:
                # a joint without a motor (limit 0) under a finger pressing
                # 1e-12 of the load got 2e-14 N·m, which its own terms (of
                # that size) called a violation "by 3 %"; a torque 1.8 times
                # a small but real limit is still one
                scale = max(lim, size[j], FEASIBILITY_TOL * hand)
                note(abs(tau[j]) - lim, scale, f"joint {j}")
        fn = full[self.grasp.normal_indices()]
        for i in self.bounded_contacts():
            fmax = self.max_normal_force[i]
            note(fn[i] - fmax, max(fmax, abs(fn[i])), f"contact {i} bound")
        if math.isfinite(self.max_squeeze):
            size = max(self.max_squeeze, np.sum(np.abs(fn)))
            note(np.sum(fn) - self.max_squeeze, size, "squeeze")
        return max(worst)

    def _balance_excess(self, Gbar, full, Tw) -> tuple[float, float]:
        """The balance's worst ``(excess, size)`` on the rows of :meth:`balanced`.

        Row ``k`` of ``Uᵀ (Ḡ f + T w)`` against its own terms, or, when they
        are smaller, against the row's coefficients on one unit of the
        friction-scaled program's forces (a solver's residual there is that
        size); the rounding of the residual's own computation is no excess.
        At ``μ = 1e-12`` the rows that only friction balances are 1e-12 of the
        others: measured against all of them a payload 4 % high passed.
        """
        Q = self.friction_scaled()
        U = _rotation(Gbar, self.grasp.normal_indices())
        M = U.T @ Gbar
        UTw = U.T @ Tw
        f = np.abs(full)
        res = np.abs(M @ full + UTw)
        terms = np.abs(M) @ f + np.abs(UTw)
        allow = (
            _rounding(U, Gbar) @ f
            + _rounding(U, Tw[:, None])[:, 0]
            + (2.0 * len(f) * _EPS) * terms
        )
        unit = np.ones(len(full))
        unit[Q.layout.columns] = Q.layout.scales
        fn = f[self.grasp.normal_indices()]
        load = float(np.max(np.abs(Tw)))
        ts = Q.tangent_scale
        fref = max(float(np.max(fn)), load / ts)
        # One force unit of the program, and the load it holds (ts of it):
        # a row no force reaches (torsion about two fingers' line) still has
        # the load's share as its noise, not 0.
        reach = np.max(np.abs(M) * unit, axis=1)
        if load > 0.0:
            reach = reach + ts * (np.abs(UTw) / load)
        # The floor excuses a solver's noise, never a load left unbalanced:
        # at μ = (0.5, 1e-12) forces of 3e8 N "held" 0.2 N with a third of it
        # unbalanced, under a floor of 1e-6 of 3e8 N.  A residual is also
        # weighed against the load (1e-3 of it), or the rounding of the
        # largest terms where those dwarf it.
        cap = max(_LOAD_SHARE * load, _TERMS_ROUNDING * float(np.max(terms)))
        size = np.maximum(terms, np.minimum(reach * fref, cap))
        size = np.maximum(size, _SUBNORMAL_SIZE)
        ratio = np.maximum(res - allow, 0.0) / size
        k = int(np.argmax(ratio))
        return float(max(res[k] - allow[k], 0.0)), float(size[k])

    def normalised(self, wrench: np.ndarray) -> np.ndarray:
        """``T w``: a wrench about the centroid, moments over the spread."""
        return self.T @ wrench


def _far_from_one(mu: float) -> bool:
    """Whether a contact's tangential variables are in units of ``μ``."""
    return mu > FRICTION_SCALING or 0.0 < mu < 1.0 / FRICTION_SCALING


def _rotation(Gbar: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """``U``: left singular vectors of the normal columns (the wrenches they make)."""
    A = Gbar[:, normals]
    # All m left vectors are needed; the full right factor (n x n, gigabytes
    # for thousands of contacts) only for the usual small grasps, whose bits
    # it keeps, or when there are fewer columns than rows.
    full = A.shape[1] <= FULL_SVD_MAX_COLUMNS or A.shape[1] < A.shape[0]
    return np.linalg.svd(A, full_matrices=full)[0]


def _rounding(U: np.ndarray, A: np.ndarray) -> np.ndarray:
    """A bound on the rounding error of each entry of ``Uᵀ A`` as computed."""
    return (2.0 * U.shape[0] * _EPS) * (np.abs(U).T @ np.abs(A))


def _balance_rows(
    Gbar: np.ndarray, scales: np.ndarray, normals: np.ndarray, tangent_scale: float
):
    """``(B, B Ḡ)`` of :meth:`LoadProblem.balanced` for variables ``f / scales``.

    An entry of ``Uᵀ Ḡ`` no larger than the rounding of its own computation is
    set to 0: a normal column's 1e-17 on a row that only friction reaches
    would, over the row's ``μ = 1e-12``, weigh 1e-5 of it.  A row no force
    reaches is divided by ``tangent_scale``, the size of a load in program
    units (at ``μ = 1e-12`` a torsion about two fingers' line was a 1e-12 in
    a row of zeros, under the solvers' tolerance: "held").
    """
    U = _rotation(Gbar, normals)
    M = U.T @ Gbar
    M[np.abs(M) <= _rounding(U, Gbar)] = 0.0
    s = np.max(np.abs(M) * scales, axis=1)
    s = np.where(s > 0.0, s, tangent_scale)
    return U.T / s[:, None], M / s[:, None]


def check_wrench(grasp: Grasp, wrench, name: str = "wrench") -> np.ndarray:
    """A finite ``[f; m]`` of the grasp's wrench dimension (3 planar, 6 spatial)."""
    _check_grasp(grasp)
    w = real_array(name, wrench, error=InvalidOptionError).reshape(-1)
    D = grasp.wrench_dim
    if w.shape != (D,) or not np.all(np.isfinite(w)):
        raise InvalidOptionError(
            f"{name} must be a finite {D}-vector [f; m] about the grasp's "
            f"reference point (the grasp is {'planar' if grasp.planar else 'spatial'}"
            f"), got {np.asarray(wrench).tolist()}"
        )
    return w


def check_direction(grasp: Grasp, direction, name: str = "direction") -> np.ndarray:
    """A load direction: a :func:`check_wrench` that is not all zeros."""
    d = check_wrench(grasp, direction, name)
    if not np.any(d):
        raise InvalidOptionError(f"{name} must be a non-zero wrench, got zeros")
    return d


def _check_cones(cones) -> str:
    cones = plain_str(cones)
    if type(cones) is not str or cones not in CONES:
        raise InvalidOptionError(f"cones must be one of {CONES}, got {describe(cones)}")
    return cones


def _check_limits(name: str, value, n: int, what: str) -> np.ndarray:
    v = real_array(name, value, error=InvalidOptionError)
    if v.ndim == 0:
        v = np.full(n, float(v))
    if v.shape != (n,) or np.any(np.isnan(v)) or np.any(v < 0.0):
        raise InvalidOptionError(
            f"{name} must be a number >= 0 or {n} of them (one per {what}; inf "
            f"for none), got {np.asarray(value).tolist()}"
        )
    return v.astype(float)


def _check_squeeze(value) -> float:
    if value is None:
        return math.inf
    v = real_array("max_squeeze", value, error=InvalidOptionError)
    if v.ndim != 0 or np.isnan(v) or v < 0.0:
        raise InvalidOptionError(
            f"max_squeeze must be one number >= 0 (N; None or inf for none), got "
            f"{np.asarray(value).tolist()}"
        )
    return float(v)


def normalising_transform(grasp: Grasp) -> np.ndarray:
    """``T`` with ``invariant_grasp_matrix(grasp) = T @ grasp_matrix(grasp)``.

    Moments move from ``p`` to the contacts' centroid ``c̄`` and are divided by
    the spread ``L`` (``docs/conventions.md``, "Invariance").
    """
    positions = grasp.positions
    centroid = positions.mean(axis=0)
    spread = float(np.max(np.linalg.norm(positions - centroid, axis=1)))
    if not (np.isfinite(spread) and spread > 0.0):
        spread = 1.0
    r = grasp.reference_point - centroid
    d = grasp.dim
    if d == 2:
        shift = np.array([[1.0, 0, 0], [0, 1.0, 0], [-r[1], r[0], 1.0]])
        return np.diag([1.0, 1.0, 1.0 / spread]) @ shift
    S = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    shift = np.block([[np.eye(3), np.zeros((3, 3))], [S, np.eye(3)]])
    return np.diag([1.0, 1.0, 1.0, 1 / spread, 1 / spread, 1 / spread]) @ shift


def load_problem(
    grasp: Grasp,
    *,
    hand_jacobian=None,
    torque_limits=None,
    max_normal_force=None,
    max_squeeze=None,
    cones: str = "exact",
    num_generators: int = DEFAULT_NUM_GENERATORS,
) -> LoadProblem:
    """Validate the options of a load program and scale its data.

    Raises
    ------
    InvalidOptionError
        Unknown ``cones``; torque limits without a hand Jacobian, or of the wrong
        length; a negative or NaN limit.
    InvalidGraspError
        A hand Jacobian of the wrong shape.
    """
    _check_grasp(grasp)
    cones = _check_cones(cones)
    n_g = check_num_generators(num_generators)
    layout = ConeLayout.of(grasp, n_g)
    cols = layout.columns
    T = normalising_transform(grasp)
    Gbar = T @ grasp_matrix(grasp)[:, cols]
    J = None
    Jt = np.zeros((0, len(cols)))
    jscale = np.zeros(0)
    limits = None
    if hand_jacobian is not None:
        J = check_hand_jacobian(grasp, hand_jacobian)
        Jc = J[cols]
        # A scaled norm: at |J_ij| ~ 1e-200 the squares underflowed, the
        # norm came out 0, the column kept its size and the limit rows
        # (1e-200 x <= 2e-200) read as none: a payload past the motors' limits.
        norms = safe_norm(Jc, axis=0) if Jc.size else np.zeros(Jc.shape[1])
        jscale = np.where(norms > 0.0, norms, 1.0)
        Jt = (Jc / jscale).T
        if torque_limits is not None:
            limits = _check_limits("torque_limits", torque_limits, J.shape[1], "joint")
    elif torque_limits is not None:
        raise InvalidOptionError(
            "torque_limits need the hand_jacobian J (the joint torques are "
            "τ = Jᵀ f); pass hand_jacobian=..."
        )
    N = grasp.num_contacts
    fmax = (
        np.full(N, math.inf)
        if max_normal_force is None
        else _check_limits("max_normal_force", max_normal_force, N, "contact")
    )
    return LoadProblem(
        grasp=grasp,
        cones=cones,
        num_generators=n_g,
        layout=layout,
        T=T,
        Gbar=Gbar,
        hand_jacobian=J,
        Jt=Jt,
        jscale=jscale,
        torque_limits=limits,
        max_normal_force=fmax,
        max_squeeze=_check_squeeze(max_squeeze),
    )


# ------------------------------------------------ constraints on the forces


def add_force_constraints(prog, P: LoadProblem, x, force_scale: float, d=None):
    """Cones (each force at least ``d`` inside when ``d`` is given) and limits.

    ``x`` are the program's force variables: the force components on
    ``P.layout.columns`` are ``force_scale * P.layout.scales * x``.  Returns
    the scaled torque expressions' matrix ``A_τ`` (``τ_j = c_j F0 (A_τ x)_j``).
    """
    add_contact_cones(
        prog, P.grasp.contacts, P.layout, x, P.grasp.characteristic_length,
        d=d, exact=P.cones == "exact",
    )  # fmt: skip
    scales = P.layout.scales
    A_tau = P.Jt * scales
    lim = P.limited_joints()
    normals = P.layout.normal_positions
    bounded = P.bounded_contacts()
    upper = np.full(len(normals), np.inf)
    # A limit over a tiny (subnormal) F0 is past the largest float: inf, "no
    # bound", is its meaning, as forces of that size never reach it.  Dividing
    # by c_j first keeps c_j F0 from underflowing to 0 (0 / 0 for τ_max = 0).
    with np.errstate(over="ignore"):
        if lim.size:
            bound = (P.torque_limits[lim] / P.jscale[lim]) / force_scale
            add_linear_constraint(prog, A_tau[lim], -bound, bound, x)
        upper[bounded] = P.max_normal_force[bounded] / force_scale
        squeeze = P.max_squeeze / force_scale
    prog.AddBoundingBoxConstraint(np.zeros(len(normals)), upper, x[normals])
    if math.isfinite(squeeze):
        add_linear_constraint(
            prog, np.ones((1, len(normals))), [-np.inf], [squeeze], x[normals]
        )
    return A_tau


def add_balance(prog, P: LoadProblem, x, rhs: np.ndarray, alpha=None) -> None:
    """``Ḡ f = rhs`` in program units; with ``alpha``: ``Ḡ f + α rhs' = 0``.

    Imposed on the rows ``B`` of :meth:`LoadProblem.balanced`.
    """
    GB, B = P.balanced()
    A = GB * P.layout.scales
    if P.balance_rows is not None:
        rhs = B @ rhs
    if alpha is None:
        add_linear_equality_constraint(prog, A, rhs, x)
    else:
        add_linear_equality_constraint(
            prog,
            np.hstack([A, rhs[:, None]]),
            np.zeros(A.shape[0]),
            np.append(x, alpha),
        )


def saturating_joints(
    joint_torques: np.ndarray | None, torque_limits: np.ndarray | None
) -> tuple[tuple[int, ...], float]:
    """Joints at their limit (most loaded first) and the largest ``|τ_j|/τ_max,j``."""
    if joint_torques is None or torque_limits is None:
        return (), math.nan
    lim = np.asarray(torque_limits, dtype=float)
    tau = np.abs(np.asarray(joint_torques, dtype=float))
    use = np.isfinite(lim) & (lim > 0.0)
    if not np.any(use):
        return (), math.nan
    ratio = np.full(len(lim), -np.inf)
    ratio[use] = tau[use] / lim[use]
    at = np.flatnonzero(use & (ratio >= 1.0 - SATURATION_TOL))
    order = at[np.argsort(-ratio[at], kind="stable")]
    return tuple(int(j) for j in order), float(np.max(ratio[use]))


_MIXED_UNIT = "N·m, N at prismatic joints"


def effort_unit_of(units: Iterable[str], default: str = "N·m") -> str:
    """The unit of joints' efforts, as drakegrasp writes it in its words.

    Each joint's effort has its own unit: ``"N·m"`` at a revolute joint (a
    torque), ``"N"`` at a prismatic one (a force).  Joints that share one are
    given in it; joints of both kinds in ``"N·m, N at prismatic joints"``,
    the one spelling of a mixed hand's unit (a planned candidate's
    ``torque_unit``, the shake test's summary, the joint torques of a
    :class:`~drakegrasp.closure.load_forces.GraspForceResult`); no joint in
    ``default``.

    Parameters
    ----------
    units : iterable of str
        One unit per joint.
    default : str, optional
        The unit of no joint (a record made before units were kept).

    Returns
    -------
    str
    """
    kinds = set(units)
    if not kinds:
        return default
    return kinds.pop() if len(kinds) == 1 else _MIXED_UNIT
