"""Placing the gripper on sampled grasp axes, and closing it in Drake.

:func:`sample_poses` turns a surface's samples and chords into hand poses
(stage 1 of :func:`~drakegrasp.planning.planner.plan_grasps`);
:class:`BodyCloser` places the open hand in the plant, rejects collisions,
closes the fingers by conservative advancement on Drake's signed distances and
reads the contacts with :func:`~drakegrasp.find_contacts` (stages 2 and 3).
"""

from __future__ import annotations

from collections import Counter

import numpy as np

from drakegrasp.errors import NoContactsError, PenetrationError
from drakegrasp.planning.gripper import ParallelJaw
from drakegrasp.plant.contacts import find_contacts
from drakegrasp.plant.validation import hand_bodies, scoped_name

__all__ = ["MAX_CLOSING_STEPS", "BodyCloser", "axis_frames", "sample_poses"]

MAX_CLOSING_STEPS = 50
"""Bound on the conservative-advancement steps of one closing."""


def axis_frames(d: np.ndarray, theta: np.ndarray) -> np.ndarray:
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


def sample_poses(surface, gripper: ParallelJaw, X_WO, n, mu, clearance, rng, tol):
    """Stage 1: antipodal hand poses from a surface's samples and chords.

    Parameters
    ----------
    surface : ObjectSurface or CloudSurface
        Anything with ``sample(n, rng) -> (p_O, nout_O, piece)`` and
        ``chord(p_O, d_O) -> (t_in, t_out, nexit_O)``, in frame O; optionally
        ``axes(p_O, nout_O)`` (grasp axes other than the inward normals; both
        normals must then lie in the friction cone about the axis) and
        ``approach_hint(p_O, d_O)`` (directions the approach is drawn around,
        within ±60°, instead of all round the axis).
    gripper : ParallelJaw
    X_WO : RigidTransform
    n : int
    mu, clearance, tol : float
    rng : numpy.random.Generator

    Returns
    -------
    poses : dict of arrays
        ``sample`` (kept sample indices), ``R_WH`` (K, 3, 3), ``p_WH`` (K, 3),
        ``opening`` (K,) for the kept samples.
    rejections : Counter
    """
    p_O, nout_O, _ = surface.sample(n, rng)
    theta = rng.uniform(0.0, 2 * np.pi, n)
    d_O = surface.axes(p_O, nout_O) if hasattr(surface, "axes") else -nout_O
    hint = (
        surface.approach_hint(p_O, d_O) if hasattr(surface, "approach_hint") else None
    )
    if hint is not None:  # approach from the hint's side, within ±60°
        R0 = axis_frames(d_O, np.zeros(n))
        centre = np.arctan2(
            np.sum(hint * R0[:, :, 2], axis=1), np.sum(hint * R0[:, :, 1], axis=1)
        )
        theta = centre + (theta / (2 * np.pi) - 0.5) * (2 * np.pi / 3)
    t_in, t_out, nexit_O = surface.chord(p_O, d_O)
    reasons = np.full(n, "", dtype=object)
    cos_cone = np.cos(np.arctan(mu))

    def reject(mask, reason):
        mask = mask & (reasons == "")
        reasons[mask] = reason

    reject(~(t_in >= -tol), "occluded")
    reject(np.isnan(t_out), "no opposite surface")
    reject(t_out > gripper.max_opening, "wider than the stroke")
    reject(t_out < gripper.min_opening, "narrower than the stroke")
    outside = np.sum(nexit_O * d_O, axis=1) < cos_cone
    outside |= np.sum(-nout_O * d_O, axis=1) < cos_cone  # an axis off the normal
    reject(outside, "outside the friction cone")
    keep = np.flatnonzero(reasons == "")
    R_WO = X_WO.rotation().matrix()
    centre_W = (
        p_O[keep] + 0.5 * t_out[keep, None] * d_O[keep]
    ) @ R_WO.T + X_WO.translation()
    R_WK = R_WO @ axis_frames(d_O[keep], theta[keep])  # built in O: invariant
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


class BodyCloser:
    """Stages 2 and 3 on an object body: place, filter, close, read contacts.

    Parameters
    ----------
    plant, ctx : MultibodyPlant, Context
        The plant and its own context (used as scratch).
    object_body : RigidBody or None
        None when the object is not in the plant (a point cloud): then every
        geometry outside the hand is the scene.
    hand : HandSpec
    gripper : ParallelJaw
    tol : float
        Distance tolerance, metres.
    """

    def __init__(self, plant, ctx, object_body, hand, gripper: ParallelJaw, tol):
        self.plant, self.ctx, self.object, self.hand = plant, ctx, object_body, hand
        self.g, self.tol = gripper, tol
        self.port = plant.get_geometry_query_input_port()
        anchor = plant.world_body() if object_body is None else object_body
        instances = {b.model_instance() for b in hand_bodies(plant, anchor, hand)}
        self.hand_instance_bodies = [
            plant.get_body(b)
            for i in sorted(instances)
            for b in plant.GetBodyIndices(i)
        ]
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
        self.object_geoms = (
            set()
            if object_body is None
            else set(plant.GetCollisionGeometriesForBody(object_body))
        )
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
        return self.clear_at(X_WH, self.g.q_for_opening(opening))

    def clear_at(self, X_WH, q):
        """Put the hand at ``X_WH`` and ``q``; None when it penetrates nothing.

        Else the rejection reason (the object, or the rest of the scene).
        """
        self._set(X_WH, q)
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
