"""A robot drawn by ``MeshcatVisualizer`` next to a grasp drawing.

A hand drawn by Drake's ``MeshcatVisualizer`` covers the contacts it makes, so
:func:`~drakegrasp.draw_grasp` can draw on top of it (``on_top=True``) or make
it translucent; this module finds the visualizer's paths of a model and sets
their opacity.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

from pydrake.geometry import Meshcat, Role, SceneGraph
from pydrake.multibody.tree import ModelInstanceIndex

from drakegrasp.core.calls import checked_call
from drakegrasp.core.validation import describe, integer_or_none, real_scalar
from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant.validation import check_plant, model_instance
from drakegrasp.visualization.primitives import check_meshcat, check_path

__all__ = ["set_translucent", "visualizer_paths"]


@checked_call
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
    model_instances : ModelInstanceIndex or str, or a list or tuple of them
        Model instances of ``plant``, by index or name (a bare ``int`` is
        refused: wrap it as ``ModelInstanceIndex(i)``).
    prefix : str, optional
        The visualizer's prefix (``MeshcatVisualizerParams.prefix``, default
        ``"visualizer"``), a non-empty string.

    Returns
    -------
    list of str
        One path per illustration geometry, in body order.

    Raises
    ------
    InvalidOptionError
        For a model instance the plant does not have (an unknown name, an
        index out of range) or that is neither an index nor a name (``99``,
        None), a ``scene_graph`` that is not a SceneGraph or an empty
        ``prefix``.
    ModelError
        For a ``plant`` that is not a finalized MultibodyPlant.
    """
    check_plant(plant)
    if not isinstance(scene_graph, SceneGraph) and not callable(
        getattr(scene_graph, "model_inspector", None)
    ):  # SceneGraph_[float], or another scalar type's
        raise InvalidOptionError(
            "scene_graph must be the pydrake SceneGraph the plant is registered "
            f"with, got {type(scene_graph).__name__}"
        )
    prefix = check_path("prefix", prefix)
    instances = [
        _model_instance(plant, spec) for spec in _instance_list(model_instances)
    ]
    inspector = scene_graph.model_inspector()
    paths = []
    for instance in instances:
        for index in plant.GetBodyIndices(instance):
            frame = plant.GetBodyFrameIdIfExists(index)
            if frame is None:
                continue
            frame_path = inspector.GetName(frame).replace("::", "/")
            for g in inspector.GetGeometries(frame, Role.kIllustration):
                name = inspector.GetName(g).replace("::", "/")
                paths.append(f"{prefix}/{frame_path}/{name}")
    return paths


_INSTANCES = (
    "model_instances must be a ModelInstanceIndex or a model instance's name, or "
    "a list of them"
)


def _instance_list(model_instances) -> list:
    if isinstance(model_instances, ModelInstanceIndex | str):
        return [model_instances]
    if isinstance(model_instances, list | tuple):
        return list(model_instances)
    raise InvalidOptionError(
        f"{_INSTANCES}, got {describe(model_instances)}" + _index_hint(model_instances)
    )


def _index_hint(spec) -> str:
    if integer_or_none(spec) is None:
        return ""
    return " (wrap an index as ModelInstanceIndex(i))"


def _model_instance(plant, spec) -> ModelInstanceIndex:
    """A model instance of ``plant`` given by index or name (InvalidOptionError)."""
    if not isinstance(spec, ModelInstanceIndex | str):
        raise InvalidOptionError(
            f"{_INSTANCES}, got {describe(spec)}{_index_hint(spec)}"
        )
    return model_instance(
        plant, spec, argument="model_instances", error=InvalidOptionError
    )


def translucent_arguments(paths, opacity) -> tuple[list[str], float]:
    """The paths and opacity of :func:`set_translucent`, checked."""
    x = real_scalar("opacity", opacity)
    if not (0.0 < x <= 1.0):
        raise InvalidOptionError(
            f"opacity must be a real number in (0, 1], got {describe(opacity)}"
        )
    if isinstance(paths, str):
        listed = [paths]
    elif isinstance(paths, Iterable) and not isinstance(paths, bytes | Mapping):
        listed = list(paths)
    else:
        raise InvalidOptionError(
            "paths must be a Meshcat path or a sequence of them (non-empty "
            f"strings), got {describe(paths)}"
        )
    return [check_path("paths", path) for path in listed], x


@checked_call
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
        Multiplies each material's own opacity (``modulated_opacity``): a real
        number (numpy's too, not a bool or a string) in (0, 1]; 1 restores
        the original look.

    Notes
    -----
    Primitive shapes (boxes, spheres, cylinders...) become translucent in
    every browser.  Mesh files are loaded by the browser after it has applied
    the property, so a browser that connects after this call shows them
    opaque; ``draw_grasp(..., on_top=True)`` keeps a drawing visible anyway.

    Raises
    ------
    InvalidOptionError
        For an opacity that is not a real number in (0, 1] (``True``, ``"0.5"``
        and NaN too), ``paths`` that are neither a string nor an iterable
        of them (None, a number, bytes), a path that is not a non-empty
        string, or a ``meshcat`` that is not a Meshcat.
    """
    check_meshcat(meshcat)
    listed, value = translucent_arguments(paths, opacity)
    for path in listed:
        meshcat.SetProperty(path, "modulated_opacity", value)
