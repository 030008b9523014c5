# ---
# jupyter:
#   jupytext:
#     formats: ipynb,py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.6
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # 7. Checking a grasp while a simulation runs
#
# The earlier notebooks analyse a grasp frozen in one configuration.  In a real
# pick the grasp changes all the time: the fingers close, the object settles in the
# hand, gravity pulls, the fingers open again.  `drakegrasp.GraspMonitor` is a Drake
# `LeafSystem` that runs the same analysis as `analyze_grasp` *inside* a running
# simulation, every `period` seconds, and reports
#
# - a vector output: status, force closure, form closure, antipodal, number of
#   contacts, $d^*$ of LP2, the Ferrari–Canny $\varepsilon$ (when asked), and the
#   grip as the simulator sees it: a *holding state* (holding, at risk, slipping,
#   dropped, ...), the friction in use $\|f_t\| / (\mu f_n)$ and the slip speed;
# - an abstract output holding the full report of the latest sample.
#
# $d^*$ is the geometric distance of the best internal force to the friction
# cones' boundaries: it depends on where the contacts are, their normals and
# $\mu$, not on how hard the fingers squeeze or what the object weighs.  Whether
# the grip *holds* is the holding state's question, read from the forces and slip
# speeds of the plant's contact results (and, without a simulation,
# `drakegrasp.grasp_forces` and the report's `load` section, tutorial 10).
#
# Here a parallel-jaw gripper picks a box off the ground, lifts it 5 cm, puts it
# down and lets go, and we watch both over time: first a firm grip, then a weak one.

# %%
import os
import time

import matplotlib.pyplot as plt
import numpy as np
from pydrake.geometry import (
    AddContactMaterial,
    AddRigidHydroelasticProperties,
    Box,
    Meshcat,
    MeshcatParams,
    MeshcatVisualizer,
    ProximityProperties,
    SceneGraphConfig,
)
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    CoulombFriction,
    MultibodyPlantConfig,
)
from pydrake.multibody.tree import FixedOffsetFrame, PdControllerGains, PrismaticJoint
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

import drakegrasp as dg

# tests/tutorials sets this to run the notebook with short loops.
TEST_MODE = os.environ.get("DRAKEGRASP_TUTORIAL_TEST") == "1"
PERIOD = 0.1 if TEST_MODE else 0.02  # seconds between two monitor samples
np.set_printoptions(precision=4, suppress=True, linewidth=110)

# %% [markdown]
# ## The pick
#
# The shipped parallel-jaw gripper hangs from the world on a vertical prismatic joint
# `lift`, fingers pointing down, above a 50 × 50 × 100 mm box (0.2 kg) resting on
# the ground.  The plant is discrete (1 ms steps, Drake's SAP solver), and its own
# PD controllers make the three actuated joints track a piecewise-linear schedule:
#
# | time (s) | fingers | lift |
# | --- | --- | --- |
# | 0 – 0.3 | open (35 mm) | 0 |
# | 0.3 – 0.7 | close to 15 mm (10 mm past the box: the PD squeezes) | 0 |
# | 1.0 – 1.5 | closed | up 5 cm |
# | 1.8 – 2.3 | closed | down |
# | 2.3 – 2.6 | open | 0 |

# %%
OPEN, CLOSED, LIFT = 0.035, 0.015, 0.05
SCHEDULE = [  # (time s, finger joint m, lift m)
    (0.0, OPEN, 0.0),
    (0.3, OPEN, 0.0),
    (0.7, CLOSED, 0.0),
    (1.0, CLOSED, 0.0),
    (1.5, CLOSED, LIFT),
    (1.8, CLOSED, LIFT),
    (2.3, CLOSED, 0.0),
    (2.6, OPEN, 0.0),
    (3.0, OPEN, 0.0),
]


def build_pick(
    *, flat=False, plant_contact="point", meshcat=None, closed=CLOSED, **monitor_options
):
    """Gripper, box, ground, PD schedule and a GraspMonitor, ready to simulate."""
    builder = DiagramBuilder()
    plant_config = MultibodyPlantConfig(
        time_step=1e-3,
        contact_model=plant_contact,
        discrete_contact_approximation="sap",
    )
    scene_graph_config = SceneGraphConfig()
    if plant_contact != "point":  # hydroelastic: make the models compliant
        defaults = scene_graph_config.default_proximity_properties
        defaults.compliance_type = "compliant"
        defaults.hydroelastic_modulus = 1e6
        defaults.resolution_hint = 0.005
    plant, scene_graph = AddMultibodyPlant(plant_config, scene_graph_config, builder)
    parser = Parser(plant)
    dg.register_models(parser)
    hand_file = "parallel_jaw_flat" if flat else "parallel_jaw"
    (gripper,) = parser.AddModels(url=f"package://drakegrasp/hands/{hand_file}.sdf")
    (box,) = parser.AddModels(url="package://drakegrasp/objects/box.sdf")
    ground = ProximityProperties()
    AddContactMaterial(friction=CoulombFriction(0.5, 0.5), properties=ground)
    if plant_contact != "point":
        AddRigidHydroelasticProperties(properties=ground)
    plant.RegisterCollisionGeometry(
        plant.world_body(),
        RigidTransform([0.0, 0.0, -0.05]),
        Box(1.0, 1.0, 0.1),
        "ground",
        ground,
    )
    # The palm on a vertical slide, fingers down (a rotation by pi about x).
    base = plant.AddFrame(
        FixedOffsetFrame(
            "lift_base",
            plant.world_frame(),
            RigidTransform(RollPitchYaw(np.pi, 0.0, 0.0), [0.0, 0.0, 0.125]),
        )
    )
    palm = plant.GetBodyByName("palm", gripper)
    lift = plant.AddJoint(PrismaticJoint("lift", base, palm.body_frame(), [0, 0, -1]))
    plant.AddJointActuator("lift", lift, 200.0)
    plant.Finalize()
    for index in plant.GetJointActuatorIndices(gripper):
        actuator = plant.get_mutable_joint_actuator(index)
        kp, kd = (20000.0, 400.0) if actuator.name() == "lift" else (300.0, 10.0)
        actuator.set_controller_gains(PdControllerGains(p=kp, d=kd))
    # Desired positions (and their derivatives) in the actuators' order.
    names = [
        plant.get_joint_actuator(i).joint().name()
        for i in plant.GetJointActuatorIndices(gripper)
    ]
    columns = {
        # `closed` sets how far past the box the PD drives the fingers: the squeeze
        "left_finger_joint": [closed if f == CLOSED else f for _, f, _ in SCHEDULE],
        "right_finger_joint": [closed if f == CLOSED else f for _, f, _ in SCHEDULE],
        "lift": [z for _, _, z in SCHEDULE],
    }
    q_desired = PiecewisePolynomial.FirstOrderHold(
        [t for t, _, _ in SCHEDULE], np.array([columns[n] for n in names])
    )
    source = builder.AddSystem(TrajectorySource(q_desired, output_derivative_order=1))
    builder.Connect(
        source.get_output_port(), plant.get_desired_state_input_port(gripper)
    )

    # The monitor: the same options as analyze_grasp, plus a period.
    monitor = dg.add_grasp_monitor(
        builder,
        plant,
        scene_graph,
        object_body=plant.GetBodyByName("box", box),
        hand=gripper,
        period=PERIOD,
        **monitor_options,
    )
    logs = {
        "verdicts": LogVectorOutput(
            monitor.get_verdicts_output_port(), builder, PERIOD
        ),
        "state": LogVectorOutput(plant.get_state_output_port(), builder, PERIOD),
    }
    if meshcat is not None:
        MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    plant_context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    for name in ("left_finger_joint", "right_finger_joint"):
        plant.GetJointByName(name, gripper).set_translation(plant_context, OPEN)
    plant.SetFreeBodyPose(
        plant_context, plant.GetBodyByName("box", box), RigidTransform([0, 0, 0.05])
    )
    return dict(
        diagram=diagram,
        plant=plant,
        box=box,
        gripper=gripper,
        monitor=monitor,
        simulator=simulator,
        logs=logs,
    )


# %% [markdown]
# The monitor's options are those of `analyze_grasp`.  Two rounded pads make two
# point contacts, which resist a torque about the line between them only through
# torsional friction, so we analyse soft fingers (ν = 0.1), with the friction the
# plant simulates (`mu="plant"`: read from the geometries' proximity properties
# with Drake's combination rule; a typed μ that disagrees would be warned about).  A simulated
# contact penetrates a little (here about 0.1 mm for a few newtons of squeeze), so
# the distance tolerance is 1 mm rather than the default 0.1 mm.

# %%
SOFT = dict(mu="plant", contact_model="soft_finger", torsional_friction=0.1)
params = MeshcatParams()
params.show_stats_plot = False
meshcat = Meshcat(params)  # open meshcat.web_url() in a browser to watch
pick = build_pick(
    distance_tolerance=1e-3, meshcat=meshcat, compute_epsilon=True, **SOFT
)

# Time every evaluation of the monitor (it stores its own wall time per sample).
costs = []
evaluate = pick["monitor"].evaluate


def timed_evaluate(context):
    sample = evaluate(context)
    costs.append(sample.seconds)
    return sample


pick["monitor"].evaluate = timed_evaluate
start = time.perf_counter()
pick["simulator"].AdvanceTo(SCHEDULE[-1][0])
wall = time.perf_counter() - start
print(f"simulated {SCHEDULE[-1][0]} s in {wall:.2f} s of wall time")
print(
    f"{len(costs)} monitor samples, {1e3 * np.median(costs):.1f} ms median, "
    f"{1e3 * np.max(costs[1:]):.1f} ms max after the first"
)

# %% [markdown]
# ## The verdict over time
#
# `VERDICT_NAMES` names the first seven rows of the logged vector (the grip
# rows that follow are named by `monitor.verdict_names`).  The status is 1 when
# the hand touches the box (the analysis ran), 0 without contact, −1 for a pose the
# analysis refuses (deep penetration, a joint beyond its limits).

# %%
from drakegrasp.systems.monitor import VERDICT_NAMES, GraspMonitor

context = pick["simulator"].get_context()
log = pick["logs"]["verdicts"].FindLog(context)
times, V = log.sample_times(), log.data()
print(VERDICT_NAMES)
previous = None
for t, v in zip(times, V.T, strict=True):
    key = (v[GraspMonitor.STATUS], v[GraspMonitor.FORCE_CLOSURE])
    if key != previous:
        values = zip(VERDICT_NAMES, v[: len(VERDICT_NAMES)], strict=True)
        print(f"t = {t:5.2f} s: " + ", ".join(f"{n} {x:.4g}" for n, x in values))
        previous = key

# %% [markdown]
# The box's height, from the logged plant state, tells when it was in the air:

# %%
plant, box = pick["plant"], pick["box"]
states = pick["logs"]["state"].FindLog(context)
scratch = plant.CreateDefaultContext()
height = []
for x in states.data().T:
    plant.SetPositionsAndVelocities(scratch, x)
    body = plant.GetBodyByName("box", box)
    height.append(plant.EvalBodyPoseInWorld(scratch, body).translation()[2])
height = np.array(height)

fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
closed = V[GraspMonitor.FORCE_CLOSURE] == 1
# fill_between(where=...) fills between consecutive True samples; a verdict holds
# from its sample to the next one, so that next sample is marked too.
shaded = closed | np.concatenate([[False], closed[:-1]])
for ax in axes:
    ax.fill_between(
        times,
        0,
        1,
        where=shaded,
        step="post",
        alpha=0.12,
        transform=ax.get_xaxis_transform(),
        label="force closure",
    )
axes[0].step(times, V[GraspMonitor.D_STAR], where="post")
axes[0].set_ylabel("LP2 $d^*$")
axes[1].step(times, V[GraspMonitor.EPSILON], where="post", color="C1")
axes[1].set_ylabel(r"Ferrari–Canny $\varepsilon$")
axes[2].plot(times, 1e3 * (height - height[0]), color="C2")
axes[2].set_ylabel("box lifted [mm]")
axes[2].set_xlabel("time [s]")
axes[0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
fig.suptitle(f"A simulated pick, checked by GraspMonitor every {1e3 * PERIOD:.0f} ms")
fig.tight_layout()

# %% [markdown]
# $d^*$ appears when the pads reach the box (~0.55 s), stays through the lift
# (the grasp's geometry does not change much: the box hangs between the pads) and
# vanishes when the fingers open (~2.5 s).  A log taken at a sample time shows the value held
# *before* that sample's update — Drake's sample-and-hold — so the plot lags the
# state by one period.
#
# ## A firm grip and a weak one: the holding state beside $d^*$
#
# Now the same pick twice with the plant's contact results as the monitor's
# source (`contacts="contact_results"`), which gives it the contact forces and
# slip speeds: once with the fingers driven 10 mm past the box (a firm squeeze of
# a few newtons), once only 3 mm past (about 1 N per finger, too little to carry
# the 0.2 kg box).  $d^*$ cannot tell them apart before the lift: the contacts
# are in the same places.  The holding state can.

# %%
from drakegrasp.systems.holding import HOLDING_STATES

UNTIL = 1.8 if TEST_MODE else SCHEDULE[-1][0]
runs = {}
for label, closed in (("firm", CLOSED), ("weak", 0.022)):
    run = build_pick(
        closed=closed, contacts="contact_results", distance_tolerance=1e-3, **SOFT
    )
    run["simulator"].AdvanceTo(UNTIL)
    ctx = run["simulator"].get_context()
    log = run["logs"]["verdicts"].FindLog(ctx)
    xs = run["logs"]["state"].FindLog(ctx).data()
    box_body = run["plant"].GetBodyByName("box", run["box"])
    scratch = run["plant"].CreateDefaultContext()
    z = []
    for x in xs.T:
        run["plant"].SetPositionsAndVelocities(scratch, x)
        z.append(run["plant"].EvalBodyPoseInWorld(scratch, box_body).translation()[2])
    runs[label] = (log.sample_times(), log.data(), np.array(z))
    seen = [HOLDING_STATES[int(c)] for c in log.data()[GraspMonitor.HOLDING]]
    lifted = 1e3 * (z[-1] - z[0])
    print(
        f"{label}: box lifted {lifted:.1f} mm by t = {UNTIL} s; states seen: "
        + ", ".join(dict.fromkeys(seen))
    )

fig, axes = plt.subplots(3, 2, figsize=(10, 7), sharex=True, sharey="row")
for col, (label, (t, V2, z)) in enumerate(runs.items()):
    axes[0, col].step(t, V2[GraspMonitor.D_STAR], where="post")
    axes[0, col].set_title(f"{label} grip")
    axes[1, col].step(t, V2[GraspMonitor.HOLDING], where="post", color="C3")
    axes[2, col].plot(t, 1e3 * (z - z[0]), color="C2")
    axes[2, col].set_xlabel("time [s]")
axes[0, 0].set_ylabel("LP2 $d^*$")
axes[1, 0].set_yticks(range(len(HOLDING_STATES)), HOLDING_STATES)
axes[1, 0].set_ylabel("holding state")
axes[2, 0].set_ylabel("box lifted [mm]")
fig.tight_layout()

# %% [markdown]
# The firm grip reads `holding` through the lift and the box rises 5 cm.  The weak
# grip has the same $d^*$ while the box is still on the ground, but when the lift
# starts the fingers slide along the box: the monitor flags `at risk` (friction
# in use at 1) as the lift starts and `slipping` 10 ms later, before the box has
# moved 5 mm relative to the fingers, and it stays `slipping` while the pads
# chatter up the box, touching it only now and then.  It says `dropped` only
# when the box has left the fingers along them: no contact for
# `hold_samples + 1` samples, and the box sliding along the fingers farther
# than `release_distance` (2 mm) from every hand body (or at rest more than
# that along them from where they last touched it), here when the pads pass
# the top of the box, about 35 mm of slide later.  A missing frame is not a drop, and a hand that opens around
# a box at rest (its fingers moving away along their normals) is a release,
# `no contact`.  The states only escalate at once; a
# calmer state needs `hold_samples + 1` samples of calmer evidence, so the plot
# does not flicker.  The thresholds are `drakegrasp.HoldingThresholds`; the
# systems tests check, on this pick and on Drake's WSG-50 with a YCB box, that
# the flag comes before the box has moved 5 mm relative to the fingers and the
# drop after it.
#
# ## A second opinion
#
# Is the monitor telling the truth?  `analyze_grasp` on a logged state, in a fresh
# context of the same diagram (so through the diagram's own scene graph, not the
# monitor's private context), must give what the monitor logged one sample later.

# %%
k = int(np.argmin(np.abs(times - 1.6)))  # the box in the air
fresh = pick["diagram"].CreateDefaultContext()
fresh_plant = plant.GetMyMutableContextFromRoot(fresh)
plant.SetPositionsAndVelocities(fresh_plant, states.data()[:, k])
report = dg.analyze_grasp(
    plant,
    fresh_plant,
    object_body=plant.GetBodyByName("box", box),
    hand=pick["gripper"],
    distance_tolerance=1e-3,
    **SOFT,
)
print(report)
assert np.isclose(report.force_closure.d_star, V[GraspMonitor.D_STAR, k + 1], rtol=1e-9)

# %% [markdown]
# ## The grasp in the air, drawn on the hand
#
# Drawn where the hand is, the contacts, cones and forces would sit inside the
# finger pads; `on_top=True` draws them over the robot that `MeshcatVisualizer`
# shows.  The pose is the logged one at 1.6 s.

# %%
pick["diagram"].ForcedPublish(fresh)  # the robot and the box at t = 1.6 s
X_WO = plant.EvalBodyPoseInWorld(fresh_plant, plant.GetBodyByName("box", box))
drawing = dg.draw_grasp(
    meshcat, report.grasp, X_WG=X_WO, result=report.force_closure, on_top=True
)
meshcat.SetCameraPose([0.1, -0.1, 0.2], X_WO.translation())
print(f"open {meshcat.web_url()}: {len(drawing.paths)} objects drawn on top")

# %% [markdown]
# The full report of the latest sample is on the monitor's abstract output port,
# with the time and the state it was computed from:

# %%
monitor = pick["monitor"]
sample = monitor.get_report_output_port().Eval(monitor.GetMyContextFromRoot(context))
print(sample)

# %% [markdown]
# ## Hydroelastic contact: the patches the simulator used
#
# With hydroelastic contact the simulator computes a contact *surface* between the
# bodies.  `contacts="contact_results"` makes the monitor read those surfaces from
# the plant's contact results instead of computing signed distances: each surface
# becomes a patch polygon, one contact per vertex, like drakegrasp's flat pads.  With
# flat pads and hard fingers, two square patches resist the torsion that two points
# cannot.

# %%
hydro = build_pick(
    flat=True,
    plant_contact="hydroelastic_with_fallback",
    contacts="contact_results",
    mu="plant",
    distance_tolerance=1e-3,
)
hydro["simulator"].AdvanceTo(1.6)  # lifted
hydro_monitor = hydro["monitor"]
lifted = hydro_monitor.evaluate(
    hydro_monitor.GetMyContextFromRoot(hydro["simulator"].get_context())
)
print(lifted)
for c in lifted.report.contacts:
    print(
        f"  {c.finger_body:<30} p_OC = {np.round(1e3 * c.p_OC, 2)} mm, "
        f"n = {np.round(c.nhat_O, 3)}  ({c.normal_source})"
    )
if not TEST_MODE:
    hydro["simulator"].AdvanceTo(SCHEDULE[-1][0])

# %% [markdown]
# Each pad's contact surface is a square within the 20 × 20 mm pad on the box's face,
# and the verdict is force closure with hard fingers.  The same monitor works with
# point contact (`contacts="geometry"`, the default, reads signed distances) and with
# any hand: pass your plant and the options you would give `analyze_grasp`.
