"""Pictures of grasps: Meshcat drawings and matplotlib plots.

- :func:`draw_grasp` / :func:`clear_grasp`: contacts, contact frames, friction
  cones and contact forces in Drake's Meshcat, framed by the camera
  (:func:`frame_points`).
- :func:`draw_scene_geometry`: a snapshot of a scene's hand and object in
  Meshcat, for a diagram built without a ``MeshcatVisualizer``.
- :func:`draw_candidates` / :func:`plot_score_distribution`: planned grasps as
  ghost hands coloured by score in Meshcat, and their scores' histogram.
- :func:`plot_planar_grasp`: a planar grasp with its outline, normals, exact
  cones and forces (matplotlib).
- :func:`plot_wrench_space`: the primitive wrenches of a planar grasp and their
  convex hull, with the origin marked (matplotlib, scipy).

matplotlib and scipy are imported only when a plot is made, so importing this
package needs neither.
"""

from drakegrasp.visualization.candidates import (
    CandidateDrawing,
    draw_candidates,
    plot_score_distribution,
    score_colors,
)
from drakegrasp.visualization.geometry import (
    cone_edge_directions,
    contact_forces_in_grasp_frame,
    contact_pose_3d,
    exact_cone_mesh,
    normalize_contact_forces,
    pyramid_mesh,
)
from drakegrasp.visualization.meshcat import (
    DEFAULT_PREFIX,
    MESHCAT_COLORS,
    GraspDrawing,
    clear_grasp,
    draw_grasp,
)
from drakegrasp.visualization.plots import (
    PLOT_COLORS,
    PlanarGraspPlot,
    plot_planar_grasp,
)
from drakegrasp.visualization.robot import set_translucent, visualizer_paths
from drakegrasp.visualization.snapshot import draw_scene_geometry
from drakegrasp.visualization.view import CameraView, frame_points, grasp_pose
from drakegrasp.visualization.wrench_space import (
    WrenchHull,
    WrenchSpacePlot,
    plot_wrench_space,
    wrench_hull,
    wrench_space_points,
)

__all__ = [
    "CameraView",
    "DEFAULT_PREFIX",
    "CandidateDrawing",
    "MESHCAT_COLORS",
    "PLOT_COLORS",
    "GraspDrawing",
    "PlanarGraspPlot",
    "WrenchHull",
    "WrenchSpacePlot",
    "clear_grasp",
    "cone_edge_directions",
    "contact_forces_in_grasp_frame",
    "contact_pose_3d",
    "draw_candidates",
    "draw_grasp",
    "draw_scene_geometry",
    "exact_cone_mesh",
    "frame_points",
    "grasp_pose",
    "normalize_contact_forces",
    "plot_planar_grasp",
    "plot_score_distribution",
    "plot_wrench_space",
    "pyramid_mesh",
    "score_colors",
    "set_translucent",
    "visualizer_paths",
    "wrench_hull",
    "wrench_space_points",
]
