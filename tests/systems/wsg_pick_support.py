"""A simulated pick with real models: the WSG-50 lifts the YCB sugar box (0.514 kg).

Drake's ``schunk_wsg_50_with_tip.sdf`` hangs from the world on a vertical
prismatic joint ``lift``, fingers pointing down; the sugar box stands on the
ground between the open fingers, its 39.1 mm side across them.  Each pad
touches the box with four 1 mm spheres (eight point contacts); the plant's
friction is μ = 1 on both models.  The plant's own PD controllers (discrete
plant, SAP, 1 ms) track a schedule: open, close, settle, lift 5 cm, hold.
The fingers' target is ``squeeze`` metres past the box faces: the PD
(1000 N/m) presses each pad with about ``1000 * squeeze`` newtons, and two
pads with μ = 1 carry the box's 5.04 N weight only above ~2.5 N each.
"""

from __future__ import annotations

import numpy as np
from holding_support import timeline
from pick_support import Pick, add_ground, add_lift, drive, monitored_pick
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig
from pydrake.systems.framework import DiagramBuilder

from drakegrasp.plant.models import use_local_drake_models

WSG_URL = "package://drake_models/wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf"
SUGAR_URL = "package://drake_models/ycb/004_sugar_box.sdf"
TOUCH = 0.01705  # finger opening q (left -q, right +q) where the pads touch, m
OPEN = 0.03  # m: 13 mm clear of each face
LIFT = 0.08  # m: the pads (16-36 mm above the ground) slide off a box left behind
LIFT_START = 0.9  # s
BOX_IN_BODY = 0.09  # box centre along the gripper body's y (towards the tips), m
BOX_HALF_HEIGHT = 0.04385  # its corner spheres above its centre, m
# (time s, opening: "open" or "closed", lift m)
SCHEDULE = [
    (0.0, "open", 0.0),
    (0.2, "open", 0.0),
    (0.6, "closed", 0.0),
    (LIFT_START, "closed", 0.0),
    (1.4, "closed", LIFT),
    (2.0, "closed", LIFT),
]
DURATION = SCHEDULE[-1][0]
FIRM, WEAK = 0.010, 0.0015  # squeeze: metres past the box faces


def build_wsg_pick(
    models_dir, *, squeeze: float, period: float = 0.01, **monitor_options
) -> Pick:
    """The pick, a GraspMonitor (``monitor_options``) and logs at ``period``."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(
        MultibodyPlantConfig(
            time_step=1e-3, contact_model="point", discrete_contact_approximation="sap"
        ),
        builder,
    )
    parser = Parser(plant)
    use_local_drake_models(parser, models_dir)
    (gripper,) = parser.AddModels(url=WSG_URL)
    (box,) = parser.AddModels(url=SUGAR_URL)
    add_ground(plant)
    # The body's y (towards the finger tips) points down: a rotation of -90 deg
    # about x.  The box centre is BOX_IN_BODY below the body origin.
    R_WB = RollPitchYaw(-np.pi / 2, 0.0, 0.0).ToRotationMatrix()
    p_WB = [0.0, 0.0, BOX_HALF_HEIGHT + BOX_IN_BODY]
    add_lift(
        plant,
        plant.GetBodyByName("body", gripper),
        RigidTransform(R_WB, p_WB),
        [0, -1, 0],
    )
    plant.Finalize()
    closed = TOUCH - squeeze
    opening = {"open": OPEN, "closed": closed}
    columns = {
        "left_finger_sliding_joint": [-opening[w] for _, w, _ in SCHEDULE],
        "right_finger_sliding_joint": [opening[w] for _, w, _ in SCHEDULE],
        "lift": [z for _, _, z in SCHEDULE],
    }
    times = [t for t, _, _ in SCHEDULE]
    drive(builder, plant, gripper, times, columns, finger_gains=(1000.0, 20.0))
    sugar = plant.get_body(plant.GetBodyIndices(box)[0])

    def initial_state(plant_context):
        plant.GetJointByName("left_finger_sliding_joint", gripper).set_translation(
            plant_context, -OPEN
        )
        plant.GetJointByName("right_finger_sliding_joint", gripper).set_translation(
            plant_context, OPEN
        )
        # Box x up, its z (39.1 mm) across the fingers (world x).
        R_WO = RotationMatrix(np.array([[0.0, 0, 1], [0, -1, 0], [1, 0, 0]]))
        plant.SetFreeBodyPose(
            plant_context, sugar, RigidTransform(R_WO, [0, 0, BOX_HALF_HEIGHT])
        )

    return monitored_pick(
        builder,
        plant,
        scene_graph,
        gripper,
        box,
        sugar,
        period=period,
        initial_state=initial_state,
        **monitor_options,
    )


def wsg_pick_timeline(models_dir, *, squeeze: float, contacts: str):
    """Run the pick to its end (μ read from the plant, 1 mm distance tolerance).

    Returns its :func:`holding_support.timeline` in the left finger's frame,
    displacements from the start of the lift.
    """
    pick = build_wsg_pick(
        models_dir,
        squeeze=squeeze,
        mu="plant",
        distance_tolerance=1e-3,
        contacts=contacts,
    )
    pick.run()
    return timeline(pick, finger="left_finger", t_ref=LIFT_START)
