r"""Ranking planned grasps: verdicts, ε on one scale, robustness and the score.

Every measure runs in the batch engine (:mod:`drakegrasp.batch`), on the
candidates grouped by their number of contacts (the engine takes ``K`` grasps
of ``N`` contacts each; a WSG finger seats one to four tip spheres, so the
counts are ragged).  Both routes of the planner rank here:
:func:`rank_candidates` the parallel jaw's candidates, :func:`rank_multifinger`
a multi-finger hand's (its capacity averaged over a cloud contact's fan,
:func:`~drakegrasp.planning.weight.fan_capacity`).

**ε on one scale.**  The Ferrari–Canny L1 ε divides moments by a length; by
default each grasp uses its own (its largest contact distance), which makes a
shallow grasp look better than a centred one.  Here every candidate of an
object uses the same ``torque_scale`` (the radius of a ball about the object's
origin holding its collision geometry), so ε compares across candidates.

**Robustness** is the fraction of ``S`` perturbed copies of a grasp that stay
force closure (LP2).  On an object body, a copy moves the object by a sampled
pose error and closes the jaws on it again
(:mod:`drakegrasp.planning.reclose`), and scales μ as below.  On a point
cloud (no surface to close on), a copy moves each finger's contacts rigidly,
as a misplaced pad would: a rotation by an angle drawn from
:math:`\mathcal N(0, \sigma_\theta^2)` about a uniformly random axis through the
finger's contact centroid, then a translation drawn from
:math:`\mathcal N(0, \sigma_p^2 I_3)`; and it scales μ by
:math:`\max(0, 1 + \sigma_\mu \xi)`, :math:`\xi \sim \mathcal N(0, 1)`, one
draw per copy.  A rigid motion of the whole grasp changes no verdict, so the
noise is per finger: it models the object's pose error and the fingers'
placement error relative to each other.  Only each copy's verdict counts, so
both routes solve their copies' LPs in verdict-only mode
(:func:`drakegrasp.batch.run.chunk.force_verdicts`): each LP stops once its
verdict is proved, and the verdicts are those of
:func:`~drakegrasp.batch.batch_force_closure`.

**Score** :math:`= \rho \cdot \alpha_{\min}` (robustness times the weight
capacity of :mod:`drakegrasp.planning.weight`: the object's weight, per newton
of squeeze on each finger, that the grasp holds in the worst of 14 directions).
A ball-shaped measure such as ε is set by a grasp's weakest wrench direction,
which for two pads is the torsion about the grasp axis, the same for every
placement of the pads; the weight capacity asks for the wrenches that gravity
and shaking apply, and falls as the pads move away from the centre of mass
(tested against Drake simulations in ``tests/planning/test_shake.py``).  The
weight capacity is computed for every force-closure candidate with
:math:`\rho > 0` (the others score 0 whatever their capacity, which is left
NaN), or, with ``weight_check``, for that many, the best by
:math:`\varepsilon \rho`; the others score 0.  Candidates are
ordered by score, then :math:`\varepsilon \rho`, ``d*`` and the sample index,
so a ranking is reproducible; scores, :math:`\varepsilon \rho` and ``d*`` are
compared to :data:`TIE_DECIMALS` decimals (:func:`tie_key`), so exact ties (symmetric
grasps) are broken by the next key and not by rounding.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from drakegrasp.batch import batch_epsilon_l1, batch_force_closure
from drakegrasp.batch.run.chunk import force_verdicts
from drakegrasp.batch.run.workers import check_workers
from drakegrasp.closure.verdicts import force_closure
from drakegrasp.core.deprecation import keyword_only, renamed_keyword
from drakegrasp.core.linalg import rotations_about
from drakegrasp.core.validation import (
    check_coefficient,
    check_length,
    describe,
    integer_or_none,
)
from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning.approach import MultiFingerHand
from drakegrasp.planning.candidates import GraspCandidate
from drakegrasp.planning.checks import (
    MAX_FINGER_LABEL,
    checked_contacts,
    checked_fingers,
    checked_friction,
    checked_noise,
    checked_rng,
    checked_samples,
)
from drakegrasp.planning.needed import needed_for
from drakegrasp.planning.reclose import perturbed_mu, reclosed_robustness
from drakegrasp.planning.weight import fan_capacity, weight_capacity
from drakegrasp.plant.validation import scoped_name

__all__ = [
    "DEFAULT_NOISE",
    "TIE_DECIMALS",
    "group_by_count",
    "grouped_verdicts",
    "perturbed_copies",
    "rank_candidates",
    "rank_multifinger",
    "rank_order",
    "ranked_candidates",
    "robustness",
    "tie_key",
    "verdicts",
]

DEFAULT_NOISE = {"position": 2e-3, "angle_deg": 3.0, "friction": 0.1}
"""Default robustness noise: σ_p (m), σ_θ (degrees), σ_μ (relative)."""


def _checked_groups(groups, fingers: np.ndarray, *, empty: bool) -> tuple[int, ...]:
    """``groups`` of :func:`perturbed_copies`: distinct finger labels of ``fingers``.

    Each an integer in ``[0, MAX_FINGER_LABEL]`` (a label outside matches no
    contact: a slip of the caller's), none twice (its contacts would move
    twice a copy, their noise doubled).  With ``K >= 1`` grasps, some label
    must be carried by some contact of the (checked, (K, N)) ``fingers``:
    else no contact would move, and the robustness would read the
    unperturbed grasp's (1.0 for a force closure grasp without μ noise).  A
    label that only some batches carry is taken (the multi-finger planner
    passes every finger of its hand, and a batch may lack one).  ``empty``:
    an empty ``groups`` is taken (no contact moves: ``perturbed_copies``,
    whose copies show it); else refused.  Nothing is drawn here.
    """
    try:
        labels = tuple(integer_or_none(g) for g in groups)
    except TypeError:
        labels = (None,)
    if isinstance(groups, (str, bytes)) or None in labels:
        raise InvalidOptionError(
            "groups must be a sequence of integer finger labels, got "
            f"{describe(groups)}"
        )
    for g in labels:
        if not 0 <= g <= MAX_FINGER_LABEL:
            raise InvalidOptionError(
                f"groups holds {g}; a finger label is an integer in "
                f"[0, {MAX_FINGER_LABEL}] (drakegrasp.planning.checks.MAX_FINGER_LABEL)"
            )
    if len(set(labels)) < len(labels):
        twice = next(g for g in labels if labels.count(g) > 1)
        raise InvalidOptionError(
            f"groups names finger {twice} more than once; each finger's contacts "
            "move once a copy"
        )
    present = np.unique(fingers).tolist()
    if not labels and not empty:
        raise InvalidOptionError(
            "groups is empty: no contact would move, and the robustness would "
            "be that of the unperturbed grasp; give the labels of the fingers "
            f"to perturb, a non-empty sequence of labels of fingers {present}"
        )
    if labels and fingers.size and not set(labels) & set(present):
        raise InvalidOptionError(
            f"groups {describe(labels)} names no finger of fingers, whose "
            f"contacts carry the labels {present}: no contact would move, and "
            "the robustness would be that of the unperturbed grasp; give the "
            "labels of the fingers to perturb, some of them among these"
        )
    return labels


def group_by_count(counts: np.ndarray) -> dict[int, np.ndarray]:
    """Candidate indices by their number of contacts, ``{N: indices}``."""
    counts = np.asarray(counts)
    return {int(n): np.flatnonzero(counts == n) for n in np.unique(counts)}


@keyword_only("mu", after=3)
def perturbed_copies(
    positions: np.ndarray,
    normals: np.ndarray,
    fingers: np.ndarray,
    *,
    mu: float,
    samples: int,
    rng: np.random.Generator,
    position: float,
    angle_deg: float,
    friction: float,
    groups=(0, 1),
):
    """``samples`` perturbed copies of each of ``K`` grasps (module docstring).

    Every argument is checked first, before any draw from ``rng``; a bad one
    raises a :class:`~drakegrasp.GraspError` naming it.

    Parameters
    ----------
    positions : (K, N, 3) float
        Contact points, metres (finite), one frame per grasp; ``K >= 0``
        grasps of ``N >= 1`` contacts.
    normals : (K, N, 3) float
        Inward contact normals (finite, non-zero; normalised here), same frame.
    fingers : (K, N) int
        Which finger made each contact: 0 or 1 for the jaws, any integer label
        in ``[0, 63]`` (:data:`~drakegrasp.planning.checks.MAX_FINGER_LABEL`)
        for a multi-finger hand and its palm.
    mu : float
        Nominal friction coefficient: 0 or in ``[1e-12, 1e12]``
        (:mod:`drakegrasp.core.validation`).
    samples : int
        Copies per grasp, an integer ``>= 0``; the copies' points
        (``K * samples * N * 3`` floats) at most
        :data:`~drakegrasp.planning.checks.MAX_COPY_BYTES`.
    rng : numpy.random.Generator
        Draws the noise (``numpy.random.default_rng(seed)``).
    position : float
        σ_p, metres, in ``[0, 1e6]``: each finger's translation.
    angle_deg : float
        σ_θ, degrees, in ``[0, 1e6]``: each finger's rotation about a
        random axis through its contacts' centroid.
    friction : float
        σ_μ, relative, in ``[0, 1e6]``: each copy's μ is
        ``mu · max(0, 1 + σ_μ ξ)``.  The three bounds are
        :data:`~drakegrasp.planning.checks.NOISE_MAX`, far above any pose or
        friction error (:func:`~drakegrasp.planning.checks.checked_noise`).
    groups : sequence of int, optional
        The finger labels whose contacts move, each in ``[0, 63]`` and none
        twice (default the two jaws; a multi-finger hand passes all its
        fingers).  With ``K >= 1`` grasps, at least one of them must be a
        label of ``fingers`` (else no contact would move); a label no contact
        carries beside ones that some carry is taken and moves nothing.
        Contacts with other labels (a palm) stay put; an empty sequence moves
        no contact (only μ is perturbed).

    Raises
    ------
    GraspError
        Naming a bad argument: :class:`~drakegrasp.InvalidContactError` for
        the contacts (``positions``, ``normals``, ``fingers``) and ``mu``,
        :class:`~drakegrasp.InvalidOptionError` for the others, among them a
        σ out of its range and ``groups`` naming no label of ``fingers`` (the
        message lists the labels there).

    Returns
    -------
    P, Nrm : (K * samples, N, 3) float
        Copies' contacts (metres) and unit normals, grasp-major (copy ``s``
        of grasp ``k`` at row ``k * samples + s``).
    mu : (K * samples,) float
        Each copy's friction coefficient; a positive one is kept within
        ``[1e-12, 1e12]``, the range the batch engine takes.
    """
    positions, normals = checked_contacts(positions, normals)
    fingers = checked_fingers(fingers, positions.shape[:2])
    mu = check_coefficient("mu", mu)
    samples = checked_samples(samples, *positions.shape[:2])
    rng = checked_rng(rng)
    sigma = {"position": position, "angle_deg": angle_deg, "friction": friction}
    position, angle_deg, friction = checked_noise(sigma).values()
    groups = _checked_groups(groups, fingers, empty=True)
    K, N, _ = positions.shape
    P = np.repeat(positions, samples, axis=0)
    Nrm = np.repeat(normals, samples, axis=0)
    F = np.repeat(fingers, samples, axis=0)
    M = K * samples
    for f in groups:
        mask = (F == f)[..., None]
        count = np.maximum(mask.sum(axis=1), 1)
        centre = (P * mask).sum(axis=1) / count  # (M, 3)
        axes = rng.standard_normal((M, 3))
        axes /= np.linalg.norm(axes, axis=1, keepdims=True)
        R = rotations_about(axes, np.radians(angle_deg) * rng.standard_normal(M))
        shift = position * rng.standard_normal((M, 3))
        moved = (
            np.einsum("mij,mnj->mni", R, P - centre[:, None])
            + (centre + shift)[:, None]
        )
        P = np.where(mask, moved, P)
        Nrm = np.where(mask, np.einsum("mij,mnj->mni", R, Nrm), Nrm)
    mus = mu * np.maximum(0.0, 1.0 + friction * rng.standard_normal(M))
    return P, Nrm, perturbed_mu(mus)


@keyword_only("mu", after=2)
@renamed_keyword("model", "contact_model")
def verdicts(
    positions,
    normals,
    *,
    mu,
    torque_scale: float,
    contact_model: str,
    torsional_friction,
    workers: int | None,
):
    """LP2 verdicts and ε (one torque scale) of ``K`` grasps of ``N`` contacts.

    Parameters
    ----------
    positions, normals : (K, N, 3) float
        Contact points (metres) and inward normals (normalised by the batch
        engine), each grasp in its own frame, moments about its origin.
    mu : float or array
        Friction coefficients, as :func:`~drakegrasp.batch.batch_force_closure`
        takes them (0 or in ``[1e-12, 1e12]``).
    torque_scale : float
        Metres dividing every grasp's moments in ε (one scale, so ε compares
        across grasps), a length in ``[2.2e-308, 1e30]``.
    contact_model : {"hard_finger", "frictionless", "soft_finger"}
    torsional_friction : float or None
        ``ν`` of soft fingers, as :func:`~drakegrasp.batch.batch_force_closure`.
    workers : int or None
        Worker processes of the batch engine (None: every core).

    Returns
    -------
    is_closure, d_star, rank, epsilon : (K,) arrays
        The LP2 verdict, its ``d*`` and the rank of ``G``
        (:func:`~drakegrasp.batch.batch_force_closure`), and the L1 ε about
        each grasp's origin with moments divided by ``torque_scale`` (0 where
        not force closure).
    """
    torque_scale = check_length("torque_scale", torque_scale, error=InvalidOptionError)
    res = batch_force_closure(
        positions,
        normals,
        mu=mu,
        contact_model=contact_model,
        torsional_friction=torsional_friction,
        workers=workers,
    )
    eps = np.zeros(len(positions))
    closed = np.flatnonzero(res.is_closure)
    if len(closed):
        eps[closed] = batch_epsilon_l1(
            positions[closed],
            normals[closed],
            mu=mu,
            contact_model=contact_model,
            torsional_friction=torsional_friction,
            characteristic_lengths=torque_scale,
            workers=workers,
        )
    return (
        np.asarray(res.is_closure, bool),
        np.asarray(res.d_star, float),
        np.asarray(res.rank, int),
        eps,
    )


@keyword_only("mu", after=3)
@renamed_keyword("model", "contact_model")
def robustness(
    positions,
    normals,
    fingers,
    *,
    mu: float,
    samples: int,
    rng: np.random.Generator,
    noise: dict,
    contact_model: str,
    torsional_friction,
    workers: int | None,
    groups=(0, 1),
) -> np.ndarray:
    """(K,) fraction of perturbed copies that stay force closure (LP2).

    The copies are those of :func:`perturbed_copies` (each finger's contacts
    moved rigidly, μ scaled); their verdicts come from the batch engine in
    verdict-only mode.  Every argument is checked first, before any draw from
    ``rng``; a bad one raises a :class:`~drakegrasp.GraspError` naming it.

    Parameters
    ----------
    positions : (K, N, 3) float
        Contact points, metres (finite), one frame per grasp, moments about
        its origin; ``K >= 0`` grasps of ``N >= 1`` contacts.
    normals : (K, N, 3) float
        Inward contact normals (finite, non-zero; normalised here).
    fingers : (K, N) int
        Finger label of each contact (0, 1 for the jaws; a multi-finger hand's
        fingers and palm), integers in ``[0, 63]``.
    mu : float
        Nominal friction coefficient: 0 or in ``[1e-12, 1e12]``
        (:mod:`drakegrasp.core.validation`).
    samples : int
        Perturbed copies per grasp, an integer ``>= 0`` (0: robustness 0),
        within :data:`~drakegrasp.planning.checks.MAX_COPY_BYTES` as for
        :func:`perturbed_copies`.
    rng : numpy.random.Generator
        Draws the noise (``numpy.random.default_rng(seed)``).
    noise : dict
        The three σ of :data:`DEFAULT_NOISE`, each in ``[0, 1e6]``
        (:data:`~drakegrasp.planning.checks.NOISE_MAX`, far above any pose or
        friction error): ``"position"`` (metres), ``"angle_deg"`` (degrees)
        and ``"friction"`` (relative); exactly these keys.
    contact_model : {"hard_finger", "frictionless", "soft_finger"}
    torsional_friction : float or None
        ``ν`` of soft fingers, 0 or in ``[1e-12, 1e12]``; None is 0, and
        refused for soft fingers (as
        :func:`~drakegrasp.batch.batch_force_closure` refuses it).
    workers : int or None
        Worker processes of the batch engine (None: every core).
    groups : sequence of int, optional
        The finger labels whose contacts move (see :func:`perturbed_copies`):
        not empty, and with ``K >= 1`` grasps at least one of them a label of
        ``fingers`` (else no contact would move and the robustness would be
        the unperturbed grasp's).

    Returns
    -------
    (K,) float
        Fraction in ``[0, 1]`` of each grasp's copies in force closure.

    Raises
    ------
    GraspError
        Naming a bad argument: :class:`~drakegrasp.InvalidContactError` for
        the contacts (``positions``, ``normals``, ``fingers``) and ``mu``,
        :class:`~drakegrasp.InvalidOptionError` for the others, among them a
        σ out of its range (``noise['position']``...) and ``groups`` empty
        or naming no label of ``fingers`` (the message lists the labels
        there).
    """
    positions, normals = checked_contacts(positions, normals)
    fingers = checked_fingers(fingers, positions.shape[:2])
    mu, contact_model, torsional_friction = checked_friction(
        mu, contact_model, torsional_friction
    )
    samples = checked_samples(samples, *positions.shape[:2])
    rng = checked_rng(rng)
    if not isinstance(noise, Mapping) or set(noise) != set(DEFAULT_NOISE):
        raise InvalidOptionError(
            f"noise must be a dict of the three σ {sorted(DEFAULT_NOISE)} (as "
            f"DEFAULT_NOISE), got {describe(noise)}"
        )
    noise = checked_noise(noise, "noise[{!r}]")
    check_workers(workers)
    groups = _checked_groups(groups, fingers, empty=False)
    if samples == 0 or len(positions) == 0:
        return np.zeros(len(positions))
    P, Nrm, mus = perturbed_copies(
        positions, normals, fingers, mu=mu, samples=samples, rng=rng,
        groups=groups, **noise,
    )  # fmt: skip
    # verdicts only: each LP stops once its verdict is proved (force_verdicts)
    held = force_verdicts(
        P,
        Nrm,
        mu=mus[:, None],  # one μ per copy, (K S, 1): never ambiguous with N
        contact_model=contact_model,
        torsional_friction=torsional_friction,
        workers=workers,
    )
    return held.astype(float).reshape(len(positions), samples).mean(axis=1)


TIE_DECIMALS = 9
"""Scores, ``ε ρ`` and ``d*`` are compared rounded to this many decimals: below the
accuracy the LPs certify, so grasps that tie in exact arithmetic (symmetric
placements on a symmetric object) are ordered by the next key, not by the last
bits of their LPs' rounding (which a rigid motion of the scene changes)."""


def tie_key(values) -> np.ndarray:
    """``values`` rounded to :data:`TIE_DECIMALS` decimals, for ordering."""
    return np.round(np.asarray(values, float), TIE_DECIMALS)


def rank_order(score, d_star, sample) -> np.ndarray:
    """Indices best first: highest score, then highest ``d*``, then lowest sample.

    Scores and ``d*`` are compared by :func:`tie_key`.
    """
    return np.lexsort((np.asarray(sample), -tie_key(d_star), -tie_key(score)))


def _finger_label(contact, names) -> int:
    """0 or 1 for a contact of finger 0 or 1, 2 for another hand body (palm)."""
    for f, bodies in enumerate(names):
        if contact.finger_body in bodies:
            return f
    return 2


def _axes_O(kept, rows, gripper, X_WO) -> np.ndarray:
    """(K, 3) grasp axes (K's x axis) of ``kept[rows]`` in the object frame O."""
    R_OW = X_WO.rotation().matrix().T
    a_H = gripper.X_HK.rotation().matrix()[:, 0]
    return np.array([R_OW @ kept[i][1].rotation().matrix() @ a_H for i in rows])


@renamed_keyword("model", "contact_model")
def ranked_candidates(
    order, scores: dict, pose, *, weight: float, certify: int, mu, contact_model, nu
) -> tuple[GraspCandidate, ...]:
    """The candidates of a ranking, best first, either hand's route.

    Parameters
    ----------
    order : (K,) int
        The rows of ``scores`` best first (any subset, in that order).
    scores : dict of str to (K,) array
        The ranking's arrays: ``is_closure`` (bool), ``d_star``
        (dimensionless), ``rank`` (int), ``eps`` (ε, dimensionless with the
        object's torque scale), ``rho`` (robustness in ``[0, 1]``),
        ``score`` and ``alpha`` (weight capacity, N of weight per N of
        squeeze; NaN where not computed).
    pose : callable
        ``pose(i)`` gives the fields of row ``i``'s own
        :class:`~drakegrasp.planning.candidates.GraspCandidate` (``sample``,
        ``X_WH``, ``q_hand``, ``contacts``...).
    weight : float
        The object's weight, newtons (NaN when unknown).
    certify : int
        The first ``certify`` candidates also get the single-grasp verdict
        with its certificate (:func:`~drakegrasp.force_closure`).
    mu : float
    contact_model : str
    nu : float or None
        The contacts' ``mu``, ``contact_model`` and ``torsional_friction``
        (each candidate's ``contact_options``).

    Returns
    -------
    tuple of GraspCandidate
        In the order of ``order``; ``squeeze_needed`` is ``weight / α``
        (newtons per finger, :func:`~drakegrasp.planning.needed.needed_for`:
        NaN without a capacity, inf at 0 and beyond the largest float).
    """
    out = []
    for place, i in enumerate(order):
        alpha = scores["alpha"][i]
        candidate = GraspCandidate(
            **pose(i),
            contact_options={
                "mu": mu,
                "contact_model": contact_model,
                "torsional_friction": nu,
            },
            is_closure=bool(scores["is_closure"][i]),
            d_star=float(scores["d_star"][i]),
            rank=int(scores["rank"][i]),
            epsilon=float(scores["eps"][i]),
            robustness=float(scores["rho"][i]),
            score=float(scores["score"][i]),
            weight_capacity=float(alpha),
            squeeze_needed=needed_for(weight, alpha),
        )
        if place < certify:
            candidate = replace(candidate, closure=force_closure(candidate.grasp))
        out.append(candidate)
    return tuple(out)


@keyword_only("mu", after=2)
@renamed_keyword("model", "contact_model")
def grouped_verdicts(
    kept, labels, *, mu, torque_scale, contact_model, nu, workers, reference=None
):  # fmt: skip
    """Stage 4a, either hand's route: every kept grasp's LP2 verdict, by count.

    Grasps with equal contact counts go to the batch engine together
    (:func:`verdicts`).

    Parameters
    ----------
    kept : sequence of tuple
        One closed pose per row; ``kept[i][4]`` are row ``i``'s contacts,
        with ``p_OC`` (metres) and ``nhat_O`` (unit) in the object frame O.
    labels : callable
        ``labels(contacts)`` numbers their fingers (a list of int).
    mu : float
        Friction coefficient, as :func:`verdicts` takes it.
    torque_scale : float
        Metres dividing the moments in ε (one scale for every grasp).
    contact_model : str
    nu : float or None
        ``torsional_friction`` of soft fingers.
    workers : int or None
        Worker processes of the batch engine (None: every core).
    reference : (3,) float, optional
        The point of O (metres) moments are taken about: the object's centre
        of mass; default O's origin.

    Returns
    -------
    verdict : dict of (K,) arrays
        ``is_closure``, ``d_star``, ``rank``, ``eps``.
    groups : list of tuple
        Per count: ``(idx, P, Nrm, L, fc)``, the rows, their contacts
        ``(n, N, 3)`` (frame O, about its origin), normals, finger labels
        ``(n, N)`` and closure mask.
    """
    reference = np.zeros(3) if reference is None else reference
    K = len(kept)
    verdict = {
        "is_closure": np.zeros(K, bool), "d_star": np.zeros(K),
        "rank": np.zeros(K, int), "eps": np.zeros(K),
    }  # fmt: skip
    groups = []
    counts = np.array([len(k[4]) for k in kept])
    for idx in group_by_count(counts).values():
        P = np.array([[c.p_OC for c in kept[i][4]] for i in idx])
        Nrm = np.array([[c.nhat_O for c in kept[i][4]] for i in idx])
        L = np.array([labels(kept[i][4]) for i in idx])
        fc, ds, rk, ep = verdicts(
            P - reference, Nrm, mu=mu, torque_scale=torque_scale,
            contact_model=contact_model, torsional_friction=nu, workers=workers,
        )  # fmt: skip
        for key, value in zip(verdict, (fc, ds, rk, ep), strict=True):
            verdict[key][idx] = value
        groups.append((idx, P, Nrm, L, fc))
    return verdict, groups


@renamed_keyword("model", "contact_model")
def rank_candidates(
    kept, *, finger_names, gripper, plant, mu, contact_model, nu, torque_scale, samples,
    noise, rng, certify, workers, X_WO, weight, weight_check, surface, tol,
    reference,
):  # fmt: skip
    """Stage 4: verdicts, ε, robustness, weight capacity, score; ranked candidates.

    The parallel-jaw route of :func:`~drakegrasp.planning.planner.plan_grasps`,
    which checks the options before it calls this.

    Parameters
    ----------
    kept : sequence of tuple
        ``(sample, X_WH, q, opening, contacts)`` of every closed pose;
        contacts have ``p_OC`` (metres), ``nhat_O`` (unit, inward) in the
        object frame O and ``finger_body``.
    finger_names : sequence of set of str
        Scoped body names of finger 0 and of finger 1 (other hand bodies are
        the palm, label 2).
    gripper : ParallelJaw
        The gripper (its grasp frame K gives each grasp's axis).
    plant : MultibodyPlant
    mu : float
        Friction coefficient (0 or in ``[1e-12, 1e12]``).
    contact_model : str
    nu : float or None
        ``torsional_friction`` of soft fingers.
    torque_scale : float
        Metres dividing the moments in ε and the weight capacity (the
        object's radius about ``reference``).
    samples : int
        Robustness copies per candidate.
    noise : dict
        The σ of :data:`DEFAULT_NOISE` (``position`` metres, ``angle_deg``
        degrees about the grasp axis, ``friction`` relative).
    rng : numpy.random.Generator
    certify : int
        How many of the best get the single-grasp verdict and certificate.
    workers : int or None
        Worker processes of the batch engine (None: every core).
    X_WO : RigidTransform
        The object's pose in the world.
    weight : float
        The object's weight (N), NaN when unknown.
    weight_check : int or None
        Compute the weight capacity for only this many candidates, the best
        by ``ε ρ`` (None: every force-closure candidate with ``ρ > 0``).
    surface : ObjectSurface or FittedCloud
        Robustness re-closes the jaws on the moved object's surface
        (:mod:`drakegrasp.planning.reclose`): an object body's
        (:class:`~drakegrasp.planning.surface.ObjectSurface`) or a cloud's
        (:class:`~drakegrasp.planning.cloud.FittedCloud`).
    tol : float
        The distance tolerance (metres) of the re-closing.
    reference : (3,) float
        Where the weight acts, in O (metres): every moment is about it.

    Returns
    -------
    tuple of GraspCandidate
        Ranked best first (:func:`ranked_candidates`).
    """
    if not kept:
        return ()
    counts = np.array([len(k[4]) for k in kept])
    K = len(kept)
    rho = np.zeros(K)
    names = finger_names
    verdict, groups = grouped_verdicts(
        kept, lambda found: [_finger_label(c, names) for c in found], mu=mu,
        torque_scale=torque_scale, contact_model=contact_model, nu=nu,
        workers=workers, reference=reference,
    )  # fmt: skip
    is_closure, d_star, rank, eps = verdict.values()
    for idx, P, _, F, fc in groups:
        closed = idx[fc]
        if len(closed):
            rho[closed] = reclosed_robustness(
                surface, P[fc], F[fc], _axes_O(kept, closed, gripper, X_WO), mu=mu,
                samples=samples, rng=rng, **noise, tol=tol,
                contact_model=contact_model, torsional_friction=nu, workers=workers,
                reference=reference,
            )  # fmt: skip
    samples_of = np.array([k[0] for k in kept])
    pre = eps * rho
    checked = rank_order(pre, d_star, samples_of)
    # score = α ρ: a candidate with ρ = 0 scores 0 whatever its α, so no LP
    checked = checked[is_closure[checked] & (rho[checked] > 0)][:weight_check]
    alpha = np.full(K, np.nan)
    for idx in group_by_count(counts[checked]).values():
        idx = checked[idx]
        alpha[idx] = weight_capacity(
            np.array([[c.p_OC for c in kept[i][4]] for i in idx]) - reference,
            np.array([[c.nhat_O for c in kept[i][4]] for i in idx]),
            np.array([[_finger_label(c, names) for c in kept[i][4]] for i in idx]),
            mu=mu, torque_scale=torque_scale, contact_model=contact_model,
            torsional_friction=nu, workers=workers, palm=2,
        ).min(axis=1)  # fmt: skip
    score = np.where(np.isfinite(alpha), alpha * rho, 0.0)
    order = np.lexsort((samples_of, -tie_key(d_star), -tie_key(pre), -tie_key(score)))
    base = scoped_name(plant, gripper.base)
    joint_names = tuple(
        f"{plant.GetModelInstanceName(j.model_instance())}::{j.name()}"
        for j in gripper.joints
    )
    scores = {
        "is_closure": is_closure, "d_star": d_star, "rank": rank, "eps": eps,
        "rho": rho, "score": score, "alpha": alpha,
    }  # fmt: skip
    signs = (
        float(np.sign(1 / gripper.pad_rate[0])),
        float(np.sign(-1 / gripper.pad_rate[1])),
    )

    def pose(i: int) -> dict:
        sample, X_WH, q, opening, found = kept[i]
        return dict(
            sample=sample, hand_base=base, X_WH=X_WH, X_WO=X_WO,
            q_hand=np.asarray(q, float), joint_names=joint_names,
            closing_signs=signs, opening=opening, contacts=tuple(found),
            reference_point=reference.copy(), torque_scale=float(torque_scale),
        )  # fmt: skip

    return ranked_candidates(
        order, scores, pose, weight=weight, certify=certify, mu=mu,
        contact_model=contact_model, nu=nu,
    )  # fmt: skip


def _labels(found, label, palm) -> list[int]:
    return [label.get(c.finger_body, palm) for c in found]


def _has_fan(found) -> bool:
    return any(getattr(c, "fan", None) is not None for c in found)


def _fans(found) -> np.ndarray:
    """(N, 2, 3) fan ends per contact, NaN where a contact has none."""
    out = np.full((len(found), 2, 3), np.nan)
    for j, c in enumerate(found):
        if getattr(c, "fan", None) is not None:
            out[j] = c.fan
    return out


@renamed_keyword("model", "contact_model")
def rank_multifinger(
    kept, *, label, hand: MultiFingerHand, plant, mu, contact_model, nu, torque_scale,
    samples, noise, rng, certify, workers, X_WO, weight, reference,
):  # fmt: skip
    """Stage 4: verdicts, ε, robustness, weight capacity, score; ranked candidates.

    ``label`` maps a finger body's scoped name to its finger; other hand
    bodies (the palm) are labelled ``F``, the number of fingers.  Moments are
    about ``reference`` ((3,) in O, metres), where the weight acts.
    """
    if not kept:
        return ()
    F = hand.num_fingers
    counts = np.array([len(k[4]) for k in kept])
    K = len(kept)
    rho = np.zeros(K)
    alpha = np.full(K, np.nan)
    verdict, groups = grouped_verdicts(
        kept, lambda found: _labels(found, label, F), mu=mu,
        torque_scale=torque_scale, contact_model=contact_model, nu=nu,
        workers=workers, reference=reference,
    )  # fmt: skip
    is_closure, d_star, rank, eps = verdict.values()
    for idx, P, Nrm, L, fc in groups:
        closed = idx[fc]
        if len(closed):
            rho[closed] = robustness(
                P[fc] - reference, Nrm[fc], L[fc], mu=mu, samples=samples,
                rng=rng, noise=noise, contact_model=contact_model,
                torsional_friction=nu, workers=workers, groups=tuple(range(F)),
            )  # fmt: skip
            alpha[closed] = weight_capacity(
                P[fc] - reference, Nrm[fc], L[fc], mu=mu,
                torque_scale=torque_scale, contact_model=contact_model,
                torsional_friction=nu, palm=F,
            ).min(axis=1)  # fmt: skip
    fanned = np.flatnonzero(
        np.isfinite(alpha) & (rho > 0) & [_has_fan(k[4]) for k in kept]
    )
    for idx in group_by_count(counts[fanned]).values():
        rows = fanned[idx]
        alpha[rows] = fan_capacity(
            np.array([[c.p_OC for c in kept[i][4]] for i in rows]) - reference,
            np.array([[c.nhat_O for c in kept[i][4]] for i in rows]),
            np.array([_fans(kept[i][4]) for i in rows]),
            np.array([_labels(kept[i][4], label, F) for i in rows]),
            mu=mu, samples=samples, rng=rng, torque_scale=torque_scale,
            contact_model=contact_model, torsional_friction=nu, palm=F,
        )  # fmt: skip
    score = np.where(np.isfinite(alpha), alpha * rho, 0.0)
    sample = np.array([k[0] for k in kept])
    order = np.lexsort((sample, -tie_key(d_star), -tie_key(eps * rho), -tie_key(score)))
    s = hand.structure
    base = scoped_name(plant, hand.base)
    scores = {
        "is_closure": is_closure, "d_star": d_star, "rank": rank, "eps": eps,
        "rho": rho, "score": score, "alpha": alpha,
    }  # fmt: skip

    def pose(i: int) -> dict:
        k, X_WH, q_pre, q, found = kept[i]
        return dict(
            sample=int(k), hand_base=base, X_WH=X_WH, X_WO=X_WO,
            q_hand=np.asarray(q, float), joint_names=s.names,
            closing_signs=tuple(float(v) for v in np.sign(q - q_pre)),
            opening=float("nan"), contacts=tuple(found),
            q_preshape=np.asarray(q_pre, float), reference_point=reference.copy(),
            torque_scale=float(torque_scale),
        )  # fmt: skip

    return ranked_candidates(
        order, scores, pose, weight=weight, certify=certify, mu=mu,
        contact_model=contact_model, nu=nu,
    )  # fmt: skip
