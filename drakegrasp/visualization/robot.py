"""A robot drawn by ``MeshcatVisualizer`` next to a grasp drawing.

A hand drawn by Drake's ``MeshcatVisualizer`` covers the contacts it makes, so
:func:`~drakegrasp.draw_grasp` can draw on top of it (``on_top=True``) or make
it translucent; this module finds the visualizer's paths of a model and sets
their opacity.
"""

from __future__ import annotations

from collections.abc import Sequence

from pydrake.geometry import Meshcat, Role
from pydrake.multibody.tree import ModelInstanceIndex

from drakegrasp.errors import InvalidOptionError

__all__ = ["set_translucent", "visualizer_paths"]


def visualizer_paths(
    plant, scene_graph, model_instances, *, prefix: str = "visualizer"
) -> list[str]:
    """Meshcat paths where ``MeshcatVisualizer`` draws some model instances.

    ``MeshcatVisualizer`` draws the illustration geometry ``g`` of frame ``F``
    at ``{prefix}/{name of F}/{name of g}``, with every ``::`` of the scoped
    names turned into ``/``; this lists those paths for the bodies of the
    given model instances (e.g. the hand, to pass to :func:`set_translucent`).

    Parameters
    ----------
    plant : pydrake.multibody.plant.MultibodyPlant
        Finalized, registered with ``scene_graph``.
    scene_graph : pydrake.geometry.SceneGraph
    model_instances : ModelInstanceIndex or str, or a sequence of them
    prefix : str, optional
        The visualizer's prefix (``MeshcatVisualizerParams.prefix``, default
        ``"visualizer"``).

    Returns
    -------
    list of str
        One path per illustration geometry, in body order.
    """
    if isinstance(model_instances, ModelInstanceIndex | str):
        model_instances = [model_instances]
    inspector = scene_graph.model_inspector()
    paths = []
    for instance in model_instances:
        if isinstance(instance, str):
            if not plant.HasModelInstanceNamed(instance):
                raise InvalidOptionError(f"no model instance named {instance!r}")
            instance = plant.GetModelInstanceByName(instance)
        for index in plant.GetBodyIndices(instance):
            frame = plant.GetBodyFrameIdIfExists(index)
            if frame is None:
                continue
            frame_path = inspector.GetName(frame).replace("::", "/")
            for g in inspector.GetGeometries(frame, Role.kIllustration):
                name = inspector.GetName(g).replace("::", "/")
                paths.append(f"{prefix}/{frame_path}/{name}")
    return paths


def set_translucent(
    meshcat: Meshcat, paths: str | Sequence[str], opacity: float = 0.3
) -> None:
    """Make what is drawn under each path translucent (e.g. a robot's meshes).

    Parameters
    ----------
    meshcat : pydrake.geometry.Meshcat
    paths : str or sequence of str
        Meshcat paths; everything below each one is affected.  For a robot
        drawn by ``MeshcatVisualizer`` pass the paths of its geometries,
        :func:`visualizer_paths` (not the model's folder: a browser that
        connects later receives a folder's properties before its children).
    opacity : float, optional
        Multiplies each material's own opacity (``modulated_opacity``), in
        (0, 1]; 1 restores the original look.

    Notes
    -----
    Primitive shapes (boxes, spheres, cylinders...) become translucent in
    every browser.  Mesh files are loaded by the browser after it has applied
    the property, so a browser that connects after this call shows them
    opaque; ``draw_grasp(..., on_top=True)`` keeps a drawing visible anyway.

    Raises
    ------
    InvalidOptionError
        For an opacity outside (0, 1] or a path that is not a non-empty string.
    """
    value = float(opacity) if isinstance(opacity, int | float) else float("nan")
    if not (0.0 < value <= 1.0):
        raise InvalidOptionError(f"opacity must be in (0, 1], got {opacity!r}")
    for path in [paths] if isinstance(paths, str) else list(paths):
        if not isinstance(path, str) or not path.strip("/"):
            raise InvalidOptionError(f"paths must be non-empty strings, got {path!r}")
        meshcat.SetProperty(path, "modulated_opacity", value)
