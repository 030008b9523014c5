"""A force-driven two-finger gripper holding a box: slips, drops and re-grips.

The review r22 audit's scene, kept small: a palm welded above a 40 x 60 x 80 mm
box, two 50 g fingers on prismatic joints (damping 2 N s/m), each pad four
2 mm spheres, driven by a squeeze force ``F(t)`` per finger; a floor 11 cm
below.  A discrete plant at 1 ms.  :func:`simulate` returns the monitors'
samples and, as independent truth, the object's height and the total normal
force the fingers apply (from the plant's own contact results).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import AddContactMaterial, Box, ProximityProperties, Sphere
from pydrake.math import RigidTransform
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    CoulombFriction,
    MultibodyPlantConfig,
)
from pydrake.multibody.tree import (
    FixedOffsetFrame,
    PrismaticJoint,
    SpatialInertia,
    UnitInertia,
)
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem

import drakegrasp as dg

HALF = np.array([0.02, 0.03, 0.04])  # the box's half sizes, m
TIP = 0.002  # pad sphere radius, m
G = 9.81


def _friction(mu: float) -> ProximityProperties:
    props = ProximityProperties()
    AddContactMaterial(friction=CoulombFriction(mu, mu), properties=props)
    return props


class _Squeeze(LeafSystem):
    def __init__(self, squeeze):
        super().__init__()
        self._squeeze = squeeze
        self.DeclareVectorOutputPort("u", 2, self._calc)

    def _calc(self, context, out):
        force = self._squeeze(context.get_time())
        out.SetFromVector([force, force])


@dataclass
class Run:
    samples: dict  # mode -> list of GraspSample, one per monitor sample
    times: np.ndarray  # (K,) s, every 10 ms
    height: np.ndarray  # (K,) m, the box's origin
    squeeze: np.ndarray  # (K,) N, total normal force of the fingers on the box

    def states(self, mode: str, start: float = 0.0, stop: float = np.inf) -> list:
        return [s.holding for s in self.samples[mode] if start <= s.time < stop]

    def first(self, mode: str, names, after: float = 0.0) -> float:
        for s in self.samples[mode]:
            if s.time >= after and s.holding in names:
                return float(s.time)
        return np.inf


def simulate(
    *,
    mu: float,
    mass: float,
    squeeze,
    duration: float,
    solver: str = "sap",
    modes=("geometry", "contact_results"),
) -> Run:
    builder = DiagramBuilder()
    config = MultibodyPlantConfig(
        time_step=1e-3, discrete_contact_approximation=solver, contact_model="point"
    )
    plant, scene_graph = AddMultibodyPlant(config, builder)
    box = plant.AddRigidBody(
        "box", SpatialInertia(mass, np.zeros(3), UnitInertia.SolidBox(*(2 * HALF)))
    )
    plant.RegisterCollisionGeometry(
        box, RigidTransform(), Box(*(2 * HALF)), "box", _friction(mu)
    )
    hand = plant.AddModelInstance("hand")
    palm = plant.AddRigidBody(
        "palm",
        hand,
        SpatialInertia(0.5, np.zeros(3), UnitInertia.SolidBox(0.15, 0.06, 0.02)),
    )
    plant.WeldFrames(
        plant.world_frame(), palm.body_frame(), RigidTransform([0, 0, 0.07])
    )
    joints = []
    for side, sign in (("left", -1.0), ("right", 1.0)):
        finger = plant.AddRigidBody(
            f"{side}_finger",
            hand,
            SpatialInertia(0.05, np.zeros(3), UnitInertia.SolidBox(0.01, 0.03, 0.08)),
        )
        k = 0
        for y in (-0.01, 0.01):
            for z in (-0.02, 0.02):
                plant.RegisterCollisionGeometry(
                    finger,
                    RigidTransform([-sign * (0.005 + TIP), y, z]),
                    Sphere(TIP),
                    f"{side}_tip{k}",
                    _friction(mu),
                )
                k += 1
        base = plant.AddFrame(
            FixedOffsetFrame(
                f"{side}_base",
                palm.body_frame(),
                RigidTransform([sign * 0.06, 0, -0.07]),
            )
        )
        joint = plant.AddJoint(
            PrismaticJoint(
                f"{side}_joint", base, finger.body_frame(), [-sign, 0, 0],
                pos_lower_limit=-0.01, pos_upper_limit=0.06, damping=2.0,
            )
        )  # fmt: skip
        plant.AddJointActuator(f"{side}_motor", joint, 200.0)
        joints.append(joint)
    plant.RegisterCollisionGeometry(
        plant.world_body(), RigidTransform([0, 0, -0.2]), Box(1, 1, 0.1), "floor",
        _friction(0.5),
    )  # fmt: skip
    plant.Finalize()
    drive = builder.AddSystem(_Squeeze(squeeze))
    builder.Connect(drive.get_output_port(0), plant.get_actuation_input_port(hand))
    monitors = {
        mode: dg.add_grasp_monitor(
            builder,
            plant,
            scene_graph,
            object_body=box,
            hand=hand,
            contacts=mode,
            mu="plant",
            distance_tolerance=1e-3,
            period=0.01,
            name=f"monitor {mode}",
        )  # fmt: skip
        for mode in modes
    }
    diagram = builder.Build()
    simulator = Simulator(diagram)
    root = simulator.get_mutable_context()
    plant_context = plant.GetMyMutableContextFromRoot(root)
    touch = 0.06 - 0.005 - 2 * TIP - HALF[0]  # tips on the box's faces
    for joint in joints:
        joint.set_translation(plant_context, touch + 5e-5)
    simulator.Initialize()
    samples = {mode: [] for mode in modes}
    times, height, pressing = [], [], []
    results = plant.get_contact_results_output_port()
    for t in np.arange(0.0, duration + 1e-9, 0.01):
        if t > 0:
            simulator.AdvanceTo(t)
        for mode, monitor in monitors.items():
            sample = monitor.get_report_output_port().Eval(
                monitor.GetMyContextFromRoot(root)
            )
            if sample.status != "not sampled" and (
                not samples[mode] or sample.time != samples[mode][-1].time
            ):
                samples[mode].append(sample)
        contact = results.Eval(plant_context)
        fn = 0.0
        for k in range(contact.num_point_pair_contacts()):
            info = contact.point_pair_contact_info(k)
            pair = {info.bodyA_index(), info.bodyB_index()}
            if box.index() in pair and plant.world_body().index() not in pair:
                fn += abs(float(info.contact_force()[0]))
        times.append(t)
        height.append(plant.EvalBodyPoseInWorld(plant_context, box).translation()[2])
        pressing.append(fn)
    return Run(samples, np.array(times), np.array(height), np.array(pressing))


def regrip(mu: float, mass: float, low: float = 0.8, hold: float = 0.1):
    """Squeeze 2x what holds, eased to ``low`` x over 0.3 s, then 2x again."""
    needed = mass * G / (2 * mu)

    def squeeze(t: float) -> float:
        if t < 1.0:
            return 2 * needed
        if t < 1.3:
            return 2 * needed * (1 - (t - 1.0) / 0.3 * (1 - low / 2))
        if t < 1.3 + hold:
            return low * needed
        return 2 * needed

    return squeeze


def let_go(mu: float, mass: float, ramp: float = 1.0):
    """Squeeze 2x what holds until 1 s, then down to 0 over ``ramp`` seconds."""
    needed = mass * G / (2 * mu)
    return lambda t: 2 * needed * (1.0 if t < 1.0 else max(0.0, 1 - (t - 1.0) / ramp))
