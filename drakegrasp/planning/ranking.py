r"""Ranking planned grasps: verdicts, ε on one scale, robustness and the score.

Every measure runs in the batch engine (:mod:`drakegrasp.batch`), on the
candidates grouped by their number of contacts (the engine takes ``K`` grasps
of ``N`` contacts each; a WSG finger seats one to four tip spheres, so the
counts are ragged).

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
(:func:`drakegrasp.batch.run.verdicts.force_verdicts`): each LP stops once its
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

from dataclasses import replace

import numpy as np

from drakegrasp.batch import batch_epsilon_l1, batch_force_closure
from drakegrasp.batch.run.verdicts import force_verdicts
from drakegrasp.closure.verdicts import force_closure
from drakegrasp.core.deprecation import keyword_only, renamed_keyword
from drakegrasp.core.linalg import rotations_about
from drakegrasp.planning.candidates import GraspCandidate
from drakegrasp.planning.reclose import reclosed_robustness
from drakegrasp.planning.weight import weight_capacity
from drakegrasp.plant.validation import scoped_name

__all__ = [
    "DEFAULT_NOISE",
    "TIE_DECIMALS",
    "group_by_count",
    "grouped_verdicts",
    "perturbed_copies",
    "rank_candidates",
    "rank_order",
    "ranked_candidates",
    "robustness",
    "tie_key",
    "verdicts",
]

DEFAULT_NOISE = {"position": 2e-3, "angle_deg": 3.0, "friction": 0.1}
"""Default robustness noise: σ_p (m), σ_θ (degrees), σ_μ (relative)."""


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

    Parameters
    ----------
    positions, normals : (K, N, 3) float
        Contacts (metres) and inward unit normals, one frame per grasp.
    fingers : (K, N) int
        Which finger (0 or 1) made each contact.
    mu : float
    samples : int
    rng : numpy.random.Generator
    position, angle_deg, friction : float
        σ_p (m), σ_θ (degrees), σ_μ.
    groups : sequence of int, optional
        The finger labels whose contacts move (default the two jaws; a
        multi-finger hand passes all its fingers).  Contacts with other labels
        (a palm) stay put.

    Returns
    -------
    P, Nrm : (K * samples, N, 3) float
        Copies, grasp-major (copy ``s`` of grasp ``k`` at row ``k * samples + s``).
    mu : (K * samples,) float
    """
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
    return P, Nrm, mus


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

    Returns
    -------
    is_closure, d_star, rank, epsilon : (K,) arrays
    """
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

    ``groups``: the finger labels whose contacts move (see
    :func:`perturbed_copies`).
    """
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


def _squeeze(weight: float, alpha: float) -> float:
    if not np.isfinite(alpha):
        return float("nan")
    return float(weight / alpha) if alpha > 0 else float("inf")


@renamed_keyword("model", "contact_model")
def ranked_candidates(
    order, scores: dict, pose, *, weight: float, certify: int, mu, contact_model, nu
) -> tuple[GraspCandidate, ...]:
    """The candidates of a ranking, best first, either hand's route.

    ``order`` gives the rows best first; ``scores`` holds the ranking's
    arrays ``is_closure``, ``d_star``, ``rank``, ``eps``, ``rho``, ``score``
    and ``alpha`` (weight capacity, N per N of squeeze); ``pose(i)`` the
    fields of row ``i``'s own (``sample``, ``X_WH``, ``q_hand``,
    ``contacts``...).  ``squeeze_needed`` is ``weight / α`` (NaN without a
    capacity, inf at 0); the first ``certify`` also get the single-grasp
    verdict with its certificate.
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
            squeeze_needed=_squeeze(weight, alpha),
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

    ``kept[i][4]`` are row ``i``'s contacts (``p_OC``, ``nhat_O``);
    ``labels(contacts)`` numbers their fingers.  Grasps with equal contact
    counts go to the batch engine together (:func:`verdicts`), with moments
    about ``reference`` ((3,) in O, metres: the object's centre of mass;
    default O's origin).

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

    ``kept`` holds ``(sample, X_WH, q, opening, contacts)`` of every closed
    pose; contacts have ``p_OC``, ``nhat_O`` and ``finger_body``.  ``weight``
    is the object's weight (N), NaN when unknown, acting at ``reference``
    ((3,) in O: every moment is about it).  Robustness re-closes the
    jaws on the moved object's ``surface`` (:mod:`drakegrasp.planning.reclose`,
    within ``tol``): an object body's
    (:class:`~drakegrasp.planning.surface.ObjectSurface`) or a cloud's
    (:class:`~drakegrasp.planning.cloud.FittedCloud`).
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
            torsional_friction=nu, workers=workers,
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
            reference_point=reference.copy(),
        )  # fmt: skip

    return ranked_candidates(
        order, scores, pose, weight=weight, certify=certify, mu=mu,
        contact_model=contact_model, nu=nu,
    )  # fmt: skip
