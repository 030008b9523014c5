r"""Multi-finger hands on a point cloud: collisions, closing, contacts.

The stages of the perception route of
:func:`~drakegrasp.planning.planner.plan_grasps` for a hand that is not a
parallel jaw (the Allegro hand, a three-finger hand).  The
plant holds the hand and the surroundings; the object is a cloud with outward
normals (:func:`~drakegrasp.planning.cloud.read_cloud`), in its centroid frame
O (:class:`~drakegrasp.planning.cloud.CloudSurface`); the driver is
:func:`~drakegrasp.planning.planner.plan_multifinger_cloud`.  Every
sampled pose becomes a candidate or is counted under one of :data:`REASONS`.

1. **Approach and pre-shape** as on a body
   (:func:`~drakegrasp.planning.approach.sample_approaches`): a cloud point,
   the approach along its inward normal (tilted), a palm stand-off, a roll
   and a pre-shape.  With a ``viewpoint`` the normals face the camera; the
   unseen side is completed by point symmetry
   (:func:`~drakegrasp.planning.cloud.complete_unseen`, an assumption the
   caller can turn off), and approaches come from either side.
2. **Collisions** with the cloud: a hand geometry with a cloud point deeper
   than the distance tolerance inside it collides.  The depth is the
   geometry's own closed-form signed distance (sphere, box, cylinder,
   capsule; Drake's ``QueryObject.ComputeSignedDistanceToPoint`` for other
   shapes) of the cloud points near it (a k-d tree ball about its bounding
   sphere: only those can be nearest).  With the rest of the plant and
   between fingers: Drake's signed distances, as on a body.  With a
   completed cloud, a hand that reaches into its interior
   (:meth:`CloudHand.inside`) is rejected, and so with a cloud given without
   a viewpoint, taken as whole (a finger link wholly inside the object holds
   no cloud point); with a ``viewpoint`` and no completion, one that reaches
   behind the seen surface (the unseen side may hold the object), open and
   closed.
3. **Closing**, as :func:`~drakegrasp.close_hand` closes on a body: each
   finger steps from the pre-shape along the steepest descent of its tip's
   distance to the cloud, ``d = −∂ψ_tip/∂q`` (re-aimed after every step,
   blocked joints dropped, followers of couplings following), until its
   distance ``ψ_f`` to the cloud's surface is within the tolerance (of
   :data:`GAP_SPACINGS` spacings, 0).  The surface is the cloud's *surfels*:
   each point's tangent disc of :data:`SURFEL_SPACINGS` spacings' radius,
   which close the gaps between sampled points that a finger would sink
   into; ``ψ_f`` is the smallest signed distance of a surfel to one of the
   finger's geometries.  Each step is
   bounded by conservative advancement (:mod:`drakegrasp.plant.advancement`:
   ``α <= (ψ_g − tol/2) / V_g`` over every finger geometry ``g``), so no step
   carries a finger through a surfel.  A finger that reaches its limits,
   circles a point where its distance stopped shrinking far from the cloud
   (the stall test ``close_hand`` applies), or takes
   :data:`~drakegrasp.plant.closing.DEFAULT_MAX_ITERATIONS` steps, misses and
   goes back to its pre-shape (it would only cross the others).
4. **Contacts**: one per touching geometry (of a touching finger or the
   palm), as :func:`~drakegrasp.find_contacts` reports one per touching pair
   of geometries on a body: the cloud point where the geometry is closest,
   with the mean of the cloud's normals there, or, across an edge (where the
   normals it nearly touches disagree, :data:`EDGE_ANGLE`), the finger's own normal
   there, as on a body where a smooth finger meets an edge; so too, on a
   completed cloud, at an open end (:data:`OPEN_END_OFFSET`: the cloud
   stops where a face was never seen, a can's rim without its caps).  Each contact
   also carries its *fan* (:data:`FAN_SIGMAS`): where the cloud within reach
   of the finger folds, the arc of normals between the faces it may meet,
   over which the ranking averages the weight capacity
   (:func:`~drakegrasp.planning.weight.fan_capacity`).  Only a box's face lying
   flat on a flat patch touches along an area and reports the patch's
   corners, as a pad on a body's flat face does (on a body, a face along a
   cylinder's side also reports the two ends of its line; a cloud has no
   axis to find it by).  (Every touched point of
   the band, or its hull's corners, made 11-28 contacts where the body
   route's analysis of the same pose finds 3-7: a finger link lying along
   the can's side became a patch 16 mm wide, resisting torsion and tilt it
   cannot resist, and inflated the verdicts, ε, weight capacity and score.)
5. **Ranking** as on a body
   (:func:`~drakegrasp.planning.ranking.rank_multifinger`).
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
from pydrake.geometry import Box, Capsule, Cylinder, Sphere
from pydrake.multibody.tree import JacobianWrtVariable
from scipy.spatial import cKDTree

from drakegrasp.planning.centring import CentredCloser, chain_groups
from drakegrasp.planning.cloud import (
    CONTACT_BAND,
    SHADOW_PROBES,
    CloudContact,
    CloudSurface,
    _hull_corners,
)
from drakegrasp.planning.surface import piece_of_shape
from drakegrasp.plant._closing_steps import stalled, unit_step
from drakegrasp.plant._shapes import bounding_sphere
from drakegrasp.plant.advancement import geometry_reach
from drakegrasp.plant.closing import DEFAULT_MAX_ITERATIONS
from drakegrasp.plant.contact_patches import PATCH_ANGLE_TOL
from drakegrasp.plant.fingers import Finger, free_part, tip_bodies
from drakegrasp.plant.validation import scoped_name

__all__ = [
    "EDGE_ANGLE",
    "FAN_SIGMAS",
    "GAP_SPACINGS",
    "OPEN_END_OFFSET",
    "OPEN_END_SPACINGS",
    "REASONS",
    "SURFEL_SPACINGS",
    "CloudHand",
    "signed_distances",
]

REASONS = {
    "hand collides with the cloud": "a cloud point lies inside the pre-shaped hand",
    "hand enters the unseen side": "the hand reaches behind a one-sided cloud "
    "(into a completed one)",
    "hand reaches inside the cloud": "the hand reaches behind the surface of a "
    "cloud given without a viewpoint (a whole one), into the object",
    "hand collides with the scene": "the pre-shaped hand penetrates another body",
    "fingers miss the object": "fewer than min_fingers fingers reach the cloud",
    "finger blocked by the scene": "a closed finger penetrates another body",
    "one finger touches": "the contacts come from fewer than two fingers",
    "fingers collide with each other": "two fingers (or a finger and the palm) "
    "penetrate each other, in the pre-shape or after closing",
}
"""Every rejection reason of the multi-finger cloud route, with what it means."""

GAP_SPACINGS = 0.0
"""Fingers stop this many cloud spacings short of the cloud's surfels (the
tangent discs, :data:`SURFEL_SPACINGS`): on them, within the distance
tolerance.  Stopped at the bare points instead, a finger sinks between them
(on 3,000 points of the YCB soup can, 1.4 mm apart, up to 1.5 mm into the
true can); stopped half a spacing short of them, it stood 0.07-0.8 mm off the
true can and pressed with less than the shake test's squeeze.  On the
surfels the touching links of the best candidates lie -0.5 to +0.6 mm from
the true can (benchmarks/bench_cloud_hold.py: with the edge normals of
:data:`EDGE_ANGLE`, the ten best held 8 times in 10, 7 before)."""

SURFEL_SPACINGS = 0.5
"""Radius of each cloud point's surfel, in cloud spacings (median
nearest-neighbour distance): the disc about the point, across its normal, that
stands for the surface around it.  The discs cover the gaps between sampled
points that a finger would otherwise sink into; on a convex surface of
curvature radius ``R`` a disc of radius ``r`` lies at most ``r²/2R`` outside it
(0.03 mm on the soup can's side), and at an edge it overhangs by up to
``r``.  At a whole spacing 41 of 164 candidates were force closure on the
soup can's full cloud, at half a spacing 59 of 185 (before the edge normals
of :data:`EDGE_ANGLE` the ten best held 5 times in 10 at either radius)."""

_DISC = np.vstack(
    [
        np.zeros(2),
        0.5 * np.column_stack([np.cos(a := np.arange(6) * np.pi / 3), np.sin(a)]),
        np.column_stack([np.cos(b := np.arange(12) * np.pi / 6), np.sin(b)]),
    ]
)
"""Sample points of the unit disc (its centre, rings of 6 and 12): a surfel's
distance is the smallest over its samples, within ``r/2`` of the exact one."""

EDGE_ANGLE = np.radians(20.0)
"""A finger lies across an edge when the normals of the cloud points it
nearly touches (within :data:`~drakegrasp.planning.cloud.CONTACT_BAND` of its
distance) turn more than this from their mean.  There the
cloud's normal is the wrong one: a finger touching a can's rim from the side
pushes along its own surface's normal (the true can's analysis found
``(0.63, −0.08, −0.77)`` where the rim's cap points said ``(0, −1, 0)``), so
a contact on an edge takes the hand geometry's normal."""

FAN_SIGMAS = 2.0
"""A contact's normal fan holds the normals of the cloud points within this
many robustness position noises ``σ_p`` of the finger (the noise's
``"position"``; 4 mm by default): the surface a finger misplaced by up to
``2 σ_p`` may meet.  See :func:`~drakegrasp.planning.weight.fan_capacity`."""

OPEN_END_SPACINGS = 6.0
"""Radius, in cloud spacings, of the neighbourhood that tells whether a
contact lies at an open end of a completed cloud: on the
soup can's one-sided cloud (1.4 mm spacing) about 8 mm, a fingertip's
width."""

OPEN_END_OFFSET = 0.25
"""A contact lies at an open end of a completed cloud when the cloud points
within :data:`OPEN_END_SPACINGS` of it, projected on its tangent plane, have
their centroid this many neighbourhood radii away from it: about 0 inside a
surface, ``4/(3π) ≈ 0.42`` on a straight border, where the cloud stops.
On the soup can's one-sided cloud (benchmarks/bench_cloud_hold.py, 600
samples, seeds 0-2, with the can's mass) the ten best held 9, 9 and 6 times
in 10 with the finger's normal there, 3, 7 and 2 with the side's: on the true
can those contacts pushed along the axis (their normals up to 80°, median
56°, from the side's), and 12 of the 15 that fell needed more than the
test's 0.5 N·m per joint there (up to 13× the planned torque, or no torque
held them)."""

_FD = 1e-7
"""Step (m) of the central differences of a signed distance's gradient."""

_PROBES = np.vstack([_FD * np.eye(3), -_FD * np.eye(3)])
"""(6, 3) float: the central differences' steps (m), +x, +y, +z, then −x, −y, −z."""

_PROBES_AT = np.vstack([np.zeros(3), _PROBES])
"""(7, 3) float: the point itself, then ``_PROBES`` (m)."""

_EXACT_WITHIN = 5e-3
"""Distances (m) of finger geometries are exact below this, lower bounds
above it (enough to bound a closing step), so only the cloud points near a
geometry are measured."""


def signed_distances(shape, q_G: np.ndarray) -> np.ndarray | None:
    """Signed distances (m) of points to a shape, closed form, or None.

    Parameters
    ----------
    shape : pydrake.geometry.Shape
        Sphere, Box, Cylinder or Capsule (None for any other shape).
    q_G : (k, 3) float
        Points in the shape's geometry frame G, metres.

    Returns
    -------
    (k,) float or None
        Negative inside.
    """
    if isinstance(shape, Sphere):
        return np.linalg.norm(q_G, axis=1) - shape.radius()
    if isinstance(shape, Capsule):
        h = 0.5 * shape.length()
        axis = np.zeros_like(q_G)
        axis[:, 2] = np.clip(q_G[:, 2], -h, h)
        return np.linalg.norm(q_G - axis, axis=1) - shape.radius()
    if isinstance(shape, Box):
        a = np.abs(q_G) - 0.5 * np.array([shape.width(), shape.depth(), shape.height()])
    elif isinstance(shape, Cylinder):
        a = np.column_stack(
            [
                np.hypot(q_G[:, 0], q_G[:, 1]) - shape.radius(),
                np.abs(q_G[:, 2]) - 0.5 * shape.length(),
            ]
        )
    else:
        return None
    outside = np.linalg.norm(np.maximum(a, 0.0), axis=1)
    return outside + np.minimum(a.max(axis=1), 0.0)


class _Geometry:
    """One hand geometry: its body, pose in the body, shape and bounding sphere."""

    def __init__(self, inspector, gid, body, rng):
        self.id, self.body = gid, body
        self.shape = inspector.GetShape(gid)
        self.X_BG = inspector.GetPoseInFrame(gid)
        self.R_BG = self.X_BG.rotation().matrix()
        self.p_BG = self.X_BG.translation()
        centre, self.radius = bounding_sphere(self.shape)
        self.centre_G = np.asarray(centre, float)
        self.centre_B = self.R_BG @ self.centre_G + self.p_BG
        piece = piece_of_shape(self.shape, self.X_BG, inspector.GetName(gid))
        self.probes_G = piece.sample(SHADOW_PROBES, rng)[0] if piece.area > 0 else None


@dataclass(frozen=True)
class _Closing:
    """One finger as :meth:`CloudHand.close` moves it.

    Its geometries, tips (indices into them), joints (a mask over the closing
    joints) and reach (:func:`~drakegrasp.plant.advancement.geometry_reach`).
    """

    finger: Finger
    geoms: list
    tips: list
    mask: np.ndarray
    reach: np.ndarray


class CloudHand(CentredCloser):
    """Stages 2-4 on a cloud for one hand (scratch: the plant context).

    Parameters
    ----------
    plant, ctx : MultibodyPlant, Context
        The plant (hand and surroundings) and its context (scratch).
    hand : MultiFingerHand
    surface : CloudSurface
    tol : float
        Distance tolerance, metres.
    min_fingers : int
    completed : bool, optional
        The cloud's unseen side was completed (keep the hand out of it).
    fan_reach : float, optional
        Metres: a contact's fan holds the normals of the cloud points within
        this distance of the finger's surface (0: no fans).
    """

    def __init__(
        self, plant, ctx, hand, surface: CloudSurface, tol, min_fingers,
        completed=False, fan_reach=0.0,
    ):  # fmt: skip
        self.plant, self.ctx, self.hand, self.surface = plant, ctx, hand, surface
        self.completed = bool(completed)
        # a cloud without a viewpoint is taken as whole: behind its surface
        # is the object (a link wholly inside holds no cloud point)
        self.whole = surface.viewpoint is None and not self.completed
        self.fan_reach = float(fan_reach)
        self.tol, self.min_fingers = tol, int(min_fingers)
        self.margin = GAP_SPACINGS * surface.spacing
        self.points_W = surface.points + surface.origin
        self.tree = cKDTree(self.points_W)
        self.surfel = SURFEL_SPACINGS * surface.spacing
        n = surface.normals
        helper = np.where(
            (np.abs(n[:, 0]) < 0.9)[:, None], [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]
        )
        e1 = np.cross(n, helper)
        e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
        self.disc_axes = np.stack([e1, np.cross(n, e1)], axis=1)  # (M, 2, 3)
        self.port = plant.get_geometry_query_input_port()
        inspector = self.port.Eval(ctx).inspector()
        s = hand.structure
        rng = np.random.default_rng(0)  # fixed: the same probe points every call
        in_finger = {int(b.index()) for f in s.fingers for b in f.bodies}
        instances = {hand.base.model_instance()} | {
            j.model_instance() for j in s.joints
        }
        bodies = [
            plant.get_body(b)
            for i in sorted(instances)
            for b in plant.GetBodyIndices(i)
        ]
        self.hand_geoms = {
            g for b in bodies for g in plant.GetCollisionGeometriesForBody(b)
        }
        self.fingers = [
            [
                _Geometry(inspector, g, b, rng)
                for b in f.bodies
                for g in plant.GetCollisionGeometriesForBody(b)
            ]
            for f in s.fingers
        ]
        self.palm = [
            _Geometry(inspector, g, b, rng)
            for b in bodies
            if int(b.index()) not in in_finger
            for g in plant.GetCollisionGeometriesForBody(b)
        ]
        self._inspector = inspector
        self._closings = [
            self._closing(f, geoms)
            for f, geoms in zip(s.fingers, self.fingers, strict=True)
        ]
        # a finger of the contacts is a kinematic chain (two that a <mimic>
        # closes as one are two), as on a body
        self.label = {}
        for c, chain in enumerate(hand.chains):
            for b in chain.bodies:
                self.label[scoped_name(plant, b)] = c
        by_body = {}
        for g in (g for geoms in self.fingers for g in geoms):
            by_body.setdefault(int(g.body.index()), []).append(g)
        self.chain_geoms = [
            [g for b in chain.bodies for g in by_body.get(int(b.index()), [])]
            for chain in hand.chains
        ]
        self.group = chain_groups(s, hand.chains)
        self.side = list(hand.sides) or None
        self.X_WH = None
        self._by_body = by_body
        self._parts = {}  # (finger, touching bodies) -> its free part's closing

    # -- distances -------------------------------------------------------------

    def _pose(self, g: _Geometry):
        X_WB = self.plant.EvalBodyPoseInWorld(self.ctx, g.body)
        R_WB = X_WB.rotation().matrix()
        return R_WB @ g.R_BG, R_WB @ g.p_BG + X_WB.translation()

    def distance(self, g: _Geometry, within=_EXACT_WITHIN):
        """(ψ_g, its witness, cloud indices near g, their signed distances).

        ``ψ_g`` (m) is exact when it is below ``within``, else a lower bound
        (at least ``within``).  Only the points within ``r + within + s`` of
        the bounding sphere's centre ``c`` (radius ``r``; ``s`` the surfels'
        radius) are measured: the surfel of any other point ``x`` has
        ``ψ >= |x − c| − r − s``.  The witness is the index of the nearest
        measured point (of the point nearest ``c`` when none is).
        """
        psi, witness, near = self.distances([g], within)
        idx, sd = near[0]
        return psi[0], witness[0], idx, sd

    def distances(self, geoms, within=_EXACT_WITHIN):
        """:meth:`distance` of several geometries: ψ (G,), witnesses, near points."""
        poses = {}
        for g in geoms:
            if id(g.body) not in poses:
                X_WB = self.plant.EvalBodyPoseInWorld(self.ctx, g.body)
                poses[id(g.body)] = (X_WB.rotation().matrix(), X_WB.translation())
        centres = np.array(
            [poses[id(g.body)][0] @ g.centre_B + poses[id(g.body)][1] for g in geoms]
        )
        d0, i0 = self.tree.query(centres)
        # a surfel reaches its radius past its point: the points' bound less
        # that (a contact measured on surfels at 0.09 mm was screened out by
        # its points' 0.56 mm, and its fan found no points: a raw TypeError)
        psi = d0 - np.array([g.radius for g in geoms]) - self.surfel
        witness = [int(i) for i in i0]
        near = [(None, None)] * len(geoms)
        for k in np.flatnonzero(psi < within):
            g = geoms[k]
            R_WB, p_WB = poses[id(g.body)]
            reach = g.radius + within + self.surfel
            idx = self.tree.query_ball_point(centres[k], reach)
            idx = np.asarray(idx, dtype=int)
            sd = self._surfels(g, R_WB @ g.R_BG, R_WB @ g.p_BG + p_WB, idx)
            j = int(np.argmin(sd))
            psi[k], witness[k], near[k] = min(sd[j], within), int(idx[j]), (idx, sd)
        return psi, witness, near

    def _surfels(self, g: _Geometry, R, p, idx) -> np.ndarray:
        """Signed distances (m) of a geometry to the surfels of points ``idx``.

        A surfel is the disc of radius ``r`` (:data:`SURFEL_SPACINGS`) about
        a point across its normal.  Its distance lies within ``r`` of the
        point's (distance is 1-Lipschitz), so only the points whose own
        distance is within ``r`` of the smallest are measured on their discs
        (:data:`_DISC` samples); the others keep their points' distances,
        which exceed every measured surfel's.
        """
        sd = self._signed(g, R, p, self.points_W[idx])
        if len(sd) == 0:
            return sd
        near = np.flatnonzero(sd - self.surfel < sd.min())
        if len(near) == 0:  # zero-radius surfels (a cloud of repeated points)
            return sd
        offsets = self.surfel * np.einsum(
            "dk,mki->mdi", _DISC, self.disc_axes[idx[near]]
        )
        discs = self.points_W[idx[near]][:, None, :] + offsets  # (m, D, 3)
        on_disc = self._signed(g, R, p, discs.reshape(-1, 3)).reshape(len(near), -1)
        sd[near] = on_disc.min(axis=1)
        return sd

    def _descent(self, f: _Closing, psi, witness, q) -> np.ndarray:
        """Steepest descent of finger ``f``'s tip distance to the cloud.

        ``d = −∂ψ_tip/∂q = n̂ᵀ J`` at the tip geometry's closest point ``y`` to
        its witness ``x`` (``n̂`` the signed distance's gradient at ``x``, by
        central differences of the closed form, and ``y = x − ψ(x) n̂``), over
        the finger's joints (a follower's part pulled back to its leader),
        zero on joints blocked by a limit, scaled to a largest entry of 1.
        """
        s, plant, ctx = self.hand.structure, self.plant, self.ctx
        k = min(f.tips, key=lambda j: psi[j])
        g = f.geoms[k]
        x_W = self.points_W[witness[k]]
        sd, n_W = self._line(g, x_W)
        if n_W is None:
            return np.zeros_like(q)
        y_W = x_W - sd * n_W
        p_BY = plant.EvalBodyPoseInWorld(ctx, g.body).inverse().multiply(y_W)
        J = plant.CalcJacobianTranslationalVelocity(
            ctx, JacobianWrtVariable.kV, g.body.body_frame(), p_BY,
            plant.world_frame(), plant.world_frame(),
        )  # fmt: skip
        d = s.coupling.pull_back(n_W @ J[:, s.velocity_indices])
        return unit_step(np.where(f.mask, d, 0.0), q, s.lower, s.upper)

    def _line(self, g: _Geometry, x_W: np.ndarray):
        """(ψ(x), n̂_W) of a cloud point ``x_W`` and a hand geometry ``g``.

        ``ψ(x)`` its signed distance to ``g`` (m), ``n̂_W`` the gradient's unit
        direction (world frame, from ``g`` towards the point; central
        differences of the closed form), None where the gradient vanishes.
        """
        R, p = self._pose(g)
        sd = self._signed(g, R, p, x_W + _PROBES_AT @ R.T)
        grad = (sd[1:4] - sd[4:7]) / (2 * _FD)
        norm = np.linalg.norm(grad)
        if not norm > 0:
            return float(sd[0]), None
        return float(sd[0]), R @ (grad / norm)

    def _gaps(self, chains):
        """The chains' gaps to the cloud and lines towards it (world frame).

        NaN for a chain whose gap cannot be measured (no geometry, no line).
        """
        psi, lines = np.full(len(chains), np.nan), np.full((len(chains), 3), np.nan)
        for i, c in enumerate(chains):
            geoms = self.chain_geoms[c]
            if not geoms:
                continue
            d, witness, _ = self.distances(geoms, within=np.inf)
            k = int(np.argmin(d))
            _, n_W = self._line(geoms[k], self.points_W[witness[k]])
            if n_W is not None:
                psi[i], lines[i] = d[k], n_W
        return psi, lines

    def _signed(self, g: _Geometry, R, p, points_W) -> np.ndarray:
        sd = signed_distances(g.shape, (points_W - p) @ R)
        if sd is None:  # another shape: Drake's distance to each point
            query = self.port.Eval(self.ctx)
            sd = np.array(
                [
                    next(
                        r.distance
                        for r in query.ComputeSignedDistanceToPoint(x, np.inf)
                        if r.id_G == g.id
                    )
                    for x in points_W
                ]
            )
        return sd

    def collides(self) -> bool:
        """Whether a cloud point lies deeper than ``tol`` inside a hand geometry."""
        every = [*self.palm, *(g for f in self.fingers for g in f)]
        return bool(np.any(self.distances(every, 2 * self.tol)[0] < -self.tol))

    def in_shadow(self) -> bool:
        """Whether the hand reaches behind a one-sided cloud's seen surface.

        As :meth:`drakegrasp.planning.cloud.CloudFingers.in_shadow`: a probe
        point of a hand geometry farther along a camera ray than a cloud point
        within one spacing of that ray, by more than two spacings plus the
        tolerance, lies where the unseen object may be.
        """
        if self.completed:
            return self.inside()
        view = self.surface.viewpoint
        if view is None:
            return False
        camera = view + self.surface.origin
        rho = self.surface.spacing
        for g in (*self.palm, *(g for f in self.fingers for g in f)):
            if g.probes_G is None:
                continue
            R, p = self._pose(g)
            h = g.probes_G @ R.T + p - camera
            dist = np.linalg.norm(h, axis=1)
            u = h / dist[:, None]
            c = R @ g.centre_G + p
            idx = self.tree.query_ball_point(c, g.radius + rho)
            if not idx:
                continue
            q = self.points_W[np.asarray(idx, dtype=int)] - camera
            along = u @ q.T
            perp2 = np.sum(q * q, axis=1)[None, :] - along**2
            if np.any(
                (perp2 <= rho * rho) & (along < dist[:, None] - self.tol - 2 * rho)
            ):
                return True
        return False

    def inside(self) -> bool:
        """Whether the hand reaches into a completed cloud's interior.

        A probe point ``x`` of a hand geometry lies inside when its nearest
        cloud point ``p`` (outward normal ``n``) has ``(x − p)·n < −tol`` and
        ``x`` lies within two spacings of ``p``'s normal line: behind the
        surface near it (the open ends of a completed can's side count as
        inside, as the unseen caps would be there).
        """
        rho = self.surface.spacing
        for g in (*self.palm, *(g for f in self.fingers for g in f)):
            if g.probes_G is None:
                continue
            R, p = self._pose(g)
            x = g.probes_G @ R.T + p
            _, j = self.tree.query(x)
            h = x - self.points_W[j]
            along = np.sum(h * self.surface.normals[j], axis=1)
            across = np.linalg.norm(
                h - along[:, None] * self.surface.normals[j], axis=1
            )
            if np.any((along < -self.tol) & (across <= 2 * rho)):
                return True
        return False

    def penetration(self):
        """None, ``"scene"`` or ``"hand"``: what a hand geometry penetrates."""
        query = self.port.Eval(self.ctx)
        found = None
        for pair in query.ComputeSignedDistancePairwiseClosestPoints(0.0):
            in_a, in_b = pair.id_A in self.hand_geoms, pair.id_B in self.hand_geoms
            if not (in_a or in_b) or pair.distance >= -self.tol:
                continue
            if in_a and in_b:
                found = "hand"
                continue
            return "scene"
        return found

    # -- closing ---------------------------------------------------------------

    def _set(self, q_all, q):
        s = self.hand.structure
        q_all[s.position_indices] = s.coupling.apply(q)
        self.plant.SetPositions(self.ctx, q_all)

    def _part(self, f: int, closing: _Closing, bodies) -> _Closing | None:
        """The closing of a coupled finger's free part (cached per touching bodies).

        :func:`~drakegrasp.plant.fingers.free_part`: the chains of finger
        ``f`` coupled to none that touches close on, as on a body.
        """
        key = (f, tuple(sorted(int(b.index()) for b in bodies)))
        if key not in self._parts:
            part = free_part(self.plant, self.hand.structure, closing.finger, bodies)
            by_body = self._by_body
            geoms = (
                []
                if part is None
                else [g for b in part.bodies for g in by_body.get(int(b.index()), [])]
            )
            self._parts[key] = self._closing(part, geoms) if geoms else None
        return self._parts[key]

    def _closing(self, finger: Finger, geoms: list) -> _Closing:
        """A finger's closing: its tips among ``geoms``, its joints, its reach."""
        s, plant = self.hand.structure, self.plant
        tip = {int(b.index()) for b in tip_bodies(plant, s, finger)}
        return _Closing(
            finger=finger,
            geoms=geoms,
            tips=[k for k, g in enumerate(geoms) if int(g.body.index()) in tip]
            or list(range(len(geoms))),
            mask=np.isin(np.arange(len(s.names)), list(finger.joints)),
            reach=geometry_reach(
                plant, self.ctx, s, [(g.id, g.body) for g in geoms], self._inspector
            ),
        )

    def close(self, q_pre):
        """Close every finger onto the cloud: (q, the touching fingers' geometries).

        A coupled finger's free part (:func:`~drakegrasp.plant.fingers.free_part`)
        closes on after the finger touches, as :func:`~drakegrasp.close_hand`
        does on a body.
        """
        s = self.hand.structure
        lower, upper = s.lower, s.upper
        touch, target = self.margin + self.tol, self.margin + 0.5 * self.tol
        q_all = self.plant.GetPositions(self.ctx)
        q = q_pre.copy()
        closings = list(self._closings)
        status = ["" if c.geoms else "fixed" for c in closings]
        watch = [SimpleNamespace(trail=[], best=np.inf, since_best=0) for _ in closings]
        for _ in range(DEFAULT_MAX_ITERATIONS):
            if all(status):
                break
            self._set(q_all, q)
            for f, c in enumerate(list(closings)):
                if status[f]:
                    continue
                psi, witness, _ = self.distances(c.geoms)
                if psi.min() <= touch:
                    status[f] = "touching"
                    if f < len(s.fingers):  # a coupled finger's free part goes on
                        near = {
                            int(g.body.index()): g.body
                            for g, d in zip(c.geoms, psi, strict=True)
                            if d <= touch
                        }
                        part = self._part(f, c, list(near.values()))
                        if part is not None:
                            closings.append(part)
                            status.append("")
                            watch.append(
                                SimpleNamespace(trail=[], best=np.inf, since_best=0)
                            )
                    continue
                if stalled(watch[f], q.copy(), float(psi.min()), target, touch):
                    status[f] = "not converged"  # it circles, far from the cloud
                    continue
                d = self._descent(c, psi, witness, q)
                with np.errstate(divide="ignore", invalid="ignore"):
                    t = np.where(d > 0, (upper - q) / d, (lower - q) / d)
                t = np.where(d != 0, np.where(np.isfinite(t), t, 1e3), 0.0)
                alpha_end = float(t.max(initial=0.0))
                if alpha_end <= 1e-12:
                    status[f] = "at limit"
                    continue
                speed = c.reach @ np.abs(s.coupling.tangent(d))
                moving = speed > 0
                alpha = np.min(
                    np.maximum(psi[moving] - target, 0.0) / speed[moving],
                    initial=np.inf,
                )
                alpha = min(float(alpha), c.finger.max_step, alpha_end)
                q = np.where(c.mask, np.clip(q + alpha * d, lower, upper), q)
        touching = [f for f, st in enumerate(status) if st == "touching"]
        for f, c in enumerate(closings):  # a finger or free part that misses
            if f not in touching:  # stays open
                q = np.where(c.mask, q_pre, q)
        self._set(q_all, q)
        return q, [closings[f].geoms for f in touching]

    def contacts(self, touching) -> list[CloudContact]:
        """One contact per touching geometry of the touching fingers and the palm.

        ``touching``: the geometries of each touching finger (:meth:`close`).

        As :func:`~drakegrasp.find_contacts` reports one contact per pair of
        touching geometries on a body (stage 4 of the module's description).
        """
        out = []
        for geoms in [*touching, self.palm]:
            for g in geoms:
                out += self._geometry_contacts(g)
        return out

    def _geometry_contacts(self, g: _Geometry) -> list[CloudContact]:
        """The contacts of one hand geometry with the cloud (none if it is clear).

        The geometry touches when its distance ``ψ_g`` to the cloud is within
        ``margin + tol``.  Its *closest points* are the cloud points within
        ``tol`` of ``ψ_g``: the contact point is the one nearest their
        centroid (well defined along a line contact), the contact normal
        their normals' mean (the mean over the whole touched patch tilts by
        6° where a box's edge touches the can's side).  A box's face flat on
        a flat patch (every normal of the *patch*, the points within
        :data:`~drakegrasp.planning.cloud.CONTACT_BAND` of ``ψ_g``, and the
        face's within :data:`~drakegrasp.plant.contact_patches.PATCH_ANGLE_TOL`
        of the mean) touches along an area, as a pad on a body's flat face:
        the corners of the closest points' convex hull across the normal, each
        with the mean normal.
        """
        touch = self.margin + self.tol
        psi, _, idx, sd = self.distance(g, within=touch + CONTACT_BAND)
        if idx is None or psi > touch:
            return []
        closest = np.flatnonzero(sd <= psi + self.tol)
        p_closest = self.surface.points[idx[closest]]
        n_O = self.surface.normals[idx[closest]].mean(axis=0)
        if not np.linalg.norm(n_O) > 1e-9:  # opposite normals cancel (a thin wall)
            n_O = self.surface.normals[idx[int(np.argmin(sd))]]
        n_O = n_O / np.linalg.norm(n_O)
        normals = self.surface.normals[idx[sd <= psi + CONTACT_BAND]]
        fan = self._fan(g, psi, n_O)
        if isinstance(g.shape, Box) and self._flat(g, normals, n_O):
            keep = [closest[k] for k in _hull_corners(p_closest, n_O)]
        else:
            centre = p_closest.mean(axis=0)
            keep = [closest[int(np.argmin(np.sum((p_closest - centre) ** 2, 1)))]]
            at = idx[keep[0]]
            if _spread(normals) > EDGE_ANGLE or (  # the finger lies across an edge
                self.completed and self._open_end(at)
            ):
                n_O = self._hand_normal(g, self.points_W[at])
        name = scoped_name(self.plant, g.body)
        return [
            CloudContact(
                p_OC=self.surface.points[idx[k]].copy(),
                nhat_O=-n_O,
                psi=float(sd[k]),
                finger_body=name,
                fan=fan,
            )
            for k in keep
        ]

    def _open_end(self, i: int) -> bool:
        """Whether cloud point ``i`` lies at an open end of a completed cloud.

        The completion (:func:`~drakegrasp.planning.cloud.complete_unseen`)
        mirrors what the camera saw, so a face it never saw (a can's caps, seen
        edge-on or from behind) is missing from both halves, and the cloud
        stops at the face's edge (the can's rim).  The object goes on there,
        and a finger touching the rim meets its corner: as on an edge
        (:data:`EDGE_ANGLE`) the contact normal is the finger's own.  The test
        is ``_open_end`` on the points within :data:`OPEN_END_SPACINGS`
        spacings of point ``i``.

        Parameters
        ----------
        i : int
            Index of the contact's cloud point (a row of the surface's points).

        Returns
        -------
        bool
        """
        radius = OPEN_END_SPACINGS * self.surface.spacing
        near = self.tree.query_ball_point(self.points_W[i], radius)
        return _open_end(
            self.points_W[np.asarray(near, dtype=int)] - self.points_W[i],
            self.surface.normals[i],
            radius,
        )

    def _fan(self, g: _Geometry, psi: float, n_O: np.ndarray):
        """The contact's normal fan (:func:`_fan`): the normals within reach."""
        if not self.fan_reach > 0:
            return None
        _, _, idx, sd = self.distance(g, within=psi + self.fan_reach + self.tol)
        return _fan(self.surface.normals[idx[sd <= psi + self.fan_reach]], n_O)

    def _hand_normal(self, g: _Geometry, x_W: np.ndarray) -> np.ndarray:
        """The hand geometry's outward normal towards a cloud point, world frame.

        The gradient of the geometry's signed distance at ``x_W`` (central
        differences of its closed form), negated: the object's outward normal
        at a contact on an object's edge, where the finger's smooth surface,
        not the object's, fixes the contact normal.
        """
        R, p = self._pose(g)
        sd = self._signed(g, R, p, x_W + _PROBES)
        grad = (sd[:3] - sd[3:]) / (2 * _FD)
        return -grad / np.linalg.norm(grad)

    def _flat(self, g: _Geometry, normals: np.ndarray, n_O: np.ndarray) -> bool:
        """Whether a box's face lies flat on a flat patch of outward normals."""
        cos_tol = np.cos(PATCH_ANGLE_TOL)
        if np.min(normals @ n_O) < cos_tol:
            return False  # a curved patch: a line or a point touches
        R, _ = self._pose(g)  # the box's face normals are ±R's columns
        return bool(np.max(np.abs(R.T @ n_O)) >= cos_tol)

    def _close(self, X_WH, q_pre):
        """One closing at ``X_WH``: (contacts, q, reason, chains touching)."""
        plant, ctx, s = self.plant, self.ctx, self.hand.structure
        plant.SetFreeBodyPose(ctx, self.hand.base, X_WH)
        self._set(plant.GetPositions(ctx), q_pre)
        hit = self.penetration()
        if hit is not None:
            reason = (
                "fingers collide with each other"
                if hit == "hand"
                else "hand collides with the scene"
            )
            return None, None, reason, set()
        if self.collides():
            return None, None, "hand collides with the cloud", set()
        if self.in_shadow():
            return None, None, "hand enters the unseen side", set()
        if self.whole and self.inside():
            return None, None, "hand reaches inside the cloud", set()
        q, touching = self.close(q_pre)
        # the chains that close as one count once here; below, each
        if len(touching) < min(self.min_fingers, len(s.fingers)):
            return None, None, "fingers miss the object", set()
        hit = self.penetration()
        if hit == "scene":
            return None, None, "finger blocked by the scene", set()
        if hit == "hand":
            return None, None, "fingers collide with each other", set()
        if self.in_shadow():
            return None, None, "hand enters the unseen side", set()
        if self.whole and self.inside():
            return None, None, "hand reaches inside the cloud", set()
        found = self.contacts(touching)
        fingers = {self.label.get(c.finger_body, -1) for c in found} - {-1}
        if len(fingers) < 2:
            return None, None, "one finger touches", fingers
        if len(fingers) < self.min_fingers:  # chains that closed as one finger
            return None, None, "fingers miss the object", fingers
        return found, s.coupling.apply(q), None, fingers


def _fan(normals: np.ndarray, n_O: np.ndarray) -> np.ndarray | None:
    """The arc of normals at an edge: its inward ends ``(2, 3)``, or None.

    ``normals`` are the outward normals of the cloud points within
    :data:`FAN_SIGMAS` placement noise of the finger, ``n_O`` the contact's
    outward normal.  None when none turns more than :data:`EDGE_ANGLE` from
    ``n_O`` (a smooth patch); else the ends ``a``, the normal turned most
    from ``n_O``, and ``b``, the one turned most from ``a`` (an edge's two
    faces), negated.
    """
    if len(normals) == 0:
        return None
    cos = normals @ n_O
    i = int(np.argmin(cos))
    if not cos[i] < np.cos(EDGE_ANGLE):
        return None
    a = normals[i]
    b = normals[int(np.argmin(normals @ a))]
    return -np.array([a, b])


def _open_end(offsets: np.ndarray, n: np.ndarray, radius: float) -> bool:
    """Whether a surface point lies where its cloud stops (an open border).

    Parameters
    ----------
    offsets : (k, 3) float
        The cloud points within ``radius`` of the point, minus the point,
        metres (any frame with world axes).
    n : (3,) float
        The point's unit normal, same axes.
    radius : float
        The neighbourhood's radius, metres.

    Returns
    -------
    bool
        The offsets' centroid, projected on the tangent plane (across ``n``),
        lies more than :data:`OPEN_END_OFFSET` ``radius`` from the point.
    """
    if len(offsets) == 0:
        return False
    mean = offsets.mean(axis=0)
    across = mean - (mean @ n) * n
    return bool(np.linalg.norm(across) > OPEN_END_OFFSET * radius)


def _spread(normals: np.ndarray) -> float:
    """Largest angle (rad) of unit normals (k, 3) from their mean (π if it is 0)."""
    mean = normals.mean(axis=0)
    norm = np.linalg.norm(mean)
    if not norm > 1e-9:
        return np.pi
    return float(np.arccos(np.clip(np.min(normals @ (mean / norm)), -1.0, 1.0)))
