"""Dense linear constraints for ``MathematicalProgram`` without importing scipy.sparse.

``MathematicalProgram.AddLinearConstraint(A, lb, ub, vars)`` and
``AddLinearEqualityConstraint(Aeq, beq, vars)`` have overloads for sparse and
dense ``A``; resolving them makes pybind11 import ``scipy.sparse`` the first
time (70–90 ms on a quiet machine, most of a first ``analyze_grasp``).
Constructing the ``LinearConstraint`` / ``LinearEqualityConstraint`` from a
dense array and binding it with ``AddConstraint`` adds exactly the same
constraint (same rows, same bounds, same solver attribute) and never touches
the sparse caster.  Core layer: ``pydrake.solvers`` and numpy only.

The Lorentz-cone rows of an exact spatial friction cone with a margin
(:func:`exact_cone_rows`), and the loop that puts every contact's force in its
cone (:func:`add_contact_cones`), live here too, so that the exact
force-closure program and the grasp-force and payload programs write them once.
"""

from __future__ import annotations

import numpy as np
from pydrake.solvers import LinearConstraint, LinearEqualityConstraint

__all__ = [
    "EXACT_CONE_COMPONENTS",
    "add_contact_cones",
    "add_linear_constraint",
    "add_linear_equality_constraint",
    "exact_cone_rows",
]

EXACT_CONE_COMPONENTS = ((0, 1, 2), (0, 1, 2, 3))
"""Components of the cones written exactly as Lorentz cones (spatial hard, soft)."""


def add_linear_constraint(prog, A, lb, ub, x):
    """``lb <= A x <= ub`` with dense ``A`` (m, n); returns the binding."""
    A = np.atleast_2d(np.asarray(A, dtype=float))
    lb = np.asarray(lb, dtype=float).reshape(-1)
    ub = np.asarray(ub, dtype=float).reshape(-1)
    return prog.AddConstraint(LinearConstraint(A, lb, ub), np.asarray(x).reshape(-1))


def add_linear_equality_constraint(prog, A, b, x):
    """``A x = b`` with dense ``A`` (m, n); returns the binding."""
    A = np.atleast_2d(np.asarray(A, dtype=float))
    b = np.asarray(b, dtype=float).reshape(-1)
    return prog.AddConstraint(LinearEqualityConstraint(A, b), np.asarray(x).reshape(-1))


def exact_cone_rows(contact, scales: np.ndarray, b: float) -> list[np.ndarray]:
    r"""Lorentz-cone rows of a spatial contact's exact friction cone with a margin.

    For each sign ``σ`` (0 for a hard finger, ``±1`` for a soft finger),
    ``z = A [f_i; d]`` in the Lorentz cone (``z_0 >= ‖z_{1:3}‖``) says

    .. math:: \|f_t\| \le \mu (f_n - \sigma m_n / (b \nu)) - \sqrt{1 + \mu^2}\, d ,

    the hard-cone margin ``d`` of the normal force left after torsion (as the
    polyhedral soft rows of :func:`~drakegrasp.core.friction_cone.soft_finger_facets`),
    divided by ``sqrt(1 + μ²)``: coefficients at most 1, so ``μ = 1e12`` does
    not make Clarabel stall or SCS answer inaccurately.

    Parameters
    ----------
    contact : Contact
        Its ``mu`` and ``torsional_friction`` (``ν``).
    scales : (3,) or (4,) float
        The contact's entries of ``ConeLayout.scales``: the variables are
        ``f_i / scales`` (a soft finger's ``m_n = scales[3] x_3``; the
        tangential entries are 1 except in a friction-scaled load problem).
    b : float
        Characteristic length, metres.

    Returns
    -------
    list of (3, k + 1) float
        One ``A`` per sign; drop the last column for ``d = 0``.
    """
    k = len(scales)
    mu = contact.mu
    rows = []
    for sign in [0.0] if k == 3 else [1.0, -1.0]:
        A = np.zeros((3, k + 1))
        A[0, 0] = mu
        if k == 4:
            A[0, 3] = -sign * mu * scales[3] / (b * contact.torsional_friction)
        A[0, -1] = -np.sqrt(1.0 + mu * mu)
        A[1, 1] = A[2, 2] = 1.0
        # A tangential variable may be scaled too (``f_t = scales x_t``, see
        # LoadProblem.friction_scaled): at μ = 1e12 the row is then μ [x_n, x_t]
        # instead of [μ x_n, x_t], whose x_t coefficient a solver reads as 0.
        A[1, 1] *= scales[1]
        A[2, 2] *= scales[2]
        A /= np.hypot(1.0, mu)
        # At μ = 1e-12 with x_t scaled too the row is μ [x_n, x_t]: to 1.
        size = np.max(np.abs(A[:, :k]))
        if 0.0 < size < 0.5:
            A /= size
        rows.append(A)
    return rows


def add_contact_cones(
    prog, contacts, layout, x, b: float, *, d=None, exact: bool = True
) -> None:
    """Each contact's scaled force ``x_i`` in its friction cone.

    With ``d``, at distance ``d`` inside it (``facets x_i >= d``, or the Lorentz
    rows of :func:`exact_cone_rows` with their margin column); without, in the
    closed cone.  With ``exact``, a spatial contact with friction (components
    in :data:`EXACT_CONE_COMPONENTS`) gets Lorentz cones; every other cone,
    and every cone when ``exact`` is False, its polyhedral facets (exact for a
    planar or frictionless contact).

    Parameters
    ----------
    prog : MathematicalProgram
    contacts : sequence of Contact
        The grasp's contacts, in the order of ``layout.cones``.
    layout : ConeLayout
        Its ``cones`` (facets and components), ``scales`` and
        ``normal_positions``: contact ``i``'s variables are
        ``x[normal_positions[i] : normal_positions[i + 1]]``, the force
        components ``scales * x``.
    x : (m,) Variable
        The force variables, ``m = len(layout.columns)``.
    b : float
        Characteristic length, metres.
    d : Variable, optional
        The margin.
    exact : bool
        Lorentz cones where the cone is spatial with friction.
    """
    starts = list(layout.normal_positions) + [len(layout.columns)]
    for i, (contact, cone) in enumerate(zip(contacts, layout.cones, strict=True)):
        xi = x[starts[i] : starts[i + 1]]
        scale = layout.scales[starts[i] : starts[i + 1]]
        if not (exact and cone.components in EXACT_CONE_COMPONENTS):
            F = cone.facets * scale
            if d is None:
                add_linear_constraint(
                    prog, F, np.zeros(len(F)), np.full(len(F), np.inf), xi
                )
            else:
                add_linear_constraint(
                    prog,
                    np.hstack([F, -np.ones((len(F), 1))]),
                    np.zeros(len(F)),
                    np.full(len(F), np.inf),
                    np.append(xi, d),
                )
            continue
        for A in exact_cone_rows(contact, scale, b):
            if d is None:
                prog.AddLorentzConeConstraint(A[:, :-1], np.zeros(3), xi)
            else:
                prog.AddLorentzConeConstraint(A, np.zeros(3), np.append(xi, d))
