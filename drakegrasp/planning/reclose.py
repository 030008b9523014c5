r"""Robustness to the object's pose error: the jaws close again on the moved object.

A planned grasp is executed on an object whose pose is known to a few
millimetres.  Each perturbed copy of a grasp moves the object by a rigid
motion :math:`\delta` relative to the hand and closes the jaws again along
their axis, as the gripper would; the copy's contacts are where the pads now
touch, with the object's own normals there, and the copy counts as robust when
they are force closure (with a perturbed μ too).

**The motion.**  About the grasp centre ``c`` (midway between the fingers'
contact centroids), in the object frame O:

.. math::

    x \mapsto R_a(\theta)\,(x - c) + c + t, \qquad
    t \sim \mathcal N(0, \sigma_p^2 I_3), \quad
    \theta \sim \mathcal N(0, \sigma_\theta^2),

with :math:`R_a(\theta)` a rotation about the grasp axis ``a``.  Tilts about
the other axes are left out on purpose: the object is free between the pads,
and the squeeze turns it until it seats on them (a flat face comes flat onto a
flat pad; a cylinder's line of contact onto the pad), which a rigid re-closing
would miss (it would report one corner touching).  A rotation about ``a`` keeps
the pads' planes and moves the contacts within them.

**The re-closing.**  A finger's *probes* are its contact points of the
unperturbed grasp (the parts of its pad that touch).  The hand moves by
:math:`\delta^{-1}` relative to the object; each probe then travels along the
finger's closing direction ``d_f`` (``+a`` for finger 0, ``-a`` for finger 1)
until it meets the surface: along the line through the probe, the first
surface point met coming from behind, given by the surface's chord of the
reversed line (its last exit), with the outward normal there.  The finger, a
rigid pad, advances by the smallest probe travel; its contacts are the probes
within ``tol`` of that travel, at their surface points with the inward
normals.  A probe whose line misses the object (the pad slid past an edge)
touches nothing; a finger with no touching probe loses the grasp.  Parts of a
pad that did not touch in the unperturbed grasp are not probed, so a copy
that slid off an edge may lose contacts a larger pad would have kept: the
estimate errs towards fewer contacts.

Everything is vectorised over all copies and probes (one chord query); the
copies' verdicts are then the batch engine's LP2 (verdicts only:
:func:`drakegrasp.batch.run.chunk.force_verdicts`), grouped by their (ragged)
contact counts, except for copies with too few contacts to be force closure
at all (:data:`NEVER_CLOSURE`).
"""

from __future__ import annotations

import numpy as np

from drakegrasp.batch.run.chunk import force_verdicts
from drakegrasp.batch.run.workers import check_workers
from drakegrasp.core.deprecation import keyword_only, renamed_keyword
from drakegrasp.core.linalg import rotations_about
from drakegrasp.core.validation import (
    COEFFICIENT_MAX,
    COEFFICIENT_MIN,
    check_length,
    check_positions,
)
from drakegrasp.errors import InvalidGraspError, InvalidOptionError
from drakegrasp.planning.checks import (
    checked_directions,
    checked_fingers,
    checked_friction,
    checked_noise,
    checked_points,
    checked_rng,
    checked_samples,
)

__all__ = ["NEVER_CLOSURE", "reclosed_copies", "reclosed_robustness"]

NEVER_CLOSURE = {"hard_finger": 2, "frictionless": 6}
"""Contacts at most this many are never force closure in space, by model: two
hard fingers' forces all meet the line through their points, so no moment
about it is resisted; six normals cannot positively span the six wrench
dimensions.  Such re-closed copies count as slipping without an LP (a sphere
between two pads leaves many with one contact per pad; a cylinder's side
touched by a flat pad gives two, the ends of the line)."""


def perturbed_mu(mus: np.ndarray) -> np.ndarray:
    """Perturbed friction coefficients kept in the range the batch engine takes.

    A copy's ``μ`` is the user's (checked) times ``max(0, 1 + σ_μ ξ)``; a
    positive product below ``COEFFICIENT_MIN`` or above ``COEFFICIENT_MAX``
    (a user's ``μ`` near either bound) is moved to the bound, 0 stays 0, so a
    valid ``mu`` never gets a copy refused by the engine.
    """
    return np.where(mus > 0.0, np.clip(mus, COEFFICIENT_MIN, COEFFICIENT_MAX), 0.0)


def reclosed_copies(
    surface,
    positions: np.ndarray,
    fingers: np.ndarray,
    axes: np.ndarray,
    translations: np.ndarray,
    angles: np.ndarray,
    *,
    tol: float,
):
    """The contacts of grasps re-closed on moved objects (module docstring).

    Parameters
    ----------
    surface : ObjectSurface
        The object's surface in O (``chord(p_O, d_O)``).
    positions : (M, N, 3) float
        Each copy's probes: the unperturbed grasp's contact points, O, metres.
    fingers : (M, N) int
        Finger (0 or 1) of each probe; any other value is not probed.
    axes : (M, 3) float
        Grasp axis ``a`` in O (from finger 0 towards finger 1), unit.
    translations : (M, 3) float
        ``t`` of each copy's motion, O, metres.
    angles : (M,) float
        ``θ`` about ``a``, radians.
    tol : float
        Probes within ``tol`` (m) of a finger's first touch touch too.

    Returns
    -------
    touch : (M, N) bool
        Which probes touch after the re-closing.
    p_OC : (M, N, 3) float
        Their contact points on the moved object, in the object's own frame
        (the object moved back; NaN where not touching).
    nhat_O : (M, N, 3) float
        Inward unit normals there (NaN where not touching).
    ok : (M,) bool
        Both fingers touch.
    """
    M, N, _ = positions.shape
    fingers = np.asarray(fingers)
    centre = np.zeros((M, 3))
    for f in (0, 1):
        mask = (fingers == f)[..., None]
        centre += (positions * mask).sum(1) / np.maximum(mask.sum(1), 1)
    centre /= 2.0
    R = rotations_about(axes, angles)
    # the object moved by δ; in its frame the hand moved by δ⁻¹:
    # q = Rᵀ (p - c - t) + c, closing directions unchanged (R fixes a)
    q = np.einsum("mji,mnj->mni", R, positions - (centre + translations)[:, None])
    q += centre[:, None]
    sign = np.where(fingers == 0, 1.0, -1.0)[..., None]
    d = sign * axes[:, None, :]  # (M, N, 3) closing direction per probe
    _, t_out, n_out = surface.chord(q.reshape(-1, 3), -d.reshape(-1, 3))
    travel = (-t_out).reshape(M, N)  # along d from the probe to the surface
    travel[~np.isin(fingers, (0, 1))] = np.nan
    touch = np.zeros((M, N), bool)
    ok = np.ones(M, bool)
    for f in (0, 1):
        mine = (fingers == f) & np.isfinite(travel)
        first = np.min(np.where(mine, travel, np.inf), axis=1)
        ok &= np.isfinite(first)
        touch |= mine & (travel <= first[:, None] + tol)
    hit = q + np.nan_to_num(travel)[..., None] * d  # on the surface, O
    inward = -n_out.reshape(M, N, 3)
    p_OC = np.where(touch[..., None], hit, np.nan)
    nhat = np.where(touch[..., None], inward, np.nan)
    return touch, p_OC, nhat, ok


@keyword_only("mu", after=4)
@renamed_keyword("model", "contact_model")
def reclosed_robustness(
    surface,
    positions: np.ndarray,
    fingers: np.ndarray,
    axes: np.ndarray,
    *,
    mu: float,
    samples: int,
    rng: np.random.Generator,
    position: float,
    angle_deg: float,
    friction: float,
    tol: float,
    contact_model: str,
    torsional_friction,
    workers: int | None,
    reference: np.ndarray | None = None,
) -> np.ndarray:
    """(K,) fraction of ``samples`` re-closed copies of each grasp in force closure.

    Every argument is checked first, before any draw from ``rng``; a bad one
    raises a :class:`~drakegrasp.GraspError` naming it.

    Parameters
    ----------
    surface : ObjectSurface
        The object's surface in O, anything with ``chord(p_O, d_O)``
        (:class:`~drakegrasp.planning.surface.ObjectSurface`, a cloud's
        :class:`~drakegrasp.planning.cloud.FittedCloud`).
    positions : (K, N, 3) float
        Contacts of ``K >= 0`` grasps of ``N >= 1`` contacts (O, metres,
        finite): each finger's probes.
    fingers : (K, N) int
        Finger of each contact: 0 and 1 are probed, any other label in
        ``[0, 63]`` (a palm) is not.
    axes : (K, 3) float
        Grasp axes in O, from finger 0 towards finger 1; finite, non-zero,
        normalised here.
    mu : float
        Nominal friction coefficient: 0 or in ``[1e-12, 1e12]``
        (:mod:`drakegrasp.core.validation`).
    samples : int
        Copies per grasp, an integer ``>= 0`` (0: robustness 0); the copies'
        points (``K * samples * N * 3`` floats) at most
        :data:`~drakegrasp.planning.checks.MAX_COPY_BYTES`.
    rng : numpy.random.Generator
        Draws the motions and μ (``numpy.random.default_rng(seed)``).
    position, angle_deg, friction : float
        σ_p (metres), σ_θ (degrees, about the axis), σ_μ (relative); each in
        ``[0, 1e6]`` (:data:`~drakegrasp.planning.checks.NOISE_MAX`: far above
        any pose or friction error, they keep the re-closing's arithmetic
        finite).
    tol : float
        Metres, a length ``> 0``: probes within ``tol`` of a finger's first
        touch touch too (the planner's distance tolerance).
    contact_model, torsional_friction, workers
        As :func:`~drakegrasp.batch.batch_force_closure`.
    reference : (3,) float, optional
        The point of O that moments are taken about (the object's centre of
        mass; default O's origin): a soft finger's torsion scale ``b`` is the
        farthest contact from it.

    Returns
    -------
    (K,) float
        Fraction in ``[0, 1]`` of each grasp's copies in force closure.

    Raises
    ------
    GraspError
        Naming a bad argument, among them a σ out of its range
        (:func:`~drakegrasp.planning.checks.checked_noise`).
    """
    if not callable(getattr(surface, "chord", None)):
        raise InvalidOptionError(
            "surface must have chord(p_O, d_O) (an ObjectSurface or a "
            f"FittedCloud), got {type(surface).__name__}"
        )
    positions = checked_points(positions)
    K, N, _ = positions.shape
    fingers = checked_fingers(fingers, (K, N))
    axes = checked_directions("axes", axes, count=K)
    mu, contact_model, torsional_friction = checked_friction(
        mu, contact_model, torsional_friction
    )
    samples = checked_samples(samples, K, N)
    rng = checked_rng(rng)
    sigma = {"position": position, "angle_deg": angle_deg, "friction": friction}
    position, angle_deg, friction = checked_noise(sigma).values()
    tol = check_length("tol", tol, error=InvalidOptionError)
    check_workers(workers)
    if reference is None:
        reference = np.zeros(3)
    else:
        reference = check_positions("reference", reference, error=InvalidGraspError)
        if reference.shape != (3,):
            raise InvalidGraspError(
                f"reference must be a point (3,) of O, got shape {reference.shape}"
            )
    if samples == 0 or K == 0:
        return np.zeros(K)
    M = K * samples
    P = np.repeat(positions, samples, axis=0)
    F = np.repeat(fingers, samples, axis=0)
    A = np.repeat(axes, samples, axis=0)
    t = position * rng.standard_normal((M, 3))
    theta = np.radians(angle_deg) * rng.standard_normal(M)
    mus = perturbed_mu(mu * np.maximum(0.0, 1.0 + friction * rng.standard_normal(M)))
    touch, p_OC, nhat, ok = reclosed_copies(surface, P, F, A, t, theta, tol=tol)
    held = np.zeros(M, bool)
    counts = np.where(ok, touch.sum(axis=1), 0)
    never = NEVER_CLOSURE.get(contact_model, 0)
    for n in np.unique(counts[counts > never]):  # the others need no LP
        rows = np.flatnonzero(counts == n)
        order = np.argsort(~touch[rows], axis=1, kind="stable")[:, :n]
        take = rows[:, None], order
        # verdicts only (each LP stops once its verdict is proved): those of
        # batch_force_closure, at a fraction of the cost
        held[rows] = force_verdicts(
            p_OC[take] - reference,
            nhat[take],
            mu=mus[rows, None],  # one μ per copy (K, 1): never read per contact
            contact_model=contact_model,
            torsional_friction=torsional_friction,
            workers=workers,
        )
    return held.reshape(K, samples).mean(axis=1)
