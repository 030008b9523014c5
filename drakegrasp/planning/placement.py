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
from pydrake.geometry import Box, Sphere
from pydrake.math import RigidTransform

from drakegrasp.core.deprecation import keyword_only
from drakegrasp.core.validation import check_coefficient, check_length
from drakegrasp.errors import InvalidOptionError, NoContactsError, PenetrationError
from drakegrasp.planning.checks import checked_count, checked_nonnegative, checked_rng
from drakegrasp.planning.gripper import ParallelJaw
from drakegrasp.plant.contacts import (
    StagedContacts,
    resolve_staged,
    stage_contacts,
    staged_contacts,
)
from drakegrasp.plant.validation import hand_bodies, hand_contact_bodies, scoped_name

__all__ = [
    "MAX_CLOSING_STEPS",
    "PAIR_REACH",
    "SURE_PENETRATION",
    "BodyCloser",
    "axis_frames",
    "onto_coupling",
    "sample_poses",
]

MAX_CLOSING_STEPS = 50
"""Bound on the conservative-advancement steps of one closing."""

PAIR_REACH = 0.02
"""Metres a closing step's distance query reaches: a finger with nothing
nearer advances by this much (minus half the tolerance), and fewer far pairs
cross from Drake into Python."""

SURE_PENETRATION = 1e-3
"""Metres beyond the distance tolerance by which :meth:`BodyCloser.sure_collisions`
needs a hand geometry to penetrate the object before it rejects a pose without
Drake (far above the error of Drake's penetration depths)."""

# geometry roles in BodyCloser.role: outside the hand, then inside it
_SCENE, _OBJECT, _HAND, _FINGER = 0, 1, 2, 3


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


@keyword_only("mu", "clearance", "rng", "tol", after=4)
def sample_poses(surface, gripper: ParallelJaw, X_WO, n, *, mu, clearance, rng, tol):
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
        The object's pose in the world.
    n : int
        Samples to draw, an integer ``>= 0``.
    mu : float
        Friction coefficient, 0 or in ``[1e-12, 1e12]``
        (:mod:`drakegrasp.core.validation`): an axis is kept when both its
        normals lie within ``atan μ`` of it.
    clearance : float
        Metres, finite and ``>= 0``, added on each side of the chord to the
        pre-grasp opening (at most the stroke).
    rng : numpy.random.Generator
        Draws the samples and approach angles.
    tol : float
        Metres, a length ``> 0``: the distance tolerance (a sample whose
        axis enters the object more than ``tol`` before its point is
        occluded).

    Returns
    -------
    poses : dict of arrays
        ``sample`` (kept sample indices), ``R_WH`` (K, 3, 3), ``p_WH`` (K, 3),
        ``opening`` (K,) for the kept samples.
    rejections : Counter

    Raises
    ------
    GraspError
        An argument out of its range, naming it (checked before any draw).
    """
    if not all(callable(getattr(surface, f, None)) for f in ("sample", "chord")):
        raise InvalidOptionError(
            "surface must have sample(n, rng) and chord(p_O, d_O) (an "
            f"ObjectSurface or a CloudSurface), got {type(surface).__name__}"
        )
    if not isinstance(gripper, ParallelJaw):
        raise InvalidOptionError(
            f"gripper must be a ParallelJaw, got {type(gripper).__name__}"
        )
    if not isinstance(X_WO, RigidTransform):
        raise InvalidOptionError(
            f"X_WO must be a pydrake RigidTransform, got {type(X_WO).__name__}"
        )
    n = checked_count("n", n)
    mu = check_coefficient("mu", mu)
    clearance = checked_nonnegative("clearance", clearance, "metres")
    rng = checked_rng(rng)
    tol = check_length("tol", tol, error=InvalidOptionError)
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
        self.role = dict.fromkeys(self.object_geoms, _OBJECT)
        self.role.update(dict.fromkeys(self.hand_geoms, _HAND))
        self.role.update({g: _FINGER + f for g, f in self.finger_of.items()})
        # keyed by the ids' integer values: hashing a GeometryId is a Python
        # call into Drake, an int's is not (the closing loop reads every pair)
        self._role_of_value = {g.get_value(): r for g, r in self.role.items()}
        self.hand_slot, self.object_slot = {}, {}
        self._cache = {}  # names and shapes of the plant's geometries
        if object_body is not None:  # find_contacts' order: body, k_f, k_o
            for b in hand_contact_bodies(plant, object_body, hand):
                for kf, g in enumerate(plant.GetCollisionGeometriesForBody(b)):
                    self.hand_slot[g] = (int(b.index()), kf, b)
            for ko, g in enumerate(plant.GetCollisionGeometriesForBody(object_body)):
                self.object_slot[g] = ko

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

    def _witnesses(self):
        """Balls inside the hand's geometries, affine in the finger joints.

        Returns ``(p0, v, r)``: ball ``i`` is centred at ``p0[i] + v[i] @ q``
        in H (``v`` (W, 2, 3): the prismatic joints move a finger rigidly)
        with radius ``r[i]``; a sphere gives its own ball, a box its centre
        with its smallest half-size, and its corners, edge midpoints and face
        centres (radius 0); other shapes none.  None when the geometry is not
        affine in ``q`` (or the other geometries in the plant are not only the
        object, or a hand-object pair is collision filtered), so no pose is
        rejected without Drake.
        """
        plant, g = self.plant, self.g
        inspector = self.port.Eval(self.ctx).inspector()
        others = set(inspector.GetAllGeometryIds()) - self.hand_geoms
        others = {o for o in others if inspector.GetProximityProperties(o)}
        if not self.object_geoms or others - self.object_geoms:
            return None  # a scene: its collisions have their own reason
        if any(
            inspector.CollisionFiltered(a, b)
            for a in self.hand_geoms
            for b in self.object_geoms
            if inspector.GetProximityProperties(a)
        ):
            return None
        ctx = plant.CreateDefaultContext()  # scratch, the hand as in self.ctx
        plant.SetPositions(ctx, plant.GetPositions(self.ctx))
        H = g.base.body_frame()
        configurations = (np.zeros(2), np.array([1.0, 0.0]), np.array([0.0, 1.0]))
        poses = []  # per configuration, {geometry: X_HG}
        for q in configurations:
            for j, v in zip(g.joints, q, strict=True):
                j.set_translation(ctx, float(v))
            poses.append(
                {
                    geom: plant.CalcRelativeTransform(ctx, H, body.body_frame())
                    @ inspector.GetPoseInFrame(geom)
                    for body in self.hand_instance_bodies
                    for geom in plant.GetCollisionGeometriesForBody(body)
                }
            )
        p0, v, r = [], [], []
        for geom, X0 in poses[0].items():
            R = X0.rotation().matrix()
            moved = [poses[i][geom] for i in (1, 2)]
            turned = [X.rotation().matrix() for X in moved]
            if any(not np.allclose(R1, R, atol=1e-12) for R1 in turned):
                return None  # not a rigid translation per joint
            rate = np.array([X.translation() - X0.translation() for X in moved])
            shape = inspector.GetShape(geom)
            if isinstance(shape, Sphere):
                local, radius = np.zeros((1, 3)), [shape.radius()]
            elif isinstance(shape, Box):  # centre; corners, edge and face midpoints
                h = np.array([shape.width(), shape.depth(), shape.height()]) / 2
                grid = np.array(np.meshgrid(*[[-1, 0, 1]] * 3)).reshape(3, -1).T
                local = grid * h
                radius = np.where(np.all(grid == 0, axis=1), h.min(), 0.0).tolist()
            else:
                continue
            p0.append(local @ R.T + X0.translation())
            v += [rate] * len(local)
            r += radius
        if not r:
            return None
        return np.vstack(p0), np.array(v), np.array(r)

    def sure_collisions(self, poses, surface, X_WO) -> np.ndarray:
        """(K,) bool: open hands at ``poses`` that surely penetrate the object.

        Decided in numpy for all poses at once, before any Drake query: a ball
        inside a hand geometry (see ``_witnesses``) whose centre lies inside
        one of the object's convex hull pieces, at depth ``δ`` (the least
        distance to a face plane, exact inside a convex polyhedron), makes the
        two penetrate by at least ``δ + r``; past ``tol +``
        :data:`SURE_PENETRATION` Drake's signed distance of the pair is below
        ``-tol``, which :meth:`close_on_body` rejects as "hand collides with
        the object" (the plant holds no other geometry).  False where unsure.

        Parameters
        ----------
        poses : dict
            :func:`sample_poses`' ``R_WH`` (K, 3, 3), ``p_WH`` (K, 3) and
            ``opening`` (K,).
        surface : ObjectSurface
            The object's pieces, frame O.
        X_WO : RigidTransform
        """
        K = len(poses["opening"])
        sure = np.zeros(K, bool)
        hulls = [p for p in getattr(surface, "pieces", ()) if p.kind == "hull"]
        if not K or not hulls:
            return sure
        if not hasattr(self, "_witness_balls"):
            self._witness_balls = self._witnesses()
        if self._witness_balls is None:
            return sure
        p0, v, r = self._witness_balls
        q = self.g.q_for_opening(poses["opening"])  # (K, 2)
        p_H = p0 + q[:, 0, None, None] * v[:, 0] + q[:, 1, None, None] * v[:, 1]
        R_OW = X_WO.rotation().matrix().T
        R_OH = R_OW @ poses["R_WH"]  # (K, 3, 3)
        p_OH = (poses["p_WH"] - X_WO.translation()) @ R_OW.T
        p_O = p_H @ R_OH.transpose(0, 2, 1) + p_OH[:, None]  # (K, W, 3)
        for piece in hulls:
            R_OG = piece.X_OG.rotation().matrix()
            N_O = piece.normals @ R_OG.T  # the faces in O
            o_O = piece.offsets + N_O @ piece.X_OG.translation()
            height = np.full(p_O.shape[:2], -np.inf)  # (K, W): max over faces
            for n_j, o_j in zip(N_O, o_O, strict=True):
                np.maximum(height, p_O @ n_j - o_j, out=height)
            deep = (height <= 0) & (r - height > self.tol + SURE_PENETRATION)
            sure |= deep.any(axis=1)
        return sure

    def close_on_body(self, X_WH, opening):
        """Stages 2 and 3: place the open hand, close it, read the contacts.

        One ``ComputeSignedDistancePairwiseClosestPoints`` (reaching
        :data:`PAIR_REACH`) per closing step serves all three: at the open
        pose it rejects penetration, at each step it gives each finger's
        smallest distance ``ψ`` to the geometry outside the hand (at least
        ``PAIR_REACH`` when nothing is nearer), and at the closed pose its
        pairs within the tolerance are those :func:`~drakegrasp.find_contacts`
        computes one by one (bitwise: the same Drake routine), so the contacts
        are exactly what :func:`~drakegrasp.analyze_grasp` reads on the
        applied candidate (once :meth:`finish` resolved them).

        A jaw whose fingers one motor drives (``gripper.coupling``) closes
        each finger on its own, then puts them back on the coupling and
        moves the hand along the grasp axis so that each pad stays where it
        stopped (:meth:`~drakegrasp.planning.gripper.ParallelJaw.coupled`),
        and reads the contacts there.

        Returns
        -------
        contacts : StagedContacts or None
            The contacts read from Drake, their points computed by
            :meth:`finish` for every candidate at once.
        q : (2,) float or None
            The closed joint values.
        reason : str or None
            The rejection reason, None when the hand closed on the object.
        X_WH : RigidTransform
            The hand's pose: ``X_WH``, moved along the grasp axis for a
            coupled jaw.
        """
        g, tol, reach = self.g, self.tol, PAIR_REACH
        q0, q1 = (float(v) for v in g.q_for_opening(opening))
        self._set(X_WH, (q0, q1))
        # Python floats, not 2-vectors: the same IEEE arithmetic, without
        # numpy's per-call cost.  Finger 0 closes along +a, finger 1 along -a.
        rate0, rate1 = (float(r) for r in g.pad_rate)
        way0, way1 = 1.0 / rate0 > 0, -1.0 / rate1 > 0  # q grows while closing
        limit0 = float(g.upper[0] if way0 else g.lower[0])
        limit1 = float(g.upper[1] if way1 else g.lower[1])
        joint0, joint1 = g.joints
        ctx, port, role = self.ctx, self.port, self._role_of_value
        half = 0.5 * tol
        moved = True  # the hand moved (placed, or shifted onto the coupling)
        for _ in range(MAX_CLOSING_STEPS):
            query = port.Eval(ctx)
            pairs = query.ComputeSignedDistancePairwiseClosestPoints(reach)
            psi0 = psi1 = reach
            hit0 = hit1 = False
            colliding = -tol if moved else -np.inf  # ψ below: rejected
            moved = False
            for pair in pairs:
                distance = pair.distance
                if distance >= colliding and distance >= psi0 and distance >= psi1:
                    continue  # lowers no finger's ψ, penetrates nothing
                ra = role.get(pair.id_A.get_value(), _SCENE)
                rb = role.get(pair.id_B.get_value(), _SCENE)
                if (ra >= _HAND) == (rb >= _HAND):
                    continue  # both in the hand, or both outside it
                mine, other = (ra, rb) if ra >= _HAND else (rb, ra)
                if distance < colliding:
                    if other == _OBJECT:
                        return None, None, "hand collides with the object", X_WH
                    return None, None, "hand collides with the scene", X_WH
                if mine == _FINGER:
                    if distance < psi0:
                        psi0, hit0 = distance, other == _OBJECT
                elif mine == _FINGER + 1 and distance < psi1:
                    psi1, hit1 = distance, other == _OBJECT
            if psi0 <= tol and psi1 <= tol:
                if not (hit0 and hit1):
                    return None, None, "finger blocked by the scene", X_WH
                m_b = g.coupling  # q1 = m q0 + b, kept within 1e-12 m
                if m_b is not None and abs(q1 - (m_b[0] * q0 + m_b[1])) > 1e-12:
                    X_WH, q = onto_coupling(g, X_WH, (q0, q1))
                    if q is None:
                        return None, None, "coupled fingers out of their stroke", X_WH
                    q0, q1 = (float(v) for v in q)
                    self._set(X_WH, (q0, q1))
                    moved = True
                    continue
                if np.min(g.travel_left((q0, q1))) <= tol:
                    return None, None, "finger at its closed limit", X_WH
                found, reason = self._contacts(query, pairs)
                return found, np.array([q0, q1]), reason, X_WH
            # each finger advances by ψ - tol/2 (a translation by ψ cannot
            # penetrate), stopping at its closed limit; one already there
            # with ψ > tol misses the object
            new0 = q0 + (psi0 - half) / rate0 if psi0 > tol else q0 + 0.0 / rate0
            new1 = q1 + -(psi1 - half) / rate1 if psi1 > tol else q1 + -0.0 / rate1
            beyond0 = (new0 - limit0 > 0) if way0 else (new0 - limit0 < 0)
            beyond1 = (new1 - limit1 > 0) if way1 else (new1 - limit1 < 0)
            if (beyond0 and abs(q0 - limit0) <= 1e-12 and psi0 > tol) or (
                beyond1 and abs(q1 - limit1) <= 1e-12 and psi1 > tol
            ):
                return None, None, "finger misses the object", X_WH
            q0 = limit0 if beyond0 else new0
            q1 = limit1 if beyond1 else new1
            joint0.set_translation(ctx, q0)
            joint1.set_translation(ctx, q1)
        return None, None, "closing did not converge", X_WH

    def _contacts(self, query, pairs):
        """The closed hand's contacts from the last step's pairs, staged.

        Returns ``(StagedContacts, None)``: the pairs within the tolerance are
        read from Drake now, their points computed for all candidates at once
        by :meth:`finish`.
        """
        results = []
        for pair in pairs:
            if pair.distance > self.tol:  # no contact (names no closest pair)
                continue
            a, b = pair.id_A, pair.id_B
            key = self.hand_slot.get(a) or self.hand_slot.get(b)
            ko = self.object_slot.get(b if a in self.hand_slot else a)
            if key is None or ko is None:
                continue
            results.append((key[0], key[1], ko, key[2], pair))
        results.sort(key=lambda r: r[:3])
        staged = stage_contacts(
            self.plant,
            self.ctx,
            self.object,
            query,
            [(r[3], r[1], r[2], r[4]) for r in results],
            distance_tolerance=self.tol,
            cache=self._cache,
        )
        return staged, None

    def finish(self, kept: list, rejections: Counter) -> list:
        """Resolve the staged contacts of ``kept`` in one batch; drop the failures.

        ``kept`` holds ``(sample, X_WH, q, opening, contacts)`` with contacts
        staged by :meth:`close_on_body` (or already a list); the result holds
        the lists, as :func:`~drakegrasp.find_contacts` reads them on the
        applied candidate, and ``rejections`` counts the candidates dropped
        (one finger touching, or a patch corner penetrating).
        """
        staged = [k[4] for k in kept if isinstance(k[4], StagedContacts)]
        resolve_staged(staged)
        out = []
        for sample, X_WH, q, opening, found in kept:
            if isinstance(found, StagedContacts):
                found, reason = self._finished(found)
                if reason is not None:
                    rejections[reason] += 1
                    continue
            out.append((sample, X_WH, q, opening, found))
        return out

    def _finished(self, staged):
        try:
            found = staged_contacts(staged)
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


def onto_coupling(gripper: ParallelJaw, X_WH: RigidTransform, q):
    """A coupled jaw's closed pose: ``(X_WH, q)`` on its coupling, pads kept.

    ``q`` (2,): each finger stopped on its own.  Returns the hand moved along
    the grasp axis and the joint values on the coupling
    (:meth:`~drakegrasp.planning.gripper.ParallelJaw.coupled`), or
    ``(X_WH, None)`` when those leave a joint's limits.
    """
    q, shift = gripper.coupled(q)
    slack = 1e-12  # the coupling's rounding at a limit
    if not (np.all(q >= gripper.lower - slack) and np.all(q <= gripper.upper + slack)):
        return X_WH, None
    q = np.clip(q, gripper.lower, gripper.upper)
    a_W = X_WH.rotation().multiply(gripper.X_HK.rotation().col(0))
    return RigidTransform(X_WH.rotation(), X_WH.translation() + shift * a_W), q
