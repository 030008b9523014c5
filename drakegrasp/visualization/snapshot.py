"""A snapshot of a scene's geometry in Meshcat, without a visualizer.

Drake's ``MeshcatVisualizer`` has to be added to the diagram before it is
built; a scene loaded by :func:`~drakegrasp.plant.load_scene` or a plant
built elsewhere has none.  :func:`draw_scene_geometry` sends each geometry of
a ``SceneGraph`` once, at its world pose in a context, so that
:func:`~drakegrasp.draw_grasp` can draw contacts and cones among the hand and
the object.  Call it again after the configuration changes.
"""

from __future__ import annotations

from pydrake.geometry import Meshcat, Rgba, Role, SceneGraph

from drakegrasp.core.calls import checked_call
from drakegrasp.core.validation import describe, plain_str, real_scalar
from drakegrasp.errors import InvalidOptionError
from drakegrasp.visualization.primitives import check_meshcat, check_path

__all__ = ["draw_scene_geometry"]

_ROLES = {"illustration": Role.kIllustration, "proximity": Role.kProximity}
_GREY = Rgba(0.7, 0.7, 0.7, 1.0)


@checked_call
def draw_scene_geometry(
    meshcat: Meshcat,
    scene_graph: SceneGraph,
    context,
    *,
    prefix: str = "scene",
    opacity: float | None = None,
    role: str = "illustration",
) -> list[str]:
    """Draw every geometry of ``scene_graph`` at its world pose in ``context``.

    Parameters
    ----------
    meshcat : pydrake.geometry.Meshcat
        (Or an object with its ``SetObject``, ``SetTransform`` and ``Delete``.)
    scene_graph : pydrake.geometry.SceneGraph
        The scene graph of the plant (``diagram.GetSubsystemByName
        ("scene_graph")``).
    context : Context
        The scene graph's context or the root context of the diagram that
        holds it; poses are read from it (world frame W).
    prefix : str, optional
        Meshcat folder to draw in (default ``"scene"``); it is cleared first.
    opacity : float, optional
        A real number in (0, 1] (numpy reals too; not a bool or a string):
        replaces each geometry's alpha (a translucent hand lets the contacts
        show); default the geometry's own.
    role : {"illustration", "proximity"}, optional
        Which geometry to draw: what a viewer shows (default) or what
        Drake's distance queries and contacts see.  Colours come from the
        geometry's ``("phong", "diffuse")`` property, grey where it has none.

    Returns
    -------
    list of str
        The Meshcat path of each geometry drawn, ``{prefix}/{geometry id}``.

    Raises
    ------
    InvalidOptionError
        For a wrong type of ``meshcat`` or ``scene_graph``, a context that is
        neither the scene graph's nor the root context of a diagram that
        holds it (None, a plant's context, another diagram's), a ``prefix``
        that is not a non-empty path, an ``opacity`` that is not a real
        number in (0, 1], or a ``role`` that is not one of the two names (a
        list too).  Nothing is drawn then.
    """
    check_meshcat(meshcat)
    if not isinstance(scene_graph, SceneGraph):
        raise InvalidOptionError(
            "scene_graph must be a pydrake SceneGraph (diagram.GetSubsystemByName"
            f"('scene_graph')), got {type(scene_graph).__name__}"
        )
    prefix = check_path("prefix", prefix)
    role = plain_str(role)
    if type(role) is not str or role not in _ROLES:
        raise InvalidOptionError(
            f"role must be one of {sorted(_ROLES)}, got {describe(role)}"
        )
    alpha = None
    if opacity is not None:
        alpha = real_scalar("opacity", opacity)
        if not (0.0 < alpha <= 1.0):
            raise InvalidOptionError(
                f"opacity must be a real number in (0, 1], got {describe(opacity)}"
            )
    query = scene_graph.get_query_output_port().Eval(_own_context(scene_graph, context))
    inspector = query.inspector()
    meshcat.Delete(prefix)
    paths = []
    for gid in inspector.GetAllGeometryIds(_ROLES[role]):
        props = (
            inspector.GetIllustrationProperties(gid)
            if role == "illustration"
            else inspector.GetProximityProperties(gid)
        )
        rgba = props.GetPropertyOrDefault("phong", "diffuse", _GREY)
        if alpha is not None:
            rgba = Rgba(rgba.r(), rgba.g(), rgba.b(), alpha)
        path = f"{prefix}/{gid.get_value()}"
        meshcat.SetObject(path, inspector.GetShape(gid), rgba)
        meshcat.SetTransform(path, query.GetPoseInWorld(gid))
        paths.append(path)
    return paths


def _own_context(scene_graph: SceneGraph, context):
    """The scene graph's own context from its context or a root context."""
    try:
        scene_graph.ValidateContext(context)
        return context
    except (RuntimeError, TypeError):
        pass
    try:
        own = scene_graph.GetMyContextFromRoot(context)
        scene_graph.ValidateContext(own)  # a scene graph outside that diagram
        return own
    except (RuntimeError, TypeError) as err:
        raise InvalidOptionError(
            "context must be the scene graph's context or the root context of "
            f"the diagram that holds it: {err}"
        ) from None
