r"""Plan parallel-jaw grasps on an object body: sample, filter, close, rank.

:func:`plan_grasps` runs four stages; every sampled pose either becomes a
candidate or is counted under one rejection reason.

1. **Antipodal sampling** (numpy, all samples at once).  Surface points of the
   object's collision geometry with their outward normals ``n``, area-uniform
   (:mod:`drakegrasp.planning.surface`); the grasp axis runs along ``−n`` through
   the object, whose chord gives the opposite point and the width ``w``.  The
   axis is kept when ``w`` fits the gripper's stroke and the exit normal lies in
   the friction cone about the axis (the angle between them at most
   ``atan μ``).  A rotation about the axis, uniform in ``[0, 2π)``, sets the
   approach.  The gripper's grasp frame K (:mod:`drakegrasp.planning.gripper`)
   is put at the chord's midpoint with its x axis along the axis, and
   ``X_WH = X_WK X_HK⁻¹``; the pre-grasp opening is ``w`` plus twice
   ``clearance``, at most the stroke.
2. **Collision filter** (Drake).  The hand is placed open at ``X_WH``; any
   pair of a hand geometry and another geometry with signed distance below
   ``−distance_tolerance`` rejects the pose (object or rest of the scene).
3. **Closing** (Drake).  Each finger moves along the grasp axis by conservative
   advancement: by its smallest signed distance ``ψ`` to the geometry outside
   the hand minus ``tol / 2`` (a translation by ``ψ`` cannot penetrate), until
   ``ψ <= tol``; a finger that reaches its joint limit misses, one stopped by
   anything but the object is blocked.  The contacts are then those of
   :func:`~drakegrasp.find_contacts` (the same as :func:`~drakegrasp.analyze_grasp`
   reads on the applied candidate), and both fingers must touch.
4. **Ranking**: verdicts, ε and robustness in the batch engine
   (:mod:`drakegrasp.planning.ranking`), weight capacity in one LP per grasp
   (:mod:`drakegrasp.planning.weight`).
"""

from __future__ import annotations

import time
from collections import Counter

import numpy as np
from pydrake.math import RigidTransform, RotationMatrix

from drakegrasp.closure.verdicts import force_closure
from drakegrasp.core.contact import Contact, ContactModel
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.validation import check_coefficient, real_scalar
from drakegrasp.errors import (
    InvalidOptionError,
    NoContactsError,
    PenetrationError,
)
from drakegrasp.planning.candidates import GraspCandidate, GraspCandidates
from drakegrasp.planning.gripper import ParallelJaw, parallel_jaw
from drakegrasp.planning.ranking import (
    DEFAULT_NOISE,
    group_by_count,
    rank_order,
    robustness,
    verdicts,
)
from drakegrasp.planning.surface import ObjectSurface, piece_of_shape
from drakegrasp.planning.weight import weight_capacity
from drakegrasp.plant.contacts import DEFAULT_DISTANCE_TOLERANCE, find_contacts
from drakegrasp.plant.validation import (
    HandSpec,
    check_distance_tolerance,
    hand_bodies,
    plant_context_of,
    resolve_object_body,
    scoped_name,
)

__all__ = ["MAX_CANDIDATES", "REASONS", "object_surface", "plan_grasps"]

MAX_CANDIDATES = 1_000_000
"""Most poses one call samples (memory grows with it; call again for more)."""

GRAVITY = 9.81
"""m/s², for the squeeze that holds the object's weight."""

MAX_CLOSING_STEPS = 50
"""Bound on the conservative-advancement steps of one closing."""

REASONS = {
    "occluded": "another part of the object lies outside the sampled point on the axis",
    "wider than the stroke": "the object's chord is wider than the open gripper",
    "narrower than the stroke": "the chord is narrower than the closed gripper",
    "outside the friction cone": "the opposite normal leaves the cone about the axis",
    "hand collides with the object": "the open hand penetrates the object",
    "hand collides with the scene": "the open hand penetrates another body",
    "finger misses the object": "a finger reached its joint limit without touching",
    "finger blocked by the scene": "a finger touched another body first",
    "closing did not converge": f"more than {MAX_CLOSING_STEPS} closing steps",
    "one finger touches": "only one finger's geometry touches the object",
}
"""Every rejection reason, with what it means."""


def object_surface(plant, plant_context, object_body) -> ObjectSurface:
    """The object's collision geometry as convex pieces in its body frame O."""
    ctx = plant_context_of(plant, plant_context)
    body = resolve_object_body(plant, object_body)
    inspector = plant.get_geometry_query_input_port().Eval(ctx).inspector()
    return ObjectSurface.from_pieces(
        piece_of_shape(
            inspector.GetShape(g), inspector.GetPoseInFrame(g), inspector.GetName(g)
        )
        for g in plant.GetCollisionGeometriesForBody(body)
    )


def _check_count(value) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise InvalidOptionError(
            f"num_candidates must be an integer >= 0, got {value!r}"
        )
    if not 0 <= int(value) <= MAX_CANDIDATES:
        raise InvalidOptionError(
            f"num_candidates must be in [0, {MAX_CANDIDATES}] (one call; call again "
            f"with another seed for more), got {value}"
        )
    return int(value)


def _axis_frames(d: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """(K, 3, 3) rotations whose x axis is ``d`` and y axis at angle θ about it.

    The angle is measured from a first tangent that depends on ``d`` alone (the
    convention of the contact frames), in the frame ``d`` is expressed in.
    """
    helper = np.zeros_like(d)
    helper[np.arange(len(d)), np.argmin(np.abs(d), axis=1)] = 1.0
    e1 = np.cross(helper, d)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(d, e1)
    y = np.cos(theta)[:, None] * e1 + np.sin(theta)[:, None] * e2
    return np.stack([d, y, np.cross(d, y)], axis=-1)


def _sample_poses(surface, gripper: ParallelJaw, X_WO, n, mu, clearance, rng, tol):
    """Stage 1: (poses dict of arrays for the kept samples, rejection Counter)."""
    p_O, nout_O, _ = surface.sample(n, rng)
    theta = rng.uniform(0.0, 2 * np.pi, n)
    d_O = -nout_O
    t_in, t_out, nexit_O = surface.chord(p_O, d_O)
    reasons = np.full(n, "", dtype=object)
    cos_cone = np.cos(np.arctan(mu))

    def reject(mask, reason):
        mask = mask & (reasons == "")
        reasons[mask] = reason

    reject(~(t_in >= -tol) | np.isnan(t_out), "occluded")
    reject(t_out > gripper.max_opening, "wider than the stroke")
    reject(t_out < gripper.min_opening, "narrower than the stroke")
    reject(np.sum(nexit_O * d_O, axis=1) < cos_cone, "outside the friction cone")
    keep = np.flatnonzero(reasons == "")
    R_WO = X_WO.rotation().matrix()
    centre_W = (
        p_O[keep] + 0.5 * t_out[keep, None] * d_O[keep]
    ) @ R_WO.T + X_WO.translation()
    R_WK = R_WO @ _axis_frames(d_O[keep], theta[keep])  # built in O: invariant
    X_KH = gripper.X_HK.inverse()
    R_WH = R_WK @ X_KH.rotation().matrix()
    p_WH = centre_W + R_WK @ X_KH.translation()
    width = t_out[keep]
    poses = {
        "sample": keep,
        "R_WH": R_WH,
        "p_WH": p_WH,
        "opening": np.minimum(width + 2 * clearance, gripper.max_opening),
    }
    return poses, Counter(r for r in reasons if r)


class _Closer:
    """Stages 2 and 3 for one plant: place, filter, close, read contacts."""

    def __init__(self, plant, ctx, object_body, hand, gripper: ParallelJaw, tol):
        self.plant, self.ctx, self.object, self.hand = plant, ctx, object_body, hand
        self.g, self.tol = gripper, tol
        self.port = plant.get_geometry_query_input_port()
        instances = {b.model_instance() for b in hand_bodies(plant, object_body, hand)}
        self.hand_geoms = {
            g
            for i in instances
            for b in plant.GetBodyIndices(i)
            for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))
        }
        self.finger_of = {
            g: f
            for f, bodies in enumerate(gripper.finger_bodies)
            for b in bodies
            for g in plant.GetCollisionGeometriesForBody(b)
        }
        self.object_geoms = set(plant.GetCollisionGeometriesForBody(object_body))
        self.finger_names = [
            {scoped_name(plant, b) for b in bodies} for bodies in gripper.finger_bodies
        ]

    def _set(self, X_WH, q):
        self.plant.SetFreeBodyPose(self.ctx, self.g.base, X_WH)
        for j, v in zip(self.g.joints, q, strict=True):
            j.set_translation(self.ctx, float(v))

    def _outside_pairs(self, query, max_distance):
        for pair in query.ComputeSignedDistancePairwiseClosestPoints(max_distance):
            a, b = pair.id_A, pair.id_B
            in_a, in_b = a in self.hand_geoms, b in self.hand_geoms
            if in_a != in_b:
                yield (a, b) if in_a else (b, a), pair.distance

    def place(self, X_WH, opening):
        """Stage 2: None when clear, else the rejection reason."""
        self._set(X_WH, self.g.q_for_opening(opening))
        query = self.port.Eval(self.ctx)
        for (_, other), distance in self._outside_pairs(query, 0.0):
            if distance < -self.tol:
                if other in self.object_geoms:
                    return "hand collides with the object"
                return "hand collides with the scene"
        return None

    def close(self, opening):
        """Stage 3 from the placed open hand: (q, reason or None)."""
        g, tol = self.g, self.tol
        q = g.q_for_opening(opening).astype(float)
        toward = np.array([1.0, -1.0])  # finger 0 closes along +a, finger 1 along -a
        closed_limit = np.where(toward / g.pad_rate > 0, g.upper, g.lower)
        for _ in range(MAX_CLOSING_STEPS):
            query = self.port.Eval(self.ctx)
            psi = np.full(2, np.inf)
            hit_object = [False, False]
            for (mine, other), distance in self._outside_pairs(query, g.max_opening):
                f = self.finger_of.get(mine)
                if f is not None and distance < psi[f]:
                    psi[f] = distance
                    hit_object[f] = other in self.object_geoms
            if np.all(psi <= tol):
                if not all(hit_object):
                    return q, "finger blocked by the scene"
                return q, None
            step = np.where(psi > tol, psi - 0.5 * tol, 0.0)
            q_new = q + toward * step / g.pad_rate
            beyond = (q_new - closed_limit) * np.sign(toward / g.pad_rate) > 0
            at_limit = np.isclose(q, closed_limit, rtol=0, atol=1e-12)
            if np.any(beyond & at_limit & (psi > tol)):
                return q, "finger misses the object"
            q = np.where(beyond, closed_limit, q_new)
            for j, v in zip(g.joints, q, strict=True):
                j.set_translation(self.ctx, float(v))
        return q, "closing did not converge"

    def contacts(self):
        """The closed hand's contacts, or (None, reason)."""
        try:
            found = find_contacts(
                self.plant,
                self.ctx,
                self.object,
                hand=self.hand,
                distance_tolerance=self.tol,
            )
        except NoContactsError:
            return None, "one finger touches"
        except PenetrationError:
            return None, "closing did not converge"
        touched = [
            any(c.finger_body in names for c in found) for names in self.finger_names
        ]
        if not all(touched):
            return None, "one finger touches"
        return found, None


def plan_grasps(
    plant,
    plant_context,
    object_body,
    *,
    hand: HandSpec,
    num_candidates: int,
    mu: float,
    seed: int | None = None,
    contact_model: ContactModel | str = ContactModel.HARD_FINGER,
    torsional_friction: float | None = None,
    clearance: float = 5e-3,
    distance_tolerance: float = DEFAULT_DISTANCE_TOLERANCE,
    robustness_samples: int = 32,
    noise: dict | None = None,
    certify: int = 10,
    weight_check: int | None = None,
    workers: int | None = 1,
    progress: bool = False,
) -> GraspCandidates:
    """Sample, filter, close and rank parallel-jaw grasps of an object body.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized, registered with a ``SceneGraph``; holds the hand (its base a
        free body), the object and anything else (a table, other objects).
    plant_context : Context
        The plant's context or its diagram's root.  The object's pose (and the
        scene's) is read from it; the hand's configuration is used as scratch
        and restored on return.
    object_body : RigidBody, BodyIndex or str
        The object to grasp (frame O).
    hand : ModelInstanceIndex, str or iterable of RigidBody
        The gripper: two prismatic fingers (see
        :mod:`drakegrasp.planning.gripper`).
    num_candidates : int
        Poses to sample, ``0 <= num_candidates <= MAX_CANDIDATES``; each
        becomes a candidate or a counted rejection.
    mu : float
        Coulomb friction coefficient of the verdicts (and of the sampler's
        cone test).
    seed : int, optional
        Seed of every random draw (sampling and robustness noise).  The same
        seed gives the same candidates.
    contact_model : {"hard_finger", "soft_finger", "frictionless"}, optional
    torsional_friction : float, optional
        ``ν`` of soft fingers.
    clearance : float, optional
        Gap (m) left on each side of the object by the pre-grasp opening.
    distance_tolerance : float, optional
        Contact and penetration tolerance (m), as in
        :func:`~drakegrasp.find_contacts`.
    robustness_samples : int, optional
        Perturbed copies per force-closure candidate (0: robustness 0).
    noise : dict, optional
        ``{"position": m, "angle_deg": deg, "friction": relative}``; default
        :data:`~drakegrasp.planning.ranking.DEFAULT_NOISE`.
    certify : int, optional
        The best ``certify`` candidates also get the single-grasp verdict with
        its certificate (``GraspCandidate.closure``).
    weight_check : int or None, optional
        How many force-closure candidates get their weight capacity and a
        score: None (default) all of them; a number limits the LPs (one per
        grasp) to the best by ``ε × robustness``, which is faster but may miss
        good grasps (see :mod:`drakegrasp.planning.ranking`).
    workers : int, optional
        Worker processes of the batch engine (default 1).
    progress : bool, optional
        A tqdm bar over the Drake stages (needs ``tqdm``).

    Returns
    -------
    GraspCandidates
        Ranked best first; ``rejections`` counts the other samples by reason
        (:data:`REASONS`); ``reason`` says why when it is empty.

    Raises
    ------
    InvalidOptionError
        Bad options (``num_candidates`` negative, not an integer or above
        :data:`MAX_CANDIDATES`; ``mu`` negative...).
    ModelError
        A hand that is not a free-based parallel jaw, an object without
        graspable collision geometry.
    """
    t0 = time.perf_counter()
    n = _check_count(num_candidates)
    mu = check_coefficient("mu", mu, error=InvalidOptionError)
    tol = check_distance_tolerance(distance_tolerance)
    clearance = real_scalar("clearance", clearance)
    if not clearance >= 0:
        raise InvalidOptionError(f"clearance must be >= 0 metres, got {clearance}")
    noise = {**DEFAULT_NOISE, **(noise or {})}
    if set(noise) != set(DEFAULT_NOISE) or any(not v >= 0 for v in noise.values()):
        raise InvalidOptionError(
            f"noise takes non-negative {sorted(DEFAULT_NOISE)}, got {noise!r}"
        )
    if weight_check is not None and (
        isinstance(weight_check, bool)
        or not isinstance(weight_check, int | np.integer)
        or weight_check < 0
    ):
        raise InvalidOptionError(
            f"weight_check must be an integer >= 0 or None, got {weight_check!r}"
        )
    model = ContactModel(contact_model).value
    ctx = plant_context_of(plant, plant_context)
    body = resolve_object_body(plant, object_body)
    gripper = parallel_jaw(plant, ctx, body, hand)
    surface = object_surface(plant, ctx, body)
    X_WO = plant.EvalBodyPoseInWorld(ctx, body)
    torque_scale = surface.radius_about(np.zeros(3))
    rng = np.random.default_rng(seed)
    settings = {
        "seed": seed,
        "contact_model": model,
        "torsional_friction": torsional_friction,
        "clearance": clearance,
        "distance_tolerance": tol,
        "robustness_samples": robustness_samples,
        "noise": noise,
        "gripper": gripper.to_dict(),
    }
    poses, rejections = _sample_poses(
        surface, gripper, X_WO, n, mu, clearance, rng, tol
    )
    saved = plant.GetPositions(ctx).copy()
    closer = _Closer(plant, ctx, body, hand, gripper, tol)
    kept = []
    order = range(len(poses["sample"]))
    if progress:
        from tqdm.auto import tqdm

        order = tqdm(order, desc="closing", unit="pose")
    try:
        for k in order:
            X_WH = RigidTransform(RotationMatrix(poses["R_WH"][k]), poses["p_WH"][k])
            opening = float(poses["opening"][k])
            reason = closer.place(X_WH, opening)
            if reason is None:
                q, reason = closer.close(opening)
            if reason is None:
                found, reason = closer.contacts()
            if reason is not None:
                rejections[reason] += 1
                continue
            kept.append((int(poses["sample"][k]), X_WH, q, opening, found))
    finally:
        plant.SetPositions(ctx, saved)
    candidates = _rank(
        kept, closer, gripper, mu, model, torsional_friction, torque_scale,
        robustness_samples, noise, rng, certify, workers, X_WO, body, plant,
        weight_check,
    )  # fmt: skip
    reason = ""
    if not candidates:
        reason = (
            "num_candidates is 0"
            if n == 0
            else f"all {n} sampled poses were rejected (see rejections)"
        )
    return GraspCandidates(
        candidates=candidates,
        rejections=dict(rejections),
        num_sampled=n,
        object_body=scoped_name(plant, body),
        mu=mu,
        torque_scale=torque_scale,
        reason=reason,
        settings=settings,
        time=time.perf_counter() - t0,
    )


def _finger_label(contact, names) -> int:
    """0 or 1 for a contact of finger 0 or 1, 2 for another hand body (palm)."""
    for f, bodies in enumerate(names):
        if contact.finger_body in bodies:
            return f
    return 2


def _squeeze(weight: float, alpha: float) -> float:
    if not np.isfinite(alpha):
        return float("nan")
    return float(weight / alpha) if alpha > 0 else float("inf")


def _rank(
    kept, closer, gripper, mu, model, nu, torque_scale, samples, noise, rng,
    certify, workers, X_WO, body, plant, weight_check,
):  # fmt: skip
    """Stage 4: verdicts, ε, robustness and score in the batch engine."""
    if not kept:
        return ()
    counts = np.array([len(k[4]) for k in kept])
    K = len(kept)
    is_closure = np.zeros(K, bool)
    d_star = np.zeros(K)
    rank = np.zeros(K, int)
    eps = np.zeros(K)
    rho = np.zeros(K)
    names = closer.finger_names
    for idx in group_by_count(counts).values():
        P = np.array([[c.p_OC for c in kept[i][4]] for i in idx])
        Nrm = np.array([[c.nhat_O for c in kept[i][4]] for i in idx])
        F = np.array([[_finger_label(c, names) for c in kept[i][4]] for i in idx])
        fc, ds, rk, ep = verdicts(
            P, Nrm, mu, torque_scale=torque_scale, model=model,
            torsional_friction=nu, workers=workers,
        )  # fmt: skip
        is_closure[idx], d_star[idx], rank[idx], eps[idx] = fc, ds, rk, ep
        closed = idx[fc]
        if len(closed):
            rho[closed] = robustness(
                P[fc], Nrm[fc], F[fc], mu, samples=samples, rng=rng, noise=noise,
                model=model, torsional_friction=nu, workers=workers,
            )  # fmt: skip
    samples_of = np.array([k[0] for k in kept])
    pre = eps * rho
    checked = rank_order(pre, d_star, samples_of)
    checked = checked[is_closure[checked]][:weight_check]
    alpha = np.full(K, np.nan)
    for idx in group_by_count(counts[checked]).values():
        idx = checked[idx]
        alpha[idx] = weight_capacity(
            np.array([[c.p_OC for c in kept[i][4]] for i in idx]),
            np.array([[c.nhat_O for c in kept[i][4]] for i in idx]),
            np.array([[_finger_label(c, names) for c in kept[i][4]] for i in idx]),
            mu, torque_scale=torque_scale, model=model, torsional_friction=nu,
        ).min(axis=1)  # fmt: skip
    score = np.where(np.isfinite(alpha), alpha * rho, 0.0)
    order = np.lexsort((samples_of, -d_star, -pre, -score))
    weight = body.get_mass(closer.ctx) * GRAVITY
    base = scoped_name(plant, gripper.base)
    joint_names = tuple(
        f"{plant.GetModelInstanceName(j.model_instance())}::{j.name()}"
        for j in gripper.joints
    )
    out = []
    for place, i in enumerate(order):
        sample, X_WH, q, opening, found = kept[i]
        grasp = Grasp(
            [
                Contact(c.p_OC, c.nhat_O, mu=mu, model=model, torsional_friction=nu)
                for c in found
            ]
        )
        out.append(
            GraspCandidate(
                sample=sample,
                hand_base=base,
                X_WH=X_WH,
                X_WO=X_WO,
                q_hand=np.asarray(q, float),
                joint_names=joint_names,
                closing_signs=(
                    float(np.sign(1 / gripper.pad_rate[0])),
                    float(np.sign(-1 / gripper.pad_rate[1])),
                ),
                opening=opening,
                contacts=tuple(found),
                grasp=grasp,
                is_closure=bool(is_closure[i]),
                d_star=float(d_star[i]),
                rank=int(rank[i]),
                epsilon=float(eps[i]),
                robustness=float(rho[i]),
                score=float(score[i]),
                weight_capacity=float(alpha[i]),
                squeeze_needed=_squeeze(weight, alpha[i]),
                closure=force_closure(grasp) if place < certify else None,
            )
        )
    return tuple(out)
