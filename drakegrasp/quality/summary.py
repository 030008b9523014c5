r"""All quality metrics of a grasp at once, and LP2's ``d*`` as a metric."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.deprecation import warn_deprecated
from drakegrasp.core.grasp import Grasp, check_hand_jacobian
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import DEFAULT_NUM_GENERATORS, DEFAULT_TOL
from drakegrasp.core.validation import check_flag
from drakegrasp.quality._common import _check_grasp, _torque_scale
from drakegrasp.quality.epsilon import _epsilons
from drakegrasp.quality.indices import (
    grasp_singular_values,
    hand_object_singular_values,
)

__all__ = ["GraspQuality", "grasp_quality", "lp2_d_star", "lp2_margin"]


@checked_call
def lp2_d_star(
    grasp: Grasp,
    *,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    tol: float = DEFAULT_TOL,
) -> float:
    r"""The optimal ``d*`` of LP2 (frictional force closure) as a quality metric.

    Parameters
    ----------
    grasp : Grasp
    num_generators : int, optional
        Generators ``n_g`` of each spatial Coulomb cone (default 8).
    tol : float, optional
        Passed to :func:`~drakegrasp.closure.verdicts.force_closure` (it only
        affects the verdict there, not ``d*``).

    Returns
    -------
    float
        ``d*`` of

        .. math:: \max d \;\text{s.t.}\; G f = 0,\; F f - \mathbf 1 d \ge 0,\;
                  d \ge 0,\; \textstyle\sum_i f_{n,i} \le N

        (``F`` with unit facet rows): the largest distance by which a
        self-balanced set of contact forces, with mean normal force at most 1,
        can stay inside every cone facet.  Dimensionless (newtons per newton of
        normal force).  It is geometry, not load: it does not change with the
        object's weight or the motors (for those see
        :func:`~drakegrasp.grasp_forces` and :func:`~drakegrasp.max_load`).
        It says nothing about the rank of ``G``: force closure
        needs ``rank(G)`` full as well (see
        :func:`~drakegrasp.closure.verdicts.force_closure`).
    """
    from drakegrasp.closure.verdicts import force_closure  # the closure programs' owner

    _check_grasp(grasp)
    result = force_closure(grasp, num_generators=num_generators, tol=tol)
    d = float(result.d_star)
    return d if math.isfinite(d) else 0.0


@checked_call
def lp2_margin(
    grasp: Grasp,
    *,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    tol: float = DEFAULT_TOL,
) -> float:
    """Deprecated name of :func:`lp2_d_star` (it returns ``d*``, not a margin).

    Elsewhere a margin is ``(d* - tol) / tol`` (``ClosureResult.margin``).
    """
    warn_deprecated(
        "lp2_margin is deprecated; use lp2_d_star (it returns LP2's d*, while a "
        "result's margin is (d* - tol) / tol)"
    )
    return lp2_d_star(grasp, num_generators=num_generators, tol=tol)


@checked_call
@dataclass(frozen=True)
class GraspQuality:
    """All quality metrics of one grasp (see the functions named in each field).

    Attributes
    ----------
    ferrari_canny_l1 : float
        :func:`ferrari_canny` with ``norm="L1"``.
    ferrari_canny_linf : float or None
        :func:`ferrari_canny` with ``norm="Linf"`` (None when not computed: not
        asked for, or too costly to compute, see :func:`grasp_quality`).
    lp2_d_star : float
        :func:`lp2_d_star`, LP2's ``d*`` (``lp2_margin``: its deprecated name).
    is_force_closure : bool
        Frictional force closure on the polyhedral cones: ``rank(G)`` full and
        ``d* > tol`` (and, with a hand Jacobian, LP3 passes).
    singular_values : (D,) float
        :func:`grasp_singular_values` of ``S G``.
    min_singular_value, isotropy, wrench_ellipsoid_volume : float
        :func:`min_singular_value`, :func:`isotropy`,
        :func:`wrench_ellipsoid_volume`.
    hand_singular_values : (D,) float or None
        :func:`hand_object_singular_values` (None without a hand Jacobian).
    distance_to_singularity, uniformity_of_transformation, manipulability_volume
        : float or None
        The indices of ``H`` (None without a hand Jacobian).
    num_generators : int
        Generators of each spatial Coulomb cone.
    torque_scale : float
        ``b_s`` (metres) dividing the moments in ε and the singular values.
    tol : float
        Threshold on ``d*`` of the force-closure verdict.
    """

    ferrari_canny_l1: float
    ferrari_canny_linf: float | None
    lp2_d_star: float
    is_force_closure: bool
    singular_values: np.ndarray
    min_singular_value: float
    isotropy: float
    wrench_ellipsoid_volume: float
    num_generators: int
    torque_scale: float
    tol: float
    hand_singular_values: np.ndarray | None = field(default=None)
    distance_to_singularity: float | None = field(default=None)
    uniformity_of_transformation: float | None = field(default=None)
    manipulability_volume: float | None = field(default=None)

    @property
    def lp2_margin(self) -> float:
        """Deprecated name of :attr:`lp2_d_star`."""
        warn_deprecated("GraspQuality.lp2_margin is deprecated; use lp2_d_star")
        return self.lp2_d_star

    def to_dict(self) -> dict:
        """JSON-ready dictionary (non-finite numbers become ``None``)."""
        return {f.name: jsonable(getattr(self, f.name)) for f in fields(self)}

    def __str__(self) -> str:
        def fmt(x):
            return "n/a" if x is None else f"{x:.6g}"

        lines = [
            f"grasp quality ({self.num_generators} generators, torque scale "
            f"{self.torque_scale:g} m)",
            f"  force closure: {'YES' if self.is_force_closure else 'no'}, "
            f"LP2 d* = {self.lp2_d_star:.6g}",
            f"  Ferrari-Canny eps: L1 {fmt(self.ferrari_canny_l1)}, "
            f"Linf {fmt(self.ferrari_canny_linf)}",
            f"  G: sigma_min {self.min_singular_value:.6g}, isotropy "
            f"{self.isotropy:.6g}, ellipsoid volume {self.wrench_ellipsoid_volume:.6g}",
        ]
        if self.hand_singular_values is not None:
            lines.append(
                f"  H: sigma_min {fmt(self.distance_to_singularity)}, uniformity "
                f"{fmt(self.uniformity_of_transformation)}, manipulability volume "
                f"{fmt(self.manipulability_volume)}"
            )
        return "\n".join(lines)


@checked_call
def grasp_quality(
    grasp: Grasp,
    *,
    hand_jacobian: np.ndarray | None = None,
    num_generators: int = DEFAULT_NUM_GENERATORS,
    torque_scale: float | None = None,
    tol: float = DEFAULT_TOL,
    linf: bool | None = None,
) -> GraspQuality:
    """Compute every quality metric of a grasp.

    Parameters
    ----------
    grasp : Grasp
    hand_jacobian : (M, n_v) float, optional
        Hand Jacobian ``J`` (rows in ``G``'s column order); enables the indices
        of ``H = (G^+)ᵀ J`` and the LP3 part of the force-closure verdict.
    num_generators : int, optional
        Generators of each spatial Coulomb cone (default 8).
    torque_scale : float, optional
        ``b_s`` (metres) dividing moments; default the grasp's characteristic
        length, ``1.0`` for none.
        An explicit length must be in ``[2.2e-308, 1e30]`` m with the grasp's
        extent (the largest distance from ``p`` to a contact) over it in
        ``[1e-4, 1e12]`` (any length when every contact is at ``p``), else
        :class:`~drakegrasp.InvalidOptionError`.
    tol : float, optional
        Threshold on LP2's ``d*`` for the force-closure verdict.
    linf : bool or None, optional
        Whether to compute the L∞ Ferrari–Canny ε.  None (default): when it is
        cheap, i.e. for planar grasps and spatial grasps with at most three
        contacts (20–60 ms for three hard fingers with 8 generators, against
        about 1 s for four), and when its candidate facet normals stay within
        :data:`~drakegrasp.quality.epsilon.LINF_MAX_CANDIDATES`: otherwise
        ``ferrari_canny_linf`` is None.  Their count is estimated from
        ``num_generators`` and the contact models before anything is built
        (three hard fingers with 128 generators, soft fingers with 32: skipped
        at once); the second pass that symmetric grasps need is counted after
        the first (three equator fingers with 64 generators: skipped after
        0.1 s).  A grasp not in force closure has ``ε_∞ = 0`` at any cost, as
        ``ε_1 = 0``.  True: computed, and a grasp past that limit is refused
        (the same :class:`~drakegrasp.InvalidOptionError` as
        :func:`ferrari_canny` with ``norm="Linf"``; from the models, before
        the L1 hull, unless the grasp is provably out of force closure).
        False: not computed.

    Returns
    -------
    GraspQuality

    Raises
    ------
    InvalidOptionError
        A bad option (``linf``, ``torque_scale``, ``num_generators``, ``tol``),
        or ``linf=True`` on a grasp whose L∞ ε needs more than
        ``LINF_MAX_CANDIDATES`` candidate normals; either ε of a grasp with
        more than :data:`~drakegrasp.core.tolerances.L1_MAX_POINTS` primitive
        wrenches.
    """
    from drakegrasp.closure.verdicts import force_closure  # the closure programs' owner

    _check_grasp(grasp)
    if linf is not None:
        linf = check_flag("linf", linf)
    b = _torque_scale(grasp, torque_scale)
    J = None if hand_jacobian is None else check_hand_jacobian(grasp, hand_jacobian)
    closure = force_closure(
        grasp, hand_jacobian=J, num_generators=num_generators, tol=tol
    )
    d_star = float(closure.d_star)
    if linf is None:  # when cheap: None skips it where it is too costly
        linf = None if grasp.planar or grasp.num_contacts <= 3 else False
    # The caller's torque_scale (None: the characteristic length, unchecked,
    # as every metric takes it) is passed on, and gives b in each metric.
    eps_1, eps_inf = _epsilons(
        grasp, num_generators=num_generators, torque_scale=torque_scale, linf=linf
    )
    s = grasp_singular_values(grasp, torque_scale=torque_scale)
    hand = {}
    if J is not None:
        sh = hand_object_singular_values(grasp, J, torque_scale=torque_scale)
        hand = {
            "hand_singular_values": sh,
            "distance_to_singularity": float(sh[-1]),
            "uniformity_of_transformation": (
                float(sh[0] / sh[-1]) if sh[-1] > 0 else math.inf
            ),
            "manipulability_volume": float(np.prod(sh)),
        }
    return GraspQuality(
        ferrari_canny_l1=eps_1,
        ferrari_canny_linf=eps_inf,
        lp2_d_star=d_star if math.isfinite(d_star) else 0.0,
        is_force_closure=bool(closure.is_closure),
        singular_values=s,
        min_singular_value=float(s[-1]),
        isotropy=float(s[-1] / s[0]) if s[0] > 0 else 0.0,
        wrench_ellipsoid_volume=float(np.prod(s)),
        num_generators=int(num_generators),
        torque_scale=b,
        tol=float(tol),
        **hand,
    )
