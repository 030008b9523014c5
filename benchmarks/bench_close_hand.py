"""Wall time of ``close_hand`` on Drake's real hands (median of repeated closings).

Usage::

    python benchmarks/bench_close_hand.py [--repeats 30] [--drake-models DIR]

Each case builds its diagram once (outside the clock), then repeatedly resets
the hand to its pre-shape and times one ``close_hand`` call: the fingers'
signed distances, Jacobians and steps until every finger touches or stops.
Targets (issue 8): <= 50 ms for the WSG-50 on a box, <= 200 ms for the
Allegro hand on a ball (a hand-written march-and-bisect loop took 0.66 s).
``drake_models`` comes from ``--drake-models``, else ``$DRAKEGRASP_DRAKE_MODELS``,
else ``../shared/drake_models``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from pydrake.math import RigidTransform, RollPitchYaw  # noqa: E402
from pydrake.multibody.parsing import Parser  # noqa: E402
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph  # noqa: E402
from pydrake.systems.framework import DiagramBuilder  # noqa: E402

from drakegrasp import analyze_grasp, close_hand  # noqa: E402
from drakegrasp.plant.models import (  # noqa: E402
    DRAKE_MODELS_ENV,
    register_models,
    use_local_drake_models,
)

DM = "package://drake_models/"
CASES = {
    # name: (hand url, frame welded to the world, object url, X_WO rpy deg + xyz,
    #        pre-shape as {joint: value})
    "WSG-50 on the YCB sugar box": (
        DM + "wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf",
        "body",
        DM + "ycb/004_sugar_box.sdf",
        ((90, 0, 90), (0, 0.09, 0)),
        {"left_finger_sliding_joint": -0.05, "right_finger_sliding_joint": 0.05},
    ),
    "WSG-50 on the 50 mm box": (
        DM + "wsg_50_description/sdf/schunk_wsg_50_with_tip.sdf",
        "body",
        "package://drakegrasp/objects/box.sdf",
        ((0, 0, 0), (0, 0.09, 0)),
        {"left_finger_sliding_joint": -0.05, "right_finger_sliding_joint": 0.05},
    ),
    "Franka hand on the 50 mm box": (
        DM + "franka_description/urdf/hand.urdf",
        "panda_hand",
        "package://drakegrasp/objects/box.sdf",
        ((0, 0, 0), (0, 0.005, 0.135)),
        {"panda_finger_joint1": 0.04, "panda_finger_joint2": 0.04},
    ),
    "Allegro hand on the 35 mm ball": (
        DM + "allegro_hand_description/sdf/allegro_hand_description_right.sdf",
        "hand_root",
        "package://drakegrasp/objects/sphere.sdf",
        ((0, 0, 0), (0.08, 0, 0.1)),
        {"joint_12": 1.0},
    ),
    "Allegro hand on the YCB soup can": (
        DM + "allegro_hand_description/sdf/allegro_hand_description_right.sdf",
        "hand_root",
        DM + "ycb/005_tomato_soup_can.sdf",
        ((90, 0, 0), (0.075, 0, 0.1)),
        {"joint_12": 1.0},
    ),
}


def build(models: Path, hand_url, frame, object_url, pose, preshape):
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    parser = Parser(plant)
    use_local_drake_models(parser, models)
    register_models(parser)
    hand = parser.AddModels(url=hand_url)[0]
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(frame, hand))
    obj_instance = parser.AddModels(url=object_url)[0]
    plant.Finalize()
    diagram = builder.Build()
    root = diagram.CreateDefaultContext()
    ctx = plant.GetMyContextFromRoot(root)
    obj = plant.get_body(plant.GetBodyIndices(obj_instance)[0])
    rpy, xyz = pose
    X_WO = RigidTransform(RollPitchYaw(np.radians(rpy)), list(xyz))
    plant.SetFreeBodyPose(ctx, obj, X_WO)
    q = plant.GetPositions(ctx)
    for name, value in preshape.items():
        q[plant.GetJointByName(name, hand).position_start()] = value
    plant.SetPositions(ctx, q)
    return plant, diagram, root, ctx, hand, obj


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=30)
    parser.add_argument("--drake-models", type=Path, default=None)
    args = parser.parse_args()
    models = args.drake_models or Path(
        os.environ.get(DRAKE_MODELS_ENV)
        or Path(__file__).resolve().parents[2] / "shared" / "drake_models"
    )
    print(f"drake_models: {models}; {args.repeats} closings per case\n")
    print(
        f"{'case':<34} {'median ms':>9} {'p90 ms':>7} {'steps':>5}  "
        f"{'touching':>8}  force closure (mu 0.5)"
    )
    for name, case in CASES.items():
        plant, _, root, ctx, hand, obj = build(models, *case)
        q0 = plant.GetPositions(ctx).copy()
        times, result = [], None
        for _ in range(args.repeats + 3):
            plant.SetPositions(ctx, q0)
            t0 = time.perf_counter()
            result = close_hand(plant, root, obj, hand=hand)
            times.append(time.perf_counter() - t0)
        times = 1e3 * np.array(times[3:])
        report = analyze_grasp(plant, ctx, obj, hand=hand, mu=0.5)
        touching = f"{len(result.touching_fingers)}/{len(result.fingers)}"
        print(
            f"{name:<34} {np.median(times):9.2f} {np.percentile(times, 90):7.2f} "
            f"{result.iterations:5d}  {touching:>8}  "
            f"{'YES' if report.is_force_closure else 'no'} "
            f"(d* {report.force_closure.d_star:.3g}, {report.grasp.num_contacts} "
            "contacts)"
        )


if __name__ == "__main__":
    main()
