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

from drakegrasp._lazy import lazy_exports

_SOURCES = {
    "drakegrasp.visualization.candidates": (
        "CandidateDrawing",
        "draw_candidates",
        "plot_score_distribution",
        "score_colors",
    ),
    "drakegrasp.visualization.geometry": (
        "cone_edge_directions",
        "contact_forces_in_grasp_frame",
        "contact_pose_3d",
        "exact_cone_mesh",
        "normalize_contact_forces",
        "pyramid_mesh",
    ),
    "drakegrasp.visualization.meshcat": (
        "DEFAULT_PREFIX",
        "MESHCAT_COLORS",
        "GraspDrawing",
        "clear_grasp",
        "draw_grasp",
    ),
    "drakegrasp.visualization.plots": (
        "PLOT_COLORS",
        "PlanarGraspPlot",
        "plot_planar_grasp",
    ),
    "drakegrasp.visualization.robot": ("set_translucent", "visualizer_paths"),
    "drakegrasp.visualization.snapshot": ("draw_scene_geometry",),
    "drakegrasp.visualization.view": ("CameraView", "frame_points", "grasp_pose"),
    "drakegrasp.visualization.wrench_space": (
        "WrenchHull",
        "WrenchSpacePlot",
        "plot_wrench_space",
        "wrench_hull",
        "wrench_space_points",
    ),
}

_SUBMODULES = (
    "candidates",
    "certificate_plots",
    "escape",
    "geometry",
    "meshcat",
    "meshcat_certificates",
    "plots",
    "primitives",
    "robot",
    "snapshot",
    "view",
    "wrench_space",
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

__getattr__, __dir__ = lazy_exports(
    __name__, globals(), _SOURCES, submodules=_SUBMODULES
)
