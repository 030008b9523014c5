r"""The witness that a load cannot be held: a Farkas dual of the grasp-force system.

A grasp holds the external wrench ``w`` (on the object, ``[f; m]`` about ``p``,
grasp frame) when contact forces ``f`` exist with

.. math::

    G f = -w,\quad f_i \in K_i,\quad |J^T f| \le \tau_{\max},\quad
    f_{n,i} \le f_{\max,i},\quad \textstyle\sum_i f_{n,i} \le s_{\max}

(``K_i`` the friction cones, ``J`` the hand Jacobian: ``τ = Jᵀ f`` are the
joint torques that press the fingers on with ``f``).  When no such ``f``
exists, Farkas' lemma for this conic system gives a **dual direction**: a twist
``y`` of the object and multipliers ``η`` (joints), ``ρ >= 0`` (per-contact
normal bounds) and ``σ >= 0`` (total squeeze) with, at every contact,

.. math::

    a_i = G_i^T y - J_i \eta - (\rho_i + \sigma)\, e_n \in -K_i^*,
    \quad\text{i.e.}\quad \max_{f_i \in K_i,\, f_{n,i} = 1} a_i^T f_i \le 0,

checked with the cones' support functions
(:func:`~drakegrasp.core.friction_cone.support_of`), and a power deficit

.. math::

    -y^T w \;>\; B = \textstyle\sum_j |\eta_j|\, \tau_{\max,j}
    + \sum_i \rho_i f_{\max,i} + \sigma s_{\max}.

Proof: for any admissible ``f``, ``Σ a_iᵀ f_i = -yᵀ w - ηᵀ Jᵀ f - Σ (ρ_i +
σ) f_{n,i} >= -yᵀ w - B > 0``, yet every term ``a_iᵀ f_i <= 0``.  In words:
moving the object along ``y``, the load delivers power ``-yᵀ w``; the contacts,
the motors within their limits and the bounded normal forces can absorb at most
``B`` of it.  The same numbers prove that ``α w`` cannot be held for any
``α > B / (-yᵀ w)`` (a **payload bound**).

When floating point leaves a contact's support ``ε_i > 0`` instead of ``<= 0``,
the argument still shows that any balancing forces need a total normal force of
at least ``(-yᵀ w - B) / max_i ε_i``; the check reports that number.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from drakegrasp.certificates._matching import _foreign, check_tolerance
from drakegrasp.certificates.kinds import (
    DEFAULT_CHECK_TOL,
    CertificateCheck,
    check_kind_and_cones,
)
from drakegrasp.core.calls import checked_call
from drakegrasp.core.friction_cone import ConeLayout, support_of
from drakegrasp.core.grasp import Grasp, check_hand_jacobian, grasp_matrix
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import (
    check_grasp,
    check_num_generators,
    describe,
    real_array,
    real_scalar,
)
from drakegrasp.errors import InvalidOptionError

__all__ = ["LOAD_NOT_HELD", "PAYLOAD_BOUND", "LoadCertificate"]

_TINY_BOUND = 1e-300
"""Bounds below this are compared absolutely (nothing is relative to 0)."""

LOAD_NOT_HELD = "load not held"
"""Kind of the witness that the wrench ``w`` itself cannot be held (bound < 1)."""
PAYLOAD_BOUND = "payload bound"
"""Kind of the witness that ``α w`` cannot be held for any ``α > bound``."""
_KINDS = (LOAD_NOT_HELD, PAYLOAD_BOUND)
_CONES = ("polyhedral", "exact")


@checked_call
@dataclass(frozen=True, eq=False)
class LoadCertificate:
    """A dual direction proving that no admissible contact forces hold a load.

    Everything is in the grasp frame, moments about ``p``
    (``docs/conventions.md``).

    Attributes
    ----------
    kind : str
        :data:`LOAD_NOT_HELD` (``wrench`` cannot be held: ``bound < 1``) or
        :data:`PAYLOAD_BOUND` (``α · wrench`` cannot be held for ``α > bound``).
    cones : {"exact", "polyhedral"}
        The cones the forces were asked to lie in.
    num_generators : int
        Generators of the polyhedral cones (unused for exact ones).
    wrench : (6,) or (3,) float
        The external wrench on the object ``[f; m]`` (N, N·m), or the payload
        direction.
    twist : (6,) or (3,) float
        ``y = [v_p; ω]``: the object's motion along which the load delivers
        more power than the grasp can absorb (any positive scale).
    joint_multipliers : (n_v,) float
        ``η``, one per column of the hand Jacobian (empty without one).
    normal_multipliers : (N,) float
        ``ρ >= 0``, on the per-contact bounds ``f_n <= max_normal_force``.
    squeeze_multiplier : float
        ``σ >= 0``, on the bound ``Σ f_n <= max_squeeze``.
    torque_limits : (n_v,) float or None
        ``τ_max`` (N·m or N; ``inf`` = no limit) the certificate refers to.
    max_normal_force : (N,) float or None
        Per-contact bounds on ``f_n`` (N; ``inf`` = none).
    max_squeeze : float
        Bound on ``Σ f_n`` (N; ``inf`` = none).
    bound : float
        The proven payload bound ``B / (-yᵀ w)`` as computed when it was found.
    """

    kind: str
    cones: str
    num_generators: int
    wrench: np.ndarray
    twist: np.ndarray
    joint_multipliers: np.ndarray
    normal_multipliers: np.ndarray
    squeeze_multiplier: float
    torque_limits: np.ndarray | None
    max_normal_force: np.ndarray | None
    max_squeeze: float
    bound: float

    def __post_init__(self):
        kind, cones = check_kind_and_cones(self.kind, self.cones, _KINDS, _CONES)
        object.__setattr__(self, "kind", kind)
        object.__setattr__(self, "cones", cones)

    def power_budget(self) -> float:
        """``B``: the most power the motors and force bounds absorb along ``y`` (W)."""
        return _budget(self)

    def check(
        self,
        grasp: Grasp,
        *,
        hand_jacobian: np.ndarray | None = None,
        tol: float = DEFAULT_CHECK_TOL,
        wrench: np.ndarray | None = None,
        torque_limits: np.ndarray | None = None,
        max_normal_force: np.ndarray | float | None = None,
        max_squeeze: float | None = None,
    ) -> CertificateCheck:
        """Re-verify the certificate on ``grasp`` with matrix products (no solver).

        The claim is about a load and limits.  By default they are the
        certificate's own (``wrench``, ``torque_limits``, ...), and the check
        proves the claim about those: a certificate whose limits were edited
        proves its bound for the edited limits, which the detail line states.
        Pass your problem's load and limits to check the claim about them:
        the same multipliers price your limits (a dual direction is one for
        any limits), so the bound is re-derived from yours.

        Parameters
        ----------
        grasp : Grasp
            The grasp the load was analysed for.
        hand_jacobian : (M, n_v) float, optional
            Needed when the certificate has joint multipliers.
        tol : float, optional
            Relative tolerance on the cone condition and on the bound.
        wrench : (D,) float, optional
            The load (N, N·m, grasp frame) in place of the certificate's.
        torque_limits : (n_v,) float, optional
            ``τ_max`` (``inf``: no limit) in place of the certificate's.
        max_normal_force : (N,) float or float, optional
            Per-contact bounds on ``f_n`` (N; a scalar is every contact's; ``inf``:
            none) in place of the certificate's.
        max_squeeze : float, optional
            Bound on ``Σ f_n`` (N; ``inf``: none) in place of the certificate's.

        Returns
        -------
        CertificateCheck
            ``violation``: the larger of the largest cone support (less the
            rounding of its own computation) over the largest contact's
            terms, and the claimed bound's shortfall relative to the bound
            (``inf`` when ``-yᵀ w <= B``, i.e. nothing is proven); ``slack``:
            the relative power deficit ``(-yᵀ w - B) / (|yᵀ w| + B)``.

        Notes
        -----
        A contact's terms are its support evaluated on the absolute values of
        what ``a_i`` sums (``|G_i|ᵀ|y| + |J_i||η| + (ρ_i + σ) e_n``), so the
        friction term is ``μ`` times the tangential ones: the measure holds
        for ``μ`` from 1e-12 to 1e12, where ``‖G‖ ‖y‖`` is up to 1e12 times
        the inequality's own terms.  A certificate that prices no limit
        (``B = 0``) is measured against ``min(1, μ) ‖G‖ ‖y‖`` too, what the
        twist could make a contact absorb.
        """
        problem = {
            "wrench": wrench,
            "torque_limits": torque_limits,
            "max_normal_force": max_normal_force,
            "max_squeeze": max_squeeze,
        }
        given = {k: v for k, v in problem.items() if v is not None}
        return check_load_certificate(self, grasp, hand_jacobian, tol, given)

    def force_reach(
        self, grasp: Grasp, *, hand_jacobian: np.ndarray | None = None
    ) -> float:
        """The total normal force (N) up to which the certificate proves its claim.

        A cone support that round-off leaves a little above 0 proves the
        claim only for forces whose ``Σ f_n`` stays below this (the check's
        caveat; per unit of α past the bound for a payload bound): ``inf``
        when every support is at most 0, 0 when nothing is proven.  At a
        tiny ``μ`` a load may need ``|w| / μ`` of normal force, beyond it.

        Parameters
        ----------
        grasp : Grasp
        hand_jacobian : (M, n_v) float, optional
            Needed when the certificate has joint multipliers.

        Returns
        -------
        float
            Newtons (``Σ f_n``).
        """
        return certificate_force_reach(self, grasp, hand_jacobian)

    def to_dict(self) -> dict:
        """JSON-ready dictionary (``inf`` limits become ``None``).

        ``LoadCertificate(**d)`` of such a dictionary checks as the original
        does: a ``None`` limit, or a ``None`` entry of one, is no limit.
        """
        return {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}

    def __str__(self) -> str:
        y = np.round(self.twist / np.linalg.norm(self.twist), 4).tolist()
        what = (
            "the load cannot be held"
            if self.kind == LOAD_NOT_HELD
            else f"no more than {self.bound:.6g} x the load can be held"
        )
        return (
            f"{self.kind} ({self.cones} cones): {what}; along the twist {y} the "
            f"load delivers more power than the grasp absorbs "
            f"(bound {self.bound:.6g})"
        )


def _budget(cert: LoadCertificate) -> float:
    total = 0.0
    eta = np.asarray(cert.joint_multipliers, dtype=float)
    if eta.size:
        # No torque limits (a Jacobian without them): every joint unlimited,
        # so a multiplier on one prices an infinite budget (it was an
        # IndexError on the 0-d array of None).
        limits = (
            np.full(eta.shape, np.inf)
            if cert.torque_limits is None
            else np.asarray(cert.torque_limits, dtype=float)
        )
        used = eta != 0.0
        total += float(np.sum(np.abs(eta[used]) * limits[used]))
    rho = np.asarray(cert.normal_multipliers, dtype=float)
    if rho.size and np.any(rho != 0.0):
        fmax = np.asarray(cert.max_normal_force, dtype=float)
        used = rho != 0.0
        total += float(np.sum(rho[used] * fmax[used]))
    if cert.squeeze_multiplier != 0.0:
        total += cert.squeeze_multiplier * cert.max_squeeze
    return total


def _supports(cert: LoadCertificate, grasp: Grasp, J: np.ndarray | None):
    """Per contact the support ``max a_iᵀ f_i`` (``f_n = 1``), its terms, its rounding.

    The terms of contact ``i`` are its support evaluated on the absolute
    values of what ``a_i`` sums, ``t = |G_i|ᵀ|y| + |J_i||η| + (ρ_i + σ) e_n``
    (``t_n + μ ‖t_t‖`` on an exact cone): friction-scaled, so that at
    ``μ = 1e-12`` the 1e-12 of ``a_t`` that friction weighs is not measured
    against ``‖G‖ ‖y‖``, 1e12 times larger (a payload bound 2 % low passed).
    The rounding is a bound on the error of computing the support in floats.
    """
    G = grasp_matrix(grasp)
    layout = ConeLayout.of(grasp, cert.num_generators)
    b = grasp.characteristic_length
    y = np.asarray(cert.twist, dtype=float)
    eta = np.asarray(cert.joint_multipliers, dtype=float)
    rho = np.asarray(cert.normal_multipliers, dtype=float)
    n_terms = G.shape[0] + (0 if J is None else J.shape[1]) + 2
    gamma = 4.0 * n_terms * np.finfo(float).eps
    support, terms = [], []
    for i, (s, cone, c) in enumerate(
        zip(grasp.component_slices(), layout.cones, grasp.contacts, strict=True)
    ):
        a = G[:, s].T @ y
        t = np.abs(G[:, s]).T @ np.abs(y)
        if J is not None:
            a = a - J[s] @ eta
            t = t + np.abs(J[s]) @ np.abs(eta)
        a[0] -= rho[i] + cert.squeeze_multiplier
        t[0] += abs(rho[i]) + abs(cert.squeeze_multiplier)
        comps = list(cone.components)
        support.append(support_of(a[comps], cone, c, cert.cones, b))
        terms.append(_support_terms(t[comps], cone, c, cert.cones, b))
    terms = np.array(terms)
    return np.array(support), terms, gamma * terms


def _support_terms(t: np.ndarray, cone, contact, cones: str, b: float) -> float:
    """:func:`support_of` on the absolute terms ``t`` (>= 0) of ``a``."""
    if not (cones == "exact" and cone.components in ((0, 1, 2), (0, 1, 2, 3))):
        return float(np.max(np.abs(cone.generators).T @ t))
    value = contact.mu * np.linalg.norm(t[1:3])
    if len(t) == 4:
        value = max(value, b * contact.torsional_friction * t[3])
    return float(t[0] + value)


def _array(cert: LoadCertificate, name: str, shape, grasp: Grasp) -> np.ndarray:
    """The certificate's ``name`` as a real array of ``shape`` (None: any length)."""
    a = real_array(
        f"the certificate's {name}", getattr(cert, name), error=InvalidOptionError
    )
    if a.ndim != 1 or (shape is not None and a.shape != shape):
        want = f"({shape[0]},)" if shape is not None else "(n_v,)"
        raise _foreign(name, a.shape, want, grasp)
    return a


def _no_limit_as_inf(value):
    """``value`` with None, and None entries of a list, as ``inf`` (no limit).

    :meth:`LoadCertificate.to_dict` writes ``inf`` as None (JSON has none).
    """
    if value is None:
        return math.inf
    if isinstance(value, (list, tuple)):
        return [math.inf if v is None else v for v in value]
    return value


def _limits(cert: LoadCertificate, name: str, n: int, grasp: Grasp) -> np.ndarray:
    """A limit array of the certificate; None means no limit (``inf``)."""
    value = _no_limit_as_inf(getattr(cert, name))
    if np.ndim(value) == 0 and name == "max_normal_force":
        value = np.full(n, value)  # one bound for every contact, as max_load's
    if np.ndim(value) == 0 and value == math.inf:
        return np.full(n, math.inf)
    return _array(replace(cert, **{name: value}), name, (n,), grasp)


def _read(cert: LoadCertificate, grasp: Grasp) -> LoadCertificate:
    """``cert`` with every array real and shaped for ``grasp``.

    Raises
    ------
    InvalidGraspError
        When ``grasp`` is not a Grasp.
    InvalidOptionError
        When a field is not real, or has the shape of another grasp or hand.
    """
    check_grasp(grasp)
    D, N = grasp.wrench_dim, grasp.num_contacts
    eta = _array(cert, "joint_multipliers", None, grasp)
    return LoadCertificate(
        kind=cert.kind,
        cones=cert.cones,
        num_generators=check_num_generators(cert.num_generators),
        wrench=_array(cert, "wrench", (D,), grasp),
        twist=_array(cert, "twist", (D,), grasp),
        joint_multipliers=eta,
        normal_multipliers=_array(cert, "normal_multipliers", (N,), grasp),
        squeeze_multiplier=real_scalar(
            "the certificate's squeeze_multiplier", cert.squeeze_multiplier
        ),
        torque_limits=_limits(cert, "torque_limits", eta.size, grasp),
        max_normal_force=_limits(cert, "max_normal_force", N, grasp),
        max_squeeze=real_scalar(
            "the certificate's max_squeeze", _no_limit_as_inf(cert.max_squeeze)
        ),
        bound=real_scalar("the certificate's bound", cert.bound),
    )


def _impossible(cert: LoadCertificate) -> str | None:
    """Why the certificate's own numbers cannot be a proof, or None."""
    arrays = (cert.wrench, cert.twist, cert.joint_multipliers, cert.normal_multipliers)
    if not all(np.all(np.isfinite(a)) for a in arrays) or not math.isfinite(
        cert.squeeze_multiplier
    ):
        return "its wrench, twist or multipliers are not finite"
    if np.any(cert.normal_multipliers < 0.0) or cert.squeeze_multiplier < 0.0:
        return "a bound's multiplier is negative"
    limits = np.concatenate(
        [cert.torque_limits, cert.max_normal_force, [cert.max_squeeze]]
    )
    if np.any(np.isnan(limits) | (limits < 0.0)):
        return "a limit it relies on is negative or NaN (no force meets it)"
    if not (math.isfinite(cert.bound) and cert.bound >= 0.0):
        return (
            f"its claimed bound {describe(cert.bound)} is not a finite number >= 0 "
            "(the "
            "grasp always holds α = 0 with no force)"
        )
    return None


def _jacobian_for(cert: LoadCertificate, grasp: Grasp, hand_jacobian):
    """The checked hand Jacobian when ``cert`` has joint multipliers, else None."""
    eta = cert.joint_multipliers
    if not (eta.size and np.any(eta != 0.0)):
        return None
    if hand_jacobian is None:
        raise InvalidOptionError(
            "this certificate has joint multipliers: checking it needs the "
            "hand_jacobian (τ = Jᵀ f)"
        )
    J = check_hand_jacobian(grasp, hand_jacobian)
    if J.shape[1] != eta.size:
        raise InvalidOptionError(
            f"hand_jacobian has {J.shape[1]} columns but the certificate has "
            f"{eta.size} joint multipliers"
        )
    return J


def _reach(cert: LoadCertificate, support, power: float, budget: float) -> float:
    """Total normal force (N) below which the proof holds (see ``force_reach``).

    A support ``eps > 0`` (round-off) weakens the proof to forces whose total
    normal force stays below ``(power - budget) / eps`` (a refutation) or
    ``power / eps`` per unit of α past the bound (a payload bound).
    """
    eps = float(np.maximum(support, 0.0).max(initial=0.0))
    if eps == 0.0:
        return math.inf
    return (power - budget) / eps if cert.kind == LOAD_NOT_HELD else power / eps


def certificate_force_reach(
    cert: LoadCertificate, grasp: Grasp, hand_jacobian=None
) -> float:
    """See :meth:`LoadCertificate.force_reach`."""
    cert = _read(cert, grasp)
    J = _jacobian_for(cert, grasp, hand_jacobian)
    power = -float(cert.twist @ cert.wrench)
    budget = _budget(cert)
    if _impossible(cert) is not None or not (power > 0.0 and math.isfinite(budget)):
        return 0.0
    support = _supports(cert, grasp, J)[0]
    return _reach(cert, support, power, budget)


def check_load_certificate(
    cert: LoadCertificate, grasp: Grasp, hand_jacobian, tol: float, problem=None
) -> CertificateCheck:
    """See :meth:`LoadCertificate.check`.

    ``problem``: the caller's ``wrench`` and limits, in place of the
    certificate's (a dict of some of those four fields).
    """
    tol = check_tolerance(tol)
    if problem:
        cert = replace(cert, **problem)
    cert = _read(cert, grasp)
    w, y = cert.wrench, cert.twist
    J = _jacobian_for(cert, grasp, hand_jacobian)
    why = _impossible(cert)
    if why is not None:
        return CertificateCheck(False, math.inf, 0.0, tol, f"nothing is proven: {why}")
    power = -float(y @ w)
    budget = _budget(cert)
    if not (power > 0.0 and math.isfinite(budget)):
        return CertificateCheck(
            False,
            math.inf,
            0.0,
            tol,
            f"the load delivers power {power:.3g} along y against a budget "
            f"{budget:.3g}: nothing is proven",
        )
    support, terms, rounding = _supports(cert, grasp, J)
    excess = np.maximum(support - rounding, 0.0)
    # Against the largest contact's terms: a support eps_i > 0 weakens the
    # bound by eps_i f_n,i over the power, and the budget is about that size.
    size = float(terms.max())
    if budget == 0.0:
        # No limit priced (a load no force balances): the proof is y alone,
        # and a support is measured against what y could make a contact
        # absorb, friction-scaled (y's share that no contact feels, a
        # torsion about two fingers' line, leaves the terms at round-off).
        mu = min([1.0] + [c.mu for c in grasp.contacts if c.mu > 0.0])
        size = max(
            size, mu * np.linalg.norm(grasp_matrix(grasp), 2) * float(np.linalg.norm(y))
        )
    if not excess.any():
        cone_violation = 0.0
    else:
        cone_violation = float(excess.max()) / size if size > 0.0 else math.inf
    bound = budget / power
    # Relative to the bound itself: at μ = 1e-12 a bound of 1e-12 claimed
    # for a true 1e-11 passed a test against max(1, bound).
    bound_violation = max(0.0, bound - cert.bound) / max(
        abs(cert.bound), bound, _TINY_BOUND
    )
    if cert.kind == LOAD_NOT_HELD and not bound < 1.0:
        bound_violation = math.inf
    violation = max(cone_violation, bound_violation)
    reach = _reach(cert, support, power, budget)
    if not math.isfinite(reach) or reach <= 0.0:  # no caveat, or nothing proven
        caveat = ""
    elif cert.kind == LOAD_NOT_HELD:
        caveat = f" (by any forces with Σ f_n < {reach:.3g} N)"
    else:
        caveat = f" (by forces with Σ f_n < {reach:.3g} N per unit α − bound)"
    if cert.kind == LOAD_NOT_HELD:
        slack = (power - budget) / (abs(power) + budget)
    else:
        slack = (cert.bound - bound) / max(1.0, abs(cert.bound))
    detail = (
        f"max over the {cert.cones} cones of a_iᵀ f_i (f_n = 1) and the power "
        f"budget: α·w cannot be held for α > {bound:.6g}{caveat}; "
        f"{_assumed(cert, bool(problem))}"
    )
    return CertificateCheck.evaluated(violation, slack, tol, detail)


def _assumed(cert: LoadCertificate, given: bool) -> str:
    """The load and limits a check proved its claim about, for its detail line."""

    def show(a) -> str:
        a = np.atleast_1d(a)
        if a.size and np.all(a == a[0]):
            return f"{a[0]:.4g}" + (f" (x{a.size})" if a.size > 1 else "")
        return "[" + ", ".join(f"{x:.4g}" for x in a) + "]"

    whose = (
        "the caller's where given, else the certificate's"
        if given
        else ("the certificate's own")
    )
    return (
        f"load and limits ({whose}): w = {show(cert.wrench)}, "
        f"τ_max = {show(cert.torque_limits) if cert.torque_limits.size else 'none'}, "
        f"f_max = {show(cert.max_normal_force)}, s_max = {cert.max_squeeze:.4g}"
    )
